"""The team over Zenoh: lockstep steps per second for N = 4 and N = 30, beside a bare Zenoh round trip.

Each team runs as real processes through ``launch_team.py`` on loopback; the
figures come from the coordinator's counters (stepping time, bytes it
received) and the launcher's wall time. Measured in the same run: the bare
Zenoh ping-pong through a router (bench/pingpong.py), the same between two
peers (the transport a team uses), and the step's exchange with no work in it
(bench/fanout.py: one go to N echo processes and their N replies). Prints a
Markdown table.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from bench.fanout import fan_out  # noqa: E402
from bench.machine import describe_machine  # noqa: E402
from bench.pingpong import free_port, ping  # noqa: E402


def run_team(agents: int, config: str | None, record: bool = False, deltas: str = "event") -> dict[str, float]:
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
            "--deltas",
            deltas,
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
        "go_bytes": counts["bytes_sent"] / steps,  # the coordinator sends one go a step (and a few others)
        "step_bytes": counts["bytes_received"] / steps / agents,  # each agent's step message
        "recording_bytes_per_1000_steps": recording_bytes / steps * 1000,
    }


def median(values: list[float]) -> float:
    return statistics.median(values)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--skip-30", action="store_true", help="only N = 4")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each N = 4 variant (default 3)")
    parser.add_argument(
        "--step-vs-exchange", action="store_true", help="only: the step against its bare exchange, cells and events"
    )
    args = parser.parse_args()
    print(f"machine: {describe_machine()}")
    if args.step_vs_exchange:
        step_against_exchange((4,) if args.skip_30 else (4, 30), args.repeats)
        return
    rtt, peer = bare_round_trips()
    small_teams(rtt, peer)
    logger_cost(args.repeats, rtt, peer)
    if not args.skip_30:
        team_of_30()


def bare_round_trips() -> tuple[dict[str, float], dict[str, float]]:
    """Zenoh's round trips via a router and between peers, and a step's exchange with no work in it."""
    rtt = ping(2000, 256)
    print(
        f"bare Zenoh ping-pong between two processes via a router: median {rtt['median_us']:.0f} µs, "
        f"p90 {rtt['p90_us']:.0f} µs"
    )
    peer = fan_out(1, 2000, 256, 256)
    print(f"bare Zenoh ping-pong between two peers (as a team runs): median {peer['median_us']:.0f} µs")
    floor = fan_out(4, 2000, 10_700, 3_070, handoff=True)
    print(
        f"a lockstep step's exchange with no work (go of 10.7 kB to 4 echo processes, 4 replies of 3.1 kB): "
        f"median {floor['median_us']:.0f} µs = {floor['median_us'] / peer['median_us']:.1f} peer round trips"
    )
    return rtt, peer


def small_teams(rtt: dict[str, float], peer: dict[str, float]) -> None:
    """The same per-step cost with fewer processes sharing the two cores."""
    for agents in (1, 2):
        row = run_team(agents, None)
        per_step = row["stepping_s"] / row["steps"] * 1e6
        print(
            f"N = {agents}: {per_step:.0f} µs a step = {per_step / peer['median_us']:.1f} peer / "
            f"{per_step / rtt['median_us']:.1f} router round trips ({row['steps']} steps)"
        )


def logger_cost(repeats: int, rtt: dict[str, float], peer: dict[str, float]) -> None:
    """N = 4 without and with the logger, interleaved, so a slow spell of a shared machine hits both alike."""
    plain: list[dict[str, float]] = []
    recorded: list[dict[str, float]] = []
    for _ in range(repeats):
        plain.append(run_team(4, None))
        recorded.append(run_team(4, None, record=True))
    print(f"\nN = 4, paper scenario, {repeats} runs each (median, then min – max):")
    print(
        "| variant | steps | stepping time (s) | launcher wall (s) | steps/s | round trips per step (router / peer)"
        " | bytes per step |"
    )
    print("|---|---|---|---|---|---|---|")
    for name, runs in (("no logger", plain), ("logger recording", recorded)):
        print(table_row(name, runs, rtt, peer))
    ratios = [
        with_logger["steps_per_s"] / without["steps_per_s"]
        for without, with_logger in zip(plain, recorded, strict=True)
    ]
    print(
        f"\nwith the logger: {100 * median(ratios):.0f} % of the step rate without it (median of {repeats} "
        f"interleaved pairs; {100 * min(ratios):.0f} – {100 * max(ratios):.0f} %); recording "
        f"{median([run['recording_bytes_per_1000_steps'] for run in recorded]) / 1e6:.2f} MB per 1,000 steps"
    )


def table_row(name: str, runs: list[dict[str, float]], rtt: dict[str, float], peer: dict[str, float]) -> str:
    """One variant's line of the Markdown table: medians, with the range of the times."""
    stepping = [run["stepping_s"] for run in runs]
    wall = [run["wall_s"] for run in runs]
    rate = [run["steps_per_s"] for run in runs]
    trips = [1e6 / r / rtt["median_us"] for r in rate]
    peer_trips = [1e6 / r / peer["median_us"] for r in rate]
    return (
        f"| {name} | {runs[0]['steps']} | {median(stepping):.1f} ({min(stepping):.1f} – {max(stepping):.1f}) | "
        f"{median(wall):.1f} ({min(wall):.1f} – {max(wall):.1f}) | {median(rate):.0f} | "
        f"{median(trips):.1f} / {median(peer_trips):.1f} | "
        f"{median([run['bus_bytes_per_step'] for run in runs]):,.0f} |"
    )


def step_against_exchange(team_sizes: tuple[int, ...], repeats: int) -> None:
    """Issue 13: a lockstep step over Zenoh against the bare exchange of the same messages with no work in
    it (bench/fanout.py, with the go and step sizes the run measured), deltas as cells (before) and as
    sensing events (after), each in the same bench run. Medians of ``repeats`` team runs."""
    print("\n| N | deltas | go / step message (B) | step (µs) | bare exchange (µs) | step / exchange |")
    print("|---|---|---|---|---|---|")
    for agents in team_sizes:
        for deltas in ("cells", "event"):
            runs = [run_team(agents, None, deltas=deltas) for _ in range(repeats if agents < 10 else 1)]
            step_us = median([run["stepping_s"] / run["steps"] * 1e6 for run in runs])
            go, reply = round(median([r["go_bytes"] for r in runs])), round(median([r["step_bytes"] for r in runs]))
            exchange = fan_out(agents, 2000 if agents < 10 else 500, go, reply, handoff=True)["median_us"]
            print(
                f"| {agents} | {deltas} | {go:,} / {reply:,} | {step_us:.0f} | {exchange:.0f} | "
                f"{step_us / exchange:.2f} |",
                flush=True,
            )


def team_of_30() -> None:
    row = run_team(30, None)
    print(
        f"\nN = 30 (30 agent processes), paper scenario: {row['steps']} steps, {row['stepping_s']:.1f} s of "
        f"stepping, {row['wall_s']:.1f} s wall, {row['steps_per_s']:.0f} steps/s, "
        f"{row['bus_bytes_per_step']:,.0f} bytes through the coordinator per step"
    )


if __name__ == "__main__":
    main()
