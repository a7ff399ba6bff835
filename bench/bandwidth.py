"""Bytes on the bus per agent-step (issue 13): a realtime team on the paper's scenario, counted by an
outside subscriber on ``anicov/<team>/**``, with deltas sent as cells and as sensing events.

Every message published under the team's keys reaches the subscriber once (each is counted once, however
many processes take it): agents' steps (delta and state), the coordinator's objectives and run control,
hellos, snapshots, the logger's traffic. Agent-steps are the step messages counted. At speed 1 a robot
takes 1/dt = 10 steps a second, so per robot: out = its steps' bytes × 10 per second; in ≈ everything
else on the bus per second (what a robot subscribes to: its teammates' steps and the coordinator's
messages). ``python bench/bandwidth.py --n 4 30`` prints a table and JSON.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
import tomllib
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import msgpack
import zenoh

from bench.machine import describe_machine
from bench.pingpong import free_port
from protocol.messages import COMPACT_STEP
from protocol.session import zenoh_config

ROOT = Path(__file__).resolve().parent.parent


def _session_when_up(port: int, patience: float = 120.0) -> zenoh.Session:
    """A client session on the launcher's router, once it listens."""
    deadline = time.monotonic() + patience
    while True:
        try:
            return zenoh.open(zenoh_config("client", connect=[f"tcp/127.0.0.1:{port}"]))
        except zenoh.ZError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def measure(agents: int, deltas: str, max_time: float, speed: float) -> dict[str, float]:
    """One realtime team to ``max_time``; the bytes an outside subscriber saw, by message type."""
    port, team = free_port(), f"bandwidth{agents}{deltas}{int(time.time() * 1000) % 100000}"
    with tempfile.TemporaryDirectory() as scratch:
        config = Path(scratch) / "scenario.toml"
        keys = tomllib.loads((ROOT / "scenarios" / "paper.toml").read_text()) | {"agents": agents, "max_time": max_time}
        config.write_text("".join(f"{key} = {json.dumps(value)}\n" for key, value in keys.items()))
        command = [sys.executable, str(ROOT / "launch_team.py"), "--quiet", "--team", team]
        command += ["--listen", f"tcp/127.0.0.1:{port}", "--config", str(config), "--out", str(Path(scratch) / "run")]
        command += ["--clock", "realtime", "--speed", str(speed), "--deltas", deltas]
        by_type: Counter[str] = Counter()
        count: Counter[str] = Counter()

        def on_sample(sample: zenoh.Sample) -> None:
            payload = sample.payload.to_bytes()
            if payload[:1] == bytes([COMPACT_STEP]):
                by_type["step"] += len(payload)
                count["step"] += 1
                return
            try:
                kind = msgpack.unpackb(payload, raw=False).get("type", "?")
            except Exception:
                kind = "other"
            by_type[kind] += len(payload)
            count[kind] += 1

        launcher = subprocess.Popen(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        with _session_when_up(port) as session:
            session.declare_subscriber(f"anicov/{team}/**", on_sample)
            started = time.monotonic()
            output, _ = launcher.communicate(timeout=max_time / speed + 600)
            wall = time.monotonic() - started
    if launcher.returncode not in (0, 1):
        raise RuntimeError(f"the team failed ({launcher.returncode}):\n{output[-2000:]}")
    steps = count["step"]
    total = sum(by_type.values())
    return {
        "agents": agents,
        "deltas": deltas,
        "agent_steps": steps,
        "wall_s": wall,
        "bytes_per_agent_step": total / steps,
        "step_message_bytes": by_type["step"] / steps,
        "other_bytes_per_agent_step": (total - by_type["step"]) / steps,
        "by_type": dict(by_type),
        "counts": dict(count),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[4, 30], help="team sizes (default 4 30)")
    parser.add_argument("--max-time", type=float, default=30.0, help="time units each run lasts (default 30)")
    parser.add_argument("--speed", type=float, default=1.0, help="realtime speed (default 1: 10 steps/s)")
    args = parser.parse_args()
    print(f"# {describe_machine()}")
    print(
        "| N | deltas | agent-steps | bytes/agent-step (all) | step message | rest | out/robot at speed 1 | in/robot |"
    )
    print("|---|---|---|---|---|---|---|---|")
    results = []
    for agents in args.n:
        for deltas in ("cells", "event"):
            found = measure(agents, deltas, args.max_time, args.speed)
            results.append(found)
            steps_per_second = 10.0  # 1/dt at speed 1
            out = found["step_message_bytes"] * steps_per_second
            into = found["bytes_per_agent_step"] * agents * steps_per_second - out
            print(
                f"| {agents} | {deltas} | {found['agent_steps']} | {found['bytes_per_agent_step']:.0f} | "
                f"{found['step_message_bytes']:.0f} | {found['other_bytes_per_agent_step']:.0f} | "
                f"{8 * out / 1000:.1f} kbit/s | {8 * into / 1000:.0f} kbit/s |",
                flush=True,
            )
    print(json.dumps(results))


if __name__ == "__main__":
    main()
