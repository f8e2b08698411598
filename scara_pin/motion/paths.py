"""Geometric paths q(s), s in [0, 1]: joint lines and splines, and straight tool lines (Cartesian).

- :class:`JointLine`: ``q0 + s (q1 - q0)``, the synchronised straight line in joint space;
- :class:`JointSpline`: a C2 cubic spline through joint waypoints (not-a-knot ends);
- :class:`CartesianSegment`: the tool moves on a straight line, yaw linear, the joints given at EVERY
  ``s`` by the closed-form IK (same elbow branch throughout, J4 continuous); :func:`cartesian_path`
  builds one per pair of consecutive poses (via points) and refuses, with a :class:`PathError` giving
  ``s`` and the pose, a line that leaves the workspace, reaches a joint limit or crosses the
  stretched/folded-arm singularity.

Time laws and the :class:`~scara_pin.motion.trajectory.Trajectory` they make live in
:mod:`scara_pin.motion.trajectory`,
which also re-exports these names (the public home of paths and trajectories).
"""

from __future__ import annotations

import abc
import enum
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .._checks import as_limit_vector, as_positive, as_rows, as_vector
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..kinematics.scara_batch import solve_batch
from ..kinematics.scara_geometry import IKStatus, branch_of
from ..limits import MAX_PATH_POINTS, check_count

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = [
    "JUMP_TOL",
    "SINGULAR_TOL",
    "CartesianPath",
    "CartesianSegment",
    "GeometricPath",
    "JointLine",
    "JointSpline",
    "PathError",
    "SegmentedPath",
    "cartesian_path",
    "joint_path",
    "joint_pose",
    "path_segments",
    "third_by_differences",
]

SINGULAR_TOL = 1e-6
"""|sin(elbow angle)| below which a Cartesian line is taken to reach the stretched/folded singularity."""
JUMP_TOL = 0.5 * math.pi
"""[rad] the largest joint change between two dense IK checkpoints of a line (more is a 2 pi wrap)."""
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
        status: enum.IntEnum | None = None,
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



# ---------------------------------------------------------------------------------------------- paths
class GeometricPath(abc.ABC):
    """A joint path ``q(s)``, ``s`` in [0, 1]; also toppra's geometric-path interface (``path(s, order)``)."""

    dof: int = 4

    @abc.abstractmethod
    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:
        """(q, q', q'', q''') at the path parameters ``s`` (1-D array), each (n, 4); up to ``order`` only.

        Every path of this package gives ``order`` 3 (exactly, or by :func:`third_by_differences` where
        it has no closed form); a path of another origin may stop at 2.
        """

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

    def eval(self, s: np.ndarray) -> np.ndarray:
        """q(s) at the path parameters ``s`` (toppra's interface): ``path(s, 0)``."""
        return self(s, 0)

    def evald(self, s: np.ndarray) -> np.ndarray:
        """dq/ds at ``s`` (toppra's interface): ``path(s, 1)``."""
        return self(s, 1)

    def evaldd(self, s: np.ndarray) -> np.ndarray:
        """d2q/ds2 at ``s`` (toppra's interface): ``path(s, 2)``."""
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
        object.__setattr__(self, "q0", as_vector("q0", self.q0, None))
        object.__setattr__(self, "q1", as_vector("q1", self.q1, len(self.q0)))

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:  # noqa: D102
        s = np.asarray(s, dtype=float).reshape(-1, 1)
        dq = self.q1 - self.q0
        zero = np.zeros((s.shape[0], len(dq)))
        out = [self.q0 + s * dq, np.broadcast_to(dq, (s.shape[0], len(dq))).copy(), zero, zero.copy()]
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

        W = as_rows("waypoints", self.waypoints)
        w = as_limit_vector("weight", self.weights, "")
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
        s = np.asarray(s, dtype=float).ravel()
        return tuple(self._spline(s, nu) for nu in range(order + 1))


def joint_path(robot: RobotModel, waypoints: Sequence[ArrayLike] | np.ndarray) -> JointLine | JointSpline:
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
    W = as_rows("waypoints", waypoints)
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


