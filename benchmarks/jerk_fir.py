"""The old jerk-BOUNDED timing: a moving-average (FIR) filter of the TOPP-RA profile, then a global slow-down.

A baseline for benchmarks/bench_jerk.py and tests/test_jerk.py (never faster than :mod:`scara_pin.motion.jerk`,
the package's jerk-limited timing); it lived in the package as ``scara_pin/motion/jerk_fir.py`` until issue 31.
It uses a few of the package's private helpers (the limits in force, a positive-number check): it is the
package's own baseline, kept beside the benchmarks that run it.

TOPP-RA's output (:class:`~scara_pin.motion.trajectory.ProfileLaw`) has a piecewise-constant path
acceleration: its jerk is infinite at every grid point. Here the path parameter law is filtered by a
moving average of width ``w`` (Biagiotti and Melchiorri's FIR trajectory filters):

    s_w(t) = (1 / w) * integral_{t - w}^{t} s_0(tau) dtau,       0 <= t <= T_0 + w,

so ``sd_w(t) = (s_0(t) - s_0(t - w)) / w``, ``sdd_w = (sd_0(t) - sd_0(t - w)) / w`` and the path jerk
``sddd_w = (sdd_0(t) - sdd_0(t - w)) / w`` is bounded and piecewise constant (breakpoints at the profile's
grid times t_i and t_i + w). The law still goes from rest (s = 0) to rest (s = 1). The joint jerk is

    qddd = q' sddd + 3 q'' sd sdd + q''' sd^3

with ``q'''`` the third path derivative (central differences of the exact ``q''`` inside each smooth piece
of the path, one-sided at its knots: the paths here are C2 across knots, so ``q''`` is continuous).

Filtering moves the profile off the limit curves, so the result is then checked densely (every
breakpoint interval at both ends and 3 interior points, and the ``check_rate`` grid of the final timeline)
and scaled in time by the k that brings the worst ratio to exactly 1 (velocity / k, acceleration and the
dynamic torque / k^2, jerk / k^3), as :mod:`scara_pin.motion.timing` does. The window w is chosen by a
small search minimising the final duration (T_0 + w) k(w). This is jerk-BOUNDED, not jerk-time-optimal.

Why not ruckig: ruckig (community edition) computes state-to-state motions per joint; it cannot keep the
joints on a given geometric path (the tool line and the arch), which is what a cycle needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from scara_pin._checks import as_positive
from scara_pin.errors import ParameterError
from scara_pin.motion.jerk import JerkRatios
from scara_pin.motion.timing import TimingError, TimingOptions
from scara_pin.motion.trajectory import GeometricPath, Motion, ProfileLaw, TimeLaw, Trajectory
from scara_pin.motion.verify import (
    LimitsInForce,
    Quantity,
    jerk_vector,
    joint_jerk,
    limits_in_force,
    path_third_derivative,
    time_scale,
)

if TYPE_CHECKING:
    from scara_pin._typing import ArrayLike
    from scara_pin.description import JointLimits
    from scara_pin.model import RobotModel as Robot

__all__ = ["FilteredLaw", "JerkRatios", "fir_jerk_limited"]

_ACCEPT = 1.0 + 1e-10
_SUB = 16
"""Checked points inside each interval between the law's breakpoints (besides both ends and the rate grid):
16 keep the acceleration between checked points within 1e-6 of its limit (4 left 1.2e-4 at 8 kHz)."""


@dataclass(frozen=True, eq=False)
class FilteredLaw(TimeLaw):
    """A :class:`ProfileLaw` filtered by a moving average of width ``window`` and slowed ``k`` times.

    Attributes:
        base: the profile s_0(t) on [0, T_0].
        window: w [s] > 0 (in the base's time).
        k: time scale >= ... (> 0): the law is s_w(t / k).
        duration: (T_0 + w) k [s].
    """

    base: ProfileLaw
    window: float
    k: float = 1.0
    duration: float = field(init=False)
    _S: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        as_positive("window", self.window, "s")
        as_positive("k", self.k)
        b = self.base
        dt = np.diff(b.t)
        seg = b.s[:-1] * dt + b.sd[:-1] * dt**2 / 2.0 + b.u * dt**3 / 6.0  # integral of s_0 over each segment
        object.__setattr__(self, "_S", np.concatenate([[0.0], np.cumsum(seg)]))
        object.__setattr__(self, "duration", (b.duration + self.window) * self.k)

    def _base(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """(S, s, sd, sdd, sddd-impulse-free) of the base at times t, extended by rest outside [0, T_0]."""
        b = self.base
        T0 = b.duration
        tc = np.clip(t, 0.0, T0)
        i = np.clip(np.searchsorted(b.t, tc, side="right") - 1, 0, len(b.u) - 1)
        d = tc - b.t[i]
        u = b.u[i]
        s = b.s[i] + b.sd[i] * d + u * d * d / 2.0
        S = self._S[i] + b.s[i] * d + b.sd[i] * d * d / 2.0 + u * d**3 / 6.0
        sd = b.sd[i] + u * d
        before, after = t < 0.0, t > T0
        S = np.where(before, 0.0, np.where(after, self._S[-1] + (t - T0), S))
        s = np.where(before, 0.0, np.where(after, 1.0, s))
        sd = np.where(before | after, 0.0, sd)
        sdd = np.where(before | after, 0.0, u)
        return S, s, sd, sdd

    def evaluate_jerk(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(s, sd, sdd, sddd) at times ``tau`` in [0, duration]."""
        k, w = self.k, self.window
        t = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration) / k
        S1, s1, sd1, sdd1 = self._base(t)
        S0, s0, sd0, sdd0 = self._base(t - w)
        s = np.clip((S1 - S0) / w, 0.0, 1.0)
        return s, (s1 - s0) / (w * k), (sd1 - sd0) / (w * k * k), (sdd1 - sdd0) / (w * k**3)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        s, sd, sdd, _ = self.evaluate_jerk(tau)
        return s, sd, sdd

    def scaled(self, k: float) -> FilteredLaw:
        """The same law ``k`` times slower."""
        return FilteredLaw(self.base, self.window, self.k * as_positive("k", k))

    def breakpoints(self) -> np.ndarray:
        """Times [s] where the path jerk changes (it is constant between them)."""
        t = np.concatenate([self.base.t, self.base.t + self.window])
        return np.unique(np.clip(t * self.k, 0.0, self.duration))


