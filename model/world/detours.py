"""Viewpoints the team reaches without a detour round the building.

:func:`model.world.reachability.viewpoints` sends a robot to an objective's own cell, or to the reachable
cell nearest it that sees it. On a real map that cell may be reachable only the long way round, while
a cell on the team's side of a wall sees the same target through a gap: on the campus map (N = 2, seed 29)
three cells in a speckled pocket had viewpoints 250 m of driving away and a seer 13 m away. Algorithm 2
measured every place at about 250 m; the robot whose place two viewpoints shared was sent to the near
seer (:mod:`model.world.crowding`), the other round the building; at the next plan the one driving round
was the nearer and the two swapped, every plan, for 3,000 time units, and nine cells were given up.

So a place that the team reaches by a path longer than DETOUR_RANGES sensing ranges than another cell
that sees the same target (a detour) is moved to the seer the team reaches soonest, counting the seer's
gap to the target too (a seer at the rim of the range covers slowest, eq. 2). In the open, and wherever
a seer's way to the target is about its straight gap, no seer saves that much (it sees the target from
closer than R), so nothing changes there.
"""

from __future__ import annotations

import math

import numpy as np

from model.world.geodesic import distance_fields
from model.world.reachability import nearest_reachable
from model.world.world import World, viewing_range_of

DETOUR_RANGES = 2.0
"""How many sensing ranges shorter the way to another seer must be before a place is moved there."""


def without_detours(
    world: World, targets: np.ndarray, places: np.ndarray, positions: np.ndarray, lengths: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``places`` (M, 2), the viewpoints of ``targets`` (M, 2), with every place reached only by a detour moved
    to the seer of its target that the team reaches soonest, and which were moved (bool, M). ``lengths``
    (N, M): the free paths from the robots at ``positions`` (N, 2) to the places. ``places`` is not changed."""
    cell, sensing_range = world.scenario.cell, viewing_range_of(world.scenario)
    saving = DETOUR_RANGES * sensing_range
    places, moved = places.copy(), np.zeros(len(places), dtype=bool)
    shortest = np.min(lengths, axis=0)
    straight = np.min(
        np.hypot(positions[:, None, 0] - targets[None, :, 0], positions[:, None, 1] - targets[None, :, 1]), axis=0
    )
    team: tuple[np.ndarray, np.ndarray] | None = None
    # A seer's way plus its gap is at least the straight line from the team to the target (+inf is tried).
    for j in np.flatnonzero(~(shortest - saving <= straight)):
        found = world.seers_of(float(targets[j, 0]), float(targets[j, 1]))
        rows, cols = np.floor(found[:, 2] / cell).astype(np.int64), np.floor(found[:, 1] / cell).astype(np.int64)
        # A seer saves at most its way round to the place less its gap: only seers across a wall can save enough.
        across = world.field(*places[j])[rows, cols] - found[:, 0] > saving
        if not across.any():
            continue
        if team is None:
            team = _team_fields(world, positions)
        fields, offsets = team
        costs = np.min(fields[:, rows[across], cols[across]] + offsets[:, None], axis=0) + found[across, 0]
        best = int(np.argmin(costs))  # seers come nearest the target first: the nearest on a tie
        if costs[best] < shortest[j] - saving:
            places[j], moved[j] = found[across][best, 1:], True
    return places, moved


def _team_fields(world: World, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The geodesic distance from each robot's cell (or the reachable cell nearest it) to every cell, (N, rows,
    cols), and each robot's way to that cell's centre, (N,)."""
    cell = world.scenario.cell
    starts = nearest_reachable(world.reachable, positions, cell)
    cells = [(math.floor(y / cell), math.floor(x / cell)) for x, y in starts]
    centres = np.array([((col + 0.5) * cell, (row + 0.5) * cell) for row, col in cells]).reshape(-1, 2)
    offsets = np.hypot(centres[:, 0] - positions[:, 0], centres[:, 1] - positions[:, 1])
    return distance_fields(world.passable, cells, cell, world.graph), offsets
