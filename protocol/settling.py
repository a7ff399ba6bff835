"""The end of a realtime run: nobody leaves the bus before every replica is whole.

Realtime processes step on their own clocks, so the end of the run reaches them at different moments,
on a busy machine far apart. A process that left as soon as its own last fetch was answered could no
longer answer a slower teammate's: its last deltas were then missing from that teammate's replica
(found in CI under pytest-xdist: four replicas with three map digests). So the end has two phases,
each a liveliness token under ``ending/<phase>/<role>/<id>``:

- ``stopped``: this process will publish no more deltas. A replica fetches a teammate's deltas "to the
  end" only once that teammate has stopped; before, the end still moves.
- ``whole``: this process has fetched everything its stopped teammates published. A process leaves only
  once every teammate still alive is whole: until then one of them may still need its history.

A process that dies withdraws its tokens with its session, so it is never waited for. One that hangs
is waited for at most :data:`END_LIMIT` seconds and then left, with a warning: that end is then what it
was before this barrier. Lockstep runs never use it: the coordinator's last go closes every step.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Iterable

import zenoh

from protocol.inbox import Inbox, Membership, Received
from protocol.keys import TeamKeys
from protocol.recovery import fill_gaps
from protocol.replica import MapReplica

log = logging.getLogger("anicov.settling")

STOPPED = "stopped"
WHOLE = "whole"
PHASES = (STOPPED, WHOLE)

END_LIMIT = 30.0
"""Seconds a process waits for its teammates at each phase before leaving anyway (a hung teammate)."""

IDLE_SLICE = 0.05
"""Seconds of inbox handling between two looks at the tokens."""

Member = tuple[str, int]
"""A process of the team: (role, id), as in ``alive/<role>/<id>``."""


def member_of_key(key: str, after: str) -> tuple[str, Member] | None:
    """The last three parts of ``…/<after>/<a>/<role>/<id>`` as (a, (role, id)); None if malformed."""
    parts = key.split("/")
    member = _member(parts) if len(parts) >= 4 and parts[-4] == after else None
    return None if member is None else (parts[-3], member)


def _member(parts: list[str]) -> Member | None:
    """(role, id) from a key's last two parts; None unless the id is a number of at most 6 digits."""
    if not parts[-1].isdigit() or len(parts[-1]) > 6:
        return None
    return parts[-2], int(parts[-1])


class EndBarrier:
    """Who of the team is alive, and who has reached each phase of the end (see the module's text).

    Made when the process joins the bus, so that the liveliness history (every token already
    declared) has long arrived when the run ends."""

    def __init__(self, session: zenoh.Session, keys: TeamKeys, role: str, ident: int) -> None:
        self.session, self.keys, self.me = session, keys, (role, ident)
        self._lock = threading.Lock()
        self._alive: set[Member] = set()
        self._reached: dict[str, set[Member]] = {phase: set() for phase in PHASES}
        self._tokens: list[zenoh.LivelinessToken] = []
        liveliness = session.liveliness()
        self._subscribers = [
            liveliness.declare_subscriber(keys.alive_everyone, self._on_alive, history=True),
            liveliness.declare_subscriber(keys.all_endings, self._on_ending, history=True),
        ]

    def _on_alive(self, sample: zenoh.Sample) -> None:
        self._note(self._alive, alive_member(f"{sample.key_expr}"), sample.kind == zenoh.SampleKind.PUT)

    def _on_ending(self, sample: zenoh.Sample) -> None:
        parsed = member_of_key(f"{sample.key_expr}", "ending")
        if parsed is not None and parsed[0] in self._reached:
            phase, member = parsed
            self._note(self._reached[phase], member, sample.kind == zenoh.SampleKind.PUT)

    def _note(self, members: set[Member], member: Member | None, present: bool) -> None:
        if member is None:
            return
        with self._lock:
            if present:
                members.add(member)
            else:
                members.discard(member)

    def declare(self, phase: str) -> None:
        """This process has reached ``phase`` (its token stays until the session closes)."""
        role, ident = self.me
        self._tokens.append(self.session.liveliness().declare_token(self.keys.ending(phase, role, ident)))

    def waiting_on(self, phase: str, roles: Iterable[str]) -> set[Member]:
        """The other live processes of these roles that have not reached ``phase``."""
        wanted = set(roles)
        with self._lock:
            return {m for m in self._alive if m[0] in wanted and m != self.me} - self._reached[phase]

    def reached(self, phase: str, role: str) -> set[int]:
        """The ids of the processes of ``role`` that have reached ``phase``."""
        with self._lock:
            return {ident for kind, ident in self._reached[phase] if kind == role}

    def wait(
        self,
        phase: str,
        roles: Iterable[str],
        idle: Callable[[float], object],
        stopped: Callable[[], bool],
        limit: float = END_LIMIT,
    ) -> bool:
        """Until every live process of ``roles`` has reached ``phase`` (True), or stopped, or ``limit``
        seconds (False). ``idle(seconds)`` handles the inbox meanwhile (teammates' last deltas)."""
        roles = tuple(roles)
        deadline = time.monotonic() + limit
        while pending := self.waiting_on(phase, roles):
            if stopped():
                return False
            if time.monotonic() >= deadline:
                log.warning("%s %d: %s not %s after %.0f s; leaving", *self.me, sorted(pending), phase, limit)
                return False
            idle(IDLE_SLICE)
        return True

    def close(self) -> None:
        for token in self._tokens:
            token.undeclare()
        for subscriber in self._subscribers:
            subscriber.undeclare()
        self._tokens.clear()


def settle(
    barrier: EndBarrier,
    replica: MapReplica,
    inbox: Inbox,
    handle: Callable[[Received | Membership], None],
    to_the_end: Iterable[int],
    stopped: Callable[[], bool],
    whole_of: tuple[str, ...] = ("agent", "coordinator"),
) -> bool:
    """A realtime run has ended for this process: stop, wait for the agents to stop, fetch every delta
    of ``to_the_end`` that this replica lacks, say it is whole and (with ``whole_of``) wait for those
    roles to be whole too. False: a teammate did not reach a phase within END_LIMIT, or stopped."""

    def idle(seconds: float) -> None:
        inbox.drain(seconds, handle)

    def handle_queued() -> None:
        while (item := inbox.get(timeout=0)) is not None:
            handle(item)

    barrier.declare(STOPPED)
    settled = barrier.wait(STOPPED, ("agent",), idle, stopped)
    handle_queued()
    fill_gaps(barrier.session, barrier.keys, replica, inbox, to_the_end=to_the_end)
    handle_queued()
    barrier.declare(WHOLE)
    if whole_of:
        settled = barrier.wait(WHOLE, whole_of, idle, stopped) and settled
    return settled


def alive_member(key: str) -> Member | None:
    """(role, id) of ``…/alive/<role>/<id>``; None if malformed."""
    parts = key.split("/")
    return _member(parts) if len(parts) >= 3 and parts[-3] == "alive" else None
