"""Identify a robot's errors from measured poses: nonlinear least squares on Pinocchio's forward kinematics.

The problem: the residuals ``f(theta) - m`` of every measured pose (positions [m]; the
yaw [rad], wrapped to (-pi, pi], times ``yaw_weight`` [m/rad]), ``f`` the chain's prediction
(:meth:`ChainModel.predict <scara_pin.calibration.chain.ChainModel.predict>`) with its analytic Jacobian.

The steps of :func:`calibrate`:

1. the error model of the robot's chain; in the device frame, the device's nominal placement is the rigid
   alignment (:func:`~scara_pin.calibration.chain.kabsch`) of the nominal predictions with the measurements;
2. the structural count: how many errors a rich set of poses separates (:func:`identify` on random poses
   inside the limits); fewer measured poses than that is refused;
3. the identifiable errors of these poses (:func:`identify` at the nominal model: first-order
   identifiability), fitted by scipy's ``least_squares`` (trust-region reflective, analytic Jacobian), the
   others fixed at zero. An error without first-order effect (J4's tilt when the target is on J4's axis)
   is fixed even if the errors of the real robot give it a second-order one: it is never fitted to noise;
4. with a robust loss: the rows whose position error exceeds ``outlier_sigmas`` robust standard deviations
   (1.4826 times the median absolute coordinate residual) are outliers, listed and left out of a final
   linear fit;
5. the covariance ``sigma^2 (J^T J)^-1`` of the identified errors, ``sigma^2`` the residual sum of squares over
   the redundancy (rows x coordinates minus identified errors);
6. a k-fold cross-validation: each fold's rows predicted by a fit (from the nominal model) on the others;
7. the calibrated URDF (:mod:`scara_pin.calibration.urdf_edit`), loaded back and checked against the fit's
   predictions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError, ParameterError
from ..kinematics.planar2r import wrap
from ..model import Robot
from .chain import ALL_GROUPS, ChainModel, Group, MeasurementFrame, kabsch
from .identify import IDENTIFY_TOL, Identifiability, identify
from .measurements import Measurements
from .results import (
    CalibrationResult,
    CrossValidation,
    Loss,
    Outlier,
    ParameterEstimate,
    ParameterStatus,
    ResidualStats,
)
from .urdf_edit import edit_origins

__all__ = ["CalibrationOptions", "calibrate", "structural_count"]

FIT_TOL = 1e-15
"""``least_squares``' ftol, xtol and gtol: the fit runs to working precision (noise-free data are met to 1e-12 m)."""
MAX_NFEV = 200
"""The most model evaluations of one fit."""
OUTLIER_FLOOR = 1e-9
"""[m] a position error below this is never an outlier (noise-free data)."""
URDF_CHECK_TOL = 1e-9
"""[m] the calibrated URDF, loaded back, must reproduce the fit's predictions to this (else: a bug)."""
STRUCTURAL_POSES = 60
"""The fewest random poses the structural count is computed on (at least 3 per candidate error)."""


