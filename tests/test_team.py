"""The team as real processes over real Zenoh sessions on loopback: launch_team.py end to end."""

from __future__ import annotations

import json
import signal
import subprocess
from pathlib import Path

import pytest

from logger.replay import summarise_recording
from tests.teamrun import (
    ROOT,
    anicov,
    check_realtime_run,
    launched_team,
    launcher_command,
    limit,
    processes_of,
    run,
    unique_team,
    wait_for,
    write_scenario,
)


def assert_same_run(engine_dir, team_dir):
    for name in ("trajectory.csv", "summary.json"):
        assert (engine_dir / name).read_bytes() == (team_dir / name).read_bytes(), name


def engine_then_team(
    tmp_path: Path, config: Path, *flags: str, team: str | None = None, timeout: float = 300
) -> subprocess.CompletedProcess[str]:
    """``anicov run`` of ``config`` into tmp_path/engine, then the launcher's team into tmp_path/team (``flags``
    added), both asserted to exit 0; the launcher's result."""
    engine = anicov("run", "--config", str(config), "--out", str(tmp_path / "engine"), "--quiet", "--no-record")
    assert engine.returncode == 0, engine.stderr
    launched = run(
        launcher_command("--config", str(config), "--out", str(tmp_path / "team"), *flags, team=team), timeout
    )
    assert launched.returncode == 0, launched.stderr + launched.stdout
    return launched


@pytest.mark.parametrize(
    ("agents", "domain", "bus", "deltas"),
    [
        (1, [40.0, 40.0], "peer", "event"),
        (1, [40.0, 40.0], "client", "cells"),
        (4, [70.0, 70.0], "peer", "event"),
        # The paper's whole square: 5,809 steps, 48 s of wall clock in the default suite's load (27 s alone).
        pytest.param(4, [100.0, 100.0], "peer", "event", marks=pytest.mark.slow),
    ],
    ids=["N=1", "N=1-through-the-router-deltas-as-cells", "N=4-half-the-paper-s-area", "N=4-paper"],
)
def test_lockstep_over_zenoh_equals_in_process_engine_byte_for_byte(tmp_path, agents, domain, bus, deltas):
    """Deltas travel as sensing events by default (protocol.events), or as cells: the same run. Peers
    (the default) or clients of the launcher's router; the two options are independent, so one run tries
    both other choices (the secure and the ROS 2 teams also run through a router)."""
    config = write_scenario(tmp_path / "s.toml", domain=domain, agents=agents, seed=3)
    team = unique_team()
    launched = engine_then_team(tmp_path, config, "--bus", bus, "--deltas", deltas, team=team)
    assert "coverage        complete" in launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")
    counts = json.loads((tmp_path / "team" / "coordinator_counts.json").read_text())
    assert counts["rejected"] == 0 and counts["gaps"] == 0
    assert processes_of(team) == []
    # What each robot sent a step: its compact step (82 bytes) with events, some 2.4 kB of cells without.
    bandwidth = json.loads((tmp_path / "team" / "bandwidth.json").read_text())
    assert "bus per robot" in launched.stdout
    assert (bandwidth["bytes_out_per_step"] < 100) == (deltas == "event")


@pytest.mark.parametrize("stations", [True, pytest.param(False, marks=pytest.mark.slow)])  # the spiral: 11 s, slow set
def test_the_anicov_controller_over_zenoh_equals_the_engine_with_the_same_messages(tmp_path, stations):
    """controller = "best" (the anicov controller): the coordinator plans the carrots (at stations, where a
    carrot on the robot is a bearing to face; or along the spiral), each agent pursues its own; lockstep over
    Zenoh is anicov run byte for byte."""
    config = write_scenario(
        tmp_path / "s.toml", domain=[40.0, 40.0], agents=3, seed=5, controller="best", stations=stations
    )
    launched = engine_then_team(tmp_path, config, "--no-record", team=unique_team())
    assert "coverage        complete" in launched.stdout
    assert json.loads((tmp_path / "team" / "summary.json").read_text())["scenario"]["controller"] == "anicov"
    assert_same_run(tmp_path / "engine", tmp_path / "team")


