"""`anicov run` as a user runs it: a real subprocess, real files."""

import json
import subprocess
import sys

from tests.conftest import ROOT
from tests.teamrun import limit


def anicov(*args, cwd=ROOT):
    return subprocess.run(
        [sys.executable, "-m", "anicov.cli", *args], cwd=cwd, capture_output=True, text=True, timeout=limit(300)
    )


def test_run_writes_outputs_byte_identically(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    for out in (first, second):
        done = anicov("run", "--n", "2", "--seed", "4", "--out", str(out), "--quiet")
        assert done.returncode == 0, done.stderr
    assert "coverage        complete" in done.stdout
    for name in ("trajectory.csv", "summary.json"):
        assert (first / name).read_bytes() == (second / name).read_bytes()
    for name in ("error.png", "velocities.png", "coverage_maps.png"):
        assert (first / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = (first / "trajectory.csv").read_text().splitlines()
    assert lines[0] == "t,agent,x,y,theta,v,omega"
    summary = json.loads((first / "summary.json").read_text())
    assert summary["completed"] is True
    assert summary["scenario"]["agents"] == 2 and summary["scenario"]["seed"] == 4
    assert len(lines) == 1 + 2 * (summary["steps"] + 1)
    assert lines[-1].endswith(",0.0,0.0")
    assert summary["time_ratio"] == summary["completion_time"] / summary["optimum_time"]
    assert abs(summary["team_path_length"] - sum(summary["path_length"])) < 1e-9
    assert set(summary) >= {
        "scenario",
        "completed",
        "completion_time",
        "steps",
        "path_length",
        "team_path_length",
        "final_error",
        "optimum_time",
        "time_ratio",
    }


def test_bad_config_fails_with_key_named(tmp_path):
    config = tmp_path / "bad.toml"
    config.write_text('controller = "fast"\n')
    done = anicov("run", "--config", str(config), "--out", str(tmp_path / "o"))
    assert done.returncode == 2
    assert "'controller': expected one of paper, paper-literal, paper-eq16, zigzag" in done.stderr
    assert "Traceback" not in done.stderr


def test_bad_team_range_is_a_clear_error(tmp_path):
    done = anicov("reproduce", "--out", str(tmp_path), "--teams", "a-b")
    assert done.returncode == 2
    assert "--teams: expected sizes like 1-30" in done.stderr


def test_a_safety_study_of_nothing_is_a_clear_error(tmp_path):
    done = anicov("safety-study", "--out", str(tmp_path), "--teams", "none", "--maps", "none")
    assert done.returncode == 2
    assert "--teams none with --maps none: nothing to run" in done.stderr
    assert not (tmp_path / "safety.md").exists()


def test_reproduce_small_writes_json_table_and_figures(tmp_path):
    done = anicov("reproduce", "--out", str(tmp_path), "--runs", "2", "--teams", "3,4", "--workers", "2")
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "reproduction.json").read_text())
    assert {"d100", "d50", "total_ability", "zigzag_time_1", "zigzag_path_1", "teams"} <= set(report)
    assert [row["n"] for row in report["teams"]] == [3, 4]
    assert all(row["runs"] == 2 and row["completed"] == 2 for row in report["teams"])
    assert "| d100 (Fig. 7) | 2.72 |" in (tmp_path / "reproduction.md").read_text()
    for name in ("fig7_straight_pass.png", "fig8_zigzag.png", "fig9_time_ratio.png", "fig10_path_length.png"):
        assert (tmp_path / name).stat().st_size > 1000


def test_launch_passes_every_flag_to_launch_team_help_included():
    done = anicov("launch", "--help")
    assert done.returncode == 0, done.stderr
    assert "usage: launch_team.py" in done.stdout and "--controller NAME" in done.stdout


def test_a_plug_in_that_returns_nan_ends_the_run_with_its_name_and_exit_3(tmp_path):
    (tmp_path / "nan_plugin.py").write_text(
        "from model.controllers import Controller\n\n\n"
        "class NaNAtOnce(Controller):\n"
        "    name = 'nan-at-once'\n\n"
        "    def command(self, view):\n"
        "        return float('nan'), 0.0\n"
    )
    done = anicov("run", "--controller", "nan_plugin.py:NaNAtOnce", "--out", str(tmp_path / "o"), cwd=tmp_path)
    assert done.returncode == 3
    assert "nan_plugin.py:NaNAtOnce', robot 0, step 0: command() returned (v, omega) = (nan, 0.0)" in done.stderr
    assert "Traceback" not in done.stderr
