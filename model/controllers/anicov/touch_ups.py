"""The ``anicov`` controller's touch-ups: what the planned routes will leave short, foreseen when they are
planned, and orbits that finish it.

Beyond the paper (docs/controller.md has the measurements). The spiral's pieces leave a few spots short
of Λ* in places its geometry decides (the centre, where the innermost ring is smaller than a run-up; the
ends of a long thin innermost ring; spots beside seams), and passes over them once the pieces were done
made a tail: at N = 10 on the paper's square the team waited 0.16 t* after its pieces for them. They are
known in advance: in the open world a robot's motion along its route depends on nothing but the route, so
flying the routes here, with the pursuit law (:func:`model.paper.control.pursuit_law`), the unicycle (eq. 1) and
the sensor (eq. 2-3), as the engine will, foretells the cells left short (:func:`simulate_routes`;
checked: 39 of the 39 cells left after the pieces of N = 10, seed 1, were among those foretold).

Each group of them gets an *orbit*: a small circle flown next to it (:func:`orbit`). A forward camera
on a circle of radius 1.5 turns through every bearing and sweeps all around, as a robot standing and
turning would; a straight pass covers only d100 to either side and needs a run-up, and over a ring-shaped
spot (the centre's) it left most of it. The orbit's centre (the spot's centroid, or 3 units off it on
either axis: a camera on a circle never looks at the circle's own centre) and its number of turns are
those that, flown on the foretold map, finish the spot in the fewest turns (:func:`orbit_for`). Orbits
are appended to the routes of the robots that will finish them soonest (:func:`with_touch_ups`); coverage
adds up (eq. 3), so a spot may be orbited before or after the pieces around it are flown.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from numba import njit

from model.controllers.anicov.law import anicov_law
from model.controllers.anicov.route import Route, Stop, advanced, carrot_on, point_on
from model.paper.coverage_map import add_window
from model.paper.dynamics import unicycle_step
from model.parameters import coverage_map_of
from model.scenario import Scenario
from model.step import LawParameters, pursue
from model.world.ground import Ground, open_ground
from model.world.wedge import sense_wedge_among

ORBIT_RADIUS = 1.5
"""Radius of a touch-up orbit (units). Measured (16 seeds, N = 2, 4, 10, 30 on the paper's square): 1.0
within 0.04 t* of it, 2.5 worse by 0.09 - 0.16."""
ORBIT_OFFSET = 3.0
"""How far off a spot's centroid the other candidate orbits are centred (units)."""
MAX_TURNS = 3
"""At most this many turns of one orbit; what they leave goes to the planner's passes."""
POINTS_PER_TURN = 24
"""Vertices of an orbit's polygon per turn."""
MAX_SIMULATED_STEPS = 10**6
"""A route not done after this many steps is given up on in a simulation (never reached in practice)."""


@dataclass
class TouchUp:
    """An orbit on a robot's route: from ``start`` to ``end`` (arc lengths along the route), for the cells
    ``spot`` (bool grid)."""

    start: float
    end: float
    spot: np.ndarray


def simulate_routes(
    scenario: Scenario,
    routes: list[np.ndarray],
    positions: np.ndarray,
    lookahead: float,
    coverage: np.ndarray | None = None,
    stops: list[list[Stop]] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each route flown from its robot's position as the engine flies it: every ``plan_steps`` the
    robot's progress is advanced and its carrot put ``lookahead`` ahead (model.controllers.anicov.lane_planner), every step
    :func:`model.paper.control.pursuit_law`, the wedge's coverage (eq. 2-3) and the unicycle (eq. 1); until the
    route is done, standing at its ``stops`` (:mod:`model.controllers.anicov.stations`) as the planner has it stand. Robots start
    heading at their first carrot (the planner knows no headings). Returns
    (Υ after all routes, eq. 4; the coverage in ticks, ``coverage`` added to in place if given; each
    route's flight time)."""
    law = anicov_law(scenario, coverage_map_of(scenario).target_ticks)
    ground, nobody = open_ground(), np.zeros((0, 2))
    ticks = coverage_map_of(scenario).coverage if coverage is None else coverage
    times = np.zeros(len(routes))
    plan_steps = scenario.plan_steps  # read once: it asks the scenario's controller
    for index, points in enumerate(routes):
        route = Route.of(points, stops=None if stops is None else stops[index])
        stop_at = np.array([stop.at for stop in route.stops], dtype=np.float64)
        bearings = np.array([bearing for stop in route.stops for bearing in stop.bearings], dtype=np.float64)
        faced_after = np.cumsum([len(stop.bearings) for stop in route.stops], dtype=np.int64)
        x, y = float(positions[index][0]), float(positions[index][1])
        steps = _fly_route(
            ticks, x, y, route.points, route.along, (stop_at, bearings, faced_after), lookahead, plan_steps, law,
            ground, nobody,
        )  # fmt: skip
        times[index] = steps * scenario.dt
    lack = np.maximum(law.target_ticks - ticks, 0).astype(np.float64) / law.target_ticks
    return lack, ticks, times


@njit(cache=True)
def _fly_route(
    ticks: np.ndarray,
    x: float,
    y: float,
    points: np.ndarray,
    along: np.ndarray,
    stops: tuple[np.ndarray, np.ndarray, np.ndarray],
    lookahead: float,
    plan_steps: int,
    law: LawParameters,
    ground: Ground,
    nobody: np.ndarray,
) -> int:
    """Steps until a route is done, flown from (x, y) as :mod:`model.controllers.anicov.lane_planner` steers
    it, with :class:`model.controllers.anicov.route.Route`'s own compiled steps (:func:`advanced`,
    :func:`carrot_on`), the robot heading at its first carrot; the wedge's coverage added to ``ticks``.
    ``stops``: the stations' arc lengths (S,), their bearings one after another, and how many bearings are
    faced once each station is done (S,). Compiled whole: called from Python every plan period, the
    flights were most of the first plan at N = 100."""
    stop_at, bearings, faced_after = stops
    length = along[-1]
    carrot_x, carrot_y = point_on(points, along, lookahead)
    theta = math.atan2(carrot_y - y, carrot_x - x)
    progress, stop, faced, step = 0.0, 0, 0, 0
    while step < MAX_SIMULATED_STEPS:
        next_stop, bearing = (stop_at[stop], bearings[faced]) if stop < len(stop_at) else (math.nan, 0.0)
        reach = progress + lookahead
        if stop < len(stop_at):
            reach = min(reach, next_stop)
        progress = advanced(points, along, progress, reach, x, y)
        if progress >= length - 1e-6 and stop == len(stop_at):  # Route.done
            break
        carrot_x, carrot_y, progress, turned = carrot_on(
            points, along, progress, next_stop, bearing, x, y, lookahead, law.face_radius, law.face_radius
        )
        if turned:
            faced += 1
            if faced == faced_after[stop]:
                stop += 1
        period = min(plan_steps, MAX_SIMULATED_STEPS - step)
        x, y, theta = _fly(ticks, x, y, theta, carrot_x, carrot_y, period, law, ground, nobody)
        step += period
    return step


@njit(cache=True)
def _fly(
    ticks: np.ndarray,
    x: float,
    y: float,
    theta: float,
    carrot_x: float,
    carrot_y: float,
    steps: int,
    law: LawParameters,
    ground: Ground,
    nobody: np.ndarray,
) -> tuple[float, float, float]:
    """(x, y, θ) after ``steps`` steps toward the carrot, as the engine flies them: each step
    :func:`model.paper.control.pursuit_law`, the wedge's coverage (eq. 2-3) added to ``ticks`` and the
    unicycle (eq. 1)."""
    for _ in range(steps):
        v, omega = pursue(x, y, theta, carrot_x, carrot_y, law)
        _, _, _, row0, col0, window = sense_wedge_among(
            ticks, law.target_ticks, x, y, theta, law.sensing_range, law.half_angle, law.alpha_max, law.dt,
            law.cell, ground, nobody, (law.position_doubt, law.heading_doubt),
        )  # fmt: skip
        add_window(ticks, row0, col0, window, law.target_ticks)
        x, y, theta = unicycle_step(x, y, theta, v, omega, law.dt)
    return x, y, theta


def orbit(centre: np.ndarray, radius: float, start_angle: float, turns: int) -> np.ndarray:
    """A circle of ``radius`` about ``centre``, counterclockwise ``turns`` times from ``start_angle``."""
    angles = start_angle + np.linspace(0.0, 2.0 * math.pi * turns, POINTS_PER_TURN * turns + 1)
    return np.stack([centre[0] + radius * np.cos(angles), centre[1] + radius * np.sin(angles)], axis=1)


def blob_labels(short: np.ndarray, cell: float, spacing: float) -> tuple[int, np.ndarray]:
    """Groups of cells closer than a lane spacing to each other (8-connected once grown by half a spacing):
    (count + 1, labels of the cells in ``short``, 0 elsewhere)."""
    reach = max(1, round(spacing / 2.0 / cell))
    grown = cv2.dilate(
        short.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1, 2 * reach + 1))
    )
    count, labels = cv2.connectedComponents(grown, connectivity=8)
    return count, labels * short.astype(labels.dtype)


def orbit_for(scenario: Scenario, coverage: np.ndarray, spot: np.ndarray, lookahead: float) -> tuple[np.ndarray, int]:
    """(centre, turns) of the orbit that finishes the cells ``spot`` (bool grid) in the fewest turns on
    the foretold ``coverage`` (ticks, not changed), the fewest cells' Υ left on a tie; centres tried: the
    spot's centroid and :data:`ORBIT_OFFSET` off it along either axis, in order."""
    rows, cols = np.nonzero(spot)
    centroid = np.array([(cols + 0.5).mean(), (rows + 0.5).mean()]) * scenario.cell
    offsets = [(0.0, 0.0), (1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)]
    best: tuple[tuple[int, float], np.ndarray, int] | None = None
    for offset in offsets:
        centre = centroid + ORBIT_OFFSET * np.array(offset)
        for turns in range(1, MAX_TURNS + 1):
            loop = orbit(centre, ORBIT_RADIUS, 0.0, turns)
            lack, _, _ = simulate_routes(scenario, [loop], loop[:1], lookahead, coverage.copy())
            left = float(lack[spot].sum())
            if left <= 0.0 or turns == MAX_TURNS:
                key = (turns if left <= 0.0 else MAX_TURNS + 1, left)
                if best is None or key < best[0]:
                    best = (key, centre, turns)
                break
    assert best is not None
    return best[1], best[2]


def with_touch_ups(
    scenario: Scenario,
    routes: list[np.ndarray],
    positions: np.ndarray,
    lookahead: float,
    spacing: float,
    stops: list[list[Stop]] | None = None,
    flown: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> tuple[list[np.ndarray], list[list[TouchUp]]]:
    """``routes`` with an orbit (:func:`orbit_for`) for every group of cells they will leave short
    (:func:`simulate_routes`, grouped as :func:`blob_labels` does), and each robot's :class:`TouchUp`
    list in route order. Each in turn, of all the groups and robots, the pair that ends soonest (the
    robot's foretold flight time, the way to the orbit at k_v, its turns at the time one turn takes) is
    taken, as a greedy schedule would; the orbit is appended to the robot's route. A team of one also
    weighs going out to the orbit from its route's nearest point and back (:func:`_cheapest`), unless its
    route has ``stops`` (:mod:`model.controllers.anicov.stations`), whose places along it an orbit put inside would move.
    ``flown``: :func:`simulate_routes`' result for these routes and stops, where the caller has it already
    (:func:`model.controllers.anicov.stations.with_patched_stops`); the routes are flown here otherwise."""
    lack, coverage, finish = flown or simulate_routes(scenario, routes, positions, lookahead, stops=stops)
    count, labels = blob_labels(lack > 0.0, scenario.cell, spacing)
    spots = [labels == k for k in range(1, count) if (labels == k).any()]
    touch_ups: list[list[TouchUp]] = [[] for _ in routes]
    if not spots:
        return routes, touch_ups
    one_turn = orbit(np.zeros(2), ORBIT_RADIUS, 0.0, 1)
    turn_time = float(simulate_routes(scenario, [one_turn], one_turn[:1], lookahead)[2][0])
    orbits = [orbit_for(scenario, coverage, spot, lookahead) for spot in spots]
    routes = [np.asarray(route, dtype=np.float64) for route in routes]
    while orbits:
        ends, k, robot, at = _cheapest(orbits, routes, finish, turn_time, scenario.k_v, detours=stops is None)
        (centre, turns), spot = orbits.pop(k), spots.pop(k)
        _place(routes, touch_ups, robot, centre, turns, spot, at)
        finish[robot] = ends
    return routes, touch_ups


def _cheapest(
    orbits: list[tuple[np.ndarray, int]],
    routes: list[np.ndarray],
    finish: np.ndarray,
    turn_time: float,
    k_v: float,
    detours: bool = True,
) -> tuple[float, int, int, float | None]:
    """(when it ends, orbit, robot, where along the route it leaves for it: None for the route's end) of
    the soonest-ending orbit and robot. Only a team of one leaves its route for an orbit and comes back:
    measured (8 seeds on the 200 x 50 strip, 16 on the paper's square), a detour in one robot's piece made
    N = 6 - 30 slower by 0.04 - 0.17 t* (its teammates' seams and claimed strips wait on it), while at
    N = 1 the strip's far end costs a detour instead of a trip back along the strip (1.709 -> 1.636 t*)."""
    best: tuple[float, int, int, float | None] | None = None
    for k, (centre, turns) in enumerate(orbits):
        for robot, points in enumerate(routes):
            way = max(0.0, float(np.linalg.norm(points[-1] - centre)) - ORBIT_RADIUS) / k_v
            ends = float(finish[robot]) + way + turns * turn_time
            if best is None or ends < best[0] - 1e-9:
                best = (ends, k, robot, None)
            if detours and len(routes) == 1 and len(points) > 2:
                route = Route.of(points)
                at = max(route.nearest(centre)[1], float(route.along[1]))  # not on the way to the spiral
                gap = float(np.linalg.norm(route.point_at(at) - centre))
                ends = float(finish[robot]) + 2.0 * max(0.0, gap - ORBIT_RADIUS) / k_v + turns * turn_time
                if at < route.length - 1e-6 and ends < best[0] - 1e-9:
                    best = (ends, k, robot, at)
    assert best is not None
    return best


def _place(
    routes: list[np.ndarray],
    touch_ups: list[list[TouchUp]],
    robot: int,
    centre: np.ndarray,
    turns: int,
    spot: np.ndarray,
    at: float | None,
) -> None:
    """Put the orbit into ``robot``'s route: at its end, or (``at``) out from that point and back to it,
    the robot's later touch-ups moved along by the orbit's length."""
    route = Route.of(routes[robot])
    leave = route.points[-1] if at is None else route.point_at(at)
    loop = orbit(centre, ORBIT_RADIUS, math.atan2(leave[1] - centre[1], leave[0] - centre[0]), turns)
    if at is None:
        routes[robot] = np.vstack([route.points, loop])
        touch_ups[robot].append(TouchUp(route.length, Route.of(routes[robot]).length, spot))
        return
    split = int(np.searchsorted(route.along, at, side="right"))
    routes[robot] = np.vstack([route.points[:split], leave, loop, leave, route.points[split:]])
    added = Route.of(routes[robot]).length - route.length
    for later in touch_ups[robot]:
        if later.start >= at:
            later.start += added
            later.end += added
    touch_ups[robot].append(TouchUp(at, at + added, spot))
    touch_ups[robot].sort(key=lambda touch_up: touch_up.start)
