"""Frames and units between a ROS 2 base and the scenario (pure functions).

ROS states poses in metres and radians in the ``map`` frame (REP 103/105); a scenario states lengths in
its own units (``metres_per_unit``) and time in its own (``seconds_per_unit``), with its (0, 0) at the
lower-left corner of its domain. With a Nav2 map the two frames differ by the map's ``origin`` (its x, y
and yaw: model.scenario.map_fit.MapFrame) and the units are metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from model.scenario.map_fit import MapFrame
from model.world.world import map_frame_of

if TYPE_CHECKING:
    from model.scenario import Scenario

Pose = tuple[float, float, float]


def yaw_of_quaternion(x: float, y: float, z: float, w: float) -> float:
    """The heading (rotation about z) of a unit quaternion, in (−π, π]: ZYX Euler yaw."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def compose(offset: Pose, pose: Pose) -> Pose:
    """``offset`` ⊕ ``pose``: a pose given in a frame whose own pose is ``offset`` (map ← odom), in the
    outer frame. θ is wrapped to (−π, π]."""
    ox, oy, otheta = offset
    x, y, theta = pose
    c, s = math.cos(otheta), math.sin(otheta)
    heading = math.atan2(math.sin(otheta + theta), math.cos(otheta + theta))
    return ox + c * x - s * y, oy + s * x + c * y, heading


@dataclass(frozen=True)
class ScenarioFrame:
    """Where the scenario sits in the robot's map frame, and its units."""

    origin: tuple[float, float] = (0.0, 0.0)  # map-frame (x, y) of the scenario's (0, 0), metres
    metres_per_unit: float = 1.0
    seconds_per_unit: float = 1.0
    yaw: float = 0.0  # the scenario's x axis in the map frame (a map whose origin has a yaw), radians

    def to_scenario(self, map_pose: Pose) -> Pose:
        """A map-frame pose (metres) in scenario units; the heading turned by the yaw (none: the same)."""
        x, y, theta = map_pose
        frame = MapFrame(self.origin, self.yaw)
        model_x, model_y = frame.from_map(x, y)
        return model_x / self.metres_per_unit, model_y / self.metres_per_unit, float(frame.heading_from_map(theta))

    def to_map(self, x: float, y: float) -> tuple[float, float]:
        """A scenario point (units) in the map frame (metres): the inverse of :meth:`to_scenario`."""
        return MapFrame(self.origin, self.yaw).to_map(x * self.metres_per_unit, y * self.metres_per_unit)

    def pose_to_map(self, pose: Pose) -> Pose:
        """A scenario pose (units) in the map frame (metres, the heading turned by the yaw): the inverse of
        :meth:`to_scenario`."""
        x, y, theta = pose
        map_x, map_y = self.to_map(x, y)
        return float(map_x), float(map_y), float(MapFrame(self.origin, self.yaw).heading_to_map(theta))

    def to_ros_velocity(self, v: float, omega: float) -> tuple[float, float]:
        """(v, ω) in scenario units per time unit as (m/s, rad/s)."""
        return v * self.metres_per_unit / self.seconds_per_unit, omega / self.seconds_per_unit

    def to_scenario_velocity(self, linear: float, angular: float) -> tuple[float, float]:
        """(m/s, rad/s) in scenario units per time unit: the inverse of :meth:`to_ros_velocity`."""
        return linear * self.seconds_per_unit / self.metres_per_unit, angular * self.seconds_per_unit


def invert(pose: Pose) -> Pose:
    """The inverse transform: ``compose(invert(p), p)`` is the identity."""
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    return -c * x - s * y, s * x - c * y, -theta


def scale_into(v: float, omega: float, max_v: float, max_omega: float) -> tuple[float, float]:
    """(v, ω) scaled by one factor in [0, 1] until |v| ≤ max_v and |ω| ≤ max_omega: the path keeps its
    curvature ω / v, and a command the safety filter let through stays inside its constraints (each
    holds at zero and is convex, so it holds on the segment between zero and the command)."""
    factor = 1.0
    if abs(v) > max_v:
        factor = max_v / abs(v)
    if abs(omega) > max_omega:
        factor = min(factor, max_omega / abs(omega))
    return v * factor, omega * factor


def frame_of(scenario: Scenario, origin: tuple[float, float] | None = None) -> ScenarioFrame:
    """The scenario in the robot's map frame: its (0, 0) at ``origin`` if given (its axes the map frame's: a
    given origin places the scenario unturned, whatever its map's yaw), else where the scenario's map puts it,
    turned by the map's yaw (the same Nav2 map: the frames then agree; :func:`model.world.world.map_frame_of`,
    the map's origin when no unknown border was cropped), else at the map frame's (0, 0); its units."""
    if origin is not None:
        return ScenarioFrame(origin, scenario.metres_per_unit, scenario.seconds_per_unit)
    frame = map_frame_of(scenario)
    return ScenarioFrame(frame.corner, scenario.metres_per_unit, scenario.seconds_per_unit, frame.yaw)
