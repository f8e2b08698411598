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
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

__all__ = ["Terminated", "handled", "kept", "raise_pending"]

_received: list[int] = []  # the signals received while a command runs, in order


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised like Ctrl-C so that the same clean-up runs (temporary files removed)."""


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
