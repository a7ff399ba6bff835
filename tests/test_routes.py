"""model.controllers.anicov.routes: the best spacing, the spiral and its symmetries, its pieces, who flies which, and progress."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from model.controllers.anicov.lane_planner import LOOKAHEAD
from model.controllers.anicov.routes import (
    CENTRE_ALLOWANCE_LEADS,
    ORDERED_VARIANTS,
    SEAM_OVERLAP,
    Route,
    assign_pieces,
    balanced_routes,
    balanced_routes_on,
    best_lane_spacing,
    bottleneck_assignment,
    lead_in,
    spiral_path,
    spiral_pieces,
    spiral_variants,
)
from model.paper.metrics import coverage_distance, straight_pass_coverage
from model.scenario import Scenario

PAPER = Scenario()


def test_the_best_spacing_is_where_two_full_speed_passes_just_bring_the_midpoint_to_lambda_star():
    spacing = best_lane_spacing(PAPER)
    midway = straight_pass_coverage(spacing / 2.0, PAPER.range, PAPER.half_angle, PAPER.alpha_max)
    assert 2.0 * midway == pytest.approx(PAPER.lambda_star, rel=1e-4)
    d50 = coverage_distance(PAPER.lambda_star / 2.0, PAPER.range, PAPER.half_angle, PAPER.alpha_max)
    assert spacing == pytest.approx(2.0 * d50, rel=1e-4)  # 7.73 on the paper's sensor (Fig. 7)
    # A slower sensor profile moves it: with Λ* doubled full speed no longer reaches it at 2·d50.
    assert best_lane_spacing(PAPER.with_overrides(lambda_star=200.0)) < spacing


def test_the_spiral_stays_inside_its_rings_at_most_a_spacing_apart_down_to_the_centre():
    spacing = best_lane_spacing(PAPER)
    path = spiral_path(PAPER, spacing)
    d100 = coverage_distance(PAPER.lambda_star, PAPER.range, PAPER.half_angle, PAPER.alpha_max)
    assert path.min() >= d100 - 1e-9 and path.max() <= 100.0 - d100 + 1e-9
    assert np.allclose(path[:2], [(d100, d100), (100.0 - d100, d100)])  # the outer ring first, d100 in
    steps = np.diff(path, axis=0)
    assert np.all((np.abs(steps[:, 0]) < 1e-9) | (np.abs(steps[:, 1]) < 1e-9))  # axis-aligned runs only
    lows = sorted({round(x, 9) for x, y in path if abs(x - y) < 1e-9 and x < 50.0})  # each ring's corner
    assert max(np.diff(lows)) <= spacing + 1e-9
    assert 50.0 - lows[-1] <= d100 + 1e-9  # the innermost ring within one pass's full coverage of the centre
    wide = spiral_path(PAPER.with_overrides(domain=[200.0, 50.0]), spacing)
    assert wide[:, 0].max() > 190.0 and wide[:, 1].max() < 50.0


def test_the_pieces_cover_the_spiral_and_each_robot_flies_one_inward_the_first_after_a_run_up():
    scenario = PAPER.with_overrides(agents=3)
    spacing = best_lane_spacing(scenario)
    whole = Route.of(spiral_path(scenario, spacing)).length
    pieces = spiral_pieces(scenario, spacing)
    assert [Route.of(piece).length for piece in pieces] == pytest.approx([whole / 3] * 3)
    starts = np.array([pieces[2][0] + [1.0, 0.0], pieces[0][-1] + [0.0, 1.0], pieces[1][0]])
    routes = assign_pieces(pieces, starts, lead=5.0)
    assert all(np.allclose(route[0], start) for route, start in zip(routes, starts, strict=True))
    for route in routes:  # its piece, flown as the spiral goes; the spiral's start entered 5 before it
        k, piece = next((k, piece) for k, piece in enumerate(pieces) if np.allclose(route[-1], piece[-1]))
        if k == 0:
            assert np.allclose(route[2:], piece) and np.linalg.norm(route[2] - route[1]) == pytest.approx(5.0)
            assert np.allclose(route[1], piece[0] - 5.0 * (piece[1] - piece[0]) / np.linalg.norm(piece[1] - piece[0]))
        else:  # where the piece before it ends
            assert np.allclose(route[1:], piece) and np.allclose(route[1], pieces[k - 1][-1])
    assert sorted(np.allclose(route[-1], piece[-1]) for route in routes for piece in pieces).count(True) == 3


def test_the_bottleneck_assignment_minimises_the_longest_cost_where_the_least_total_would_not():
    cost = np.array([[0.0, 5.0], [5.0, 9.0]])  # least total: 0 + 9 (longest 9); least longest: 5 + 5
    rows, cols = bottleneck_assignment(cost)
    assert cost[rows, cols].max() == 5.0
    big = np.random.default_rng(3).uniform(0, 100, (12, 12))
    rows, cols = bottleneck_assignment(big)
    assert sorted(cols) == list(range(12))
    best_total_rows, best_total_cols = linear_sum_assignment(big)
    assert big[rows, cols].max() <= big[best_total_rows, best_total_cols].max()


def test_balanced_pieces_make_every_robot_finish_closer_together_than_equal_ones():
    scenario = PAPER.with_overrides(agents=6, seed=2)
    spacing, lead = best_lane_spacing(scenario), 7.6
    positions = np.random.default_rng(2).uniform(0, 100, (6, 2))

    def finishes(routes):
        """Transit + run-up + piece (time at k_v), and the passes left at the centre for the robot that ends
        there (CENTRE_ALLOWANCE_LEADS run-ups)."""
        lengths = np.array([Route.of(route).length for route in routes])
        at_centre = np.argmin([np.linalg.norm(route[-1] - 50.0) for route in routes])
        lengths[at_centre] += CENTRE_ALLOWANCE_LEADS * lead
        return lengths

    equal = finishes(assign_pieces(spiral_pieces(scenario, spacing), positions, lead))
    routes = balanced_routes(scenario, spacing, positions, lead)
    balanced = finishes(routes)
    assert max(balanced) < max(equal)
    # Every robot, the one at the centre too, done together: that one flies the allowance less of its route.
    assert max(balanced) - min(balanced) < 2.0
    flown = np.array([Route.of(route).length for route in routes])
    at_centre = int(np.argmin([np.linalg.norm(route[-1] - 50.0) for route in routes]))
    assert np.delete(flown, at_centre).min() - flown[at_centre] > CENTRE_ALLOWANCE_LEADS * lead - 2.0


def test_the_spiral_is_flown_on_one_of_the_soonest_of_its_8_symmetries_with_every_robot_done_at_once():
    scenario = PAPER.with_overrides(agents=4, domain=[100.0, 60.0])
    spacing, lead = best_lane_spacing(scenario), lead_in(scenario, best_lane_spacing(scenario))
    variants = spiral_variants(scenario, spacing)
    lengths = [Route.of(variant).length for variant in variants]
    assert lengths == pytest.approx([lengths[0]] * 8)  # the same rings ...
    for axis in (0, 1):
        rings = set(np.round(variants[0][:, axis], 6))
        assert all(set(np.round(variant[:, axis], 6)) == rings for variant in variants)
    innermost = variants[0][-4:]  # the last ring's corners: every variant ends on one (the centre allowance)
    corners = {(x, y) for x in np.round(innermost[:, 0], 6) for y in np.round(innermost[:, 1], 6)}
    assert all(tuple(np.round(variant[-1], 6)) in corners for variant in variants)
    assert len({tuple(np.round(variant[0], 6)) for variant in variants}) == 4  # ... from each corner ...
    assert len({tuple(np.round(np.r_[variant[0], variant[1]], 6)) for variant in variants}) == 8  # either way round
    for variant in variants:
        assert variant[:, 0].min() > 0.0 and variant[:, 0].max() < 100.0
        assert variant[:, 1].min() > 0.0 and variant[:, 1].max() < 60.0
    positions = np.random.default_rng(7).uniform([0.0, 0.0], [100.0, 60.0], (4, 2))
    finishes = [balanced_routes_on(scenario, variant, positions, lead)[1] for variant in variants]
    assert min(finishes) < finishes[0]  # here the spiral as drawn is not the best start
    chosen = balanced_routes(scenario, spacing, positions, lead)
    # Flown on one of the ORDERED_VARIANTS soonest symmetries (whose order of robots is then improved):
    # the route with a run-up enters that variant's first stretch; every robot is done at once, no later
    # than the resized pieces would have been but for the seams' overlaps.
    soonest = np.argsort(finishes, kind="stable")[:ORDERED_VARIANTS]
    starts = [route for route in chosen if len(route) > 2 and any(np.allclose(route[2], v[0]) for v in variants)]
    flown = [k for k, v in enumerate(variants) for route in starts if _enters(route, v)]
    assert len(flown) == 1 and flown[0] in soonest
    done = _finishes(chosen, lead, variants[flown[0]][-1])
    assert done == pytest.approx([done[0]] * 4, abs=1e-6)
    assert done[0] <= min(finishes) + 2 * SEAM_OVERLAP + 1e-6  # each overlap costs at most twice its length


def _enters(route: np.ndarray, variant: np.ndarray) -> bool:
    """Whether ``route`` (position, run-up start, spiral start, ...) flies ``variant``'s first stretch."""
    ahead = (variant[1] - variant[0]) / np.linalg.norm(variant[1] - variant[0])
    run_up = (route[2] - route[1]) / np.linalg.norm(route[2] - route[1])
    return bool(np.allclose(route[2], variant[0]) and np.allclose(run_up, ahead))


