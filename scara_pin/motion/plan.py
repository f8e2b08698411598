"""One move, planned: from a :class:`MotionRequest` (endpoints, vias, timing wishes) to a timed trajectory.

:func:`plan_motion` chooses the method, the one place where that choice is made (``scara-pin traj`` only
parses its arguments into a request and prints the plan):

==============================  ==========================================  =========================
request                         path                                        time law
==============================  ==========================================  =========================
``arch`` (path jump)            free joint path over the clearance          minimum time (IPOPT), jump
``arch``, path lines            lift, traverse, descend, blended (SCARA)    TOPP-RA
``linear`` and ``duration``     straight tool line through the poses        quintic
``linear``                      straight tool line through the poses        TOPP-RA
``duration``, vias              joint spline through the waypoints          quintic
``duration``, no via            joint line                                  quintic (``jtraj``)
no via, no tool speed, torque   joint line                                  trapezoid (time-optimal)
otherwise                       joint line or spline                        TOPP-RA
==============================  ==========================================  =========================

Poses given as endpoints of a joint-space move are solved by the closed-form IK: the start nearest the
middle of the joint ranges, the end nearest the previous waypoint. SI units: [rad, m, s].
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, cast

import numpy as np

from .._checks import as_vector
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..summary import Summarized
from . import trajectory as tr

if TYPE_CHECKING:
    from ..cell import Cell, Scene
    from ..cell.sweep import Contact
    from ..description import JointLimits
    from ..model import RobotModel
    from ..units import DisplayUnits
    from .cycle import ArchMove
    from .jump import JumpMove
    from .paths import GeometricPath
    from .payload import Payload, PayloadLike
    from .verify import Clearance

__all__ = ["Method", "MotionPlan", "MotionRequest", "check_fixed_path", "plan_motion"]

class Method(enum.Enum):
    """How a move is made; the value is the sentence ``scara-pin traj`` prints."""

    JOINT_QUINTIC = "joint quintic (jtraj)"
    JOINT_SPLINE_QUINTIC = "joint spline, quintic law"
    JOINT_TRAPEZOID = "joint line, time-optimal"
    JOINT_TOPPRA = "joint path, time-optimal (TOPP-RA)"
    LINE_QUINTIC = "straight line, quintic time law"
    LINE_TOPPRA = "straight line, time-optimal (TOPP-RA)"
    JUMP = "jump (arch move), time-optimal, joint path free"
    ARCH = "straight-leg arch (lift, traverse, descend, blended), time-optimal (TOPP-RA)"
    JOINT_JERK = "joint path, jerk-limited time-optimal"
    LINE_JERK = "straight line, jerk-limited time-optimal"


@dataclass(frozen=True, eq=False)
class MotionRequest:
    """What a move should do. Exactly one start (``start_q`` or ``start_pose``) and one end.

    Attributes:
        start_q, end_q: joint values [rad, m] (URDF order).
        start_pose, end_pose: tool poses (x, y, z, yaw) in the base frame [m, rad].
        vias: joint waypoints between start and end [rad, m]; with ``arch`` (the jump), hints of the way through a
            cell (:func:`~scara_pin.motion.jump.jump_move`'s ``via``).
        duration: a quintic time law over this many seconds; None: time-optimal.
        linear: a straight tool line (SCARA) through the start, the vias' poses and the end.
        arch: an arch (jump) move between the two poses (SCARA; not with ``linear``, vias or a duration).
        tool_speed: a tool speed limit [m/s] for time-optimal moves; None: no limit.
        torque: respect the effort limits (time-optimal moves).
        rise: [m] the arch's clearance above the higher pose; None: the standard one.
        blend: [m] the straight-leg arch's corner blend distance; None: as large as allowed (path "lines").
        payload: a payload at the tool (``torque`` moves and arches): a
            :class:`~scara_pin.motion.payload.Payload` or a mass [kg]; None: none.
        jerk: joint jerk limits [rad/s^3, m/s^3], one per joint, for a jerk-limited time-optimal move (arches
            too); None: none.
        path: "jump" (the time-optimal jump, the joint path free) or "lines" (the straight-leg arch).
        clearance_radius: [m] the jump's clearance radius; None: the standard one (path "jump").
        max_height: [m] a ceiling for the tool's z during the arch, or None.
        cell: obstacles, the carried part and the margin (:mod:`scara_pin.cell`), or None. The jump plans
            around and over them; every other move's path is fixed: it is verified (every checked pair at every
            10 kHz sample) and refused if it comes closer than the margin.
        limits: joint limits instead of ``robot.limits`` for the time-optimal moves and the jump (a speed
            override scales them); None: the robot's.
    """

    start_q: np.ndarray | None = None
    end_q: np.ndarray | None = None
    start_pose: np.ndarray | None = None
    end_pose: np.ndarray | None = None
    vias: tuple[np.ndarray, ...] = ()
    duration: float | None = None
    linear: bool = False
    arch: bool = False
    tool_speed: float | None = None
    torque: bool = False
    rise: float | None = None
    blend: float | None = None
    payload: Payload | PayloadLike = field(default=None)
    jerk: tuple[float, ...] | None = None
    path: str = "jump"
    clearance_radius: float | None = None
    max_height: float | None = None
    cell: Cell | None = None
    limits: JointLimits | None = None

    def __post_init__(self) -> None:
        for name in ("start_q", "end_q", "start_pose", "end_pose"):
            value = getattr(self, name)  # one per joint (4, or 3 without a wrist)
            object.__setattr__(self, name, None if value is None else as_vector(name, value, None))
        if self.payload is not None:  # a mass [kg] becomes a Payload
            from .payload import as_payload

            object.__setattr__(self, "payload", as_payload(self.payload))
        object.__setattr__(self, "vias", tuple(as_vector(f"via {i + 1}", v, None) for i, v in enumerate(self.vias)))
        if (self.start_q is None) == (self.start_pose is None):
            raise InvalidInputError("a move needs exactly one start: start_q or start_pose")
        if (self.end_q is None) == (self.end_pose is None):
            raise InvalidInputError("a move needs exactly one end: end_q or end_pose")
        for name in ("duration", "tool_speed"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise ParameterError(name, value, "must be finite and > 0", "s" if name == "duration" else "m/s")
        if self.rise is not None and not math.isfinite(self.rise):
            raise ParameterError("rise", self.rise, "must be finite", "m")
        if self.arch and self.vias and self.path != "jump":
            raise InvalidInputError("a straight-leg arch takes no via (one arch between two poses; the jump takes via "
                                    "points as hints)")
        if self.arch and self.duration is not None:
            raise InvalidInputError("an arch move is time-optimal: a duration does not apply")
        if self.jerk is not None and self.duration is not None:
            raise InvalidInputError("--jerk-limit is time-optimal: --duration does not apply")
        if self.jerk is not None and self.tool_speed is not None:
            raise InvalidInputError("--jerk-limit with --tool-speed is not supported: give one of them")
        if self.path not in ("jump", "lines"):
            raise ParameterError("path", self.path, "must be 'jump' or 'lines'")
        if self.path == "jump" and self.blend is not None:
            raise InvalidInputError("a blend distance shapes the straight-leg arch (path 'lines'), not the jump")
        if self.path == "lines" and self.clearance_radius is not None:
            raise InvalidInputError("a clearance radius applies to the jump (path 'jump'): the straight-leg arch lifts "
                                    "vertically")  # fmt: skip
        if not self.arch and (self.rise, self.blend, self.clearance_radius, self.max_height) != (None,) * 4:
            raise InvalidInputError("rise, blend, clearance radius and max height shape an arch move: set arch")
        if self.limits is not None and self.duration is not None:
            raise InvalidInputError("limits shape a time-optimal move: a move of a given duration is only checked "
                                    "against the robot's")  # fmt: skip
        if self.limits is not None and self.arch and self.path == "lines":
            raise InvalidInputError("limits other than the robot's apply to the jump (path 'jump'), not the "
                                    "straight-leg arch")  # fmt: skip


@dataclass(frozen=True, eq=False, repr=False)
class MotionPlan(Summarized):
    """A planned move (``repr``: the method and the trajectory; an arch's legs and ratios).

    Attributes:
        trajectory: the timed joint trajectory.
        method: how it was made.
        robot: the robot it was planned for (the request's payload attached, when one was given).
        arch: the arch move (its legs, ratios and payload) for ``Method.JUMP`` and ``Method.ARCH``; else None.
        clearance: with a cell, the smallest verified distance of its checked pairs, which and when.
    """

    trajectory: tr.Trajectory
    method: Method
    robot: RobotModel
    arch: ArchMove | JumpMove | None = None
    clearance: Clearance | None = None

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The method, the robot and the trajectory; an arch's own summary below."""
        head = f"MotionPlan ({self.method.value}) for {self.robot.name!r}: {self.trajectory.summary(units)}"
        return head if self.arch is None else head + "\n" + self.arch.summary(units)


def plan_motion(robot: RobotModel, request: MotionRequest) -> MotionPlan:
    """Choose the method for ``request`` (see the module docstring) and make the trajectory.

    With a cell (``request.cell``) the jump plans around and over the obstacles; any other move's path is fixed:
    it is checked against the cell before any timing (:func:`check_fixed_path`), then the timed motion is verified
    (:func:`~scara_pin.motion.verify.clear_of`), and refused if it comes closer than the margin.

    Raises:
        InvalidInputError: a straight line or an arch asked of a robot other than a SCARA, an arch with
            ``linear``, a payload without ``torque``; a start or end in collision (naming the pair).
        InfeasibleError: a pose out of reach, a path the robot cannot follow, a timing failure, or a fixed path
            that comes closer than the cell's margin (naming the pair, when and where).
    """
    check_fixed_path(robot, request)  # before any timing: the endpoints and the geometric path, in the cell
    plan = _plan(robot, request)
    if request.cell is None or plan.method is Method.JUMP:
        return plan
    from .verify import clear_of

    return replace(plan, clearance=clear_of(robot, plan.trajectory, request.cell))


def check_fixed_path(robot: RobotModel, request: MotionRequest) -> None:
    """A fixed path clear of the request's cell, BEFORE any timing: its ends, then its geometric path ``q(s)``.

    Every move but the jump has its path fixed by the request (a straight tool line, a joint line or spline through
    the vias), whatever its time law: the path is followed from its start by conservative advancement on coal's
    exact distances (:func:`~scara_pin.cell.sweep.first_contact`: no obstacle, however thin, is stepped over), so a
    path through an obstacle is refused before TOPP-RA or the 10 kHz verifier run (a straight move through a post
    took 39 s to be refused). Nothing is checked without a cell, nor for a jump (it plans around the obstacles).

    Raises:
        InCollisionError: the start or the end is closer than the margin (exit 2, naming the pair).
        InfeasibleError: the path comes closer than the margin (exit 3): the pair, where in the base frame it first
            comes to the margin and how far along the path.
    """
    if request.cell is None or request.arch:
        return
    from ..cell import scene
    from ..cell.sweep import first_contact

    paths, q_from, q_to = _fixed_path(robot, request)
    sc = scene(robot, request.cell)
    sc.check(q_from, "the start")
    sc.check(q_to, "the end")
    for k, path in enumerate(paths):
        contact = first_contact(sc, path)
        if contact is not None:
            raise InfeasibleError(_blocked(sc, contact, k, len(paths)))


def _fixed_path(robot: RobotModel, request: MotionRequest) -> tuple[list[GeometricPath], np.ndarray, np.ndarray]:
    """(the path's smooth pieces, its start, its end): what :func:`_line` or :func:`_joint` time (not for an arch)."""
    if request.linear:
        q_from, q_to = request.start_q, request.end_q
        first = request.start_pose if q_from is None else tr.joint_pose(robot, q_from)
        last = request.end_pose if q_to is None else tr.joint_pose(robot, q_to)
        poses = [first, *(tr.joint_pose(robot, v) for v in request.vias), last]
        line = tr.cartesian_path(robot, poses, start=q_from, end=q_to)  # type: ignore[arg-type]
        return list(line.segments), line.q_start, line.q_end
    q0, q1, vias = _joint_ends(robot, request)
    return [tr.joint_path(robot, [q0, *vias, q1])], q0, q1


def _blocked(sc: Scene, contact: Contact, k: int, n: int) -> str:
    """The message of a fixed path that comes to the margin at ``contact`` (the pair, where, how far along the path).

    The place is where the path first comes to the margin (the pair's witness points there): exact, where a depth
    further on would be EPA's estimate.
    """
    found = contact.closest
    mid = (found.point_a + found.point_b) / 2.0
    piece = f" of segment {k + 1} of {n}" if n > 1 else ""
    return (f"the motion comes closer than the margin: {found.pair.label} at {contact.s:.1%} of the path{piece} near "
            f"({', '.join(f'{v * 1e3:.1f}' for v in mid)}) mm in base (margin {sc.margin * 1e3:g} mm), and closer "
            "beyond (found before any timing)")


def _plan(robot: RobotModel, request: MotionRequest) -> MotionPlan:
    if request.linear and robot.kind != "scara":
        raise InvalidInputError(f"a straight tool line (--linear) is SCARA-only for now; robot {robot.name!r} is a "
                                f"{robot.kind} (joint-space --duration and TOPP-RA timing work)")  # fmt: skip
    payload = cast("Payload | None", request.payload)  # a Payload once the request is made
    if payload is not None and payload.mass and not request.torque:
        raise InvalidInputError("--payload changes only the torques: give --torque too")
    if request.arch:
        if request.linear:
            raise InvalidInputError("--arch is a SCARA move on its own (not with --linear)")
        if robot.kind != "scara" and request.path == "lines":
            raise InvalidInputError(f"the straight-leg arch (--path lines) is SCARA-only; robot {robot.name!r} is a "
                                    f"{robot.kind} (the jump, --path jump, works)")  # fmt: skip
        return _jump(robot, request) if request.path == "jump" else _arch(robot, request)
    if payload is not None and payload.mass:
        from .payload import with_payload

        robot = with_payload(robot, payload)
    if request.linear:
        return _line(robot, request)
    return _joint(robot, request)


def _time_optimal(robot: RobotModel, path: object, request: MotionRequest) -> tr.Trajectory:
    if request.jerk is not None:
        from .jerk import time_optimal_jerk

        if request.limits is not None:
            raise InvalidInputError("limits other than the robot's are not supported with a jerk limit")
        return time_optimal_jerk(robot, path, request.jerk, torque=request.torque).trajectory  # type: ignore[arg-type]
    from .timing import time_optimal

    return time_optimal(robot, path, tool_speed=request.tool_speed, torque=request.torque,  # type: ignore[arg-type]
                        limits=request.limits)  # fmt: skip


def _line(robot: RobotModel, request: MotionRequest) -> MotionPlan:
    q_from, q_to = request.start_q, request.end_q
    first = request.start_pose if q_from is None else tr.joint_pose(robot, q_from)
    last = request.end_pose if q_to is None else tr.joint_pose(robot, q_to)
    poses: list[np.ndarray] = [first, *(tr.joint_pose(robot, v) for v in request.vias), last]  # type: ignore[list-item]
    path = tr.cartesian_path(robot, poses, start=q_from, end=q_to)
    if request.duration is not None:
        return MotionPlan(tr.timed(path, request.duration), Method.LINE_QUINTIC, robot)
    method = Method.LINE_TOPPRA if request.jerk is None else Method.LINE_JERK
    return MotionPlan(_time_optimal(robot, path, request), method, robot)


def _joint_ends(robot: RobotModel, request: MotionRequest) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """(start, end, vias) of a joint move: poses by the closed-form IK, the start nearest the middle of the ranges."""
    vias = list(request.vias)
    q_from, q_to = request.start_q, request.end_q
    if q_from is None:
        mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2
        q_from = _pose_to_q(robot, request.start_pose, mid, "--from-pose")
    if q_to is None:
        q_to = _pose_to_q(robot, request.end_pose, vias[-1] if vias else q_from, "--to-pose")
    return q_from, q_to, vias


def _joint(robot: RobotModel, request: MotionRequest) -> MotionPlan:
    q_from, q_to, vias = _joint_ends(robot, request)
    if request.duration is not None:
        if vias:
            path = tr.joint_path(robot, [q_from, *vias, q_to])
            return MotionPlan(tr.timed(path, request.duration), Method.JOINT_SPLINE_QUINTIC, robot)
        return MotionPlan(tr.quintic(q_from, q_to, request.duration), Method.JOINT_QUINTIC, robot)
    if not vias and request.tool_speed is None and not request.torque and request.jerk is None:
        lim = robot.limits if request.limits is None else request.limits
        return MotionPlan(tr.trapezoidal(q_from, q_to, lim.velocity, lim.acceleration), Method.JOINT_TRAPEZOID, robot)
    method = Method.JOINT_TOPPRA if request.jerk is None else Method.JOINT_JERK
    return MotionPlan(_time_optimal(robot, [q_from, *vias, q_to], request), method, robot)


def _arch(robot: RobotModel, request: MotionRequest) -> MotionPlan:
    from .cycle import STANDARD_RISE, arch_move

    first = request.start_pose if request.start_q is None else tr.joint_pose(robot, request.start_q)
    last = request.end_pose if request.end_q is None else tr.joint_pose(robot, request.end_q)
    poses = np.array([first, last], dtype=float)
    rise = STANDARD_RISE if request.rise is None else request.rise
    if request.max_height is not None and request.max_height < max(poses[:, 2]) + rise:
        raise InfeasibleError(f"max_height {request.max_height:.6g} m is below the traverse height "
                              f"{max(poses[:, 2]) + rise:.6g} m of the arch")  # fmt: skip
    move = arch_move(robot, poses, rise=rise, blend=request.blend, payload=request.payload, torque=request.torque,
                     start=request.start_q, tool_speed=request.tool_speed, jerk=request.jerk)  # fmt: skip
    return MotionPlan(move.trajectory, Method.ARCH, robot, move)


def _jump(robot: RobotModel, request: MotionRequest) -> MotionPlan:
    from .jump import STANDARD_CLEARANCE, STANDARD_RISE, jump_move

    first = request.start_pose if request.start_q is None else tr.joint_pose(robot, request.start_q)
    last = request.end_pose if request.end_q is None else tr.joint_pose(robot, request.end_q)
    move = jump_move(robot, np.asarray(first, dtype=float), np.asarray(last, dtype=float),
                     rise=STANDARD_RISE if request.rise is None else request.rise,
                     clearance_radius=STANDARD_CLEARANCE if request.clearance_radius is None
                     else request.clearance_radius, max_height=request.max_height, payload=request.payload,
                     torque=request.torque, tool_speed=request.tool_speed, start=request.start_q,
                     end=request.end_q, jerk=request.jerk, limits=request.limits, cell=request.cell,
                     via=request.vias)  # fmt: skip
    return MotionPlan(move.trajectory, Method.JUMP, robot, move, move.distance)


def _pose_to_q(robot: RobotModel, pose: np.ndarray | None, near: np.ndarray, what: str) -> np.ndarray:
    """The closed-form IK solution of ``pose`` nearest ``near``; an :class:`InfeasibleError` if none."""
    result = robot.ik(pose)
    best = result.nearest(near) if result.success else None
    if best is None:
        shown = np.asarray(pose).tolist()
        raise InfeasibleError(f"{what} {shown}: {result.status.name}: {result.message}")
    return best.q
