"""model.controllers.anicov.terrain_turns: of two robots whose next stations are too near for both, the one
nearer its own goes first and the other waits out of the way, facing its station; far apart, nobody waits. And the
lab run that two such pairs held to the end now completes."""

from __future__ import annotations

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.controllers.anicov.route import CARROT_PERIOD, Route, Stop, face_radius_of
from model.controllers.anicov.terrain_flight import TerrainFlight
from model.controllers.anicov.terrain_relief import aside
from model.controllers.anicov.terrain_turns import aside_carrot, station_gap, wait_carrot, who_waits
from model.scenario import load_scenario
from model.scenario.physics_keys import pair_margin_of
from model.world.world import world_of
from tests.test_real_maps import REAL, map_of
from tests.test_terrain_stations import ROOMS


def route_to(start: list[float], station: list[float]) -> Route:
    """A straight route from ``start`` to a station at its end, with one bearing to face there."""
    points = np.array([start, station], dtype=np.float64)
    length = float(np.hypot(*(points[1] - points[0])))
    return Route.of(points, stops=[Stop(length, [0.0])])


def test_the_gap_lets_both_look_ahead_points_swing_clear_of_each_other():
    gap = station_gap(ROOMS)
    assert gap == pytest.approx(2 * ROOMS.robot_radius + pair_margin_of(ROOMS) + 4 * ROOMS.lookahead)
    # Two centres the gap apart, look-ahead points turned straight at each other: the filter's pair clearance is left.
    assert gap - 2 * ROOMS.lookahead == pytest.approx(
        2 * ROOMS.robot_radius + pair_margin_of(ROOMS) + 2 * ROOMS.lookahead
    )


APPROACH = ROOMS.k_v * CARROT_PERIOD  # a plan period's way
SPACING = 0.5 * ROOMS.cell


def test_the_robot_farther_from_its_station_waits_for_the_nearer_one_once_it_comes_near():
    gap = station_gap(ROOMS)
    routes = {0: route_to([6.5, 4.0], [6.5, 8.5]), 1: route_to([6.5, 10.5], [6.5, 9.0])}
    near = np.array([[6.5, 9.0 - gap - 0.5 * APPROACH], [6.5, 10.5]])  # robot 0 enters the gap in this period
    routes[0].progress = near[0, 1] - 4.0
    assert who_waits(routes, near, [0, 1], gap, APPROACH, SPACING) == {0: [1]}  # robot 1 has 1.5 of its way left
    assert who_waits(routes, near[::-1].copy(), [1, 0], gap, APPROACH, SPACING) == {1: [0]}  # indices follow ids' order
    far = np.array([[6.5, 9.0 - gap - 1.5 * APPROACH], [6.5, 10.5]])  # robot 1 may be gone when it comes
    routes[0].progress = far[0, 1] - 4.0
    assert who_waits(routes, far, [0, 1], gap, APPROACH, SPACING) == {}


def test_a_tie_goes_to_the_lower_id_and_stations_far_apart_keep_everyone_going():
    gap = station_gap(ROOMS)
    tied = {3: route_to([6.5, 7.0], [6.5, 8.5]), 5: route_to([6.5, 10.5], [6.5, 9.0])}
    assert who_waits(tied, np.array([[6.5, 7.0], [6.5, 10.5]]), [3, 5], gap, APPROACH, SPACING) == {1: [0]}
    apart = {0: route_to([6.5, 7.0], [6.5, 8.5]), 1: route_to([6.5, 10.5], [6.5, 8.5 + gap + 0.01])}
    assert who_waits(apart, np.array([[6.5, 7.0], [6.5, 10.5]]), [0, 1], gap, APPROACH, SPACING) == {}
    no_stop = {0: route_to([6.5, 7.0], [6.5, 8.5]), 1: Route.of(np.array([[6.5, 8.6]]), cleanup=True)}
    idle = np.array([[6.5, 7.0], [6.5, 8.6]])  # robot 1 stands with nothing to do: make_way's, not this rule's
    assert who_waits(no_stop, idle, [0, 1], gap, APPROACH, SPACING) == {}


def test_the_way_left_ranks_them_and_a_robot_on_the_other_s_way_does_not_wait_there():
    gap = station_gap(ROOMS)
    # Robot 1 is nearer its station in a straight line (1.5 against 2.5); round the block it has 7.5 left, robot 0 2.5.
    around = Route.of(np.array([[14.0, 10.0], [17.0, 10.0], [17.0, 8.5], [14.0, 8.5]]), stops=[Stop(7.5, [0.0])])
    routes = {0: route_to([14.0, 5.0], [14.0, 7.5]), 1: around}
    positions = np.array([[14.0, 5.0], [14.0, 10.0]])
    assert who_waits(routes, positions, [0, 1], gap, 10.0, SPACING) == {1: [0]}
    # Robot 0 stands on robot 1's way up the corridor; robot 1 has less left, but robot 0 does not wait there.
    detour = Route.of(np.array([[6.5, 6.0], [3.0, 6.0], [3.0, 9.0], [6.0, 9.0]]), stops=[Stop(9.5, [0.0])])
    routes = {0: detour, 1: route_to([6.5, 4.0], [6.5, 9.5])}
    positions = np.array([[6.5, 6.0], [6.5, 4.0]])
    assert who_waits(routes, positions, [0, 1], gap, 10.0, SPACING) == {}
    positions[0] = [3.0, 6.1]  # off its way, 5.9 left against 5.5: now it waits
    routes[0].progress = 3.6
    assert who_waits(routes, positions, [0, 1], gap, 10.0, SPACING) == {0: [1]}


