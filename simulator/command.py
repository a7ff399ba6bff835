"""``anicov sim``: its arguments, and the start of the simulator process from them.

Light on imports: the CLI builds its parser from here; MuJoCo, Zenoh and rosbags load only when it runs.
"""

from __future__ import annotations

import argparse

from model.scenario import ScenarioError
from runtime.arguments import add_process_arguments, scenario_from_arguments

COMMAND_TIMEOUT = 0.5
"""Wall seconds without a command after which a realtime base stops on its own, as a real one does."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--namespace-prefix",
        default="bot",
        help="robot i's base lives in ROS namespace <prefix><i> (default bot: bot0/cmd_vel, bot0/odom)",
    )
    parser.add_argument(
        "--localiser-topic",
        default="amcl_pose",
        help="with a [noise] localiser: the topic of its fixes, PoseWithCovarianceStamped (default amcl_pose)",
    )
    parser.add_argument(
        "--command-timeout",
        type=float,
        default=COMMAND_TIMEOUT,
        help=f"realtime: a base stops after this many wall seconds without a command (default {COMMAND_TIMEOUT})",
    )
    parser.add_argument("--out", help="write sim.json (contacts, the truth's coverage) and sim-truth.csv here")
    add_process_arguments(parser)


def main(args: argparse.Namespace) -> int:
    from protocol.ros2 import require_rosbags
    from protocol.session import config_from_arguments
    from runtime.lifecycle import StopFlag, setup_logging
    from simulator.process import SimOptions, run_simulator

    setup_logging("sim", args.verbose)
    stop = StopFlag().install()
    require_rosbags()
    scenario = scenario_from_arguments(args)
    if scenario.physics != "mujoco":
        raise ScenarioError(
            f"scenario key 'physics': anicov sim plays the bases in a physics world: expected \"mujoco\", got "
            f"{scenario.physics!r}"
        )
    if not (args.command_timeout > 0):
        raise ScenarioError(f"--command-timeout: expected a positive number of seconds, got {args.command_timeout}")
    options = SimOptions(
        args.team, args.clock, args.speed, args.namespace_prefix, args.localiser_topic, args.command_timeout, args.out
    )
    return run_simulator(scenario, options, config_from_arguments(args), stop)
