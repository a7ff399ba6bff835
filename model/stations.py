"""The ``anicov`` controller's stations: robots that stand and turn their camera, then hop to the next place.

Beyond the paper (docs/controller.md has the measurements). The sensor's ability (eq. 2) over its wedge adds
up to t*_1's rate, 15.7 area of Λ* per time unit on the paper's sensor (eq. 19), wherever it points; the
question is only how much of it lands on cells already at Λ* or outside the domain. A straight pass at k_v
pours 5 Λ* onto its own course; a robot standing and turning its heading spreads its wedge over a disc of
radius R with a cone's profile, and the cones of neighbouring stations add up (eq. 3) to a nearly flat
field. What it pays is the hops between stations, and a hop is path and time that a sweep pays too.

- **Where the robots stand** (:func:`layout`): a grid of stations at :data:`SPACING_PER_RANGE` R apart, the
  outer ones :data:`MARGIN_PER_RANGE` R inside the edges, visited row by row (or column by column), turning
  at each row's end (a serpentine).
- **Which way they look, and how long**: in each plan period (:data:`model.scenario.CARROT_PERIOD`) a
  robot at a station faces one of :data:`BEARINGS` bearings. How many periods each station spends at each
  bearing is a linear programme (scipy's HiGHS): the fewest periods for which the stations' stares and the
  hops between them (eq. 2-3 summed cell by cell, flown as the engine flies them) bring every cell to Λ*.
  The periods of a station are flown in one sweep of the bearings it needs, counterclockwise from the
  one after its largest gap (:func:`bearing_sequence`).
- **Who goes where**: the serpentine as a line in time (hops at k_v, stations as their periods) is cut for an
  order of robots exactly as the spiral is (:mod:`model.piece_order`: each robot's transit plus its share
  takes every robot the same time), on each of the domain's 4 mirror images and both serpentines; the
  order is improved by the same local search on the :data:`model.routes.ORDERED_VARIANTS` soonest, and the
  soonest is flown.

The messages stay the paper's: the carrot at a station is a point :data:`FACE_RADIUS` / 2 from the robot in
the bearing to face, and the law (:func:`model.control.pursuit_law`) stands and turns toward a carrot so
near. Lockstep over Zenoh still equals the engine byte for byte (the planner reads only positions).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import csc_matrix

from model.coverage_map import CoverageMap, add_window
from model.ground import open_ground
from model.piece_order import Spiral, cuts_for, improved_order, order_finishes
from model.route import Stop
from model.routes import ORDERED_VARIANTS
from model.scenario import CARROT_PERIOD, Scenario
from model.sensing import sense_wedge_among
from model.zigzag import point_along

BEARINGS = 24
"""Bearings a robot at a station may face (15° apart): the wedge (2F = 54° on the paper's sensor) laid at
neighbouring bearings overlaps, so their stares add up to a smooth fan. Measured (6 seeds, the paper's
square, N = 4 / 10): 16 bearings 2.27 / 2.47 t*, 24 2.28 / 2.36."""
SPACING_PER_RANGE = 1.25
"""Stations lie this share of R apart (25 units on the paper's sensor)."""
MARGIN_PER_RANGE = 0.15
"""The outer stations lie this share of R inside the edges (3 units on the paper's sensor)."""
DEMAND = 1.12
"""The programme asks this share of Λ* of every cell: the robots' turns between bearings, their way in and
out of a station and the hops as the law flies them differ a little from the stares and straight hops it
counts, and a cell left a few per cent short costs an orbit or a stare later. Measured (16 bearings, 6
seeds, the paper's square, N = 4 / 10): 1.03 2.40 / 2.54 t*, 1.08 2.29 / 2.48, 1.12 2.27 / 2.47, 1.18 2.37 /
2.52."""
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
    periods: np.ndarray, arrive: float | None = None, leave: float | None = None, turn: float = TURN_PER_PERIOD
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
    return sequence


def _turn(a: float | None, b: float | None) -> float:
    """The turn (radians, 0 - π) from heading ``a`` to ``b``; none where either is not given."""
    return 0.0 if a is None or b is None else abs(math.remainder(b - a, 2.0 * math.pi))


class _Deposit:
    """The coverage (in Λ*) a camera adds over the scenario's grid, as the engine's sensor adds it."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.shape = scenario.grid_shape
        self.target_ticks = CoverageMap(*self.shape, scenario.cell, scenario.lambda_star).target_ticks
        self.ground, self.nobody = open_ground(), np.zeros((0, 2))

    def add(self, ticks: np.ndarray, x: float, y: float, theta: float) -> None:
        scenario = self.scenario
        _, _, _, row0, col0, window = sense_wedge_among(
            ticks, 1 << 62, x, y, theta, scenario.range, scenario.half_angle, scenario.alpha_max, scenario.dt,
            scenario.cell, self.ground, self.nobody,
        )  # fmt: skip
        add_window(ticks, row0, col0, window, 1 << 62)

    def stare(self, x: float, y: float, theta: float) -> np.ndarray:
        """One plan period facing ``theta`` from (x, y), per cell (Λ*)."""
        ticks = np.zeros(self.shape, dtype=np.int64)
        for _ in range(self.scenario.plan_steps):
            self.add(ticks, x, y, theta)
        return ticks.ravel() / self.target_ticks

    def hops(self, stations: np.ndarray) -> np.ndarray:
        """The hops between consecutive stations flown straight at k_v, per cell (Λ*)."""
        ticks = np.zeros(self.shape, dtype=np.int64)
        step = self.scenario.k_v * self.scenario.dt
        for a, b in itertools.pairwise(stations):
            heading = math.atan2(b[1] - a[1], b[0] - a[0])
            steps = round(float(np.linalg.norm(b - a)) / step)
            for k in range(steps):
                x, y = a + (b - a) * k / steps
                self.add(ticks, float(x), float(y), heading)
        return ticks.ravel() / self.target_ticks


@functools.cache
def layout(scenario: Scenario, by_columns: bool) -> Layout:
    """The stations of a serpentine and the bearings each faces (the linear programme of the module)."""
    width, height = scenario.domain
    stations = grid(width, height, SPACING_PER_RANGE * scenario.range, MARGIN_PER_RANGE * scenario.range, by_columns)
    deposit = _Deposit(scenario)
    angles = 2.0 * math.pi * np.arange(BEARINGS) / BEARINGS
    stares = np.stack([deposit.stare(float(x), float(y), float(a)) for x, y in stations for a in angles], axis=1)
    need = np.maximum(DEMAND - deposit.hops(stations), 0.0)
    reachable = stares.sum(axis=1) > 0.0
    if not reachable.all():  # stations at most 0.88 R from any point never leave one out; a guard all the same
        raise ValueError(f"stations {SPACING_PER_RANGE} R apart leave {int((~reachable).sum())} cells out of view")
    solved = linprog(
        np.ones(stares.shape[1]), A_ub=-csc_matrix(stares), b_ub=-need, bounds=(0, None),
        method="highs",
    )  # fmt: skip
    if solved.x is None:
        raise ValueError(f"no station layout covers the domain: {solved.message}")
    periods = np.ceil(solved.x.reshape(len(stations), BEARINGS) - 1e-6).astype(int)
    ways = np.arctan2(*np.diff(stations, axis=0)[:, ::-1].T) if len(stations) > 1 else np.zeros(0)
    turn = math.pi * scenario.k_omega * CARROT_PERIOD
    bearings = tuple(
        tuple(bearing_sequence(row, ways[k - 1] if k else None, ways[k] if k < len(ways) else None, turn))
        for k, row in enumerate(periods)
    )
    return Layout(stations, bearings)


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
    """The serpentine as a line in time for :mod:`model.piece_order` (:func:`station_times`): each station's
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
