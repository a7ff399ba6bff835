"""Robots with bodies that Algorithm 2 sends to one objective: each to a place of its own.

Algorithm 2 gives each objective ⌊N/M⌋ to ⌈N/M⌉ robots, and at the end of a run one or two blobs are left
for the whole team. Point robots in the open share a point harmlessly. Robots with bodies on a map do not:
on the lab map of issue 34 every team of 2 to 8 that did not finish ended with its robots queued in a
passage one robot wide toward one viewpoint, the first unable to turn to the blob with a teammate's
barrier at its back and a wall ahead, the others held behind it, for good.

So on a terrain with bodies (:func:`team_spacing` > 0), of the robots that share an objective the one with
the shortest free path goes to its viewpoint (:func:`model.world.reachability.viewpoints`), and each of the
others to the reachable cell nearest itself that sees the same target (:func:`model.world.reachability.seers`)
at least the spacing from every place already given; a robot for which no such cell is left stays clear of
them: where it is, or the nearest reachable cell that is far enough from all of them.
"""

from __future__ import annotations

import math

import numpy as np

from model.scenario import Scenario
from model.scenario.physics_keys import pair_margin_of
from model.world.ground import PLANNING_MARGIN
from model.world.world import World


def team_spacing(scenario: Scenario) -> float:
    """How far apart the places given to robots that share an objective are: what the safety filter keeps
    between two robots' look-ahead points (2r + s + 2l) plus a cell and the planning margin, as a robot
    stops anywhere within half a cell of its place; with the filter off, the bodies (2r) plus as much. 0 for
    point robots: the paper's robots share objectives as Algorithm 2 has it."""
    if scenario.robot_radius <= 0.0:
        return 0.0
    clearance = 2.0 * scenario.robot_radius
    if scenario.filters:
        clearance += pair_margin_of(scenario) + 2.0 * scenario.lookahead
    return clearance + scenario.cell + PLANNING_MARGIN * scenario.cell


def spread_shared(
    world: World,
    targets: np.ndarray,
    places: np.ndarray,
    choice: np.ndarray,
    lengths: np.ndarray,
    positions: np.ndarray,
    spacing: float,
) -> np.ndarray:
    """The place (x, y) of every robot, (N, 2). ``targets`` (M, 2): Algorithm 1's objectives (what to see);
    ``places`` (M, 2): their viewpoints; ``choice`` (N,): Algorithm 2's objective of each robot; ``lengths``
    (N, M): the free paths' lengths from each robot to each viewpoint. An objective's first robot (shortest
    path, then lowest id) gets its viewpoint, unless an objective before it has that place (two blobs may
    share their nearest seer: two robots on the lab map were sent to one spot, N = 8 seed 20); then the
    others, in the same order, their own places."""
    goals = places[choice].copy()
    order = sorted(range(len(choice)), key=lambda i: (lengths[i, choice[i]], i))
    first = {int(choice[i]): i for i in reversed(order)}
    taken: list[np.ndarray] = []
    for j in sorted(first):
        if not _clear_of(places[j], taken, spacing):
            goals[first[j]] = _own_place(world, targets[j], positions[first[j]], taken, spacing)
        taken.append(goals[first[j]])
    for i in order:
        j = int(choice[i])
        if first[j] == i:
            continue
        goals[i] = _own_place(world, targets[j], positions[i], taken, spacing)
        taken.append(goals[i])
    return goals


def _clear_of(point: np.ndarray, taken: list[np.ndarray], spacing: float) -> bool:
    return all(math.hypot(point[0] - other[0], point[1] - other[1]) >= spacing for other in taken)


def _own_place(
    world: World, target: np.ndarray, position: np.ndarray, taken: list[np.ndarray], spacing: float
) -> np.ndarray:
    """The reachable cell nearest the robot that sees ``target`` and is clear of every place taken; with none
    left, the robot's own position if it is clear of them, else the nearest reachable cell centre that is.
    Nearest the robot, not the target: a helper sent to the seer nearest the blob drove round to the far
    side of the teammate at the blob's viewpoint, in a passage, and the two held each other for good, one
    unable to pass, the other looking at the cell through the first one's body (the campus map, N = 4 seed 12)."""
    cell = world.scenario.cell
    found = world.seers_of(float(target[0]), float(target[1]))  # what coverable means (viewpoints does the same)
    order = np.argsort(np.hypot(found[:, 1] - position[0], found[:, 2] - position[1]), kind="stable")
    for _, x, y in found[order]:
        if _clear_of(np.array((x, y)), taken, spacing):
            return np.array((x, y))
    if _clear_of(position, taken, spacing):
        return position.copy()
    rows, cols = np.nonzero(world.reachable)
    centres = np.column_stack(((cols + 0.5) * cell, (rows + 0.5) * cell))
    clear = np.ones(len(centres), dtype=bool)
    for other in taken:
        clear &= np.hypot(centres[:, 0] - other[0], centres[:, 1] - other[1]) >= spacing
    if not clear.any():
        return position.copy()
    candidates = centres[clear]
    return candidates[int(np.argmin(np.hypot(candidates[:, 0] - position[0], candidates[:, 1] - position[1])))]
