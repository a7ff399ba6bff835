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
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

TIMEOUT_SCALE = float(os.environ.get("ANICOV_TEST_TIMEOUT_SCALE", "1"))
"""Multiplies every outer limit of the tests (``limit``, ``wait_for``, ``run``): set
ANICOV_TEST_TIMEOUT_SCALE=3 on a slow or crowded machine. A limit only bounds a hang: each test waits
on the event it needs (a file, a log line, a step of the run, a process's exit) and goes on as soon as
it comes, so no verdict depends on how fast the machine is, only how long a hang takes to be reported."""
if not TIMEOUT_SCALE > 0:
    raise ValueError(f"ANICOV_TEST_TIMEOUT_SCALE: expected a positive number, got {TIMEOUT_SCALE}")


def limit(seconds: float) -> float:
    """An outer limit of ``seconds`` (generous on this project's busy 2-core machine), scaled."""
    return seconds * TIMEOUT_SCALE


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
    """Run to its end; ``timeout`` (scaled by ``limit``) only bounds a hang."""
    return subprocess.run(
        command,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=limit(timeout),
        env=os.environ | {"PYTHONUNBUFFERED": "1"},
    )


def anicov(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    return run(anicov_command(*args), timeout=timeout)


def processes_of(team: str) -> list[str]:
    """Command lines of live processes that mention this team (should be none after a run)."""
    found = subprocess.run(["pgrep", "-af", f"team {team}"], capture_output=True, text=True)
    return [line for line in found.stdout.splitlines() if "pgrep" not in line]


def wait_for(condition, timeout: float, period: float = 0.1) -> bool:
    """True as soon as ``condition()`` is; False only after ``timeout`` seconds (scaled by ``limit``): an
    outer limit, never a verdict on how fast the machine is."""
    deadline = time.monotonic() + limit(timeout)
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(period)
    return condition()


def log_says(path: Path, text: str) -> bool:
    """Whether the log at ``path`` exists and holds ``text`` (an event to wait for)."""
    return path.exists() and text in path.read_text()


class RunProgress:
    """The last step a running team's coordinator reported on run/status (every 0.25 s; -1 before the
    first): a test acts at a point of the run ("well into it") whatever the machine's speed, not after a
    sleep that a busy machine spends before the run has got anywhere, or a fast one after it ended."""

    def __init__(self, session, team: str) -> None:
        from protocol.keys import TeamKeys

        self.step = -1
        self._subscriber = session.declare_subscriber(TeamKeys(team).status, self._on_status)

    def _on_status(self, sample) -> None:
        from protocol.decoding import decode
        from protocol.messages import Limits, ProtocolError, RunControl

        try:
            message = decode(sample.payload.to_bytes(), Limits(rows=1, cols=1, agents=1))
        except ProtocolError:
            return
        if isinstance(message, RunControl):
            self.step = max(self.step, message.step)

    def wait_for_step(self, step: int, process: subprocess.Popen) -> None:
        """Wait until the run reached ``step``; fail at once if ``process`` (the team) exited first."""
        assert wait_for(lambda: self.step >= step or process.poll() is not None, timeout=300), self.step
        assert self.step >= step, f"the team exited at step {self.step}, before step {step}"


@contextmanager
def run_progress(port: int, team: str) -> Iterator[RunProgress]:
    """A client of the team's router on ``port`` (retried until it is up) following the run's progress."""
    from protocol.session import open_session, zenoh_config

    with open_session(zenoh_config("client", connect=[f"tcp/127.0.0.1:{port}"]), patience=limit(120)) as session:
        yield RunProgress(session, team)


PARKED = """
import json
import sys
from pathlib import Path

preload, argv = json.loads(Path(sys.argv[2]).read_text())
for module in preload:
    __import__(module)
from anicov.cli import main

Path(sys.argv[1]).write_text("parked")
if sys.stdin.readline() != "go\\n":
    sys.exit(0)
sys.exit(main(argv))
"""
"""A parked process's code; its arguments are in a file, so that its command line is not taken for the
team process it will become (tests find those by their command lines: pgrep)."""


@dataclass
class Parked:
    """``anicov ARGS`` in a process that has imported ``preload`` and waits for :meth:`release`: a
    process started at a moment of a run is then there in the time it takes to do its work, not its
    interpreter's and libraries' start (seconds, and many more on a busy machine)."""

    process: subprocess.Popen
    ready_file: Path
    log: Path
    released_at: float | None = field(default=None)

    def ready(self) -> bool:
        return self.ready_file.exists()

    def release(self) -> None:
        assert self.process.poll() is None, self.log.read_text()
        self.released_at = time.time()
        assert self.process.stdin is not None
        self.process.stdin.write("go\n")
        self.process.stdin.close()

    def wait(self, timeout: float = 120) -> int:
        """Its exit code; ``timeout`` (scaled) only bounds a hang, which fails with its log."""
        try:
            return self.process.wait(timeout=limit(timeout))
        except subprocess.TimeoutExpired:
            raise AssertionError(f"still running after {limit(timeout):.0f} s:\n{self.log.read_text()}") from None


@contextmanager
def parked(args: list[str], preload: list[str], folder: Path, name: str) -> Iterator[Parked]:
    """``anicov ARGS`` parked (see :class:`Parked`) until it is ready; its output in ``folder/name.log``;
    killed if still running at the end of the block."""
    ready_file, log, arguments = folder / f"{name}.parked", folder / f"{name}.log", folder / f"{name}.args.json"
    arguments.write_text(json.dumps([preload, args]))
    with open(log, "w") as output:
        process = subprocess.Popen(
            [sys.executable, "-c", PARKED, str(ready_file), str(arguments)],
            cwd=ROOT,
            stdin=subprocess.PIPE,
            stdout=output,
            stderr=subprocess.STDOUT,
            text=True,
            env=os.environ | {"PYTHONUNBUFFERED": "1"},
        )
    try:
        here = Parked(process, ready_file, log)
        assert wait_for(lambda: here.ready() or process.poll() is not None, timeout=120), log.read_text()
        assert here.ready(), log.read_text()
        yield here
    finally:
        if process.poll() is None:
            process.kill()
        process.wait()


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
    from model.paper.dynamics import unicycle_step

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
