"""The progress watchdog (issue 34): a run that stops covering cells is noticed, explained and acted on.

It runs inside the team's planning (:meth:`model.planning.TeamPlanner.plan_watched`), so the in-process engine
and the coordinator process, which plan at the same steps from the same map, see the same stalls and do the
same about them (lockstep stays equal to the engine byte for byte).

- **Progress**: a cell was covered: fewer cells are uncovered than the fewest seen. A plan that finds no
  progress for ``patience`` time units while coverable cells remain uncovered is a *stall*. (Σ Υ falling is
  not enough: a robot looking at a cell on the rim of its range, where eq. 2's α is nearly 0, raised it by a
  tick now and then for 15,000 time units on the lab map of issue 34, and was never called stalled.)
- **What it says**: for each robot, where it stands, the objective it was given, how far it moved during the
  stall, and why it does not get there or see it (:func:`robot_reasons`).
- **What it does**: the uncovered cells within R of each robot's objective (what the robot was sent to see)
  are *set aside*: the planner plans as if they were covered, so the robots go elsewhere. They come back
  after another ``patience``, or at once when nothing else is left. A cell set aside at a second stall is
  *given up*: the run ends when only given-up cells are left, and says which cells, and why.

``patience`` defaults to twice the time a robot takes to drive across its reachable space at k_v (a robot
crossing the map to its next blob covers nothing on the way), and at least 20 replanning periods.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from model.scenario.map_fit import MapFrame

ReasonFunction = Callable[[int, tuple[float, float], tuple[float, float], float], str]
"""(agent, position, objective, path since the last progress) → why the robot made no progress, in words."""


def rounded(point: tuple[float, float]) -> list[float]:
    """A point for summary.json, to 0.1 mm (rounded as its own number type rounds: the same as before the
    map frame could turn)."""
    return [round(point[0], 4), round(point[1], 4)]


@dataclass(frozen=True)
class RobotStall:
    """One robot at a stall: where it stood, what it was sent to, and why it did not get there."""

    agent: int
    position: tuple[float, float]
    objective: tuple[float, float]
    moved: float  # path length since the last progress (units)
    reason: str

    def as_dict(self, frame: MapFrame) -> dict[str, object]:
        """For summary.json: positions in the map's frame."""
        return {
            "agent": self.agent,
            "position": rounded(frame.to_map(*self.position)),
            "objective": rounded(frame.to_map(*self.objective)),
            "moved": round(self.moved, 4),
            "reason": self.reason,
        }


@dataclass(frozen=True)
class Stall:
    """One intervention: when, what was done ("set aside" or "given up"), on which cells, and each robot."""

    time: float
    action: str
    cells: tuple[tuple[int, int], ...]  # (row, col)
    robots: tuple[RobotStall, ...]

    def as_dict(self, cell: float, frame: MapFrame) -> dict[str, object]:
        return {
            "time": round(self.time, 6),
            "action": self.action,
            "cells": len(self.cells),
            "cell_centres": [rounded(frame.to_map((col + 0.5) * cell, (row + 0.5) * cell)) for row, col in self.cells],
            "robots": [robot.as_dict(frame) for robot in self.robots],
        }

    def line(self, cell: float, frame: MapFrame) -> str:
        """One line for the console and the recording (positions in the map's frame)."""
        robots = "; ".join(
            "robot {} at ({:.2f}, {:.2f}) for ({:.2f}, {:.2f}): {}".format(
                r.agent, *frame.to_map(*r.position), *frame.to_map(*r.objective), r.reason
            )
            for r in self.robots
        )
        return f"watchdog at t = {self.time:.1f}: no progress; {len(self.cells)} cells {self.action}. {robots}"


def cells_near(points: np.ndarray, uncovered: np.ndarray, radius: float, cell: float) -> np.ndarray:
    """Uncovered cells whose centres lie within ``radius`` of any of ``points`` (K, 2)."""
    rows, cols = uncovered.shape
    near = np.zeros_like(uncovered)
    span = math.ceil(radius / cell)
    for x, y in points:
        row, col = math.floor(y / cell), math.floor(x / cell)
        r0, r1 = max(row - span, 0), min(row + span + 1, rows)
        c0, c1 = max(col - span, 0), min(col + span + 1, cols)
        if r0 >= r1 or c0 >= c1:
            continue
        centre_y = (np.arange(r0, r1) + 0.5) * cell
        centre_x = (np.arange(c0, c1) + 0.5) * cell
        gap = np.hypot(centre_x[None, :] - x, centre_y[:, None] - y)
        near[r0:r1, c0:c1] |= gap <= radius
    return near & uncovered


