"""Joint and Cartesian paths, time laws, and the :class:`Trajectory` they make (sampling, export, setpoints).

A motion is a geometric path followed by a time law. The path is ``q(s)`` for ``s`` in [0, 1]; the law
is ``s(t)`` for ``t`` in [0, T]; the chain rule gives the joint trajectory

    q(t) = q(s(t)),    qd = q'(s) sd,    qdd = q'(s) sdd + q''(s) sd^2,

with ``'`` a derivative in ``s`` and ``d`` one in ``t``. Paths (:class:`GeometricPath`):

- :class:`JointLine`: ``q0 + s (q1 - q0)``, the synchronised straight line in joint space;
- :class:`JointSpline`: a C2 cubic spline through joint waypoints (not-a-knot ends);
- :class:`CartesianSegment`: the tool moves on a straight line, yaw linear, the joints given at EVERY
  ``s`` by the closed-form IK (same elbow branch throughout, J4 continuous); :func:`cartesian_path`
  builds one per pair of consecutive poses (via points) and refuses, with a :class:`PathError` giving
  ``s`` and the pose, a line that leaves the workspace, reaches a joint limit or crosses the
  stretched/folded-arm singularity.

Time laws: :class:`QuinticLaw` (``jtraj``: zero velocity and acceleration at both ends),
:class:`TrapezoidLaw` (bang-coast-bang, time-optimal on a straight joint line), :class:`ProfileLaw`
(piecewise-constant path acceleration between grid points: the exact output of a TOPP-RA profile, see
:mod:`scara_pin.timing`).

A :class:`Trajectory` strings motions together, rest to rest. Outside [0, T] it holds its end positions
(zero velocity and acceleration). It samples at any times, resamples at a fixed rate, exports to CSV and
JSON (and reads them back: between samples a quintic Hermite through q, qd, qdd), and produces
controller setpoints (:meth:`Trajectory.setpoints`): per-axis latency compensation and integer motor
steps. Files are written atomically. Units are SI throughout: [s], [rad] or [m], [rad/s] or [m/s], ...
"""

from __future__ import annotations

import abc
import json
import logging
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .description import JOINT_NAMES
from .errors import InfeasibleError, InvalidInputError, ParameterError
from .files import write_text_atomic
from .ik import IKStatus, branch_of, solve_batch

if TYPE_CHECKING:
    from ._typing import ArrayLike
    from .model import Robot
    from .palletizer import PalletizerIKStatus

__all__ = [
    "CSV_HEADER",
    "SINGULAR_TOL",
    "CartesianPath",
    "CartesianSegment",
    "GeometricPath",
    "JointLine",
    "JointSpline",
    "MotorUnits",
    "Motion",
    "PathError",
    "ProfileLaw",
    "QuinticLaw",
    "Samples",
    "Setpoints",
    "TimeLaw",
    "Trajectory",
    "TrapezoidLaw",
    "cartesian_path",
    "joint_path",
    "joint_pose",
    "line_optimal_duration",
    "load_trajectory",
    "quintic",
    "quintic_min_duration",
    "timed",
    "trapezoidal",
]

logger = logging.getLogger(__name__)

CSV_HEADER: tuple[str, ...] = ("t",) + tuple(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 5))
"""Columns of the trajectory CSV: t, q1..q4, qd1..qd4, qdd1..qdd4 (SI units)."""
SINGULAR_TOL = 1e-6
"""|sin(elbow angle)| below which a Cartesian line is taken to reach the stretched/folded singularity."""
JUMP_TOL = 0.5 * math.pi
"""[rad] the largest joint change between two dense IK checkpoints of a line (more is a 2 pi wrap)."""
_FORMAT = "scara-pin/trajectory"
_DENSE_STEP = 5e-4  # [m] position step of the continuity/singularity check between checkpoints
_DENSE_YAW_STEP = 0.01  # [rad] yaw step of the same check
_DEFAULT_STEP = 2e-3  # [m] default checkpoint spacing of a Cartesian line
_DEFAULT_YAW_STEP = 0.02  # [rad]


class PathError(InfeasibleError):
    """A path the robot cannot follow, with where it fails (exit code 3).

    Attributes:
        s: the path parameter where it fails, in [0, 1] of ``segment``.
        segment: index of the failing segment (via points split a path into segments).
        pose: the tool pose (x, y, z, yaw) there [m, rad], for a Cartesian path; else None.
        q: the joint values there (or the last reachable ones), if known.
        status: the closed-form IK status there, if IK failed.
        reason: a sentence with the numbers.
    """

    def __init__(
        self,
        reason: str,
        *,
        s: float,
        segment: int = 0,
        pose: np.ndarray | None = None,
        q: np.ndarray | None = None,
        status: IKStatus | PalletizerIKStatus | None = None,
    ) -> None:
        self.s = float(s)
        self.segment = segment
        self.pose = None if pose is None else np.array(pose, dtype=float)
        self.q = None if q is None else np.array(q, dtype=float)
        self.status = status
        self.reason = reason
        where = f"s = {self.s:.9f} of segment {segment}"
        if self.pose is not None:
            x, y, z, yaw = self.pose
            where += f" (pose x = {x:.6g} m, y = {y:.6g} m, z = {z:.6g} m, yaw = {yaw:.6g} rad)"
        super().__init__(f"the path fails at {where}: {reason}")


# ---------------------------------------------------------------------------------------------- checks
def _vector(name: str, value: object, n: int = 4) -> np.ndarray:
    """``value`` as ``n`` finite floats, or a :class:`ParameterError`."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, value, f"must be {n} numbers") from None
    if arr.shape != (n,):
        raise ParameterError(name, value, f"must be {n} numbers (got shape {arr.shape})")
    if not np.isfinite(arr).all():
        raise ParameterError(name, arr.tolist(), "must be finite")
    return arr


def _positive(name: str, value: object, unit: str = "") -> float:
    """``value`` as a finite float > 0, or a :class:`ParameterError`."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be a number") from None
    if not (math.isfinite(v) and v > 0.0):
        raise ParameterError(name, v, "must be finite and > 0", unit)
    return v


def _rows(name: str, value: object) -> np.ndarray:
    """``value`` as an (m, 4) float array of finite numbers, m >= 2, or a :class:`ParameterError`."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be rows of 4 numbers") from None
    if arr.ndim != 2 or arr.shape[1] != 4 or arr.shape[0] < 2:
        raise ParameterError(name, f"array of shape {arr.shape}", "must have shape (m, 4) with m >= 2")
    if not np.isfinite(arr).all():
        raise ParameterError(name, arr.tolist(), "must be finite")
    return arr


def _limit_vector(name: str, values: ArrayLike, unit: str) -> np.ndarray:
    """Per-joint limits (velocity, acceleration...) as an array; each finite and > 0."""
    arr = np.array(values, dtype=float)
    if arr.shape != (4,):
        raise ParameterError(name, values, "must hold 4 values")
    for joint, v in zip(JOINT_NAMES, arr.tolist()):
        if math.isnan(v):
            raise ParameterError(f"{joint}_{name}", v, "must be given (a URDF file has no acceleration limits)")
        if not (math.isfinite(v) and v > 0.0):
            raise ParameterError(f"{joint}_{name}", v, "must be finite and > 0", unit)
    return arr


# ---------------------------------------------------------------------------------------------- paths
class GeometricPath(abc.ABC):
    """A joint path ``q(s)``, ``s`` in [0, 1]; also toppra's geometric-path interface (``path(s, order)``)."""

    dof: int = 4

    @abc.abstractmethod
    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:
        """(q, q', q'') at the path parameters ``s`` (1-D array), each (n, 4); up to ``order`` only."""

    def knots(self) -> np.ndarray:
        """Parameters where the path is only piecewise smooth (a timing grid should include them)."""
        return np.array([0.0, 1.0])

    def __call__(self, s: float | np.ndarray, order: int = 0) -> np.ndarray:
        """Q (order 0), q' (1) or q'' (2) at ``s``: (4,) for a scalar, (n, 4) for an array."""
        arr = np.asarray(s, dtype=float)
        out = self.evaluate(np.atleast_1d(arr).ravel(), order)[order]
        return out[0] if arr.ndim == 0 else out

    @property
    def path_interval(self) -> np.ndarray:
        """[0, 1] (toppra's interface)."""
        return np.array([0.0, 1.0])

    def eval(self, s: np.ndarray) -> np.ndarray:  # noqa: D102 - toppra's interface
        return self(s, 0)

    def evald(self, s: np.ndarray) -> np.ndarray:  # noqa: D102
        return self(s, 1)

    def evaldd(self, s: np.ndarray) -> np.ndarray:  # noqa: D102
        return self(s, 2)


