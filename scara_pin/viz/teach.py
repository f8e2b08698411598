"""The browser as a teach pendant: a session of the robot's q, and a local web server for it.

The session is answered by the library's IK and FK; the server (tornado, meshcat's own dependency) serves
the pendant page and its JSON requests.

:class:`TeachSession` is the logic, without a browser: set the joints, jog the tool along x, y, z or about
its yaw in the base frame, or go to a pose; each Cartesian request is answered by the closed-form IK nearest
to the current q (:meth:`scara_pin.model.Robot.ik_nearest`, on the selected branch), or by the numeric solver
(:func:`scara_pin.kinematics.numeric.solve_numeric`) where the closed form refuses the robot's model. A refused
move leaves q unchanged and says why (the IK status code and its reason).

:class:`TeachServer` serves the page (:mod:`scara_pin.viz.page`, with meshcat's viewer script) and the
routes ``GET /api/state``, ``POST /api/q``, ``/api/jog``, ``/api/goto`` (JSON bodies, JSON answers) on
127.0.0.1 only. It runs in the calling process: it stops with it.
"""

from __future__ import annotations

import enum
import json
import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import _vector
from ..errors import InvalidInputError, NoSolutionError, ScaraError, UrdfError

if TYPE_CHECKING:
    from ..model import Robot

__all__ = ["JogAxis", "Solver", "TeachReply", "TeachServer", "TeachSession"]

log = logging.getLogger(__name__)

HOST = "127.0.0.1"
_MAX_BODY = 64 * 1024


class JogAxis(enum.Enum):
    """A Cartesian jog direction in the base frame: along x, y, z [m] or about the tool's yaw [rad]."""

    X = 0
    Y = 1
    Z = 2
    YAW = 3


class Solver(enum.Enum):
    """What answered a request."""

    NONE = "none"  # nothing solved (a joint move, or a refusal before any solver)
    CLOSED_FORM = "closed-form"
    NUMERIC = "numeric"


@dataclass(frozen=True, eq=False)
class TeachReply:
    """The answer to one request: the session's q after it, and whether it moved.

    Attributes:
        q: the joint values after the request [rad or m] (unchanged when refused).
        pose: tool0 in the base frame at ``q``: (x, y, z, yaw) [m, rad], Pinocchio's FK.
        branch: the IK branch of ``q`` ("right"/"left", "up"/"down"; "" when the model has none).
        moved: whether the request was carried out.
        status: ``"OK"``, or the refusal's code (an IK status name such as ``OUT_OF_REACH``, ``JOINT_LIMIT``,
            ``NUMERIC_NO_SOLUTION``).
        message: the reason of a refusal ("" when moved).
        solver: what answered.
    """

    q: np.ndarray
    pose: np.ndarray
    branch: str
    moved: bool
    status: str
    message: str
    solver: Solver

    def to_json(self) -> dict[str, Any]:
        """The reply as the page reads it; the ``*_text`` values are ``repr`` (full precision)."""
        return {
            "q": [float(v) for v in self.q],
            "pose": [float(v) for v in self.pose],
            "q_text": [repr(float(v)) for v in self.q],
            "pose_text": [repr(float(v)) for v in self.pose],
            "branch": self.branch,
            "moved": self.moved,
            "status": self.status,
            "message": self.message,
            "solver": self.solver.value,
        }


