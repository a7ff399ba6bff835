"""Terrain: which cells of the coverage grid are occupied, from a ROS map or from polygons.

A map is the ROS map_server / Nav2 format: a YAML file naming an image (PGM or PNG), its
``resolution`` (domain units per pixel), ``origin`` [x, y, yaw] (the pose of the image's lower-left
pixel in the map's frame: the image's x axis lies at ``yaw``), ``negate``, ``occupied_thresh`` and ``free_thresh``. A pixel's occupancy is
p = (255 − value) / 255 (p = value / 255 with ``negate``); it is occupied when p > occupied_thresh,
free when p < free_thresh, and unknown in between, which counts as occupied (not free). Image row 0
is the top of the map; grid row 0 is the bottom (y grows with the row, as everywhere in the model).

On the coverage grid (cells of side ``cell``, a whole multiple of the resolution) a cell is occupied
when any map pixel in it is. A polygon ``[[x, y], ...]`` occupies a cell when it contains one of the
cell's 8 × 8 sub-pixel centres (even-odd rule) or has a vertex strictly inside it: a polygon that only
touches a cell's edge does not occupy it (see :func:`polygons_on_grid`).

Every error names the file or the polygon and what is wrong.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import yaml

POLYGON_SUPERSAMPLING = 8
"""Sub-pixels per cell side when a polygon is rasterised."""
MAP_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh")


class TerrainError(ValueError):
    """A map or a polygon that cannot be used; the message names the file or the polygon."""


@dataclass(frozen=True)
class OccupancyMap:
    """A map as read: one bool per pixel (row 0 at the bottom), its resolution and where it lies."""

    occupied: np.ndarray  # bool (height_px, width_px), row 0 = lowest y: occupied or unknown
    resolution: float  # domain units per pixel
    origin: tuple[float, float]  # world (x, y) of the lower-left corner of the lower-left pixel
    path: Path
    sha256: str  # of the YAML file and of the image, so either changing shows
    known: np.ndarray | None = None  # bool like ``occupied``: occupied or free (not unknown); None: every pixel
    yaw: float = 0.0  # radians: the image's x axis in the map's frame (origin's third value)

    @property
    def extent(self) -> tuple[float, float]:
        """(width, height) in domain units."""
        rows, cols = self.occupied.shape
        return cols * self.resolution, rows * self.resolution


def file_sha256(*paths: Path) -> str:
    """sha256 over the bytes of the given files, in order."""
    digest = hashlib.sha256()
    for path in paths:
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _map_number(path: Path, values: dict[str, Any], key: str, low: float, high: float) -> float:
    value = values.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise TerrainError(f"map {path}: key '{key}': expected a number, got {value!r}")
    if not low <= value <= high:
        raise TerrainError(f"map {path}: key '{key}': expected a number in [{low}, {high}], got {value!r}")
    return float(value)


def _read_yaml(path: Path) -> dict[str, Any]:
    try:
        values = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise TerrainError(f"cannot read map {path}: {error.strerror}") from error
    except (yaml.YAMLError, UnicodeDecodeError) as error:
        raise TerrainError(f"map {path} is not a ROS map YAML file: {error}") from error
    if not isinstance(values, dict):
        raise TerrainError(f"map {path} is not a ROS map YAML file: expected keys {', '.join(MAP_KEYS)}")
    missing = [key for key in MAP_KEYS if key not in values]
    if missing:
        raise TerrainError(f"map {path}: missing key '{missing[0]}' (a ROS map has {', '.join(MAP_KEYS)})")
    mode = values.get("mode", "trinary")
    if mode not in ("trinary", "scale"):
        raise TerrainError(f"map {path}: key 'mode': expected trinary or scale (thresholded alike), got {mode!r}")
    return values


def _origin(path: Path, value: Any) -> tuple[float, float, float]:
    if not isinstance(value, list) or len(value) != 3:
        raise TerrainError(f"map {path}: key 'origin': expected [x, y, yaw], got {value!r}")
    x, y, yaw = (_map_number(path, {"origin": item}, "origin", -math.inf, math.inf) for item in value)
    return x, y, yaw


def load_occupancy_map(path: str | Path) -> OccupancyMap:
    """Read a ROS map YAML and its image; raise TerrainError naming the file on any problem."""
    path = Path(path)
    values = _read_yaml(path)
    resolution = _map_number(path, values, "resolution", 1e-9, math.inf)
    occupied_thresh = _map_number(path, values, "occupied_thresh", 0.0, 1.0)
    free_thresh = _map_number(path, values, "free_thresh", 0.0, 1.0)
    if free_thresh > occupied_thresh:
        raise TerrainError(f"map {path}: free_thresh {free_thresh} is above occupied_thresh {occupied_thresh}")
    negate = values["negate"]
    if negate not in (0, 1, True, False):
        raise TerrainError(f"map {path}: key 'negate': expected 0 or 1, got {negate!r}")
    x, y, yaw = _origin(path, values["origin"])
    image_path = path.parent / str(values["image"])
    if not image_path.is_file():
        raise TerrainError(f"map {path}: its image {image_path} does not exist")
    pixels = cv2.imread(str(image_path), cv2.IMREAD_GRAYSCALE)
    if pixels is None or pixels.size == 0:
        raise TerrainError(f"map {path}: its image {image_path} is not a PGM or PNG image")
    occupancy = pixels.astype(np.float64) / 255.0 if negate else (255.0 - pixels.astype(np.float64)) / 255.0
    free = occupancy < free_thresh
    # Unknown (between the thresholds) is not free: a robot must not plan through it.
    occupied = np.flipud(~free).copy()
    known = np.flipud(free | (occupancy > occupied_thresh)).copy()
    return OccupancyMap(occupied, resolution, (x, y), path, file_sha256(path, image_path), known, yaw)


def coarsen(occupied: np.ndarray, factor: int) -> np.ndarray:
    """A grid ``factor`` times coarser: a cell is occupied when any of its factor × factor pixels is."""
    rows, cols = occupied.shape
    if rows % factor or cols % factor:
        raise ValueError(f"a {cols} × {rows} grid does not split into {factor} × {factor} blocks")
    return occupied.reshape(rows // factor, factor, cols // factor, factor).any(axis=(1, 3))


def map_on_grid(occupancy_map: OccupancyMap, cell: float) -> np.ndarray:
    """The map's occupancy on coverage cells of side ``cell`` (a whole multiple of the resolution)."""
    factor = round(cell / occupancy_map.resolution)
    if factor < 1 or abs(factor * occupancy_map.resolution - cell) > 1e-9 * cell:
        raise TerrainError(
            f"map {occupancy_map.path}: a cell of {cell} is not a whole number of pixels of {occupancy_map.resolution}"
        )
    rows, cols = occupancy_map.occupied.shape
    if rows % factor or cols % factor:
        raise TerrainError(
            f"map {occupancy_map.path}: its {cols} × {rows} pixels do not split into cells of {factor} × {factor}"
        )
    return coarsen(occupancy_map.occupied, factor)


