"""The logger process: subscribes to the whole team and writes its rerun recording.

It keeps its own replica of the map (so a late start still ends with the full
map: it loads the coordinator's snapshot first), logs every agent's state,
the objectives and blobs, e_D, and the team's events, and flushes the
recording when the run ends or when it is stopped. What each message becomes
is decided in :class:`logger.team_logger.TeamLogger`; this file is the shell
that opens the session, feeds it and ends it.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable
from functools import partial

import zenoh

from logger.team_logger import LoggerOptions, TeamLogger
from model.radio.exact_coverage import load_kernels as load_event_kernel
from model.scenario import Scenario
from protocol.agreement import (
    ScenarioMismatch,
    check_agreement,
    check_peers,
    coordinator_digest,
    digest_of,
    peer_digests,
)
from protocol.keys import TeamKeys
from protocol.recovery import fetch, fetch_snapshot
from protocol.session import open_session
from runtime.lifecycle import EXIT_OK, EXIT_USAGE, StopFlag, parent_is_gone, settle_garbage_collector
from runtime.rundir import write_counts

log = logging.getLogger("anicov.logger")

FLUSH_PERIOD = 0.5
"""Seconds between sends of the buffered per-step columns."""
READ_PERIOD = 0.25
"""Lockstep: seconds between reads of the coordinator's history of gos (the live view lags this much)."""


def run_logger(scenario: Scenario, options: LoggerOptions, config: zenoh.Config, stop: StopFlag) -> int:
    node = TeamLogger(scenario, options)
    keys = TeamKeys(options.team)
    parent = os.getppid()
    with open_session(config) as session:
        # Lockstep bundles every step's deltas, states and objectives in the coordinator's go. The
        # logger reads them in batches from the coordinator's history rather than one sample a step:
        # a process's cost is per message, not per byte, and this one is off the critical path.
        lockstep = options.clock == "lockstep"
        _subscribe(session, keys, node, lockstep)
        try:
            _await_agreement(session, keys, node, lambda: stop.stopped or parent_is_gone(parent))
        except ScenarioMismatch as error:
            log.error("the logger refuses to record: %s", error)
            node.finish()
            return EXIT_USAGE
        # The snapshot before the liveliness token: a run started with --await-logger waits for the token,
        # so every go of a fresh run comes after this snapshot (a loaded machine once let a run's first
        # steps into it, and the logger skipped their gos); a late logger starts from the map as it is.
        if not options.no_coordinator:
            _load_snapshot(session, keys, node)
        token = session.liveliness().declare_token(keys.alive("logger"))
        settle_garbage_collector()
        load_event_kernel(node.limits.kernel)  # it decodes every event of the team
        read_gos = partial(_read_gos, session, keys, node) if lockstep else None
        ended = node.everyone_left if options.no_coordinator else lambda: False
        _follow(node, read_gos, lambda: stop.stopped or parent_is_gone(parent) or ended())
        _drain(node, read_gos)
        if node.finished is not None and not node.replica.map.complete and not options.no_coordinator:
            _load_snapshot(session, keys, node)  # anything lost on the way: the coordinator's map is the reference
        token.undeclare()
    node.finish()
    write_counts(options.counts_file, node.inbox.counts() | {"bandwidth": node.bandwidth()})
    return stop.exit_code(EXIT_OK)


def _subscribe(session: zenoh.Session, keys: TeamKeys, node: TeamLogger, lockstep: bool) -> None:
    """Subscribe to what the logger reads live (realtime: the steps and objectives too)."""
    live_steps = () if lockstep else (keys.all_steps, keys.objectives)
    for key in (*live_steps, keys.control, keys.all_traffic):
        session.declare_subscriber(key, node.inbox.on_sample)
    session.liveliness().declare_subscriber(keys.alive_agents, node.inbox.on_liveliness, history=True)


def _await_agreement(session: zenoh.Session, keys: TeamKeys, node: TeamLogger, stopped: Callable[[], bool]) -> None:
    """Until the coordinator (with no coordinator: the first agents) answers: it must run this logger's
    scenario and map (ScenarioMismatch)."""
    mine = digest_of(node.scenario)
    while not stopped():
        if node.options.no_coordinator:
            found = peer_digests(session, keys, node.limits, timeout=0.2)
            check_peers(mine, found, node.scenario)
            if found:
                return
            continue
        theirs = coordinator_digest(session, keys, node.limits, timeout=0.2)
        if theirs is not None:
            check_agreement(mine, theirs, node.scenario)
            return


def _load_snapshot(session: zenoh.Session, keys: TeamKeys, node: TeamLogger) -> None:
    """A late logger starts from the coordinator's map."""
    snapshot = fetch_snapshot(session, keys.snapshot, node.limits, timeout=5.0)
    if snapshot is None:
        return
    node.load_snapshot(snapshot)
    log.info("loaded the coordinator's snapshot (e_D = %.4f)", node.replica.map.domain_error())


def _read_gos(session: zenoh.Session, keys: TeamKeys, node: TeamLogger) -> None:
    """Every go since the last read (and the end of the run, once known), in step order."""
    fetch(session, keys.go_history, node.inbox, first=node.next_go, timeout=5.0, recovery=False)


def _follow(node: TeamLogger, read_gos: Callable[[], None] | None, stopped: Callable[[], bool]) -> None:
    """Until the run ends (or the logger is stopped): handle what arrives, flush the states now and then."""
    next_flush = time.monotonic() + FLUSH_PERIOD
    next_read = 0.0
    while node.finished is None and not stopped():
        if read_gos is not None and time.monotonic() >= next_read:
            read_gos()
            next_read = time.monotonic() + READ_PERIOD
        item = node.inbox.get(timeout=READ_PERIOD / 2)
        if item is not None:
            node.handle(item)
        if time.monotonic() >= next_flush:
            node.recorder.flush_states()
            next_flush = time.monotonic() + FLUSH_PERIOD


def _drain(node: TeamLogger, read_gos: Callable[[], None] | None) -> None:
    """Handle what is already here (the last deltas travel beside the end-of-run message)."""
    if read_gos is not None and node.finished is not None:
        read_gos()  # the gos up to the end, if the end came first on run/control
    deadline = time.monotonic() + 0.5
    while time.monotonic() < deadline and (item := node.inbox.get(timeout=0.05)) is not None:
        node.handle(item)
