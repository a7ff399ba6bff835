"""The order in which the ``anicov`` controller's robots take the spiral's pieces
(:mod:`model.controllers.anicov.piece_order`): improved by local search from the order of the resized pieces.

Beyond the paper (docs/controller.md). Every swap of two robots and every move of one robot to another
place is a neighbour; the soonest (as far as a bracket 20 % under the best so far tells) is taken while
one is sooner (steepest descent). A round walks each neighbour's pieces at one finish over the places it
changes only, and bisects only those that reach the end there (:func:`_soonest_neighbour`, compiled):
the same orders to the bit as bisecting every neighbour, and the paper's square at N = 100 (14,650
neighbours a round, 43 rounds) plans its order in about a second, not a minute (bench/bench_planner.py).
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

from model.controllers.anicov.piece_order import (
    NEIGHBOUR_BISECTIONS,
    Spiral,
    WalkArrays,
    bisected,
    order_finishes,
    walk_arrays,
    walk_pieces,
)

MAX_ROUNDS = 60
"""Local search rounds at most (a round takes the best of all swaps and moves)."""


def neighbours(order: np.ndarray) -> np.ndarray:
    """Every order one swap of two robots, or one move of a robot to another place, from ``order``: the
    swaps (i, j), i < j, then the moves of place i to place j, |i - j| > 1 (to i +- 1 is a swap)."""
    return order[_neighbour_places(len(order))]


@functools.cache
def _neighbour_places(agents: int) -> np.ndarray:
    """:func:`neighbours` as places: row r holds, for each place, which place of the order it takes (built
    whole, not row by row: N = 100 has 14,650 rows)."""
    place = np.arange(agents)
    i, j = np.triu_indices(agents, k=1)  # the swaps, (i, j) in row-major order
    swaps = np.where(place == i[:, None], j[:, None], np.where(place == j[:, None], i[:, None], place))
    i, j = (grid.ravel() for grid in np.meshgrid(place, place, indexing="ij"))
    keep = np.abs(j - i) > 1
    i, j = i[keep, None], j[keep, None]  # the moves of place i to place j: the rest close up, i goes in at j
    later = (place >= i) & (place < j)  # moved later: the places from i up to j take the next one's
    earlier = (place > j) & (place <= i)  # moved earlier: the places after j up to i take the one before's
    moves = np.where(place == j, i, np.where(later, place + 1, np.where(earlier, place - 1, place)))
    return np.ascontiguousarray(np.vstack([swaps, moves]), dtype=np.intp).reshape(-1, agents)


def improved_order(order: np.ndarray, positions: np.ndarray, spiral: Spiral) -> tuple[np.ndarray, float]:
    """(order, its finish): from ``order``, the soonest of all its :func:`neighbours` while it finishes
    sooner (steepest descent, at most :data:`MAX_ROUNDS` rounds; neighbours more than 20 % sooner than the
    best so far all look alike to the rough bracket, and the first of them is taken). Each round is
    :func:`_soonest_neighbour`."""
    order = np.ascontiguousarray(order, dtype=np.intp)
    walk = walk_arrays(positions, spiral)
    best = float(order_finishes(order[None, :], positions, spiral)[0])
    places = _neighbour_places(len(order))
    moved = _moved_places(len(order))
    for _ in range(MAX_ROUNDS):
        if not len(places):
            break
        k, rough = _soonest_neighbour(order, places, moved, best, NEIGHBOUR_BISECTIONS, walk)
        if k < 0 or rough >= best - 1e-9:
            break
        candidate = order[places[k]]
        exact = float(order_finishes(candidate[None, :], positions, spiral)[0])
        if exact >= best - 1e-9:
            break
        order, best = candidate, exact
    return order, best


@functools.cache
def _moved_places(agents: int) -> tuple[np.ndarray, np.ndarray]:
    """For each row of :func:`_neighbour_places`, the first and the last place whose robot it changes."""
    changed = _neighbour_places(agents) != np.arange(agents)
    first = changed.argmax(axis=1)
    last = agents - 1 - changed[:, ::-1].argmax(axis=1)
    return np.ascontiguousarray(first, dtype=np.intp), np.ascontiguousarray(last, dtype=np.intp)


@njit(cache=True)
def _soonest_neighbour(
    order: np.ndarray,
    places: np.ndarray,
    moved: tuple[np.ndarray, np.ndarray],
    best: float,
    halvings: int,
    walk: WalkArrays,
) -> tuple[int, float]:
    """(row of ``places``, its rough finish): the first of the neighbours whose rough finish (bisected from
    within 20 % under ``best``, :func:`order_finishes`' ``below``) is least; (-1, ``best``) if none is
    under ``best``. The same answer as bisecting every neighbour, at a fraction of the work (N = 100: 14,650
    neighbours a round): a neighbour's bracket only ever falls below ``best`` if its pieces reach the end at
    the bracket's last midpoint on the way up, and the finish is monotone in T and in the cut a robot
    starts from (a later finish, or a later cut, lengthens every piece after it: a piece's entry moves no
    farther than its cut, so no transit grows faster). So each neighbour is walked at that one T over the
    places it changes only (``moved``: the first and last of each): the places before are the order's own,
    walked once, and the order's own places after reach the end from a cut at or above a threshold
    (:func:`_suffix_thresholds`); a cut within the thresholds' bracket walks on. Only the neighbours that
    reach are bisected, each given up once its bracket lies above the least found so far (no rough finish
    below it is left there)."""
    rising = np.empty(halvings)  # the midpoints of a neighbour that fails at each: its bracket's low ends
    low = 0.8 * best
    for k in range(halvings):
        low = rising[k] = 0.5 * (low + best)
    agents = len(order)
    cut_before = np.zeros(agents + 1)
    reached_before = np.zeros(agents + 1, dtype=np.bool_)
    for k in range(agents):
        reached, cut = walk_pieces(order, k, k + 1, cut_before[k], low, walk)
        cut_before[k + 1] = cut
        reached_before[k + 1] = reached_before[k] or reached
    fails_up_to, reaches_from = _suffix_thresholds(order, low, walk)
    soonest, chosen = best, -1
    neighbour = order.copy()  # a neighbour is the order but for the places it changes
    for m in range(len(places)):
        start, after = moved[0][m], moved[1][m] + 1
        for k in range(start, after):
            neighbour[k] = order[places[m, k]]
        reached = reached_before[start]
        if not reached:
            reached, cut = walk_pieces(neighbour, start, after, cut_before[start], low, walk)
            if not reached and cut > fails_up_to[after]:
                reached = cut >= reaches_from[after] or walk_pieces(neighbour, after, agents, cut, low, walk)[0]
        if reached:
            rough = _rough_finish(neighbour, rising, best, soonest, walk)
            if rough < soonest:
                soonest, chosen = rough, m
        neighbour[start:after] = order[start:after]
    return chosen, soonest


@njit(cache=True)
def _rough_finish(order: np.ndarray, rising: np.ndarray, best: float, soonest: float, walk: WalkArrays) -> float:
    """:func:`bisected` from within 20 % under ``best`` (``rising``: the midpoints of a bracket that fails at
    each), given up above ``soonest``; first tried at the last of ``rising`` under ``soonest``: failing
    there, the bisection would have failed at every one before it too (the finish is monotone in T), and
    goes on from there, bracket for bracket the same."""
    below = np.searchsorted(rising, soonest) - 1  # the last midpoint under soonest
    if below >= 0 and not walk_pieces(order, 0, len(order), 0.0, rising[below], walk)[0]:
        return bisected(order, rising[below], best, len(rising) - below - 1, soonest, walk)
    return bisected(order, 0.8 * best, best, len(rising), soonest, walk)


@njit(cache=True)
def _suffix_thresholds(order: np.ndarray, finish: float, walk: WalkArrays) -> tuple[np.ndarray, np.ndarray]:
    """(fails_up_to, reaches_from), (N + 1,) each: the robots at places p to N - 1 of ``order``, starting
    from a cut at most ``fails_up_to[p]``, do not reach the spiral's end at ``finish``; from a cut at least
    ``reaches_from[p]``, they do. From the last place back: a cut at place p is shown to reach (or to fail)
    by robot p's own piece and the thresholds of place p + 1, so each place costs a bisection of one robot's
    piece (:data:`THRESHOLD_HALVINGS` each way), and each threshold is a cut so shown (the empty suffix
    fails from every cut)."""
    first, _, _, along, overlap, allowance = walk
    agents = len(order)
    fails_up_to = np.full(agents + 1, np.inf)
    reaches_from = np.full(agents + 1, np.inf)
    # A cut this far reaches the end with any robot's own piece: no transit exceeds the way to the spiral's
    # first point, the spiral and the overlap.
    high_cut = 2.0 * along[-1] + allowance + overlap + first.max() + abs(finish) + 1.0
    for p in range(agents - 1, -1, -1):
        reaches_from[p] = _threshold(order, p, finish, True, high_cut, fails_up_to, reaches_from, walk)
        fails_up_to[p] = _threshold(order, p, finish, False, high_cut, fails_up_to, reaches_from, walk)
    return fails_up_to, reaches_from


THRESHOLD_HALVINGS = 60
"""Halvings of a threshold's bracket (from twice the spiral's length and more: far below a rounding of the
cut that matters, so almost no neighbour's cut falls between a place's two thresholds)."""


@njit(cache=True)
def _threshold(
    order: np.ndarray,
    place: int,
    finish: float,
    reaching: bool,
    high_cut: float,
    fails_up_to: np.ndarray,
    reaches_from: np.ndarray,
    walk: WalkArrays,
) -> float:
    """:func:`_suffix_thresholds` at ``place``: the least cut in [0, ``high_cut``] shown to reach
    (``reaching``; infinite if none), or the most shown to fail (minus infinity if none), bisected."""
    inside, outside = (high_cut, 0.0) if reaching else (0.0, high_cut)  # shown, and not shown
    if _shown(order, place, outside, finish, reaching, fails_up_to, reaches_from, walk):
        return outside
    if not _shown(order, place, inside, finish, reaching, fails_up_to, reaches_from, walk):
        return np.inf if reaching else -np.inf
    for _ in range(THRESHOLD_HALVINGS):
        middle = 0.5 * (inside + outside)
        if _shown(order, place, middle, finish, reaching, fails_up_to, reaches_from, walk):
            inside = middle
        else:
            outside = middle
    return inside


@njit(cache=True)
def _shown(
    order: np.ndarray,
    place: int,
    cut: float,
    finish: float,
    reaching: bool,
    fails_up_to: np.ndarray,
    reaches_from: np.ndarray,
    walk: WalkArrays,
) -> bool:
    """Whether the robots from ``place`` on, from ``cut``, are shown to reach the end at ``finish``
    (``reaching``), or shown not to: by the piece of the robot at ``place`` and the next place's
    thresholds."""
    reached, after = walk_pieces(order, place, place + 1, cut, finish, walk)
    if reaching:
        return reached or after >= reaches_from[place + 1]
    return not reached and after <= fails_up_to[place + 1]
