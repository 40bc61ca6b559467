"""surfmod.child: a foreign call in a child process answers, raises, times out or dies,
and the caller always gets control back."""

from __future__ import annotations

import os
import signal
import time

import pytest

from surfmod import child
from surfmod.errors import SurfmodError


def _raises(message):
    raise SurfmodError(message)


def _crashes():
    os.kill(os.getpid(), signal.SIGSEGV)


def test_value_and_exception_come_back():
    assert child.call(pow, (2, 10), 60.0, "pow") == 1024
    with pytest.raises(SurfmodError, match=r"^size: too small$"):
        child.call(_raises, ("size: too small",), 60.0, "raiser")


def test_a_stuck_child_is_killed_at_its_deadline():
    start = time.monotonic()
    with pytest.raises(child.ChildFailure, match=r"^sleeper did not finish within 2 s$"):
        child.call(time.sleep, (600,), 2.0, "sleeper")
    assert time.monotonic() - start < 30  # the deadline plus a spawn, never the 600 s


def test_a_crash_is_a_failure_not_a_dead_caller():
    with pytest.raises(child.ChildFailure, match=r"^crasher died \(exit code -11\)$"):
        child.call(_crashes, (), 60.0, "crasher")


def test_a_server_whose_warm_up_dies_says_its_start_failed():
    """The warm-up's failure is the child's start, not the call's (the STEP reader names
    it "the reader process did not start"); the next call starts a fresh child."""
    server = child.Server(warmup=(_crashes, ()))
    try:
        with pytest.raises(child.ChildFailure, match=r"^pow: the child's start died \(exit code -11\)$") as caught:
            server.call(pow, (2, 10), 60.0, "pow")
        assert caught.value.cause == "start" and caught.value.returncode == -11
        server.warmup = None
        assert server.call(pow, (2, 10), 60.0, "pow") == 1024
    finally:
        server.close()
