"""A wedge's pass over the grid: what an agent observes (eq. 6, 9) and the coverage it adds (eq. 3).

The map is a grid of cells of side ``cell``; cell (row, col) has its centre at
((col + ½)·cell, (row + ½)·cell). Coverage is held in fixed-point ticks
(:mod:`model.paper.fixed_point`) so deltas from different agents commute exactly.

The sensor itself (eq. 2, 4) is :mod:`model.paper.sensing`. :func:`sense_wedge` makes one pass over the wedge's cells and returns:

- e_Ω, eq. 6: mean lack of coverage over the wedge's cells. Cells outside the domain are in the wedge
  (S_Ω is the area the camera sees) but have nothing left to cover, Υ = 0.
- w_left, w_right: the integral of eq. 9 split by side. Over uncovered cells (Ω − Υ₀) the integrand
  (R − r)(θ_i − θ_x)/(R F θ_ix) is ±(R − r)/(R F); w_left sums (R − r)/(R F)·cell² over uncovered
  cells to the left of the heading (θ_x > θ_i), w_right those to the right, so
  ∂ẽ/∂θ_i = (w_right − w_left)/Λ*.
- the coverage delta of eq. 3, Λ += α_i·dt, as a window of fixed-point ticks clipped to the grid.

On a terrain with occlusion (:class:`model.world.ground.Ground`) a cell of the wedge whose centre is hidden
(:func:`model.world.visibility.line_of_sight`: a wall or a teammate's disk on the way) stays in S_Ω but, like
a cell outside the domain, has nothing the camera can cover: no ticks, Υ = 0 in e_Ω and eq. 9. The
exact test runs only on cells that something may hide (:mod:`model.world.occlusion`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.paper.fixed_point import COVERAGE_SCALE
from model.paper.geometry import wedge_cell_range
from model.paper.sensing import lack_of_coverage, offset_from_heading, sure_sensing_ability, wedge_reach
from model.world.ground import Ground
from model.world.occlusion import add_teammate_shadows, pseudo_bin, teammates_in_view, wall_shadows
from model.world.visibility import hidden_by_teammates, segment_crosses_occupied

SURELY_IN_CONE = 1e-9
"""How far past the cone's cheap test a point must lie, in cos θ_ix (along ≥ r·(cos F + this)), for the
wedge to hold it surely, without the arctangent of the exact test: far more than the rounding of either,
at any scale."""


@njit(cache=True)
def _delta_window(rows: int, cols: int, row0: int, row1: int, col0: int, col1: int) -> tuple[int, int, np.ndarray]:
    """The top-left cell and the zeroed ticks of a wedge's delta, its window clipped to the grid."""
    clip_row0, clip_col0 = max(row0, 0), max(col0, 0)
    height, width = max(min(row1, rows) - clip_row0, 0), max(min(col1, cols) - clip_col0, 0)
    return clip_row0, clip_col0, np.zeros((height, width), dtype=np.int64)


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
    doubt: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, float, float, int, int, np.ndarray]:
    """One pass over the wedge Ω_i (see the module): (e_Ω, w_left, w_right, row0, col0, ticks of eq. 3).
    ``positions`` (N, 2): every robot's (NaN: unknown; ``me``: this one), read only with occlusion; ``doubt``
    (position, heading): the ticks are the sure ones (:func:`model.paper.sensing.sure_sensing_ability`)."""
    teammates = teammates_in_view(ground, positions, me, x, y, sensing_range)
    return sense_wedge_among(
        coverage, target_ticks, x, y, theta, sensing_range, half_angle, alpha_max, dt, cell, ground, teammates,
        doubt,
    )  # fmt: skip


