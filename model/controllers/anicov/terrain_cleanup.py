"""anicov's cleanup among walls (issue 36, items 1 and 2): the stations' programme again, on what is left.

The flight is not the programme: a robot passes a station a little off, the safety filter holds it, a turn
between bearings sweeps less than a stare. So routes leave cells short, scattered over the map. Sending
free robots to those cells one by one, nearest first, crosses the building back and forth (measured on the
lab, N = 1: 32 cells left when the tour ended took 900 of the run's 3,300 time units). Instead:

- **What is left to others** (:func:`residual_lack`): Υ less what the stops and legs still ahead on the busy
  robots' routes will add (:class:`model.controllers.anicov.deposit.Deposit`'s stares and legs, the
  programme's model), so that a free robot does not clean up what a teammate is about to see.
- **The stations** (:func:`cleanup_stations`): the reachable cells within R of a short cell, every
  :data:`CANDIDATE_STRIDE`-th row and column, plus a seer of its own for a short cell none of them sees; the
  least periods of their stares that bring each short cell :data:`CLEANUP_DEMAND` of its lack (the relaxed
  programme, then whole periods: :func:`model.controllers.anicov.stations.whole_periods`).
- **Who flies them** (:func:`cleanup_pieces`): the stations in a tour by free-path length from the one nearest
  the first free robot (nearest first, then 2-opt), cut at stations into as many pieces of about equal time
  as there are free robots (or stations), and each piece given so that the slowest robot's free path to it
  plus the piece is least. A station is never split between two robots.
"""

from __future__ import annotations

import itertools
import math

import cv2
import numpy as np
from scipy.optimize import Bounds, LinearConstraint, linprog, milp
from scipy.sparse import csc_matrix, hstack, identity, vstack

from model.controllers.anicov.deposit import Deposit
from model.controllers.anicov.route import CARROT_PERIOD, Route, face_radius_of
from model.controllers.anicov.routes import bottleneck_assignment
from model.controllers.anicov.stations import bearing_sequence, whole_periods
from model.controllers.anicov.terrain_routes import station_tour, travel_lengths
from model.controllers.anicov.terrain_stations import ANGLES
from model.planning import path_lengths
from model.scenario import Scenario
from model.world.geodesic import in_sight
from model.world.reachability import in_reachable_cell
from model.world.world import World

CLEANUP_DEMAND = 1.1
"""The share of a short cell's lack its cleanup stares aim for: a little over, as the flight brings a little
less than the stares it counts (:data:`model.controllers.anicov.stations.PATCH_DEMAND` on the open square)."""
CLEANUP_MARGIN = 0.05
"""Λ* added to what a short cell's cleanup stares aim for: a cell short by a hair is otherwise aimed at by a
stare that brings a hair, and the flight brings a little less."""
STATION_HOPS = 1.0
"""What using a station costs in the cleanup's programme: this many hops of R at k_v, in periods (a cleanup
flies between scattered stations, and a station less saves its hop)."""
MOST_PERIODS = 48
"""The most periods a cleanup station may stare (two full turns of its bearings)."""
NODE_LIMIT = 2000
"""Branch-and-bound nodes HiGHS may explore for the cleanup's programme: a limit of work, not of time, so that
every machine finds the same stations."""
LARGE_PROGRAMME = 300
"""Stares (variables) above which the programme is large and gets :data:`LARGE_NODE_LIMIT` nodes: each node's
relaxation costs more, and more nodes gain little. The studies' cleanups have at most 135 (campus N = 8); a
robot planning on a replica that missed its teammates' steps (a limited radio) met 556 - 704, at 23 - 55 s
each with NODE_LIMIT; on the 556 one 200 nodes found 799 periods in 9.5 s, 10 nodes 803 in 2.3 s."""
LARGE_NODE_LIMIT = 20
PATCH_REACH = 0.25
"""A station patches a short cell only where one period of its stare brings at least this share of what the
cell lacks."""
SURE_SPREADS = 1.5
"""A stare is sure when it reaches a cell from every point this many face radii from its station. A robot may
stand up to its arrival radius off (route.arrive_radius_of, at most a step); sure over 1.5 arrival radii, the
lab's cleanups asked for stares too few cells pass and its runs stalled (four of four trials), so the spread
stays the face radius's, which held in every run of the study."""
SEER_SPREADS = (SURE_SPREADS, 0.5, 0.0)
"""The spreads, in face radii, a short cell's own seer is sure over (:func:`_sure_seer`), widest first: a cell seen
only through a gap, from one cell's centre, is seen from no point a noisy localiser's face radius round it
(the MRPT lab, σ 0.05 m on cells of 0.2 m: 7 - 16 cells stood short for ever with no station, the run never done).
A narrower seer may be flown in vain; its cleanup is then judged and banned (:mod:`terrain_flight`)."""
SEERS_TRIED = 5
"""A short cell that no candidate's sure stare reaches tries this many of its nearest seers."""
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
CANDIDATE_STRIDE = 3
"""Candidate stations lie on every this-many-th row and column of reachable cells (at 36 µs a stare and 24
bearings, a few hundred candidates cost a few tenths of a second)."""


