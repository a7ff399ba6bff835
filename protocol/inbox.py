"""The inbox of a process: it decodes, validates and counts what Zenoh delivers.

Zenoh delivers samples on its own threads. The inbox decodes each sample at
once (a bad payload is rejected, logged and counted there, never queued) and
hands good messages to the process's single main thread through a queue, so
the control code never runs concurrently with itself.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, replace

import zenoh

from protocol.decoding import decode
from protocol.keys import agent_of_key
from protocol.messages import AgentStep, Limits, Message, ProtocolError, Traffic

log = logging.getLogger("anicov.bus")


ANY_AGENT = -1
"""``relayed`` for an anti-entropy reply (protocol.sync): steps of any agent, from a teammate in range."""


@dataclass(frozen=True)
class Received:
    key: str
    message: Message
    payload: bytes = b""  # as it came: a relay keeps teammates' steps to serve them again
    live: bool = True  # published to us; False: the answer to a query (history, relay, anti-entropy)


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
            self.queue.put(replace(received, live=False))

    def _validate(self, key: str, payload: bytes, relayed: int | None = None) -> Received | None:
        try:
            message = decode(payload, self.limits)
            agent = getattr(message, "agent", None)
            if relayed is not None:
                if not isinstance(message, AgentStep) or (agent != relayed and relayed != ANY_AGENT):
                    raise ProtocolError("wrong-relay", f"{key} relayed {type(message).__name__} for agent {agent}")
            elif "/agent/" in key and agent is not None and agent != agent_of_key(key):
                raise ProtocolError("wrong-sender", f"agent {agent} published on {key}")
            elif isinstance(message, Traffic) and not key.endswith(f"/traffic/{message.role}/{message.ident}"):
                raise ProtocolError("wrong-sender", f"{message.role} {message.ident}'s traffic published on {key}")
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
