"""A team driving anicov sim's bases over Zenoh (issue 37, item 1), beside the same team in process.

Two rooms and a door, N = 4, anicov, the physics world (scenarios/physics-rooms.toml), with and without its
``[noise]``: ``launch_team.py --robot ros2 --sim-bases`` in lockstep (real processes on loopback, the ROS 2 wire)
against ``anicov run``. Prints a Markdown table: wall clock, the team's steps, agent-steps per second of wall
clock, completion time.

    .venv/bin/python bench/bench_sim_team.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from bench.machine import describe_machine  # noqa: E402
from bench.pingpong import free_port  # noqa: E402

ROOMS = HERE.parent / "scenarios" / "physics-rooms.toml"


def timed(command: list[str], out: Path) -> tuple[float, dict]:
    started = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True, cwd=HERE.parent)
    wall = time.perf_counter() - started
    return wall, json.loads((out / "summary.json").read_text())


def row(where: str, noise: str, wall: float, summary: dict, agents: int) -> str:
    steps = summary["steps"]
    return (
        f"| {where} | {noise} | {wall:.1f} s | {steps} | {agents * steps / wall:,.0f} | "
        f"{summary['completion_time']:.1f} | {summary.get('physical_contacts', '-')} | "
        f"{100 * summary.get('true_coverage', float('nan')):.1f} % |"
    )


def main() -> None:
    print(f"machine: {describe_machine()}")
    print("| where | noise | wall clock | steps | agent-steps/s | completion | contacts | true coverage |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        quiet = Path(folder) / "rooms-quiet.toml"
        quiet.write_text(ROOMS.read_text().split("[noise]")[0])
        for config, noise in ((quiet, "none"), (ROOMS, "the issue's")):
            agents = 4
            out = Path(folder) / f"run-{noise[:4]}"
            engine = [sys.executable, "-m", "anicov.cli", "run", "--config", str(config), "--out", str(out)]
            wall, summary = timed([*engine, "--quiet", "--no-record"], out)
            print(row("in process (anicov run)", noise, wall, summary, agents), flush=True)
            out = Path(folder) / f"team-{noise[:4]}"
            launcher = [sys.executable, str(HERE.parent / "launch_team.py"), "--quiet", "--no-record"]
            launcher += ["--config", str(config), "--robot", "ros2", "--sim-bases", "--out", str(out)]
            wall, summary = timed([*launcher, "--listen", f"tcp/127.0.0.1:{free_port()}"], out)
            print(row("over Zenoh, anicov sim, lockstep", noise, wall, summary, agents), flush=True)


if __name__ == "__main__":
    main()
