"""The ``anicov`` controller's stations: robots that stand and turn their camera, then hop to the next place.

Beyond the paper (docs/controller.md has the measurements). The sensor's ability (eq. 2) over its wedge adds
up to t*_1's rate, 15.7 area of Λ* per time unit on the paper's sensor (eq. 19), wherever it points; the
question is only how much of it lands on cells already at Λ* or outside the domain. A straight pass at k_v
pours 5 Λ* onto its own course; a robot standing and turning its heading spreads its wedge over a disc of
radius R with a cone's profile, and the cones of neighbouring stations add up (eq. 3) to a nearly flat
field. What it pays is the hops between stations, and a hop is path and time that a sweep pays too.

- **Where the robots stand** (:func:`layout`): a grid of stations at most one of :data:`SPACINGS_PER_RANGE` R
  apart (whichever takes the least time), the outer ones :data:`MARGIN_PER_RANGE` R inside the edges,
  visited row by row (or column by column), turning at each row's end (a serpentine).
- **Which way they look, and how long**: in each plan period (:data:`model.controllers.anicov.route.CARROT_PERIOD`) a
  robot at a station faces one of :data:`BEARINGS` bearings. How many periods each station spends at each
  bearing is a linear programme (scipy's HiGHS): the fewest periods for which the stations' stares and the
  hops between them (eq. 2-3 summed cell by cell, :mod:`model.controllers.anicov.deposit`) bring every cell to Λ*, made
  whole by :func:`whole_periods`. The periods of a station are flown in one sweep of the bearings it needs, counterclockwise from the
  one after its largest gap (:func:`bearing_sequence`).
- **Who goes where**: the serpentine as a line in time (hops at k_v, stations as their periods) is cut for an
  order of robots exactly as the spiral is (:mod:`model.controllers.anicov.piece_order`: each robot's transit plus its share
  takes every robot the same time), on each of the domain's 4 mirror images and both serpentines; the
  order is improved by the same local search on the :data:`model.controllers.anicov.routes.ORDERED_VARIANTS` soonest, and the
  soonest is flown.
- **What the flight leaves short** (:func:`with_patched_stops`): the routes are flown as the engine flies
  them, and a cell left short gets periods put in at a station near it, facing it.

The messages stay the paper's: the carrot at a station is a point :data:`FACE_RADIUS` / 2 from the robot in
the bearing to face, and the law (:func:`model.paper.control.pursuit_law`) stands and turns toward a carrot so
near. Lockstep over Zenoh still equals the engine byte for byte (the planner reads only positions).
"""

from __future__ import annotations

import dataclasses
import functools
import heapq
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import csc_matrix, csr_matrix

from model.controllers.anicov.deposit import Deposit
from model.controllers.anicov.order_search import improved_order
from model.controllers.anicov.piece_order import Spiral, cuts_for, order_finishes
from model.controllers.anicov.route import CARROT_PERIOD, Route, Stop
from model.controllers.anicov.routes import ORDERED_VARIANTS
from model.controllers.anicov.touch_ups import simulate_routes
from model.paper.polyline import point_along
from model.scenario import Scenario

