"""The meshcat server of the live viewer: a child process, bound to 127.0.0.1 only, that dies with its parent.

It is stopped by :meth:`MeshcatServer.close`, and it exits by itself when its parent dies, even by SIGKILL: it
watches its stdin (a pipe from the parent, at end of file once the parent is gone) and its parent pid. (Linux's
``PR_SET_PDEATHSIG`` is not used: it fires when the *thread* that started the child ends.)
"""

from __future__ import annotations

import collections
import contextlib
import logging
import os
import queue
import subprocess
import sys
import threading
import time

from .window import ViewerError, load_meshcat

__all__ = ["MeshcatServer"]

log = logging.getLogger(__name__)

_SERVER_MARK = "scara-pin-meshcat-server"
"""Argument that marks our meshcat server processes (tests find leftovers by it)."""

_SERVER_SCRIPT = r"""
import os, sys, threading, time
parent = int(sys.argv[2])

def _stdin_closed():  # the parent holds the other end of this pipe: EOF when it closes it or dies
    try:
        while sys.stdin.buffer.read(65536):
            pass
    finally:
        os._exit(0)

def _orphaned():  # a second guard: reparented (the parent died) -> exit
    while True:
        if os.getppid() != parent:
            os._exit(0)
        time.sleep(0.25)

threading.Thread(target=_stdin_closed, daemon=True).start()
threading.Thread(target=_orphaned, daemon=True).start()

import tornado.web
from meshcat.servers import zmqserver as z

class _LoopbackApp(tornado.web.Application):
    def listen(self, port, address=None, **kwargs):  # meshcat listens on every interface: loopback only
        return super().listen(port, "127.0.0.1", **kwargs)

class _Bridge(z.ZMQWebSocketBridge):
    def make_app(self):
        return _LoopbackApp([
            (r"/static/(.*)", z.StaticFileHandlerNoCache, {"path": z.VIEWER_ROOT, "default_filename": z.VIEWER_HTML}),
            (r"/", z.WebSocketHandler, {"bridge": self}),
        ])

bridge = _Bridge(host="127.0.0.1")
print("zmq_url=" + bridge.zmq_url)
print("web_url=" + bridge.web_url, flush=True)
bridge.run()
"""


class MeshcatServer:
    """A meshcat server in a child process, bound to 127.0.0.1, that dies with its parent."""

    def __init__(self, timeout: float) -> None:
        load_meshcat()
        cmd = [sys.executable, "-u", "-c", _SERVER_SCRIPT, _SERVER_MARK, str(os.getpid())]
        try:
            # a session of its own: Ctrl-C in a terminal reaches us; we stop the server ourselves
            self.proc: subprocess.Popen[bytes] = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                                                  stderr=subprocess.STDOUT, start_new_session=True)
        except OSError as exc:
            raise ViewerError(f"cannot start the meshcat server: {exc}") from None
        self.output: collections.deque[str] = collections.deque(maxlen=50)
        lines: queue.Queue[str | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, args=(lines,), daemon=True, name="meshcat-server-output")
        self._reader.start()
        urls: dict[str, str] = {}
        deadline = time.monotonic() + timeout
        while len(urls) < 2:
            try:
                line = lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                line = None
            if line is None:  # end of output or time out
                self.close()
                said = "\n".join(self.output) or "(nothing)"
                raise ViewerError(f"the meshcat server did not start within {timeout:g} s; it said:\n{said}")
            for key in ("zmq_url", "web_url"):
                if line.startswith(key + "="):
                    urls[key] = line.split("=", 1)[1]
        self.zmq_url = urls["zmq_url"]
        self.web_url = urls["web_url"]
        log.info("meshcat server (pid %d) at %s", self.proc.pid, self.web_url)

    def _read(self, lines: queue.Queue[str | None]) -> None:
        """Drain the server's output (so it never blocks on a full pipe); pass lines until both URLs came."""
        assert self.proc.stdout is not None
        for raw in self.proc.stdout:
            line = raw.decode(errors="replace").rstrip()
            self.output.append(line)
            lines.put(line)
            log.debug("meshcat server: %s", line)
        lines.put(None)

    @property
    def pid(self) -> int:
        """The server's process id."""
        return self.proc.pid

    def close(self) -> None:
        """Stop the server: close its stdin (it exits), then SIGKILL if it has not within 2 s."""
        proc = self.proc
        if proc.poll() is None:
            if proc.stdin is not None:
                with contextlib.suppress(OSError):
                    proc.stdin.close()
            try:
                proc.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        elif proc.stdin is not None:
            proc.stdin.close()
        self._reader.join(timeout=2.0)
        if proc.stdout is not None:
            proc.stdout.close()