class TeachSession:
    """The robot's current q and the requests that move it (no browser, no server).

    Example::

        session = TeachSession(robot)
        reply = session.jog(JogAxis.X, 0.01)          # 10 mm along x of the base frame
        if not reply.moved:
            print(reply.status, reply.message)
    """

    def __init__(self, robot: Robot, q: object | None = None) -> None:
        """Start at ``q`` (default: zero), which must be inside the joint limits.

        Raises:
            InvalidInputError: ``q`` is not 4 finite numbers, or is outside the limits.
        """
        self.robot = robot
        start = np.zeros(robot.dof) if q is None else robot.check_q(q)
        outside = robot.outside_limits(start)
        if outside:
            raise InvalidInputError(f"the start configuration is outside the limits: {'; '.join(outside)}")
        self._q = start.copy()

    # ----------------------------------------------------------------- state
    @property
    def q(self) -> np.ndarray:
        """The current joint values (a copy)."""
        return self._q.copy()

    @property
    def branches(self) -> tuple[str, ...]:
        """The branch names the IK takes ("all" first: the nearest solution on any branch)."""
        return ("all", "up", "down") if self.robot.kind == "palletizer" else ("all", "right", "left")

    def _branch_of(self, q: np.ndarray) -> str:
        try:
            return self.robot.branch_of(q)
        except UrdfError:  # a model the closed form does not know has no named branches
            return ""

    def _reply(self, moved: bool, status: str = "OK", message: str = "", solver: Solver = Solver.NONE) -> TeachReply:
        q = self.q
        return TeachReply(q, self.robot.tool_pose(q), self._branch_of(q), moved, status, message, solver)

    def state(self) -> TeachReply:
        """The current state (moved is False, status OK)."""
        return self._reply(False)

    # ----------------------------------------------------------------- requests
    def set_q(self, q: object) -> TeachReply:
        """Move the joints to ``q`` (refused, status ``JOINT_LIMIT``, outside the limits)."""
        values = self.robot.check_q(q)
        outside = self.robot.outside_limits(values)
        if outside:
            return self._reply(False, "JOINT_LIMIT", "; ".join(outside))
        self._q = values.copy()
        return self._reply(True)

    def jog(self, axis: JogAxis, step: float, branch: str = "all") -> TeachReply:
        """Move the tool by ``step`` [m, or rad for the yaw] along ``axis`` of the base frame, the rest kept.

        The target is the current FK pose plus the step; the answer the IK solution nearest to q.
        """
        if not isinstance(axis, JogAxis):
            raise InvalidInputError(f"axis {axis!r} must be a JogAxis (X, Y, Z or YAW)")
        if not (isinstance(step, (int, float)) and math.isfinite(step)):
            raise InvalidInputError(f"jog step is {step!r}; it must be a finite number [m or rad]")
        target = self.robot.tool_pose(self._q)
        target[axis.value] += float(step)
        return self.go_to(target, branch)

    def go_to(self, pose: object, branch: str = "all") -> TeachReply:
        """Move to the pose (x, y, z, yaw) of tool0 in the base frame [m, rad]: the IK solution nearest to q."""
        target = _vector("pose", pose)
        if branch not in self.branches:
            raise InvalidInputError(f"branch {branch!r} must be one of {', '.join(self.branches)}")
        try:
            q = self.robot.ik_nearest(target, self._q, branch=branch)
            solver = Solver.CLOSED_FORM
        except NoSolutionError as exc:
            return self._reply(False, getattr(exc.status, "name", str(exc.status)), exc.reason, Solver.CLOSED_FORM)
        except UrdfError as exc:  # the closed form refuses this model (NotScaraError): the numeric solver
            from ..kinematics.numeric import solve_numeric

            log.debug("closed-form IK refused (%s); numeric IK", exc)
            result = solve_numeric(self.robot, target, q0=self._q)
            if not result.success:
                return self._reply(
                    False,
                    "NUMERIC_NO_SOLUTION",
                    f"the numeric IK did not reach the target (residual {result.residual:.3g} after "
                    f"{result.iterations} iterations, {result.reason.name}); the closed form refuses this model: {exc}",
                    Solver.NUMERIC,
                )
            q, solver = np.asarray(result.q, dtype=float), Solver.NUMERIC
        self._q = np.array(q, dtype=float)
        return self._reply(True, solver=solver)

    def handle(self, route: str, body: dict[str, Any] | None) -> TeachReply:
        """Answer one request of the page (``state``, ``q``, ``jog``, ``goto``) in SI from its JSON body.

        The page's jog step and go-to pose are in millimetres and degrees; converted here.

        Raises:
            InvalidInputError: an unknown route or a malformed body.
        """
        body = body or {}
        if route == "state":
            return self.state()
        if route == "q":
            return self.set_q(_vector("q", body.get("q")))
        branch = str(body.get("branch", "all"))
        if route == "jog":
            names = {a.name.lower(): a for a in JogAxis}
            axis = names.get(str(body.get("axis")))
            if axis is None:
                raise InvalidInputError(f"jog axis {body.get('axis')!r} must be one of {', '.join(names)}")
            step = _vector("step", [body.get("step")], 1)[0]
            scale = math.radians(1.0) if axis is JogAxis.YAW else 1e-3  # deg, mm -> rad, m
            return self.jog(axis, float(step) * scale, branch)
        if route == "goto":
            x, y, z, yaw = _vector("pose", body.get("pose")).tolist()
            return self.go_to([x * 1e-3, y * 1e-3, z * 1e-3, math.radians(yaw)], branch)
        raise InvalidInputError(f"unknown request {route!r}")