BEARINGS = 24
"""Bearings a robot at a station may face (15° apart): the wedge (2F = 54° on the paper's sensor) laid at
neighbouring bearings overlaps, so their stares add up to a smooth fan. Measured (6 seeds, the paper's
square, N = 4 / 10): 16 bearings 2.27 / 2.47 t*, 24 2.28 / 2.36."""
SPACINGS_PER_RANGE = (1.1, 1.25)
"""Stations lie at most one of these shares of R apart: whichever takes the least time (the programme's
stares and the hops at k_v; 25 units on the paper's sensor, 11 on the strip's)."""
MARGIN_PER_RANGE = 0.15
"""The outer stations lie this share of R inside the edges (3 units on the paper's sensor)."""
DEMAND = 1.0
"""The programme asks this share of Λ* of every cell. The robots' turns between bearings, their way in and
out of a station and the hops as the law flies them differ a little from the stares and straight hops it
counts; what that leaves short is patched where it falls (:func:`with_patched_stops`), which costs less than
a margin everywhere. Measured (6 seeds, N = 1 / 30 on the paper's square, N = 1 on the strip, one round of
patches to the same demand): 1.18 2.12 / 2.87, 1.70; 1.12 2.03 / 2.79, 1.62; 1.06 1.98 / 2.79, 1.57; 1.03
1.96 / 2.78, 1.54; 1.0 1.93 / 2.83, 1.60; 1.0 with two rounds to :data:`PATCH_DEMAND` 1.94 / 2.71, 1.51."""
PATCH_DEMAND = 1.06
"""The share of Λ* that periods put in at stations aim for, in a cell the flight leaves short."""
PATCH_ROUNDS = 2
"""How many times the routes are flown and patched (a third round changed no mean of 6 seeds × 7 cases)."""
NEAREST_PATCH_CELLS = 1.0
"""A foretold short cell is not patched from a station nearer than this many cells: there the wedge's apex
sees it or not as the robot stands a few hundredths off the station (a stare's deposit there is not what
the flight brings)."""
TURN_PER_PERIOD = math.pi / 2
"""The most a robot turns in one plan period at the bound π k_ω, for k_ω = 1 (the layout passes its
scenario's)."""


@dataclass(frozen=True)
class Layout:
    """Stations in the order flown (K, 2) and, for each, the bearings (radians) it faces, one per plan
    period."""

    stations: np.ndarray
    bearings: tuple[tuple[float, ...], ...]

    def mirrored(self, width: float, height: float, flip_x: bool, flip_y: bool) -> Layout:
        """The same layout in the domain's mirror image (bearings mirrored too)."""
        stations = self.stations.copy()
        bearings = [np.array(b) for b in self.bearings]
        if flip_x:
            stations[:, 0] = width - stations[:, 0]
            bearings = [math.pi - b for b in bearings]
        if flip_y:
            stations[:, 1] = height - stations[:, 1]
            bearings = [-b for b in bearings]
        return Layout(stations, tuple(tuple(float(math.remainder(b, 2 * math.pi)) for b in bs) for bs in bearings))


def grid(width: float, height: float, spacing: float, margin: float, by_columns: bool) -> np.ndarray:
    """Stations at most ``spacing`` apart, ``margin`` inside the edges, in serpentine order: row by row from
    the bottom left (or column by column)."""
    xs = np.linspace(margin, width - margin, max(1, math.ceil((width - 2 * margin) / spacing - 1e-9) + 1))
    ys = np.linspace(margin, height - margin, max(1, math.ceil((height - 2 * margin) / spacing - 1e-9) + 1))
    outer, inner = (xs, ys) if by_columns else (ys, xs)
    points = []
    for k, a in enumerate(outer):
        for b in inner if k % 2 == 0 else inner[::-1]:
            points.append((a, b) if by_columns else (b, a))
    return np.array(points, dtype=np.float64)


