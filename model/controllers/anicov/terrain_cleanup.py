"""anicov's cleanup among walls (issue 36, items 1 and 2): the stations' programme again, on what is left.

The flight is not the programme: a robot passes a station a little off, the safety filter holds it, a turn
between bearings sweeps less than a stare. So routes leave cells short, scattered over the map. Sending
free robots to those cells one by one, nearest first, crosses the building back and forth (measured on the
lab, N = 1: 32 cells left when the tour ended took 900 of the run's 3,300 time units). Instead:

- **What is left to others** (:func:`residual_lack`): Υ less what the stops and legs still ahead on the busy
  robots' routes will add (:class:`model.controllers.anicov.deposit.Deposit`'s stares and legs, the
  programme's model), so that a free robot does not clean up what a teammate is about to see.
- **The stations** (:func:`cleanup_stations`): the reachable cells within R of a short cell, every
  :data:`CANDIDATE_STRIDE`-th row and column, plus a seer of its own for a short cell none of them sees (with a
  localiser's noise, or sees too little for :data:`MOST_PERIODS`: :mod:`model.controllers.anicov.terrain_seers`); the
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
from model.controllers.anicov.terrain_seers import SURE_SPREADS, with_seers
from model.controllers.anicov.terrain_stations import ANGLES
from model.planning import path_lengths
from model.scenario import Scenario
from model.scenario.physics_keys import localiser_sigma_of
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
    wanted_all = np.minimum(CLEANUP_DEMAND * need.ravel() + CLEANUP_MARGIN, 1.0)
    least = _least_a_period(world.scenario, wanted_all)
    stations, stares = with_seers(world, deposit, short, (stations, stares), banned, least)
    rows = np.flatnonzero(short.ravel() & (np.asarray(stares.sum(axis=1)).ravel() > 0.0))
    if not len(rows):
        return empty
    demand = stares.tocsr()[rows]
    wanted = wanted_all[rows]
    periods = _fewest_stations(demand.tocsc(), wanted, world.scenario).reshape(len(stations), len(ANGLES))
    used = periods.sum(axis=1) > 0
    return _merged(stations[used], periods[used])


def _least_a_period(scenario: Scenario, wanted: np.ndarray) -> np.ndarray:
    """What a short cell's stations must bring it in a period (Λ*, their best bearings summed) before it is left
    without a seer of its own (:func:`terrain_seers.with_seers`): with a localiser's noise, ``wanted`` over
    :data:`MOST_PERIODS` (the most the programme gives a station); else any stare at all (0). A cell that the
    candidates reach only at a wedge's rim, through the spread of a sure stare, was otherwise stared at for the
    relaxed programme's hundreds of periods (the MRPT lab, N = 10, seed 0: 710 periods at 0.0014 Λ*, 355 time
    units of a 601.3 run, where its own seer's stares bring 0.071)."""
    if localiser_sigma_of(scenario) > 0.0:
        return wanted / MOST_PERIODS
    return np.zeros_like(wanted)


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
