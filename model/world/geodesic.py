"""Shortest free paths on the grid, for a global law and an assignment that know the walls (issue 11).

- Passable cells: those whose centre can hold the robot's disk (:func:`model.world.clearance.disk_is_free`),
  so the robot's radius is in every distance.
- The distance field of an objective: Dijkstra (scipy.sparse.csgraph) over the passable cells,
  8-connected, a step costing ``cell`` straight and √2·``cell`` diagonally; a diagonal step is allowed
  only when both cells beside it are passable (no cutting a wall's corner). Unreachable: +inf.
- The way to follow it (:func:`descent_waypoint`): from the robot's entry cell (its own, or, when that
  one is not passable, as for a robot held inside the planning margin, the best cell in sight beside
  it: :func:`entry_cell`), walk down the field to the lowest neighbour the graph connects (no corner
  cutting), up to ``lookahead`` cells, and aim at the farthest cell of that walk that a straight drive
  reaches with the disk free all the way (else the entry cell's centre; the walk's cells are tried from
  the farthest); the distance is the field at the entry cell plus the way to its centre. When a
  straight drive reaches the objective itself, aim at it, at its straight distance,
  exactly as the paper's eq. 10–11 do in an empty domain.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import dijkstra

from model.world.clearance import clearance_within, disk_is_free, swept_disk_is_free
from model.world.visibility import segment_crosses_occupied

NEIGHBOURS = ((0, 1), (1, 0), (0, -1), (-1, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))


def passable_cells(
    wall_grid: np.ndarray,
    radius: float,
    cell: float,
    bounded: bool,
    grain: float | None = None,
    shape: tuple[int, int] | None = None,
) -> np.ndarray:
    """Coverage cells (``shape``, side ``cell``) whose centre can hold the robot's disk among the wall squares
    (side ``grain``); by default the wall squares are the cells themselves."""
    rows, cols = wall_grid.shape if shape is None else shape
    return _passable_centres(wall_grid, radius, cell, bounded, cell if grain is None else grain, rows, cols)


@njit(cache=True)
def _passable_centres(
    wall_grid: np.ndarray, radius: float, cell: float, bounded: bool, grain: float, rows: int, cols: int
) -> np.ndarray:
    passable = np.zeros((rows, cols), dtype=np.bool_)
    for row in range(rows):
        for col in range(cols):
            x, y = (col + 0.5) * cell, (row + 0.5) * cell
            passable[row, col] = disk_is_free(wall_grid, x, y, radius, grain, bounded)
    return passable


def grid_graph(passable: np.ndarray, cell: float) -> coo_matrix:
    """The 8-connected graph of passable cells (node = row·cols + col), no corner cutting."""
    rows, cols = passable.shape
    sources, targets, costs = [], [], []
    for d_row, d_col in NEIGHBOURS:
        row0, row1 = max(0, -d_row), rows - max(0, d_row)
        col0, col1 = max(0, -d_col), cols - max(0, d_col)
        here = passable[row0:row1, col0:col1]
        there = passable[row0 + d_row : row1 + d_row, col0 + d_col : col1 + d_col]
        ok = here & there
        if d_row and d_col:  # diagonal: both cells beside the step must be passable too
            ok &= passable[row0 + d_row : row1 + d_row, col0:col1] & passable[row0:row1, col0 + d_col : col1 + d_col]
        r, c = np.nonzero(ok)
        sources.append((r + row0) * cols + (c + col0))
        targets.append((r + row0 + d_row) * cols + (c + col0 + d_col))
        costs.append(np.full(len(r), cell * (math.sqrt(2.0) if d_row and d_col else 1.0)))
    size = rows * cols
    return coo_matrix((np.concatenate(costs), (np.concatenate(sources), np.concatenate(targets))), shape=(size, size))


def passage_graph(
    passable: np.ndarray, cell: float, wall_grid: np.ndarray, grain: float, radius: float, bounded: bool
) -> coo_matrix:
    """:func:`grid_graph`, less the steps the disk of ``radius`` cannot drive straight among wall squares finer
    than the cell: two passable centres may hold the disk with a thin wall between them. With squares of a
    whole cell the graph's own rule settles it (a wall between two neighbours is a cell that is not passable)."""
    graph = grid_graph(passable, cell)
    if wall_grid.shape == passable.shape:
        return graph
    cols = passable.shape[1]
    keep = _drivable(graph.row, graph.col, cols, cell, wall_grid, grain, radius, bounded)
    return coo_matrix((graph.data[keep], (graph.row[keep], graph.col[keep])), shape=graph.shape)


