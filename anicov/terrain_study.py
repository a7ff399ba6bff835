"""The terrain experiments of issue 11: every shipped map against the empty domain of the same area.

For each map (scenarios/<map>.toml), each team size and occlusion on and off, ``runs`` seeded runs
(run r uses seed r); the empty domain (scenarios/paper.toml, 100 x 100 like the maps) with the same
seeds. Writes terrain.json (every run's figures), terrain.md (the table: mean t_N / t*_N with t*_N
on the coverable area, mean team path, completions, and the ratio to the empty domain against the
goal of 1.5) and <map>_coverage.png (Fig. 6 on the map, seed 0, N = 4). Runs in parallel over the
cores with a progress bar; the means are summed in seed order, so the files do not depend on it.
"""

from __future__ import annotations

import json
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from anicov.engine import run_scenario
from model.scenario import PAPER_SCENARIO, Scenario, load_scenario
from runtime.plots import plot_coverage_maps
from runtime.rundir import summary_of

MAPS = ("warehouse", "office", "field")
SCENARIOS = PAPER_SCENARIO.parent
GOAL = 1.5
"""Issue 11: on every map, mean t_N / t*_N within 1.5 x the empty domain's for the same N."""


def _one_run(scenario: Scenario) -> dict[str, Any]:
    summary = summary_of(run_scenario(scenario, record_trace=False))
    return {
        "seed": scenario.seed,
        "completed": summary["completed"],
        "ratio": summary["time_ratio"],
        "team_path": summary["team_path_length"],
    }


def _cases(runs: int, teams: list[int]) -> dict[tuple[str, int, bool], list[Scenario]]:
    cases: dict[tuple[str, int, bool], list[Scenario]] = {}
    settings = [("empty", True)] + [(name, occlusion) for name in MAPS for occlusion in (True, False)]
    for name, occlusion in settings:
        base = load_scenario(PAPER_SCENARIO if name == "empty" else SCENARIOS / f"{name}.toml")
        for agents in teams:
            overrides: dict[str, Any] = {"agents": agents}
            if name != "empty":  # as measured for issue 11, before the safety filter (issue 12) existed
                overrides |= {"occlusion": occlusion, "safety": False}
            cases[(name, agents, occlusion)] = [base.with_overrides(**overrides, seed=seed) for seed in range(runs)]
    return cases


def run_study(runs: int, teams: list[int], out_dir: Path, workers: int | None = None) -> dict[str, Any]:
    """Every case, in parallel; returns (and writes) the report."""
    from tqdm import tqdm

    cases = _cases(runs, teams)
    results: dict[tuple[str, int, bool], list[dict[str, Any]]] = {key: [] for key in cases}
    jobs = [(key, scenario) for key, scenarios in cases.items() for scenario in scenarios]
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
        futures = {pool.submit(_one_run, scenario): key for key, scenario in jobs}
        for future in tqdm(as_completed(futures), total=len(futures), desc="terrain runs", unit="run"):
            results[futures[future]].append(future.result())
    rows = [
        _row(name, agents, occlusion, sorted(found, key=lambda run: run["seed"]))
        for (name, agents, occlusion), found in results.items()
    ]
    report = {"runs": runs, "teams": teams, "goal": GOAL, "rows": rows}
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "terrain.json").write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
    (out_dir / "terrain.md").write_text(format_table(report), encoding="utf-8")
    for name in MAPS:
        scenario = load_scenario(SCENARIOS / f"{name}.toml")
        plot_coverage_maps(run_scenario(scenario), out_dir / f"{name}_coverage.png")
    return report


def _row(name: str, agents: int, occlusion: bool, found: list[dict[str, Any]]) -> dict[str, Any]:
    ratios = [run["ratio"] for run in found if run["ratio"] is not None]
    return {
        "map": name,
        "agents": agents,
        "occlusion": occlusion,
        "runs": len(found),
        "completed": sum(run["completed"] for run in found),
        "mean_ratio": float(np.sum(ratios) / len(ratios)) if ratios else None,
        "mean_team_path": float(np.sum([run["team_path"] for run in found]) / len(found)),
        "failed_seeds": [run["seed"] for run in found if not run["completed"]],
    }


def format_table(report: dict[str, Any]) -> str:
    """terrain.md: one line per map, team size and occlusion setting."""
    empty = {row["agents"]: row for row in report["rows"] if row["map"] == "empty"}
    lines = [
        f"# Terrain: t_N / t*_N on the shipped maps ({report['runs']} seeded runs each)",
        "",
        "t*_N (eq. 19) on each map's coverable area. Ratio to empty: the map's mean t_N / t*_N over the",
        f"empty 100 x 100 domain's for the same N and seeds; goal: at most {report['goal']}.",
        "",
        "| map | N | occlusion | completed | mean t_N / t*_N | mean team path | ratio to empty | goal |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in sorted(report["rows"], key=lambda r: (r["map"] != "empty", r["map"], r["agents"], not r["occlusion"])):
        base = empty[row["agents"]]["mean_ratio"]
        relative = row["mean_ratio"] / base if row["mean_ratio"] is not None and base else None
        verdict = (
            "-" if row["map"] == "empty" or relative is None else ("met" if relative <= report["goal"] else "NOT met")
        )
        lines.append(
            f"| {row['map']} | {row['agents']} | {'on' if row['occlusion'] else 'off'} | "
            f"{row['completed']}/{row['runs']} | {_fmt(row['mean_ratio'])} | {row['mean_team_path']:.0f} | "
            f"{_fmt(relative)} | {verdict} |"
        )
    return "\n".join(lines) + "\n"


def _fmt(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}"
