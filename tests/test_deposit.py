import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from model.controllers.anicov.deposit import Deposit
from model.paper.coverage_map import add_window
from model.parameters import coverage_map_of
from model.scenario import load_scenario
from model.scenario.physics_keys import COVER_MARGIN, cover_margin_of
from model.world.wedge import sense_wedge_among

PAPER = Path(__file__).resolve().parents[1] / "scenarios" / "paper.toml"


def small():
    return dataclasses.replace(load_scenario(PAPER), controller="anicov").with_overrides(domain=[40.0, 30.0])


def flown(scenario, poses):
    """What the engine's sensor adds, step by step, from ``poses`` (Λ*)."""
    deposit = Deposit(scenario)
    ticks = np.zeros(scenario.grid_shape, dtype=np.int64)
    for x, y, theta in poses:
        _, _, _, row0, col0, window = sense_wedge_among(
            ticks, 1 << 62, x, y, theta, scenario.range, scenario.half_angle, scenario.alpha_max, scenario.dt,
            scenario.cell, deposit.ground, deposit.nobody,
        )  # fmt: skip
        add_window(ticks, row0, col0, window, 1 << 62)
    return ticks.ravel() / deposit.target_ticks


def test_a_stare_is_a_plan_period_of_the_sensor_standing_still():
    scenario = small()
    stare = Deposit(scenario).stare(12.3, 7.9, 0.7)
    assert stare.sum() > 0.0
    assert np.array_equal(stare, flown(scenario, [(12.3, 7.9, 0.7)] * scenario.plan_steps))


def test_stares_are_the_columns_of_every_station_and_angle():
    scenario = small()
    deposit = Deposit(scenario)
    stations = np.array([[5.0, 5.0], [30.0, 20.0]])
    angles = np.array([0.0, 2.0, -2.5])
    matrix = deposit.stares(stations, angles)
    assert matrix.shape == (40 * 30, 6)
    for k, (station, angle) in enumerate((s, a) for s in stations for a in angles):
        assert np.array_equal(matrix[:, k].toarray().ravel(), deposit.stare(*station, angle))


def test_hops_are_flown_straight_at_k_v_from_station_to_station():
    scenario = small()
    stations = np.array([[5.0, 5.0], [15.0, 5.0], [15.0, 20.0]])
    steps = [(5.0 + k * 0.1, 5.0, 0.0) for k in range(100)] + [(15.0, 5.0 + k * 0.1, math.pi / 2) for k in range(150)]
    assert Deposit(scenario).hops(stations) == pytest.approx(flown(scenario, steps))


def test_a_sure_stare_is_the_least_of_the_station_s_and_of_eight_points_round_it():
    from model.world.world import world_of
    from tests.test_terrain_stations import ROOMS

    deposit = Deposit(ROOMS, world_of(ROOMS).ground, 5)
    station, angles, spread = np.array([[11.0, 3.5]]), np.array([0.0, math.pi / 4]), 0.3  # beside the wall's end
    sure = deposit.sure_stares(station, angles, spread).toarray()
    least = deposit.stares(station, angles).toarray()
    for way in np.arange(8) * math.pi / 4:
        near = station + spread * np.array([math.cos(way), math.sin(way)])
        least = np.minimum(least, deposit.stares(near, angles).toarray())
    assert np.array_equal(sure, least)
    assert (sure <= deposit.stares(station, angles).toarray()).all()
    assert sure.sum() < deposit.stares(station, angles).toarray().sum()  # the wall hides some from some points


def test_sure_stares_kept_are_those_computed_afresh_station_by_station():
    from model.world.world import world_of
    from tests.test_terrain_stations import ROOMS

    ground, angles, spread = world_of(ROOMS).ground, np.array([0.0, math.pi / 4, -2.0]), 0.3
    kept = Deposit(ROOMS, ground, 5)
    first = kept.sure_stares(np.array([[11.0, 3.5], [4.0, 4.0]]), angles, spread)
    again = kept.sure_stares(np.array([[4.0, 4.0], [15.0, 6.0], [11.0, 3.5]]), angles, spread)  # two kept, one new
    fresh = Deposit(ROOMS, ground, 5)
    for k, station in enumerate(([4.0, 4.0], [15.0, 6.0], [11.0, 3.5])):
        alone = fresh.sure_stares(np.array([station]), angles, spread)
        assert alone.nnz > 0
        assert (again[:, 3 * k : 3 * k + 3] != alone).nnz == 0
    assert (again[:, 0:3] != first[:, 3:6]).nnz == 0
    assert kept.sure_stares(np.zeros((0, 2)), angles, spread).shape == (ROOMS.grid_shape[0] * ROOMS.grid_shape[1], 0)


def test_with_noise_a_stare_is_counted_in_the_team_map_s_units_which_ask_the_cover_margin_more():
    """The team's map asks (1 + cover_margin) Λ* of each cell with noise: a stare counted in Λ* made every station
    leave its cells that much short (the square, N = 10: cleanups of 400 - 700 cells)."""
    plain = small()
    noisy = plain.with_overrides(
        physics="mujoco", robot_radius=0.4, noise={"localiser_sigma": 0.05, "localiser_rate": 10.0}
    )
    assert cover_margin_of(noisy) == COVER_MARGIN > 0.0
    assert Deposit(noisy).target_ticks == coverage_map_of(noisy).target_ticks
    assert Deposit(plain).target_ticks == coverage_map_of(plain).target_ticks
    stare, plain_stare = Deposit(noisy).stare(12.3, 7.9, 0.7), Deposit(plain).stare(12.3, 7.9, 0.7)
    assert np.allclose(stare * (1.0 + COVER_MARGIN), plain_stare, rtol=1e-6)