@dataclass(frozen=True, eq=False)
class JointLine(GeometricPath):
    """The straight joint-space line ``q0 + s (q1 - q0)`` (all joints start and stop together).

    Attributes:
        q0, q1: start and end joint values [rad, m].
    """

    q0: np.ndarray
    q1: np.ndarray

    def __post_init__(self) -> None:
        object.__setattr__(self, "q0", _vector("q0", self.q0))
        object.__setattr__(self, "q1", _vector("q1", self.q1))

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:  # noqa: D102
        s = np.asarray(s, dtype=float).reshape(-1, 1)
        dq = self.q1 - self.q0
        out = [self.q0 + s * dq, np.broadcast_to(dq, (s.shape[0], 4)).copy(), np.zeros((s.shape[0], 4))]
        return tuple(out[: order + 1])


@dataclass(frozen=True, eq=False)
class JointSpline(GeometricPath):
    """A C2 cubic spline through joint waypoints (scipy's not-a-knot ends), ``s`` in [0, 1].

    The knots are the cumulative weighted chord lengths ``max_j w_j |dq_j|`` normalised to [0, 1]; with
    ``w = 1 / vmax`` that is each stretch's duration at full speed (see :func:`joint_path`).

    Attributes:
        waypoints: (m, 4) joint values, m >= 2, no two consecutive ones equal.
        weights: per-joint weights of the chord length.
    """

    waypoints: np.ndarray
    weights: tuple[float, ...] = (1.0, 1.0, 1.0, 1.0)
    _knots: np.ndarray = field(init=False, repr=False)
    _spline: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        from scipy.interpolate import CubicSpline

        W = _rows("waypoints", self.waypoints)
        w = _limit_vector("weight", self.weights, "")
        chord = np.max(np.abs(np.diff(W, axis=0)) * w, axis=1)
        if not (chord > 0).all():
            k = int(np.argmin(chord))
            raise ParameterError(f"waypoint {k + 1}", W[k + 1].tolist(), "must differ from the one before it")
        knots = np.concatenate([[0.0], np.cumsum(chord)])
        knots /= knots[-1]
        knots[-1] = 1.0
        object.__setattr__(self, "waypoints", W)
        object.__setattr__(self, "weights", tuple(float(v) for v in w))
        object.__setattr__(self, "_knots", knots)
        object.__setattr__(self, "_spline", CubicSpline(knots, W, bc_type="not-a-knot"))

    def knots(self) -> np.ndarray:  # noqa: D102
        return self._knots.copy()

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:  # noqa: D102
        # the spline's piecewise cubic coefficients, evaluated for all orders at once (one interval search)
        s = np.asarray(s, dtype=float).ravel()
        x, c = self._spline.x, self._spline.c  # c[k, i, j]: coefficient of (s - x_i)^(3 - k), joint j
        i = np.clip(np.searchsorted(x, s, side="right") - 1, 0, len(x) - 2)
        d = (s - x[i])[:, None]
        c0, c1, c2, c3 = c[0, i], c[1, i], c[2, i], c[3, i]
        out = [((c0 * d + c1) * d + c2) * d + c3, (3.0 * c0 * d + 2.0 * c1) * d + c2, 6.0 * c0 * d + 2.0 * c1]
        return tuple(out[: order + 1])


def joint_path(robot: Robot, waypoints: Sequence[ArrayLike] | np.ndarray) -> JointLine | JointSpline:
    """The path through joint waypoints: a :class:`JointLine` for two, else a :class:`JointSpline`.

    Consecutive equal waypoints are merged. The spline's knots weight each joint by 1 / vmax. The path
    is checked against the position limits on a dense grid (a spline may overshoot between waypoints).

    Args:
        robot: the robot (its position and velocity limits).
        waypoints: (m, 4) joint values [rad, m], m >= 2.

    Raises:
        ParameterError: a waypoint is not 4 finite numbers, is outside the joint limits, or all are equal.
        PathError: the spline leaves the joint limits between waypoints (s and q where it does).
    """
    W = _rows("waypoints", waypoints)
    for k, q in enumerate(W):
        robot.check_q(q)
        out = robot.outside_limits(q, tol=1e-10)
        if out:
            raise ParameterError(f"waypoint {k}", q.tolist(), "is outside the joint limits: " + "; ".join(out))
    keep = np.concatenate([[True], np.abs(np.diff(W, axis=0)).max(axis=1) > 0.0])
    W = W[keep]
    if W.shape[0] < 2:
        raise ParameterError("waypoints", W[0].tolist(), "are all the same configuration: nothing to move")
    if W.shape[0] == 2:
        return JointLine(W[0], W[1])
    vmax = np.array(robot.limits.velocity, dtype=float)
    weights = tuple(1.0 / v if math.isfinite(v) and v > 0 else 1.0 for v in vmax)
    path = JointSpline(W, weights)
    _check_joint_limits(robot, path)
    return path


def _check_joint_limits(robot: Robot, path: GeometricPath, n: int = 2001) -> None:
    """Raise :class:`PathError` where a path leaves the position limits (dense grid, then bisection)."""
    lo = np.array(robot.limits.lower) - 1e-10
    hi = np.array(robot.limits.upper) + 1e-10
    s = np.unique(np.concatenate([np.linspace(0.0, 1.0, n), path.knots()]))
    q = path(s)
    bad = ((q < lo) | (q > hi)).any(axis=1)
    if not bad.any():
        return
    k = int(np.argmax(bad))
    a, b = float(s[k - 1]), float(s[k])
    for _ in range(60):
        mid = 0.5 * (a + b)
        qm = path(mid)
        if ((qm < lo) | (qm > hi)).any():
            b = mid
        else:
            a = mid
    qb = path(b)
    raise PathError("the spline leaves the joint limits: " + "; ".join(robot.outside_limits(qb)), s=b, q=qb)