def _finishes(routes: list[np.ndarray], lead: float, centre: np.ndarray) -> list[float]:
    """Transit, run-up and piece of each robot at k_v = 1, the one ending at ``centre`` counted the centre's
    allowance more."""
    return [
        Route.of(route).length + (CENTRE_ALLOWANCE_LEADS * lead if np.allclose(route[-1], centre) else 0.0)
        for route in routes
    ]


def test_progress_follows_the_robot_along_its_route_never_back_and_never_onto_the_next_ring():
    route = Route.of(np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 8.0], [0.0, 8.0]]))
    route.advance(np.array([4.0, 0.5]), window=5.0)
    assert route.progress == pytest.approx(4.0)
    route.advance(np.array([2.0, 0.0]), window=5.0)  # behind: progress stays
    assert route.progress == pytest.approx(4.0)
    route.advance(np.array([4.0, 7.5]), window=5.0)  # close to the ring above, but far ahead along it
    assert route.progress <= 9.0 + 1e-9
    assert np.allclose(route.point_at(route.length + 3.0), [0.0, 8.0])


def test_progress_on_a_pass_that_doubles_back_never_takes_the_way_back_for_the_way_out():
    """A pass over a small blob where the robot stands: out to the entry, back over the blob. Going out,
    the robot is nearer the way back than the way out; progress stays within the carrot's reach."""
    route = Route.of(np.array([[24.5, 23.35], [27.2, 23.5], [24.5, 23.5]]))
    route.advance(np.array([25.6, 23.45]), window=LOOKAHEAD)
    route.advance(np.array([26.5, 23.5]), window=LOOKAHEAD)
    assert route.progress < 2.7  # still on the way out (the corner is at 2.70)
    assert not route.done()


