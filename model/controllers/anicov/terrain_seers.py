"""A short cell's own seer among walls, for anicov's cleanup (:mod:`model.controllers.anicov.terrain_cleanup`).

The cleanup's candidate stations lie on a coarse lattice of reachable cells, and some short cells none of their
sure stares reaches: a cell seen past a wall's corner, or through a gap in a SLAM map's unscanned islands, is
seen from a sliver of the floor. Such a cell gets a station of its own (:func:`with_seers`): among the places
about the nearest cells whose centres see it (:func:`seer_places`), one whose stare reaches it from everywhere
a robot standing there may be (:func:`sure_seer`), over the widest spread that any does.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import csc_matrix, hstack

from model.controllers.anicov.deposit import Deposit
from model.controllers.anicov.route import face_radius_of
from model.controllers.anicov.terrain_stations import ANGLES
from model.scenario.physics_keys import localiser_sigma_of
from model.world.geodesic import in_sight
from model.world.reachability import in_reachable_cell
from model.world.world import World

SURE_SPREADS = 1.5
"""A stare is sure when it reaches a cell from every point this many face radii from its station. A robot may
stand up to its arrival radius off (route.arrive_radius_of, at most a step); sure over 1.5 arrival radii, the
lab's cleanups asked for stares too few cells pass and its runs stalled (four of four trials), so the spread
stays the face radius's, which held in every run of the study."""
SEER_SPREADS = (SURE_SPREADS, 0.5, 0.0)
"""The spreads, in face radii, a short cell's own seer is sure over (:func:`sure_seer`), widest first: a cell seen
only through a gap, from one cell's centre, is seen from no point a noisy localiser's face radius round it
(the MRPT lab, σ 0.05 m on cells of 0.2 m: 7 - 16 cells stood short for ever with no station, the run never done).
A narrower seer may be flown in vain; its cleanup is then judged and banned (:mod:`terrain_flight`)."""
SEERS_TRIED = 5
"""A short cell that no candidate's sure stare reaches (with noise, or brings too little: :func:`with_seers`) tries
this many of its nearest seers."""
SHIFT_SPREADS = 3.0
"""How far from a seer's centre, in face radii, a station that surely sees past a wall's corner is tried."""
FINE_RINGS = 4
"""With a localiser's noise, a seer is also tried on rings 1, 2, ... this many face radii from its centre, the
k-th ring at 8 k points (about 0.8 face radii apart), after the centres and the ring of :data:`SHIFT_SPREADS`,
whose finds are kept. The face radius is then a quarter of a cell on the MRPT lab (σ 0.05 m, cells of 0.2 m), and
8 points 0.15 m off jump over the sliver from which a cell seen through a gap in the SLAM map's islands is seen.
Of the lab's 2,426 coverable cells, 11 had no station sure over 1.5 face radii, and 3 of them get one on these
rings; a robot arriving 1 σ off a station sure over less may see nothing of its cell (N = 10, seed 1: the cell
(41, 56) given up at t = 797 before the rings, complete with them). Without noise the face radius is half a
step, and the runs stay as they were (the rings are not tried)."""


def with_seers(
    world: World,
    deposit: Deposit,
    short: np.ndarray,
    candidates: tuple[np.ndarray, csc_matrix],
    banned: frozenset[tuple[int, int]],
    least: np.ndarray,
) -> tuple[np.ndarray, csc_matrix]:
    """(stations, their sure stares): ``candidates`` and, while a short cell lies outside every stare, or their
    best bearings (:func:`best_bearings`) bring it less than ``least`` a period (Λ*, flat; 0 asks only for a
    stare), a station that surely sees it (:func:`sure_seer`, asked for what the others leave of ``least``; a cell
    none sees is left: the engine's watchdog reports what no robot can cover). Each cell is tried once."""
    stations, stares = candidates
    brought = best_bearings(stares)
    tried = np.zeros(brought.shape, dtype=bool)
    waiting = np.flatnonzero(short.ravel() & _wants_a_seer(brought, least))
    added, blocks = [], [stares]
    while len(waiting):
        flat = int(waiting[0])
        found = sure_seer(world, deposit, flat, banned, max(0.0, float(least[flat] - brought[flat])))
        if found is not None:
            added.append(found[0][None, :])
            blocks.append(found[1])
            brought = brought + best_bearings(found[1])
        tried[flat] = True  # tried once
        waiting = waiting[~tried[waiting] & _wants_a_seer(brought[waiting], least[waiting])]
    return np.vstack([stations.reshape(-1, 2), *added]), hstack(blocks).tocsc()


def _wants_a_seer(brought: np.ndarray, least: np.ndarray) -> np.ndarray:
    """Whether cells whose stations bring ``brought`` a period (:func:`best_bearings`) want a seer of their own:
    where nothing reaches them, or less than ``least`` does."""
    return (brought <= 0.0) | (brought < least)