def test_a_robot_clear_of_the_station_stands_and_faces_its_own():
    gap, face = station_gap(ROOMS), face_radius_of(ROOMS)
    route = route_to([4.5, 2.5], [6.5, 8.5])
    position = np.array([5.0, 4.0])
    carrot = wait_carrot(route, position, [np.array([6.5, 9.0])], gap, face, 0.5)
    assert np.hypot(*(carrot - position)) == pytest.approx(0.5 * face)  # nearer than the face radius: stand
    toward = np.array([6.5, 8.5]) - position
    assert np.dot(carrot - position, toward) == pytest.approx(0.5 * face * np.hypot(*toward))


def test_a_robot_inside_the_gap_backs_off_along_the_way_it_came():
    gap, face = station_gap(ROOMS), face_radius_of(ROOMS)
    route = route_to([6.5, 2.5], [6.5, 8.5])
    route.progress = 5.5  # at (6.5, 8.0), beside the teammate's station at (6.5, 9.0)
    blocker = np.array([6.5, 9.0])
    carrot = wait_carrot(route, route.point_at(route.progress), [blocker], gap, face, 0.5)
    assert carrot[0] == pytest.approx(6.5) and carrot[1] == pytest.approx(8.0 - 0.5)  # a step back down the route
    route.progress = 5.5  # advance never goes back: standing at (6.5, 7.3) now, inside the gap still
    carrot = wait_carrot(route, np.array([6.5, 7.3]), [blocker], gap, face, 0.5)
    assert np.hypot(*(carrot - blocker)) >= gap and carrot[1] < 7.3  # the last step, to the nearest clear point
    assert np.hypot(*(carrot - blocker)) < gap + 0.5


def test_the_lab_run_two_pairs_of_neighbouring_stations_held_now_completes():
    """The MRPT lab, N = 10, seed 4, kinematic: two robots drove at stations 0.2 m from stations teammates stood at
    from t = 50 on, the filter held both of each pair (400 deadlocks) and the watchdog gave a cell up (not complete,
    9,360 steps). With turns: complete, no deadlock."""
    scenario_path = REAL / "uwb-lab.toml"
    map_of(scenario_path)
    scenario = load_scenario(scenario_path).with_overrides(agents=10, seed=4, controller="anicov", max_time=1500.0)
    result = run_scenario(scenario, record_trace=False)
    assert result.completed and not result.given_up.any()


def test_two_robots_each_on_the_other_s_way_take_turns_and_the_second_steps_aside():
    """Two robots held off stations nearer than the gap, each on the other's way (the MRPT lab, N = 10, seed 7, with
    noise: 0.11 and 0.14 m off stations 0.3 m apart): before, neither waited, and the filter held both for good. Now
    the one nearer its station goes (both have come to their stations: the way left ties at 0, and the straight line
    ranks them before the id), and the other steps aside along the free path (the flight's carrot for it)."""
    gap = station_gap(ROOMS)
    routes = {0: route_to([5.0, 8.5], [6.0, 8.5]), 7: route_to([8.0, 8.5], [7.0, 8.5])}
    positions = np.array([[5.7, 8.5], [7.2, 8.5]])  # 0.3 and 0.2 off; disks (r = 0.4) 1.5 apart
    for route in routes.values():
        route.progress = route.length  # come to its station: progress never passes a stop not yet done
    assert (
        np.hypot(*(positions[0] - [7.0, 8.5])) < gap and np.hypot(*(positions[1] - [6.0, 8.5])) < gap
    )  # each on the other's way
    assert who_waits(routes, positions, [0, 7], gap, APPROACH, SPACING) == {0: [1]}  # robot 7 is nearer: 0 waits
    world = world_of(ROOMS)
    carrot = aside_carrot(world, positions[0], [routes[7]], gap, APPROACH)
    assert carrot is not None and np.hypot(*(carrot - positions[0])) == pytest.approx(APPROACH, abs=1e-6)
    place = aside(world, positions[0], [routes[7]], gap)
    assert np.hypot(*(place - positions[0])) > np.hypot(*(carrot - positions[0]))  # a step on the way there
    flight = TerrainFlight(ROOMS)
    flight.take_turns(routes, positions, [0, 7])
    assert set(flight.held) == {0} and np.allclose(flight.held[0], carrot)
    assert aside_carrot(world, np.array([2.5, 2.5]), [routes[7]], gap, APPROACH) is None  # not on its way: no step