@dataclass(frozen=True)
class CalibrationOptions:
    """How to calibrate.

    Attributes:
        groups: the error groups fitted (:class:`~scara_pin.calibration.chain.Group`; ``device`` follows
            from ``frame``).
        frame: the frame the positions are measured in.
        loss: the fit's loss; a robust one (soft_l1, huber, cauchy, arctan) finds and leaves out outliers.
        f_scale: the robust loss's inlier scale [m] (residuals well below it count as with the linear loss).
        outlier_sigmas: a row whose position error exceeds this many robust standard deviations is an outlier.
        yaw_weight: [m/rad] the weight of a yaw residual against a position one (the ratio of the position's
            measurement noise to the yaw's).
        folds: the cross-validation's folds (0: none).
        seed: the seed of the random poses of the structural count and of the folds' rows.
        tol: the identification's tolerance (:data:`~scara_pin.calibration.identify.IDENTIFY_TOL`).
    """

    groups: frozenset[Group] = ALL_GROUPS
    frame: MeasurementFrame = MeasurementFrame.BASE
    loss: Loss = Loss.LINEAR
    f_scale: float = 1e-4
    outlier_sigmas: float = 5.0
    yaw_weight: float = 0.1
    folds: int = 5
    seed: int = 0
    tol: float = IDENTIFY_TOL

    def __post_init__(self) -> None:
        object.__setattr__(self, "groups", frozenset(self.groups) - {Group.DEVICE})
        if not self.groups and self.frame is MeasurementFrame.BASE:
            raise ParameterError("groups", "none", "must name at least one error group")
        for name in ("f_scale", "outlier_sigmas", "yaw_weight"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ParameterError(name, v, "must be a finite number > 0")
        if not isinstance(self.folds, int) or self.folds < 0 or self.folds == 1 or self.folds > 100:
            raise ParameterError("folds", self.folds, "must be 0 (no cross-validation) or 2 .. 100")
        if not (math.isfinite(self.tol) and 0 < self.tol < 1):
            raise ParameterError("tol", self.tol, "must be within (0, 1)")


@dataclass(eq=False)
class _Problem:
    """The residuals and their Jacobian for a chain and a set of measured rows."""

    chain: ChainModel
    measurements: Measurements
    device0: pin.SE3
    yaw_weight: float
    qpin: np.ndarray = field(init=False)
    target: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.qpin = self.chain.pinocchio_q(self.measurements.q)
        self.target = self.measurements.values()

    def residuals(self, theta: np.ndarray, jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """(n, k) residuals (model minus measurement, yaw wrapped, unweighted) and the weighted Jacobian."""
        out, J = self.chain.predict(theta, self.qpin, self.device0, jacobian=jacobian)
        r = out - self.target
        if self.chain.yaw:
            r[:, 3] = wrap(r[:, 3])  # type: ignore[arg-type]
            if J is not None:
                J = J.copy()
                J[3::4] *= self.yaw_weight
        return r, J

    def weighted(self, r: np.ndarray) -> np.ndarray:
        """The residual vector the fit minimises (the yaw times ``yaw_weight``)."""
        if self.chain.yaw:
            r = r.copy()
            r[:, 3] *= self.yaw_weight
        return r.ravel()

    def subset(self, rows: np.ndarray) -> _Problem:
        return _Problem(self.chain, self.measurements.subset(rows), self.device0, self.yaw_weight)


def _fit(problem: _Problem, kept: tuple[int, ...], theta0: np.ndarray, loss: Loss,
         f_scale: float) -> tuple[np.ndarray, int]:  # fmt: skip
    """The errors ``kept`` fitted from ``theta0`` (the others kept at their ``theta0`` value)."""
    from scipy.optimize import least_squares

    idx = np.array(kept, dtype=int)
    cache: dict[str, np.ndarray] = {}

    def full(x: np.ndarray) -> np.ndarray:
        theta = theta0.copy()
        theta[idx] = x
        return theta

    def fun(x: np.ndarray) -> np.ndarray:
        r, J = problem.residuals(full(x))
        cache["x"], cache["J"] = x.copy(), J[:, idx]  # type: ignore[index]
        return problem.weighted(r)

    def jac(x: np.ndarray) -> np.ndarray:
        if "x" not in cache or not np.array_equal(cache["x"], x):
            fun(x)
        return cache["J"]

    if len(idx) == 0:
        return theta0.copy(), 0
    # f_scale is in metres: the weighted residuals are metres too
    sol = least_squares(fun, theta0[idx], jac=jac, method="trf", loss=loss.value, f_scale=f_scale, x_scale="jac",
                        ftol=FIT_TOL, xtol=FIT_TOL, gtol=FIT_TOL, max_nfev=MAX_NFEV)  # fmt: skip
    return full(sol.x), int(sol.nfev)


def _identify_at(problem: _Problem, theta: np.ndarray, tol: float) -> tuple[Identifiability, list[int]]:
    """The identifiability at ``theta`` (errors in the model's order of preference), and that order."""
    _, J = problem.residuals(theta)
    order = list(range(problem.chain.size))
    return identify(J, tol), order  # type: ignore[arg-type]


def _fit_identified(problem: _Problem, theta0: np.ndarray, loss: Loss, f_scale: float,
                    tol: float) -> tuple[np.ndarray, tuple[int, ...], int]:  # fmt: skip
    """The errors these poses separate at the nominal model, fitted from ``theta0``."""
    idf, order = _identify_at(problem, np.zeros(problem.chain.size), tol)
    kept = tuple(sorted(order[i] for i in idf.kept))
    theta, nfev = _fit(problem, kept, theta0, loss, f_scale)
    return theta, kept, nfev


def _random_poses(robot: Robot, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` joint readings drawn uniformly inside the limits (a continuous joint's are one turn, -pi .. pi)."""
    return rng.uniform(np.array(robot.limits.lower), np.array(robot.limits.upper), size=(n, robot.dof))


def structural_count(chain: ChainModel, seed: int = 0, tol: float = IDENTIFY_TOL, yaw_weight: float = 0.1) -> int:
    """How many of the chain's errors a rich set of poses identifies (random poses inside the limits).

    At the nominal model, from ``max(3 x errors, STRUCTURAL_POSES)`` poses drawn with ``seed``.
    """
    rng = np.random.default_rng(seed)
    q = _random_poses(chain.robot, max(3 * chain.size, STRUCTURAL_POSES), rng)
    _, J = chain.predict(np.zeros(chain.size), chain.pinocchio_q(q), pin.SE3.Identity())
    if chain.yaw:
        J = J.copy()  # type: ignore[union-attr]
        J[3::4] *= yaw_weight
    return len(identify(J, tol).kept)  # type: ignore[arg-type]


def _covariance(problem: _Problem, theta: np.ndarray, kept: tuple[int, ...]) -> tuple[np.ndarray, float]:
    """The covariance of the identified errors and the noise estimate sigma (NaN without redundancy)."""
    r, J = problem.residuals(theta)
    Jk = J[:, list(kept)]  # type: ignore[index]
    dof = Jk.shape[0] - Jk.shape[1]
    if not kept:
        return np.zeros((0, 0)), math.nan
    _, s, Vt = np.linalg.svd(Jk, full_matrices=False)
    inv = (Vt.T / s**2) @ Vt
    if dof <= 0:
        return np.full_like(inv, math.nan), math.nan
    sigma2 = float(problem.weighted(r) @ problem.weighted(r)) / dof
    return sigma2 * inv, math.sqrt(sigma2)


def calibrate(robot: Robot, measurements: Measurements, options: CalibrationOptions | None = None) -> CalibrationResult:
    """Identify the robot's errors from measured poses and write the calibrated URDF (see the module docstring).

    Args:
        robot: the nominal robot (any serial chain the toolkit loads: a SCARA with 4 or 3 joints).
        measurements: the measured poses (joint readings, positions, optionally yaws).
        options: how (default :class:`CalibrationOptions`).

    Raises:
        InvalidInputError: (exit code 2) a robot the error model refuses (mimic joints), readings that do not
            fit the robot, fewer poses than identifiable errors (naming both counts), too many outliers.
    """
    opt = options if options is not None else CalibrationOptions()
    notes: list[str] = []
    outside = measurements.check(robot)
    if outside:
        notes.append(f"{len(outside)} pose(s) outside the joint limits (used): " + "; ".join(outside[:5])
                     + ("; ..." if len(outside) > 5 else ""))  # fmt: skip
    chain = ChainModel.from_robot(robot, frame=opt.frame, yaw=measurements.yaw is not None, groups=opt.groups)
    notes.extend(chain.notes)
    count = structural_count(chain, opt.seed, opt.tol, opt.yaw_weight)
    n = len(measurements)
    if n < count:
        raise InvalidInputError(
            f"{measurements.source}: {n} measured poses for {count} identifiable parameters: at least {count} "
            f"poses are needed, a few times more to average the noise (scara-pin calibrate --plan {3 * count} "
            "proposes poses)"
        )
    zero = np.zeros(chain.size)
    device0 = pin.SE3.Identity()
    if opt.frame is MeasurementFrame.DEVICE:
        nominal = ChainModel.from_robot(robot, yaw=False, groups=())
        p_base, _ = nominal.predict(np.zeros(0), nominal.pinocchio_q(measurements.q), device0, jacobian=False)
        device0 = kabsch(p_base, measurements.position)
    problem = _Problem(chain, measurements, device0, opt.yaw_weight)
    theta, kept, nfev = _fit_identified(problem, zero, opt.loss, opt.f_scale, opt.tol)
    used = np.ones(n, dtype=bool)
    outliers: tuple[Outlier, ...] = ()
    if opt.loss is not Loss.LINEAR:
        r, _ = problem.residuals(theta, jacobian=False)
        dist = np.linalg.norm(r[:, :3], axis=1)
        robust_sigma = 1.4826 * float(np.median(np.abs(r[:, :3])))
        used = dist <= max(opt.outlier_sigmas * robust_sigma, OUTLIER_FLOOR)
        if int(used.sum()) < count:
            raise InvalidInputError(f"{measurements.source}: {int((~used).sum())} of {n} poses are outliers: "
                                    f"{int(used.sum())} remain for {count} identifiable parameters")  # fmt: skip
        if not used.all():
            theta, kept, nfev = _fit_identified(problem.subset(used), theta, Loss.LINEAR, opt.f_scale, opt.tol)
    final = problem.subset(used)
    covariance, sigma = _covariance(final, theta, kept)
    if len(kept) < count:
        notes.append(f"these poses identify {len(kept)} of the {count} errors a richer set of poses would: add "
                     "poses (scara-pin calibrate --plan proposes well-conditioned ones)")  # fmt: skip
    r_before, _ = problem.residuals(zero, jacobian=False)
    r_after, _ = problem.residuals(theta, jacobian=False)
    if not used.all():
        dist = np.linalg.norm(r_after[:, :3], axis=1)
        outliers = tuple(Outlier(int(i), measurements.where(int(i)), float(dist[i])) for i in np.flatnonzero(~used))
    names = chain.names()
    # why each fixed error is fixed: said at the nominal model, where it was decided
    idf, order = _identify_at(final, zero, opt.tol)
    reasons = {order[i]: why for i, why in idf.reasons([names[k] for k in order]).items()}
    stds = np.sqrt(np.clip(np.diag(covariance), 0.0, None)) if len(kept) else np.zeros(0)
    std_of = dict(zip(kept, stds))
    estimates = tuple(
        ParameterEstimate(p.name, p.group, p.unit, float(theta[k]), float(std_of[k]), ParameterStatus.IDENTIFIED)
        if k in std_of else
        ParameterEstimate(p.name, p.group, p.unit, 0.0, 0.0, ParameterStatus.FIXED, reasons.get(k, "fixed"))
        for k, p in enumerate(chain.parameters)
    )  # fmt: skip
    cv = _cross_validation(final, opt, count, notes)
    urdf = _calibrated_urdf(chain, theta)
    _check_urdf(problem, theta, urdf)
    return CalibrationResult(
        chain=chain, measurements=measurements, theta=theta, parameters=estimates,
        identified=tuple(names[k] for k in kept), covariance=covariance, sigma=sigma, device0=device0, used=used,
        residuals_before=r_before, residuals_after=r_after, before=ResidualStats.of(r_before[used]),
        after=ResidualStats.of(r_after[used]), outliers=outliers, cross_validation=cv, structural_count=count,
        condition=idf.condition, loss=opt.loss, nfev=nfev, notes=tuple(notes), urdf=urdf,
    )  # fmt: skip


def _cross_validation(problem: _Problem, opt: CalibrationOptions, count: int,
                      notes: list[str]) -> CrossValidation | None:  # fmt: skip
    """Each fold's rows predicted by a fit on the other rows (from the nominal model)."""
    n = len(problem.measurements)
    if opt.folds == 0:
        return None
    folds = min(opt.folds, n)
    perm = np.random.default_rng(opt.seed).permutation(n)
    if n - math.ceil(n / folds) < count:
        notes.append(f"no cross-validation: {opt.folds} folds of {n} poses leave fewer than {count} poses to fit")
        return None
    held = []
    for f in range(folds):
        test = np.zeros(n, dtype=bool)
        test[perm[f::folds]] = True
        theta, _, _ = _fit_identified(problem.subset(~test), np.zeros(problem.chain.size), Loss.LINEAR, opt.f_scale,
                                  opt.tol)  # fmt: skip
        r, _ = problem.subset(test).residuals(theta, jacobian=False)
        held.append(r)
    return CrossValidation(folds, ResidualStats.of(np.vstack(held)))


def _calibrated_urdf(chain: ChainModel, theta: np.ndarray) -> str:
    """The input URDF with each calibrated joint's ``<origin>`` (only what changed)."""
    edits: dict[str, tuple[np.ndarray | None, np.ndarray | None]] = {}
    for o, (xyz, rpy) in zip(chain.origins, chain.calibrated_origins(theta).values()):
        moved = not np.array_equal(xyz, o.xyz)
        turned = not np.array_equal(rpy, o.rpy)
        if moved or turned:
            edits[o.name] = (xyz if moved else None, rpy if turned else None)
    return edit_origins(chain.robot.urdf, edits)


def _check_urdf(problem: _Problem, theta: np.ndarray, urdf: str) -> None:
    """The calibrated URDF, loaded back, reproduces the fit's predictions (base frame) to URDF_CHECK_TOL."""
    chain = problem.chain
    robot = Robot(urdf, base_frame=chain.robot.base_frame, tool_frame=chain.robot.tool_frame)
    pred, _ = chain.predict(theta, problem.qpin, problem.device0, jacobian=False)
    bMd = chain.device_placement(theta, problem.device0).inverse()
    p_base = pred[:, :3] @ bMd.rotation.T + bMd.translation
    names = chain.robot.joint_names
    scale = np.ones(chain.robot.dof)
    for joint, s in chain.scales(theta).items():
        scale[names.index(joint)] = s
    worst = max(float(np.linalg.norm(robot.tool_placement(q * scale).translation - p))
                for q, p in zip(problem.measurements.q, p_base))  # fmt: skip
    if worst > URDF_CHECK_TOL:
        raise RuntimeError(f"the calibrated URDF misses the fit's predictions by {worst:.3g} m (a bug)")
