"""The ``anicov`` command: run one team in process, or reproduce the paper's experiments."""

from __future__ import annotations

import argparse
import dataclasses
import shutil
import subprocess
import sys
import time
import uuid
from pathlib import Path

from agents import command as agent_command
from anicov import bound as bound_command
from coordinator import command as coordinator_command
from logger import command as logger_command
from model.scenario import ScenarioError
from runtime.arguments import add_scenario_arguments, note_map_fit, scenario_from_arguments
from runtime.lifecycle import EXIT_FAILED, EXIT_INCOMPLETE, EXIT_OK, EXIT_USAGE
from simulator import command as simulator_command


def command_run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from anicov.engine import run_scenario
    from runtime.rundir import format_summary, write_run_directory

    scenario = scenario_from_arguments(args)
    note_map_fit(scenario)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    with tqdm(total=100, desc="coverage", unit="%", disable=args.quiet or None, leave=False) as bar:

        def progress(sim_time: float, domain_error: float) -> None:
            bar.set_postfix_str(f"t={sim_time:.0f}", refresh=False)
            bar.update(round(100 * (1 - domain_error)) - bar.n)

        result = run_scenario(scenario, progress=progress)
    summary = write_run_directory(result, out_dir)
    if not args.no_record:
        from logger.recording import record_result

        record_result(
            result, out_dir / "recording.rrd", recording_id=f"run-{uuid.uuid4().hex[:12]}", map_every=args.map_every
        )
        if args.viewer:
            open_viewer(out_dir / "recording.rrd")
    print(format_summary(summary, out_dir))
    print(f"  wall time       {time.perf_counter() - started:.1f} s")
    return EXIT_OK if result.completed else EXIT_INCOMPLETE


def open_viewer(path: Path) -> None:
    """Open a recording in the rerun viewer (the one shipped with rerun-sdk)."""
    viewer = shutil.which("rerun") or str(Path(sys.executable).parent / "rerun")
    subprocess.Popen([viewer, str(path)], start_new_session=True)


def command_replay(args: argparse.Namespace) -> int:
    path = Path(args.recording)
    if not path.is_file():
        raise ScenarioError(f"replay: no recording at {path}")
    if args.summary:
        from logger.replay import format_recording_summary, summarise_recording

        print(format_recording_summary(summarise_recording(path)))
        return EXIT_OK
    open_viewer(path)
    return EXIT_OK


def command_reproduce(args: argparse.Namespace) -> int:
    from anicov.reproduce import parse_team_range, reproduce

    teams = parse_team_range(args.teams)
    reproduce(Path(args.out), runs=args.runs, teams=teams, workers=args.workers, seed=args.seed)
    return EXIT_OK


def command_terrain_study(args: argparse.Namespace) -> int:
    from anicov.reproduce import parse_team_range
    from anicov.terrain_study import run_study

    if args.runs < 1:
        raise ScenarioError(f"--runs: expected a positive number of runs, got {args.runs}")
    run_study(args.runs, parse_team_range(args.teams), Path(args.out), args.workers)
    print(f"terrain study written to {args.out}/terrain.md")
    return EXIT_OK


def command_safety_study(args: argparse.Namespace) -> int:
    from anicov.reproduce import parse_team_range
    from anicov.safety_study import MAPS, run_study

    if args.runs < 1:
        raise ScenarioError(f"--runs: expected a positive number of runs, got {args.runs}")
    maps = tuple(name for name in args.maps.split(",") if name and name != "none")
    unknown = sorted(set(maps) - set(MAPS))
    if unknown:
        raise ScenarioError(f"--maps: expected names among {', '.join(MAPS)} (or none), got {unknown[0]!r}")
    teams = [] if args.teams == "none" else parse_team_range(args.teams)
    if not teams and not maps:
        raise ScenarioError("--teams none with --maps none: nothing to run")
    run_study(args.runs, teams, Path(args.out), args.workers, maps)
    print(f"safety study written to {args.out}/safety.md")
    return EXIT_OK


