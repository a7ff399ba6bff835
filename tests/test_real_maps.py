"""scenarios/real/: public SLAM maps that robots made, fetched from Debian's registry (scenarios/real/README.md).

The maps are not committed: ``./go test`` fetches them first (scenarios/real/fetch_maps.sh). Where this
machine cannot (no apt), these tests are skipped with that reason, except under CI, where they must run.
"""

from __future__ import annotations

import csv
import hashlib
import json
import os
import re
from pathlib import Path

import numpy as np
import pytest

from anicov.engine import run_scenario
from model.parameters import starting_poses
from model.scenario import load_scenario
from model.scenario.map_fit import MapFrame
from model.world.world import fitted_map_of, map_frame_of, world_of
from runtime.lifecycle import EXIT_INCOMPLETE
from runtime.rundir import summary_of
from tests.conftest import ROOT
from tests.teamrun import anicov, check_realtime_run, launcher_command, processes_of, run, unique_team
from tests.test_team import assert_same_run

REAL = ROOT / "scenarios" / "real"
SCENARIOS = sorted(REAL.glob("*.toml"))
PUBLISHED = {  # sha256 of each file as Debian's mrpt-common 1:2.5.8+ds-2 ships it (README.md's table)
    "uwb_ro-localization_demo_map.gridmap.gz": "eb7e9b3a611d024a4c9695fb9085be03bf6bd614c0e33bb7890bc938540bc3d3",
    "2006-MalagaCampus.gridmap.gz": "a39128e24c79c6ed0b79b7e370c6b95145db71faaceffb6ca17be2170415bcb7",
}


def map_of(scenario_path):
    name = re.search(r'^map = "([^"]+)"', scenario_path.read_text(), re.MULTILINE).group(1)
    path = REAL / name
    if not path.is_file():
        if os.environ.get("CI"):
            pytest.fail(f"{path} is missing: CI runs ./go test, which fetches it (scenarios/real/fetch_maps.sh)")
        pytest.skip(f"{path} is not fetched here (scenarios/real/fetch_maps.sh needs apt-get)")
    return path


def test_the_corpus_has_its_scenarios_and_the_readme_names_each():
    readme = (REAL / "README.md").read_text()
    assert len(SCENARIOS) >= 2
    for scenario in SCENARIOS:
        assert f"`{scenario.name}`" in readme
    for name in PUBLISHED:
        assert name in readme


@pytest.mark.parametrize("scenario_path", SCENARIOS, ids=[path.stem for path in SCENARIOS])
def test_every_corpus_map_loads_as_published_cropped_to_what_is_known_in_its_own_frame(scenario_path):
    path = map_of(scenario_path)
    assert hashlib.sha256(path.read_bytes()).hexdigest() == PUBLISHED[path.name]
    scenario = load_scenario(scenario_path)
    occupancy, fitted = fitted_map_of(scenario)
    rows, cols = occupancy.occupied.shape
    width, height = scenario.domain
    assert width < cols * occupancy.resolution and height < rows * occupancy.resolution  # the void cropped
    left, _, bottom, _ = fitted.cropped
    corner = map_frame_of(scenario).corner
    assert corner == pytest.approx(
        (occupancy.origin[0] + left * occupancy.resolution, occupancy.origin[1] + bottom * occupancy.resolution)
    )
    world = world_of(scenario)
    assert world.coverable.sum() > 100 and world.reachable.any()


def test_a_short_seeded_run_on_the_lab_map_completes():
    scenario_path = REAL / "uwb-lab.toml"
    map_of(scenario_path)
    # N = 2, seed 1: 2173.9 time units (t* 519.9), about 3 s (26611f6).
    result = run_scenario(load_scenario(scenario_path).with_overrides(agents=2, seed=1), record_trace=False)
    assert result.completed, (result.errors[-1], [stall.line(0.2, MapFrame()) for stall in result.stalls])


def test_a_team_of_eight_completes_the_campus_map():
    # N = 8, seed 0: complete at t = 2890.7 (t* 314.8; 26611f6), the watchdog never needed, robots kept 2r + s apart and
    # r off every wall.
    scenario_path = REAL / "malaga-campus.toml"
    map_of(scenario_path)
    scenario = load_scenario(scenario_path).with_overrides(agents=8, seed=0)
    result = run_scenario(scenario)  # with the trace: separation and clearance are measured on it
    assert result.completed, (result.errors[-1], [stall.line(scenario.cell, MapFrame()) for stall in result.stalls])
    assert not result.given_up.any()
    report = summary_of(result)
    assert result.stalls == []
    assert report["min_separation"] >= 2 * scenario.robot_radius + scenario.safety_margin - 0.01
    assert report["min_clearance"] >= scenario.robot_radius


