"""Issue 37's study table: each controller kinematic, in the physics world without noise and with the issue's
noise, per map and team size (``anicov physics-table DIR [DIR ...]``, the sweeps of ``sweeps/physics/``).

A map has two sweeps: ``<map>`` (``[grid] physics = ["kinematic", "mujoco"]``, no noise) and ``<map>-noise``
(physics with ``[noise]``); a DIR's name without ``-noise`` is the map's. A row's mode is read from the row's
``physics`` (or the sweep's base, DIR/sweep.json, where the grid does not hold it) and the base's noise.

Per map, team size and controller: the mean time of each mode over its completed runs, how much longer the
noisy runs take than the kinematic ones, the runs complete, the physics runs' contacts and their least true
coverage. The issue's goals are checked over every run:

- every run complete;
- ``physical_contacts`` = 0 in every physics run (the safety filter on);
- ``true_coverage`` at least :data:`TRUE_COVERAGE_GOAL` at declared completion in every physics run;
- each physics mode's mean time (without and with noise) within :data:`TIME_GOAL` of the kinematic runs'.

A goal missed names what missed it; a mode a map has no run of is "—" and checks nothing.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from pathlib import Path
from typing import Any

from anicov.controller_table import figure, least, mean, read_runs
from model.scenario.physics_keys import RULES

TRUE_COVERAGE_GOAL = 0.995
TIME_GOAL = 0.15
MODES = ("kinematic", "physics", "noise")
NOISE_SUFFIX = "-noise"
HEADER = (
    "| map | N | controller | kinematic | physics (more by) | physics and noise (more by) | complete (k / p / n) "
    "| contacts (p / n) | least true coverage (p / n) | goals |"
)

Runs = dict[str, list[dict[str, str]]]
"""A map's runs at one team size and controller, by mode."""


def map_name(out_dir: Path) -> str:
    """The map a sweep's DIR holds runs of: its name without :data:`NOISE_SUFFIX`."""
    name = out_dir.name
    return name[: -len(NOISE_SUFFIX)] if name.endswith(NOISE_SUFFIX) else name


def _mode(row: dict[str, str], base: dict[str, Any]) -> str:
    """A row's mode: its physics, and with physics whether the base has any noise (its rules, such as
    ``cover_margin`` alone, are not noise: :func:`model.scenario.physics_keys.cover_margin_of` reads it so)."""
    physics = row.get("physics") or str(base.get("physics", "kinematic"))
    if physics == "kinematic":
        return "kinematic"
    noise = dict(base.get("noise") or {})
    return "noise" if any(value > 0.0 for key, value in noise.items() if key not in RULES) else "physics"


def collect(out_dirs: list[Path], seeds: int | None = None) -> dict[str, dict[tuple[int, str], Runs]]:
    """Every sweep's rows: map → (team size, controller) → mode → runs, maps in the order first given; with
    ``seeds``, only seeds below it (a study whose modes ran to different seeds, compared on the same runs)."""
    maps: dict[str, dict[tuple[int, str], Runs]] = {}
    for out_dir in out_dirs:
        base = json.loads((out_dir / "sweep.json").read_text(encoding="utf-8"))["base"]
        groups = maps.setdefault(map_name(out_dir), defaultdict(lambda: defaultdict(list)))
        for key, rows in read_runs(out_dir).items():
            for row in rows:
                if seeds is None or int(row["seed"]) < seeds:
                    groups[key][_mode(row, base)].append(row)
    return maps


def _mean_time(runs: list[dict[str, str]]) -> float:
    return mean([float(row["completion_time"]) for row in runs if row["completed"] == "True"])


def _contacts(runs: list[dict[str, str]]) -> int:
    return sum(int(float(row["physical_contacts"])) for row in runs if row.get("physical_contacts", ""))


def misses(runs: Runs) -> list[str]:
    """What of the issue's goals one map's runs at one team size and controller miss (see the module)."""
    found = []
    for mode in MODES:
        short = sum(row["completed"] != "True" for row in runs.get(mode, []))
        if short:
            found.append(f"{mode}: {short} of {len(runs[mode])} incomplete")
    kinematic = _mean_time(runs.get("kinematic", []))
    for mode in ("physics", "noise"):
        rows = runs.get(mode, [])
        if not rows:
            continue
        if contacts := _contacts(rows):
            found.append(f"{mode}: {contacts} contacts")
        if unjudged := sum(row.get("true_coverage", "") in ("", "nan") for row in rows):
            found.append(f"{mode}: {unjudged} runs without a true coverage")
        lowest = least(rows, "true_coverage")
        if lowest < TRUE_COVERAGE_GOAL:
            found.append(f"{mode}: true coverage {100 * lowest:.2f} % < {100 * TRUE_COVERAGE_GOAL:.1f} %")
        if math.isnan(kinematic):
            found.append(f"{mode}: no complete kinematic run to time it against")
            continue
        more = _mean_time(rows) / kinematic - 1.0
        if more > TIME_GOAL:
            found.append(f"{mode}: {100 * more:+.1f} % over kinematic, not within {100 * TIME_GOAL:.0f} %")
    return found


def _pair(runs: Runs, mode: str, kinematic: float) -> str:
    mean = _mean_time(runs.get(mode, []))
    if math.isnan(mean):
        return "—"
    return f"{mean:,.1f}" if math.isnan(kinematic) else f"{mean:,.1f} ({100 * (mean / kinematic - 1.0):+.1f} %)"


def row_cells(name: str, agents: int, controller: str, runs: Runs) -> list[str]:
    """One line of the table (see the module)."""
    kinematic = _mean_time(runs.get("kinematic", []))
    done = " / ".join(
        f"{sum(row['completed'] == 'True' for row in runs[mode])}/{len(runs[mode])}" if runs.get(mode) else "—"
        for mode in MODES
    )
    contacts = " / ".join(str(_contacts(runs[mode])) if runs.get(mode) else "—" for mode in ("physics", "noise"))
    coverage = " / ".join(
        figure(100 * least(runs.get(mode, []), "true_coverage"), 2, " %") for mode in ("physics", "noise")
    )
    missed = misses(runs)
    return [
        name,
        str(agents),
        controller,
        figure(kinematic, 1),
        _pair(runs, "physics", kinematic),
        _pair(runs, "noise", kinematic),
        done,
        contacts,
        coverage,
        "met" if not missed else "missed: " + "; ".join(missed),
    ]


def physics_table(out_dirs: list[Path], seeds: int | None = None) -> str:
    """The Markdown table of the sweeps in ``out_dirs`` (see the module), of their seeds below ``seeds`` if given."""
    lines = [HEADER, "|" + "---|" * HEADER.count(" | ") + "---|"]
    for name, groups in collect(out_dirs, seeds).items():
        for agents, controller in sorted(groups):
            cells = row_cells(name, agents, controller, groups[(agents, controller)])
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
