"""The engine's steps for a controller written in Python (:meth:`model.controllers.interface.Controller.command`).

The same step as :func:`anicov.engine.advance_team` runs for a compiled law, in the same order: every robot
reads its wedge and decides from the poses at t_k (:func:`model.controllers.plugin_step.decide_with`, the call
the agent process makes), its command passes the safety filter, the deltas are added, then every robot
moves (eq. 1). So a plug-in team over Zenoh in lockstep equals this engine byte for byte.
"""

from __future__ import annotations

import numpy as np

from model.controllers.interface import Controller
from model.controllers.plugin_step import decide_with
from model.paper.coverage_map import add_window
from model.safety.safety import SafetyParameters, filter_command
from model.scenario import Scenario
from model.step import LawParameters, move
from model.world.ground import Ground


def advance_plugin_team(
    controller: Controller,
    scenario: Scenario,
    coverage: np.ndarray,
    poses: np.ndarray,
    objectives: np.ndarray,
    law: LawParameters,
    ground: Ground,
    fields: np.ndarray,
    safety: SafetyParameters,
    memory: np.ndarray,
    looks: np.ndarray,
    first_step: int,
    steps: int,
    uncovered: int,
    deficit: int,
    total_deficit: int,
    trace: np.ndarray,
    errors: np.ndarray,
    flags: np.ndarray,
) -> tuple[int, int, int]:
    """:func:`anicov.engine.advance_team` with ``controller.command`` deciding (``fields`` and ``looks``, the
    paper's law's, are not read); returns (steps done, uncovered, deficit)."""
    for step in range(steps):
        windows = _decide_team(
            controller, scenario, first_step + step, coverage, poses, objectives, law, ground, safety, memory,
            trace[step], flags[step],
        )  # fmt: skip
        for row0, col0, ticks in windows:
            removed, covered = add_window(coverage, row0, col0, ticks, law.target_ticks)
            deficit -= removed
            uncovered -= covered
        for i in range(poses.shape[0]):
            poses[i, 0], poses[i, 1], poses[i, 2] = move(
                poses[i, 0], poses[i, 1], poses[i, 2], trace[step, i, 3], trace[step, i, 4], law, ground
            )
        errors[step] = deficit / total_deficit
        if uncovered == 0:
            return step + 1, uncovered, deficit
    return steps, uncovered, deficit


def _decide_team(
    controller: Controller,
    scenario: Scenario,
    step: int,
    coverage: np.ndarray,
    poses: np.ndarray,
    objectives: np.ndarray,
    law: LawParameters,
    ground: Ground,
    safety: SafetyParameters,
    memory: np.ndarray,
    trace_row: np.ndarray,
    flags_row: np.ndarray,
) -> list[tuple[int, int, np.ndarray]]:
    """Every robot's command from the poses at t_k, through the safety filter (``trace_row`` and ``flags_row``
    written); the delta windows, in id order."""
    agents = poses.shape[0]
    fresh, teammates = np.zeros(agents), np.zeros(agents, dtype=np.int64)  # lockstep: every pose is t_k's
    positions = poses[:, :2].copy()
    windows = []
    for i in range(agents):
        pose = (float(poses[i, 0]), float(poses[i, 1]), float(poses[i, 2]))
        objective = (float(objectives[i, 0]), float(objectives[i, 1]))
        v, omega, e_omega, row0, col0, ticks = decide_with(
            controller, scenario, step, coverage, pose, objective, law, ground, positions, i
        )
        windows.append((row0, col0, ticks))
        if safety.enabled:
            v, omega, flags_row[i] = filter_command(
                v, omega, i, poses, fresh, teammates, ground, law.cell, safety, memory[i]
            )
        trace_row[i] = (*pose, v, omega, e_omega)
    return windows
