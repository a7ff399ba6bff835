"""model.scenario.terrain: ROS maps and polygons on the coverage grid, and every way a map can be wrong."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from model.scenario.terrain import (
    TerrainError,
    check_polygon,
    coarsen,
    load_occupancy_map,
    map_on_grid,
    polygons_on_grid,
)
from tests.conftest import ROOT

MAPS = ROOT / "scenarios" / "maps"

ROS_YAML = """image: {image}
mode: trinary
resolution: {resolution}
origin: {origin}
negate: {negate}
occupied_thresh: 0.65
free_thresh: 0.25
"""


def write_map(tmp_path, pixels: np.ndarray, resolution=1.0, origin="[0.0, 0.0, 0.0]", negate=0, name="m"):
    cv2.imwrite(str(tmp_path / f"{name}.pgm"), pixels)
    path = tmp_path / f"{name}.yaml"
    path.write_text(ROS_YAML.format(image=f"{name}.pgm", resolution=resolution, origin=origin, negate=negate))
    return path


@pytest.mark.parametrize("name", ["warehouse", "office", "field"])
def test_every_shipped_map_loads_as_100_by_100_units_with_free_space(name):
    occupancy = load_occupancy_map(MAPS / f"{name}.yaml")
    assert occupancy.extent == (100.0, 100.0)
    assert occupancy.occupied.shape == (200, 200)
    grid = map_on_grid(occupancy, 1.0)
    assert grid.shape == (100, 100)
    assert 0.5 < 1.0 - grid.mean() < 0.97  # mostly free, with real obstacles
    assert len(occupancy.sha256) == 64


def test_image_row_zero_is_the_top_of_the_map_and_grid_row_zero_the_bottom(tmp_path):
    pixels = np.full((4, 6), 254, dtype=np.uint8)
    pixels[0, 5] = 0  # top-right pixel of the image
    occupancy = load_occupancy_map(write_map(tmp_path, pixels))
    assert occupancy.occupied.shape == (4, 6)
    assert np.argwhere(occupancy.occupied).tolist() == [[3, 5]]  # the highest y, the largest x


def test_trinary_thresholds_and_negate(tmp_path):
    pixels = np.array([[0, 100, 205, 254]], dtype=np.uint8)  # p = 1.0, 0.61, 0.20, 0.004
    plain = load_occupancy_map(write_map(tmp_path, pixels, name="plain")).occupied[0].tolist()
    assert plain == [True, True, False, False]  # 0.61 is unknown: not free, so occupied
    negated = load_occupancy_map(write_map(tmp_path, pixels, negate=1, name="neg")).occupied[0].tolist()
    assert negated == [False, True, True, True]  # p = value/255: 0, 0.39 (unknown), 0.80, 1.0


def test_a_coarse_cell_is_occupied_when_any_of_its_pixels_is():
    fine = np.zeros((4, 4), dtype=bool)
    fine[3, 0] = True
    assert coarsen(fine, 2).tolist() == [[False, False], [True, False]]


def test_a_wall_in_three_lines_occupies_exactly_the_cells_it_overlaps():
    wall = check_polygon(0, [[10.0, 0.0], [11.0, 0.0], [11.0, 20.0], [10.0, 20.0]])
    grid = polygons_on_grid([wall], rows=30, cols=30, cell=1.0)
    assert np.argwhere(grid.any(axis=0)).ravel().tolist() == [10]  # the column 10 ≤ x < 11 only
    assert np.argwhere(grid.any(axis=1)).ravel().tolist() == list(range(20))
    thin = check_polygon(1, [[5.2, 5.2], [5.4, 5.2], [5.4, 5.4]])  # far smaller than a cell
    assert np.argwhere(polygons_on_grid([thin], 10, 10, 1.0)).tolist() == [[5, 5]]


def test_the_cell_size_must_be_a_whole_number_of_map_pixels():
    occupancy = load_occupancy_map(MAPS / "warehouse.yaml")
    assert map_on_grid(occupancy, 2.0).shape == (50, 50)
    with pytest.raises(TerrainError, match=r"is not a whole number of pixels of 0.5"):
        map_on_grid(occupancy, 0.75)
    with pytest.raises(TerrainError, match="do not split into cells of 3 × 3"):
        map_on_grid(occupancy, 1.5)


def test_bad_maps_are_refused_naming_the_file(tmp_path):
    with pytest.raises(TerrainError, match=r"cannot read map .*nowhere.yaml"):
        load_occupancy_map(tmp_path / "nowhere.yaml")
    (tmp_path / "junk.yaml").write_text("just a string\n")
    with pytest.raises(TerrainError, match=r"junk.yaml is not a ROS map YAML file"):
        load_occupancy_map(tmp_path / "junk.yaml")
    (tmp_path / "short.yaml").write_text("image: x.pgm\nresolution: 1\n")
    with pytest.raises(TerrainError, match=r"short.yaml: missing key 'origin'"):
        load_occupancy_map(tmp_path / "short.yaml")
    pixels = np.full((4, 4), 254, dtype=np.uint8)
    assert load_occupancy_map(write_map(tmp_path, pixels, origin="[0.0, 0.0, 0.5]", name="turned")).yaw == 0.5
    with pytest.raises(TerrainError, match="key 'resolution'"):
        load_occupancy_map(write_map(tmp_path, pixels, resolution=-1, name="negative"))
    (tmp_path / "text.pgm").write_text("not an image")
    path = tmp_path / "text.yaml"
    path.write_text(ROS_YAML.format(image="text.pgm", resolution=1.0, origin="[0, 0, 0]", negate=0))
    with pytest.raises(TerrainError, match=r"text.pgm is not a PGM or PNG image"):
        load_occupancy_map(path)
    path.write_text(ROS_YAML.format(image="gone.pgm", resolution=1.0, origin="[0, 0, 0]", negate=0))
    with pytest.raises(TerrainError, match=r"gone.pgm does not exist"):
        load_occupancy_map(path)


@pytest.mark.parametrize(
    ("points", "message"),
    [
        ([[0, 0], [1, 1]], "3 or more points"),
        ([[0, 0], [1, "a"], [2, 0]], "finite numbers"),
        ([[0, 0], [1, 1], [2, 2]], "no area"),
        ([[0, 0], [2, 2], [2, 0], [0, 2]], "crosses itself"),
        ("square", "3 or more points"),
    ],
)
def test_a_polygon_that_is_not_one_is_refused_by_index(points, message):
    with pytest.raises(TerrainError, match=rf"obstacles\[3\].*{message}"):
        check_polygon(3, points)


def test_the_sha256_follows_the_image_too(tmp_path):
    pixels = np.full((4, 4), 254, dtype=np.uint8)
    path = write_map(tmp_path, pixels)
    before = load_occupancy_map(path).sha256
    pixels[0, 0] = 0
    cv2.imwrite(str(tmp_path / "m.pgm"), pixels)
    assert load_occupancy_map(path).sha256 != before
