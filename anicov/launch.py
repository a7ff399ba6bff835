"""``launch_team.py`` / ``anicov launch``: a whole team on this machine, one OS process per role.

Opens an embedded Zenoh router on ``--listen``, starts the coordinator, N
agents (and the logger, when recording) as child processes connected to it,
shows progress, prints the run's summary and exits 0 when coverage is
complete. Ctrl-C or SIGTERM stops every child (SIGTERM, then SIGKILL after a
grace period), closes the router and exits 130 / 143. Children also die with
the launcher if it is killed outright (Linux parent-death signal).
"""

from __future__ import annotations

import argparse
import json
import logging
import subprocess
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING

from agents.command import add_deltas_argument
from anicov.ros2_team import (
    SIM_LOCALISER_TOPIC,
    add_ros2_team_arguments,
    check_ros2_team,
    merge_simulator_figures,
    ros2_agent_flags,
    test_base_commands,
)
from model.scenario import Scenario
from runtime.arguments import add_team_arguments, note_map_fit, scenario_from_arguments
from runtime.lifecycle import (
    EXIT_FAILED,
    EXIT_INCOMPLETE,
    EXIT_OK,
    EXIT_USAGE,
    StopFlag,
    setup_logging,
)

if TYPE_CHECKING:
    import zenoh

    from protocol.messages import RunControl

log = logging.getLogger("anicov.launch")

GRACE_SECONDS = 10.0
"""How long children get to exit after SIGTERM before SIGKILL."""
SIM_END_SECONDS = 5.0
"""Seconds the launcher gives anicov sim to write its figures and leave by itself after the team; then SIGTERM."""
LOGGER_NICE = 10
"""The logger's CPU priority below the team's: it is off the critical path and catches up when cores idle."""
COORDINATOR_RESTARTS = 3
"""How many times a coordinator killed by a signal is started again (it resumes from the agents)."""


