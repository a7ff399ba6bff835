"""model.controllers.anicov.terrain_relief: a robot done takes over the end of the route with the most left,
the two routes keep every stop between them, and the team's end comes sooner; no relief where none helps."""

from __future__ import annotations

import numpy as np
import pytest

from model.controllers.anicov.route import Route, Stop
from model.controllers.anicov.terrain_relief import RELIEF_GAIN, aside, in_the_way, relief, time_left
from model.scenario import load_scenario
from model.scenario.physics_keys import pair_margin_of
from model.world.world import world_of
from tests.teamrun import ROOT
from tests.test_terrain_stations import ROOMS


def long_route() -> Route:
    """West room, bottom to top: 5 stations of 6 periods each along x = 4.5."""
    points = np.array([[4.5, 1.5], [4.5, 14.5]])
    return Route.of(points, stops=[Stop(at, [0.0] * 6) for at in (0.0, 3.0, 6.0, 9.0, 12.0)])


def test_time_left_counts_the_way_at_k_v_and_the_periods():
    route = long_route()
    assert time_left(route, ROOMS.k_v) == pytest.approx(13.0 / ROOMS.k_v + 30 * 0.5)
    route.progress = 13.0
    route.stops = []
    assert time_left(route, ROOMS.k_v) == 0.0


def test_a_robot_done_takes_the_end_of_the_longest_route_and_every_stop_is_kept_once():
    world = world_of(ROOMS)
    routes = {0: long_route(), 1: Route.of(np.array([[2.5, 12.5], [3.5, 12.5]]))}
    routes[1].progress = routes[1].length  # done
    given = relief(world, routes, [0], np.array([3.5, 12.5]))
    assert given is not None and given.relieved == 0
    before = [routes[0].point_at(stop.at).tolist() for stop in routes[0].stops]
    kept = [given.kept.point_at(stop.at).tolist() for stop in given.kept.stops]
    taken = [given.taken.point_at(stop.at).tolist() for stop in given.taken.stops]
    assert kept + taken == before and kept and taken
    assert np.allclose(given.taken.points[0], [3.5, 12.5])  # from where the reliever stands
    last = given.kept.stops[-1].at  # the robot relieved ends at its last stop, not at the reliever's first
    assert given.kept.length == pytest.approx(last)
    assert given.kept.length < routes[0].stops[len(given.kept.stops)].at
    end = max(time_left(given.kept, ROOMS.k_v), time_left(given.taken, ROOMS.k_v))
    assert end <= time_left(routes[0], ROOMS.k_v) - RELIEF_GAIN * 0.5


def test_no_relief_where_the_way_there_costs_more_than_it_saves():
    world = world_of(ROOMS)
    short = Route.of(np.array([[4.5, 1.5], [4.5, 3.5]]), stops=[Stop(0.0, [0.0]), Stop(2.0, [0.0])])
    assert relief(world, {0: short}, [0], np.array([22.5, 14.5])) is None
    assert relief(world, {0: short}, [], np.array([4.5, 2.5])) is None


def test_a_robot_with_nothing_to_do_in_a_teammate_s_way_is_sent_aside_out_of_it():
    world = world_of(ROOMS)
    busy = Route.of(np.array([[3.5, 8.5], [8.5, 8.5]]), stops=[Stop(5.0, [0.0])])  # to a station at (8.5, 8.5)
    gap = 2.0 * (2.0 * ROOMS.robot_radius + ROOMS.safety_margin) + ROOMS.lookahead
    standing = np.array([8.5, 9.0])  # beside the station
    assert in_the_way(busy, standing, gap, 0.5)
    assert not in_the_way(busy, np.array([3.5, 14.5]), gap, 0.5)
    place = aside(world, standing, [busy], gap)
    assert place is not None and not in_the_way(busy, place, gap, 0.5)
    assert world.reachable[int(place[1] // ROOMS.cell), int(place[0] // ROOMS.cell)]
    assert np.hypot(*(place - standing)) < 1.5 * gap + ROOMS.cell  # near: the nearest clear cell by the free path


def test_a_robot_standing_outside_the_team_s_space_is_still_sent_aside():
    """With the issue's noise the clearance reserve takes the cells beside the rooms' wall out of the team's space,
    and a robot's disk still stands there (its centre 0.9 off the wall). Measured from its own cell no free path
    went anywhere, and it held a teammate orbiting the station beside it to the end of the run (two rooms, seed 7)."""
    rooms = load_scenario(ROOT / "scenarios" / "physics-rooms.toml")
    world = world_of(rooms)
    standing = np.array([11.1, 12.09])
    assert not world.reachable[12, 11]
    busy = Route.of(np.array([[9.15, 12.87], [9.5, 12.5], [9.5, 0.5]]), stops=[Stop(0.51, [0.0])])
    gap = 2.0 * (2.0 * rooms.robot_radius + pair_margin_of(rooms)) + rooms.lookahead
    assert in_the_way(busy, standing, gap, 0.5)
    place = aside(world, standing, [busy], gap)
    assert place is not None and not in_the_way(busy, place, gap, 0.5)
    assert world.reachable[int(place[1] // rooms.cell), int(place[0] // rooms.cell)]
