"""The safety filter's slide along a wall (issue 12, :mod:`model.safety.safety`): where a robot whose law drives
it into a wall turns, so that the centre barrier lets it move on along the wall."""

from __future__ import annotations

import math

from numba import njit

from model.paper.geometry import wrap_angle
from model.safety.barrier_constraints import SafetyParameters

SLIDE_AWAY = math.radians(20.0)
"""How far from the wall's tangent a robot sliding along it heads: at the barrier (h = 0) the filter lets a
robot move only if it heads away from the wall by more than asin(κ) (9° at the paper's gains)."""


@njit(cache=True)
def slide_along_wall(theta: float, wall_x: float, wall_y: float, safety: SafetyParameters) -> float:
    """An ω that slides a robot pressed on a wall along it (the wall-following rule of bug algorithms):
    toward the wall's tangent nearest its heading, SLIDE_AWAY off the wall; head-on, to the right. The
    centre barrier holds v alone, so a robot heading into a wall whose law does not turn it would stand
    there for ever. From the heading, not the law's wish: that one may point back into the wall."""
    gain = safety.omega_max / math.pi  # k_ω
    along = math.cos(theta) * wall_x + math.sin(theta) * wall_y
    tx, ty = math.cos(theta) - along * wall_x, math.sin(theta) - along * wall_y
    if math.hypot(tx, ty) < 1e-6:
        tx, ty = -wall_y, wall_x  # straight at it: to the right (n points back at the robot)
    side = math.atan2(ty, tx)
    heading = side + SLIDE_AWAY * math.sin(wrap_angle(math.atan2(wall_y, wall_x) - side))
    return gain * wrap_angle(heading - theta)
