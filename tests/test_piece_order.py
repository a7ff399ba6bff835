"""model.controllers.anicov.piece_order: pieces cut for an order of robots, the order's finish, its local search, and the run-up
before the spiral's first point."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from model.controllers.anicov.lane_planner import LOOKAHEAD
from model.controllers.anicov.piece_order import (
    Spiral,
    cuts_for,
    improved_order,
    neighbours,
    order_finishes,
    start_run_ups,
)
from model.controllers.anicov.routes import (
    CENTRE_ALLOWANCE_LEADS,
    SEAM_OVERLAP,
    Route,
    balanced_routes_on,
    best_lane_spacing,
    lead_in,
    ordered_routes,
    spiral_path,
    with_run_up,
)
from model.controllers.anicov.touch_ups import simulate_routes
from model.paper.polyline import path_between
from model.scenario import Scenario

PAPER = Scenario().with_overrides(controller="anicov")
SPACING = best_lane_spacing(PAPER)
LEAD = lead_in(PAPER, SPACING)


def _spiral(scenario: Scenario = PAPER) -> tuple[Route, Spiral]:
    whole = Route.of(spiral_path(scenario, SPACING))
    return whole, Spiral(whole.points, whole.along, LEAD, CENTRE_ALLOWANCE_LEADS * LEAD)


def _times(pieces: list[tuple[int, float, float]], positions: np.ndarray, cut_on: Spiral) -> list[float]:
    """Each piece's robot's time at k_v = 1, from the pieces themselves: transit to where the piece begins
    (the first: to its run-up, and the run-up), the piece, and the allowance for the one ending at the end."""
    times = []
    for robot, start, end in pieces:
        if start == 0.0:
            transit = float(cut_on.first_transits(positions[robot]))
        else:  # entered the overlap before its cut (or at the spiral's start, if that is nearer)
            entered = max(start - cut_on.overlap, 0.0)
            transit = float(np.linalg.norm(positions[robot] - Route.of(cut_on.points).point_at(entered)))
            transit += start - entered
        times.append(transit + end - start)
    return times


@pytest.mark.parametrize("overlap", [0.0, SEAM_OVERLAP])
def test_an_orders_finish_is_the_least_at_which_its_pieces_reach_the_spirals_end(overlap):
    whole, cut_on = _spiral()
    cut_on = Spiral(cut_on.points, cut_on.along, cut_on.lead, cut_on.allowance, overlap)
    positions = np.random.default_rng(3).uniform(0.0, 100.0, (6, 2))
    order = np.array([4, 0, 5, 2, 1, 3])
    finish = float(order_finishes(order[None, :], positions, cut_on)[0])
    pieces = cuts_for(order, finish, positions, cut_on)
    # Consecutive from the spiral's start to its end, every robot done within the finish, all at it.
    assert pieces[0][1] == 0.0 and pieces[-1][2] == pytest.approx(whole.length)
    assert all(a[2] == pytest.approx(b[1]) for a, b in itertools.pairwise(pieces))
    # Every robot but the last takes the finish exactly; the last has the allowance to spare.
    times = _times(pieces, positions, cut_on)
    assert times[:-1] == pytest.approx([finish] * (len(pieces) - 1), abs=1e-6)
    assert times[-1] + cut_on.allowance == pytest.approx(finish, abs=1e-6)
    # A little sooner, the same order's pieces fall short of the end, or the last robot's allowance does.
    sooner = cuts_for(order, finish - 0.01, positions, cut_on)
    assert (
        sooner[-1][2] < whole.length - 1e-3
        or _times(sooner, positions, cut_on)[-1] + cut_on.allowance > finish - 0.01 + 1e-6
    )
    # Many orders at once give what each gives alone.
    orders = np.array([order, order[::-1], np.roll(order, 2)])
    each = [order_finishes(o[None, :], positions, cut_on)[0] for o in orders]
    assert order_finishes(orders, positions, cut_on) == pytest.approx(each)


def test_a_robot_whose_transit_alone_is_too_long_flies_nothing_and_the_next_starts_the_spiral_with_a_run_up():
    whole, cut_on = _spiral(PAPER.with_overrides(agents=2))
    near_start = whole.points[0] + np.array([20.0, 20.0])
    far_off = np.array([5000.0, 5000.0])  # farther than the whole spiral takes one robot
    positions = np.array([far_off, near_start])
    order = np.array([0, 1])
    finish = float(order_finishes(order[None, :], positions, cut_on)[0])
    assert finish == pytest.approx(whole.length + cut_on.allowance + cut_on.first_transits(near_start), abs=1e-6)
    assert cuts_for(order, finish, positions, cut_on) == [(1, 0.0, pytest.approx(whole.length))]
    routes, routes_finish = ordered_routes(PAPER.with_overrides(agents=2), whole.points, positions, LEAD, order)
    assert routes_finish == pytest.approx(finish)
    assert np.array_equal(routes[0], far_off[None, :])  # no route: it takes passes from the start
    assert np.allclose(routes[1][2], whole.points[0]) and np.linalg.norm(routes[1][2] - routes[1][1]) == pytest.approx(
        LEAD
    )


def test_the_neighbours_are_every_swap_and_every_move_once():
    order = np.arange(6)
    around = neighbours(order)
    assert all(sorted(o) == list(range(6)) for o in around)
    assert len({tuple(o) for o in around}) == len(around) == 15 + 6 * 6 - 6 - 2 * 5  # swaps, then moves by 2+
    assert [1, 0, 2, 3, 4, 5] in around.tolist() and [1, 2, 3, 0, 4, 5] in around.tolist()


def test_the_improved_order_finds_the_best_of_all_orders_of_five_and_is_never_later_than_where_it_began():
    _, cut_on = _spiral()
    positions = np.random.default_rng(2).uniform(0.0, 100.0, (5, 2))
    every = np.array(list(itertools.permutations(range(5))))
    finishes = order_finishes(every, positions, cut_on)
    worst = every[int(np.argmax(finishes))]
    order, finish = improved_order(worst, positions, cut_on)
    assert finish == pytest.approx(finishes.min(), abs=1e-6) and finishes.min() < finishes.max() - 40.0
    assert finish == pytest.approx(float(order_finishes(order[None, :], positions, cut_on)[0]))
    # From the resized pieces' own order (model.controllers.anicov.routes), never later than they were estimated.
    scenario = PAPER.with_overrides(agents=8, seed=5)
    positions = np.random.default_rng(5).uniform(0.0, 100.0, (8, 2))
    _, resized, owners = balanced_routes_on(scenario, cut_on.points, positions, LEAD)
    assert improved_order(np.array(owners), positions, cut_on)[1] <= resized + 1e-6


def _steepest_descent_by_definition(
    order: np.ndarray, positions: np.ndarray, cut_on: Spiral
) -> tuple[np.ndarray, float]:
    """improved_order as its docstring defines it: every neighbour's rough finish bisected, the first least
    taken while it is sooner."""
    best = float(order_finishes(order[None, :], positions, cut_on)[0])
    while True:
        around = neighbours(order)
        rough = order_finishes(around, positions, cut_on, below=np.full(len(around), best))
        k = int(np.argmin(rough))
        exact = float(order_finishes(around[k : k + 1], positions, cut_on)[0])
        if rough[k] >= best - 1e-9 or exact >= best - 1e-9:
            return order, best
        order, best = around[k], exact


@pytest.mark.parametrize("seed", range(6))
def test_the_improved_order_is_the_steepest_descent_over_every_neighbours_bisected_finish(seed):
    # improved_order walks each neighbour at one T and bisects only those that reach the end there, from the
    # first place it changes: the same orders, to the bit, as bisecting all of them.
    whole, _ = _spiral()
    cut_on = Spiral(whole.points, whole.along, LEAD, CENTRE_ALLOWANCE_LEADS * LEAD, SEAM_OVERLAP)
    rng = np.random.default_rng(seed)
    agents = int(rng.integers(3, 16))
    positions = rng.uniform(-10.0, 110.0, (agents, 2))
    start = rng.permutation(agents)
    order, finish = improved_order(start, positions, cut_on)
    expected_order, expected_finish = _steepest_descent_by_definition(start, positions, cut_on)
    assert order.tolist() == expected_order.tolist() and finish == expected_finish
    assert finish < float(order_finishes(start[None, :], positions, cut_on)[0])  # it did improve


def test_a_robot_starting_near_the_spirals_first_point_gets_twice_the_run_up_and_leaves_its_corner_covered():
    whole, _ = _spiral()
    start = whole.points[0]
    assert start_run_ups(np.array([start + 1.0, start + 20.0]), start, LEAD) == pytest.approx([2 * LEAD, LEAD])
    # At (1, 1), inside the corner, the single run-up left cells of the corner short; the double one
    # none (the first 50 units flown by this robot, the rest of the spiral by another).
    robot = np.array([1.0, 1.0])
    first, rest = path_between(whole.points, 0.0, 50.0), path_between(whole.points, 50.0, whole.length)
    corner = (slice(0, round(12.0 / PAPER.cell)), slice(0, round(12.0 / PAPER.cell)))
    short = []
    for run_up in (LEAD, float(start_run_ups(robot, start, LEAD))):
        routes = [np.vstack([robot, with_run_up(first, run_up)]), rest]
        lack, _, _ = simulate_routes(PAPER, routes, np.array([robot, rest[0]]), LOOKAHEAD)
        short.append(int((lack[corner] > 0.0).sum()))
    assert short[0] > 0 and short[1] == 0


def test_the_centres_allowance_may_be_shared_by_the_robot_reaching_the_end_and_the_next_who_flies_no_spiral():
    """At a finish where robot 0 reaches the spiral's end with half the allowance to spare, robot 1 flies
    no spiral and goes to the centre with the rest: the order is done by then."""
    whole, cut_on = _spiral()
    positions = np.array([whole.points[0] + np.array([-5.0, 0.0]), whole.points[-1] + np.array([10.0, 10.0])])
    order = np.array([0, 1])
    finish = float(cut_on.first_transits(positions[0])) + whole.length + cut_on.allowance / 2.0
    pieces = cuts_for(order, finish, positions, cut_on)
    assert pieces[0] == (0, 0.0, pytest.approx(whole.length))
    assert pieces[1] == (1, pytest.approx(whole.length), pytest.approx(whole.length))
    first, helper = _times(pieces, positions, cut_on)
    assert finish - first == pytest.approx(cut_on.allowance / 2.0)  # robot 0's spare, short of the allowance
    assert finish - helper > cut_on.allowance / 2.0  # robot 1's, at the centre, is the rest and more
    assert order_finishes(order[None, :], positions, cut_on)[0] <= finish + 1e-6
    # Robot 0 alone is not done by then: it would need the whole allowance on top of the spiral.
    assert cuts_for(order[:1], finish, positions, cut_on) == [(0, 0.0, pytest.approx(whole.length))]
    assert order_finishes(order[None, :1], positions, cut_on)[0] == pytest.approx(finish + cut_on.allowance / 2.0)


def test_the_routes_give_a_robot_near_the_spirals_start_twice_the_run_up_and_the_others_their_overlap():
    scenario = PAPER.with_overrides(agents=3)
    whole, _ = _spiral(scenario)
    positions = np.array([whole.points[0] + [2.0, 2.0], [50.0, 20.0], [30.0, 70.0]])
    routes, _ = ordered_routes(scenario, whole.points, positions, LEAD, np.array([0, 1, 2]))
    first = routes[0]
    assert np.allclose(first[2], whole.points[0])
    assert np.linalg.norm(first[2] - first[1]) == pytest.approx(2 * LEAD)  # twice the run-up, from outside
    for route in routes[1:]:
        if len(route) > 1:  # entered SEAM_OVERLAP back along the spiral from where its piece is cut
            entry = Route.of(whole.points).nearest(route[1])[1]
            ends = [Route.of(whole.points).nearest(other[-1])[1] for other in routes if len(other) > 1]
            assert any(end - entry == pytest.approx(SEAM_OVERLAP, abs=1e-6) for end in ends)
