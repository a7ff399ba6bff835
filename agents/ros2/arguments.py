"""``anicov agent --robot ros2`` flags (light imports: the CLI builds its parsers from here), and the
driver's options from them, each checked with the flag named."""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from agents.ros2.options import Ros2Options

ROBOTS = ("sim", "ros2")
FLAGS = (
    "--ros-namespace",
    "--ros-transport",
    "--ros-cmd-topic",
    "--ros-stamped",
    "--ros-frame-id",
    "--ros-pose-topic",
    "--ros-pose-type",
    "--ros-odom-offset",
    "--ros-origin",
    "--ros-pose-timeout",
    "--ros-max-linear",
    "--ros-max-angular",
    "--ros-domain",
    "--ros-distro",
    "--ros-connect",
)


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--robot",
        choices=ROBOTS,
        default="sim",
        help="sim: the simulated unicycle (default); ros2: a ROS 2 base over Zenoh (deploy/ros2.md)",
    )
    ros = parser.add_argument_group("ROS 2 base (--robot ros2)")
    ros.add_argument("--ros-namespace", default="", help="the base's namespace, e.g. bot1 (launcher: bot{id})")
    ros.add_argument(
        "--ros-transport",
        choices=("bridge", "rmw-zenoh"),
        default="bridge",
        help="bridge: zenoh-bridge-ros2dds on the robot (default); rmw-zenoh: ROS 2's Zenoh middleware",
    )
    ros.add_argument("--ros-cmd-topic", default="cmd_vel", help="velocity command topic (default cmd_vel)")
    ros.add_argument("--ros-stamped", action="store_true", help="send TwistStamped instead of Twist")
    ros.add_argument("--ros-frame-id", default="base_link", help="TwistStamped header frame (default base_link)")
    ros.add_argument(
        "--ros-pose-type",
        choices=("odometry", "pose"),
        default="odometry",
        help="odometry: nav_msgs/Odometry (default); pose: PoseWithCovarianceStamped (e.g. amcl_pose)",
    )
    ros.add_argument("--ros-pose-topic", help="pose topic (default odom, or amcl_pose with --ros-pose-type pose)")
    ros.add_argument(
        "--ros-odom-offset",
        type=float,
        nargs=3,
        metavar=("X", "Y", "YAW_DEG"),
        help="fixed map <- odom transform (metres, degrees) when the pose is odometry (default 0 0 0)",
    )
    ros.add_argument(
        "--ros-origin",
        type=float,
        nargs=2,
        metavar=("X", "Y"),
        help="map-frame point (metres) of the scenario's (0, 0) (default: the scenario map's origin, or 0 0)",
    )
    ros.add_argument(
        "--ros-pose-timeout",
        type=float,
        default=0.5,
        help="seconds without a pose before the robot is stopped (default 0.5)",
    )
    ros.add_argument("--ros-max-linear", type=float, help="the base's speed limit, m/s")
    ros.add_argument("--ros-max-angular", type=float, help="the base's turn-rate limit, rad/s")
    ros.add_argument("--ros-domain", type=int, default=0, help="ROS_DOMAIN_ID (rmw-zenoh keys; default 0)")
    ros.add_argument(
        "--ros-distro",
        choices=("humble", "jazzy", "kilted"),
        default="jazzy",
        help="ROS 2 distribution of the message definitions and type hashes (default jazzy)",
    )
    ros.add_argument(
        "--ros-connect",
        action="append",
        help="Zenoh endpoint of the robot's bridge or router, if not the team's bus (repeatable)",
    )


class RobotArgumentError(ValueError):
    """A --robot / --ros-* flag that cannot be used; the message names it."""


def ros2_options_from(args: argparse.Namespace) -> Ros2Options:
    from agents.ros2.options import Ros2Options

    for flag, value in (
        ("--ros-pose-timeout", args.ros_pose_timeout),
        ("--ros-max-linear", args.ros_max_linear),
        ("--ros-max-angular", args.ros_max_angular),
    ):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise RobotArgumentError(f"{flag}: expected a positive number, got {value}")
    if args.ros_domain is not None and not 0 <= args.ros_domain <= 232:
        raise RobotArgumentError(f"--ros-domain: expected a ROS domain id from 0 to 232, got {args.ros_domain}")
    offset = args.ros_odom_offset or (0.0, 0.0, 0.0)
    if args.ros_odom_offset and args.ros_pose_type == "pose":
        raise RobotArgumentError("--ros-odom-offset: a PoseWithCovarianceStamped is already in the map frame")
    if not all(math.isfinite(value) for value in (*offset, *(args.ros_origin or ()))):
        raise RobotArgumentError("--ros-odom-offset / --ros-origin: expected finite numbers")
    pose_topic = args.ros_pose_topic or ("amcl_pose" if args.ros_pose_type == "pose" else "odom")
    return Ros2Options(
        namespace=args.ros_namespace,
        transport=args.ros_transport,
        command_topic=args.ros_cmd_topic,
        stamped=args.ros_stamped,
        frame_id=args.ros_frame_id,
        pose_topic=pose_topic,
        pose_type=args.ros_pose_type,
        odom_offset=(offset[0], offset[1], math.radians(offset[2])),
        pose_timeout=args.ros_pose_timeout,
        max_linear=args.ros_max_linear or math.inf,
        max_angular=args.ros_max_angular or math.inf,
        domain_id=args.ros_domain,
        distribution=args.ros_distro,
        connect=tuple(args.ros_connect or ()),
        origin=(args.ros_origin[0], args.ros_origin[1]) if args.ros_origin else None,
    )
