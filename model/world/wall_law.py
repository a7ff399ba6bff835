"""The global law (eq. 10–11) among walls: how it was read for a terrain (docs/paper-notes.md).

- A straight drive reaches the objective (:func:`model.world.geodesic.in_sight`): eq. 10–11 as printed,
  except that u_glo < 0 (inside R/2) does not back the robot away: eq. 10's reverse is blind, and
  among walls it backs the robot into them, or out of sight of the objective and in again, for ever.
  The robot stops instead and turns to look at what is left to cover there: the objective's cell if
  it is uncovered and in clear sight, else the cell it looked at in the step before while that one is
  still uncovered, within R and in clear sight, else the nearest uncovered cell within R in clear sight
  (the camera's rule: no wall across and, with occlusion, no teammate's disk). With nothing left in sight
  it goes nearer to the objective at eq. 10's speed taken positive: a robot that stood still looking at
  a cell a teammate or a wall's rim hid waited for ever (the field map, N = 4: 17 of 100 runs). (An objective moved into
  the team's space, or on a cell's edge where the robot may stand, may lie beside the blob it stands
  for; Algorithm 1 drops it only once its cell is covered.)
- The objective's cell is covered (a viewpoint: a covered cell from which the blob is seen; or a blob done
  since the last plan): the robot drives to the point itself, not to R/2 short of it, and looks there; on
  the way, an uncovered cell in clear sight within R/2 stops it to look, as above, where it stands clear of
  walls by the planning radius.
- A wall is in the way and the robot is more than a cell away by path: the heading is toward the
  waypoint of the shortest free path
  (:func:`model.world.geodesic.descent_waypoint`) and u_glo comes from that path's length, without eq. 10's
  stop at R/2 (:func:`model.paper.control.global_law_around_walls`). Within a cell by path of an objective
  it cannot drive straight to (one on a cell's corner by a wall), the robot has arrived: it stops and
  looks, as above.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.paper.control import global_law_around_walls
from model.paper.geometry import square_gap2
from model.world.clearance import disk_is_free
from model.world.geodesic import descent_waypoint
from model.world.ground import Ground
from model.world.visibility import first_occupied_crossed, hidden_by_teammates, line_of_sight


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
    look: np.ndarray,
) -> tuple[float, float]:
    """(u_glo, θ_glo*) on a terrain, from the open world's (``u_glo``, ``theta_glo``): see the module.
    ``teammates`` (K, 2): the other robots' positions whose disks may hide a cell (occlusion). ``look`` (2,):
    the centre of the cell the robot looked at in the step before (NaN: none), read and written."""
    distance, waypoint_x, waypoint_y = _waypoint(field, ground, x, y, objective_x, objective_y, cell)
    detour = waypoint_x != objective_x or waypoint_y != objective_y
    if not detour and _covered_cell(coverage, target_ticks, ground, objective_x, objective_y, cell):
        # A viewpoint (model.world.reachability.viewpoints: a covered cell from which the blob is seen), or a
        # blob done since the last plan: eq. 10's stop at R/2 frames nothing there (the robot waited R/2 short
        # of it with what it was sent to see nearly out of range). Go to the point itself, and look there.
        # Arrived within half a cell; one that stopped to look (``look`` set) keeps looking within three quarters
        # of a cell (less than the gap to any other cell's centre, so a new viewpoint is always driven to): at
        # exactly half a cell a robot crept across the line and back, turning to the point and to the cell in
        # turn, for 200 time units and more, and covered nothing (issue 34, the lab map, N = 1 seed 24).
        # On the way there, a cell to stop for (_cell_on_the_way).
        gap = math.hypot(objective_x - x, objective_y - y)
        if gap > (0.75 * cell if look[0] == look[0] else 0.5 * cell):
            look_x, look_y = _cell_on_the_way(
                coverage, target_ticks, ground, teammates, x, y, objective_x, objective_y, sensing_range, cell, look
            )
            look[0], look[1] = look_x, look_y
            if look_x == look_x:
                return 0.0, math.atan2(look_y - y, look_x - x)
            return global_law_around_walls(x, y, objective_x, objective_y, gap, literal_heading)
    elif (detour and distance > cell) or (not detour and u_glo >= 0.0):
        look[0], look[1] = math.nan, math.nan  # driving: the next stop looks anew
        if detour:
            return global_law_around_walls(x, y, waypoint_x, waypoint_y, distance, literal_heading)
        return u_glo, theta_glo
    look_x, look_y = cell_to_look_at(
        coverage, target_ticks, ground, teammates, x, y, objective_x, objective_y, sensing_range, cell, look
    )
    look[0], look[1] = look_x, look_y
    if look_x != look_x:
        # Nothing uncovered in sight from here (a wall's rim or a teammate's disk hides what is left): go
        # nearer, at eq. 10's speed for this distance taken positive, rather than wait for ever.
        return abs(u_glo), math.atan2(objective_y - y, objective_x - x)
    return 0.0, math.atan2(look_y - y, look_x - x)


@njit(cache=True)
def _cell_on_the_way(
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
    look: np.ndarray,
) -> tuple[float, float]:
    """The cell a robot on its way to a covered objective stops to look at (NaN: none, drive on): an
    uncovered cell in clear sight within R/2 (eq. 10's stop, where eq. 2's α is half its most), where the
    robot stands clear of walls by the planning radius. Driving on to the point past what it was sent to
    see cost the drawn office map, N = 10 with occlusion, 314.6 -> 343.5 of mean t_N, over issue 11's goal;
    with this stop 311.8. Within R less a cell instead (318.1 there), robots stared from afar where α is a
    tenth of its most: the campus map's single robots took 20 % longer and 4 of 30 left cells to the
    watchdog. Without the room test a stop among the campus's speckle left a single robot where the filter
    let it neither turn nor drive (e_D 0.60 at the end)."""
    roomy = disk_is_free(ground.wall_grid, x, y, ground.plan_radius, ground.grain, ground.bounded)
    if not roomy:
        return math.nan, math.nan
    return cell_to_look_at(
        coverage, target_ticks, ground, teammates, x, y, objective_x, objective_y, 0.5 * sensing_range, cell, look
    )


@njit(cache=True)
def _waypoint(
    field: np.ndarray, ground: Ground, x: float, y: float, objective_x: float, objective_y: float, cell: float
) -> tuple[float, float, float]:
    """:func:`model.world.geodesic.descent_waypoint` on this ground."""
    passable, walls, grain = ground.passable, ground.wall_grid, ground.grain
    lookahead, radius, bounded = ground.lookahead, ground.plan_radius, ground.bounded
    return descent_waypoint(
        field, passable, walls, grain, x, y, objective_x, objective_y, cell, lookahead, radius, bounded,
        ground.wall_clearance,
    )  # fmt: skip


@njit(cache=True)
def _covered_cell(
    coverage: np.ndarray, target_ticks: int, ground: Ground, point_x: float, point_y: float, cell: float
) -> bool:
    """Whether the point's cell has nothing left to cover (covered, or a wall)."""
    rows, cols = coverage.shape
    row = min(max(math.floor(point_y / cell), 0), rows - 1)
    col = min(max(math.floor(point_x / cell), 0), cols - 1)
    return coverage[row, col] >= target_ticks or ground.occupied[row, col]


