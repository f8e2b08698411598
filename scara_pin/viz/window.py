"""Where a meshcat scene's commands go: to a meshcat server, and into a record of the scene for a page.

:class:`Window` plays meshcat's ``ViewerWindow`` role: it sends each command to a meshcat server, every request
with a time limit instead of blocking forever, and records the latest state of every node; without a server it
only records. :func:`html_page` makes the recorded commands a self-contained page.

Known meshcat 0.3.2 behaviour designed around: after ``Visualizer.wait()`` the next command can hang forever,
so nothing here waits for a browser (the server replays the scene to every browser that connects).
"""

from __future__ import annotations

import collections
import warnings
import webbrowser
from pathlib import Path
from typing import Any

from ..errors import ScaraError
from .page import SHARE_GEOMETRY, render

__all__ = ["ViewerError", "Window", "html_page", "load_meshcat"]


class ViewerError(ScaraError):
    """The viewer cannot work: meshcat missing, or its server failed to start or stopped answering."""


def load_meshcat() -> Any:
    """Import meshcat (and check Pinocchio's visualizer can use it), or raise :class:`ViewerError`."""
    try:
        with warnings.catch_warnings():  # meshcat 0.3.2 imports pyzmq's deprecated zmq.eventloop.ioloop
            warnings.filterwarnings("ignore", message="zmq.eventloop.ioloop is deprecated", category=DeprecationWarning)
            import meshcat
            import meshcat.animation
            import meshcat.geometry
    except ImportError as exc:
        raise ViewerError(f"the browser viewer needs meshcat ({exc}); install it with: "
                          "pip install 'meshcat>=0.3.2'") from None
    return meshcat


class _Recorder:
    """The latest state of every scene node, as meshcat's server keeps it, to replay in a static page."""

    def __init__(self) -> None:
        self.objects: dict[str, bytes] = {}
        self.properties: dict[str, list[bytes]] = collections.defaultdict(list)
        self.transforms: dict[str, bytes] = {}
        self.shares: dict[str, tuple[str, bytes]] = {}  # path -> (source path, command): see SHARE_GEOMETRY
        self.animation: bytes | None = None

    def add(self, kind: str, path: str, packed: bytes, source: str = "") -> None:
        path = path.rstrip("/")
        if kind == SHARE_GEOMETRY:
            self.shares[path] = (source.rstrip("/"), packed)
        elif kind == "set_object":
            self.objects.pop(path, None)  # re-inserted last: drawn after what it may depend on
            self.objects[path] = packed
            self.properties.pop(path, None)
            self.shares.pop(path, None)
        elif kind == "set_property":
            self.properties[path].append(packed)
        elif kind == "set_transform":
            self.transforms[path] = packed
        elif kind == "set_animation":
            self.animation = packed
        elif kind == "delete":
            def under(key: str) -> bool:
                return key == path or key.startswith(path + "/")

            for table in (self.objects, self.properties, self.transforms):
                for key in [k for k in table if under(k)]:
                    del table[key]
            for key in [k for k, (src, _) in self.shares.items() if under(k) or under(src)]:
                del self.shares[key]

    def commands(self) -> list[bytes]:
        """List the commands to replay, in an order that works.

        Objects and their properties, then the shared geometries (once both their objects exist), then the
        properties of nodes without objects, then transforms, then the animation.
        """
        out: list[bytes] = []
        for path, packed in self.objects.items():
            out.append(packed)
            out.extend(self.properties.get(path, ()))
        out.extend(packed for _, packed in self.shares.values())
        out.extend(p for path, props in self.properties.items() if path not in self.objects for p in props)
        out.extend(self.transforms.values())
        if self.animation is not None:
            out.append(self.animation)
        return out


def html_page(title: str, commands: list[bytes], data: dict[str, Any] | None = None) -> str:
    """Make a self-contained HTML page: meshcat's viewer script and the scene's commands replayed at load.

    With ``data``, also the pendant panel (:func:`scara_pin.viz.page.render`).
    """
    js_path = Path(load_meshcat().__file__).parent / "viewer" / "dist" / "main.min.js"
    try:
        js = js_path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ViewerError(f"meshcat's viewer script {js_path} cannot be read ({exc.strerror})") from None
    return render(title, js.replace("</script", "<\\/script"), commands, data)


class Window:
    """meshcat's ``ViewerWindow`` role: send commands to a server (with a time limit) and record them.

    Without ``zmq_url`` it only records (for :func:`scara_pin.viz.meshcat.static_html`).
    """

    def __init__(self, zmq_url: str | None = None, timeout: float = 10.0) -> None:
        self.recorder = _Recorder()
        self.zmq_url = zmq_url
        self.web_url: str | None = None
        self.timeout = timeout
        self._socket: Any = None
        if zmq_url is not None:
            self._connect()
            self.web_url = self._request([b"url"]).decode("utf-8")
            # meshcat's own client reconnects after asking for the URL (its server's receiver needs it)
            self._connect()

    def _connect(self) -> None:
        import zmq

        self._close_socket()
        sock: Any = zmq.Context.instance().socket(zmq.REQ)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.SNDTIMEO, int(self.timeout * 1000))
        sock.connect(self.zmq_url)
        self._socket = sock

    def _close_socket(self) -> None:
        if self._socket is not None:
            self._socket.close(linger=0)
            self._socket = None

    def _request(self, frames: list[bytes]) -> bytes:
        import zmq

        if self._socket is None:
            raise ViewerError(f"not connected to the meshcat server at {self.zmq_url} (closed, or it stopped "
                              "answering)")
        try:
            self._socket.send_multipart(frames)
            if not self._socket.poll(int(self.timeout * 1000), zmq.POLLIN):
                raise zmq.Again()
            return bytes(self._socket.recv())
        except zmq.ZMQError:
            self._close_socket()  # a REQ socket without its answer is unusable
            raise ViewerError(f"the meshcat server at {self.zmq_url} did not answer within "
                              f"{self.timeout:g} s") from None

    def send(self, command: Any) -> None:
        """Record a command (meshcat's, with ``lower()``) and send it to the server when there is one."""
        import umsgpack

        data = command.lower()
        packed = umsgpack.packb(data)
        self.recorder.add(data["type"], data.get("path", ""), packed, data.get("source", ""))
        if data["type"] == SHARE_GEOMETRY:
            if self.zmq_url is not None:  # meshcat's server has no such command: never sent to it
                raise ViewerError("a shared mesh geometry is for offline pages only (the live viewer sends copies)")
            return
        if self.zmq_url is not None:
            answer = self._request([data["type"].encode("utf-8"), data.get("path", "").encode("utf-8"), packed])
            if answer != b"ok":
                raise ViewerError(f"the meshcat server refused {data['type']}: {answer.decode(errors='replace')}")

    def get_scene(self) -> str:
        """The recorded scene as a self-contained page (meshcat's ``Visualizer.static_html``)."""
        return html_page("scara-pin", self.recorder.commands())

    def open(self) -> Window:
        """Open the server's page in the default web browser (when there is a server)."""
        if self.web_url is not None:
            webbrowser.open(self.web_url, new=2)
        return self

    def wait(self) -> str:
        """Refused: with meshcat 0.3.2 the next command can hang forever after it."""
        raise ViewerError("waiting for a browser is not supported (with meshcat 0.3.2 the next command can hang "
                          "forever); the server replays the scene to every browser that connects")

    def get_image(self) -> Any:
        """Refused: take a screenshot of the page."""
        raise ViewerError("image capture is not supported by scara_pin.viz; take a screenshot of the page")

    def close(self) -> None:
        """Close the connection to the server."""
        self._close_socket()
