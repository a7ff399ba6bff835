"""The team over Zenoh: lockstep steps per second for N = 4 and N = 30, beside a bare Zenoh round trip.

Each team runs as real processes through ``launch_team.py`` on loopback; the
figures come from the coordinator's counters (stepping time, bytes it
received) and the launcher's wall time. The ping-pong is measured in the same
run (bench/pingpong.py). Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from bench.machine import describe_machine  # noqa: E402
from bench.pingpong import free_port, ping  # noqa: E402


def run_team(agents: int, config: str | None, record: bool = False) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as out:
        command = [
            sys.executable,
            str(HERE.parent / "launch_team.py"),
            "--quiet",
            "--n",
            str(agents),
            "--listen",
            f"tcp/127.0.0.1:{free_port()}",
            "--out",
            out,
        ]
        if not record:
            command.append("--no-record")
        if config:
            command += ["--config", config]
        started = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        wall = time.perf_counter() - started
        counts = json.loads((Path(out) / "coordinator_counts.json").read_text())
        recording = Path(out) / "recording.rrd"
        recording_bytes = recording.stat().st_size if recording.exists() else 0
        summary = json.loads((Path(out) / "summary.json").read_text())
    steps = summary["steps"]
    return {
        "agents": agents,
        "steps": steps,
        "stepping_s": counts["wall_seconds"],
        "wall_s": wall,
        "steps_per_s": steps / counts["wall_seconds"],
        "bus_bytes_per_step": counts["bytes_received"] / steps + counts["bytes_sent"] / steps,
        "recording_bytes_per_1000_steps": recording_bytes / steps * 1000,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--skip-30", action="store_true", help="only N = 4")
    args = parser.parse_args()
    print(f"machine: {describe_machine()}")
    rtt = ping(2000, 256)
    print(
        f"bare Zenoh ping-pong between two processes via a router: median {rtt['median_us']:.0f} µs, "
        f"p90 {rtt['p90_us']:.0f} µs"
    )
    print(
        "| team | steps | stepping time (s) | launcher wall (s) | steps/s | round trips per step | "
        "coordinator bytes in+out per step |"
    )
    print("|---|---|---|---|---|---|---|")
    rows = {}
    for agents in (4,) if args.skip_30 else (4, 30):
        row = rows[agents] = run_team(agents, None)
        per_step_us = 1e6 / row["steps_per_s"]
        print(
            f"| N = {agents} (paper) | {row['steps']} | {row['stepping_s']:.1f} | {row['wall_s']:.1f} | "
            f"{row['steps_per_s']:.0f} | {per_step_us / rtt['median_us']:.1f} | {row['bus_bytes_per_step']:,.0f} |"
        )
    recorded = run_team(4, None, record=True)
    print(
        f"\nwith the logger recording (N = 4): {recorded['steps_per_s']:.0f} steps/s, "
        f"{100 * recorded['steps_per_s'] / rows[4]['steps_per_s']:.0f} % of the rate without; "
        f"recording {recorded['recording_bytes_per_1000_steps'] / 1e6:.2f} MB per 1,000 steps"
    )


if __name__ == "__main__":
    main()
