"""Recovering what the bus lost: each process's history of what it published, relays of teammates'
steps (for when one dies), the loss timer of a lockstep wait, and the fetches that ask them.

Zenoh delivers reliably on a healthy link, but links drop, processes die and restart, and the tests
inject loss on purpose: every receiver can ask again, and the replica applies each (agent, sequence)
once however often it comes.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Iterable

import zenoh

from protocol.decoding import decode
from protocol.inbox import Inbox
from protocol.keys import TeamKeys
from protocol.messages import Limits, ProtocolError, Snapshot
from protocol.replica import MapReplica

log = logging.getLogger("anicov.bus")


END_ONLY = 2**60
"""A history query from this step returns no step, only the end of the run once it is known."""
MAX_STEPS_ASKED = 2000
"""The most single steps one history query may name (a selector must stay a reasonable size)."""


HISTORY_STEPS = 20_000
"""Steps a process keeps of what it published: a whole paper run (a restarted coordinator rebuilds from step 0)."""


class History:
    """The last ``capacity`` steps of what a process published, served to whoever lost some of it.

    Zenoh delivers reliably on a healthy link, but a link can drop, a process
    can be slow to subscribe, and the tests inject loss on purpose: a receiver
    that notices a missing step asks the sender's history queryable for it.
    """

    def __init__(self, key: str, capacity: int = HISTORY_STEPS) -> None:
        self.key = key  # replies name this key, never the query's (which may be a wildcard)
        self.capacity = capacity
        self._items: dict[int, list[bytes]] = {}
        self._lock = threading.Lock()
        self.final: list[bytes] = []  # sent with every reply once set (the end of the run)
        self.bytes_served = 0  # payload bytes of every reply (the process's traffic out)

    def add(self, step: int, *payloads: bytes) -> None:
        with self._lock:
            self._items[step] = list(payloads)
            if len(self._items) > self.capacity:
                del self._items[min(self._items)]

    def between(self, first: int, last: int) -> list[bytes]:
        with self._lock:
            steps = [step for step in self._items if first <= step <= last]
            return [payload for step in sorted(steps) for payload in self._items[step]] + list(self.final)

    def after(self, step: int, limit: int) -> list[bytes]:
        """At most ``limit`` payloads of the steps after ``step``, oldest first (no end of the run)."""
        with self._lock:
            steps = sorted(kept for kept in self._items if kept > step)[: max(limit, 0)]
            return [payload for kept in steps for payload in self._items[kept]][: max(limit, 0)]

    def at(self, steps: list[int]) -> list[bytes]:
        with self._lock:
            return [payload for step in sorted(set(steps)) for payload in self._items.get(step, [])]

    def serve(self, query: zenoh.Query) -> None:
        """Reply to ``?from=K;to=L`` (both optional) or ``?steps=K,L,…`` with every payload kept for
        those steps. A malformed selector gets no reply."""
        parameters = query.parameters
        try:
            if parameters.get("steps"):
                steps = [int(step) for step in str(parameters.get("steps")).split(",")[:MAX_STEPS_ASKED]]
                payloads = self.at(steps)
            else:
                first = int(parameters.get("from") or 0)
                last = int(parameters.get("to") or 2**62)
                payloads = self.between(first, last)
        except ValueError:
            return
        self.bytes_served += sum(len(payload) for payload in payloads)
        for payload in payloads:
            query.reply(self.key, payload)


RELAY_STEPS = 1000
"""Steps of each teammate a realtime process keeps for the relay: many gap checks' worth even at
speed 20 (200 steps a second), a few MB per teammate."""


class Relay:
    """Teammates' recent steps, served in their place once they are gone (realtime).

    A delta lost on the way to one replica is normally fetched from its
    sender's history. If the sender has died meanwhile, that history is gone
    too, but its teammates received the delta: each keeps the last
    ``capacity`` steps of every teammate and answers ``?agent=I;steps=…`` (or
    ``?agent=I;from=K``) on its own relay key. A relayed step is trusted as
    far as the replier is (a team member, authenticated in the secure profile),
    and is asked for only when the agent's own history does not answer.
    """

    def __init__(self, key: str, capacity: int = RELAY_STEPS) -> None:
        self.key = key
        self.capacity = capacity
        self._steps: dict[int, History] = {}

    def add(self, agent: int, seq: int, payload: bytes) -> None:
        history = self._steps.get(agent)
        if history is None:
            history = self._steps.setdefault(agent, History(self.key, self.capacity))
        history.add(seq, payload)

    @property
    def bytes_served(self) -> int:
        """Payload bytes of every reply so far."""
        return sum(history.bytes_served for history in list(self._steps.values()))

    def of(self, agent: int) -> History | None:
        """The kept steps of one teammate, if any."""
        return self._steps.get(agent)

    def serve(self, query: zenoh.Query) -> None:
        """Reply with the kept steps of the agent named by ``?agent=``; anything malformed gets no reply."""
        try:
            agent = int(str(query.parameters.get("agent")))
        except ValueError:
            return
        history = self._steps.get(agent)
        if history is not None:
            history.serve(query)


class LossTimer:
    """When silence means loss: a few times the usual step time, never under a floor.

    A busy machine (thirty processes on two cores) makes every step slow;
    recovering after a fixed short silence would then flood histories with
    queries for messages that are only late.
    """

    def __init__(self, floor: float = 0.05, factor: float = 5.0) -> None:
        self.floor = floor
        self.factor = factor
        self.typical = floor / factor
        self._last = time.monotonic()
        self._clean = True

    def recovering(self) -> None:
        """A fetch was needed: this step's time says nothing about the usual pace."""
        self._clean = False

    def step_done(self) -> None:
        now = time.monotonic()
        if self._clean:  # learning from steps slowed by a loss would feed back into ever longer waits
            self.typical = 0.9 * self.typical + 0.1 * (now - self._last)
        self._last = now
        self._clean = True

    @property
    def patience(self) -> float:
        return max(self.floor, self.factor * self.typical)


