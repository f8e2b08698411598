"""The browser as a teach pendant: a session of the robot's q, and a local web server for it.

:class:`TeachSession` is the logic, without a browser, in SI units (m, rad):

- joint jogs (:meth:`~TeachSession.jog_joint`) and Cartesian jogs in the BASE or the TOOL frame
  (:meth:`~TeachSession.jog`), by steps that stop ON the edge and name what stopped them
  (:mod:`scara_pin.motion.manual`); the jogs keep the elbow branch and J4's turn;
- hold-to-jog (:meth:`~TeachSession.hold`, :meth:`~TeachSession.alive`, :meth:`~TeachSession.release`,
  :meth:`~TeachSession.tick`): the motion advances every :data:`CONTROL_PERIOD` at a rate limited by the
  speed override, and stops on release, on the edge, or when nothing was heard from the page for
  :data:`WATCHDOG` (a closed or frozen page); how it ended (a :class:`~scara_pin.motion.manual.StopReason` and
  how far it went) is in every ``alive``, ``release`` and ``state`` reply until the next move;
- go to a pose (:meth:`~TeachSession.go_to`, the IK solution nearest to q on the chosen branch) or to joint
  values (:meth:`~TeachSession.set_q`);
- taught points (:meth:`~TeachSession.record`, :meth:`~TeachSession.rename`, :meth:`~TeachSession.delete`,
  :meth:`~TeachSession.go_to_point`), saved to and loaded from a points file
  (:mod:`scara_pin.motion.points`) that ``traj --points`` and ``cycle --points`` read.

A refused request leaves q unchanged and says why (a status code and its reason).

In a cell (``cell=``: obstacles, the carried part, the margin; :mod:`scara_pin.cell`), every jog, step or hold,
stops where a checked pair first comes to the cell's margin (reason kind
:attr:`~scara_pin.motion.manual.StopKind.OBSTACLE`, naming the obstacle and the robot's shape, and the pair in
the reply's ``contact``); a go-to (a pose, joint values, a taught point) whose target is closer than the margin,
or whose straight joint move there comes to it, is refused (status ``COLLISION``) naming the pair; a start closer
than the margin is an :class:`~scara_pin.cell.InCollisionError` (exit code 2). The page draws the cell.

:class:`TeachServer` serves the page (:mod:`scara_pin.viz.page`, with meshcat's viewer script) and the JSON
routes of :meth:`TeachSession.handle` under ``/api/`` on 127.0.0.1 only, in the calling process (it stops with
it). Every route checks the Host header (only ``127.0.0.1:PORT`` and ``localhost:PORT``: a DNS-rebinding
page is refused); a malformed body is a 400 with a one-line JSON error.
"""

from __future__ import annotations

import json
import logging
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError, ParameterError, ScaraError, UrdfError
from ..motion.manual import (
    JogAxis,
    JogFrame,
    JogMotion,
    JogMove,
    JogOutcome,
    Solver,
    StopKind,
    StopReason,
    branch_of,
    hold_advance,
    jog_step,
    pose_ik,
)
from ..motion.points import PointSet, PosePoint, TaughtPoint, points_format, read_points, write_points
from .scene import recorded_scene

if TYPE_CHECKING:
    from ..cell import Cell, PairDistance, Scene
    from ..model import RobotModel

__all__ = [
    "CONTROL_PERIOD",
    "KEEPALIVE",
    "MAX_STEP_ANGLE",
    "MAX_STEP_LENGTH",
    "MIN_STEP_ANGLE",
    "MIN_STEP_LENGTH",
    "STEP_TOL",
    "WATCHDOG",
    "JogAxis",
    "JogFrame",
    "Solver",
    "StopKind",
    "StopReason",
    "TeachReply",
    "TeachServer",
    "TeachSession",
]

log = logging.getLogger(__name__)

HOST = "127.0.0.1"
_MAX_BODY = 64 * 1024

CONTROL_PERIOD = 0.05
"""[s] a hold-to-jog advances once per period (the server's timer)."""
KEEPALIVE = 0.1
"""[s] the page says "still held" this often while a jog button is held."""
WATCHDOG = 0.25
"""[s] a hold not heard from for this long stops (a closed, frozen or disconnected page): two and a half
keep-alives, so that a browser timer's usual jitter (tens of ms) does not stop a held jog. Counted while the
server runs: a tick that comes late (this process was not running) waits for the keep-alives to be read."""
_LATE_TICK = 2 * CONTROL_PERIOD  # [s] a tick this long after the previous one: the server itself did not run
MIN_STEP_LENGTH = 1e-6
"""[m] the smallest step jog of a length (1 um: the readout's resolution)."""
MAX_STEP_LENGTH = 1.0
"""[m] the largest step jog of a length."""
MIN_STEP_ANGLE = math.radians(1e-3)
"""[rad] the smallest step jog of an angle (0.001 deg: the readout's resolution)."""
MAX_STEP_ANGLE = math.pi
"""[rad] the largest step jog of an angle (half a turn)."""
STEP_TOL = 1e-12
"""[-] relative: a step this close outside its range counts as its end (the largest is then the end itself): the
12 digits a page shows after converting 180 deg to rad, 3.14159265359, are a valid half turn."""

