"""model.world.world: what a scenario's terrain makes of the grid, built once."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from model.paper.fixed_point import COVERAGE_SCALE
from model.parameters import coverage_map_of, starting_poses
from model.scenario import Scenario, load_scenario, validate
from model.world.world import team_space, world_of
from tests.conftest import ROOT

# Four walls 1 unit thick closing a 6 x 6 room whose inside spans [12, 18] x [12, 18].
CLOSED_ROOM = [
    [[11.0, 11.0], [19.0, 11.0], [19.0, 12.0], [11.0, 12.0]],
    [[11.0, 18.0], [19.0, 18.0], [19.0, 19.0], [11.0, 19.0]],
    [[11.0, 12.0], [12.0, 12.0], [12.0, 18.0], [11.0, 18.0]],
    [[18.0, 12.0], [19.0, 12.0], [19.0, 18.0], [18.0, 18.0]],
]


def test_the_open_world_leaves_every_cell_to_cover():
    world = world_of(Scenario())
    assert world.open and not world.occupied.any() and world.coverable.all()
    assert world.unreachable_cells == 0
    assert coverage_map_of(Scenario()).coverage.sum() == 0


def test_a_closed_room_is_unreachable_and_left_out_of_the_error():
    scenario = validate({"domain": [40.0, 40.0], "obstacles": CLOSED_ROOM, "robot_radius": 0.4, "agents": 2})
    world = world_of(scenario)
    assert world.unreachable_cells == 36  # the room's 6 x 6 free cells
    rows, cols = np.nonzero(~world.occupied & ~world.coverable)
    assert rows.min() == 12 and rows.max() == 17 and cols.min() == 12 and cols.max() == 17
    coverage_map = coverage_map_of(scenario)
    assert (
        coverage_map.counted_cells == int(world.coverable.sum()) == 40 * 40 - 28 - 36
    )  # the walls: an 8 x 8 ring of 28 cells
    assert coverage_map.domain_error() == 1.0  # nothing is covered yet, of what can be
    assert (coverage_map.coverage[~world.coverable] == coverage_map.target_ticks).all()
    assert (coverage_map.coverage[world.coverable] == 0).all()


def test_the_office_store_room_is_found_unreachable_when_the_scenario_loads():
    world = world_of(load_scenario(ROOT / "scenarios" / "office.toml"))
    assert world.unreachable_cells == 169  # the 13 x 13 free cells of the store room, which has no door
    rows, cols = np.nonzero(~world.occupied & ~world.coverable)
    assert rows.min() >= 85 and cols.min() >= 85


def test_a_pocket_narrower_than_the_robot_is_outside_the_team_space():
    occupied = np.zeros((20, 20), dtype=bool)
    occupied[10, :] = True
    occupied[10, 5] = False  # a one-cell gap: a robot of radius 0.6 does not pass
    # Issue 11's rule alone: with the safety filter on, its margin s would also count (model.world.world.plan_radius_of).
    scenario_free = world_of(
        validate({"domain": [20.0, 20.0], "robot_radius": 0.4, "safety": False, "obstacles": _walls(occupied)})
    )
    scenario_wide = world_of(
        validate({"domain": [20.0, 20.0], "robot_radius": 0.6, "safety": False, "obstacles": _walls(occupied)})
    )
    assert scenario_free.reachable[15, 5] and scenario_free.reachable[5, 5]
    assert scenario_wide.reachable[:10].any() != scenario_wide.reachable[11:].any()


def _walls(occupied: np.ndarray) -> list[list[list[float]]]:
    return [
        [[float(col), float(row)], [col + 1.0, float(row)], [col + 1.0, row + 1.0], [float(col), row + 1.0]]
        for row, col in zip(*np.nonzero(occupied), strict=True)
    ]


def test_team_space_is_the_largest_component():
    passable = np.zeros((5, 9), dtype=bool)
    passable[:, :2] = True  # 10 cells
    passable[:, 4:] = True  # 25 cells
    assert (team_space(passable, 1.0) == (passable & (np.arange(9) >= 4))).all()


def test_every_robot_starts_in_the_team_space():
    scenario = load_scenario(ROOT / "scenarios" / "office.toml").with_overrides(agents=10, seed=4)
    world = world_of(scenario)
    for x, y, _ in starting_poses(scenario):
        assert world.reachable[int(y), int(x)]


def test_a_priority_map_gives_each_cell_its_own_target(tmp_path):
    image = np.zeros((10, 20), dtype=np.uint8)
    image[:, 10:] = 255  # right half: the highest priority
    cv2.imwrite(str(tmp_path / "priority.png"), image)
    scenario = validate(
        {"domain": [20.0, 10.0], "lambda_star": "priority.png", "lambda_star_min": 20.0, "lambda_star_max": 100.0},
        tmp_path,
    )
    world = world_of(scenario)
    assert (world.targets[:, :10] == 20 * COVERAGE_SCALE).all() and (
        world.targets[:, 10:] == 100 * COVERAGE_SCALE
    ).all()
    coverage_map = coverage_map_of(scenario)
    assert (coverage_map.coverage[:, :10] == 80 * COVERAGE_SCALE).all()  # a head start to the common target
    assert (coverage_map.coverage[:, 10:] == 0).all()
    assert coverage_map.domain_error() == pytest.approx((100 * 0.2 * 100 + 100 * 100) / (200 * 100))
    assert world.summary()["priority_sha256"]
