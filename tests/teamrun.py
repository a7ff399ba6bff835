"""Helpers for tests that start real processes on real Zenoh sessions (loopback, free ports)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import uuid
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


def run(command: list[str], timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        command, cwd=ROOT, capture_output=True, text=True, timeout=timeout, env=os.environ | {"PYTHONUNBUFFERED": "1"}
    )


def anicov(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return run([sys.executable, "-m", "anicov.cli", *args], timeout=timeout)


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
        lines.append(f"{key} = {value!r}".replace("'", '"') if not isinstance(value, list) else f"{key} = {value}")
    path.write_text("\n".join(lines) + "\n")
    return path
