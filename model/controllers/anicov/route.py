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

from model.paper.polyline import point_along
from model.scenario import Scenario

CARROT_PERIOD = 0.5
"""Time units between two carrots of one robot (:mod:`model.controllers.anicov.lane_planner`): the anicov
controller's plan period."""
FACE_RADIUS = 0.05
"""A carrot nearer the robot than this is a bearing to face (units; :func:`model.paper.control.pursuit_law`, the
stations of :mod:`model.controllers.anicov.stations`): half a step at k_v = 1, dt = 0.1, which the pursuit's last step toward a
station reaches (v = d/dt within one step of it)."""


def face_radius_of(scenario: Scenario) -> float:
    """:data:`FACE_RADIUS` where the anicov controller's robots stand at stations (its default, ``stations``),
    else 0: the one rule the planner's carrots and the robots' law both read."""
    return FACE_RADIUS if scenario.stations else 0.0


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
        if len(self.points) == 1:
            return self.points[0].copy()
        return point_along(self.points, self.along, min(max(distance, 0.0), self.length))

    def advance(self, position: np.ndarray, window: float) -> None:
        """Progress := the nearest point of the route to ``position`` at most ``window`` ahead of where
        it was: no farther than the carrot the robot was given (so a neighbouring ring is never taken,
        nor, on a pass that doubles back over a small blob, the way back while it is still going out);
        the first such along the route on a tie; never past a stop not yet done."""
        reach = self.progress + window
        if self.stops:
            reach = min(reach, self.stops[0].at)
        best, best_distance = self.progress, math.inf
        for k in range(len(self.points) - 1):
            start, end = self.along[k], self.along[k + 1]
            if end < self.progress or start > reach:
                continue
            at = min(max(self._foot(k, position), self.progress), reach)
            gap = float(np.linalg.norm(self.point_at(at) - position))
            if gap < best_distance - 1e-9:
                best, best_distance = at, gap
        self.progress = max(self.progress, best)

    def done(self) -> bool:
        return self.progress >= self.length - 1e-6 and not self.stops

    def carrot(self, position: np.ndarray, lookahead: float, face_radius: float) -> np.ndarray:
        """The carrot for the coming plan period (after :meth:`advance`): ``lookahead`` ahead along the
        route, held at the next stop; at a stop (the robot within ``face_radius`` of it), a point
        ``face_radius`` / 2 from the robot in the next bearing to face there, which the law turns toward
        (:func:`model.paper.control.pursuit_law`), that bearing then done."""
        if self.stops and float(np.linalg.norm(position - self.point_at(self.stops[0].at))) < face_radius:
            # There (the law stands within ``face_radius`` of a carrot, so progress may stop short).
            stop = self.stops[0]
            self.progress = max(self.progress, stop.at)
            bearing = stop.bearings.pop(0)
            if not stop.bearings:
                self.stops.pop(0)
            return np.asarray(position, dtype=np.float64) + 0.5 * face_radius * np.array(
                [math.cos(bearing), math.sin(bearing)]
            )
        ahead = self.progress + lookahead
        if self.stops:
            ahead = min(ahead, self.stops[0].at)
        target = self.point_at(ahead)
        if float(np.linalg.norm(target - position)) < face_radius:
            # The law would stand here (a carrot this near is a bearing): at the route's end it is done (at
            # the next plan); where the route doubles back past the robot, it has come this far.
            self.progress = self.length if ahead >= self.length - 1e-9 else ahead
            if ahead < self.length - 1e-9 and not (self.stops and ahead >= self.stops[0].at):
                return self.carrot(position, lookahead, face_radius)
        return target

    def nearest(self, position: np.ndarray) -> tuple[float, float]:
        """(distance, arc length) of the route's point nearest to ``position``, the first on a tie."""
        if len(self.points) == 1:
            return float(np.linalg.norm(self.points[0] - position)), 0.0
        best_gap, best_at = math.inf, 0.0
        for k in range(len(self.points) - 1):
            at = self._foot(k, position)
            gap = float(np.linalg.norm(self.point_at(at) - position))
            if gap < best_gap - 1e-9:
                best_gap, best_at = gap, at
        return best_gap, best_at

    def _foot(self, k: int, position: np.ndarray) -> float:
        """Arc length of the point of segment k nearest to ``position``."""
        a, b = self.points[k], self.points[k + 1]
        d = b - a
        span2 = float(d @ d)
        t = 0.0 if span2 == 0.0 else float(np.clip((position - a) @ d / span2, 0.0, 1.0))
        return float(self.along[k] + t * (self.along[k + 1] - self.along[k]))

    def draw_ahead(self, canvas: np.ndarray, cell: float, width: int) -> None:
        """Draw what is left of the route (from its progress on) into ``canvas`` (uint8 grid), ``width``
        cells wide."""
        ahead = self.points[self.along > self.progress]
        line = np.vstack([self.point_at(self.progress), ahead]) / cell
        cv2.polylines(canvas, [np.round(line).astype(np.int32)], False, 1, thickness=width)
