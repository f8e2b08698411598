"""Manual-mode moves of a teach pendant: step jogs that stop ON the edge, and hold-to-jog advances.

What moves. A :class:`JogMotion` is one joint (J1..J4 by its index in q, in its + or - sense) or the tool
frame along x, y or z, or turning about the vertical (:attr:`JogAxis.YAW`), in the BASE frame or in the
TOOL frame (the tool's own axes at the current q). A Schoenflies robot turns its tool only about the
vertical: in the tool frame, + turns about the tool's own z axis, vertical up or down, so the yaw changes by
+step or -step; a tool frame whose z axis is not vertical cannot be turned and the jog is refused.

A Cartesian jog is a straight move of the tool frame, followed continuously: the IK keeps the current
elbow branch (a straight line cannot flip the elbow) and each joint's turn (no jump of 2 pi in J4). It is
checked every :data:`SAMPLE_LENGTH` (:data:`SAMPLE_ANGLE` for turns), at most :data:`MAX_STEP_SAMPLES`
times per step; two consecutive samples whose revolute joints differ by more than :data:`JUMP` are not
one continuous move.

Where it stops. When the reachable set ends before the step does, the move ends ON the edge and says what
stopped it (``limit``):

- a joint step: the joint's limit (``joint2_upper``);
- a translation of a SCARA: the first edge along the step of the exact workspace
  (:meth:`scara_pin.workspace.Workspace.ray`, J3's stroke included), whose arc names the joint limit or the
  singular pose (``joint1_lower``, ``outer``); the tool goes to the ray's point;
- before that edge, or where no ray applies (turns, the palletizer, a model the closed form refuses): the
  first sample the continuous IK refuses, bisected to :data:`BISECT_TOL`; the refusal just beyond it names
  the limit (``JOINT_LIMIT: ... joint4 ...``, ``OUT_OF_REACH``).

Hold-to-jog (:func:`hold_advance`): the motion advances one control period at a time, at the manual
reduced speed of ISO 10218-1 (:data:`MANUAL_SPEED`, 250 mm/s of the tool frame's origin) times the speed
override for translations, :data:`MANUAL_TURN_RATE` times the override for turns, and the joint's velocity
limit times the override for joint jogs. Whatever is jogged, each period's step is shortened until no joint
moves faster than its velocity limit times the override and the tool frame's origin no faster than
:data:`MANUAL_SPEED` times the override (measured over the period: near a singularity the tool slows down).
No acceleration ramp is simulated: a hold starts and stops at once.

In a cell (``scene=``, :func:`scara_pin.cell.scene`), every move also stops before a checked pair (a link or the
carried part against an obstacle, or two links checked against each other) comes closer than the cell's margin:
the move above is followed as the joint path it is (a straight joint line, or the straight tool line by the
closed-form IK, :class:`~scara_pin.motion.paths.CartesianSegment`; its last or first micrometre through its IK
solutions when it ends or starts on the stretched or folded arm) by
:func:`scara_pin.cell.sweep.first_contact`, and ends where the first pair comes to the margin (clear of it by
0 to 1e-9 m), never beyond; the reason names the obstacle and the robot's shape: ``stopped 0.002 m from post
(flange)``. A move that would bring a pair at the margin closer does not move (``AT_EDGE``).

Why it stopped (:class:`StopReason`): a kind (:class:`StopKind`: a joint limit, an edge of the workspace, the
IK's refusal, a singularity, the cell's margin; for a hold also the release and the watchdog), a sentence, and
the machine name of the limit. Every length or angle in the sentence is written ``<number> <unit>`` with the
unit m, rad or deg (``2.30383461 rad``, ``0.002 m``, the workspace's ``132 deg``; an interval ``[a, b] m``), so
that a page shown in other units can restate it in its own.
"""

from __future__ import annotations

import enum
import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._checks import as_limit_vector, as_vector
from ..errors import InvalidInputError, NoSolutionError, ParameterError, ScaraError, UrdfError

if TYPE_CHECKING:
    from ..cell import PairDistance, Scene
    from ..cell.sweep import JointPath
    from ..model import RobotModel
    from ..workspace.scara import RayHit, Workspace