def _knot_times(law: FilteredLaw, knots: np.ndarray) -> np.ndarray:
    """The times the monotonic law reaches the path's knots (bisection, all at once), and just before each."""
    s_target = np.asarray(knots, dtype=float)
    lo, hi = np.zeros(len(s_target)), np.full(len(s_target), float(law.duration))
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = law.evaluate(mid)[0] < s_target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return np.clip(np.concatenate([hi, hi * (1.0 - 1e-9), hi * (1.0 + 1e-9)]), 0.0, float(law.duration))


def _times(law: FilteredLaw, sub: int, rate: float | None, t_start: float) -> np.ndarray:
    """The breakpoints, each interval's end (the jerk's left limit), ``sub`` points per interval, the rate grid."""
    bp = law.breakpoints()
    parts = [bp, bp[:-1] + np.diff(bp) * (1.0 - 1e-9)]
    parts.append((bp[:-1, None] + np.diff(bp)[:, None] * (np.arange(1, sub) / sub)[None, :]).ravel())
    if rate is not None:
        k0 = math.ceil(t_start * rate - 1e-9)
        k1 = math.floor((t_start + law.duration) * rate + 1e-9)
        parts.append(np.clip(np.arange(k0, k1 + 1) / rate - t_start, 0.0, law.duration))
    return np.concatenate(parts)


class _Table:
    """The path's q and its first three s-derivatives on a fine grid, interpolated linearly (window search)."""

    def __init__(self, path: GeometricPath, n: int = 1000) -> None:
        self.s = np.unique(np.concatenate([np.linspace(0.0, 1.0, n + 1), np.clip(path.knots(), 0.0, 1.0)]))
        self.d = (*path.evaluate(self.s, 2), path_third_derivative(path, self.s))

    def __call__(self, s: np.ndarray) -> tuple[np.ndarray, ...]:
        return tuple(np.column_stack([np.interp(s, self.s, d[:, j]) for j in range(4)]) for d in self.d)


