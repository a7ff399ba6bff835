"""The messaging floor under a lockstep step: the step's exchange with no work in it.

A lockstep step is one fan-out and one fan-in: the coordinator publishes a go
(about 10 kB at N = 4: every member's previous delta and state) and waits for
one step message (about 3 kB) from each of N agent processes, which publish
theirs as soon as the go arrives. Here the agents echo at once, computing
nothing, as Zenoh peers over loopback exactly as ``launch_team.py`` connects
them. Beside it, the 1:1 round trip of the same transport (N = 1, 256 bytes).
``python bench/fanout.py`` prints JSON; ``bench/bench_team.py`` reports it.
"""

from __future__ import annotations

import argparse
import json
import queue
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import zenoh

from bench.pingpong import free_port
from protocol.session import team_publisher, zenoh_config


def peer_config(router: str) -> zenoh.Config:
    return zenoh_config("peer", connect=[router], listen=["tcp/127.0.0.1:0"])


def echo(router: str, ident: int, reply_bytes: int, handoff: bool) -> None:
    """An agent without work: answer every go with a step message of ``reply_bytes``, from Zenoh's
    delivery thread, or (``handoff``) from the main thread, as the agent process does."""
    with zenoh.open(peer_config(router)) as session:
        publisher = team_publisher(session, f"bench/step/{ident}")
        inbox: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        reply = bytes(reply_bytes)

        def on_go(sample: zenoh.Sample) -> None:
            payload = sample.payload.to_bytes()
            if handoff or payload == b"stop":
                inbox.put(payload)
            else:
                publisher.put(payload[:8] + reply)

        session.declare_subscriber("bench/go", on_go)
        token = session.liveliness().declare_token(f"bench/ready/{ident}")  # noqa: F841 (undeclared when dropped)
        while True:
            try:
                payload = inbox.get(timeout=0.05)
            except queue.Empty:
                continue
            if payload == b"stop":
                break
            publisher.put(payload[:8] + reply)


def fan_out(agents: int, rounds: int, go_bytes: int, reply_bytes: int, handoff: bool = False) -> dict[str, float]:
    """Median and p90 time of one go to ``agents`` echo processes and all their replies back, in µs."""
    router_endpoint = f"tcp/127.0.0.1:{free_port()}"
    with zenoh.open(zenoh_config("router", listen=[router_endpoint])):  # where the peers meet
        children = [
            subprocess.Popen(
                [sys.executable, __file__, "--echo", router_endpoint, str(i), str(reply_bytes), str(int(handoff))]
            )
            for i in range(agents)
        ]
        try:
            with zenoh.open(peer_config(router_endpoint)) as session:
                replies: queue.SimpleQueue[bytes] = queue.SimpleQueue()
                session.declare_subscriber("bench/step/*", lambda s: replies.put(s.payload.to_bytes()[:8]))
                publisher = team_publisher(session, "bench/go")
                deadline = time.monotonic() + 60
                while len([r for r in session.liveliness().get("bench/ready/*", timeout=1) if r.ok]) < agents:
                    if time.monotonic() > deadline:
                        raise RuntimeError("echo processes did not come up")
                    time.sleep(0.1)
                samples = []
                for index in range(-200, rounds):  # 200 rounds first, until every route is in place
                    tag = index.to_bytes(8, "little", signed=True)
                    started = time.perf_counter()
                    publisher.put(tag + bytes(go_bytes - 8))
                    received = 0
                    while received < agents:
                        try:
                            if replies.get(timeout=1.0) == tag:
                                received += 1
                        except queue.Empty:
                            break  # a go lost while routes were forming: count it as a warm-up
                    if index >= 0:
                        samples.append((time.perf_counter() - started) * 1e6)
                publisher.put(b"stop")
        finally:
            for child in children:
                try:
                    child.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    child.kill()
    samples.sort()
    return {
        "agents": agents,
        "median_us": statistics.median(samples),
        "p90_us": samples[int(0.9 * len(samples))],
        "rounds": rounds,
        "go_bytes": go_bytes,
        "reply_bytes": reply_bytes,
        "handoff": handoff,
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--echo", nargs=4, help=argparse.SUPPRESS)
    parser.add_argument("--rounds", type=int, default=2000)
    args = parser.parse_args()
    if args.echo:
        echo(args.echo[0], int(args.echo[1]), int(args.echo[2]), bool(int(args.echo[3])))
    else:
        print(json.dumps(fan_out(1, args.rounds, 256, 256)))
        print(json.dumps(fan_out(4, args.rounds, 10_700, 3_070)))  # echoed from Zenoh's thread
        print(json.dumps(fan_out(4, args.rounds, 10_700, 3_070, handoff=True)))  # from the main thread