class _Kinematics:
    """Task Jacobian J = d(x, y, z, yaw)/dq and its derivative along a direction, on private Pinocchio data."""

    def __init__(self, robot: Robot) -> None:
        self.model = robot.model
        self.data = robot.model.createData()
        self.tool_id = robot.tool_id
        # continuous joints: Pinocchio takes their (cos, sin); v stays the 4 joint rates
        self.to_pin = robot.to_pinocchio_q if getattr(robot, "has_continuous", False) else None
        pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
        self.Rbo = self.data.oMf[robot.base_id].rotation.T.copy()  # base axes from world axes

    def _task(self, J6: np.ndarray) -> np.ndarray:
        out = np.empty((4, 4))
        out[:3] = self.Rbo @ J6[:3]
        out[3] = self.Rbo[2] @ J6[3:]
        return out

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """The 4 x 4 task Jacobian at q."""
        if self.to_pin is not None:
            q = self.to_pin(q)
        return self._task(pin.computeFrameJacobian(self.model, self.data, q, self.tool_id, pin.LOCAL_WORLD_ALIGNED))

    def jacobian_rate(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """dJ/dt of the task Jacobian when the joints move at v (Pinocchio's time variation)."""
        if self.to_pin is not None:
            q = self.to_pin(q)
        pin.computeJointJacobiansTimeVariation(self.model, self.data, q, v)
        pin.updateFramePlacements(self.model, self.data)
        dJ = pin.getFrameJacobianTimeVariation(self.model, self.data, self.tool_id, pin.LOCAL_WORLD_ALIGNED)
        return self._task(dJ)


@dataclass(frozen=True, eq=False)
class CartesianSegment(GeometricPath):
    """A straight tool line, yaw linear: ``pose(s) = pose0 + s (pose1 - pose0)``, joints by exact IK.

    ``q(s)`` is the closed-form IK of ``pose(s)`` on ``branch``, the 2 pi turn of each revolute joint
    nearest to the dense reference solutions computed when the segment was checked (so J4 is continuous);
    ``q' = J^-1 pose'`` and ``q'' = -J^-1 (dJ/ds) q'`` (the pose is linear in s), J the task Jacobian.
    Build it with :func:`cartesian_path`, which checks it.

    Attributes:
        robot: the robot.
        branch: ``"right"`` or ``"left"``.
        pose0, pose1: (x, y, z, yaw) at s = 0 and 1 [m, rad]; the yaw is interpolated as given (no wrap).
        s_ref, q_ref: the dense checked solutions (increasing s, from 0 to 1).
    """

    robot: Robot
    branch: str
    pose0: np.ndarray
    pose1: np.ndarray
    s_ref: np.ndarray = field(repr=False)
    q_ref: np.ndarray = field(repr=False)
    _kin: _Kinematics = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_kin", _Kinematics(self.robot))

    @property
    def delta(self) -> np.ndarray:
        """pose1 - pose0: the constant d(pose)/ds."""
        return self.pose1 - self.pose0

    def poses(self, s: np.ndarray) -> np.ndarray:
        """(n, 4) tool poses at s."""
        return self.pose0 + np.asarray(s, dtype=float).reshape(-1, 1) * self.delta

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:  # noqa: D102
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        idx = np.clip(np.searchsorted(self.s_ref, s, side="right") - 1, 0, len(self.s_ref) - 1)
        res = solve_batch(self.robot.kinematics, self.poses(s), branch=self.branch, reference=self.q_ref[idx])
        if (res.status != 0).any():  # cannot happen on a checked segment
            k = int(np.argmax(res.status != 0))
            raise PathError(f"no IK solution ({IKStatus(int(res.status[k])).name})", s=s[k], pose=self.poses(s[k])[0],
                            status=IKStatus(int(res.status[k])))  # fmt: skip
        q = res.q
        if order == 0:
            return (q,)
        n = len(s)
        dq = np.empty((n, 4))
        ddq = np.empty((n, 4))
        d = self.delta
        for k in range(n):
            J = self._kin.jacobian(q[k])
            try:
                dq[k] = np.linalg.solve(J, d)
                if order >= 2:
                    ddq[k] = -np.linalg.solve(J, self._kin.jacobian_rate(q[k], dq[k]) @ dq[k])
            except np.linalg.LinAlgError:
                raise PathError("the task Jacobian is singular (stretched or folded arm)", s=s[k],
                                pose=self.poses(s[k])[0], q=q[k]) from None  # fmt: skip
        return (q, dq, ddq)[: order + 1]


@dataclass(frozen=True, eq=False)
class CartesianPath:
    """Straight tool lines through poses (via points), one :class:`CartesianSegment` per pair, one branch.

    Attributes:
        robot: the robot.
        poses: (m, 4) poses [m, rad], m >= 2.
        branch: the elbow branch of every configuration on the path.
        segments: the m - 1 segments.
        checkpoints: per segment, (s, q) at the requested points (n points or the maximum step).
    """

    robot: Robot
    poses: np.ndarray
    branch: str
    segments: tuple[CartesianSegment, ...]
    checkpoints: tuple[tuple[np.ndarray, np.ndarray], ...]

    @property
    def q_start(self) -> np.ndarray:
        """The configuration at the start."""
        return self.segments[0].q_ref[0].copy()

    @property
    def q_end(self) -> np.ndarray:
        """The configuration at the end."""
        return self.segments[-1].q_ref[-1].copy()


def joint_pose(robot: Robot, q: ArrayLike) -> np.ndarray:
    """The tool pose (x, y, z, yaw) at q with the yaw UNWRAPPED as the joints turn.

    The yaw is yaw0 plus the signed revolute angles, equal to FK's yaw modulo 2 pi. A line between two
    such poses turns the tool the way the joints go (through +/-pi if they do), so
    ``cartesian_path(robot, [joint_pose(robot, qa), joint_pose(robot, qb)], start=qa, end=qb)`` ends at qb
    whenever the line stays feasible.
    """
    q = robot.check_q(q)
    geo = robot.kinematics
    pose = robot.tool_pose(q)
    turned = geo.yaw0 + sum(geo.signs[i] * float(q[i]) for i in geo.revolute)
    pose[3] += 2.0 * math.pi * round((turned - pose[3]) / (2.0 * math.pi))
    return pose


def _elbow_sin(robot: Robot, q: np.ndarray) -> np.ndarray:
    """sin(gamma) of configurations (n, 4): > 0 on the right branch, < 0 on the left, 0 when singular."""
    geo = robot.kinematics
    return np.sin(geo.elbow_angle(q[..., geo.revolute[1]]))


def cartesian_path(
    robot: Robot,
    poses: Sequence[ArrayLike] | np.ndarray,
    *,
    start: ArrayLike | None = None,
    end: ArrayLike | None = None,
    branch: str | None = None,
    n: int | None = None,
    max_step: float | None = None,
    max_yaw_step: float | None = None,
) -> CartesianPath:
    """Straight tool lines through ``poses``, on one elbow branch, J4 continuous; checked before use.

    The checkpoints of each segment are ``n`` equally spaced points (ends included) or, by default, as
    many as needed for steps of at most ``max_step`` (2 mm) and ``max_yaw_step`` (0.02 rad), as S4 splits
    a line. At each the closed-form IK (``robot.ik``) is solved and the solution of the branch nearest to
    the previous one kept. Between checkpoints the line is checked again on a finer grid (0.5 mm,
    0.01 rad), vectorised, so that no failure hides between two checkpoints.

    Args:
        robot: the robot.
        poses: (m, 4) tool poses (x, y, z, yaw) in the base frame [m, rad], m >= 2; the yaw is
            interpolated linearly as written (370 deg is a turn beyond 10 deg).
        start: the configuration at ``poses[0]`` (its FK must be that pose); it fixes the branch and the
            J4 turn. Default: the IK solution of ``branch`` nearest the middle of the joint ranges.
        end: if given, the configuration the path must end at (else :class:`PathError`).
        branch: ``"right"`` or ``"left"`` (default: the start's branch, or ``"right"``).
        n: checkpoints per segment (>= 2, ends included); exclusive with the step options.
        max_step: [m] largest position step between checkpoints.
        max_yaw_step: [rad] largest yaw step between checkpoints.

    Raises:
        ParameterError: malformed poses/options, or ``start`` not at ``poses[0]``.
        PathError: the line leaves the workspace or the joint limits, crosses the singularity, would
            make a joint jump (J4 at its limit), or does not end at ``end``; with ``s`` and the pose.
    """
    P = _rows("poses", poses)
    if branch is not None and branch not in ("right", "left"):
        raise InvalidInputError(f"branch {branch!r} must be 'right' or 'left'")
    if n is not None and (max_step is not None or max_yaw_step is not None):
        raise InvalidInputError("give either n (points per segment) or max_step/max_yaw_step, not both")
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2):
        raise ParameterError("n", n, "must be an integer >= 2 (points per segment, ends included)")
    step = _positive("max_step", _DEFAULT_STEP if max_step is None else max_step, "m")
    yaw_step = _positive("max_yaw_step", _DEFAULT_YAW_STEP if max_yaw_step is None else max_yaw_step, "rad")
    geo = robot.kinematics
    if start is not None:
        q0 = robot.check_q(start).astype(float)
        fk = robot.tool_pose(q0)
        dyaw = math.remainder(fk[3] - P[0, 3], 2 * math.pi)
        if np.abs(fk[:3] - P[0, :3]).max() > 1e-9 or abs(dyaw) > 1e-9:
            rule = f"must reach poses[0] = {P[0].tolist()}; it reaches {fk.tolist()}"
            raise ParameterError("start", q0.tolist(), rule)
        start_branch = branch_of(geo, q0)
        if branch is not None and branch != start_branch and abs(_elbow_sin(robot, q0)) > SINGULAR_TOL:
            raise InvalidInputError(f"the start configuration is on the {start_branch} branch, not {branch}")
        branch = branch or start_branch
    else:
        branch = branch or "right"
        res = robot.ik(P[0], branch=branch)
        mid = (np.array(geo.lower) + np.array(geo.upper)) / 2
        sol = res.nearest(mid, branch=branch)
        if sol is None:
            raise PathError(f"no {branch} IK solution at the start: {res.message}", s=0.0, pose=P[0], status=res.status)
        q0 = sol.q.copy()
    segments: list[CartesianSegment] = []
    checkpoints: list[tuple[np.ndarray, np.ndarray]] = []
    q_prev = q0
    for k in range(P.shape[0] - 1):
        seg_start = q_prev
        a, b = P[k], P[k + 1]
        d = b - a
        if np.abs(d).max() == 0.0:
            raise ParameterError(f"pose {k + 1}", b.tolist(), "must differ from the one before it")
        m = n - 1 if n is not None else max(1, math.ceil(np.linalg.norm(d[:3]) / step - 1e-9),
                                            math.ceil(abs(d[3]) / yaw_step - 1e-9))  # fmt: skip
        s_pts = np.linspace(0.0, 1.0, m + 1)
        q_pts = np.empty((m + 1, 4))
        _check_start(robot, a, seg_start, k)
        q_pts[0] = seg_start
        for j in range(1, m + 1):
            q_pts[j] = _checkpoint(robot, branch, a, d, k, s_pts[j - 1], s_pts[j], q_pts[j - 1])
        s_ref, q_ref = _dense_check(robot, branch, a, d, k, s_pts, q_pts)
        segments.append(CartesianSegment(robot, branch, a.copy(), b.copy(), s_ref, q_ref))
        checkpoints.append((s_pts, q_pts))
        q_prev = q_pts[-1]
    if end is not None:
        q_end = robot.check_q(end)
        if np.abs(q_end - q_prev).max() > 1e-9:
            raise PathError(f"the line ends at q = {np.round(q_prev, 9).tolist()} ({branch} branch), not at the "
                            f"requested end q = {np.round(q_end, 9).tolist()} (another elbow branch or J4 turn)",
                            s=1.0, segment=P.shape[0] - 2, pose=P[-1], q=q_prev)  # fmt: skip
    return CartesianPath(robot, P, branch, tuple(segments), tuple(checkpoints))


