"""Unicycle kinematics, eq. 1."""

from __future__ import annotations

import math

from numba import njit

from agents.geometry import wrap_angle


@njit(cache=True)
def unicycle_step(x: float, y: float, theta: float, v: float, omega: float, dt: float) -> tuple[float, float, float]:
    """Integrate eq. 1 exactly over dt with (v, ω) held constant (an arc, or a line if ω = 0)."""
    if abs(omega) < 1e-9:
        return x + v * dt * math.cos(theta), y + v * dt * math.sin(theta), theta
    new_theta = theta + omega * dt
    radius = v / omega
    new_x = x + radius * (math.sin(new_theta) - math.sin(theta))
    new_y = y - radius * (math.cos(new_theta) - math.cos(theta))
    return new_x, new_y, wrap_angle(new_theta)
