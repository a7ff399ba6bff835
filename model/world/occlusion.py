"""What may hide a wedge's cells, found once per sensing pass so that the exact test runs on few cells.

The rule is :mod:`model.world.visibility`'s; this module only prunes. For walls: a segment from the robot at
p to a cell centre c crosses an occupied square Q only if c's bearing lies in Q's angular span seen
from p and c is farther than Q's nearest point. The wedge's bearings (±F, plus a bin each side) are
cut into SHADOW_BINS bins; each bin keeps the nearest distance of the occupied squares (and teammates'
disks, :func:`add_teammate_shadows`) of the wedge's
window whose angular span (widened by PSEUDO_SLACK) meets it (a square beside the robot spans only
its part in front, up to ±90° on its side: a segment to a cell in front never enters the part behind; a
square with no corner in front is left out, unless the robot stands on its edge: then it spans every bin), and,
for the bins wholly inside a
square's span, the distance of its farthest corner: a ray there crosses the square's inside, so a cell
beyond is hidden without a traversal. Squares farther than R, squares wholly past the line of an edge of
the wedge (:func:`_past_an_edge`), and squares whose four neighbours are occupied (a segment reaches one
only through a neighbour, unless it ends there), are left out. A cell nearer than its bin's distance
cannot be hidden by a wall; the others get the exact traversal. (A segment from p to c stays in the
window grown to the robot's own cell, which holds both, so squares outside it cannot hide anything.) For teammates: those whose
disk can reach the wedge, each tested exactly.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from model.paper.geometry import square_gap2
from model.world.ground import Ground

SHADOW_BINS = 64
PSEUDO_SLACK = 1e-9
"""How far, in pseudo-angle, a square's span is widened before it is binned: far more than the rounding
of a corner's or a cell centre's pseudo-angle (~1e-16), so a cell on the bearing of a square's edge or
corner is still in a bin the square marks. (Until 2026-12-03 a whole bin each side: half the visible
cells that went to the exact traversal on the warehouse map went there only for that bin.)"""


@njit(cache=True)
def wall_shadows(
    ground: Ground,
    x: float,
    y: float,
    theta: float,
    half_angle: float,
    sensing_range: float,
    cell: float,
    row0: int,
    row1: int,
    col0: int,
    col1: int,
) -> np.ndarray:
    """(2, SHADOW_BINS): per bearing bin (:func:`pseudo_bin`), the squared nearest distance of a wall that
    may hide cells there, and the squared distance beyond which a wall hides every cell there (+inf: none)."""
    shadows = np.full((2, SHADOW_BINS), np.inf)
    if not ground.occlusion:
        return shadows
    walls, grain = ground.wall_grid, ground.grain
    rows, cols = walls.shape
    heading_x, heading_y = math.cos(theta), math.sin(theta)
    reach2 = sensing_range * sensing_range
    cos_half_angle, sin_half_angle = math.cos(half_angle), math.sin(half_angle)
    # The window of the wedge's cells and the robot's own cell: a segment between them stays inside.
    # The wall squares of that window (a coverage cell holds split × split of them).
    split = round(cell / grain)
    row0, row1 = min(row0, math.floor(y / cell)) * split, (max(row1, math.floor(y / cell) + 1)) * split
    col0, col1 = min(col0, math.floor(x / cell)) * split, (max(col1, math.floor(x / cell) + 1)) * split
    for row in range(max(row0, 0), min(row1, rows)):
        for col in range(max(col0, 0), min(col1, cols)):
            if not walls[row, col] or _inside_a_wall(walls, row, col, rows, cols):
                continue  # a segment reaches a cell inside a wall only through the wall cells around it
            left, bottom = col * grain - x, row * grain - y
            nearest2 = square_gap2(left, bottom, grain)
            if nearest2 > reach2 or _past_an_edge(
                left, bottom, grain, heading_x, heading_y, cos_half_angle, sin_half_angle
            ):
                continue  # farther than R, or no bearing of it in the wedge
            smallest, largest, farthest2, behind = _square_span(left, bottom, grain, heading_x, heading_y)
            if nearest2 == 0.0:
                # The robot stands on its edge: the traversal's tie rules (a segment from a grid corner)
                # may test it whatever the bearing.
                first, last = 0, SHADOW_BINS - 1
            elif smallest > largest:
                continue  # wholly behind the robot: a segment to a cell in front never enters it
            else:
                first = pseudo_bin(smallest - PSEUDO_SLACK, half_angle)
                last = pseudo_bin(largest + PSEUDO_SLACK, half_angle)
            for k in range(max(first, 0), min(last, SHADOW_BINS - 1) + 1):
                shadows[0, k] = min(shadows[0, k], nearest2)
            if behind:
                continue
            # Bins wholly inside the span (past the bins of its ends, slack included): every ray there
            # crosses the square's inside, so a cell beyond its farthest corner is hidden for sure.
            for k in range(
                max(pseudo_bin(smallest + PSEUDO_SLACK, half_angle) + 1, 0),
                min(pseudo_bin(largest - PSEUDO_SLACK, half_angle) - 1, SHADOW_BINS - 1) + 1,
            ):
                shadows[1, k] = min(shadows[1, k], farthest2)
    return shadows


@njit(cache=True)
def _past_an_edge(
    left: float, bottom: float, cell: float, heading_x: float, heading_y: float, cos_half: float, sin_half: float
) -> bool:
    """Whether the square with lower-left corner (left, bottom), relative to the robot, lies wholly past the
    line of the wedge's edge on its side, by its circumscribed circle (radius 0.7072 cell, a little over
    √2/2 for rounding): the line through the robot at bearing ±F, the side away from the heading. Such a
    square's bearings, seen from the robot, all lie beyond ±F (with F ≤ 90°, the far side of the line holds
    bearings F to F + 180°; with F > 90°, a circle centred past F and clear of the line spans bearings
    past F only), so no segment to a cell of the wedge enters it."""
    centre_x, centre_y = left + 0.5 * cell, bottom + 0.5 * cell
    beside = abs(heading_x * centre_y - heading_y * centre_x) * cos_half
    return beside - (centre_x * heading_x + centre_y * heading_y) * sin_half > 0.7072 * cell


@njit(cache=True)
def _square_span(
    left: float, bottom: float, cell: float, heading_x: float, heading_y: float
) -> tuple[float, float, float, bool]:
    """(smallest and largest pseudo-angle of the square's part in front of the robot, squared distance of
    its farthest corner, whether a corner is beside or behind the robot), corners relative to the robot.

    That part is bounded by the square's corners in front and, for a square that reaches beside the robot,
    by the points where its edges cross the robot's sideways line (along = 0): a bearing of ±90°,
    pseudo-angle ±1 on the side of the crossing. A crossing at the robot itself (within 1e-9: the robot on
    the square's edge) counts on both sides, so every bearing is spanned. A square with no corner in front
    has no part there: smallest > largest (a segment to a cell in front never enters it)."""
    right, top = left + cell, bottom + cell
    if left > 0.0 or right < 0.0 or bottom > 0.0 or top < 0.0:
        # Seen from outside, the span's ends are two corners known from where the robot lies (the
        # clockwise-most, then the anticlockwise-most); when both are in front, so is every corner.
        if left > 0.0:  # to the right of the robot: above it, below it, or level with it
            if bottom > 0.0:
                first_x, first_y, last_x, last_y = right, bottom, left, top
            elif top < 0.0:
                first_x, first_y, last_x, last_y = left, bottom, right, top
            else:
                first_x, first_y, last_x, last_y = left, bottom, left, top
        elif right < 0.0:  # to its left
            if bottom > 0.0:
                first_x, first_y, last_x, last_y = right, top, left, bottom
            elif top < 0.0:
                first_x, first_y, last_x, last_y = left, top, right, bottom
            else:
                first_x, first_y, last_x, last_y = right, top, right, bottom
        elif bottom > 0.0:  # straight above it
            first_x, first_y, last_x, last_y = right, bottom, left, bottom
        else:  # straight below it
            first_x, first_y, last_x, last_y = left, top, right, top
        first_along = first_x * heading_x + first_y * heading_y
        last_along = last_x * heading_x + last_y * heading_y
        if first_along > 0.0 and last_along > 0.0:
            first_across = heading_x * first_y - heading_y * first_x
            last_across = heading_x * last_y - heading_y * last_x
            farthest2 = max(left * left, right * right) + max(bottom * bottom, top * top)
            return (
                first_across / (first_along + abs(first_across)),
                last_across / (last_along + abs(last_across)),
                farthest2,
                False,
            )
    return _square_span_by_corners(left, bottom, cell, heading_x, heading_y)


@njit(cache=True)
def _square_span_by_corners(
    left: float, bottom: float, cell: float, heading_x: float, heading_y: float
) -> tuple[float, float, float, bool]:
    """:func:`_square_span` from all four corners and the crossings of the robot's sideways line: every
    case, the robot on the square's edge and squares reaching beside or behind it included."""
    corners_x = (left, left + cell, left + cell, left)  # counter-clockwise: edge k joins corners k and k + 1
    corners_y = (bottom, bottom, bottom + cell, bottom + cell)
    smallest, largest, farthest2, behind = math.inf, -math.inf, 0.0, False
    for k in range(4):
        corner_x, corner_y = corners_x[k], corners_y[k]
        along = corner_x * heading_x + corner_y * heading_y
        across = heading_x * corner_y - heading_y * corner_x
        farthest2 = max(farthest2, corner_x * corner_x + corner_y * corner_y)
        if along > 0.0:
            bearing = across / (along + abs(across))
            smallest, largest = min(smallest, bearing), max(largest, bearing)
            continue
        behind = True
        for other in ((k + 1) % 4, (k + 3) % 4):  # the two edges from this corner
            other_along = corners_x[other] * heading_x + corners_y[other] * heading_y
            if other_along <= 0.0:
                continue
            other_across = heading_x * corners_y[other] - heading_y * corners_x[other]
            crossing = across + (other_across - across) * along / (along - other_along)
            if crossing >= -1e-9:
                largest = 1.0
                smallest = min(smallest, 1.0)
            if crossing <= 1e-9:
                smallest = -1.0
                largest = max(largest, -1.0)
    return smallest, largest, farthest2, behind


@njit(cache=True)
def _inside_a_wall(occupied: np.ndarray, row: int, col: int, rows: int, cols: int) -> bool:
    """All four edge neighbours are occupied cells of the grid."""
    if row == 0 or col == 0 or row == rows - 1 or col == cols - 1:
        return False
    return occupied[row - 1, col] and occupied[row + 1, col] and occupied[row, col - 1] and occupied[row, col + 1]


@njit(cache=True)
def pseudo_bin(bearing: float, half_angle: float) -> int:
    """The bin of a pseudo-angle across / (along + |across|) (monotone in the bearing in front of the
    robot, and cheaper than an arctangent); the bins cut that of ±F into SHADOW_BINS − 2, one more each side."""
    edge = math.sin(half_angle) / (math.cos(half_angle) + math.sin(half_angle))
    width = 2.0 * edge / (SHADOW_BINS - 2)
    return min(max(math.floor((bearing + edge + width) / width), 0), SHADOW_BINS - 1)


@njit(cache=True)
def teammates_in_view(
    ground: Ground, positions: np.ndarray, me: int, x: float, y: float, sensing_range: float
) -> np.ndarray:
    """Positions of the teammates whose disk can hide part of the wedge. Bodies that overlap this one
    (closer than 2r: robots that drove through each other, which only a safety filter prevents) hide
    nothing: a robot inside another would otherwise be blind."""
    near = np.zeros((positions.shape[0], 2))
    count = 0
    if not ground.occlusion or ground.radius <= 0.0:
        return near[:0]
    for k in range(positions.shape[0]):
        px, py = positions[k, 0], positions[k, 1]
        gap = math.hypot(px - x, py - y)
        if k == me or px != px or gap > sensing_range + ground.radius or gap < 2.0 * ground.radius:
            continue
        near[count, 0], near[count, 1] = px, py
        count += 1
    return near[:count]


@njit(cache=True)
def add_teammate_shadows(
    shadows: np.ndarray, teammates: np.ndarray, radius: float, x: float, y: float, theta: float, half_angle: float
) -> None:
    """Mark the bins a teammate's disk may hide, from its nearest point on: the bearings of its two
    tangents (widened by PSEUDO_SLACK), cut to the robot's front half (a segment to a cell in front has a
    bearing there): a disk that reaches beside the robot spans up to ±90° on its side, one wholly behind
    it spans nothing. (``teammates`` are never within 2r, so the robot is never inside a disk.)

    The tangents are the direction to the centre turned by ±asin(r / gap), taken as rotations in the
    robot's frame (along the heading, across to its left): no angle is computed. This needs gap ≥ √2·r
    (tangents at most 45° off the centre's bearing, so a disk with a tangent behind on the wrong side lies
    wholly behind); :func:`teammates_in_view` gives only teammates at gap ≥ 2r."""
    heading_x, heading_y = math.cos(theta), math.sin(theta)
    for k in range(teammates.shape[0]):
        dx, dy = teammates[k, 0] - x, teammates[k, 1] - y
        gap = math.hypot(dx, dy)
        nearest2 = max(gap - radius, 0.0) ** 2
        along, across = (dx * heading_x + dy * heading_y) / gap, (heading_x * dy - heading_y * dx) / gap
        sine = radius / gap
        cosine = math.sqrt(1.0 - sine * sine)
        low_along, low_across = along * cosine + across * sine, across * cosine - along * sine  # clockwise
        high_along, high_across = along * cosine - across * sine, across * cosine + along * sine
        if (high_along < 0.0 and high_across < 0.0) or (low_along < 0.0 and low_across > 0.0):
            # The anticlockwise tangent behind on the right (or the clockwise one behind on the left): the
            # disk spans less than a half turn, so all of it lies behind the robot.
            continue
        first = pseudo_bin(_front_pseudo(low_along, low_across) - PSEUDO_SLACK, half_angle)
        last = pseudo_bin(_front_pseudo(high_along, high_across) + PSEUDO_SLACK, half_angle)
        for b in range(max(first, 0), min(last, SHADOW_BINS - 1) + 1):
            shadows[0, b] = min(shadows[0, b], nearest2)


@njit(cache=True)
def _front_pseudo(along: float, across: float) -> float:
    """The pseudo-angle of :func:`pseudo_bin` of a direction, a bearing behind the robot taken as ±90° on
    its side (±1)."""
    if along > 0.0:
        return across / (along + abs(across))
    return 1.0 if across > 0.0 else -1.0
