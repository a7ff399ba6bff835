"""``anicov agent --robot ros2`` flags (light imports: the CLI builds its parsers from here), and the
driver's options from them, each checked with the flag named."""

from __future__ import annotations

import argparse
import math
import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from protocol.ros2.options import Ros2Options

ROBOTS = ("sim", "ros2")
NAME_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
"""One token of a ROS 2 name (REP 144 / rcl's validation): a letter or underscore, then letters, digits,
underscores. Also what keeps Zenoh's wildcards (*, **, $*) out of the keys the driver publishes on."""


def add_robot_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--robot",
        choices=ROBOTS,
        default="sim",
        help="sim: the simulated unicycle (default); ros2: a ROS 2 base over Zenoh (deploy/ros2.md)",
    )
    ros = parser.add_argument_group("ROS 2 base (--robot ros2)")
    ros.add_argument("--ros-namespace", default="", help="the base's namespace, e.g. bot1 (launcher: bot<id>)")
    ros.add_argument(
        "--ros-transport",
        choices=("bridge", "rmw-zenoh"),
        default="bridge",
        help="bridge: zenoh-bridge-ros2dds on the robot (default); rmw-zenoh: ROS 2's Zenoh middleware",
    )
    ros.add_argument("--ros-cmd-topic", default="cmd_vel", help="velocity command topic (default cmd_vel)")
    ros.add_argument("--ros-stamped", action="store_true", help="send TwistStamped instead of Twist")
    ros.add_argument("--ros-frame-id", default="base_link", help="TwistStamped header frame (default base_link)")
    ros.add_argument("--ros-odom-topic", default="odom", help="nav_msgs/Odometry topic (default odom)")
    ros.add_argument(
        "--ros-localiser-topic",
        metavar="TOPIC",
        help="PoseWithCovarianceStamped in the map frame (e.g. amcl_pose) that corrects map <- odom",
    )
    ros.add_argument(
        "--ros-odom-offset",
        type=float,
        nargs=3,
        metavar=("X", "Y", "YAW_DEG"),
        help="fixed map <- odom transform (metres, degrees) without a localiser (default 0 0 0)",
    )
    ros.add_argument(
        "--ros-origin",
        type=float,
        nargs=2,
        metavar=("X", "Y"),
        help="map-frame point (metres) of the scenario's (0, 0) (default: where the scenario's map puts it, its origin plus any unknown border cropped; or 0 0)",
    )
    ros.add_argument(
        "--ros-pose-timeout",
        type=float,
        default=0.5,
        help="seconds without odometry before the robot is stopped (default 0.5)",
    )
    ros.add_argument("--ros-max-linear", type=float, help="the base's speed limit, m/s")
    ros.add_argument("--ros-max-angular", type=float, help="the base's turn-rate limit, rad/s")
    _add_route_arguments(ros)


def _add_route_arguments(ros: argparse._ArgumentGroup) -> None:
    """Where the base is reached, and on whose clock."""
    ros.add_argument("--ros-domain", type=int, default=0, help="ROS_DOMAIN_ID (rmw-zenoh keys; default 0)")
    ros.add_argument(
        "--ros-distro",
        choices=("humble", "jazzy", "kilted"),
        default="jazzy",
        help="ROS 2 distribution of the message definitions and type hashes (default jazzy)",
    )
    ros.add_argument(
        "--ros-sim-time",
        action="store_true",
        help="the base is anicov sim's, on the team's clock (ROS's use_sim_time): in lockstep each step acts on "
        "the odometry of the next simulated instant, published once every robot's command is in; realtime at any --speed",
    )
    ros.add_argument(
        "--ros-connect",
        action="append",
        help="Zenoh endpoint of the robot's bridge or router, if not the team's bus (repeatable)",
    )


class RobotArgumentError(ValueError):
    """A --robot / --ros-* flag that cannot be used; the message names it."""


def real_time_speed(seconds_per_unit: float) -> float:
    """The --speed at which the realtime clock runs with a real base: one scenario time unit per
    ``seconds_per_unit`` wall seconds."""
    return 1.0 / seconds_per_unit


