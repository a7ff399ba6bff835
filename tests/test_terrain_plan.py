"""model.controllers.anicov.terrain_plan: the tour's whole periods and hops cover every coverable cell, its hops
join its stations, its line in time adds up, it starts near a lone robot, and the shares tile the line and even
out each robot's way plus piece."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from model.controllers.anicov.route import CARROT_PERIOD
from model.controllers.anicov.stations import BEARINGS
from model.controllers.anicov.terrain_plan import tour_line, tour_plan, tour_shares
from model.controllers.anicov.terrain_stations import ANGLES, programme_among_walls
from model.world.world import world_of
from tests.test_terrain_stations import ROOMS, deposit_of


@pytest.fixture(scope="module")
def plan():
    return tour_plan(ROOMS)


def test_the_tour_s_hops_join_its_stations_and_some_stare(plan):
    assert sum(len(bearings) > 0 for bearings in plan.bearings) > len(plan.stations) / 2  # the others are passed
    assert len(plan.hops) == len(plan.stations) - 1
    for k, hop in enumerate(plan.hops):
        assert np.array_equal(hop[0], plan.stations[k]) and np.array_equal(hop[-1], plan.stations[k + 1])


def stared_periods(plan) -> np.ndarray:
    """(K, BEARINGS): the periods the plan's stations face each bearing (a turn's bearings included)."""
    width = 2 * np.pi / BEARINGS
    periods = np.zeros((len(plan.stations), BEARINGS))
    for k, bearings in enumerate(plan.bearings):
        for bearing in bearings:
            periods[k, round(bearing / width) % BEARINGS] += 1
    return periods


def test_the_tour_s_stares_and_hops_bring_every_coverable_cell_to_lambda_star(plan):
    world, deposit = world_of(ROOMS), deposit_of(ROOMS)
    stares = deposit.stares(plan.stations, ANGLES) @ stared_periods(plan).ravel()
    hops = sum(deposit.path(hop) for hop in plan.hops)
    assert ((stares + hops)[world.coverable.ravel()] >= 1.0 - 1e-9).all()
    assert not (stares[world.coverable.ravel()] >= 1.0 - 1e-9).all()  # the hops' view counted: stares fall short


def test_counting_the_hops_needs_fewer_stares_than_the_programme_alone():
    tour = tour_plan(ROOMS)
    assert stared_periods(tour).sum() * CARROT_PERIOD < programme_among_walls(ROOMS).stare_time


def test_the_line_in_time_is_the_hops_at_k_v_and_the_stations_periods(plan):
    points, along, arrivals = tour_line(plan, ROOMS.k_v)
    assert (np.diff(along) >= 0.0).all() and along[0] == 0.0
    assert np.array_equal(points[np.searchsorted(along, arrivals)], plan.stations)  # each reached at its arrival
    hops = sum(float(np.linalg.norm(np.diff(hop, axis=0), axis=1).sum()) for hop in plan.hops)
    stares = sum(len(bearings) for bearings in plan.bearings) * CARROT_PERIOD * ROOMS.k_v
    assert along[-1] == pytest.approx(hops + stares)
    assert np.array_equal(points[-1], plan.stations[-1])


def test_the_shares_tile_the_line_and_even_out_each_robot_s_way_plus_piece(plan):
    world = world_of(ROOMS)
    points, along, _ = tour_line(plan, ROOMS.k_v)
    positions = np.array([[2.5, 2.5], [20.5, 13.5], [6.5, 13.5]])
    shares = tour_shares(world, points, along, positions)
    pieces = sorted(shares)
    assert pieces[0][0] == 0.0 and pieces[-1][1] == pytest.approx(along[-1])
    assert all(a[1] == pytest.approx(b[0]) for a, b in itertools.pairwise(pieces))

    def way(robot, start):  # the free path's length from the robot to the piece's start
        x, y = np.interp(start, along, points[:, 0]), np.interp(start, along, points[:, 1])
        field = world.field(x, y)
        return field[int(positions[robot, 1]), int(positions[robot, 0])]

    finish = max(way(robot, start) + end - start for robot, (start, end) in enumerate(shares))
    thirds = [(k * along[-1] / 3, (k + 1) * along[-1] / 3) for k in range(3)]
    equal = min(
        max(way(robot, thirds[order[robot]][0]) + along[-1] / 3 for robot in range(3))
        for order in itertools.permutations(range(3))
    )
    assert finish <= equal + 1e-9  # no later than the best of equal pieces
    assert finish < 1.01 * (along[-1] + sum(way(robot, start) for robot, (start, _) in enumerate(shares))) / 3


def test_the_tour_starts_at_the_station_nearest_a_lone_robot():
    world = world_of(ROOMS)
    for robot in (np.array([2.5, 2.5]), np.array([21.5, 13.5])):
        tour = tour_plan(ROOMS, robot[None, :])
        field = world.field(*robot)
        ways = [field[int(y), int(x)] for x, y in tour.stations]
        assert ways[0] == min(ways)
