"""The safety filter's quadratic programme, solved exactly: the point nearest a command inside a polygon.

Every constraint of the filter (:mod:`model.safety.safety`) is a half-plane g·z ≥ c in the plane of
z = (v, l·ω), and its objective |z − ẑ|² is the Euclidean distance to the nominal command ẑ. The QP
is therefore the projection of ẑ onto a convex polygon, which has a closed form by enumeration: the
projection is ẑ itself when ẑ is feasible, else it lies on the boundary, either inside one edge (the
projection of ẑ onto that edge's line, if feasible) or at a vertex (two lines' intersection, if
feasible); the nearest feasible candidate is the optimum. With m constraints that is m + m(m−1)/2
candidates, each checked against the m constraints: exact, and fast for the few (4 to 20) that a
robot's filter holds. ``tests/test_barrier_qp.py`` checks it against quadprog (Goldfarb–Idnani).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

FEASIBILITY_TOLERANCE = 1e-9
"""How far a candidate may fall short of a constraint (rounding). The filter's slack ε (a step's
arc against its chord, :data:`model.safety.safety` docstring) is many orders larger, so this never costs safety."""


@njit(cache=True)
def _feasible(gx: np.ndarray, gy: np.ndarray, c: np.ndarray, count: int, zx: float, zy: float) -> bool:
    for k in range(count):
        if gx[k] * zx + gy[k] * zy < c[k] - FEASIBILITY_TOLERANCE * (1.0 + abs(c[k])):
            return False
    return True


@njit(cache=True)
def project_onto_polygon(
    gx: np.ndarray, gy: np.ndarray, c: np.ndarray, count: int, target_x: float, target_y: float
) -> tuple[bool, float, float]:
    """argmin |z − target|² subject to gx[k]·z_x + gy[k]·z_y ≥ c[k] for k < ``count``.

    Returns (feasible, z_x, z_y); (False, 0, 0) when the polygon is empty."""
    if _feasible(gx, gy, c, count, target_x, target_y):
        return True, target_x, target_y
    best, best_x, best_y = math.inf, 0.0, 0.0
    for k in range(count):  # inside one edge
        norm2 = gx[k] * gx[k] + gy[k] * gy[k]
        shortfall = c[k] - (gx[k] * target_x + gy[k] * target_y)
        if norm2 == 0.0 or shortfall <= 0.0:
            continue
        zx, zy = target_x + shortfall / norm2 * gx[k], target_y + shortfall / norm2 * gy[k]
        cost = (zx - target_x) ** 2 + (zy - target_y) ** 2
        if cost < best and _feasible(gx, gy, c, count, zx, zy):
            best, best_x, best_y = cost, zx, zy
    for k in range(count):  # at a vertex
        for j in range(k + 1, count):
            det = gx[k] * gy[j] - gy[k] * gx[j]
            if abs(det) < 1e-12 * math.hypot(gx[k], gy[k]) * math.hypot(gx[j], gy[j]):
                continue  # parallel edges meet nowhere
            zx = (c[k] * gy[j] - gy[k] * c[j]) / det
            zy = (gx[k] * c[j] - c[k] * gx[j]) / det
            cost = (zx - target_x) ** 2 + (zy - target_y) ** 2
            if cost < best and _feasible(gx, gy, c, count, zx, zy):
                best, best_x, best_y = cost, zx, zy
    if best == math.inf:
        return False, 0.0, 0.0
    return True, best_x, best_y