def path_segments(
    robot: RobotModel,
    path: GeometricPath | CartesianPath | Sequence[GeometricPath | CartesianPath] | Sequence[ArrayLike] | np.ndarray,
) -> tuple[GeometricPath, ...]:
    """The paths a timing takes one by one, each rest to rest.

    A Cartesian path's segments (the tool stops where the line turns), a path itself, a sequence of those
    (one after the other), or the joint path through (m, 4) waypoints (:func:`joint_path`).
    """
    if isinstance(path, CartesianPath):
        return path.segments
    if isinstance(path, GeometricPath):
        return (path,)
    if isinstance(path, Sequence) and path and all(isinstance(p, (GeometricPath, CartesianPath)) for p in path):
        return tuple(seg for p in path for seg in path_segments(robot, p))  # type: ignore[arg-type]
    return (joint_path(robot, path),)  # type: ignore[arg-type]


def _check_joint_limits(robot: RobotModel, path: GeometricPath, n: int = 2001) -> None:
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


def _singular(J: np.ndarray) -> bool:
    """True when np.linalg.solve refuses J (exactly singular in LAPACK's LU)."""
    try:
        np.linalg.solve(J, np.zeros(J.shape[0]))
    except np.linalg.LinAlgError:
        return True
    return False


_FD_STEP = 1e-4
"""Finite-difference step of q''' relative to the width of the smooth piece of the path."""


def third_by_differences(path: GeometricPath, s: np.ndarray) -> np.ndarray:
    """q'''(s), (n, dof), by finite differences of the exact q'' (a path without a closed form of q''').

    The differences are central, of step h = 1e-4 of the width of the smooth piece (between knots);
    second-order one-sided within h of a knot, so a difference never straddles a knot.
    """
    s = np.asarray(s, dtype=float).ravel()
    knots = np.unique(np.clip(path.knots(), 0.0, 1.0))
    i = np.clip(np.searchsorted(knots, s, side="right") - 1, 0, len(knots) - 2)
    lo, hi = knots[i], knots[i + 1]
    h = _FD_STEP * (hi - lo)
    left = s - h < lo
    right = s + h > hi
    # offsets (in units of h) of the three points: centred (-1, 0, 1), forward (0, 1, 2), backward (-2, -1, 0)
    base = np.where(left, s, np.where(right, s - 2 * h, s - h))
    n = len(s)
    d2 = path.evaluate(np.concatenate([base, base + h, base + 2 * h]), 2)[2]
    f0, f1, f2 = d2[:n], d2[n : 2 * n], d2[2 * n :]
    central = (f2 - f0) / 2.0
    forward = (-3.0 * f0 + 4.0 * f1 - f2) / 2.0
    backward = (f0 - 4.0 * f1 + 3.0 * f2) / 2.0
    out = np.where(left[:, None], forward, np.where(right[:, None], backward, central))
    return out / h[:, None]


