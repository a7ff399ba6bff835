"""The start of a run: wait for every agent's hello, or find the team already running and rebuild it.

A coordinator that finds agents already stepping replaces one that died: it reads the agents'
histories (and, for robots that died before it, a live member's replica) and resumes where the run
is (:mod:`coordinator.rebuild`).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import zenoh

from coordinator.endpoints import CoordinatorBus
from coordinator.node import Coordinator
from coordinator.rebuild import HistoryMessages, rebuild
from protocol.inbox import Membership, Received
from protocol.keys import TeamKeys, agent_of_key
from protocol.messages import AgentState, AgentStep, Limits, Snapshot
from protocol.recovery import fetch, fetch_snapshot
from protocol.session import logger_listens
from runtime.lifecycle import StopFlag, parent_is_gone

log = logging.getLogger("anicov.coordinator")

START_TIMEOUT = 120.0
"""Seconds to wait for every agent's hello before giving up."""
HISTORY_TIMEOUT = 30.0
"""Seconds a restarted coordinator waits for the agents' full histories (a long run has many steps)."""


@dataclass
class Gathering:
    """What the wait for the team found: hellos in the node, or steps of a team already running."""

    running: HistoryMessages = field(default_factory=list)
    logger_ready: bool = True

    def take(self, item: Received | Membership, node: Coordinator) -> None:
        """A step already taken means the team is past its hellos: keep it for the rebuild."""
        if isinstance(item, Received) and isinstance(item.message, AgentStep):
            self.running += [item.message.delta, item.message.state]
        else:
            node.handle(item)


def gather_team(bus: CoordinatorBus, await_logger: bool, stop: StopFlag, parent: int) -> Gathering:
    """Wait until every agent has said hello (its pose at t_0) and, if asked, a logger listens, unless
    the team is already running (then this coordinator replaces one that died)."""
    node, keys, session = bus.node, bus.keys, bus.session
    found = Gathering(logger_ready=not await_logger)
    deadline = time.monotonic() + START_TIMEOUT
    next_look = 0.0
    while not (found.running or stop.stopped) and (
        len(node.positions) < node.scenario.agents or not found.logger_ready
    ):
        if not found.logger_ready:
            found.logger_ready = logger_listens(session, keys.alive("logger"), timeout=0.5)
        if time.monotonic() >= next_look:  # lockstep agents that lost their coordinator wait in silence
            fetch(session, keys.all_histories, node.inbox, first=0, last=0, timeout=0.5)
            next_look = time.monotonic() + 0.5
        item = node.inbox.get(timeout=0.1)
        if item is not None:
            found.take(item, node)
        if parent_is_gone(parent) or time.monotonic() > deadline:
            break
    return found


def resume_running_team(bus: CoordinatorBus, found: Gathering) -> int:
    """Rebuild a running team's run from the agents' histories; return the step it resumes at."""
    node, keys, session = bus.node, bus.keys, bus.session
    # Robots that died before this coordinator started left no history, but their coverage is in
    # every live replica: take one, first (anything in it is then also in the histories below).
    # Any live agent's replica will do (dead ones do not answer).
    snapshot = member_snapshot(session, keys, node.limits, set(range(node.scenario.agents)))
    # Ends when every history has replied in full; live messages keep coming meanwhile,
    # so take only what is queued then: the rest is for the main loop.
    fetch(session, keys.all_histories, node.inbox, first=0, timeout=HISTORY_TIMEOUT)
    for _ in range(node.inbox.queue.qsize()):
        item = node.inbox.get(timeout=0)
        if item is None:
            break
        found.take(item, node)
    # Members: whoever holds a liveliness token now, and whoever answered from its history
    # (only a live process answers; a token may not have reached this new session yet).
    members = alive_agents(session, keys, node.scenario.agents) | node.alive
    members |= {message.agent for message in found.running if isinstance(message, AgentState)}
    step = rebuild(node, found.running, members, snapshot)
    node.log.events.append(f"coordinator resumed at step {step}")
    log.warning("a running team: resumed at step %d from the histories of agents %s", step, sorted(node.members))
    return step


def alive_agents(session: zenoh.Session, keys: TeamKeys, agents: int) -> set[int]:
    """The agents whose liveliness token is declared now (asked, not waited for)."""
    alive = set()
    for reply in session.liveliness().get(keys.alive_agents, timeout=2.0):
        if reply.ok is not None:
            agent = agent_of_key(str(reply.ok.key_expr))
            if agent is not None and 0 <= agent < agents:
                alive.add(agent)
    return alive


def member_snapshot(session: zenoh.Session, keys: TeamKeys, limits: Limits, members: set[int]) -> Snapshot | None:
    """The replica of the first member that answers, or None."""
    for agent in sorted(members):
        snapshot = fetch_snapshot(session, keys.agent_snapshot(agent), limits, timeout=2.0)
        if snapshot is not None:
            return snapshot
    return None