_AXES = {"x": JogAxis.X, "y": JogAxis.Y, "z": JogAxis.Z, "yaw": JogAxis.YAW}
_FRAMES = {f.value: f for f in JogFrame}


@dataclass(frozen=True, eq=False, kw_only=True)
class TeachReply:
    """The answer to one request: the session's q after it, and whether it moved.

    Attributes:
        q: the joint values after the request [rad or m] (unchanged when refused).
        pose: the tool frame in the base frame at ``q``: (x, y, z, yaw) [m, rad], Pinocchio's FK.
        branch: the IK branch of ``q`` ("right"/"left", "up"/"down"; "" when the model has none).
        moved: whether q changed.
        status: ``"OK"``, ``"STOPPED"`` (moved, and stopped short: ON an edge or limit, or a hold ended by the
            watchdog or an error after it moved), ``"AT_EDGE"`` (did not move: already there), or the code of a
            refusal (an IK status name such as ``OUT_OF_REACH``, ``JOINT_LIMIT``; ``COLLISION`` for a go-to into
            the cell; ``WATCHDOG`` or ``ERROR`` for a hold that ended before it moved).
        message: what stopped or refused it, or what was done ("" otherwise).
        solver: what answered.
        reason: why a jog stopped or did not move, or how a hold ended (None otherwise).
        travelled: how far the jog went [m or rad] (a hold: so far, or in all once ended); requested: how far
            a step was asked to go (0 for a hold).
        angle: whether ``travelled`` and ``requested`` are angles [rad] (else lengths [m]).
        holding: whether a hold-to-jog is running after this request.
        points: the taught points, in replies that change or list them (None otherwise).
        contact: in a cell, the pair at the margin that stopped the jog (its distance at ``q``), else None.
    """

    q: np.ndarray
    pose: np.ndarray
    branch: str
    moved: bool
    status: str
    message: str
    solver: Solver
    reason: StopReason | None = None
    travelled: float = 0.0
    requested: float = 0.0
    angle: bool = False
    holding: bool = False
    points: PointSet | None = None
    contact: PairDistance | None = None

    @property
    def limit(self) -> str:
        """What stopped a jog (the reason's limit: ``joint2_upper``, ``outer``, an IK code; "" when nothing did)."""
        return "" if self.reason is None else self.reason.limit

    def to_json(self) -> dict[str, Any]:
        """The reply as the page reads it (SI; full precision: the page rounds for display)."""
        out: dict[str, Any] = {
            "q": [float(v) for v in self.q],
            "pose": [float(v) for v in self.pose],
            "branch": self.branch,
            "moved": self.moved,
            "status": self.status,
            "message": self.message,
            "solver": self.solver.value,
            "limit": self.limit,
            "reason": None if self.reason is None else self.reason.to_json(),
            "travelled": self.travelled,
            "requested": self.requested,
            "angle": self.angle,
            "holding": self.holding,
            "contact": None if self.contact is None else self.contact.to_dict(),
        }
        if self.points is not None:
            out["points"] = [p.to_dict() for p in self.points]
        return out


@dataclass
class _Hold:
    """A running hold-to-jog: what it moves, how fast, how far it went, and its times [s, monotonic].

    ``heard``: the page's last word; ``moved_to``: the time the robot has moved up to; ``ticked``: the last tick.
    """

    motion: JogMotion
    override: float
    heard: float
    moved_to: float
    ticked: float
    angle: bool
    travelled: float = 0.0


@dataclass(frozen=True)
class _HoldEnd:
    """How the last hold-to-jog ended: told in every alive, release and state reply until the next move."""

    status: str
    reason: StopReason
    solver: Solver
    travelled: float
    angle: bool
    contact: PairDistance | None = None


