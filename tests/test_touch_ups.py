"""model.controllers.anicov.touch_ups: the cells the planned routes will leave short, foreseen, and the orbits that finish them."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.controllers.anicov.lane_planner import LOOKAHEAD, LanePlanner
from model.controllers.anicov.route import Route
from model.controllers.anicov.touch_ups import ORBIT_RADIUS, TouchUp, orbit, orbit_for, simulate_routes, with_touch_ups
from model.paper.metrics import pass_reach
from model.parameters import coverage_map_of
from model.scenario import Scenario

SMALL = Scenario().with_overrides(domain=[40.0, 40.0], agents=1, controller="anicov", weave=False, stations=False)
"""Straight passes: the touch-ups' geometry below is the straight pass's (test_weave.py has the weave)."""


def test_a_simulated_straight_pass_covers_d100_to_either_side_and_not_much_more():
    """Eq. 2-3 along a straight route at k_v: cells within d100 of its middle reach Λ*, cells well beyond
    the wedge's reach R sin F do not (Fig. 7's straight pass)."""
    route = np.array([[0.0, 20.0], [40.0, 20.0]])
    lack, _, times = simulate_routes(SMALL, [route], route[:1], LOOKAHEAD)
    d100 = pass_reach(SMALL)
    rows = np.arange(SMALL.grid_shape[0]) + 0.5
    near = np.abs(rows - 20.0) < d100 - 0.5
    far = np.abs(rows - 20.0) > SMALL.range * math.sin(SMALL.half_angle) + 1.0
    assert (lack[near, 20:30] == 0.0).all()
    assert (lack[far, :] == 1.0).all()
    assert times[0] == pytest.approx(40.0 / SMALL.k_v, rel=0.02)  # the pursuit flies it at k_v


def test_the_simulation_foretells_the_engines_run_of_the_same_route():
    """The robot's start heading aside (the planner knows positions only), the engine flies a route as
    simulate_routes does: the same cells are left short."""
    scenario = SMALL.with_overrides(initial_poses=[[3.0, 3.0, 0.0]], max_time=0.5)
    planner = LanePlanner(scenario)
    planner.plan(np.ones(scenario.grid_shape), np.array([[3.0, 3.0]]))
    route = planner.routes[0].points
    start = route[1] - route[0]
    heading = math.degrees(math.atan2(start[1], start[0]))
    lack, _, times = simulate_routes(scenario, [route], route[:1], LOOKAHEAD)
    engine = run_scenario(scenario.with_overrides(initial_poses=[[3.0, 3.0, heading]], max_time=times[0] - 0.5))
    left = engine.snapshots[-1] > 0
    assert abs(int(left.sum()) - int((lack > 0).sum())) <= 0.05 * max(int((lack > 0).sum()), 20)


def test_an_orbit_turns_about_its_centre_and_a_short_spot_gets_one_that_finishes_it():
    loop = orbit(np.array([10.0, 10.0]), ORBIT_RADIUS, 0.5, 2)
    assert np.allclose(np.linalg.norm(loop - [10.0, 10.0], axis=1), ORBIT_RADIUS)
    assert Route.of(loop).length == pytest.approx(2 * 2 * math.pi * ORBIT_RADIUS, rel=0.01)
    coverage = np.full(SMALL.grid_shape, coverage_map_of(SMALL).target_ticks, dtype=np.int64)
    spot = np.zeros(SMALL.grid_shape, dtype=bool)
    spot[19:22, 19:22] = True  # three by three cells around (20.5, 20.5) at 40 % of Λ*, the rest at Λ*
    coverage[spot] = 0.4 * coverage_map_of(SMALL).target_ticks
    centre, turns = orbit_for(SMALL, coverage, spot, LOOKAHEAD)
    loop = orbit(centre, ORBIT_RADIUS, 0.0, turns)
    lack, _, _ = simulate_routes(SMALL, [loop], loop[:1], LOOKAHEAD, coverage.copy())
    assert not (lack[spot] > 0).any()
    fewer = orbit(centre, ORBIT_RADIUS, 0.0, turns - 1) if turns > 1 else None
    if fewer is not None:  # the fewest turns that do it
        assert (simulate_routes(SMALL, [fewer], fewer[:1], LOOKAHEAD, coverage.copy())[0][spot] > 0).any()


def test_touch_ups_finish_what_the_routes_leave_and_nothing_is_added_when_they_leave_nothing():
    scenario = SMALL.with_overrides(agents=2)
    half = np.array([[0.0, 10.0], [40.0, 10.0]])  # lanes over the lower half only
    other = np.array([[40.0, 14.0], [0.0, 14.0]])
    positions = np.array([[0.0, 10.0], [40.0, 14.0]])
    routes, touch_ups = with_touch_ups(scenario, [half, other], positions, LOOKAHEAD, 7.7)
    assert sum(len(t) for t in touch_ups) >= 1
    for robot, route in enumerate(routes):
        for touch_up in touch_ups[robot]:
            assert isinstance(touch_up, TouchUp) and touch_up.end > touch_up.start
            assert touch_up.end == pytest.approx(Route.of(route).length)  # appended, for a team of two
    lack, _, _ = simulate_routes(scenario, routes, positions, LOOKAHEAD)
    before, _, _ = simulate_routes(scenario, [half, other], positions, LOOKAHEAD)
    assert int((lack > 0).sum()) < int((before > 0).sum())
    everything = [np.array([[-20.0, y], [60.0, y]]) for y in np.arange(0.0, 41.0, 4.0)]
    starts = np.array([route[0] for route in everything])
    unchanged, none = with_touch_ups(SMALL.with_overrides(agents=len(everything)), everything, starts, LOOKAHEAD, 7.7)
    assert all(not t for t in none) and all(np.array_equal(a, b) for a, b in zip(unchanged, everything, strict=True))


def test_a_team_of_one_leaves_its_route_for_an_orbit_and_comes_back_to_it():
    """One robot whose lanes leave a gap across the domain's middle: the gap's orbits are flown out from
    the route's nearest point and back to it, not after the last lane."""
    lanes = [y for y in np.arange(2.0, 40.0, 4.0) if not 17.0 < y < 24.0]
    route = np.vstack([[[-10.0, y], [50.0, y]][:: 1 if k % 2 == 0 else -1] for k, y in enumerate(lanes)])
    routes, touch_ups = with_touch_ups(SMALL, [route], route[:1], LOOKAHEAD, 7.7)
    (touch_up, *_) = touch_ups[0]
    flown = Route.of(routes[0])
    assert touch_up.end < flown.length - 1.0  # the lane goes on after it
    assert np.allclose(flown.point_at(touch_up.start), flown.point_at(touch_up.end))  # out and back


def test_a_touch_up_whose_spot_is_covered_when_its_robot_gets_there_is_skipped():
    scenario = SMALL.with_overrides(agents=2)
    planner = LanePlanner(scenario)
    lack = np.ones(scenario.grid_shape)
    planner.plan(lack, np.array([[2.0, 2.0], [38.0, 38.0]]))
    spot = np.zeros(scenario.grid_shape, dtype=bool)
    spot[0, 0] = True
    route = planner.routes[0]
    planner.touch_ups[0] = [TouchUp(route.length - 5.0, route.length, spot)]
    route.progress = route.length - 6.0
    covered = lack.copy()
    covered[spot] = 0.0
    here = np.array([route.point_at(route.progress), planner.routes[1].point_at(0.0)])
    planner.plan(covered, here)
    assert planner.routes[0].cleanup or planner.routes[0].progress >= route.length - 1e-9
    assert planner.touch_ups[0] == []