__all__ = [
    "BISECT_TOL",
    "MAX_POLYLINE_POINTS",
    "POLYLINE_SPACING",
    "JUMP",
    "MANUAL_SPEED",
    "MANUAL_TURN_RATE",
    "MAX_STEP_SAMPLES",
    "SAMPLE_ANGLE",
    "SAMPLE_LENGTH",
    "JogAxis",
    "JogFrame",
    "JogMotion",
    "JogMove",
    "JogOutcome",
    "PoseAnswer",
    "Solver",
    "StopKind",
    "StopReason",
    "hold_advance",
    "jog_step",
    "pose_ik",
]

log = logging.getLogger(__name__)

MANUAL_SPEED = 0.25
"""[m/s] the manual reduced speed of ISO 10218-1 (5.7.3): the tool frame's origin never jogs faster."""
MANUAL_TURN_RATE = math.pi / 2
"""[rad/s] the turning rate of a hold-to-jog about the vertical at 100 % override (90 deg/s)."""
SAMPLE_LENGTH = 1e-3
"""[m] the continuity check's sample spacing along a Cartesian step (at most :data:`MAX_STEP_SAMPLES`)."""
SAMPLE_ANGLE = math.radians(1.0)
"""[rad] the sample spacing of a turn."""
MAX_STEP_SAMPLES = 200
"""Samples of one step at most (a longer step is sampled more coarsely)."""
JUMP = math.pi / 2
"""[rad] a revolute joint moving more than this between two samples is a jump (an elbow flip, a 2 pi turn
of J4): not one continuous move. Near the stretched arm a 1 mm sample moves the elbow by about
sqrt(2 mm (l1 + l2) / (l1 l2)): 0.14 rad for l1 = l2 = 0.2 m, 0.6 rad for l1 = l2 = 0.05 m."""
BISECT_TOL = 1e-10
"""[m or rad] the bisection of the first refused sample stops this close to it."""
POLYLINE_SPACING = 1e-4
"""[m or rad] in a cell, the part of a Cartesian move the closed form cannot follow (next to the stretched or
folded arm) is followed through its IK solutions this far apart (at least 16, at most
:data:`MAX_POLYLINE_POINTS`), joined by straight joint lines."""
MAX_POLYLINE_POINTS = 2000
"""The IK solutions of such a move at most."""
_EDGE = 1e-9  # [m] a ray edge this close is where the tool is (the workspace's EDGE_TOL)
_AIM = 0.999  # a shortened hold step aims at this fraction of the speed limits (1 would converge from above)


class JogAxis(enum.Enum):
    """A Cartesian jog direction: along x, y, z [m] or about the vertical (the yaw) [rad]."""

    X = 0
    Y = 1
    Z = 2
    YAW = 3


class JogFrame(enum.Enum):
    """The frame a Cartesian jog's axes are taken in."""

    BASE = "base"
    TOOL = "tool"


class Solver(enum.Enum):
    """What answered a request."""

    NONE = "none"  # nothing solved (a joint move, or a refusal before any solver)
    CLOSED_FORM = "closed-form"
    NUMERIC = "numeric"


class JogOutcome(enum.Enum):
    """How a jog ended."""

    OK = "OK"  # moved by the whole step
    STOPPED = "STOPPED"  # moved, and stopped short ON an edge or a limit (named)
    AT_EDGE = "AT_EDGE"  # did not move: already on the edge or the limit in that direction
    REFUSED = "REFUSED"  # did not move: the request cannot be carried out (the status says why)


class StopKind(enum.Enum):
    """What stopped a jog short (or kept it from moving), or ended a hold-to-jog."""

    JOINT_LIMIT = "joint-limit"  # a joint's position limit (a joint jog)
    WORKSPACE = "workspace"  # an edge of the exact workspace: an arc of a joint limit or a singular pose, a stroke end
    IK = "ik"  # the IK refuses just beyond (its status code is the limit)
    SINGULAR = "singular"  # too close to a singularity to move at the jog's speed
    OBSTACLE = "obstacle"  # a checked pair of the cell at the margin: an obstacle (or a link) and the robot's shape
    RELEASED = "released"  # a hold: the button was released
    WATCHDOG = "watchdog"  # a hold: the page stopped confirming the held button
    ERROR = "error"  # a hold: the advance raised (the message says what)


