"""The coordinator's decisions without Zenoh: closing lockstep steps, gos, membership, the run log."""

from __future__ import annotations

import math

import numpy as np

from coordinator.node import Coordinator, CoordinatorOptions
from model.controllers import law_parameters
from model.paper.coverage_map import CoverageMap
from model.parameters import initial_poses
from model.scenario import Scenario
from model.step import decide_and_sense, move, no_look
from model.world.ground import NO_FIELD, NO_POSITIONS, open_ground
from protocol.inbox import Membership, Received
from protocol.messages import AgentState, AgentStep, MapDelta

OPEN = open_ground()

SCENARIO = Scenario(domain=(30.0, 30.0), agents=2, range=8.0, seed=3)


def hello(agent: int, pose: tuple[float, float, float]) -> Received:
    return Received("", AgentState(agent, -1, pose, 0.0, 0.0, 0.0, pose))


def team_steps(scenario: Scenario, steps: int) -> list[list[AgentStep]]:
    """What each agent publishes at steps 0..steps-1 of a lockstep run toward fixed objectives, computed
    with the model's own functions on one shared map (as the engine does)."""
    grid = CoverageMap(*scenario.grid_shape, scenario.cell, scenario.lambda_star)
    law = law_parameters(scenario, grid)
    poses = [tuple(pose) for pose in initial_poses(scenario)]
    out = []
    for step in range(steps):
        of_step = []
        for agent, (x, y, theta) in enumerate(poses):
            v, omega, e_omega, row0, col0, ticks = decide_and_sense(
                grid.coverage, x, y, theta, 15.0, 15.0, law, OPEN, NO_FIELD, NO_POSITIONS, 0, no_look()
            )
            next_pose = move(x, y, theta, v, omega, law, OPEN)
            delta = MapDelta(agent, step, row0, col0, ticks)
            of_step.append(AgentStep(delta, AgentState(agent, step, (x, y, theta), v, omega, e_omega, next_pose)))
            poses[agent] = next_pose
        for message in of_step:
            grid.add(message.delta.row0, message.delta.col0, message.delta.ticks)
        out.append(of_step)
    return out


def started_coordinator() -> Coordinator:
    node = Coordinator(SCENARIO, CoordinatorOptions("t"))
    for agent, pose in enumerate(initial_poses(SCENARIO)):
        node.handle(hello(agent, tuple(pose)))
    node.members = {0, 1}
    node.closed_states = node.states_by_step.pop(-1, {})
    return node


def test_the_first_go_carries_the_hellos_and_objectives_for_every_member():
    node = started_coordinator()
    go = node.go(0, [])
    assert go.step == 0 and go.members == (0, 1) and go.deltas == ()
    assert [state.agent for state in go.states] == [0, 1]
    assert go.objectives is not None and go.objectives.members == (0, 1)
    assert go.objectives.targets.shape == (2, 2)


def test_a_step_closes_only_when_every_members_delta_and_state_are_in():
    node = started_coordinator()
    steps = team_steps(SCENARIO, 2)
    node.handle(Received("", steps[0][0]))
    assert not node.step_complete(0)
    assert node.missing(0) == [1]
    node.handle(Received("", steps[1][0]))  # agent 0 is a step ahead: held back, not in the map yet
    assert not node.replica.has(0, 1)
    node.handle(Received("", steps[0][1]))
    assert node.step_complete(0) and node.missing(0) == []
    go = node.go(1, node.open_next_step())
    assert [delta.agent for delta in go.deltas] == [0, 1]
    assert all(delta.seq == 0 for delta in go.deltas)
    assert [state.step for state in go.states] == [0, 0]
    assert go.objectives is None  # step 1 is not a replanning step
    assert node.replica.has(0, 1)  # let in once step 1 opened


def test_an_agent_that_leaves_is_dropped_and_the_next_go_replans_for_the_others():
    node = started_coordinator()
    node.handle(Membership(1, alive=False))
    assert node.members == {0}
    assert any("agent 1 left" in event for event in node.log.events)
    go = node.go(3, [])
    assert go.members == (0,)
    assert go.objectives is not None and go.objectives.members == (0,)


