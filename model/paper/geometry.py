"""Angles and the wedge footprint of a forward-looking camera (Fig. 1)."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def wrap_angle(angle: float) -> float:
    """Wrap an angle to (-π, π], the range the paper uses for θ_i and e_θ (eq. 14)."""
    return angle - 2.0 * math.pi * math.ceil((angle - math.pi) / (2.0 * math.pi))


@njit(cache=True)
def wedge_bounds(
    x: float, y: float, theta: float, sensing_range: float, half_angle: float
) -> tuple[float, float, float, float]:
    """Axis-aligned box (x_min, x_max, y_min, y_max) around the wedge of eq. 2.

    The wedge is the apex, the two edge rays and the arc between them; its box
    is spanned by the apex, the arc's end points and any axis direction that
    falls inside the arc.
    """
    x_min = x
    x_max = x
    y_min = y
    y_max = y
    for edge in (theta - half_angle, theta + half_angle):
        ex = x + sensing_range * math.cos(edge)
        ey = y + sensing_range * math.sin(edge)
        x_min = min(x_min, ex)
        x_max = max(x_max, ex)
        y_min = min(y_min, ey)
        y_max = max(y_max, ey)
    for quarter in range(4):
        axis = quarter * 0.5 * math.pi
        if abs(wrap_angle(axis - theta)) <= half_angle:
            ax = x + sensing_range * math.cos(axis)
            ay = y + sensing_range * math.sin(axis)
            x_min = min(x_min, ax)
            x_max = max(x_max, ax)
            y_min = min(y_min, ay)
            y_max = max(y_max, ay)
    return x_min, x_max, y_min, y_max


@njit(cache=True)
def wedge_cell_range(
    x: float, y: float, theta: float, sensing_range: float, half_angle: float, cell: float
) -> tuple[int, int, int, int]:
    """Cell index ranges [row0, row1) × [col0, col1) whose centres may lie in the wedge.

    Not clipped to the grid: cells outside the domain still count in the
    sensed area S_Ω of eq. 6 (the domain of motion is all of ℝ²).
    """
    x_min, x_max, y_min, y_max = wedge_bounds(x, y, theta, sensing_range, half_angle)
    col0 = math.ceil(x_min / cell - 0.5)
    col1 = math.floor(x_max / cell - 0.5) + 1
    row0 = math.ceil(y_min / cell - 0.5)
    row1 = math.floor(y_max / cell - 0.5) + 1
    return row0, row1, col0, col1


@njit(cache=True)
def square_gap2(left: float, bottom: float, side: float) -> float:
    """Squared distance from the origin to the nearest point of the square [left, left + side] x
    [bottom, bottom + side] (0 when the origin lies in it or on its edge)."""
    gap_x = max(left, 0.0, -left - side)
    gap_y = max(bottom, 0.0, -bottom - side)
    return gap_x * gap_x + gap_y * gap_y
