"""A radio of 1 Mbit/s per robot, for real (issue 13): the router and coordinator in one network
namespace, each robot in its own, joined to the router's bridge by a veth whose both ends are capped
with `tc ... tbf`. A realtime team of 8 completes within 15 % of the same team's time uncapped.
Needs root (ip netns, tc). Slow (two realtime runs of 8 robots): run with -m slow."""

from __future__ import annotations

import json
import os
import subprocess
import uuid

import pytest

from tests.teamrun import ROOT, limit, unique_team, write_scenario
from tests.test_deploy_netns import _ip, _namespaces_available, in_namespace

AGENTS = 8
ROUTER_ADDRESS = "10.213.80.1"
RATE = "1mbit"


def _tc(namespace: str, device: str) -> None:
    done = subprocess.run(
        ["ip", "netns", "exec", namespace, "tc", "qdisc", "add", "dev", device, "root", "tbf",
         "rate", RATE, "burst", "32kbit", "latency", "400ms"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr


@pytest.fixture
def radio_hosts():
    """(router namespace, robot namespaces, cap(): put the tbf on every link)."""
    reason = _namespaces_available()
    if reason:
        pytest.skip(reason)
    tag = uuid.uuid4().hex[:5]
    router_ns = f"anicov-rr{tag}"
    robots = [f"anicov-ra{tag}{i}" for i in range(AGENTS)]
    links = [(f"h{tag}{i}", f"r{tag}{i}") for i in range(AGENTS)]
    commands = [
        ("netns", "add", router_ns),
        ("-n", router_ns, "link", "add", "br0", "type", "bridge"),
        ("-n", router_ns, "addr", "add", f"{ROUTER_ADDRESS}/24", "dev", "br0"),
        ("-n", router_ns, "link", "set", "br0", "up"),
        ("-n", router_ns, "link", "set", "lo", "up"),
    ]
    for i, (robot_ns, (host_if, robot_if)) in enumerate(zip(robots, links, strict=True)):
        commands += [
            ("netns", "add", robot_ns),
            ("link", "add", host_if, "type", "veth", "peer", "name", robot_if),
            ("link", "set", host_if, "netns", router_ns),
            ("link", "set", robot_if, "netns", robot_ns),
            ("-n", router_ns, "link", "set", host_if, "master", "br0"),
            ("-n", router_ns, "link", "set", host_if, "up"),
            ("-n", robot_ns, "addr", "add", f"10.213.80.{i + 2}/24", "dev", robot_if),
            ("-n", robot_ns, "link", "set", robot_if, "up"),
            ("-n", robot_ns, "link", "set", "lo", "up"),
        ]

    def cap() -> None:
        for robot_ns, (host_if, robot_if) in zip(robots, links, strict=True):
            _tc(router_ns, host_if)  # router → robot
            _tc(robot_ns, robot_if)  # robot → router

    try:
        for command in commands:
            done = _ip(*command)
            assert done.returncode == 0, f"ip {' '.join(command)}: {done.stderr}"
        yield router_ns, robots, cap
    finally:
        for namespace in (router_ns, *robots):
            _ip("netns", "del", namespace)


def run_team(tmp_path, name: str, router_ns: str, robots: list[str], config) -> dict:
    """Router and coordinator in the router's namespace, agent i in robots[i]; realtime; the summary."""
    endpoint = f"tcp/{ROUTER_ADDRESS}:7447"
    environment = os.environ | {"PYTHONPATH": str(ROOT)}
    team = ["--team", unique_team(), "--config", str(config), "--clock", "realtime", "--speed", "5",
            "--zenoh-config", "deploy/client.json5", "--connect", endpoint]  # fmt: skip
    out = tmp_path / name
    processes = [
        subprocess.Popen(
            in_namespace(router_ns, "router", "--zenoh-config", "deploy/router.json5", "--listen", endpoint),
            cwd=ROOT, env=environment,
        )
    ]  # fmt: skip
    try:
        coordinator = subprocess.Popen(
            in_namespace(router_ns, "coordinator", *team, "--out", str(out)),
            cwd=ROOT, env=environment, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        processes.append(coordinator)
        for agent, robot_ns in enumerate(robots):
            counts = ["--counts", str(tmp_path / f"{name}-agent-{agent}.json")]
            command = in_namespace(robot_ns, "agent", *team, "--id", str(agent), *counts)
            processes.append(subprocess.Popen(command, cwd=ROOT, env=environment))
        _, stderr = coordinator.communicate(timeout=limit(400))
        assert coordinator.returncode == 0, stderr
        for agent_process in processes[2:]:
            assert agent_process.wait(timeout=limit(60)) == 0
    finally:
        for process in processes:
            if process.poll() is None:
                process.terminate()
                try:
                    process.wait(timeout=limit(30))
                except subprocess.TimeoutExpired:
                    process.kill()
    return json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_eight_robots_on_1_mbit_links_complete_within_15_percent_of_uncapped(tmp_path, radio_hosts):
    router_ns, robots, cap = radio_hosts
    config = write_scenario(tmp_path / "s.toml", domain=[60.0, 60.0], agents=AGENTS, seed=4)
    free = run_team(tmp_path, "uncapped", router_ns, robots, config)
    cap()
    capped = run_team(tmp_path, "capped", router_ns, robots, config)
    assert free["completed"] and capped["completed"]
    received = [json.loads((tmp_path / f"capped-agent-{i}.json").read_text())["bytes_received"] for i in range(AGENTS)]
    print(f"completion uncapped {free['completion_time']}, capped {capped['completion_time']}; bytes in {received}")
    assert capped["completion_time"] <= 1.15 * free["completion_time"]