@njit(cache=True)
def sense_wedge_among(
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
    teammates: np.ndarray,
    doubt: tuple[float, float] = (0.0, 0.0),
) -> tuple[float, float, float, int, int, np.ndarray]:
    """:func:`sense_wedge` with the teammates that may hide part of the wedge already found
    (:func:`model.world.occlusion.teammates_in_view`), for a caller that needs them too."""
    rows, cols = coverage.shape
    row0, row1, col0, col1 = wedge_cell_range(x, y, theta, sensing_range, half_angle, cell)
    clip_row0, clip_col0, ticks = _delta_window(rows, cols, row0, row1, col0, col1)
    shadows = wall_shadows(ground, x, y, theta, half_angle, sensing_range, cell, row0, row1, col0, col1)
    add_teammate_shadows(shadows, teammates, ground.radius, x, y, theta, half_angle)
    cells_in_wedge, lack_sum, w_left, w_right = _sweep(
        coverage, target_ticks, (x, y, theta), (sensing_range, half_angle, alpha_max, dt, cell, doubt), ground, teammates,
        shadows, ticks, (row0, row1, col0, col1), (clip_row0, clip_col0),
    )  # fmt: skip
    e_omega = lack_sum / cells_in_wedge if cells_in_wedge > 0 else 0.0
    return e_omega, w_left, w_right, clip_row0, clip_col0, ticks


@njit(cache=True)
def _sweep(
    coverage: np.ndarray,
    target_ticks: int,
    pose: tuple[float, float, float],
    sensor: tuple[float, float, float, float, float, tuple[float, float]],
    ground: Ground,
    teammates: np.ndarray,
    shadows: np.ndarray,
    ticks: np.ndarray,
    window: tuple[int, int, int, int],
    clip: tuple[int, int],
) -> tuple[int, float, float, float]:
    """:func:`sense_wedge`'s pass over ``window`` (row0, row1, col0, col1) from ``pose`` with ``sensor`` (R, F, α_M,
    dt, cell, doubt): writes ``ticks`` (top-left cell ``clip``); (cells in the wedge, Σ lack, w_left, w_right)."""
    (x, y, theta), (sensing_range, half_angle, alpha_max, dt, cell, doubt) = pose, sensor
    (rows, cols), (row0, row1, col0, col1), (clip_row0, clip_col0) = coverage.shape, window, clip
    heading_x, heading_y, cos_half_angle = math.cos(theta), math.sin(theta), math.cos(half_angle)
    tick_scale, area_weight = dt * COVERAGE_SCALE, cell * cell / (sensing_range * half_angle)
    cells_in_wedge, lack_sum, w_left, w_right = 0, 0.0, 0.0, 0.0
    for row in range(row0, row1):
        cy = (row + 0.5) * cell - y
        row_inside = 0 <= row < rows
        for col in range(col0, col1):
            cx = (col + 0.5) * cell - x
            distance, along, across = wedge_reach(cx, cy, heading_x, heading_y, sensing_range, cos_half_angle)
            if distance < 0.0:
                continue
            on_grid = row_inside and 0 <= col < cols
            if ground.occlusion and on_grid:
                # The bins of model.world.occlusion first: nearer than every wall of its bin, seen; beyond a wall
                # that hides the whole bin, hidden; the exact test of model.world.visibility for the rest.
                distance2, k = distance * distance, pseudo_bin(across / (along + abs(across) + 1e-300), half_angle)
                near, beyond = shadows[0, k], shadows[1, k]
                target_x, target_y = (col + 0.5) * cell, (row + 0.5) * cell
                if distance2 > near and (
                    distance2 > beyond
                    or hidden_by_teammates(teammates, ground.radius, x, y, target_x, target_y)
                    or segment_crosses_occupied(ground.wall_grid, x, y, target_x, target_y, ground.grain)
                ):
                    # Hidden, yet in S_Ω if in the wedge: no arctangent where the cone's cheap test settles it.
                    surely = along >= distance * (cos_half_angle + SURELY_IN_CONE)
                    cells_in_wedge += surely or offset_from_heading(distance, along, across) <= half_angle
                    continue
            offset = offset_from_heading(distance, along, across)
            if offset > half_angle:
                continue
            cells_in_wedge += 1
            if not on_grid:
                continue
            ability = sure_sensing_ability(distance, offset, sensing_range, half_angle, alpha_max, doubt)
            ticks[row - clip_row0, col - clip_col0] = int(ability * tick_scale + 0.5)
            lack = lack_of_coverage(coverage[row, col], target_ticks)
            if lack > 0.0:
                lack_sum += lack
                weight = (sensing_range - distance) * area_weight
                if across > 0.0:
                    w_left += weight
                elif across < 0.0:
                    w_right += weight
    return cells_in_wedge, lack_sum, w_left, w_right
