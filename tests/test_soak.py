"""Soak variants of the fault tests: longer runs, more loss, repeated kills, more fuzz. Marked slow,
outside the default suite: ``./go test -m slow tests/test_soak.py``."""

from __future__ import annotations

import json
import os
import signal

import pytest

from tests.teamrun import anicov, free_port, launched_team, limit, processes_of, run_progress, unique_team, wait_for
from tests.test_faults import (
    agent_pid,
    assert_every_replica_holds_every_published_delta_once,
    fuzz_a_running_team,
    pid_of,
)

pytestmark = pytest.mark.slow


def restarted(out, count: int) -> bool:
    log = out / "logs" / f"coordinator.restart-{count}.log"
    return log.exists() and "resumed at step" in log.read_text()


def test_soak_lockstep_paper_run_with_10_percent_loss_and_three_coordinator_kills(tmp_path):
    team, port = unique_team(), free_port()
    out = tmp_path / "run"
    with (
        launched_team(
            "--n", "4", "--seed", "1", "--drop-rate", "0.10", "--no-record", "--out", str(out), team=team, port=port
        ) as process,
        run_progress(port, team) as progress,
    ):
        for kill in range(1, 4):  # a quarter, a half and three quarters into the run's 6,000 or so steps
            progress.wait_for_step(1500 * kill, process)
            os.kill(pid_of(team, "coordinator"), signal.SIGKILL)
            assert wait_for(lambda kill=kill: restarted(out, kill), timeout=120)
        stdout, stderr = process.communicate(timeout=limit(1200))
    assert process.returncode == 0, stderr + stdout
    assert "killed and restarted 3 time(s)" in stdout
    engine = anicov("run", "--n", "4", "--seed", "1", "--out", str(tmp_path / "engine"), "--quiet", "--no-record")
    assert engine.returncode == 0
    for name in ("trajectory.csv", "summary.json"):
        assert (tmp_path / "engine" / name).read_bytes() == (out / name).read_bytes(), name
    assert_every_replica_holds_every_published_delta_once(out, agents=4)
    assert wait_for(lambda: processes_of(team) == [], timeout=60)


def test_soak_realtime_eight_agents_with_loss_a_dead_agent_and_a_coordinator_kill(tmp_path):
    team, port = unique_team(), free_port()
    out = tmp_path / "run"
    with (
        launched_team(
            "--n",
            "8",
            "--seed",
            "2",
            "--clock",
            "realtime",
            "--speed",
            "20",
            "--drop-rate",
            "0.10",
            "--no-record",
            "--out",
            str(out),
            team=team,
            port=port,
        ) as process,
        run_progress(port, team) as progress,
    ):
        progress.wait_for_step(600, process)  # 3 s in at speed 20
        os.kill(agent_pid(team, 5), signal.SIGKILL)
        progress.wait_for_step(1000, process)  # 2 s later
        os.kill(pid_of(team, "coordinator"), signal.SIGKILL)
        stdout, stderr = process.communicate(timeout=limit(1200))
    assert process.returncode == 0, stderr + stdout
    assert json.loads((out / "summary.json").read_text())["completed"] is True
    coordinator = json.loads((out / "coordinator_counts.json").read_text())
    survivors = [json.loads((out / "logs" / f"agent-{i}.counts.json").read_text()) for i in range(8) if i != 5]
    assert len({counts["map_digest"] for counts in (coordinator, *survivors)}) == 1
    assert wait_for(lambda: processes_of(team) == [], timeout=60)


def test_soak_fuzz_four_hundred_thousand_payloads(tmp_path):
    # 100 x 100: the run goes on 15 s after the last payload here (on 60 x 60 it ended about with the fuzz).
    fuzz_a_running_team(tmp_path, domain=[100.0, 100.0], payloads=400_000)
