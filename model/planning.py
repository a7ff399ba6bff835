"""The team's planning step: Algorithm 1 (objectives from blobs) then Algorithm 2 (assignment).

The in-process engine and the coordinator process call the same :class:`Planner`, so the objectives of a run do not depend on where the planning runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from model.assignment import assign_objectives
from model.objectives import BlobObjectives, fallback_objective, select_objectives
from model.scenario import Scenario

Plan = tuple[int, tuple[int, ...], np.ndarray, np.ndarray, np.ndarray | None]
"""(step, members, targets (N, 2), blob objectives Ψ (M, 2), blob labels of the grid or None)."""


@dataclass
class Planner:
    """Algorithm 1 then Algorithm 2, with the blob objectives kept between calls (Alg. 1 reuses them)."""

    scenario: Scenario
    blobs: BlobObjectives = field(default_factory=BlobObjectives)

    def plan(self, lack: np.ndarray, positions: np.ndarray) -> np.ndarray:
        """Objective (x, y) for every agent, shape (N, 2)."""
        self.blobs = select_objectives(lack, self.blobs, self.scenario.cell, self.scenario.range)
        objectives = self.blobs.positions
        if len(objectives) == 0:
            fallback = fallback_objective(lack, positions, self.scenario.cell)
            if fallback is None:
                return positions.copy()
            objectives = fallback[None, :]
        return objectives[assign_objectives(positions, objectives)]

    def labels(self) -> np.ndarray | None:
        """The blob labels of the last plan, as the recording keeps them (uint16), or None."""
        return None if self.blobs.labels is None else self.blobs.labels.astype(np.uint16)

    def record(self, step: int, targets: np.ndarray) -> Plan:
        """This plan as kept for the recording: members are all agents, in id order."""
        return (step, tuple(range(len(targets))), targets.copy(), self.blobs.positions.copy(), self.labels())
