"""model.scenario.mrpt_gridmap: MRPT's saved occupancy grids, written here byte by byte as MRPT lays them out."""

from __future__ import annotations

import gzip
import struct

import numpy as np
import pytest

from model.scenario.map_file import load_map
from model.scenario.terrain import TerrainError


def write_gridmap(path, cells: np.ndarray, x_min=-1.0, y_min=-2.0, resolution=0.05, version=3, compress=True):
    """An MRPT COccupancyGridMap2D file: class name, version, bits per cell, sizes, extent, int8 log-odds."""
    rows, cols = cells.shape
    header = bytes([0x80 | 19]) + b"COccupancyGridMap2D" + bytes([version, 8])
    header += struct.pack("<II5f", cols, rows, x_min, x_min + cols * resolution, y_min, y_min + rows * resolution,
                          resolution)  # fmt: skip
    data = header + cells.astype(np.int8).tobytes() + b"\x00" * 64  # the options that follow are not read
    path.write_bytes(gzip.compress(data) if compress else data)
    return path


def test_log_odds_of_being_free_are_thresholded_as_map_saver_would(tmp_path):
    cells = np.zeros((4, 6), dtype=np.int8)  # 0: unknown (p = 0.5)
    cells[0, :] = 100  # p(free) = 1/(1 + e^(−100/16)) ≈ 0.998: free
    cells[1, :] = -100  # occupied
    cells[2, :] = 10  # p(free) ≈ 0.65: p(occupied) 0.35, between the thresholds: unknown
    occupancy = load_map(write_gridmap(tmp_path / "m.gridmap.gz", cells))
    assert occupancy.resolution == 0.05 and occupancy.origin == (-1.0, -2.0)
    assert not occupancy.occupied[0].any() and occupancy.occupied[1:].all()  # row 0 at y_min: no flip
    assert occupancy.known[:2].all() and not occupancy.known[2:].any()


def test_an_uncompressed_gridmap_reads_alike(tmp_path):
    cells = np.full((3, 3), 100, dtype=np.int8)
    assert not load_map(write_gridmap(tmp_path / "m.gridmap", cells, compress=False)).occupied.any()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"\x85hello", "not an MRPT grid map"),
        (bytes([0x80 | 19]) + b"COccupancyGridMap2D" + bytes([1]), "version 1 is not read"),
        (bytes([0x80 | 19]) + b"COccupancyGridMap2D" + bytes([3, 8]) + b"\x00" * 5, "ends inside its header"),
    ],
)
def test_a_broken_gridmap_names_the_file_and_the_problem(tmp_path, content, message):
    path = tmp_path / "bad.gridmap"
    path.write_bytes(content)
    with pytest.raises(TerrainError, match=message) as error:
        load_map(path)
    assert str(path) in str(error.value)


def test_a_gridmap_cut_short_is_refused(tmp_path):
    path = write_gridmap(tmp_path / "m.gridmap", np.zeros((10, 10), dtype=np.int8), compress=False)
    path.write_bytes(path.read_bytes()[:80])
    with pytest.raises(TerrainError, match="ends before its 10 × 10 cells"):
        load_map(path)
