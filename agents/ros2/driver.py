"""The ROS 2 base behind an agent: :class:`Ros2Robot` implements :class:`agents.robot.Robot` over Zenoh.

It publishes velocity commands on the base's command topic and keeps the latest pose read from its
odometry or localisation topic (callback thread, under a lock). What it does for a real base's sake:

- every command is clamped to the scenario's bounds (|v| ≤ k_v, |ω| ≤ π k_ω: eq. 6, 12) and then to the
  robot's own (``max_linear`` m/s, ``max_angular`` rad/s);
- a pose older than ``pose_timeout`` seconds is stale: the robot is sent zero, the agent holds its step
  (:meth:`pose_is_current` is False) and says so, until a pose that arrived after that moment;
- :meth:`stop` sends zero; the agent process calls it when its loop ends for any reason (end of run,
  Ctrl-C, SIGTERM, an exception) before the session closes. A lost router cannot carry that zero: the
  base's own command timeout stops it then, as every ROS base has one, and the stale pose keeps the
  agent from moving it again before fresh odometry comes through the router.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from typing import Any

import zenoh

from agents.ros2.frames import Pose, ScenarioFrame, clamp, compose
from agents.ros2.messages import BadRosMessage, decode_pose, encode_velocity
from agents.ros2.options import Ros2Options
from agents.ros2.transport import Ros2Topics
from model.dynamics import unicycle_step
from model.scenario import Scenario
from model.terrain import load_occupancy_map

log = logging.getLogger("anicov.ros2")

WAIT_LOG_PERIOD = 2.0
"""Seconds between the 'waiting for a pose' lines while the agent waits for its robot."""


def frame_of(scenario: Scenario, options: Ros2Options) -> ScenarioFrame:
    """The scenario in the robot's map frame: its (0, 0) at ``origin`` if given, else at the scenario map's
    origin (the same Nav2 map: the frames then agree), else at the map frame's (0, 0); its units."""
    origin = options.origin
    if origin is None:
        origin = load_occupancy_map(scenario.map).origin if scenario.map else (0.0, 0.0)
    return ScenarioFrame(origin, scenario.metres_per_unit, scenario.seconds_per_unit)


