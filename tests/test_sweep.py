"""anicov sweep: a grid of runs into one table that resumes where it stopped, locally or on a Dask cluster."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import sys

import pytest

import anicov.sweep
from anicov.sweep import load_sweep, run_sweep
from model.scenario import ScenarioError
from tests.teamrun import ROOT, limit, wait_for

SMALL = """
seeds = {seeds}
[grid]
agents = [1, 2]
controller = ["paper", "zigzag"]
[fixed]
domain = [24.0, 24.0]
range = 8.0
"""


def write_sweep(tmp_path, seeds: int = 2, text: str = SMALL):
    path = tmp_path / "sweep.toml"
    path.write_text(text.format(seeds=seeds))
    return path


def rows_of(out) -> list[dict[str, str]]:
    with open(out / "runs.csv") as source:
        return list(csv.DictReader(source))


def test_every_point_of_the_grid_is_one_row_with_the_runs_figures(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))
    assert run_sweep(sweep, tmp_path / "out", workers=1, progress=False) == (0, 8)
    rows = rows_of(tmp_path / "out")
    assert sorted((r["agents"], r["controller"], r["seed"]) for r in rows) == sorted(
        (a, c, s) for a in "12" for c in ("paper", "zigzag") for s in "01"
    )
    assert all(r["completed"] == "True" and float(r["time_ratio"]) > 1.0 for r in rows)
    # The same point gives the same row: the runs are seeded.
    again = run_sweep(sweep, tmp_path / "again", workers=2, progress=False)
    assert again == (0, 8)
    assert sorted(map(str, rows)) == sorted(map(str, rows_of(tmp_path / "again")))


def test_a_stopped_sweep_runs_only_what_it_lacks_and_drops_a_cut_line(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path))
    out = tmp_path / "out"
    run_sweep(sweep, out, workers=1, progress=False)
    lines = (out / "runs.csv").read_text().splitlines(keepends=True)
    (out / "runs.csv").write_text("".join(lines[:4]) + lines[4][:11])  # three rows whole, a fourth cut by a kill
    assert run_sweep(sweep, out, workers=1, progress=False) == (3, 5)
    assert len(rows_of(out)) == 8 and len({tuple(r.values()) for r in rows_of(out)}) == 8


def test_a_study_run_in_stages_takes_the_first_seeds_then_resumes_with_the_rest(tmp_path, capsys):
    from anicov.cli import main

    path, out = write_sweep(tmp_path, seeds=3, text=SMALL.replace("agents = [1, 2]", "agents = [1]")), tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--quiet", "--seeds", "1"]) == 0
    assert sorted((r["controller"], r["seed"]) for r in rows_of(out)) == [("paper", "0"), ("zigzag", "0")]
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert "sweep: 6 runs; 2 found done" in capsys.readouterr().out
    assert sorted(r["seed"] for r in rows_of(out)) == ["0", "0", "1", "1", "2", "2"]
    assert main(["sweep", str(path), "--out", str(out), "--seeds", "0"]) != 0
    assert "--seeds: expected a positive number, got 0" in capsys.readouterr().err


def flaky_run(sweep, point):
    """run_point, but the zig-zag pair of two fails (module level: the pool's workers import it)."""
    if point["agents"] == 2 and point["controller"] == "zigzag":
        raise RuntimeError("a broken run")
    return REAL_RUN_POINT(sweep, point)


REAL_RUN_POINT = anicov.sweep.run_point


def test_one_failing_run_loses_none_of_the_others(tmp_path, monkeypatch):
    monkeypatch.setattr(anicov.sweep, "run_point", flaky_run)
    with pytest.raises(ScenarioError, match=r"2 run\(s\) failed.*a broken run"):
        run_sweep(load_sweep(write_sweep(tmp_path)), tmp_path / "out", workers=None, cluster=None, progress=False)
    assert len(rows_of(tmp_path / "out")) == 6


def test_grid_values_are_read_as_the_scenario_holds_them(tmp_path):
    sweep = load_sweep(
        write_sweep(tmp_path, text="seeds = 1\n[grid]\nrange = [8, 9.5]\n[fixed]\ndomain = [24.0, 24.0]\n")
    )
    assert sweep.grid["range"] == [8.0, 9.5]
    with pytest.raises(ScenarioError, match="given twice"):
        load_sweep(write_sweep(tmp_path, text="[grid]\nrange = [8, 8.0]\n"))


def test_a_sweep_resumed_with_other_fixed_keys_is_refused(tmp_path):
    run_sweep(load_sweep(write_sweep(tmp_path, seeds=1)), tmp_path / "out", workers=1, progress=False)
    changed = write_sweep(tmp_path, seeds=1, text=SMALL.replace("range = 8.0", "range = 9.0"))
    with pytest.raises(ScenarioError, match="another base scenario"):
        run_sweep(load_sweep(changed), tmp_path / "out", workers=1, progress=False)


def test_a_killed_sweep_process_loses_nothing_and_resumes(tmp_path):
    """SIGKILL to the sweep and its workers mid-way; started again it makes only the rest."""
    path = write_sweep(tmp_path, seeds=8)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "anicov.cli", "sweep", str(path), "--out", str(out), "--workers", "2", "--quiet"]
    process = subprocess.Popen(command, cwd=ROOT, start_new_session=True, stdout=subprocess.PIPE, text=True)
    try:
        assert wait_for(lambda: (out / "runs.csv").exists() and len(rows_of(out)) >= 4, timeout=240)
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
    kept = len(rows_of(out))
    assert 4 <= kept < 32
    again = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=limit(600))
    assert again.returncode == 0, again.stderr
    assert f"32 runs; {kept} found done" in again.stdout
    rows = rows_of(out)
    assert len(rows) == 32 and len({(r["agents"], r["controller"], r["seed"]) for r in rows}) == 32