class TeachSession:
    """The robot's current q and the requests that move it (no browser, no server).

    Example::

        session = TeachSession(robot)
        reply = session.jog(JogAxis.X, 0.01)                       # 10 mm along x of the base frame
        reply = session.jog(JogAxis.X, 0.01, JogFrame.TOOL)        # 10 mm along the tool's own x
        reply = session.jog_joint(1, math.radians(5))              # J2 by +5 deg
        if not reply.moved:
            print(reply.status, reply.message)
        session.record("P1")
        session.save_points("cell.yaml")
    """

    def __init__(self, robot: RobotModel, q: object | None = None, *, points_file: str | Path | None = None,
                 cell: Cell | None = None) -> None:  # fmt: skip
        """Start at ``q`` (default: zero), which must be inside the joint limits (and clear of the cell).

        Args:
            robot: the robot.
            q: the start configuration [rad, m].
            points_file: the points file (.yaml, .yml or .csv) :meth:`save_points` writes and
                :meth:`load_points` reads; read now when it exists.
            cell: the robot's cell (a 4-joint SCARA's): jogs stop at its margin, go-tos into it are refused.

        Raises:
            InvalidInputError: ``q`` is not 4 finite numbers or is outside the limits; a points file with a
                bad name, or unreadable, or taught on another robot; a cell for a robot other than a 4-joint
                SCARA with its closed-form IK.
            InCollisionError: ``q`` is closer than the cell's margin (naming the pair).
        """
        self.robot = robot
        start = robot.default_q if q is None else robot.check_q(q)
        outside = robot.outside_limits(start)
        if outside:
            raise InvalidInputError(f"the start configuration is outside the limits: {'; '.join(outside)}")
        self.cell = cell
        self._scene = None if cell is None else _cell_scene(robot, cell)
        if self._scene is not None:
            self._scene.check(start, "the pendant's start")  # exit 2 naming the pair
        self._q = start.copy()
        self._hold: _Hold | None = None
        self._last_end: _HoldEnd | None = None  # how the last hold ended, until the next move
        self.points_file = None if points_file is None else Path(points_file)
        self._points = PointSet(robot=robot.name, base=robot.base_frame, tool=robot.tool_frame)
        if self.points_file is not None:
            points_format(self.points_file)  # the name says the format: refused now, not at the first save
            if self.points_file.exists():
                self._points = self._adopt(read_points(self.points_file, robot))

    # ----------------------------------------------------------------- state
    @property
    def q(self) -> np.ndarray:
        """The current joint values (a copy)."""
        return self._q.copy()

    @property
    def branches(self) -> tuple[str, ...]:
        """The branch names the go-to IK takes ("all" first: the nearest solution on any branch)."""
        return ("all", "up", "down") if self.robot.kind == "palletizer" else ("all", "right", "left")

    @property
    def points(self) -> PointSet:
        """The taught points."""
        return self._points

    @property
    def holding(self) -> bool:
        """Whether a hold-to-jog is running."""
        return self._hold is not None

    def _reply(self, moved: bool, status: str = "OK", message: str = "", solver: Solver = Solver.NONE, *,
               move: JogMove | None = None, motion: JogMotion | None = None, points: bool = False,
               ) -> TeachReply:  # fmt: skip
        q = self.q
        extra: dict[str, Any] = {}
        if move is not None:
            extra = {"reason": move.reason, "travelled": move.travelled, "requested": move.requested,
                     "angle": motion is not None and motion.is_angle(self.robot), "contact": move.contact}
        elif self._hold is not None:  # a running hold: how far so far
            extra = {"travelled": self._hold.travelled, "angle": self._hold.angle}
        return TeachReply(q=q, pose=self.robot.tool_pose(q), branch=branch_of(self.robot, q), moved=moved,
                          status=status, message=message, solver=solver, holding=self.holding,
                          points=self._points if points else None, **extra)  # fmt: skip

    def state(self) -> TeachReply:
        """The current state and the points (moved is False); after a hold ended, how it ended."""
        return self._ended_reply(points=True) if self._hold is None else self._reply(False, points=True)

    # ----------------------------------------------------------------- moves
    def set_q(self, q: object) -> TeachReply:
        """Move the joints to ``q`` (refused, status ``JOINT_LIMIT``, outside the limits).

        In a cell, refused (status ``COLLISION``, naming the pair) when ``q`` is closer than the margin or the
        straight joint move there comes to it.
        """
        values = self.robot.check_q(q)
        outside = self.robot.outside_limits(values)
        if outside:
            return self._reply(False, "JOINT_LIMIT", "; ".join(outside))
        blocked = self._collision(values)
        if blocked:
            return self._reply(False, "COLLISION", blocked)
        self._stop_hold()
        self._q = values.copy()
        return self._reply(True)

    def _collision(self, target: np.ndarray) -> str:
        """Why the straight joint move from q to ``target`` is refused in the cell ("" when it is clear of it)."""
        if self._scene is None:
            return ""
        from ..cell.scene import describe
        from ..cell.sweep import first_contact
        from ..motion.paths import JointLine

        c = self._scene.distances(target).closest
        if c is not None and c.distance < self._scene.margin:
            return f"the target is in collision: {describe(c, self._scene.margin, unit='m')}"
        found = first_contact(self._scene, JointLine(self._q, target))
        if found is None:
            return ""
        c = found.closest
        x, y, z = self.robot.tool_pose(found.q)[:3]
        return (f"the straight joint move there comes to the margin ({self._scene.margin:g} m) of {c.pair.b} "
                f"({c.pair.a}) {found.s:.0%} of the way, the tool at x {x:.6g} m, y {y:.6g} m, z {z:.6g} m")

    def jog(self, axis: JogAxis, step: float, frame: JogFrame = JogFrame.BASE) -> TeachReply:
        """Move the tool by ``step`` [m, or rad for the yaw; the sign is the sense] along ``axis`` of ``frame``.

        A straight move that keeps the elbow branch; it stops ON the edge (status ``STOPPED``, ``limit`` names
        what stopped it) or does not move when already there (``AT_EDGE``).

        Raises:
            InvalidInputError: a step that is not a finite number, or whose size is outside
                [:data:`MIN_STEP_LENGTH`, :data:`MAX_STEP_LENGTH`] ([:data:`MIN_STEP_ANGLE`, :data:`MAX_STEP_ANGLE`]
                for the yaw); a turn in a tool frame whose z is not vertical.
        """
        if not isinstance(axis, JogAxis):
            raise InvalidInputError(f"axis {axis!r} must be a JogAxis (X, Y, Z or YAW)")
        sign, size = _signed_step(step, axis is JogAxis.YAW)
        return self._step(JogMotion(sign, axis=axis, frame=frame), size)

    def jog_joint(self, joint: int | str, step: float) -> TeachReply:
        """Move one joint (its index in q, or its name) by ``step`` [rad or m; the sign is the sense].

        The joint moves by exactly ``step``, or stops ON its limit (status ``STOPPED``).
        """
        j = self._joint_index(joint)
        sign, size = _signed_step(step, self.robot.joint_kinds[j] == "angle")
        return self._step(JogMotion(sign, joint=j), size)

    def _joint_index(self, joint: object) -> int:
        names = self.robot.joint_names
        if isinstance(joint, str) and joint in names:
            return names.index(joint)
        if isinstance(joint, int) and not isinstance(joint, bool) and 0 <= joint < self.robot.dof:
            return joint
        raise InvalidInputError(f"joint {joint!r} must be an index 0..{self.robot.dof - 1} or one of "
                                f"{', '.join(names)}")  # fmt: skip

    def _step(self, motion: JogMotion, size: float) -> TeachReply:
        self._stop_hold()  # a step while a hold runs: the hold ends first
        move = jog_step(self.robot, self._q, motion, size, scene=self._scene)
        return self._apply(move, motion)

    def _apply(self, move: JogMove, motion: JogMotion) -> TeachReply:
        if move.moved:
            self._q = np.array(move.q, dtype=float)
        return self._reply(move.moved, move.status, move.message, move.solver, move=move, motion=motion)

    def go_to(self, pose: object, branch: str = "all") -> TeachReply:
        """Move to the pose (x, y, z, yaw) of the tool frame in the base frame [m, rad].

        The IK solution nearest to q on ``branch`` (``"all"``: any branch).
        """
        if branch not in self.branches:
            raise InvalidInputError(f"branch {branch!r} must be one of {', '.join(self.branches)}")
        self._stop_hold()
        answer = pose_ik(self.robot, pose, self._q, branch)
        if answer.q is None:
            return self._reply(False, answer.status, answer.message, answer.solver)
        blocked = self._collision(answer.q)
        if blocked:
            return self._reply(False, "COLLISION", blocked, answer.solver)
        self._q = answer.q.copy()
        return self._reply(True, solver=answer.solver)

    # ----------------------------------------------------------------- hold-to-jog
    def hold(self, motion: JogMotion, override: float, now: float | None = None) -> TeachReply:
        """Start a hold-to-jog of ``motion`` at ``override`` (a fraction in (0, 1]).

        It runs on :meth:`tick` until :meth:`release`, an edge, or :data:`WATCHDOG` without :meth:`alive`.

        ``now`` [s] is the monotonic clock (default ``time.monotonic()``); tests pass their own.
        """
        if not isinstance(motion, JogMotion):
            raise InvalidInputError("hold needs a JogMotion")
        if motion.joint is not None:
            self._joint_index(motion.joint)
        if not (isinstance(override, (int, float)) and not isinstance(override, bool) and 0.0 < override <= 1.0):
            raise ParameterError("speed override", override, "must be a fraction in (0, 1] (1 = 100 %)")
        now = time.monotonic() if now is None else float(now)
        self._stop_hold()
        self._hold = _Hold(motion, float(override), now, now, now, motion.is_angle(self.robot))
        return self._reply(False)

    def alive(self, now: float | None = None) -> TeachReply:
        """The page still holds the button: the watchdog restarts.

        The reply says whether the hold runs and how far it went; after it ended (released, on an edge, by the
        watchdog), how and why, until the next move.
        """
        now = time.monotonic() if now is None else float(now)
        if self._hold is None:
            return self._ended_reply()
        self._hold.heard = now
        return self._reply(False)

    def release(self, now: float | None = None) -> TeachReply:
        """The button is released: the hold stops now (no further advance); message ``released``.

        When the hold had ended before (on an edge, by the watchdog), the reply says how, as :meth:`alive` does.
        """
        hold = self._hold
        if hold is not None:
            self._hold = None
            self._last_end = _HoldEnd("OK", StopReason(StopKind.RELEASED, "released"), Solver.NONE, hold.travelled,
                                      hold.angle)  # fmt: skip
        return self._ended_reply()

    def tick(self, now: float | None = None) -> TeachReply | None:
        """Advance a running hold by the time since it last moved (at most :data:`WATCHDOG`); None without a hold.

        The hold ends when the page was not heard from for :data:`WATCHDOG` (reason kind ``WATCHDOG``), or when
        the advance stops on an edge or raises (kind ``ERROR``). An end after the hold moved has status
        ``STOPPED``: the robot moved, then stopped (a refusal code only when it never moved).

        A tick more than two periods after the previous one (this process did not run: a busy PC) neither
        judges nor moves: the page's keep-alives may be waiting unread in the server's socket. The next tick,
        once they are read, does both (by the time since the last move, at most :data:`WATCHDOG`).
        """
        hold = self._hold
        if hold is None:
            return None
        now = time.monotonic() if now is None else float(now)
        late, hold.ticked = now - hold.ticked > _LATE_TICK, now
        if late:
            return self._reply(False)
        if now - hold.heard > WATCHDOG:
            silent = now - hold.heard
            return self._end(StopReason(StopKind.WATCHDOG, f"stopped by the watchdog: the page did not confirm the "
                                        f"held button for {silent:.3f} s (> {WATCHDOG} s)"), "WATCHDOG")  # fmt: skip
        dt = min(now - hold.moved_to, WATCHDOG)
        if not dt > 0:
            return self._reply(False)
        hold.moved_to = now
        try:
            move = hold_advance(self.robot, self._q, hold.motion, dt, hold.override, scene=self._scene)
        except ScaraError as exc:
            return self._end(StopReason(StopKind.ERROR, " ".join(str(exc).split())), "ERROR")
        if move.moved:
            self._q = np.array(move.q, dtype=float)
            hold.travelled += move.travelled
        if move.outcome is JogOutcome.OK:
            return self._reply(True, solver=move.solver)
        reason = move.reason or StopReason(StopKind.IK, move.status, move.status)  # (a stop always has a reason)
        return self._end(reason, move.status, move.solver, moved=move.moved, contact=move.contact)

    def _end(self, reason: StopReason, status: str, solver: Solver = Solver.NONE, *, moved: bool = False,
             contact: PairDistance | None = None) -> TeachReply:  # fmt: skip
        """End the running hold for ``reason``: status ``STOPPED`` once it has moved, else ``status``."""
        travelled, angle = (0.0, False) if self._hold is None else (self._hold.travelled, self._hold.angle)
        self._hold = None
        self._last_end = _HoldEnd("STOPPED" if travelled > 0 else status, reason, solver, travelled, angle, contact)
        reply = self._ended_reply()
        return replace(reply, moved=True) if moved else reply

    def _stop_hold(self) -> None:
        """A new move: a running hold stops, and the last hold's end is forgotten."""
        self._hold = None
        self._last_end = None

    def _ended_reply(self, points: bool = False) -> TeachReply:
        ended = self._last_end  # how the last hold ended, with the current state (kept until the next move)
        if ended is None:
            return self._reply(False, points=points)
        reply = self._reply(False, ended.status, ended.reason.text, ended.solver, points=points)
        return replace(reply, reason=ended.reason, travelled=ended.travelled, angle=ended.angle, contact=ended.contact)

    # ----------------------------------------------------------------- points
    def _adopt(self, points: PointSet) -> PointSet:
        return PointSet(points.points, self.robot.name, self.robot.base_frame, self.robot.tool_frame)

    def record(self, name: str | None = None, form: str = "joint") -> TeachReply:
        """Record the current q as a point named ``name`` (default: the first free ``P1``, ``P2``, ...).

        ``form``: ``"joint"`` (the joint values: the point) or ``"pose"`` (the tool pose with its branch and wrist
        turn, SPEL+'s ``XY() /R``: :class:`~scara_pin.motion.points.PosePoint`; a YAML points file holds it).
        """
        if form not in ("joint", "pose"):
            raise InvalidInputError(f"form {form[:40]!r} must be joint or pose")
        name = self._points.next_name() if name in (None, "") else name
        make = TaughtPoint.at if form == "joint" else PosePoint.at
        self._points = self._points.added(make(self.robot, str(name), self._q))
        return self._reply(False, "OK", f"recorded {name}", points=True)

    def rename(self, old: str, new: str) -> TeachReply:
        """Rename point ``old`` to ``new``."""
        self._points = self._points.renamed(old, new)
        return self._reply(False, points=True)

    def delete(self, name: str) -> TeachReply:
        """Delete point ``name``."""
        self._points = self._points.removed(name)
        return self._reply(False, points=True)

    def go_to_point(self, name: str) -> TeachReply:
        """Move to point ``name``'s joint values (its own branch and J4 turn; a pose point's IK on them)."""
        point = self._points[name]
        self._stop_hold()
        return self.set_q(point.q if isinstance(point, TaughtPoint) else point.solve(self.robot))

    def save_points(self, path: str | Path | None = None) -> TeachReply:
        """Write the points to ``path`` (default: the session's points file), atomically."""
        target = self._file(path)
        write_points(target, self._points)
        return self._reply(False, "OK", f"saved {len(self._points)} point(s) to {target}", points=True)

    def load_points(self, path: str | Path | None = None) -> TeachReply:
        """Replace the points by those of ``path`` (default: the session's points file)."""
        source = self._file(path)
        self._points = self._adopt(read_points(source, self.robot))
        return self._reply(False, "OK", f"loaded {len(self._points)} point(s) from {source}", points=True)

    def _file(self, path: str | Path | None) -> Path:
        if path is None:
            if self.points_file is None:
                raise InvalidInputError("no points file: start the pendant with --points FILE (.yaml or .csv)")
            return self.points_file
        return Path(path)

    # ----------------------------------------------------------------- the page's requests
    def handle(self, route: str, body: dict[str, Any] | None, now: float | None = None) -> TeachReply:
        """Answer one request of the page from its JSON body, in SI units (m, rad; the page converts).

        Routes: ``state``; ``q`` {q}; ``jog`` {axis: x|y|z|yaw, frame: base|tool | joint: index, direction: +1|-1,
        step: > 0}; ``goto`` {pose, branch}; ``hold`` {the jog's fields without step, speed: percent in (0, 100]};
        ``alive``; ``release``; ``points/record`` {name?, form?: joint|pose}; ``points/rename`` {old, new};
        ``points/delete`` {name}; ``points/goto`` {name}; ``points/save``; ``points/load``.

        Raises:
            InvalidInputError: an unknown route or a malformed body (the message names the field).
        """
        body = body or {}
        if route == "state":
            return self.state()
        if route == "q":
            return self.set_q(body.get("q"))
        if route == "jog":
            motion = self._motion(body)
            size = _step_size(body.get("step"), motion.is_angle(self.robot))
            return self._step(motion, size)
        if route == "goto":
            return self.go_to(body.get("pose"), str(body.get("branch", "all")))
        if route == "hold":
            speed = body.get("speed")
            if isinstance(speed, bool) or not isinstance(speed, (int, float)) or not 0 < speed <= 100:
                raise ParameterError("speed", speed, "must be a number in (0, 100]", "%")
            return self.hold(self._motion(body), float(speed) / 100.0, now)
        if route == "alive":
            return self.alive(now)
        if route == "release":
            return self.release(now)
        if route == "points/record":
            return self.record(None if body.get("name") is None else _text(body, "name"),
                               "joint" if body.get("form") is None else _text(body, "form"))
        if route == "points/rename":
            return self.rename(_text(body, "old"), _text(body, "new"))
        if route == "points/delete":
            return self.delete(_text(body, "name"))
        if route == "points/goto":
            return self.go_to_point(_text(body, "name"))
        if route == "points/save":
            return self.save_points()
        if route == "points/load":
            return self.load_points()
        raise InvalidInputError(f"unknown request {route!r}")

    def _motion(self, body: dict[str, Any]) -> JogMotion:
        sense = body.get("direction")
        if sense not in (1, -1) or isinstance(sense, bool):
            raise InvalidInputError(f"direction {sense!r} must be 1 or -1")
        if "joint" in body:
            return JogMotion(int(sense), joint=self._joint_index(body["joint"]))
        axis = _AXES.get(body.get("axis"))  # type: ignore[arg-type]
        if axis is None:
            raise InvalidInputError(f"jog axis {body.get('axis')!r} must be one of {', '.join(_AXES)} (or give joint)")
        frame = _FRAMES.get(body.get("frame", "base"))  # type: ignore[arg-type]
        if frame is None:
            raise InvalidInputError(f"jog frame {body.get('frame')!r} must be one of {', '.join(_FRAMES)}")
        return JogMotion(int(sense), axis=axis, frame=frame)


