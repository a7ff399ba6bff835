"""protocol.recovery against a real Zenoh router on loopback: histories, gap filling, relays, the loss timer."""

from __future__ import annotations

import numpy as np
import pytest
import zenoh

from protocol.inbox import Inbox, Received
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, RunControl, encode
from protocol.recovery import END_ONLY, History, LossTimer, Relay, fetch, fill_gaps
from protocol.replica import MapReplica
from protocol.session import zenoh_config
from tests.teamrun import free_port, limit, unique_team, wait_for

LIMITS = Limits(rows=20, cols=20, agents=3)
ANSWERED = limit(30)
"""A query's outer limit: Zenoh ends it when every queryable has answered (at once here), so a generous
one costs nothing, and a reply that is due is never cut off by a busy machine, nor an undue one missed."""


def delta(agent: int, seq: int) -> MapDelta:
    return MapDelta(agent, seq, seq % 10, agent, np.full((2, 2), seq + 1, dtype=np.int64))


@pytest.fixture(scope="module")
def sessions():
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    router = zenoh.open(zenoh_config("router", listen=[endpoint]))
    server = zenoh.open(zenoh_config(connect=[endpoint]))
    asker = zenoh.open(zenoh_config(connect=[endpoint]))
    yield server, asker
    for session in (asker, server, router):
        session.close()


@pytest.fixture
def team_history(sessions):
    """Agent 1 of a fresh team has published steps 0..49; its history serves them."""
    server, asker = sessions
    keys = TeamKeys(unique_team())
    history = History(keys.agent_history(1))
    for seq in range(50):
        history.add(seq, encode(delta(1, seq)))
    queryable = server.declare_queryable(keys.agent_history(1), history.serve)
    # The declaration reaches the router asynchronously: wait until it answers.
    assert wait_for(lambda: fetch(asker, keys.agent_history(1), Inbox(LIMITS), steps=[0]) == 1, timeout=60)
    yield keys, history, asker
    queryable.undeclare()


def drain(inbox: Inbox) -> list[Received]:
    items = []
    while (item := inbox.get(timeout=0)) is not None:
        items.append(item)
    return items


def test_a_history_answers_ranges_single_steps_and_wildcard_queries_on_its_own_key(team_history):
    keys, _, asker = team_history
    inbox = Inbox(LIMITS)
    assert fetch(asker, keys.agent_history(1), inbox, first=10, last=12, timeout=ANSWERED) == 3
    assert fetch(asker, keys.agent_history(1), inbox, steps=[3, 40, 40, 77], timeout=ANSWERED) == 2  # 77: never sent
    assert fetch(asker, keys.all_histories, inbox, first=48, timeout=ANSWERED) == 2  # asked with a wildcard
    items = drain(inbox)
    assert [item.message.seq for item in items] == [10, 11, 12, 3, 40, 48, 49]
    assert {item.key for item in items} == {keys.agent_history(1)}  # so the sender check applies
    assert inbox.counts()["recovered"] == 7 and inbox.counts()["rejected"] == 0


def test_a_malformed_history_selector_gets_no_reply(team_history):
    keys, _, asker = team_history
    replies = list(asker.get(f"{keys.agent_history(1)}?from=abc", timeout=ANSWERED))
    assert [reply for reply in replies if reply.ok is not None] == []


def test_the_end_of_the_run_comes_with_every_history_reply(team_history):
    """What a realtime agent that lost the end of the run asks for: no step, only the end."""
    keys, history, asker = team_history
    inbox = Inbox(LIMITS)
    assert fetch(asker, keys.agent_history(1), inbox, first=END_ONLY, timeout=ANSWERED) == 0
    history.final = [encode(RunControl("done", 50, True, 0.0))]
    assert fetch(asker, keys.agent_history(1), inbox, first=END_ONLY, timeout=ANSWERED) == 1
    assert [item.message.kind for item in drain(inbox)] == ["done"]


def test_fill_gaps_fetches_known_missing_deltas_and_at_the_end_the_last_ones(team_history):
    keys, _, asker = team_history
    replica = MapReplica(20, 20, 1.0, 1.0)
    for seq in [*range(0, 20), *range(25, 30)]:  # 20..24 lost; 30..49 lost with nothing after them
        replica.apply(delta(1, seq))
    assert replica.gaps() == {1: [20, 21, 22, 23, 24]}
    inbox = Inbox(LIMITS)
    assert fill_gaps(asker, keys, replica, inbox) == 5
    for item in drain(inbox):
        replica.apply(item.message)
    assert replica.gaps() == {} and replica.contiguous() == {"1": 29}
    fill_gaps(asker, keys, replica, inbox, to_the_end=[1, 2])  # agent 2 has no history: nothing, no error
    for item in drain(inbox):
        replica.apply(item.message)
    assert replica.contiguous() == {"1": 49}
    expected = MapReplica(20, 20, 1.0, 1.0)
    for seq in range(50):
        expected.apply(delta(1, seq))
    assert replica.digest() == expected.digest()  # every delta once: the sum of all published


def agent_step(agent: int, seq: int) -> AgentStep:
    pose = (1.0, 2.0, 0.5)
    return AgentStep(delta(agent, seq), AgentState(agent, seq, pose, 1.0, 0.1, 0.0, pose))


def test_a_dead_agents_lost_steps_come_from_a_teammates_relay(sessions):
    """Agent 0 died (no history answers); agent 2 kept its steps 0..9 and relays them."""
    server, asker = sessions
    keys = TeamKeys(unique_team())
    relay = Relay(keys.agent_relay(2))
    for seq in range(10):
        relay.add(0, seq, encode(agent_step(0, seq)))
    queryable = server.declare_queryable(keys.agent_relay(2), relay.serve)
    try:
        assert wait_for(lambda: fetch(asker, keys.all_relays, Inbox(LIMITS), steps=[0], relayed=0) == 1, timeout=60)
        replica = MapReplica(20, 20, 1.0, 1.0)
        for seq in (0, 1, 2, 3, 6):
            replica.apply(delta(0, seq))
        inbox = Inbox(LIMITS)
        assert fill_gaps(asker, keys, replica, inbox) == 2  # 4 and 5, from the relay
        for item in drain(inbox):
            replica.apply(item.message.delta)
        assert replica.gaps() == {} and replica.contiguous() == {"0": 6}
        assert fill_gaps(asker, keys, replica, inbox, to_the_end=[0]) == 3  # 7..9: the last ones
        for item in drain(inbox):
            replica.apply(item.message.delta)
        assert replica.contiguous() == {"0": 9} and inbox.counts()["rejected"] == 0
        expected = MapReplica(20, 20, 1.0, 1.0)
        for seq in range(10):
            expected.apply(delta(0, seq))
        assert replica.digest() == expected.digest()
        # The relay answers only for the agent asked about, and nothing for a malformed or unknown one.
        assert fetch(asker, keys.all_relays, inbox, steps=[4], relayed=1, timeout=ANSWERED) == 0
        asked = asker.get(f"{keys.all_relays}?agent=x;steps=4", timeout=ANSWERED)
        assert [r for r in asked if r.ok is not None] == []
    finally:
        queryable.undeclare()


def test_loss_patience_never_falls_under_its_floor_and_follows_slow_steps():
    timer = LossTimer(floor=0.05, factor=5.0)
    assert timer.patience == 0.05
    timer.typical = 0.1
    assert timer.patience == pytest.approx(0.5)
