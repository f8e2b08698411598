"""See the robot in a browser: meshcat scenes of a configuration, a motion, tool paths, targets, workspaces.

Two ways out, sharing one scene builder:

- :class:`Viewer` starts a meshcat server (a child process bound to 127.0.0.1 only) or connects to a
  running one, and updates the browser live: :meth:`Viewer.display`, :meth:`Viewer.animate` (the
  browser plays the motion in real time), :meth:`Viewer.play` (Python steps it in real time),
  :meth:`Viewer.draw_path`, :meth:`Viewer.draw_targets`, :meth:`Viewer.draw_polylines`,
  :meth:`Viewer.draw_cell` (a cell's obstacles, and the part the tool carries: :func:`draw_cell`).
- :func:`export_html` writes ONE self-contained HTML file (meshcat's JavaScript, ~850 KB, and the scene,
  animation included) that renders offline from ``file://``. It needs no server: the scene's commands are
  recorded and replayed synchronously by the page (no ``fetch``, no network request at all).

Frames: the scene's world is Pinocchio's ``universe`` (the root link). Points, poses and polylines given
to the ``draw_*`` functions are in the robot's base frame (the package's convention, see
:mod:`scara_pin.model`) and converted here. meshcat's three.js scene is Y-up; meshcat turns its root
(``scene.rotateX(-pi/2)``) so that the scene's coordinates are z-up like Pinocchio's: a point (x, y, z)
of the scene is at three.js world (x, z, -y).

The server process is killed by :meth:`Viewer.close` (also on leaving a ``with`` block, and at interpreter
exit through :mod:`atexit`), and it exits by itself when its parent dies, even by SIGKILL: it watches its
stdin (a pipe from the parent, at end of file once the parent is gone) and its parent pid. (Linux's
``PR_SET_PDEATHSIG`` is not used: it fires when the *thread* that started the child ends.)

Known meshcat 0.3.2 behaviour designed around: after ``Visualizer.wait()`` the next command can hang
forever, so nothing here waits for a browser (the server replays the scene to every browser that
connects); every request to the server has a time limit instead of blocking forever.

meshcat and Pinocchio's ``MeshcatVisualizer`` are imported inside the functions that need them; no
solver module imports this one.
"""

from __future__ import annotations

import atexit
import collections
import functools
import logging
import math
import os
import queue
import subprocess
import sys
import threading
import time
import warnings
import webbrowser
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
import pinocchio as pin

from ..description.placeholders import PLACEHOLDER_SIZE
from ..errors import InvalidInputError, ScaraError
from ..limits import MAX_FRAMES, check_count
from .page import SHARE_GEOMETRY

if TYPE_CHECKING:
    from ..cell import Cell
    from ..cell.shapes import Shape
    from ..model import RobotModel

__all__ = [
    "CARRIED_COLOR",
    "CELL_NODE",
    "OBSTACLE_COLOR",
    "ROBOT_NODE",
    "Viewer",
    "ViewerError",
    "draw_cell",
    "export_html",
    "read_trajectory_csv",
    "static_html",
    "tool_path",
]

log = logging.getLogger(__name__)

ROBOT_NODE = "robot"
"""The robot's node under meshcat's root: visuals in ``/meshcat/robot/visuals/<geometry>``, the tool frame's
triad in ``/meshcat/robot/frames/<tool frame>``."""

_OVERLAYS = "overlays"
_DEFAULT_FPS = 30
_PATH_COLOR = 0x1E90FF  # dodger blue: the tool path
_WORKSPACE_COLOR = 0x2E8B57  # sea green: the workspace boundary
_GRID_COLOR = 0x8C96A0  # grey blue: the floor grid
OBSTACLE_COLOR = 0x6A5ACD
"""Slate blue: a cell's obstacles (drawn three-quarters opaque)."""
CARRIED_COLOR = 0x20B2AA
"""Light sea green: the part the tool carries."""
_CELL_OPACITY = 0.75
CELL_NODE = "cell"
"""The cell's obstacles are under ``/meshcat/cell/<obstacle>``; the carried part is under the tool's joint node,
``<joint node>/cell_carried``, so it moves with the robot."""
_SERVER_MARK = "scara-pin-meshcat-server"
"""Argument that marks our meshcat server processes (tests find leftovers by it)."""


class ViewerError(ScaraError):
    """The viewer cannot work: meshcat missing, or its server failed to start or stopped answering."""


# ------------------------------------------------------------------------------------------ lazy imports
def _meshcat() -> Any:
    """Import meshcat (and check Pinocchio's visualizer can use it), or raise :class:`ViewerError`."""
    try:
        with warnings.catch_warnings():  # meshcat 0.3.2 imports pyzmq's deprecated zmq.eventloop.ioloop
            warnings.filterwarnings("ignore", message="zmq.eventloop.ioloop is deprecated", category=DeprecationWarning)
            import meshcat
            import meshcat.animation
            import meshcat.geometry
    except ImportError as exc:
        raise ViewerError(
            f"the browser viewer needs meshcat ({exc}); install it with: pip install 'meshcat>=0.3.2'"
        ) from None
    return meshcat


def _tree_visualizer(robot: RobotModel, paths: list[str]) -> Any:
    """Pinocchio's ``MeshcatVisualizer`` (its geometry and mesh loaders), with tree node names.

    Each geometry's node is under its joint's node of the scene tree (``<joint path>/visuals/<geometry>``),
    instead of one flat group.
    """
    _meshcat()
    from pinocchio.visualize import MeshcatVisualizer

    class _TreeVisualizer(MeshcatVisualizer):  # type: ignore[misc]
        def getViewerNodeName(self, geometry_object: Any, geometry_type: Any) -> str:  # noqa: N802 - Pinocchio's
            group = "visuals" if geometry_type == pin.GeometryType.VISUAL else "collisions"
            return f"{paths[geometry_object.parentJoint]}/{group}/{geometry_object.name}"

    return _TreeVisualizer(robot.model, robot.collision_model, robot.visual_model)