def test_lead_in_is_where_a_point_half_a_spacing_aside_enters_the_wedge():
    spacing = best_lane_spacing(PAPER)
    assert lead_in(PAPER, spacing) == pytest.approx(spacing / 2.0 / math.tan(PAPER.half_angle))


def test_the_symmetries_of_a_non_square_domain_do_not_check_its_scenario_again():
    """The transposed spiral is geometry only: a scenario whose poses lie outside the transposed rectangle
    (a 100 x 60 domain, a robot at x = 90) still gets its 8 spirals (it once raised ScenarioError)."""
    scenario = PAPER.with_overrides(
        agents=2, domain=[100.0, 60.0], initial_poses=[[90.0, 10.0, 0.0], [10.0, 50.0, 0.0]]
    )
    variants = spiral_variants(scenario, best_lane_spacing(scenario))
    assert len(variants) == 8
    assert all(variant[:, 0].max() < 100.0 and variant[:, 1].max() < 60.0 for variant in variants)


def test_a_domain_within_one_pass_of_its_centre_sends_every_robot_to_the_one_point_of_its_spiral():
    scenario = PAPER.with_overrides(domain=[4.0, 4.0], agents=2, controller="anicov")
    spacing = best_lane_spacing(scenario)
    positions = np.array([[1.0, 1.0], [3.0, 3.0]])
    routes = balanced_routes(scenario, spacing, positions, lead_in(scenario, spacing))
    assert [route.tolist() for route in routes] == [[[1.0, 1.0], [2.0, 2.0]], [[3.0, 3.0], [2.0, 2.0]]]