def test_lockstep_over_zenoh_equals_the_engine_byte_for_byte_on_the_lab_map(tmp_path):
    """The team as processes on a map robots made, at Burger units (N = 2, seed 1, the first 150 time units:
    1,500 steps with robots among the lab's pillars, the filter and the crowding rule at work): trajectory.csv
    (in the map's frame) and summary.json are the engine's, byte for byte."""
    config = lab_config(tmp_path, agents=2, seed=1, max_time=150.0)
    engine = anicov("run", "--config", str(config), "--out", str(tmp_path / "engine"), "--quiet", "--no-record")
    assert engine.returncode == EXIT_INCOMPLETE, engine.stderr  # max_time: 150 of the 2173.9 it needs
    team = unique_team()
    launched = run(launcher_command("--config", str(config), "--out", str(tmp_path / "team"), "--no-record", team=team))
    assert launched.returncode == EXIT_INCOMPLETE, launched.stderr + launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")
    assert json.loads((tmp_path / "team" / "summary.json").read_text())["terrain"]["map_corner"] == pytest.approx(
        [-3.4, -9.6]
    )
    assert processes_of(team) == []


def lab_config(tmp_path, agents: int, seed: int, max_time: float) -> Path:
    """The lab scenario with its map named by absolute path, for a team launched from anywhere."""
    scenario_path = REAL / "uwb-lab.toml"
    map_path = map_of(scenario_path)
    text = re.sub(r'^map = "[^"]+"', f'map = "{map_path}"', scenario_path.read_text(), flags=re.MULTILINE)
    text = re.sub(r"^max_time = .*$", f"max_time = {max_time}", text, flags=re.MULTILINE)
    config = tmp_path / "lab.toml"
    config.write_text(text.replace("agents = 4", f"agents = {agents}").replace("seed = 0", f"seed = {seed}"))
    return config


@pytest.mark.slow  # a minute of realtime (30 s for the ROS 2 one): outside the default suite, run with -m slow
def test_the_team_completes_the_lab_map_in_realtime(tmp_path):
    """launch_team.py --clock realtime on a map robots made: N = 4, seed 1 (in process: complete at 986 time
    units; realtime here 994, a minute), at 20 time units a wall second; complete, every robot's rows dt apart,
    commands within the paper's bounds, each robot's path as its commands ask (tests/teamrun.check_realtime_run).
    (Eight robots at that speed on two cores stand still: the filter stops a robot whose teammate's pose is
    older than max_pose_age, 0.5 time units, 25 ms of wall time at speed 20.)"""
    config = lab_config(tmp_path, agents=4, seed=1, max_time=20000.0)
    team = unique_team()
    command = launcher_command(
        "--config", str(config), "--clock", "realtime", "--speed", "20", "--out", str(tmp_path / "team"), team=team
    )
    launched = run(command, timeout=600)
    assert launched.returncode == 0, launched.stderr + launched.stdout
    scenario = load_scenario(config)
    summary = check_realtime_run(tmp_path / "team", scenario.k_v, scenario.k_omega, scenario.dt, simulated=True)
    assert summary["min_clearance"] >= scenario.robot_radius and summary["terrain"]["map_corner"] == pytest.approx(
        [-3.4, -9.6]
    )
    assert (tmp_path / "team" / "recording.rrd").stat().st_size > 0
    assert processes_of(team) == []


@pytest.mark.slow  # a minute of realtime (30 s for the ROS 2 one): outside the default suite, run with -m slow
def test_ros2_bases_drive_the_lab_map_at_a_burger_s_real_units(tmp_path):
    """The ROS 2 team (stand-in bases: deploy/ros2/test_base.py, odometry at 30 Hz) on the lab map at the map's
    own units, metres and seconds (a Burger's 0.22 m/s, 10 Hz control): 20 s of driving, then max_time. The
    bases' odometry, in the map's frame, stays in the lab's free space, off the walls by r, each base at the
    start pose the scenario draws, and the team covers some of the lab."""
    config = lab_config(tmp_path, agents=2, seed=1, max_time=20.0)
    team = unique_team()
    command = launcher_command(
        "--config", str(config), "--robot", "ros2", "--test-bases", "--clock", "realtime", "--out", str(tmp_path / "team"),
        team=team,
    )  # fmt: skip
    launched = run(command, timeout=300)
    assert launched.returncode == EXIT_INCOMPLETE, launched.stderr + launched.stdout
    scenario = load_scenario(config)
    summary = json.loads((tmp_path / "team" / "summary.json").read_text())
    assert summary["min_clearance"] >= scenario.robot_radius and summary["final_error"] < 0.99
    with open(tmp_path / "team" / "trajectory.csv") as source:
        rows = list(csv.DictReader(source))
    corner = map_frame_of(scenario).corner
    starts = starting_poses(scenario)
    world = world_of(scenario)
    for agent in range(2):
        mine = [row for row in rows if int(row["agent"]) == agent]
        xs, ys = np.array([float(r["x"]) for r in mine]), np.array([float(r["y"]) for r in mine])
        assert (xs[0] - corner[0], ys[0] - corner[1]) == pytest.approx(tuple(starts[agent, :2]), abs=0.02)
        assert np.hypot(np.diff(xs), np.diff(ys)).sum() > 1.0  # it drove
        cols = ((xs - corner[0]) / scenario.cell).astype(int)
        rows_ = ((ys - corner[1]) / scenario.cell).astype(int)
        assert not world.occupied[rows_, cols].any()
    assert processes_of(team) == []
