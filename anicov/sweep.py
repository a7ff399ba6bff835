"""``anicov sweep``: a grid of runs over scenario keys, controllers, team sizes and seeds, from a TOML file,
into one tidy table (issue 14).

A sweep file::

    scenario = "../scenarios/paper.toml"   # the base scenario, relative to this file (default: the paper's)
    seeds = 10                              # seeds 0..9, or a list [3, 7]
    [grid]                                  # every combination of these scenario keys
    agents = [1, 2, 4]
    controller = ["paper", "zigzag"]
    [fixed]                                 # the same override for every run
    max_time = 5000.0

writes ``OUT/runs.csv``: one row per run, with every grid key, the seed and every figure of the run's
summary (completed, completion_time, optimum_time, time_ratio, steps, team_path_length, final_error,
the safety figures when robots have a body, the watchdog's interventions and cells given up, the radio's with a limited
comm_range or local planning, and with ``physics = "mujoco"`` the contacts and the true coverage). Each row is written and flushed as its run ends, so a
sweep killed at any point loses at most the runs under way; started again on the same OUT it reads the
table (a last line cut by the kill is dropped), runs only what is missing and says how many it found.
Locally it uses every core; ``--cluster ADDRESS`` sends the runs to the workers of a running Dask
distributed scheduler instead (the table is written here). ``anicov sweep-plot`` draws any figure
against any key.
"""

from __future__ import annotations

import csv
import itertools
import math
import os
import tomllib
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from model.controllers.registry import is_file_path
from model.scenario import PAPER_SCENARIO, Scenario, ScenarioError, load_scenario

FIGURES = (
    "completed",
    "completion_time",
    "optimum_time",
    "time_ratio",
    "steps",
    "team_path_length",
    "final_error",
    "min_separation",
    "min_clearance",
    "filter_active_fraction",
    "deadlocks",
    "watchdog_interventions",
    "cells_given_up",
    "divergence_mean",
    "divergence_max",
    "teammates_heard_mean",
)
"""The summary's figures a row carries (those a run does not have are left empty)."""
PHYSICS_FIGURES = ("physical_contacts", "true_coverage", "true_cells_short")
"""And those of a sweep with ``physics = "mujoco"`` in its base or grid (issue 37): a kinematic sweep's columns,
and so its resumed tables, stay as they were."""
SWEEP_KEYS = ("scenario", "seeds", "grid", "fixed")


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep file: the base scenario, the grid (key → values, in file order), the seeds."""

    base: Scenario
    grid: dict[str, list[Any]]
    seeds: list[int]

    @property
    def figures(self) -> tuple[str, ...]:
        """The figures its rows carry: :data:`FIGURES`, and :data:`PHYSICS_FIGURES` where a run has physics."""
        physics = self.base.physics == "mujoco" or "mujoco" in self.grid.get("physics", [])
        return FIGURES + PHYSICS_FIGURES if physics else FIGURES

    @property
    def columns(self) -> list[str]:
        return [*self.grid, "seed", *self.figures]

    def points(self) -> Iterator[dict[str, Any]]:
        """Every run's keys: each combination of the grid, for each seed."""
        names = list(self.grid)
        for values in itertools.product(*(self.grid[name] for name in names)):
            for seed in self.seeds:
                yield dict(zip(names, values, strict=True)) | {"seed": seed}

    def scenario_of(self, point: dict[str, Any]) -> Scenario:
        return self.base.with_overrides(**point)


def load_sweep(path: Path) -> Sweep:
    """Read and check a sweep file; every error names the key and what was expected."""
    try:
        spec = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise ScenarioError(f"{path}: cannot read the sweep file ({error.strerror})") from None
    except tomllib.TOMLDecodeError as error:
        raise ScenarioError(f"{path}: not valid TOML ({error})") from None
    unknown = sorted(set(spec) - set(SWEEP_KEYS))
    if unknown:
        raise ScenarioError(f"{path}: unknown key {unknown[0]!r}; expected keys among {', '.join(SWEEP_KEYS)}")
    base_path = PAPER_SCENARIO if "scenario" not in spec else path.parent / str(spec["scenario"])
    base = load_scenario(base_path)
    fixed = spec.get("fixed", {})
    if not isinstance(fixed, dict):
        raise ScenarioError(f"{path}: fixed: expected a table of scenario keys")
    try:
        base = base.with_overrides(**fixed)
    except ScenarioError as error:
        raise ScenarioError(f"{path}: fixed: {error}") from None
    grid = spec.get("grid", {})
    if not isinstance(grid, dict) or not all(isinstance(values, list) and values for values in grid.values()):
        raise ScenarioError(f"{path}: grid: expected a table of scenario keys, each a non-empty list of values")
    if "seed" in grid:
        raise ScenarioError(f"{path}: grid: 'seed' is given by the top-level key seeds")
    for name, values in grid.items():
        for index, value in enumerate(values):
            if name == "controller" and isinstance(value, str) and is_file_path(value):
                value = str(path.parent / value)  # a controller's file, relative to this file as the scenario is
            try:
                # As the scenario holds it (20 and 20.0 are one range), so a resumed sweep finds its rows.
                values[index] = _plain(getattr(base.with_overrides(**{name: value}), name, value))
            except ScenarioError as error:
                raise ScenarioError(f"{path}: grid.{name} = {value!r}: {error}") from None
        if len({_cell(value) for value in values}) != len(values):
            raise ScenarioError(f"{path}: grid.{name}: a value is given twice")
    seeds = spec.get("seeds", 1)
    if isinstance(seeds, int) and not isinstance(seeds, bool) and seeds >= 1:
        seeds = list(range(seeds))
    elif not (isinstance(seeds, list) and seeds and all(isinstance(s, int) and not isinstance(s, bool) for s in seeds)):
        raise ScenarioError(f"{path}: seeds: expected a positive number of seeds or a list of integers")
    return Sweep(base, grid, list(seeds))


