"""A map as saved by SLAM, fitted to the coverage grid: the unknown around it cropped, the rest padded to
whole cells (issue 34: map_saver writes whatever size the robot explored, often a small building in a wide
border of unknown).

- **Crop**: to the bounding box of the known pixels (free or occupied), plus :data:`MARGIN_CELLS` cells of
  margin, cut in whole cells counted from the image's lower-left corner, so that every coverage cell is the
  cell it would be on the whole image.
- **Pad**: with unknown pixels (not free, like the map's own unknown) on the right and at the top, up to a
  whole number of cells.
- **Frame**: the model's domain starts at (0, 0) at the fitted image's lower-left corner, its x axis along
  the image's rows; in the map's own frame (REP 105's ``map``, what RViz shows) that corner lies at
  :attr:`FittedMap.corner`, the map's ``origin`` plus the pixels cropped at the left and bottom (turned by
  the origin's yaw), and the model's x axis at that yaw (:class:`MapFrame`). Poses written for a user
  (trajectory.csv, the ROS 2 bases' odometry, the watchdog's report) and read from one (``initial_poses``,
  ``objectives``) are in the map's frame.

Unknown pixels inside the free space (a SLAM map's unscanned islands) stay not free: no robot plans through
them and no camera sees through them. A map whose known pixels span the whole image and split into whole
cells is not changed at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from model.scenario.terrain import OccupancyMap, TerrainError

MARGIN_CELLS = 1
"""Cells of unknown kept around the known pixels when the border is cropped: the outermost walls stay whole
and a robot's wedge may reach past them (it sees nothing there)."""


@dataclass(frozen=True)
class MapFrame:
    """Where the model's frame lies in the map's (see the module's docstring): the model's (0, 0) at ``corner``,
    its x axis at ``yaw`` radians. Without a yaw a point is only shifted (exactly the model's value plus the
    corner); points and headings may be floats or arrays."""

    corner: tuple[float, float] = (0.0, 0.0)
    yaw: float = 0.0

    def to_map(self, x: Any, y: Any) -> tuple[Any, Any]:
        """A model point in the map's frame."""
        if self.yaw == 0.0:
            return x + self.corner[0], y + self.corner[1]
        cos_yaw, sin_yaw = math.cos(self.yaw), math.sin(self.yaw)
        return self.corner[0] + cos_yaw * x - sin_yaw * y, self.corner[1] + sin_yaw * x + cos_yaw * y

    def from_map(self, x: Any, y: Any) -> tuple[Any, Any]:
        """A map-frame point in the model's frame."""
        dx, dy = x - self.corner[0], y - self.corner[1]
        if self.yaw == 0.0:
            return dx, dy
        cos_yaw, sin_yaw = math.cos(self.yaw), math.sin(self.yaw)
        return cos_yaw * dx + sin_yaw * dy, -sin_yaw * dx + cos_yaw * dy

    def heading_to_map(self, theta: Any) -> Any:
        """A model heading in the map's frame, in (−π, π] when turned."""
        return theta if self.yaw == 0.0 else _wrapped(theta + self.yaw)

    def heading_from_map(self, theta: Any) -> Any:
        """A map-frame heading in the model's frame, in (−π, π] when turned."""
        return theta if self.yaw == 0.0 else _wrapped(theta - self.yaw)


def _wrapped(angle: Any) -> Any:
    """model.paper.geometry.wrap_angle's (−π, π], for arrays too."""
    return angle - 2.0 * math.pi * np.ceil((angle - math.pi) / (2.0 * math.pi))


