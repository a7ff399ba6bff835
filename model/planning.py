"""What every team planner shares: the plan as the recording keeps it, the interface the engine and the
coordinator call, and eq. 17's distances on a terrain (the lengths of the shortest free paths).

Each controller's planner lives with its controller (:mod:`model.controllers`); the in-process engine and the
coordinator process call the same one, so the objectives of a run do not depend on where the planning runs.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from model.paper.objectives import BlobObjectives
from model.scenario import Scenario
from model.watchdog import ProgressWatchdog, Stall
from model.world.geodesic import path_length
from model.world.visibility import segment_crosses_occupied
from model.world.world import World, world_of

Plan = tuple[int, tuple[int, ...], np.ndarray, np.ndarray, np.ndarray | None]
"""(step, members, targets (N, 2), blob objectives Ψ (M, 2), blob labels of the grid or None)."""


class TeamPlanner:
    """The team's planning: ``plan`` gives every member (by id; default all, in id order) its objective
    (x, y), shape (N, 2); ``labels`` and ``record`` are what the recording keeps of the last plan."""

    blobs: BlobObjectives | None = None
    """Algorithm 1's blobs of the last plan, when the planner runs it: what the recording keeps of a plan."""

    replayed = False
    """True when each plan builds on the ones before (anicov's routes, cut once from the starting poses, and
    their progress, patches and cleanups): a coordinator restarted in realtime then replays every plan step
    from the agents' histories, as a lockstep one always does (:mod:`coordinator.rebuild`)."""

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
                field,
                ground.wall_grid,
                ground.grain,
                x,
                y,
                goal_x,
                goal_y,
                cell,
                ground.plan_radius,
                ground.bounded,
                lengths[i, j],
            )
    return lengths


def stall_reason(
    world: World,
    lack: np.ndarray,
    agent: int,
    position: tuple[float, float],
    objective: tuple[float, float],
    moved: float,
) -> str:
    """Why a robot made no progress, in words (model.watchdog): did it move, is it at its objective, can it
    get there, and what uncovered cells it sees from where it stands (within R, no wall across)."""
    cell = world.scenario.cell
    x, y = position
    gap = float(np.hypot(objective[0] - x, objective[1] - y))
    parts = ["stood still" if moved < cell else f"drove {moved:.1f} and covered nothing"]
    rows, cols = lack.shape
    goal = min(max(int(objective[1] // cell), 0), rows - 1), min(max(int(objective[0] // cell), 0), cols - 1)
    if gap <= cell:
        parts.append("at its objective")
    elif not world.reachable[goal]:
        parts.append(
            f"its objective, {gap:.2f} away, is not where a robot of radius {world.scenario.robot_radius} can go"
        )
    else:
        parts.append(f"{gap:.2f} from its objective")
    seen = _uncovered_in_sight(world, lack, x, y)
    parts.append(f"sees {seen} uncovered cells within R" if seen else "sees no uncovered cell within R")
    return ", ".join(parts)


def _uncovered_in_sight(world: World, lack: np.ndarray, x: float, y: float) -> int:
    cell, reach = world.scenario.cell, world.scenario.range
    rows, cols = lack.shape
    span = int(np.ceil(reach / cell))
    row, col = int(y // cell), int(x // cell)
    count = 0
    for r in range(max(row - span, 0), min(row + span + 1, rows)):
        for c in range(max(col - span, 0), min(col + span + 1, cols)):
            if lack[r, c] <= 0.0:
                continue
            cx, cy = (c + 0.5) * cell, (r + 0.5) * cell
            if np.hypot(cx - x, cy - y) < reach and not segment_crosses_occupied(
                world.wall_grid, x, y, cx, cy, world.grain
            ):
                count += 1
    return count


def default_patience(world: World) -> float:
    """model.watchdog's default: twice the time to drive across the reachable space at k_v
    (:attr:`model.world.world.World.across`), and at least 20 replanning periods."""
    scenario = world.scenario
    return max(2.0 * world.across / scenario.k_v, 20.0 * scenario.replan_period)


@dataclass
class WatchedPlanner:
    """A team planner with the progress watchdog (model.watchdog) around it: the engine and the coordinator
    call :meth:`plan` with the time, so both see the same stalls and plan the same."""

    planner: TeamPlanner
    world: World
    watchdog: ProgressWatchdog | None

    def plan(
        self, time: float, lack: np.ndarray, positions: np.ndarray, members: list[int] | None = None
    ) -> np.ndarray:
        if self.watchdog is None:
            return self.planner.plan(lack, positions, members)
        ids = list(range(len(positions))) if members is None else list(members)
        self.watchdog.observe(time, lack, positions, ids, functools.partial(stall_reason, self.world, lack))
        targets = self.planner.plan(self.watchdog.masked(lack), positions, members)
        self.watchdog.remember(targets, ids)
        return targets

    def only_given_up_left(self, lack: np.ndarray) -> bool:
        """The run is over: every cell left was given up by the watchdog."""
        return self.watchdog is not None and self.watchdog.only_given_up_left(lack)

    @property
    def stalls(self) -> list[Stall]:
        return [] if self.watchdog is None else self.watchdog.stalls

    def given_up(self) -> np.ndarray | None:
        return None if self.watchdog is None else self.watchdog.given_up


def watched_planner(scenario: Scenario, planner: TeamPlanner) -> WatchedPlanner:
    """The scenario's planner with its watchdog (none when ``watchdog = false``)."""
    world = world_of(scenario)
    if not scenario.watchdog:
        return WatchedPlanner(planner, world, None)
    patience = scenario.watchdog_time or default_patience(world)
    return WatchedPlanner(planner, world, ProgressWatchdog(patience, scenario.range, scenario.cell))
