"""Separate hosts, for real: the router and coordinator on one network namespace, the robots on another,
joined only by a veth link. Uses the deploy/ Zenoh configs as a user would. Needs root (ip netns)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import uuid

import pytest

from tests.teamrun import ROOT, anicov, limit, write_scenario

ROUTER_ADDRESS = "10.213.77.1"
ROBOT_ADDRESS = "10.213.77.2"


def _ip(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["ip", *args], capture_output=True, text=True)


def _namespaces_available() -> str | None:
    if shutil.which("ip") is None:
        return "the ip command (iproute2) is not installed"
    probe = f"anicovprobe{uuid.uuid4().hex[:6]}"
    made = _ip("netns", "add", probe)
    if made.returncode != 0:
        return f"cannot create network namespaces here: {made.stderr.strip()}"
    _ip("netns", "del", probe)
    return None


@pytest.fixture
def two_hosts():
    reason = _namespaces_available()
    if reason:
        pytest.skip(reason)
    tag = uuid.uuid4().hex[:6]
    router_ns, robot_ns = f"anicov-r{tag}", f"anicov-a{tag}"
    router_if, robot_if = f"vr{tag}", f"va{tag}"
    commands = [
        ("netns", "add", router_ns),
        ("netns", "add", robot_ns),
        ("link", "add", router_if, "type", "veth", "peer", "name", robot_if),
        ("link", "set", router_if, "netns", router_ns),
        ("link", "set", robot_if, "netns", robot_ns),
        ("-n", router_ns, "addr", "add", f"{ROUTER_ADDRESS}/30", "dev", router_if),
        ("-n", robot_ns, "addr", "add", f"{ROBOT_ADDRESS}/30", "dev", robot_if),
        ("-n", router_ns, "link", "set", router_if, "up"),
        ("-n", robot_ns, "link", "set", robot_if, "up"),
        ("-n", router_ns, "link", "set", "lo", "up"),
        ("-n", robot_ns, "link", "set", "lo", "up"),
    ]
    try:
        for command in commands:
            done = _ip(*command)
            assert done.returncode == 0, f"ip {' '.join(command)}: {done.stderr}"
        yield router_ns, robot_ns
    finally:
        _ip("netns", "del", router_ns)
        _ip("netns", "del", robot_ns)


def in_namespace(namespace: str, *args: str) -> list[str]:
    return ["ip", "netns", "exec", namespace, sys.executable, "-m", "anicov.cli", *args]


def test_team_across_two_network_namespaces_equals_engine(tmp_path, two_hosts):
    router_ns, robot_ns = two_hosts
    config = write_scenario(tmp_path / "s.toml", domain=[30.0, 30.0], agents=2, seed=5)
    engine = anicov("run", "--config", str(config), "--out", str(tmp_path / "engine"), "--quiet", "--no-record")
    assert engine.returncode == 0, engine.stderr
    endpoint = f"tcp/{ROUTER_ADDRESS}:7447"
    environment = os.environ | {"PYTHONPATH": str(ROOT)}
    team = ["--team", "hosts", "--config", str(config), "--zenoh-config", "deploy/client.json5", "--connect", endpoint]
    processes = []
    try:
        processes.append(
            subprocess.Popen(
                in_namespace(router_ns, "router", "--zenoh-config", "deploy/router.json5", "--listen", endpoint),
                cwd=ROOT,
                env=environment,
            )
        )
        coordinator = subprocess.Popen(
            in_namespace(router_ns, "coordinator", *team, "--out", str(tmp_path / "team")),
            cwd=ROOT,
            env=environment,
            stderr=subprocess.PIPE,
            text=True,
        )
        processes.append(coordinator)
        for agent in range(2):
            processes.append(
                subprocess.Popen(in_namespace(robot_ns, "agent", *team, "--id", str(agent)), cwd=ROOT, env=environment)
            )
        _, stderr = coordinator.communicate(timeout=limit(240))
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
    for name in ("trajectory.csv", "summary.json"):
        assert (tmp_path / "engine" / name).read_bytes() == (tmp_path / "team" / name).read_bytes()


def test_robot_namespace_cannot_reach_router_without_the_link(two_hosts):
    """The namespaces really are separate hosts: no route but the veth link."""
    _, robot_ns = two_hosts
    assert _ip("-n", robot_ns, "route", "get", "127.0.0.2").returncode == 0  # its own loopback only
    done = _ip("-n", robot_ns, "route", "get", "192.0.2.1")  # TEST-NET-1: no default route exists
    assert done.returncode != 0
