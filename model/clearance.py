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

from model.dynamics import unicycle_step


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
            gap_x = max(col * cell - x, 0.0, x - (col + 1) * cell)
            gap_y = max(row * cell - y, 0.0, y - (row + 1) * cell)
            distance2 = gap_x * gap_x + gap_y * gap_y
            if distance2 == 0.0 or distance2 < radius * radius:
                return False
    return True


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
    """Whether the disk stays free along the segment (x0, y0) → (x1, y1), tested every quarter of the
    smaller of the cell and the radius (a straight drive toward a waypoint, in steps shorter than that)."""
    spacing = 0.25 * min(cell, radius) if radius > 0.0 else 0.25 * cell
    samples = max(1, math.ceil(math.hypot(x1 - x0, y1 - y0) / spacing))
    for k in range(1, samples + 1):
        t = k / samples
        if not disk_is_free(occupied, x0 + t * (x1 - x0), y0 + t * (y1 - y0), radius, cell, bounded):
            return False
    return True