def check_real_time(clock: str, speed: float, seconds_per_unit: float, sim_time: bool = False) -> None:
    """A real base moves in real time: the realtime clock at :func:`real_time_speed`, else the flag. A simulated
    one (``anicov sim``, ``sim_time``) runs on the team's clock, either clock at any speed."""
    if sim_time:
        return
    if clock != "realtime":
        raise RobotArgumentError(
            "--robot ros2 drives a real base, which cannot wait for a lockstep go: use --clock realtime (or, against "
            "anicov sim's bases, --ros-sim-time)"
        )
    expected = real_time_speed(seconds_per_unit)
    if not math.isclose(speed, expected, rel_tol=1e-9):
        raise RobotArgumentError(
            f"--speed: a real base moves in real time: expected --speed {expected:g} (1 / the scenario's "
            f"seconds_per_unit {seconds_per_unit:g}), got {speed:g}"
        )


def check_name(flag: str, name: str, namespace: bool = False) -> None:
    """A ROS 2 namespace or topic name: tokens joined by '/', a leading '/' allowed (absolute), no
    private '~' names and no Zenoh wildcards (a namespace '*' would drive every robot)."""
    tokens = name.strip("/").split("/") if name.strip("/") else []
    if (
        (not tokens and not namespace)
        or any(not NAME_TOKEN.fullmatch(token) for token in tokens)
        or name.endswith("//")
    ):
        raise RobotArgumentError(
            f"{flag}: expected a ROS 2 {'namespace' if namespace else 'topic name'} (letters, digits and '_' "
            f"in tokens joined by '/', each token not starting with a digit), got {name!r}"
        )


def ros2_options_from(args: argparse.Namespace) -> Ros2Options:
    from protocol.ros2.options import Ros2Options

    for flag, value in (
        ("--ros-pose-timeout", args.ros_pose_timeout),
        ("--ros-max-linear", args.ros_max_linear),
        ("--ros-max-angular", args.ros_max_angular),
    ):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise RobotArgumentError(f"{flag}: expected a positive number, got {value}")
    if not 0 <= args.ros_domain <= 232:
        raise RobotArgumentError(f"--ros-domain: expected a ROS domain id from 0 to 232, got {args.ros_domain}")
    check_name("--ros-namespace", args.ros_namespace, namespace=True)
    for flag, topic in (
        ("--ros-cmd-topic", args.ros_cmd_topic),
        ("--ros-odom-topic", args.ros_odom_topic),
        ("--ros-localiser-topic", args.ros_localiser_topic),
    ):
        if topic is not None:
            check_name(flag, topic)
    if args.ros_transport == "rmw-zenoh" and args.ros_distro == "humble":
        raise RobotArgumentError(
            "--ros-distro humble with --ros-transport rmw-zenoh: humble's messages have no RIHS01 type hash (REP 2011 came "
            "after it), which rmw_zenoh's keys carry from jazzy on; use the bridge"
        )
    offset = args.ros_odom_offset or (0.0, 0.0, 0.0)
    if args.ros_odom_offset and args.ros_localiser_topic:
        raise RobotArgumentError("--ros-odom-offset: with --ros-localiser-topic the localiser gives map <- odom")
    if not all(math.isfinite(value) for value in (*offset, *(args.ros_origin or ()))):
        raise RobotArgumentError("--ros-odom-offset / --ros-origin: expected finite numbers")
    return Ros2Options(
        namespace=args.ros_namespace,
        transport=args.ros_transport,
        command_topic=args.ros_cmd_topic,
        stamped=args.ros_stamped,
        frame_id=args.ros_frame_id,
        odometry_topic=args.ros_odom_topic,
        localiser_topic=args.ros_localiser_topic,
        odom_offset=(offset[0], offset[1], math.radians(offset[2])),
        pose_timeout=args.ros_pose_timeout,
        max_linear=args.ros_max_linear or math.inf,
        max_angular=args.ros_max_angular or math.inf,
        domain_id=args.ros_domain,
        distribution=args.ros_distro,
        connect=tuple(args.ros_connect or ()),
        origin=(args.ros_origin[0], args.ros_origin[1]) if args.ros_origin else None,
        sim_time=args.ros_sim_time,
        lockstep=getattr(args, "clock", "realtime") == "lockstep",
    )
