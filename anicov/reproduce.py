"""The paper's experiments (Section V): Fig. 7–10 and every number of DESIGN.md §4.

Runs ``runs`` seeded teams for every team size, in parallel over the cores,
with a progress bar, and writes ``reproduction.json``, ``reproduction.md``
(our numbers beside the paper's) and the plots of Fig. 7, 8, 9 and 10.
Run r of every team size uses seed ``seed + r``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from anicov.engine import run_scenario
from anicov.sweep import Sweep, read_done, run_sweep
from model.controllers import BUILT_IN
from model.paper.metrics import optimum_time, pass_reach, straight_pass_coverage, total_sensing_ability
from model.scenario import PAPER_SCENARIO, Scenario, ScenarioError, load_scenario

PAPER = {
    "d100": 2.72,
    "d50": 3.865,
    "total_ability": 1570.8,
    "zigzag_time_1": 2080.6,
    "zigzag_path_1": 2054.6,
    "time_ratio_small": 4.0,
    "time_ratio_30": 5.0,
    "path_vs_zigzag": 0.55,
}


def parse_team_range(text: str) -> list[int]:
    """'1-30' or '1,4,10' or '1-5,10' → sorted team sizes."""
    sizes: set[int] = set()
    try:
        for part in text.split(","):
            if "-" in part:
                low, high = (int(item) for item in part.split("-", 1))
                sizes.update(range(low, high + 1))
            else:
                sizes.add(int(part))
    except ValueError as error:
        raise ScenarioError(f"--teams: expected sizes like 1-30 or 1,4,10, got {text!r}") from error
    if not sizes or min(sizes) < 1:
        raise ScenarioError(f"--teams: expected positive team sizes, got {text!r}")
    return sorted(sizes)


def paper_curve(agents: int) -> float:
    """The paper's Fig. 9 read as a line: t_N/t*_N ≈ 4 for one agent rising to 5 at N = 30."""
    return 4.0 + (agents - 1) / 29.0


def zigzag_reference(base: Scenario) -> dict[str, Any]:
    """One agent flying the Fig. 8 plan from its start: time and path to the plan's end."""
    scenario = base.with_overrides(controller="zigzag", agents=1)
    result = run_scenario(scenario, poses=BUILT_IN["zigzag"].start_poses(scenario), record_trace=True)
    return {
        "result": result,
        "time": result.plan_time,
        "path": float(result.path_lengths.sum()),
        "coverage_time": result.completion_time,
        "completed": result.completed,
    }


def reproduce(
    out_dir: Path, runs: int, teams: list[int], workers: int | None = None, seed: int = 0, base: Scenario | None = None
) -> dict[str, Any]:
    """Run the experiments and write every output; returns the reproduction.json content."""

    out_dir.mkdir(parents=True, exist_ok=True)
    base = load_scenario(PAPER_SCENARIO) if base is None else base
    ability = total_sensing_ability(base.range, base.half_angle, base.alpha_max)
    area = base.domain[0] * base.domain[1]
    zigzag = zigzag_reference(base)
    # One anicov sweep (anicov.sweep): its table OUT/runs.csv is kept, so a reproduction stopped half-way
    # resumes where it stopped. Team sizes in order, one agent (the longest runs) first.
    sweep = Sweep(base.with_overrides(controller="paper"), {"agents": sorted(teams)}, [seed + r for r in range(runs)])
    run_sweep(sweep, out_dir, workers)
    outcomes: dict[int, list[tuple[int, bool, float, float]]] = {n: [] for n in teams}
    for row in read_done(out_dir / "runs.csv", sweep.columns):
        if int(row["agents"]) not in outcomes or int(row["seed"]) not in sweep.seeds:
            continue  # an earlier reproduction in this directory with other team sizes or seeds
        completed = row["completed"] == "True"
        time, path = float(row["completion_time"] or "nan"), float(row["team_path_length"])
        outcomes[int(row["agents"])].append((int(row["seed"]), completed, time, path))
    for results in outcomes.values():
        results.sort()  # by seed: the means must not depend on which run finished first
    rows = []
    for n in teams:
        done = [(time, path) for _, completed, time, path in outcomes[n] if completed]
        times = np.array([time for time, _ in done])
        paths = np.array([path for _, path in done])
        ratios = times / optimum_time(area, base.lambda_star, ability, n)
        rows.append(
            {
                "n": n,
                "runs": len(outcomes[n]),
                "completed": len(done),
                "mean_time": float(times.mean()) if done else None,
                "mean_time_ratio": float(ratios.mean()) if done else None,
                "std_time_ratio": float(ratios.std()) if done else None,
                "mean_team_path": float(paths.mean()) if done else None,
                "mean_path_vs_zigzag": float(paths.mean() / zigzag["path"]) if done else None,
            }
        )
    report = {
        "scenario": base.to_dict(),
        "seed": seed,
        "d100": pass_reach(base),
        "d50": pass_reach(base, 0.5),
        "total_ability": ability,
        "zigzag_time_1": zigzag["time"],
        "zigzag_path_1": zigzag["path"],
        "zigzag_coverage_time_1": zigzag["coverage_time"],
        "teams": rows,
    }
    (out_dir / "reproduction.json").write_text(json.dumps(report, indent=2) + "\n", encoding="utf-8")
    (out_dir / "reproduction.md").write_text(comparison_table(report), encoding="utf-8")
    plot_reproduction(report, base, zigzag["result"], out_dir)
    print(comparison_table(report))
    return report


