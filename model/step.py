"""One agent's control step, composed from the pure laws: read the map, decide, sense, move.

The in-process engine and the agent process both call these functions, so a
run over the bus and a run in one process execute the very same arithmetic.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from model.control import combined_law, global_law, local_law
from model.dynamics import unicycle_step
from model.sensing import sense_wedge


class LawParameters(NamedTuple):
    """Everything the control law and the sensor need, in the paper's symbols and units."""

    sensing_range: float  # R
    half_angle: float  # F, radians
    alpha_max: float  # α_M
    beta: float  # β
    k_v: float
    k_omega: float
    dt: float
    cell: float
    target_ticks: int  # Λ* in fixed-point ticks
    literal_heading: bool  # eq. 11 as printed
    literal_omega: bool  # eq. 16 as printed


@njit(cache=True)
def decide_and_sense(
    coverage: np.ndarray, x: float, y: float, theta: float, objective_x: float, objective_y: float, law: LawParameters
) -> tuple[float, float, float, int, int, np.ndarray]:
    """(v, ω, e_Ω) of one agent from its map and objective (eq. 6–16), and its delta window (eq. 3)."""
    e_omega, w_left, w_right, row0, col0, ticks = sense_wedge(
        coverage, law.target_ticks, x, y, theta, law.sensing_range, law.half_angle, law.alpha_max, law.dt, law.cell
    )
    u_loc, theta_loc = local_law(e_omega, w_left, w_right, theta, law.half_angle)
    u_glo, theta_glo = global_law(x, y, objective_x, objective_y, law.sensing_range, law.literal_heading)
    v, omega = combined_law(
        theta, e_omega, u_loc, theta_loc, u_glo, theta_glo, law.beta, law.k_v, law.k_omega, law.literal_omega
    )
    return v, omega, e_omega, row0, col0, ticks


def load_kernels(coverage: np.ndarray, pose: tuple[float, float, float], law: LawParameters) -> None:
    """Have numba load the control kernels now, with the argument types of the real calls (half a second
    from its cache at the first call), on a scratch map: nothing of the agent's state changes."""
    x, y, theta = pose
    v, omega, _, _, _, _ = decide_and_sense(np.zeros_like(coverage), x, y, theta, x + 1.0, y, law)
    move(x, y, theta, v, omega, law)


@njit(cache=True)
def sense_only(
    coverage: np.ndarray, x: float, y: float, theta: float, law: LawParameters
) -> tuple[int, int, np.ndarray]:
    """The delta window of an agent whose velocities come from elsewhere (the zig-zag pilot)."""
    _, _, _, row0, col0, ticks = sense_wedge(
        coverage, law.target_ticks, x, y, theta, law.sensing_range, law.half_angle, law.alpha_max, law.dt, law.cell
    )
    return row0, col0, ticks


@njit(cache=True)
def move(x: float, y: float, theta: float, v: float, omega: float, law: LawParameters) -> tuple[float, float, float]:
    """The pose after one step, eq. 1."""
    return unicycle_step(x, y, theta, v, omega, law.dt)
