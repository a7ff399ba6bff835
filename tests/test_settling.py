"""protocol.settling on a real Zenoh router on loopback: the two-phase end of a realtime run."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
import zenoh

from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, encode
from protocol.recovery import History
from protocol.replica import MapReplica
from protocol.session import zenoh_config
from protocol.settling import STOPPED, WHOLE, EndBarrier, alive_member, member_of_key, settle
from tests.teamrun import free_port, limit, unique_team, wait_for

LIMITS = Limits(rows=20, cols=20, agents=3)


@pytest.fixture(scope="module")
def endpoint():
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    router = zenoh.open(zenoh_config("router", listen=[endpoint]))
    yield endpoint
    router.close()


@pytest.fixture
def team(endpoint):
    """Three processes of a fresh team, each with its own session and its alive token."""
    keys = TeamKeys(unique_team())
    sessions = [zenoh.open(zenoh_config(connect=[endpoint])) for _ in range(3)]
    tokens = [session.liveliness().declare_token(keys.alive("agent", agent)) for agent, session in enumerate(sessions)]
    yield keys, sessions, tokens
    for session in sessions:
        session.close()


def step_of(agent: int, seq: int) -> AgentStep:
    pose = (1.0, 2.0, 0.5)
    delta = MapDelta(agent, seq, seq % 10, agent, np.full((2, 2), seq + 1, dtype=np.int64))
    return AgentStep(delta, AgentState(agent, seq, pose, 1.0, 0.1, 0.0, pose))


def never_stopped() -> bool:
    return False


def test_keys_of_the_two_phases_parse_and_malformed_ones_do_not():
    keys = TeamKeys("t")
    assert member_of_key(keys.ending(WHOLE, "agent", 3), "ending") == (WHOLE, ("agent", 3))
    assert member_of_key(keys.ending(STOPPED, "coordinator"), "ending") == (STOPPED, ("coordinator", 0))
    assert member_of_key("anicov/t/ending/whole/agent/x", "ending") is None
    assert member_of_key("anicov/t/alive/agent/3", "ending") is None
    assert alive_member(keys.alive("agent", 7)) == ("agent", 7)
    assert alive_member(keys.alive("logger")) == ("logger", 0)
    assert alive_member("anicov/t/alive/agent/1234567") is None


def test_a_process_waits_for_live_teammates_to_reach_a_phase_and_not_for_one_that_left(team):
    keys, sessions, _ = team
    barriers = [EndBarrier(session, keys, "agent", agent) for agent, session in enumerate(sessions)]
    assert wait_for(lambda: barriers[0].waiting_on(STOPPED, ["agent"]) == {("agent", 1), ("agent", 2)}, timeout=30)
    assert barriers[0].waiting_on(STOPPED, ["coordinator"]) == set()  # nobody of that role is alive
    barriers[1].declare(STOPPED)
    assert wait_for(lambda: barriers[0].waiting_on(STOPPED, ["agent"]) == {("agent", 2)}, timeout=30)
    assert barriers[0].waiting_on(WHOLE, ["agent"]) == {("agent", 1), ("agent", 2)}  # one phase is not the other
    sessions[2].close()  # it dies: its tokens go with its session
    assert barriers[0].wait(STOPPED, ["agent"], time.sleep, never_stopped, limit=limit(30))


def test_a_hung_teammate_is_left_after_the_limit_and_a_stop_ends_the_wait(team):
    keys, sessions, _ = team
    barrier = EndBarrier(sessions[0], keys, "agent", 0)
    assert wait_for(lambda: ("agent", 1) in barrier.waiting_on(WHOLE, ["agent"]), timeout=30)
    began = time.monotonic()
    assert not barrier.wait(WHOLE, ["agent"], time.sleep, never_stopped, limit=0.3)
    assert time.monotonic() - began >= 0.3
    assert not barrier.wait(WHOLE, ["agent"], time.sleep, lambda: True)


def test_settle_fetches_a_stopped_teammates_last_deltas_and_waits_until_it_is_whole(team):
    """Agent 1 published steps 0..9; agent 0's replica got 0..4 only. Once agent 1 has stopped, agent 0 fetches
    5..9 from its history, says it is whole, and leaves only once agent 1 is whole too."""
    keys, sessions, tokens = team
    tokens[2].undeclare()  # a team of two here
    history = History(keys.agent_history(1))
    for seq in range(10):
        history.add(seq, encode(step_of(1, seq)))
    sessions[1].declare_queryable(keys.agent_history(1), history.serve)
    replica = MapReplica(20, 20, 1.0, 1.0)
    for seq in range(5):
        replica.apply(step_of(1, seq).delta)
    handled: list[Received | Membership] = []

    def handle(item: Received | Membership) -> None:
        handled.append(item)
        if isinstance(item, Received):
            replica.apply(item.message.delta)

    mine, theirs = EndBarrier(sessions[0], keys, "agent", 0), EndBarrier(sessions[1], keys, "agent", 1)
    assert wait_for(lambda: mine.waiting_on(STOPPED, ["agent"]) == {("agent", 1)}, timeout=30)
    theirs.declare(STOPPED)
    # Agent 1 says it is whole half a second in: agent 0's settle must still be waiting then.
    theirs_whole_after = time.monotonic() + 0.5
    threading.Timer(0.5, theirs.declare, args=(WHOLE,)).start()
    assert settle(mine, replica, Inbox(LIMITS), handle, [1], never_stopped)
    assert time.monotonic() >= theirs_whole_after
    assert replica.contiguous() == {"1": 9} and len(handled) == 5
    assert wait_for(lambda: theirs.waiting_on(WHOLE, ["agent"]) == set(), timeout=30)  # agent 1 sees ours