@dataclass(frozen=True)
class StopReason:
    """Why a jog stopped, in words and as data.

    Attributes:
        kind: what kind of thing stopped it.
        text: the sentence (``stopped at joint1's upper limit 2.30383461 rad``); each length or angle written
            ``<number> <unit>`` (m, rad or deg), which a page restates in its units.
        limit: the machine name of what stopped it: a joint limit (``joint2_upper``), a workspace
            :class:`~scara_pin.workspace.Limit` value (``outer``), an IK status code (``JOINT_LIMIT``), the
            obstacle (or link) of the cell a robot's shape came to (``post``); "" for none.
    """

    kind: StopKind
    text: str
    limit: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.kind, StopKind):
            raise InvalidInputError(f"stop kind {self.kind!r} must be a StopKind")

    def __str__(self) -> str:
        return self.text

    def to_json(self) -> dict[str, str]:
        """``{"kind", "text", "limit"}`` (the kind's value: ``joint-limit``, ``workspace``, ...)."""
        return {"kind": self.kind.value, "text": self.text, "limit": self.limit}


@dataclass(frozen=True)
class JogMotion:
    """What a jog moves.

    Attributes:
        sign: +1 or -1, the sense.
        joint: the joint's index in q for a joint jog; None for a Cartesian one.
        axis: the Cartesian axis (None for a joint jog).
        frame: the frame of ``axis``.
    """

    sign: int
    joint: int | None = None
    axis: JogAxis | None = None
    frame: JogFrame = JogFrame.BASE

    def __post_init__(self) -> None:
        if self.sign not in (1, -1) or isinstance(self.sign, bool):
            raise InvalidInputError(f"jog sense {self.sign!r} must be +1 or -1")
        if (self.joint is None) == (self.axis is None):
            raise InvalidInputError("a jog moves either a joint or the tool along an axis, not both")
        if self.axis is not None and not isinstance(self.axis, JogAxis):
            raise InvalidInputError(f"axis {self.axis!r} must be a JogAxis (X, Y, Z or YAW)")
        if not isinstance(self.frame, JogFrame):
            raise InvalidInputError(f"frame {self.frame!r} must be a JogFrame (BASE or TOOL)")
        if self.joint is not None and (isinstance(self.joint, bool) or not isinstance(self.joint, int)):
            raise InvalidInputError(f"joint {self.joint!r} must be an index into q (0 for J1)")

    def is_angle(self, robot: RobotModel) -> bool:
        """Whether the step is an angle [rad] (a revolute joint, a turn) rather than a length [m]."""
        if self.joint is not None:
            return robot.joint_kinds[self.joint] == "angle"
        return self.axis is JogAxis.YAW


@dataclass(frozen=True, eq=False)
class PoseAnswer:
    """The IK's answer for one pose: ``q`` (None when refused), what solved it, and why not."""

    q: np.ndarray | None
    solver: Solver
    status: str = "OK"
    message: str = ""


@dataclass(frozen=True, eq=False, kw_only=True)
class JogMove:
    """The result of one jog step.

    Attributes:
        q: the joint values after it [rad, m] (the start when it did not move).
        outcome: how it ended.
        status: ``"OK"``, ``"STOPPED"``, ``"AT_EDGE"`` (the outcome's value: the default), or the code of the
            refusal (an IK status name).
        reason: what stopped or refused it (None for a whole step).
        travelled: how far it moved along the motion [m or rad] (>= 0).
        requested: the step asked for [m or rad] (> 0).
        solver: what answered the last IK.
        contact: in a cell, the pair at the margin that stopped it (its distance at ``q``), else None.
    """

    q: np.ndarray
    outcome: JogOutcome
    status: str = ""
    reason: StopReason | None = None
    travelled: float
    requested: float
    solver: Solver = Solver.NONE
    contact: PairDistance | None = None

    def __post_init__(self) -> None:
        if not self.status:
            object.__setattr__(self, "status", self.outcome.value)

    @property
    def moved(self) -> bool:
        """Whether q changed."""
        return self.outcome in (JogOutcome.OK, JogOutcome.STOPPED)

    @property
    def message(self) -> str:
        """The reason's sentence ("" for a whole step)."""
        return "" if self.reason is None else self.reason.text

    @property
    def limit(self) -> str:
        """What stopped it (the reason's limit; "" when nothing did)."""
        return "" if self.reason is None else self.reason.limit


