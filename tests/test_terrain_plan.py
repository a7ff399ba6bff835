"""model.controllers.anicov.terrain_plan: the tour's whole periods cover every coverable cell, its hops join
its stations, its line in time adds up, and the shares are the pieces the slowest robot reaches soonest."""

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


def test_every_station_of_the_tour_stares_and_its_hops_join_them(plan):
    assert all(len(bearings) > 0 for bearings in plan.bearings)
    assert len(plan.hops) == len(plan.stations) - 1
    for k, hop in enumerate(plan.hops):
        assert np.array_equal(hop[0], plan.stations[k]) and np.array_equal(hop[-1], plan.stations[k + 1])


def test_the_tour_s_whole_periods_bring_every_coverable_cell_to_lambda_star(plan):
    world = world_of(ROOMS)
    stares = deposit_of(ROOMS).stares(plan.stations, ANGLES)
    width = 2 * np.pi / BEARINGS
    periods = np.zeros((len(plan.stations), BEARINGS))
    for k, bearings in enumerate(plan.bearings):
        for bearing in bearings:
            periods[k, round(bearing / width) % BEARINGS] += 1
    reached = stares @ periods.ravel()
    assert (reached[world.coverable.ravel()] >= 1.0 - 1e-9).all()
    assert periods.sum() * CARROT_PERIOD >= programme_among_walls(ROOMS).stare_time - 1e-9  # whole ≥ relaxed


def test_the_line_in_time_is_the_hops_at_k_v_and_the_stations_periods(plan):
    points, along, arrivals = tour_line(plan, ROOMS.k_v)
    assert (np.diff(along) >= 0.0).all() and along[0] == 0.0
    assert np.array_equal(points[np.searchsorted(along, arrivals)], plan.stations)  # each reached at its arrival
    hops = sum(float(np.linalg.norm(np.diff(hop, axis=0), axis=1).sum()) for hop in plan.hops)
    stares = sum(len(bearings) for bearings in plan.bearings) * CARROT_PERIOD * ROOMS.k_v
    assert along[-1] == pytest.approx(hops + stares)
    assert np.array_equal(points[-1], plan.stations[-1])


def test_the_shares_cut_the_line_and_the_slowest_robot_is_as_soon_as_it_can_be(plan):
    world = world_of(ROOMS)
    points, along, _ = tour_line(plan, ROOMS.k_v)
    positions = np.array([[2.5, 2.5], [20.5, 13.5], [6.5, 13.5]])
    shares = tour_shares(world, points, along, positions)
    assert sorted(shares) == [(0.0, along[-1] / 3), (along[-1] / 3, 2 * along[-1] / 3), (2 * along[-1] / 3, along[-1])]

    def way(robot, start):  # the free path's length from the robot to the piece's start
        x, y = np.interp(start, along, points[:, 0]), np.interp(start, along, points[:, 1])
        field = world.field(x, y)
        return field[int(positions[robot, 1]), int(positions[robot, 0])]

    slowest = max(way(robot, start) for robot, (start, _) in enumerate(shares))
    pieces = sorted(shares)
    for order in itertools.permutations(range(3)):
        assert slowest <= max(way(robot, pieces[order[robot]][0]) for robot in range(3)) + 1e-9