def test_anicov_among_walls_with_bodies_over_zenoh_equals_the_engine_byte_for_byte(tmp_path):
    """Issue 36: anicov on a map with robot bodies and the safety filter (two rooms joined by a door, N = 4):
    the coordinator's patches, detours, reliefs, cleanups and turns at stations are the engine's, carrot for carrot
    (seed 1: a robot waits its turn at a station in 10 of the run's 306 plans, measured in process at c7b31b6)."""
    config = write_scenario(
        tmp_path / "s.toml", domain=[24.0, 16.0], cell=1.0, range=5.0, robot_radius=0.4, occlusion=True,
        agents=4, seed=1, controller="anicov",
        obstacles=[[[12.0, 0.0], [13.0, 0.0], [13.0, 6.0], [12.0, 6.0]],
                   [[12.0, 10.0], [13.0, 10.0], [13.0, 16.0], [12.0, 16.0]]],
    )  # fmt: skip
    launched = engine_then_team(tmp_path, config, "--no-record")
    assert "coverage        complete" in launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")


@pytest.mark.slow  # 35 - 38 s of wall clock (31 processes start on 2 cores): the scale check, outside the default suite
def test_thirty_agent_processes_equal_the_engine(tmp_path):
    config = write_scenario(tmp_path / "s.toml", domain=[50.0, 50.0], agents=30, seed=1)
    team = unique_team()
    launched = engine_then_team(tmp_path, config, team=team, timeout=480)
    assert "coordinator + 30 agents" in launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")
    assert processes_of(team) == []


@pytest.mark.slow  # a minute of wall clock: the paper's N = 4 run at speed 10 (realtime runs stay in the suite, smaller)
def test_realtime_clock_completes_within_15_percent_of_lockstep(tmp_path):
    engine = anicov("run", "--n", "4", "--seed", "0", "--out", str(tmp_path / "l"), "--quiet")
    assert engine.returncode == 0, engine.stderr
    lockstep = json.loads((tmp_path / "l" / "summary.json").read_text())
    launched = run(
        launcher_command(
            "--n", "4", "--seed", "0", "--clock", "realtime", "--speed", "10", "--out", str(tmp_path / "rt")
        ),
        timeout=400,
    )
    assert launched.returncode == 0, launched.stderr + launched.stdout
    summary = check_realtime_run(tmp_path / "rt", k_v=1.0, k_omega=1.0, dt=0.1, simulated=True)  # as test_ros2_team.py
    ratio = summary["completion_time"] / lockstep["completion_time"]
    (tmp_path / "ratio.txt").write_text(f"{ratio:.3f}\n")
    assert 0.85 <= ratio <= 1.15, ratio


