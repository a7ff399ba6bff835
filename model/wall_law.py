"""The global law (eq. 10–11) among walls: how it was read for a terrain (docs/paper-notes.md).

- A straight drive reaches the objective (:func:`model.geodesic.in_sight`): eq. 10–11 as printed,
  except that u_glo < 0 (inside R/2) does not back the robot away: eq. 10's reverse is blind, and
  among walls it backs the robot into them, or out of sight of the objective and in again, for ever.
  The robot stops instead and turns to look at what is left to cover there: the objective's cell if
  it is uncovered and in clear sight, else the nearest uncovered cell within R in clear sight (the
  camera's rule: no wall across and, with occlusion, no teammate's disk). With nothing left in sight
  it goes nearer to the objective at eq. 10's speed taken positive: a robot that stood still looking at
  a cell a teammate or a wall's rim hid waited for ever (the field map, N = 4: 17 of 100 runs). (An objective moved into
  the team's space, or on a cell's edge where the robot may stand, may lie beside the blob it stands
  for; Algorithm 1 drops it only once its cell is covered.)
- A wall is in the way and the robot is more than a cell away by path: the heading is toward the
  waypoint of the shortest free path
  (:func:`model.geodesic.descent_waypoint`) and u_glo comes from that path's length, without eq. 10's
  stop at R/2 (:func:`model.control.global_law_around_walls`). Within a cell by path of an objective
  it cannot drive straight to (one on a cell's corner by a wall), the robot has arrived: it stops and
  looks, as above.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.control import global_law_around_walls
from model.geodesic import descent_waypoint
from model.ground import Ground
from model.visibility import line_of_sight


@njit(cache=True)
def global_law_among_walls(
    coverage: np.ndarray,
    target_ticks: int,
    x: float,
    y: float,
    objective_x: float,
    objective_y: float,
    u_glo: float,
    theta_glo: float,
    sensing_range: float,
    cell: float,
    literal_heading: bool,
    ground: Ground,
    field: np.ndarray,
    teammates: np.ndarray,
) -> tuple[float, float]:
    """(u_glo, θ_glo*) on a terrain, from the open world's (``u_glo``, ``theta_glo``): see the module.
    ``teammates`` (K, 2): the other robots' positions whose disks may hide a cell (occlusion)."""
    distance, waypoint_x, waypoint_y = descent_waypoint(
        field,
        ground.passable,
        ground.occupied,
        x,
        y,
        objective_x,
        objective_y,
        cell,
        ground.lookahead,
        ground.plan_radius,
        ground.bounded,
    )
    detour = waypoint_x != objective_x or waypoint_y != objective_y
    if detour and distance > cell:
        return global_law_around_walls(x, y, waypoint_x, waypoint_y, distance, literal_heading)
    if not detour and u_glo >= 0.0:
        return u_glo, theta_glo
    look_x, look_y = uncovered_to_look_at(
        coverage, target_ticks, ground, teammates, x, y, objective_x, objective_y, sensing_range, cell
    )
    if look_x != look_x:
        # Nothing uncovered in sight from here (a wall's rim or a teammate's disk hides what is left): go
        # nearer, at eq. 10's speed for this distance taken positive, rather than wait for ever.
        return abs(u_glo), math.atan2(objective_y - y, objective_x - x)
    return 0.0, math.atan2(look_y - y, look_x - x)


@njit(cache=True)
def uncovered_to_look_at(
    coverage: np.ndarray,
    target_ticks: int,
    ground: Ground,
    teammates: np.ndarray,
    x: float,
    y: float,
    objective_x: float,
    objective_y: float,
    sensing_range: float,
    cell: float,
) -> tuple[float, float]:
    """The centre of the objective's cell if it is uncovered and in clear sight, else of the nearest
    uncovered cell within R of (x, y) in clear sight (no wall and, with occlusion, no teammate's disk
    across: the camera's own rule); (NaN, NaN) if there is none."""
    occupied = ground.occupied
    rows, cols = coverage.shape
    row = min(max(math.floor(objective_y / cell), 0), rows - 1)
    col = min(max(math.floor(objective_x / cell), 0), cols - 1)
    centre_x, centre_y = (col + 0.5) * cell, (row + 0.5) * cell
    if coverage[row, col] < target_ticks and _in_clear_sight(ground, teammates, x, y, centre_x, centre_y, cell):
        return centre_x, centre_y
    span = math.ceil(sensing_range / cell)
    centre_row, centre_col = math.floor(y / cell), math.floor(x / cell)
    best, best_x, best_y = sensing_range, math.nan, math.nan
    for r in range(max(centre_row - span, 0), min(centre_row + span + 1, rows)):
        for c in range(max(centre_col - span, 0), min(centre_col + span + 1, cols)):
            if coverage[r, c] >= target_ticks or occupied[r, c]:
                continue
            cx, cy = (c + 0.5) * cell, (r + 0.5) * cell
            gap = math.hypot(cx - x, cy - y)
            if gap < best and _in_clear_sight(ground, teammates, x, y, cx, cy, cell):
                best, best_x, best_y = gap, cx, cy
    return best_x, best_y


@njit(cache=True)
def _in_clear_sight(
    ground: Ground, teammates: np.ndarray, x: float, y: float, target_x: float, target_y: float, cell: float
) -> bool:
    """The camera's rule (model.visibility.line_of_sight), teammates' disks only with occlusion."""
    hiding = teammates if ground.occlusion else teammates[:0]
    return line_of_sight(ground.occupied, x, y, target_x, target_y, cell, hiding, ground.radius)
