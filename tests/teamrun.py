"""Helpers for tests that start real processes on real Zenoh sessions (loopback, free ports)."""

from __future__ import annotations

import csv
import itertools
import json
import math
import os
import signal
import socket
import subprocess
import sys
import time
import uuid
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def unique_team() -> str:
    return "t" + uuid.uuid4().hex[:10]


def launcher_command(*args: str, team: str | None = None, port: int | None = None) -> list[str]:
    port = port or free_port()
    return [
        sys.executable,
        str(ROOT / "launch_team.py"),
        "--quiet",
        "--team",
        team or unique_team(),
        "--listen",
        f"tcp/127.0.0.1:{port}",
        *args,
    ]


@contextmanager
def running(command: list[str]) -> Iterator[subprocess.Popen[str]]:
    """A process in the background (output piped), killed if still running at the end of the block."""
    process = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        yield process
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()


def launched_team(*args: str, team: str | None = None, port: int | None = None):
    """``launch_team.py`` in the background: ``with launched_team(...) as process:``."""
    return running(launcher_command(*args, team=team, port=port))


def anicov_command(*args: str) -> list[str]:
    return [sys.executable, "-m", "anicov.cli", *args]


def run(command: list[str], timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        command, cwd=ROOT, capture_output=True, text=True, timeout=timeout, env=os.environ | {"PYTHONUNBUFFERED": "1"}
    )


def anicov(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return run(anicov_command(*args), timeout=timeout)


def processes_of(team: str) -> list[str]:
    """Command lines of live processes that mention this team (should be none after a run)."""
    found = subprocess.run(["pgrep", "-af", f"team {team}"], capture_output=True, text=True)
    return [line for line in found.stdout.splitlines() if "pgrep" not in line]


def wait_for(condition, timeout: float, period: float = 0.1) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(period)
    return condition()


def interrupt(process: subprocess.Popen, number: int = signal.SIGINT) -> None:
    process.send_signal(number)


def write_scenario(path: Path, **values: object) -> Path:
    lines = []
    for key, value in values.items():
        if isinstance(value, bool):
            lines.append(f"{key} = {str(value).lower()}")
            continue
        lines.append(f"{key} = {value!r}".replace("'", '"') if not isinstance(value, list) else f"{key} = {value}")
    path.write_text("\n".join(lines) + "\n")
    return path


def check_realtime_run(run_dir: Path, k_v: float, k_omega: float, dt: float, simulated: bool) -> dict:
    """The checks every realtime run passes, simulated robots or real bases (returns summary.json):
    complete with e_D = 0; trajectory.csv in its form, every robot's rows dt apart (none lost, its last
    one too); commands within the paper's bounds (|v| ≤ k_v, |ω| ≤ π k_ω, eq. 15-16); and each robot's
    path measured from its poses within 3 % of the path its commands ask for (Σ |v| dt): the robot moved
    as it was told. ``simulated``: every row also follows from the one before by eq. 1, exactly."""
    from model.dynamics import unicycle_step

    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["completed"] is True and summary["final_error"] == 0.0, summary
    with open(run_dir / "trajectory.csv", newline="") as file:
        assert file.readline() == "t,agent,x,y,theta,v,omega\n"
        file.seek(0)
        rows = list(csv.DictReader(file))
    by_agent: dict[int, list[dict[str, float]]] = {}
    for row in rows:
        by_agent.setdefault(int(row["agent"]), []).append({key: float(value) for key, value in row.items()})
    assert sorted(by_agent) == list(range(summary["scenario"]["agents"]))
    for agent, steps in by_agent.items():
        times = [step["t"] for step in steps]
        assert all(math.isclose(b - a, dt, rel_tol=1e-6) for a, b in itertools.pairwise(times)), agent
        assert max(abs(step["v"]) for step in steps) <= k_v + 1e-9
        assert max(abs(step["omega"]) for step in steps) <= math.pi * k_omega + 1e-9
        measured = sum(math.hypot(b["x"] - a["x"], b["y"] - a["y"]) for a, b in itertools.pairwise(steps))
        commanded = sum(abs(step["v"]) * dt for step in steps[:-1])
        assert abs(measured - commanded) <= 0.03 * commanded, (agent, measured, commanded)
        if simulated:
            for a, b in itertools.pairwise(steps):
                expected = unicycle_step(a["x"], a["y"], a["theta"], a["v"], a["omega"], dt)
                assert math.dist(expected[:2], (b["x"], b["y"])) < 1e-9, (agent, a["t"], expected, b)
    return summary
