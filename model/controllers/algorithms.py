"""The paper's planning step, Algorithm 1 (objectives from blobs) then Algorithm 2 (assignment): the planner
of the paper's controllers, and of every plug-in that brings none of its own.

On a terrain each objective is moved into the team's space and Algorithm 2 takes the lengths of the
shortest free paths (:func:`model.planning.path_lengths`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from model.paper.assignment import assign_objectives
from model.paper.objectives import BlobObjectives, cell_of, fallback_objective, select_objectives
from model.planning import TeamPlanner, path_lengths
from model.scenario import Scenario
from model.world.crowding import spread_shared, team_spacing
from model.world.detours import without_detours
from model.world.reachability import viewpoints
from model.world.world import map_frame_of, viewing_range_of, world_of

COMMITMENT = 1.0
"""On a terrain, how much nearer, in cells, Algorithm 2 counts the place each robot was sent to in the plan
before, while that place is still an objective (:func:`held_to_their_places`)."""


@dataclass
class Planner(TeamPlanner):
    """Algorithm 1 then Algorithm 2, with the blob objectives kept between calls (Alg. 1 reuses them)."""

    scenario: Scenario
    blobs: BlobObjectives = field(default_factory=BlobObjectives)
    sent: dict[int, tuple[float, float]] = field(default_factory=dict)  # on a terrain: agent → its place last plan

    def plan(self, lack: np.ndarray, positions: np.ndarray, members: list[int] | None = None) -> np.ndarray:
        """Objective (x, y) for every agent (``members``, by id; default all, in id order), shape (N, 2).

        A scenario with fixed ``objectives`` gives each robot its own, Algorithms 1–2 do not run.

        On a terrain Algorithm 1 runs on the same Υ (cells nobody can cover are at Λ* already), each
        objective is taken at the centre of the blob's cell it was found in, then moved to where a robot can see it from (:func:`model.world.reachability.viewpoints`)
        and Algorithm 2 takes the lengths of the shortest free paths to them (:func:`path_lengths`); robots with
        bodies that share an objective each get a place of their own (:mod:`model.world.crowding`)."""
        ids = list(range(len(positions))) if members is None else list(members)
        if self.scenario.objectives:  # in the map's frame, with a map (model.scenario.safety_keys)
            fixed = np.array([self.scenario.objectives[agent] for agent in ids], dtype=np.float64).reshape(-1, 2)
            return np.stack(map_frame_of(self.scenario).from_map(fixed[:, 0], fixed[:, 1]), axis=1)
        world = world_of(self.scenario)
        terrain = bool(world.ground.walls)
        self.blobs = select_objectives(lack, self.blobs, self.scenario.cell, self.scenario.range, by_paths=terrain)
        objectives = self.blobs.positions
        if len(objectives) == 0:
            fallback = fallback_objective(lack, positions, self.scenario.cell)
            if fallback is None:
                return positions.copy()
            objectives = fallback[None, :]
        if not terrain:
            return objectives[assign_objectives(positions, objectives)]
        if len(self.blobs.positions) and self.blobs.cells is not None:
            objectives = blob_targets(self.blobs, lack, self.scenario.cell)
        places = viewpoints(
            world.wall_grid,
            world.grain,
            world.reachable,
            objectives,
            viewing_range_of(self.scenario),
            self.scenario.cell,
        )
        lengths = path_lengths(world, positions, places)
        places, moved = without_detours(world, objectives, places, positions, lengths)
        if moved.any():
            lengths[:, moved] = path_lengths(world, positions, places[moved])
        held = held_to_their_places(lengths, places, [self.sent.get(agent) for agent in ids], self.scenario.cell)
        choice = assign_objectives(positions, places, held)
        self.sent = {agent: (float(places[j, 0]), float(places[j, 1])) for agent, j in zip(ids, choice, strict=True)}
        if (spacing := team_spacing(self.scenario)) > 0.0:
            return spread_shared(world, objectives, places, choice, lengths, positions, spacing)
        return places[choice]


def held_to_their_places(
    lengths: np.ndarray, places: np.ndarray, sent: list[tuple[float, float] | None], cell: float
) -> np.ndarray:
    """``lengths`` (N, M) with each robot's way to the place it was sent to before (``sent``, per robot; None:
    nowhere) shortened by COMMITMENT cells (not below 0), where that place is still one of ``places``: a robot keeps
    its objective unless another is that much nearer. Greedy Algorithm 2 on the bare lengths swapped two robots
    between three places every plan as they drove, each turning back before it arrived: on the lab map (N = 8
    seed 11, N = 4 seed 9 in a trial) they covered nothing for 200 time units and 4 cells were given up."""
    held = lengths.copy()
    for robot, place in enumerate(sent):
        if place is None:
            continue
        same = np.flatnonzero((places[:, 0] == place[0]) & (places[:, 1] == place[1]))
        held[robot, same] = np.maximum(held[robot, same] - COMMITMENT * cell, 0.0)
    return held


def blob_targets(blobs: BlobObjectives, lack: np.ndarray, cell: float) -> np.ndarray:
    """(M, 2): the centre of an uncovered cell of each objective's blob, for its viewpoint: the cell Algorithm 1
    found the objective in (:attr:`BlobObjectives.cells`) while it is uncovered, else the cell its point falls
    in (what lines 1-5 keep the objective for), else the blob's uncovered cell nearest the point (the first in
    row order on a tie). An objective
    kept for the cell its point falls in, its own cell covered, sent a lone robot on the campus map to a
    viewpoint of that covered cell, from which the blob's last two cells could not be seen (seed 15)."""
    assert blobs.cells is not None
    rows, cols = lack.shape
    targets = np.zeros((blobs.count, 2))
    for j, ((row, col), point) in enumerate(zip(blobs.cells, blobs.positions, strict=True)):
        if lack[row, col] <= 0.0:
            row, col = cell_of(point, cell, lack.shape)
        if lack[row, col] <= 0.0 and blobs.labels is not None:
            left = np.argwhere((blobs.labels == j + 1) & (lack > 0.0))
            if len(left):
                gaps = np.hypot((left[:, 1] + 0.5) * cell - point[0], (left[:, 0] + 0.5) * cell - point[1])
                row, col = left[int(np.argmin(gaps))]
        targets[j] = (min(max(col, 0), cols - 1) + 0.5) * cell, (min(max(row, 0), rows - 1) + 0.5) * cell
    return targets
