"""A restarted coordinator rebuilt from the agents' histories, without Zenoh: it must end where a
coordinator that lived the run would be."""

from __future__ import annotations

import numpy as np
import pytest

from coordinator.node import Coordinator, CoordinatorOptions
from coordinator.rebuild import by_step, rebuild, resume_step
from model.controllers.anicov.lane_planner import LanePlanner
from model.paper.coverage_map import CoverageMap
from model.parameters import initial_poses
from tests.test_coordinator_node import SCENARIO, team_steps


def history(steps, last_step_of: dict[int, int]):
    """Deltas and states of each agent up to its last step, as read from its history (any order)."""
    messages = []
    for of_step in reversed(steps):  # order must not matter
        for message in of_step:
            if message.agent in last_step_of and message.state.step <= last_step_of[message.agent]:
                messages += [message.delta, message.state]
    return messages


def test_a_rebuilt_lockstep_coordinator_resumes_at_the_last_step_everyone_published():
    steps = team_steps(SCENARIO, 6)
    node = Coordinator(SCENARIO, CoordinatorOptions("t"))
    resume = rebuild(node, history(steps, {0: 5, 1: 4}), members={0, 1})
    assert resume == 4
    assert node.members == {0, 1}
    assert node.open_step == 4  # still open: its deltas go into the next go
    assert node.step_complete(4)
    assert sorted(node.open_deltas) == [0, 1]
    assert node.held_back and all(delta.seq == 5 for delta in node.held_back)  # agent 0's step 5 waits


def test_the_rebuilt_e_d_and_snapshots_are_those_of_the_run_step_by_step():
    steps = team_steps(SCENARIO, 6)
    node = Coordinator(SCENARIO, CoordinatorOptions("t"))
    resume = rebuild(node, history(steps, {0: 5, 1: 5}), members={0, 1})
    grid = CoverageMap(*SCENARIO.grid_shape, SCENARIO.cell, SCENARIO.lambda_star)
    expected = [grid.domain_error()]
    for of_step in steps[:resume]:
        for message in of_step:
            grid.add(message.delta.row0, message.delta.col0, message.delta.ticks)
        expected.append(grid.domain_error())
    assert node.log.errors == expected
    assert node.log.snapshot_times == [0.0]  # snapshots every 5 time units = 50 steps
    assert node.positions[1] == steps[resume][1].state.next_pose[:2]


def test_a_realtime_coordinator_keeps_no_open_step_after_a_rebuild():
    steps = team_steps(SCENARIO, 3)
    node = Coordinator(SCENARIO, CoordinatorOptions("t", clock="realtime"))
    resume = rebuild(node, history(steps, {0: 2, 1: 2}), members={0, 1})
    assert resume == 2 and node.open_step is None
    assert all(node.replica.has(agent, step) for agent in (0, 1) for step in range(3))


def test_members_without_a_history_are_left_out_and_no_history_at_all_is_an_error():
    steps = team_steps(SCENARIO, 3)
    deltas, states = by_step(history(steps, {0: 2, 1: 2}), members={0})
    assert {delta.agent for of_step in deltas.values() for delta in of_step} == {0}
    assert resume_step(states, {0}) == (2, {0})
    with pytest.raises(RuntimeError, match="no history of agents"):
        resume_step({}, {0, 1})


def test_a_realtime_anicov_coordinator_replays_its_plans_as_a_lockstep_one_does():
    """Issue 36, item 3: anicov's plans build on each other (routes cut once, their progress, patches and
    cleanups, among walls too), so a coordinator restarted in realtime replays every plan step from the
    histories: its planner ends where a lockstep rebuild's (which equals the engine's) does, robots part way
    along their routes, not put back at the routes' starts nor cut afresh."""
    wall = [[14.0, 0.0], [16.0, 0.0], [16.0, 18.0], [14.0, 18.0]]
    scenario = SCENARIO.with_overrides(controller="anicov", robot_radius=0.3, occlusion=True, obstacles=[wall])
    steps = team_steps(scenario, 41)
    planners = {}
    for clock in ("lockstep", "realtime"):
        node = Coordinator(scenario, CoordinatorOptions("t", clock=clock))
        rebuild(node, history(steps, {0: 40, 1: 40}), members={0, 1})
        planners[clock] = node.planner
    assert "plans replayed from the histories to step 40" in node.log.events
    lockstep, realtime = planners["lockstep"], planners["realtime"]
    assert isinstance(realtime, LanePlanner) and realtime.flight is not None  # the flight among walls
    for agent in (0, 1):
        ours, theirs = realtime.routes[agent], lockstep.routes[agent]
        assert np.array_equal(ours.points, theirs.points) and ours.progress == theirs.progress
        assert ours.stops == theirs.stops
    assert realtime.flight.stops_left == lockstep.flight.stops_left and realtime.flight.idle == lockstep.flight.idle
    fresh = LanePlanner(scenario)
    fresh.plan(np.ones(scenario.grid_shape), initial_poses(scenario)[:, :2])
    assert any(realtime.routes[agent].progress > fresh.routes[agent].progress for agent in (0, 1))