def test_a_state_of_a_closed_step_is_kept_for_the_trace_and_the_final_pose():
    node = started_coordinator()
    steps = team_steps(SCENARIO, 2)
    for of_step in steps:
        for message in of_step:
            node.handle(Received("", message))
    result = node.result(2, completed=False, completion_step=2)
    assert result.trace.shape == (3, 2, 6)
    assert result.trace[0, 1, 0] == steps[0][1].state.pose[0]
    assert tuple(result.trace[2, 0, :3]) == steps[1][0].state.next_pose
    assert result.completion_time == math.inf


def test_the_run_log_leaves_nan_where_a_state_was_never_heard():
    node = started_coordinator()
    steps = team_steps(SCENARIO, 1)
    node.handle(Received("", steps[0][0]))  # agent 1's state of step 0 never came
    result = node.result(1, completed=False, completion_step=1)
    assert not np.isnan(result.trace[0, 0]).any()
    assert np.isnan(result.trace[0, 1]).all()


def test_each_agents_last_row_is_where_its_last_heard_step_took_it_so_rows_follow_by_eq_1():
    """Realtime: agent 1's last state heard is of step 0 while the run ends after 3 steps; its last row
    is its pose at t_1 (the end of step 0), not at t_3 (issue 13: a final row one step's travel off)."""
    from coordinator.run_log import RunLog

    log = RunLog(agents=2)
    pose = (1.0, 1.0, 0.0)
    for step in range(4):  # agent 0: one step ahead of the run's 3
        log.record(AgentState(0, step, (1.0 + step, 1.0, 0.0), 1.0, 0.0, 0.0, (2.0 + step, 1.0, 0.0)))
    log.record(AgentState(1, 0, pose, 1.0, 0.0, 0.0, (2.0, 1.0, 0.0)))
    trace = log.result(SCENARIO, 3, completed=True, completion_step=3, final_lack=np.zeros((1, 1))).trace
    assert tuple(trace[1, 1, :3]) == (2.0, 1.0, 0.0) and tuple(trace[1, 1, 3:5]) == (0.0, 0.0)
    assert np.isnan(trace[2:, 1]).all()
    assert tuple(trace[3, 0, :3]) == (4.0, 1.0, 0.0)  # its state of step 3 started there, as step 2 ended


def test_a_delta_of_an_agent_that_left_before_its_step_closed_still_goes_to_everyone():
    """Agent 1's delta of step 0 is in the coordinator's map when agent 1 is found dead (SIGKILL under
    load: its teammates' deltas were late); step 0 closes on agent 0 alone, and the go must carry agent 1's
    delta too, or the coordinator's map alone would hold it."""
    node = started_coordinator()
    steps = team_steps(SCENARIO, 1)
    node.handle(Received("", steps[0][1]))
    node.handle(Membership(1, alive=False))
    node.handle(Received("", steps[0][0]))
    assert node.step_complete(0)
    go = node.go(1, node.open_next_step())
    assert [delta.agent for delta in go.deltas] == [0, 1] and go.members == (0,)
    assert [state.agent for state in go.states] == [0]


def test_a_late_delta_of_a_closed_step_is_dropped_not_applied():
    """Step 0 closed without agent 1 (it left); its delta of step 0 coming now cannot go out in any go,
    so the coordinator must not apply it either."""
    node = started_coordinator()
    steps = team_steps(SCENARIO, 1)
    node.handle(Membership(1, alive=False))
    node.handle(Received("", steps[0][0]))
    node.go(1, node.open_next_step())
    before = node.replica.map.coverage.copy()
    node.handle(Received("", steps[0][1]))
    assert not node.replica.has(1, 0)
    assert np.array_equal(node.replica.map.coverage, before)
    assert any("late delta of agent 1 for closed step 0" in event for event in node.log.events)
