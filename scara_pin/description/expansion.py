"""xacro's expansion, bounded in time and memory: it runs in a child process that is stopped at the bounds.

Expanding a xacro file runs the Python expressions written in it (``${...}``), and its macros may call
themselves: ``${(9**9**9) % 7}`` computes a number of 370 million digits, and a macro calling itself twice 30
levels deep makes 2^30 calls. Neither can be stopped from inside the process for sure (a big integer's
multiplication does not look at signals, and a list of 10^9 items takes the machine's memory). So
:func:`bounded` runs the expansion in a child process (``fork``: the modules already imported are shared, a fork
costs about 40 ms): at most :data:`~scara_pin.limits.MAX_XACRO_SECONDS` seconds (wall clock, then the child
is killed), :data:`~scara_pin.limits.MAX_XACRO_MEMORY` bytes of memory more than the process held (its address
space is capped: an allocation beyond fails, a ``MemoryError``), and a result of at most
:data:`~scara_pin.limits.MAX_DOCUMENT_BYTES` bytes. Each bound reached is one ``UrdfError`` naming the file and
the bound, never a hang.

The child sends back its result (or its error) and the files it read, which join the command's record
(:func:`scara_pin.limits.record_read`: an output is never written over an include). Ctrl-C and SIGTERM stop the
child with the parent. :data:`xacro_lock` (xacro keeps its state in module globals) is held by the parent for
the child's life. Without ``fork`` (not POSIX) the expansion runs in the process, unbounded.
"""

from __future__ import annotations

import os
import pickle
import select
import signal
import threading
import time
from collections.abc import Callable
from typing import TypeVar

from ..errors import UrdfError
from ..limits import MAX_DOCUMENT_BYTES, MAX_XACRO_MEMORY, MAX_XACRO_SECONDS, files_read, record_read

__all__ = ["bounded", "xacro_lock"]

xacro_lock = threading.Lock()
"""Held while xacro runs: xacro keeps its state in module globals (file stack, arguments), and the
expansion of a user's file replaces its ``open`` and ``$(find)`` for a while."""

T = TypeVar("T")

_child = False
"""True in the child process of :func:`bounded` (an expansion inside it runs there, not in another child)."""
_CHUNK = 1 << 20


def bounded(what: str, work: Callable[[], T]) -> T:
    """``work()`` (an expansion) in a child process under the bounds of the module docstring; its result or error.

    Args:
        what: the file expanded, for messages.
        work: what runs in the child; its result and any exception must pickle.

    Raises:
        UrdfError: a bound reached (time, memory, result size), or the child ended without a result.
        Exception: what ``work`` raised (re-raised here).
    """
    if _child or not hasattr(os, "fork"):
        return work()
    seconds, memory = MAX_XACRO_SECONDS, MAX_XACRO_MEMORY
    with xacro_lock:  # no other thread is inside xacro while the process forks
        read_end, write_end = os.pipe()
        pid = os.fork()
        if pid == 0:  # the child: never returns
            os.close(read_end)
            _run_child(work, write_end, memory)
        os.close(write_end)
        try:
            data = _receive(read_end, pid, seconds, what)
        finally:
            os.close(read_end)
    status, payload, reads = pickle.loads(data)  # noqa: S301 - our own child's bytes, through our own pipe
    for identity, (kind, name) in reads.items():  # the files the child read are the command's inputs
        record_read(identity, name, kind)
    if status == "error":
        raise payload
    return payload  # type: ignore[no-any-return]


def _run_child(work: Callable[[], object], out: int, memory: int) -> None:
    """The child's life: bounds set, ``work()`` run, its pickled (status, result or error, files read) sent."""
    global _child
    code = 0
    try:
        _child = True
        xacro_lock.release()  # the parent's, held across the fork: this process's copy is free
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, signal.SIG_DFL)  # Ctrl-C stops the child with the parent
        _cap_memory(memory)
        try:
            result: tuple[str, object] = ("ok", work())
            if isinstance(result[1], (str, tuple)) and len(pickle.dumps(result[1])) > MAX_DOCUMENT_BYTES:
                result = ("error", UrdfError(f"the expansion is larger than {MAX_DOCUMENT_BYTES:,} bytes, the cap "
                                             "(MAX_DOCUMENT_BYTES)"))  # fmt: skip
        except MemoryError:
            result = ("error", UrdfError(f"the expansion needed more than {memory / 2**20:,.0f} MiB of memory, the "
                                         "cap (MAX_XACRO_MEMORY)"))  # fmt: skip
        except Exception as exc:  # xacro's or ours: re-raised in the parent
            result = ("error", exc)
        try:
            data = pickle.dumps((*result, files_read()))
        except Exception as exc:  # an exception that does not pickle: its message
            data = pickle.dumps(("error", UrdfError(f"{type(exc).__name__}: {result[1]}"), files_read()))
        view = memoryview(data)
        while view:
            view = view[os.write(out, view[:_CHUNK]) :]
    except BaseException:  # noqa: BLE001 - nothing may escape a forked child
        code = 70
    finally:
        os._exit(code)


def _cap_memory(memory: int) -> None:
    """The child's address space: what it holds now (its parent's) plus ``memory`` bytes."""
    import resource

    try:
        with open("/proc/self/statm") as handle:
            size = int(handle.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError):
        return  # no /proc: time bound only
    limit = size + memory
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY:
        limit = min(limit, hard)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))


def _receive(fd: int, pid: int, seconds: float, what: str) -> bytes:
    """The child's bytes until it closes the pipe, within ``seconds``; the child reaped, killed if need be."""
    chunks: list[bytes] = []
    size = 0
    deadline = time.monotonic() + seconds
    done = False
    try:
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                raise UrdfError(f"{what}: xacro: the expansion took more than {seconds:g} s, the cap "
                                "(MAX_XACRO_SECONDS): a macro that calls itself, or an expression too costly "
                                "(such as 9**9**9); not expanded")  # fmt: skip
            ready, _, _ = select.select([fd], [], [], left)
            if not ready:
                continue
            chunk = os.read(fd, _CHUNK)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
            if size > 2 * MAX_DOCUMENT_BYTES + _CHUNK:  # the child caps its text; this bounds a broken one
                raise UrdfError(f"{what}: xacro: the expansion sent more than {2 * MAX_DOCUMENT_BYTES:,} bytes")
        _, status = os.waitpid(pid, 0)
        done = True
    finally:
        if not done:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    if not chunks or status != 0:
        how = f"signal {os.WTERMSIG(status)}" if os.WIFSIGNALED(status) else f"status {os.WEXITSTATUS(status)}"
        raise UrdfError(f"{what}: xacro: the expansion ended without a result ({how})")
    return b"".join(chunks)
