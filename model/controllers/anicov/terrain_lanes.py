"""anicov's routes among walls, flown as on the open square (issue 36, items 1 and 2): each robot's share of the
tour (:mod:`model.controllers.anicov.terrain_plan`) as a route of hops and stops.

- **A share's route**: the free path from the robot to its share's first point on the line, then the line's
  points within the share (hop legs and stations), with a stop at each station whose periods fall in the
  share (whole periods, the nearest cut, as on the open square), and a turn in place at every sharp corner
  (:func:`corner_turns`).
- **A piece's route** (:func:`piece_route`): the same through a cleanup's stations
  (:mod:`model.controllers.anicov.terrain_cleanup`); what a robot does once its route is done is
  :mod:`model.controllers.anicov.terrain_flight`'s.
"""

from __future__ import annotations

import math

import numpy as np

from model.controllers.anicov.route import CARROT_PERIOD, Stop
from model.controllers.anicov.terrain_plan import TourPlan, tour_line, tour_of, tour_plan, tour_shares
from model.controllers.anicov.terrain_routes import hop_path
from model.paper.polyline import point_along
from model.scenario import Scenario
from model.world.reachability import in_reachable_cell, nearest_reachable
from model.world.world import World, world_of

CORNER_TURN = math.radians(30.0)
"""A route's corner that turns more than this is turned in place (:func:`corner_turns`)."""


def terrain_routes(scenario: Scenario, positions: np.ndarray) -> tuple[list[np.ndarray], list[list[Stop]]]:
    """Every robot's route (M_i, 2) and its stops, from its position through its share of the tour."""
    world, plan = world_of(scenario), tour_plan(scenario, positions)
    points, along, arrivals = tour_line(plan, scenario.k_v)
    shares = tour_shares(world, points, along, positions)
    routes, stops = [], []
    for robot, (start, end) in enumerate(shares):
        route, own = _share(world, plan, (points, along), arrivals, positions[robot], (start, end), scenario)
        routes.append(route)
        stops.append(own)
    return routes, stops


def piece_route(
    world: World, scenario: Scenario, position: np.ndarray, stations: np.ndarray, periods: np.ndarray
) -> tuple[np.ndarray, list[Stop]]:
    """One robot's route and stops from ``position`` through ``stations`` (in this order) and their whole
    ``periods`` (K, BEARINGS): a cleanup's piece (:func:`model.controllers.anicov.terrain_cleanup.cleanup_pieces`)."""
    plan = tour_of(world, stations, periods, scenario)
    points, along, arrivals = tour_line(plan, scenario.k_v)
    return _share(world, plan, (points, along), arrivals, position, (0.0, float(along[-1])), scenario)


def _share(
    world: World,
    plan: TourPlan,
    line: tuple[np.ndarray, np.ndarray],
    arrivals: np.ndarray,
    position: np.ndarray,
    share: tuple[float, float],
    scenario: Scenario,
) -> tuple[np.ndarray, list[Stop]]:
    """One robot's route and stops for its share (start, end) of the line (``arrivals``: where along it each
    station is reached)."""
    points, along = line
    start, end = share
    period = CARROT_PERIOD * scenario.k_v
    inside = np.flatnonzero((along >= start - 1e-9) & (along <= end + 1e-9))
    # A share begins and ends where the line is cut, inside a hop's leg as often as not: the leg's two parts are
    # flown by the robots on either side (the tour's stares count every leg's view: terrain_plan).
    first = np.array(point_along(points, along, start), dtype=np.float64)
    route = [*free_path(world, position, first)]
    wanted: list[tuple[int, list[float]]] = []
    stations = {tuple(station): k for k, station in enumerate(plan.stations)}
    for index in inside:
        point = points[index]
        if not np.allclose(route[-1], point):
            route.append(point)
        k = stations.get(tuple(point))
        if k is None or not plan.bearings[k] or (wanted and wanted[-1][0] == len(route) - 1):
            continue
        arrive = arrivals[k]
        low, high = max(0, round((start - arrive) / period)), min(len(plan.bearings[k]), round((end - arrive) / period))
        if high > low:
            wanted.append((len(route) - 1, list(plan.bearings[k][low:high])))
    last = np.array(point_along(points, along, end), dtype=np.float64)
    if not np.allclose(route[-1], last):
        route.append(last)
    route_points = np.array(route, dtype=np.float64).reshape(-1, 2)
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(route_points, axis=0), axis=1))])
    wanted = sorted([*wanted, *corner_turns(route_points, {index for index, _ in wanted}, scenario)])
    return route_points, [Stop(float(lengths[index]), bearings) for index, bearings in wanted]


def corner_turns(points: np.ndarray, stations: set[int], scenario: Scenario) -> list[tuple[int, list[float]]]:
    """(point index, bearings): at every inner corner of a route (not a station) that turns more than
    :data:`CORNER_TURN`, the robot stops and turns in place toward the next leg, a period at a time at the bound
    π k_ω (the last facing the leg). Driven round it, the pursuit's ω = k_ω e_θ (eq. 16) turns a third as fast
    as the bound and its speed falls with the heading's error all the while (campus, k_ω = 0.48: a right angle
    takes about 5 time units of creeping)."""
    turn = math.pi * scenario.k_omega * CARROT_PERIOD
    found = []
    for k in range(1, len(points) - 1):
        if k in stations:
            continue
        before = math.atan2(points[k][1] - points[k - 1][1], points[k][0] - points[k - 1][0])
        after = math.atan2(points[k + 1][1] - points[k][1], points[k + 1][0] - points[k][0])
        gap = math.remainder(after - before, 2.0 * math.pi)
        if abs(gap) > CORNER_TURN:
            steps = math.ceil(abs(gap) / turn - 1e-9)
            found.append((k, [before + gap * j / steps for j in range(1, steps + 1)]))
    return found


def free_path(world: World, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """The free path's points from ``start`` (anywhere a robot stands) to ``goal`` (a reachable cell's centre,
    or a point on a free path): from the reachable cell nearest the start where its own is not."""
    cell = world.scenario.cell
    inside = in_reachable_cell(world.reachable, start[0], start[1], cell)
    begin = (
        np.asarray(start, dtype=np.float64) if inside else nearest_reachable(world.reachable, start[None, :], cell)[0]
    )
    end = nearest_reachable(world.reachable, np.asarray(goal, dtype=np.float64)[None, :], cell)[0]
    path = hop_path(world, begin, end)
    path = np.vstack([start[None, :], path[1:]]) if not inside else path
    return np.vstack([path, np.asarray(goal)[None, :]]) if not np.allclose(path[-1], goal) else path