def command_sweep(args: argparse.Namespace) -> int:
    from anicov.sweep import load_sweep, run_sweep

    sweep = load_sweep(Path(args.sweep))
    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers: expected a positive number, got {args.workers}")
    if args.seeds is not None:
        if args.seeds < 1:
            raise ScenarioError(f"--seeds: expected a positive number, got {args.seeds}")
        sweep = dataclasses.replace(sweep, seeds=sweep.seeds[: args.seeds])
    total = len(list(sweep.points()))
    found, made = run_sweep(sweep, Path(args.out), args.workers, args.cluster, progress=not args.quiet)
    where = f"on the cluster at {args.cluster}" if args.cluster else "on this machine"
    print(f"sweep: {total} runs; {found} found done in {args.out}/runs.csv, {made} run now {where}")
    return EXIT_OK


def command_sweep_plot(args: argparse.Namespace) -> int:
    from anicov.sweep import mean_table, plot_sweep

    path = Path(args.png) if args.png else Path(args.out) / f"{args.y}_by_{args.x}.png"
    print(mean_table(Path(args.out), args.x, args.y, args.by))
    print(f"plot written to {plot_sweep(Path(args.out), args.x, args.y, args.by, path)}")
    return EXIT_OK


def _shown(table: str, write: str | None) -> int:
    """A study's Markdown table printed, and written to ``write`` where given."""
    if write:
        Path(write).write_text(table)
    print(table, end="")
    return EXIT_OK


def command_controller_table(args: argparse.Namespace) -> int:
    from anicov.controller_table import controller_table

    return _shown(controller_table(Path(args.out), args.challenger), args.write)


def command_maps_table(args: argparse.Namespace) -> int:
    from anicov.maps_table import maps_table

    return _shown(maps_table([Path(out) for out in args.out], args.challenger), args.write)


def command_physics_table(args: argparse.Namespace) -> int:
    from anicov.physics_table import physics_table

    return _shown(physics_table([Path(out) for out in args.out], args.seeds), args.write)


def command_router(args: argparse.Namespace) -> int:
    import zenoh

    from protocol.session import zenoh_config
    from runtime.lifecycle import StopFlag, setup_logging

    setup_logging("router")
    stop = StopFlag().install()
    config = zenoh_config("router", listen=args.listen, config_file=args.zenoh_config)
    with zenoh.open(config):
        print(f"anicov router listening on {', '.join(args.listen or ['(config file)'])}; Ctrl-C stops it", flush=True)
        while not stop.wait(3600.0):
            pass
    return stop.exit_code(EXIT_OK)


def command_certs(args: argparse.Namespace) -> int:
    from anicov.secure import DEFAULT_HOSTS, make_profile

    profile = make_profile(
        Path(args.out),
        args.n,
        team=args.team,
        hosts=tuple(args.host or DEFAULT_HOSTS),
        endpoint=args.endpoint,
        days=args.days,
    )
    print(f"anicov certs: CA, {len(profile.roles)} certificates and Zenoh configs in {profile.directory}")
    print(f"  router:  anicov router --zenoh-config {profile.config('router')}")
    print(f"  agent i: anicov agent --team {args.team} --id i --zenoh-config {profile.directory}/agent-i.json5 ...")
    print(f"  a whole team here: launch_team.py --n {args.n} --team {args.team} --secure {profile.directory}")
    return EXIT_OK


def command_launch(args: argparse.Namespace) -> int:
    from anicov.launch import main as launch_main

    return launch_main(args.rest)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="anicov", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    _add_in_process_commands(commands)
    # The team's processes: each part declares its own arguments (agents/, coordinator/, logger/, simulator/ command.py).
    for name, part, text in (
        ("agent", agent_command, "one robot of a team, on the Zenoh bus"),
        ("coordinator", coordinator_command, "the team's coordinator (Algorithms 1-2), on the bus"),
        ("logger", logger_command, "record a team over the bus into a rerun recording"),
        ("sim", simulator_command, "play every robot's ROS 2 base in a physics world, on the bus (--robot ros2)"),
    ):
        command = commands.add_parser(name, help=text)
        part.add_arguments(command)
        command.set_defaults(handler=part.main)
    _add_sweep(commands)
    _add_bus_tools(commands)
    launch = commands.add_parser("launch", help="a whole team on this machine (same as launch_team.py)", add_help=False)
    launch.add_argument("rest", nargs=argparse.REMAINDER)
    launch.set_defaults(handler=command_launch)
    return parser


