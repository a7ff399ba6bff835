"""The agent's decisions between messages, without a Zenoh session: messages go in as the inbox
would hand them over, and the node's state (replica, step, objective, membership) comes out."""

from __future__ import annotations

import numpy as np
import pytest

from agents.node import AgentNode, AgentOptions
from model.scenario import Scenario
from protocol.inbox import Membership, Received
from protocol.messages import AgentState, AgentStep, MapDelta, Objectives, RunControl, Snapshot, StepGo, encode

MEMBERS = (0, 1, 2, 3)


def node_for(agent: int = 0, scenario: Scenario | None = None, clock: str = "lockstep") -> AgentNode:
    return AgentNode(scenario or Scenario(), AgentOptions("test", agent, clock))


def delta(agent: int, seq: int, value: int = 3, row0: int = 10, col0: int = 20) -> MapDelta:
    return MapDelta(agent, seq, row0, col0, np.full((2, 2), value, dtype=np.int64))


def objectives(step: int, members: tuple[int, ...] = MEMBERS) -> Objectives:
    targets = np.array([[10.0 + 10 * agent, 50.0] for agent in members])
    return Objectives(step, members, targets)


def go(step: int, *deltas: MapDelta, members: tuple[int, ...] = MEMBERS, targets: bool = False) -> Received:
    return Received("go", StepGo(step, members, deltas, objectives(step, members) if targets else None))


def state(agent: int, step: int, next_pose: tuple[float, float, float] = (1.0, 2.0, 0.5)) -> AgentState:
    return AgentState(agent, step, (0.0, 0.0, 0.0), 1.0, 0.0, 0.0, next_pose)


def test_a_step_waits_for_its_go_which_brings_the_targets():
    node = node_for(agent=2)
    assert not node.ready_for_step() and not node.started
    node.handle(go(0, targets=True))
    assert node.started
    assert node.ready_for_step()
    assert node.objective == (30.0, 50.0) and node.last_go == 0
    assert not node.ready_for_step()  # that go is used: the next step needs the next one


def test_a_go_brings_the_teammates_deltas_into_the_replica_but_not_our_own():
    node = node_for(agent=0)
    node.handle(go(0, targets=True))
    assert node.ready_for_step()
    node.step = 1
    node.handle(go(1, delta(0, 0, value=100), delta(1, 0, value=3), delta(2, 0, value=4, row0=50)))
    assert node.ready_for_step()
    assert node.replica.has(1, 0) and node.replica.has(2, 0)
    assert not node.replica.has(0, 0)  # our own delta entered when we made it, not from the go
    assert node.replica.map.coverage[10, 20] == 3 and node.replica.map.coverage[50, 20] == 4


def test_a_go_for_a_step_already_taken_is_ignored():
    node = node_for()
    node.step = 5
    node.handle(go(4, delta(1, 3)))
    assert node.gos == {} and node.started  # it still says the run has begun
    node.handle(go(5, delta(1, 4)))
    assert list(node.gos) == [5]


def test_the_last_go_only_completes_the_map():
    node = node_for(scenario=Scenario(max_time=0.2))  # two steps
    node.handle(go(0, targets=True))
    assert node.ready_for_step()
    node.step = 2
    node.handle(go(2, delta(1, 1)))
    assert not node.ready_for_step()  # no step 2 to take
    assert node.replica.has(1, 1) and node.last_go == 2


def test_a_step_without_any_objective_is_an_error():
    node = node_for(agent=1)
    node.handle(go(0))
    with pytest.raises(RuntimeError, match="no objective"):
        node.ready_for_step()


def test_a_returning_member_is_skipped_over_the_steps_it_missed():
    node = node_for(agent=0)
    node.handle(go(0, members=(0, 1), targets=True))
    assert node.ready_for_step()
    node.step = 1
    node.handle(go(1, delta(1, 0), members=(0, 1, 2)))
    assert node.ready_for_step()
    assert node.replica.has(2, 0) and not node.replica.has(2, 1)  # its steps 0..go−1 will never come
    assert node.replica.gaps() == {}


def test_a_fresh_agent_is_admitted_by_the_first_go_or_objectives():
    node = node_for()
    assert not node.admitted()
    node.handle(Received("objectives", objectives(0)))
    assert node.admitted() and node.objective == (10.0, 50.0)


def test_a_rejoining_agent_is_admitted_only_by_a_go_that_lists_it():
    node = node_for(agent=3)
    node.rejoining = True
    node.step = 4
    node.handle(go(5, delta(1, 4), members=(0, 1, 2)))
    assert not node.admitted()
    node.handle(go(6, delta(1, 5), members=MEMBERS, targets=True))
    assert node.admitted() and not node.rejoining
    assert node.step == 6 and list(node.gos) == [6]
    assert node.replica.has(1, 4)  # the earlier go only completed the map
    assert node.replica.has(3, 5) and not node.replica.has(3, 6)  # our steps before 6 will never come
    assert node.members_seen == set(MEMBERS)
    assert node.ready_for_step() and node.objective == (40.0, 50.0)


def test_the_end_of_the_run_is_a_done_or_an_abort_not_a_status():
    node = node_for()
    node.handle(Received("control", RunControl("status", 3)))
    assert node.finished is None
    node.handle(Received("control", RunControl("done", 7, True, 0.0)))
    assert node.finished is not None and node.finished.kind == "done" and node.finished.step == 7