@njit(cache=True)
def cell_to_look_at(
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
    look: np.ndarray,
) -> tuple[float, float]:
    """What a robot standing at (x, y) looks at: the objective's cell if it is uncovered and in clear sight;
    else the cell it looked at in the step before (``look``) while that one is still uncovered, within R and
    in clear sight; else the nearest such cell (:func:`_nearest_uncovered_in_sight`; NaN if none: with ``look``
    NaN, this is the objective's cell or the nearest, the rule before a cell was kept). A cell is so kept until it is
    covered, leaves R or clear sight, or the objective's cell comes first, or the robot drives again (the law
    then forgets it): a search of R every step found the same cell nearly always (99 % of a standing robot's
    steps on the warehouse map) and could turn the robot between two cells as it crept."""
    centre_x, centre_y = _objective_cell_in_sight(
        coverage, target_ticks, ground, teammates, x, y, objective_x, objective_y, cell
    )
    if centre_x == centre_x:
        return centre_x, centre_y
    look_x, look_y = look[0], look[1]
    if look_x == look_x:
        row, col = math.floor(look_y / cell), math.floor(look_x / cell)
        gap2 = (look_x - x) * (look_x - x) + (look_y - y) * (look_y - y)
        if (
            coverage[row, col] < target_ticks
            and not ground.occupied[row, col]
            and gap2 < sensing_range * sensing_range
            and _in_clear_sight(ground, teammates, x, y, look_x, look_y, cell)
        ):
            return look_x, look_y
    hiding = teammates if ground.occlusion else teammates[:0]
    return _nearest_uncovered_in_sight(coverage, target_ticks, ground, hiding, x, y, sensing_range, cell)