def _ik_step(
    robot: Robot, branch: str, pose: np.ndarray, q_prev: np.ndarray
) -> tuple[np.ndarray | None, str, IKStatus | PalletizerIKStatus | None]:
    """The branch solution at ``pose`` nearest ``q_prev``, or None with the reason and the IK status."""
    res = robot.ik(pose, branch=branch)
    sol = res.nearest(q_prev, branch=branch) if res.success else None
    if sol is None:
        if res.success:
            return None, f"no {branch} IK solution (the elbow would change branch)", res.status
        return None, f"{res.status.name}: {res.message}", res.status
    q = sol.q
    if sol.singular or abs(float(_elbow_sin(robot, q))) < SINGULAR_TOL:
        return None, "the arm reaches the stretched/folded singularity (sin(elbow) = 0)", None
    if float(_elbow_sin(robot, q)) * (1.0 if branch == "right" else -1.0) < 0.0:
        return None, f"the elbow leaves the {branch} branch", None
    return q, "", None


def _jump(robot: Robot, q: np.ndarray, q_prev: np.ndarray) -> str:
    """Why q does not follow q_prev continuously, or '' if it does."""
    dq = np.abs(q - q_prev)
    j = int(np.argmax(dq))
    if dq[j] <= JUMP_TOL:
        return ""
    name = robot.kinematics.names[j]
    turns = dq[j] / (2 * math.pi)
    if j in robot.kinematics.revolute and abs(turns - round(turns)) < 0.05:
        return (f"{name} would jump by {round(turns)} turn(s), from {q_prev[j]:.9g} to {q[j]:.9g} rad: it reaches "
                "its limit and the line cannot continue on this turn")  # fmt: skip
    return f"{name} would jump from {q_prev[j]:.9g} to {q[j]:.9g}: the arm passes through the singularity"


def _check_start(robot: Robot, pose: np.ndarray, q: np.ndarray, segment: int) -> None:
    """Refuse a singular configuration at a segment's start."""
    if abs(float(_elbow_sin(robot, q))) < SINGULAR_TOL:
        raise PathError("the arm is at the stretched/folded singularity (sin(elbow) = 0): a straight line from "
                        "here needs infinite joint speed", s=0.0, segment=segment, pose=pose, q=q)  # fmt: skip


def _checkpoint(
    robot: Robot, branch: str, a: np.ndarray, d: np.ndarray, segment: int, s0: float, s1: float, q0: np.ndarray
) -> np.ndarray:
    """IK at s1 continuing q0 (at s0); on failure, locate it by bisection and raise :class:`PathError`."""
    q, _, _ = _ik_step(robot, branch, a + s1 * d, q0)
    if q is not None and not _jump(robot, q, q0):
        return q
    _fail(robot, branch, a, d, segment, s0, s1, q0)
    raise AssertionError("unreachable")  # pragma: no cover


def _fail(
    robot: Robot,
    branch: str,
    a: np.ndarray,
    d: np.ndarray,
    segment: int,
    s_good: float,
    s_bad: float,
    q_good: np.ndarray,
) -> None:
    """Bisect between a good and a failing parameter; raise :class:`PathError` at the first failing one."""
    for _ in range(60):
        if s_bad - s_good <= 1e-13:
            break
        mid = 0.5 * (s_good + s_bad)
        q, _, _ = _ik_step(robot, branch, a + mid * d, q_good)
        if q is not None and not _jump(robot, q, q_good):
            s_good, q_good = mid, q
        else:
            s_bad = mid
    q, reason, status = _ik_step(robot, branch, a + s_bad * d, q_good)
    if q is not None:
        reason = _jump(robot, q, q_good) or "the solution changes discontinuously"
    raise PathError(reason, s=s_bad, segment=segment, pose=a + s_bad * d, q=q_good, status=status)


