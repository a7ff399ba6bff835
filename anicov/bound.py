"""``anicov bound``: what anicov's stations say this sensor needs on a map, beside t*_N (issue 36, item 6).

For the scenario's map (or the open domain) and each team size: t*_N (eq. 19, on the coverable area) and
the stations' bound, the relaxed programme's stare time shared by N robots nobody travelling
(:mod:`model.controllers.anicov.terrain_stations`, through the registry), with their ratio; how many stations, and how many
coverable cells no stare reaches (0 means none is left out). One table on the console, and a JSON file
with ``--out``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

from model.controllers.registry import stations_programme
from model.paper.metrics import optimum_time, total_sensing_ability
from model.scenario import Scenario
from model.world.world import world_of
from runtime.arguments import note_map_fit, scenario_from_arguments
from runtime.lifecycle import EXIT_OK, EXIT_USAGE
from runtime.rundir import covered_area


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--teams", default="1,2,4,8", help="team sizes (default 1,2,4,8)")
    parser.add_argument("--out", help="also write the figures to this JSON file")


def bound_rows(scenario: Scenario, teams: list[int]) -> dict[str, Any]:
    """The figures of ``anicov bound`` for one scenario."""
    started = time.perf_counter()
    programme = stations_programme(scenario)
    ability = total_sensing_ability(scenario.range, scenario.half_angle, scenario.alpha_max)
    area = covered_area(world_of(scenario))
    rows = []
    for agents in teams:
        optimum = optimum_time(area, scenario.lambda_star, ability, agents)
        bound = programme.stare_time / agents
        rows.append({"agents": agents, "optimum_time": optimum, "stations_bound": bound, "ratio": bound / optimum})
    return {
        "map": scenario.map or None,
        "stations": len(programme.stations),
        "unseen_cells": programme.unseen,
        "stare_time": programme.stare_time,
        "seconds": time.perf_counter() - started,
        "rows": rows,
    }


def main(args: argparse.Namespace) -> int:
    scenario = scenario_from_arguments(args)
    note_map_fit(scenario)
    try:
        teams = [int(part) for part in args.teams.split(",")]
    except ValueError:
        teams = []
    if not teams or min(teams) < 1:
        print(f"anicov bound: --teams expects team sizes such as 1,2,4,8, got {args.teams!r}", file=sys.stderr)
        return EXIT_USAGE
    figures = bound_rows(scenario, teams)
    print(
        f"stations {figures['stations']}, coverable cells no stare reaches {figures['unseen_cells']}, "
        f"stare time {figures['stare_time']:.1f} ({figures['seconds']:.1f} s)"
    )
    print("| N | t*_N | stations' bound | bound / t*_N |")
    print("|---|---|---|---|")
    for row in figures["rows"]:
        print(f"| {row['agents']} | {row['optimum_time']:.1f} | {row['stations_bound']:.1f} | {row['ratio']:.2f} |")
    if args.out:
        Path(args.out).write_text(json.dumps(figures, indent=2) + "\n", encoding="utf-8")
    return EXIT_OK