def run_point(sweep: Sweep, point: dict[str, Any]) -> dict[str, Any]:
    """One run of the sweep in this process: its row of the table."""
    from anicov.engine import run_scenario
    from runtime.rundir import summary_of

    scenario = sweep.scenario_of(point)
    # The safety figures read the whole trace (robots with a body); the rest need only the path lengths.
    summary = summary_of(run_scenario(scenario, record_trace=scenario.robot_radius > 0.0))
    figures = summary | summary.get("radio", {})
    if scenario.watchdog:  # what the progress watchdog did (model.watchdog; summary.json reports it when it acted)
        report = summary.get("watchdog") or {}
        figures |= {
            "watchdog_interventions": len(report.get("interventions", [])),
            "cells_given_up": report.get("cells_given_up", 0),
        }
    return point | {figure: figures.get(figure) for figure in sweep.figures}


def _key(point: dict[str, Any], names: list[str]) -> tuple[str, ...]:
    """A row's identity in the table, as its cells read back from CSV."""
    return tuple(_cell(point[name]) for name in [*names, "seed"])


def _plain(value: Any) -> Any:
    """A scenario value as plain Python (tuples as lists), for the table and for TOML-like comparison."""
    return [_plain(item) for item in value] if isinstance(value, tuple | list) else value


