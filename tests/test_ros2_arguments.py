"""``anicov agent --robot ros2`` and ``launch_team.py --robot ros2``: flags checked before anything starts,
each error in one line that names the flag."""

from __future__ import annotations

import argparse
import math
import subprocess
import sys

import pytest

from agents.ros2.arguments import RobotArgumentError, add_robot_arguments, ros2_options_from
from tests.teamrun import ROOT, anicov, limit


def parse(*flags: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_robot_arguments(parser)
    return parser.parse_args(list(flags))


def test_defaults_are_a_bridge_base_with_odometry():
    options = ros2_options_from(parse("--robot", "ros2", "--ros-namespace", "bot1"))
    assert (options.namespace, options.transport, options.command_topic, options.odometry_topic) == (
        "bot1",
        "bridge",
        "cmd_vel",
        "odom",
    )
    assert options.max_linear == math.inf and options.origin is None and not options.stamped
    assert options.localiser_topic is None


def test_a_localiser_topic_and_offsets_in_degrees():
    assert ros2_options_from(parse("--ros-localiser-topic", "amcl_pose")).localiser_topic == "amcl_pose"
    options = ros2_options_from(parse("--ros-odom-offset", "1", "2", "90", "--ros-origin", "-5", "3"))
    assert options.odom_offset == pytest.approx((1.0, 2.0, math.pi / 2)) and options.origin == (-5.0, 3.0)


@pytest.mark.parametrize(
    ("flags", "named"),
    [
        (("--ros-pose-timeout", "0"), "--ros-pose-timeout"),
        (("--ros-max-linear", "-1"), "--ros-max-linear"),
        (("--ros-max-angular", "nan"), "--ros-max-angular"),
        (("--ros-domain", "300"), "--ros-domain"),
        (("--ros-localiser-topic", "amcl_pose", "--ros-odom-offset", "0", "0", "0"), "--ros-odom-offset"),
        (("--ros-origin", "inf", "0"), "--ros-origin"),
        (("--ros-namespace", "*"), "--ros-namespace"),  # a wildcard would drive every robot
        (("--ros-namespace", "bot*"), "--ros-namespace"),
        (("--ros-namespace", "a//b"), "--ros-namespace"),
        (("--ros-namespace", "2bot"), "--ros-namespace"),
        (("--ros-cmd-topic", "/"), "--ros-cmd-topic"),
        (("--ros-odom-topic", "odom/**"), "--ros-odom-topic"),
        (("--ros-localiser-topic", "~/pose"), "--ros-localiser-topic"),
        (("--ros-transport", "rmw-zenoh", "--ros-distro", "humble"), "--ros-distro humble"),
    ],
)
def test_a_bad_flag_is_refused_by_name(flags, named):
    with pytest.raises(RobotArgumentError, match=named):
        ros2_options_from(parse(*flags))


@pytest.mark.parametrize("namespace", ["", "bot1", "/bot1", "fleet/bot_2", "/fleet/bot2/"])
def test_ros_names_are_accepted(namespace):
    assert ros2_options_from(parse("--ros-namespace", namespace, "--ros-cmd-topic", "/cmd_vel")).namespace == namespace


def test_the_agent_refuses_the_lockstep_clock_for_a_real_base():
    result = anicov("agent", "--id", "0", "--n", "1", "--robot", "ros2", "--team", "none", timeout=60)
    assert result.returncode == 2
    assert "--robot ros2 drives a real base, which cannot wait for a lockstep go: use --clock realtime" in result.stderr


def test_the_agent_refuses_a_speed_that_is_not_the_robots_own():
    config = str(ROOT / "scenarios" / "ros2-paper.toml")
    result = anicov("agent", "--id", "0", "--config", config, "--robot", "ros2", "--clock", "realtime", "--speed", "10")
    assert result.returncode == 2
    assert "--speed: a real base moves in real time: expected --speed 20 " in result.stderr


def test_the_launcher_refuses_stand_in_bases_without_ros2_robots():
    launched = subprocess.run(
        [sys.executable, str(ROOT / "launch_team.py"), "--n", "2", "--test-bases"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert launched.returncode == 2 and "--test-bases: stand-in ROS 2 bases need --robot ros2" in launched.stderr


def test_without_the_extra_the_agent_says_what_to_install_in_one_line():
    # rosbags made unimportable, as in an install without anicov[ros2].
    code = (
        "import sys; sys.modules['rosbags'] = None; sys.modules['rosbags.typesys'] = None\n"
        "from anicov.cli import main\n"
        "sys.exit(main(['agent', '--id', '0', '--robot', 'ros2', '--clock', 'realtime']))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=limit(60))
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert lines == [
        "anicov: error: --robot ros2 needs the ROS 2 extra: pip install 'anicov[ros2]' (it adds rosbags, for CDR)"
    ]
