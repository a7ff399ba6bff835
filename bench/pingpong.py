"""Bare Zenoh ping-pong between two processes through a router: the floor under a lockstep step.

``python bench/pingpong.py`` opens a router, starts a ponger process that
echoes every ping, and prints the median and p90 round trip in microseconds.
"""

from __future__ import annotations

import argparse
import json
import queue
import socket
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import zenoh

from protocol.session import team_publisher, zenoh_config


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def pong(endpoint: str) -> None:
    with zenoh.open(zenoh_config("client", connect=[endpoint])) as session:
        publisher = team_publisher(session, "bench/pong")
        done = queue.SimpleQueue()

        def echo(sample: zenoh.Sample) -> None:
            payload = sample.payload.to_bytes()
            if payload == b"stop":
                done.put(True)
            elif done.empty():
                publisher.put(payload)

        session.declare_subscriber("bench/ping", echo)
        session.put("bench/ready", b"1")
        done.get()


def ping(rounds: int, size: int) -> dict[str, float]:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    with zenoh.open(zenoh_config("router", listen=[endpoint])) as router:
        ready: queue.SimpleQueue[bytes] = queue.SimpleQueue()
        router.declare_subscriber("bench/ready", lambda s: ready.put(b""))
        child = subprocess.Popen([sys.executable, __file__, "--pong", endpoint])
        try:
            with zenoh.open(zenoh_config("client", connect=[endpoint])) as session:
                replies: queue.SimpleQueue[bytes] = queue.SimpleQueue()
                session.declare_subscriber("bench/pong", lambda s: replies.put(s.payload.to_bytes()))
                publisher = team_publisher(session, "bench/ping")
                ready.get(timeout=60)
                payload = bytes(size)
                for _ in range(50):  # until routes are in place
                    publisher.put(payload)
                    try:
                        replies.get(timeout=0.5)
                    except queue.Empty:
                        continue
                samples = []
                for _ in range(rounds):
                    started = time.perf_counter()
                    publisher.put(payload)
                    replies.get(timeout=5)
                    samples.append((time.perf_counter() - started) * 1e6)
                publisher.put(b"stop")
        finally:
            child.wait(timeout=10)
    samples.sort()
    return {
        "median_us": statistics.median(samples),
        "p90_us": samples[int(0.9 * len(samples))],
        "rounds": rounds,
        "payload_bytes": size,
    }


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--pong", help=argparse.SUPPRESS)
    parser.add_argument("--rounds", type=int, default=2000)
    parser.add_argument("--size", type=int, default=256)
    args = parser.parse_args()
    if args.pong:
        pong(args.pong)
    else:
        print(json.dumps(ping(args.rounds, args.size)))
