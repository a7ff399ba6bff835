"""runtime.rundir: what a run leaves on disk, the same from the engine's CLI and from the coordinator."""

from __future__ import annotations

import json

from anicov.engine import run_scenario
from model.scenario import Scenario
from runtime.rundir import format_summary, write_counts, write_run_directory


def test_a_run_directory_holds_the_trajectory_the_summary_the_plots_and_the_counts(tmp_path):
    scenario = Scenario(domain=(30.0, 30.0), agents=2, range=8.0, seed=1)
    result = run_scenario(scenario)
    summary = write_run_directory(result, tmp_path / "run", counts={"accepted": 3})
    files = sorted(path.name for path in (tmp_path / "run").iterdir())
    assert files == [
        "coordinator_counts.json",
        "coverage_maps.png",
        "error.png",
        "summary.json",
        "trajectory.csv",
        "velocities.png",
    ]
    assert json.loads((tmp_path / "run" / "summary.json").read_text()) == summary
    assert summary["completed"] and summary["steps"] == result.steps
    rows = (tmp_path / "run" / "trajectory.csv").read_text().splitlines()
    assert len(rows) == 1 + 2 * (result.steps + 1)
    assert json.loads((tmp_path / "run" / "coordinator_counts.json").read_text()) == {"accepted": 3}
    assert "2 agent(s)" in format_summary(summary, tmp_path)


def test_counts_go_nowhere_without_a_path(tmp_path):
    write_counts(None, {"a": 1})
    write_counts("", {"a": 1})
    assert list(tmp_path.iterdir()) == []
    write_counts(str(tmp_path / "c.json"), {"b": 2, "a": 1})
    assert (tmp_path / "c.json").read_text() == '{\n  "a": 1,\n  "b": 2\n}\n'
