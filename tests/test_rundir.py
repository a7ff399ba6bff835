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


def test_bandwidth_is_per_robot_and_step_and_per_second_at_speed_one():
    from runtime.rundir import bandwidth_of, format_bandwidth

    counts = [
        {"steps": 100, "bytes_sent": 8200, "bytes_received": 30000},
        {"steps": 50, "bytes_sent": 4300, "bytes_received": 10000},
        {"steps": 0, "bytes_sent": 0, "bytes_received": 500},  # a robot that never stepped is left out
    ]
    bandwidth = bandwidth_of(counts, dt=0.1)
    assert bandwidth["agents_counted"] == 2
    assert bandwidth["bytes_out_per_step"] == (82 + 86) / 2 and bandwidth["bytes_in_per_step"] == (300 + 200) / 2
    assert bandwidth["bytes_out_per_second_at_speed_1"] == 840.0 and bandwidth["max_bytes_in_per_step"] == 300
    assert "out 84 B, in 250 B a step (deltas as events); at speed 1: out 6.7 kbit/s, in 20.0 kbit/s" in (
        format_bandwidth(bandwidth, "event")
    )
    assert bandwidth_of(counts[2:], dt=0.1) is None
    assert "bytes_out_per_wall_second" not in bandwidth  # counts written before the wall clock was counted


def test_bandwidth_counts_replies_to_teammates_and_the_wall_clock_rate():
    from runtime.rundir import bandwidth_of, format_bandwidth

    counts = [
        {"steps": 100, "bytes_sent": 8000, "bytes_served": 2000, "bytes_received": 30000, "wall_seconds": 10.0},
        {"steps": 100, "bytes_sent": 8000, "bytes_served": 0, "bytes_received": 10000, "wall_seconds": 5.0},
    ]
    bandwidth = bandwidth_of(counts, dt=0.1)
    assert bandwidth["bytes_out_per_step"] == (100 + 80) / 2
    assert bandwidth["bytes_out_per_wall_second"] == (1000 + 1600) / 2
    assert bandwidth["bytes_in_per_wall_second"] == (3000 + 2000) / 2
    assert "bus this run    out 1300 B/s, in 2500 B/s per robot" in format_bandwidth(bandwidth, "event")
