"""Identify a robot's errors from measured poses: nonlinear least squares on Pinocchio's forward kinematics.

The problem: the residuals ``f(theta) - m`` of every measured pose (positions [m]; the
yaw [rad], wrapped to (-pi, pi], times ``yaw_weight`` [m/rad]), ``f`` the chain's prediction
(:meth:`ChainModel.predict <scara_pin.calibration.chain.ChainModel.predict>`) with its analytic Jacobian.

The steps of :func:`calibrate`:

1. the error model of the robot's chain, and the structural count: how many errors a rich set of poses
   separates at the nominal model (:func:`identify` on random poses inside the limits);
2. the data checked against the nominal model (:func:`~scara_pin.calibration.screen.screen`: units, degrees,
   limits, distinct poses); in the device frame, the device's nominal placement is the rigid alignment
   (:func:`~scara_pin.calibration.chain.kabsch`) of the nominal predictions with the measurements;
3. the identified errors, judged where the model is (``_solve``): first at the nominal model, on the
   DISTINCT poses (a repeated pose adds rows, not rank), fitted by scipy's ``least_squares`` (trust-region
   reflective, analytic Jacobian), the others fixed at zero; then again at the estimate, the errors already
   identified first: an error without first-order effect at the nominal model may act at the estimate (J4's
   tilts move the target once the fit has found a tool offset the nominal model lacks). Such second-order
   errors (separated from the identified ones by a sine of at least ``SECOND_ORDER_SINE``) join the fit
   when the data are not yet explained to working precision (``EXPLAINED``), the fit with them lowers the
   residual significantly (an F-test at ``SIGNIFICANCE`` on the inlying rows) and each is determined to
   better than ``SECOND_ORDER_STD``; else they stay fixed, never fitted to noise. Repeated until no error
   joins (at most ``MAX_PASSES``);
4. with a robust loss (the default, soft_l1): the rows whose weighted residual exceeds ``outlier_sigmas``
   robust standard deviations (the median norm of a row's residual over the median of a chi distribution
   with as many degrees of freedom as the row has coordinates) are outliers, listed and left out; the final
   fit is the linear one of step 3 on the other rows, and the outliers are judged again against it (its
   inlying rows give the standard deviation; a soft_l1 fit still leans towards gross rows) until they stay
   the same. With the linear loss they are kept, and named in a warning;
5. the covariance ``sigma^2 (J^T J)^-1`` of the identified errors, ``sigma^2`` the residual sum of squares over
   the redundancy (rows x coordinates minus identified errors), and each row's standardised residual
   ``sqrt(r^T (I - H)^-1 r) / sigma`` (``H``: the row's block of the hat matrix; ``I + H`` for a row left out);
6. a k-fold cross-validation by pose: each fold's poses (all their rows) predicted by a fit on the others
   (step 3 on them, started from the fit on all the rows: the same minimum, sooner);
7. the calibrated URDF (:mod:`scara_pin.calibration.urdf_edit`), loaded back and checked against the fit's
   predictions.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError, ParameterError
from ..kinematics.planar2r import wrap
from ..model import RobotModel
from .chain import ALL_GROUPS, ChainModel, Group, MeasurementFrame
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
from .screen import screen
from .urdf_edit import edit_origins

__all__ = ["CalibrationOptions", "calibrate", "structural_count"]

FIT_TOL = 1e-15
"""``least_squares``' ftol, xtol and gtol: the fit runs to working precision (noise-free data are met to 1e-12 m)."""
MAX_NFEV = 200
"""The most model evaluations of one fit."""
OUTLIER_FLOOR = 1e-9
"""[m] a row's weighted residual below this is never an outlier (noise-free data)."""
URDF_CHECK_TOL = 1e-9
"""[m] the calibrated URDF, loaded back, must reproduce the fit's predictions to this (else: a bug)."""
STRUCTURAL_POSES = 60
"""The fewest random poses the structural count is computed on (at least 3 per candidate error)."""
MAX_PASSES = 4
"""The most re-identifications at the estimate (each adds the second-order errors that act there)."""
EXPLAINED = 1e-12
"""[m] data whose weighted residual RMS is at most this are explained (working precision): no error joins."""
SIGNIFICANCE = 0.01
"""The F-test's level: second-order errors join when the residual they remove would be this unlikely by chance."""
SECOND_ORDER_SINE = 1e-3
"""The smallest sine between a second-order error's unit column and the span of the identified ones for it to
join (theirs are near 1; a gauge the estimate's small errors break shows sines near their product, 1e-6)."""
SECOND_ORDER_STD = {"m": 1e-3, "rad": 1e-2, "1": 1e-3}
"""Per unit: a second-order error joins only when the data determine it to better than this (1 mm, 0.57 deg)."""
LARGE_ERROR = {"m": 0.05, "rad": math.radians(5.0), "1": 0.01}
"""Per unit: an identified error above this (a fraction of the chain's length for "m") is warned about."""


