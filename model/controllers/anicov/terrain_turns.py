"""Turns at stations among walls (issue 37's study): two robots whose next stations lie nearer than
:func:`station_gap` cannot both stand at them, so the one nearer its own station goes first and the other waits.

The programme places stations with no thought of who stands where when: two robots' shares may pass the same
corridor, a relief or a cleanup may give a robot the station beside one a teammate is still staring from. Each
then drives at its station and the safety filter holds it off the other; the one standing turns its look-ahead
point toward the other and is held too, and the deadlock's detours take both away and back for good (the MRPT
lab, N = 10, seed 4, kinematic: two such pairs from t = 50 to the end, 400 deadlocks, a cell given up; two rooms,
N = 10, seed 1, physics: about 15 time units).

- **Who waits** (:func:`who_waits`): a robot whose next station is within the gap of a teammate's next station
  waits when that teammate is nearer its own (ties: the lower id goes first), once it would come within the gap of
  the teammate's station in the coming plan period; farther off it flies on, as the teammate may be gone by the
  time it arrives. The nearest robot of every such group goes, so some robot always goes.
- **Where it waits** (:func:`wait_carrot`): where it stands, facing its station, when it is at least the gap from
  every station it waits for; else back along its own route (a way it has come, so free) to the nearest point
  that far; where there is none, where it stands.

The rule is the planner's, pure, so the coordinator's carrots are the engine's; it changes nothing where no two
next stations are that near.
"""

from __future__ import annotations

import math

import numpy as np

from model.controllers.anicov.route import Route
from model.scenario import Scenario
from model.scenario.physics_keys import pair_margin_of


def station_gap(scenario: Scenario) -> float:
    """The least distance between two robots' stations at which both may turn in place at once: the filter
    keeps their look-ahead points 2 r + the pair's margin + 2 l apart (:mod:`model.safety.barrier_constraints`),
    and each point swings l round its centre, so their centres 2 r + margin + 4 l."""
    return 2.0 * scenario.robot_radius + pair_margin_of(scenario) + 4.0 * scenario.lookahead


def next_station(route: Route) -> np.ndarray | None:
    """Where a route's next stop lies; None without one."""
    return route.point_at(route.stops[0].at) if route.stops else None


def who_waits(
    routes: dict[int, Route], positions: np.ndarray, ids: list[int], gap: float, approach: float
) -> dict[int, list[int]]:
    """For each robot (index into ``ids``) that waits, the indices of the robots it waits for (see the module):
    ``approach`` is how far a robot goes in a plan period."""
    stations = {index: next_station(routes[agent]) for index, agent in enumerate(ids)}
    ahead = {index: place for index, place in stations.items() if place is not None}
    distance = {index: float(np.hypot(*(place - positions[index]))) for index, place in ahead.items()}
    waits: dict[int, list[int]] = {}
    for index, place in ahead.items():
        first = [
            other
            for other, there in ahead.items()
            if other != index
            and float(np.hypot(*(there - place))) < gap
            and float(np.hypot(*(there - positions[index]))) < gap + approach
            and (distance[other], ids[other]) < (distance[index], ids[index])
        ]
        if first:
            waits[index] = first
    return waits


def wait_carrot(
    route: Route, position: np.ndarray, blockers: list[np.ndarray], gap: float, face_radius: float, spacing: float
) -> np.ndarray:
    """The carrot of a robot at ``position`` that waits for the stations ``blockers`` (see the module): a point
    ``face_radius`` / 2 toward its station (the law stands and faces it), or the point of its route behind it
    (every ``spacing`` back from its progress) nearest it that is ``gap`` from every blocker."""
    blocked = np.asarray(blockers, dtype=np.float64).reshape(-1, 2)

    def clear(point: np.ndarray) -> bool:
        return bool(np.min(np.hypot(*(blocked - point).T)) >= gap)

    if not clear(position):
        at = route.progress
        while at > 0.0:
            at = max(0.0, at - spacing)
            back = route.point_at(at)
            if clear(back):
                return back
    station = next_station(route)
    toward = (station - position) if station is not None else np.zeros(2)
    length = float(np.hypot(*toward))
    if length < 1e-9:
        bearing = route.stops[0].bearings[0] if route.stops and route.stops[0].bearings else 0.0
        toward, length = np.array([math.cos(bearing), math.sin(bearing)]), 1.0
    return np.asarray(position, dtype=np.float64) + 0.5 * face_radius * toward / length