@njit(cache=True)
def _objective_cell_in_sight(
    coverage: np.ndarray,
    target_ticks: int,
    ground: Ground,
    teammates: np.ndarray,
    x: float,
    y: float,
    objective_x: float,
    objective_y: float,
    cell: float,
) -> tuple[float, float]:
    """The centre of the objective's cell if it is uncovered and in clear sight, else (NaN, NaN)."""
    rows, cols = coverage.shape
    row = min(max(math.floor(objective_y / cell), 0), rows - 1)
    col = min(max(math.floor(objective_x / cell), 0), cols - 1)
    centre_x, centre_y = (col + 0.5) * cell, (row + 0.5) * cell
    if coverage[row, col] < target_ticks and _in_clear_sight(ground, teammates, x, y, centre_x, centre_y, cell):
        return centre_x, centre_y
    return math.nan, math.nan


@njit(cache=True)
def _nearest_uncovered_in_sight(
    coverage: np.ndarray,
    target_ticks: int,
    ground: Ground,
    hiding: np.ndarray,
    x: float,
    y: float,
    sensing_range: float,
    cell: float,
) -> tuple[float, float]:
    """:func:`cell_to_look_at`'s search beyond the objective's cell: the centre of the nearest uncovered
    free cell within R of (x, y) that no wall and no disk of ``hiding`` hides; (NaN, NaN) if none."""
    rows, cols = coverage.shape
    centre_row, centre_col = math.floor(y / cell), math.floor(x / cell)
    # Ring by ring outward (Chebyshev rings round the robot's cell), a ring's four sides each as one run of
    # cells, until no cell of the next ring can be nearer than the best found; a side whose cells are all
    # farther along one axis than the best is skipped. The nearest wins, and of equal gaps the first in
    # row-major order: the comparison takes both, so the order of the scan does not matter.
    # Each wall square a line was found to cross hides, for sure, every cell beyond its farthest corner
    # on the bearings strictly inside its span (their segments cross its inside): kept per bearing bin, so
    # a robot among walls tests a few lines, not every cell within R.
    # Gaps are compared squared, as rounded (no square root per cell): of two cells at the same true
    # distance, the smaller rounded square is the nearer, and of equal ones the first in row-major order.
    occupied, wall_grid, grain, radius = ground.occupied, ground.wall_grid, ground.grain, ground.radius
    beyond = np.full(LOOK_BINS, np.inf)
    reach2 = sensing_range * sensing_range
    best2, best_index, best_x, best_y = reach2, rows * cols, math.nan, math.nan
    for ring in range(math.ceil(sensing_range / cell) + 1):
        if ring > 0 and ((ring - 0.5) * cell) ** 2 > best2:
            break
        for side in range(4 if ring > 0 else 1):
            r, c, d_row, d_col, count, axis_gap = _ring_side(ring, side, centre_row, centre_col, rows, cols, x, y, cell)
            if axis_gap * axis_gap > best2:
                continue  # (a cell's rounded squared gap is at least its rounded squared axis gap)
            for _ in range(count):
                if coverage[r, c] < target_ticks and not occupied[r, c]:
                    cx, cy = (c + 0.5) * cell, (r + 0.5) * cell
                    dx, dy = cx - x, cy - y
                    gap2 = dx * dx + dy * dy
                    index = r * cols + c
                    if gap2 < reach2 and (gap2 < best2 or (gap2 == best2 and index < best_index)):
                        # (A robot on the cell's centre sees it: no bearing, nothing between.)
                        if gap2 == 0.0 or gap2 <= beyond[_look_bin(dx, dy)]:
                            wall_row, wall_col = first_occupied_crossed(wall_grid, x, y, cx, cy, grain)
                            if wall_row >= 0:
                                _shadow_behind(beyond, wall_col * grain - x, wall_row * grain - y, grain)
                            elif not hidden_by_teammates(hiding, radius, x, y, cx, cy):
                                best2, best_index, best_x, best_y = gap2, index, cx, cy
                r, c = r + d_row, c + d_col
    return best_x, best_y