def bearing_sequence(
    periods: np.ndarray,
    arrive: float | None = None,
    leave: float | None = None,
    turn: float = TURN_PER_PERIOD,
    turn_in: bool = False,
) -> list[float]:
    """The bearings (radians) to face, one per period, for ``periods`` (BEARINGS,) periods at each: one sweep
    over the bearings needed, from the one after the largest gap between them counterclockwise (or back from
    its other end, clockwise, whichever turns less from ``arrive``, the heading the robot comes in with, and
    to ``leave``, the way to the next station), with a bearing put in wherever two needed ones lie more than
    a period's ``turn`` apart, and one period facing ``leave`` at the end where the last bearing is more than a
    bearing's step from it (the law backs up toward a carrot behind it)."""
    width = 2.0 * math.pi / BEARINGS
    needed = [b for b in range(BEARINGS) if periods[b] > 0]
    if not needed:
        return []
    gaps = [((needed[(k + 1) % len(needed)] - needed[k]) % BEARINGS or BEARINGS, k) for k in range(len(needed))]
    _, widest = max(gaps)
    start = needed[(widest + 1) % len(needed)]
    span = (needed[widest] - start) % BEARINGS
    step = max(1, int(turn / width + 1e-9))
    sweep: list[int] = []
    last = start
    for offset in range(span + 1):
        bearing = (start + offset) % BEARINGS
        if periods[bearing] <= 0:
            continue
        while (bearing - last) % BEARINGS > step:  # a turn longer than a period: face the way between
            last = (last + step) % BEARINGS
            sweep.append(last)
        sweep += [bearing] * int(periods[bearing])
        last = bearing
    ways = [[b * width for b in sweep], [b * width for b in reversed(sweep)]]
    sequence = min(ways, key=lambda way: _turn(arrive, way[0]) + _turn(way[-1], leave))
    if leave is not None and _turn(sequence[-1], leave) > width + 1e-9:
        sequence.append(leave)
    if turn_in and arrive is not None:
        sequence = _turning_in(arrive, sequence[0], turn) + sequence
    return sequence


def _turning_in(arrive: float, first: float, turn: float) -> list[float]:
    """The bearings a robot faces while it turns from ``arrive`` to ``first`` at ``turn`` a period, the last
    period's turn excluded (a stare's period begins facing its bearing, not turning to it)."""
    gap = math.remainder(first - arrive, 2.0 * math.pi)
    steps = int(abs(gap) / turn - 1e-9)
    return [arrive + gap * k / (steps + 1) for k in range(1, steps + 1)]


def _turn(a: float | None, b: float | None) -> float:
    """The turn (radians, 0 - π) from heading ``a`` to ``b``; none where either is not given."""
    return 0.0 if a is None or b is None else abs(math.remainder(b - a, 2.0 * math.pi))


def layout(scenario: Scenario, by_columns: bool) -> Layout:
    """The stations of a serpentine and the bearings each faces (the linear programme of the module), at
    whichever of :data:`SPACINGS_PER_RANGE` takes the least time (its stares and hops at k_v); computed once
    per process for all the teams, seeds and time limits of one domain and sensor (a sweep's runs share it:
    1.5 s on the paper's square, 4.9 s on the strip)."""
    return _layout(dataclasses.replace(scenario, agents=1, seed=0, max_time=1.0), by_columns)


def forget_layouts() -> None:
    """Drop the layouts computed so far in this process (a benchmark times them afresh)."""
    _layout.cache_clear()


@functools.cache
def _layout(scenario: Scenario, by_columns: bool) -> Layout:
    """:func:`layout` of a scenario whose team, seed and time limit are set aside."""
    width, height = scenario.domain
    margin = MARGIN_PER_RANGE * scenario.range
    grids: dict[bytes, np.ndarray] = {}
    for share in SPACINGS_PER_RANGE:  # two shares may give the same grid
        stations = grid(width, height, share * scenario.range, margin, by_columns)
        grids.setdefault(stations.tobytes(), stations)
    layouts = [_programme(scenario, stations) for stations in grids.values()]
    return min(layouts, key=lambda chosen: float(station_times(chosen, scenario.k_v)[1][-1]))


