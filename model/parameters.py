"""From a scenario to what one agent needs: its control-law parameters and its initial pose.

Kept apart from the engine so that an agent process imports only what it runs.
"""

from __future__ import annotations

import math

import numpy as np

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