def _resample(times: np.ndarray, qs: np.ndarray, fps: int) -> tuple[np.ndarray, np.ndarray]:
    """The motion on a grid of ``fps`` frames per second: (frame numbers, (F, 4) joint values).

    Joint values are interpolated linearly between samples; the last frame is the last sample.
    """
    if not (isinstance(fps, int) and 1 <= fps <= 1000):
        raise InvalidInputError(f"fps is {fps!r}; it must be a whole number of frames per second in [1, 1000]")
    duration = float(times[-1] - times[0])
    check_count(f"animation frames ({duration:.6g} s at {fps} fps)", duration * fps + 2.0, MAX_FRAMES,
                "shorten the motion")  # fmt: skip
    n = int(math.floor(duration * fps + 1e-9))
    frames = np.arange(n + 1, dtype=float)
    if duration * fps - n > 1e-9:
        frames = np.append(frames, duration * fps)
    grid = times[0] + frames / fps
    q = np.column_stack([np.interp(grid, times, qs[:, j]) for j in range(qs.shape[1])])
    return frames, q


# ------------------------------------------------------------------------------------------ input checks
def _width(value: object) -> int | None:
    """The number of columns of a 2-D array-like (None for anything else)."""
    shape = getattr(value, "shape", None)
    if shape is None:
        try:
            shape = np.shape(value)  # type: ignore[call-overload]
        except ValueError:  # ragged
            return None
    return int(shape[1]) if len(shape) == 2 else None


def _points(name: str, value: object, dim: int) -> np.ndarray:
    """``value`` as an (N, dim) float array of finite numbers, N >= 2, or raise InvalidInputError."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be an array of points of {dim} numbers") from None
    if arr.ndim != 2 or arr.shape[1] != dim or arr.shape[0] < 2:
        raise InvalidInputError(f"{name} must be at least 2 points of {dim} numbers (got shape {arr.shape})")
    if not np.isfinite(arr).all():
        row = int(np.argwhere(~np.isfinite(arr))[0, 0])
        raise InvalidInputError(f"{name}: point {row} is {arr[row].tolist()}; every value must be finite")
    return arr


def _motion(robot: RobotModel, times: object, qs: object, rate: float = _DEFAULT_FPS) -> tuple[np.ndarray, np.ndarray]:
    """Check a sampled motion: (N,) strictly increasing finite times [s] and (N, dof) joint values.

    ``times`` may be a :class:`~scara_pin.motion.trajectory.Trajectory` instead (``qs`` None): it is sampled at
    ``rate`` [Hz], both ends included (the frame count checked against :data:`~scara_pin.limits.MAX_FRAMES`
    before any sample is made).
    """
    from ..motion.trajectory import Trajectory

    n = robot.dof
    if isinstance(times, Trajectory):
        if qs is not None:
            raise InvalidInputError("give a trajectory alone, or times and qs (not both)")
        duration = float(times.duration)
        check_count(f"frames ({duration:.6g} s at {rate:g} fps)", duration * rate + 2.0, MAX_FRAMES)
        t = np.linspace(0.0, duration, max(2, int(math.ceil(duration * rate)) + 1))
        qs = times.sample(t)[0]
        times = t
    elif qs is None:
        raise InvalidInputError(f"give a trajectory, or (N,) times [s] and (N, {n}) joint values qs")
    try:
        t = np.array(times, dtype=float)
        q = np.array(qs, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"times and qs must be numbers: (N,) times [s] and (N, {n}) joint values") from None
    if t.ndim != 1 or t.shape[0] < 1:
        raise InvalidInputError(f"times must be a 1-D array of at least one time [s] (got shape {t.shape})")
    if q.shape != (t.shape[0], n):
        raise InvalidInputError(f"qs must have shape ({t.shape[0]}, {n}), one row per time (got {q.shape})")
    if not np.isfinite(t).all():
        raise InvalidInputError("times must be finite")
    steps = np.diff(t)
    if (steps <= 0).any():
        k = int(np.argmax(steps <= 0))
        raise InvalidInputError(f"times must increase strictly: t[{k + 1}] = {t[k + 1]!r} s after t[{k}] = {t[k]!r} s")
    for row in q:
        robot.check_q(row)
    return t, q


def read_trajectory_csv(path: str | os.PathLike[str], dof: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Read the times and joint values of a trajectory CSV (columns ``t,q1..q{dof}``; others ignored).

    Reads the files of :meth:`scara_pin.motion.trajectory.Trajectory.to_csv` (header ``t,q1..q4,qd1..,qdd1..``)
    with the package's one CSV reader (:func:`scara_pin.tables.read_csv`: bounded, blank lines and lines
    starting with ``#`` skipped).

    Returns:
        ``(times, qs)``: (N,) times [s] and (N, 4) joint values [rad or m].

    Raises:
        InvalidInputError: unreadable file, missing columns, a bad number (the message gives the line).
    """
    from ..limits import MAX_SAMPLES
    from ..tables import read_csv

    table = read_csv(path, ("t", *(f"q{i + 1}" for i in range(dof))), max_rows=MAX_SAMPLES)
    return table[:, 0], table[:, 1:]


def tool_path(robot: RobotModel, qs: object) -> np.ndarray:
    """(N, 3) positions of the tool frame in the base frame [m] along the joint values ``qs`` (N, 4)."""
    q = np.array(qs, dtype=float)
    if q.ndim != 2 or q.shape[1] != robot.dof:
        raise InvalidInputError(f"qs must have shape (N, {robot.dof}) (got {q.shape})")
    return np.array([robot.tool_placement(robot.check_q(row)).translation for row in q])