# ------------------------------------------------------------------------------------------ the server
class TeachServer:
    """The teach pendant page and its requests, served on 127.0.0.1 by tornado, in this process.

    Attributes:
        session: the session the requests act on.
        port: the port listened on (a free one when asked for 0).
        url: the page's address.
    """

    def __init__(self, robot: Robot, port: int = 0, q: object | None = None) -> None:
        """Build the page and listen on 127.0.0.1:``port`` (0: a free port).

        Raises:
            InvalidInputError: a bad port or start configuration, or the port is taken.
        """
        import asyncio

        if not (isinstance(port, int) and 0 <= port <= 65535):
            raise InvalidInputError(f"port is {port!r}; it must be a whole number in [0, 65535]")
        self.session = TeachSession(robot, q)
        self.page = _teach_page(robot, self.session)
        self._loop = asyncio.new_event_loop()
        asyncio.set_event_loop(self._loop)
        import tornado.httpserver
        import tornado.netutil

        app = self._app()
        self._server = tornado.httpserver.HTTPServer(app, max_body_size=_MAX_BODY)
        try:
            sockets = tornado.netutil.bind_sockets(port, HOST)
        except OSError as exc:
            raise InvalidInputError(f"cannot listen on {HOST}:{port} ({exc.strerror})") from None
        self._server.add_sockets(sockets)
        self.port = int(sockets[0].getsockname()[1])
        self.url = f"http://{HOST}:{self.port}/"

    def _app(self) -> Any:
        import tornado.web

        server = self

        class Page(tornado.web.RequestHandler):
            def get(self) -> None:
                self.set_header("Content-Type", "text/html; charset=utf-8")
                self.set_header("Cache-Control", "no-store")
                self.write(server.page)

        class Api(tornado.web.RequestHandler):
            def prepare(self) -> None:
                # another site's page must not drive the pendant: only our own host name, and JSON bodies
                # (a cross-site form cannot send those without a CORS preflight, which is never granted)
                host = self.request.host
                if host not in (f"{HOST}:{server.port}", f"localhost:{server.port}"):
                    raise tornado.web.HTTPError(403, reason="wrong Host")
                if self.request.method == "POST" and not self.request.headers.get("Content-Type", "").startswith(
                    "application/json"
                ):
                    raise tornado.web.HTTPError(415, reason="JSON only")

            def get(self, route: str) -> None:
                self._answer(route, None)

            def post(self, route: str) -> None:
                try:
                    body = json.loads(self.request.body or b"{}")
                except ValueError:
                    self._error("the request body is not JSON")
                    return
                if not isinstance(body, dict):
                    self._error("the request body must be a JSON object")
                    return
                self._answer(route, body)

            def _answer(self, route: str, body: dict[str, Any] | None) -> None:
                try:
                    reply = server.session.handle(route, body)
                except ScaraError as exc:
                    self._error(" ".join(str(exc).split()))
                    return
                self.set_header("Cache-Control", "no-store")
                self.write(reply.to_json())

            def _error(self, message: str) -> None:
                self.set_status(400)
                self.write({"error": message})

        def access(handler: Any) -> None:  # requests are logged at debug level (-v), not on stderr
            log.debug("%d %s %s", handler.get_status(), handler.request.method, handler.request.uri)

        return tornado.web.Application([(r"/", Page), (r"/api/(state|q|jog|goto)", Api)], log_function=access)

    def serve_forever(self) -> None:
        """Serve until interrupted (KeyboardInterrupt passes to the caller) or :meth:`stop`."""
        try:
            self._loop.run_forever()
        finally:
            self.close()

    def stop(self) -> None:
        """Make :meth:`serve_forever` return (from any thread)."""
        self._loop.call_soon_threadsafe(self._loop.stop)

    def close(self) -> None:
        """Stop listening (idempotent)."""
        self._server.stop()


def _teach_page(robot: Robot, session: TeachSession) -> str:
    """The pendant page of the live teach server (no motion player; a ``teach`` section)."""
    from .meshcat import _page, _Scene, _Window

    window = _Window()
    scene = _Scene(robot, window)
    scene.display(session.q)
    data = scene.page_data()
    data["q"] = [float(v) for v in session.q]
    labels = {"all": "nearest (any branch)"}
    data["teach"] = {"api": "/api", "branches": [[b, labels.get(b, b)] for b in session.branches]}
    return _page(f"scara-pin teach: {robot.name}", window.recorder.commands(), data)
