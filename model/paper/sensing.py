"""Wedge sensing (eq. 2, 4): the camera's sensing ability at a point and the lack of coverage of a cell.

The pass of a wedge over the grid (eq. 3, 6, 9), with what walls and teammates hide, is
:mod:`model.world.wedge`; the functions here are the sensor itself, pure.
"""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def sensing_ability(
    distance: float, bearing_offset: float, sensing_range: float, half_angle: float, alpha_max: float
) -> float:
    """Sensing ability α_i(r, θ_ix) of a wedge camera, eq. 2 (θ_ix = |θ_i − θ_x| ≥ 0)."""
    if distance <= sensing_range and bearing_offset <= half_angle:
        return alpha_max * (sensing_range - distance) * (half_angle - bearing_offset) / (sensing_range * half_angle)
    return 0.0


@njit(cache=True)
def sure_sensing_ability(
    distance: float,
    bearing_offset: float,
    sensing_range: float,
    half_angle: float,
    alpha_max: float,
    doubt: tuple[float, float],
) -> float:
    """α_i of eq. 2 where the wedge holds the point from every pose within ``doubt`` (position, heading) of the
    believed one, else 0: the wedge shrunk by the pose's doubt (issue 37, item 4). From a position δ off, the
    point lies at most δ farther, and its bearing turns by at most asin(δ / r), the angle a disk of radius δ
    subtends at it. No doubt: eq. 2 itself.

    Why the support and not the least α: a localiser's error is drawn afresh at every fix, and eq. 2 is linear
    inside the wedge, so what a robot believes it gave a cell inside is, on average over the steps, what it gave;
    only at the wedge's edges, where α is cut at 0, does the belief give on average more than the truth
    (rooms, N = 4, the issue's noise: the least α over the doubt took +55 % time at one σ, +110 % at two)."""
    position_doubt, heading_doubt = doubt
    if position_doubt <= 0.0 and heading_doubt <= 0.0:
        return sensing_ability(distance, bearing_offset, sensing_range, half_angle, alpha_max)
    if distance <= position_doubt or distance + position_doubt > sensing_range:
        return 0.0  # the robot may stand on the point or past it, or the point beyond its reach
    if bearing_offset + heading_doubt + math.asin(position_doubt / distance) > half_angle:
        return 0.0  # the point may lie outside the cone
    return sensing_ability(distance, bearing_offset, sensing_range, half_angle, alpha_max)


@njit(cache=True)
def lack_of_coverage(coverage_ticks: int, target_ticks: int) -> float:
    """Lack of coverage Υ = max(0, 1 − Λ/Λ*), eq. 4, from fixed-point ticks."""
    if coverage_ticks >= target_ticks:
        return 0.0
    return (target_ticks - coverage_ticks) / target_ticks


@njit(cache=True)
def wedge_reach(
    cx: float, cy: float, heading_x: float, heading_y: float, sensing_range: float, cos_half_angle: float
) -> tuple[float, float, float]:
    """(r, along, across) of a point at (cx, cy) from the robot when it lies within R and passes the cone's
    cheap test (cos θ_ix ≥ cos F, to rounding), else r = −1: the support of eq. 2 before the exact test of
    :func:`offset_from_heading`. ``across`` > 0: the point is left of the heading."""
    distance = math.sqrt(cx * cx + cy * cy)
    if distance > sensing_range:
        return -1.0, 0.0, 0.0
    along = cx * heading_x + cy * heading_y
    across = heading_x * cy - heading_y * cx
    if along < distance * cos_half_angle - 1e-12:
        return -1.0, 0.0, 0.0
    return distance, along, across


@njit(cache=True)
def offset_from_heading(distance: float, along: float, across: float) -> float:
    """θ_ix = |θ_i − θ_x| of a point (0 at the robot itself): the wedge holds it when θ_ix ≤ F."""
    return abs(math.atan2(across, along)) if distance > 0.0 else 0.0
