"""Jerk-limited TIME-OPTIMAL timing of a path: joint velocity, acceleration, jerk (and torque) limits, each local.

The path ``q(s)`` is followed exactly; only the time law ``s(t)`` is computed, by direct collocation in
time solved by IPOPT (casadi). The law has N intervals of free lengths h_k and a constant path jerk
``c_k`` on each: s(t) is a C2 piecewise cubic, integrated exactly from node to node,

    s_{k+1} = s_k + h sd_k + h^2 sdd_k / 2 + h^3 c_k / 6,   sd_{k+1} = sd_k + h sdd_k + h^2 c_k / 2,
    sdd_{k+1} = sdd_k + h c_k,        rest at both ends: (s, sd, sdd) = (0, 0, 0) and (1, 0, 0).

**The points are fixed in s.** The node values s_k are GIVEN (a node on each knot of the path, where
q''' jumps), and so is one point m_k inside each interval, reached at a free time u_k h_k
(``m_k = s_k + tau sd_k + tau^2 sdd_k / 2 + tau^3 c_k / 6``, tau = u_k h_k). The path derivatives q',
q'', q''' (both sides of the knots) and the torque coefficients are evaluated ONCE, exactly, at those
points; the unknowns are the times and the states there. Minimise T = sum h_k subject to, at every node
and every inner point,

    |q'(s) sd| <= vmax,   |q'(s) sdd + q''(s) sd^2| <= amax,
    |q'(s) c + 3 q''(s) sd sdd + q'''(s) sd^3| <= jmax (at a node: the jerk of both intervals),
    |a(s) sdd + b(s) sd^2 + g(s)| <= tau_max

(the torque coefficients of :func:`~scara_pin.motion.verify.torque_coefficients`, as TOPP-RA's in
:mod:`~scara_pin.motion.timing`). Each limit binds where it binds: there is no global slow-down. Working in
time avoids the rest-to-rest singularity of the s-domain (a jerk-limited start has ``sd ~ s^(2/3)``, no
polynomial in s); fixing the points in s makes the NLP's data exact and constant: ONE NLP per grid.

**Grids.** The first grid puts the nodes at equal times of a feasible double-S law; the
second at equal times of the first solution weighted by where its jerk switches (a
switch inside an interval costs to first order in its length), solved warm.

**Between the points** (the promise is the :mod:`~scara_pin.motion.verify` grid, 10 kHz): the exact
joint states are evaluated at 8 points inside every interval and on both sides of every node; where an
interval exceeds a limit by more than 1e-3 the limits at its points are divided by the excess and the
NLP solved again (warm). Then, on the trajectory's 10 kHz grid and both sides of every node, the time
scale k that brings the worst ratio to 1 is applied (:func:`~scara_pin.motion.verify.time_scale`: a
final correction of a few 1e-4 at most, reported as ``correction``, never the old global slow-down) with
a 2e-6 margin. A path that runs an earlier one backwards (a cycle's return move) takes its law reversed
in time (:meth:`JerkLaw.reversed`), checked the same way.

Why IPOPT through casadi: the NLP is small (5 N + 2 variables), sparse and smooth, its data constant;
IPOPT with casadi's exact Hessians converges in 15-40 iterations from a feasible start and every step is
robust to an infeasible one. A sequential LP (HiGHS) needs a merit function and more iterations; the
s-domain SOCP (Clarabel) cannot represent the jerk-limited rest. casadi is imported only inside the
solver. See ``docs/jerk.md``.
"""

from __future__ import annotations

