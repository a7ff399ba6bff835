"""Bandwidth you can see (issue 13): each process reports its byte counters on ``traffic/<role>/<id>``.

A :class:`TrafficReporter` publishes, every :data:`TRAFFIC_PERIOD` wall seconds and once more when it
stops, how many payload bytes its process has put on the bus and taken from it since it started (the
counters its shell already keeps). The logger turns two reports into bytes per second in the recording.
A report is about 60 bytes: at one a second it adds well under 1 % to a robot's traffic.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

import zenoh

from protocol.messages import Traffic, encode

TRAFFIC_PERIOD = 1.0
"""Wall seconds between two reports of one process."""


class TrafficReporter:
    """A background thread that publishes ``counters()`` = (bytes out, bytes in) as :class:`Traffic`."""

    def __init__(
        self, session: zenoh.Session, key: str, role: str, ident: int, counters: Callable[[], tuple[int, int]]
    ) -> None:
        self._publisher = session.declare_publisher(key)
        self._role, self._ident, self._counters = role, ident, counters
        self._started = time.monotonic()
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"traffic-{role}-{ident}", daemon=True)

    def start(self) -> TrafficReporter:
        """Start reporting; the rates count from here (not from the wait for the team before it)."""
        self._started = time.monotonic()
        self._thread.start()
        return self

    def report(self) -> Traffic:
        bytes_out, bytes_in = self._counters()
        return Traffic(self._role, self._ident, time.monotonic() - self._started, bytes_out, bytes_in)

    def _run(self) -> None:
        while not self._stopped.wait(TRAFFIC_PERIOD):
            self._publisher.put(encode(self.report()))

    def stop(self) -> None:
        """Stop the thread and publish the final counters (before the session closes); once only."""
        if self._stopped.is_set():
            return
        self._stopped.set()
        if self._thread.is_alive():
            self._thread.join(timeout=2 * TRAFFIC_PERIOD)
        self._publisher.put(encode(self.report()))
        self._publisher.undeclare()