def _cell_scene(robot: RobotModel, cell: Cell) -> Scene:
    """The scene of ``robot`` in ``cell`` for the pendant.

    A 4-joint SCARA whose closed form takes its model: its Cartesian jogs are followed as straight tool lines by
    that IK.
    """
    from ..cell import scene

    if robot.kind != "scara" or robot.dof != 4:
        raise InvalidInputError(f"the teach pendant's cell is for 4-joint SCARA robots for now; {robot.name!r} is a "
                                f"{robot.kind} with {robot.dof} joints")  # fmt: skip
    try:
        robot.kinematics  # noqa: B018 - the closed form refuses some models (NotScaraError)
    except UrdfError as exc:
        raise InvalidInputError(f"the teach pendant's cell needs the closed-form IK of {robot.name!r}: {exc}") from None
    return scene(robot, cell)


def _signed_step(step: object, angle: bool) -> tuple[int, float]:
    if isinstance(step, bool) or not isinstance(step, (int, float)) or not math.isfinite(step) or step == 0:
        raise ParameterError("jog step", step, "must be a finite number, not 0", "rad" if angle else "m")
    return (1 if step > 0 else -1), _step_size(abs(float(step)), angle)


def _step_size(step: object, angle: bool) -> float:
    """``step`` if it is a number within the step range of its kind, else a :class:`ParameterError`."""
    lo, hi, unit = (MIN_STEP_ANGLE, MAX_STEP_ANGLE, "rad") if angle else (MIN_STEP_LENGTH, MAX_STEP_LENGTH, "m")
    if isinstance(step, bool) or not isinstance(step, (int, float)):
        raise ParameterError("jog step", step if isinstance(step, str) else ParameterError.NOTHING,
                             f"must be a number in [{lo:.6g}, {hi:.6g}] {unit}")  # fmt: skip
    if not (math.isfinite(step) and lo * (1 - STEP_TOL) <= step <= hi * (1 + STEP_TOL)):
        raise ParameterError("jog step", step, f"must be in [{lo:.6g}, {hi:.6g}]", unit)
    return min(float(step), hi)


