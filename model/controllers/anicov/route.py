"""A robot's route in the ``anicov`` controller: its polyline, how far along it the robot has come, the stations
it stands at (:mod:`model.controllers.anicov.stations`), and the carrot the planner gives it each plan period.

Beyond the paper (docs/controller.md): :class:`Route` is what :mod:`model.controllers.anicov.lane_planner` steers every robot
along and :func:`model.controllers.anicov.touch_ups.simulate_routes` flies to foretell it, so both give the same carrots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import cv2
import numpy as np
from numba import njit

from model.scenario import Scenario
from model.scenario.physics_keys import localiser_sigma_of

CARROT_PERIOD = 0.5
"""Time units between two carrots of one robot (:mod:`model.controllers.anicov.lane_planner`): the anicov
controller's plan period."""
FACE_RADIUS = 0.05
"""A carrot nearer the robot than this is a bearing to face (units; :func:`model.paper.control.pursuit_law`, the
stations of :mod:`model.controllers.anicov.stations`): half a step at k_v = 1, dt = 0.1, which the pursuit's last step toward a
station reaches (v = d/dt within one step of it)."""


def arrive_radius_of(scenario: Scenario) -> float:
    """How near its station a robot has arrived: the face radius (:func:`face_radius_of`), but among walls up to
    a step at k_v, and at most :data:`ARRIVE_CELLS` of a cell. A carrot a hair beside or behind the robot makes
    the pursuit creep round it (its speed falls with the heading's error and ω = k_ω e_θ turns slowly: on the
    campus, k_ω = 0.48, 696 of the run's 13,500 time units went below a tenth of k_v, nearly all of them beside
    a station; a step brought the run to 12,673); but a robot standing off its station sees the cells past a
    wall's corner less well than the stares count (on the lab, cells of 0.2 m, a step of 0.022 m made the runs
    4 % slower)."""
    face = face_radius_of(scenario)
    if not (scenario.has_terrain and scenario.stations):
        return face
    return max(face, min(scenario.k_v * scenario.dt, ARRIVE_CELLS * scenario.cell))


ARRIVE_CELLS = 1.0 / 16.0
"""The widest a robot's arrival at a station among walls may be, in cells (:func:`arrive_radius_of`)."""


def face_radius_of(scenario: Scenario) -> float:
    """:data:`FACE_RADIUS` where the anicov controller's robots stand at stations (its default, ``stations``),
    else 0: the one rule the planner's carrots and the robots' law both read. With a localiser's noise
    (physics, ``[noise]``) at least :data:`NOISE_FACE_SIGMAS` of its σ: a robot inside its belief's jitter
    has arrived; with late commands at least :data:`LATENCY_FACE_TRAVEL` times the way a robot goes at k_v
    before a command reaches its wheels."""
    if not scenario.stations:
        return 0.0
    if not scenario.has_terrain:
        return FACE_RADIUS
    face = FACE_RADIUS * scenario.k_v * scenario.dt / 0.1  # among walls, at the robot's units: half a step
    noise = dict(scenario.noise)
    late = LATENCY_FACE_TRAVEL * scenario.k_v * noise.get("command_latency", 0.0)
    return max(face, NOISE_FACE_SIGMAS * localiser_sigma_of(scenario), late)


LATENCY_FACE_TRAVEL = 2.0
"""A robot whose commands reach its wheels late runs past the point where it was told to stop and turns back
for it: two rooms and a door, N = 4, commands 0.1 late and no other noise, took 450 - 517 time units (seeds
0 - 4; 163.1 - 184.4 without the latency) with a face radius of half a step; with 2 k_v × 0.1, 158.1 - 168.1
(seeds 0 - 4). Not more: at 3 k_v × 0.1 one run in three (seeds 0 - 2) ended short."""

NOISE_FACE_SIGMAS = 1.0
"""A robot inside its belief's jitter has arrived. While each fix replaced the belief, a standing robot's belief
jumped by σ every period and it chased it round its station: two rooms and a door, N = 4, σ = 0.05, took 567.3
time units against 161.9 without noise; 2, 4 and 6 σ took 292.6, 204.9 and 194.0, and 6 σ was kept. The fused
belief (:mod:`model.physics.noise`) holds still while the robot stands, so 1 σ is enough: the two rooms, seeds
0 - 9, 182.4 against 180.8 at 6 σ (true coverage 100 % each; the command latency's face radius, 0.2, binds there).
On the MRPT lab, where σ is a quarter of a cell, 6 σ (1.5 cells) left 73 cells short with no station that surely
sees them at t = 1,400; 1 σ, with the cleanup's narrower seers, one."""


