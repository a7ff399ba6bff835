"""anicov's way between its stations among walls (issue 36, item 1): the order the stations are visited in,
by the length of the free path between them, and each hop's path.

- **The order** (:func:`station_tour`): on the open square the serpentine's rows are the order, and a straight
  hop is the way. Among walls the straight distance lies: two stations on either side of a wall are near and
  far apart. The tour starts at a given station (:mod:`model.controllers.anicov.terrain_plan` tries the one
  nearest each robot) and always goes on to the nearest station not visited yet by the free path's length
  (the geodesic field of each station, :meth:`World.field`), then 2-opt reverses any stretch that shortens it,
  until none does. A room's stations lie nearer each other than any station beyond its door, so the tour
  covers the building room by room, not back and forth.
- **A hop's path** (:func:`hop_path`): the shortest path on the passage graph (the disk with its clearance
  and margin drives straight between joined cell centres: :mod:`model.world.world`), followed cell by cell
  down the goal's field, then pulled tight: from each point it goes straight to the farthest later point a
  straight drive reaches (:func:`model.world.geodesic.in_sight` with the planning radius).
"""

from __future__ import annotations

import math

import numpy as np

from model.world.geodesic import in_sight
from model.world.world import World


def travel_lengths(world: World, stations: np.ndarray) -> np.ndarray:
    """(K, K): the free path's length between every two stations (each at a reachable cell's centre); +inf
    where none joins them."""
    cell = world.scenario.cell
    rows = np.floor(stations[:, 1] / cell).astype(np.int64)
    cols = np.floor(stations[:, 0] / cell).astype(np.int64)
    lengths = np.empty((len(stations), len(stations)))
    for k, (x, y) in enumerate(stations):
        lengths[k] = world.field(float(x), float(y))[rows, cols]
    return np.minimum(lengths, lengths.T)  # the graph is symmetric; both halves agree but for rounding


def station_tour(lengths: np.ndarray, first: int = 0) -> np.ndarray:
    """The order (K,) of a tour over the stations from station ``first``: nearest unvisited first, then 2-opt on
    the open path (its first station kept) until no reversal shortens it."""
    count = len(lengths)
    if count < 3:
        return np.array([first, *(k for k in range(count) if k != first)], dtype=np.int64)[:count]
    tour, left = [first], np.ones(count, dtype=bool)
    left[first] = False
    for _ in range(count - 1):
        ahead = np.where(left, lengths[tour[-1]], np.inf)
        nearest = int(np.argmin(ahead))  # lowest index on a tie
        tour.append(nearest)
        left[nearest] = False
    return _two_opt(np.array(tour), lengths)


def _two_opt(tour: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Reverse tour[i + 1 .. j] wherever that shortens the open path (for each i, first i first, the j that
    shortens it most), until no reversal does. Reversing drops the edges a-b and c-d (a = tour[i], b its next,
    c = tour[j], d its next if any) for a-c and b-d."""
    improved = True
    while improved:
        improved = False
        for i in range(len(tour) - 2):
            a, b = tour[i], tour[i + 1]
            c = tour[i + 2 :]
            d = np.append(tour[i + 3 :], -1)  # the stop after each c; -1: c is the last
            has_d, d = d >= 0, np.maximum(d, 0)
            gains = lengths[a, b] - lengths[a, c] + np.where(has_d, lengths[c, d] - lengths[b, d], 0.0)
            best = int(np.argmax(gains))
            if gains[best] > 1e-9:
                j = i + 2 + best
                tour[i + 1 : j + 1] = tour[i + 1 : j + 1][::-1].copy()
                improved = True
    return tour


def hop_path(world: World, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """The points (M, 2) of the free path from ``start`` to ``goal`` (both reachable cells' centres): down the
    goal's field on the passage graph, pulled tight by straight drives the disk can make."""
    cell, ground = world.scenario.cell, world.ground
    field = world.field(float(goal[0]), float(goal[1]))
    cols = world.passable.shape[1]
    graph = world.graph
    at = math.floor(start[1] / cell) * cols + math.floor(start[0] / cell)
    end = math.floor(goal[1] / cell) * cols + math.floor(goal[0] / cell)
    if not math.isfinite(field.flat[at]):
        raise ValueError(f"no free path joins {tuple(start)} and {tuple(goal)}")
    cells = [at]
    while at != end and graph is not None:
        neighbours = graph.indices[graph.indptr[at] : graph.indptr[at + 1]]
        steps = graph.data[graph.indptr[at] : graph.indptr[at + 1]]
        at = int(neighbours[int(np.argmin(field.flat[neighbours] + steps))])
        cells.append(at)
    points = np.array([((c % cols + 0.5) * cell, (c // cols + 0.5) * cell) for c in cells])
    points[0], points[-1] = start, goal
    tight, k = [points[0]], 0
    while k < len(points) - 1:
        far = k + 1
        for m in range(len(points) - 1, k + 1, -1):
            if in_sight(ground.wall_grid, points[k][0], points[k][1], points[m][0], points[m][1], ground.grain,
                        ground.plan_radius, ground.bounded):  # fmt: skip
                far = m
                break
        tight.append(points[far])
        k = far
    return np.array(tight)