# ------------------------------------------------------------------------------------------ recorded scene
class _Recorder:
    """The latest state of every scene node, as meshcat's server keeps it, to replay in a static page."""

    def __init__(self) -> None:
        self.objects: dict[str, bytes] = {}
        self.properties: dict[str, list[bytes]] = collections.defaultdict(list)
        self.transforms: dict[str, bytes] = {}
        self.shares: dict[str, tuple[str, bytes]] = {}  # path -> (source path, command): see _ShareGeometry
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


def _viewer_js() -> str:
    meshcat = _meshcat()
    js_path = Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js"
    try:
        js = js_path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ViewerError(f"meshcat's viewer script {js_path} cannot be read ({exc.strerror})") from None
    return js.replace("</script", "<\\/script")


def _page(title: str, commands: list[bytes], data: dict[str, Any] | None = None) -> str:
    """Make a self-contained HTML page: meshcat's viewer script and the scene's commands replayed at load.

    With ``data``, also the pendant panel (:func:`scara_pin.viz.page.render`).
    """
    from .page import render

    return render(title, _viewer_js(), commands, data)


# ------------------------------------------------------------------------------------------ server side
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


class _Server:
    """A meshcat server in a child process, bound to 127.0.0.1, that dies with its parent."""

    def __init__(self, timeout: float) -> None:
        _meshcat()
        cmd = [sys.executable, "-u", "-c", _SERVER_SCRIPT, _SERVER_MARK, str(os.getpid())]
        try:
            self.proc: subprocess.Popen[bytes] = subprocess.Popen(
                cmd,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                start_new_session=True,  # Ctrl-C in a terminal reaches us; we stop the server ourselves
            )
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
        return self.proc.pid

    def close(self) -> None:
        """Stop the server: close its stdin (it exits), then SIGKILL if it has not within 2 s."""
        proc = self.proc
        if proc.poll() is None:
            if proc.stdin is not None:
                try:
                    proc.stdin.close()
                except OSError:
                    pass
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


