"""model.watchdog: a stall is noticed, explained, acted on, and reported, alike in the engine and over Zenoh."""

from __future__ import annotations

import json

import numpy as np

from anicov.engine import run_scenario
from model.scenario import validate
from model.watchdog import ProgressWatchdog, cells_near
from runtime.lifecycle import EXIT_INCOMPLETE
from runtime.rundir import format_summary, summary_of, write_run_directory
from tests.teamrun import anicov, launcher_command, processes_of, run, unique_team, write_scenario
from tests.test_team import assert_same_run


def no_reason(agent, position, objective, moved):
    return "test"


def test_cells_near_are_the_uncovered_cells_within_the_radius():
    uncovered = np.ones((10, 10), dtype=bool)
    uncovered[5, 5] = False
    near = cells_near(np.array([[5.5, 5.5]]), uncovered, 1.0, 1.0)
    assert near.sum() == 4 and not near[5, 5]  # the four neighbours at distance 1; the centre is covered


def test_the_watchdog_waits_its_patience_then_sets_aside_then_gives_up():
    watchdog = ProgressWatchdog(patience=10.0, sensing_range=1.0, cell=1.0)
    lack = np.zeros((5, 5))
    lack[2, 2] = 0.5
    lack[0, 4] = 1.0  # far from the objective: never near it, never set aside
    positions, members = np.array([[0.5, 0.5]]), [0]
    assert watchdog.observe(0.0, lack, positions, members, no_reason) is None  # the first sum is progress
    watchdog.remember(np.array([[2.5, 2.5]]), members)
    assert watchdog.observe(5.0, lack, positions, members, no_reason) is None  # within patience
    first = watchdog.observe(10.0, lack, positions, members, no_reason)
    assert first is not None and first.action == "set aside" and first.cells == ((2, 2),)
    assert watchdog.masked(lack)[2, 2] == 0.0  # planned as if covered: the robots go elsewhere
    lack[0, 4] = 0.5  # Σ Υ falls, but no cell is covered: not progress (a cell on the rim of R crept so)
    assert watchdog.observe(12.0, lack, positions, members, no_reason) is None and watchdog.since == 10.0
    lack[0, 4] = 0.0  # a cell covered: progress; now only the set-aside cell is left, so it is back at once
    assert watchdog.observe(15.0, lack, positions, members, no_reason) is None and watchdog.since == 15.0
    assert watchdog.masked(lack)[2, 2] == 0.5
    second = watchdog.observe(25.0, lack, positions, members, no_reason)
    assert second is not None and second.action == "given up" and watchdog.only_given_up_left(lack)


def stalling_values(**extra):
    """A robot held at a fixed objective in a corner of an open square: it covers what it sees from there
    and nothing more, so e_D stops falling (a stall built on purpose)."""
    return {
        "domain": [20.0, 20.0], "agents": 1, "range": 3.0, "initial_poses": [[2.0, 2.0, 0.0]],
        "objectives": [[2.5, 2.5]], "watchdog_time": 40.0, "max_time": 2000.0, **extra,
    }  # fmt: skip


def test_a_stalled_run_is_reported_and_ends_when_only_given_up_cells_are_left(tmp_path):
    result = run_scenario(validate(stalling_values()))
    assert not result.completed and result.steps * result.scenario.dt < 2000.0  # it ended, not at max_time
    actions = [stall.action for stall in result.stalls]
    assert actions[0] == "set aside" and actions[-1] == "given up"
    # The paper's law parks R/2 short of its objective, facing it: the cells it is not facing stay uncovered.
    assert result.stalls[0].robots[0].reason.startswith("stood still, 1.50 from its objective, sees ")
    summary = summary_of(result)
    report = summary["watchdog"]
    assert report["why"] == "every cell left was given up by the watchdog"
    assert report["cells_left"] == report["cells_given_up"] == len(report["cells_left_centres"]) > 0
    assert report["patience"] == 40.0 and len(report["interventions"]) == len(actions)
    assert "NOT complete (every cell left was given up by the watchdog)" in format_summary(summary)
    write_run_directory(result, tmp_path / "out")
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["watchdog"]["why"] == report["why"]


def test_without_the_watchdog_the_same_run_waits_until_max_time():
    result = run_scenario(validate(stalling_values(watchdog=False, max_time=300.0)))
    assert not result.completed and result.stalls == [] and result.steps == 3000


def test_the_coordinator_sees_the_same_stalls_as_the_engine_byte_for_byte(tmp_path):
    config = write_scenario(tmp_path / "s.toml", **stalling_values(max_time=600.0))
    engine = anicov("run", "--config", str(config), "--out", str(tmp_path / "engine"), "--quiet", "--no-record")
    assert engine.returncode == EXIT_INCOMPLETE, engine.stderr
    assert "watchdog        " in engine.stdout
    team = unique_team()
    launched = run(launcher_command("--config", str(config), "--out", str(tmp_path / "team"), "--no-record", team=team))
    assert launched.returncode == EXIT_INCOMPLETE, launched.stderr + launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")
    assert json.loads((tmp_path / "team" / "summary.json").read_text())["watchdog"]["interventions"]
    assert processes_of(team) == []
