"""From a scenario to what one agent needs: its control-law parameters and its initial pose.

Kept apart from the engine so that an agent process imports only what it runs.
"""

from __future__ import annotations

import math

import numpy as np

from model.clearance import disk_is_free
from model.coverage_map import CoverageMap
from model.scenario import Scenario
from model.step import LawParameters


def law_parameters(scenario: Scenario, coverage_map: CoverageMap) -> LawParameters:
    """The control and sensing parameters of a scenario."""
    return LawParameters(
        sensing_range=scenario.range,
        half_angle=scenario.half_angle,
        alpha_max=scenario.alpha_max,
        beta=scenario.beta,
        k_v=scenario.k_v,
        k_omega=scenario.k_omega,
        dt=scenario.dt,
        cell=scenario.cell,
        target_ticks=coverage_map.target_ticks,
        literal_heading=scenario.controller == "paper-literal",
        literal_omega=scenario.controller in ("paper-literal", "paper-eq16"),
    )


def initial_poses(scenario: Scenario) -> np.ndarray:
    """Poses (N, 3) drawn uniformly in the domain and in (−π, π] from the scenario's seed."""
    rng = np.random.default_rng(scenario.seed)
    width, height = scenario.domain
    x = rng.uniform(0.0, width, scenario.agents)
    y = rng.uniform(0.0, height, scenario.agents)
    theta = rng.uniform(-math.pi, math.pi, scenario.agents)
    return np.stack([x, y, theta], axis=1)


POSE_ATTEMPTS = 10_000
"""Draws per robot before the free space is declared too small for the team."""


def free_initial_poses(
    occupied: np.ndarray,
    cell: float,
    agents: int,
    seed: int,
    radius: float,
    clearance: float,
    reachable: np.ndarray | None = None,
) -> np.ndarray:
    """Poses (N, 3) drawn from ``seed`` uniformly over the grid, keeping those whose disk is free of
    obstacles and of the map's edge by ``clearance``, at least 2·radius + clearance from the robots drawn
    before, and (given ``reachable``) in a reachable cell: the terrain's counterpart of
    :func:`initial_poses`. Raises ValueError when the free space cannot hold the team."""
    rng = np.random.default_rng(seed)
    rows, cols = occupied.shape
    poses: list[tuple[float, float, float]] = []
    for agent in range(agents):
        for _ in range(POSE_ATTEMPTS):
            x, y = rng.uniform(0.0, cols * cell), rng.uniform(0.0, rows * cell)
            theta = rng.uniform(-math.pi, math.pi)
            if not disk_is_free(occupied, x, y, radius + clearance, cell, True):
                continue
            if reachable is not None and not reachable[min(int(y / cell), rows - 1), min(int(x / cell), cols - 1)]:
                continue
            if all(math.hypot(x - px, y - py) >= 2.0 * radius + clearance for px, py, _ in poses):
                poses.append((x, y, theta))
                break
        else:
            raise ValueError(
                f"no free place for robot {agent} of {agents} after {POSE_ATTEMPTS} draws: the free space "
                f"cannot hold {agents} robots of radius {radius} with clearance {clearance}"
            )
    return np.array(poses, dtype=np.float64)