def _programme(scenario: Scenario, stations: np.ndarray) -> Layout:
    """The bearings each of ``stations`` faces and for how many periods (the linear programme of the
    module, in whole periods), in the order of a sweep (:func:`bearing_sequence`)."""
    deposit = Deposit(scenario)
    stares = deposit.stares(stations, 2.0 * math.pi * np.arange(BEARINGS) / BEARINGS)
    need = np.maximum(DEMAND - deposit.hops(stations), 0.0)
    reachable = np.asarray(stares.sum(axis=1)).ravel() > 0.0
    if not reachable.all():  # stations at most 0.88 R from any point never leave one out; a guard all the same
        raise ValueError(f"stations {len(stations)} leave {int((~reachable).sum())} cells out of view")
    solved = linprog(np.ones(stares.shape[1]), A_ub=-stares, b_ub=-need, bounds=(0, None), method="highs")
    if solved.x is None:
        raise ValueError(f"no station layout covers the domain: {solved.message}")
    periods = whole_periods(stares, need, solved.x).reshape(len(stations), BEARINGS)
    ways = np.arctan2(*np.diff(stations, axis=0)[:, ::-1].T) if len(stations) > 1 else np.zeros(0)
    turn = math.pi * scenario.k_omega * CARROT_PERIOD
    bearings = tuple(
        tuple(bearing_sequence(row, ways[k - 1] if k else None, ways[k] if k < len(ways) else None, turn))
        for k, row in enumerate(periods)
    )
    return Layout(stations, bearings)


def whole_periods(stares: csc_matrix, need: np.ndarray, relaxed: np.ndarray) -> np.ndarray:
    """Whole periods (int, per column of ``stares``) that bring every cell to ``need``, from the linear
    programme's ``relaxed`` solution: its periods rounded down, then one period at a time where it brings
    the most of what is still missing (Σ over cells of min(stare, missing); the first such column on a tie),
    until nothing is. Measured (the 200 x 50 strip, demand 1.12): the programme asks 2,832 time units of
    stares; every fraction rounded up, 3,161; this, 2,966 (HiGHS's integer programme had 2,942 after 20 s and
    no better after 60).

    A column's gain only falls as cells fill, so each is kept with its last gain as a bound in a heap and only
    the top is computed again (lazy greedy): the same choice as every gain computed each time, summed the same
    way (the campus: 1.8 - 2.3 s -> 0.8 - 1.1 s, some 1,500 periods over 6,048 columns)."""
    periods = np.floor(relaxed + 1e-6)
    missing = need - stares @ periods
    by_column = stares.T.tocsr()
    clipped = by_column.copy()
    clipped.data = np.minimum(by_column.data, np.maximum(missing, 0.0)[by_column.indices])
    bounds = [(-float(gain), column) for column, gain in enumerate(np.asarray(clipped.sum(axis=1)).ravel())]
    heapq.heapify(bounds)
    while (missing > 1e-9).any():
        best = _next_best(bounds, by_column, missing)
        periods[best] += 1.0
        missing -= stares[:, best].toarray().ravel()
    return periods.astype(int)


def _next_best(bounds: list[tuple[float, int]], by_column: csr_matrix, missing: np.ndarray) -> int:
    """The column that brings the most of ``missing`` now, the first on a tie, from ``bounds`` (a heap of
    (−gain bound, column)), its own bound made its gain now."""
    while True:
        _, column = heapq.heappop(bounds)
        start, end = by_column.indptr[column], by_column.indptr[column + 1]
        clipped = np.minimum(by_column.data[start:end], np.maximum(missing, 0.0)[by_column.indices[start:end]])
        gain = float(np.add.reduceat(clipped, [0])[0]) if end > start else 0.0  # summed as csr_matrix.sum sums
        heapq.heappush(bounds, (-gain, column))
        if bounds[0] == (-gain, column):
            if gain <= 0.0:
                raise ValueError("no stare reaches a cell the stations must cover")
            return column


def station_times(chosen: Layout, k_v: float) -> tuple[np.ndarray, np.ndarray]:
    """When (in units of k_v travel along the serpentine) each station is reached and left: the hops at
    k_v, each station held for its periods."""
    arrive, leave, now = [], [], 0.0
    for k, station in enumerate(chosen.stations):
        if k:
            now += float(np.linalg.norm(station - chosen.stations[k - 1]))
        arrive.append(now)
        now += len(chosen.bearings[k]) * CARROT_PERIOD * k_v
        leave.append(now)
    return np.array(arrive), np.array(leave)