@dataclass
class ProgressWatchdog:
    """See the module's docstring. ``patience`` in time units; ``sensing_range`` R and ``cell`` in units."""

    patience: float
    sensing_range: float
    cell: float
    best: float = math.inf  # the fewest uncovered cells seen
    since: float = 0.0  # time of the last progress
    set_aside: np.ndarray | None = None  # bool (rows, cols)
    set_aside_until: float = math.inf
    struck: np.ndarray | None = None  # cells set aside at some stall
    given_up: np.ndarray | None = None
    stalls: list[Stall] = field(default_factory=list)
    moved: dict[int, float] = field(default_factory=dict)  # agent → path since the last progress
    last_positions: dict[int, tuple[float, float]] = field(default_factory=dict)
    last_objectives: dict[int, tuple[float, float]] = field(default_factory=dict)

    def _ensure(self, shape: tuple[int, int]) -> None:
        if self.set_aside is None:
            self.set_aside = np.zeros(shape, dtype=bool)
            self.struck = np.zeros(shape, dtype=bool)
            self.given_up = np.zeros(shape, dtype=bool)

    def _track(self, positions: np.ndarray, members: list[int]) -> None:
        for agent, (x, y) in zip(members, positions, strict=True):
            last = self.last_positions.get(agent)
            if last is not None:
                self.moved[agent] = self.moved.get(agent, 0.0) + math.hypot(x - last[0], y - last[1])
            self.last_positions[agent] = (float(x), float(y))

    def masked(self, lack: np.ndarray) -> np.ndarray:
        """The lack the planner plans on: set-aside and given-up cells as if covered."""
        self._ensure(lack.shape)
        hidden = self.set_aside | self.given_up
        return np.where(hidden, 0.0, lack) if hidden.any() else lack

    def only_given_up_left(self, lack: np.ndarray) -> bool:
        """Every uncovered cell was given up: nothing a robot of this team can still cover."""
        if self.given_up is None or not self.given_up.any():
            return False
        uncovered = lack > 0.0
        return bool(uncovered.any()) and not (uncovered & ~self.given_up).any()

    def observe(
        self,
        time: float,
        lack: np.ndarray,
        positions: np.ndarray,
        members: list[int],
        explain: ReasonFunction,
    ) -> Stall | None:
        """Called at every plan with the map and poses of ``time``; acts on a stall and returns it, else None."""
        self._ensure(lack.shape)
        self._track(positions, members)
        uncovered = lack > 0.0
        remaining = int(uncovered.sum())
        others = uncovered & ~self.set_aside & ~self.given_up
        if self.set_aside.any() and (time >= self.set_aside_until or not others.any()):
            self.set_aside[:] = False  # their turn again
            self.set_aside_until = math.inf
        if remaining < self.best or not uncovered.any():
            self.best, self.since = remaining, time
            self.moved.clear()
            return None
        if time - self.since < self.patience or not self.last_objectives:
            return None
        objectives = np.array([self.last_objectives[a] for a in members if a in self.last_objectives]).reshape(-1, 2)
        near = cells_near(objectives, uncovered & ~self.given_up, self.sensing_range, self.cell)
        if not near.any():
            near = uncovered & ~self.given_up & ~self.set_aside  # the objectives see nothing left: all of it
        again = near & self.struck
        fresh = near & ~self.struck
        robots = []
        for agent in members:
            position = self.last_positions[agent]
            objective = self.last_objectives.get(agent, position)
            moved = self.moved.get(agent, 0.0)
            robots.append(RobotStall(agent, position, objective, moved, explain(agent, position, objective, moved)))
        stall: Stall
        if again.any():
            self.given_up |= again
            stall = Stall(time, "given up", tuple(map(tuple, np.argwhere(again).tolist())), tuple(robots))
        else:
            self.set_aside |= fresh
            self.struck |= fresh
            self.set_aside_until = time + self.patience
            stall = Stall(time, "set aside", tuple(map(tuple, np.argwhere(fresh).tolist())), tuple(robots))
        self.stalls.append(stall)
        self.since = time  # a fresh start for the next window
        self.moved.clear()
        return stall

    def remember(self, objectives: np.ndarray, members: list[int]) -> None:
        """The objectives the plan gave (by member)."""
        for agent, (x, y) in zip(members, objectives, strict=True):
            self.last_objectives[agent] = (float(x), float(y))
