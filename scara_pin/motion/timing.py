"""Time-optimal timing of a joint path with TOPP-RA (``toppra``), with limits that hold BETWEEN grid points.

The promise: the returned trajectory, sampled at 1 kHz (or at any times: see below), never exceeds a
joint velocity or acceleration limit (nor the optional tool-speed and torque limits) by more than 1e-6
relative. toppra alone enforces the limits at its grid points only, and its spline output overshoots
between them. Here:

1. **Problem.** The path ``q(s)`` is rescaled to ``s' = L s`` with L its duration at full speed, so
   that the path velocity is of order 1 (toppra's solvers bound it). On toppra's grid ``s_i`` the path
   acceleration ``u_i`` is constant on each segment, so ``x = sd^2`` is linear in s:
   ``x(s_i + sigma D_i) = x_i + 2 sigma D_i u_i``. Each limit, written at the sub-points
   ``sigma = 0, 1/m, ..., 1`` of the segment, is then LINEAR in the stage's (u_i, x_i):

       velocity:      x_i + 2 sigma D_i u_i <= vmax_j^2 / q'_j(s)^2            (and the tool speed)
       acceleration:  |q'_j(s) u_i + q''_j(s) (x_i + 2 sigma D_i u_i)| <= amax_j
       torque:        |a_j(s) u_i + b_j(s) (x_i + 2 sigma D_i u_i) + c_j(s)| <= tau_j

   with the torque coefficients from Pinocchio's RNEA as in toppra's JointTorqueConstraint:
   ``c = rnea(q, 0, 0)``, ``a = rnea(q, 0, q') - c``, ``b = rnea(q, q', q'') - c``. They go to toppra
   as ONE precomputed canonical linear constraint (collocation type); sigma in {0, 1} is toppra's own
   "interpolation" discretisation, the interior sub-points shrink what is left between them ~m^2 times.
2. **Output.** Not toppra's spline: the exact constant-path-acceleration kinematics between grid points
   (:class:`~scara_pin.motion.trajectory.ProfileLaw`), q, q', q'' from the path itself.
3. **Verification and rescaling.** The result is evaluated at ``check_subdivisions`` points of every
   segment and on the ``check_rate`` grid (1 kHz) and, for joint lines and splines (cubic between grid
   points), at every interior extremum of each joint's velocity and acceleration, found in closed form:
   then the limits hold at ANY time, not only at the samples. The time scale k that makes the worst ratio exactly
   1 is applied (velocity scales with 1/k, acceleration with 1/k^2, the dynamic part of the torque with
   1/k^2); k < 1 too, which removes toppra's own safety margins. Then the NEW 1 kHz grid is checked
   again, until the worst ratio is within [1 - 1e-7, 1 + 1e-10].

Failures are :class:`TimingError` (with toppra's return code and the likely cause) or, for bad limits,
:class:`~scara_pin.errors.ParameterError`; never ``None``. toppra is imported only inside the
functions of this module (it costs more than a second).
"""

from __future__ import annotations

