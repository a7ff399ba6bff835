"""Issue 12 over a lossy bus: a realtime team of 8 robots of radius 1 over Zenoh, 10 % of messages
dropped at every receiver, 10 runs (seeds 0-9), speed 5: no two robots ever closer than 2r. Slow (6-8 minutes):
``./go test -m slow -k realtime_safety``; the figures of the last run are in docs/safety.md.
The separation is taken on the wall clock (each state is stamped), not by step index."""

from __future__ import annotations

import json

import pytest

from tests.teamrun import launcher_command, processes_of, run, unique_team, write_scenario

RUNS = 10


@pytest.mark.slow
def test_realtime_safety_with_message_loss(tmp_path):
    config = write_scenario(tmp_path / "s.toml", domain=[50.0, 50.0], agents=8, robot_radius=1.0)
    figures = []
    for seed in range(RUNS):
        team, out = unique_team(), tmp_path / f"run{seed}"
        launched = run(
            launcher_command(
                "--config",
                str(config),
                "--seed",
                str(seed),
                "--clock",
                "realtime",
                # Speed 5: at 10 this VM's 2 cores cannot keep 8 agents and a coordinator on their clock
                # (measured 2026-12-02: 73 - 88 % of agent-steps late, before and after the event form;
                # one run with events and loss had not completed after 300 s). Late steps hold robots
                # still, so the run stalls; at 5, 31 % late and it completes (115.4 against 84.3 in process).
                "--speed",
                "5",
                "--drop-rate",
                "0.1",
                "--no-record",
                "--out",
                str(out),
                team=team,
            ),
            timeout=300,
        )
        assert launched.returncode in (0, 1), launched.stderr + launched.stdout
        summary = json.loads((out / "summary.json").read_text())
        figures.append(
            (
                seed,
                summary["completed"],
                summary["min_separation"],
                summary["filter_active_fraction"],
                summary["late_steps"],
            )
        )
        assert processes_of(team) == []
    print("seed, completed, min separation, filter active, late steps:", figures)
    assert all(separation >= 2.0 for _, _, separation, _, _ in figures), figures