def _cell(value: Any) -> str:
    """A value as the table writes it (and a resumed sweep compares it): floats by repr, exactly."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float | np.floating):
        return repr(float(value))
    if isinstance(value, int | np.integer):
        return str(int(value))
    return str(value)


def read_done(table: Path, columns: list[str]) -> list[dict[str, str]]:
    """The rows a previous run of this sweep wrote; a last line cut short by a kill is left out (and cut
    from the file, so appending goes on from a whole line)."""
    if not table.exists():
        return []
    text = table.read_text(encoding="utf-8")
    if not text.endswith("\n"):  # cut the partial line in place (a rewrite killed half-way would lose all)
        text = text[: text.rfind("\n") + 1]
        os.truncate(table, len(text.encode("utf-8")))
    lines = text.splitlines()
    if not lines:
        return []
    header = next(csv.reader([lines[0]]))
    if header != columns:
        raise ScenarioError(f"{table}: written by another sweep (its columns differ); give another --out")
    return [dict(zip(header, row, strict=True)) for row in csv.reader(lines[1:]) if len(row) == len(header)]


def run_sweep(
    sweep: Sweep, out_dir: Path, workers: int | None = None, cluster: str | None = None, progress: bool = True
) -> tuple[int, int]:
    """Run what the table lacks; returns (runs found done, runs made now)."""
    from tqdm import tqdm

    out_dir.mkdir(parents=True, exist_ok=True)
    _check_same_base(sweep, out_dir)
    table = out_dir / "runs.csv"
    names = list(sweep.grid)
    done = {tuple(row[name] for name in [*names, "seed"]) for row in read_done(table, sweep.columns)}
    todo = [point for point in sweep.points() if _key(point, names) not in done]
    fresh = not table.exists() or table.stat().st_size == 0
    with open(table, "a", encoding="utf-8", newline="") as sink:
        writer = csv.writer(sink, lineterminator="\n")
        if fresh:
            writer.writerow(sweep.columns)
            sink.flush()
        bar = tqdm(total=len(todo), desc="sweep runs", unit="run", disable=not progress)
        failed: list[str] = []
        for row in _results(sweep, todo, workers, cluster):
            if isinstance(row, str):
                failed.append(row)
            else:
                writer.writerow([_cell(row[column]) for column in sweep.columns])
                sink.flush()
                os.fsync(sink.fileno())
            bar.update()
        bar.close()
    if failed:
        raise ScenarioError(f"{len(failed)} run(s) failed, the others are in {table}; first: {failed[0]}")
    return len(done), len(todo)


def _check_same_base(sweep: Sweep, out_dir: Path) -> None:
    """OUT/sweep.json holds the base scenario (the fixed keys included) whose runs the table holds: a row
    is reused only for the same base, so a sweep resumed with other fixed keys is refused, not mixed. A map file
    is held by its path from OUT (:func:`_portable`), so a study resumes from any checkout that keeps both."""
    import json

    record = out_dir / "sweep.json"
    base = _portable(json.loads(json.dumps(sweep.base.to_dict())), out_dir)
    if record.exists():
        if _portable(json.loads(record.read_text(encoding="utf-8")).get("base", {}), out_dir) != base:
            raise ScenarioError(f"{out_dir}: holds runs of another base scenario or fixed keys; give another --out")
        return
    record.write_text(json.dumps({"base": base}, indent=1) + "\n", encoding="utf-8")


def _portable(base: dict[str, Any], out_dir: Path) -> dict[str, Any]:
    """``base`` with its map file's path relative to ``out_dir`` (an absolute one, as sweep.json held it before
    2026-12-07, is made relative too: the same file from the same checkout compares equal)."""
    if not base.get("map"):
        return base
    where = Path(base["map"])
    if not where.is_absolute():
        return base
    return {**base, "map": os.path.relpath(where.resolve(), out_dir.resolve())}


def _results(
    sweep: Sweep, todo: list[dict[str, Any]], workers: int | None, cluster: str | None
) -> Iterator[dict[str, Any] | str]:
    """Each run's row as it ends, from this machine's cores or a Dask cluster's workers (a run that
    raised: what it was and why, so the others are still written)."""
    if not todo:
        return
    if cluster is not None:
        from distributed import Client
        from distributed import as_completed as cluster_completed

        with Client(cluster, timeout="30s") as client:
            futures = [client.submit(run_point, sweep, point, pure=False) for point in todo]
            for future, point in zip(futures, todo, strict=True):
                future.point = point  # type: ignore[attr-defined]
            for future in cluster_completed(futures):
                yield _outcome(future, future.point)  # type: ignore[attr-defined]
        return
    with ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
        pending = {pool.submit(run_point, sweep, point): point for point in todo}
        for future in as_completed(pending):
            yield _outcome(future, pending[future])


def _outcome(future: Any, point: dict[str, Any]) -> dict[str, Any] | str:
    try:
        return future.result()
    except Exception as error:  # one bad point must not lose the rest of the sweep
        return f"{point}: {type(error).__name__}: {error}"


def grouped(out_dir: Path, x: str, y: str, by: str | None) -> dict[str, dict[float, list[float]]]:
    """Figure ``y`` of every run that has it, by value of ``by`` (one group without it) and of key ``x``."""
    table = out_dir / "runs.csv"
    with open(table, encoding="utf-8") as source:
        rows = list(csv.DictReader(source))
    if not rows:
        raise ScenarioError(f"{table}: no runs yet")
    for name, what in ((x, "--x"), (y, "--y"), (by, "--by")):
        if name is not None and name not in rows[0]:
            raise ScenarioError(f"{what}: expected a column of {table} ({', '.join(rows[0])}), got {name!r}")
    groups: dict[str, dict[float, list[float]]] = {}
    for row in rows:
        if row[y] in ("", "None"):
            continue  # a run without this figure (not completed: no completion time)
        series = groups.setdefault(row[by] if by else y, {})
        series.setdefault(_number(row[x], x), []).append(_number(row[y], y))
    return groups


def mean_table(out_dir: Path, x: str, y: str, by: str | None) -> str:
    """A markdown table of the mean of ``y`` (and how many runs had it) per value of ``x``, a column per ``by``."""
    groups = grouped(out_dir, x, y, by)
    labels = sorted(groups)
    xs = sorted({value for series in groups.values() for value in series})
    lines = [f"| {x} | " + " | ".join(f"{label} (runs)" for label in labels) + " |", "|---" * (len(labels) + 1) + "|"]
    for value in xs:
        cells = [
            f"{sum(groups[label][value]) / len(groups[label][value]):.3f} ({len(groups[label][value])})"
            if value in groups[label]
            else "-"
            for label in labels
        ]
        lines.append(f"| {value:g} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot_sweep(out_dir: Path, x: str, y: str, by: str | None, path: Path) -> Path:
    """Mean of figure ``y`` against key ``x`` (one line per value of ``by``), with its standard deviation."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    groups = grouped(out_dir, x, y, by)
    fig, axes = plt.subplots(figsize=(6.4, 4.2))
    for label, series in sorted(groups.items()):
        xs = sorted(series)
        means = [sum(series[v]) / len(series[v]) for v in xs]
        spreads = [
            math.sqrt(sum((s - m) ** 2 for s in series[v]) / len(series[v])) for v, m in zip(xs, means, strict=True)
        ]
        axes.errorbar(xs, means, yerr=spreads, marker="o", capsize=3, label=f"{by} = {label}" if by else label)
    axes.set_xlabel(x)
    axes.set_ylabel(f"{y} (mean ± sd over seeds)")
    axes.grid(alpha=0.3)
    axes.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _number(text: str, column: str) -> float:
    if text in ("True", "False"):
        return float(text == "True")
    try:
        return float(text)
    except ValueError:
        raise ScenarioError(f"column {column!r} holds {text!r}, not a number: plot it with --by instead") from None
