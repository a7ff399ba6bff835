"""How anicov's robots fly among walls once their routes are cut (issue 36, items 1 and 2): patches as a
station is left, and the cleanup when a route is done (:mod:`model.controllers.anicov.terrain_cleanup` has the
programmes).

- **A patch where the robot stands** (:meth:`TerrainFlight.patch`): the moment a robot has faced its station's
  last bearing, the cells its stares there should have finished may still be short (it stood a little off,
  turned between bearings, a wall hid a corner). A robot there now pays a few periods for what a cleanup
  later pays a trip across the map for: the station gets the periods that bring what is left near it to Λ*,
  where nothing still on anyone's route will stare.
- **The cleanup**: when a robot's route is done, or every :data:`CLEANUP_RETRY` plans while one waits, the
  cleanup is planned again for every robot done with its route or still on its way to its cleanup's first
  station, on what the others will not stare at; a robot given nothing stays. A cleanup route flown to its
  end that took less than :data:`CLEANUP_PROGRESS` of its cells' Υ has its stations banned from later
  cleanups (the robot could not stand or face as the stares assume), so that no robot is sent there for ever.
- **Turns** (:mod:`model.controllers.anicov.terrain_turns`): of two robots whose next stations are too near for both
  to stand there, the one with more of its way left waits once it comes near (:attr:`TerrainFlight.held` has its
  carrot).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from model.controllers.anicov.deposit import Deposit
from model.controllers.anicov.route import CARROT_PERIOD, Route, Stop, arrive_radius_of, face_radius_of
from model.controllers.anicov.terrain_cleanup import (
    cleanup_pieces,
    cleanup_stations,
    left_near,
    residual_lack,
    station_patch,
)
from model.controllers.anicov.terrain_lanes import free_path, piece_route
from model.controllers.anicov.terrain_relief import aside, in_the_way, relief
from model.controllers.anicov.terrain_seers import cell_of
from model.controllers.anicov.terrain_stations import ANGLES, deposit_among_walls
from model.controllers.anicov.terrain_turns import (
    MOST_WAIT_PLANS,
    aside_carrot,
    next_station,
    station_gap,
    wait_carrot,
    who_waits,
)
from model.scenario import Scenario
from model.scenario.physics_keys import pair_margin_of
from model.world.world import world_of

CLEANUP_RETRY = 4
"""Plans between two tries at a cleanup while a robot waits with nothing to do (2 time units)."""
DETOUR_MOST = 2.0
"""The longest detour (there and back, in R) a robot leaving a station takes to finish what it leaves behind."""
CLEANUP_PROGRESS = 0.1
"""The share of its cells' Υ a cleanup route must take away, or its stations are banned."""


