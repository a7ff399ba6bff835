"""A straightforward numpy formulation of one team step: vectorised over cells, a loop over agents.

It is the yardstick the engine is benchmarked against (bench/bench_engine.py)
and an independent check of the numba kernels (tests/test_reference.py). It
computes the same quantities (eq. 2–9) in floating point without the
fixed-point rounding of the deltas.
"""

from __future__ import annotations

import numpy as np

from model.paper.control import combined_law, global_law, local_law
from model.paper.dynamics import unicycle_step
from model.paper.fixed_point import COVERAGE_SCALE
from model.step import LawParameters


def wedge_readings(
    lack: np.ndarray, x: float, y: float, theta: float, law: LawParameters, centres: tuple[np.ndarray, np.ndarray]
):
    """(e_Ω, w_left, w_right, α·dt grid) of one agent over the whole grid, eq. 2, 6, 9."""
    cx, cy = centres[0] - x, centres[1] - y
    distance = np.hypot(cx, cy)
    bearing = np.arctan2(cy, cx) - theta
    bearing = (bearing + np.pi) % (2 * np.pi) - np.pi
    in_wedge = (distance <= law.sensing_range) & (np.abs(bearing) <= law.half_angle)
    ability = np.where(
        in_wedge,
        law.alpha_max
        * (law.sensing_range - distance)
        * (law.half_angle - np.abs(bearing))
        / (law.sensing_range * law.half_angle),
        0.0,
    )
    # Cells of the wedge outside the grid count in S_Ω: add them analytically from the area.
    wedge_cells = law.sensing_range**2 * law.half_angle / law.cell**2
    uncovered = in_wedge & (lack > 0.0)
    weight = (law.sensing_range - distance) * law.cell**2 / (law.sensing_range * law.half_angle)
    w_left = float(weight[uncovered & (bearing > 0)].sum())
    w_right = float(weight[uncovered & (bearing < 0)].sum())
    e_omega = float(lack[in_wedge].sum() / max(wedge_cells, 1.0))
    return e_omega, w_left, w_right, ability * law.dt


def numpy_team_step(coverage: np.ndarray, poses: np.ndarray, objectives: np.ndarray, law: LawParameters) -> np.ndarray:
    """One step of the whole team (eq. 1–16) with numpy, a Python loop over agents; returns (v, ω) per agent."""
    rows, cols = coverage.shape
    centres = np.meshgrid((np.arange(cols) + 0.5) * law.cell, (np.arange(rows) + 0.5) * law.cell)
    lack = np.maximum(0.0, 1.0 - coverage / law.target_ticks)
    controls = np.zeros((len(poses), 2))
    added = np.zeros_like(coverage)
    for i, (x, y, theta) in enumerate(poses):
        e_omega, w_left, w_right, delta = wedge_readings(lack, x, y, theta, law, centres)
        u_loc, theta_loc = local_law(e_omega, w_left, w_right, theta, law.half_angle)
        u_glo, theta_glo = global_law(x, y, objectives[i, 0], objectives[i, 1], law.sensing_range, law.literal_heading)
        controls[i] = combined_law(
            theta, e_omega, u_loc, theta_loc, u_glo, theta_glo, law.beta, law.k_v, law.k_omega, law.literal_omega
        )
        added += np.floor(delta * COVERAGE_SCALE + 0.5).astype(np.int64)
    coverage += added
    for i in range(len(poses)):
        poses[i] = unicycle_step(*poses[i], *controls[i], law.dt)
    return controls
