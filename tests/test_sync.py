"""protocol.sync: anti-entropy between two robots on real Zenoh sessions (loopback)."""

from __future__ import annotations

import numpy as np
import zenoh

from protocol.inbox import Inbox
from protocol.keys import TeamKeys
from protocol.messages import AgentState, AgentStep, Limits, MapDelta, encode
from protocol.recovery import History, Relay
from protocol.replica import MapReplica
from protocol.session import zenoh_config
from protocol.sync import SyncServer, parse_summary, summary_of, sync_with
from tests.teamrun import free_port, limit, unique_team, wait_for

LIMITS = Limits(rows=20, cols=20, agents=3)
ANSWERED = limit(30)
"""A query's outer limit: Zenoh ends it when every queryable has answered (at once here), so a generous
one costs nothing, and an answer that is due is never cut short by a busy machine."""


def step(agent: int, seq: int) -> AgentStep:
    pose = (1.0, 2.0, 0.5)
    delta = MapDelta(agent, seq, seq % 10, agent, np.full((2, 2), seq + 1, dtype=np.int64))
    return AgentStep(delta, AgentState(agent, seq, pose, 1.0, 0.1, 0.0, pose))


def test_a_summary_is_the_contiguous_count_of_every_agent_and_bad_ones_are_refused():
    replica = MapReplica(20, 20, 1.0, 1.0)
    for seq in (0, 1, 2, 5):
        replica.apply(step(2, seq).delta)
    assert summary_of(replica, 3) == "-1,-1,2"
    assert parse_summary("-1,-1,2", 3) == [-1, -1, 2]
    for bad in ("1,2", "a,b,c", "-2,0,0", None, "1,2,3,4"):
        assert parse_summary(bad, 3) is None


def test_anti_entropy_brings_what_a_teammate_holds_of_every_agent_and_nothing_twice():
    """Robot 1 made steps 0..9 and heard robot 2's 0..4 and robot 0's 0..2; robot 0 heard nothing of 1 and
    has 2's 0..1. One exchange gives robot 0 exactly what it lacked; a second brings nothing."""
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    keys = TeamKeys(unique_team())
    with (
        zenoh.open(zenoh_config("router", listen=[endpoint])),
        zenoh.open(zenoh_config(connect=[endpoint])) as server,
        zenoh.open(zenoh_config(connect=[endpoint])) as asker,
    ):
        history, relay = History(keys.agent_history(1)), Relay(keys.agent_relay(1), capacity=100)
        for seq in range(10):
            history.add(seq, encode(step(1, seq)))
        for agent, last in ((2, 4), (0, 2)):
            for seq in range(last + 1):
                relay.add(agent, seq, encode(step(agent, seq)))
        sync = SyncServer(keys.agent_sync(1), 1, 3, history, relay)
        server.declare_queryable(keys.agent_sync(1), sync.serve)
        replica = MapReplica(20, 20, 1.0, 1.0)
        for seq in range(3):
            replica.apply(step(0, seq).delta)  # our own
        for seq in range(2):
            replica.apply(step(2, seq).delta)
        inbox = Inbox(LIMITS)
        assert wait_for(lambda: sync_with(asker, keys.agent_sync(1), replica, inbox, 3, ANSWERED) > 0, timeout=60)
        received = []
        while (item := inbox.get(timeout=0)) is not None:
            received.append(item)
            assert not item.live  # an answer, not a live step: the receiver's range filter does not apply
            replica.apply(item.message.delta)
        assert sorted((item.message.agent, item.message.delta.seq) for item in received) == [
            *((1, seq) for seq in range(10)),
            *((2, seq) for seq in range(2, 5)),
        ]
        assert replica.contiguous() == {"0": 2, "1": 9, "2": 4} and inbox.counts()["rejected"] == 0
        assert sync_with(asker, keys.agent_sync(1), replica, inbox, 3, ANSWERED) == 0
        # A malformed summary gets no reply.
        assert [r for r in asker.get(f"{keys.agent_sync(1)}?have=x", timeout=ANSWERED) if r.ok is not None] == []