def residual_lack(
    deposit: Deposit, lack: np.ndarray, routes: list[Route], around: tuple[np.ndarray, float] | None = None
) -> np.ndarray:
    """Υ (grid) less what the stops and the legs still ahead on ``routes`` will add, at least 0; ``around``
    (point, radius): only the stops and legs within the radius of the point are counted (a camera reaches R:
    those farther than 2 R from a point add nothing within R of it). The legs count since the tour's stares
    are planned beside what its hops see (:mod:`model.controllers.anicov.terrain_plan`): a robot leaving a
    station that counted only stops patched there what its own next hop was to see (office, N = 1: 2,455.1
    time units against 1,788.7)."""
    expected = np.zeros(lack.size)
    for route in routes:
        for stop in route.stops:
            x, y = route.point_at(stop.at)
            if around is not None and math.hypot(x - around[0][0], y - around[0][1]) > around[1]:
                continue
            for bearing in stop.bearings:
                flat, added = deposit.stare_cells(float(x), float(y), float(bearing))
                expected[flat] += added  # one stare reaches each cell once
        for a, b in legs_ahead(route, around):
            flat, added = deposit.leg_cells(a, b)
            expected[flat] += added
    return np.maximum(lack.ravel() - expected, 0.0).reshape(lack.shape)


