"""``launch_team.py --robot ros2``: a team whose agents drive ROS 2 bases over Zenoh (agents/ros2).

Each agent ``i`` drives the base in namespace ``bot<i>`` through the launcher's router (bridge-style
keys, or rmw_zenoh's with ``--ros-transport rmw-zenoh``). ``--test-bases`` also starts one stand-in base
per robot (``deploy/ros2/test_base.py``, which shares no code with the driver) at the robot's seeded
starting pose, so the whole chain runs on one machine without ROS. A real base moves in real time, so
the clock is realtime at speed 1 / ``seconds_per_unit``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from model.scenario import Scenario, ScenarioError

TEST_BASE = Path(__file__).resolve().parent.parent / "deploy" / "ros2" / "test_base.py"
ODOMETRY_RATE = 30.0
"""Hz of the stand-in bases' odometry: a typical wheel-odometry rate (TurtleBot 4: 20-62 Hz)."""


def add_ros2_team_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--robot",
        choices=("sim", "ros2"),
        default="sim",
        help="sim: simulated unicycles (default); ros2: each agent drives the ROS 2 base in namespace bot<i>",
    )
    parser.add_argument(
        "--ros-transport", choices=("bridge", "rmw-zenoh"), default="bridge", help="--robot ros2: the Zenoh route"
    )
    parser.add_argument(
        "--test-bases",
        action="store_true",
        help="--robot ros2: also start a stand-in base per robot (deploy/ros2/test_base.py), bridge keys only",
    )


def check_ros2_team(args: argparse.Namespace, scenario: Scenario, speed_given: bool) -> None:
    """Settle the clock (lockstep by default; a ROS 2 team's realtime at speed 1 / seconds_per_unit) or say
    which flag is wrong."""
    if args.robot != "ros2":
        if args.test_bases:
            raise ScenarioError("--test-bases: stand-in ROS 2 bases need --robot ros2")
        args.clock = args.clock or "lockstep"
        return
    from agents.ros2 import require_rosbags

    require_rosbags()
    if args.test_bases and args.ros_transport != "bridge":
        raise ScenarioError("--test-bases: the stand-in bases speak bridge-style keys; use --ros-transport bridge")
    if args.test_bases and args.secure:
        raise ScenarioError(
            "--test-bases: the stand-in bases are not members of a --secure team (no certificate); with a "
            "secure profile, bases are reached on the robot's own bridge (deploy/ros2.md)"
        )
    from agents.ros2.arguments import check_real_time, real_time_speed

    args.clock = args.clock or "realtime"
    if not speed_given:
        args.speed = real_time_speed(scenario.seconds_per_unit)
    check_real_time(args.clock, args.speed, scenario.seconds_per_unit)


def ros2_agent_flags(args: argparse.Namespace, agent: int) -> list[str]:
    """The ``--robot ros2`` flags of agent ``agent`` (empty for simulated robots)."""
    if args.robot != "ros2":
        return []
    return ["--robot", "ros2", "--ros-namespace", f"bot{agent}", "--ros-transport", args.ros_transport]


def test_base_commands(args: argparse.Namespace, scenario: Scenario, logs: Path) -> list[list[str]]:
    """One stand-in base per robot, at its seeded starting pose in the map frame (metres, degrees)."""
    if not args.test_bases:
        return []
    from agents.ros2.driver import frame_of
    from agents.ros2.options import Ros2Options
    from model.parameters import starting_poses

    frame = frame_of(scenario, Ros2Options())
    commands = []
    for agent, (x, y, theta) in enumerate(starting_poses(scenario)):
        map_x, map_y = frame.to_map(x, y)
        commands.append(
            [
                sys.executable,
                str(TEST_BASE),
                "--connect",
                args.listen,
                "--namespace",
                f"bot{agent}",
                "--pose",
                repr(float(map_x)),
                repr(float(map_y)),
                repr(float(math.degrees(theta))),
                "--rate",
                str(ODOMETRY_RATE),
                "--log",
                str(logs / f"base-{agent}.jsonl"),
            ]
        )
    return commands
