"""``launch_team.py --robot ros2``: a team whose agents drive ROS 2 bases over Zenoh (agents/ros2).

Each agent ``i`` drives the base in namespace ``bot<i>`` through the launcher's router (bridge-style
keys, or rmw_zenoh's with ``--ros-transport rmw-zenoh``). ``--test-bases`` also starts one stand-in base
per robot (``deploy/ros2/test_base.py``, which shares no code with the driver) at the robot's seeded
starting pose, so the whole chain runs on one machine without ROS. A real base moves in real time, so
the clock is realtime at speed 1 / ``seconds_per_unit``.

``--sim-bases`` starts ``anicov sim`` instead (simulator/): one process plays every base in the scenario's
physics world (``physics = "mujoco"``, its ``[robot]`` and ``[noise]``), on the team's clock: lockstep by
default (the world steps when every robot's command is in; the agents get ``--ros-sim-time``), or realtime at
any ``--speed``. With a ``[noise]`` localiser the agents read its fixes (``amcl_pose``) as they would AMCL's.
Its figures (contacts, the truth's coverage) join summary.json.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from model.scenario import Scenario, ScenarioError

TEST_BASE = Path(__file__).resolve().parent.parent / "deploy" / "ros2" / "test_base.py"
SIM_LOCALISER_TOPIC = "amcl_pose"
"""Where anicov sim publishes a ``[noise]`` localiser's fixes and the agents read them (the launcher gives both
the topic, so the two cannot disagree)."""
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
    parser.add_argument(
        "--sim-bases",
        action="store_true",
        help='--robot ros2: play every base in the scenario\'s physics world (anicov sim; physics = "mujoco"), '
        "lockstep by default",
    )


def check_ros2_team(args: argparse.Namespace, scenario: Scenario, speed_given: bool) -> None:
    """Settle the clock (lockstep by default; a ROS 2 team's realtime at speed 1 / seconds_per_unit) or say
    which flag is wrong."""
    if args.robot != "ros2":
        for flag, given in (("--test-bases", args.test_bases), ("--sim-bases", args.sim_bases)):
            if given:
                raise ScenarioError(f"{flag}: stand-in ROS 2 bases need --robot ros2")
        args.clock = args.clock or "lockstep"
        return
    if args.sim_bases:
        check_sim_bases(args, scenario)
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


def check_sim_bases(args: argparse.Namespace, scenario: Scenario) -> None:
    """``--sim-bases``: a physics scenario, bridge keys, no --test-bases, no --secure; the clock lockstep unless
    given. Notes whether the agents read a localiser."""
    from agents.ros2 import require_rosbags
    from model.physics.noise import noise_of

    require_rosbags()
    if scenario.physics != "mujoco":
        raise ScenarioError(
            f"--sim-bases: the simulator plays the bases in a physics world: expected scenario key 'physics' = "
            f'"mujoco", got {scenario.physics!r}'
        )
    for flag, wrong in (
        ("--test-bases", args.test_bases),
        ("--ros-transport rmw-zenoh", args.ros_transport != "bridge"),
        ("--secure", bool(args.secure)),
        ("--no-coordinator", args.no_coordinator),
    ):
        if wrong:
            raise ScenarioError(f"--sim-bases: not with {flag} (the simulator speaks bridge keys as a team member)")
    args.clock = args.clock or "lockstep"
    args.sim_localiser = noise_of(scenario).localiser_period > 0


def ros2_agent_flags(args: argparse.Namespace, agent: int) -> list[str]:
    """The ``--robot ros2`` flags of agent ``agent`` (empty for simulated robots)."""
    if args.robot != "ros2":
        return []
    flags = ["--robot", "ros2", "--ros-namespace", f"bot{agent}", "--ros-transport", args.ros_transport]
    if args.sim_bases:
        flags += ["--ros-sim-time"] + ["--ros-localiser-topic", SIM_LOCALISER_TOPIC] * args.sim_localiser
    return flags


def test_base_commands(args: argparse.Namespace, scenario: Scenario, logs: Path) -> list[list[str]]:
    """One stand-in base per robot, at its seeded starting pose in the map frame (metres, degrees)."""
    if not args.test_bases:
        return []
    from model.parameters import starting_poses
    from protocol.ros2.frames import frame_of

    frame = frame_of(scenario)
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


def merge_simulator_figures(out_dir: Path) -> dict | None:
    """anicov sim's figures (OUT/sim.json: contacts, the truth's coverage) into OUT/summary.json, where the
    coordinator wrote the run's; the figures, or None if either file is missing."""
    import json

    sim_path, summary_path = out_dir / "sim.json", out_dir / "summary.json"
    if not (sim_path.exists() and summary_path.exists()):
        return None
    figures = json.loads(sim_path.read_text(encoding="utf-8"))
    summary = json.loads(summary_path.read_text(encoding="utf-8")) | figures
    summary_path.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    return figures
