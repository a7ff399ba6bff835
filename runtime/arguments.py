"""The command-line arguments every part of a run shares, and the scenario they select.

``anicov run``, ``launch_team.py`` and each process (``anicov agent | coordinator | logger``) build their
parsers from these, so a flag means the same everywhere and the CLI and the launcher need not import
each other.
"""

from __future__ import annotations

import argparse
import sys

from model.controllers import choices, controller_of
from model.parameters import starting_poses
from model.scenario import PAPER_SCENARIO, Scenario, ScenarioError, load_scenario
from model.world.world import map_note_of

CLOCKS = ("lockstep", "realtime")


def add_scenario_arguments(parser: argparse.ArgumentParser) -> None:
    """--config, --n, --seed, --controller: which scenario, with overrides of its keys."""
    parser.add_argument("--config", help="scenario TOML (default: scenarios/paper.toml)")
    parser.add_argument("--n", type=int, help="team size (overrides the scenario's 'agents'; the paper's is 4)")
    parser.add_argument("--seed", type=int, help="seed of the initial poses (overrides 'seed')")
    parser.add_argument(
        "--controller",
        metavar="NAME",
        help=f"controller (overrides 'controller'): one of {', '.join(choices())}, or module.path:Class or "
        "path/to/file.py:Class (docs/controllers.md)",
    )


def add_team_arguments(parser: argparse.ArgumentParser) -> None:
    """The scenario arguments of a team on the bus, and its clock."""
    add_scenario_arguments(parser)
    parser.add_argument(
        "--clock",
        choices=CLOCKS,
        default="lockstep",
        help="lockstep: deterministic, equal to 'anicov run'; realtime: wall-clock steps",
    )
    parser.add_argument(
        "--speed",
        type=float,
        default=10.0,
        help="realtime only: simulated time units per wall-clock second (default 10)",
    )
    parser.add_argument(
        "--no-coordinator",
        action="store_true",
        help='a team without a coordinator process: needs planning = "local" and --clock realtime; the agents '
        "check each other's scenario, start when all are there and end the run themselves",
    )


def add_process_arguments(parser: argparse.ArgumentParser) -> None:
    """What a team process (agent, coordinator, logger) is told: the team and how to reach the bus."""
    add_team_arguments(parser)
    parser.add_argument("--team", default="team", help="team name: keys live under anicov/<team>/")
    parser.add_argument(
        "--connect", action="append", help="Zenoh endpoint to connect to (repeatable), e.g. tcp/192.168.1.10:7447"
    )
    parser.add_argument("--listen", action="append", help="Zenoh endpoint to listen on (peer mode)")
    parser.add_argument("--mode", choices=("client", "peer"), default="client", help="Zenoh mode (default client)")
    parser.add_argument("--zenoh-config", help="a Zenoh JSON5 config file (see deploy/); flags add endpoints")
    parser.add_argument("--drop-rate", type=float, default=0.0, help=argparse.SUPPRESS)  # test hook
    parser.add_argument("--verbose", action="store_true", help="debug logging")


def scenario_from_arguments(args: argparse.Namespace) -> Scenario:
    """The scenario file (or the paper's) with the command line's overrides applied and checked."""
    scenario = load_scenario(args.config or PAPER_SCENARIO)
    scenario = scenario.with_overrides(agents=args.n, seed=args.seed, controller=args.controller)
    speed = getattr(args, "speed", None)
    if speed is not None and speed <= 0:
        raise ScenarioError(f"--speed: expected a positive number, got {speed}")
    if getattr(args, "clock", None) == "lockstep" and scenario.comm_range != float("inf"):
        # Lockstep delivers every step through the coordinator's go: no radio to limit. (In process,
        # `anicov run` models the range; over the bus the receivers filter realtime steps.)
        raise ScenarioError(
            f"scenario key 'comm_range' ({scenario.comm_range}): a limited radio needs --clock realtime on the bus "
            "(lockstep steps travel in the coordinator's go); leave comm_range out, or run it with anicov run"
        )
    controller = controller_of(scenario)
    if getattr(args, "clock", None) is not None and (not controller.supports.team or controller.flies_pilots):
        # A team command (it has a clock): every robot must decide step by step on its own.
        raise ScenarioError(
            f"scenario key 'controller': '{scenario.controller}' flies paths planned once for the team and runs "
            "in process only (anicov run, anicov sweep)"
        )
    if hasattr(args, "clock") and scenario.physics != "kinematic" and getattr(args, "robot", "ros2") != "ros2":
        # A team command whose agents would move their robots by eq. 1 (the coordinator and the logger move none).
        raise ScenarioError(
            f"scenario key 'physics': '{scenario.physics}': a team over Zenoh moves simulated robots by eq. 1; with "
            "physics its agents drive ROS 2 bases that the simulator plays: launch_team.py --robot ros2 --sim-bases "
            "(or anicov run in process)"
        )
    if getattr(args, "no_coordinator", False):
        check_no_coordinator(scenario, getattr(args, "clock", None))
    check_world(scenario)
    return scenario


def note_map_fit(scenario: Scenario) -> None:
    """Say on the console what fitting the scenario's map to its cells changed (model.scenario.map_fit)."""
    note = map_note_of(scenario)
    if note:
        print(f"note: {note}", file=sys.stderr)


def check_no_coordinator(scenario: Scenario, clock: str | None) -> None:
    """A team with no coordinator: each robot must plan for itself, on the wall clock (lockstep's step
    is the coordinator's go)."""
    if scenario.planning != "local":
        raise ScenarioError(
            f"--no-coordinator: scenario key 'planning' must be \"local\" (got {scenario.planning!r}): "
            "with central planning the coordinator chooses every objective"
        )
    if clock != "realtime":
        raise ScenarioError(
            f"--no-coordinator: expected --clock realtime, got {clock}: a lockstep step is the coordinator's go"
        )


def check_world(scenario: Scenario) -> None:
    """Build the scenario's world and the team's starting poses now, so that a map with no room for the
    team fails here, with the file named, before any process starts."""
    where = f"map {scenario.map}" if scenario.map else "scenario"
    try:
        starting_poses(scenario)
    except ValueError as error:  # TerrainError, or no room for the team
        raise ScenarioError(f"{where}: {error}") from error
