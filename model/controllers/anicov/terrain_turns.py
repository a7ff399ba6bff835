"""Turns at stations among walls (issue 37's study): two robots whose next stations lie nearer than
:func:`station_gap` cannot both stand at them, so the one nearer its own station goes first and the other waits.

The programme places stations with no thought of who stands where when: two robots' shares may pass the same
corridor, a relief or a cleanup may give a robot the station beside one a teammate is still staring from. Each
then drives at its station and the safety filter holds it off the other; the one standing turns its look-ahead
point toward the other and is held too, and the deadlock's detours take both away and back for good (the MRPT
lab, N = 10, seed 4, kinematic: two such pairs from t = 50 to the end, 400 deadlocks, a cell given up; two rooms,
N = 10, seed 1, physics: about 15 time units).

- **Who waits** (:func:`who_waits`): a robot whose next station is within the gap of a teammate's next station waits
  when that teammate has less of its route left to its own (ties, as between two robots that have both come to their
  stations: the one nearer its own in a straight line, then the lower id), once it would come within the gap of the
  teammate's station in the coming plan period; farther off it flies on, as the teammate may be gone by the time it
  arrives. The way left along the route, not the straight line, ranks them: it never grows, so two robots round a
  pillar do not swap. A robot standing on the teammate's way to its station does not wait there: it would hold the
  teammate it waits for, and going it clears the way. Where each stands on the other's way (both near stations
  nearer than the gap), going holds both for good, so the one ranked second waits, out of the way (the MRPT lab,
  N = 10, seed 7, the issue's noise: two robots 0.11 and 0.14 m off stations 0.3 m apart held each other and two
  teammates waiting for them from t = 282 to 584). The first robot of every such group goes, so some robot always
  goes; and a robot waits at most :data:`MOST_WAIT_PLANS` plans in a row (two planners that differ about a teammate,
  with a limited radio, could each make their own robot wait).
- **Where it waits** (:func:`wait_carrot`): where it stands, facing its station, when it is at least the gap from
  every station it waits for; else back along its own route, a plan period's way at a time, to the nearest point
  that far; where there is none, where it stands. A robot on a teammate's way steps aside to wait
  (:func:`aside_carrot`), as a robot with nothing to do does.

The rule is the planner's, pure, so the coordinator's carrots are the engine's; it changes nothing where no two
next stations are that near.
"""

from __future__ import annotations

import math

import numpy as np

from model.controllers.anicov.route import Route
from model.controllers.anicov.terrain_lanes import free_path
from model.controllers.anicov.terrain_relief import aside, in_the_way
from model.scenario import Scenario
from model.scenario.physics_keys import pair_margin_of
from model.world.world import World

MOST_WAIT_PLANS = 120
"""The most plans in a row a robot waits its turn (60 time units): longer than a teammate's longest cleanup station
(48 periods) and the next beside it."""


def station_gap(scenario: Scenario) -> float:
    """The least distance between two robots' stations at which both may turn in place at once: the filter
    keeps their look-ahead points 2 r + the pair's margin + 2 l apart (:mod:`model.safety.barrier_constraints`),
    and each point swings l round its centre, so their centres 2 r + margin + 4 l."""
    return 2.0 * scenario.robot_radius + pair_margin_of(scenario) + 4.0 * scenario.lookahead


def next_station(route: Route) -> np.ndarray | None:
    """Where a route's next stop lies; None without one."""
    return route.point_at(route.stops[0].at) if route.stops else None