def _relative(ours: float | None, paper: float) -> str:
    return "-" if ours is None else f"{100.0 * (ours - paper) / paper:+.1f} %"


def comparison_table(report: dict[str, Any]) -> str:
    """Markdown: every reference number of DESIGN.md §4, ours beside the paper's."""
    zigzag_ratio = report["zigzag_time_1"] / (
        report["scenario"]["domain"][0]
        * report["scenario"]["domain"][1]
        * report["scenario"]["lambda_star"]
        / report["total_ability"]
    )
    lines = [
        "| quantity | paper | ours | difference |",
        "|---|---|---|---|",
        f"| d100 (Fig. 7) | 2.72 | {report['d100']:.4f} | {_relative(report['d100'], 2.72)} |",
        f"| d50 (Fig. 7) | 3.865 | {report['d50']:.4f} | {_relative(report['d50'], 3.865)} |",
        f"| total ability 𝒜 (eq. 18) | 1570.8 | {report['total_ability']:.1f} | {_relative(report['total_ability'], 1570.8)} |",
        f"| zig-zag t₁ (Fig. 8) | 2080.6 | {report['zigzag_time_1']:.1f} | {_relative(report['zigzag_time_1'], 2080.6)} |",
        f"| zig-zag path (Fig. 8) | 2054.6 | {report['zigzag_path_1']:.1f} | {_relative(report['zigzag_path_1'], 2054.6)} |",
        f"| zig-zag t_N / t*_N (Fig. 9) | 3.27 | {zigzag_ratio:.2f} | {_relative(zigzag_ratio, 3.27)} |",
    ]
    for row in report["teams"]:
        n = row["n"]
        lines.append(
            f"| t_N / t*_N, N = {n} (Fig. 9; {row['completed']}/{row['runs']} runs complete) | ≈ {paper_curve(n):.2f} "
            f"| {row['mean_time_ratio']:.2f} ± {row['std_time_ratio']:.2f} | {_relative(row['mean_time_ratio'], paper_curve(n))} |"
            if row["mean_time_ratio"] is not None
            else f"| t_N / t*_N, N = {n} | ≈ {paper_curve(n):.2f} | - | - |"
        )
    for row in report["teams"]:
        if row["mean_path_vs_zigzag"] is not None:
            lines.append(
                f"| team path / zig-zag path, N = {row['n']} (Fig. 10) | ≈ 0.55 | {row['mean_path_vs_zigzag']:.2f} "
                f"| {_relative(row['mean_path_vs_zigzag'], 0.55)} |"
            )
    return "\n".join(lines) + "\n"


def plot_reproduction(report: dict[str, Any], base: Scenario, zigzag_result: Any, out_dir: Path) -> None:
    """Fig. 7 (straight-pass profile), Fig. 8 (zig-zag path), Fig. 9 (time), Fig. 10 (path)."""
    import matplotlib

    matplotlib.use("Agg")
    teams = [row for row in report["teams"] if row["mean_time_ratio"] is not None]
    _plot_straight_pass(report, base, out_dir / "fig7_straight_pass.png")
    _plot_zigzag(report, base, zigzag_result, out_dir / "fig8_zigzag.png")
    _plot_time_ratio(report, base, teams, out_dir / "fig9_time_ratio.png")
    _plot_path_length(report, teams, out_dir / "fig10_path_length.png")


def _figure(figsize: tuple[float, float]) -> tuple[Any, Any]:
    import matplotlib.pyplot as plt

    return plt.subplots(figsize=figsize)