def test_the_same_sweep_on_a_dask_cluster_started_here(tmp_path):
    from distributed import LocalCluster

    path = write_sweep(tmp_path, seeds=1)
    local = tmp_path / "local"
    run_sweep(load_sweep(path), local, workers=1, progress=False)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        done = subprocess.run(
            [sys.executable, "-m", "anicov.cli", "sweep", str(path), "--out", str(tmp_path / "cluster"), "--quiet",
             "--cluster", cluster.scheduler_address],
            cwd=ROOT, capture_output=True, text=True, timeout=limit(600),
        )  # fmt: skip
        assert done.returncode == 0, done.stderr
    assert f"on the cluster at {cluster.scheduler_address}" in done.stdout
    assert sorted(map(str, rows_of(tmp_path / "cluster"))) == sorted(map(str, rows_of(local)))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("seeds = 2\ncolour = 1\n", "unknown key 'colour'"),
        ("[grid]\nagents = [1, -3]\n", "grid.agents = -3"),
        ("[grid]\nwingspan = [1]\n", "grid.wingspan"),
        ("[grid]\nagents = []\n", "non-empty list"),
        ("seeds = 0\n", "seeds: expected"),
        ("[fixed]\nrange = -1.0\n", "fixed: "),
        ("[grid]\nseed = [1, 2]\n", "'seed' is given by the top-level key seeds"),
        ("scenario = 'nowhere.toml'\n", "nowhere.toml"),
    ],
)
def test_a_bad_sweep_file_is_a_clear_error(tmp_path, text, message):
    with pytest.raises(ScenarioError, match=message.replace("(", r"\(").replace(".", r"\.")):
        load_sweep(write_sweep(tmp_path, text=text))