@dataclass
class Stop:
    """A station on a route (:mod:`model.controllers.anicov.stations`): where it lies (arc length along the route) and the
    bearings (radians) left to face there, one per plan period."""

    at: float
    bearings: list[float] = field(default_factory=list)


@dataclass
class Route:
    """A robot's polyline and how far along it (arc length) the robot has come."""

    points: np.ndarray  # (K, 2)
    along: np.ndarray  # (K,) cumulative arc length
    progress: float = 0.0
    cleanup: bool = False  # a pass over a blob (True) or the robot's piece of the lanes
    stops: list[Stop] = field(default_factory=list)  # stations still to stand at, in route order

    @classmethod
    def of(cls, points: np.ndarray, cleanup: bool = False, stops: list[Stop] | None = None) -> Route:
        points = np.asarray(points, dtype=np.float64)
        keep = np.concatenate([[True], np.linalg.norm(np.diff(points, axis=0), axis=1) > 1e-9])
        points = points[keep]
        along = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
        kept = [Stop(stop.at, list(stop.bearings)) for stop in stops or [] if stop.bearings]  # none to face: none
        return cls(points, along, 0.0, cleanup, kept)

    @property
    def length(self) -> float:
        return float(self.along[-1])

    def point_at(self, distance: float) -> np.ndarray:
        """The point ``distance`` along the route, held to its ends."""
        return np.array(point_on(self.points, self.along, distance))

    def advance(self, position: np.ndarray, window: float) -> None:
        """Progress := the nearest point of the route to ``position`` at most ``window`` ahead of where
        it was: no farther than the carrot the robot was given (so a neighbouring ring is never taken,
        nor, on a pass that doubles back over a small blob, the way back while it is still going out);
        the first such along the route on a tie; never past a stop not yet done (:func:`advanced`)."""
        reach = self.progress + window
        if self.stops:
            reach = min(reach, self.stops[0].at)
        self.progress = advanced(self.points, self.along, self.progress, reach, float(position[0]), float(position[1]))

    def done(self) -> bool:
        return self.progress >= self.length - 1e-6 and not self.stops

    def carrot(
        self, position: np.ndarray, lookahead: float, face_radius: float, arrive_radius: float | None = None
    ) -> np.ndarray:
        """The carrot for the coming plan period (after :meth:`advance`; :func:`carrot_on`): ``lookahead``
        ahead along the route, held at the next stop; at a stop, a bearing to face there, that bearing then
        done."""
        stop_at, bearing = (self.stops[0].at, self.stops[0].bearings[0]) if self.stops else (math.nan, 0.0)
        if lookahead <= 0.0:
            raise ValueError(f"a carrot's lookahead must be above 0, got {lookahead}")
        x, y = float(position[0]), float(position[1])
        carrot_x, carrot_y, self.progress, faced = carrot_on(
            self.points, self.along, self.progress, stop_at, bearing, x, y, lookahead, face_radius,
            face_radius if arrive_radius is None else arrive_radius,
        )  # fmt: skip
        if faced:
            self.stops[0].bearings.pop(0)
            if not self.stops[0].bearings:
                self.stops.pop(0)
        return np.array([carrot_x, carrot_y])

    def nearest(self, position: np.ndarray) -> tuple[float, float]:
        """(distance, arc length) of the route's point nearest to ``position``, the first on a tie."""
        if len(self.points) == 1:
            return float(np.linalg.norm(self.points[0] - position)), 0.0
        best_gap, best_at = math.inf, 0.0
        for k in range(len(self.points) - 1):
            at = _foot(self.points, self.along, k, float(position[0]), float(position[1]))
            gap = float(np.linalg.norm(self.point_at(at) - position))
            if gap < best_gap - 1e-9:
                best_gap, best_at = gap, at
        return best_gap, best_at

    def draw_ahead(self, canvas: np.ndarray, cell: float, width: int) -> None:
        """Draw what is left of the route (from its progress on) into ``canvas`` (uint8 grid), ``width``
        cells wide."""
        ahead = self.points[self.along > self.progress]
        line = np.vstack([self.point_at(self.progress), ahead]) / cell
        cv2.polylines(canvas, [np.round(line).astype(np.int32)], False, 1, thickness=width)