def _save(fig: Any, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _plot_straight_pass(report: dict[str, Any], base: Scenario, path: Path) -> None:
    """Fig. 7: the coverage across one straight pass, with d100 and d50 marked."""
    offsets = np.linspace(0.0, base.range * math.sin(base.half_angle), 200)
    profile = [straight_pass_coverage(d, base.range, base.half_angle, base.alpha_max) for d in offsets]
    fig, ax = _figure((6, 3.5))
    ax.plot(np.concatenate([-offsets[::-1], offsets]), np.concatenate([profile[::-1], profile]), color="black")
    for level, key in ((base.lambda_star, "d100"), (base.lambda_star / 2, "d50")):
        ax.axhline(level, color="grey", linewidth=0.6)
        ax.axvline(report[key], color="tab:red", linestyle="--", linewidth=0.8)
        ax.text(report[key], level, f" {key} = {report[key]:.3f}", fontsize=8)
    ax.set_xlabel("distance perpendicular to the pass")
    ax.set_ylabel("coverage Λ")
    ax.set_title("Coverage of one straight pass at v = 1 (Fig. 7)")
    _save(fig, path)


def _plot_zigzag(report: dict[str, Any], base: Scenario, zigzag_result: Any, path: Path) -> None:
    """Fig. 8: the zig-zag agent's path and waypoints in the domain."""
    fig, ax = _figure((5.5, 4.5))
    one = base.with_overrides(controller="zigzag", agents=1)
    waypoints = BUILT_IN["zigzag"]().pilots(one, BUILT_IN["zigzag"].start_poses(one))[0].waypoints
    ax.plot(zigzag_result.trace[:, 0, 0], zigzag_result.trace[:, 0, 1], color="tab:blue", linewidth=0.8)
    ax.plot(waypoints[:, 0], waypoints[:, 1], ".", color="tab:red", markersize=3)
    width, height = base.domain
    ax.plot([0, width, width, 0, 0], [0, 0, height, height, 0], "k--", linewidth=0.8)
    ax.set_aspect("equal")
    ax.set_title(f"Zig-zag path: t₁ = {report['zigzag_time_1']:.1f}, length {report['zigzag_path_1']:.1f} (Fig. 8)")
    _save(fig, path)


def _plot_time_ratio(report: dict[str, Any], base: Scenario, teams: list[dict[str, Any]], path: Path) -> None:
    """Fig. 9: t_N / t*_N per team size, beside the paper's curve, the zig-zag and the optimum."""
    sizes = np.array([row["n"] for row in teams])
    area = base.domain[0] * base.domain[1]
    fig, ax = _figure((6, 3.8))
    if len(teams):
        ax.errorbar(
            sizes,
            [row["mean_time_ratio"] for row in teams],
            yerr=[row["std_time_ratio"] for row in teams],
            fmt="o-",
            markersize=3,
            capsize=2,
            label="ours (mean ± std)",
        )
        ax.plot(sizes, [paper_curve(n) for n in sizes], "--", color="grey", label="paper (≈ 4 → 5)")
    zigzag_ratio = report["zigzag_time_1"] / (area * base.lambda_star / report["total_ability"])
    ax.axhline(zigzag_ratio, color="tab:red", label=f"zig-zag ({zigzag_ratio:.2f})")
    ax.axhline(1.0, color="black", linewidth=0.8, label="optimum")
    ax.set_xlabel("agents N")
    ax.set_ylabel("$t_N / t^*_N$")
    ax.set_ylim(0, None)
    ax.legend(fontsize=8)
    ax.set_title("Time to completion relative to the optimum (Fig. 9)")
    _save(fig, path)


def _plot_path_length(report: dict[str, Any], teams: list[dict[str, Any]], path: Path) -> None:
    """Fig. 10: the team's path length per team size, beside the zig-zag's and the paper's 55 %."""
    sizes = np.array([row["n"] for row in teams])
    fig, ax = _figure((6, 3.8))
    if len(teams):
        ax.plot(sizes, [row["mean_team_path"] for row in teams], "o-", markersize=3, label="ours (mean team path)")
    ax.axhline(report["zigzag_path_1"], color="tab:red", label="zig-zag")
    ax.axhline(0.55 * report["zigzag_path_1"], color="grey", linestyle="--", label="paper: ≈ 55 % of zig-zag")
    ax.set_xlabel("agents N")
    ax.set_ylabel("team path length")
    ax.set_ylim(0, None)
    ax.legend(fontsize=8)
    ax.set_title("Path length of the team (Fig. 10)")
    _save(fig, path)
