"""model.scenario.map_fit: a map as map_saver writes it (any pixel size, a wide unknown border, an origin
that is not (0, 0)) loads with any cell that is a whole number of its pixels: the border cropped, the rest
padded with unknown to whole cells, the console told; the run's poses are in the map's own frame."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import cv2
import numpy as np
import pytest

from anicov.engine import run_scenario
from model.scenario import ScenarioError, load_scenario
from model.scenario.map_fit import MARGIN_CELLS, MapFrame, fit_to_cells
from model.scenario.terrain import coarsen, load_occupancy_map, map_on_grid
from model.world.world import map_frame_of, map_note_of, world_of
from runtime.rundir import write_run_directory
from tests.teamrun import ROOT, limit

FREE, WALL, UNKNOWN = 254, 0, 205
ORIGIN = (-10.0, -12.3)
RESOLUTION = 0.05


def saved_map(folder, rows=423, cols=286, yaw=0.0):
    """A map_saver-like map: 0.05 m pixels, unknown everywhere but a 6.05 × 4.05 m room (121 × 81 pixels, an
    odd number of each: no cell of 0.1 m fits it whole), its walls one pixel thick with a one-pixel gap, an
    unknown island and a round pillar inside."""
    image = np.full((rows, cols), UNKNOWN, dtype=np.uint8)
    top, left, height, width = 150, 70, 81, 121  # image rows count from the top
    image[top : top + height, left : left + width] = WALL
    image[top + 1 : top + height - 1, left + 1 : left + width - 1] = FREE
    image[top + 40, left] = FREE  # a one-pixel gap in the west wall: the map's truth
    image[top + 20 : top + 24, left + 30 : left + 34] = UNKNOWN  # an unscanned island
    cv2.circle(image, (left + 80, top + 50), 5, WALL, -1)  # a pillar
    cv2.imwrite(str(folder / "saved.pgm"), image)
    (folder / "saved.yaml").write_text(
        "image: saved.pgm\nmode: trinary\nresolution: 0.05\n"
        f"origin: [{ORIGIN[0]}, {ORIGIN[1]}, {yaw}]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    room_bottom_row = rows - (top + height)  # the room's lowest pixel row, counted from the bottom
    return folder / "saved.yaml", (left, room_bottom_row, width, height)


def test_the_unknown_border_is_cropped_in_whole_cells_and_the_rest_padded(tmp_path):
    path, (left, bottom, _, _) = saved_map(tmp_path)
    source = load_occupancy_map(path)
    fitted = fit_to_cells(source, 0.1)
    assert fitted.factor == 2 and fitted.occupied.shape[0] % 2 == 0 and fitted.occupied.shape[1] % 2 == 0
    cut_left, cut_right, cut_bottom, cut_top = fitted.cropped
    assert cut_left % 2 == 0 and cut_bottom % 2 == 0  # whole cells from the image's corner
    assert left - 2 * MARGIN_CELLS - 1 <= cut_left <= left - 2 * MARGIN_CELLS  # a cell of margin, no more
    assert bottom - 2 * MARGIN_CELLS - 1 <= cut_bottom <= bottom - 2 * MARGIN_CELLS
    assert fitted.padded != (0, 0)
    # Every pixel the fit kept is the map's, every pixel it added is unknown (not free).
    rows, cols = source.occupied.shape
    kept = source.occupied[cut_bottom : rows - cut_top, cut_left : cols - cut_right]
    assert np.array_equal(fitted.occupied[: kept.shape[0], : kept.shape[1]], kept)
    assert fitted.occupied[kept.shape[0] :, :].all() and fitted.occupied[:, kept.shape[1] :].all()
    # The domain is the building, not the void: about the room plus a cell each side.
    assert fitted.extent[0] < 6.6 and fitted.extent[1] < 4.6
    assert fitted.corner == pytest.approx((ORIGIN[0] + cut_left * RESOLUTION, ORIGIN[1] + cut_bottom * RESOLUTION))
    note = fitted.note(source)
    assert "286 × 423 pixels" in note and "padded with unknown to whole cells of 0.1" in note


def test_cells_are_the_whole_images_cells(tmp_path):
    """Cropping in whole cells from the corner leaves every kept cell what it is on the whole image."""
    path, _ = saved_map(tmp_path, rows=424, cols=286)  # even sizes: the whole image splits into cells
    source = load_occupancy_map(path)
    fitted = fit_to_cells(source, 0.1)
    whole = map_on_grid(source, 0.1)
    left, bottom = fitted.cropped[0] // 2, fitted.cropped[2] // 2
    cells = coarsen(fitted.occupied, 2)
    kept = whole[bottom : bottom + cells.shape[0], left : left + cells.shape[1]]
    assert np.array_equal(cells[: kept.shape[0], : kept.shape[1]], kept)


def test_a_map_known_everywhere_in_whole_cells_is_not_changed():
    source = load_occupancy_map(ROOT / "scenarios" / "maps" / "office.yaml")
    fitted = fit_to_cells(source, 1.0)
    assert fitted.cropped == (0, 0, 0, 0) and fitted.padded == (0, 0) and fitted.corner == (0.0, 0.0)
    assert np.array_equal(fitted.occupied, source.occupied) and fitted.note(source) is None


def test_a_cell_that_is_not_whole_pixels_is_refused_by_key(tmp_path):
    path, _ = saved_map(tmp_path)
    (tmp_path / "s.toml").write_text(f'map = "{path.name}"\ncell = 0.075\n')
    with pytest.raises(ScenarioError, match=r"'cell': expected a whole multiple of the map's resolution 0\.05"):
        load_scenario(tmp_path / "s.toml")


def scenario_on_saved_map(tmp_path, yaw=0.0):
    path, _ = saved_map(tmp_path, yaw=yaw)
    (tmp_path / "s.toml").write_text(
        f'map = "{path.name}"\ncell = 0.1\nagents = 1\nseed = 3\nrange = 1.2\nhalf_angle_deg = 30.0\n'
        "robot_radius = 0.105\nk_v = 0.22\nk_omega = 0.9\nmax_time = 6000.0\n"
    )
    return load_scenario(tmp_path / "s.toml")


def test_a_run_on_a_saved_map_completes_with_its_poses_in_the_maps_frame(tmp_path):
    scenario = scenario_on_saved_map(tmp_path)
    corner = map_frame_of(scenario).corner
    assert scenario.domain[0] < 6.6 and corner != (0.0, 0.0)
    world = world_of(scenario)
    # The one-pixel gap and the island: no coverable cell outside the room's walls is reached through it.
    assert world.coverable.sum() > 0 and world.unreachable_cells >= 0
    result = run_scenario(scenario)
    assert result.completed, result.errors[-1]
    summary = write_run_directory(result, tmp_path / "out")
    assert summary["terrain"]["map_corner"] == pytest.approx(list(corner))
    with open(tmp_path / "out" / "trajectory.csv") as source:
        rows = list(csv.DictReader(source))
    xs, ys = np.array([float(r["x"]) for r in rows]), np.array([float(r["y"]) for r in rows])
    model_x, model_y = result.trace[:, 0, 0], result.trace[:, 0, 1]
    assert np.allclose(xs, model_x + corner[0]) and np.allclose(ys, model_y + corner[1])
    # In the map's frame the robot stays inside the room the image draws (origin + pixels × resolution).
    room_x = ORIGIN[0] + 70 * RESOLUTION, ORIGIN[0] + (70 + 121) * RESOLUTION
    assert room_x[0] < xs.min() and xs.max() < room_x[1]


def test_anicov_run_says_on_the_console_what_the_fit_changed(tmp_path):
    scenario_on_saved_map(tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "anicov.cli", "run", "--config", str(tmp_path / "s.toml"), "--out", str(tmp_path / "o"),
         "--quiet", "--no-record"],
        cwd=ROOT, capture_output=True, text=True, timeout=limit(300),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "note: map saved.yaml: 286 × 423 pixels of 0.05; unknown border cropped" in done.stderr
    assert "padded with unknown to whole cells of 0.1" in done.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["completed"]


def test_another_cell_refits_the_map_with_its_own_domain_and_corner(tmp_path):
    """The fitted extent and corner depend on the cell (the crop is in whole cells): a scenario on a saved
    map takes another cell (a sweep's grid.cell) and gets that cell's fit, not the old domain refused."""
    scenario = scenario_on_saved_map(tmp_path)
    coarser = scenario.with_overrides(cell=0.2)
    path, _ = saved_map(tmp_path)
    fitted = fit_to_cells(load_occupancy_map(path), 0.2)
    assert coarser.domain == pytest.approx(fitted.extent) and map_frame_of(coarser).corner == pytest.approx(
        fitted.corner
    )
    assert coarser.grid_shape == (fitted.occupied.shape[0] // 4, fitted.occupied.shape[1] // 4)
    with pytest.raises(ScenarioError, match=r"'domain': the map .* spans"):
        scenario.with_overrides(cell=0.2, domain=list(scenario.domain))


def test_initial_poses_and_objectives_are_read_in_the_maps_frame(tmp_path):
    """A user gives poses as RViz shows them: in the map's frame. The room of saved_map spans x -6.5 .. -0.45
    and y -2.7 .. 1.35 there; a robot started at (-3, -0.5) heading north and sent to (-1.5, 0.5) starts and
    ends there in trajectory.csv, and a pose given in the model's own frame (0 .. 6.6) is refused, by key."""
    scenario_on_saved_map(tmp_path)
    text = (tmp_path / "s.toml").read_text().replace("max_time = 6000.0", "max_time = 40.0")
    (tmp_path / "s.toml").write_text(text + "initial_poses = [[-3.0, -0.5, 90.0]]\nobjectives = [[-1.5, 0.5]]\n")
    scenario = load_scenario(tmp_path / "s.toml")
    write_run_directory(run_scenario(scenario), tmp_path / "out")
    with open(tmp_path / "out" / "trajectory.csv") as source:
        rows = list(csv.DictReader(source))
    assert (float(rows[0]["x"]), float(rows[0]["y"])) == pytest.approx((-3.0, -0.5))
    gaps = [np.hypot(float(row["x"]) + 1.5, float(row["y"]) - 0.5) for row in rows]
    assert gaps[0] > 1.5 and min(gaps) <= scenario.range / 2 + 0.05  # eq. 10 stops it R/2 short
    (tmp_path / "s.toml").write_text(text + "initial_poses = [[3.0, 2.0, 90.0]]\n")
    with pytest.raises(
        ScenarioError,
        match=r"'initial_poses': entry 0 \[3.0, 2.0\] lies outside the domain \(in the map's frame\) \[-6\.6",
    ):
        load_scenario(tmp_path / "s.toml")


def turned_scenario(tmp_path, yaw: float):
    """The saved map with its origin at ``yaw``, a 40-unit run from a start to a goal given in the map's frame:
    (scenario, the frame it should have, start, goal)."""
    (tmp_path / "flat").mkdir()
    unturned = fit_to_cells(load_occupancy_map(saved_map(tmp_path / "flat")[0]), 0.1)
    cropped_x, cropped_y = unturned.corner[0] - ORIGIN[0], unturned.corner[1] - ORIGIN[1]
    turned = MapFrame(
        (
            ORIGIN[0] + np.cos(yaw) * cropped_x - np.sin(yaw) * cropped_y,
            ORIGIN[1] + np.sin(yaw) * cropped_x + np.cos(yaw) * cropped_y,
        ),
        yaw,
    )
    scenario_on_saved_map(tmp_path, yaw=yaw)
    text = (tmp_path / "s.toml").read_text().replace("max_time = 6000.0", "max_time = 40.0")
    start, goal = turned.to_map(2.0, 2.0), turned.to_map(4.5, 2.0)  # in the room; heading along the image's x
    poses = f"initial_poses = [[{start[0]}, {start[1]}, {np.degrees(yaw)}]]\nobjectives = [[{goal[0]}, {goal[1]}]]\n"
    (tmp_path / "s.toml").write_text(text + poses)
    return load_scenario(tmp_path / "s.toml"), turned, start, goal


def test_a_map_turned_by_its_origin_s_yaw_keeps_poses_in_its_own_frame(tmp_path):
    """map_saver's origin [x, y, yaw]: the image's x axis lies at yaw in the map's frame. Poses given and written
    are in that frame: the model's turned by the yaw about the fitted corner, which the crop moved along the
    turned axes."""
    yaw = 0.5
    scenario, turned, start, goal = turned_scenario(tmp_path, yaw)
    assert map_frame_of(scenario).corner == pytest.approx(turned.corner) and map_frame_of(scenario).yaw == yaw
    assert "x axis at yaw 0.5 rad" in map_note_of(scenario)
    result = run_scenario(scenario)
    assert result.trace[0, 0, :3] == pytest.approx((2.0, 2.0, 0.0))  # the model's frame is the image's
    summary = write_run_directory(result, tmp_path / "out")
    assert summary["terrain"]["map_yaw"] == yaw
    with open(tmp_path / "out" / "trajectory.csv") as source:
        rows = list(csv.DictReader(source))
    assert (float(rows[0]["x"]), float(rows[0]["y"]), float(rows[0]["theta"])) == pytest.approx((*start, yaw))
    xs, ys = np.array([float(r["x"]) for r in rows]), np.array([float(r["y"]) for r in rows])
    steps = len(result.trace)
    assert np.allclose(np.stack(turned.from_map(xs, ys), axis=1)[:steps], result.trace[:, 0, :2])
    assert min(np.hypot(xs - goal[0], ys - goal[1])) <= scenario.range / 2 + 0.05  # it drove to the goal given


def test_obstacles_on_a_map_are_given_in_the_map_s_frame(tmp_path):
    """A polygon on a map lies where the map's frame puts it (as poses do): a small square around a point of the
    room, read off the map's frame, walls exactly the cells around that point in the model's frame, turned too."""
    scenario, turned, _, _ = turned_scenario(tmp_path, yaw=0.5)
    inside = [float(v) for v in turned.to_map(3.05, 2.05)]  # the centre of model cell (row 20, col 30): cell 0.1
    square = [
        [inside[0] + dx, inside[1] + dy] for dx, dy in ((-0.02, -0.02), (0.02, -0.02), (0.02, 0.02), (-0.02, 0.02))
    ]
    (tmp_path / "s.toml").write_text((tmp_path / "s.toml").read_text() + f"obstacles = [{square}]\n")
    with_square = world_of(load_scenario(tmp_path / "s.toml"))
    added = coarsen(with_square.wall_grid, round(scenario.cell / with_square.grain)) & ~world_of(scenario).occupied
    assert [tuple(cell) for cell in np.argwhere(added)] == [(20, 30)]