# ------------------------------------------------------------------------------------------ IK
def pose_ik(robot: RobotModel, target: object, reference: np.ndarray, branch: str = "all") -> PoseAnswer:
    """The IK solution of ``target`` (x, y, z, yaw) [m, rad] nearest to ``reference`` on ``branch``.

    The closed form (:meth:`scara_pin.model.RobotModel.ik_nearest`) where it takes the robot's model, else the
    numeric solver (:func:`scara_pin.kinematics.numeric.solve_numeric`) started at ``reference``. A refusal
    is an answer (``q`` None, its status code and reason), never an exception.
    """
    pose = as_vector("pose", target)
    try:
        return PoseAnswer(np.asarray(robot.ik_nearest(pose, reference, branch=branch), dtype=float),
                          Solver.CLOSED_FORM)  # fmt: skip
    except NoSolutionError as exc:
        return PoseAnswer(None, Solver.CLOSED_FORM, getattr(exc.status, "name", str(exc.status)), exc.reason)
    except UrdfError as exc:  # the closed form refuses this model (NotScaraError): the numeric solver
        from ..kinematics.numeric import solve_numeric

        log.debug("closed-form IK refused (%s); numeric IK", exc)
        result = solve_numeric(robot, pose, q0=reference)
        if not result.success:
            return PoseAnswer(None, Solver.NUMERIC, "NUMERIC_NO_SOLUTION",
                              f"the numeric IK did not reach the target (residual {result.residual:.3g} after "
                              f"{result.iterations} iterations, {result.reason.name}); the closed form refuses "
                              f"this model: {exc}")  # fmt: skip
        return PoseAnswer(np.asarray(result.q, dtype=float), Solver.NUMERIC)


def branch_of(robot: RobotModel, q: np.ndarray) -> str:
    """The IK branch of ``q`` ("" when the robot's model has no named branches)."""
    try:
        return robot.branch_of(q)
    except UrdfError:
        return ""


# ------------------------------------------------------------------------------------------ steps
def jog_step(robot: RobotModel, q: object, motion: JogMotion, step: float, *, ws: Workspace | None = None,
             scene: Scene | None = None) -> JogMove:  # fmt: skip
    """Move by ``step`` [m or rad] > 0 in the sense and along the axis (or joint) of ``motion``.

    See the module docstring for where it stops. ``ws`` is the workspace of the jog's tool point, when
    already built (:func:`scara_pin.motion.jog.edge_workspace`); otherwise built here for SCARA translations.
    ``scene``: the robot in its cell (a 4-joint SCARA with its closed form, for Cartesian moves): the move also
    stops where a checked pair first comes to the margin.

    Raises:
        InvalidInputError: a step that is not a finite number > 0, a joint index out of range, a turn in a
            tool frame whose z axis is not vertical.
        InCollisionError: in a cell, q is closer than the margin (exit code 2), naming the pair.
    """
    q0 = robot.check_q(q)
    if isinstance(step, bool) or not isinstance(step, (int, float)) or not (math.isfinite(step) and step > 0):
        raise ParameterError("jog step", step, "must be a finite number > 0", "m or rad")
    length = float(step)
    if motion.joint is not None:
        move = _joint_step(robot, q0, motion.joint, motion.sign, length)
    else:
        move = _cartesian_step(robot, q0, motion, length, ws)
    if scene is None or not move.moved:
        return move
    return _before_contact(robot, scene, q0, motion, move)


def _before_contact(robot: RobotModel, scene: Scene, q0: np.ndarray, motion: JogMotion, move: JogMove) -> JogMove:
    """``move`` (from ``q0``), ended where a checked pair of ``scene`` first comes to the margin, if it does."""
    from ..cell.sweep import first_contact
    from .jog import CONTACT_ROOM

    done = 0.0
    for path, length in _move_paths(robot, q0, motion, move):
        found = first_contact(scene, path)  # InCollisionError (exit 2) when q0 is closer than the margin
        if found is not None:
            break
        done += length
    else:
        return move
    c = found.closest
    pair = f"{c.pair.b} ({c.pair.a})"
    travelled = done + found.s * length
    if not travelled > CONTACT_ROOM:
        reason = StopReason(StopKind.OBSTACLE, f"at the margin: {c.distance:.6g} m from {pair}, and this way "
                            "comes closer", c.pair.b)  # fmt: skip
        return JogMove(q=q0, outcome=JogOutcome.AT_EDGE, reason=reason, travelled=0.0, requested=move.requested,
                       contact=scene.distances(q0).of(c.pair))  # fmt: skip
    reason = StopReason(StopKind.OBSTACLE, f"stopped {c.distance:.6g} m from {pair}", c.pair.b)
    return JogMove(q=found.q, outcome=JogOutcome.STOPPED, reason=reason, travelled=travelled, requested=move.requested,
                   solver=move.solver, contact=c)  # fmt: skip