def _text(body: dict[str, Any], key: str) -> str:
    value = body.get(key)
    if not isinstance(value, str):
        raise InvalidInputError(f"{key} must be a text")
    return value


# ------------------------------------------------------------------------------------------ the server
class TeachServer:
    """The teach pendant page and its requests, served on 127.0.0.1 by tornado, in this process.

    Attributes:
        session: the session the requests act on.
        port: the port listened on (a free one when asked for 0).
        url: the page's address.
    """

    def __init__(self, robot: RobotModel, port: int = 0, q: object | None = None, *,
                 points_file: str | Path | None = None, controls: bool = False, cell: Cell | None = None,
                 ) -> None:  # fmt: skip
        """Build the page and listen on 127.0.0.1:``port`` (0: a free port).

        Args:
            robot: the robot.
            port: the port (0: a free one).
            q: the start configuration [rad, m].
            points_file: the session's points file (see :class:`TeachSession`).
            controls: show meshcat's own control panel (hidden by default; the page's ``?controls=1`` shows it).
            cell: the robot's cell (see :class:`TeachSession`); the page draws it.

        Raises:
            InvalidInputError: a bad port, start configuration, points file or cell, or the port is taken;
                :class:`~scara_pin.cell.InCollisionError` for a start closer than the cell's margin.
        """
        import asyncio

        if not (isinstance(port, int) and 0 <= port <= 65535):
            raise InvalidInputError(f"port is {port!r}; it must be a whole number in [0, 65535]")
        self.session = TeachSession(robot, q, points_file=points_file, cell=cell)
        self.page = _teach_page(robot, self.session, controls)
        self._loop = asyncio.new_event_loop()
        asyncio.set_event_loop(self._loop)
        import tornado.httpserver
        import tornado.ioloop
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
        self._timer = tornado.ioloop.PeriodicCallback(self._tick, CONTROL_PERIOD * 1000.0)
        self._timer.start()

    def _tick(self) -> None:
        try:
            self.session.tick()
        except Exception as exc:  # a bug must not kill the timer: the hold stops, the server goes on (one line)
            log.error("internal error in a hold-to-jog (%s: %s); the hold stops", type(exc).__name__, exc)
            self.session.release()

    def _app(self) -> Any:
        import tornado.web

        server = self

        class Base(tornado.web.RequestHandler):
            """Every route: only our own Host (a DNS-rebinding page is refused), errors as one JSON line."""

            def prepare(self) -> None:
                if self.request.host not in (f"{HOST}:{server.port}", f"localhost:{server.port}"):
                    raise tornado.web.HTTPError(403, reason="Forbidden Host")

            def write_error(self, status_code: int, **kwargs: Any) -> None:
                reason = self._reason if status_code != 500 else "internal error"
                self.set_header("Content-Type", "application/json; charset=utf-8")
                self.finish(json.dumps({"error": f"{status_code} {reason}"}) + "\n")

            def log_exception(self, typ: Any, value: Any, tb: Any) -> None:
                if isinstance(value, tornado.web.HTTPError):
                    log.debug("%s %s: %s", self.request.method, self.request.uri, value)
                else:  # one line, never a traceback on the terminal
                    log.error("%s %s: internal error (%s: %s)", self.request.method, self.request.uri,
                              type(value).__name__, value)  # fmt: skip

        class Page(Base):
            def get(self) -> None:
                self.set_header("Content-Type", "text/html; charset=utf-8")
                self.set_header("Cache-Control", "no-store")
                self.write(server.page)

        class Missing(Base):
            def prepare(self) -> None:
                super().prepare()
                raise tornado.web.HTTPError(404, reason="Not Found")

        class Export(Base):
            def get(self) -> None:
                fmt = self.get_query_argument("format", "yaml")
                if fmt not in ("yaml", "csv"):
                    raise tornado.web.HTTPError(400, reason="format must be yaml or csv")
                points = server.session.points
                kind = "text/csv" if fmt == "csv" else "application/yaml"
                self.set_header("Content-Type", kind + "; charset=utf-8")
                self.set_header("Content-Disposition", f'attachment; filename="points.{fmt}"')
                self.set_header("Cache-Control", "no-store")
                self.write(points.to_csv() if fmt == "csv" else points.to_yaml())

        class Api(Base):
            def prepare(self) -> None:
                super().prepare()
                # another site's page must not drive the pendant: JSON bodies only (a cross-site form cannot
                # send those without a CORS preflight, which is never granted)
                if self.request.method == "POST" and not self.request.headers.get("Content-Type", "").startswith(
                    "application/json"
                ):
                    raise tornado.web.HTTPError(415, reason="JSON only")

            def get(self, route: str) -> None:
                if route != "state":
                    raise tornado.web.HTTPError(405, reason="POST only")
                self._answer(route, None)

            def post(self, route: str) -> None:
                try:
                    body = json.loads(self.request.body or b"{}")
                except RecursionError:
                    self._error("the request body is nested too deeply")
                    return
                except ValueError:  # not JSON, not UTF-8
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
                except RecursionError:  # a deeply nested value inside a valid body
                    self._error("a value of the request body is nested too deeply")
                    return
                self.set_header("Cache-Control", "no-store")
                self.write(reply.to_json())

            def _error(self, message: str) -> None:
                self.set_status(400)
                self.write({"error": message})

        def access(handler: Any) -> None:  # requests are logged at debug level (-v), not on stderr
            log.debug("%d %s %s", handler.get_status(), handler.request.method, handler.request.uri)

        routes = [(r"/", Page), (r"/api/points/export", Export), (r"/api/([a-z]+(?:/[a-z]+)?)", Api)]
        return tornado.web.Application(routes, log_function=access, default_handler_class=Missing)

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
        """Stop listening and stop any hold (idempotent)."""
        self._timer.stop()
        self.session.release()
        self._server.stop()