def legs_ahead(route: Route, around: tuple[np.ndarray, float] | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """The legs of ``route`` still to fly, from where the robot has come (its leg begun, from that point), those
    that pass within ``around``'s radius of its point if given."""
    ahead = route.points[route.along > route.progress + 1e-9]
    points = np.vstack([route.point_at(route.progress)[None, :], ahead])
    legs = list(itertools.pairwise(points))
    if around is None:
        return legs
    centre, radius = around
    return [(a, b) for a, b in legs if _gap_to_leg(centre, a, b) <= radius]


def _gap_to_leg(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    leg = b - a
    length = float(leg @ leg)
    along = 0.0 if length == 0.0 else min(max(float((point - a) @ leg) / length, 0.0), 1.0)
    return float(np.linalg.norm(a + along * leg - point))


def station_patch(
    world: World,
    deposit: Deposit,
    lack: np.ndarray,
    station: np.ndarray,
    routes: list[Route],
    turns: tuple[float | None, float | None],
) -> list[float]:
    """The bearings (one per period) a robot standing at ``station`` faces to finish the short cells near it that
    no stop still on ``routes`` will (:func:`residual_lack`): those its sure stares there bring, in one period,
    at least :data:`PATCH_REACH` of what they lack (a cell at the wedge's rim is left to a nearer station), to
    :data:`CLEANUP_DEMAND` of it; the least periods (the relaxed programme made whole), flown in one sweep from
    the heading it faces to the way it leaves (``turns``). None where none is left."""
    scenario = world.scenario
    need = residual_lack(deposit, lack, routes, (station, 2.0 * scenario.range)).ravel()
    stares = deposit.sure_stares(station[None, :], ANGLES, SURE_SPREADS * face_radius_of(scenario)).tocsr()
    wanted = np.minimum(CLEANUP_DEMAND * need + CLEANUP_MARGIN, 1.0)
    best = np.asarray(stares.max(axis=1).todense()).ravel()
    rows = np.flatnonzero(world.coverable.ravel() & (need > 0.0) & (best >= PATCH_REACH * wanted))
    if not len(rows):
        return []
    demand = stares[rows].tocsc()
    relaxed = linprog(np.ones(len(ANGLES)), A_ub=-demand, b_ub=-wanted[rows], bounds=(0, None), method="highs")
    if relaxed.x is None:
        return []
    periods = whole_periods(demand, wanted[rows], relaxed.x)
    turn = math.pi * scenario.k_omega * CARROT_PERIOD
    return bearing_sequence(periods, turns[0], turns[1], turn, turn_in=True)


def left_near(world: World, deposit: Deposit, lack: np.ndarray, station: np.ndarray, routes: list[Route]) -> np.ndarray:
    """What a robot leaving ``station`` would leave behind within R of it: the residual Υ (:func:`residual_lack`,
    every stop still on ``routes`` counted, the robot's own patch there included) of the cells within R, 0
    elsewhere."""
    scenario = world.scenario
    need = residual_lack(deposit, lack, routes, (station, 2.0 * scenario.range))
    rows, cols = np.indices(need.shape)
    centres_x, centres_y = (cols + 0.5) * scenario.cell, (rows + 0.5) * scenario.cell
    within = np.hypot(centres_x - station[0], centres_y - station[1]) <= scenario.range
    return np.where(within & world.coverable, need, 0.0)


def cleanup_stations(
    world: World, deposit: Deposit, need: np.ndarray, banned: frozenset[tuple[int, int]] = frozenset()
) -> tuple[np.ndarray, np.ndarray]:
    """(stations (K, 2), whole periods (K, BEARINGS)) whose stares bring every short coverable cell (``need``
    > 0, in Λ*) to :data:`CLEANUP_DEMAND` of its need; stations at the cells in ``banned`` (row, col) are not
    tried. Empty where nothing is short or no stare reaches what is."""
    short = world.coverable & (need > 0.0)
    empty = np.zeros((0, 2)), np.zeros((0, len(ANGLES)))
    if not short.any():
        return empty
    spread = SURE_SPREADS * face_radius_of(world.scenario)
    stations = _candidates(world, short, banned)
    stares = deposit.sure_stares(stations, ANGLES, spread)
    stations, stares = _with_seers(world, deposit, short, (stations, stares), banned)
    rows = np.flatnonzero(short.ravel() & (np.asarray(stares.sum(axis=1)).ravel() > 0.0))
    if not len(rows):
        return empty
    demand = stares.tocsr()[rows]
    wanted = np.minimum(CLEANUP_DEMAND * need.ravel()[rows] + CLEANUP_MARGIN, 1.0)
    periods = _fewest_stations(demand.tocsc(), wanted, world.scenario).reshape(len(stations), len(ANGLES))
    used = periods.sum(axis=1) > 0
    return _merged(stations[used], periods[used])


def _merged(stations: np.ndarray, periods: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The stations with those at the same point made one (a candidate and a seer may coincide), their
    periods added, in order of first appearance."""
    unique, first, inverse = np.unique(stations, axis=0, return_index=True, return_inverse=True)
    added = np.zeros((len(unique), periods.shape[1]))
    np.add.at(added, inverse.ravel(), periods)
    order = np.argsort(first, kind="stable")
    return unique[order], added[order]


def _fewest_stations(demand: csc_matrix, wanted: np.ndarray, scenario: Scenario) -> np.ndarray:
    """Whole periods per stare (column of ``demand``, station by station, bearing by bearing) that bring each
    row to ``wanted`` for the least time: the periods, plus :data:`STATION_HOPS` hops of R at k_v for every
    station used (HiGHS's branch and bound, on at most :data:`NODE_LIMIT` nodes, :data:`LARGE_NODE_LIMIT` for a
    large programme: the same answer on any machine; the relaxed programme made whole where it finds none)."""
    useful = np.flatnonzero(np.diff(demand.indptr) > 0)  # stares that reach a short cell
    owner = useful // len(ANGLES)
    stations, station_of = np.unique(owner, return_inverse=True)
    count, used = len(useful), len(stations)
    hop = STATION_HOPS * scenario.range / (scenario.k_v * CARROT_PERIOD)  # in periods
    cost = np.concatenate([np.ones(count), np.full(used, hop)])
    sums = csc_matrix((np.ones(count), (station_of, np.arange(count))), shape=(used, count))
    rows = vstack([
        hstack([demand[:, useful], csc_matrix((demand.shape[0], used))]),
        hstack([sums, -MOST_PERIODS * identity(used)]),  # Σ_b x_kb <= M y_k
    ]).tocsc()  # fmt: skip
    low = np.concatenate([wanted, np.full(used, -np.inf)])
    high = np.concatenate([np.full(len(wanted), np.inf), np.zeros(used)])
    bounds = Bounds(np.zeros(count + used), np.concatenate([np.full(count, MOST_PERIODS), np.ones(used)]))
    node_limit = NODE_LIMIT if count <= LARGE_PROGRAMME else LARGE_NODE_LIMIT
    solved = milp(
        cost, constraints=LinearConstraint(rows, low, high), integrality=np.ones(count + used),
        bounds=bounds, options={"node_limit": node_limit, "mip_rel_gap": 0.02},
    )  # fmt: skip
    periods = np.zeros(demand.shape[1])
    if solved.x is not None:
        periods[useful] = np.round(solved.x[:count])
        return periods
    relaxed = linprog(np.ones(demand.shape[1]), A_ub=-demand, b_ub=-wanted, bounds=(0, None), method="highs")
    if relaxed.x is None:
        raise ValueError(f"the cleanup's programme has no solution: {relaxed.message}")
    return whole_periods(demand, wanted, relaxed.x)


def _candidates(world: World, short: np.ndarray, banned: frozenset[tuple[int, int]]) -> np.ndarray:
    """The centres (K, 2) of the reachable cells within R of a short cell, on every
    :data:`CANDIDATE_STRIDE`-th row and column, less the banned ones."""
    cell, reach = world.scenario.cell, world.scenario.range / world.scenario.cell
    size = 2 * int(np.ceil(reach)) + 1
    disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (size, size))
    near = cv2.dilate(short.astype(np.uint8), disk).astype(bool) & world.reachable
    rows, cols = np.indices(near.shape)
    near &= (rows % CANDIDATE_STRIDE == 0) & (cols % CANDIDATE_STRIDE == 0)
    kept = [(row, col) for row, col in np.argwhere(near) if (int(row), int(col)) not in banned]
    return (np.array(kept, dtype=np.float64).reshape(-1, 2)[:, ::-1] + 0.5) * cell


def _with_seers(
    world: World,
    deposit: Deposit,
    short: np.ndarray,
    candidates: tuple[np.ndarray, csc_matrix],
    banned: frozenset[tuple[int, int]],
) -> tuple[np.ndarray, csc_matrix]:
    """While a short cell lies outside every stare (``candidates``: stations and their sure stares), a station
    that surely sees it joins them (:func:`_sure_seer`; a cell none sees is left: the engine's watchdog reports
    what no robot can cover)."""
    stations, stares = candidates
    seen = np.asarray(stares.sum(axis=1)).ravel() > 0.0
    waiting = np.flatnonzero(short.ravel() & ~seen)
    added, blocks = [], [stares]
    while len(waiting):
        found = _sure_seer(world, deposit, int(waiting[0]), banned)
        if found is not None:
            added.append(found[0][None, :])
            blocks.append(found[1])
            seen |= np.asarray(found[1].sum(axis=1)).ravel() > 0.0
        seen[waiting[0]] = True  # tried once
        waiting = waiting[~seen[waiting]]
    return np.vstack([stations.reshape(-1, 2), *added]), hstack(blocks).tocsc()


def _sure_seer(
    world: World, deposit: Deposit, flat: int, banned: frozenset[tuple[int, int]]
) -> tuple[np.ndarray, csc_matrix] | None:
    """(station, its sure stares) that reach the cell ``flat``: among the :data:`SEERS_TRIED` nearest seers not
    banned (:meth:`World.seers_of`, the cells whose centres see it), the first whose centre, or a point
    :data:`SHIFT_SPREADS` face radii from it toward one of 8 ways, sees it from everywhere a robot standing there
    may be (a cell seen past a wall's corner is seen from one side of a line through the seer, not the other),
    then, with a localiser's noise, the points of :func:`fine_rings`; where none does, the same over each
    narrower spread of :data:`SEER_SPREADS`. A place whose own stare does not reach the cell is not tried
    over any spread (a sure stare is the least of its own and its neighbours')."""
    scenario = world.scenario
    cell, face = scenario.cell, face_radius_of(scenario)
    row, col = divmod(flat, scenario.grid_shape[1])
    seers = [s for s in world.seers_of((col + 0.5) * cell, (row + 0.5) * cell)[:, 1:] if cell_of(s, cell) not in banned]
    ways = np.array([(np.cos(a), np.sin(a)) for a in np.arange(8) * np.pi / 4])
    groups = [np.vstack([np.zeros((1, 2)), SHIFT_SPREADS * face * ways])]
    if dict(scenario.noise).get("localiser_sigma", 0.0) > 0.0:  # after the others: what they find is kept
        groups.append(fine_rings(face))
    ground = world.ground
    stations = []
    for offsets in groups:
        for seer in seers[:SEERS_TRIED]:
            for station in seer + offsets:
                if not in_reachable_cell(world.reachable, *station, scenario.cell):
                    continue  # a wide face radius (a noisy localiser's) shifts it off the team's space
                if not in_sight(ground.wall_grid, *seer, *station, ground.grain, ground.plan_radius, ground.bounded):
                    continue  # the disk with its clearance does not fit there: the filter would hold it short
                stations.append(station)
    reaches: dict[int, bool] = {}  # whether a place's own stare reaches the cell: else no spread's can
    for spread in SEER_SPREADS:  # the places tried once, over each spread in turn
        for index, station in enumerate(stations):
            if index not in reaches:
                reaches[index] = bool(deposit.stares(station[None, :], ANGLES)[flat].sum() > 0.0)
            if not reaches[index]:
                continue
            stares = deposit.sure_stares(station[None, :], ANGLES, spread * face)
            if stares[flat].sum() > 0.0:
                return station, stares
    return None


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


def cleanup_pieces(
    world: World, stations: np.ndarray, periods: np.ndarray, positions: np.ndarray
) -> list[tuple[np.ndarray, np.ndarray]]:
    """For each free robot at ``positions`` (F, 2), its piece: (stations in the order flown, their periods),
    both empty for a robot given none (see the module)."""
    scenario = world.scenario
    robots, count = len(positions), len(stations)
    if not count:
        return [(np.zeros((0, 2)), np.zeros((0, len(ANGLES))))] * robots
    reach = path_lengths(world, positions, stations)  # (F, K)
    first = int(np.argmin(reach[0]))
    order = np.array([first, *[k for k in range(count) if k != first]])
    lengths = travel_lengths(world, stations[order])
    order = order[station_tour(lengths)]
    lengths = travel_lengths(world, stations[order])
    stay = periods[order].sum(axis=1) * CARROT_PERIOD * scenario.k_v  # each station's periods, as k_v travel
    hops = np.concatenate([[0.0], np.diagonal(lengths, offset=1)])
    cuts = _cuts(np.cumsum(stay + hops), min(robots, count))
    cost = np.zeros((robots, robots))  # pieces beyond the cuts' are empty, at no cost
    for piece, (start, end) in enumerate(itertools.pairwise(cuts)):
        time = float(stay[start:end].sum() + hops[start + 1 : end].sum())
        cost[:, piece] = reach[:, order[start]] + time
    given, pieces = bottleneck_assignment(np.where(np.isfinite(cost), cost, 1e12))
    out = [(np.zeros((0, 2)), np.zeros((0, len(ANGLES))))] * robots
    for robot, piece in zip(given, pieces, strict=True):
        if piece < len(cuts) - 1:
            chosen = order[cuts[piece] : cuts[piece + 1]]
            out[int(robot)] = (stations[chosen], periods[chosen])
    return out


def _cuts(elapsed: np.ndarray, pieces: int) -> list[int]:
    """Station indices [0, c_1, ..., K] cutting a tour whose station k ends at ``elapsed[k]`` into ``pieces``
    non-empty runs of about equal time: each cut at the station boundary nearest its share of the total."""
    count, total = len(elapsed), float(elapsed[-1])
    cuts = [0]
    for piece in range(1, pieces):
        target = total * piece / pieces
        boundary = int(np.argmin(np.abs(elapsed - target))) + 1  # cut after the station ending nearest it
        low, high = cuts[-1] + 1, count - (pieces - piece)
        cuts.append(min(max(boundary, low), high))
    return [*cuts, count]