def test_a_lost_last_go_is_noticed_only_after_a_done():
    node = node_for()
    node.last_go = 6
    node.handle(Received("control", RunControl("abort", 7)))
    assert not node.lost_last_go()
    node.handle(Received("control", RunControl("done", 7, True, 0.0)))
    assert node.lost_last_go()
    node.step = 7
    node.handle(go(7, delta(1, 6)))
    assert not node.lost_last_go()
    node.apply_remaining_gos()
    assert node.replica.has(1, 6) and node.gos == {}


def test_teammates_leaving_are_noted_until_the_run_is_over():
    node = node_for(agent=0)
    for agent in (0, 1, 2):
        node.handle(Membership(agent, True))
    assert node.teammates == {1, 2}  # never itself
    node.handle(Membership(1, False))
    node.handle(Membership(3, False))  # never seen: nothing to note
    assert node.teammates == {2} and node.teammates_left == [1]
    node.handle(Membership(1, True))
    assert node.teammates == {1, 2}
    node.handle(Received("control", RunControl("done", 7, True, 0.0)))
    node.handle(Membership(2, False))  # teammates leave as they finish
    assert node.teammates == {1} and node.teammates_left == [1]


def test_realtime_teammates_steps_enter_the_replica_and_the_relay_but_not_our_echo():
    node = node_for(agent=0, clock="realtime")
    node.handle(Received("step/1", AgentStep(delta(1, 0), state(1, 0)), b"payload"))
    node.handle(Received("step/0", AgentStep(delta(0, 0), state(0, 0))))
    assert node.replica.has(1, 0) and not node.replica.has(0, 0)
    assert node.relay._steps[1].at([0]) == [b"payload"] and 0 not in node.relay._steps


def test_a_restarted_agent_continues_after_its_last_step_anyone_holds():
    node = node_for(agent=0)
    coverage = np.zeros((100, 100), dtype=np.int64)
    coverage[10:12, 20:22] = 3
    snapshot = Snapshot(coverage, {0: (4, (6,)), 1: (2, ())}, {0: (5.0, 6.0, 0.25)})
    assert node.load_snapshot(snapshot) == 5  # the relays are asked from our first missing step
    assert node.step == 7 and node.replica.has(1, 2) and node.replica.map.coverage[10, 20] == 3
    node.inbox.deliver("relay/1", encode(AgentStep(delta(0, 7, row0=40), state(0, 7, (7.0, 8.0, 0.5)))), relayed=0)
    node.inbox.deliver("go/history", encode(StepGo(9, MEMBERS, ())))
    node.finish_resume(snapshot.poses[0])
    assert node.step == 8 and node.replica.has(0, 7)
    assert node.robot.pose() == (7.0, 8.0, 0.5)
    assert list(node.gos) == [9]  # anything else queued is handled as usual


def test_a_restarted_agent_without_relayed_steps_starts_from_the_snapshot_pose():
    node = node_for(agent=0)
    snapshot = Snapshot(np.zeros((100, 100), dtype=np.int64), {0: (4, ())}, {0: (5.0, 6.0, 0.25)})
    assert node.load_snapshot(snapshot) == 5
    node.finish_resume(snapshot.poses[0])
    assert node.step == 5 and node.robot.pose() == (5.0, 6.0, 0.25)


def test_a_snapshot_without_our_agent_is_a_fresh_run():
    node = node_for(agent=2)
    start = node.robot.pose()
    assert node.load_snapshot(Snapshot(np.ones((100, 100), dtype=np.int64), {0: (4, ())})) is None
    assert node.step == 0 and node.robot.pose() == start
    assert node.replica.map.coverage.sum() == 0


def test_a_control_step_covers_our_own_replica_and_moves_the_robot():
    node = node_for(agent=1)
    node.handle(go(0, targets=True))
    assert node.ready_for_step()
    before = node.robot.pose()
    made, said = node.control_step()
    assert (made.agent, made.seq) == (1, 0) and node.replica.has(1, 0)
    assert node.replica.map.coverage.sum() == made.ticks.sum() > 0
    assert said.pose == before and said.next_pose == node.robot.pose() != before
    assert node.step == 1
    counts = node.counts()
    assert counts["steps"] == 1 and counts["teammates_left"] == [] and counts["applied"] == {"1": 0}


def test_a_teammates_hello_tells_where_its_robot_really_is():
    node = node_for(agent=0, clock="realtime")
    hello = AgentState(2, -1, (40.0, 60.0, 1.0), 0.0, 0.0, 0.0, (40.0, 60.0, 1.0))
    node.handle(Received("agent", hello))
    assert tuple(node.poses[2]) == (40.0, 60.0, 1.0) and tuple(node.positions[2]) == (40.0, 60.0)
    node.handle(Received("agent", AgentState(0, -1, (1.0, 1.0, 0.0), 0.0, 0.0, 0.0, (1.0, 1.0, 0.0))))
    assert tuple(node.poses[0]) != (1.0, 1.0, 0.0)  # our own echo is not a teammate


def test_teammates_done_for_good_are_parked_for_the_filter_and_nothing_else_changes():
    """Realtime: a teammate whose run is over (its 'stopped' token, protocol.settling) stands still; the filter
    keeps it as a body instead of a pose growing old, which stopped a robot near it for up to the barrier's
    limit. Ids outside the team, and our own, are ignored."""
    from model.safety.safety import PARKED, TEAMMATE

    node = node_for(agent=0, clock="realtime")
    node.park({0, 2, 99})
    assert node.kinds.tolist() == [TEAMMATE, TEAMMATE, PARKED, TEAMMATE]