def _move_paths(robot: RobotModel, q0: np.ndarray, motion: JogMotion, move: JogMove) -> list[tuple[JointPath, float]]:
    """The joint paths ``move`` follows from ``q0``, one after the other, each with the length [m or rad] it covers.

    A joint move: the straight joint line. A Cartesian one: the straight tool line followed by the closed-form IK
    (the branch and the J4 turn of ``q0``). That IK's joint rates have no bound on the stretched or folded arm
    (:func:`~scara_pin.motion.paths.cartesian_path` refuses a line that starts or ends there): the line's last (or
    first) :data:`~scara_pin.motion.jog.SINGULAR_EDGE_GAP` is followed through its IK solutions instead
    (:func:`_ik_polyline`), and a line that does both, or that the closed form refuses otherwise, all of it.
    """
    from .jog import SINGULAR_EDGE_GAP
    from .paths import JointLine, PathError, cartesian_path

    if motion.joint is not None:
        return [(JointLine(q0, move.q), move.travelled)]
    d = direction(robot, q0, motion)
    pose0 = np.asarray(robot.tool_pose(q0), dtype=float)
    length, gap = move.travelled, SINGULAR_EDGE_GAP

    def line(a: float, b: float, start: np.ndarray) -> JointPath:
        return cartesian_path(robot, [pose0 + a * d, pose0 + b * d], start=start).segments[0]

    try:
        return [(line(0.0, length, q0), length)]
    except PathError as exc:
        log.debug("the jog's line near a singular arm: %s", exc)
    if length > 2.0 * gap:
        try:  # it ends on the singular arm
            head = line(0.0, length - gap, q0)
            q_near = head.evaluate(np.ones(1), 0)[0][0]
            tail = _ik_polyline(robot, q_near, pose0 + (length - gap) * d, d, gap, move.q)
            return [(head, length - gap), (tail, gap)]
        except PathError as exc:
            log.debug("not only its end: %s", exc)
        try:  # it starts on it
            start = _ik_polyline(robot, q0, pose0, d, gap)
            return [(start, gap), (line(gap, length, start.Q[-1]), length - gap)]
        except PathError as exc:
            log.debug("not only its start: %s", exc)
    return [(_ik_polyline(robot, q0, pose0, d, length, move.q), length)]


def _ik_polyline(robot: RobotModel, q0: np.ndarray, pose0: np.ndarray, d: np.ndarray, length: float,
                 q_end: np.ndarray | None = None) -> _Polyline:  # fmt: skip
    """The IK solutions of the line ``pose0 + s d``, s in [0, ``length``], joined by straight joint lines.

    At least 16, at most :data:`MAX_POLYLINE_POINTS`, :data:`POLYLINE_SPACING` apart where that allows; each the
    solution of ``q0``'s branch nearest to the one before (:func:`_continuous`); ``q_end`` is the last if given.

    Raises:
        PathError: a point of the line without such a solution.
    """
    from .paths import PathError

    n = min(MAX_POLYLINE_POINTS - 1, max(16, math.ceil(length / POLYLINE_SPACING)))
    s = np.linspace(0.0, 1.0, n + 1)
    Q = np.empty((n + 1, robot.dof))
    Q[0] = q0
    branch = branch_of(robot, q0) or "all"
    for k in range(1, n + 1):
        if k == n and q_end is not None:
            Q[k] = q_end
            break
        answer = _continuous(robot, pose0 + s[k] * length * d, Q[k - 1], branch)
        if answer.q is None:
            raise PathError(f"no IK solution on the jog's line ({answer.status}: {answer.message})", s=float(s[k]),
                            pose=pose0 + s[k] * length * d)  # fmt: skip
        Q[k] = answer.q
    return _Polyline(s, Q)


