"""Relief among walls (issue 36, item 2: the team's shares re-balanced when someone falls behind).

The shares are cut so that every robot would finish together if each flew its line as planned; none does
(a filter holds one, another's hops wind round more corners than the line counted, patches and detours add
periods where the flight fell short). The team finishes with its slowest robot. So a robot done with its
route takes over the end of the route of the robot with the most left to fly
(:func:`relief`): the cut is put before the stop that makes the later of the two finish soonest, the robot
behind keeps the stops before it, and the one relieving drives the free path to it and flies the rest.

A robot with nothing to do stands still, and standing beside a teammate's next station it holds that teammate
for good (the filter keeps them 2 r + s apart; lab N = 2 seed 15 gave 3 cells up so): it steps aside
(:func:`in_the_way`, :func:`aside`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from model.controllers.anicov.route import CARROT_PERIOD, Route, Stop
from model.controllers.anicov.terrain_lanes import free_path
from model.world.reachability import nearest_reachable
from model.world.world import World

RELIEF_GAIN = 4.0
"""A relief is made only where it brings the team's end at least this many plan periods sooner."""


@dataclass(frozen=True)
class Relief:
    """The robot relieved, what it keeps (its route up to its last stop before the cut) and the reliever's route from
    where it stands."""

    relieved: int
    kept: Route
    taken: Route


def time_left(route: Route, k_v: float) -> float:
    """Time units a robot needs for what is left of its route: its length at k_v and its stops' periods."""
    stares = sum(len(stop.bearings) for stop in route.stops) * CARROT_PERIOD
    return max(0.0, route.length - route.progress) / k_v + stares


def relief(world: World, routes: dict[int, Route], busy: list[int], position: np.ndarray) -> Relief | None:
    """The relief a robot standing at ``position`` gives (see the module) to the robot among ``busy`` with the
    most left to fly; None where no cut brings the end :data:`RELIEF_GAIN` periods sooner."""
    scenario = world.scenario
    k_v = scenario.k_v
    if not busy:
        return None
    behind = max(busy, key=lambda agent: (time_left(routes[agent], k_v), -agent))
    route = routes[behind]
    alone = time_left(route, k_v)
    field = world.field(float(position[0]), float(position[1]))
    best: tuple[float, int] | None = None
    stares_after = np.cumsum([len(stop.bearings) for stop in route.stops][::-1])[::-1] * CARROT_PERIOD
    for j, stop in enumerate(route.stops):
        if j == 0 or stop.at <= route.progress:
            continue  # the stop it is at or going to stays its own
        x, y = route.point_at(stop.at)
        row, col = int(y // scenario.cell), int(x // scenario.cell)
        way = float(field[row, col]) / k_v
        if not np.isfinite(way):
            continue
        kept = (stop.at - route.progress) / k_v + float(stares_after[0] - stares_after[j])
        taken = way + (route.length - stop.at) / k_v + float(stares_after[j])
        end = max(kept, taken)
        if best is None or end < best[0]:
            best = (end, j)
    if best is None or best[0] > alone - RELIEF_GAIN * CARROT_PERIOD:
        return None
    return _cut(world, route, best[1], behind, position)


def _cut(world: World, route: Route, j: int, behind: int, position: np.ndarray) -> Relief:
    """The routes of a relief cut before stop ``j`` of ``route``: the robot relieved keeps its route up to its last
    stop before the cut. Driven on to the cut, the reliever's first stop, it had nothing left to do there and
    stood in the reliever's way (the MRPT lab with the issue's noise, N = 4, seed 1: with an idle robot stepping
    aside, three robots jammed in a pocket by a wall from t = 685 to 1,010; 1,012.1 -> 853.3). What the hops between
    that stop and the cut would have seen is left to the cleanup. (:func:`relief` still times the robot relieved
    to the cut: an upper bound.)"""
    at, last = route.stops[j].at, route.stops[j - 1].at  # j >= 1: the stop a robot is at or going to stays its own
    head = np.vstack([route.points[route.along < last], route.point_at(last)[None, :]])
    kept = Route.of(head, stops=[Stop(stop.at, stop.bearings) for stop in route.stops[:j]])
    kept.progress = route.progress
    way = free_path(world, position, route.point_at(at))
    way_length = Route.of(way).length
    tail = route.points[route.along > at]
    points = np.vstack([way, tail])
    stops = [Stop(stop.at - at + way_length, stop.bearings) for stop in route.stops[j:]]
    return Relief(behind, kept, Route.of(points, stops=stops))


def in_the_way(route: Route, position: np.ndarray, gap: float, spacing: float) -> bool:
    """Whether a robot standing at ``position`` is within ``gap`` of what is left of ``route`` up to its next
    stop (points every ``spacing`` along it): the safety filter would hold the robot flying it there."""
    return bool(np.min(np.hypot(*(_ahead(route, spacing) - position).T)) < gap)


def aside(world: World, position: np.ndarray, ways: list[Route], gap: float) -> np.ndarray | None:
    """Where a robot with nothing to do stands out of the way of ``ways`` (each up to its next stop): the
    reachable cell's centre nearest it by the free path at least 1.5 ``gap`` from each; None where none is."""
    cell = world.scenario.cell
    blocked = np.vstack([_ahead(route, 0.5 * cell) for route in ways])
    centres = (np.argwhere(world.reachable)[:, ::-1] + 0.5) * cell
    clear = cKDTree(blocked).query(centres)[0] >= 1.5 * gap
    if not clear.any():
        return None
    # A robot may stand in a cell outside the team's space (the filter keeps its disk off the wall, not its centre
    # off the cell's): the free paths are measured from the reachable cell nearest it, as free_path goes.
    start = nearest_reachable(world.reachable, np.asarray(position, dtype=np.float64)[None, :], cell)[0]
    field = world.field(float(start[0]), float(start[1]))
    rows, cols = np.floor(centres[clear, 1] / cell).astype(int), np.floor(centres[clear, 0] / cell).astype(int)
    lengths = field[rows, cols]
    if not np.isfinite(lengths).any():
        return None
    return centres[clear][int(np.argmin(lengths))]


def _ahead(route: Route, spacing: float) -> np.ndarray:
    """Points every ``spacing`` along ``route`` from its progress to its next stop (its end if none)."""
    end = route.stops[0].at if route.stops else route.length
    steps = max(1, int(np.ceil(max(0.0, end - route.progress) / spacing)))
    return np.array([route.point_at(route.progress + (end - route.progress) * k / steps) for k in range(steps + 1)])
