"""Issue 14's comparison table, from a sweep of controllers and team sizes (``anicov controller-table DIR``).

Reads DIR/runs.csv (``anicov sweep sweeps/controllers.toml --out DIR``) and writes a Markdown table: per
team size, every controller's mean t_N/t*_N, its team path as a share of the one-robot zig-zag's (the
``zigzag`` rows at N = 1 in the same table), how many runs completed, and, for the challenger
(default ``anicov``), the issue's goals: below every other controller; t_N/t*_N ≤ 2.5 for N ≤ 10 and
≤ 3.0 beyond; team path ≤ 55 % of the zig-zag's. Where a goal is missed the cell says by how much.
"""

from __future__ import annotations

import csv
from collections import defaultdict
from pathlib import Path

TIME_GOAL_SMALL, TIME_GOAL_LARGE, SMALL_TEAM = 2.5, 3.0, 10
PATH_GOAL = 0.55
ORDER = ("paper", "zigzag", "boustrophedon", "anicov")


def read_runs(out_dir: Path) -> dict[tuple[int, str], list[dict[str, str]]]:
    """The sweep's rows grouped by (team size, controller)."""
    groups: dict[tuple[int, str], list[dict[str, str]]] = defaultdict(list)
    with open(out_dir / "runs.csv", newline="") as file:
        for row in csv.DictReader(file):
            groups[(int(row["agents"]), controller_label(row["controller"]))].append(row)
    return groups


def controller_label(name: str) -> str:
    """A controller's name as the table heads its columns: a plug-in's file by its own name
    (``/abs/path/mine.py:Mine`` → ``mine.py:Mine``), every other name as it is."""
    module, _, attribute = name.rpartition(":")
    return f"{Path(module).name}:{attribute}" if module.endswith(".py") else name


def mean(values: list[float]) -> float:
    """The mean of ``values``; NaN where there are none."""
    return sum(values) / len(values) if values else float("nan")


def least(rows: list[dict[str, str]], key: str) -> float:
    """The least of a figure over the runs that have it (a lone robot has no centre gap): NaN where none does."""
    found = [float(row[key]) for row in rows if row.get(key, "") not in ("", "nan")]
    return min(found) if found else float("nan")


def figure(value: float, digits: int, unit: str = "") -> str:
    """A table's cell for a figure: "—" where there is none (NaN)."""
    return "—" if value != value else f"{value:,.{digits}f}{unit}"


def controller_table(out_dir: Path, challenger: str = "anicov") -> str:
    """The Markdown table (see the module)."""
    groups = read_runs(out_dir)
    controllers = [c for c in ORDER if any(key[1] == c for key in groups)]
    controllers += sorted({key[1] for key in groups} - set(controllers))
    one_robot = [float(row["team_path_length"]) for row in groups.get((1, "zigzag"), [])]
    if not one_robot:
        raise ValueError(f"{out_dir}/runs.csv: no zigzag run at N = 1, the path's yardstick")
    yardstick = mean(one_robot)
    header = ["N", *(f"{c} t/t*" for c in controllers), *(f"{c} path" for c in controllers), "complete"]
    if challenger in controllers:
        header += [f"{challenger} vs best other", "time goal", "path goal"]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for agents in sorted({key[0] for key in groups}):
        ratio, path, done, total = {}, {}, 0, 0
        for controller in controllers:
            rows = groups.get((agents, controller), [])
            finished = [row for row in rows if row["completed"] == "True"]
            ratio[controller] = mean([float(row["time_ratio"]) for row in finished])
            path[controller] = mean([float(row["team_path_length"]) for row in rows]) / yardstick
            done, total = done + len(finished), total + len(rows)
        cells = [
            str(agents),
            *(f"{ratio[c]:.2f}" for c in controllers),
            *(f"{100 * path[c]:.0f} %" for c in controllers),
        ]
        cells.append(f"{done}/{total}")
        if challenger in controllers:
            others = [ratio[c] for c in controllers if c != challenger]
            best_other = min(others) if others else float("nan")
            cells.append(f"{100 * (ratio[challenger] / best_other - 1):+.1f} %")
            goal = TIME_GOAL_SMALL if agents <= SMALL_TEAM else TIME_GOAL_LARGE
            over = ratio[challenger] - goal
            cells.append("met" if over <= 0 else f"over by {over:.2f}")
            over_path = path[challenger] - PATH_GOAL
            cells.append("met" if over_path <= 0 else f"over by {100 * over_path:.1f} points")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
