"""The ``anicov`` command: run one team in process, or reproduce the paper's experiments."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from anicov.scenario import CONTROLLERS, Scenario, ScenarioError, load_scenario

EXIT_OK = 0
EXIT_INCOMPLETE = 1
EXIT_USAGE = 2
DEFAULT_CONFIG = Path(__file__).resolve().parent.parent / "scenarios" / "paper.toml"


def resolve_scenario(args: argparse.Namespace) -> Scenario:
    """The scenario file (or the paper's) with command-line overrides applied."""
    scenario = load_scenario(args.config) if args.config else load_scenario(DEFAULT_CONFIG)
    return scenario.with_overrides(agents=args.n, seed=args.seed, controller=args.controller)


def command_run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from anicov.engine import run_scenario
    from anicov.outputs import format_summary, summary_of, write_summary, write_trajectory
    from anicov.plots import write_run_plots

    scenario = resolve_scenario(args)
    out_dir = Path(args.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    with tqdm(total=100, desc="coverage", unit="%", disable=args.quiet or None, leave=False) as bar:

        def progress(sim_time: float, domain_error: float) -> None:
            bar.set_postfix_str(f"t={sim_time:.0f}", refresh=False)
            bar.update(round(100 * (1 - domain_error)) - bar.n)

        result = run_scenario(scenario, progress=progress)
    write_trajectory(result, out_dir / "trajectory.csv")
    summary = summary_of(result)
    write_summary(summary, out_dir / "summary.json")
    write_run_plots(result, out_dir)
    print(format_summary(summary, out_dir))
    print(f"  wall time       {time.perf_counter() - started:.1f} s")
    return EXIT_OK if result.completed else EXIT_INCOMPLETE


def command_reproduce(args: argparse.Namespace) -> int:
    from anicov.reproduce import parse_team_range, reproduce

    teams = parse_team_range(args.teams)
    reproduce(Path(args.out), runs=args.runs, teams=teams, workers=args.workers, seed=args.seed)
    return EXIT_OK


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="anicov", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)

    run = commands.add_parser("run", help="run one team in this process and write its outputs")
    run.add_argument("--config", help="scenario TOML (default: scenarios/paper.toml)")
    run.add_argument("--n", type=int, help="team size (overrides 'agents')")
    run.add_argument("--seed", type=int, help="seed of the initial poses (overrides 'seed')")
    run.add_argument("--controller", choices=CONTROLLERS, help="overrides 'controller'")
    run.add_argument("--out", required=True, help="output directory")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.set_defaults(handler=command_run)

    reproduce = commands.add_parser("reproduce", help="the paper's experiments (Fig. 7–10) with a table and plots")
    reproduce.add_argument("--out", required=True, help="output directory")
    reproduce.add_argument("--runs", type=int, default=100, help="runs per team size (default 100)")
    reproduce.add_argument("--teams", default="1-30", help="team sizes, e.g. 1-30 or 1,4,10 (default 1-30)")
    reproduce.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    reproduce.add_argument("--seed", type=int, default=0, help="base seed; run r of every team uses seed+r")
    reproduce.set_defaults(handler=command_reproduce)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.handler(args))
    except ScenarioError as error:
        print(f"anicov: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("anicov: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