def test_a_plot_of_any_figure_against_any_key(tmp_path):
    from anicov.sweep import mean_table, plot_sweep

    run_sweep(load_sweep(write_sweep(tmp_path)), tmp_path / "out", workers=1, progress=False)
    rows = rows_of(tmp_path / "out")
    table = mean_table(tmp_path / "out", "agents", "steps", "controller").splitlines()
    assert table[0] == "| agents | paper (runs) | zigzag (runs) |"
    paper_one = [int(r["steps"]) for r in rows if r["controller"] == "paper" and r["agents"] == "1"]
    assert table[2].startswith(f"| 1 | {sum(paper_one) / 2:.3f} (2) |")
    png = plot_sweep(tmp_path / "out", "agents", "team_path_length", "controller", tmp_path / "p.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ScenarioError, match="--y: expected a column"):
        plot_sweep(tmp_path / "out", "agents", "speed", None, tmp_path / "q.png")


def test_a_plug_in_controller_runs_in_a_sweep_its_file_relative_to_the_sweep_file(tmp_path):
    """The worked example (examples/) beside the built-in controllers, named relative to the sweep file as the
    base scenario is; its rows name it by its absolute path, and the controller table by its file."""
    from anicov.controller_table import controller_table

    example = os.path.relpath(ROOT / "examples" / "nearest_uncovered.py", tmp_path)
    text = SMALL.replace('["paper", "zigzag"]', f'["paper", "zigzag", "{example}:NearestUncovered"]')
    sweep = load_sweep(write_sweep(tmp_path, seeds=1, text=text))
    assert run_sweep(sweep, tmp_path / "out", workers=1, progress=False) == (0, 6)
    rows = rows_of(tmp_path / "out")
    mine = [row for row in rows if row["controller"].endswith("nearest_uncovered.py:NearestUncovered")]
    assert len(mine) == 2 and all(row["completed"] == "True" for row in mine)
    assert mine[0]["controller"] == f"{ROOT / 'examples' / 'nearest_uncovered.py'}:NearestUncovered"
    table = controller_table(tmp_path / "out", challenger="nearest_uncovered.py:NearestUncovered")
    assert "| N | paper t/t* | zigzag t/t* | nearest_uncovered.py:NearestUncovered t/t* |" in table
    assert "nearest_uncovered.py:NearestUncovered vs best other" in table


PHYSICS = """
seeds = 1
[grid]
physics = ["kinematic", "mujoco"]
[fixed]
domain = [12.0, 12.0]
range = 4.0
robot_radius = 0.4
agents = 2
"""


def test_a_sweep_with_physics_carries_the_contacts_and_the_truth_and_a_kinematic_one_does_not(tmp_path):
    sweep = load_sweep(write_sweep(tmp_path, text=PHYSICS))
    assert run_sweep(sweep, tmp_path / "out", workers=1, progress=False) == (0, 2)
    rows = {row["physics"]: row for row in rows_of(tmp_path / "out")}
    assert rows["mujoco"]["completed"] == "True"
    assert rows["mujoco"]["physical_contacts"] == "0"
    assert float(rows["mujoco"]["true_coverage"]) == 1.0 and rows["mujoco"]["true_cells_short"] == "0"
    assert rows["kinematic"]["physical_contacts"] == rows["kinematic"]["true_coverage"] == ""
    kinematic = load_sweep(write_sweep(tmp_path, text=SMALL))
    assert "true_coverage" not in kinematic.columns  # its tables, and resumed ones, keep their columns


def test_a_study_on_a_map_resumes_from_another_checkout_its_map_held_by_its_path_from_the_table(tmp_path):
    """sweep.json held the map's absolute path, so a study's tables (docs/physics/study/) resumed only from a checkout
    at the same place. It holds the path from OUT now; a record in the old form still resumes from its own checkout."""
    import json
    import shutil

    first = tmp_path / "first"
    (first / "maps").mkdir(parents=True)
    for name in ("field.yaml", "field.pgm"):
        shutil.copy(ROOT / "scenarios" / "maps" / name, first / "maps" / name)
    (first / "scenario.toml").write_text('map = "maps/field.yaml"\nrange = 8.0\nmax_time = 2.0\n')
    (first / "sweep.toml").write_text('scenario = "scenario.toml"\nseeds = 1\n[grid]\nagents = [1, 2]\n')
    assert run_sweep(load_sweep(first / "sweep.toml"), first / "out", workers=1, progress=False) == (0, 2)
    record = json.loads((first / "out" / "sweep.json").read_text())
    assert record["base"]["map"] == os.path.join("..", "maps", "field.yaml")

    moved = tmp_path / "elsewhere" / "checkout"
    shutil.copytree(first, moved)
    assert run_sweep(load_sweep(moved / "sweep.toml"), moved / "out", workers=1, progress=False) == (2, 0)

    record["base"]["map"] = str((moved / "maps" / "field.yaml").resolve())  # as sweep.json held it before
    (moved / "out" / "sweep.json").write_text(json.dumps(record))
    assert run_sweep(load_sweep(moved / "sweep.toml"), moved / "out", workers=1, progress=False) == (2, 0)
    record["base"]["map"] = str((first / "maps" / "field.yaml").resolve())  # another checkout's file: refused
    (moved / "out" / "sweep.json").write_text(json.dumps(record))
    with pytest.raises(ScenarioError, match="another base scenario"):
        run_sweep(load_sweep(moved / "sweep.toml"), moved / "out", workers=1, progress=False)
