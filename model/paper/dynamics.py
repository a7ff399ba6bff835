"""Unicycle kinematics, eq. 1."""

from __future__ import annotations

import math

from numba import njit

from model.paper.geometry import wrap_angle


@njit(cache=True)
def unicycle_step(x: float, y: float, theta: float, v: float, omega: float, dt: float) -> tuple[float, float, float]:
    """Integrate eq. 1 exactly over dt with (v, ω) held constant.

    The arc is written as a chord of length v·dt·sinc(ω·dt/2) along the mean
    heading θ + ω·dt/2, which stays accurate for any ω, including ω → 0
    (the radius form v/ω·(sin θ' − sin θ) cancels catastrophically there).
    """
    half_turn = 0.5 * omega * dt
    if abs(half_turn) > 1e-4:
        sinc = math.sin(half_turn) / half_turn
    else:
        sinc = 1.0 - half_turn * half_turn / 6.0
    chord = v * dt * sinc
    mean_heading = theta + half_turn
    return x + chord * math.cos(mean_heading), y + chord * math.sin(mean_heading), wrap_angle(theta + omega * dt)
