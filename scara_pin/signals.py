"""Ctrl-C and SIGTERM keep their meaning while third-party code runs.

Python turns SIGINT into a ``KeyboardInterrupt`` raised wherever the main thread is; code that catches
``BaseException`` there (trimesh does, around many of its parsers and texture loads) swallows it and goes
on. While a command runs (:func:`kept`), the handlers of SIGINT and SIGTERM record the signal before they
raise, so a swallowed one is not lost:

- :func:`raise_pending` raises it again; it is called right after each call into a library that may
  swallow it (a mesh load), and by the atomic writer (:mod:`scara_pin.files`) just before it renames its
  temporary file into place: no output file is written after a signal, whatever happened in between;
- the command line calls it once more when the command returns, so the exit code is 130 (Ctrl-C) or
  143 (SIGTERM) even when nothing was to be written;
- :func:`handled` forgets a SIGINT that a command handled on purpose (a server stopped with Ctrl-C).

The record is process-wide, as signals are; it is cleared when :func:`kept` starts. Outside :func:`kept`
(a library user's own program) nothing is installed and :func:`raise_pending` never raises.

A time limit is the same kind of interruption, kept by the thread that set it (a sweep's variant on a Dask worker
runs in a worker's thread, where no alarm signal reaches): within :func:`time_limit`, :func:`check_time` raises
:class:`TimeLimit` once the time is up. The planners call it where a stop is cheap (before each solver call, each
step of a job), so a computation past its limit stops within one solver call.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

__all__ = ["Terminated", "TimeLimit", "check_time", "handled", "kept", "raise_pending", "time_limit"]

_received: list[int] = []  # the signals received while a command runs, in order
_limit = threading.local()  # .at: (the perf_counter time past which check_time raises, the limit) or None


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that the same clean-up runs (temporary files removed)."""


class TimeLimit(Exception):
    """A computation past the time limit of :func:`time_limit` (raised by :func:`check_time`).

    Attributes:
        limit: [s] the limit.
    """

    def __init__(self, limit: float) -> None:
        super().__init__(limit)
        self.limit = limit

    def __str__(self) -> str:
        return f"past the time limit of {self.limit:g} s"


def _raise(signum: int) -> None:
    if signum == signal.SIGTERM:
        raise Terminated()
    raise KeyboardInterrupt()


def _on_signal(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    _raise(signum)


@contextmanager
def kept() -> Iterator[None]:
    """While a command runs: SIGINT and SIGTERM raise and are recorded (main thread only; restored after).

    A SIGINT that the process ignores (a background job of a shell) stays ignored.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received.clear()
    previous = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    signal.signal(signal.SIGTERM, _on_signal)
    if previous[signal.SIGINT] is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_signal)
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def raise_pending() -> None:
    """Raise again a signal received since the command started (``Terminated`` first), if any.

    Raises:
        Terminated: a SIGTERM was received.
        KeyboardInterrupt: a SIGINT was received (and not :func:`handled`).
    """
    if signal.SIGTERM in _received:
        _raise(signal.SIGTERM)
    if _received:
        _raise(_received[0])


def handled(signum: int = signal.SIGINT) -> None:
    """Forget the received ``signum`` signals: the command handled them (a server stopped by Ctrl-C)."""
    _received[:] = [s for s in _received if s != signum]


@contextmanager
def time_limit(seconds: float | None) -> Iterator[None]:
    """Within: :func:`check_time` raises :class:`TimeLimit` once ``seconds`` have passed, in this thread.

    None: no limit of its own; an outer limit that ends sooner stays in force.
    """
    outer = getattr(_limit, "at", None)
    at = None if seconds is None else time.perf_counter() + seconds
    if at is not None and (outer is None or at < outer[0]):
        _limit.at = (at, seconds)
    try:
        yield
    finally:
        _limit.at = outer


def check_time() -> None:
    """Raise :class:`TimeLimit` if this thread's :func:`time_limit` has passed; else nothing (cheap: a clock read).

    Raises:
        TimeLimit: the time is up.
    """
    at = getattr(_limit, "at", None)
    if at is not None and time.perf_counter() > at[0]:
        raise TimeLimit(at[1])
