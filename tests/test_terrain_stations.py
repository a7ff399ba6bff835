"""model.controllers.anicov.terrain_stations: stations stand where a robot fits, their stares stop at walls,
every coverable cell is reached by some stare (or reported), and the relaxed programme covers every one."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model.controllers.anicov.deposit import Deposit
from model.controllers.anicov.route import CARROT_PERIOD
from model.controllers.anicov.terrain_stations import (
    ANGLES,
    _solved,
    _with_stations_for_unseen,
    programme_among_walls,
    stations_among_walls,
)
from model.scenario import validate
from model.world.world import world_of

# A room of 24 x 16 split by a wall at x = 12 with a door (y 6 - 10); robots of radius 0.4, R = 5, occlusion.
ROOMS = validate(
    {
        "agents": 1,
        "domain": [24.0, 16.0],
        "cell": 1.0,
        "range": 5.0,
        "robot_radius": 0.4,
        "occlusion": True,
        "safety": False,
        "obstacles": [
            [[12.0, 0.0], [13.0, 0.0], [13.0, 6.0], [12.0, 6.0]],
            [[12.0, 10.0], [13.0, 10.0], [13.0, 16.0], [12.0, 16.0]],
        ],
    }
)


def deposit_of(scenario) -> Deposit:
    return Deposit(scenario, world_of(scenario).ground, round(CARROT_PERIOD / scenario.dt))


def test_every_station_stands_in_a_reachable_cell_at_its_centre():
    world = world_of(ROOMS)
    stations = stations_among_walls(world, 5.5)
    assert len(stations) > 4
    cols, rows = (stations / ROOMS.cell - 0.5).round().astype(int).T
    assert world.reachable[rows, cols].all()
    assert np.allclose(stations, (np.stack([cols, rows], axis=1) + 0.5) * ROOMS.cell)
    assert len({(int(c), int(r)) for c, r in zip(cols, rows, strict=True)}) == len(stations)  # one a cell


def test_a_stare_stops_at_the_wall():
    world, deposit = world_of(ROOMS), deposit_of(ROOMS)
    beside, through = deposit.stare(10.5, 3.5, 0.0).reshape(world.occupied.shape), deposit.stare(10.5, 8.5, 0.0)
    assert beside[:, 13:].sum() == 0.0  # facing the wall: nothing past it
    assert through.reshape(world.occupied.shape)[8, 14] > 0.0  # facing the door: the next room


def test_with_no_station_at_all_every_coverable_cell_gets_a_seer():
    world, deposit = world_of(ROOMS), deposit_of(ROOMS)
    empty = deposit.stares(np.zeros((0, 2)), ANGLES)
    stations, stares, unseen = _with_stations_for_unseen(world, deposit, np.zeros((0, 2)), empty)
    assert unseen == 0 and len(stations) > 0
    seen = np.asarray(stares.sum(axis=1)).ravel() > 0.0
    assert seen[world.coverable.ravel()].all()
    cols, rows = (stations / ROOMS.cell - 0.5).round().astype(int).T
    assert world.reachable[rows, cols].all()


def test_the_relaxed_programme_brings_every_coverable_cell_to_lambda_star():
    world = world_of(ROOMS)
    programme = _solved(world, 5.5)
    stares = deposit_of(ROOMS).stares(programme.stations, ANGLES)
    reached = stares @ programme.periods.ravel()
    assert programme.unseen == 0
    assert (reached[world.coverable.ravel()] >= 1.0 - 1e-6).all()
    assert programme.stare_time == pytest.approx(programme.periods.sum() * CARROT_PERIOD)


def test_the_stare_time_never_beats_the_sensors_own_rate():
    one = programme_among_walls(ROOMS)
    # Every stare pours at most the wedge's ability a step (eq. 2 summed: t*'s rate), so no programme covers
    # the coverable area faster than t*_1 does.
    world = world_of(ROOMS)
    area = float(world.coverable.sum()) * ROOMS.cell**2
    in_the_open = Deposit(ROOMS, None, round(CARROT_PERIOD / ROOMS.dt))  # the whole wedge, no wall in its way
    rate = max(in_the_open.stare(12.0, 8.0, angle).sum() for angle in ANGLES) * ROOMS.cell**2 / CARROT_PERIOD
    assert one.stare_time >= area / rate - 1e-6
    assert math.isfinite(one.stare_time)
