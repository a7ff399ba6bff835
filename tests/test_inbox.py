"""protocol.inbox: what it rejects and counts before anything reaches a process's main thread."""

from __future__ import annotations

from protocol.inbox import Inbox
from protocol.messages import RunControl, Traffic, encode
from tests.test_recovery import LIMITS, agent_step, delta, drain


def test_a_relay_may_answer_only_with_a_step_of_the_agent_asked_about():
    inbox = Inbox(LIMITS)
    inbox.deliver("anicov/t/agent/2/relay", encode(agent_step(1, 0)), relayed=0)  # another agent's step
    inbox.deliver("anicov/t/agent/2/relay", encode(delta(0, 0)), relayed=0)  # not a step
    inbox.deliver("anicov/t/agent/2/relay", encode(RunControl("done", 5, True, 0.0)), relayed=0)
    assert drain(inbox) == []
    assert inbox.counts()["rejected.wrong-relay"] == 3
    inbox.deliver("anicov/t/agent/2/relay", encode(agent_step(0, 0)), relayed=0)
    assert [item.message.agent for item in drain(inbox)] == [0]


def test_the_inbox_rejects_a_message_published_on_another_agents_key():
    inbox = Inbox(LIMITS)
    inbox.deliver("anicov/t/agent/2/delta", encode(delta(1, 0)))
    assert drain(inbox) == []
    assert inbox.counts()["rejected.wrong-sender"] == 1


def test_a_traffic_report_must_come_on_its_own_processes_key():
    inbox = Inbox(LIMITS)
    inbox.deliver("anicov/t/traffic/agent/2", encode(Traffic("agent", 1, 1.0, 10, 20)))
    inbox.deliver("anicov/t/traffic/coordinator/0", encode(Traffic("agent", 0, 1.0, 10, 20)))
    assert drain(inbox) == []
    assert inbox.counts()["rejected.wrong-sender"] == 2
    inbox.deliver("anicov/t/traffic/agent/1", encode(Traffic("agent", 1, 1.0, 10, 20)))
    assert [item.message.ident for item in drain(inbox)] == [1]


def test_the_drop_hook_drops_about_the_configured_fraction_and_counts_it():
    inbox = Inbox(LIMITS, drop_rate=0.25, seed=7)

    class FakeSample:  # the hook is the inbox's own logic; what delivered the sample does not matter
        key_expr = "anicov/t/agent/1/delta"

        class payload:  # mirrors zenoh.Sample.payload
            @staticmethod
            def to_bytes() -> bytes:
                return encode(delta(1, 0))

    for _ in range(4000):
        inbox.on_sample(FakeSample)  # type: ignore[arg-type]
    assert 800 < inbox.counts()["dropped"] < 1200
    assert inbox.counts()["dropped"] + inbox.counts()["accepted"] == 4000