@njit(cache=True)
def _ring_side(
    ring: int, side: int, centre_row: int, centre_col: int, rows: int, cols: int, x: float, y: float, cell: float
) -> tuple[int, int, int, int, int, float]:
    """The run of grid cells on one side of the Chebyshev ring ``ring`` round cell (centre_row, centre_col):
    (first row, first col, row step, col step, count, the side's gap from (x, y) across it). Sides 0 and 1
    are the bottom and top rows whole, 2 and 3 the left and right columns between them."""
    if side < 2:
        row = centre_row - ring if side == 0 else centre_row + ring
        first_col = max(centre_col - ring, 0)
        count = min(centre_col + ring, cols - 1) - first_col + 1 if 0 <= row < rows else 0
        return row, first_col, 0, 1, count, (row + 0.5) * cell - y
    col = centre_col - ring if side == 2 else centre_col + ring
    first_row = max(centre_row - ring + 1, 0)
    count = min(centre_row + ring - 1, rows - 1) - first_row + 1 if 0 <= col < cols else 0
    return first_row, col, 1, 0, count, (col + 0.5) * cell - x


LOOK_BINS = 360
"""Bearing bins of the look-at search's shadows (by the diamond angle: 90 a quadrant; timed in turn, 10 rounds,
at the fixed point of the warehouse, N = 4: 180, 360, 720 and 1,440 bins 2.05 - 2.07, 2.05, 2.08 - 2.09 and
2.12 - 2.13 x the empty domain's agent-step)."""
DIAMOND_SLACK = 1e-9
"""How far inside a square's span, in diamond angle, a bearing must lie to be called inside: far more than
the rounding of a diamond angle (~1e-16), so a line grazing the square's corner is never taken for one
crossing it. (A diamond angle grows at most as fast as the bearing in radians: the slack is at least 1e-9
radians.)"""


@njit(cache=True)
def _diamond(dx: float, dy: float) -> float:
    """The diamond angle of the direction (dx, dy) ≠ (0, 0): in [0, 4), increasing with the bearing from +x
    anticlockwise like the angle itself, and a division where the angle needs an arctangent."""
    if dy >= 0.0:
        return dy / (dx + dy) if dx >= 0.0 else 1.0 - dx / (dy - dx)
    return 2.0 - dy / (-dx - dy) if dx < 0.0 else 3.0 + dx / (dx - dy)


@njit(cache=True)
def _look_bin(dx: float, dy: float) -> int:
    """The bearing bin of the direction (dx, dy)."""
    return min(math.floor(_diamond(dx, dy) * (LOOK_BINS / 4.0)), LOOK_BINS - 1)


@njit(cache=True)
def _shadow_behind(beyond: np.ndarray, left: float, bottom: float, cell: float) -> None:
    """Mark the bins wholly inside the angular span of the square with lower-left corner (left, bottom)
    relative to the robot with the squared distance of its farthest corner.

    The span is taken in diamond angle, which is monotone in the bearing, so its ends are its extreme
    corners' diamond angles, measured from the centre's: a square that does not hold the robot spans less
    than a half turn, 2 in diamond angle, so each corner lies within ±2 of the centre."""
    if square_gap2(left, bottom, cell) < 1e-12:
        return  # the robot on its edge: no span to speak of
    centre = _diamond(left + 0.5 * cell, bottom + 0.5 * cell)
    low, high, farthest2 = math.inf, -math.inf, 0.0
    for corner_x, corner_y in (
        (left, bottom),
        (left + cell, bottom),
        (left, bottom + cell),
        (left + cell, bottom + cell),
    ):
        offset = _diamond(corner_x, corner_y) - centre
        if offset > 2.0:
            offset -= 4.0
        elif offset < -2.0:
            offset += 4.0
        low, high = min(low, offset), max(high, offset)
        farthest2 = max(farthest2, corner_x * corner_x + corner_y * corner_y)
    start, end = centre + low + DIAMOND_SLACK, centre + high - DIAMOND_SLACK
    if start >= end:
        return
    if start < 0.0:
        start, end = start + 4.0, end + 4.0  # across the +x axis: bins counted on from the last
    first = math.floor(start * (LOOK_BINS / 4.0)) + 1
    last = math.floor(end * (LOOK_BINS / 4.0)) - 1
    for k in range(first, last + 1):
        b = k % LOOK_BINS
        beyond[b] = min(beyond[b], farthest2)


@njit(cache=True)
def _in_clear_sight(
    ground: Ground, teammates: np.ndarray, x: float, y: float, target_x: float, target_y: float, cell: float
) -> bool:
    """The camera's rule (model.world.visibility.line_of_sight), teammates' disks only with occlusion."""
    hiding = teammates if ground.occlusion else teammates[:0]
    return line_of_sight(ground.wall_grid, x, y, target_x, target_y, ground.grain, hiding, ground.radius)
