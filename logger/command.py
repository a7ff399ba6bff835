"""``anicov logger``: its arguments, and the start of the logger process from them.

Light on imports: the CLI builds its parser from here; rerun and Zenoh load only when it runs.
"""

from __future__ import annotations

import argparse
import os
import uuid

from runtime.arguments import add_process_arguments, scenario_from_arguments


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", default="recording.rrd", help="recording file (default recording.rrd)")
    parser.add_argument("--recording-id", help="share one recording id with other loggers of the run")
    parser.add_argument("--no-record", action="store_true", help="no file (only a live viewer)")
    parser.add_argument("--viewer", action="store_true", help="spawn a live rerun viewer")
    parser.add_argument("--serve", action="store_true", help="serve a web viewer for a remote browser")
    parser.add_argument("--web-port", type=int, default=9090, help="--serve: HTTP port of the web viewer")
    parser.add_argument("--grpc-port", type=int, default=9876, help="--serve: port of the recording's gRPC server")
    parser.add_argument("--map-every", type=int, default=50, help="log the map every K steps (default 50)")
    parser.add_argument("--counts", help="write message counters to this JSON file at exit")
    parser.add_argument(
        "--nice", type=int, default=0, help="lower this process's CPU priority by this much (default 0)"
    )
    add_process_arguments(parser)


def main(args: argparse.Namespace) -> int:
    from logger.process import run_logger
    from logger.team_logger import LoggerOptions
    from protocol.session import config_from_arguments
    from runtime.lifecycle import StopFlag, setup_logging

    setup_logging("logger", args.verbose)
    if args.nice:
        # The logger is off the team's critical path: let the robots' processes have the CPU first.
        os.nice(args.nice)
    stop = StopFlag().install()
    scenario = scenario_from_arguments(args)
    options = LoggerOptions(
        args.team,
        args.recording_id or f"{args.team}-{uuid.uuid4().hex[:12]}",
        None if args.no_record else args.out,
        args.viewer,
        args.serve,
        args.map_every,
        args.counts,
        args.clock,
        args.web_port,
        args.grpc_port,
        args.no_coordinator,
    )
    return run_logger(scenario, options, config_from_arguments(args), stop)
