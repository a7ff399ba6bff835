"""model.controllers.anicov.terrain_cleanup: what the stops and legs still ahead will see is not cleaned up again,
the cleanup's stations surely bring every short cell to its need, a patch finishes what a station leaves, and the
pieces give each station to one robot (a short cell's own seer: tests/test_terrain_seers.py)."""

from __future__ import annotations

import numpy as np
import pytest

from model.controllers.anicov.route import Route, Stop, face_radius_of
from model.controllers.anicov.terrain_cleanup import (
    CLEANUP_DEMAND,
    _cuts,
    cleanup_pieces,
    cleanup_stations,
    left_near,
    residual_lack,
    station_patch,
)
from model.controllers.anicov.terrain_seers import SURE_SPREADS
from model.controllers.anicov.terrain_stations import ANGLES
from model.world.world import world_of
from tests.test_terrain_stations import ROOMS, deposit_of


def short_spots(cells: list[tuple[int, int]], value: float = 0.6) -> np.ndarray:
    lack = np.zeros(ROOMS.grid_shape)
    for row, col in cells:
        lack[row, col] = value
    return lack


def test_the_stops_and_legs_still_ahead_are_taken_off_what_is_left_to_clean_up():
    deposit = deposit_of(ROOMS)
    lack = np.full(ROOMS.grid_shape, 0.5) * world_of(ROOMS).coverable
    route = Route.of(np.array([[3.5, 8.5], [6.5, 8.5], [6.5, 4.5]]), stops=[Stop(3.0, [0.0, 0.0])])
    route.progress = 1.0  # a third of the first leg flown
    left = residual_lack(deposit, lack, [route])
    expected = np.zeros(lack.size)
    flat, added = deposit.stare_cells(6.5, 8.5, 0.0)
    expected[flat] += 2.0 * added
    expected += deposit.path(np.array([[4.5, 8.5], [6.5, 8.5], [6.5, 4.5]]))  # the legs from where it has come
    assert left.ravel() == pytest.approx(np.maximum(lack.ravel() - expected, 0.0))
    untouched = np.flatnonzero(expected == 0.0)
    assert len(untouched) and np.array_equal(left.ravel()[untouched], lack.ravel()[untouched])
    far = residual_lack(deposit, lack, [route], (np.array([22.5, 2.5]), 2.0 * ROOMS.range))
    assert np.array_equal(far, lack)  # the stop and both legs are farther than 2 R: not counted there
    near = residual_lack(deposit, lack, [route], (np.array([6.5, 0.5]), 4.5))  # only the second leg passes within
    alone = np.maximum(lack.ravel() - deposit.path(np.array([[6.5, 8.5], [6.5, 4.5]])), 0.0)
    assert near.ravel() == pytest.approx(alone)


def test_the_cleanup_s_stations_surely_bring_every_short_cell_to_its_need():
    world, deposit = world_of(ROOMS), deposit_of(ROOMS)
    cells = [(2, 3), (3, 3), (12, 20), (13, 21), (8, 14)]
    need = short_spots(cells)
    stations, periods = cleanup_stations(world, deposit, need)
    assert len(stations) >= 1 and periods.sum() >= 1 and (periods == np.round(periods)).all()
    assert len({tuple(point) for point in stations}) == len(stations)  # one station per point
    sure = deposit.sure_stares(stations, ANGLES, SURE_SPREADS * face_radius_of(ROOMS))
    brought = sure @ periods.ravel()
    for row, col in cells:
        assert brought[row * ROOMS.grid_shape[1] + col] >= CLEANUP_DEMAND * 0.6 - 1e-9
    for x, y in stations:
        assert world.reachable[int(y // ROOMS.cell), int(x // ROOMS.cell)]


def test_nothing_short_needs_no_station_and_a_banned_cell_is_never_one():
    world, deposit = world_of(ROOMS), deposit_of(ROOMS)
    stations, periods = cleanup_stations(world, deposit, np.zeros(ROOMS.grid_shape))
    assert stations.shape == (0, 2) and periods.shape == (0, len(ANGLES))
    need = short_spots([(8, 14)])
    first, _ = cleanup_stations(world, deposit, need)
    banned = frozenset((int(y // ROOMS.cell), int(x // ROOMS.cell)) for x, y in first)
    again, _ = cleanup_stations(world, deposit, need, banned)
    assert len(again) and not banned & {(int(y // ROOMS.cell), int(x // ROOMS.cell)) for x, y in again}


def test_a_patch_finishes_what_is_left_near_the_station_and_nothing_when_all_is_done():
    world, deposit = world_of(ROOMS), deposit_of(ROOMS)
    station = np.array([6.5, 8.5])
    lack = short_spots([(8, 7), (8, 8)], 0.4)  # two cells 1 and 2 east of the station (a period: 0.2, 0.15)
    route = Route.of(station[None, :])
    bearings = station_patch(world, deposit, lack, station, [route], (np.pi, None))
    assert bearings
    brought = sum(deposit.stare(*station, bearing) for bearing in bearings)
    for row, col in [(8, 7), (8, 8)]:
        assert brought[row * ROOMS.grid_shape[1] + col] >= 0.4
    assert station_patch(world, deposit, np.zeros(ROOMS.grid_shape), station, [route], (0.0, None)) == []
    assert left_near(world, deposit, lack, station, [route]).sum() == pytest.approx(0.8)
    planned = Route.of(station[None, :], stops=[Stop(0.0, list(bearings))])
    assert station_patch(world, deposit, lack, station, [planned], (np.pi, None)) == []  # already on a route


def test_the_pieces_give_each_station_to_one_robot_and_a_robot_without_one_nothing():
    world = world_of(ROOMS)
    stations = np.array([[2.5, 2.5], [3.5, 12.5], [20.5, 3.5], [21.5, 13.5]])
    periods = np.zeros((4, len(ANGLES)))
    periods[:, 0] = [2, 3, 4, 1]
    positions = np.array([[2.5, 8.5], [20.5, 8.5], [10.5, 8.5]])
    pieces = cleanup_pieces(world, stations, periods, positions)
    flown = [tuple(point) for own, _ in pieces for point in own]
    assert sorted(flown) == sorted(tuple(point) for point in stations)
    assert sum(own_periods.sum() for _, own_periods in pieces) == periods.sum()
    west = [own for (own, _), position in zip(pieces, positions, strict=True) if position[0] < 5]
    assert all(point[0] < 12 for point in west[0])  # the room it stands in, not beyond the wall
    lone = cleanup_pieces(world, stations[:1], periods[:1], positions)
    assert sorted(len(own) for own, _ in lone) == [0, 0, 1]


def test_the_cuts_are_whole_stations_of_about_equal_time():
    assert _cuts(np.array([1.0, 2.0, 3.0, 4.0]), 2) == [0, 2, 4]
    assert _cuts(np.array([10.0, 11.0, 12.0]), 3) == [0, 1, 2, 3]  # never an empty piece
    assert _cuts(np.array([5.0]), 1) == [0, 1]
