"""Numeric inverse kinematics with Pinocchio: damped least squares on the 4-D task (x, y, z, yaw).

A 3-joint arm (a SCARA without a wrist, an R-R-R arm) solves (x, y, z) of its tool point the same way.

It is the independent check of the closed form (:mod:`scara_pin.kinematics.scara`) and the fallback for robots the
closed form refuses. Each iteration solves

    (J^T J + lambda^2 I) dq = J^T e,    e = (p* - p(q), wrap(yaw* - yaw(q))),

with J the task Jacobian from ``pin.computeFrameJacobian`` (LOCAL_WORLD_ALIGNED, expressed in the base
frame), lambda adapted Levenberg-Marquardt style, and q projected into the joint limits after every step
(revolute joints first try the 2 pi-equivalent inside the limits). When a start stalls it restarts from
the mirrored elbow, then from seeded random configurations inside the limits.

The damping follows Nielsen's rule (Madsen, Nielsen, Tingleff, "Methods for non-linear least squares
problems", 2004): after an accepted step lambda^2 is scaled by max(1/3, 1 - (2 rho - 1)^3), rho the ratio
of the actual to the predicted decrease of |e|^2 / 2; after a rejected one it is multiplied by 2, 4, 8, ...
A start stalls when lambda reaches 1e3, or when it keeps sliding along a joint limit (six accepted steps
in a row clipped by the projection, which cut the residual by less than half). A converged start is
polished by undamped Gauss-Newton steps to full precision.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin
from scipy.linalg.lapack import dgesv as _gesv

from ..errors import InvalidInputError, ParameterError

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = ["NumericIKOptions", "NumericIKReason", "NumericIKResult", "elbow_index", "elbow_sign", "solve_numeric"]

_TWO_PI = 2.0 * math.pi
_PI = math.pi
_atan2, _sqrt = math.atan2, math.sqrt
_array = np.array
_fk, _frame = pin.forwardKinematics, pin.updateFramePlacement
_jac, _LWA = pin.computeFrameJacobian, pin.LOCAL_WORLD_ALIGNED
_TASK_ROWS = [0, 1, 2, 5]  # x, y, z and the yaw rate (angular z) of a 6-D Jacobian
_EYE4 = np.eye(4)
_POLISHED = 1e-9
"""[rad, m] a Gauss-Newton step this small ends the polish: the next one would be ~its square."""
_STALL_WINDOW = 6
"""A start that ends its last this-many accepted steps against a joint limit ..."""
_STALL_RATIO = 0.5
"""... having cut the residual by less than this factor over them is stalled: it slides along the limit."""


class NumericIKReason(enum.Enum):
    """How the numeric solver ended."""

    CONVERGED = "converged"
    MAX_ITERATIONS = "max_iterations"  # every start used up its iterations without converging


@dataclass(frozen=True)
class NumericIKOptions:
    """Options of :func:`solve_numeric`.

    Attributes:
        tol: convergence when |e| (position [m] and yaw [rad] together) is below this.
        max_iterations: per start.
        restarts: random restarts after the initial start and its mirrored elbow.
        damping: initial lambda of the damped least squares.
        seed: seed of the random restarts (np.random.default_rng).
    """

    tol: float = 1e-12
    max_iterations: int = 60
    restarts: int = 40
    damping: float = 1e-3
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("tol", "damping"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ParameterError(name, value, "must be a finite number > 0")
        for name in ("max_iterations", "restarts"):
            value = getattr(self, name)
            if not isinstance(value, int) or value < 0 or (name == "max_iterations" and value == 0):
                raise ParameterError(name, value, "must be a whole number (>= 1 for max_iterations)")


@dataclass(frozen=True)
class NumericIKResult:
    """Outcome of the numeric solver; never ``None``.

    Attributes:
        q: the best configuration found (inside the limits).
        success: the residual is below the tolerance.
        iterations: total iterations over all starts.
        residual: |e| at ``q`` (position [m] and yaw [rad]).
        reason: :class:`NumericIKReason`.
        starts: how many starts were used.
    """

    q: np.ndarray
    success: bool
    iterations: int
    residual: float
    reason: NumericIKReason
    starts: int


_DEFAULTS = NumericIKOptions()


def _error(robot: RobotModel, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    pose = robot.tool_pose(q)
    e = target - pose
    e[3] = (e[3] + math.pi) % _TWO_PI - math.pi
    return e


def solve_numeric(
    robot: RobotModel,
    target: ArrayLike,
    q0: ArrayLike | None = None,
    options: NumericIKOptions | None = None,
) -> NumericIKResult:
    """Solve for (x, y, z, yaw) of the tool in the base frame [m, rad] by damped least squares.

    Args:
        robot: the loaded robot.
        target: (x, y, z, yaw).
        q0: the first start (default: the middle of the joint ranges, the elbow turned off the
            stretched/folded singularity to half-way to its upper limit).
        options: :class:`NumericIKOptions`.

    Returns:
        NumericIKResult with the best q found; ``success`` tells whether it reaches the target.
    """
    opts = options or _DEFAULTS
    n = robot.dof
    if n not in (3, 4):
        raise InvalidInputError(f"the numeric IK solves 4 joints (x, y, z, yaw) or 3 (x, y, z); robot {robot.name!r} "
                                f"has {n}")  # fmt: skip
    tgt = np.asarray(target, dtype=float)
    if tgt.shape != (n,) or not np.isfinite(tgt).all():
        what = "4 finite numbers (x, y, z, yaw)" if n == 4 else "3 finite numbers (x, y, z): 3 joints choose no yaw"
        raise ParameterError("target", tgt.tolist(), f"must be {what}")
    lo = np.asarray(robot.limits.lower)
    hi = np.asarray(robot.limits.upper)
    # the actuated joints in q order (mimic joints, nv = 0, follow others and are not in q)
    actuated = [jm for jm in robot.model.joints[1:] if jm.nv > 0]
    revolute = [jm.shortname().startswith("JointModelR") for jm in actuated]
    elbow = elbow_index(robot)
    start = (lo + hi) / 2 if q0 is None else robot.check_q(q0)
    if n == 3:  # a 3-joint arm: the task (x, y, z) padded with a free 4th coordinate (see _Task)
        lo, hi, start, tgt = np.append(lo, -1.0), np.append(hi, 1.0), np.append(start, 0.0), np.append(tgt, 0.0)
        revolute = [*revolute, False]
    if elbow is not None and abs(math.sin(start[elbow])) < 1e-3:
        # a stretched or folded start has a rank-deficient Jacobian: step off the singularity; the
        # default start goes half-way to the upper limit (a well-conditioned elbow: fewer restarts),
        # a given one only by 0.1 rad
        start = start.copy()
        if q0 is None:
            start[elbow] = (start[elbow] + hi[elbow]) / 2
        else:
            start[elbow] += 0.1 if start[elbow] + 0.1 <= hi[elbow] else -0.1
    task = _Task(robot, tgt, lo, hi, revolute, opts)
    rng = None  # the random restarts' generator, made when the first one is needed
    best_q, best_res = task.project(start), math.inf
    total = 0
    starts = 0
    candidates: list[np.ndarray] = [start]
    while candidates or starts < 2 + opts.restarts:
        if candidates:
            q = candidates.pop(0)
        else:
            if rng is None:
                rng = np.random.default_rng(opts.seed)
            q = rng.uniform(lo, hi)
        starts += 1
        q, res, its = task.descend(task.project(q))
        total += its
        if res < best_res:
            best_q, best_res = q, res
        if res <= opts.tol:
            return NumericIKResult(best_q[:n].copy(), True, total, best_res, NumericIKReason.CONVERGED, starts)
        if starts == 1 and elbow is not None:  # next: the mirrored elbow of where this start ended
            mirrored = q.copy()
            mirrored[elbow] = -mirrored[elbow] if abs(mirrored[elbow]) > 1e-3 else (hi[elbow] - lo[elbow]) / 4
            candidates.append(mirrored)
        if starts >= 2 + opts.restarts:
            break
    return NumericIKResult(best_q[:n].copy(), False, total, best_res, NumericIKReason.MAX_ITERATIONS, starts)


ELBOW_PARALLEL = 0.02
"""[rad] two revolute axes within this angle make the shoulder and elbow of an arm (near-parallel included)."""


def elbow_index(robot: RobotModel) -> int | None:
    """The index in q of the elbow, or None when the arm has none.

    The elbow is the second of the first two revolute joints (in q order) with parallel axes at q = 0: a
    SCARA's J2 (J1 and J2 vertical), an articulated or palletizer arm's third joint (after the waist, the
    shoulder and elbow about parallel horizontal axes). Without such a pair, the second revolute joint.
    """
    turning = [a for a in robot.axes if a.kind == "revolute"]
    for k, b in enumerate(turning):
        for a in turning[:k]:
            if float(np.linalg.norm(np.cross(a.axis, b.axis))) <= math.sin(ELBOW_PARALLEL):
                return b.index
    return turning[1].index if len(turning) >= 2 else None


def elbow_sign(robot: RobotModel, q: ArrayLike) -> str:
    """The branch of a numeric solution, for any arm: ``elbow+`` / ``elbow-``, the sign of sin(q_elbow).

    The elbow as :func:`elbow_index` finds it; ``elbow 0`` when it is stretched or folded (|sin| < 1e-12) or
    the arm has no elbow.
    """
    e = elbow_index(robot)
    if e is None:
        return "elbow 0"
    s = math.sin(float(np.asarray(q, dtype=float)[e]))
    return "elbow 0" if abs(s) < 1e-12 else ("elbow+" if s > 0 else "elbow-")


class _Task:
    """One target's damped least squares, on plain floats; Pinocchio only for FK and the Jacobian.

    Works on the robot's private model re-rooted at the base frame (its ``oMf`` are placements in
    ``base``, its LOCAL_WORLD_ALIGNED Jacobians are in base axes), with the tool frame id: no input
    re-validation per iteration (q stays a float64 4-vector inside the limits); the 4 x 4 systems are
    LAPACK's (gesv, through scipy), and the Jacobian and J^T J, J^T e are reused while a rejected step
    leaves q unchanged.
    """

    def __init__(self, robot: RobotModel, target: np.ndarray, lo: np.ndarray, hi: np.ndarray, revolute: list[bool],
                 opts: NumericIKOptions) -> None:  # fmt: skip
        self.robot = robot
        # a 3-joint arm: q and the task carry a 4th coordinate that nothing moves (error 0, Jacobian row and
        # column of the identity, limits [-1, 1]): the 4 x 4 steps solve (x, y, z) and leave it at 0
        self.three = robot.dof == 3
        # continuous joints (Pinocchio's q holds their cos, sin): through the robot's public methods, which
        # convert q; the joint values themselves stay angles, wrapped into [-pi, pi] by the projection
        plain = not getattr(robot, "has_continuous", False) and not self.three
        self.model = getattr(robot, "_base_model", None) if plain else None
        self.data = getattr(robot, "_base_data", None) if plain else None
        self.tool = robot.tool_id
        self.x, self.y, self.z, self.yaw = target.tolist()
        self.target = target
        lo_, hi_ = lo.tolist(), hi.tolist()
        self.joints = list(zip(range(4), lo_, hi_, revolute, strict=True))
        self.box = (lo_[0], hi_[0], lo_[1], hi_[1], lo_[2], hi_[2], lo_[3], hi_[3])
        self.opts = opts

    # ------------------------------------------------------------------ kinematics
    def error(self, q: np.ndarray) -> tuple[list[float], float]:
        """Return e = target - (x, y, z, yaw) at q (yaw wrapped to [-pi, pi)) and |e|."""
        model = self.model
        if self.three:
            p = self.robot.tool_placement(q[:3]).translation
            e = [self.x - p[0], self.y - p[1], self.z - p[2], 0.0]
            return e, math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
        if model is None:  # a Robot without the re-rooted model: its public methods
            e = _error(self.robot, q, self.target).tolist()
            return e, math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3])
        data = self.data
        _fk(model, data, q)
        r0, r1, r2, _ = _frame(model, data, self.tool).homogeneous.tolist()
        ex, ey, ez = self.x - r0[3], self.y - r1[3], self.z - r2[3]
        ew = (self.yaw - _atan2(r1[0], r0[0]) + _PI) % _TWO_PI - _PI
        return [ex, ey, ez, ew], _sqrt(ex * ex + ey * ey + ez * ez + ew * ew)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Return the 4 x 4 task Jacobian (rows x, y, z, yaw) at q, in base axes."""
        if self.three:
            J = np.eye(4)
            J[:3, :3] = np.asarray(self.robot.task_jacobian(q[:3]), dtype=float)[:3]
            return J
        if self.model is None:
            return np.asarray(self.robot.task_jacobian(q), dtype=float)
        return _jac(self.model, self.data, q, self.tool, _LWA).take(_TASK_ROWS, 0)

    def project(self, q: np.ndarray) -> np.ndarray:
        """Into the limits: revolute joints by a 2 pi turn when that lands inside, then clipping."""
        return self.clip(q.tolist())[0]

    def clip(self, v: list[float]) -> tuple[np.ndarray, bool]:
        """:meth:`project` of plain values; also whether a joint was clipped onto a limit."""
        lo0, hi0, lo1, hi1, lo2, hi2, lo3, hi3 = self.box
        a, b, c, d = v
        if lo0 <= a <= hi0 and lo1 <= b <= hi1 and lo2 <= c <= hi2 and lo3 <= d <= hi3:
            return _array(v), False
        clipped = False
        for i, lo, hi, revolute in self.joints:
            x = v[i]
            if x < lo or x > hi:
                if revolute:
                    k = math.ceil((lo - x) / _TWO_PI)
                    if x + k * _TWO_PI <= hi:
                        x += k * _TWO_PI
                if x < lo:
                    x, clipped = lo, True
                elif x > hi:
                    x, clipped = hi, True
                v[i] = x
        return _array(v), clipped

    # ------------------------------------------------------------------ one start
    def descend(self, q: np.ndarray) -> tuple[np.ndarray, float, int]:
        """One damped least-squares descent; returns (q, residual, iterations)."""
        opts = self.opts
        tol = opts.tol
        mu = opts.damping * opts.damping
        nu = 2.0
        error, jacobian, clip = self.error, self.jacobian, self.clip
        e, res = error(q)
        normal: Any = None  # (J, J^T J, J^T e) at the current q
        history = [res]  # residuals after the accepted steps
        limited = 0  # how many of the last accepted steps ended against a joint limit
        for it in range(1, opts.max_iterations + 1):
            if res <= tol:
                return self.polish(q, e, res, it - 1, normal)
            if normal is None:
                J = jacobian(q)
                normal = (J, J.T @ J, J.T @ np.array(e))
            g = normal[2].tolist()
            d0, d1, d2, d3 = _damped_solve(normal[1], mu, normal[2])
            q0, q1, q2, q3 = q.tolist()
            q_new, clipped = clip([q0 + d0, q1 + d1, q2 + d2, q3 + d3])
            e_new, res_new = error(q_new)
            if res_new < res:
                # gain ratio: actual / predicted decrease of |e|^2 / 2 (Nielsen's update of mu)
                pred = 0.5 * (d0 * (mu * d0 + g[0]) + d1 * (mu * d1 + g[1])
                              + d2 * (mu * d2 + g[2]) + d3 * (mu * d3 + g[3]))  # fmt: skip
                rho = 0.5 * (res * res - res_new * res_new) / pred if pred > 0.0 else 1.0
                q, e, res = q_new, e_new, res_new
                normal = None
                mu = max(mu * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3), 1e-24)
                nu = 2.0
                history.append(res)
                limited = limited + 1 if clipped else 0
                if limited >= _STALL_WINDOW and res > _STALL_RATIO * history[-1 - _STALL_WINDOW]:
                    return q, res, it  # sliding along a limit, slowly: another start does better
            else:
                mu = min(mu * nu, 1e6)
                nu *= 2.0
                if mu >= 1e6:  # stalled (a limit or a singularity in the way)
                    return q, res, it
        return q, res, opts.max_iterations

    def polish(self, q: np.ndarray, e: list[float], res: float, its: int, normal: Any) -> tuple[np.ndarray, float, int]:
        """Undamped Gauss-Newton steps while they still reduce the residual (to full precision).

        Near the stretched/folded singularity the joint error is the residual divided by sin(gamma): a
        residual at the tolerance is not yet a joint solution at full precision.
        """
        for _ in range(4):
            if res == 0.0:
                break
            J = normal[0] if normal is not None else self.jacobian(q)
            normal = None
            dq = _solve(J, np.asarray(e))
            if dq is None:
                break
            a, b, c, d = q.tolist()
            q_new = self.clip([a + dq[0], b + dq[1], c + dq[2], d + dq[3]])[0]
            e_new, res_new = self.error(q_new)
            its += 1
            if not res_new < res:
                break
            q, e, res = q_new, e_new, res_new
            if max(abs(dq[0]), abs(dq[1]), abs(dq[2]), abs(dq[3])) <= _POLISHED:
                break  # quadratic convergence: the next step would be below rounding
        return q, res, its


def _damped_solve(G: np.ndarray, l2: float, g: np.ndarray) -> list[float]:
    """Solve (J^T J + l2 I) x = g (J^T J given); no step (zeros, rejected) when it is exactly singular."""
    x = _solve(G + l2 * _EYE4, g)
    return [0.0, 0.0, 0.0, 0.0] if x is None else x


def _solve(A: np.ndarray, b: np.ndarray) -> list[float] | None:
    """Solve the 4 x 4 system A x = b (LAPACK's gesv); ``None`` when A is exactly singular.

    LAPACK through scipy's thin wrapper: the same routine as ``np.linalg.solve``, without its ~3 us of
    Python around a 4 x 4 system (0.6 us here).
    """
    _, _, x, info = _gesv(A, b)
    return None if info != 0 else x.tolist()
