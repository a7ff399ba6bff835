"""model.controllers.anicov.terrain_lanes and the LanePlanner among walls: every robot's route starts where it
stands and drives on legs the disk can make, the stops share out the tour's periods exactly, and a sharp corner
is turned in place."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from model.controllers.anicov.lane_planner import LanePlanner
from model.controllers.anicov.route import FACE_RADIUS, NOISE_FACE_SIGMAS, Route, arrive_radius_of, face_radius_of
from model.controllers.anicov.terrain_lanes import corner_turns, terrain_routes
from model.controllers.anicov.terrain_plan import tour_plan
from model.scenario import validate
from model.world.geodesic import in_sight
from model.world.world import world_of
from tests.test_terrain_stations import ROOMS

POSITIONS = np.array([[2.3, 2.7], [20.6, 13.1], [6.4, 13.8]])


def test_every_route_starts_at_its_robot_and_drives_on_legs_the_disk_can_make():
    world = world_of(ROOMS)
    ground = world.ground
    routes, _ = terrain_routes(ROOMS, POSITIONS)
    assert len(routes) == len(POSITIONS)
    for route, position in zip(routes, POSITIONS, strict=True):
        assert np.array_equal(route[0], position)
        for (x0, y0), (x1, y1) in itertools.pairwise(route):
            assert in_sight(ground.wall_grid, x0, y0, x1, y1, ground.grain, ground.plan_radius, ground.bounded)


def test_the_stops_share_out_every_period_of_the_tour():
    routes, stops = terrain_routes(ROOMS, POSITIONS)
    stations = {tuple(station) for station in tour_plan(ROOMS).stations}
    given = 0
    for route, own in zip(routes, stops, strict=True):
        flown = Route.of(route, stops=own)
        given += sum(len(stop.bearings) for stop in own if tuple(flown.point_at(stop.at)) in stations)
    assert given == sum(len(bearings) for bearings in tour_plan(ROOMS).bearings)
    for own in stops:  # in route order
        assert all(a.at <= b.at for a, b in itertools.pairwise(own))


def test_a_sharp_corner_is_turned_in_place_a_period_at_a_time_and_a_station_or_a_gentle_bend_is_not():
    points = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [5.0, 8.0], [9.0, 8.0]])
    turns = corner_turns(points, {3}, ROOMS)  # point 3 (a 76 degree turn) is a station: its own stop turns it
    per_period = np.pi * ROOMS.k_omega * 0.5
    assert [index for index, _ in turns] == [1]  # point 2 bends by 14 degrees: driven round
    bearings = turns[0][1]
    assert len(bearings) == math.ceil((np.pi / 2) / per_period - 1e-9)
    assert bearings[-1] == pytest.approx(np.pi / 2)  # the last faces the next leg


def test_the_first_plan_among_walls_gives_each_robot_a_carrot_on_its_route():
    planner = LanePlanner(ROOMS.with_overrides(agents=3))
    carrots = planner.plan(np.ones(ROOMS.grid_shape), POSITIONS)
    assert carrots.shape == (3, 2)
    for agent, carrot in enumerate(carrots):
        route = planner.routes[agent]
        assert route.nearest(carrot)[0] < 1e-9  # on its own route
        assert np.linalg.norm(carrot - POSITIONS[agent]) <= planner.lookahead + 1e-9
    assert planner.lookahead == 2.0 * 0.5 * ROOMS.k_v


def test_the_face_radius_is_the_open_square_s_there_and_half_a_step_among_walls_where_arrival_is_wider():
    square = validate({"controller": "anicov"})
    assert face_radius_of(square) == arrive_radius_of(square) == FACE_RADIUS
    slow = ROOMS.with_overrides(k_v=0.22, controller="anicov")
    assert face_radius_of(slow) == FACE_RADIUS * 0.22 * slow.dt / 0.1
    assert arrive_radius_of(slow) == 0.22 * slow.dt  # a step: within a sixteenth of the 1.0 cell
    fine = slow.with_overrides(cell=0.25, domain=[24.0, 16.0])
    assert arrive_radius_of(fine) == 0.25 / 16


def test_with_late_commands_the_face_radius_is_twice_the_way_gone_before_a_command_reaches_the_wheels():
    """A robot told to stop runs on k_v × latency: with a face radius of half a step it turned back for its
    station again and again (two rooms, commands 0.1 late: 450 - 517 time units against 158 - 168)."""
    late = validate({**ROOMS.to_dict(), "controller": "anicov", "physics": "mujoco", "noise": {"command_latency": 0.3}})
    assert face_radius_of(late) == pytest.approx(2.0 * late.k_v * 0.3)
    sigma = 0.8 / NOISE_FACE_SIGMAS
    seen = late.with_overrides(noise={"command_latency": 0.3, "localiser_sigma": sigma})
    assert face_radius_of(seen) == pytest.approx(0.8)  # the localiser's jitter, wider here
