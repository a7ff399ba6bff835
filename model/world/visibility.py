"""Line of sight on the coverage grid: what walls and teammates hide from a camera (issue 11).

The rule, exactly as implemented: a cell is seen from a robot at p when its centre c lies in the
wedge of eq. 2 *and* the open segment p → c crosses no occupied cell and no other robot's disk.

- Cells crossed: the grid traversal of Amanatides and Woo ("A fast voxel traversal algorithm", 1987)
  from the cell of p to the cell of c: every cell whose interior the segment passes through, in order.
  Where the segment passes exactly through a grid corner, both cells beside the corner are tested
  too, so a wall drawn as a diagonal staircase of cells does not leak. The robot's own cell and the target cell are not tested: the robot never
  stands in an occupied cell, and an occupied target has nothing to cover.
- Teammates: a disk of radius r around each other robot's position hides c when the segment p → c
  comes closer than r to its centre (a robot does not hide itself; point robots, r = 0, hide nothing;
  a teammate whose disk overlaps this robot's, closer than 2r, hides nothing either: without a safety
  filter robots drive through each other, and a robot inside another would see nothing at all).

Pure numba kernels: the engine and the agent processes call the same code.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def segment_crosses_occupied(occupied: np.ndarray, x0: float, y0: float, x1: float, y1: float, cell: float) -> bool:
    """Whether the segment (x0, y0) → (x1, y1) passes through an occupied cell other than its two end cells
    (Amanatides–Woo traversal; cells outside the grid count as free here)."""
    return first_occupied_crossed(occupied, x0, y0, x1, y1, cell)[0] >= 0


@njit(cache=True)
def first_occupied_crossed(
    occupied: np.ndarray, x0: float, y0: float, x1: float, y1: float, cell: float
) -> tuple[int, int]:
    """(row, col) of the first occupied cell the traversal of :func:`segment_crosses_occupied` meets,
    (−1, −1) if none."""
    rows, cols = occupied.shape
    col, row = math.floor(x0 / cell), math.floor(y0 / cell)
    end_col, end_row = math.floor(x1 / cell), math.floor(y1 / cell)
    dx, dy = x1 - x0, y1 - y0
    step_col = 1 if dx > 0 else -1
    step_row = 1 if dy > 0 else -1
    # Distance along the segment (as a fraction of it) to the next vertical / horizontal grid line.
    if dx != 0.0:
        next_x = (col + (1 if dx > 0 else 0)) * cell
        t_max_x, t_delta_x = (next_x - x0) / dx, cell / abs(dx)
    else:
        t_max_x, t_delta_x = math.inf, math.inf
    if dy != 0.0:
        next_y = (row + (1 if dy > 0 else 0)) * cell
        t_max_y, t_delta_y = (next_y - y0) / dy, cell / abs(dy)
    else:
        t_max_y, t_delta_y = math.inf, math.inf
    while col != end_col or row != end_row:
        if min(t_max_x, t_max_y) > 1.0:
            break
        if t_max_x == t_max_y:
            # Exactly through a grid corner: both cells beside it count, so a diagonal wall does not leak.
            if _occupied_at(occupied, row, col + step_col, rows, cols, end_row, end_col):
                return row, col + step_col
            if _occupied_at(occupied, row + step_row, col, rows, cols, end_row, end_col):
                return row + step_row, col
            col += step_col
            row += step_row
            t_max_x += t_delta_x
            t_max_y += t_delta_y
        elif t_max_x < t_max_y:
            col += step_col
            t_max_x += t_delta_x
        else:
            row += step_row
            t_max_y += t_delta_y
        if _occupied_at(occupied, row, col, rows, cols, end_row, end_col):
            return row, col
    return -1, -1


@njit(cache=True)
def _occupied_at(occupied: np.ndarray, row: int, col: int, rows: int, cols: int, end_row: int, end_col: int) -> bool:
    """An occupied cell inside the grid that is not the target's own cell."""
    if row == end_row and col == end_col:
        return False
    return 0 <= row < rows and 0 <= col < cols and bool(occupied[row, col])


@njit(cache=True)
def segment_passes_disk(x0: float, y0: float, x1: float, y1: float, cx: float, cy: float, radius: float) -> bool:
    """Whether the segment (x0, y0) → (x1, y1) comes closer than ``radius`` to (cx, cy)."""
    if radius <= 0.0:
        return False
    dx, dy = x1 - x0, y1 - y0
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, ((cx - x0) * dx + (cy - y0) * dy) / length2))
    px, py = x0 + t * dx - cx, y0 + t * dy - cy
    return px * px + py * py < radius * radius


@njit(cache=True)
def line_of_sight(
    occupied: np.ndarray,
    x: float,
    y: float,
    target_x: float,
    target_y: float,
    cell: float,
    others: np.ndarray,
    radius: float,
) -> bool:
    """The rule of the module's docstring: nothing occupied and no teammate's disk between the robot at
    (x, y) and the point (target_x, target_y). ``others``: (K, 2) positions of the other robots."""
    if hidden_by_teammates(others, radius, x, y, target_x, target_y):
        return False
    return not segment_crosses_occupied(occupied, x, y, target_x, target_y, cell)


@njit(cache=True)
def hidden_by_teammates(
    teammates: np.ndarray, radius: float, x: float, y: float, target_x: float, target_y: float
) -> bool:
    """A teammate's disk (``teammates``: (K, 2) positions) lies across the segment from (x, y) to the target."""
    for k in range(teammates.shape[0]):
        if segment_passes_disk(x, y, target_x, target_y, teammates[k, 0], teammates[k, 1], radius):
            return True
    return False