def _dense_check(
    robot: Robot, branch: str, a: np.ndarray, d: np.ndarray, segment: int, s_pts: np.ndarray, q_pts: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Solve the line on a fine grid between checkpoints (vectorised); return it as the IK reference."""
    m = len(s_pts) - 1
    ds = 1.0 / m
    sub = max(4, math.ceil(np.linalg.norm(d[:3]) * ds / _DENSE_STEP), math.ceil(abs(d[3]) * ds / _DENSE_YAW_STEP))
    geo = robot.kinematics
    sign = 1.0 if branch == "right" else -1.0
    q_prev = q_pts[:-1]
    rows = [q_pts[:-1]]
    for k in range(1, sub + 1):
        s = s_pts[:-1] + (s_pts[1:] - s_pts[:-1]) * (k / sub)
        res = solve_batch(geo, a + s[:, None] * d, branch=branch, reference=q_prev)
        q = np.where((res.status != 0)[:, None], np.nan, res.q)
        if k == sub:
            q = np.where(np.isnan(q), np.nan, q_pts[1:])  # the checkpoints themselves (same solutions)
        ok = (res.status == 0) & (sign * _elbow_sin(robot, q) >= SINGULAR_TOL)
        ok &= np.abs(q - q_prev).max(axis=1) <= JUMP_TOL
        if not ok.all():
            j = int(np.argmax(~ok))
            s_lo = s_pts[j] + (s_pts[j + 1] - s_pts[j]) * ((k - 1) / sub)
            _fail(robot, branch, a, d, segment, float(s_lo), float(s[j]), q_prev[j])
        rows.append(q)
        q_prev = q
    # interleave: interval j contributes its sub-points in order
    Q = np.stack(rows, axis=1)  # (m, sub + 1, 4); [:, sub] is the next checkpoint
    S = s_pts[:-1, None] + (s_pts[1:] - s_pts[:-1])[:, None] * (np.arange(sub + 1) / sub)[None, :]
    s_ref = np.concatenate([S[:, :-1].ravel(), [1.0]])
    q_ref = np.concatenate([Q[:, :-1].reshape(-1, 4), q_pts[-1:]])
    return s_ref, q_ref


# ---------------------------------------------------------------------------------------------- time laws
class TimeLaw(abc.ABC):
    """A path parameter law ``s(t)`` on [0, duration], from s = 0 to s = 1, at rest at both ends."""

    duration: float

    @abc.abstractmethod
    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s, sd, sdd) at times ``tau`` in [0, duration] (1-D array)."""

    def scaled(self, k: float) -> TimeLaw:
        """The same law ``k`` times slower: s_k(t) = s(t / k), so sd / k and sdd / k^2."""
        return _ScaledLaw(self, _positive("k", k))


@dataclass(frozen=True)
class _ScaledLaw(TimeLaw):
    base: TimeLaw
    k: float
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", self.base.duration * self.k)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, sd, sdd = self.base.evaluate(np.asarray(tau) / self.k)
        return s, sd / self.k, sdd / (self.k * self.k)


@dataclass(frozen=True)
class QuinticLaw(TimeLaw):
    """``s = 10 x^3 - 15 x^4 + 6 x^5``, x = t / T (``jtraj``): zero velocity and acceleration at both ends.

    Peak sd = 1.875 / T at T / 2; peak |sdd| = (10 / sqrt(3)) / T^2 at x = 1/2 -/+ sqrt(3) / 6.

    Attributes:
        duration: T [s].
    """

    duration: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", _positive("duration", self.duration, "s"))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        T = self.duration
        x = np.clip(np.asarray(tau, dtype=float) / T, 0.0, 1.0)
        x2 = x * x
        s = x2 * x * (10.0 + x * (-15.0 + 6.0 * x))
        sd = 30.0 * x2 * (1.0 + x * (-2.0 + x)) / T
        sdd = 60.0 * x * (1.0 + x * (-3.0 + 2.0 * x)) / (T * T)
        return s, sd, sdd


@dataclass(frozen=True)
class TrapezoidLaw(TimeLaw):
    """Bang-coast-bang in s: accelerate at A, coast at the peak velocity, decelerate at A; s from 0 to 1.

    The peak is ``min(velocity, sqrt(acceleration))`` (a triangle when the velocity is not reached).

    Attributes:
        velocity: largest path velocity [1/s].
        acceleration: path acceleration [1/s^2].
    """

    velocity: float
    acceleration: float
    duration: float = field(init=False)
    peak: float = field(init=False)
    t_acc: float = field(init=False)

    def __post_init__(self) -> None:
        V = _positive("velocity", self.velocity, "1/s")
        A = _positive("acceleration", self.acceleration, "1/s^2")
        peak = min(V, math.sqrt(A))
        t_acc = peak / A
        coast = max(1.0 / peak - peak / A, 0.0)
        object.__setattr__(self, "peak", peak)
        object.__setattr__(self, "t_acc", t_acc)
        object.__setattr__(self, "duration", 2.0 * t_acc + coast)

    @classmethod
    def for_duration(cls, acceleration: float, duration: float) -> TrapezoidLaw:
        """The law of the given duration with acceleration A: peak V solves 1/V + V/A = T.

        Raises:
            InfeasibleError: T < 2 / sqrt(A) (even a triangle at A is slower).
        """
        A = _positive("acceleration", acceleration, "1/s^2")
        T = _positive("duration", duration, "s")
        disc = A * A * T * T - 4.0 * A
        if disc < -1e-12 * A * A * T * T:
            raise InfeasibleError(f"duration {T:.9g} s is shorter than the fastest move {2 / math.sqrt(A):.9g} s")
        V = 2.0 * A / (A * T + math.sqrt(max(disc, 0.0)))  # the small root, without cancellation
        return cls(V, A)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        A, V, ta, T = self.acceleration, self.peak, self.t_acc, self.duration
        t = np.clip(np.asarray(tau, dtype=float), 0.0, T)
        r = T - t
        up, down = t < ta, r < ta
        s = np.where(up, 0.5 * A * t * t, np.where(down, 1.0 - 0.5 * A * r * r, 0.5 * A * ta * ta + V * (t - ta)))
        sd = np.where(up, A * t, np.where(down, A * r, V))
        sdd = np.where(up, A, np.where(down, -A, 0.0))
        return np.minimum(s, 1.0), sd, sdd


@dataclass(frozen=True, eq=False)
class ProfileLaw(TimeLaw):
    """A phase-plane profile: path velocity ``sd_i`` at grid points ``s_i``, constant ``sdd`` between them.

    On segment i: ``u_i = (sd_{i+1}^2 - sd_i^2) / (2 (s_{i+1} - s_i))``, duration
    ``2 (s_{i+1} - s_i) / (sd_i + sd_{i+1})``, and exactly ``sd(t) = sd_i + u_i t``,
    ``s(t) = s_i + sd_i t + u_i t^2 / 2``: the kinematics between grid points are those of the law
    itself, not an interpolation of it.

    Attributes:
        s: (N + 1,) grid, increasing from 0 to 1.
        sd: (N + 1,) path velocities >= 0 [1/s]; sd_i + sd_{i+1} > 0 on every segment.
        t: (N + 1,) times of the grid points [s] (derived).
        u: (N,) path accelerations [1/s^2] (derived).
    """

    s: np.ndarray
    sd: np.ndarray
    t: np.ndarray = field(init=False)
    u: np.ndarray = field(init=False)
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        s = np.array(self.s, dtype=float)
        sd = np.array(self.sd, dtype=float)
        if s.ndim != 1 or s.shape != sd.shape or len(s) < 2:
            raise ParameterError("profile", f"shapes {s.shape}, {sd.shape}", "must be two equal 1-D arrays of >= 2")
        if not (np.isfinite(s).all() and np.isfinite(sd).all()):
            raise ParameterError("profile", "non-finite values", "must be finite")
        ds = np.diff(s)
        if s[0] != 0.0 or s[-1] != 1.0 or not (ds > 0).all():
            raise ParameterError("profile s", f"[{s[0]}, ..., {s[-1]}]", "must increase strictly from 0 to 1")
        if (sd < 0).any():
            raise ParameterError("profile sd", float(sd.min()), "must be >= 0")
        mean = sd[1:] + sd[:-1]
        if not (mean > 0).all():
            k = int(np.argmin(mean))
            raise InfeasibleError(f"the path velocity is zero on a whole segment at s = {s[k]:.9g}: the motion stops")
        dt = 2.0 * ds / mean
        object.__setattr__(self, "s", s)
        object.__setattr__(self, "sd", sd)
        object.__setattr__(self, "t", np.concatenate([[0.0], np.cumsum(dt)]))
        object.__setattr__(self, "u", (sd[1:] ** 2 - sd[:-1] ** 2) / (2.0 * ds))
        object.__setattr__(self, "duration", float(self.t[-1]))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.u) - 1)
        dt = tau - self.t[i]
        u = self.u[i]
        sd = np.maximum(self.sd[i] + u * dt, 0.0)
        s = np.clip(self.s[i] + self.sd[i] * dt + 0.5 * u * dt * dt, self.s[i], self.s[i + 1])
        return s, sd, u

    def scaled(self, k: float) -> ProfileLaw:
        """The same profile ``k`` times slower (sd / k; hence times * k and u / k^2), exactly."""
        return ProfileLaw(self.s, self.sd / _positive("k", k))