import functools
import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import as_positive
from ..errors import InfeasibleError, ParameterError
from ..limits import MAX_SAMPLES, check_count
from ..summary import Summarized
from .paths import CartesianPath, GeometricPath, path_segments
from .timing import TimingError
from .trajectory import Motion, TimeLaw, Trajectory
from .verify import (
    VERIFY_RATE,
    LimitsInForce,
    Quantity,
    jerk_vector,
    limits_in_force,
    motion_states,
    state_ratios,
    time_scale,
    torque_coefficients,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..description import JointLimits
    from ..model import RobotModel
    from ..units import DisplayUnits

__all__ = ["JerkLaw", "JerkOptions", "JerkRatios", "JerkResult", "minimum_duration", "time_optimal_jerk"]

logger = logging.getLogger(__name__)

_SIDE = 1e-9
"""The left side of a node, as a fraction of the interval before it (the jerk switches at the node)."""
_MARGIN = 2e-6
"""The final time margin (relative) over the checked grid."""
_ACCEPT = 1.0 + 1e-9
"""The final correction brings the worst checked ratio to 1; this small margin covers rounding."""
_CORRECTION_MAX = 0.02
"""A final correction above 2 % means the NLP did not converge to the exact path: an error, not a slow motion."""
_REGRIDS = 1
"""Grids after the first: each from the last solution, denser where its jerk switches (:func:`_density`)."""
_PROBES = 8
_PER_PIECE = 4
"""Intervals per smooth piece of the path at least (on average; the grid follows the time, not the pieces)."""
_MAX_INTERVALS = 2000
"""The most intervals of one NLP (sized before any work: a path through more waypoints is refused)."""
"""Points inside each interval where the tightening rounds check the exact limits (besides the nodes)."""
_TIGHT_TOL = 1e-3
"""Between-point excess left to the final uniform correction (a time scale of at most ~1e-3)."""


@dataclass(frozen=True)
class JerkOptions:
    """Options of :func:`time_optimal_jerk`.

    Attributes:
        intervals: N, the intervals of constant path jerk (more: closer to the continuous optimum, slower
            to plan; see ``docs/jerk.md`` for the figures).
        max_iterations: the largest number of NLPs per path (two grids, then the local tightening rounds).
        ipopt_iterations: IPOPT's iteration limit per NLP.
        check_rate: [Hz] the verification rate (the grid the result is checked and corrected on; the
            samples a trajectory of the implied duration would need are sized against
            :data:`~scara_pin.limits.MAX_SAMPLES`).
    """

    intervals: int = 48
    max_iterations: int = 8
    ipopt_iterations: int = 500
    check_rate: float = VERIFY_RATE

    def __post_init__(self) -> None:
        for name, low, high in (("intervals", 8, 2000), ("max_iterations", 2, 1000), ("ipopt_iterations", 10, 100000)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not low <= v <= high:
                raise ParameterError(name, v, f"must be an integer in [{low}, {high}]")
        as_positive("check_rate", self.check_rate, "Hz")


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
        s: (N + 1,) node path positions (derived) [-].
        sd: (N + 1,) node path velocities (derived) [1/s].
        sdd: (N + 1,) node path accelerations (derived) [1/s^2].
        duration: ``t[-1]`` [s].
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
        k = as_positive("k", k)
        return JerkLaw(self.t * k, self.c / k**3, self.knots)

    def breakpoints(self) -> np.ndarray:
        """The node times [s] (the path jerk is constant between them)."""
        return self.t.copy()

    def reversed(self, knots: tuple[float, ...] | None = None) -> JerkLaw:
        """The law run backwards on the reversed path: s_r(t) = 1 - s(T - t).

        So sd_r(t) = sd(T - t), sdd_r(t) = -sdd(T - t) and the path jerk c_r(t) = c(T - t) (the intervals
        in reverse order). On q_r(s) = q(1 - s) the joints then move as q_r(s_r(t)) = q(s(T - t)): the
        motion in reverse, velocities and jerks negated, accelerations and torques unchanged (frictionless
        rigid bodies: the Coriolis and centrifugal terms are quadratic in qd).

        Args:
            knots: the reversed path's own knots (1 - each of :attr:`knots` up to rounding: the nodes must
                sit on the path's values exactly); default 1 - each.
        """
        t = self.duration - self.t[::-1]
        t[0] = 0.0
        knots = tuple(1.0 - k for k in self.knots) if knots is None else knots
        return JerkLaw.from_jerks(t, self.c[::-1].copy(), knots)


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


def _size(path: GeometricPath, jv: np.ndarray, lim: LimitsInForce, opts: JerkOptions) -> None:
    """Refuse (exit 2) a jerk limit whose implied duration needs more verified samples than the cap."""
    T = minimum_duration(path, jv, lim.velocity, lim.acceleration)
    check_count(f"verified samples of the jerk-limited motion (at least {T:.3g} s at {opts.check_rate:g} Hz)",
                T * opts.check_rate, MAX_SAMPLES, "the jerk limit is too low for this move (raise it)")  # fmt: skip


# ---------------------------------------------------------------------------------------------- the NLP
@functools.lru_cache(maxsize=8)
def _nlp(n: int, torque: bool, dof: int, ipopt_iterations: int) -> Any:
    """The parametric NLP (casadi/IPOPT) of n intervals: built once per shape, reused for every path.

    Variables x = (H, P, R, C, U) in a reference time T_ref: H (n) the interval lengths in units of
    T_ref / n, P = T_ref sd and R = T_ref^2 sdd at the nodes (n + 1), C = T_ref^3 sddd on the intervals (n),
    U (n) the fraction of each interval where its midpoint in s is reached. Parameters: the nodes' s
    (n + 1) and the midpoints' s (n), the path data there (module docstring), the limits there (each point
    its own, in reference units: the local tightening).

    Returns:
        (solver, number of equality rows, number of limit rows).
    """
    import casadi as ca

    H, P, R, C, U = (ca.SX.sym(name, size) for name, size in (("H", n), ("P", n + 1), ("R", n + 1), ("C", n),
                                                                ("U", n)))  # fmt: skip
    cn, cm = (7 if torque else 4) * dof, (6 if torque else 3) * dof
    sizes = (n + 1, n, (n + 1) * cn, n * cm, (n + 1) * 4 * dof, n * 4 * dof)
    par = ca.SX.sym("par", sum(sizes))
    cut = np.cumsum((0, *sizes))
    S, M = par[cut[0] : cut[1]], par[cut[1] : cut[2]]
    DN = ca.reshape(par[cut[2] : cut[3]], n + 1, cn)
    DM = ca.reshape(par[cut[3] : cut[4]], n, cm)
    LN = ca.reshape(par[cut[4] : cut[5]], n + 1, 4 * dof)
    LM = ca.reshape(par[cut[5] : cut[6]], n, 4 * dof)
    h = H / n
    tau = U * h
    p0, r0 = P[:-1], R[:-1]
    eq = [S[1:] - S[:-1] - (h * p0 + h**2 / 2 * r0 + h**3 / 6 * C),
          P[1:] - (p0 + h * r0 + h**2 / 2 * C),
          R[1:] - (r0 + h * C),
          M - S[:-1] - (tau * p0 + tau**2 / 2 * r0 + tau**3 / 6 * C)]  # fmt: skip
    pm, rm = p0 + tau * r0 + tau**2 / 2 * C, r0 + tau * C
    rows: list[Any] = []
    for j in range(dof):
        d1, d2, d3l, d3r = (DN[:, k * dof + j] for k in range(4))
        m1, m2, m3 = (DM[:, k * dof + j] for k in range(3))
        v, a, jk, e = (LN[:, k * dof + j] for k in range(4))
        vm, am, jm, em = (LM[:, k * dof + j] for k in range(4))
        rows += [d1 * P / v, (d1 * R + d2 * P**2) / a,
                 (d1[1:] * C + 3 * d2[1:] * P[1:] * R[1:] + d3l[1:] * P[1:] ** 3) / jk[1:],  # left of node k + 1
                 (d1[:-1] * C + 3 * d2[:-1] * p0 * r0 + d3r[:-1] * p0**3) / jk[:-1],  # right of node k
                 m1 * pm / vm, (m1 * rm + m2 * pm**2) / am, (m1 * C + 3 * m2 * pm * rm + m3 * pm**3) / jm]  # fmt: skip
        if torque:
            A, B, G = (DN[:, (4 + k) * dof + j] for k in range(3))
            Am, Bm, Gm = (DM[:, (3 + k) * dof + j] for k in range(3))
            rows += [(A * R + B * P**2 + G) / e, (Am * rm + Bm * pm**2 + Gm) / em]
    g = ca.vertcat(*eq, *rows, pm)
    n_eq = 4 * n
    n_lim = int(g.numel()) - n_eq - n
    nlp = {"x": ca.vertcat(H, P, R, C, U), "f": ca.sum1(H) / n, "g": g, "p": par}
    opts: dict[str, Any] = {
        "ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-9,
        "ipopt.constr_viol_tol": 1e-11, "ipopt.max_iter": ipopt_iterations, "ipopt.mu_strategy": "adaptive",
        # MUMPS' own scaling costs more than the factorisation of this small, well-scaled system
        "ipopt.mumps_scaling": 0, "ipopt.mumps_permuting_scaling": 0,
        "ipopt.warm_start_init_point": "yes", "ipopt.warm_start_bound_push": 1e-9,
        "ipopt.warm_start_mult_bound_push": 1e-9}  # fmt: skip
    return ca.nlpsol("jerk_time_optimal", "ipopt", nlp, opts), n_eq, n_lim


def _path_data(robot: RobotModel, path: GeometricPath, s: np.ndarray, torque: bool, Tr: float) -> np.ndarray:
    """(n, 3 dof) q', q'', q''' at s; with ``torque`` also the RNEA coefficients a, b (in reference units) and g.

    tau = a sdd + b sd^2 + g (:func:`~scara_pin.motion.verify.torque_coefficients`); a and b are divided by
    T_ref^2 (the NLP's R and P are T_ref^2 sdd and T_ref sd).
    """
    q, d1, d2, d3 = path.evaluate(s, 3)
    cols = [d1, d2, d3]
    if torque:
        a, b, g = torque_coefficients(robot, q, d1, d2)
        cols += [a / Tr**2, b / Tr**2, g]
    out = np.hstack(cols)
    if not np.isfinite(out).all():
        raise TimingError("JerkNLP", "the path derivatives are not finite (a singular point)")
    return out


@dataclass(frozen=True, eq=False)
class _Grid:
    """The points of the NLP, FIXED in s: nodes S (a node on each knot of the path), midpoints M; and x0.

    Attributes:
        S: (n + 1,) the nodes' s, 0 to 1.
        M: (n,) the midpoints' s, strictly inside their interval.
        knot_nodes: indices of the nodes on the path's knots.
        x0: the initial variables (from the law the grid was made from).
    """

    S: np.ndarray
    M: np.ndarray
    knot_nodes: np.ndarray
    x0: np.ndarray

    @classmethod
    def from_law(cls, law: JerkLaw, knots: np.ndarray, n: int, Tr: float, segment: int,
                 density: np.ndarray | None = None) -> _Grid:  # fmt: skip
        """Nodes at n + 1 equal times of ``law`` (the node nearest each knot's time moved onto the knot)."""
        T = law.duration
        t = np.linspace(0.0, T, n + 1)
        if density is not None:
            C = np.concatenate([[0.0], np.cumsum(density * np.diff(law.t))])
            t = np.interp(np.linspace(0.0, C[-1], n + 1), C, law.t)
        s = law.evaluate(t)[0]
        s[0], s[-1] = 0.0, 1.0
        nodes = np.clip(np.round(np.interp(knots, s, np.arange(n + 1.0))).astype(int), 1, n - 1)
        for i in range(1, len(nodes)):  # two knots never share a node
            nodes[i] = max(nodes[i], nodes[i - 1] + 1)
        if len(nodes) and nodes[-1] > n - 1:
            raise TimingError("JerkNLP", f"the path has {len(knots)} knots: too many for {n} intervals (more "
                              "intervals needed)", segment=segment)  # fmt: skip
        t[nodes] = law.times_at(knots)
        s[nodes] = knots
        if not (np.diff(t) > 0).all():
            raise TimingError("JerkNLP", f"the path's knots are too close in time for {n} intervals (more "
                              "intervals needed)", segment=segment)  # fmt: skip
        tm = 0.5 * (t[:-1] + t[1:])
        m, _, _, c = law.evaluate_jerk(tm)
        _, sd, sdd, _ = law.evaluate_jerk(t)
        if not ((m > s[:-1]) & (m < s[1:])).all():
            raise TimingError("JerkNLP", "the initial law does not advance along the path", segment=segment)
        x0 = np.concatenate([np.diff(t) / (Tr / n), sd * Tr, sdd * Tr**2, c * Tr**3, np.full(n, 0.5)])
        return cls(s, m, nodes, x0)


class _Solver:
    """The NLP on one path (module docstring): guess, solve, re-grid, solve, tighten locally where exceeded."""

    def __init__(self, robot: RobotModel, path: GeometricPath, lim: LimitsInForce, jv: np.ndarray, opts: JerkOptions,
                 segment: int) -> None:  # fmt: skip
        self.robot, self.path, self.lim, self.jv, self.opts, self.segment = robot, path, lim, jv, opts, segment
        self.knots = np.unique(np.clip(path.knots(), 0.0, 1.0))[1:-1]
        # a node on every knot, and at least _PER_PIECE intervals per smooth piece on average (a spline through
        # many waypoints gets more intervals than the default)
        self.n = n = max(opts.intervals, _PER_PIECE * (len(self.knots) + 1))
        check_count(f"intervals of the jerk-limited timing ({len(self.knots) + 1} smooth pieces)", n, _MAX_INTERVALS,
                    "fewer waypoints (each starts a smooth piece of the path)")  # fmt: skip
        self.dof = len(lim.velocity)
        self.torque = lim.effort is not None
        self.solver, self.n_eq, self.n_lim = _nlp(n, self.torque, self.dof, opts.ipopt_iterations)
        guess = _guess(robot, path, lim, jv, n)
        self.Tr = Tr = guess.duration
        e = lim.effort if lim.effort is not None else np.ones(self.dof)
        self.limits = np.concatenate([lim.velocity * Tr, lim.acceleration * Tr**2, jv * Tr**3, e])
        self.tight_nodes = np.ones((n + 1, 4 * self.dof))
        self.tight_mids = np.ones((n, 4 * self.dof))
        self.grid = _Grid.from_law(guess, self.knots, n, Tr, segment)
        self.warm: dict[str, Any] = {}
        self.nlps = 0
        o = n
        lbx, ubx = np.full(5 * n + 2, -np.inf), np.full(5 * n + 2, np.inf)
        lbx[:n] = 1e-4  # H
        lbx[o : o + n + 1] = 0.0  # P >= 0
        for i in (o, o + n, o + n + 1, o + 2 * n + 1):  # rest at both ends: P and R are 0 at nodes 0 and n
            lbx[i] = ubx[i] = 0.0
        lbx[4 * n + 2 :], ubx[4 * n + 2 :] = 1e-3, 1.0 - 1e-3  # U
        self.lbx, self.ubx = lbx, ubx

    def _parameters(self, grid: _Grid) -> np.ndarray:
        """The NLP's parameters: the points' s, the exact path data there, the (tightened) limits there."""
        S, M = grid.S, grid.M
        DN = _path_data(self.robot, self.path, S, self.torque, self.Tr)
        d = self.dof
        left = DN[:, 2 * d : 3 * d].copy()  # q''' on the left of each node: differs on the knots
        if len(grid.knot_nodes):
            left[grid.knot_nodes] = _path_data(self.robot, self.path, self.knots - 1e-12, False, self.Tr)[:, 2 * d :]
        DN = np.hstack([DN[:, : 2 * d], left, DN[:, 2 * d :]])
        DM = _path_data(self.robot, self.path, M, self.torque, self.Tr)
        LN = self.limits[None, :] * self.tight_nodes
        LM = self.limits[None, :] * self.tight_mids
        return np.concatenate([S, M, *(a.ravel(order="F") for a in (DN, DM, LN, LM))])

    def solve(self, grid: _Grid, x0: np.ndarray) -> JerkLaw:
        """Solve the NLP on ``grid`` from x0; the law it gives."""
        n = self.n
        lbg = np.concatenate([np.zeros(self.n_eq), -np.ones(self.n_lim), np.zeros(n)])
        ubg = np.concatenate([np.zeros(self.n_eq), np.ones(self.n_lim), np.full(n, np.inf)])
        t0 = time.perf_counter()
        res = self.solver(x0=x0, lbx=self.lbx, ubx=self.ubx, lbg=lbg, ubg=ubg, p=self._parameters(grid), **self.warm)
        self.nlps += 1
        stats = self.solver.stats()
        status = stats["return_status"]
        if status not in ("Solve_Succeeded", "Solved_To_Acceptable_Level"):
            raise TimingError("JerkNLP", f"IPOPT did not converge ({status}) on NLP {self.nlps}",
                              segment=self.segment)  # fmt: skip
        x = np.asarray(res["x"], dtype=float).ravel()
        self.warm = {"lam_x0": res["lam_x"], "lam_g0": res["lam_g"]}
        self.grid, self.x = grid, x
        logger.debug("segment %d NLP %d: T = %.9f s (%d IPOPT iterations, %.3f s)", self.segment, self.nlps,
                     float(np.sum(x[:n])) * self.Tr / n, stats["iter_count"], time.perf_counter() - t0)  # fmt: skip
        t = np.concatenate([[0.0], np.cumsum(x[:n] * self.Tr / n)])
        return JerkLaw.from_jerks(t, x[3 * n + 2 : 4 * n + 2] / self.Tr**3, tuple(self.knots.tolist()))

    def tighten(self, over: np.ndarray) -> bool:
        """Divide the limits at the points of each interval whose (N, 4 dof) ``over`` ratios exceed 1 + tol.

        Returns False when nothing exceeds (the law is final up to the uniform correction).
        """
        bad = over > 1.0 + _TIGHT_TOL
        if not bad.any():
            return False
        f = 1.0 / np.where(bad, over * (1.0 + _TIGHT_TOL / 2.0), 1.0)
        self.tight_mids *= f
        self.tight_nodes[:-1] *= f
        self.tight_nodes[1:] *= f
        return True


def _guess(robot: RobotModel, path: GeometricPath, lim: LimitsInForce, jv: np.ndarray, n: int) -> JerkLaw:
    """A feasible law on n equal intervals: a double-S in s, slowed as a whole to fit the limits.

    The path jerk is +c, 0, -c, 0, -c, 0, +c over seven equal phases; the law is then slowed until every
    limit holds at 8 points per interval (:func:`~scara_pin.motion.verify.time_scale`).
    """
    t = np.linspace(0.0, 1.0, n + 1)
    pattern = np.array([1.0, 0.0, -1.0, 0.0, -1.0, 0.0, 1.0])
    c = pattern[np.minimum((7 * (np.arange(n) + 0.5) / n).astype(int), 6)]
    law = JerkLaw(t, c)
    law = JerkLaw.from_jerks(t, c / law.s[-1])
    tt = np.linspace(0.0, 1.0, 8 * n + 1)
    k, _ = time_scale(robot, lim, motion_states(Motion(path, law), tt), jv)
    return law.scaled(k)


def _check_times(law: JerkLaw, t_start: float, rate: float) -> np.ndarray:
    """The trajectory's ``rate`` grid that falls in this motion, and both sides of every node (and knot)."""
    T = law.duration
    k0, k1 = math.ceil(t_start * rate - 1e-9), math.floor((t_start + T) * rate + 1e-9)
    t = np.concatenate([np.arange(k0, k1 + 1) / rate - t_start, law.t, law.t[1:] - np.diff(law.t) * _SIDE])
    return np.clip(t, 0.0, T)


def _ratios_at(robot: RobotModel, motion: Motion, t: np.ndarray, lim: LimitsInForce, jv: np.ndarray) -> np.ndarray:
    """(len(t), 4 dof): |velocity|, |acceleration|, |jerk|, |torque| over their limits at local times t."""
    r = state_ratios(robot, lim, motion_states(motion, t), jv)
    d = len(lim.velocity)
    out = np.zeros((len(t), 4 * d))
    for b, quantity in enumerate((Quantity.VELOCITY, Quantity.ACCELERATION, Quantity.JERK, Quantity.TORQUE)):
        if quantity in r:
            out[:, b * d : (b + 1) * d] = r[quantity]
    return out


def _interval_worst(law: JerkLaw, t: np.ndarray, ratios: np.ndarray) -> np.ndarray:
    """(N, 4 dof): the worst ratio in each interval of the law (the left side of a node counts in the left one)."""
    n = len(law.c)
    i = np.clip(np.searchsorted(law.t, t, side="right") - 1, 0, n - 1)
    out = np.zeros((n, ratios.shape[1]))
    np.maximum.at(out, i, ratios)
    return out


def _time_path(
    robot: RobotModel, path: GeometricPath, lim: LimitsInForce, jv: np.ndarray, opts: JerkOptions, segment: int
) -> tuple[JerkLaw, int]:
    """(law, NLPs) of one path before the final correction (module docstring)."""
    solver = _Solver(robot, path, lim, jv, opts, segment)
    law = solver.solve(solver.grid, solver.grid.x0)
    for _ in range(_REGRIDS):
        grid = _Grid.from_law(law, solver.knots, solver.n, solver.Tr, segment, _density(law))
        law = solver.solve(grid, grid.x0)
    for _ in range(opts.max_iterations - 1 - _REGRIDS):
        t = _probe_times(law)
        try:
            r = _ratios_at(robot, Motion(path, law), t, lim, jv)
        except InfeasibleError as exc:
            raise TimingError("VerificationFailed", str(exc), segment=segment) from None
        if not solver.tighten(_interval_worst(law, t, r)):
            break
        law = solver.solve(solver.grid, solver.x)
    return law, solver.nlps


def _finish(
    robot: RobotModel, path: GeometricPath, law: JerkLaw, lim: LimitsInForce, jv: np.ndarray, t_start: float,
    rate: float, segment: int, k: float | None = None,
) -> tuple[Motion, JerkRatios, float]:
    """(motion, ratios, k): ``law`` slowed k times until its worst ratio on the ``rate`` grid and nodes is 1.

    The time scale brings the worst ratio on the final grid to 1, with a margin of 2e-6 in time (4e-6 of
    the accelerations): the limits then hold at ANY time, not only on the checked grid (an 8 kHz grid found
    1.1e-6 of excess between the 10 kHz samples without it); again if the shifted grid needs it. A given
    ``k`` (the scale of the same law reversed) is tried first.
    """
    if k is not None:
        law = law.scaled(k)
    for _ in range(8):
        t = _check_times(law, t_start, rate)
        step, worst = time_scale(robot, lim, motion_states(Motion(path, law), t), jv)
        if step <= _ACCEPT and k is not None:
            break
        law = law.scaled(step * (1.0 + _MARGIN))
        k = (1.0 if k is None else k) * step * (1.0 + _MARGIN)
    else:  # pragma: no cover - time scaling is exact
        raise TimingError("VerificationFailed", f"the time scale does not settle ({step:.12g})", segment=segment)
    if k is None or not k <= 1.0 + _CORRECTION_MAX:  # None: cannot happen (the loop sets it)
        raise TimingError("JerkNLP", f"the solution exceeds a limit by {(k or 0.0) - 1:.3g} (time scale) between its "
                          "points: more intervals needed", segment=segment)  # fmt: skip
    ratios = JerkRatios(worst[Quantity.VELOCITY], worst[Quantity.ACCELERATION], worst[Quantity.JERK],
                        worst.get(Quantity.TORQUE))  # fmt: skip
    return Motion(path, law), ratios, k


def _reverses(a: GeometricPath, b: GeometricPath) -> bool:
    """True when b(s) = a(1 - s) (to 1e-9 rad or m, q and q', at the knots and 17 points): a run backwards."""
    ka, kb = np.unique(np.clip(a.knots(), 0.0, 1.0)), np.unique(np.clip(b.knots(), 0.0, 1.0))
    if len(ka) != len(kb) or np.abs(kb - (1.0 - ka[::-1])).max() > 1e-9:
        return False
    s = np.unique(np.concatenate([np.linspace(0.0, 1.0, 17), kb]))
    qa, da = a.evaluate(1.0 - s, 1)
    qb, db = b.evaluate(s, 1)
    return bool(np.abs(qb - qa).max() <= 1e-9 and np.abs(db + da).max() <= 1e-9 * max(1.0, np.abs(da).max()))


def _density(law: JerkLaw) -> np.ndarray:
    """Per interval of ``law``, the node density of the next grid (per unit time): more where the jerk switches.

    1 + (|c_k - c_{k-1}| + |c_{k+1} - c_k|) / (2 median |c|): the piecewise-constant jerk approximates a
    switch inside an interval to first order in its length, a smooth law to second order.
    """
    dc = np.abs(np.diff(law.c))
    scale = max(float(np.median(np.abs(law.c))), 1e-300)
    return 1.0 + (np.concatenate([[0.0], dc]) + np.concatenate([dc, [0.0]])) / (2.0 * scale)


def _probe_times(law: JerkLaw) -> np.ndarray:
    """Both sides of every node and :data:`_PROBES` points inside every interval (the tightening's check)."""
    h = np.diff(law.t)
    sig = (np.arange(_PROBES) + 0.5) / _PROBES
    return np.concatenate([law.t, law.t[1:] - h * _SIDE, (law.t[:-1, None] + h[:, None] * sig[None, :]).ravel()])


# ---------------------------------------------------------------------------------------------- public
@dataclass(frozen=True, eq=False, repr=False)
class JerkResult(Summarized):
    """A jerk-limited time-optimal trajectory and how it was obtained.

    Attributes:
        trajectory: one motion (a :class:`JerkLaw`) per path segment.
        ratios: worst limit ratios over the final check.
        correction: the largest final time scale (1 + a few 1e-4 at most): a duration is k times the NLP's.
        nlps: the number of NLPs solved (all segments).
        options: the options used.
    """

    trajectory: Trajectory
    ratios: JerkRatios
    correction: float
    nlps: int
    options: JerkOptions = field(default_factory=JerkOptions)

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The duration and the worst ratio of each limit (ratios have no unit)."""
        r = self.ratios
        torque = "" if r.torque is None else f", torque {r.torque:.4f}"
        return (f"JerkResult {self.trajectory.duration:.6f} s ({len(self.trajectory.pieces)} segment(s), {self.nlps} "
                f"NLP(s)): worst |value| / limit: velocity {r.velocity:.4f}, acceleration {r.acceleration:.4f}, "
                f"jerk {r.jerk:.4f}{torque}")  # fmt: skip


def time_optimal_jerk(
    robot: RobotModel,
    path: GeometricPath | CartesianPath | Sequence[GeometricPath | CartesianPath] | Sequence[ArrayLike] | np.ndarray,
    jerk: float | ArrayLike,
    *,
    torque: bool = False,
    limits: JointLimits | None = None,
    options: JerkOptions | None = None,
) -> JerkResult:
    """The minimum-time, rest-to-rest motion along ``path`` under joint velocity, acceleration, jerk (torque) limits.

    Args:
        robot: the robot (limits; its model for the torques: carry a payload with
            :func:`~scara_pin.motion.payload.with_payload`).
        path: a path, a :class:`~scara_pin.motion.paths.CartesianPath` (each segment rest to rest: the tool
            stops at every via point, where the line turns), a sequence of those (one after the other, at
            rest between them; e.g. the paths of a trajectory's motions), or (m, 4) joint waypoints.
        jerk: joint jerk limit [rad/s^3 or m/s^3], one number or one per joint.
        torque: also keep the effort limits (RNEA, gravity included).
        limits: joint limits instead of ``robot.limits``.
        options: the NLP's options.

    Raises:
        ParameterError: a limit is NaN, zero, negative or not finite.
        InvalidInputError: the jerk limit implies a duration whose verified samples exceed the cap.
        TimingError: the NLP did not converge (IPOPT's status), or the path is singular.
        InfeasibleError: the static load alone reaches an effort limit somewhere on the path.
    """
    paths = path_segments(robot, path)
    opts = JerkOptions() if options is None else options
    lim = limits_in_force(robot, limits, None, torque)
    jv = jerk_vector(jerk, len(lim.velocity))
    for p in paths:
        _size(p, jv, lim, opts)
    out: list[Motion] = []
    ratios: list[JerkRatios] = []
    laws: list[JerkLaw] = []  # before the final correction
    scales: list[float] = []
    k_max, nlps, t_start = 1.0, 0, 0.0
    for segment, p in enumerate(paths):
        # a path that runs an earlier one backwards (the return move of a cycle) takes its law reversed in
        # time: the limits are symmetric and the rigid-body torque is unchanged when qd changes sign (see
        # :meth:`JerkLaw.reversed`), so it is feasible and optimal; it is checked on its own grid all the same
        back = next((j for j in range(segment) if _reverses(paths[j], p)), None)
        if back is None:
            law, used, k0 = *_time_path(robot, p, lim, jv, opts, segment), None
        else:
            knots = tuple(np.unique(np.clip(p.knots(), 0.0, 1.0))[1:-1].tolist())
            law, used, k0 = laws[back].reversed(knots), 0, scales[back]
        motion, r, k = _finish(robot, p, law, lim, jv, t_start, opts.check_rate, segment, k0)
        laws.append(law)
        scales.append(k)
        out.append(motion)
        ratios.append(r)
        k_max, nlps, t_start = max(k_max, k), nlps + used, t_start + motion.duration
    tops = [r.torque for r in ratios if r.torque is not None]
    worst = JerkRatios(max(r.velocity for r in ratios), max(r.acceleration for r in ratios),
                       max(r.jerk for r in ratios), max(tops) if tops else None)  # fmt: skip
    return JerkResult(Trajectory(tuple(out)), worst, k_max, nlps, opts)