def timeline(chosen: Layout, k_v: float) -> Spiral:
    """The serpentine as a line in time for :mod:`model.controllers.anicov.piece_order` (:func:`station_times`): each station's
    point at its arrival and again at its leaving."""
    arrive, leave = station_times(chosen, k_v)
    points = np.repeat(chosen.stations, 2, axis=0)
    along = np.stack([arrive, leave], axis=1).ravel()
    keep = np.concatenate([[True], np.diff(along) > 1e-9])
    return Spiral(points[keep], along[keep], 0.0, 0.0, 0.0)


def station_routes(scenario: Scenario, positions: np.ndarray) -> tuple[list[np.ndarray], list[list[Stop]], float]:
    """Every robot's route (its position, then the hops of its share of the serpentine) and its stops, on the
    serpentine and mirror image whose order of robots finishes soonest; and that finish (units of k_v
    travel)."""
    width, height = scenario.domain
    tried = []
    for by_columns in (False, True):
        base = layout(scenario, by_columns)
        for flip_x in (False, True):
            for flip_y in (False, True):
                mirrored = base.mirrored(width, height, flip_x, flip_y)
                line = timeline(mirrored, scenario.k_v)
                order = _first_order(positions, line)
                tried.append((float(order_finishes(order[None, :], positions, line)[0]), mirrored, line, order))
    soonest = sorted(range(len(tried)), key=lambda k: tried[k][0])  # stable: the first on a tie
    best: tuple[float, Layout, Spiral, np.ndarray] | None = None
    for k in soonest[: 1 if len(positions) == 1 else ORDERED_VARIANTS]:
        _, mirrored, line, order = tried[k]
        order, finish = improved_order(order, positions, line) if len(positions) > 1 else (order, tried[k][0])
        if best is None or finish < best[0] - 1e-9:
            best = (finish, mirrored, line, order)
    assert best is not None
    finish, chosen, line, order = best
    routes = [positions[robot][None, :].copy() for robot in range(len(positions))]
    stops: list[list[Stop]] = [[] for _ in positions]
    for robot, start, end in cuts_for(order, finish, positions, line):
        routes[robot], stops[robot] = _share(chosen, line, positions[robot], start, end, scenario.k_v)
    return routes, stops, finish


def _first_order(positions: np.ndarray, line: Spiral) -> np.ndarray:
    """Robots in the order in which their nearest points lie along the line (where the local search
    starts)."""
    nearest = np.argmin(np.linalg.norm(positions[:, None, :] - line.points[None, :, :], axis=2), axis=1)
    return np.argsort(line.along[nearest], kind="stable")


def _share(
    chosen: Layout, line: Spiral, position: np.ndarray, start: float, end: float, k_v: float
) -> tuple[np.ndarray, list[Stop]]:
    """One robot's route and stops for its share [start, end] of the line: the hops within it, and at each
    station whose periods overlap it, those periods' bearings (a share cut inside a station's periods
    takes the whole periods before or after the cut, rounded to the nearest)."""
    period = CARROT_PERIOD * k_v
    points = [position, point_along(line.points, line.along, start)]
    wanted: list[tuple[int, list[float]]] = []  # (index in points, bearings)
    for station, bearings, arrive, leave in zip(
        chosen.stations, chosen.bearings, *station_times(chosen, k_v), strict=True
    ):
        if arrive > start + 1e-9 and arrive < end - 1e-9:
            points.append(station)
        if leave > start + 1e-9 and arrive < end - 1e-9 and bearings:
            first = max(0, round((start - arrive) / period))
            last = min(len(bearings), round((end - arrive) / period))
            if last > first:
                if not np.allclose(points[-1], station):
                    points.append(station)
                wanted.append((len(points) - 1, list(bearings[first:last])))
    if end < line.length - 1e-9:
        points.append(point_along(line.points, line.along, end))
    route = np.array(points, dtype=np.float64)
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(route, axis=0), axis=1))])
    return route, [Stop(float(lengths[index]), bearings) for index, bearings in wanted]


