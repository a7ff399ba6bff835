"""The Zenoh side of a process: configuration, and an inbox that decodes, validates and counts.

Zenoh delivers samples on its own threads. The inbox decodes each sample at
once (a bad payload is rejected, logged and counted there, never queued) and
hands good messages to the process's single main thread through a queue, so
the control code never runs concurrently with itself.
"""

from __future__ import annotations

import json
import logging
import queue
import threading
import time
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import zenoh

from protocol.keys import TeamKeys, agent_of_key
from protocol.messages import AgentStep, Limits, Message, ProtocolError, Snapshot, decode
from protocol.replica import MapReplica

log = logging.getLogger("anicov.bus")

DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"


def zenoh_config(
    mode: str = "client",
    connect: list[str] | None = None,
    listen: list[str] | None = None,
    config_file: str | None = None,
) -> zenoh.Config:
    """A Zenoh config: from a JSON5 file if given, else built from flags; multicast scouting off.

    Endpoints are explicit so that parallel teams (and parallel tests) never
    discover each other.
    """
    config = zenoh.Config.from_file(config_file) if config_file else zenoh.Config()
    if not config_file:
        config.insert_json5("mode", json.dumps(mode))
        config.insert_json5("scouting/multicast/enabled", "false")
        # Nothing to discover with multicast off: do not wait for it (a router opens 0.5 s sooner).
        config.insert_json5("scouting/delay", "0")
        # Loopback links of a single host: a lost peer is noticed within the lease.
    if connect:
        config.insert_json5("connect/endpoints", json.dumps(connect))
    if listen:
        config.insert_json5("listen/endpoints", json.dumps(listen))
    return config


class RouterUnreachable(RuntimeError):
    """No session could be opened within the patience given (the router is down, or refuses us)."""


def open_session(config: zenoh.Config, patience: float = 30.0, delay: float = 0.25) -> zenoh.Session:
    """Open a session, retrying while the router is not up yet (a robot may boot before it)."""
    deadline = time.monotonic() + patience
    while True:
        try:
            return zenoh.open(config)
        except zenoh.ZError as error:
            if time.monotonic() >= deadline:
                raise RouterUnreachable(f"no Zenoh session after {patience:.0f} s of retries: {error}") from error
            log.debug("zenoh open failed (%s), retrying", error)
            time.sleep(delay)


def team_publisher(session: zenoh.Session, key: str) -> zenoh.Publisher:
    """A publisher for team traffic: reliable, never dropped under congestion (lockstep would
    wait forever for a dropped delta), and express (sent at once, not batched: a step waits on it)."""
    return session.declare_publisher(
        key,
        congestion_control=zenoh.CongestionControl.BLOCK,
        reliability=zenoh.Reliability.RELIABLE,
        express=True,
    )


@dataclass(frozen=True)
class Received:
    key: str
    message: Message
    payload: bytes = b""  # as it came: a relay keeps teammates' steps to serve them again


MAX_STEPS_ASKED = 2000
"""The most single steps one history query may name (a selector must stay a reasonable size)."""


class History:
    """The last ``capacity`` steps of what a process published, served to whoever lost some of it.

    Zenoh delivers reliably on a healthy link, but a link can drop, a process
    can be slow to subscribe, and the tests inject loss on purpose: a receiver
    that notices a missing step asks the sender's history queryable for it.
    """

    def __init__(self, key: str, capacity: int = 20_000) -> None:
        self.key = key  # replies name this key, never the query's (which may be a wildcard)
        self.capacity = capacity
        self._items: dict[int, list[bytes]] = {}
        self._lock = threading.Lock()
        self.final: list[bytes] = []  # sent with every reply once set (the end of the run)

    def add(self, step: int, *payloads: bytes) -> None:
        with self._lock:
            self._items[step] = list(payloads)
            if len(self._items) > self.capacity:
                del self._items[min(self._items)]

    def between(self, first: int, last: int) -> list[bytes]:
        with self._lock:
            steps = [step for step in self._items if first <= step <= last]
            return [payload for step in sorted(steps) for payload in self._items[step]] + list(self.final)

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


@dataclass(frozen=True)
class _Raw:
    key: str
    payload: bytes


@dataclass(frozen=True)
class Membership:
    agent: int
    alive: bool


