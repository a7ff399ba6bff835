"""What every team planner shares: the plan as the recording keeps it, the interface the engine and the
coordinator call, and eq. 17's distances on a terrain (the lengths of the shortest free paths).

Each controller's planner lives with its controller (:mod:`model.controllers`); the in-process engine and the
coordinator process call the same one, so the objectives of a run do not depend on where the planning runs.
"""

from __future__ import annotations

import numpy as np

from model.paper.objectives import BlobObjectives
from model.world.geodesic import path_length
from model.world.world import World

Plan = tuple[int, tuple[int, ...], np.ndarray, np.ndarray, np.ndarray | None]
"""(step, members, targets (N, 2), blob objectives Ψ (M, 2), blob labels of the grid or None)."""


class TeamPlanner:
    """The team's planning: ``plan`` gives every member (by id; default all, in id order) its objective
    (x, y), shape (N, 2); ``labels`` and ``record`` are what the recording keeps of the last plan."""

    blobs: BlobObjectives | None = None
    """Algorithm 1's blobs of the last plan, when the planner runs it: what the recording keeps of a plan."""

    cut_at_start = False
    """True when the first plan fixes each robot's whole route from the starting poses: a coordinator
    rebuilt in realtime plans step 0 again from those poses, then :meth:`resume`s."""

    def plan(self, lack: np.ndarray, positions: np.ndarray, members: list[int] | None = None) -> np.ndarray:
        raise NotImplementedError

    def labels(self) -> np.ndarray | None:
        """The blob labels of the last plan, as the recording keeps them (uint16), or None."""
        if self.blobs is None or self.blobs.labels is None:
            return None
        return self.blobs.labels.astype(np.uint16)

    def record(self, step: int, targets: np.ndarray) -> Plan:
        """This plan as kept for the recording: members are all agents, in id order."""
        centres = np.zeros((0, 2)) if self.blobs is None else self.blobs.positions.copy()
        return (step, tuple(range(len(targets))), targets.copy(), centres, self.labels())

    def resume(self, lack: np.ndarray, positions: list[tuple[float, float]], members: list[int]) -> str | None:
        """Put each member back on its plan after a restart (realtime); what was done, for the run log."""
        return None


def path_lengths(world: World, positions: np.ndarray, objectives: np.ndarray) -> np.ndarray:
    """(N, M) lengths of the shortest free paths from each robot to each objective: the straight
    distance when a straight drive gets there (as eq. 17 has it in the open), else the geodesic one."""
    ground = world.ground
    cell = world.scenario.cell
    lengths = np.linalg.norm(positions[:, None, :] - objectives[None, :, :], axis=2)
    for j, (goal_x, goal_y) in enumerate(objectives):
        field = world.field(goal_x, goal_y)
        for i, (x, y) in enumerate(positions):
            lengths[i, j] = path_length(
                field, ground.occupied, x, y, goal_x, goal_y, cell, ground.plan_radius, ground.bounded, lengths[i, j]
            )
    return lengths