def with_patched_stops(
    scenario: Scenario, routes: list[np.ndarray], stops: list[list[Stop]], positions: np.ndarray, lookahead: float
) -> tuple[list[list[Stop]], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """``stops`` with periods added wherever the flight of ``routes`` (:func:`model.controllers.anicov.touch_ups.simulate_routes`,
    as the engine flies it) leaves cells short of Λ*: at a station within R of them (and no nearer than
    :data:`NEAREST_PATCH_CELLS`), facing one of them, one period at a time where it brings the most of what
    they miss (up to :data:`PATCH_DEMAND`), each put in its station's sweep after the bearing nearest it;
    at most :data:`PATCH_ROUNDS` times. The programme's stares and straight hops are not quite the flight
    (the law's way in and out of a station, its turns), and a cell left a few per cent short would cost an
    orbit at the end of a route; a period is half a time unit where the robot stands anyway. Returns the
    stops and the flight of the routes with them (``simulate_routes``' result), which
    :func:`model.controllers.anicov.touch_ups.with_touch_ups` reads for the orbits over what is still short.
    Measured (the 200 x 50 strip, N = 1, seed 0, before whole periods): 8 single cells foretold short, an
    orbit trip of 343 time units."""
    for _ in range(PATCH_ROUNDS):
        flown = simulate_routes(scenario, routes, positions, lookahead, stops=stops)
        if not (flown[0] > 0.0).any():
            return stops, flown
        stops = _patched(scenario, routes, stops, flown[0])
    return stops, simulate_routes(scenario, routes, positions, lookahead, stops=stops)


def _patched(
    scenario: Scenario, routes: list[np.ndarray], stops: list[list[Stop]], lack: np.ndarray
) -> list[list[Stop]]:
    """One round of :func:`with_patched_stops` on the foretold ``lack`` (Υ, in Λ*)."""
    rows, cols = np.nonzero(lack > 0.0)
    cells = (np.stack([cols, rows], axis=1) + 0.5) * scenario.cell
    missing = lack[rows, cols] + (PATCH_DEMAND - 1.0)
    deposit = Deposit(scenario)
    patched = [[Stop(stop.at, list(stop.bearings)) for stop in robot] for robot in stops]
    candidates: list[tuple[int, int, float, np.ndarray]] = []  # (robot, stop, bearing, deposit on the cells)
    for robot, robot_stops in enumerate(patched):
        route = Route.of(routes[robot])
        for index, stop in enumerate(robot_stops):
            station = route.point_at(stop.at)
            gaps = np.linalg.norm(cells - station, axis=1)
            for cell in np.nonzero((gaps >= NEAREST_PATCH_CELLS * scenario.cell) & (gaps < scenario.range))[0]:
                bearing = math.atan2(cells[cell, 1] - station[1], cells[cell, 0] - station[0])
                stare = deposit.stare(float(station[0]), float(station[1]), bearing).reshape(lack.shape)
                candidates.append((robot, index, bearing, stare[rows, cols]))
    while candidates and (missing > 1e-9).any():
        gains = [float(np.minimum(stare, np.maximum(missing, 0.0)).sum()) for *_, stare in candidates]
        best = int(np.argmax(gains))
        if gains[best] <= 0.0:
            break  # what no station reaches is left to the orbits
        robot, index, bearing, stare = candidates[best]
        bearings = patched[robot][index].bearings
        nearest = min(range(len(bearings)), key=lambda k: _turn(bearings[k], bearing))
        bearings.insert(nearest + 1, bearing)
        missing -= stare
    return patched
