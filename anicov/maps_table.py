"""Issue 36's study table: a challenger against the paper's law on maps, robots with bodies and the safety filter
(``anicov maps-table DIR [DIR ...]``, one sweep of ``sweeps/anicov-maps/`` per DIR).

Per map (the DIR's name) and team size: each controller's mean time over its completed runs, how much less the
challenger takes, the runs complete, the mean team paths, and the least centre gap and wall clearance over the
challenger's runs. The issue's goals are checked over every run of both controllers:

- every run complete;
- no collision: no two robots' centres ever nearer than 2r (the bodies would overlap);
- no wall contact: no robot's centre ever nearer a wall than r;
- the challenger's mean time at least :data:`LESS_GOAL` under the paper's law's.

r is the sweep's base scenario's ``robot_radius`` (DIR/sweep.json). A goal missed names what missed it.
"""

from __future__ import annotations

import json
from pathlib import Path

from anicov.controller_table import figure, least, mean, read_runs

LESS_GOAL = 0.30
BASELINE = "paper"
HEADER = (
    "| map | N | {c}, mean | the paper's law, mean | {c} less by | complete ({c} / paper) | team path ({c} / paper) "
    "| least centre gap / clearance ({c}) | goals |"
)


def _misses(rows: dict[str, list[dict[str, str]]], less: float, radius: float) -> list[str]:
    """What of the goals the runs of both controllers at one team size miss (see the module)."""
    misses = []
    for controller, runs in rows.items():
        short = sum(row["completed"] != "True" for row in runs)
        if short:
            misses.append(f"{controller}: {short} incomplete")
        gap, clearance = least(runs, "min_separation"), least(runs, "min_clearance")
        if gap < 2.0 * radius:
            misses.append(f"{controller}: a collision (centre gap {gap:.3f} < 2r)")
        if clearance < radius:
            misses.append(f"{controller}: a wall contact (clearance {clearance:.3f} < r)")
    if not less >= LESS_GOAL:
        misses.append(f"{100 * less:.1f} % less, not {100 * LESS_GOAL:.0f} %")
    return misses


def map_rows(out_dir: Path, challenger: str = "anicov") -> list[str]:
    """The table's rows of one map's sweep (see the module)."""
    groups = read_runs(out_dir)
    radius = float(json.loads((out_dir / "sweep.json").read_text(encoding="utf-8"))["base"].get("robot_radius", 0.0))
    lines = []
    for agents in sorted({agents for agents, _ in groups}):
        rows = {controller: groups.get((agents, controller), []) for controller in (challenger, BASELINE)}
        if not all(rows.values()):
            continue  # a team size one controller has no run of is no comparison
        times = {
            c: mean([float(r["completion_time"]) for r in runs if r["completed"] == "True"]) for c, runs in rows.items()
        }
        paths = {c: mean([float(r["team_path_length"]) for r in runs]) for c, runs in rows.items()}
        done = {c: sum(r["completed"] == "True" for r in runs) for c, runs in rows.items()}
        less = 1.0 - times[challenger] / times[BASELINE]
        mine = rows[challenger]
        misses = _misses(rows, less, radius)
        cells = [
            out_dir.name,
            str(agents),
            figure(times[challenger], 1),
            figure(times[BASELINE], 1),
            f"{100 * less:.1f} %",
            f"{done[challenger]} / {len(mine)}, {done[BASELINE]} / {len(rows[BASELINE])}",
            f"{figure(paths[challenger], 0)} / {figure(paths[BASELINE], 0)}",
            f"{figure(least(mine, 'min_separation'), 3)} / {figure(least(mine, 'min_clearance'), 3)}",
            "met" if not misses else "missed: " + "; ".join(misses),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def maps_table(out_dirs: list[Path], challenger: str = "anicov") -> str:
    """The Markdown table of every map's sweep (see the module)."""
    header = HEADER.format(c=challenger)
    lines = [header, "|" + "---|" * header.count(" | ") + "---|"]
    for out_dir in out_dirs:
        lines += map_rows(out_dir, challenger)
    return "\n".join(lines) + "\n"