@njit(cache=True)
def _drivable(
    sources: np.ndarray,
    targets: np.ndarray,
    cols: int,
    cell: float,
    wall_grid: np.ndarray,
    grain: float,
    radius: float,
    bounded: bool,
) -> np.ndarray:
    keep = np.zeros(sources.shape[0], dtype=np.bool_)
    for k in range(sources.shape[0]):
        keep[k] = drivable_step(wall_grid, grain, cell, cols, sources[k], targets[k], radius, bounded)
    return keep


@njit(cache=True)
def drivable_step(
    wall_grid: np.ndarray, grain: float, cell: float, cols: int, node: int, other: int, radius: float, bounded: bool
) -> bool:
    """Whether the disk drives straight between the centres of two cells (nodes row·cols + col) among the wall
    squares: a step of :func:`passage_graph`. Swept from the lower node, so each way gives the same answer."""
    low, high = min(node, other), max(node, other)
    x0, y0 = (low % cols + 0.5) * cell, (low // cols + 0.5) * cell
    x1, y1 = (high % cols + 0.5) * cell, (high // cols + 0.5) * cell
    return swept_disk_is_free(wall_grid, x0, y0, x1, y1, radius, grain, bounded)


def distance_fields(
    passable: np.ndarray, goals: list[tuple[int, int]], cell: float, graph: csr_matrix | None = None
) -> np.ndarray:
    """Geodesic distance from every cell to each goal cell, shape (len(goals), rows, cols); +inf where
    a cell cannot reach the goal (or is not passable). ``graph``: :func:`grid_graph` in CSR form, if
    the caller keeps it (it depends on the passable cells only)."""
    rows, cols = passable.shape
    if not goals:
        return np.zeros((0, rows, cols))
    graph = grid_graph(passable, cell).tocsr() if graph is None else graph
    indices = [row * cols + col for row, col in goals]
    # The graph is symmetric: distances from the goal are distances to it.
    fields = dijkstra(graph, directed=True, indices=indices)
    return np.asarray(fields).reshape(len(goals), rows, cols)


OWN_CLEARANCE_SLACK = 1e-9
"""How much of its own clearance, in wall squares, a robot inside the planning margin leaves out of the drive's disk
test (:func:`in_sight`): far above rounding, far below anything a robot could hit."""


@njit(cache=True)
def in_sight(
    wall_grid: np.ndarray,
    x: float,
    y: float,
    target_x: float,
    target_y: float,
    grain: float,
    radius: float,
    bounded: bool,
) -> bool:
    """A straight drive from (x, y) to the target crosses no occupied cell and keeps the disk of ``radius``
    free, or, where the robot already stands closer to a wall than that, a disk of its clearance there:
    a robot inside the planning margin may still drive on (else every drive would be refused there,
    and its waypoint would jump between cells from one step to the next). That clearance is taken a hair
    short (OWN_CLEARANCE_SLACK): measured from the very point the drive starts at, rounding made the start
    itself fail the test, and a robot the filter held exactly r + s off a door's jamb found no drive at all
    and headed straight into the jamb for the rest of the run (issue 34, the lab map, N = 2 seed 4)."""
    if segment_crosses_occupied(wall_grid, x, y, target_x, target_y, grain):
        return False
    clearance = clearance_within(wall_grid, x, y, radius, grain, bounded)
    if clearance < radius:
        clearance -= OWN_CLEARANCE_SLACK * grain
    return clearance <= 0.0 or swept_disk_is_free(wall_grid, x, y, target_x, target_y, clearance, grain, bounded)


@njit(cache=True)
def descent_waypoint(
    field: np.ndarray,
    passable: np.ndarray,
    wall_grid: np.ndarray,
    grain: float,
    x: float,
    y: float,
    objective_x: float,
    objective_y: float,
    cell: float,
    lookahead: int,
    radius: float,
    bounded: bool,
    body_radius: float,
) -> tuple[float, float, float]:
    """(distance, waypoint x, waypoint y) for the global law at (x, y) (see the module's docstring); ``radius``:
    what paths keep free (the planning radius), ``body_radius``: what the robot's body needs (r, + s with the
    filter)."""
    if in_sight(wall_grid, x, y, objective_x, objective_y, grain, radius, bounded):
        return math.hypot(objective_x - x, objective_y - y), objective_x, objective_y
    row, col = entry_cell(field, wall_grid, grain, x, y, cell, radius, bounded)
    if row < 0:
        return math.hypot(objective_x - x, objective_y - y), objective_x, objective_y  # cut off: head straight
    waypoint_x, waypoint_y = (col + 0.5) * cell, (row + 0.5) * cell
    distance = field[row, col] + math.hypot(waypoint_x - x, waypoint_y - y)  # as length_by_field measures it
    walk, steps = _walk_down(field, passable, wall_grid, grain, row, col, cell, lookahead, radius, bounded)
    for k in range(steps - 1, -1, -1):  # the farthest first: usually in sight along a corridor
        centre_x, centre_y = (walk[k, 1] + 0.5) * cell, (walk[k, 0] + 0.5) * cell
        if in_sight(wall_grid, x, y, centre_x, centre_y, grain, radius, bounded):
            return distance, centre_x, centre_y
    if steps > 0:
        # None in sight: the entry cell's centre, unless the robot is already past it on the way to the walk's
        # first cell and its body (``body_radius``, without the planning margin) drives there straight; then
        # that cell. A robot a hair too near a wall ahead of its cell's centre was sent back to it, saw far along
        # the walk from there, drove on, and so round for good (the campus map, N = 1 seed 15: 12,000 time units
        # on one spot). Without the body's test a robot of r = 0.4 on the warehouse map, no filter, headed into a
        # wall's corner for good (3 of 100 seeds).
        first_x, first_y = (walk[0, 1] + 0.5) * cell, (walk[0, 0] + 0.5) * cell
        if math.hypot(first_x - x, first_y - y) < math.hypot(first_x - waypoint_x, first_y - waypoint_y) and in_sight(
            wall_grid, x, y, first_x, first_y, grain, body_radius, bounded
        ):
            return distance, first_x, first_y
    return distance, waypoint_x, waypoint_y


@njit(cache=True)
def _walk_down(
    field: np.ndarray,
    passable: np.ndarray,
    wall_grid: np.ndarray,
    grain: float,
    row: int,
    col: int,
    cell: float,
    lookahead: int,
    radius: float,
    bounded: bool,
) -> tuple[np.ndarray, int]:
    """(cells (lookahead, 2), how many): :func:`descent_waypoint`'s walk down the field from (row, col), steps the
    graph has."""
    rows, cols = field.shape
    walk = np.empty((lookahead, 2), dtype=np.int64)
    steps = 0
    fine = wall_grid.shape[0] != rows  # wall squares finer than the cells: the graph may lack a step
    for _ in range(lookahead):
        best_row, best_col, best = row, col, field[row, col]
        for k in range(8):
            d_row = (0, 1, 0, -1, 1, 1, -1, -1)[k]
            d_col = (1, 0, -1, 0, 1, -1, 1, -1)[k]
            r, c = row + d_row, col + d_col
            if not (0 <= r < rows and 0 <= c < cols) or field[r, c] >= best:
                continue
            if d_row != 0 and d_col != 0 and not (passable[r, col] and passable[row, c]):
                continue  # the graph's rule: no cutting a corner
            if fine and not drivable_step(
                wall_grid, grain, cell, cols, row * cols + col, r * cols + c, radius, bounded
            ):
                continue  # nor a step passage_graph left out (a thin wall between two passable centres)
            best_row, best_col, best = r, c, field[r, c]
        if best_row == row and best_col == col:
            break  # the goal cell
        row, col = best_row, best_col
        walk[steps, 0], walk[steps, 1] = row, col
        steps += 1
    return walk, steps


@njit(cache=True)
def path_length(
    field: np.ndarray,
    wall_grid: np.ndarray,
    grain: float,
    x: float,
    y: float,
    goal_x: float,
    goal_y: float,
    cell: float,
    radius: float,
    bounded: bool,
    straight: float,
) -> float:
    """Length of the shortest free path from (x, y) to the goal: ``straight`` (its straight distance)
    when a straight drive gets there, else the goal's field at the robot's cell plus the way to that
    cell's centre (:func:`length_by_field`, as :func:`descent_waypoint` measures it); +inf when the goal cannot be reached."""
    if in_sight(wall_grid, x, y, goal_x, goal_y, grain, radius, bounded):
        return straight
    return length_by_field(field, wall_grid, grain, x, y, cell, radius, bounded)


@njit(cache=True)
def length_by_field(
    field: np.ndarray,
    wall_grid: np.ndarray,
    grain: float,
    x: float,
    y: float,
    cell: float,
    radius: float,
    bounded: bool,
) -> float:
    """The field at the entry cell of (x, y) (:func:`entry_cell`) plus the way from (x, y) to its centre;
    +inf if there is none."""
    row, col = entry_cell(field, wall_grid, grain, x, y, cell, radius, bounded)
    if row < 0:
        return math.inf
    return field[row, col] + math.hypot((col + 0.5) * cell - x, (row + 0.5) * cell - y)


ENTRY_RINGS = 2
"""How many rings of cells around a robot's own are searched for a way onto the graph (see entry_cell)."""


@njit(cache=True)
def entry_cell(
    field: np.ndarray,
    wall_grid: np.ndarray,
    grain: float,
    x: float,
    y: float,
    cell: float,
    radius: float,
    bounded: bool,
) -> tuple[int, int]:
    """Where the robot at (x, y) joins the graph of passable cells: its own cell when the field is finite
    there; else, within ENTRY_RINGS rings, the cell in sight (:func:`in_sight`, which allows a robot
    inside the planning margin to drive on) with the least field plus way to its centre; (−1, −1) if
    none. A robot the safety filter holds s off a wall stands inside the planning margin r + s (+5 % of
    a cell), so its own cell may not be passable: the field there is +inf, and heading straight at the
    objective from there drove it into the wall for ever (issue 12's stalls on the maps)."""
    rows, cols = field.shape
    row = min(max(math.floor(y / cell), 0), rows - 1)
    col = min(max(math.floor(x / cell), 0), cols - 1)
    if math.isfinite(field[row, col]):
        return row, col
    best, best_row, best_col = math.inf, -1, -1
    for r in range(max(row - ENTRY_RINGS, 0), min(row + ENTRY_RINGS + 1, rows)):
        for c in range(max(col - ENTRY_RINGS, 0), min(col + ENTRY_RINGS + 1, cols)):
            if not math.isfinite(field[r, c]):
                continue
            centre_x, centre_y = (c + 0.5) * cell, (r + 0.5) * cell
            total = field[r, c] + math.hypot(centre_x - x, centre_y - y)
            if total < best and in_sight(wall_grid, x, y, centre_x, centre_y, grain, radius, bounded):
                best, best_row, best_col = total, r, c
    return best_row, best_col
