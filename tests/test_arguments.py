"""The shared command-line arguments: one meaning for a flag in every command, bad values named."""

from __future__ import annotations

import argparse

import pytest

from agents import command as agent_command
from coordinator import command as coordinator_command
from logger import command as logger_command
from model.scenario import ScenarioError
from runtime.arguments import add_process_arguments, add_scenario_arguments, scenario_from_arguments


def parse(add, *argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add(parser)
    return parser.parse_args(list(argv))


def test_no_config_means_the_papers_scenario_with_the_overrides_applied():
    scenario = scenario_from_arguments(parse(add_scenario_arguments, "--n", "7", "--seed", "11"))
    assert (scenario.agents, scenario.seed, scenario.domain, scenario.range) == (7, 11, (100.0, 100.0), 20.0)


def test_a_bad_override_names_its_key():
    with pytest.raises(ScenarioError, match="'agents'"):
        scenario_from_arguments(parse(add_scenario_arguments, "--n", "0"))


def test_a_speed_that_is_not_positive_is_refused_by_name():
    with pytest.raises(ScenarioError, match=r"--speed: expected a positive number, got 0\.0"):
        scenario_from_arguments(parse(add_process_arguments, "--clock", "realtime", "--speed", "0"))


def test_a_team_on_the_bus_cannot_ask_for_the_zigzag_pilot():
    with pytest.raises(ScenarioError, match="'controller': 'zigzag' flies paths planned once for the team"):
        scenario_from_arguments(parse(add_process_arguments, "--controller", "zigzag"))
    assert scenario_from_arguments(parse(add_scenario_arguments, "--controller", "zigzag")).controller == "zigzag"


@pytest.mark.parametrize("part", [agent_command, coordinator_command, logger_command])
def test_every_process_takes_the_same_team_and_bus_flags(part):
    extra = ["--id", "1"] if part is agent_command else []
    args = parse(part.add_arguments, *extra, "--team", "blue", "--connect", "tcp/10.0.0.1:7447", "--mode", "peer")
    assert (args.team, args.connect, args.mode, args.clock, args.speed) == (
        "blue",
        ["tcp/10.0.0.1:7447"],
        "peer",
        "lockstep",
        10.0,
    )


def test_a_team_without_a_coordinator_needs_local_planning_and_the_wall_clock(tmp_path):
    local = tmp_path / "local.toml"
    local.write_text('planning = "local"\n')
    with pytest.raises(ScenarioError, match="--no-coordinator: scenario key 'planning' must be \"local\""):
        scenario_from_arguments(parse(add_process_arguments, "--no-coordinator", "--clock", "realtime"))
    with pytest.raises(ScenarioError, match="--no-coordinator: expected --clock realtime, got lockstep"):
        scenario_from_arguments(parse(add_process_arguments, "--no-coordinator", "--config", str(local)))
    args = parse(add_process_arguments, "--no-coordinator", "--config", str(local), "--clock", "realtime")
    assert scenario_from_arguments(args).planning == "local"