# ---------------------------------------------------------------------------------------------- motions
class Piece(abc.ABC):
    """A part of a trajectory: ``duration`` and (q, qd, qdd) at local times in [0, duration]."""

    duration: float

    @abc.abstractmethod
    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd), each (n, 4), at local times ``tau`` (1-D array)."""


@dataclass(frozen=True, eq=False)
class Motion(Piece):
    """A path followed with a time law: q(t) = path(law(t)) (see the module docstring).

    Attributes:
        path: the geometric path.
        law: the time law.
    """

    path: GeometricPath
    law: TimeLaw
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", float(self.law.duration))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        s, sd, sdd = self.law.evaluate(tau)
        q, dq, ddq = self.path.evaluate(s, 2)
        return q, dq * sd[:, None], dq * sdd[:, None] + ddq * (sd * sd)[:, None]

    def scaled(self, k: float) -> Motion:
        """The same motion k times slower."""
        return Motion(self.path, self.law.scaled(k))


@dataclass(frozen=True, eq=False)
class Samples:
    """Sampled joint trajectory: times and q, qd, qdd (SI).

    Attributes:
        t: (n,) increasing times from 0 [s].
        q, qd, qdd: (n, 4) positions, velocities, accelerations.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=float)
        if t.ndim != 1 or len(t) < 2:
            raise ParameterError("t", f"array of shape {t.shape}", "must be 1-D with at least 2 samples")
        if not np.isfinite(t).all() or t[0] != 0.0 or not (np.diff(t) > 0).all():
            raise ParameterError("t", f"[{t[0]}, ..., {t[-1]}]", "must be finite, start at 0 and increase strictly")
        object.__setattr__(self, "t", t)
        for name in ("q", "qd", "qdd"):
            arr = np.array(getattr(self, name), dtype=float)
            if arr.shape != (len(t), 4):
                raise ParameterError(name, f"array of shape {arr.shape}", f"must have shape ({len(t)}, 4)")
            if not np.isfinite(arr).all():
                raise ParameterError(name, "non-finite values", "must be finite")
            object.__setattr__(self, name, arr)

    def table(self) -> np.ndarray:
        """(n, 13) array in :data:`CSV_HEADER` order."""
        return np.column_stack([self.t, self.q, self.qd, self.qdd])

    def csv_text(self) -> str:
        """The CSV text (header, then one row per sample; shortest round-trip float text)."""
        lines = [",".join(CSV_HEADER)]
        lines += [",".join(map(repr, row)) for row in self.table().tolist()]
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (``format``, ``version``, ``joints``, ``duration``, ``t``, ``q``, ``qd``, ``qdd``)."""
        return {
            "format": _FORMAT,
            "version": 1,
            "units": "SI: s; rad or m; per s; per s^2",
            "joints": list(JOINT_NAMES),
            "duration": float(self.t[-1]),
            "t": self.t.tolist(),
            "q": self.q.tolist(),
            "qd": self.qd.tolist(),
            "qdd": self.qdd.tolist(),
        }

    @classmethod
    def from_table(cls, table: np.ndarray) -> Samples:
        """From an (n, 13) array in :data:`CSV_HEADER` order."""
        table = np.asarray(table, dtype=float)
        return cls(table[:, 0], table[:, 1:5], table[:, 5:9], table[:, 9:13])


@dataclass(frozen=True, eq=False)
class _SampledPiece(Piece):
    """Samples joined by quintic Hermite polynomials (q, qd, qdd matched at every sample)."""

    samples: Samples
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", float(self.samples.t[-1]))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        S = self.samples
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(S.t, tau, side="right") - 1, 0, len(S.t) - 2)
        h = (S.t[i + 1] - S.t[i])[:, None]
        x = ((tau - S.t[i]) / (S.t[i + 1] - S.t[i]))[:, None]
        p0, v0, a0 = S.q[i], S.qd[i] * h, S.qdd[i] * h * h
        p1, v1, a1 = S.q[i + 1], S.qd[i + 1] * h, S.qdd[i + 1] * h * h
        dp = p1 - p0
        c3 = 10 * dp - 6 * v0 - 4 * v1 - (3 * a0 - a1) / 2
        c4 = -15 * dp + 8 * v0 + 7 * v1 + (3 * a0 - 2 * a1) / 2
        c5 = 6 * dp - 3 * (v0 + v1) - (a0 - a1) / 2
        c2 = a0 / 2
        q = p0 + x * (v0 + x * (c2 + x * (c3 + x * (c4 + x * c5))))
        qd = (v0 + x * (2 * c2 + x * (3 * c3 + x * (4 * c4 + x * 5 * c5)))) / h
        qdd = (2 * c2 + x * (6 * c3 + x * (12 * c4 + x * 20 * c5))) / (h * h)
        for j in (i, i + 1):  # at the samples themselves: the stored values, bit for bit
            at = tau == S.t[j]
            q[at], qd[at], qdd[at] = S.q[j[at]], S.qd[j[at]], S.qdd[j[at]]
        return q, qd, qdd


# ---------------------------------------------------------------------------------------------- trajectory
@dataclass(frozen=True, eq=False)
class Trajectory:
    """A joint trajectory made of pieces played one after the other, from rest to rest.

    Attributes:
        pieces: the motions (or imported samples), in order; each starts where the previous ends.
        duration: total duration T [s].
        starts: (len(pieces) + 1,) start time of each piece, then T.
    """

    pieces: tuple[Piece, ...]
    duration: float = field(init=False)
    starts: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        pieces = tuple(self.pieces)
        if not pieces or not all(isinstance(p, Piece) for p in pieces):
            raise ParameterError("pieces", self.pieces, "must be a non-empty sequence of motions")
        for k, p in enumerate(pieces):
            if not (math.isfinite(p.duration) and p.duration > 0):
                raise ParameterError(f"piece {k} duration", p.duration, "must be finite and > 0", "s")
        for k in range(len(pieces) - 1):
            end = pieces[k].evaluate(np.array([pieces[k].duration]))[0][0]
            start = pieces[k + 1].evaluate(np.array([0.0]))[0][0]
            if np.abs(end - start).max() > 1e-9:
                rule = f"must start where piece {k} ends, {end.tolist()}"
                raise ParameterError(f"piece {k + 1}", start.tolist(), rule)
        starts = np.concatenate([[0.0], np.cumsum([p.duration for p in pieces])])
        object.__setattr__(self, "pieces", pieces)
        object.__setattr__(self, "starts", starts)
        object.__setattr__(self, "duration", float(starts[-1]))

    # --------------------------------------------------------------------------------- sampling
    def sample(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at times ``t`` [s]: (4,) each for a scalar, (n, 4) for an array.

        Before 0 and after T the robot holds the end positions (qd = qdd = 0).
        """
        arr = np.asarray(t, dtype=float)
        tt = np.atleast_1d(arr).ravel()
        if not np.isfinite(tt).all():
            raise ParameterError("t", "non-finite times", "must be finite")
        q = np.empty((len(tt), 4))
        qd = np.zeros((len(tt), 4))
        qdd = np.zeros((len(tt), 4))
        k = np.clip(np.searchsorted(self.starts, tt, side="right") - 1, 0, len(self.pieces) - 1)
        inside = (tt >= 0.0) & (tt <= self.duration)
        for j, piece in enumerate(self.pieces):
            sel = np.nonzero((k == j) & inside)[0]
            if len(sel):
                q[sel], qd[sel], qdd[sel] = piece.evaluate(tt[sel] - self.starts[j])
        if not inside.all():
            last = self.pieces[-1]
            q[tt < 0.0] = self.pieces[0].evaluate(np.array([0.0]))[0][0]
            q[tt > self.duration] = last.evaluate(np.array([last.duration]))[0][0]
        if arr.ndim == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    @property
    def q_start(self) -> np.ndarray:
        """Joint values at t = 0."""
        return self.sample(0.0)[0]

    @property
    def q_end(self) -> np.ndarray:
        """Joint values at t = T."""
        return self.sample(self.duration)[0]

    def times(self, rate: float) -> np.ndarray:
        """The fixed-rate grid k / rate, k = 0, 1, ..., through T (the last sample is at or just after T)."""
        rate = _positive("rate", rate, "Hz")
        n = math.floor(self.duration * rate + 1e-9)
        if n / rate < self.duration * (1 - 1e-12):
            n += 1
        if n > 50_000_000:
            raise ParameterError("rate", rate, f"gives {n} samples over {self.duration:.6g} s; lower it", "Hz")
        return np.arange(n + 1) / rate

    def resample(self, rate: float) -> Samples:
        """Samples on the fixed-rate grid :meth:`times`."""
        t = self.times(rate)
        return Samples(t, *self.sample(t))

    def scaled(self, k: float) -> Trajectory:
        """The same trajectory ``k`` times slower (velocities / k, accelerations / k^2)."""
        k = _positive("k", k)
        pieces = []
        for p in self.pieces:
            if not isinstance(p, Motion):
                raise InvalidInputError("only trajectories made of motions (not imported samples) can be rescaled")
            pieces.append(p.scaled(k))
        return Trajectory(tuple(pieces))

    def then(self, other: Trajectory) -> Trajectory:
        """This trajectory followed by ``other`` (which must start where this one ends)."""
        return Trajectory(self.pieces + other.pieces)

    # --------------------------------------------------------------------------------- export
    def to_csv(self, path: str | os.PathLike[str], rate: float = 1000.0) -> Path:
        """Write the samples at ``rate`` [Hz] as CSV (:data:`CSV_HEADER`), atomically; return the path."""
        text = self.resample(rate).csv_text()
        return write_text_atomic(Path(path), text)

    def to_json(self, path: str | os.PathLike[str], rate: float = 1000.0) -> Path:
        """Write the samples at ``rate`` [Hz] as JSON (see :meth:`Samples.to_dict`), atomically."""
        data = self.resample(rate).to_dict()
        data["rate"] = float(rate)
        return write_text_atomic(Path(path), json.dumps(data) + "\n")

    @classmethod
    def from_samples(cls, samples: Samples) -> Trajectory:
        """A trajectory through samples (quintic Hermite between them: q, qd, qdd matched)."""
        return cls((_SampledPiece(samples),))

    # --------------------------------------------------------------------------------- controller
    def setpoints(
        self, rate: float, *, delays: Sequence[float] | None = None, motor: MotorUnits | None = None
    ) -> Setpoints:
        """Controller setpoints at a fixed rate, with per-axis latency compensation and motor steps.

        Axis i's command reaches its drive ``delays[i]`` late (S4: station i after i sigma), so the
        setpoint sent at time t is ``q_i(t + delays[i])``: every axis then arrives at q(t') at the same
        t'. Sending starts ``max(delays)`` early (rounded up to whole periods): the send times ``t`` may
        be negative (relative to the start of the motion).

        Args:
            rate: setpoint rate [Hz] (controllers use 250 Hz to 1 kHz).
            delays: per-axis command latency [s], >= 0 (default: none).
            motor: conversion to integer motor steps (optional).
        """
        rate = _positive("rate", rate, "Hz")
        d = np.zeros(4) if delays is None else _vector("delays", delays)
        if (d < 0).any():
            raise ParameterError("delays", d.tolist(), "must be >= 0", "s")
        lead = math.ceil(float(d.max()) * rate - 1e-9)
        t = np.concatenate([np.arange(-lead, 0) / rate, self.times(rate)])
        q = np.empty((len(t), 4))
        shifted: dict[float, np.ndarray] = {}  # one evaluation per distinct delay
        for i, di in enumerate(d.tolist()):
            if di not in shifted:
                shifted[di] = self.sample(t + di)[0]
            q[:, i] = shifted[di][:, i]
        return Setpoints(rate, tuple(d.tolist()), t, q, None if motor is None else motor.counts(q))


