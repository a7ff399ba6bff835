#!/usr/bin/env python3
"""A stand-in ROS 2 base on Zenoh, for trying and testing ``anicov agent --robot ros2`` without a robot.

It behaves as a base behind zenoh-bridge-ros2dds does on the wire: it takes
``geometry_msgs/msg/Twist`` (or ``TwistStamped``) on ``<namespace>/cmd_vel`` and publishes
``nav_msgs/msg/Odometry`` on ``<namespace>/odom`` at ``--rate`` Hz, CDR by rosbags, no attachment. It
integrates a unicycle exactly (constant v, ω over each tick) and, like every real base, stops on its
own when no command came for ``--command-timeout`` seconds. Odometry is in the map frame (a simulator's
ground truth) unless ``--odom-from-start``: then it starts at (0, 0, 0), as wheel odometry does.

On purpose it shares no code with the driver (agents/ros2): only zenoh, rosbags and the standard
library, so a test through it checks the driver against an independent reading of the messages.

``--log FILE`` writes one JSON line per command received and per event (``start``, ``timeout-stop``
with the speeds it cut, ``odometry-off`` / ``odometry-on``, ``exit``), each stamped with ``time.time()``,
for tests and for looking at afterwards. SIGUSR1 switches the odometry off and on again (a localiser
that dies, for the driver's stale-pose stop). It waits for its router or bridge, as a robot that boots
first does, and its session reconnects by itself when that router comes back.

    python deploy/ros2/test_base.py --connect tcp/127.0.0.1:7447 --namespace bot1 --pose 10 10 0
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import threading
import time

import numpy as np
import zenoh
from rosbags.typesys import Stores, get_typestore

STORE = get_typestore(Stores.ROS2_JAZZY)
T = STORE.types


class Base:
    """The unicycle, its latest command, and its watchdog."""

    def __init__(self, args: argparse.Namespace) -> None:
        self.args = args
        self.x, self.y, self.theta = args.pose[0], args.pose[1], math.radians(args.pose[2])
        self.start = (self.x, self.y, self.theta)
        self.v = self.omega = 0.0
        self.last_command_at = -math.inf
        self.timed_out = True
        self.lock = threading.Lock()
        self.log = open(args.log, "a", buffering=1) if args.log else None
        self.commands = 0

    def record(self, **event: object) -> None:
        if self.log is not None:
            self.log.write(json.dumps({"t": time.time(), **event}) + "\n")

    def on_command(self, sample: zenoh.Sample) -> None:
        typename = "geometry_msgs/msg/TwistStamped" if self.args.stamped else "geometry_msgs/msg/Twist"
        try:
            message = STORE.deserialize_cdr(sample.payload.to_bytes(), typename)
        except Exception as error:  # a foreign payload: ignore it, as a base would
            self.record(event="bad-command", error=str(error))
            return
        twist = message.twist if self.args.stamped else message
        v = max(-self.args.max_linear, min(self.args.max_linear, twist.linear.x))
        omega = max(-self.args.max_angular, min(self.args.max_angular, twist.angular.z))
        with self.lock:
            self.v, self.omega = v, omega
            self.last_command_at = time.monotonic()
            self.timed_out = False
            self.commands += 1
        self.record(event="command", v=twist.linear.x, omega=twist.angular.z)

    def tick(self, dt: float) -> None:
        """Move for dt at the current command (exact arc), after the watchdog."""
        with self.lock:
            if not self.timed_out and time.monotonic() - self.last_command_at > self.args.command_timeout:
                self.record(event="timeout-stop", x=self.x, y=self.y, v=self.v, omega=self.omega)
                self.v = self.omega = 0.0
                self.timed_out = True
            v, omega = self.v, self.omega
        if abs(omega) < 1e-9:
            self.x += v * dt * math.cos(self.theta)
            self.y += v * dt * math.sin(self.theta)
        else:
            turned = self.theta + omega * dt
            self.x += v / omega * (math.sin(turned) - math.sin(self.theta))
            self.y -= v / omega * (math.cos(turned) - math.cos(self.theta))
            self.theta = math.atan2(math.sin(turned), math.cos(turned))

    def odometry(self) -> bytes:
        x, y, theta = self.x, self.y, self.theta
        if self.args.odom_from_start:  # the pose relative to where the base started
            sx, sy, st = self.start
            dx, dy = x - sx, y - sy
            x, y = math.cos(st) * dx + math.sin(st) * dy, -math.sin(st) * dx + math.cos(st) * dy
            theta = math.atan2(math.sin(theta - st), math.cos(theta - st))
        now = time.time_ns()
        header = T["std_msgs/msg/Header"](
            stamp=T["builtin_interfaces/msg/Time"](sec=now // 10**9, nanosec=now % 10**9), frame_id="odom"
        )
        vector = T["geometry_msgs/msg/Vector3"]
        pose = T["geometry_msgs/msg/Pose"](
            position=T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
            orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2)),
        )
        twist = T["geometry_msgs/msg/Twist"](
            linear=vector(x=self.v, y=0.0, z=0.0), angular=vector(x=0.0, y=0.0, z=self.omega)
        )
        message = T["nav_msgs/msg/Odometry"](
            header=header,
            child_frame_id="base_link",
            pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.zeros(36)),
            twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=twist, covariance=np.zeros(36)),
        )
        return bytes(STORE.serialize_cdr(message, "nav_msgs/msg/Odometry"))


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--connect", action="append", required=True, help="Zenoh endpoint (router or bridge)")
    parser.add_argument("--namespace", default="", help="ROS namespace: keys <namespace>/cmd_vel and /odom")
    parser.add_argument("--pose", type=float, nargs=3, default=(0.0, 0.0, 0.0), metavar=("X", "Y", "YAW_DEG"))
    parser.add_argument("--rate", type=float, default=30.0, help="odometry rate, Hz (default 30)")
    parser.add_argument("--command-timeout", type=float, default=0.5, help="stop after this long without a command")
    parser.add_argument("--max-linear", type=float, default=math.inf, help="m/s")
    parser.add_argument("--max-angular", type=float, default=math.inf, help="rad/s")
    parser.add_argument("--stamped", action="store_true", help="take TwistStamped")
    parser.add_argument("--odom-from-start", action="store_true", help="odometry starts at (0, 0, 0)")
    parser.add_argument("--log", help="JSON lines of commands and events")
    return parser.parse_args(argv)


def open_when_up(config: zenoh.Config, stopping: threading.Event) -> zenoh.Session | None:
    """The session, once the router or bridge answers (None if stopped first)."""
    while not stopping.is_set():
        try:
            return zenoh.open(config)
        except zenoh.ZError:
            stopping.wait(0.25)
    return None


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    base = Base(args)
    stopping, odometry_on = threading.Event(), threading.Event()
    odometry_on.set()

    def toggle_odometry(*_: object) -> None:
        (odometry_on.clear if odometry_on.is_set() else odometry_on.set)()
        base.record(event="odometry-on" if odometry_on.is_set() else "odometry-off")

    signal.signal(signal.SIGTERM, lambda *_: stopping.set())
    signal.signal(signal.SIGINT, lambda *_: stopping.set())
    signal.signal(signal.SIGUSR1, toggle_odometry)
    config = zenoh.Config()
    config.insert_json5("mode", '"client"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps(args.connect))
    prefix = args.namespace.strip("/") + "/" if args.namespace.strip("/") else ""
    session = open_when_up(config, stopping)
    if session is None:
        return 0
    with session:
        session.declare_subscriber(prefix + "cmd_vel", base.on_command)
        odometry = session.declare_publisher(prefix + "odom")
        base.record(event="start", x=base.x, y=base.y)
        period = 1.0 / args.rate
        next_tick = time.monotonic()
        while not stopping.is_set():
            base.tick(period)
            if odometry_on.is_set():
                odometry.put(base.odometry())
            next_tick += period
            stopping.wait(max(0.0, next_tick - time.monotonic()))
    base.record(event="exit", commands=base.commands)
    return 0


if __name__ == "__main__":
    sys.exit(main())