@dataclass(frozen=True, eq=False)
class _Polyline:
    """The joint path through ``Q`` (rows) at the parameters ``s`` (increasing, 0 to 1), straight between them."""

    s: np.ndarray
    Q: np.ndarray

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:
        """(q, q', q'' = 0) at ``s`` (1-D), each (n, dof); q' of the piece on the right of a knot."""
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        i = np.clip(np.searchsorted(self.s, s, side="right") - 1, 0, len(self.s) - 2)
        rate = (self.Q[i + 1] - self.Q[i]) / (self.s[i + 1] - self.s[i])[:, None]
        out = (self.Q[i] + (s - self.s[i])[:, None] * rate, rate, np.zeros_like(rate))
        return out[: order + 1]


def _joint_step(robot: RobotModel, q0: np.ndarray, j: int, sign: int, length: float) -> JogMove:
    if not 0 <= j < robot.dof:
        raise InvalidInputError(f"joint index {j} must be in [0, {robot.dof - 1}] (J1..J{robot.dof})")
    q = q0.copy()
    q[j] = q0[j] + sign * length
    name = robot.joint_names[j]
    side, bound = ("upper", robot.limits.upper[j]) if sign > 0 else ("lower", robot.limits.lower[j])
    if robot.continuous[j] or ((q[j] <= bound) if sign > 0 else (q[j] >= bound)):
        return JogMove(q=q, outcome=JogOutcome.OK, travelled=length, requested=length)
    unit = "rad" if robot.joint_kinds[j] == "angle" else "m"
    room = (bound - q0[j]) * sign
    if not room > 0:
        reason = StopReason(StopKind.JOINT_LIMIT, f"{name} is at its {side} limit {bound:.9g} {unit}", f"{name}_{side}")
        return JogMove(q=q0, outcome=JogOutcome.AT_EDGE, reason=reason, travelled=0.0, requested=length)
    q[j] = bound
    reason = StopReason(StopKind.JOINT_LIMIT, f"stopped at {name}'s {side} limit {bound:.9g} {unit}", f"{name}_{side}")
    return JogMove(q=q, outcome=JogOutcome.STOPPED, reason=reason, travelled=float(room), requested=length)


def direction(robot: RobotModel, q: np.ndarray, motion: JogMotion) -> np.ndarray:
    """The (dx, dy, dz, dyaw) of the tool per unit of step for a Cartesian ``motion`` at ``q`` (unit length).

    Raises:
        InvalidInputError: a turn in the tool frame whose z axis is not vertical.
    """
    if motion.axis is None:
        raise InvalidInputError("a joint jog has no Cartesian direction")
    d = np.zeros(4)
    if motion.frame is JogFrame.BASE:
        d[motion.axis.value] = motion.sign
        return d
    R = np.asarray(robot.tool_placement(q).rotation)
    if motion.axis is JogAxis.YAW:
        up = float(R[2, 2])
        if not abs(abs(up) - 1.0) <= 1e-9:
            raise InvalidInputError(f"the tool's z axis is not vertical (its z component is {up:.6g}); a 4-axis robot "
                                    "turns only about the vertical: turn in the base frame")  # fmt: skip
        d[3] = motion.sign * math.copysign(1.0, up)
        return d
    d[:3] = motion.sign * R[:, motion.axis.value]
    return d