def load_trajectory(path: str | os.PathLike[str]) -> Trajectory:
    """Read a trajectory written by :meth:`Trajectory.to_csv` or :meth:`Trajectory.to_json` (by suffix).

    Raises:
        InvalidInputError: unreadable file, wrong header or format, or bad values (with the line).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{path}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
    if path.suffix.lower() == ".json":
        return Trajectory.from_samples(_samples_from_json(text, str(path)))
    return Trajectory.from_samples(_samples_from_csv(text, str(path)))


def _samples_from_csv(text: str, origin: str) -> Samples:
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines or tuple(c.strip() for c in lines[0].split(",")) != CSV_HEADER:
        raise InvalidInputError(f"{origin}: the first line must be the header {','.join(CSV_HEADER)}")
    rows = []
    for k, line in enumerate(lines[1:], start=2):
        cells = line.split(",")
        try:
            if len(cells) != len(CSV_HEADER):
                raise ValueError(f"{len(cells)} values, expected {len(CSV_HEADER)}")
            rows.append([float(c) for c in cells])
        except ValueError as exc:
            raise InvalidInputError(f"{origin}, line {k}: {exc}") from None
    try:
        return Samples.from_table(np.array(rows).reshape(-1, len(CSV_HEADER)))
    except ParameterError as exc:
        raise InvalidInputError(f"{origin}: {exc}") from None


def _samples_from_json(text: str, origin: str) -> Samples:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InvalidInputError(f"{origin}: not JSON: {exc}") from None
    if not isinstance(data, dict) or data.get("format") != _FORMAT:
        raise InvalidInputError(f"{origin}: not a {_FORMAT} file")
    try:
        return Samples(np.array(data["t"], dtype=float), np.array(data["q"], dtype=float),
                       np.array(data["qd"], dtype=float), np.array(data["qdd"], dtype=float))  # fmt: skip
    except (KeyError, TypeError, ValueError) as exc:
        raise InvalidInputError(f"{origin}: bad trajectory data ({exc})") from None


# ---------------------------------------------------------------------------------------------- setpoints
@dataclass(frozen=True)
class MotorUnits:
    """Conversion of joint values to integer motor steps: ``steps = round(q * counts_per_unit)``.

    Each setpoint rounds the ABSOLUTE position: the error never exceeds half a step and never
    accumulates (increments are differences of rounded absolutes, never rounded themselves).

    Attributes:
        counts_per_unit: per joint [steps/rad] (revolute) or [steps/m] (prismatic).
    """

    counts_per_unit: tuple[float, ...]

    def __post_init__(self) -> None:
        arr = _limit_vector("counts_per_unit", self.counts_per_unit, "steps per unit")
        object.__setattr__(self, "counts_per_unit", tuple(float(v) for v in arr))

    @classmethod
    def from_drive(
        cls,
        gear_ratio: Sequence[float],
        steps_per_revolution: Sequence[float],
        screw_lead: float,
        prismatic: int = 2,
    ) -> MotorUnits:
        """From the drive train.

        Revolute joints ``gear * steps_per_rev / (2 pi)`` [steps/rad]; the prismatic joint
        ``gear * steps_per_rev / lead`` [steps/m], ``lead`` the screw's travel per turn [m].

        Args:
            gear_ratio: motor turns per joint turn (per screw turn for the prismatic joint).
            steps_per_revolution: motor steps (microsteps) per motor turn.
            screw_lead: [m] travel per screw turn.
            prismatic: index of the prismatic joint in q.
        """
        g = _limit_vector("gear_ratio", gear_ratio, "")
        spr = _limit_vector("steps_per_revolution", steps_per_revolution, "")
        lead = _positive("screw_lead", screw_lead, "m")
        if prismatic not in range(4):
            raise ParameterError("prismatic", prismatic, "must be a joint index 0..3")
        cpu = g * spr / (2.0 * math.pi)
        cpu[prismatic] = g[prismatic] * spr[prismatic] / lead
        return cls(tuple(cpu.tolist()))

    def counts(self, q: np.ndarray) -> np.ndarray:
        """Integer steps (int64) of joint values q (..., 4), rounded from the absolute position."""
        x = np.asarray(q, dtype=float) * np.asarray(self.counts_per_unit)
        if not np.isfinite(x).all() or np.abs(x).max(initial=0.0) > 2.0**62:
            raise ParameterError("q", "values", "give step counts beyond the int64 range")
        return np.rint(x).astype(np.int64)


@dataclass(frozen=True, eq=False)
class Setpoints:
    """Fixed-rate controller setpoints (see :meth:`Trajectory.setpoints`).

    Attributes:
        rate: [Hz].
        delays: per-axis latency compensated [s].
        t: (n,) send times [s] (negative while the late axes are sent ahead).
        q: (n, 4) commanded joint values; column i is q_i(t + delays[i]).
        steps: (n, 4) int64 motor steps, or None.
    """

    rate: float
    delays: tuple[float, ...]
    t: np.ndarray
    q: np.ndarray
    steps: np.ndarray | None = None

    @property
    def increments(self) -> np.ndarray:
        """(n, 4) int64 step increments per period (first row 0): differences of absolute counts."""
        if self.steps is None:
            raise InvalidInputError("these setpoints have no motor units")
        return np.diff(self.steps, axis=0, prepend=self.steps[:1])

    def csv_text(self) -> str:
        """CSV: t, q1..q4 and, with motor units, steps1..steps4."""
        head = ["t", "q1", "q2", "q3", "q4"] + ([f"steps{i}" for i in range(1, 5)] if self.steps is not None else [])
        lines = [",".join(head)]
        for k in range(len(self.t)):
            row = [repr(float(self.t[k]))] + [repr(v) for v in self.q[k].tolist()]
            if self.steps is not None:
                row += [str(v) for v in self.steps[k].tolist()]
            lines.append(",".join(row))
        return "\n".join(lines) + "\n"

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`csv_text` atomically."""
        return write_text_atomic(Path(path), self.csv_text())


