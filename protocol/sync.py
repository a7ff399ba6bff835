"""Anti-entropy over the bus (issue 13): the rule of :mod:`model.radio.radio` between processes.

With a limited ``comm_range`` a robot takes only the steps of teammates in range, so replicas diverge.
Every ``SYNC_PERIOD`` seconds a robot sends each teammate it is in contact with its summary, the
count of contiguous steps it holds of every agent (``?have=c0,c1,…``, −1 for none), on that teammate's
``agent/<id>/sync`` queryable; the teammate answers with every step it holds beyond those counts: its
own (from its history) and its teammates' (from its relay, which then keeps a whole run). The asker
validates and applies them like any step (each (agent, seq) once), so after contact it holds everything
its teammate held, directly heard or learnt from others: events travel from robot to robot as robots
meet. A reply is at most ``MAX_SYNC_STEPS`` steps, oldest first; the rest comes at the next exchange.
"""

from __future__ import annotations

import logging

import zenoh

from protocol.inbox import ANY_AGENT, Inbox
from protocol.recovery import History, Relay
from protocol.replica import MapReplica

log = logging.getLogger("anicov.bus")

SYNC_PERIOD = 1.0
"""Wall seconds between two exchanges with one teammate in contact."""
MAX_SYNC_STEPS = 5000
"""The most steps one anti-entropy reply carries (about 430 kB of event steps)."""


def summary_of(replica: MapReplica, agents: int) -> str:
    """What a replica holds, as the ``have`` parameter: contiguous step count − 1 of every agent."""
    return ",".join(
        str(replica.applied[agent].contiguous) if agent in replica.applied else "-1" for agent in range(agents)
    )


def parse_summary(text: object, agents: int) -> list[int] | None:
    """The counts of a ``have`` parameter, or None if it is not one (then no reply is sent)."""
    try:
        counts = [int(item) for item in str(text).split(",")]
    except ValueError:
        return None
    if len(counts) != agents or any(count < -1 for count in counts):
        return None
    return counts


class SyncServer:
    """Answers a teammate's summary with the steps it lacks: ours from our history, others' from the relay."""

    def __init__(self, key: str, me: int, agents: int, history: History, relay: Relay) -> None:
        self.key = key
        self.me = me
        self.agents = agents
        self.history = history
        self.relay = relay
        self.served = 0  # steps sent to teammates
        self.bytes_served = 0  # their payload bytes

    def lacking(self, have: list[int]) -> list[bytes]:
        """Every step we hold that a replica with these counts lacks, oldest first within each agent."""
        payloads: list[bytes] = []
        for agent, contiguous in enumerate(have):
            source = self.history if agent == self.me else self.relay.of(agent)
            if source is not None:
                payloads += source.after(contiguous, MAX_SYNC_STEPS - len(payloads))
            if len(payloads) >= MAX_SYNC_STEPS:
                break
        return payloads

    def serve(self, query: zenoh.Query) -> None:
        have = parse_summary(query.parameters.get("have"), self.agents)
        if have is None:
            return  # malformed: no reply
        payloads = self.lacking(have)
        self.served += len(payloads)
        self.bytes_served += sum(len(payload) for payload in payloads)
        for payload in payloads:
            query.reply(self.key, payload)


def sync_with(
    session: zenoh.Session, key: str, replica: MapReplica, inbox: Inbox, agents: int, timeout: float = 1.0
) -> int:
    """One exchange: send our summary to a teammate's sync queryable (``key``); what it answers goes
    through the inbox's validation as steps of any agent. Returns how many steps came."""
    count = 0
    selector = f"{key}?have={summary_of(replica, agents)}"
    for reply in session.get(selector, timeout=timeout, consolidation=zenoh.ConsolidationMode.NONE):
        if reply.ok is not None:
            inbox.deliver(str(reply.ok.key_expr), reply.ok.payload.to_bytes(), recovery=False, relayed=ANY_AGENT)
            count += 1
    return count