def _cartesian_step(robot: RobotModel, q0: np.ndarray, motion: JogMotion, length: float,
                    ws: Workspace | None) -> JogMove:  # fmt: skip
    d = direction(robot, q0, motion)
    pose0 = np.asarray(robot.tool_pose(q0), dtype=float)
    branch = branch_of(robot, q0) or "all"
    end, hit = length, None
    if d[3] == 0.0 and robot.kind == "scara":
        hit = _ray(robot, q0, pose0, d[:3], ws)
        if hit is not None and hit.distance < length:
            if hit.distance <= _EDGE:
                reason = StopReason(StopKind.WORKSPACE, f"on the edge: {hit.description}", hit.limit.value)
                return JogMove(q=q0, outcome=JogOutcome.AT_EDGE, reason=reason, travelled=0.0, requested=length)
            end = hit.distance
        else:
            hit = None

    def target(s: float) -> np.ndarray:
        if hit is not None and s == end:  # the ray's own edge point
            return np.array([*hit.point, pose0[3]])
        return pose0 + s * d

    spacing = SAMPLE_ANGLE if d[3] != 0.0 else SAMPLE_LENGTH
    n = min(MAX_STEP_SAMPLES, max(1, math.ceil(end / spacing)))
    last_s, last_q, solver = 0.0, q0, Solver.NONE
    for k in range(1, n + 1):
        s = end if k == n else end * k / n
        answer = _continuous(robot, target(s), last_q, branch)
        if answer.q is None:
            break
        last_s, last_q, solver = s, answer.q, answer.solver
    else:
        if hit is None:
            return JogMove(q=last_q, outcome=JogOutcome.OK, travelled=length, requested=length, solver=solver)
        here = _at_limits(robot, last_q)  # which joints the robot has at a limit there (the edge may have two names)
        message = f"stopped on the edge: {hit.description}" + (f" (here {', '.join(here)})" if here else "")
        reason = StopReason(StopKind.WORKSPACE, message, hit.limit.value)
        return JogMove(q=last_q, outcome=JogOutcome.STOPPED, reason=reason, travelled=end, requested=length,
                       solver=solver)  # fmt: skip
    # the first refused sample: bisect between the last reachable one and it
    lo, hi, refusal = last_s, s, answer
    while hi - lo > BISECT_TOL:
        mid = 0.5 * (lo + hi)
        answer = _continuous(robot, pose0 + mid * d, last_q, branch)
        if answer.q is None:
            hi, refusal = mid, answer
        else:
            lo, last_q, solver = mid, answer.q, answer.solver
    if lo == 0.0:
        reason = StopReason(StopKind.IK, refusal.message, refusal.status)
        return JogMove(q=q0, outcome=JogOutcome.AT_EDGE, status=refusal.status, reason=reason, travelled=0.0,
                       requested=length, solver=refusal.solver)  # fmt: skip
    words = refusal.status.lower().replace("_", " ")  # OUT_OF_REACH: out of reach (the code stays in limit)
    reason = StopReason(StopKind.IK, f"stopped where the IK stops; just beyond: {words}: {refusal.message}",
                        refusal.status)  # fmt: skip
    return JogMove(q=last_q, outcome=JogOutcome.STOPPED, reason=reason, travelled=lo, requested=length, solver=solver)


def _at_limits(robot: RobotModel, q: np.ndarray) -> list[str]:
    """The joints of ``q`` at a position limit (within 1e-9), as "joint2 at its upper limit 2.61799388 rad"."""
    out = []
    for i, name in enumerate(robot.joint_names):
        unit = "rad" if robot.joint_kinds[i] == "angle" else "m"
        for side, bound in (("lower", robot.limits.lower[i]), ("upper", robot.limits.upper[i])):
            if not robot.continuous[i] and abs(q[i] - bound) <= 1e-9:
                out.append(f"{name} at its {side} limit {bound:.9g} {unit}")
    return out


def _region(robot: RobotModel, q: np.ndarray) -> Workspace | None:
    """The workspace of the tool point at q's yaw (:func:`scara_pin.motion.jog.edge_workspace`), or None.

    None where it is not defined (a tool offset with J4 limited to less than a turn): the IK decides.
    """
    from .jog import edge_workspace

    try:
        return edge_workspace(robot, float(robot.tool_pose(q)[3]))
    except ScaraError as exc:
        log.debug("no workspace region: %s", exc)
        return None


def _ray(robot: RobotModel, q0: np.ndarray, pose0: np.ndarray, u: np.ndarray, ws: Workspace | None) -> RayHit | None:
    """The workspace's edge along ``u`` from the tool point, or None where the region does not apply."""
    region = ws if ws is not None else _region(robot, q0)
    if region is None:
        return None
    try:
        return region.ray(pose0[:3], u)
    except ScaraError as exc:  # outside the region by a rounding: the IK decides
        log.debug("no workspace ray: %s", exc)
        return None


def _continuous(robot: RobotModel, pose: np.ndarray, previous: np.ndarray, branch: str) -> PoseAnswer:
    """The IK of ``pose`` on ``branch`` nearest ``previous``, refused when a revolute joint jumps (> JUMP)."""
    answer = pose_ik(robot, pose, previous, branch)
    if answer.q is None:
        return answer
    for i, kind in enumerate(robot.joint_kinds):
        if kind == "angle" and abs(answer.q[i] - previous[i]) > JUMP:
            name = robot.joint_names[i]
            mid = 0.5 * (robot.limits.lower[i] + robot.limits.upper[i])
            side = "upper" if previous[i] > mid else "lower"
            bound = robot.limits.upper[i] if side == "upper" else robot.limits.lower[i]
            return PoseAnswer(None, answer.solver, "JOINT_LIMIT",
                              f"{name} would pass its {side} limit {bound:.9g} rad (the only solution there turns it "
                              f"by {answer.q[i] - previous[i]:.6g} rad at once: not a continuous move)")  # fmt: skip
    return answer


