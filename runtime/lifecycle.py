"""Process lifecycle: stop cleanly on SIGINT, SIGTERM or SIGHUP, and never outlive the launcher."""

from __future__ import annotations

import ctypes
import logging
import os
import signal
import sys
import time
from types import FrameType

log = logging.getLogger("anicov")

EXIT_OK = 0
EXIT_INCOMPLETE = 1
EXIT_USAGE = 2
EXIT_FAILED = 3
EXIT_SIGINT = 130
EXIT_SIGTERM = 143


class StopFlag:
    """Set by SIGINT, SIGTERM or SIGHUP; main loops poll it and leave through their ``with`` blocks.

    The handler only assigns attributes: it runs between two bytecodes of the
    main thread, which may be holding a lock at that moment (inside
    ``Event.set`` or a ``Condition``), so taking any lock here could deadlock
    the process for good. Waiting is done by polling in short sleeps.
    """

    POLL_SECONDS = 0.02

    def __init__(self) -> None:
        self._stopped = False
        self.signal_number: int | None = None

    def install(self) -> StopFlag:
        signal.signal(signal.SIGINT, self._on_signal)
        signal.signal(signal.SIGTERM, self._on_signal)
        signal.signal(signal.SIGHUP, self._on_signal)  # a closed terminal or SSH link: stop as cleanly
        return self

    def _on_signal(self, number: int, _frame: FrameType | None) -> None:
        if self.signal_number is None:
            self.signal_number = number
        self._stopped = True

    def set(self) -> None:
        self._stopped = True

    @property
    def stopped(self) -> bool:
        return self._stopped

    def wait(self, seconds: float) -> bool:
        """Sleep up to ``seconds``, returning early (True) once stopped."""
        deadline = time.monotonic() + seconds
        while not self._stopped:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            time.sleep(min(remaining, self.POLL_SECONDS))
        return True

    def exit_code(self, otherwise: int) -> int:
        if self.signal_number == signal.SIGINT:
            return EXIT_SIGINT
        if self.signal_number == signal.SIGTERM:
            return EXIT_SIGTERM
        if self.signal_number is not None:
            return 128 + self.signal_number  # SIGHUP: 129
        return otherwise


def die_with_parent() -> None:
    """Ask Linux to send SIGTERM to this process when its parent dies (no orphans after a SIGKILL)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        pr_set_pdeathsig = 1
        libc.prctl(pr_set_pdeathsig, signal.SIGTERM)
    except OSError:
        log.debug("prctl unavailable; relying on the launcher to stop this process")


def parent_is_gone(original_parent: int) -> bool:
    return os.getppid() != original_parent


def setup_logging(name: str, verbose: bool = False) -> None:
    logging.basicConfig(
        level=logging.DEBUG if verbose else logging.INFO,
        format=f"%(asctime)s {name} %(levelname)s %(message)s",
        stream=sys.stderr,
    )


GC_THRESHOLD = 50_000
"""Allocations between young-generation collections in a team process (Python's default: 700)."""


def settle_garbage_collector() -> None:
    """For a long-running team process, once its modules are loaded and its session is open.

    Every step allocates many short-lived, acyclic objects (decoded messages,
    small arrays) that reference counting frees at once; with the default
    threshold the cyclic collector still runs every 700 allocations and, now
    and then, walks the whole heap of numpy, numba, zenoh and rerun objects.
    Profiling the logger showed a third of its main thread in the collector.
    Freezing what exists now takes it out of every later collection, and a
    higher threshold makes young collections rare; cycles are still collected.
    """
    import gc

    gc.collect()
    gc.freeze()
    gc.set_threshold(GC_THRESHOLD, 20, 20)
