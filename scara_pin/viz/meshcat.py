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
:mod:`scara_pin.model`) and converted by the scene. meshcat's three.js scene is Y-up; meshcat turns its root
(``scene.rotateX(-pi/2)``) so that the scene's coordinates are z-up like Pinocchio's: a point (x, y, z)
of the scene is at three.js world (x, z, -y).

The server process is killed by :meth:`Viewer.close` (also on leaving a ``with`` block, and at interpreter
exit through :mod:`atexit`), and it exits by itself when its parent dies (:mod:`scara_pin.viz.server`). The
scene is built by :mod:`scara_pin.viz.scene`, its commands sent and recorded by :mod:`scara_pin.viz.window`.
meshcat and Pinocchio's ``MeshcatVisualizer`` are imported inside the functions that need them; no solver
module imports this one.
"""

from __future__ import annotations

import atexit
import logging
import math
import os
import time
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from ..errors import InvalidInputError
from ..files import write_text_atomic
from .scene import (
    CARRIED_COLOR,
    CELL_NODE,
    DEFAULT_FPS,
    OBSTACLE_COLOR,
    OVERLAYS,
    PATH_COLOR,
    ROBOT_NODE,
    WORKSPACE_COLOR,
    MeshcatScene,
    checked_motion,
    recorded_scene,
    tool_path,
)
from .server import MeshcatServer
from .window import ViewerError, Window

if TYPE_CHECKING:
    from ..cell import Cell
    from ..model import RobotModel

__all__ = ["CARRIED_COLOR", "CELL_NODE", "OBSTACLE_COLOR", "ROBOT_NODE", "Viewer", "ViewerError", "draw_cell",
           "export_html", "read_trajectory_csv", "static_html", "tool_path"]

log = logging.getLogger(__name__)


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
    fps: int = DEFAULT_FPS,
    loop: bool = True,
    title: str | None = None,
    cell: Cell | None = None,
    target_names: Iterable[str] | None = None,
) -> str:
    """Make a self-contained HTML page of the robot (no server needed; arguments as :func:`export_html`)."""
    scene, data = recorded_scene(robot, q, times, qs, polylines, path_points, targets, draw_tool_path=draw_tool_path,
                                 fps=fps, loop=loop, cell=cell, target_names=target_names)  # fmt: skip
    return scene.page(title or f"scara-pin: {robot.name}", data)


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
    fps: int = DEFAULT_FPS,
    loop: bool = True,
    title: str | None = None,
    cell: Cell | None = None,
    target_names: Iterable[str] | None = None,
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
        cell: a cell whose obstacles (and carried part, on the tool) are drawn (:func:`draw_cell`), each named.
        target_names: the targets' names (taught points), written beside them.

    Returns:
        The path written.

    Raises:
        InvalidInputError: bad inputs, or the file cannot be written.
        ViewerError: meshcat is not installed.
    """
    text = static_html(
        robot, q, times, qs, polylines, path_points, targets,
        draw_tool_path=draw_tool_path, fps=fps, loop=loop, title=title, cell=cell, target_names=target_names,
    )  # fmt: skip
    return write_text_atomic(path, text)


def draw_cell(target: Viewer | MeshcatScene, cell: Cell) -> None:
    """Draw a cell: its obstacles where they stand, and the part the tool carries on the tool (it moves with it).

    Boxes, spheres and cylinders are meshcat's primitives (a cylinder along its own z axis, as in URDF: Pinocchio's
    loader turns three.js's y-axis cylinder), meshes their triangles; obstacles in :data:`OBSTACLE_COLOR`, the
    carried part in :data:`CARRIED_COLOR`. Drawing again replaces the cell drawn before (``/meshcat/cell``).

    Args:
        target: a live :class:`Viewer`, or the scene of a page being recorded (the teach pendant's).
        cell: the cell (its shapes in the robot's base frame; the carried part in the tool frame).
    """
    (target._live() if isinstance(target, Viewer) else target).draw_cell(cell)


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
        self._server: MeshcatServer | None = None
        self._window: Window | None = None
        self._closed = False
        atexit.register(self.close)
        try:
            if zmq_url is None:
                self._server = MeshcatServer(timeout)
                zmq_url = self._server.zmq_url
            self._window = Window(zmq_url, timeout)
            self._scene = MeshcatScene(robot, self._window)
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
    def _live(self) -> MeshcatScene:
        if self._closed:
            raise ViewerError("the viewer is closed")
        return self._scene

    def display(self, q: object) -> None:
        """Show the robot at ``q`` [rad or m] (stops nothing: an animation playing keeps playing)."""
        self._live().display(q)

    def animate(
        self, times: object, qs: object = None, *, fps: int = DEFAULT_FPS, loop: bool = False, play: bool = True
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
        t, q = checked_motion(self.robot, times, qs, fps)
        if len(t) < 2:
            raise InvalidInputError("an animation needs at least 2 samples; use display() for one")
        scene.vis.set_animation(scene.animation(t, q, fps), play=play, repetitions=math.inf if loop else 1)

    def play(self, times: object, qs: object = None, *, speed: float = 1.0, rate: float = DEFAULT_FPS) -> None:
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
        t, q = checked_motion(self.robot, times, qs, rate)
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

    def draw_path(self, points: object, *, name: str = "path", color: int = PATH_COLOR) -> None:
        """Draw a tool path: a line through (N, 3) points in the base frame [m]."""
        self._live().draw_path(points, name, color)

    def draw_tool_path(self, qs: object, *, name: str = "path", color: int = PATH_COLOR) -> None:
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
        color: int = WORKSPACE_COLOR,
    ) -> None:
        """Draw polylines of (x, y) points in the base frame [m], e.g. a workspace boundary.

        They lie on the floor (z = 0 of the root link) unless ``z`` gives a height in the base frame [m].
        Drawing again under the same ``name`` replaces them.
        """
        self._live().draw_polylines(polylines, name, z, color)

    def draw_cell(self, cell: Cell) -> None:
        """Draw a cell's obstacles and the part the tool carries (:func:`draw_cell`)."""
        self._live().draw_cell(cell)

    def clear(self, name: str) -> None:
        """Remove an overlay drawn under ``name`` ("path", "targets", "workspace", ...)."""
        self._live().vis[f"{OVERLAYS}/{name}"].delete()

    # ----------------------------------------------------------------- export
    def static_html(self, title: str | None = None) -> str:
        """Return the current scene (animation included) as a self-contained HTML page."""
        return self._live().page(title or f"scara-pin: {self.robot.name}")

    def save_html(self, path: str | os.PathLike[str], title: str | None = None) -> Path:
        """Write :meth:`static_html` to ``path``, atomically; return the path."""
        return write_text_atomic(path, self.static_html(title))

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
