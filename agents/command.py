"""``anicov agent``: its arguments, and the start of one agent process from them.

Light on imports: the CLI builds its parser from here; the process itself (Zenoh, numba, numpy) loads
only when the command runs.
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from agents.ros2.arguments import add_robot_arguments
from model.scenario import Scenario, ScenarioError
from runtime.arguments import add_process_arguments, scenario_from_arguments

if TYPE_CHECKING:
    from protocol.ros2.options import Ros2Options


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--id", type=int, required=True, help="this agent's id, 0..N-1")
    parser.add_argument("--counts", help="write message counters to this JSON file at exit")
    parser.add_argument(
        "--await-logger",
        action="store_true",
        help="with --no-coordinator: start the run only once a logger is listening (so its recording has every "
        "step); the coordinator waits for it otherwise",
    )
    add_deltas_argument(parser)
    add_process_arguments(parser)
    add_robot_arguments(parser)


def add_deltas_argument(parser: argparse.ArgumentParser) -> None:
    """How an agent's map deltas travel (protocol.events); the run is the same either way."""
    parser.add_argument(
        "--deltas",
        choices=("event", "cells"),
        default="event",
        help="event (default): each step's sensing event, ~65 bytes, every replica computes the cells; "
        "cells: the cells themselves (~2.4 kB on the paper's sensor)",
    )


def main(args: argparse.Namespace) -> int:
    from agents.node import AgentOptions
    from agents.process import run_agent
    from protocol.session import config_from_arguments
    from runtime.lifecycle import StopFlag, setup_logging

    setup_logging(f"agent-{args.id}", args.verbose)
    stop = StopFlag().install()
    scenario = scenario_from_arguments(args)
    if not 0 <= args.id < scenario.agents:
        raise ScenarioError(f"--id: expected an agent id from 0 to {scenario.agents - 1}, got {args.id}")
    if args.await_logger and not args.no_coordinator:
        raise ScenarioError("--await-logger: only with --no-coordinator (with a coordinator, it waits for the logger)")
    options = AgentOptions(
        args.team,
        args.id,
        args.clock,
        args.speed,
        args.drop_rate,
        args.counts,
        args.deltas,
        args.no_coordinator,
        args.await_logger,
    )
    ros2 = ros2_options(args, scenario) if args.robot == "ros2" else None
    return run_agent(scenario, options, config_from_arguments(args), stop, ros2)


def ros2_options(args: argparse.Namespace, scenario: Scenario) -> Ros2Options:
    """The ROS 2 driver's options, once the extra is installed and the clock is the robot's own."""
    from agents.ros2 import require_rosbags
    from agents.ros2.arguments import check_real_time, ros2_options_from

    require_rosbags()
    check_real_time(args.clock, args.speed, scenario.seconds_per_unit, args.ros_sim_time)
    return ros2_options_from(args)