def _add_in_process_commands(commands: argparse._SubParsersAction) -> None:
    """run, replay, reproduce: work done in this process."""
    run = commands.add_parser("run", help="run one team in this process and write its outputs")
    add_scenario_arguments(run)
    run.add_argument("--out", required=True, help="output directory")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument("--no-record", action="store_true", help="do not write OUT/recording.rrd")
    run.add_argument("--viewer", action="store_true", help="open the recording in the rerun viewer afterwards")
    run.add_argument("--map-every", type=int, default=50, help="log the map every K steps (default 50)")
    run.set_defaults(handler=command_run)

    replay = commands.add_parser("replay", help="open a recording in the viewer, or summarise it (--summary)")
    replay.add_argument("recording", help="a .rrd file written by a run")
    replay.add_argument("--summary", action="store_true", help="print what it holds, headless")
    replay.set_defaults(handler=command_replay)

    reproduce = commands.add_parser("reproduce", help="the paper's experiments (Fig. 7–10) with a table and plots")
    reproduce.add_argument("--out", required=True, help="output directory")
    reproduce.add_argument("--runs", type=int, default=100, help="runs per team size (default 100)")
    reproduce.add_argument("--teams", default="1-30", help="team sizes, e.g. 1-30 or 1,4,10 (default 1-30)")
    reproduce.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    reproduce.add_argument("--seed", type=int, default=0, help="base seed; run r of every team uses seed+r")
    reproduce.set_defaults(handler=command_reproduce)

    terrain = commands.add_parser("terrain-study", help="every shipped map against the empty domain (issue 11)")
    terrain.add_argument("--out", required=True, help="output directory (docs/terrain holds the committed one)")
    terrain.add_argument("--runs", type=int, default=100, help="seeded runs per case (default 100)")
    terrain.add_argument("--teams", default="1,4,10", help="team sizes (default 1,4,10)")
    terrain.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    terrain.set_defaults(handler=command_terrain_study)

    safety = commands.add_parser("safety-study", help="the safety filter on and off, same seeds (issue 12)")
    safety.add_argument("--out", required=True, help="output directory (docs/safety holds the committed one)")
    safety.add_argument("--runs", type=int, default=100, help="seeded runs per case (default 100)")
    safety.add_argument("--teams", default="1-30", help="team sizes on the paper's domain (default 1-30, or none)")
    safety.add_argument("--maps", default="warehouse,office,field", help="shipped maps, N = 4 and 10 (or none)")
    safety.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    safety.set_defaults(handler=command_safety_study)

    bound = commands.add_parser("bound", help="anicov's stations' bound beside t*_N on a scenario's map (issue 36)")
    add_scenario_arguments(bound)
    bound_command.add_arguments(bound)
    bound.set_defaults(handler=bound_command.main)


