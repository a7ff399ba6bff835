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
    order_finishes,
    start_run_ups,
)
from model.controllers.anicov.routes import (
    CENTRE_ALLOWANCE_LEADS,
    SEAM_OVERLAP,
    Route,
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