def best_bearings(stares: csc_matrix) -> np.ndarray:
    """Per cell (flat), the sum over the stations of ``stares`` (columns station by station, bearing by bearing)
    of what its best bearing brings in a period (Λ*)."""
    bearings = len(ANGLES)
    best = stares[:, 0::bearings]
    for bearing in range(1, bearings):
        best = best.maximum(stares[:, bearing::bearings])
    return np.asarray(best.sum(axis=1)).ravel()


def sure_seer(
    world: World, deposit: Deposit, flat: int, banned: frozenset[tuple[int, int]], enough: float = 0.0
) -> tuple[np.ndarray, csc_matrix] | None:
    """(station, its sure stares) that reach the cell ``flat``: among the places of :func:`seer_places`, the first that
    sees it from everywhere a robot standing there may be (a cell seen past a wall's corner is seen from one
    side of a line through the seer, not the other) and whose best bearing brings it at least ``enough`` a period
    (Λ*), over :data:`SEER_SPREADS`' widest spread; where none brings that much, the one that brings most (the
    first on a tie); where none is sure, the same over each narrower spread in turn. ``enough`` is 0 but for a
    localiser's noise (:func:`with_seers`): the first sure place may see the cell only at its wedge's rim (the
    MRPT lab's cell (41, 22): 0.0034 Λ* a period, and a programme past
    :data:`model.controllers.anicov.terrain_cleanup.MOST_PERIODS`, where another place 0.1 m from it brings
    0.027). The best place of all, not the first that is enough, made the lab's noisy run at N = 1, seed 0, take
    3,135.5 time units against 2,547.7. A place whose own stare does not reach the cell is not tried over any
    spread (a sure stare is the least of its own and its neighbours')."""
    face = face_radius_of(world.scenario)
    places = seer_places(world, flat, banned)
    reaches: dict[int, bool] = {}  # whether a place's own stare reaches the cell: else no spread's can
    for spread in SEER_SPREADS:  # the places tried once, over each spread in turn
        best: tuple[float, np.ndarray, csc_matrix] | None = None
        for index, place in enumerate(places):
            if index not in reaches:
                reaches[index] = bool(deposit.stares(place[None, :], ANGLES)[flat].sum() > 0.0)
            if not reaches[index]:
                continue
            stares = deposit.sure_stares(place[None, :], ANGLES, spread * face)
            brings = float(stares[flat].max())
            if brings > 0.0 and brings >= enough:
                return place, stares
            if brings > 0.0 and (best is None or brings > best[0]):
                best = (brings, place, stares)
        if best is not None:
            return best[1], best[2]
    return None


def seer_places(world: World, flat: int, banned: frozenset[tuple[int, int]]) -> list[np.ndarray]:
    """The places a short cell's own seer may stand (:func:`sure_seer`), in the order tried: the centres of the
    :data:`SEERS_TRIED` nearest seers not banned (:meth:`World.seers_of`, the cells whose centres see it) and
    the points :data:`SHIFT_SPREADS` face radii from each toward one of 8 ways, then, with a localiser's noise,
    the points of :func:`fine_rings`; each where the disk with its clearance fits, in sight of its seer."""
    scenario = world.scenario
    cell, face = scenario.cell, face_radius_of(scenario)
    row, col = divmod(flat, scenario.grid_shape[1])
    seers = [s for s in world.seers_of((col + 0.5) * cell, (row + 0.5) * cell)[:, 1:] if cell_of(s, cell) not in banned]
    ways = np.array([(np.cos(a), np.sin(a)) for a in np.arange(8) * np.pi / 4])
    groups = [np.vstack([np.zeros((1, 2)), SHIFT_SPREADS * face * ways])]
    if localiser_sigma_of(scenario) > 0.0:  # after the others: what they find is kept
        groups.append(fine_rings(face))
    ground = world.ground
    places = []
    for offsets in groups:
        for seer in seers[:SEERS_TRIED]:
            for place in seer + offsets:
                if not in_reachable_cell(world.reachable, *place, scenario.cell):
                    continue  # a wide face radius (a noisy localiser's) shifts it off the team's space
                if not in_sight(ground.wall_grid, *seer, *place, ground.grain, ground.plan_radius, ground.bounded):
                    continue  # the disk with its clearance does not fit there: the filter would hold it short
                places.append(place)
    return places


def fine_rings(face: float) -> np.ndarray:
    """(M, 2) the offsets of :data:`FINE_RINGS`' points from a seer's centre, ring by ring, less the 8 of the ring
    :data:`SHIFT_SPREADS` off (tried before them: tried again, they would find nothing new)."""
    rings = [np.zeros((0, 2))]
    for ring in range(1, FINE_RINGS + 1):
        steps = np.arange(8 * ring)
        if ring == SHIFT_SPREADS:
            steps = steps[steps % ring != 0]  # the 8 ways every 45°
        angles = steps * 2.0 * np.pi / (8 * ring)
        rings.append(ring * face * np.stack([np.cos(angles), np.sin(angles)], axis=1))
    return np.vstack(rings)


def cell_of(point: np.ndarray, cell: float) -> tuple[int, int]:
    """(row, col) of the cell about ``point``."""
    return int(point[1] // cell), int(point[0] // cell)
