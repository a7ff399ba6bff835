"""anicov's routes among walls, flown as on the open square (issue 36, items 1 and 2): each robot's share of the
tour (:mod:`model.controllers.anicov.terrain_plan`) as a route of hops and stops, and what a robot does when
its route is done.

- **A share's route**: the free path from the robot to its share's first point on the line, then the line's
  points within the share (hop legs and stations), with a stop at each station whose periods fall in the
  share (whole periods, the nearest cut, as on the open square).
- **When routes are done** and cells are left (the flight is not the programme: robots pass a station a
  little off, the filter holds them, a stare is cut short), each free robot is sent, as the paper's
  planner sends robots among walls (Algorithm 1's blobs, their viewpoints, Algorithm 2 on the free paths'
  lengths), to its blob's viewpoint along the free path, and stares at the blob from there for
  :data:`STARE_PERIODS` periods; a robot with nothing left for it stays.
"""

from __future__ import annotations

import math

import numpy as np

from model.controllers.anicov.route import CARROT_PERIOD, Stop
from model.controllers.anicov.terrain_plan import TourPlan, tour_line, tour_plan, tour_shares
from model.controllers.anicov.terrain_routes import hop_path
from model.scenario import Scenario
from model.world.reachability import nearest_reachable
from model.world.world import World, world_of

STARE_PERIODS = 4
"""Plan periods a robot sent to a blob's viewpoint faces the blob (a blob left after that gets another)."""


def terrain_routes(scenario: Scenario, positions: np.ndarray) -> tuple[list[np.ndarray], list[list[Stop]]]:
    """Every robot's route (M_i, 2) and its stops, from its position through its share of the tour."""
    world, plan = world_of(scenario), tour_plan(scenario)
    points, along, arrivals = tour_line(plan, scenario.k_v)
    shares = tour_shares(world, points, along, positions)
    routes, stops = [], []
    for robot, (start, end) in enumerate(shares):
        route, own = _share(world, plan, (points, along), arrivals, positions[robot], (start, end), scenario)
        routes.append(route)
        stops.append(own)
    return routes, stops


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
    first = points[inside[0]] if len(inside) else points[np.searchsorted(along, start).clip(0, len(points) - 1)]
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
    route_points = np.array(route, dtype=np.float64).reshape(-1, 2)
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(route_points, axis=0), axis=1))])
    return route_points, [Stop(float(lengths[index]), bearings) for index, bearings in wanted]


def free_path(world: World, start: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """The free path's points from ``start`` (anywhere a robot stands) to ``goal`` (a reachable cell's centre,
    or a point on a free path): from the reachable cell nearest the start where its own is not."""
    cell = world.scenario.cell
    row, col = math.floor(start[1] / cell), math.floor(start[0] / cell)
    rows, cols = world.reachable.shape
    inside = 0 <= row < rows and 0 <= col < cols and world.reachable[row, col]
    begin = (
        np.asarray(start, dtype=np.float64) if inside else nearest_reachable(world.reachable, start[None, :], cell)[0]
    )
    end = nearest_reachable(world.reachable, np.asarray(goal, dtype=np.float64)[None, :], cell)[0]
    path = hop_path(world, begin, end)
    path = np.vstack([start[None, :], path[1:]]) if not inside else path
    return np.vstack([path, np.asarray(goal)[None, :]]) if not np.allclose(path[-1], goal) else path


def stare_route(world: World, position: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, Stop]:
    """A free robot's way to where it sees the uncovered cell at ``target`` (:func:`stand_for`) and its stop
    there facing it."""
    place = stand_for(world, position, target)
    path = free_path(world, position, place)
    length = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) if len(path) > 1 else 0.0
    bearing = math.atan2(float(target[1] - place[1]), float(target[0] - place[0]))
    return path, Stop(length, [bearing] * STARE_PERIODS)


def stand_for(world: World, position: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Where a robot stands to look at the cell about ``target``: the reachable cell that sees its centre
    (:func:`model.world.reachability.seers`) at a gap between R/4 and R/2 (a camera never sees what it stands
    on, and eq. 2's α falls off toward R), nearest the robot; any seer where none lies so; the nearest
    reachable cell where none sees it."""
    found = world.seers_of(float(target[0]), float(target[1]))
    if not len(found):
        return nearest_reachable(world.reachable, np.asarray(target, dtype=np.float64)[None, :], world.scenario.cell)[0]
    mid = (found[:, 0] >= 0.25 * world.scenario.range) & (found[:, 0] <= 0.5 * world.scenario.range)
    pool = found[mid] if mid.any() else found
    nearest = int(np.argmin(np.hypot(pool[:, 1] - position[0], pool[:, 2] - position[1])))
    return pool[nearest, 1:].copy()