@dataclass(frozen=True)
class FittedMap:
    """See the module's docstring. ``occupied`` has a whole number of cells of ``factor`` pixels a side."""

    occupied: np.ndarray  # bool (rows_px, cols_px), row 0 = lowest y
    resolution: float
    factor: int  # pixels a cell side
    corner: tuple[float, float]  # map-frame (x, y) of the fitted image's lower-left corner
    cropped: tuple[int, int, int, int]  # pixels cut at the left, right, bottom and top
    padded: tuple[int, int]  # pixels of unknown added on the right and at the top
    yaw: float = 0.0  # the image's x axis in the map's frame (the origin's yaw)

    @property
    def frame(self) -> MapFrame:
        return MapFrame(self.corner, self.yaw)

    @property
    def extent(self) -> tuple[float, float]:
        """(width, height) of the domain, in the map's units."""
        rows, cols = self.occupied.shape
        return cols * self.resolution, rows * self.resolution

    def note(self, source: OccupancyMap) -> str | None:
        """What the fit changed, for the console; None when nothing was."""
        if not any(self.cropped) and not any(self.padded) and not self.yaw:
            return None
        rows, cols = source.occupied.shape
        width, height = self.extent
        parts = [f"map {source.path.name}: {cols} × {rows} pixels of {source.resolution}"]
        if any(self.cropped):
            left, right, bottom, top = self.cropped
            parts.append(
                f"unknown border cropped (left {left}, right {right}, bottom {bottom}, top {top} pixels; "
                f"{MARGIN_CELLS} cell of margin kept)"
            )
        if any(self.padded):
            parts.append(
                f"padded with unknown to whole cells of {self.factor * self.resolution:g} "
                f"({self.padded[0]} columns right, {self.padded[1]} rows at the top)"
            )
        turned = f", its x axis at yaw {self.yaw:g} rad" if self.yaw else ""
        parts.append(
            f"domain {width:g} × {height:g}, its lower-left corner at ({self.corner[0]:g}, {self.corner[1]:g}) in the map's frame{turned}"
        )
        return "; ".join(parts)


def cell_factor(occupancy_map: OccupancyMap, cell: float) -> int:
    """Pixels a cell side, or TerrainError when ``cell`` is not a whole multiple of the resolution."""
    factor = round(cell / occupancy_map.resolution)
    if factor < 1 or abs(factor * occupancy_map.resolution - cell) > 1e-9 * cell:
        raise TerrainError(
            f"scenario key 'cell': expected a whole multiple of the map's resolution {occupancy_map.resolution}, "
            f"got {cell!r}"
        )
    return factor


def fit_to_cells(occupancy_map: OccupancyMap, cell: float) -> FittedMap:
    """The map cropped and padded for cells of side ``cell`` (see the module's docstring)."""
    factor = cell_factor(occupancy_map, cell)
    occupied = occupancy_map.occupied
    rows, cols = occupied.shape
    known = occupancy_map.known if occupancy_map.known is not None else np.ones_like(occupied)
    if not known.any():
        raise TerrainError(f"map {occupancy_map.path}: every pixel is unknown: nothing to cover")
    known_rows, known_cols = np.nonzero(known.any(axis=1))[0], np.nonzero(known.any(axis=0))[0]
    margin = MARGIN_CELLS * factor
    # Cut in whole cells from the lower-left corner: the cells kept are the whole image's.
    bottom = max(known_rows[0] - margin, 0) // factor * factor
    left = max(known_cols[0] - margin, 0) // factor * factor
    top = min(known_rows[-1] + 1 + margin, rows)
    right = min(known_cols[-1] + 1 + margin, cols)
    kept = occupied[bottom:top, left:right]
    pad_rows, pad_cols = -kept.shape[0] % factor, -kept.shape[1] % factor
    fitted = np.pad(kept, ((0, pad_rows), (0, pad_cols)), constant_values=True)
    # The origin's yaw turns the image about its lower-left corner, the cropped pixels with it.
    corner = MapFrame(occupancy_map.origin, occupancy_map.yaw).to_map(
        int(left) * occupancy_map.resolution, int(bottom) * occupancy_map.resolution
    )
    corner = (float(corner[0]), float(corner[1]))
    return FittedMap(
        fitted,
        occupancy_map.resolution,
        factor,
        corner,
        (int(left), int(cols - right), int(bottom), int(rows - top)),
        (int(pad_cols), int(pad_rows)),
        occupancy_map.yaw,
    )
