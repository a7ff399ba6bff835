"""What a team can cover at all: cells that no reachable pose can see (issue 11, "what complete means").

A pose is reachable when its cell is passable (:func:`model.world.geodesic.passable_cells`) and connected to
a robot's start through passable cells (the 8-connected graph of :mod:`model.world.geodesic`, no corner
cutting, or its :func:`model.world.geodesic.passage_graph`). A free cell is coverable when its centre lies
closer than the viewing range (R less a cell: :func:`model.world.world.viewing_range_of`, passed in as
``sensing_range``) to the centre of a reachable cell with a clear line of sight past the wall squares
(:func:`model.world.visibility.segment_crosses_occupied`; squares of ``grain``, the cell unless given): the robot can turn
its camera any way, and eq. 2 gives α = 0 at r = R. Occupied cells and the rest of the free cells
(an enclosed room, a pocket narrower than the robot) are left out of e_D and of completion.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from model.scenario.terrain import coarsen
from model.world.geodesic import grid_graph
from model.world.visibility import segment_crosses_occupied


def reachable_cells(
    passable: np.ndarray, starts: list[tuple[int, int]], cell: float, graph: coo_matrix | None = None
) -> np.ndarray:
    """Passable cells connected to any of the start cells (by ``graph``, else :func:`grid_graph`)."""
    rows, cols = passable.shape
    _, labels = connected_components(grid_graph(passable, cell) if graph is None else graph, directed=False)
    labels = labels.reshape(rows, cols)
    start_labels = {labels[row, col] for row, col in starts if passable[row, col]}
    return np.isin(labels, list(start_labels)) & passable


@njit(cache=True)
def _seen_from(
    candidates: np.ndarray, wall_grid: np.ndarray, grain: float, reachable: np.ndarray, sensing_range: float,
    cell: float, spread: float = 0.0,
) -> np.ndarray:  # fmt: skip
    """The ``candidates`` that some reachable cell's centre sees: closer than R less ``spread``, in clear sight from
    the centre and from the eight points ``spread`` off it (:func:`_clear_over`). A reachable cell sees itself; any
    other looks for one reachable centre, stopping at the first (most cells are near one)."""
    rows, cols = candidates.shape
    seen = reachable.copy()
    span = math.ceil(sensing_range / cell)
    for row in range(rows):
        for col in range(cols):
            if seen[row, col] or not candidates[row, col]:
                continue
            tx, ty = (col + 0.5) * cell, (row + 0.5) * cell
            found = False
            for r in range(max(row - span, 0), min(row + span + 1, rows)):
                for c in range(max(col - span, 0), min(col + span + 1, cols)):
                    if not reachable[r, c]:
                        continue
                    x, y = (c + 0.5) * cell, (r + 0.5) * cell
                    if math.hypot(tx - x, ty - y) + spread >= sensing_range:
                        continue
                    if _clear_over(wall_grid, x, y, tx, ty, grain, spread):
                        found = True
                        break
                if found:
                    break
            seen[row, col] = found
    return seen


@njit(cache=True)
def _clear_over(wall_grid: np.ndarray, x: float, y: float, tx: float, ty: float, grain: float, spread: float) -> bool:
    """Clear sight to (tx, ty) from (x, y) and, ``spread`` > 0, from the eight points ``spread`` off it (every 45°)."""
    if segment_crosses_occupied(wall_grid, x, y, tx, ty, grain):
        return False
    if spread > 0.0:
        for way in range(8):
            u, v = math.cos(way * math.pi / 4), math.sin(way * math.pi / 4)
            if segment_crosses_occupied(wall_grid, x + spread * u, y + spread * v, tx, ty, grain):
                return False
    return True


def unsure_cells(
    wall_grid: np.ndarray, grain: float, reachable: np.ndarray, coverable: np.ndarray, sensing_range: float, cell: float,
    spread: float,
) -> np.ndarray:  # fmt: skip
    """Coverable cells that no reachable cell sees surely over ``spread`` (:func:`_seen_from`): seen only through a
    gap between walls, from a point a robot must stand on to better than ``spread``. None where ``spread`` is 0."""
    if spread <= 0.0:
        return np.zeros_like(coverable)
    return coverable & ~_seen_from(coverable, wall_grid, grain, reachable, sensing_range, cell, spread)


def coverable_cells(
    wall_grid: np.ndarray,
    passable: np.ndarray,
    starts: list[tuple[int, int]],
    sensing_range: float,
    cell: float,
    grain: float | None = None,
    graph: coo_matrix | None = None,
) -> np.ndarray:
    """Free cells some reachable pose can see (see the module's docstring)."""
    grain = cell if grain is None else grain
    occupied = coarsen(wall_grid, round(cell / grain))
    reachable = reachable_cells(passable, starts, cell, graph)
    return _seen_from(~occupied, wall_grid, grain, reachable, sensing_range, cell)


def in_reachable_cell(reachable: np.ndarray, x: float, y: float, cell: float) -> bool:
    """Whether (x, y) lies in a reachable cell, its cell as the free paths find it: floor(x / cell), which differs
    from x // cell on a cell's edge (10.0 // 0.2 is 49, floor(10.0 / 0.2) is 50); off the grid it does not."""
    row, col = math.floor(y / cell), math.floor(x / cell)
    rows, cols = reachable.shape
    return 0 <= row < rows and 0 <= col < cols and bool(reachable[row, col])


def nearest_reachable(reachable: np.ndarray, points: np.ndarray, cell: float) -> np.ndarray:
    """Each point (K, 2) moved to the centre of the nearest reachable cell, unless its own cell is
    reachable (then it stays as it is). A point off the grid has no cell of its own: it is moved (a robot of
    an unbounded map may stand past its edge; clamped into the grid's edge cell, it stayed where no free path
    starts). Its cell is floor(x / cell), as the free paths find it (:func:`in_reachable_cell`)."""
    cells = np.argwhere(reachable)
    if len(cells) == 0:
        raise ValueError("no reachable cell: nowhere to send the robots")
    centres = (cells[:, ::-1] + 0.5) * cell  # (x, y) of each reachable cell
    moved = np.array(points, dtype=np.float64, copy=True).reshape(-1, 2)
    for k, (x, y) in enumerate(moved):
        if not in_reachable_cell(reachable, x, y, cell):
            moved[k] = centres[int(np.argmin(np.hypot(centres[:, 0] - x, centres[:, 1] - y)))]
    return moved


@njit(cache=True)
def seers(
    wall_grid: np.ndarray,
    grain: float,
    reachable: np.ndarray,
    x: float,
    y: float,
    sensing_range: float,
    cell: float,
) -> np.ndarray:
    """The reachable cells that see the point (x, y): closer than R, clear sight from the centre, as
    coverable cells are defined. (M, 3) rows (gap, centre x, centre y), nearest first, row order on a tie."""
    rows, cols = reachable.shape
    span = math.ceil(sensing_range / cell)
    row, col = math.floor(y / cell), math.floor(x / cell)
    found = np.empty(((2 * span + 1) ** 2, 3))
    count = 0
    for r in range(max(row - span, 0), min(row + span + 1, rows)):
        for c in range(max(col - span, 0), min(col + span + 1, cols)):
            if not reachable[r, c]:
                continue
            cx, cy = (c + 0.5) * cell, (r + 0.5) * cell
            gap = math.hypot(cx - x, cy - y)
            if gap < sensing_range and not segment_crosses_occupied(wall_grid, cx, cy, x, y, grain):
                found[count, 0], found[count, 1], found[count, 2] = gap, cx, cy
                count += 1
    order = np.argsort(found[:count, 0], kind="mergesort")  # stable: row order on a tie
    return found[:count][order]


def viewpoints(
    wall_grid: np.ndarray,
    grain: float,
    reachable: np.ndarray,
    points: np.ndarray,
    sensing_range: float,
    cell: float,
) -> np.ndarray:
    """Where a robot goes to cover each point (K, 2) (an objective of Algorithm 1, on an uncovered cell): the
    point itself when its cell is reachable, else the centre of the nearest reachable cell that sees its cell's
    centre (closer than R, no wall across: how coverable cells are defined, so a coverable cell has one). The
    nearest reachable cell alone (:func:`nearest_reachable`) may lie behind the wall the point is on: a
    robot sent there looked at a wall for the rest of the run (issue 34's stalls). A point that no
    reachable cell sees goes to the nearest reachable cell."""
    rows, cols = reachable.shape
    moved = np.array(points, dtype=np.float64, copy=True).reshape(-1, 2)
    for k, (x, y) in enumerate(moved):
        row, col = min(max(int(y // cell), 0), rows - 1), min(max(int(x // cell), 0), cols - 1)
        if reachable[row, col]:
            continue
        # From the cell's centre: coverable cells are those a reachable centre sees centre to centre, and
        # a viewpoint of a point off the centre (Algorithm 1's centroid) may see that point but not the cell.
        centre_x, centre_y = (col + 0.5) * cell, (row + 0.5) * cell
        seen_from = seers(wall_grid, grain, reachable, centre_x, centre_y, sensing_range, cell)
        if len(seen_from):
            moved[k] = seen_from[0, 1:]
        else:
            moved[k] = nearest_reachable(reachable, moved[k : k + 1], cell)[0]
    return moved
