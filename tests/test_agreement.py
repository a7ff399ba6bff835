"""protocol.agreement: a process joins only a run of its own scenario and map, over real Zenoh."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from model.scenario import load_scenario, validate
from protocol.agreement import ScenarioMismatch, check_agreement, digest_of
from tests.conftest import write_map
from tests.teamrun import ROOT, anicov_command, free_port, limit, unique_team, write_scenario


def _walled_map(folder, name: str, door: int = 10):
    occupied = np.zeros((30, 30), dtype=bool)
    occupied[15, :] = True
    occupied[15, door : door + 4] = False
    return write_map(folder, name, occupied)


def test_the_digest_follows_the_maps_content_not_its_path(tmp_path):
    for folder in ("a", "b"):
        (tmp_path / folder).mkdir()
        _walled_map(tmp_path / folder, "room")
    first = validate({"map": "room.yaml", "agents": 2}, tmp_path / "a")
    second = validate({"map": "room.yaml", "agents": 2}, tmp_path / "b")
    assert first.map != second.map and digest_of(first) == digest_of(second)
    assert digest_of(first).map_sha256 and digest_of(first).scenario != digest_of(first.with_overrides(seed=1)).scenario


def test_a_different_map_or_scenario_is_refused_with_both_digests_named(tmp_path):
    for folder, door in (("a", 10), ("b", 20)):
        (tmp_path / folder).mkdir()
        _walled_map(tmp_path / folder, "room", door)
    mine = validate({"map": "room.yaml", "agents": 2}, tmp_path / "a")
    theirs = validate({"map": "room.yaml", "agents": 2}, tmp_path / "b")
    with pytest.raises(ScenarioMismatch, match=r"room.yaml has sha256 [0-9a-f]{16}\.\.\., the coordinator's map has"):
        check_agreement(digest_of(mine), digest_of(theirs), mine)
    with pytest.raises(ScenarioMismatch, match=r"scenario digest .* differs .* \(--n, --seed, --controller\)"):
        check_agreement(digest_of(mine), digest_of(mine.with_overrides(seed=4)), mine)
    check_agreement(digest_of(load_scenario(ROOT / "scenarios" / "paper.toml")), digest_of(validate({})), mine)


def test_an_agent_with_another_map_refuses_to_join_the_coordinators_run(tmp_path):
    for folder, door in (("a", 10), ("b", 20)):
        (tmp_path / folder).mkdir()
        _walled_map(tmp_path / folder, "room", door)
        write_scenario(tmp_path / folder / "s.toml", map="room.yaml", agents=1, robot_radius=0.4)
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    team = ["--team", unique_team(), "--connect", endpoint]
    router = subprocess.Popen(anicov_command("router", "--listen", endpoint), cwd=ROOT)
    coordinator = subprocess.Popen(
        anicov_command(
            "coordinator", *team, "--config", str(tmp_path / "a" / "s.toml"), "--out", str(tmp_path / "run")
        ),
        cwd=ROOT,
    )
    try:
        agent = subprocess.run(
            anicov_command("agent", *team, "--config", str(tmp_path / "b" / "s.toml"), "--id", "0"),
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=limit(120),
        )
        assert agent.returncode == 2, agent.stderr
        assert "agent 0 refuses to join" in agent.stderr and "the coordinator's map has" in agent.stderr
        assert coordinator.poll() is None  # the coordinator is still waiting for a robot of its own run
    finally:
        for process in (coordinator, router):
            process.terminate()
            process.wait(timeout=limit(60))