class _Kinematics:
    """Task Jacobian J = d(x, y, z, yaw)/dq and its derivative along a direction, on private Pinocchio data.

    :meth:`derivatives` gives the exact q', q'', q''' along a tool curve (CasADi, built on first use).
    """

    def __init__(self, robot: RobotModel) -> None:
        self.model = robot.model
        self.data = robot.model.createData()
        self.tool_id = robot.tool_id
        # continuous joints: Pinocchio takes their (cos, sin); v stays the 4 joint rates
        self.to_pin = robot.to_pinocchio_q if getattr(robot, "has_continuous", False) else None
        pin.framesForwardKinematics(self.model, self.data, pin.neutral(self.model))
        self.Rbo = self.data.oMf[robot.base_id].rotation.T.copy()  # base axes from world axes
        self.robot = robot
        self._derivatives: Any = None

    @property
    def exact_derivatives(self) -> bool:
        """True when :meth:`derivatives` applies: 4 joints, every axis exactly vertical (yaw linear in q)."""
        geo = self.robot.kinematics.geometry
        return self.robot.dof == 4 and geo.tilt == 0.0 and geo.wrist_tilt == 0.0

    def derivatives(self, q: np.ndarray, p1: np.ndarray, p2: np.ndarray, p3: np.ndarray) -> tuple[np.ndarray, ...]:
        """(q', q'', q''') (n, 4) where the pose x(q) = (p(q), yaw(q)) follows a curve with derivatives p1, p2, p3.

        Differentiating x(q(s)) = pose(s) three times (J = dx/dq; D2, D3 the second and third directional
        derivatives of x; the yaw, yaw0 plus the signed revolute angles, is linear in q):

            J q' = p1,   J q'' = p2 - D2[q', q'],   J q''' = p3 - 3 D2[q', q''] - D3[q', q', q'],

        p(q) the tool position of :func:`~scara_pin.symbolic.symbolic_model` (the Pinocchio model
        in CasADi: exact derivatives), all the points in one call. Only when :attr:`exact_derivatives`.
        """
        if self._derivatives is None:
            self._derivatives = self._build_derivatives()
        out = self._derivatives(q.T, p1.T, p2.T, p3.T)
        return tuple(np.asarray(v, dtype=float).reshape(4, len(q)).T for v in out)

    def _build_derivatives(self) -> Any:
        import casadi as ca

        from ..symbolic import symbolic_model

        geo = self.robot.kinematics.geometry
        q, a, b = ca.SX.sym("q", 4), ca.SX.sym("a", 4), ca.SX.sym("b", 4)
        p = symbolic_model(self.robot).tool_position(q)
        yaw_row = np.zeros(4)
        for i in geo.revolute:
            yaw_row[i] = geo.signs[i]
        J = ca.vertcat(ca.jacobian(p, q), ca.DM(yaw_row).T)
        # D2, D3 as functions of independent directions (q' depends on q: it must not be differentiated)
        d2 = ca.Function("d2", [q, a, b], [ca.vertcat(ca.jtimes(ca.jtimes(p, q, a), q, b), 0)])
        d3 = ca.Function("d3", [q, a], [ca.vertcat(ca.jtimes(ca.jtimes(ca.jtimes(p, q, a), q, a), q, a), 0)])
        p1, p2, p3 = ca.SX.sym("p1", 4), ca.SX.sym("p2", 4), ca.SX.sym("p3", 4)
        Jinv = ca.inv(J)  # one factorisation for the three solves
        q1 = Jinv @ p1
        q2 = Jinv @ (p2 - d2(q, q1, q1))
        q3 = Jinv @ (p3 - 3 * d2(q, q1, q2) - d3(q, q1))
        return ca.Function("path_derivatives", [q, p1, p2, p3], [q1, q2, q3])

    def _task(self, J6: np.ndarray) -> np.ndarray:
        out = np.empty((4, J6.shape[1]))
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

    robot: RobotModel
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

    def pose_derivatives(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(pose', pose'') at s, each (n, 4): the constant ``delta`` and zero on a line."""
        n = np.asarray(s).size
        return np.broadcast_to(self.delta, (n, 4)), np.zeros((n, 4))

    def pose_third_derivative(self, s: np.ndarray) -> np.ndarray:
        """The third derivative of the pose at s, (n, 4): zero on a line."""
        return np.zeros((np.asarray(s).size, 4))

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:
        """(q, q', q'', q''') at s: ``q' = J^-1 pose'``, ``q'' = J^-1 (pose'' - (dJ/ds) q')`` (J the task Jacobian).

        All the derivatives at once (exact, CasADi); on a robot whose
        axes are not exactly vertical, q' and q'' by Pinocchio's Jacobian and its time variation and q''' by
        :func:`third_by_differences`.
        """
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        idx = np.clip(np.searchsorted(self.s_ref, s, side="right") - 1, 0, len(self.s_ref) - 1)
        res = solve_batch(self.robot.kinematics.geometry, self.poses(s), branch=self.branch, reference=self.q_ref[idx])
        if (res.status != 0).any():  # cannot happen on a checked segment
            k = int(np.argmax(res.status != 0))
            raise PathError(f"no IK solution ({IKStatus(int(res.status[k])).name})", s=s[k], pose=self.poses(s[k])[0],
                            status=IKStatus(int(res.status[k])))  # fmt: skip
        q = res.q
        if order == 0:
            return (q,)
        if self._kin.exact_derivatives:
            p1, p2 = self.pose_derivatives(s)
            d = self._kin.derivatives(q, np.asarray(p1, dtype=float), np.asarray(p2, dtype=float),
                                      self.pose_third_derivative(s))  # fmt: skip
            bad = ~np.isfinite(np.hstack(d)).all(axis=1)
            if bad.any():
                k = int(np.argmax(bad))
                raise PathError("the task Jacobian is singular (stretched or folded arm)", s=s[k],
                                pose=self.poses(s[k])[0], q=q[k])  # fmt: skip
            return (q, *d)[: order + 1]
        if order >= 3:
            return (*self.evaluate(s, 2), third_by_differences(self, s))
        n = len(s)
        d1, d2 = self.pose_derivatives(s)
        J = np.empty((n, 4, 4))
        for k in range(n):
            J[k] = self._kin.jacobian(q[k])
        # one stacked solve per order: LAPACK's gesv on each matrix, as n separate calls would do, without
        # numpy's per-call overhead (that overhead was most of the time of a timed Cartesian path)
        try:
            dq = np.linalg.solve(J, d1[:, :, None])[:, :, 0]
            if order < 2:
                return (q, dq)
            rhs = np.empty((n, 4))
            for k in range(n):
                rhs[k] = d2[k] - self._kin.jacobian_rate(q[k], dq[k]) @ dq[k]
            ddq = np.linalg.solve(J, rhs[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            k = next(k for k in range(n) if _singular(J[k]))
            raise PathError("the task Jacobian is singular (stretched or folded arm)", s=s[k],
                            pose=self.poses(s[k])[0], q=q[k]) from None  # fmt: skip
        return (q, dq, ddq)


class SegmentedPath:
    """A path made of ``segments`` (each a :class:`CartesianSegment`): its configurations at both ends."""

    segments: tuple[CartesianSegment, ...]

    @property
    def q_start(self) -> np.ndarray:
        """The configuration at the start."""
        return self.segments[0].q_ref[0].copy()

    @property
    def q_end(self) -> np.ndarray:
        """The configuration at the end."""
        return self.segments[-1].q_ref[-1].copy()


@dataclass(frozen=True, eq=False)
class CartesianPath(SegmentedPath):
    """Straight tool lines through poses (via points), one :class:`CartesianSegment` per pair, one branch.

    Attributes:
        robot: the robot.
        poses: (m, 4) poses [m, rad], m >= 2.
        branch: the elbow branch of every configuration on the path.
        segments: the m - 1 segments.
        checkpoints: per segment, (s, q) at the requested points (n points or the maximum step).
    """

    robot: RobotModel
    poses: np.ndarray
    branch: str
    segments: tuple[CartesianSegment, ...]
    checkpoints: tuple[tuple[np.ndarray, np.ndarray], ...]


def joint_pose(robot: RobotModel, q: ArrayLike) -> np.ndarray:
    """The tool pose (x, y, z, yaw) at q with the yaw UNWRAPPED as the joints turn.

    The yaw is the kind's unwrapped yaw (``geometry.yaw_of``: a SCARA's yaw0 plus its signed revolute angles, a
    palletizer's waist plus flange), equal to FK's yaw modulo 2 pi. A line between two such poses turns the tool
    the way the joints go (through +/-pi if they do), so
    ``cartesian_path(robot, [joint_pose(robot, qa), joint_pose(robot, qb)], start=qa, end=qb)`` ends at qb
    whenever the line stays feasible.
    """
    q = robot.check_q(q)
    pose = robot.tool_pose(q)
    turned = robot.kinematics.geometry.yaw_of(q)
    pose[3] += 2.0 * math.pi * round((turned - pose[3]) / (2.0 * math.pi))
    return pose


def _elbow_sin(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    """sin(gamma) of configurations (n, 4): > 0 on the right branch, < 0 on the left, 0 when singular."""
    geo = robot.kinematics.geometry
    return np.sin(geo.elbow_angle(q[..., geo.revolute[1]]))


def cartesian_path(
    robot: RobotModel,
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
    P = as_rows("poses", poses)
    if branch is not None and branch not in ("right", "left"):
        raise InvalidInputError(f"branch {branch!r} must be 'right' or 'left'")
    if n is not None and (max_step is not None or max_yaw_step is not None):
        raise InvalidInputError("give either n (points per segment) or max_step/max_yaw_step, not both")
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2):
        raise ParameterError("n", n, "must be an integer >= 2 (points per segment, ends included)")
    step = as_positive("max_step", _DEFAULT_STEP if max_step is None else max_step, "m")
    yaw_step = as_positive("max_yaw_step", _DEFAULT_YAW_STEP if max_yaw_step is None else max_yaw_step, "rad")
    geo = robot.kinematics.geometry
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
        mid = np.array([0.5 * (lo + hi) if math.isfinite(lo + hi) else 0.0 for lo, hi in zip(geo.lower, geo.upper)])
        res = robot.ik(P[0], branch=branch, reference=mid)
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
        check_count(f"path points of segment {k + 1} ({np.linalg.norm(d[:3]):.6g} m, {abs(d[3]):.6g} rad)", m + 1,
                    MAX_PATH_POINTS, "a shorter move or a smaller yaw change")  # fmt: skip
        line = _Line(a, d)
        s_pts, q_pts, s_ref, q_ref = follow_curve(robot, branch, line, seg_start, m, k)
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


PoseCurve = Callable[[np.ndarray], np.ndarray]
"""A tool-pose curve: (n, 4) poses (x, y, z, yaw) at n parameters s in [0, 1]."""


@dataclass(frozen=True)
class _Line:
    """The pose curve ``a + s d`` (a straight tool line, yaw linear)."""

    a: np.ndarray
    d: np.ndarray

    def __call__(self, s: np.ndarray) -> np.ndarray:
        return self.a + np.asarray(s, dtype=float).reshape(-1, 1) * self.d

    @property
    def extent(self) -> tuple[float, float]:
        """(position length [m], |yaw change| [rad])."""
        return float(np.linalg.norm(self.d[:3])), abs(float(self.d[3]))


def follow_curve(
    robot: RobotModel, branch: str, curve: PoseCurve, q_start: np.ndarray, m: int, segment: int = 0,
    extent: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Follow a tool-pose curve with the closed-form IK on one branch, continuously; checked densely.

    The curve is solved at ``m + 1`` equally spaced checkpoints (each the branch solution nearest the
    previous one), then between them on the fine grid of :func:`cartesian_path` (0.5 mm, 0.01 rad).

    Args:
        robot: the robot.
        branch: ``"right"`` or ``"left"``.
        curve: the poses at parameters in [0, 1] (``curve.extent``, or ``extent``, gives its position
            length [m] and yaw change [rad], for the fine grid; a bound is enough).
        q_start: the configuration at ``curve(0)``.
        m: checkpoint intervals (>= 1).
        segment: index of the segment (error messages).
        extent: (length [m], yaw change [rad]) when ``curve`` has no ``extent``.

    Returns:
        (s_pts, q_pts) the checkpoints and (s_ref, q_ref) the dense checked solutions.

    Raises:
        PathError: the curve leaves the workspace or the joint limits, reaches the singularity, or makes a
            joint jump; with ``s`` and the pose.
    """
    ext = extent if extent is not None else curve.extent  # type: ignore[attr-defined]
    s_pts = np.linspace(0.0, 1.0, m + 1)
    q_pts = np.empty((m + 1, 4))
    _check_start(robot, curve(np.zeros(1))[0], q_start, segment)
    q_pts[0] = q_start
    for j in range(1, m + 1):
        q_pts[j] = _checkpoint(robot, branch, curve, segment, s_pts[j - 1], s_pts[j], q_pts[j - 1])
    s_ref, q_ref = _dense_check(robot, branch, curve, ext, segment, s_pts, q_pts)
    return s_pts, q_pts, s_ref, q_ref


def _at(curve: PoseCurve, s: float) -> np.ndarray:
    return curve(np.array([s]))[0]


def _ik_step(
    robot: RobotModel, branch: str, pose: np.ndarray, q_prev: np.ndarray
) -> tuple[np.ndarray | None, str, enum.IntEnum | None]:
    """The branch solution at ``pose`` nearest ``q_prev``, or None with the reason and the IK status."""
    res = robot.ik(pose, branch=branch, reference=q_prev)
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


def _jump(robot: RobotModel, q: np.ndarray, q_prev: np.ndarray) -> str:
    """Why q does not follow q_prev continuously, or '' if it does."""
    dq = np.abs(q - q_prev)
    j = int(np.argmax(dq))
    if dq[j] <= JUMP_TOL:
        return ""
    name = robot.joint_names[j]
    turns = dq[j] / (2 * math.pi)
    if robot.joint_kinds[j] == "angle" and abs(turns - round(turns)) < 0.05:
        return (f"{name} would jump by {round(turns)} turn(s), from {q_prev[j]:.9g} to {q[j]:.9g} rad: it reaches "
                "its limit and the line cannot continue on this turn")  # fmt: skip
    return f"{name} would jump from {q_prev[j]:.9g} to {q[j]:.9g}: the arm passes through the singularity"


def _check_start(robot: RobotModel, pose: np.ndarray, q: np.ndarray, segment: int) -> None:
    """Refuse a singular configuration at a segment's start."""
    if abs(float(_elbow_sin(robot, q))) < SINGULAR_TOL:
        raise PathError("the arm is at the stretched/folded singularity (sin(elbow) = 0): a straight line from "
                        "here needs infinite joint speed", s=0.0, segment=segment, pose=pose, q=q)  # fmt: skip


def _checkpoint(
    robot: RobotModel, branch: str, curve: PoseCurve, segment: int, s0: float, s1: float, q0: np.ndarray
) -> np.ndarray:
    """IK at s1 continuing q0 (at s0); on failure, locate it by bisection and raise :class:`PathError`."""
    q, _, _ = _ik_step(robot, branch, _at(curve, s1), q0)
    if q is not None and not _jump(robot, q, q0):
        return q
    _fail(robot, branch, curve, segment, s0, s1, q0)
    raise AssertionError("unreachable")  # pragma: no cover


def _fail(
    robot: RobotModel,
    branch: str,
    curve: PoseCurve,
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
        q, _, _ = _ik_step(robot, branch, _at(curve, mid), q_good)
        if q is not None and not _jump(robot, q, q_good):
            s_good, q_good = mid, q
        else:
            s_bad = mid
    q, reason, status = _ik_step(robot, branch, _at(curve, s_bad), q_good)
    if q is not None:
        reason = _jump(robot, q, q_good) or "the solution changes discontinuously"
    raise PathError(reason, s=s_bad, segment=segment, pose=_at(curve, s_bad), q=q_good, status=status)


def _dense_check(
    robot: RobotModel,
    branch: str,
    curve: PoseCurve,
    extent: tuple[float, float],
    segment: int,
    s_pts: np.ndarray,
    q_pts: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Solve the curve on a fine grid between checkpoints (vectorised); return it as the IK reference."""
    m = len(s_pts) - 1
    ds = 1.0 / m
    sub = max(4, math.ceil(extent[0] * ds / _DENSE_STEP), math.ceil(extent[1] * ds / _DENSE_YAW_STEP))
    geo = robot.kinematics.geometry
    sign = 1.0 if branch == "right" else -1.0
    q_prev = q_pts[:-1]
    rows = [q_pts[:-1]]
    for k in range(1, sub + 1):
        s = s_pts[:-1] + (s_pts[1:] - s_pts[:-1]) * (k / sub)
        res = solve_batch(geo, curve(s), branch=branch, reference=q_prev)
        q = np.where((res.status != 0)[:, None], np.nan, res.q)
        if k == sub:
            q = np.where(np.isnan(q), np.nan, q_pts[1:])  # the checkpoints themselves (same solutions)
        ok = (res.status == 0) & (sign * _elbow_sin(robot, q) >= SINGULAR_TOL)
        ok &= np.abs(q - q_prev).max(axis=1) <= JUMP_TOL
        if not ok.all():
            j = int(np.argmax(~ok))
            s_lo = s_pts[j] + (s_pts[j + 1] - s_pts[j]) * ((k - 1) / sub)
            _fail(robot, branch, curve, segment, float(s_lo), float(s[j]), q_prev[j])
        rows.append(q)
        q_prev = q
    # interleave: interval j contributes its sub-points in order
    Q = np.stack(rows, axis=1)  # (m, sub + 1, 4); [:, sub] is the next checkpoint
    S = s_pts[:-1, None] + (s_pts[1:] - s_pts[:-1])[:, None] * (np.arange(sub + 1) / sub)[None, :]
    s_ref = np.concatenate([S[:, :-1].ravel(), [1.0]])
    q_ref = np.concatenate([Q[:, :-1].reshape(-1, 4), q_pts[-1:]])
    return s_ref, q_ref