@dataclass
class TerrainFlight:
    """The state of the flight among walls: how many stops each robot had at the last plan and the bearing it
    was given then, the robots standing with nothing to do, the plans until the cleanup is tried again, each
    cleaning robot's (station cells, cells its stares reach, their Υ when given), the banned cells, and who waits its turn at a station (:meth:`TerrainFlight.take_turns`)."""

    scenario: Scenario
    stops_left: dict[int, int] = field(default_factory=dict)
    facing: dict[int, float] = field(default_factory=dict)
    patched: dict[int, float] = field(default_factory=dict)  # where a robot's patch stop stands (arc length)
    detour_ends: dict[int, float] = field(default_factory=dict)  # where a robot's detour rejoins its route
    idle: set[int] = field(default_factory=set)
    cleanup_wait: int = 0
    cleaning: dict[int, tuple[list[tuple[int, int]], np.ndarray, float]] = field(default_factory=dict)
    banned: set[tuple[int, int]] = field(default_factory=set)
    held: dict[int, np.ndarray] = field(default_factory=dict)  # this plan's carrot of each robot that waits its turn
    waited: dict[int, int] = field(default_factory=dict)  # plans in a row each robot has waited its turn

    def steer(
        self, routes: dict[int, Route], lack: np.ndarray, positions: np.ndarray, ids: list[int], free: list[int]
    ) -> None:
        """Before this plan's carrots (after every route's advance): patches, the cleanup, robots with nothing to do
        stepping aside, then who waits its turn at a station."""
        for agent in ids:
            route = routes[agent]
            if not route.cleanup and len(route.stops) < self.stops_left.get(agent, 0):
                patch_done = self.patched.pop(agent, None) == route.progress
                if not patch_done and route.progress > self.detour_ends.get(agent, -1.0):  # nor a detour's stop
                    self.patch(routes, agent, lack)
        self.clean_up(routes, lack, positions, ids, free)
        self.make_way(routes, positions, ids)
        self.take_turns(routes, positions, ids)
        for agent in ids:
            route = routes[agent]
            self.stops_left[agent] = len(route.stops)
            if route.stops and route.stops[0].bearings:
                self.facing[agent] = route.stops[0].bearings[0]

    def make_way(self, routes: dict[int, Route], positions: np.ndarray, ids: list[int]) -> None:
        """A robot with nothing to do that stands in a busy teammate's way to its next stop steps aside
        (:func:`terrain_relief.aside`); it stays idle."""
        scenario = self.scenario
        gap = 2.0 * (2.0 * scenario.robot_radius + pair_margin_of(scenario)) + scenario.lookahead
        busy = [routes[agent] for agent in ids if agent not in self.idle and not routes[agent].done()]
        for index, agent in enumerate(ids):
            if agent not in self.idle or not routes[agent].done() or not busy:
                continue
            if not any(in_the_way(way, positions[index], gap, 0.5 * scenario.cell) for way in busy):
                continue
            world = world_of(scenario)
            place = aside(world, positions[index], busy, gap)
            if place is not None:
                routes[agent] = Route.of(free_path(world, positions[index], place), cleanup=True)

    def take_turns(self, routes: dict[int, Route], positions: np.ndarray, ids: list[int]) -> None:
        """Who waits for a teammate's station this plan, and where (:mod:`terrain_turns`): :attr:`held`; a robot
        that has waited :data:`terrain_turns.MOST_WAIT_PLANS` plans in a row goes on until it waits no more."""
        scenario = self.scenario
        gap, face, approach = station_gap(scenario), face_radius_of(scenario), scenario.k_v * CARROT_PERIOD
        waits = who_waits(routes, positions, ids, gap, approach, 0.5 * scenario.cell)
        self.held = {}
        for index, agent in enumerate(ids):
            if index not in waits:
                self.waited.pop(agent, None)
                continue
            self.waited[agent] = self.waited.get(agent, 0) + 1
            if self.waited[agent] > MOST_WAIT_PLANS:
                continue
            ways = [routes[ids[other]] for other in waits[index]]
            held = aside_carrot(world_of(scenario), positions[index], ways, gap, approach)
            if held is None:
                blockers = [next_station(way) for way in ways]
                held = wait_carrot(routes[agent], positions[index], blockers, gap, face, approach)
            self.held[agent] = held

    def patch(self, routes: dict[int, Route], agent: int, lack: np.ndarray) -> None:
        """The robot has just faced its station's last bearing: a stop where it stands with the bearings that
        finish the cells near it (:func:`terrain_cleanup.station_patch`), if any are left to it."""
        route = routes[agent]
        station = route.point_at(route.progress)
        ahead = route.point_at(route.progress + 2.0 * self.scenario.range)
        leave = math.atan2(ahead[1] - station[1], ahead[0] - station[0]) if route.progress < route.length else None
        others = [other for key, other in routes.items() if key != agent] + [route]
        world, deposit = world_of(self.scenario), self._deposit()
        bearings = station_patch(world, deposit, lack, station, others, (self.facing.get(agent), leave))
        if bearings:
            route.stops.insert(0, Stop(route.progress, bearings))
            self.patched[agent] = route.progress
        behind = left_near(world, deposit, lack, station, others)
        if not (behind > 0.0).any():
            return
        stations, periods = cleanup_stations(world, deposit, behind, frozenset(self.banned))
        detour = self._detour(route, stations, periods) if len(stations) else None
        if detour is not None:
            routes[agent], self.detour_ends[agent] = detour
            if bearings:
                self.patched[agent] = 0.0

    def _detour(self, route: Route, stations: np.ndarray, periods: np.ndarray) -> tuple[Route, float] | None:
        """(``route`` from where it has come with a detour through ``stations`` (their ``periods``) and back to
        that point first, the detour's length), when that length is at most :data:`DETOUR_MOST` R; else None."""
        world, scenario = world_of(self.scenario), self.scenario
        here = route.point_at(route.progress)
        out, stops = piece_route(world, scenario, here, stations, periods)
        back = free_path(world, out[-1], here)
        there = Route.of(out).length + Route.of(back).length
        if there > DETOUR_MOST * scenario.range:
            return None
        rest = np.vstack([here[None, :], route.points[route.along > route.progress]])
        here_first = [Stop(0.0, stop.bearings) for stop in route.stops if stop.at <= route.progress + 1e-9]  # its patch
        later = [
            Stop(stop.at - route.progress + there, stop.bearings)
            for stop in route.stops
            if stop.at > route.progress + 1e-9
        ]
        return Route.of(np.vstack([out, back[1:], rest[1:]]), stops=[*here_first, *stops, *later]), there

    def clean_up(
        self, routes: dict[int, Route], lack: np.ndarray, positions: np.ndarray, ids: list[int], free: list[int]
    ) -> None:
        """The cleanup (see the module). ``free`` was found before this plan's patches: a robot given a patch or a
        detour has its route again and is left out (else its patch is thrown away for a standing cleanup route)."""
        free = [index for index in free if routes[ids[index]].done()]
        just_done = [index for index in free if ids[index] not in self.idle]
        for index in just_done:
            self._judge(ids[index], lack)
            routes[ids[index]] = Route.of(positions[index][None, :], cleanup=True)
            self.idle.add(ids[index])
        self.cleanup_wait -= 1
        if not free or not (just_done or self.cleanup_wait <= 0):
            return
        self.cleanup_wait = CLEANUP_RETRY
        for index in free:
            self._relieve(routes, ids, ids[index], positions[index])
        free = [index for index in free if ids[index] in self.idle]
        if not free:
            return
        team = [index for index, agent in enumerate(ids) if self._may_recut(routes[agent])]
        busy = [routes[agent] for index, agent in enumerate(ids) if index not in team]
        world, deposit = world_of(self.scenario), self._deposit()
        need = residual_lack(deposit, lack, busy)
        stations, periods = cleanup_stations(world, deposit, need, frozenset(self.banned))
        pieces = cleanup_pieces(world, stations, periods, positions[team])
        for index, (own, own_periods) in zip(team, pieces, strict=True):
            agent = ids[index]
            self.cleaning.pop(agent, None)  # cut anew before it was done: not judged
            if not len(own):
                routes[agent] = Route.of(positions[index][None, :], cleanup=True)
                self.idle.add(agent)
                continue
            path, stops = piece_route(world, self.scenario, positions[index], own, own_periods)
            routes[agent] = Route.of(path, cleanup=True, stops=stops)
            self.idle.discard(agent)
            reached = np.unique(np.concatenate([deposit.stare_cells(*xy, a)[0] for xy in own for a in ANGLES]))
            cells = [cell_of(point, self.scenario.cell) for point in own]
            self.cleaning[agent] = (cells, reached, float(lack.ravel()[reached].sum()))

    def _relieve(self, routes: dict[int, Route], ids: list[int], agent: int, position: np.ndarray) -> None:
        """``agent``, done, takes over the end of the route of the robot with the most left to fly, where that
        brings the team's end sooner (:func:`terrain_relief.relief`)."""
        busy = [other for other in ids if not routes[other].cleanup and not routes[other].done()]
        given = relief(world_of(self.scenario), routes, busy, position)
        if given is None:
            return
        routes[given.relieved], routes[agent] = given.kept, given.taken
        self.idle.discard(agent)
        self.patched.pop(agent, None)
        self.detour_ends.pop(agent, None)

    def _may_recut(self, route: Route) -> bool:
        """Whether a robot joins the cleanup's next cut: done with its route, or on its way to the first station of
        its cleanup route (one standing at a station finishes its stares there: cut anew, it would begin them
        again)."""
        if route.done():
            return True
        first = route.stops[0].at if route.stops else route.length
        return route.cleanup and route.progress < first - arrive_radius_of(self.scenario)

    def _judge(self, agent: int, lack: np.ndarray) -> None:
        """Ban the stations of a cleanup route flown to its end that took too little (see the module)."""
        judged = self.cleaning.pop(agent, None)
        if judged is None:
            return
        cells, reached, before = judged
        if before > 0.0 and float(lack.ravel()[reached].sum()) > (1.0 - CLEANUP_PROGRESS) * before:
            self.banned.update(cells)

    def _deposit(self) -> Deposit:
        return deposit_among_walls(self.scenario)