@dataclass(frozen=True)
class CalibrationOptions:
    """How to calibrate.

    Attributes:
        groups: the error groups fitted (:class:`~scara_pin.calibration.chain.Group`; ``device`` follows
            from ``frame``).
        frame: the frame the positions are measured in.
        loss: the first fit's loss; a robust one (soft_l1, the default; huber, cauchy, arctan) finds the
            outliers, which are listed and left out of the final (linear) fit; linear keeps every row.
        f_scale: the robust loss's inlier scale [m] (residuals well below it count as with the linear loss).
        outlier_sigmas: a row whose weighted residual exceeds this many robust standard deviations is an
            outlier.
        yaw_weight: [m/rad] the weight of a yaw residual against a position one (the ratio of the position's
            measurement noise to the yaw's).
        folds: the cross-validation's folds (0: none).
        seed: the seed of the random poses of the structural count and of the folds' poses.
        tol: the identification's tolerance (:data:`~scara_pin.calibration.identify.IDENTIFY_TOL`).
        accept_outside_limits: use readings outside the joint limits (with a warning) instead of refusing
            them (for a URDF whose limits are narrower than the controller's).
    """

    groups: frozenset[Group] = ALL_GROUPS
    frame: MeasurementFrame = MeasurementFrame.BASE
    loss: Loss = Loss.SOFT_L1
    f_scale: float = 1e-4
    outlier_sigmas: float = 5.0
    yaw_weight: float = 0.1
    folds: int = 5
    seed: int = 0
    tol: float = IDENTIFY_TOL
    accept_outside_limits: bool = False

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
    pose: np.ndarray = field(init=False)
    distinct: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.qpin = self.chain.pinocchio_q(self.measurements.q)
        self.target = self.measurements.values()
        self.pose, _ = self.measurements.poses()
        self.distinct = np.unique(self.pose, return_index=True)[1]  # the first row of each pose, in pose order

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
        """The (n, k) residuals the fit minimises (the yaw times ``yaw_weight``)."""
        if self.chain.yaw:
            r = r.copy()
            r[:, 3] *= self.yaw_weight
        return r

    def design(self, J: np.ndarray) -> np.ndarray:
        """The Jacobian's rows of the distinct poses (one row block per pose: the identification's design)."""
        k = self.chain.rows_per_pose
        return J.reshape(len(self.qpin), k, -1)[self.distinct].reshape(len(self.distinct) * k, -1)

    def subset(self, rows: np.ndarray) -> _Problem:
        return _Problem(self.chain, self.measurements.subset(rows), self.device0, self.yaw_weight)


