"""model.controllers.anicov.terrain_lanes and the LanePlanner among walls: every robot's route starts where it
stands and drives on legs the disk can make, the stops share out the tour's periods exactly, and a robot sent
to an uncovered cell stands where it sees it. (anicov still refuses maps in a scenario: these reach the
planner directly.)"""

from __future__ import annotations

import itertools

import numpy as np

from model.controllers.anicov.lane_planner import LanePlanner
from model.controllers.anicov.route import FACE_RADIUS, face_radius_of
from model.controllers.anicov.terrain_lanes import stand_for, terrain_routes
from model.controllers.anicov.terrain_plan import tour_plan
from model.scenario import validate
from model.world.geodesic import in_sight
from model.world.visibility import segment_crosses_occupied
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
    _, stops = terrain_routes(ROOMS, POSITIONS)
    given = sum(len(stop.bearings) for own in stops for stop in own)
    assert given == sum(len(bearings) for bearings in tour_plan(ROOMS).bearings)
    for own in stops:  # in route order
        assert all(a.at <= b.at for a, b in itertools.pairwise(own))


def test_a_robot_sent_to_a_cell_stands_where_it_sees_it_neither_on_it_nor_at_the_rim():
    world = world_of(ROOMS)
    target = np.array([18.5, 3.5])
    place = stand_for(world, np.array([2.5, 2.5]), target)
    gap = float(np.linalg.norm(place - target))
    assert ROOMS.range / 4 <= gap <= ROOMS.range / 2
    col, row = (place / ROOMS.cell).astype(int)
    assert world.reachable[row, col]
    assert not segment_crosses_occupied(world.wall_grid, place[0], place[1], target[0], target[1], world.grain)


def test_the_first_plan_among_walls_gives_each_robot_a_carrot_on_its_route():
    planner = LanePlanner(ROOMS.with_overrides(agents=3))
    carrots = planner.plan(np.ones(ROOMS.grid_shape), POSITIONS)
    assert carrots.shape == (3, 2)
    for agent, carrot in enumerate(carrots):
        route = planner.routes[agent]
        assert route.nearest(carrot)[0] < 1e-9  # on its own route
        assert np.linalg.norm(carrot - POSITIONS[agent]) <= planner.lookahead + 1e-9
    assert planner.lookahead == 2.0 * 0.5 * ROOMS.k_v


def test_the_face_radius_is_the_open_square_s_there_and_half_a_step_among_walls():
    assert face_radius_of(validate({"controller": "anicov"})) == FACE_RADIUS
    slow = ROOMS.with_overrides(k_v=0.22)
    assert face_radius_of(slow) == FACE_RADIUS * 0.22 * slow.dt / 0.1
