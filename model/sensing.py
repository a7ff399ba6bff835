"""Wedge sensing (eq. 2): what an agent observes (eq. 6, 9) and the coverage it adds (eq. 3).

The map is a grid of cells of side ``cell``; cell (row, col) has its centre at
((col + ½)·cell, (row + ½)·cell). Coverage is held in fixed-point ticks
(:mod:`model.fixed_point`) so deltas from different agents commute exactly.

:func:`sense_wedge` makes one pass over the wedge's cells and returns:

- e_Ω, eq. 6: mean lack of coverage over the wedge's cells. Cells outside the domain are in the wedge
  (S_Ω is the area the camera sees) but have nothing left to cover, Υ = 0.
- w_left, w_right: the integral of eq. 9 split by side. Over uncovered cells (Ω − Υ₀) the integrand
  (R − r)(θ_i − θ_x)/(R F θ_ix) is ±(R − r)/(R F); w_left sums (R − r)/(R F)·cell² over uncovered
  cells to the left of the heading (θ_x > θ_i), w_right those to the right, so
  ∂ẽ/∂θ_i = (w_right − w_left)/Λ*.
- the coverage delta of eq. 3, Λ += α_i·dt, as a window of fixed-point ticks clipped to the grid.

On a terrain with occlusion (:class:`model.ground.Ground`) a cell of the wedge whose centre is hidden
(:func:`model.visibility.line_of_sight`: a wall or a teammate's disk on the way) stays in S_Ω but, like
a cell outside the domain, has nothing the camera can cover: no ticks, Υ = 0 in e_Ω and eq. 9. The
test is skipped when nothing in the wedge's window can hide anything (no occupied cell there, no
teammate's disk near), so an open stretch of a map costs what the open world costs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.fixed_point import COVERAGE_SCALE
from model.geometry import wedge_cell_range
from model.ground import Ground
from model.visibility import segment_crosses_occupied, segment_passes_disk


@njit(cache=True)
def sensing_ability(
    distance: float, bearing_offset: float, sensing_range: float, half_angle: float, alpha_max: float
) -> float:
    """Sensing ability α_i(r, θ_ix) of a wedge camera, eq. 2 (θ_ix = |θ_i − θ_x| ≥ 0)."""
    if distance <= sensing_range and bearing_offset <= half_angle:
        return alpha_max * (sensing_range - distance) * (half_angle - bearing_offset) / (sensing_range * half_angle)
    return 0.0


@njit(cache=True)
def lack_of_coverage(coverage_ticks: int, target_ticks: int) -> float:
    """Lack of coverage Υ = max(0, 1 − Λ/Λ*), eq. 4, from fixed-point ticks."""
    if coverage_ticks >= target_ticks:
        return 0.0
    return (target_ticks - coverage_ticks) / target_ticks


@njit(cache=True)
def wedge_polar(
    cx: float,
    cy: float,
    heading_x: float,
    heading_y: float,
    sensing_range: float,
    half_angle: float,
    cos_half_angle: float,
) -> tuple[float, float, float]:
    """(r, θ_ix, across) of a point at (cx, cy) from the robot when it lies in the wedge (the support of
    eq. 2), else r = −1. ``across`` > 0: the point is left of the heading."""
    distance = math.sqrt(cx * cx + cy * cy)
    if distance > sensing_range:
        return -1.0, 0.0, 0.0
    along = cx * heading_x + cy * heading_y
    across = heading_x * cy - heading_y * cx
    # Cheap rejection before the arctangent: outside the cone cos(offset) < cos F.
    if along < distance * cos_half_angle - 1e-12:
        return -1.0, 0.0, 0.0
    offset = abs(math.atan2(across, along)) if distance > 0.0 else 0.0
    if offset > half_angle:
        return -1.0, 0.0, 0.0
    return distance, offset, across


@njit(cache=True)
def sense_wedge(
    coverage: np.ndarray,
    target_ticks: int,
    x: float,
    y: float,
    theta: float,
    sensing_range: float,
    half_angle: float,
    alpha_max: float,
    dt: float,
    cell: float,
    ground: Ground,
    positions: np.ndarray,
    me: int,
) -> tuple[float, float, float, int, int, np.ndarray]:
    """One pass over agent i's wedge Ω_i: (e_Ω of eq. 6, w_left, w_right of eq. 9, and eq. 3's delta as
    ticks from cell (row0, col0)); see the module's docstring. ``positions`` (N, 2), every robot's (NaN:
    unknown; ``me``: this one) is read only with occlusion. The map is only read: deltas are applied later."""
    rows, cols = coverage.shape
    row0, row1, col0, col1 = wedge_cell_range(x, y, theta, sensing_range, half_angle, cell)
    clip_row0, clip_col0 = max(row0, 0), max(col0, 0)
    height = max(min(row1, rows) - clip_row0, 0)
    width = max(min(col1, cols) - clip_col0, 0)
    ticks = np.zeros((height, width), dtype=np.int64)
    heading_x, heading_y = math.cos(theta), math.sin(theta)
    cos_half_angle = math.cos(half_angle)
    tick_scale = dt * COVERAGE_SCALE
    area_weight = cell * cell / (sensing_range * half_angle)
    occluded_walls, occluders = _what_may_hide(ground, positions, me, x, y, sensing_range, row0, row1, col0, col1)
    cells_in_wedge, lack_sum, w_left, w_right = 0, 0.0, 0.0, 0.0
    for row in range(row0, row1):
        cy = (row + 0.5) * cell - y
        row_inside = 0 <= row < rows
        for col in range(col0, col1):
            cx = (col + 0.5) * cell - x
            distance, offset, across = wedge_polar(
                cx, cy, heading_x, heading_y, sensing_range, half_angle, cos_half_angle
            )
            if distance < 0.0:
                continue
            cells_in_wedge += 1
            if not row_inside or col < 0 or col >= cols:
                continue
            if (occluded_walls or occluders.shape[0] > 0) and _hidden(ground, occluders, x, y, row, col, cell):
                continue
            ability = sensing_ability(distance, offset, sensing_range, half_angle, alpha_max)
            ticks[row - clip_row0, col - clip_col0] = int(ability * tick_scale + 0.5)
            lack = lack_of_coverage(coverage[row, col], target_ticks)
            if lack > 0.0:
                lack_sum += lack
                weight = (sensing_range - distance) * area_weight
                if across > 0.0:
                    w_left += weight
                elif across < 0.0:
                    w_right += weight
    e_omega = lack_sum / cells_in_wedge if cells_in_wedge > 0 else 0.0
    return e_omega, w_left, w_right, clip_row0, clip_col0, ticks


@njit(cache=True)
def _what_may_hide(
    ground: Ground,
    positions: np.ndarray,
    me: int,
    x: float,
    y: float,
    sensing_range: float,
    row0: int,
    row1: int,
    col0: int,
    col1: int,
) -> tuple[bool, np.ndarray]:
    """(an occupied cell lies in the wedge's window, positions of the teammates whose disk reaches the
    wedge's range): what :func:`sense_wedge` must test; nothing at all without occlusion."""
    if not ground.occlusion:
        return False, np.zeros((0, 2))
    rows, cols = ground.occupied.shape
    walls = False
    for row in range(max(row0, 0), min(row1, rows)):
        for col in range(max(col0, 0), min(col1, cols)):
            if ground.occupied[row, col]:
                walls = True
                break
        if walls:
            break
    near = np.zeros((positions.shape[0], 2))
    count = 0
    if ground.radius > 0.0:
        for k in range(positions.shape[0]):
            px, py = positions[k, 0], positions[k, 1]
            gap = math.hypot(px - x, py - y)
            # Bodies that overlap (closer than 2r: robots that drove through each other, which only the
            # safety filter prevents) hide nothing from each other: one would otherwise be blind.
            if k == me or px != px or gap > sensing_range + ground.radius or gap < 2.0 * ground.radius:
                continue
            near[count, 0], near[count, 1] = px, py
            count += 1
    return walls, near[:count]


@njit(cache=True)
def _hidden(ground: Ground, occluders: np.ndarray, x: float, y: float, row: int, col: int, cell: float) -> bool:
    """Whether a teammate's disk or an occupied cell lies between (x, y) and the centre of cell (row, col)."""
    target_x, target_y = (col + 0.5) * cell, (row + 0.5) * cell
    for k in range(occluders.shape[0]):
        if segment_passes_disk(x, y, target_x, target_y, occluders[k, 0], occluders[k, 1], ground.radius):
            return True
    return segment_crosses_occupied(ground.occupied, x, y, target_x, target_y, cell)