def _add_sweep(commands: argparse._SubParsersAction) -> None:
    """sweep, sweep-plot: grids of runs into one table (issue 14)."""
    sweep = commands.add_parser("sweep", help="a grid of runs from a TOML file into one table (OUT/runs.csv)")
    sweep.add_argument("sweep", help="the sweep file (see anicov/sweep.py and sweeps/)")
    sweep.add_argument("--out", required=True, help="output directory; a sweep started again there resumes")
    sweep.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    sweep.add_argument("--cluster", metavar="ADDRESS", help="a Dask distributed scheduler, e.g. tcp://host:8786")
    sweep.add_argument("--quiet", action="store_true", help="no progress bar")
    sweep.add_argument(
        "--seeds",
        type=int,
        metavar="K",
        help="only the file's first K seeds (a study in stages: the rest run later on the same OUT, which resumes)",
    )
    sweep.set_defaults(handler=command_sweep)

    plot = commands.add_parser(
        "sweep-plot", help="a figure of a sweep's table against one of its keys: its means (markdown) and a PNG"
    )
    plot.add_argument("out", help="the sweep's output directory")
    plot.add_argument("--x", required=True, help="the key on the x axis, e.g. agents")
    plot.add_argument("--y", required=True, help="the figure on the y axis, e.g. time_ratio")
    plot.add_argument("--by", help="one line per value of this key, e.g. controller")
    plot.add_argument("--png", help="where to write it (default OUT/<y>_by_<x>.png)")
    plot.set_defaults(handler=command_sweep_plot)

    table = commands.add_parser(
        "controller-table", help="issue 14's comparison of controllers from a sweep's table, goals checked"
    )
    table.add_argument("out", help="the sweep's output directory (sweeps/controllers.toml)")
    table.add_argument("--write", help="also write the Markdown table to this file")
    table.add_argument(
        "--challenger",
        default="anicov",
        help="the controller whose goals the table checks (default anicov; a plug-in by its column's name, "
        "e.g. mine.py:Mine)",
    )
    table.set_defaults(handler=command_controller_table)

    maps = commands.add_parser(
        "maps-table", help="issue 36's study: a controller against the paper's law on maps, goals checked"
    )
    maps.add_argument("out", nargs="+", help="one sweep's output directory per map (sweeps/anicov-maps/*.toml)")
    maps.add_argument("--write", help="also write the Markdown table to this file")
    maps.add_argument("--challenger", default="anicov", help="the controller set against the paper's law")
    maps.set_defaults(handler=command_maps_table)

    physics = commands.add_parser(
        "physics-table", help="issue 37's study: kinematic, physics and physics with noise per map, goals checked"
    )
    physics.add_argument(
        "out", nargs="+", help="sweep output directories (sweeps/physics/*.toml): <map> and <map>-noise per map"
    )
    physics.add_argument("--write", help="also write the Markdown table to this file")
    physics.add_argument(
        "--seeds", type=int, metavar="K", help="only each table's seeds below K: every mode measured on the same runs"
    )
    physics.set_defaults(handler=command_physics_table)


def _add_bus_tools(commands: argparse._SubParsersAction) -> None:
    """router, certs: what a team spread over hosts needs besides its processes."""
    router = commands.add_parser("router", help="a standalone Zenoh router for a team spread over hosts")
    router.add_argument("--listen", action="append", help="endpoint (repeatable), e.g. tcp/0.0.0.0:7447")
    router.add_argument("--zenoh-config", help="a Zenoh JSON5 config file (see deploy/router.json5)")
    router.set_defaults(handler=command_router)

    certs = commands.add_parser(
        "certs", help="a secure profile: test CA, per-process certificates, mutual-TLS and access-control configs"
    )
    certs.add_argument("--out", required=True, help="directory for the profile (keys are written mode 0600)")
    certs.add_argument("--n", type=int, default=4, help="team size: certificates agent-0 .. agent-(n-1) (default 4)")
    certs.add_argument("--team", default="team", help="the team the access-control list admits (default team)")
    certs.add_argument(
        "--host",
        action="append",
        help="router host name or IP in its certificate (repeatable; default localhost, 127.0.0.1)",
    )
    certs.add_argument("--endpoint", default="tls/localhost:7447", help="router endpoint (default tls/localhost:7447)")
    certs.add_argument("--days", type=int, default=365, help="validity in days (default 365)")
    certs.set_defaults(handler=command_certs)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["launch"]:  # every flag is launch_team.py's, --help too (argparse's REMAINDER drops it)
        from anicov.launch import main as launch_main

        return launch_main(argv[1:])
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args))
    except (ScenarioError, ValueError) as error:
        print(f"anicov: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except RuntimeError as error:  # e.g. protocol.session.RouterUnreachable: say what, not a traceback
        print(f"anicov: error: {error}", file=sys.stderr)
        return EXIT_FAILED
    except KeyboardInterrupt:
        print("anicov: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
