"""Numeric inverse kinematics with Pinocchio: damped least squares on the 4-D task (x, y, z, yaw).

It is the independent check of the closed form (:mod:`scara_pin.ik`) and the fallback for robots the
closed form refuses. Each iteration solves

    (J^T J + lambda^2 I) dq = J^T e,    e = (p* - p(q), wrap(yaw* - yaw(q))),

with J the task Jacobian from ``pin.computeFrameJacobian`` (LOCAL_WORLD_ALIGNED, expressed in the base
frame), lambda adapted Levenberg-Marquardt style, and q projected into the joint limits after every step
(revolute joints first try the 2 pi-equivalent inside the limits). When a start stalls it restarts from
the mirrored elbow, then from seeded random configurations inside the limits.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .errors import ParameterError

if TYPE_CHECKING:
    from .model import Robot

__all__ = ["NumericIKOptions", "NumericIKReason", "NumericIKResult", "solve_numeric"]

_TWO_PI = 2.0 * math.pi


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
    restarts: int = 20
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


def _error(robot: Robot, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    pose = robot.tool_pose(q)
    e = target - pose
    e[3] = (e[3] + math.pi) % _TWO_PI - math.pi
    return e


def _project(q: np.ndarray, lo: np.ndarray, hi: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """Into the limits: revolute joints by a 2 pi turn when that lands inside, then clipping."""
    out = q.copy()
    for i in np.flatnonzero(revolute):
        if out[i] < lo[i] or out[i] > hi[i]:
            k = math.ceil((lo[i] - out[i]) / _TWO_PI)
            if out[i] + k * _TWO_PI <= hi[i]:
                out[i] += k * _TWO_PI
    return np.clip(out, lo, hi)


def solve_numeric(
    robot: Robot,
    target: Sequence[float],
    q0: Sequence[float] | None = None,
    options: NumericIKOptions | None = None,
) -> NumericIKResult:
    """Solve for (x, y, z, yaw) of the tool in the base frame [m, rad] by damped least squares.

    Args:
        robot: the loaded robot.
        target: (x, y, z, yaw).
        q0: the first start (default: the middle of the joint ranges).
        options: :class:`NumericIKOptions`.

    Returns:
        NumericIKResult with the best q found; ``success`` tells whether it reaches the target.
    """
    opts = options or NumericIKOptions()
    tgt = np.asarray(target, dtype=float)
    if tgt.shape != (4,) or not np.isfinite(tgt).all():
        raise ParameterError("target", tgt.tolist(), "must be 4 finite numbers (x, y, z, yaw)")
    lo = np.asarray(robot.limits.lower)
    hi = np.asarray(robot.limits.upper)
    revolute = np.array([robot.model.joints[j].shortname().startswith("JointModelR") for j in range(1, 5)])
    elbow = int(np.flatnonzero(revolute)[1]) if revolute.sum() >= 2 else None
    start = (lo + hi) / 2 if q0 is None else robot.check_q(q0)
    if elbow is not None and abs(math.sin(start[elbow])) < 1e-3:
        # a stretched or folded start has a rank-deficient Jacobian: step off the singularity
        start = start.copy()
        start[elbow] += 0.1 if start[elbow] + 0.1 <= hi[elbow] else -0.1
    rng = np.random.default_rng(opts.seed)
    best_q, best_res = _project(start, lo, hi, revolute), math.inf
    total = 0
    starts = 0
    candidates: list[np.ndarray] = [start]
    while candidates or starts < 2 + opts.restarts:
        if candidates:
            q = candidates.pop(0)
        else:
            q = rng.uniform(lo, hi)
        starts += 1
        q, res, its = _descend(robot, _project(q, lo, hi, revolute), tgt, lo, hi, revolute, opts)
        total += its
        if res < best_res:
            best_q, best_res = q, res
        if res <= opts.tol:
            return NumericIKResult(best_q, True, total, best_res, NumericIKReason.CONVERGED, starts)
        if starts == 1 and elbow is not None:  # next: the mirrored elbow of where this start ended
            mirrored = q.copy()
            mirrored[elbow] = -mirrored[elbow] if abs(mirrored[elbow]) > 1e-3 else (hi[elbow] - lo[elbow]) / 4
            candidates.append(mirrored)
        if starts >= 2 + opts.restarts:
            break
    return NumericIKResult(best_q, False, total, best_res, NumericIKReason.MAX_ITERATIONS, starts)


def _descend(
    robot: Robot,
    q: np.ndarray,
    target: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    revolute: np.ndarray,
    opts: NumericIKOptions,
) -> tuple[np.ndarray, float, int]:
    """One damped least-squares descent; returns (q, residual, iterations)."""
    lam = opts.damping
    e = _error(robot, q, target)
    res = float(np.linalg.norm(e))
    eye = np.eye(4)
    for it in range(1, opts.max_iterations + 1):
        if res <= opts.tol:
            return _polish(robot, q, e, res, target, lo, hi, revolute, it - 1)
        J = robot.task_jacobian(q)
        JtJ = J.T @ J
        dq = np.linalg.solve(JtJ + lam * lam * eye, J.T @ e)
        q_new = _project(q + dq, lo, hi, revolute)
        e_new = _error(robot, q_new, target)
        res_new = float(np.linalg.norm(e_new))
        if res_new < res:
            q, e, res = q_new, e_new, res_new
            lam = max(lam / 10.0, 1e-12)
        else:
            lam = min(lam * 10.0, 1e3)
            if lam >= 1e3:  # stalled (a limit or a singularity in the way)
                return q, res, it
    return q, res, opts.max_iterations


def _polish(
    robot: Robot,
    q: np.ndarray,
    e: np.ndarray,
    res: float,
    target: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    revolute: np.ndarray,
    its: int,
) -> tuple[np.ndarray, float, int]:
    """Undamped Gauss-Newton steps while they still reduce the residual (to full precision).

    Near the stretched/folded singularity the joint error is the residual divided by sin(gamma): a
    residual at the tolerance is not yet a joint solution at full precision.
    """
    for _ in range(4):
        if res == 0.0:
            break
        J = robot.task_jacobian(q)
        try:
            dq = np.linalg.solve(J, e)
        except np.linalg.LinAlgError:
            break
        q_new = _project(q + dq, lo, hi, revolute)
        e_new = _error(robot, q_new, target)
        res_new = float(np.linalg.norm(e_new))
        its += 1
        if not res_new < res:
            break
        q, e, res = q_new, e_new, res_new
    return q, res, its
