"""Where a robot's disk may stand: never over an occupied cell, never off a map (issue 11).

A robot is a disk of radius r (r = 0: the paper's point robot). It overlaps an occupied cell when the
distance from its centre to the cell's square is below r, or, for any r, when its centre lies in the
closed square. With a map the domain's edge is a wall too: the disk must lie inside [0, W] × [0, H].
A step whose end pose would overlap is not taken as a move: the robot keeps its position and turns
(:func:`step_or_stay`), so it can never pass into or through a wall, whatever its speed.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.paper.dynamics import unicycle_step


@njit(cache=True)
def disk_is_free(occupied: np.ndarray, x: float, y: float, radius: float, cell: float, bounded: bool) -> bool:
    """Whether a disk of ``radius`` at (x, y) overlaps no occupied cell (and, ``bounded``, stays on the grid)."""
    rows, cols = occupied.shape
    if bounded and (x - radius < 0.0 or y - radius < 0.0 or x + radius > cols * cell or y + radius > rows * cell):
        return False
    # One cell more on each side: a disk that only touches a cell's edge must still find that cell.
    col0, col1 = max(math.floor((x - radius) / cell) - 1, 0), min(math.floor((x + radius) / cell) + 1, cols - 1)
    row0, row1 = max(math.floor((y - radius) / cell) - 1, 0), min(math.floor((y + radius) / cell) + 1, rows - 1)
    for row in range(row0, row1 + 1):
        for col in range(col0, col1 + 1):
            if not occupied[row, col]:
                continue
            # Distance from the centre to the cell's closed square.
            distance2 = _point_box_distance2(x, y, col * cell, row * cell, (col + 1) * cell, (row + 1) * cell)
            if distance2 == 0.0 or distance2 < radius * radius:
                return False
    return True


@njit(cache=True)
def clearance_within(occupied: np.ndarray, x: float, y: float, radius: float, cell: float, bounded: bool) -> float:
    """The distance from (x, y) to the nearest occupied square (and, ``bounded``, the grid's edge), or
    ``radius`` if nothing is that close."""
    rows, cols = occupied.shape
    nearest = radius
    if bounded:
        nearest = max(min(nearest, x, y, cols * cell - x, rows * cell - y), 0.0)
    col0, col1 = max(math.floor((x - radius) / cell) - 1, 0), min(math.floor((x + radius) / cell) + 1, cols - 1)
    row0, row1 = max(math.floor((y - radius) / cell) - 1, 0), min(math.floor((y + radius) / cell) + 1, rows - 1)
    for row in range(row0, row1 + 1):
        for col in range(col0, col1 + 1):
            if occupied[row, col]:
                distance2 = _point_box_distance2(x, y, col * cell, row * cell, (col + 1) * cell, (row + 1) * cell)
                nearest = min(nearest, math.sqrt(distance2))
    return nearest


@njit(cache=True)
def step_or_stay(
    occupied: np.ndarray,
    x: float,
    y: float,
    theta: float,
    v: float,
    omega: float,
    dt: float,
    radius: float,
    cell: float,
    bounded: bool,
) -> tuple[float, float, float]:
    """Eq. 1 over dt, unless the end pose's disk would overlap an obstacle: then only the turn is taken."""
    next_x, next_y, next_theta = unicycle_step(x, y, theta, v, omega, dt)
    if disk_is_free(occupied, next_x, next_y, radius, cell, bounded):
        return next_x, next_y, next_theta
    return x, y, next_theta


@njit(cache=True)
def swept_disk_is_free(
    occupied: np.ndarray, x0: float, y0: float, x1: float, y1: float, radius: float, cell: float, bounded: bool
) -> bool:
    """Whether the disk stays free along the segment (x0, y0) → (x1, y1), exactly: no occupied cell's
    square comes closer than ``radius`` to the segment (and, ``bounded``, both ends keep the disk on the
    grid, which then holds for the whole segment). A square that close lies in a row the segment comes
    within ``radius`` of, and within ``radius`` of the part of the segment in that row's band: row by row,
    the squares of that stretch (a cell more each side, for rounding) get the exact test."""
    rows, cols = occupied.shape
    if bounded and not (_on_grid(x0, y0, radius, rows, cols, cell) and _on_grid(x1, y1, radius, rows, cols, cell)):
        return False
    reach2 = max(radius * radius, 1e-300)
    dx, dy = x1 - x0, y1 - y0
    row_lo = max(math.floor((min(y0, y1) - radius) / cell) - 1, 0)
    row_hi = min(math.floor((max(y0, y1) + radius) / cell) + 1, rows - 1)
    for row in range(row_lo, row_hi + 1):
        # The stretch of the segment whose y lies within radius of this row's band [row, row + 1) cells.
        band_lo, band_hi = row * cell - radius, (row + 1) * cell + radius
        if dy == 0.0:
            if y0 < band_lo or y0 > band_hi:
                continue
            t_lo, t_hi = 0.0, 1.0
        else:
            t_lo, t_hi = (band_lo - y0) / dy, (band_hi - y0) / dy
            t_lo, t_hi = max(min(t_lo, t_hi), 0.0), min(max(t_lo, t_hi), 1.0)
            if t_lo > t_hi:
                continue
        x_lo, x_hi = min(x0 + t_lo * dx, x0 + t_hi * dx), max(x0 + t_lo * dx, x0 + t_hi * dx)
        col_lo = max(math.floor((x_lo - radius) / cell) - 1, 0)
        col_hi = min(math.floor((x_hi + radius) / cell) + 1, cols - 1)
        for col in range(col_lo, col_hi + 1):
            if (
                occupied[row, col]
                and _segment_square_distance2(
                    x0, y0, x1, y1, col * cell, row * cell, (col + 1) * cell, (row + 1) * cell
                )
                < reach2
            ):
                return False
    return True


@njit(cache=True)
def _on_grid(x: float, y: float, radius: float, rows: int, cols: int, cell: float) -> bool:
    return x - radius >= 0.0 and y - radius >= 0.0 and x + radius <= cols * cell and y + radius <= rows * cell


@njit(cache=True)
def _segment_square_distance2(
    x0: float, y0: float, x1: float, y1: float, left: float, bottom: float, right: float, top: float
) -> float:
    """Squared distance between a segment and a closed axis-aligned square (0 when they meet)."""
    if _segment_meets_box(x0, y0, x1, y1, left, bottom, right, top):
        return 0.0
    best = min(
        _point_box_distance2(x0, y0, left, bottom, right, top), _point_box_distance2(x1, y1, left, bottom, right, top)
    )
    for corner_x, corner_y in ((left, bottom), (right, bottom), (left, top), (right, top)):
        best = min(best, _point_segment_distance2(corner_x, corner_y, x0, y0, x1, y1))
    return best


@njit(cache=True)
def _point_box_distance2(x: float, y: float, left: float, bottom: float, right: float, top: float) -> float:
    gap_x = max(left - x, 0.0, x - right)
    gap_y = max(bottom - y, 0.0, y - top)
    return gap_x * gap_x + gap_y * gap_y


@njit(cache=True)
def _point_segment_distance2(px: float, py: float, x0: float, y0: float, x1: float, y1: float) -> float:
    dx, dy = x1 - x0, y1 - y0
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, ((px - x0) * dx + (py - y0) * dy) / length2))
    ex, ey = x0 + t * dx - px, y0 + t * dy - py
    return ex * ex + ey * ey


@njit(cache=True)
def _segment_meets_box(
    x0: float, y0: float, x1: float, y1: float, left: float, bottom: float, right: float, top: float
) -> bool:
    """Liang–Barsky: whether the segment has a point in the closed box."""
    t0, t1 = 0.0, 1.0
    dx, dy = x1 - x0, y1 - y0
    for p, q in ((-dx, x0 - left), (dx, right - x0), (-dy, y0 - bottom), (dy, top - y0)):
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            t = q / p
            if p < 0.0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
            if t0 > t1:
                return False
    return True