@dataclass
class Child:
    role: str
    process: subprocess.Popen[bytes]
    log_path: Path


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="launch_team.py", description=__doc__.split("\n\n")[0])
    add_team_arguments(parser)
    parser.set_defaults(speed=None, clock=None)  # given or not: a ROS 2 team's are the robots' (anicov.ros2_team)
    add_ros2_team_arguments(parser)
    parser.add_argument(
        "--listen",
        help="router endpoint (default tcp/127.0.0.1:7447, or the --secure profile's tls endpoint)",
    )
    parser.add_argument(
        "--bus",
        choices=("peer", "client"),
        default="peer",
        help="peer (default): the processes exchange data directly over loopback and meet through the "
        "router; client: everything goes through the router, as across hosts (forced by --secure)",
    )
    parser.add_argument(
        "--secure",
        metavar="DIR",
        help="mutual TLS and access control from a profile made by 'anicov certs --out DIR'",
    )
    parser.add_argument("--team", default="team", help="team name: keys live under anicov/<team>/")
    add_deltas_argument(parser)
    parser.add_argument("--out", help="run directory (default runs/<date-time>)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument("--no-record", action="store_true", help="no logger, no OUT/recording.rrd")
    parser.add_argument(
        "--coordinator-restarts",
        type=int,
        default=COORDINATOR_RESTARTS,
        help=f"times a killed coordinator is started again (default {COORDINATOR_RESTARTS}); with planning = "
        '"local" in the scenario the robots go on without it',
    )
    parser.add_argument("--drop-rate", type=float, default=0.0, help=argparse.SUPPRESS)  # test hook: loss
    parser.add_argument("--viewer", action="store_true", help="spawn a live rerun viewer")
    parser.add_argument("--serve", action="store_true", help="serve a web viewer (for a browser on another machine)")
    parser.add_argument("--web-port", type=int, default=9090, help="--serve: HTTP port of the web viewer")
    parser.add_argument("--grpc-port", type=int, default=9876, help="--serve: port of the recording's gRPC server")
    parser.add_argument("--map-every", type=int, default=50, help="log the map every K steps (default 50)")
    return parser


def child_command(role: str, args: argparse.Namespace, extra: list[str], identity: str | None = None) -> list[str]:
    """The command line of one child; ``identity`` names its certificate and config in a --secure profile."""
    command = [
        sys.executable,
        "-m",
        "anicov.cli",
        role,
        "--team",
        args.team,
        "--connect",
        args.listen,
        *(["--mode", "peer", "--listen", "tcp/127.0.0.1:0"] if args.bus == "peer" else []),
        "--clock",
        args.clock,
        "--speed",
        str(args.speed),
    ]
    for flag, value in (
        ("--config", args.config),
        ("--n", args.n),
        ("--seed", args.seed),
        ("--controller", args.controller),
        ("--drop-rate", args.drop_rate or None),
        ("--zenoh-config", str(Path(args.secure).resolve() / f"{identity or role}.json5") if args.secure else None),
    ):
        if value is not None:
            command += [flag, str(value)]
    return command + ["--no-coordinator"] * bool(args.no_coordinator) + extra


def spawn(role: str, command: list[str], logs: Path) -> Child:
    from runtime.lifecycle import die_with_parent

    log_path = logs / f"{role}.log"
    with open(log_path, "wb") as sink:
        # A new session: a Ctrl-C in the terminal reaches the launcher only, which then stops
        # the children in order, so none is cut off in the middle of writing its outputs.
        process = subprocess.Popen(
            command,
            stdout=sink,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
            preexec_fn=die_with_parent,
        )
    return Child(role, process, log_path)


def stop_children(children: list[Child], grace: float = GRACE_SECONDS) -> None:
    for child in children:
        if child.process.poll() is None:
            child.process.terminate()
    deadline = time.monotonic() + grace
    for child in children:
        try:
            child.process.wait(timeout=max(0.1, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            log.warning("%s did not stop in %.0f s; killing it", child.role, grace)
            child.process.kill()
            child.process.wait()


def wait_for_exit(children: list[Child], timeout: float) -> None:
    deadline = time.monotonic() + timeout
    for child in children:
        try:
            child.process.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            pass


def warm_numba_cache(scenario: Scenario) -> None:
    """Compile (or load) the jitted kernels once here, so N children do not all compile at once."""
    from model.controllers import law_parameters
    from model.paper.coverage_map import load_kernels as load_map_kernels
    from model.parameters import coverage_map_of, exact_kernel_of, safety_parameters, starting_poses
    from model.radio.exact_coverage import load_kernels as load_event_kernel
    from model.safety.safety import load_kernels as load_safety_kernels
    from model.step import load_kernels
    from model.world.world import world_of

    grid, ground = coverage_map_of(scenario), world_of(scenario).ground
    load_kernels(grid.coverage, tuple(starting_poses(scenario)[0]), law_parameters(scenario, grid), ground)
    load_safety_kernels(safety_parameters(scenario), ground, scenario.cell, scenario.agents)
    load_map_kernels()
    load_event_kernel(exact_kernel_of(scenario))


@dataclass
class Supervision:
    """What the launcher saw while the team ran: the coordinator's exit code, robots lost, restarts."""

    exit_code: int = EXIT_FAILED
    lost: list[str] = field(default_factory=list)
    restarts: int = 0
    coordinator_lost: bool = False  # killed for good; local planning: the robots ended the run themselves


class ControlWatch:
    """The run's control and status messages, read on the router's session (decoded, validated)."""

    def __init__(self, scenario: Scenario) -> None:
        from protocol.messages import Limits

        self.limits = Limits.of(scenario)
        self.latest: dict[str, RunControl] = {}

    def on_sample(self, sample: zenoh.Sample) -> None:
        from protocol.decoding import decode
        from protocol.messages import ProtocolError, RunControl

        try:
            message = decode(sample.payload.to_bytes(), self.limits, expected="control")
        except ProtocolError:
            return
        assert isinstance(message, RunControl)
        self.latest["done" if message.kind in ("done", "abort") else "status"] = message


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    setup_logging("launch")
    stop = StopFlag().install()
    speed_given, args.speed = args.speed is not None, 10.0 if args.speed is None else args.speed
    try:
        scenario = scenario_from_arguments(args)
        note_map_fit(scenario)
        check_ros2_team(args, scenario, speed_given)  # settles the clock too
        router_config_file = apply_secure_profile(args, scenario.agents)
    except ValueError as error:  # ScenarioError, or a --secure profile that does not fit
        print(f"launch_team: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    out_dir = Path(args.out or Path("runs") / datetime.now().strftime("%Y%m%d-%H%M%S"))
    logs = out_dir / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    warm_numba_cache(scenario)

    import zenoh

    from protocol.keys import TeamKeys
    from protocol.session import zenoh_config

    started = time.monotonic()
    try:
        router = zenoh.open(zenoh_config("router", listen=[args.listen], config_file=router_config_file))
    except zenoh.ZError as error:
        print(f"launch_team: error: cannot open the router on {args.listen}: {error}", file=sys.stderr)
        return EXIT_USAGE
    children: list[Child] = []
    bases = start_bases(args, scenario, out_dir)
    with router:
        keys, watch = TeamKeys(args.team), ControlWatch(scenario)
        router.declare_subscriber(keys.control, watch.on_sample)
        router.declare_subscriber(keys.status, watch.on_sample)
        coordinator_command = start_team(args, scenario.agents, out_dir, children)
        seen = Supervision()
        try:
            if args.no_coordinator:  # local planning: the robots start, plan and end the run themselves
                agent_children = [child for child in children if child.role.startswith("agent-")]
                seen = Supervision(coordinator_lost=True, exit_code=wait_for_agents(agent_children, stop))
            else:
                seen = supervise(
                    children, coordinator_command, logs, watch, scenario, args.quiet, stop, args.coordinator_restarts
                )
        finally:
            if not stop.stopped:
                # After the end of the run every child leaves by itself (the logger flushes first).
                wait_for_exit(children, GRACE_SECONDS)
                if not args.no_coordinator:
                    note_failed_agents(children, seen, watch)
            stop_children(children)
            stop_bases(bases, args.sim_bases and not stop.stopped, out_dir)
    if stop.stopped:
        print(f"launch_team: stopped by signal; every child stopped. Logs in {logs}", file=sys.stderr)
        return stop.exit_code(EXIT_FAILED)
    return report(args, scenario.agents, out_dir, children, seen, time.monotonic() - started, scenario.dt)


def start_bases(args: argparse.Namespace, scenario: Scenario, out_dir: Path) -> list[Child]:
    """Stand-in ROS 2 bases (--test-bases) or the simulator playing them all (--sim-bases, anicov.ros2_team):
    up before the agents wait for their poses, stopped after them."""
    logs = out_dir / "logs"
    bases = [spawn(f"base-{i}", command, logs) for i, command in enumerate(test_base_commands(args, scenario, logs))]
    if args.sim_bases:
        flags = ["--out", str(out_dir), "--localiser-topic", SIM_LOCALISER_TOPIC]  # where the agents read fixes
        bases.append(spawn("sim", child_command("sim", args, flags), logs))
    return bases


def stop_bases(bases: list[Child], simulated: bool, out_dir: Path) -> None:
    """Stop the bases after the team; a simulator first gets SIM_END_SECONDS to leave by itself (it does once
    every agent has), then its figures join summary.json."""
    if simulated:
        wait_for_exit(bases, SIM_END_SECONDS)
    stop_children(bases)
    if simulated:
        merge_simulator_figures(out_dir)


def apply_secure_profile(args: argparse.Namespace, agents: int) -> str | None:
    """With --secure: the router's config file, and the profile's endpoint and client bus; else None."""
    router_config_file = None
    if args.secure:
        from anicov.secure import load_profile

        profile, endpoint = load_profile(Path(args.secure), args.team, agents)
        router_config_file = str(profile.config("router"))
        args.bus = "client"  # the profile's certificates and access control are the router's
        args.listen = args.listen or endpoint
    args.listen = args.listen or "tcp/127.0.0.1:7447"
    return router_config_file


def start_team(args: argparse.Namespace, agents: int, out_dir: Path, children: list[Child]) -> list[str]:
    """Spawn the coordinator, the logger (when recording) and the agents; return the coordinator's
    command line (a killed coordinator is started again with it).

    All children start at once; the coordinator starts the run when every agent has said hello and,
    when recording, the logger listens (so the recording holds every step). With no coordinator, the
    agents wait for the logger themselves (--await-logger).
    """
    logs = out_dir / "logs"
    recording = not args.no_record or args.viewer or args.serve
    coordinator_command = child_command(
        "coordinator", args, ["--out", str(out_dir)] + ["--await-logger"] * bool(recording)
    )
    if not args.no_coordinator:
        children.append(spawn("coordinator", coordinator_command, logs))
    if recording:
        logger_flags = ["--out", str(out_dir / "recording.rrd"), "--map-every", str(args.map_every)]
        logger_flags += ["--recording-id", f"{args.team}-{out_dir.name}"]
        logger_flags += ["--counts", str(logs / "logger.counts.json"), "--nice", str(LOGGER_NICE)]
        logger_flags += ["--no-record"] * args.no_record + ["--viewer"] * args.viewer
        if args.serve:
            logger_flags += ["--serve", "--web-port", str(args.web_port), "--grpc-port", str(args.grpc_port)]
        children.append(spawn("logger", child_command("logger", args, logger_flags), logs))
    for agent in range(agents):
        agent_flags = [
            "--id",
            str(agent),
            "--counts",
            str(logs / f"agent-{agent}.counts.json"),
            "--deltas",
            args.deltas,
        ]
        agent_flags += ["--await-logger"] * bool(args.no_coordinator and recording)  # the coordinator's job else
        agent_flags += ros2_agent_flags(args, agent)
        name = f"agent-{agent}"
        children.append(spawn(name, child_command("agent", args, agent_flags, identity=name), logs))
    return coordinator_command


def supervise(
    children: list[Child],
    coordinator_command: list[str],
    logs: Path,
    watch: ControlWatch,
    scenario: Scenario,
    quiet: bool,
    stop: StopFlag,
    restarts: int = COORDINATOR_RESTARTS,
) -> Supervision:
    """Show progress until the coordinator exits; restart a killed coordinator (``restarts`` times); report
    lost robots. With local planning a coordinator killed for good leaves the run to the robots."""
    from tqdm import tqdm

    seen = Supervision()
    reported: set[str] = set()
    with tqdm(total=100, desc=f"team of {scenario.agents}", unit="%", disable=quiet or None) as bar:
        while not stop.stopped:
            status = watch.latest.get("status")
            if status is not None:
                bar.set_postfix_str(f"t={status.step * scenario.dt:.0f}", refresh=False)
                bar.update(max(0, round(100 * (1 - status.domain_error)) - bar.n))
            code = children[0].process.poll()
            if code is not None and code < 0 and seen.restarts < restarts:
                # Killed, not finished: a new coordinator rebuilds the run from the agents' histories.
                seen.restarts += 1
                log.warning("the coordinator was killed (signal %d); starting it again (%d)", -code, seen.restarts)
                children[0] = spawn(f"coordinator.restart-{seen.restarts}", coordinator_command, logs)
                continue
            if code is not None and code < 0 and scenario.planning == "local":
                log.warning("the coordinator was killed (signal %d); with local planning the robots go on", -code)
                seen.coordinator_lost = True
                seen.exit_code = wait_for_agents([child for child in children if child.role.startswith("agent-")], stop)
                break
            if code is not None:
                seen.exit_code = code
                break
            # A robot that dies is the team's problem, not the run's: the coordinator notices it
            # through liveliness and carries on without it. Only report it.
            for child in children[1:]:
                code = child.process.poll()
                if code is not None and child.role not in reported:
                    reported.add(child.role)
                    if code != 0 and "done" not in watch.latest:
                        log.warning("%s exited with %s; the team carries on (see %s)", child.role, code, child.log_path)
                        seen.lost.append(child.role)
            stop.wait(0.1)
    return seen


def note_failed_agents(children: list[Child], seen: Supervision, watch: ControlWatch) -> None:
    """Agents that left the run failing and were not seen go (one that failed as the run ended, after the
    last look of :func:`supervise`): reported as lost, never silently. An aborted run's agents all exit
    failing: that is the abort, reported as such."""
    ending = watch.latest.get("done")
    if ending is not None and ending.kind == "abort":
        return
    for child in children:
        code = child.process.poll()
        if child.role.startswith("agent-") and code not in (None, 0) and child.role not in seen.lost:
            log.warning("%s exited with %s during the run (see %s)", child.role, code, child.log_path)
            seen.lost.append(child.role)


def report_without_coordinator(
    args: argparse.Namespace,
    agents: int,
    out_dir: Path,
    children: list[Child],
    seen: Supervision,
    wall: float,
    dt: float,
) -> int:
    """Local planning after the coordinator was killed for good, or with none started: what the robots did
    (no summary.json: the coordinator writes it; the recording has the run)."""
    from runtime.rundir import read_counts

    logs = out_dir / "logs"
    done = [child.role for child in children if child.role.startswith("agent-") and child.process.returncode == 0]
    how = "was not started (--no-coordinator)" if args.no_coordinator else "was killed and not restarted"
    print(f"launch_team: the coordinator {how}; local planning: {len(done)} of {agents} robots")
    print("  ended the run on their own, each with a complete replica" if len(done) == agents else "  ended the run")
    every_counts = [read_counts(logs / f"agent-{agent}.counts.json") or {} for agent in range(agents)]
    for agent, counts in enumerate(every_counts):
        print(
            f"  agent {agent}         e_D of its replica {counts.get('domain_error', '-')}, steps {counts.get('steps', '-')}"
        )
    if (out_dir / "recording.rrd").exists():
        print(f"  recording       {out_dir / 'recording.rrd'}   (no summary.json: the coordinator writes it)")
    report_bandwidth([counts for counts in every_counts if counts], dt, args.deltas, out_dir)
    print(f"  wall time       {wall:.1f} s")
    return seen.exit_code


def report_bandwidth(agent_counts: list[dict], dt: float, deltas: str, out_dir: Path) -> None:
    """Each robot's bytes on the bus (runtime.rundir.bandwidth_of): printed and kept in bandwidth.json."""
    from runtime.rundir import bandwidth_of, format_bandwidth

    bandwidth = bandwidth_of(agent_counts, dt)
    if bandwidth is not None:
        (out_dir / "bandwidth.json").write_text(json.dumps(bandwidth | {"deltas": deltas}, indent=2) + "\n")
        print(format_bandwidth(bandwidth, deltas))


def wait_for_agents(agents: list[Child], stop: StopFlag) -> int:
    """Local planning without a coordinator: each robot ends the run when its replica is complete.
    EXIT_OK if every one of them did, else EXIT_FAILED."""
    while not stop.stopped and any(child.process.poll() is None for child in agents):
        stop.wait(0.2)
    return EXIT_OK if all(child.process.poll() == 0 for child in agents) else EXIT_FAILED


def report(
    args: argparse.Namespace,
    agents: int,
    out_dir: Path,
    children: list[Child],
    seen: Supervision,
    wall: float,
    dt: float,
) -> int:
    """The one-screen summary of a finished run (or what failed), and the launcher's exit code."""
    logs = out_dir / "logs"
    summary_path = out_dir / "summary.json"
    if seen.coordinator_lost:
        return report_without_coordinator(args, agents, out_dir, children, seen, wall, dt)
    if seen.exit_code in (EXIT_OK, EXIT_INCOMPLETE) and summary_path.exists():
        from runtime.rundir import format_summary, read_counts

        summary = json.loads(summary_path.read_text())
        print(format_summary(summary, out_dir).replace("anicov run:", f"launch_team ({args.clock}, over Zenoh):"))
        print(
            f"  processes       coordinator + {agents} agents"
            + ("" if args.no_record else " + logger")
            + (f" + {agents} stand-in ROS 2 bases" if args.test_bases else "")
            + (" + anicov sim (the bases in the physics world)" if args.sim_bases else "")
            + f", logs in {logs}"
        )
        if seen.lost:
            print(f"  lost on the way {', '.join(seen.lost)} (the team went on without them)")
        if seen.restarts:
            print(
                f"  coordinator     killed and restarted {seen.restarts} time(s); it resumed from the agents' histories"
            )
        agent_counts = [
            counts for agent in range(agents) if (counts := read_counts(logs / f"agent-{agent}.counts.json"))
        ]
        report_bandwidth(agent_counts, dt, args.deltas, out_dir)
        if (out_dir / "recording.rrd").exists():
            print(f"  recording       {out_dir / 'recording.rrd'}   (anicov replay {out_dir / 'recording.rrd'})")
        print(f"  wall time       {wall:.1f} s")
        return EXIT_OK if summary["completed"] else EXIT_INCOMPLETE
    print(f"launch_team: the run failed (exit {seen.exit_code}); logs in {logs}", file=sys.stderr)
    for child in children:
        tail = child.log_path.read_text(errors="replace").strip().splitlines()[-3:]
        if child.process.returncode not in (0, None) and tail:
            print(f"  {child.role} (exit {child.process.returncode}): " + " | ".join(tail), file=sys.stderr)
    return EXIT_FAILED