# ---------------------------------------------------------------------------------------------- constructors
def quintic(q0: ArrayLike, q1: ArrayLike, duration: float) -> Trajectory:
    """``jtraj``: q0 to q1 in ``duration`` with a quintic, zero velocity and acceleration at both ends.

    Each joint: ``q0 + (q1 - q0) (10 x^3 - 15 x^4 + 6 x^5)``, x = t / T; peak velocity
    ``1.875 dq / T`` at T / 2, peak acceleration ``(10 / sqrt(3)) dq / T^2`` at x = 1/2 -/+ sqrt(3)/6.

    Args:
        q0: start [rad, m].
        q1: end [rad, m].
        duration: T [s] > 0.
    """
    return Trajectory((Motion(JointLine(_vector("q0", q0), _vector("q1", q1)), QuinticLaw(duration)),))


def _line_rates(
    q0: ArrayLike, q1: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> tuple[JointLine, float, float]:
    line = JointLine(_vector("q0", q0), _vector("q1", q1))
    v = _limit_vector("velocity", velocity, "rad/s or m/s")
    a = _limit_vector("acceleration", acceleration, "rad/s^2 or m/s^2")
    dq = np.abs(line.q1 - line.q0)
    moving = dq > 0
    if not moving.any():
        raise ParameterError("q1", line.q1.tolist(), "must differ from q0: there is nothing to move")
    V = float(np.min(v[moving] / dq[moving]))
    A = float(np.min(a[moving] / dq[moving]))
    return line, V, A


def quintic_min_duration(
    q0: ArrayLike, q1: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> float:
    """The shortest duration of :func:`quintic` within the limits.

    The peaks 1.875 |dq| / T and (10 / sqrt(3)) |dq| / T^2 reach a limit:
    T = max_i max(1.875 |dq_i| / v_i, sqrt(10 / sqrt(3) |dq_i| / a_i)).
    """
    line = JointLine(_vector("q0", q0), _vector("q1", q1))
    v = _limit_vector("velocity", velocity, "rad/s or m/s")
    a = _limit_vector("acceleration", acceleration, "rad/s^2 or m/s^2")
    dq = np.abs(line.q1 - line.q0)
    return float(max(np.max(1.875 * dq / v), np.max(np.sqrt(10.0 / math.sqrt(3.0) * dq / a))))


def line_optimal_duration(
    q0: ArrayLike, q1: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> float:
    """T*: the shortest duration of the synchronised straight joint move under per-joint limits.

    With s in [0, 1]: V = min_i vmax_i / |dq_i|, A = min_i amax_i / |dq_i|;
    T* = 1/V + V/A if V^2 / A < 1 (the velocity limit is reached), else 2 sqrt(1 / A).
    """
    _, V, A = _line_rates(q0, q1, velocity, acceleration)
    return 1.0 / V + V / A if V * V / A < 1.0 else 2.0 * math.sqrt(1.0 / A)


def trapezoidal(
    q0: ArrayLike,
    q1: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    duration: float | None = None,
) -> Trajectory:
    """Synchronised point-to-point move: all joints start and stop together, trapezoidal velocity.

    Without ``duration`` it is the time-optimal one (:func:`line_optimal_duration`): the binding joint
    reaches its velocity and/or acceleration limit and no joint exceeds any. With ``duration`` >= T*,
    the same acceleration and a lower coast velocity.

    Args:
        q0: start [rad, m].
        q1: end [rad, m].
        velocity: per-joint velocity limits (> 0).
        acceleration: per-joint acceleration limits (> 0).
        duration: [s], optional.

    Raises:
        ParameterError: bad limits, or q1 == q0.
        InfeasibleError: ``duration`` shorter than T*.
    """
    line, V, A = _line_rates(q0, q1, velocity, acceleration)
    if duration is None:
        law = TrapezoidLaw(V, A)
    else:
        T = _positive("duration", duration, "s")
        T_opt = line_optimal_duration(q0, q1, velocity, acceleration)
        if T < T_opt * (1 - 1e-12):
            raise InfeasibleError(f"duration {T:.9g} s is shorter than the fastest synchronised move {T_opt:.9g} s")
        law = TrapezoidLaw(V, A) if T <= T_opt * (1 + 1e-12) else TrapezoidLaw.for_duration(A, T)
    return Trajectory((Motion(line, law),))


def timed(path: GeometricPath | CartesianPath, duration: float) -> Trajectory:
    """Follow a path in ``duration`` with the quintic time law (rest to rest, smooth).

    A Cartesian path with via points stops at each: its segments share ``duration`` in proportion to
    their joint-space lengths weighted by 1 / vmax (so all peak at comparable speeds).
    """
    T = _positive("duration", duration, "s")
    if isinstance(path, GeometricPath):
        return Trajectory((Motion(path, QuinticLaw(T)),))
    if not isinstance(path, CartesianPath):
        raise InvalidInputError(f"cannot time a {type(path).__name__}: give a path")
    v = np.array(path.robot.limits.velocity, dtype=float)
    w = np.where(np.isfinite(v) & (v > 0), 1.0 / v, 1.0)
    lengths = np.array([np.sum(np.max(np.abs(np.diff(seg.q_ref, axis=0)) * w, axis=1)) for seg in path.segments])
    lengths = np.maximum(lengths, 1e-12 * lengths.max(initial=1.0) + 1e-300)
    shares = T * lengths / lengths.sum()
    return Trajectory(tuple(Motion(seg, QuinticLaw(float(Tk))) for seg, Tk in zip(path.segments, shares)))