def who_waits(
    routes: dict[int, Route], positions: np.ndarray, ids: list[int], gap: float, approach: float, spacing: float
) -> dict[int, list[int]]:
    """For each robot (index into ``ids``) that waits, the indices of the robots it waits for (see the module):
    ``approach`` is how far a robot goes in a plan period, ``spacing`` the step of the test whether it stands on a
    teammate's way (:func:`model.controllers.anicov.terrain_relief.in_the_way`)."""
    stations = {index: next_station(routes[agent]) for index, agent in enumerate(ids)}
    ahead = {index: place for index, place in stations.items() if place is not None}
    left = {index: routes[ids[index]].stops[0].at - routes[ids[index]].progress for index in ahead}
    rank = {
        index: (left[index], float(np.hypot(*(place - positions[index]))), ids[index]) for index, place in ahead.items()
    }
    waits: dict[int, list[int]] = {}
    for index, place in ahead.items():
        first = [
            other
            for other, there in ahead.items()
            if other != index
            and float(np.hypot(*(there - place))) < gap
            and float(np.hypot(*(there - positions[index]))) < gap + approach
            and rank[other] < rank[index]
            and not _holds_only(routes, positions, ids, (index, other), (gap, spacing))
        ]
        if first:
            waits[index] = first
    return waits


def _holds_only(
    routes: dict[int, Route], positions: np.ndarray, ids: list[int], pair: tuple[int, int], reach: tuple[float, float]
) -> bool:
    """Whether the robot ``pair[0]`` stands on the way of ``pair[1]`` to its station while that one does not stand
    on its own (``reach``: the gap and the test's spacing): going, it clears the way (:func:`who_waits`)."""
    index, other = pair
    gap, spacing = reach
    return in_the_way(routes[ids[other]], positions[index], gap, spacing) and not in_the_way(
        routes[ids[index]], positions[other], gap, spacing
    )


def aside_carrot(
    world: World, position: np.ndarray, blockers: list[Route], gap: float, step: float
) -> np.ndarray | None:
    """The carrot of a robot at ``position`` that waits for teammates on whose ways (``blockers``, each up to its
    next stop) it stands: ``step`` along the free path to where it stands out of them
    (:func:`model.controllers.anicov.terrain_relief.aside`); None where it stands on none of them, or there is no
    such place (it waits as :func:`wait_carrot` says)."""
    if not any(in_the_way(route, position, gap, 0.5 * world.scenario.cell) for route in blockers):
        return None
    place = aside(world, position, blockers, gap)
    if place is None:
        return None
    return Route.of(free_path(world, np.asarray(position, dtype=np.float64), place)).point_at(step)


def wait_carrot(
    route: Route, position: np.ndarray, blockers: list[np.ndarray], gap: float, face_radius: float, step: float
) -> np.ndarray:
    """The carrot of a robot at ``position`` that waits for the stations ``blockers`` (see the module): a point
    ``face_radius`` / 2 toward its station (the law stands and faces it) where it is ``gap`` from every blocker; else
    its route's point at most ``step`` behind where it stands on it, toward the nearest point behind that is ``gap``
    from every blocker (searched back from its progress every ``step``), or where it stands if there is none."""
    blocked = np.asarray(blockers, dtype=np.float64).reshape(-1, 2)

    def clear(point: np.ndarray) -> bool:
        return bool(np.min(np.hypot(*(blocked - point).T)) >= gap)

    if not clear(position):
        at = route.progress
        while at > 0.0:
            at = max(0.0, at - step)
            if clear(route.point_at(at)):
                return route.point_at(max(at, _standing_at(route, position, at, step) - step))
    station = next_station(route)
    toward = (station - position) if station is not None else np.zeros(2)
    length = float(np.hypot(*toward))
    if length < 1e-9:
        bearing = route.stops[0].bearings[0] if route.stops and route.stops[0].bearings else 0.0
        toward, length = np.array([math.cos(bearing), math.sin(bearing)]), 1.0
    return np.asarray(position, dtype=np.float64) + 0.5 * face_radius * toward / length


def _standing_at(route: Route, position: np.ndarray, back: float, step: float) -> float:
    """The arc length between ``back`` and the route's progress (every ``step`` / 4) nearest ``position``: where a
    robot backing off along the route stands on it (the last such on a tie: the one it has come least far from)."""
    count = max(1, math.ceil((route.progress - back) / (0.25 * step)))
    arcs = np.linspace(back, route.progress, count + 1)
    gaps = [float(np.hypot(*(route.point_at(float(arc)) - position))) for arc in arcs]
    return float(arcs[len(gaps) - 1 - int(np.argmin(gaps[::-1]))])
