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
from numba import njit, prange

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
SCREEN_MARGIN = 1e-9
"""How far above the round's last midpoint, relative to the best finish, neighbours are screened
(:func:`_soonest_neighbour`): far above a rounding (1e-16), far below a halving's step (1e-5)."""
THRESHOLD_HALVINGS = 60
"""Halvings of a threshold's bracket (from twice the spiral's length and more: far below a rounding of the
cut that matters, so almost no neighbour's cut falls between a place's two thresholds)."""


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
    moved = (*_moved_places(len(order)), _later_moves(len(order)))
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


@functools.cache
def _later_moves(agents: int) -> np.ndarray:
    """(N, N): the row of :func:`_neighbour_places` that moves place i later, to place j (j > i + 1); -1
    elsewhere."""
    place = np.arange(agents)
    i, j = (grid.ravel() for grid in np.meshgrid(place, place, indexing="ij"))
    moves = np.abs(j - i) > 1
    rows = agents * (agents - 1) // 2 + np.arange(int(moves.sum()))  # the moves come after the swaps
    i, j = i[moves], j[moves]
    later = np.full((agents, agents), -1, dtype=np.intp)
    later[i[j > i], j[j > i]] = rows[j > i]
    return later


@njit(cache=True)
def _soonest_neighbour(
    order: np.ndarray,
    places: np.ndarray,
    moved: tuple[np.ndarray, np.ndarray, np.ndarray],
    best: float,
    halvings: int,
    walk: WalkArrays,
) -> tuple[int, float]:
    """(row of ``places``, its rough finish): the first of the neighbours whose rough finish (bisected from
    within 20 % under ``best``, :func:`order_finishes`' ``below``) is least; (-1, ``best``) if none is
    under ``best``. The same answer as bisecting every neighbour, at a fraction of the work (N = 100: 14,650
    neighbours a round): a neighbour's bracket only ever falls below ``best`` if its pieces reach the end at
    the bracket's last midpoint on the way up (:func:`_reaching_at`), and the finish is monotone in T. Only
    the neighbours that reach there are bisected, each given up once its bracket lies above the least found
    so far (no rough finish below it is left there). Screened a hair above that midpoint, by
    :data:`SCREEN_MARGIN`."""
    rising = np.empty(halvings)  # the midpoints of a neighbour that fails at each: its bracket's low ends
    low = 0.8 * best
    for k in range(halvings):
        low = rising[k] = 0.5 * (low + best)
    # Screened a hair above that midpoint: the walk is monotone in T and in the cut only in exact arithmetic,
    # and at the midpoint itself a neighbour that reaches there could fall a rounding short of a threshold
    # (a team of three, tests/test_order_search.py). Every neighbour screened in is decided by
    # _rough_finish's own bisection, as before.
    screen = low + SCREEN_MARGIN * best
    soonest, chosen = best, -1
    for m in np.flatnonzero(_reaching_at(order, places, moved, screen, walk)):
        rough = _rough_finish(order[places[m]], rising, best, soonest, walk)
        if rough < soonest:
            soonest, chosen = rough, m
    return chosen, soonest


@njit(cache=True, parallel=True)
def _reaching_at(
    order: np.ndarray,
    places: np.ndarray,
    moved: tuple[np.ndarray, np.ndarray, np.ndarray],
    finish: float,
    walk: WalkArrays,
) -> np.ndarray:
    """(M,): whether each neighbour's pieces reach the spiral's end at ``finish``. Reaching is monotone in the
    cut a robot starts from too, in exact arithmetic: the next cut, max(c, c + T - transit), and the reach
    test, c + T - transit, never fall as c grows (a piece's entry moves no farther along the spiral than
    the cut, so no transit grows faster; leaving a cut of 0 drops the run-up, which is at least the way to
    the spiral's first point from its start). So a neighbour is walked over the places it changes
    only (``moved``: the first and last of each, and :func:`_later_moves`): the places before are the
    order's own, walked once, and the order's own places after reach the end from a cut at or above a
    threshold (:func:`_suffix_thresholds`); a cut within the thresholds' bracket walks on. The moves of a
    place to a later one share their walk (:func:`_later_moves_reaching`)."""
    agents = len(order)
    cut_before = np.zeros(agents + 1)
    reached_before = np.zeros(agents + 1, dtype=np.bool_)
    for k in range(agents):
        reached, cut = walk_pieces(order, k, k + 1, cut_before[k], finish, walk)
        cut_before[k + 1] = cut
        reached_before[k + 1] = reached_before[k] or reached
    thresholds = _suffix_thresholds(order, finish, walk)
    reaching = np.zeros(len(places), dtype=np.bool_)
    known = _later_moves_reaching(order, moved[2], finish, (cut_before, reached_before), thresholds, walk, reaching)
    for m in prange(len(places)):  # each neighbour alone: the same answer on any number of threads
        if known[m]:
            continue
        start, after = moved[0][m], moved[1][m] + 1
        reached = reached_before[start]
        if not reached:
            neighbour = order.copy()  # a neighbour is the order but for the places it changes
            for k in range(start, after):
                neighbour[k] = order[places[m, k]]
            reached, cut = walk_pieces(neighbour, start, after, cut_before[start], finish, walk)
            reached = reached or _reaches_from(order, after, cut, finish, thresholds, walk)
        reaching[m] = reached
    return reaching


@njit(cache=True)
def _reaches_from(
    order: np.ndarray,
    place: int,
    cut: float,
    finish: float,
    thresholds: tuple[np.ndarray, np.ndarray],
    walk: WalkArrays,
) -> bool:
    """Whether the order's own robots from ``place`` on, from ``cut``, reach the end at ``finish``: by the
    thresholds (``fails_up_to``, ``reaches_from``) of :func:`_suffix_thresholds`, else walked."""
    fails_up_to, reaches_from = thresholds
    if cut <= fails_up_to[place]:
        return False
    return cut >= reaches_from[place] or walk_pieces(order, place, len(order), cut, finish, walk)[0]


@njit(cache=True, parallel=True)
def _later_moves_reaching(
    order: np.ndarray,
    later: np.ndarray,
    finish: float,
    prefix: tuple[np.ndarray, np.ndarray],
    thresholds: tuple[np.ndarray, np.ndarray],
    walk: WalkArrays,
    reaching: np.ndarray,
) -> np.ndarray:
    """:func:`_reaching_at` for the moves of a place i to a later place j (``later``, :func:`_later_moves`),
    written into ``reaching``; returns which rows it decided. Such a move puts the order's robots i + 1 to j
    at places i to j - 1 and robot i at j: for one i and j rising, the walk of the robots before robot i is
    the last one's and one robot more (``prefix``: the order's cut before each place, and whether it reached
    before it)."""
    cut_before, reached_before = prefix
    agents = len(order)
    known = np.zeros(len(reaching), dtype=np.bool_)
    for i in prange(agents):  # each i writes rows of its own
        cut, reached = cut_before[i], reached_before[i]
        for j in range(i + 1, agents):
            if not reached:
                reached, cut = walk_pieces(order, j, j + 1, cut, finish, walk)  # robot j, at place j - 1
            m = later[i, j]
            if m < 0:
                continue
            known[m] = True
            if reached:
                reaching[m] = True
                continue
            at_j, after = walk_pieces(order, i, i + 1, cut, finish, walk)  # robot i, at place j
            reaching[m] = at_j or _reaches_from(order, j + 1, after, finish, thresholds, walk)
    return known


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