def fetch(
    session: zenoh.Session,
    key: str,
    inbox: Inbox,
    first: int = 0,
    last: int | None = None,
    timeout: float = 1.0,
    steps: list[int] | None = None,
    recovery: bool = True,
    relayed: int | None = None,
) -> int:
    """Ask a history queryable for steps first..last, or for the given steps; replies go through the
    inbox's validation (and count as recovered, unless ``recovery`` is False: a routine read).
    ``relayed``: ask relays (``key`` then names them) for that agent's steps."""
    if steps:
        selector = f"{key}?steps={','.join(str(step) for step in steps[:MAX_STEPS_ASKED])}"
    else:
        selector = f"{key}?from={first}" + (f";to={last}" if last is not None else "")
    if relayed is not None:
        selector += f";agent={relayed}"
    count = 0
    # No consolidation: a history replies several payloads on one key (Zenoh would keep only the last).
    for reply in session.get(selector, timeout=timeout, consolidation=zenoh.ConsolidationMode.NONE):
        if reply.ok is not None:
            inbox.deliver(str(reply.ok.key_expr), reply.ok.payload.to_bytes(), recovery, relayed)
            count += 1
    return count


def fetch_snapshot(session: zenoh.Session, key: str, limits: Limits, timeout: float) -> Snapshot | None:
    """The first valid snapshot a snapshot queryable answers with; a malformed one is logged and skipped."""
    for reply in session.get(key, timeout=timeout):
        if reply.ok is None:
            continue
        try:
            snapshot = decode(reply.ok.payload.to_bytes(), limits, expected="snapshot")
        except ProtocolError as error:
            log.warning("snapshot from %s rejected: %s", key, error)
            continue
        assert isinstance(snapshot, Snapshot)
        return snapshot
    return None


GAP_CHECK_PERIOD = 0.5
"""Realtime: seconds between looks for known-missing deltas (a later one of the same agent arrived)."""


def fill_gaps(
    session: zenoh.Session, keys: TeamKeys, replica: MapReplica, inbox: Inbox, to_the_end: Iterable[int] = ()
) -> int:
    """Realtime recovery: ask each sender's history for the deltas this replica knows it lacks.

    A gap shows only once a later delta of the same agent arrives; the last
    deltas of a run have none after them, so at the end ``to_the_end`` names
    the agents whose every delta after the replica's contiguous run is asked
    for. Replies go through the inbox like any message (validated, counted);
    the replica applies each (agent, sequence) once, however often it comes.
    An agent whose history does not answer has died: its teammates' relays
    are asked instead (see :class:`Relay`).
    """

    def from_agent_or_relays(agent: int, first: int = 0, steps: list[int] | None = None) -> int:
        """Its own history; if that does not answer (it died), its teammates' relays."""
        return fetch(session, keys.agent_history(agent), inbox, first=first, steps=steps) or fetch(
            session, keys.all_relays, inbox, first=first, steps=steps, relayed=agent
        )

    asked = 0
    for agent, missing in replica.gaps().items():
        asked += from_agent_or_relays(agent, steps=missing)
    for agent in to_the_end:
        applied = replica.applied.get(agent)
        asked += from_agent_or_relays(agent, first=applied.contiguous + 1 if applied else 0)
    return asked