class _Window:
    """meshcat's ``ViewerWindow`` role: send commands to a server (with a time limit) and record them.

    Without ``zmq_url`` it only records (for :func:`static_html`).
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
            raise ViewerError(
                f"not connected to the meshcat server at {self.zmq_url} (closed, or it stopped answering)"
            )
        try:
            self._socket.send_multipart(frames)
            if not self._socket.poll(int(self.timeout * 1000), zmq.POLLIN):
                raise zmq.Again()
            return bytes(self._socket.recv())
        except zmq.ZMQError:
            self._close_socket()  # a REQ socket without its answer is unusable
            raise ViewerError(
                f"the meshcat server at {self.zmq_url} did not answer within {self.timeout:g} s"
            ) from None

    def send(self, command: Any) -> None:
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
        return _page("scara-pin", self.recorder.commands())

    def open(self) -> _Window:
        if self.web_url is not None:
            webbrowser.open(self.web_url, new=2)
        return self

    def wait(self) -> str:
        raise ViewerError(
            "waiting for a browser is not supported (with meshcat 0.3.2 the next command can hang forever); "
            "the server replays the scene to every browser that connects"
        )

    def get_image(self) -> Any:
        raise ViewerError("image capture is not supported by scara_pin.viz; take a screenshot of the page")

    def close(self) -> None:
        self._close_socket()


# ------------------------------------------------------------------------------------------ meshes (issue 13)
class _ShareGeometry:
    """The :data:`SHARE_GEOMETRY` command (meshcat's command interface: ``lower()``)."""

    def __init__(self, path: str, source: str) -> None:
        self.path, self.source = path, source

    def lower(self) -> dict[str, str]:
        return {"type": SHARE_GEOMETRY, "path": self.path, "source": self.source}


@functools.cache
def _scaled_mesh_class() -> Any:
    """Meshcat's triangle mesh geometry, with a visual's ``scale`` as the object's matrix.

    The vertices are sent as read (the file's unit applied), so one copy serves visuals of any scale.
    """
    mg = _meshcat().geometry

    class ScaledMesh(mg.TriangularMeshGeometry):  # type: ignore[misc, name-defined]
        def __init__(self, vertices: np.ndarray, faces: np.ndarray, scale: tuple[float, float, float]) -> None:
            super().__init__(vertices, faces)
            self.scale = scale

        def intrinsic_transform(self) -> np.ndarray:
            return np.diag([*self.scale, 1.0])

    return ScaledMesh


_STAND_IN = (np.eye(3, dtype=np.float32) * PLACEHOLDER_SIZE, np.array([[0, 1, 2]], dtype=np.uint32))
"""The one triangle a sharing visual's object holds until the page gives it the shared geometry."""


def _draw_meshes(vis: Any, robot: RobotModel, viz: Any, share: bool) -> None:
    """Set each readable mesh of the robot's visuals (:func:`scara_pin.cell.meshes.visual_meshes`) on its node.

    The scene drew a placeholder box for each mesh at the geometry's node (``viz.getViewerNodeName``, under
    its joint's node); the mesh replaces the box there, in the URDF's colour, its ``scale`` as the object's
    matrix. With ``share`` (a recorded page), a mesh named by several visuals is embedded once
    (:data:`SHARE_GEOMETRY`); else (meshcat's live server) each visual gets a copy, and the copies count
    against :data:`~scara_pin.limits.MAX_PAGE_MESH_BYTES` together.
    """
    from ..cell.meshes import visual_meshes
    from ..limits import MAX_PAGE_MESH_BYTES

    mg = _meshcat().geometry
    scaled = _scaled_mesh_class()
    visuals = robot.visual_model
    drawn: dict[int, str] = {}  # id of a MeshGeometry -> the node path (lowered) holding its triangles
    sent = 0
    over: dict[str, list[str]] = {}  # the meshes whose copies went over the cap -> the links left as boxes
    for mesh in visual_meshes(robot):
        if not visuals.existGeometryName(mesh.name):
            continue
        geometry_object = visuals.geometryObjects[visuals.getGeometryId(mesh.name)]
        rgba = geometry_object.meshColor
        color = int(rgba[0] * 255) * 65536 + int(rgba[1] * 255) * 256 + int(rgba[2] * 255)
        material = mg.MeshPhongMaterial(color=color, opacity=float(rgba[3]), transparent=float(rgba[3]) < 1.0)
        node = vis[viz.getViewerNodeName(geometry_object, pin.GeometryType.VISUAL)]
        source = drawn.get(id(mesh.geometry)) if share else None
        if source is not None:
            node.set_object(scaled(*_STAND_IN, mesh.scale), material)
            node.window.send(_ShareGeometry(node.path.lower(), source))
            continue
        size = mesh.geometry.embedded_bytes
        if not share and sent + size > MAX_PAGE_MESH_BYTES:
            over.setdefault(mesh.filename, []).append(mesh.link)
            continue
        sent += size
        node.set_object(scaled(mesh.geometry.vertices, mesh.geometry.faces, mesh.scale), material)
        drawn[id(mesh.geometry)] = node.path.lower()
    for filename, links in over.items():
        log.warning("mesh %r: %d of its copies (links %s) would take the meshes sent over %.0f MiB, the cap; drawn "
                    "as %g m boxes", filename, len(links), ", ".join(sorted(set(links))),
                    MAX_PAGE_MESH_BYTES / 2**20, PLACEHOLDER_SIZE)  # fmt: skip


# ------------------------------------------------------------------------------------------ the scene
class _Scene:
    """The robot and the overlays in a meshcat visualizer (live or recording).

    The robot is a tree of nodes under ``/meshcat/robot``: one node per joint, nested as the kinematic tree
    (``robot/joint1/joint2/...``), holding Pinocchio's ``liMi`` (see :mod:`scara_pin.viz.tree`); each
    link's geometries in ``<joint node>/visuals/<geometry>`` and the frames' triads in
    ``<joint node>/frames/<frame>``, at their constant placements. Showing a configuration sets the joint
    nodes' transforms only. The floor grid lies at z = 0 of the root link; the camera frames the workspace.
    """

    def __init__(self, robot: RobotModel, window: _Window) -> None:
        from ..cell.meshes import check_visual_count
        from .tree import framing, joint_nodes, node_paths

        check_visual_count(robot)  # sized first: each visual is a node and a geometry of the page
        meshcat = _meshcat()
        self.robot = robot
        self.vis = meshcat.Visualizer(window=window)
        self.joints = joint_nodes(robot, ROBOT_NODE)
        self.paths = node_paths(robot, ROBOT_NODE)
        self.framing = framing(robot)
        self._data = robot.model.createData()
        q0 = pin.neutral(robot.model)
        pin.framesForwardKinematics(robot.model, self._data, q0)
        self.oMb: pin.SE3 = self._data.oMf[robot.base_id].copy()
        # scene size [m]: the robot's reach (axes and markers scale with it)
        self.size = max(0.05, self.framing.reach)
        self.viz = _tree_visualizer(robot, self.paths)
        self.viz.initViewer(viewer=self.vis)
        try:  # an unreadable geometry: the user's file, not a bug
            for geometry in robot.visual_model.geometryObjects:
                self._load_geometry(geometry)
        except (ValueError, RuntimeError, OSError) as exc:
            raise InvalidInputError(f"cannot show the robot's geometry: {' '.join(str(exc).split())}") from None
        # the real meshes in place of their placeholder boxes; a recorded page embeds each mesh once
        _draw_meshes(self.vis, robot, self.viz, share=window.zmq_url is None)
        self.frame_paths: dict[str, str] = {}
        for frame_id in (robot.base_id, robot.tool_id):
            self._triad(frame_id, 0.25 * self.size)
        # the tool frame's zero-yaw rotation in the base frame: target markers are Rz(yaw) * R0
        zero = robot.tool_placement(np.zeros(robot.dof))
        yaw0 = math.atan2(zero.rotation[1, 0], zero.rotation[0, 0])
        self.tool_r0 = pin.utils.rotate("z", -yaw0) @ zero.rotation
        self._floor()
        self._camera()
        self.display(robot.default_q)

    def _load_geometry(self, geometry: pin.GeometryObject) -> None:
        """Load one visual geometry (primitive or mesh, by Pinocchio's loader) under its joint's node."""
        from pinocchio.visualize.meshcat_visualizer import applyScalingOnHomegeneousTransform

        self.viz.loadViewerGeometryObject(geometry, pin.GeometryType.VISUAL)
        path = self.viz.getViewerNodeName(geometry, pin.GeometryType.VISUAL)
        matrix = applyScalingOnHomegeneousTransform(geometry.placement.homogeneous, geometry.meshScale)
        self.vis[path].set_transform(matrix)

    def _triad(self, frame_id: int, length: float) -> None:
        """Draw a frame's axes (x red, y green, z blue) under its joint's node."""
        mg = _meshcat().geometry
        frame = self.robot.model.frames[frame_id]
        path = f"{self.paths[frame.parentJoint]}/frames/{frame.name}"
        self.vis[path].set_object(mg.triad(length))
        self.vis[path].set_transform(frame.placement.homogeneous)
        self.frame_paths[frame.name] = path

    def _floor(self) -> None:
        """A grid on the floor (z = 0 of the root link), sized to the reach, instead of meshcat's 20 m one."""
        mg = _meshcat().geometry
        cell, half = self.framing.grid_cell, self.framing.grid_half
        ticks = np.arange(-half, half + 0.5 * cell, cell)
        segments = []
        for t in ticks.tolist():
            segments += [[t, -half, 0.0], [t, half, 0.0], [-half, t, 0.0], [half, t, 0.0]]
        geometry = mg.PointsGeometry(np.ascontiguousarray(np.array(segments).T, dtype=np.float32))
        self.vis[f"{_OVERLAYS}/floor"].set_object(mg.LineSegments(geometry, mg.LineBasicMaterial(color=_GRID_COLOR)))
        self.vis["/Grid"].set_property("visible", False)
        # meshcat's world axes are 0.5 m long whatever the robot: the base frame's triad shows the axes
        self.vis["/Axes"].set_property("visible", False)
        self.vis["/Background"].set_property("top_color", [0.97, 0.97, 0.98])
        self.vis["/Background"].set_property("bottom_color", [0.72, 0.76, 0.82])

    def _camera(self) -> None:
        """Frame the workspace from the front right, above (:func:`scara_pin.viz.tree.framing`).

        meshcat's orbit controls turn about the origin, so the live viewer's camera is placed to frame the
        workspace seen from there; the pages move the orbit target to the workspace's centre as well.
        """
        from .tree import FIELD_OF_VIEW

        f = self.framing
        target, position = np.array(f.target), np.array(f.position)
        # seen from the origin: the same direction, farther by the target's distance from the origin
        live = position - target
        live = live * (1.0 + float(np.linalg.norm(target)) / float(np.linalg.norm(live)))
        x, y, z = live.tolist()
        # the camera lives in /Cameras/default/rotated, turned by +pi/2 about x: scene (x, y, z) -> (x, z, -y)
        camera = self.vis["/Cameras/default/rotated/<object>"]
        camera.set_property("position", [x, z, -y])
        camera.set_property("fov", FIELD_OF_VIEW)

    def page_data(self) -> dict[str, Any]:
        """What the page's script needs: the joint nodes, the sliders' ranges and units, frames, camera."""
        robot = self.robot
        kinds = robot.joint_kinds
        f = self.framing
        return {
            "robot": robot.name,
            "root": f"meshcat/{ROBOT_NODE}",
            "joints": [
                {
                    "name": j.name,
                    "path": f"meshcat/{j.path}",
                    "kind": j.kind,
                    "axis": list(j.axis),
                    "placement": [x for row in j.placement for x in row],
                    "source": j.source,
                    "multiplier": j.multiplier,
                    "offset": j.offset,
                }
                for j in self.joints
            ],
            "sliders": [
                {
                    "name": j.name,
                    "index": j.source,
                    "lower": robot.limits.lower[j.source],
                    "upper": robot.limits.upper[j.source],
                    "unit": "m" if kinds[j.source] == "length" else "rad",
                    "continuous": robot.continuous[j.source],
                }
                for j in self.joints
                if j.actuated
            ],
            "base": f"meshcat/{self.frame_paths[robot.base_frame]}",
            "tool": f"meshcat/{self.frame_paths[robot.tool_frame]}",
            "base_frame": robot.base_frame,
            "tool_frame": robot.tool_frame,
            "target": list(f.target),
            "camera": list(f.position),
        }

    def display(self, q: object) -> None:
        """Show the robot at the user's joint values ``q``: set every joint node's ``liMi``."""
        self._set_joints(self.vis, self.robot.to_pinocchio_q(q))  # continuous joints: their (cos, sin)

    def _set_joints(self, vis: Any, q_pin: np.ndarray) -> None:
        pin.forwardKinematics(self.robot.model, self._data, q_pin)
        for j in range(1, self.robot.model.njoints):
            vis[self.paths[j]].set_transform(self._data.liMi[j].homogeneous)

    def animation(self, times: np.ndarray, qs: np.ndarray, fps: int) -> Any:
        """Build a meshcat animation of the motion, ``fps`` frames per second.

        Joint values are interpolated linearly between the samples; three.js interpolates between frames.
        """
        meshcat = _meshcat()
        frames, q = _resample(times, qs, fps)
        anim = meshcat.animation.Animation(default_framerate=fps)
        for frame, row in zip(frames.tolist(), q, strict=True):
            with anim.at_frame(self.vis, frame) as at:
                self._set_joints(at, self.robot.to_pinocchio_q(row))
        return anim

    def _world(self, points_base: np.ndarray) -> np.ndarray:
        """(N, 3) base-frame points -> (N, 3) scene (universe) points."""
        return points_base @ self.oMb.rotation.T + self.oMb.translation

    def line(self, path: str, points_world: np.ndarray, color: int) -> None:
        mg = _meshcat().geometry
        geometry = mg.PointsGeometry(np.ascontiguousarray(points_world.T, dtype=np.float32))
        self.vis[path].set_object(mg.Line(geometry, mg.LineBasicMaterial(color=color)))

    def draw_path(self, points: object, name: str, color: int) -> None:
        pts = _points("points", points, 3)
        self.line(f"{_OVERLAYS}/{name}", self._world(pts), color)

    def draw_targets(self, poses: object, name: str) -> None:
        """Target poses as triads oriented as the tool frame would be there: ``Rz(yaw) * R0``."""
        mg = _meshcat().geometry
        arr = np.array(poses, dtype=float)
        if arr.ndim == 1:
            arr = arr[None, :]
        if arr.ndim != 2 or arr.shape[1] != 4 or not np.isfinite(arr).all():
            raise InvalidInputError(f"poses must be finite (x, y, z, yaw) rows [m, rad] (got shape {arr.shape})")
        node = self.vis[f"{_OVERLAYS}/{name}"]
        node.delete()
        for i, (x, y, z, yaw) in enumerate(arr.tolist()):
            bMt = pin.SE3(pin.utils.rotate("z", yaw) @ self.tool_r0, np.array([x, y, z]))
            node[str(i)].set_object(mg.triad(0.15 * self.size))
            node[str(i)].set_transform((self.oMb * bMt).homogeneous)

    def draw_polylines(self, polylines: Iterable[object], name: str, z: float | None, color: int) -> None:
        if isinstance(polylines, np.ndarray) and polylines.ndim == 2:
            polylines = [polylines]
        # (x, y) points, drawn at one height, or (x, y, z) points, drawn as given (base frame)
        checked = [_points(f"polyline {i}", p, 3 if _width(p) == 3 else 2) for i, p in enumerate(polylines)]
        # default height: the floor, z = 0 of the root link, expressed in the base frame
        zb = -float(self.oMb.translation[2]) if z is None else float(z)
        node = self.vis[f"{_OVERLAYS}/{name}"]
        node.delete()
        for i, xy in enumerate(checked):
            pts = xy if xy.shape[1] == 3 else np.column_stack([xy, np.full(len(xy), zb)])
            self.line(f"{_OVERLAYS}/{name}/{i}", self._world(pts), color)


def _scene(
    scene: _Scene,
    q: object | None,
    times: object | None,
    qs: object | None,
    polylines: Iterable[object] | None,
    path_points: object | None,
    targets: object | None,
    *,
    draw_tool_path: bool,
    fps: int,
    loop: bool,
    cell: Cell | None = None,
) -> dict[str, Any]:
    """Fill a scene with what :func:`static_html` and :func:`export_html` take; return the page's data.

    A motion is not a meshcat animation here: the page's player interpolates the joint values (resampled at
    ``fps``) and moves the joints through the same code as the sliders.
    """
    robot = scene.robot
    if (times is None) != (qs is None):
        raise InvalidInputError("times and qs go together: give both or neither")
    data = scene.page_data()
    shown = robot.default_q if q is None else robot.check_q(q)
    if polylines is not None:
        scene.draw_polylines(polylines, "workspace", None, _WORKSPACE_COLOR)
    if path_points is not None:
        scene.draw_path(path_points, "path", _PATH_COLOR)
    if targets is not None:
        scene.draw_targets(targets, "targets")
    if cell is not None:
        draw_cell(scene, cell)
    if times is not None:
        t, qq = _motion(robot, times, qs)
        if q is None:
            shown = qq[0]
        if path_points is None and draw_tool_path and len(t) >= 2:
            scene.draw_path(tool_path(robot, qq), "path", _PATH_COLOR)
        if len(t) >= 2:
            frames, grid = _resample(t, qq, fps)
            data["motion"] = {
                "times": (frames / fps).tolist(),
                "qs": grid.tolist(),
                "loop": bool(loop),
                "play": q is None,
            }
    scene.display(shown)
    data["q"] = [float(v) for v in shown]
    return data


def static_html(
    robot: RobotModel,
    q: object | None = None,
    times: object | None = None,
    qs: object | None = None,
    polylines: Iterable[object] | None = None,
    path_points: object | None = None,
    targets: object | None = None,
    *,
    draw_tool_path: bool = True,
    fps: int = _DEFAULT_FPS,
    loop: bool = True,
    title: str | None = None,
    cell: Cell | None = None,
) -> str:
    """Make a self-contained HTML page of the robot (no server needed; arguments as :func:`export_html`)."""
    window = _Window()
    scene = _Scene(robot, window)
    data = _scene(
        scene, q, times, qs, polylines, path_points, targets, draw_tool_path=draw_tool_path, fps=fps, loop=loop,
        cell=cell,
    )
    return _page(title or f"scara-pin: {robot.name}", window.recorder.commands(), data)


def export_html(
    robot: RobotModel,
    path: str | os.PathLike[str],
    q: object | None = None,
    times: object | None = None,
    qs: object | None = None,
    polylines: Iterable[object] | None = None,
    path_points: object | None = None,
    targets: object | None = None,
    *,
    draw_tool_path: bool = True,
    fps: int = _DEFAULT_FPS,
    loop: bool = True,
    title: str | None = None,
    cell: Cell | None = None,
) -> Path:
    """Write one self-contained HTML page of the robot, that renders offline from ``file://``; atomically.

    The page holds meshcat's viewer script (~850 KB) and the scene; it makes no network request.

    Args:
        robot: the robot.
        path: the file to write.
        q: the configuration shown [rad or m] (default: the first sample of the motion, else neutral).
        times: (N,) sample times of a motion [s], strictly increasing; with ``qs``.
        qs: (N, 4) joint values at those times; the page plays the motion in real time (looping unless
            ``loop=False``) with the panel's play / pause button and time slider, which drive the joint
            sliders (a given ``q`` is shown first, paused).
        polylines: workspace boundary: (M, 2) arrays of (x, y) in the base frame [m], drawn on the floor,
            or (M, 3) arrays of (x, y, z) in the base frame [m].
        path_points: (K, 3) points of a tool path in the base frame [m]; by default the path of the tool
            along ``qs`` is drawn (``draw_tool_path=False`` turns that off).
        targets: (P, 4) target poses (x, y, z, yaw) in the base frame [m, rad], drawn as small frames.
        draw_tool_path: draw the path of the tool along ``qs`` when no ``path_points`` are given.
        fps: the player's samples per second (joint values are interpolated linearly between samples).
        loop: repeat the animation forever (else play it once and hold the last frame).
        title: the page title.
        cell: a cell whose obstacles (and carried part, on the tool) are drawn (:func:`draw_cell`).

    Returns:
        The path written.

    Raises:
        InvalidInputError: bad inputs, or the file cannot be written.
        ViewerError: meshcat is not installed.
    """
    from ..files import write_atomic_with

    text = static_html(
        robot, q, times, qs, polylines, path_points, targets,
        draw_tool_path=draw_tool_path, fps=fps, loop=loop, title=title, cell=cell,
    )  # fmt: skip
    out = Path(path)
    write_atomic_with(out, lambda handle: handle.write(text))
    return out


# ------------------------------------------------------------------------------------------ the cell
def draw_cell(target: Viewer | _Scene, cell: Cell) -> None:
    """Draw a cell: its obstacles where they stand, and the part the tool carries on the tool (it moves with it).

    Boxes, spheres and cylinders are meshcat's primitives (a cylinder along its own z axis, as in URDF: Pinocchio's
    loader turns three.js's y-axis cylinder), meshes their triangles; obstacles in :data:`OBSTACLE_COLOR`, the
    carried part in :data:`CARRIED_COLOR`. Drawing again replaces the cell drawn before (``/meshcat/cell``).

    Args:
        target: a live :class:`Viewer`, or the scene of a page being recorded (the teach pendant's).
        cell: the cell (its shapes in the robot's base frame; the carried part in the tool frame).
    """
    scene = target._live() if isinstance(target, Viewer) else target
    mg = _meshcat().geometry
    node = scene.vis[CELL_NODE]
    node.delete()
    robot = scene.robot
    tool = robot.model.frames[robot.tool_id]
    carried_path = f"{scene.paths[tool.parentJoint]}/cell_carried"
    scene.vis[carried_path].delete()
    for o in cell.obstacles:
        material = mg.MeshLambertMaterial(color=OBSTACLE_COLOR, opacity=_CELL_OPACITY, transparent=True)
        scene.vis[f"{CELL_NODE}/{o.name}"].set_object(_cell_object(o.shape), material)
        scene.vis[f"{CELL_NODE}/{o.name}"].set_transform((scene.oMb * o.shape.placement()).homogeneous)
    if cell.carried is not None:
        material = mg.MeshLambertMaterial(color=CARRIED_COLOR, opacity=1.0)
        scene.vis[carried_path].set_object(_cell_object(cell.carried), material)
        scene.vis[carried_path].set_transform((tool.placement * cell.carried.placement()).homogeneous)


def _cell_object(shape: Shape) -> Any:
    """A meshcat geometry of a cell shape, in the shape's own frame."""
    from pinocchio.visualize.meshcat_visualizer import loadPrimitive

    if shape.kind == "mesh":
        assert shape.vertices is not None and shape.faces is not None  # noqa: S101 - a mesh shape has them
        return _meshcat().geometry.TriangularMeshGeometry(shape.vertices, shape.faces)
    return loadPrimitive(pin.GeometryObject("cell", 0, 0, pin.SE3.Identity(), shape.geometry()))


# ------------------------------------------------------------------------------------------ live viewer
class Viewer:
    """A live meshcat view of a robot in the browser, at :attr:`url`.

    Starts its own meshcat server (a child process on 127.0.0.1) unless ``zmq_url`` names a running one.
    Use it as a context manager, or call :meth:`close`; the server is also stopped at interpreter exit
    and when this process dies.

    Example::

        with Viewer(robot) as viewer:
            print(viewer.url)
            viewer.display([0.1, 0.2, 0.05, 0.3])
            viewer.play(trajectory)         # Python steps it in real time
            viewer.animate(trajectory)      # the browser plays it (play / pause / time slider)

    Attributes:
        robot: the robot shown.
    """

    robot: RobotModel
    DEFAULT_TIMEOUT: ClassVar[float] = 20.0

    def __init__(
        self,
        robot: RobotModel,
        open: bool = False,  # noqa: A002 - the name the command line uses (--open)
        *,
        zmq_url: str | None = None,
        timeout: float = DEFAULT_TIMEOUT,
    ) -> None:
        """Start (or connect to) a meshcat server and load the robot into it.

        Args:
            robot: the robot to show.
            open: open the page in the default web browser.
            zmq_url: a running meshcat server's ZeroMQ address (``tcp://127.0.0.1:6000``); default: start one.
            timeout: the longest wait for the server to start or to answer a command [s].

        Raises:
            ViewerError: meshcat is missing, or the server does not start or answer.
        """
        self.robot = robot
        self._server: _Server | None = None
        self._window: _Window | None = None
        self._closed = False
        atexit.register(self.close)
        try:
            if zmq_url is None:
                self._server = _Server(timeout)
                zmq_url = self._server.zmq_url
            self._window = _Window(zmq_url, timeout)
            self._scene = _Scene(robot, self._window)
        except BaseException:
            self.close()
            raise
        if open:
            self._window.open()

    # ----------------------------------------------------------------- properties
    @property
    def url(self) -> str:
        """The page to open in a browser (``http://127.0.0.1:<port>/static/``)."""
        assert self._window is not None and self._window.web_url is not None
        return self._window.web_url

    @property
    def zmq_url(self) -> str:
        """The server's ZeroMQ address (another :class:`Viewer` can connect to it)."""
        assert self._window is not None and self._window.zmq_url is not None
        return self._window.zmq_url

    @property
    def server_pid(self) -> int | None:
        """Process id of the server this viewer started (None when it connected to a running one)."""
        return None if self._server is None else self._server.pid

    @property
    def visualizer(self) -> Any:
        """The underlying ``meshcat.Visualizer`` (for drawing anything else)."""
        return self._scene.vis

    # ----------------------------------------------------------------- drawing
    def _live(self) -> _Scene:
        if self._closed:
            raise ViewerError("the viewer is closed")
        return self._scene

    def display(self, q: object) -> None:
        """Show the robot at ``q`` [rad or m] (stops nothing: an animation playing keeps playing)."""
        self._live().display(q)

    def animate(
        self, times: object, qs: object = None, *, fps: int = _DEFAULT_FPS, loop: bool = False, play: bool = True
    ) -> None:
        """Send the motion to the browser, which plays it in real time (play / pause / time controls).

        Args:
            times: (N,) strictly increasing sample times [s], N >= 2; or a
                :class:`~scara_pin.motion.trajectory.Trajectory` (``qs`` None), sampled at ``fps``.
            qs: (N, 4) joint values [rad or m].
            fps: animation frames per second (joint values are interpolated linearly between samples).
            loop: repeat forever (else play once and hold the last frame).
            play: start playing at once (meshcat's time slider moves the robot only once the animation
                has been played: press play, then pause).
        """
        scene = self._live()
        t, q = _motion(self.robot, times, qs, fps)
        if len(t) < 2:
            raise InvalidInputError("an animation needs at least 2 samples; use display() for one")
        scene.vis.set_animation(scene.animation(t, q, fps), play=play, repetitions=math.inf if loop else 1)

    def play(self, times: object, qs: object = None, *, speed: float = 1.0, rate: float = _DEFAULT_FPS) -> None:
        """Step the robot through the motion from Python, in real time (blocks until the end).

        ``viewer.play(trajectory)`` plays a :class:`~scara_pin.motion.trajectory.Trajectory` (sampled at
        ``rate`` [Hz]); ``viewer.play(times, qs)`` plays samples. Samples whose time has passed while the
        previous one was sent are skipped, so the motion keeps to the clock. ``speed`` > 1 plays faster.
        """
        if not (math.isfinite(speed) and speed > 0):
            raise InvalidInputError(f"speed is {speed}; it must be > 0")
        if not (math.isfinite(rate) and rate > 0):
            raise InvalidInputError(f"rate is {rate} Hz; it must be > 0")
        scene = self._live()
        t, q = _motion(self.robot, times, qs, rate)
        start = time.monotonic()
        k = 0
        while k < len(t):
            now = (time.monotonic() - start) * speed + t[0]
            # the latest sample that is due
            k_due = int(np.searchsorted(t, now, side="right")) - 1
            if k_due >= k:
                k = k_due
                scene.display(q[k])
                k += 1
            if k < len(t):
                time.sleep(max(0.0, (t[k] - t[0]) / speed - (time.monotonic() - start)))

    def draw_path(self, points: object, *, name: str = "path", color: int = _PATH_COLOR) -> None:
        """Draw a tool path: a line through (N, 3) points in the base frame [m]."""
        self._live().draw_path(points, name, color)

    def draw_tool_path(self, qs: object, *, name: str = "path", color: int = _PATH_COLOR) -> None:
        """Draw the path of the tool frame along (N, 4) joint values."""
        self._live().draw_path(tool_path(self.robot, qs), name, color)

    def draw_targets(self, poses: object, *, name: str = "targets") -> None:
        """Draw target poses (x, y, z, yaw) in the base frame [m, rad] as small frames (red x, green y, blue z)."""
        self._live().draw_targets(poses, name)

    def draw_polylines(
        self,
        polylines: Iterable[object],
        *,
        name: str = "workspace",
        z: float | None = None,
        color: int = _WORKSPACE_COLOR,
    ) -> None:
        """Draw polylines of (x, y) points in the base frame [m], e.g. a workspace boundary.

        They lie on the floor (z = 0 of the root link) unless ``z`` gives a height in the base frame [m].
        Drawing again under the same ``name`` replaces them.
        """
        self._live().draw_polylines(polylines, name, z, color)

    def draw_cell(self, cell: Cell) -> None:
        """Draw a cell's obstacles and the part the tool carries (:func:`draw_cell`)."""
        draw_cell(self, cell)

    def clear(self, name: str) -> None:
        """Remove an overlay drawn under ``name`` ("path", "targets", "workspace", ...)."""
        self._live().vis[f"{_OVERLAYS}/{name}"].delete()

    # ----------------------------------------------------------------- export
    def static_html(self, title: str | None = None) -> str:
        """Return the current scene (animation included) as a self-contained HTML page."""
        assert self._window is not None
        self._live()
        return _page(title or f"scara-pin: {self.robot.name}", self._window.recorder.commands())

    def save_html(self, path: str | os.PathLike[str], title: str | None = None) -> Path:
        """Write :meth:`static_html` to ``path``, atomically; return the path."""
        from ..files import write_atomic_with

        text = self.static_html(title)
        out = Path(path)
        write_atomic_with(out, lambda handle: handle.write(text))
        return out

    # ----------------------------------------------------------------- life cycle
    def serve(self, poll: float = 0.5) -> None:
        """Block while the server runs (for a command that serves until Ctrl-C: KeyboardInterrupt passes).

        Raises:
            ViewerError: the server this viewer started stopped (it was killed).
        """
        self._live()
        while True:
            if self._server is not None and self._server.proc.poll() is not None:
                code = self._server.proc.returncode
                self.close()
                raise ViewerError(f"the meshcat server stopped (exit status {code})")
            time.sleep(poll)

    def close(self) -> None:
        """Disconnect and stop the server this viewer started (idempotent)."""
        if self._closed:
            return
        self._closed = True
        atexit.unregister(self.close)
        if self._window is not None:
            self._window.close()
        if self._server is not None:
            self._server.close()
            log.info("meshcat server (pid %d) stopped", self._server.pid)

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        state = "closed" if self._closed else (self._window.web_url if self._window else "starting")
        return f"<Viewer of {self.robot.name!r} at {state}>"