@pytest.mark.parametrize(("number", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["SIGINT", "SIGTERM"])
def test_signal_stops_every_child_and_exits_with_its_code(tmp_path, number, code):
    team = unique_team()
    with launched_team("--n", "3", "--out", str(tmp_path / "run"), team=team) as process:
        # Wait until the team is really running: all three agents logged their start.
        logs = tmp_path / "run" / "logs"
        assert wait_for(
            lambda: all(
                (logs / f"agent-{i}.log").exists() and "starts" in (logs / f"agent-{i}.log").read_text()
                for i in range(3)
            ),
            timeout=120,
        )
        assert len(processes_of(team)) >= 4
        process.send_signal(number)
        _, stderr = process.communicate(timeout=limit(120))
    assert process.returncode == code, stderr
    assert "every child stopped" in stderr
    assert wait_for(lambda: processes_of(team) == [], timeout=60), processes_of(team)


def test_busy_router_port_is_a_clear_error(tmp_path):
    import socket

    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = holder.getsockname()[1]
        done = run(launcher_command("--n", "1", "--out", str(tmp_path), port=port), timeout=60)
    assert done.returncode == 2
    assert f"cannot open the router on tcp/127.0.0.1:{port}" in done.stderr


def test_agent_with_bad_id_fails_with_a_clear_message():
    done = anicov("agent", "--id", "7", "--n", "4", "--connect", "tcp/127.0.0.1:1", "--team", "x", timeout=60)
    assert done.returncode == 2
    assert "--id: expected an agent id from 0 to 3, got 7" in done.stderr


def test_a_team_on_a_map_equals_the_engine_and_its_recording_shows_the_map(tmp_path):
    import numpy as np

    from tests.conftest import write_map

    occupied = np.zeros((40, 40), dtype=bool)
    occupied[20, :30] = True  # a wall with a 10-unit gap at one end
    occupied[30:36, 5:11] = True  # and a block
    write_map(tmp_path, "site", occupied)
    # Issue 11's terrain alone; the filter on a map over Zenoh is tests/test_safety_cases.py's corridor.
    config = write_scenario(tmp_path / "s.toml", map="site.yaml", agents=3, seed=2, robot_radius=0.4, safety=False)
    team = unique_team()
    launched = engine_then_team(tmp_path, config, team=team)
    assert "coverage        complete" in launched.stdout and "terrain" in launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")
    summary = json.loads((tmp_path / "team" / "summary.json").read_text())
    assert summary["terrain"]["occupied_cells"] == int(occupied.sum()) and summary["terrain"]["map_sha256"]
    assert "/world/map/occupancy" in summarise_recording(tmp_path / "team" / "recording.rrd", load_maps=False).entities
    assert processes_of(team) == []


def test_a_plug_in_controller_over_zenoh_equals_the_engine_byte_for_byte(tmp_path):
    """The worked example of examples/ (a controller from outside the package, by file): the agents call
    it through the same function as the engine (model.controllers.plugin_step.decide_with)."""
    example = ROOT / "examples" / "nearest_uncovered.py"
    config = write_scenario(
        tmp_path / "s.toml", domain=[40.0, 40.0], agents=2, seed=3, controller=f"{example}:NearestUncovered"
    )
    launched = engine_then_team(tmp_path, config, "--no-record")
    assert "coverage        complete" in launched.stdout
    assert_same_run(tmp_path / "engine", tmp_path / "team")


def test_a_plug_in_that_fails_mid_run_is_reported_with_its_name_and_the_team_carries_on(tmp_path):
    """A plug-in's bad command (NaN at step 20 on robot 1) fails that agent's process, as any agent's failure
    does (docs/reliability.md): the launcher says which and where its log is, the team goes on without it
    (here to max_time: the plug-in only drives straight), and the agent's log names the controller, the robot
    and the step."""
    plugin = tmp_path / "bad_plugin.py"
    plugin.write_text(
        "from model.controllers import Controller\n\n\n"
        "class NaNAtTwenty(Controller):\n"
        "    name = 'nan-at-twenty'\n\n"
        "    def command(self, view):\n"
        "        return (float('nan'), 0.0) if view.step == 20 and view.agent == 1 else (0.5, 0.0)\n"
    )
    config = write_scenario(
        tmp_path / "s.toml",
        domain=[40.0, 40.0],
        agents=2,
        seed=3,
        max_time=30.0,
        controller="bad_plugin.py:NaNAtTwenty",
    )
    team = unique_team()
    launched = run(launcher_command("--config", str(config), "--out", str(tmp_path / "team"), "--no-record", team=team))
    assert launched.returncode == 1, launched.stderr + launched.stdout  # max_time ran out, coverage incomplete
    assert "lost on the way agent-1" in launched.stdout
    assert "agent-1.log" in launched.stderr
    log = (tmp_path / "team" / "logs" / "agent-1.log").read_text()
    assert "NaNAtTwenty', robot 1, step 20: command() returned (v, omega) = (nan, 0.0)" in log
    assert processes_of(team) == []


@pytest.mark.slow  # 52 s; the map team of test_a_team_on_a_map_equals_the_engine... stays in the default suite
def test_a_team_on_a_map_saved_with_an_unknown_border_equals_the_engine_in_the_maps_frame(tmp_path):
    """A map_saver-like map (tests/test_map_fit.py: 286 × 423 pixels of 0.05 m, origin not (0, 0), a room in a
    wide unknown border) at a TurtleBot3 Burger's units: cropped and padded alike in every process, its
    trajectory.csv in the map's frame, lockstep over Zenoh equal to the engine byte for byte."""
    from tests.test_map_fit import scenario_on_saved_map

    scenario_on_saved_map(tmp_path)
    config = tmp_path / "s.toml"
    launched = engine_then_team(tmp_path, config, "--no-record")
    assert "unknown border cropped" in launched.stderr
    assert_same_run(tmp_path / "engine", tmp_path / "team")
    corner = json.loads((tmp_path / "team" / "summary.json").read_text())["terrain"]["map_corner"]
    assert corner[0] < -6.0 and corner[1] < -2.0  # the map's own frame, not the model's