class Ros2Robot:
    """A ROS 2 base commanded over Zenoh; poses and commands in scenario units (see :mod:`.frames`)."""

    def __init__(
        self,
        session: zenoh.Session,
        options: Ros2Options,
        scenario: Scenario,
        agent: int,
    ) -> None:
        self.options, self.agent = options, agent
        self.frame = frame_of(scenario, options)
        self._max_speed, self._max_turn_rate = scenario.k_v, math.pi * scenario.k_omega  # eq. 15-16's bounds
        self._dt = scenario.dt
        self.topics = Ros2Topics.of(options)
        self._publisher = session.declare_publisher(self.topics.command_key)
        self._lock = threading.Lock()
        self._map_pose: Pose | None = None
        self._received_at = -math.inf  # monotonic seconds of the latest pose
        self._stale_since: float | None = None  # the pose went stale then; only a later one is fresh
        self.poses_received = 0
        self.poses_rejected = 0
        self.commands_sent = 0
        self.last_command: tuple[float, float] = (0.0, 0.0)  # applied, scenario units
        self._subscriber = session.declare_subscriber(self.topics.pose_key, self._on_pose)

    # ------------------------------------------------------------ pose

    def _on_pose(self, sample: zenoh.Sample) -> None:
        try:
            read = decode_pose(sample.payload.to_bytes(), self.options.pose_typename, self.options.distribution)
        except BadRosMessage as error:
            with self._lock:
                self.poses_rejected += 1
                first = self.poses_rejected == 1
            if first or self.poses_rejected % 100 == 0:
                log.warning(
                    "agent %d: rejected a pose on %s (%d so far): %s",
                    self.agent,
                    sample.key_expr,
                    self.poses_rejected,
                    error,
                )
            return
        pose = read.pose if self.options.pose_type == "pose" else compose(self.options.odom_offset, read.pose)
        with self._lock:
            self._map_pose = pose
            self._received_at = time.monotonic()
            self.poses_received += 1

    def pose(self) -> Pose:
        with self._lock:
            map_pose = self._map_pose
        if map_pose is None:
            raise RuntimeError(f"agent {self.agent}: no pose yet on {self.topics.pose_key}")
        return self.frame.to_scenario(map_pose)

    def has_pose(self) -> bool:
        with self._lock:
            return self._map_pose is not None

    def pose_is_current(self) -> bool:
        """The latest pose is younger than ``pose_timeout`` and, after a stale spell, arrived after it began."""
        now = time.monotonic()
        with self._lock:
            received = self._received_at
        if self._stale_since is None:
            if now - received <= self.options.pose_timeout:
                return True
            self._stale_since = now
            log.warning(
                "agent %d: no pose on %s for %.2f s: the robot is stopped until a fresh one arrives",
                self.agent,
                self.topics.pose_key,
                now - received,
            )
            return False
        if received > self._stale_since and now - received <= self.options.pose_timeout:
            log.warning(
                "agent %d: a fresh pose on %s after %.2f s: the robot moves again",
                self.agent,
                self.topics.pose_key,
                now - self._stale_since,
            )
            self._stale_since = None
            return True
        return False

    def wait_for_pose(self, stopped: Any, give_up: Any) -> bool:
        """Block until a first pose arrives, saying where it waits; False if ``stopped()`` or ``give_up()``."""
        next_line = time.monotonic()
        while not self.has_pose():
            if stopped() or give_up():
                return False
            if time.monotonic() >= next_line:
                log.info(
                    "agent %d waits for its robot's pose: %s on Zenoh key %s (%s)",
                    self.agent,
                    self.options.pose_typename,
                    self.topics.pose_key,
                    self.options.transport,
                )
                next_line = time.monotonic() + WAIT_LOG_PERIOD
            time.sleep(0.02)
        log.info("agent %d: robot pose %s from %s", self.agent, _rounded(self.pose()), self.topics.pose_key)
        return True

    # ------------------------------------------------------------ commands

    def command(self, v: float, omega: float) -> Pose:
        """Send (v, ω) (scenario units, clamped; zero while the pose is stale); return the pose the base
        reaches in one period if it follows (eq. 1), for teammates until its next odometry."""
        if not self.pose_is_current():
            v, omega = 0.0, 0.0
        v, omega = clamp(v, self._max_speed), clamp(omega, self._max_turn_rate)
        linear, angular = self.frame.to_ros_velocity(v, omega)
        linear, angular = clamp(linear, self.options.max_linear), clamp(angular, self.options.max_angular)
        self._send(linear, angular)
        scale = self.frame.metres_per_unit / self.frame.seconds_per_unit
        self.last_command = (linear / scale, angular * self.frame.seconds_per_unit)
        return unicycle_step(*self.pose(), *self.last_command, self._dt)

    def stop(self) -> None:
        """Zero velocity, now."""
        self._send(0.0, 0.0)
        self.last_command = (0.0, 0.0)

    def _send(self, linear: float, angular: float) -> None:
        payload = encode_velocity(
            linear, angular, self.options.stamped, time.time_ns(), self.options.frame_id, self.options.distribution
        )
        self.commands_sent += 1
        attachment = self.topics.attachment(self.commands_sent)
        if attachment is None:
            self._publisher.put(payload)
        else:
            self._publisher.put(payload, attachment=attachment)

    def close(self) -> None:
        """Stop the base and leave the bus."""
        try:
            self.stop()
        finally:
            self._subscriber.undeclare()
            self._publisher.undeclare()

    def counts(self) -> dict[str, int]:
        return {
            "poses_received": self.poses_received,
            "poses_rejected": self.poses_rejected,
            "commands_sent": self.commands_sent,
        }


def _rounded(pose: Pose) -> tuple[float, float, float]:
    return round(pose[0], 3), round(pose[1], 3), round(pose[2], 3)
