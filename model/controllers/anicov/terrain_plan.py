"""anicov's plan among walls as one line in time, and each robot's share of it (issue 36, item 1).

- **The tour** (:func:`tour_plan`): the programme's periods made whole (:func:`stations.whole_periods`, as on
  the open square), the stations that stare at all visited in a tour by the free path's length
  (:func:`terrain_routes.station_tour`), the hops between them as free paths (:func:`terrain_routes.hop_path`),
  and at each station its bearings in one sweep (:func:`stations.bearing_sequence`), arriving along the hop
  in and leaving along the hop out.
- **The line in time** (:func:`tour_line`): the hops at k_v, each station held for its periods, in units of
  k_v travel, as :func:`stations.timeline` has the serpentine.
- **The shares** (:func:`tour_shares`): the line cut into N pieces of equal time and each piece given to a
  robot so that the slowest robot's way to its piece (the free path's length) plus the piece is least
  (:func:`routes.bottleneck_assignment`). Robots that start among the stations they stare from go to the
  nearest piece; a share cut inside a station's periods keeps whole periods, as on the open square.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from model.controllers.anicov.route import CARROT_PERIOD
from model.controllers.anicov.routes import bottleneck_assignment
from model.controllers.anicov.stations import bearing_sequence, whole_periods
from model.controllers.anicov.terrain_routes import hop_path, station_tour, travel_lengths
from model.controllers.anicov.terrain_stations import programme_among_walls
from model.paper.polyline import point_along
from model.scenario import Scenario
from model.world.reachability import nearest_reachable
from model.world.world import World, world_of


@dataclass(frozen=True)
class TourPlan:
    """The stations in the order flown (K, 2), the bearings each faces (one per period), and the hop from
    each station to the next (K - 1 free paths, each from one station's centre to the next's)."""

    stations: np.ndarray
    bearings: tuple[tuple[float, ...], ...]
    hops: tuple[np.ndarray, ...]


def tour_plan(scenario: Scenario) -> TourPlan:
    """The tour among the scenario's walls (see the module)."""
    world = world_of(scenario)
    programme = programme_among_walls(scenario)
    need = np.ones(len(programme.rows))
    periods = whole_periods(programme.stares, need, programme.periods.ravel()).reshape(programme.periods.shape)
    staring = np.flatnonzero(periods.sum(axis=1) > 0)
    stations = programme.stations[staring]
    order = station_tour(travel_lengths(world, stations))
    return tour_of(world, stations[order], periods[staring][order], scenario)


def tour_of(world: World, stations: np.ndarray, periods: np.ndarray, scenario: Scenario) -> TourPlan:
    """The tour over ``stations`` (K, 2) in this order, each with its whole ``periods`` (K, BEARINGS): the hops
    between them as free paths, and at each its bearings in one sweep, arriving along the hop in and leaving
    along the hop out."""
    hops = tuple(hop_path(world, a, b) for a, b in itertools.pairwise(stations))
    turn = math.pi * scenario.k_omega * CARROT_PERIOD
    bearings = []
    for k, row in enumerate(periods):
        arrive = _heading(hops[k - 1][-2], hops[k - 1][-1]) if k and len(hops[k - 1]) > 1 else None
        leave = _heading(hops[k][0], hops[k][1]) if k < len(hops) and len(hops[k]) > 1 else None
        bearings.append(tuple(bearing_sequence(row, arrive, leave, turn, turn_in=True)))
    return TourPlan(np.asarray(stations, dtype=np.float64).reshape(-1, 2), tuple(bearings), hops)


def _heading(a: np.ndarray, b: np.ndarray) -> float:
    return math.atan2(float(b[1] - a[1]), float(b[0] - a[0]))


def tour_line(plan: TourPlan, k_v: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(points (M, 2), along (M,), arrivals (K,)): the tour as a line in time, in units of k_v travel (each
    hop's legs, each station's point at its arrival and again when its periods are done), and where along it
    each station is reached."""
    period = CARROT_PERIOD * k_v
    points, along, arrivals, now = [], [], [], 0.0
    for k, station in enumerate(plan.stations):
        if k:
            for a, b in itertools.pairwise(plan.hops[k - 1]):
                now += float(np.linalg.norm(b - a))
                points.append(b)
                along.append(now)
        else:
            points.append(station)
            along.append(now)
        arrivals.append(now)
        if plan.bearings[k]:
            now += len(plan.bearings[k]) * period
            points.append(station)
            along.append(now)
    return np.array(points, dtype=np.float64).reshape(-1, 2), np.array(along), np.array(arrivals)


def tour_shares(
    world: World, points: np.ndarray, along: np.ndarray, positions: np.ndarray
) -> list[tuple[float, float]]:
    """Each robot's share (start, end) of the line, in units of k_v travel: N pieces of equal time, given so
    that the slowest robot's free path to its piece's start plus the piece is least."""
    agents, total = len(positions), float(along[-1]) if len(along) else 0.0
    cuts = np.linspace(0.0, total, agents + 1)
    cell = world.scenario.cell
    cost = np.zeros((agents, agents))
    for piece in range(agents):
        start = point_along(points, along, float(cuts[piece]))
        goal = nearest_reachable(world.reachable, np.asarray(start)[None, :], cell)[0]
        field = world.field(float(goal[0]), float(goal[1]))
        for robot, (x, y) in enumerate(positions):
            row, col = min(int(y // cell), field.shape[0] - 1), min(int(x // cell), field.shape[1] - 1)
            cost[robot, piece] = field[row, col] + cuts[piece + 1] - cuts[piece]
    robots, pieces = bottleneck_assignment(np.where(np.isfinite(cost), cost, 1e12))
    shares: list[tuple[float, float]] = [(0.0, 0.0)] * agents
    for robot, piece in zip(robots, pieces, strict=True):
        shares[int(robot)] = (float(cuts[piece]), float(cuts[piece + 1]))
    return shares