def _joint_values(
    motion: Motion, t: np.ndarray, table: _Table | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(q, qd, qdd, qddd) at local times t: exact, or from the tabulated path."""
    if table is None:
        q, qd, qdd = motion.evaluate(t)
        return q, qd, qdd, joint_jerk(motion, t)
    s, sd, sdd, sddd = motion.law.evaluate_jerk(t)  # type: ignore[attr-defined]
    q, d1, d2, d3 = table(s)
    sd_, sdd_ = sd[:, None], sdd[:, None]
    return q, d1 * sd_, d1 * sdd_ + d2 * sd_**2, d1 * sddd[:, None] + 3.0 * d2 * sd_ * sdd_ + d3 * sd_**3


def _scale(
    robot: Robot, motion: Motion, t: np.ndarray, lim: LimitsInForce, jv: np.ndarray, table: _Table | None = None
) -> tuple[float, JerkRatios]:
    """(k, ratios): the time scale making the worst ratio at times t exactly 1, and the ratios now."""
    k, worst = time_scale(robot, lim, _joint_values(motion, t, table), jv)
    return k, JerkRatios(worst[Quantity.VELOCITY], worst[Quantity.ACCELERATION], worst[Quantity.JERK],
                         worst.get(Quantity.TORQUE))  # fmt: skip


def fir_jerk_limited(
    robot: Robot,
    trajectory: Trajectory,
    jerk: float | ArrayLike,
    *,
    torque: bool = False,
    limits: JointLimits | None = None,
    options: TimingOptions | None = None,
) -> tuple[Trajectory, JerkRatios]:
    """The old, jerk-BOUNDED timing: each TOPP-RA motion filtered (:class:`FilteredLaw`) then slowed as a whole.

    Kept as the baseline the time-optimal :func:`~scara_pin.motion.jerk.time_optimal_jerk` is compared with
    (it is never faster).

    Args:
        robot: the robot (its model for the torques: carry the payload in it, see
            :func:`~scara_pin.motion.payload.with_payload`).
        trajectory: motions timed by :func:`~scara_pin.motion.timing.parameterize` (ProfileLaw each).
        jerk: joint jerk limit [rad/s^3 or m/s^3]: one number for all joints or four.
        torque: also keep the effort limits.
        limits: joint limits instead of ``robot.limits``.
        options: ``check_rate`` of the verification.

    Returns:
        The trajectory and its worst limit ratios (all <= 1 + 1e-10 at the checked samples).

    Raises:
        ParameterError: a jerk limit is not finite and > 0, or a motion is not a TOPP-RA profile.
    """
    opts = TimingOptions() if options is None else options
    jv = jerk_vector(jerk)
    lim = limits_in_force(robot, limits, None, torque)
    out: list[Motion] = []
    ratios: list[JerkRatios] = []
    t_start = 0.0
    for piece in trajectory.pieces:
        if not (isinstance(piece, Motion) and isinstance(piece.law, ProfileLaw)):
            raise ParameterError("trajectory", type(piece).__name__, "must be made of TOPP-RA motions (ProfileLaw)")
        base, path = piece.law, piece.path
        T0 = base.duration
        table = _Table(path)  # the search uses the tabulated path; the final law is verified exactly

        def final_time(w: float, base: ProfileLaw = base, path: GeometricPath = path, table: _Table = table) -> float:
            law = FilteredLaw(base, w)
            k, _ = _scale(robot, Motion(path, law), _times(law, 4, None, 0.0), lim, jv, table)
            return law.duration * k

        # coarse search over w / T0, then golden-section refinement in the best bracket
        grid = np.array([0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5]) * T0
        costs = [final_time(float(w)) for w in grid]
        b = int(np.argmin(costs))
        lo, hi = grid[max(b - 1, 0)], grid[min(b + 1, len(grid) - 1)]
        g = (math.sqrt(5.0) - 1.0) / 2.0
        x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
        f1, f2 = final_time(x1), final_time(x2)
        for _ in range(6):
            if f1 < f2:
                hi, x2, f2 = x2, x1, f1
                x1 = hi - g * (hi - lo)
                f1 = final_time(x1)
            else:
                lo, x1, f1 = x1, x2, f2
                x2 = lo + g * (hi - lo)
                f2 = final_time(x2)
        w = float(min([(costs[b], grid[b]), (f1, x1), (f2, x2)])[1])
        law = FilteredLaw(base, w)
        k, _ = _scale(robot, Motion(path, law), _times(law, _SUB, None, 0.0), lim, jv)
        law = law.scaled(k)
        for _ in range(8):
            # the law's breakpoints, the rate grid, and both sides of the path's knots (where q''' jumps: the
            # joints' jerk has its one-sided extremes there, which the rate grid alone steps over)
            t = np.concatenate([_times(law, _SUB, opts.check_rate, t_start), _knot_times(law, path.knots())])
            k, r = _scale(robot, Motion(path, law), t, lim, jv)
            if k <= _ACCEPT:
                break
            law = law.scaled(k * (1.0 + 1e-12))
        else:  # pragma: no cover - time scaling is exact
            raise TimingError("VerificationFailed", f"the jerk-limited law could not reach ratio 1 ({r.worst:.12g})")
        out.append(Motion(path, law))
        ratios.append(r)
        t_start += law.duration
    tops = [r.torque for r in ratios if r.torque is not None]
    worst = JerkRatios(max(r.velocity for r in ratios), max(r.acceleration for r in ratios),
                       max(r.jerk for r in ratios), max(tops) if tops else None)  # fmt: skip
    return Trajectory(tuple(out)), worst
