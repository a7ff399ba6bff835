"""The coordinator's side of the bus: what it subscribes to, serves and publishes, declared once.

Subscribers feed the node's inbox; queryables serve the map snapshot, the history of gos (and, in
realtime, the relay of the agents' steps); every payload sent is counted in ``node.bytes_sent``.
"""

from __future__ import annotations

from dataclasses import dataclass

import zenoh

from coordinator.node import Coordinator
from protocol.agreement import digest_of, serve_digest
from protocol.keys import TeamKeys
from protocol.messages import Message, RunControl, StepGo, encode
from protocol.recovery import History
from protocol.session import team_publisher
from protocol.settling import EndBarrier


@dataclass
class CoordinatorBus:
    session: zenoh.Session
    keys: TeamKeys
    node: Coordinator
    objectives: zenoh.Publisher
    go: zenoh.Publisher
    go_history: History
    control: zenoh.Publisher
    status: zenoh.Publisher
    token: zenoh.LivelinessToken
    barrier: EndBarrier | None  # realtime: the run's end waits for the agents to stop (protocol.settling)

    @classmethod
    def declare(cls, session: zenoh.Session, node: Coordinator) -> CoordinatorBus:
        keys = node.keys
        session.declare_subscriber(keys.all_steps, node.inbox.on_sample)
        session.liveliness().declare_subscriber(keys.alive_agents, node.inbox.on_liveliness, history=True)
        session.declare_queryable(keys.snapshot, lambda query: query.reply(keys.snapshot, node.snapshot_payload()))
        serve_digest(session, keys.scenario, digest_of(node.scenario))  # processes check they run what it runs
        objectives = team_publisher(session, keys.objectives)
        go = team_publisher(session, keys.go)
        go_history = History(keys.go_history)
        session.declare_queryable(keys.go_history, go_history.serve)
        if not node.lockstep:
            session.declare_queryable(keys.coordinator_relay, node.relay.serve)
        control = team_publisher(session, keys.control)
        status = team_publisher(session, keys.status)
        token = session.liveliness().declare_token(keys.alive("coordinator"))
        barrier = None if node.lockstep else EndBarrier(session, keys, "coordinator", 0)
        return cls(session, keys, node, objectives, go, go_history, control, status, token, barrier)

    def traffic(self) -> tuple[int, int]:
        """Payload bytes out (published, and the gos served again) and in, so far."""
        return self.node.bytes_sent + self.go_history.bytes_served, self.node.inbox.bytes_received

    def publish(self, publisher: zenoh.Publisher, message: Message | bytes) -> None:
        payload = message if isinstance(message, bytes) else encode(message)
        self.node.bytes_sent += len(payload)
        publisher.put(payload)

    def publish_go(self, go: StepGo) -> None:
        """A lockstep go, kept in the history for whoever lost it."""
        payload = encode(go)
        self.go_history.add(go.step, payload)
        self.publish(self.go, payload)

    def announce(self, control: RunControl) -> None:
        self.publish(self.control, control)