@njit(cache=True)
def point_on(points: np.ndarray, along: np.ndarray, distance: float) -> tuple[float, float]:
    """:meth:`Route.point_at` of the polyline ``points`` (K, 2) with arc lengths ``along`` (K,), compiled
    (:func:`model.paper.polyline.point_along`'s arithmetic, held to the ends)."""
    if len(points) == 1:
        return points[0, 0], points[0, 1]
    distance = min(max(distance, 0.0), along[-1])
    segment = min(np.searchsorted(along, distance, side="right") - 1, len(points) - 2)
    share = (distance - along[segment]) / max(along[segment + 1] - along[segment], 1e-300)
    x = points[segment, 0] + share * (points[segment + 1, 0] - points[segment, 0])
    y = points[segment, 1] + share * (points[segment + 1, 1] - points[segment, 1])
    return x, y


@njit(cache=True)
def advanced(points: np.ndarray, along: np.ndarray, progress: float, reach: float, x: float, y: float) -> float:
    """:meth:`Route.advance`'s new progress: the nearest point of the route to (x, y) between ``progress``
    and ``reach`` (arc lengths), the first on a tie, never behind ``progress``."""
    best, best_distance = progress, math.inf
    for k in range(len(points) - 1):
        start, end = along[k], along[k + 1]
        if end < progress or start > reach:
            continue
        at = min(max(_foot(points, along, k, x, y), progress), reach)
        point_x, point_y = point_on(points, along, at)
        gap = math.sqrt((point_x - x) * (point_x - x) + (point_y - y) * (point_y - y))
        if gap < best_distance - 1e-9:
            best, best_distance = at, gap
    return max(progress, best)


@njit(cache=True)
def carrot_on(
    points: np.ndarray,
    along: np.ndarray,
    progress: float,
    stop_at: float,
    bearing: float,
    x: float,
    y: float,
    lookahead: float,
    face_radius: float,
    arrive_radius: float,
) -> tuple[float, float, float, bool]:
    """(carrot x, y, new progress, whether the stop's bearing was faced) of :meth:`Route.carrot`: ``lookahead``
    ahead along the route, held at the next stop (``stop_at``; NaN: none); at that stop (the robot within
    ``arrive_radius`` of it: :func:`arrive_radius_of`), a point ``face_radius`` / 2 from the robot in ``bearing``, which the law turns
    toward (:func:`model.paper.control.pursuit_law`). A carrot nearer than ``face_radius`` is a bearing the law
    would stand at: at the route's end the route is done (at the next plan); where the route doubles back
    past the robot, it has come this far, and the carrot is taken from there (``lookahead`` > 0, or this
    would look at the same point for ever: :meth:`Route.carrot` says so)."""
    length = along[-1]
    has_stop = stop_at == stop_at
    if has_stop:
        stop_x, stop_y = point_on(points, along, stop_at)
        if math.sqrt((x - stop_x) * (x - stop_x) + (y - stop_y) * (y - stop_y)) < arrive_radius:
            offset = 0.5 * face_radius
            return x + offset * math.cos(bearing), y + offset * math.sin(bearing), max(progress, stop_at), True
    while True:
        ahead = progress + lookahead
        if has_stop:
            ahead = min(ahead, stop_at)
        target_x, target_y = point_on(points, along, ahead)
        if math.sqrt((target_x - x) * (target_x - x) + (target_y - y) * (target_y - y)) < face_radius:
            progress = length if ahead >= length - 1e-9 else ahead
            if ahead < length - 1e-9 and not (has_stop and ahead >= stop_at):
                continue
        return target_x, target_y, progress, False


@njit(cache=True)
def _foot(points: np.ndarray, along: np.ndarray, k: int, x: float, y: float) -> float:
    """Arc length of the point of segment k nearest to (x, y)."""
    d_x, d_y = points[k + 1, 0] - points[k, 0], points[k + 1, 1] - points[k, 1]
    span2 = d_x * d_x + d_y * d_y
    t = 0.0 if span2 == 0.0 else min(max(((x - points[k, 0]) * d_x + (y - points[k, 1]) * d_y) / span2, 0.0), 1.0)
    return along[k] + t * (along[k + 1] - along[k])
