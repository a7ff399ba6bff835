"""runtime.lifecycle: the signals that stop a process cleanly, and the exit code each leaves."""

from __future__ import annotations

import os
import signal

import pytest

from runtime.lifecycle import EXIT_FAILED, StopFlag
from tests.teamrun import limit


@pytest.mark.parametrize(("number", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143), (signal.SIGHUP, 129)])
def test_a_stopping_signal_sets_the_flag_and_names_the_exit_code(number, code):
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        stop = StopFlag().install()
        assert not stop.stopped and stop.exit_code(EXIT_FAILED) == EXIT_FAILED
        os.kill(os.getpid(), number)
        assert stop.wait(limit(60)) and stop.stopped  # returns as the handler runs
        assert stop.exit_code(EXIT_FAILED) == code
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)
