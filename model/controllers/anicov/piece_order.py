"""The ``anicov`` controller's pieces cut for an order of robots: who flies the spiral's first piece, who the
next, and where each piece ends, so that the team finishes as soon as it can.

Beyond the paper (docs/controller.md has the measurements). Robots in a given order take consecutive pieces
of the spiral from its start; robot k's piece begins where robot k - 1's ends. For a finish time T, each
piece is as long as T less its robot's transit to where the piece begins (the first piece: to its run-up,
and the run-up itself; after the first: to :attr:`Spiral.overlap` before it, and the overlap): the pieces
then take every robot exactly T, and the least T at which they reach the spiral's end with the centre's
allowance to spare is the order's finish (:func:`order_finishes`, by bisection, for many orders at once).
The allowance may be shared: a robot that reaches the end with less than the allowance to spare leaves the
rest to the next in the order, who flies no spiral, goes to the centre and is counted what it has left (on
the paper's square at N = 30 most plans end so: two robots share the centre's orbit and passes). A robot
whose transit alone is longer than T flies no piece, nor do the robots after the end is reached; they take
passes from the start. The order is improved by local search
(:func:`model.controllers.anicov.order_search.improved_order`): every swap of two robots and every move of
one robot to another place in the order, the soonest (as far as a bracket 20 % under the best so far
tells) taken while one is sooner. :func:`model.controllers.anicov.routes.balanced_routes` starts it from
the order of its resized pieces: on the paper's square (16 seeds, 2026-12-04) that alone made N = 20 2.965
-> 2.906 t* and N = 30 3.395 -> 3.216, and N = 2 - 10 moved by less than 0.01. Resizing the pieces in
rounds, robots reassigned in each, did not settle where thirty robots and thirty pieces are all a transit
apart: their estimated finish was 3.69 t*_30 on average, this search's 2.95.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import njit

from model.paper.polyline import point_along

BISECTIONS = 40
"""Halvings of the bracket of an order's finish (from one spiral length: far below a time step)."""
NEIGHBOUR_BISECTIONS = 14
"""Halvings when only whether a neighbour beats the best so far is asked (from within 20 % below it)."""


@dataclass(frozen=True)
class Spiral:
    """What the cut needs of the spiral: its polyline (K, 2) and arc lengths (K,), the run-up's length
    (:func:`model.controllers.anicov.routes.lead_in`), the centre's allowance and the seams' overlap (units)."""

    points: np.ndarray
    along: np.ndarray
    lead: float
    allowance: float
    overlap: float = 0.0
    """How far back along the spiral from its cut a piece after the first is entered (units)."""

    @property
    def length(self) -> float:
        return float(self.along[-1])

    def entered(self, cut: Any) -> Any:
        """Where (arc length) a piece cut at ``cut`` (> 0; a float or an array) is entered: :attr:`overlap`
        before it, no farther back than the spiral's start, the cut held to the spiral's end."""
        return np.maximum(np.minimum(cut, self.length) - self.overlap, 0.0)

    def first_transits(self, positions: np.ndarray) -> np.ndarray:
        """The way (units) from each of ``positions`` (..., 2) to the spiral's first point: to where its
        run-up begins (:func:`start_run_ups`, :func:`run_up_entries`), then the run-up."""
        run_up = start_run_ups(positions, self.points[0], self.lead)
        return np.linalg.norm(positions - run_up_entries(self.points, run_up), axis=-1) + run_up


def run_up_entries(path: np.ndarray, run_ups: np.ndarray | float) -> np.ndarray:
    """Where a run-up of each of ``run_ups`` before ``path``'s first point begins, back along its first
    stretch ((..., 2) for (...) run-ups): the one definition of the run-up's start, for the estimate here
    and the routes flown (:func:`model.controllers.anicov.routes.with_run_up`)."""
    heading = path[1] - path[0]
    heading = heading / max(float(np.linalg.norm(heading)), 1e-300)
    return path[0] - np.asarray(run_ups)[..., None] * heading


def start_run_ups(positions: np.ndarray, start: np.ndarray, lead: float) -> np.ndarray:
    """The run-up (units) before the spiral's first point for a robot at each of ``positions`` (..., 2):
    ``lead``, or twice that for a robot that starts within ``lead`` of that point. Such a robot goes out
    back along the run-up and turns about outside the domain, and the run-up alone left 1 - 3 cells of the
    corner short (a robot at 9 of 36 places within 14 of the corner; at none with twice the run-up). The
    robot that finished soonest then flew across the domain to orbit them: at N = 10, seed 15, the team was
    done at 3.16 t* (2.67 with twice the run-up)."""
    near = np.linalg.norm(positions - start, axis=-1) < lead
    return np.where(near, 2.0 * lead, lead)


def order_finishes(
    orders: np.ndarray, positions: np.ndarray, spiral: Spiral, below: np.ndarray | None = None
) -> np.ndarray:
    """The least finish T of each order (``orders``: (M, N) robot indices; returns (M,)): the least T at
    which consecutive pieces, each T less its robot's transit to where it begins (and the first's run-up),
    reach the spiral's end with the centre's allowance to spare (shared with the next robot, see the
    module). ``below``: only whether T lies under these is asked (the bracket starts 20 % under them, fewer
    halvings)."""
    orders = np.ascontiguousarray(orders, dtype=np.intp)
    walk = walk_arrays(positions, spiral)
    if below is None:
        top = spiral.length + spiral.lead + spiral.allowance + walk[0][orders].max() + _span(positions, spiral)
        low, high, halvings = np.zeros(len(orders)), np.full(len(orders), top), BISECTIONS
    else:
        low, high, halvings = 0.8 * below, np.array(below, dtype=np.float64), NEIGHBOUR_BISECTIONS
    return np.array(
        [bisected(order, lo, hi, halvings, np.inf, walk) for order, lo, hi in zip(orders, low, high, strict=True)]
    )