import dataclasses
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..description import JointLimits
from ..errors import InfeasibleError, ParameterError
from ..limits import MAX_SAMPLES, check_count
from .paths import path_segments
from .trajectory import (
    CartesianPath,
    GeometricPath,
    JointLine,
    JointSpline,
    Motion,
    ProfileLaw,
    Trajectory,
    as_positive,
)
from .verify import (
    LimitsInForce,
    Quantity,
    limits_in_force,
    static_overload,
    time_scale,
    tool_speeds,
    torque_coefficients,
    verify,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = [
    "LimitRatios",
    "TimingError",
    "TimingOptions",
    "TimingResult",
    "limit_ratios",
    "parameterize",
    "time_optimal",
]

logger = logging.getLogger(__name__)

_ACCEPT = 1.0 + 1e-10
"""The verification accepts a worst limit ratio up to this: far inside the 1e-6 promise."""
_END = 1.0 - 1e-9
"""Fraction of a grid segment where its end value (the left limit at the next grid point) is checked."""
_X_CAP = 1e8
"""Cap of the path-velocity-squared bound where q' = 0 (the acceleration limit then decides)."""


class TimingError(InfeasibleError):
    """No time parameterisation was found (exit code 3).

    Attributes:
        return_code: toppra's ``ParameterizationReturnCode`` name (``FailUncontrollable``,
            ``ErrShortPath``, ``ErrForwardPassFail``, ``ErrUnknown``); ``Exception`` when toppra raised;
            ``VerificationFailed`` when the check after the solver finds a limit no time scaling can meet;
            ``JerkNLP`` from the jerk-limited timing (:mod:`scara_pin.motion.jerk`, IPOPT).
        cause: the likely cause, with numbers.
        segment: index of the failing path segment.
        s: path parameter in [0, 1] of the segment where it fails, when known.
    """

    def __init__(self, return_code: str, cause: str, *, segment: int = 0, s: float | None = None) -> None:
        self.return_code = return_code
        self.cause = cause
        self.segment = segment
        self.s = s
        where = f" (segment {segment}" + (f", s = {s:.6f})" if s is not None else ")")
        solver = "ipopt" if return_code == "JerkNLP" else "toppra"
        super().__init__(f"time-optimal timing failed{where}: {cause} [{solver}: {return_code}]")


@dataclass(frozen=True)
class TimingOptions:
    """Options of :func:`parameterize`.

    Attributes:
        grid_points: toppra grid segments per path segment (the path's knots are added).
        subdivisions: m, the constraint sub-points per grid segment are sigma = 0, 1/m, ..., 1.
        check_rate: [Hz] the sampling rate whose samples are verified (the promise).
        check_subdivisions: verified points per grid segment, besides the check_rate grid.
    """

    grid_points: int = 100
    subdivisions: int = 4
    check_rate: float = 1000.0
    check_subdivisions: int = 16

    def __post_init__(self) -> None:
        for name, low in (("grid_points", 2), ("subdivisions", 1), ("check_subdivisions", 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low or v > 1_000_000:
                raise ParameterError(name, v, f"must be an integer in [{low}, 1000000]")
        as_positive("check_rate", self.check_rate, "Hz")


@dataclass(frozen=True)
class LimitRatios:
    """Worst ratios |value| / limit over the checked samples (1.0 = on the limit).

    Attributes:
        velocity, acceleration: max over joints and samples.
        tool_speed: of the tool-speed limit, or None when not limited.
        torque: of the effort limits, or None when not limited.
    """

    velocity: float
    acceleration: float
    tool_speed: float | None = None
    torque: float | None = None

    @property
    def worst(self) -> float:
        """The largest of the ratios (NaN if any is NaN: an unknown limit passes no check)."""
        present = [v for v in (self.velocity, self.acceleration, self.tool_speed, self.torque) if v is not None]
        return math.nan if any(math.isnan(v) for v in present) else max(present)

    @staticmethod
    def combine(items: Sequence[LimitRatios]) -> LimitRatios:
        """The worst of several."""

        def top(vals: list[float | None]) -> float | None:
            present = [v for v in vals if v is not None]
            return max(present) if present else None

        return LimitRatios(
            max(r.velocity for r in items),
            max(r.acceleration for r in items),
            top([r.tool_speed for r in items]),
            top([r.torque for r in items]),
        )


@dataclass(frozen=True, eq=False)
class TimingResult:
    """A time-optimal trajectory and how it was obtained.

    Attributes:
        trajectory: the trajectory.
        toppra_duration: [s] duration of toppra's profile (constant path acceleration between its grid
            points) before verification.
        scale: trajectory duration / toppra_duration (the verification's time scaling).
        ratios: worst limit ratios over the checked samples of the final trajectory.
        grid_points: toppra grid points used (all segments).
        options: the options used.
    """

    trajectory: Trajectory
    toppra_duration: float
    scale: float
    ratios: LimitRatios
    grid_points: int
    options: TimingOptions = field(default_factory=TimingOptions)


def time_optimal(
    robot: RobotModel,
    path: GeometricPath | CartesianPath | Sequence[ArrayLike] | np.ndarray,
    *,
    tool_speed: float | None = None,
    torque: bool = False,
    limits: JointLimits | None = None,
    options: TimingOptions | None = None,
) -> Trajectory:
    """The time-optimal trajectory along ``path`` (see :func:`parameterize`, which also reports)."""
    return parameterize(robot, path, tool_speed=tool_speed, torque=torque, limits=limits, options=options).trajectory


def parameterize(
    robot: RobotModel,
    path: GeometricPath | CartesianPath | Sequence[ArrayLike] | np.ndarray,
    *,
    tool_speed: float | None = None,
    torque: bool = False,
    limits: JointLimits | None = None,
    options: TimingOptions | None = None,
) -> TimingResult:
    """Time-optimal, rest-to-rest timing of a path under the robot's limits, verified (module docstring).

    Args:
        robot: the robot (limits; Pinocchio model for the tool speed and the torques).
        path: a path, a :class:`~scara_pin.motion.paths.CartesianPath` (its segments are timed one by
            one: the tool stops at each via point, where the line turns), or (m, 4) joint waypoints
            (:func:`~scara_pin.motion.paths.joint_path`).
        tool_speed: [m/s] limit of the tool origin's speed |J_xyz(q) qd|, optional.
        torque: also limit the joint efforts (``limits.effort``) computed with Pinocchio's RNEA from the
            model's inertias (gravity included).
        limits: joint limits to use instead of ``robot.limits``.
        options: grid and verification options.

    Raises:
        ParameterError: a limit is missing (NaN), zero, negative or not finite.
        PathError: the path itself is invalid (outside the limits, singular).
        TimingError: toppra found no parameterisation (return code and likely cause).
    """
    opts = TimingOptions() if options is None else options
    lim = limits_in_force(robot, limits, tool_speed, torque)
    paths = path_segments(robot, path)
    motions: list[Motion] = []
    t_toppra, ratios, npts, t_start = 0.0, [], 0, 0.0
    for k, p in enumerate(paths):
        motion, tt, r, n = _time_segment(robot, p, lim, opts, k, t_start)
        t_start += motion.duration
        motions.append(motion)
        t_toppra += tt
        ratios.append(r)
        npts += n
    traj = Trajectory(tuple(motions))
    return TimingResult(traj, t_toppra, traj.duration / t_toppra, LimitRatios.combine(ratios), npts, opts)


# ---------------------------------------------------------------------------------------------- one segment
class _ToppraPath:
    """The path in toppra's units s' = L s (only what toppra's algorithm reads)."""

    def __init__(self, path: GeometricPath, L: float, dof: int = 4) -> None:
        self.path = path
        self.L = L
        self.dof = dof
        self.path_interval = np.array([0.0, L])

    def __call__(self, s: Any, order: int = 0) -> np.ndarray:
        return self.path(np.asarray(s) / self.L, order) / self.L**order


def _grid(path: GeometricPath, n: int) -> np.ndarray:
    """N uniform segments on [0, 1] plus the path's knots (uniform points too close to a knot dropped)."""
    knots = np.unique(np.clip(path.knots(), 0.0, 1.0))
    uniform = np.linspace(0.0, 1.0, n + 1)
    gap = 1e-3 / n
    near = np.abs(uniform[:, None] - knots[None, :]).min(axis=1) < gap
    grid = np.unique(np.concatenate([uniform[~near], knots, [0.0, 1.0]]))
    grid[0], grid[-1] = 0.0, 1.0
    return grid


def _time_segment(
    robot: RobotModel, path: GeometricPath, lim: LimitsInForce, opts: TimingOptions, segment: int, t_start: float
) -> tuple[Motion, float, LimitRatios, int]:
    """Time one path segment that starts at ``t_start`` in the whole trajectory (for its 1 kHz grid)."""
    import toppra
    import toppra.algorithm

    v, a = lim.velocity, lim.acceleration
    # 1. grid and its sub-points, in s
    grid = _grid(path, opts.grid_points)
    N = len(grid) - 1
    m = opts.subdivisions
    sigma = np.arange(m + 1) / m
    ds = np.append(np.diff(grid), 0.0)
    S = np.minimum(grid[:, None] + sigma[None, :] * ds[:, None], 1.0)
    q, dq, ddq = path.evaluate(S.ravel(), 2)
    if not (np.isfinite(dq).all() and np.isfinite(ddq).all()):
        raise TimingError("ErrUnknown", "the path derivatives are not finite (a singular point)", segment=segment)
    # 2. toppra's units: s' = L s, L the path's duration at full speed, so that ds'/dt is of order 1
    L = float(np.max(np.abs(dq) / v))
    if not L > 1e-12:
        raise TimingError("ErrShortPath", f"the path is too short: {L:.3g} s at full speed (joints barely move)",
                          segment=segment)  # fmt: skip
    D = ds * L
    dq = dq / L
    ddq = ddq / (L * L)
    tw = (2.0 * D[:, None] * sigma[None, :]).ravel()  # x(sub-point) = x_i + tw u_i
    rows = N + 1
    # velocity (and tool speed): x_i + tw u_i <= B
    with np.errstate(divide="ignore"):
        B = np.min(v**2 / dq**2, axis=1)
        if lim.tool_speed is not None:
            B = np.minimum(B, lim.tool_speed**2 / tool_speeds(robot, q, dq) ** 2)
    B = np.minimum(B, _X_CAP)
    blocks_a = [tw.reshape(rows, m + 1)]
    blocks_b = [np.ones((rows, m + 1))]
    blocks_c = [-B.reshape(rows, m + 1)]
    two_sided = []
    # acceleration: q' u + q'' (x + tw u)
    blocks_a.append((dq + tw[:, None] * ddq).reshape(rows, -1))
    blocks_b.append(ddq.reshape(rows, -1))
    blocks_c.append(np.zeros((rows, dq.shape[1] * (m + 1))))
    two_sided.append(np.tile(a, m + 1))
    g_static = None
    if lim.effort is not None:
        at, bt, c = torque_coefficients(robot, q, dq, ddq)
        g_static = c
        blocks_a.append((at + tw[:, None] * bt).reshape(rows, -1))
        blocks_b.append(bt.reshape(rows, -1))
        blocks_c.append(c.reshape(rows, -1))
        two_sided.append(np.tile(lim.effort, m + 1))
    A_ = np.concatenate(blocks_a, axis=1)
    B_ = np.concatenate(blocks_b, axis=1)
    C_ = np.concatenate(blocks_c, axis=1)
    n_one = m + 1
    n_two = sum(len(x) for x in two_sided)
    F = np.zeros((n_one + 2 * n_two, n_one + n_two))
    F[:n_one, :n_one] = np.eye(n_one)
    F[n_one : n_one + n_two, n_one:] = np.eye(n_two)
    F[n_one + n_two :, n_one:] = -np.eye(n_two)
    g = np.concatenate([np.zeros(n_one), *two_sided, *two_sided])
    constraint = _precomputed_constraint(A_, B_, C_, F, g)
    # 3. toppra
    try:
        inst = toppra.algorithm.TOPPRA([constraint], _ToppraPath(path, L, q.shape[1]), gridpoints=grid * L,
                                       solver_wrapper="seidel")  # fmt: skip
        inst.compute_parameterization(0.0, 0.0)
        data = inst.problem_data
    except Exception as exc:  # toppra raises assorted exceptions: the likely cause when there is one, else typed
        if g_static is not None and lim.effort is not None and static_overload(g_static, lim.effort) is not None:
            raise _diagnose("Exception", robot, grid, B, q, g_static, lim, m, segment, None) from exc  # a static load
        raise TimingError("Exception", f"toppra raised {type(exc).__name__}: {exc}", segment=segment) from exc
    code = data.return_code.name
    if code != "Ok" or data.sd_vec is None or not np.isfinite(data.sd_vec).all():
        raise _diagnose(code, robot, grid, B, q, g_static, lim, m, segment, data)
    sd = np.maximum(np.asarray(data.sd_vec, dtype=float) / L, 0.0)  # toppra's sd' = ds'/dt = L ds/dt
    try:
        law = ProfileLaw(grid, sd)
    except InfeasibleError as exc:
        raise TimingError(code, f"{exc} (a singular point, or too few grid points)", segment=segment) from None
    t_toppra = law.duration
    # 4. verify and rescale. First the time scale that makes the worst checked ratio exactly 1 (k < 1
    # removes toppra's safety margins); then verification at check_rate on the final timeline.
    extremes = _polynomial_extremes(path, law) if isinstance(path, (JointLine, JointSpline)) else None
    k, _ = _check(robot, Motion(path, law), law, lim, opts, t_start if extremes is None else None, extremes)
    law = law.scaled(k)
    total = k
    for _ in range(8):
        k, ratios = _check(robot, Motion(path, law), law, lim, opts, t_start, extremes, scale=total)
        if k <= _ACCEPT:
            break
        law = law.scaled(k * (1.0 + 1e-12))
        total *= k * (1.0 + 1e-12)
    else:  # pragma: no cover - would be a bug: time scaling is exact
        raise TimingError(code, f"the verification could not bring the limit ratio {ratios.worst:.12g} to 1",
                          segment=segment)  # fmt: skip
    logger.debug("segment %d: %d grid points, toppra %.6f s, final %.6f s, ratios %s",
                 segment, N + 1, t_toppra, law.duration, ratios)  # fmt: skip
    return Motion(path, law), t_toppra, ratios, N + 1


def _precomputed_constraint(a: np.ndarray, b: np.ndarray, c: np.ndarray, F: np.ndarray, g: np.ndarray) -> Any:
    """Toppra's canonical linear constraint a u + b x + c = v, F v <= g, with our own coefficients."""
    from toppra.constraint import DiscretizationType, LinearConstraint

    class _Precomputed(LinearConstraint):  # type: ignore[misc]
        def __init__(self) -> None:
            super().__init__()
            self.dof = 4
            self.identical = True
            self.discretization_type = DiscretizationType.Collocation

        def compute_constraint_params(self, path: Any, gridpoints: np.ndarray, *args: Any, **kwargs: Any) -> tuple:
            return a, b, c, F, g, None, None

    return _Precomputed()


def _diagnose(
    code: str,
    robot: RobotModel,
    grid: np.ndarray,
    B: np.ndarray,
    q: np.ndarray,
    g_static: np.ndarray | None,
    lim: LimitsInForce,
    m: int,
    segment: int,
    data: Any,
) -> TimingError:
    """The likely cause of a failed parameterisation."""
    rows = len(grid)
    S = grid[:, None] + np.append(np.diff(grid), 0.0)[:, None] * (np.arange(m + 1) / m)[None, :]
    S = S.ravel()
    bad = None if g_static is None or lim.effort is None else static_overload(g_static, lim.effort, robot.joint_names)
    if bad is not None:
        return TimingError(code, bad.reason(), segment=segment, s=float(S[bad.index]))
    Bmin = B.reshape(rows, m + 1).min(axis=1)
    if Bmin.min() < 1e-12:
        k = int(np.argmin(Bmin))
        return TimingError(code, "the path speed is forced to zero inside the path (|q'| unbounded: a singular "
                           "point or a cusp)", segment=segment, s=float(grid[k]))  # fmt: skip
    K = getattr(data, "K", None)
    s_bad = None
    if K is not None and np.isnan(K).any():
        s_bad = float(grid[int(np.argwhere(np.isnan(K).any(axis=1))[-1, 0])])
    if code == "FailUncontrollable":
        cause = "no profile satisfies every limit from rest to rest (the limits are inconsistent along the path"
        cause += ", e.g. an effort limit too low for the accelerations needed)" if lim.effort is not None else ")"
    else:
        cause = "numerical failure in toppra (try more grid points)"
    return TimingError(code, cause, segment=segment, s=s_bad)


# ---------------------------------------------------------------------------------------------- verification
def _check_times(law: ProfileLaw, opts: TimingOptions, sub: bool, t_start: float | None) -> np.ndarray:
    """Local times to check.

    The grid points; with ``sub``, check_subdivisions points per segment; with ``t_start`` (the segment's
    start in the whole trajectory), the trajectory's check_rate grid k / rate (the promise) that falls in
    this segment.
    """
    # the grid points give each segment's value at its start; the path acceleration jumps there, so the
    # value at each segment's END (its left limit at the next grid point) is checked as well
    parts = [law.t, law.t[:-1] + np.diff(law.t) * _END]
    if sub:
        M = opts.check_subdivisions
        parts.append((law.t[:-1, None] + np.diff(law.t)[:, None] * (np.arange(1, M) / M)[None, :]).ravel())
    if t_start is not None:
        rate = opts.check_rate
        check_count(f"checked samples ({law.duration:.6g} s at {rate:.6g} Hz)", law.duration * rate + 2.0,
                    MAX_SAMPLES, "the motion is too slow (a tiny --tool-speed or effort limit?)")
        k0 = math.ceil(t_start * rate - 1e-9)
        k1 = math.floor((t_start + law.duration) * rate + 1e-9)
        parts.append(np.clip(np.arange(k0, k1 + 1) / rate - t_start, 0.0, law.duration))
    return np.concatenate(parts)


def _check(
    robot: RobotModel,
    motion: Motion,
    law: ProfileLaw,
    lim: LimitsInForce,
    opts: TimingOptions,
    t_start: float | None,
    extremes: tuple[np.ndarray, np.ndarray] | None = None,
    scale: float = 1.0,
) -> tuple[float, LimitRatios]:
    """(k, ratios): the time scale making the worst checked ratio 1, and the ratios now.

    Checked: the grid points; the closed-form extrema ``extremes`` (qd, qdd of joint lines and splines,
    computed on the profile before it was slowed ``scale`` times: they scale exactly) or else
    check_subdivisions points per segment; with ``t_start``, the trajectory's check_rate grid.
    """
    sub = extremes is None or lim.tool_speed is not None or lim.effort is not None
    t = _check_times(law, opts, sub, t_start)
    q, qd, qdd = motion.evaluate(t)
    try:
        k, worst = time_scale(robot, lim, (q, qd, qdd))
    except InfeasibleError as exc:
        raise TimingError("VerificationFailed", str(exc)) from None
    if extremes is not None and len(extremes[0]):  # computed before the slow-down: qd / scale, qdd / scale^2
        e_v, e_a = extremes[0] / scale, extremes[1] / (scale * scale)
        only_va = dataclasses.replace(lim, effort=None, tool_speed=None)
        k_e, worst_e = time_scale(robot, only_va, (np.zeros_like(e_v), e_v, e_a))
        k = max(k, k_e)
        for quantity in (Quantity.VELOCITY, Quantity.ACCELERATION):
            worst[quantity] = max(worst[quantity], worst_e[quantity])
    return k, LimitRatios(worst[Quantity.VELOCITY], worst[Quantity.ACCELERATION], worst.get(Quantity.TOOL_SPEED),
                          worst.get(Quantity.TORQUE))  # fmt: skip


def _polynomial_extremes(path: GeometricPath, law: ProfileLaw) -> tuple[np.ndarray, np.ndarray]:
    """Qd and qdd at every interior extremum of qd or qdd and at each segment end, for a path cubic between knots.

    On grid segment i (inside one cubic piece, the knots being grid points) ``x = sd^2`` is linear in s
    and ``qdd_j(s) = q'_j(s) u_i + q''_j(s) x(s)`` is a quadratic in s: its extremum is at its vertex,
    and since ``d(qd_j^2)/ds = 2 q'_j qdd_j``, qd_j's interior extrema are at the roots of qdd_j. Both
    are found in closed form from qdd_j at sigma = 0, 1/2, 1 of the segment.
    """
    s0, s1 = law.s[:-1], law.s[1:]
    x0, x1 = law.sd[:-1] ** 2, law.sd[1:] ** 2
    u = law.u
    n = len(s0)
    _, d1, d2 = path.evaluate(np.concatenate([s0, 0.5 * (s0 + s1), s1]), 2)
    f0 = d1[:n] * u[:, None] + d2[:n] * x0[:, None]
    fm = d1[n : 2 * n] * u[:, None] + d2[n : 2 * n] * (0.5 * (x0 + x1))[:, None]
    f1 = d1[2 * n :] * u[:, None] + d2[2 * n :] * x1[:, None]
    b = -3.0 * f0 + 4.0 * fm - f1  # f(sigma) = f0 + b sigma + c sigma^2
    c = 2.0 * f0 - 4.0 * fm + 2.0 * f1
    scale = np.abs(f0) + np.abs(fm) + np.abs(f1) + 1e-300
    quad = np.abs(c) > 1e-12 * scale
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = np.where(quad, -b / (2.0 * c), np.nan)
        disc = np.sqrt(np.where(quad, b * b - 4.0 * c * f0, np.nan))
        r1 = np.where(quad, (-b - disc) / (2.0 * c), np.where(np.abs(b) > 1e-12 * scale, -f0 / b, np.nan))
        r2 = np.where(quad, (-b + disc) / (2.0 * c), np.nan)
    ends = np.full_like(vertex, _END)  # each segment's end: the left limit of qdd at the next grid point
    sig = np.concatenate([vertex, r1, r2, ends]).ravel()  # (4 n 4,), segment index = (row // 4) % n
    dof = d1.shape[1]
    seg = np.tile(np.repeat(np.arange(n), dof), 4)
    keep = np.isfinite(sig) & (sig > 0.0) & (sig < 1.0)
    sig, seg = sig[keep], seg[keep]
    if not len(sig):
        return np.zeros((0, dof)), np.zeros((0, dof))
    s = s0[seg] + sig * (s1 - s0)[seg]
    x = np.maximum(x0[seg] + 2.0 * u[seg] * (s - s0[seg]), 0.0)
    _, e1, e2 = path.evaluate(s, 2)
    return e1 * np.sqrt(x)[:, None], e1 * u[seg][:, None] + e2 * x[:, None]


def limit_ratios(
    robot: RobotModel,
    trajectory: Trajectory,
    *,
    rate: float = 1000.0,
    tool_speed: float | None = None,
    torque: bool = False,
    limits: JointLimits | None = None,
) -> LimitRatios:
    """Worst |value| / limit of a trajectory (velocity, acceleration, tool speed, torque).

    Joint velocity and acceleration of a straight joint move under a closed-form law (quintic, trapezoid)
    are checked on the law's exact maxima (:meth:`~scara_pin.motion.trajectory.TimeLaw.peaks`), never only
    on samples: a move shorter than one sample period is checked as well as a long one. Everything else
    is checked at ``rate`` and at 65 points inside every piece (however short). An unknown limit (NaN, a
    URDF's acceleration) gives a NaN ratio, which no check passes.
    """
    v = verify(robot, trajectory, rate=rate, tool_speed=tool_speed, torque=torque, limits=limits)
    return LimitRatios(v.velocity.ratio, v.acceleration.ratio, None if v.tool_speed is None else v.tool_speed.ratio,
                       None if v.torque is None else v.torque.ratio)  # fmt: skip