def _fit(problem: _Problem, kept: tuple[int, ...] | list[int], theta0: np.ndarray, loss: Loss,
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
        return problem.weighted(r).ravel()

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


def _robust_sigma(w: np.ndarray) -> float:
    """The noise per coordinate, robustly, from the (n, k) weighted residuals.

    The median norm of the rows over the median of a chi distribution with k degrees of freedom (1.538 for
    k = 3: the norm of k coordinates of Gaussian noise).
    """
    from scipy.stats import chi2

    return float(np.median(np.linalg.norm(w, axis=1))) / math.sqrt(float(chi2.ppf(0.5, w.shape[1]))) if w.size else 0.0


def _inliers(w: np.ndarray, sigmas: float, among: np.ndarray | None = None) -> np.ndarray:
    """The rows of the (n, k) weighted residuals within ``sigmas`` robust standard deviations (or the floor).

    The standard deviation from the rows ``among`` (a mask; default all).
    """
    sigma = _robust_sigma(w if among is None else w[among])
    return np.linalg.norm(w, axis=1) <= max(sigmas * sigma, OUTLIER_FLOOR)


@dataclass(frozen=True)
class _Solution:
    """A fit with its identification.

    Attributes:
        theta: the errors. kept: the identified ones (ascending). second: those among them identified at the
        estimate only. weak: per second-order error left fixed, why. nominal: the identification at the
        nominal model on these poses. nfev: the last fit's model evaluations.
    """

    theta: np.ndarray
    kept: tuple[int, ...]
    second: tuple[int, ...]
    weak: dict[int, str]
    nominal: Identifiability
    nfev: int


def _solve(problem: _Problem, loss: Loss, opt: CalibrationOptions, start: _Solution | None = None, *,
           keep_weak: bool = True) -> _Solution:  # fmt: skip
    """The identified errors fitted, identifiability judged at the nominal model, then at each estimate.

    ``start``: a solution on other rows of the same chain: its second-order errors are kept (if these poses
    identify them at its estimate), those it left fixed stay fixed (with ``keep_weak``; else they are tested
    again), and the fit starts from its estimate (the same minimum, sooner).
    """
    size = problem.chain.size
    zero = np.zeros(size)
    _, J0 = problem.residuals(zero)
    nominal = identify(problem.design(J0), opt.tol)  # type: ignore[arg-type]
    kept = list(nominal.kept)
    second: list[int] = []
    weak: dict[int, str] = {}
    theta = zero
    if start is not None:
        weak = dict(start.weak) if keep_weak else {}
        if start.second:
            _, Js = problem.residuals(start.theta)
            order = kept + list(start.second) + [k for k in range(size) if k not in kept and k not in start.second]
            at = identify(problem.design(Js), opt.tol, order)  # type: ignore[arg-type]
            second = [k for k in start.second if k in at.kept]
            kept = sorted(kept + second)
        theta = np.where(np.isin(np.arange(size), kept), start.theta, 0.0)
    theta, nfev = _fit(problem, kept, theta, loss, opt.f_scale)
    for _ in range(MAX_PASSES):
        r, J = problem.residuals(theta)
        w = problem.weighted(r)
        rows = _inliers(w, opt.outlier_sigmas) if loss is not Loss.LINEAR else np.ones(len(w), dtype=bool)
        if math.sqrt(float(np.mean(w[rows] ** 2))) <= EXPLAINED:
            break
        order = kept + [k for k in range(size) if k not in kept]
        idf = identify(problem.design(J), opt.tol, order)  # type: ignore[arg-type]
        new = [k for k in idf.kept if k not in kept and k not in weak and idf.sines[k] >= SECOND_ORDER_SINE]
        if not new:
            break
        trial, trial_nfev = _fit(problem, kept + new, theta, loss, opt.f_scale)
        accepted = _second_order(problem, theta, trial, kept, new, rows, weak)
        if not accepted:
            break
        if accepted != new:
            trial, trial_nfev = _fit(problem, kept + accepted, theta, loss, opt.f_scale)
        kept = sorted(kept + accepted)
        second += accepted
        theta, nfev = trial, trial_nfev
    return _Solution(theta, tuple(kept), tuple(sorted(second)), weak, nominal, nfev)


def _second_order(problem: _Problem, theta: np.ndarray, trial: np.ndarray, kept: list[int], new: list[int],
                  rows: np.ndarray, weak: dict[int, str]) -> list[int]:  # fmt: skip
    """Which of the errors ``new`` (acting at the estimate only) join the fit; why the others do not, in ``weak``.

    ``theta``: the fit without them; ``trial``: with them. Tested on the rows ``rows`` (the inlying ones).
    """
    from scipy.stats import f as fisher

    params = problem.chain.parameters
    r0, _ = problem.residuals(theta, jacobian=False)
    r1, J1 = problem.residuals(trial)
    w0, w1 = problem.weighted(r0)[rows], problem.weighted(r1)[rows]
    rss0, rss1 = float(np.sum(w0**2)), float(np.sum(w1**2))
    cols = kept + new
    k = problem.chain.rows_per_pose
    Jr = J1.reshape(len(r1), k, -1)[rows].reshape(-1, problem.chain.size)[:, cols]  # type: ignore[union-attr]
    dof = Jr.shape[0] - len(cols)
    if dof <= 0:
        for i in new:
            weak[i] = "acts only through the other errors here (second order); no redundancy left to test it"
        return []
    _, sv, Vt = np.linalg.svd(Jr, full_matrices=False)
    std = np.sqrt(rss1 / dof * np.sum((Vt / sv[:, None]) ** 2, axis=0))[len(kept):]
    p_value = float(fisher.sf((rss0 - rss1) / len(new) / (rss1 / dof), len(new), dof)) if rss1 > 0 else 0.0
    accepted = []
    for i, s in zip(new, std):
        unit = params[i].unit
        if p_value > SIGNIFICANCE:
            weak[i] = (f"acts only through the other errors here (second order); not significant in these "
                       f"measurements (F-test p = {p_value:.2g})")  # fmt: skip
        elif not s <= SECOND_ORDER_STD[unit]:
            weak[i] = (f"acts only through the other errors here (second order); these measurements determine it "
                       f"to +/- {s:.2g} {unit} only")  # fmt: skip
        else:
            accepted.append(i)
    return accepted


def random_poses(robot: RobotModel, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` joint readings drawn uniformly inside the limits (a continuous joint's are one turn, -pi .. pi)."""
    return rng.uniform(np.array(robot.limits.lower), np.array(robot.limits.upper), size=(n, robot.dof))


def structural_count(chain: ChainModel, seed: int = 0, tol: float = IDENTIFY_TOL, yaw_weight: float = 0.1) -> int:
    """How many of the chain's errors a rich set of poses identifies (random poses inside the limits).

    At the nominal model, from ``max(3 x errors, STRUCTURAL_POSES)`` poses drawn with ``seed``.
    """
    rng = np.random.default_rng(seed)
    q = random_poses(chain.robot, max(3 * chain.size, STRUCTURAL_POSES), rng)
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
    w = problem.weighted(r).ravel()
    sigma2 = float(w @ w) / dof
    return sigma2 * inv, math.sqrt(sigma2)


def _standardised(problem: _Problem, used: np.ndarray, theta: np.ndarray, kept: tuple[int, ...],
                  sigma: float) -> np.ndarray:  # fmt: skip
    """Per row, its standardised residual ``sqrt(r^T (I -/+ H)^-1 r) / sigma`` (NaN when it cannot be said).

    ``r``: the row's weighted residual; ``H``: its block of the hat matrix of the rows used (``I - H``), or
    of its prediction (``I + H``) for a row left out.
    """
    n, k = len(problem.qpin), problem.chain.rows_per_pose
    out = np.full(n, math.nan)
    if not (math.isfinite(sigma) and sigma > 0) or not kept:
        return out
    r, J = problem.residuals(theta)
    w = problem.weighted(r)
    Jk = J[:, list(kept)].reshape(n, k, len(kept))  # type: ignore[index]
    _, s, Vt = np.linalg.svd(Jk[used].reshape(-1, len(kept)), full_matrices=False)
    A = Jk @ (Vt.T / s)  # (n, k, kept): each row's hat block is A A^T
    H = A @ np.transpose(A, (0, 2, 1))
    sign = np.where(used, -1.0, 1.0)[:, None, None]
    M = np.eye(k)[None] + sign * H
    for i in range(n):
        with contextlib.suppress(np.linalg.LinAlgError):  # a row the fit meets exactly whatever its value: NaN
            out[i] = math.sqrt(max(float(w[i] @ np.linalg.solve(M[i], w[i])), 0.0)) / sigma
    return out


def calibrate(robot: RobotModel, measurements: Measurements,
              options: CalibrationOptions | None = None) -> CalibrationResult:  # fmt: skip
    """Identify the robot's errors from measured poses and write the calibrated URDF (see the module docstring).

    Args:
        robot: the nominal robot (any serial chain the toolkit loads: a SCARA with 4 or 3 joints).
        measurements: the measured poses (joint readings, positions, optionally yaws).
        options: how (default :class:`CalibrationOptions`).

    Raises:
        InvalidInputError: (exit code 2) a robot the error model refuses (mimic joints), readings that do not
            fit the robot, data the nominal model says cannot be a calibration's (units, degrees, readings
            outside the limits, another robot: :func:`~scara_pin.calibration.screen.screen`), fewer distinct
            poses than identifiable errors (naming both counts), too many outliers.
    """
    opt = options if options is not None else CalibrationOptions()
    measurements.check(robot)
    chain = ChainModel.from_robot(robot, frame=opt.frame, yaw=measurements.yaw is not None, groups=opt.groups)
    notes: list[str] = list(chain.notes)
    count = structural_count(chain, opt.seed, opt.tol, opt.yaw_weight)
    screening = screen(chain, measurements, count, accept_outside_limits=opt.accept_outside_limits)
    warnings = list(screening.warnings)
    n = len(measurements)
    zero = np.zeros(chain.size)
    problem = _Problem(chain, measurements, screening.device0, opt.yaw_weight)
    used = np.ones(n, dtype=bool)
    start: _Solution | None = None
    if opt.loss is not Loss.LINEAR:  # the robust fit's outliers, then each linear fit's, until they stay the same
        start = _solve(problem, opt.loss, opt)
        r, _ = problem.residuals(start.theta, jacobian=False)
        used = _inliers(problem.weighted(r), opt.outlier_sigmas)
    for attempt in range(MAX_PASSES):
        left = len(np.unique(problem.pose[used]))
        if left < count:
            raise InvalidInputError(f"{measurements.source}: {int((~used).sum())} of {n} rows are outliers: "
                                    f"{left} distinct poses remain for {count} identifiable parameters")  # fmt: skip
        final = problem.subset(used)
        sol = _solve(final, Loss.LINEAR, opt, start, keep_weak=False)
        if opt.loss is Loss.LINEAR:
            break
        r, _ = problem.residuals(sol.theta, jacobian=False)
        again = _inliers(problem.weighted(r), opt.outlier_sigmas, used)
        if np.array_equal(again, used) or attempt == MAX_PASSES - 1:
            break
        used, start = again, sol
    theta, kept = sol.theta, sol.kept
    covariance, sigma = _covariance(final, theta, kept)
    if len(sol.nominal.kept) < count:
        notes.append(f"these poses identify {len(sol.nominal.kept)} of the {count} errors a richer set of poses "
                     "would: add poses (scara-pin calibrate --plan proposes well-conditioned ones)")  # fmt: skip
    r_before, _ = problem.residuals(zero, jacobian=False)
    r_after, _ = problem.residuals(theta, jacobian=False)
    standardised = _standardised(problem, used, theta, kept, sigma)
    dist = np.linalg.norm(r_after[:, :3], axis=1)
    outliers = tuple(Outlier(int(i), measurements.where(int(i)), float(dist[i]), float(standardised[i]))
                     for i in np.flatnonzero(~used))  # fmt: skip
    if opt.loss is Loss.LINEAR:
        gross = np.flatnonzero(~_inliers(problem.weighted(r_after), opt.outlier_sigmas))
        if len(gross):
            shown = ", ".join(f"{measurements.where(int(i))} ({dist[i] * 1e3:.3g} mm)" for i in gross[:5])
            warnings.append(f"{len(gross)} row(s) are off by more than {opt.outlier_sigmas:g} robust standard "
                            f"deviations: {shown}{', ...' if len(gross) > 5 else ''}: outliers kept by the linear "
                            "loss; the default loss (soft_l1) leaves them out")  # fmt: skip
    names = chain.names()
    reasons = {**sol.nominal.reasons(names), **sol.weak}
    stds = np.sqrt(np.clip(np.diag(covariance), 0.0, None)) if len(kept) else np.zeros(0)
    std_of = dict(zip(kept, stds))
    estimates = tuple(
        ParameterEstimate(p.name, p.group, p.unit, float(theta[k]), float(std_of[k]), ParameterStatus.IDENTIFIED)
        if k in std_of else
        ParameterEstimate(p.name, p.group, p.unit, 0.0, 0.0, ParameterStatus.FIXED, reasons.get(k, "fixed"))
        for k, p in enumerate(chain.parameters)
    )  # fmt: skip
    warnings.extend(_large_errors(estimates, chain.length))
    cv = _cross_validation(final, opt, count, notes, sol)
    urdf = _calibrated_urdf(chain, theta)
    _check_urdf(problem, theta, urdf)
    _, J_final = final.residuals(theta)
    return CalibrationResult(
        chain=chain, measurements=measurements, theta=theta, parameters=estimates,
        identified=tuple(names[k] for k in kept), covariance=covariance, sigma=sigma, device0=screening.device0,
        used=used, residuals_before=r_before, residuals_after=r_after, before=ResidualStats.of(r_before[used]),
        after=ResidualStats.of(r_after[used]), outliers=outliers, cross_validation=cv, structural_count=count,
        condition=_condition(final.design(J_final)[:, list(kept)]), loss=opt.loss,  # type: ignore[arg-type]
        nfev=sol.nfev, notes=tuple(notes), urdf=urdf, warnings=tuple(warnings), distinct=screening.distinct,
        second_order=tuple(names[k] for k in sol.second), standardised=standardised,
    )  # fmt: skip


def _condition(W: np.ndarray) -> float:
    """The condition number of the unit-scaled columns of ``W`` (inf when empty or singular)."""
    if W.shape[1] == 0:
        return math.inf
    sv = np.linalg.svd(W / np.linalg.norm(W, axis=0), compute_uv=False)
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf


def _large_errors(estimates: tuple[ParameterEstimate, ...], length: float) -> list[str]:
    """A warning naming the identified errors too large for a calibration (see LARGE_ERROR), or none."""
    big = []
    for p in estimates:
        bound = LARGE_ERROR[p.unit] * (length if p.unit == "m" else 1.0)
        if p.status is ParameterStatus.IDENTIFIED and abs(p.value) > bound:
            shown = f"{math.degrees(p.value):.3g} deg" if p.unit == "rad" else f"{p.value:.3g} {p.unit}"
            big.append(f"{p.name} = {shown}")
    if not big:
        return []
    return [f"large errors for a calibration: {', '.join(big)}: check the joints' zeros, the readings' units and "
            "the tool offset; the calibrated URDF takes them as real"]  # fmt: skip


def _cross_validation(problem: _Problem, opt: CalibrationOptions, count: int, notes: list[str],
                      whole: _Solution) -> CrossValidation | None:  # fmt: skip
    """Each fold's poses (all their rows) predicted by a fit on the other poses.

    The fit: ``_solve``, started from the fit on all of them (``whole``).
    """
    if opt.folds == 0:
        return None
    poses = len(problem.distinct)
    folds = min(opt.folds, poses)
    if poses - math.ceil(poses / folds) < count:
        notes.append(f"no cross-validation: {opt.folds} folds of {poses} distinct poses leave fewer than {count} "
                     "poses to fit")  # fmt: skip
        return None
    perm = np.random.default_rng(opt.seed).permutation(poses)
    held = np.empty_like(problem.target)
    for f in range(folds):
        test = np.isin(problem.pose, perm[f::folds])
        theta = _solve(problem.subset(~test), Loss.LINEAR, opt, whole).theta
        held[test], _ = problem.subset(test).residuals(theta, jacobian=False)
    return CrossValidation(folds, ResidualStats.of(held), held)


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
    robot = RobotModel(urdf, base_frame=chain.robot.base_frame, tool_frame=chain.robot.tool_frame)
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
