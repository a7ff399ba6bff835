"""Helpers for tests that start real processes on real Zenoh sessions (loopback, free ports)."""

from __future__ import annotations

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
