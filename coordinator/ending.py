"""The end of a run: announce it, let the last deltas land, write the counts and the run directory."""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from pathlib import Path

from coordinator.endpoints import CoordinatorBus
from coordinator.stepping import Stepping
from protocol.messages import RunControl, encode
from protocol.session import logger_listens
from protocol.settling import settle
from runtime.rundir import write_run_directory

log = logging.getLogger("anicov.coordinator")

LOGGER_GRACE = 10.0
"""Seconds the coordinator stays on the bus after the run while a logger still listens (see await_loggers)."""


def announce_end(bus: CoordinatorBus, stepping: Stepping) -> bytes | None:
    """'done' with the outcome (kept in the go history for whoever lost it), or 'abort' if stopped."""
    node = bus.node
    if stepping.outcome is None:
        reason = "coordinator stopped"
        bus.announce(RunControl("abort", stepping.step, False, node.replica.map.domain_error(), reason=reason))
        return None
    steps, completed, _ = stepping.outcome
    done = encode(RunControl("done", steps, completed, node.replica.map.domain_error()))
    bus.go_history.final = [done]  # an agent that lost the end of the run finds it here
    # Logged before it is announced: a log without this line is a run whose processes all still listen.
    log.info(
        "run %s after %d steps (e_D = %.4f)",
        "complete" if completed else "incomplete",
        steps,
        node.replica.map.domain_error(),
    )
    bus.publish(bus.control, done)
    return done


def settle_last_deltas(bus: CoordinatorBus, done: bytes | None, stopped: Callable[[], bool]) -> None:
    """Deltas still in flight (realtime agents step until they hear the end) join the map, and those lost
    on the way, last ones included: once every agent has stopped, each history is asked for what follows
    the replica's contiguous run (see protocol.settling). Lockstep: nothing is in flight, the last go
    closed every step."""
    node = bus.node
    node.open_step = None
    if done is not None:
        bus.publish(bus.control, done)  # again, for whoever lost the first (it is idempotent)
    if bus.barrier is not None and not stopped():
        # The agents wait for our 'whole' before they leave; we wait for no one's (we serve no deltas).
        settle(bus.barrier, node.replica, node.inbox, node.handle, range(node.scenario.agents), stopped, ())


def write_outputs(bus: CoordinatorBus, stepping: Stepping, resumed_at: int | None, out: str | None) -> None:
    """The counters, and (a finished run with --out) trajectory.csv, summary.json and the plots, written while
    still on the bus: a late logger can fetch the final map's snapshot meanwhile."""
    node = bus.node
    counts = (
        node.inbox.counts()
        | node.replica.counts()
        | {
            "bytes_sent": node.bytes_sent,
            "wall_seconds": time.monotonic() - stepping.began,
            "events": node.log.events,
            "resumed_at": resumed_at,
        }
    )
    if stepping.outcome is not None and out:
        steps, completed, completion_step = stepping.outcome
        write_run_directory(node.result(steps, completed, completion_step), Path(out), counts)


def await_loggers(bus: CoordinatorBus, stopped: Callable[[], bool]) -> None:
    """Stay on the bus until no logger listens (each withdraws its token once it has the run's end), at most
    LOGGER_GRACE seconds, unless stopped. A logger reads the last gos from the coordinator's history and, if
    anything is missing, its snapshot: a logger started by hand mid-run, behind on a busy machine, once found
    the coordinator gone and recorded a final map with cells still uncovered."""
    deadline = time.monotonic() + LOGGER_GRACE
    alive = bus.keys.alive("logger")
    while not stopped():
        if not logger_listens(bus.session, alive, timeout=0.2):
            return
        if time.monotonic() >= deadline:
            log.warning("a logger still listens %.0f s after the run; leaving it", LOGGER_GRACE)
            return
        time.sleep(0.1)
