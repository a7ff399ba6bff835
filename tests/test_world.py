"""model.world.world: what a scenario's terrain makes of the grid, built once."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from model.paper.fixed_point import COVERAGE_SCALE
from model.parameters import coverage_map_of, starting_poses
from model.scenario import Scenario, load_scenario, validate
from model.world.world import closed_gaps, team_space, world_of
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


def two_rooms_map(folder, crack: bool = True, resolution: float = 0.08):
    """A map_saver-like map 16 × 8 m, walls one pixel thick: a west room opens to the east one by a door 1.76 m
    wide; in the east's north-east corner a third room, 4 × 3.2 m, is closed but (``crack``) for a crack one
    pixel wide. Drawn in 0.08 m pixels (10 a cell of 0.8 m), or, ``resolution`` 0.16, in pixels twice as big."""
    scale = round(resolution / 0.08)
    image = np.full((100, 200), 254, dtype=np.uint8)  # image rows count from the top
    image[[0, -1], :] = 0
    image[:, [0, -1]] = 0
    image[:, 99] = 0  # the wall between the west and east rooms: cell column 9
    image[44:66, 99] = 254  # its door: y from 2.72 to 4.48 m
    image[40, 150:] = 0  # the closed room's south wall (cell row 5) and west wall (cell column 15)
    image[:40, 150] = 0
    image = image[::scale, ::scale].copy()  # (at 0.16 m every wall drawn above keeps one pixel)
    if crack:
        image[20 // scale, 150 // scale] = 254
    cv2.imwrite(str(folder / "rooms.pgm"), image)
    (folder / "rooms.yaml").write_text(
        f"image: rooms.pgm\nmode: trinary\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return folder / "rooms.yaml"


def rooms_scenario(folder, crack: bool = True, resolution: float = 0.08, **keys) -> Scenario:
    """The campus scenario's robot and camera (r 0.3 m, s 0.1 m, R 8 m, 0.8 m cells) on :func:`two_rooms_map`."""
    folder.mkdir(exist_ok=True)
    values = {
        "map": str(two_rooms_map(folder, crack, resolution)),
        "cell": 0.8,
        "range": 8.0,
        "robot_radius": 0.3,
        "safety_margin": 0.1,
        "lookahead": 0.3,
        "k_v": 0.5,
        "k_omega": 0.48,
        "agents": 1,
    }
    return validate(values | keys, folder)


def test_walls_kept_to_the_map_s_pixel_let_a_robot_through_a_door_that_whole_cells_close(tmp_path):
    fine = world_of(rooms_scenario(tmp_path))
    coarse = world_of(rooms_scenario(tmp_path, wall_detail="cell"))
    # Wall squares of 0.16 m: 5 a cell side, the largest divisor of the 10 pixels a cell up to 5.
    assert fine.grain == pytest.approx(0.16) and coarse.grain == 0.8
    assert (fine.occupied == coarse.occupied).all()  # what there is to cover is the same
    west, east = np.s_[:, :9], np.s_[:5, 10:]
    # On whole cells the door's jambs are cells of wall: the 1.76 m door is one row of free cells, its centre
    # 0.4 m from them, too little for r + s and the planning margin (0.44 m). To the pixel that centre is
    # 0.88 m off each jamb, enough for that and half a cell more (0.84 m: world.FINE_WALL_MARGIN).
    assert fine.reachable[west].any() and fine.reachable[east].any()
    assert coarse.reachable[west].any() != coarse.reachable[east].any()
    assert fine.coverable[west].all() == (~fine.occupied[west]).all() and fine.coverable[east].sum() > 0
    assert fine.unreachable_cells < coarse.unreachable_cells


@pytest.mark.parametrize("resolution", [0.08, 0.16])
def test_no_coverable_cell_is_seen_only_through_a_one_pixel_crack(tmp_path, resolution):
    # At 0.16 m the wall squares are the pixels themselves (5 a cell): only the gap's closing seals the crack.
    cracked = world_of(rooms_scenario(tmp_path / "cracked", resolution=resolution))
    sealed = world_of(rooms_scenario(tmp_path / "sealed", crack=False, resolution=resolution))
    assert cracked.grain == pytest.approx(0.16)
    inside = np.s_[6:9, 16:19]  # the closed room's free cells (row 9 holds the map's edge, column 19 too)
    assert not cracked.occupied[inside].any()
    assert not cracked.coverable[inside].any()
    assert (cracked.coverable == sealed.coverable).all()


def test_walls_drawn_on_whole_cells_keep_the_world_fitted_to_cells(tmp_path):
    image = np.full((40, 40), 254, dtype=np.uint8)
    image[10:20, 10:20] = 0  # a block of 2 × 2 cells of 5 pixels
    cv2.imwrite(str(tmp_path / "block.pgm"), image)
    (tmp_path / "block.yaml").write_text(
        "image: block.pgm\nmode: trinary\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    world = world_of(validate({"map": "block.yaml", "cell": 0.5, "robot_radius": 0.2}, tmp_path))
    assert world.grain == 0.5 and world.wall_grid is world.wall_grid and world.wall_grid.shape == world.occupied.shape


def test_gaps_narrower_than_a_tenth_of_a_unit_are_filled_and_nothing_else():
    wall = np.zeros((7, 14), dtype=bool)
    wall[3, :12] = True  # a wall that stops two pixels short of the image's right edge
    wall[3, 3] = False  # a gap of one pixel
    wall[3, 6:8] = False  # a gap of two
    closed = {resolution: closed_gaps(wall, resolution) for resolution in (1.0, 0.05, 0.04)}
    assert closed[1.0][3, 3] and closed[0.05][3, 3]  # one pixel: always a gap
    assert not closed[0.05][3, 6:8].any() and closed[0.04][3, 6:8].all()  # 0.1 wide at 0.05; 0.08 at 0.04
    for image in closed.values():
        assert not image[3, 12:].any()  # a run to the image's edge has no wall at one end
        assert (image[[0, 1, 2, 4, 5, 6]] == wall[[0, 1, 2, 4, 5, 6]]).all()  # nothing else changes
    pocket = np.ones((10, 10), dtype=bool)
    pocket[4:6, 4:6] = False  # a free square two pixels wide, walls all round: a room at 1 unit a pixel
    assert (closed_gaps(pocket, 1.0) == pocket).all()