def _segments_cross(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> bool:
    """Whether segments ab and cd cross at a point inside both (touching ends do not count)."""

    def side(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> float:
        return float((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    return side(a, b, c) * side(a, b, d) < 0.0 and side(c, d, a) * side(c, d, b) < 0.0


def check_polygon(index: int, points: Any) -> np.ndarray:
    """A polygon as an (K, 2) array, or TerrainError: at least 3 finite vertices, an area, no self-crossing."""
    name = f"obstacles[{index}]"
    if not isinstance(points, list | tuple) or len(points) < 3:
        raise TerrainError(
            f"scenario key '{name}': expected a polygon [[x, y], ...] of 3 or more points, got {points!r}"
        )
    for point in points:
        if (
            not isinstance(point, list | tuple)
            or len(point) != 2
            or any(isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) for v in point)
        ):
            raise TerrainError(f"scenario key '{name}': expected points [x, y] of finite numbers, got {point!r}")
    polygon = np.array(points, dtype=np.float64)
    count = len(polygon)
    for i in range(count):
        for j in range(i + 2, count):
            if i == 0 and j == count - 1:
                continue  # neighbours through the closing edge
            if _segments_cross(polygon[i], polygon[(i + 1) % count], polygon[j], polygon[(j + 1) % count]):
                raise TerrainError(f"scenario key '{name}': the polygon crosses itself (edges {i} and {j})")
    x, y = polygon[:, 0], polygon[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    if area <= 0.0:
        raise TerrainError(f"scenario key '{name}': the polygon has no area (its points are on one line)")
    return polygon


def contains(polygon: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Even-odd rule: which points (x, y) lie inside the polygon (a point on an edge may go either way)."""
    inside = np.zeros(x.shape, dtype=bool)
    for (x0, y0), (x1, y1) in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        if y0 == y1:
            continue
        straddles = (y0 > y) != (y1 > y)
        crossing_x = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        inside ^= straddles & (x < crossing_x)
    return inside


def polygons_on_grid(polygons: list[np.ndarray], rows: int, cols: int, cell: float) -> np.ndarray:
    """Cells (rows, cols) that the polygons occupy: a cell is occupied when a polygon contains one of its
    8 × 8 sub-pixel centres, or has a vertex strictly inside it. Sub-pixel centres never lie on a cell's
    edge, so a polygon that only touches a cell does not occupy it; a wall thinner than cell/8 may slip
    between sub-pixel centres away from its vertices: draw walls at least that thick."""
    occupied = np.zeros((rows, cols), dtype=bool)
    fine = POLYGON_SUPERSAMPLING
    for polygon in polygons:
        low = np.clip(np.floor(polygon.min(axis=0) / cell).astype(int), 0, [cols, rows])
        high = np.clip(np.ceil(polygon.max(axis=0) / cell).astype(int), 0, [cols, rows])
        if np.any(high <= low):
            continue  # wholly outside the grid
        xs = (np.arange(low[0] * fine, high[0] * fine) + 0.5) * cell / fine
        ys = (np.arange(low[1] * fine, high[1] * fine) + 0.5) * cell / fine
        grid_x, grid_y = np.meshgrid(xs, ys)
        inside = contains(polygon, grid_x, grid_y)
        shape = (high[1] - low[1], fine, high[0] - low[0], fine)
        occupied[low[1] : high[1], low[0] : high[0]] |= inside.reshape(shape).any(axis=(1, 3))
        for x, y in polygon:
            col, row = x / cell, y / cell
            if 0 <= col < cols and 0 <= row < rows and col != int(col) and row != int(row):
                occupied[int(row), int(col)] = True
    return occupied