class Inbox:
    """Validated messages (and liveliness changes) for the main thread, with rejection counts."""

    def __init__(self, limits: Limits, drop_rate: float = 0.0, seed: int = 0, defer_decoding: bool = False) -> None:
        """``defer_decoding``: decode on the main thread instead of Zenoh's. A process off the critical
        path (the logger) then never slows Zenoh's delivery thread, and through it the publishers."""
        self.limits = limits
        self.defer_decoding = defer_decoding
        self.queue: queue.SimpleQueue[Received | Membership] = queue.SimpleQueue()
        self.rejected: Counter[str] = Counter()
        self.accepted = 0
        self.bytes_received = 0
        self._lock = threading.Lock()
        # Test hook (issue 5): drop this fraction of incoming samples at random.
        self._drop_rate = drop_rate
        self._drop_random = __import__("random").Random(seed)
        self.dropped = 0
        self.recovered = 0
        self.relayed = 0  # accepted from a relay: a dead teammate's step

    def on_sample(self, sample: zenoh.Sample) -> None:
        key = str(sample.key_expr)
        try:
            payload = sample.payload.to_bytes()
        except Exception:  # a payload Zenoh cannot hand over as bytes
            self._reject("unreadable", key)
            return
        with self._lock:
            self.bytes_received += len(payload)
            if self._drop_rate and self._drop_random.random() < self._drop_rate:
                self.dropped += 1
                return
        if self.defer_decoding:
            self.queue.put(_Raw(key, payload))
            return
        received = self._validate(key, payload)
        if received is not None:
            self.queue.put(received)

    def deliver(self, key: str, payload: bytes, recovery: bool = True, relayed: int | None = None) -> None:
        """A payload fetched by a query (not subject to the drop hook): validate and queue it.
        ``recovery``: it replaces a lost one (counted as recovered), rather than being read routinely.
        ``relayed``: it came from a relay, which may answer only with that agent's steps."""
        if recovery:
            with self._lock:
                self.recovered += 1
        received = self._validate(key, payload, relayed)
        if received is not None:
            if relayed is not None:
                with self._lock:
                    self.relayed += 1
            self.queue.put(received)

    def _validate(self, key: str, payload: bytes, relayed: int | None = None) -> Received | None:
        try:
            message = decode(payload, self.limits)
            agent = getattr(message, "agent", None)
            if relayed is not None:
                if not isinstance(message, AgentStep) or agent != relayed:
                    raise ProtocolError("wrong-relay", f"{key} relayed {type(message).__name__} for agent {agent}")
            elif "/agent/" in key and agent is not None and agent != agent_of_key(key):
                raise ProtocolError("wrong-sender", f"agent {agent} published on {key}")
        except ProtocolError as error:
            self._reject(error.reason, key, str(error))
            return None
        with self._lock:
            self.accepted += 1
        return Received(key, message, payload)

    def on_liveliness(self, sample: zenoh.Sample) -> None:
        agent = agent_of_key(str(sample.key_expr))
        if agent is not None and 0 <= agent < self.limits.agents:
            self.queue.put(Membership(agent, sample.kind == zenoh.SampleKind.PUT))

    def _reject(self, reason: str, key: str, detail: str = "") -> None:
        with self._lock:
            self.rejected[reason] += 1
            count = self.rejected[reason]
        # Log the first few of each reason, then every 1000th: a flood must not flood the log.
        if count <= 3 or count % 1000 == 0:
            log.warning("rejected payload on %s: %s (%d so far)", key, detail or reason, count)

    def get(self, timeout: float | None) -> Received | Membership | None:
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            remaining = None if deadline is None else deadline - time.monotonic()
            try:
                item = (
                    self.queue.get(timeout=remaining) if remaining is None or remaining > 0 else self.queue.get_nowait()
                )
            except queue.Empty:
                return None
            if not isinstance(item, _Raw):
                return item
            received = self._validate(item.key, item.payload)
            if received is not None:
                return received

    def drain(self, seconds: float, handle: Callable[[Received | Membership], None]) -> None:
        """Hand ``handle`` everything that arrives for ``seconds`` (at the end of a run: what is in flight)."""
        until = time.monotonic() + seconds
        while time.monotonic() < until:
            item = self.get(timeout=0.05)
            if item is not None:
                handle(item)

    def counts(self) -> dict[str, int]:
        with self._lock:
            return {
                "accepted": self.accepted,
                "rejected": sum(self.rejected.values()),
                "dropped": self.dropped,
                "recovered": self.recovered,
                "relayed": self.relayed,
                "bytes_received": self.bytes_received,
                **{f"rejected.{k}": v for k, v in self.rejected.items()},
            }


def write_counts(path: Path | None, counts: dict[str, object]) -> None:
    """Persist a process's message counters (read by tests and the launcher's summary)."""
    if path is not None:
        path.write_text(json.dumps(counts, indent=2, sort_keys=True) + "\n", encoding="utf-8")
