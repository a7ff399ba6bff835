"""``anicov coordinator``: its arguments, and the start of the coordinator process from them.

Light on imports: the CLI builds its parser from here; the process itself loads only when it runs.
"""

from __future__ import annotations

import argparse
import logging
import os
import sys

from runtime.arguments import add_process_arguments, scenario_from_arguments


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", help="write the run directory here at the end")
    parser.add_argument("--await-logger", action="store_true", help="start the run only once a logger is listening")
    add_process_arguments(parser)


def main(args: argparse.Namespace) -> int:
    from coordinator.process import CoordinatorOptions, run_coordinator
    from protocol.session import config_from_arguments
    from runtime.lifecycle import StopFlag, setup_logging

    setup_logging("coordinator", args.verbose)
    stop = StopFlag().install()
    scenario = scenario_from_arguments(args)
    options = CoordinatorOptions(args.team, args.clock, args.speed, args.out, args.drop_rate, args.await_logger)
    code = run_coordinator(scenario, options, config_from_arguments(args), stop)
    # Its session is closed and its files are written: skip the interpreter's teardown of numba,
    # matplotlib and friends (half a second), which the whole team's launcher would wait for.
    logging.shutdown()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