def _span(positions: np.ndarray, spiral: Spiral) -> float:
    """An upper bound on any transit: the diagonal of the box around the robots and the spiral."""
    both = np.vstack([positions, spiral.points])
    return float(np.linalg.norm(both.max(axis=0) - both.min(axis=0)))


WalkArrays = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float, float]
"""What :func:`walk_pieces` reads (:func:`walk_arrays`): each robot's way to the spiral's first point (N,) and
position (N, 2), the spiral's polyline (K, 2) and arc lengths (K,), its seams' overlap and the centre's
allowance."""


def walk_arrays(positions: np.ndarray, spiral: Spiral) -> WalkArrays:
    """:data:`WalkArrays` of these robots and this spiral, contiguous for the compiled walk."""
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    first = np.ascontiguousarray(spiral.first_transits(positions), dtype=np.float64)
    points = np.ascontiguousarray(spiral.points, dtype=np.float64)
    along = np.ascontiguousarray(spiral.along, dtype=np.float64)
    return first, positions, points, along, float(spiral.overlap), float(spiral.allowance)


@njit(cache=True)
def _point_at(points: np.ndarray, along: np.ndarray, at: float) -> tuple[float, float]:
    """The point ``at`` along the polyline, as ``np.interp`` of each coordinate computes it (the same
    rounding): held to the ends outside them."""
    last = len(along) - 1
    if at <= along[0]:
        return points[0, 0], points[0, 1]
    if at >= along[last]:
        return points[last, 0], points[last, 1]
    j = np.searchsorted(along, at, side="right") - 1
    if along[j] == at:
        return points[j, 0], points[j, 1]
    gap, offset = along[j + 1] - along[j], at - along[j]
    x = (points[j + 1, 0] - points[j, 0]) / gap * offset + points[j, 0]
    y = (points[j + 1, 1] - points[j, 1]) / gap * offset + points[j, 1]
    return x, y


@njit(cache=True)
def walk_pieces(
    order: np.ndarray, start: int, stop: int, cut: float, finish: float, walk: WalkArrays
) -> tuple[bool, float]:
    """(whether the end is reached, the cut after them, or before the robot that reaches it): the robots at
    places ``start`` to ``stop`` of ``order`` take their pieces at ``finish``, the spiral cut at ``cut``
    before them."""
    first, positions, points, along, overlap, allowance = walk
    length = along[-1]
    for k in range(start, stop):
        robot = order[k]
        if cut > 0.0:
            held = min(cut, length)
            entered = max(held - overlap, 0.0)
            x, y = _point_at(points, along, entered)
            transit = math.hypot(positions[robot, 0] - x, positions[robot, 1] - y) + (held - entered)
        else:
            # At a cut of 0 this robot starts the spiral (the robots before it, if any, took nothing: their
            # transit alone was longer than ``finish``).
            transit = first[robot]
        if cut + finish - transit - allowance >= length:
            return True, cut
        cut = cut + max(0.0, finish - transit)
    return False, cut


@njit(cache=True)
def bisected(order: np.ndarray, low: float, high: float, halvings: int, give_up_at: float, walk: WalkArrays) -> float:
    """The least finish of ``order`` in (low, high], to ``halvings`` halvings of the bracket; once its low end
    reaches ``give_up_at``, the bracket's high end as it is (then above ``give_up_at``)."""
    for _ in range(halvings):
        if low >= give_up_at:
            break
        finish = 0.5 * (low + high)
        reached, _ = walk_pieces(order, 0, len(order), 0.0, finish, walk)
        if reached:
            high = finish
        else:
            low = finish
    return high


def cuts_for(order: np.ndarray, finish: float, positions: np.ndarray, spiral: Spiral) -> list[tuple[int, float, float]]:
    """The pieces at ``finish`` for ``order``, as (robot, from, to) arc lengths, in the spiral's order: the
    robots that fly one, up to the one that reaches the spiral's end (``finish`` from
    :func:`order_finishes`); a robot whose transit alone is longer than ``finish`` is left out. A piece
    after the first is entered :meth:`Spiral.entered` (its robot flies the overlap before ``from``)."""
    pieces = []
    cut = 0.0
    for robot in order:
        if cut == 0.0:  # the spiral's first piece
            transit = float(spiral.first_transits(positions[robot]))
        else:
            entered = float(spiral.entered(cut))
            transit = float(np.linalg.norm(positions[robot] - point_along(spiral.points, spiral.along, entered)))
            transit += min(cut, spiral.length) - entered
        if cut + finish - transit - spiral.allowance >= spiral.length - 1e-9:
            pieces.append((int(robot), min(cut, spiral.length), spiral.length))
            break
        end = cut + max(0.0, finish - transit)
        if end > cut:
            pieces.append((int(robot), min(cut, spiral.length), min(end, spiral.length)))
        cut = end
    return pieces