# ------------------------------------------------------------------------------------------ hold-to-jog
def nominal_rate(robot: RobotModel, motion: JogMotion, override: float) -> float:
    """The hold-to-jog rate [m/s or rad/s] before the limits of the period (see the module docstring)."""
    override = _override(override)
    if motion.joint is not None:
        velocity = as_limit_vector("velocity", robot.limits.velocity, "rad/s or m/s")
        return override * float(velocity[motion.joint])
    return override * (MANUAL_TURN_RATE if motion.axis is JogAxis.YAW else MANUAL_SPEED)


def hold_advance(
    robot: RobotModel, q: object, motion: JogMotion, dt: float, override: float, *, ws: Workspace | None = None,
    scene: Scene | None = None,
) -> JogMove:
    """One control period of a hold-to-jog.

    The step of ``dt`` [s] at the rate of ``motion`` and ``override`` (a fraction in (0, 1]), shortened until
    every joint and the tool's origin keep their speeds (module docstring), stopping ON the edge, and in a cell
    (``scene``) before contact, as :func:`jog_step` does. The shortened steps are parts of the step checked
    against the cell: they are not checked again.
    """
    q0 = robot.check_q(q)
    if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
        raise ParameterError("control period", dt, "must be a finite number > 0", "s")
    velocity = as_limit_vector("velocity", robot.limits.velocity, "rad/s or m/s")
    override = _override(override)
    length = nominal_rate(robot, motion, override) * dt
    if ws is None and motion.axis not in (None, JogAxis.YAW) and robot.kind == "scara":
        ws = _region(robot, q0)  # built once for the period's trial steps
    move = jog_step(robot, q0, motion, length, ws=ws, scene=scene)
    ratio = _speed_ratio(robot, q0, move.q, dt, override, velocity)
    if not move.moved or ratio <= 1.0:
        return move
    # too fast: shorten the step by the ratio (exact where the move is linear in the step), a few times, keeping
    # the longest step within the speeds; near a singularity (a square-root law) bisect instead
    best: JogMove | None = None
    trial_length = move.travelled * _AIM / ratio
    for _ in range(4):
        trial = jog_step(robot, q0, motion, trial_length, ws=ws)
        r = _speed_ratio(robot, q0, trial.q, dt, override, velocity)
        if r <= 1.0 and (best is None or trial.travelled > best.travelled):
            best = trial
        if _AIM - 1e-3 <= r <= 1.0 or not trial.moved:
            break
        trial_length = trial.travelled * _AIM / r
    if best is not None:
        return best
    lo, hi = 0.0, move.travelled / ratio
    singular = StopReason(StopKind.SINGULAR, "too close to a singularity to move at the jog's speed", "singular")
    good = JogMove(q=q0, outcome=JogOutcome.AT_EDGE, reason=singular, travelled=0.0, requested=length)
    for _ in range(20):  # to a millionth of the step
        mid = 0.5 * (lo + hi)
        trial = jog_step(robot, q0, motion, mid, ws=ws)
        if _speed_ratio(robot, q0, trial.q, dt, override, velocity) <= 1.0:
            lo, good = mid, trial
        else:
            hi = mid
    return good


def _override(value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (0.0 < value <= 1.0):
        raise ParameterError("speed override", value, "must be a fraction in (0, 1] (1 = 100 %)")
    return float(value)


def _speed_ratio(
    robot: RobotModel, q0: np.ndarray, q1: np.ndarray, dt: float, override: float, velocity: np.ndarray
) -> float:
    """The largest of |dq_i| / (override vmax_i dt) and |dp| / (override MANUAL_SPEED dt) over one period."""
    joints = float(np.max(np.abs(q1 - q0) / (override * velocity * dt)))
    p0 = np.asarray(robot.tool_placement(q0).translation)
    p1 = np.asarray(robot.tool_placement(q1).translation)
    return max(joints, float(np.linalg.norm(p1 - p0)) / (override * MANUAL_SPEED * dt))