def _cell_words(cell: Cell) -> str:
    """The page's line about the cell: ``cell post.yaml: 1 obstacle(s); every jog stops 0.002 m from them``."""
    carried = "" if cell.carried is None else f" and a carried {cell.carried.kind}"
    name = Path(cell.origin).name
    return (f"cell{'' if name == 'cell' else ' ' + name}: {len(cell.obstacles)} obstacle(s){carried}; every jog "
            f"stops {cell.margin:g} m from them (the margin)")


def _teach_page(robot: RobotModel, session: TeachSession, controls: bool = False) -> str:
    """The pendant page of the live teach server (no motion player; a ``teach`` section)."""
    scene, data = recorded_scene(robot, session.q, cell=session.cell)
    data["controls"] = bool(controls)
    labels = {"all": "nearest (any branch)"}
    data["teach"] = {
        "api": "/api",
        "branches": [[b, labels.get(b, b)] for b in session.branches],
        "points_file": "" if session.points_file is None else str(session.points_file),
        "control_period": CONTROL_PERIOD,
        "keepalive": KEEPALIVE,
        "step_length": [MIN_STEP_LENGTH, MAX_STEP_LENGTH],
        "step_angle": [MIN_STEP_ANGLE, MAX_STEP_ANGLE],
        "step_tol": STEP_TOL,
        "cell": "" if session.cell is None else _cell_words(session.cell),
    }
    return scene.page(f"scara-pin teach: {robot.name}", data)
