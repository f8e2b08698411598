"""Jerk-limited TIME-OPTIMAL timing of a path: joint velocity, acceleration, jerk (and torque) limits, each local.

The law is found by direct collocation in time, solved by IPOPT (casadi); the path ``q(s)`` is followed
exactly (only the time law ``s(t)`` is computed). With N intervals of equal length h = T / N and a
constant path jerk ``c_k`` on each, ``s(t)`` is a C2 piecewise cubic, integrated exactly:

    s_{k+1} = s_k + h sd_k + h^2 sdd_k / 2 + h^3 c_k / 6,   sd_{k+1} = sd_k + h sdd_k + h^2 c_k / 2,
    sdd_{k+1} = sdd_k + h c_k,        rest at both ends: (s, sd, sdd) = (0, 0, 0) and (1, 0, 0).

Minimise T subject to, at sigma = 0, 1/2, 1 of every interval (the jerk at both sides of every node),

    |q'(s) sd| <= vmax,   |q'(s) sdd + q''(s) sd^2| <= amax,
    |q'(s) c + 3 q''(s) sd sdd + q'''(s) sd^3| <= jmax,   |a(s) sdd + b(s) sd^2 + g(s)| <= tau_max

(torques as in :mod:`~scara_pin.motion.timing`: ``g = rnea(q, 0, 0)``, ``a = rnea(q, 0, q') - g``,
``b = rnea(q, q', q'') - g``). Each limit binds where it binds: there is no global slow-down. Working in
time avoids the rest-to-rest singularity of the s-domain (sd = 0 at both ends, where a jerk-limited start
has ``sd ~ s^(2/3)``, no polynomial in s).

**The path inside the NLP.** The path derivatives are evaluated EXACTLY (:meth:`GeometricPath.evaluate`,
:func:`~scara_pin.motion.verify.path_third_derivative`) at the collocation points of the current iterate
and expanded to second order in ``s - s_bar`` (q' + q'' ds + q''' ds^2 / 2, q'' + q''' ds, q''') inside a
trust region |s - s_bar| <= delta: a sequence of NLPs, each warm-started from the last, delta halved after
the first few, until the points stop moving (1e-9 in s). At convergence every constraint holds with the
exact path at every collocation point.

**Between the points** (the promise is the :mod:`~scara_pin.motion.verify` grid, 10 kHz): the exact joint
states q, qd, qdd, qddd are computed at sigma = 0, 1/4, 1/2, 3/4 and 1- of every interval (and densely in
the intervals that hold a knot of the path, where q''' jumps), interpolated by the quartic through them
(errors ~ (h / T_phase)^5) at :data:`_DENSE` points per interval, and the time scale k that brings the
worst ratio there to 1 is applied (:func:`~scara_pin.motion.verify.time_scale`): a final correction of a
few 1e-4 at most (reported as ``correction``), never the old global slow-down.

**Initial guess**: the TOPP-RA profile filtered by a moving average (:class:`~scara_pin.motion.jerk_fir.FilteredLaw`).

Why IPOPT through casadi: the NLP is small (4 N + 1 variables), sparse, smooth; IPOPT with casadi's exact
Hessians converges in 20-60 iterations from the filtered profile and every step is robust to an
infeasible start. A sequential LP (HiGHS) needs a merit function and more iterations; the s-domain SOCP
(Clarabel) cannot represent the jerk-limited rest. casadi is imported only inside the solver (about
0.15 s). See ``docs/jerk.md``.
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import _positive
from ..errors import InfeasibleError, ParameterError
from ..limits import MAX_SAMPLES, check_count
from .paths import CartesianPath, GeometricPath, joint_path
from .timing import TimingError, TimingOptions, parameterize
from .trajectory import Motion, ProfileLaw, TimeLaw, Trajectory
from .verify import (
    VERIFY_RATE,
    Quantity,
    _Limits,
    _limits,
    _rnea,
    jerk_vector,
    joint_jerk,
    path_third_derivative,
    state_ratios,
    time_scale,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..description import JointLimits
    from ..model import Robot

__all__ = ["JerkLaw", "JerkOptions", "JerkRatios", "JerkResult", "jerk_limited", "minimum_duration",
           "time_optimal_jerk"]  # fmt: skip

logger = logging.getLogger(__name__)

_SIGMA = (0.0, 0.5, 1.0)
"""Collocation points in each interval (fractions of h)."""
_CHECK_SIGMA = np.array([0.0, 0.25, 0.5, 0.75, 1.0 - 1e-9])
"""Exact evaluation points of the final check in each interval (the quartic through them interpolates)."""
_DENSE = 48
"""Interpolated points per interval in the final check (h / 48 < 0.1 ms for h < 4.8 ms)."""
_KNOT_DENSE = 64
"""Exact points in an interval that holds a knot of the path (q''' jumps there: no interpolation)."""
_FIRST_DELTA = 0.05
"""Trust region in s of the first NLPs; halved each time after the first three."""
_S_TOL = 1e-7
"""Convergence: the collocation points moved less than this in s (the expansion is then exact to ~1e-14)."""
_MARGIN = 2e-6
"""The final time margin (relative) over the checked grid."""
_T_TOL = 1e-7
"""Convergence also when the duration changed less than this (relative) and the exact path data are kept."""
_ACCEPT = 1.0 + 1e-9
"""The final correction brings the worst checked ratio to 1; this small margin covers rounding."""
_CORRECTION_MAX = 0.02
_TIGHTEN_ROUNDS = 6
"""NLP rounds with the limits tightened where the dense check found them exceeded."""
_BINS = 2000
"""Bins of s that carry the local tightening of the limits."""
_TIGHT_TOL = 1e-3
"""Between-point excess left to the final uniform correction (a time scale of at most ~1e-3)."""
"""A final correction above 2 % means the NLP did not converge to the exact path: an error, not a slow motion."""


@dataclass(frozen=True)
class JerkOptions:
    """Options of :func:`time_optimal_jerk`.

    Attributes:
        intervals: N, the intervals of constant path jerk (more: closer to the continuous optimum, slower
            to plan; 40 is within about 0.3 % of the optimum on the moves tested, see ``docs/jerk.md``).
        max_iterations: the largest number of NLPs (each warm-started) before giving up.
        ipopt_iterations: IPOPT's iteration limit per NLP.
        check_rate: [Hz] the verification rate the duration is sized for (the samples a trajectory of the
            implied duration would need, against :data:`~scara_pin.limits.MAX_SAMPLES`).
    """

    intervals: int = 40
    max_iterations: int = 25
    ipopt_iterations: int = 500
    check_rate: float = VERIFY_RATE

    def __post_init__(self) -> None:
        for name, low, high in (("intervals", 8, 2000), ("max_iterations", 1, 1000), ("ipopt_iterations", 10, 100000)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not low <= v <= high:
                raise ParameterError(name, v, f"must be an integer in [{low}, {high}]")
        _positive("check_rate", self.check_rate, "Hz")


@dataclass(frozen=True)
class JerkRatios:
    """Worst |value| / limit over the checked samples of a jerk-limited trajectory.

    Attributes:
        velocity, acceleration, jerk: max over joints and samples.
        torque: of the effort limits, or None when not limited.
    """

    velocity: float
    acceleration: float
    jerk: float
    torque: float | None = None

    @property
    def worst(self) -> float:
        """The largest of the ratios."""
        return max(v for v in (self.velocity, self.acceleration, self.jerk, self.torque) if v is not None)


# ---------------------------------------------------------------------------------------------- the law
@dataclass(frozen=True, eq=False)
class JerkLaw(TimeLaw):
    """s(t): constant path jerk ``c[k]`` on ``[t[k], t[k+1]]``, from rest at s = 0 to rest at s = 1 (C2).

    The node states are integrated exactly from rest; :meth:`from_jerks` first corrects the jerks by the
    least-norm change that makes the end exactly (1, 0, 0).

    Attributes:
        t: (N + 1,) node times from 0 [s].
        c: (N,) path jerks [1/s^3].
        knots: the path's knots that nodes sit on (a node within 1e-9 of one starts exactly at it).
        s, sd, sdd: (N + 1,) node states (derived).
        duration: t[-1] [s].
    """

    t: np.ndarray
    c: np.ndarray
    knots: tuple[float, ...] = ()
    s: np.ndarray = field(init=False)
    sd: np.ndarray = field(init=False)
    sdd: np.ndarray = field(init=False)
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=float)
        c = np.array(self.c, dtype=float)
        if t.ndim != 1 or c.shape != (len(t) - 1,) or len(t) < 2:
            raise ParameterError("jerk law", f"shapes {t.shape}, {c.shape}", "must be (N + 1,) times and (N,) jerks")
        h = np.diff(t)
        if not (np.isfinite(t).all() and np.isfinite(c).all() and t[0] == 0.0 and (h > 0).all()):
            raise ParameterError("jerk law", "times or jerks", "must be finite, the times increasing from 0")
        s, sd, sdd = _integrate(h, c)
        for kn in self.knots:  # a node on a knot of the path starts exactly there (its piece, its jerk)
            near = np.abs(s - kn) < 1e-9
            s[near] = kn
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "c", c)
        object.__setattr__(self, "s", s)
        object.__setattr__(self, "sd", sd)
        object.__setattr__(self, "sdd", sdd)
        object.__setattr__(self, "duration", float(t[-1]))

    @classmethod
    def from_jerks(cls, t: np.ndarray, c: np.ndarray, knots: tuple[float, ...] = ()) -> JerkLaw:
        """The law with times t and the jerks nearest ``c`` (least norm) that end exactly at rest at s = 1."""
        h = np.diff(np.asarray(t, dtype=float))
        c = np.asarray(c, dtype=float)
        E = _end_map(h)  # (s, sd, sdd)_N = E @ c
        c = c + np.linalg.lstsq(E, np.array([1.0, 0.0, 0.0]) - E @ c, rcond=None)[0]
        return cls(t, c, knots)

    def evaluate_jerk(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(s, sd, sdd, sddd) at times ``tau`` (held at the ends outside [0, duration])."""
        tau = np.asarray(tau, dtype=float)
        tc = np.clip(tau, 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tc, side="right") - 1, 0, len(self.c) - 1)
        d = tc - self.t[i]
        c = self.c[i]
        s = self.s[i] + self.sd[i] * d + self.sdd[i] * d * d / 2.0 + c * d**3 / 6.0
        sd = self.sd[i] + self.sdd[i] * d + c * d * d / 2.0
        sdd = self.sdd[i] + c * d
        # within its interval (the next node excluded): a node on a knot of the path is reached from the
        # left on the left piece, with the left interval's jerk
        s = np.clip(s, self.s[i], np.maximum(np.nextafter(self.s[i + 1], -np.inf), self.s[i]))
        s = np.where(tc >= self.duration, self.s[-1], s)
        out = (tau < 0.0) | (tau > self.duration)
        return np.clip(s, 0.0, 1.0), np.where(out, 0.0, sd), np.where(out, 0.0, sdd), np.where(out, 0.0, c)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        s, sd, sdd, _ = self.evaluate_jerk(tau)
        return s, sd, sdd

    def scaled(self, k: float) -> JerkLaw:
        """The same law ``k`` times slower (times * k, jerks / k^3), exactly."""
        k = _positive("k", k)
        return JerkLaw(self.t * k, self.c / k**3, self.knots)

    def breakpoints(self) -> np.ndarray:
        """The node times [s] (the path jerk is constant between them)."""
        return self.t.copy()


def _integrate(h: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n = len(c)
    s, sd, sdd = np.zeros(n + 1), np.zeros(n + 1), np.zeros(n + 1)
    for k in range(n):
        hk, ck = h[k], c[k]
        s[k + 1] = s[k] + hk * sd[k] + hk * hk * sdd[k] / 2.0 + hk**3 * ck / 6.0
        sd[k + 1] = sd[k] + hk * sdd[k] + hk * hk * ck / 2.0
        sdd[k + 1] = sdd[k] + hk * ck
    return s, sd, sdd


def _end_map(h: np.ndarray) -> np.ndarray:
    """E (3, N): the end state (s, sd, sdd) from rest is E @ c (the integration is linear in c)."""
    n = len(h)
    E = np.empty((3, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = 1.0
        s, sd, sdd = _integrate(h, e)
        E[:, k] = s[-1], sd[-1], sdd[-1]
    return E


# ---------------------------------------------------------------------------------------------- sizing
def minimum_duration(path: GeometricPath, jerk: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> float:
    """[s] a lower bound of the rest-to-rest duration along ``path``, from its endpoints alone.

    Each joint must cover d = |q_j(1) - q_j(0)| from rest to rest; with only a jerk limit J that takes at
    least (32 d / J)^(1/3) (four phases of +J, -J, -J, +J), with only an acceleration limit 2 sqrt(d / A),
    with only a velocity limit d / V; the duration is at least the largest.
    """
    q = path.evaluate(np.array([0.0, 1.0]), 0)[0]
    d = np.abs(q[1] - q[0])
    return float(np.max(np.maximum.reduce([np.cbrt(32.0 * d / jerk), 2.0 * np.sqrt(d / acceleration), d / velocity])))


def _size(path: GeometricPath, jv: np.ndarray, lim: _Limits, opts: JerkOptions) -> None:
    """Refuse (exit 2) a jerk limit whose implied duration needs more verified samples than the cap."""
    T = minimum_duration(path, jv, lim.velocity, lim.acceleration)
    check_count(f"verified samples of the jerk-limited motion (at least {T:.3g} s at {opts.check_rate:g} Hz)",
                T * opts.check_rate, MAX_SAMPLES, "the jerk limit is too low for this move (raise it)")  # fmt: skip


# ---------------------------------------------------------------------------------------------- the NLP
@functools.lru_cache(maxsize=8)
def _nlp(n: int, torque: bool, dof: int, ipopt_iterations: int) -> Any:
    """The parametric NLP (casadi/IPOPT) for n intervals: built once per shape, reused for every path.

    Variables x = (H, s, p, r, c) in the reference time T_ref (parameters): H the interval length in units
    of T_ref / n (equal on every interval), p = T_ref sd, r = T_ref^2 sdd, c = T_ref^3 sddd. Parameters:
    the collocation points' s_bar, the path data there, the limits in reference units.
    """
    import casadi as ca

    H = ca.SX.sym("H", n)
    S, P, R, C = ca.SX.sym("s", n + 1), ca.SX.sym("p", n + 1), ca.SX.sym("r", n + 1), ca.SX.sym("c", n)
    npt = len(_SIGMA) * n
    cols = (6 if torque else 3) * dof
    par = ca.SX.sym("par", npt * (1 + cols + 4 * dof))
    s_bar = par[:npt]
    D = ca.reshape(par[npt : npt * (1 + cols)], npt, cols)
    L = ca.reshape(par[npt * (1 + cols) :], npt, 4 * dof)  # the limits at each point (tightened locally)
    h = H / n
    dyn = [S[1:] - (S[:-1] + h * P[:-1] + h**2 / 2 * R[:-1] + h**3 / 6 * C),
           P[1:] - (P[:-1] + h * R[:-1] + h**2 / 2 * C), R[1:] - (R[:-1] + h * C), H[1:] - H[:-1]]  # fmt: skip
    pts = []
    for k in range(n):
        for sig in _SIGMA:
            t = sig * h[k]
            pts.append((S[k] + P[k] * t + R[k] * t**2 / 2 + C[k] * t**3 / 6, P[k] + R[k] * t + C[k] * t**2 / 2,
                        R[k] + C[k] * t, C[k]))  # fmt: skip
    sp, pp, rp, cp = (ca.vertcat(*[x[i] for x in pts]) for i in range(4))
    ds = sp - s_bar
    cons = []
    for j in range(dof):
        D1, D2, D3 = D[:, j], D[:, dof + j], D[:, 2 * dof + j]
        d1 = D1 + D2 * ds + D3 * ds**2 / 2
        d2 = D2 + D3 * ds
        cons += [d1 * pp / L[:, j], (d1 * rp + d2 * pp**2) / L[:, dof + j],
                 (d1 * cp + 3 * d2 * pp * rp + D3 * pp**3) / L[:, 2 * dof + j]]  # fmt: skip
        if torque:
            A, B, G = D[:, 3 * dof + j], D[:, 4 * dof + j], D[:, 5 * dof + j]
            cons.append((A * rp + B * pp**2 + G) / L[:, 3 * dof + j])
    nlp = {"x": ca.vertcat(H, S, P, R, C), "f": ca.sum1(H) / n, "g": ca.vertcat(*dyn, *cons, pp, ds), "p": par}
    opts: dict[str, Any] = {"ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-8,
            "ipopt.max_iter": ipopt_iterations, "ipopt.warm_start_init_point": "yes",
            "ipopt.mu_init": 1e-3}  # fmt: skip
    g = ca.Function("jerk_constraints", [nlp["x"], par], [nlp["g"]])
    return ca.nlpsol("jerk_time_optimal", "ipopt", nlp, opts), g, 4 * n - 1, len(cons) * npt, npt


def _bin(s: np.ndarray | float) -> np.ndarray:
    """The bin of s in [0, 1] (_BINS of them)."""
    return np.clip((np.asarray(s) * _BINS).astype(int), 0, _BINS - 1)


def _path_data(robot: Robot, path: GeometricPath, s: np.ndarray, torque: bool) -> np.ndarray:
    """(n, 3 dof) q', q'', q''' at s, and with ``torque`` the RNEA coefficients a, b, g: (n, 6 dof)."""
    q, d1, d2 = path.evaluate(s, 2)
    cols = [d1, d2, path_third_derivative(path, s)]
    if torque:
        zero = np.zeros_like(d1)
        g = _rnea(robot, q, zero, zero)
        cols += [_rnea(robot, q, zero, d1) - g, _rnea(robot, q, d1, d2) - g, g]
    return np.hstack(cols)


def _points(x: np.ndarray, n: int) -> np.ndarray:
    """The collocation points' s for the variables x."""
    H, S, P, R, C = (x[:n], x[n : 2 * n + 1], x[2 * n + 1 : 3 * n + 2], x[3 * n + 2 : 4 * n + 3],
                     x[4 * n + 3 :])  # fmt: skip
    t = np.array(_SIGMA)[None, :] * (H[:, None] / n)
    return (S[:-1, None] + P[:-1, None] * t + R[:-1, None] * t**2 / 2 + C[:, None] * t**3 / 6).ravel()


class _Solver:
    """The sequence of NLPs on one path (module docstring), warm-started, with per-point limit factors."""

    def __init__(self, robot: Robot, path: GeometricPath, base: ProfileLaw, lim: _Limits, jv: np.ndarray,
                 opts: JerkOptions, segment: int) -> None:  # fmt: skip
        from .jerk_fir import FilteredLaw

        n = opts.intervals
        self.robot, self.path, self.lim, self.jv, self.opts, self.segment = robot, path, lim, jv, opts, segment
        self.dof = len(lim.velocity)
        self.torque = lim.effort is not None
        self.solver, self.g, self.n_dyn, self.n_con, self.npt = _nlp(n, self.torque, self.dof, opts.ipopt_iterations)
        guess = FilteredLaw(base, 0.15 * base.duration)
        self.Tr = Tr = guess.duration
        s0, sd0, sdd0, _ = guess.evaluate_jerk(np.linspace(0.0, 1.0, n + 1) * Tr)
        self.x = np.concatenate([np.ones(n), s0, sd0 * Tr, sdd0 * Tr**2, np.diff(sdd0 * Tr**2) * n])
        o = n
        self.lbx, self.ubx = np.full(len(self.x), -np.inf), np.full(len(self.x), np.inf)
        self.lbx[:n] = 1e-3
        self.lbx[o : o + n + 1], self.ubx[o : o + n + 1] = 0.0, 1.0
        self.lbx[o + n + 1 : o + 2 * n + 2] = 0.0
        for i, value in ((o, 0.0), (o + n, 1.0), (o + n + 1, 0.0), (o + 2 * n + 1, 0.0), (o + 2 * n + 2, 0.0),
                         (o + 3 * n + 2, 0.0)):  # fmt: skip
            self.lbx[i] = self.ubx[i] = value
        # nodes pinned at the path's knots (the third derivative jumps there): the node nearest the guess's
        # crossing time; the interval length is equal within each smooth piece, free from one piece to the next
        knots = np.unique(np.clip(path.knots(), 0.0, 1.0))[1:-1]
        cross = np.interp(knots, s0, np.arange(n + 1)) if len(knots) else np.zeros(0)
        nodes = np.clip(np.round(cross).astype(int), 1, n - 1)
        if len(nodes) and ((np.diff(nodes) < 1).any() or len(nodes) > n // 4):
            raise TimingError("JerkNLP", f"the path has {len(knots)} knots too close in time for {n} intervals "
                              "(more intervals needed)", segment=segment)  # fmt: skip
        for m, kn in zip(nodes, knots):
            self.lbx[o + m] = self.ubx[o + m] = kn
        self.knot_nodes, self.knots = nodes, knots
        self.chain_free = np.zeros(n - 1, dtype=bool)
        self.chain_free[nodes - 1] = True  # row k of H[k+1] - H[k]: free where node k + 1 is a knot
        e = lim.effort if lim.effort is not None else np.ones(self.dof)
        self.limits = np.concatenate([lim.velocity * Tr, lim.acceleration * Tr**2, jv * Tr**3, e])
        self.warm: dict[str, Any] = {}
        self.nlps = 0

    def _feasible(self, x: np.ndarray) -> bool:
        """True when x keeps every limit (1e-6) with the EXACT path data at its own collocation points."""
        n = self.opts.intervals
        s_bar = np.clip(_points(x, n), 0.0, 1.0)
        s_eval = s_bar.copy()
        s_eval[len(_SIGMA) * (self.knot_nodes - 1) + len(_SIGMA) - 1] = self.knots - 1e-12
        D = _path_data(self.robot, self.path, s_eval, self.torque)
        L = (self.limits[None, :] * self.tight[_bin(s_bar)]).ravel(order="F")
        g = np.asarray(self.g(x, np.concatenate([s_bar, D.ravel(order="F"), L])), dtype=float).ravel()
        return bool(np.all(np.abs(g[self.n_dyn : self.n_dyn + self.n_con]) <= 1.0 + 1e-6))

    def run(self, tight: np.ndarray) -> JerkLaw:
        """Solve with the limits multiplied by ``tight`` (_BINS, 4 dof: a factor per bin of s), until converged."""
        n, npt, x = self.opts.intervals, self.npt, self.x
        self.tight = tight
        delta = _FIRST_DELTA
        for it in range(self.opts.max_iterations):
            s_bar = np.clip(_points(x, n), 0.0, 1.0)
            L = (self.limits[None, :] * tight[_bin(s_bar)]).ravel(order="F")
            s_eval = s_bar.copy()
            s_eval[len(_SIGMA) * (self.knot_nodes - 1) + len(_SIGMA) - 1] = self.knots - 1e-12  # the left side
            D = _path_data(self.robot, self.path, s_eval, self.torque)
            if not np.isfinite(D).all():
                raise TimingError("JerkNLP", "the path derivatives are not finite (a singular point)",
                                  segment=self.segment)  # fmt: skip
            lbg = np.concatenate([np.zeros(self.n_dyn), -np.ones(self.n_con), np.zeros(npt), np.full(npt, -delta)])
            ubg = np.concatenate([np.zeros(self.n_dyn), np.ones(self.n_con), np.full(npt, np.inf), np.full(npt, delta)])
            chain = slice(3 * n, 4 * n - 1)
            lbg[chain] = np.where(self.chain_free, -np.inf, 0.0)
            ubg[chain] = np.where(self.chain_free, np.inf, 0.0)
            res = self.solver(x0=x, lbx=self.lbx, ubx=self.ubx, lbg=lbg, ubg=ubg,
                              p=np.concatenate([s_bar, D.ravel(order="F"), L]), **self.warm)  # fmt: skip
            self.nlps += 1
            status = self.solver.stats()["return_status"]
            if status not in ("Solve_Succeeded", "Solved_To_Acceptable_Level"):
                raise TimingError("JerkNLP", f"IPOPT did not converge ({status}) on NLP {self.nlps}",
                                  segment=self.segment)  # fmt: skip
            x_new = np.asarray(res["x"], dtype=float).ravel()
            self.warm = {"lam_x0": res["lam_x"], "lam_g0": res["lam_g"]}
            step = float(np.max(np.abs(_points(x_new, n) - s_bar)))
            T_change = abs(x_new[0] - x[0]) / x[0] if it else math.inf
            x = x_new
            logger.debug("segment %d NLP %d: T = %.9f s, step %.3g", self.segment, self.nlps, x[0] * self.Tr, step)
            if step < _S_TOL or (T_change < _T_TOL and self._feasible(x)):
                break
            if it >= 2:
                delta = max(delta / 2.0, 1e-12)
        else:
            raise TimingError("JerkNLP", f"the collocation points still move after {self.opts.max_iterations} NLPs",
                              segment=self.segment)  # fmt: skip
        self.x = x
        t = np.concatenate([[0.0], np.cumsum(x[:n] * self.Tr / n)])
        return JerkLaw.from_jerks(t, x[n + 3 * n + 3 :] / self.Tr**3, tuple(self.knots.tolist()))


def _states(motion: Motion, law: JerkLaw, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """(q, qd, qdd, qddd) at times t, from exact values at sigma = 0, 1/4, 1/2, 3/4, 1- of each interval.

    Interpolated by the quartic through them; exact where the interval holds a knot of the path.
    """
    t = np.clip(np.asarray(t, dtype=float), 0.0, law.duration)
    n = len(law.c)
    i = np.clip(np.searchsorted(law.t, t, side="right") - 1, 0, n - 1)
    h = np.diff(law.t)
    sig = (t - law.t[i]) / h[i]
    knots = np.unique(np.clip(motion.path.knots(), 0.0, 1.0))[1:-1]
    rough = np.asarray(((knots[None, :] > law.s[:-1, None] - 1e-12) & (knots[None, :] < law.s[1:, None] + 1e-12))
                       .any(axis=1), dtype=bool)  # fmt: skip
    exact = rough[i]
    need = np.unique(i[~exact])
    out = [np.empty((len(t), motion.path.dof if hasattr(motion.path, "dof") else 4)) for _ in range(4)]
    if len(need):
        tt = (law.t[need, None] + h[need, None] * _CHECK_SIGMA[None, :]).ravel()
        vals = (*motion.evaluate(tt), joint_jerk(motion, tt))
        row = np.full(n, -1)
        row[need] = np.arange(len(need))
        sel = np.nonzero(~exact)[0]
        W = _lagrange(_CHECK_SIGMA, sig[sel])  # (m, 5)
        r = row[i[sel]]
        for o, v in zip(out, vals):
            V = v.reshape(len(need), len(_CHECK_SIGMA), -1)
            o[sel] = np.einsum("ms,msj->mj", W, V[r])
    if exact.any():
        sel = np.nonzero(exact)[0]
        tt = t[sel]
        for o, v in zip(out, (*motion.evaluate(tt), joint_jerk(motion, tt))):
            o[sel] = v
    return tuple(out)


def _interval_ratios(motion: Motion, law: JerkLaw, lim: _Limits, jv: np.ndarray, robot: Robot) -> np.ndarray:
    """(N, 4 dof): per interval the worst ratio of velocity, acceleration, jerk, torque of each joint."""
    n = len(law.c)
    sig = np.linspace(0.0, 1.0 - 1e-9, _DENSE)
    t = (law.t[:-1, None] + np.diff(law.t)[:, None] * sig[None, :]).ravel()
    q, qd, qdd, qddd = _states(motion, law, t)
    r = state_ratios(robot, lim, q, qd, qdd, qddd, jv)
    dof = q.shape[1]
    out = np.zeros((n, 4 * dof))
    for b, quantity in enumerate((Quantity.VELOCITY, Quantity.ACCELERATION, Quantity.JERK, Quantity.TORQUE)):
        if quantity in r:
            out[:, b * dof : (b + 1) * dof] = r[quantity].reshape(n, _DENSE, dof).max(axis=1)
    return out


def _final_scale(
    robot: Robot, motion: Motion, law: JerkLaw, lim: _Limits, jv: np.ndarray, t_start: float, rate: float
) -> tuple[float, JerkRatios]:
    """(k, ratios) on the trajectory's ``rate`` grid that falls in this motion, its nodes (both sides) and knots."""
    T = law.duration
    k0, k1 = math.ceil(t_start * rate - 1e-9), math.floor((t_start + T) * rate + 1e-9)
    # the nodes sit on the knots: both sides of every node are both sides of every knot
    t = np.concatenate([np.arange(k0, k1 + 1) / rate - t_start, law.t, law.t[1:] - np.diff(law.t) * 1e-9])
    q, qd, qdd, qddd = _states(motion, law, np.clip(t, 0.0, T))
    k, worst = time_scale(robot, lim, q, qd, qdd, qddd, jv)
    return k, JerkRatios(worst[Quantity.VELOCITY], worst[Quantity.ACCELERATION], worst[Quantity.JERK],
                         worst.get(Quantity.TORQUE))  # fmt: skip


def _lagrange(nodes: np.ndarray, x: np.ndarray) -> np.ndarray:
    """W (len(x), len(nodes)): the Lagrange basis of ``nodes`` at x."""
    W = np.ones((len(x), len(nodes)))
    for i, xi in enumerate(nodes):
        for j, xj in enumerate(nodes):
            if i != j:
                W[:, i] *= (x - xj) / (xi - xj)
    return W


# ---------------------------------------------------------------------------------------------- public
@dataclass(frozen=True, eq=False)
class JerkResult:
    """A jerk-limited time-optimal trajectory and how it was obtained.

    Attributes:
        trajectory: one motion (a :class:`JerkLaw`) per path segment.
        ratios: worst limit ratios over the final check.
        correction: the final time scale k >= ... (1 + a few 1e-4 at most): the duration is k times the NLP's.
        nlps: the number of NLPs solved (all segments).
        options: the options used.
    """

    trajectory: Trajectory
    ratios: JerkRatios
    correction: float
    nlps: int
    options: JerkOptions = field(default_factory=JerkOptions)


def time_optimal_jerk(
    robot: Robot,
    path: GeometricPath | CartesianPath | Sequence[ArrayLike] | np.ndarray,
    jerk: float | ArrayLike,
    *,
    torque: bool = False,
    limits: JointLimits | None = None,
    options: JerkOptions | None = None,
    timing_options: TimingOptions | None = None,
) -> JerkResult:
    """The minimum-time, rest-to-rest motion along ``path`` under joint velocity, acceleration, jerk (torque) limits.

    Args:
        robot: the robot (limits; its model for the torques: carry a payload with
            :func:`~scara_pin.motion.payload.with_payload`).
        path: a path, a :class:`~scara_pin.motion.paths.CartesianPath` (each segment rest to rest: the tool
            stops at every via point, where the line turns), or (m, 4) joint waypoints.
        jerk: joint jerk limit [rad/s^3 or m/s^3], one number or one per joint.
        torque: also keep the effort limits (RNEA, gravity included).
        limits: joint limits instead of ``robot.limits``.
        options: the NLP's options.
        timing_options: TOPP-RA's options (the initial guess).

    Raises:
        ParameterError: a limit is NaN, zero, negative or not finite.
        InvalidInputError: the jerk limit implies a duration whose verified samples exceed the cap.
        TimingError: the NLP did not converge (IPOPT's status), or TOPP-RA failed on the path.
    """
    opts = JerkOptions() if options is None else options
    if isinstance(path, CartesianPath):
        paths: tuple[GeometricPath, ...] = path.segments
    elif isinstance(path, GeometricPath):
        paths = (path,)
    else:
        paths = (joint_path(robot, path),)
    lim = _limits(robot, limits, None, torque)
    jv = jerk_vector(jerk, len(lim.velocity))
    for p in paths:
        _size(p, jv, lim, opts)
    base = parameterize(robot, path if not isinstance(path, (list, tuple, np.ndarray)) else paths[0], torque=torque,
                        limits=limits, options=timing_options)  # fmt: skip
    return _time_motions(robot, [m for m in base.trajectory.pieces if isinstance(m, Motion)], lim, jv, opts)


def _time_motions(
    robot: Robot, motions: Sequence[Motion], lim: _Limits, jv: np.ndarray, opts: JerkOptions
) -> JerkResult:
    """Each motion's path timed by the NLP, tightened locally where it exceeds a limit between its points."""
    out: list[Motion] = []
    ratios: list[JerkRatios] = []
    k_max, nlps, t_start = 1.0, 0, 0.0
    for segment, m in enumerate(motions):
        if not isinstance(m.law, ProfileLaw):
            raise ParameterError("trajectory", type(m.law).__name__, "must be made of TOPP-RA motions (ProfileLaw)")
        solver = _Solver(robot, m.path, m.law, lim, jv, opts, segment)
        tight = np.ones((_BINS, 4 * solver.dof))
        for _ in range(_TIGHTEN_ROUNDS):
            law = solver.run(tight)
            try:
                over = _interval_ratios(Motion(m.path, law), law, lim, jv, robot)
            except InfeasibleError as exc:
                raise TimingError("VerificationFailed", str(exc), segment=segment) from None
            if over.max() <= 1.0 + _TIGHT_TOL:
                break
            # the limits where an interval exceeded them (the bins of s it covers), divided by the excess: the
            # tightening stays at that place of the path while the intervals move over it
            for i in np.nonzero(over.max(axis=1) > 1.0 + _TIGHT_TOL)[0].tolist():
                bins = np.arange(int(_bin(law.s[i])), int(_bin(law.s[i + 1])) + 1)
                tight[bins] = tight[bins] / np.maximum(over[i], 1.0) / (1.0 + _TIGHT_TOL / 2)
        k = 1.0
        for _ in range(8):  # the time scale that brings the worst ratio on the final grid into [1 - 1e-7, 1 + 1e-9]
            k_step, r = _final_scale(robot, Motion(m.path, law), law, lim, jv, t_start, opts.check_rate)
            if 1.0 - 1e-7 <= k_step <= _ACCEPT:
                break
            law = law.scaled(k_step * (1.0 + 1e-12))
            k *= k_step * (1.0 + 1e-12)
        # a margin of 2e-6 in time (4e-6 of the accelerations): the limits then hold at ANY time, not only on
        # the checked grid (an 8 kHz grid found 1.1e-6 of excess between the 10 kHz samples without it)
        law = law.scaled(1.0 + _MARGIN)
        k *= 1.0 + _MARGIN
        _, r = _final_scale(robot, Motion(m.path, law), law, lim, jv, t_start, opts.check_rate)
        if not k <= 1.0 + _CORRECTION_MAX:
            raise TimingError("JerkNLP", f"the solution exceeds a limit by {k - 1:.3g} (time scale) between its "
                              "collocation points: more intervals needed", segment=segment)  # fmt: skip
        out.append(Motion(m.path, law))
        ratios.append(r)
        k_max, nlps, t_start = max(k_max, float(k)), nlps + solver.nlps, t_start + law.duration
    tops = [r.torque for r in ratios if r.torque is not None]
    worst = JerkRatios(max(r.velocity for r in ratios), max(r.acceleration for r in ratios),
                       max(r.jerk for r in ratios), max(tops) if tops else None)  # fmt: skip
    return JerkResult(Trajectory(tuple(out)), worst, k_max, nlps, opts)


def jerk_limited(
    robot: Robot,
    trajectory: Trajectory,
    jerk: float | ArrayLike,
    *,
    torque: bool = False,
    limits: JointLimits | None = None,
    options: TimingOptions | None = None,
) -> tuple[Trajectory, JerkRatios]:
    """Each TOPP-RA motion of ``trajectory`` re-timed time-optimally under a joint jerk limit (module docstring).

    Args:
        robot: the robot (its model for the torques: carry the payload in it, see
            :func:`~scara_pin.motion.payload.with_payload`).
        trajectory: motions timed by :func:`~scara_pin.motion.timing.parameterize` (ProfileLaw each): their
            paths, and their profiles as the initial guess.
        jerk: joint jerk limit [rad/s^3 or m/s^3]: one number for all joints or one per joint.
        torque: also keep the effort limits.
        limits: joint limits instead of ``robot.limits``.
        options: unused by the solver (kept for the callers' signature); see :func:`time_optimal_jerk`.

    Returns:
        The trajectory and its worst limit ratios over the final check.

    Raises:
        ParameterError: a jerk limit is not finite and > 0, or a motion is not a TOPP-RA profile.
        InvalidInputError: the jerk limit implies more verified samples than the cap.
        TimingError: the NLP did not converge.
    """
    del options
    lim = _limits(robot, limits, None, torque)
    jv = jerk_vector(jerk, len(lim.velocity))
    motions = []
    for piece in trajectory.pieces:
        if not isinstance(piece, Motion):
            raise ParameterError("trajectory", type(piece).__name__, "must be made of TOPP-RA motions (ProfileLaw)")
        motions.append(piece)
    opts = JerkOptions()
    for m in motions:
        _size(m.path, jv, lim, opts)
    res = _time_motions(robot, motions, lim, jv, opts)
    return res.trajectory, res.ratios

