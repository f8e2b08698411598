"""An INDEPENDENT minimum-time, jerk-limited timing of a given path (tests/test_jerk.py, benchmarks/bench_jerk.py).

Not the library's route (scara_pin.motion.jerk: points FIXED in s with free times, the path's own exact
derivatives there, an adaptive grid, local tightening). Here:

- **the path data** by finite differences of the closed-form IK alone (``path.evaluate(s, 0)``): the
  degree-8 polynomial through 9 points of each smooth piece (one-sided at its ends) differentiated, at
  the Chebyshev points of each piece, then the Chebyshev series through them;
- **the transcription**: one phase per smooth piece of the path (its knots are nodes), each with
  intervals of EQUAL length in time (each phase's duration free), s FREE at the other nodes, a constant
  path jerk on each interval (s(t) integrated exactly: the class of the bang-bang optimum); the limits at
  every node (the jerk of both intervals) and the middle of every interval; minimise the duration (IPOPT
  through CasADi's MX);
- **the check**: q(t) by IK at 100 kHz, velocity and acceleration by central differences, the jerk by
  third differences 10 samples apart (each a positive-weight mean of the true value: never above its
  largest), torques by Pinocchio's RNEA on the model given; the law is then slowed uniformly until every
  ratio is <= 1, so the duration returned is FEASIBLE: an upper bound of the true minimum, as fine as N.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from scara_pin.motion.trajectory import TimeLaw

CHECK_RATE = 100_000.0
"""[Hz] samples of q(t) in the dense check."""
JERK_SPAN = 10
"""Samples between the four points of a third difference (1e-4 s at CHECK_RATE)."""


# ---------------------------------------------------------------------------------------------- path data
def derivatives(path, s: np.ndarray, step: float = 4e-3) -> tuple[np.ndarray, ...]:
    """(q, q', q'', q''') at s from IK values only: the degree-8 interpolant through 9 points of the piece.

    The points are s0 + step * width * (0..8), placed around s and inside the smooth piece (between knots)
    holding s (one-sided at its ends), so no stencil straddles a knot.
    """
    s = np.asarray(s, dtype=float)
    knots = np.unique(np.clip(path.knots(), 0.0, 1.0))
    i = np.clip(np.searchsorted(knots, s, side="right") - 1, 0, len(knots) - 2)
    lo, hi = knots[i], knots[i + 1]
    d = step * (hi - lo)
    start = np.clip(s - 4.0 * d, lo, hi - 8.0 * d)
    pts = start[:, None] + d[:, None] * np.arange(9.0)[None, :]
    q = path.evaluate(pts.ravel(), 0)[0].reshape(len(s), 9, -1)
    x = (s - start) / d  # where s sits in the stencil, in steps
    V = np.arange(9.0)[None, :, None] - x[:, None, None]  # (n, 9 points, 1)
    A = V ** np.arange(9.0)[None, None, :]  # Taylor basis at s: row p = (o_p - x)^k
    coef = np.linalg.solve(A, q)  # (n, 9 orders, dof): q^(k)(s) d^k / k!
    fact = np.array([1.0, 1.0, 2.0, 6.0])
    return tuple(coef[:, k, :] * fact[k] / d[:, None] ** k for k in range(4))


# ---------------------------------------------------------------------------------------------- the law
@dataclass(frozen=True, eq=False)
class CubicLaw(TimeLaw):
    """s(t) with a constant path jerk c_k on [t_k, t_k+1] from the node states (s, sd, sdd)."""

    t: np.ndarray
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    c: np.ndarray
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", float(self.t[-1]))

    def evaluate_jerk(self, tau: np.ndarray) -> tuple[np.ndarray, ...]:
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.c) - 1)
        d, c = tau - self.t[i], self.c[i]
        return (self.s[i] + self.sd[i] * d + self.sdd[i] * d**2 / 2 + c * d**3 / 6,
                self.sd[i] + self.sdd[i] * d + c * d**2 / 2, self.sdd[i] + c * d, c)  # fmt: skip

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.evaluate_jerk(tau)[:3]

    def scaled(self, k: float) -> CubicLaw:
        return CubicLaw(self.t * k, self.s, self.sd / k, self.sdd / k**2, self.c / k**3)


# ---------------------------------------------------------------------------------------------- the check
def dense_ratios(model: pin.Model, path, law, velocity, acceleration, jerk, effort=None) -> dict[str, float]:
    """Worst |value| / limit of ``path`` timed by ``law`` (finite differences of IK samples, module docstring)."""
    h = 1.0 / CHECK_RATE
    pad = 3 * JERK_SPAN
    t = np.arange(-pad, math.ceil(law.duration * CHECK_RATE) + pad + 1) * h
    s = np.clip(law.evaluate(np.clip(t, 0.0, law.duration))[0], 0.0, 1.0)
    q = path.evaluate(s, 0)[0]
    qd = (q[2:] - q[:-2]) / (2 * h)
    qdd = (q[2:] - 2 * q[1:-1] + q[:-2]) / h**2
    H = JERK_SPAN * h
    n = JERK_SPAN
    qddd = (q[3 * n :] - 3 * q[2 * n : -n] + 3 * q[n : -2 * n] - q[: -3 * n]) / H**3
    out = {"velocity": float(np.max(np.abs(qd) / velocity)), "acceleration": float(np.max(np.abs(qdd) / acceleration)),
           "jerk": float(np.max(np.abs(qddd) / jerk))}  # fmt: skip
    if effort is not None:
        data = model.createData()
        tau = np.array([pin.rnea(model, data, q[k + 1], qd[k], qdd[k]) for k in range(len(qd))])
        out["torque"] = float(np.max(np.abs(tau) / effort))
    return out


# ---------------------------------------------------------------------------------------------- the solve
@dataclass(frozen=True)
class Reference:
    """duration: feasible (checked) [s]; nlp: the NLP's own [s]; scale: duration / nlp; seconds: compute time."""

    duration: float
    nlp: float
    scale: float
    seconds: float
    law: CubicLaw
    ratios: dict[str, float]


def _piece_data(model: pin.Model, path, lo: float, hi: float, degree: int, torque: bool) -> np.ndarray:
    """Chebyshev coefficients (degree + 1, columns) in x = 2 (s - lo) / (hi - lo) - 1 on a smooth piece.

    Of the first three path derivatives (and the torques' a, b, g: tau = a sdd + b sd^2 + g) on [lo, hi],
    through the finite-difference values at the Chebyshev points.
    """
    x = np.cos(np.pi * (np.arange(degree + 1) + 0.5) / (degree + 1))
    s = lo + (x + 1.0) * (hi - lo) / 2.0
    q, d1, d2, d3 = derivatives(path, s)
    cols = [d1, d2, d3]
    if torque:
        data, zero = model.createData(), np.zeros(q.shape[1])
        G = np.array([pin.rnea(model, data, q[k], zero, zero) for k in range(len(s))])
        cols += [np.array([pin.rnea(model, data, q[k], zero, d1[k]) for k in range(len(s))]) - G,
                 np.array([pin.rnea(model, data, q[k], d1[k], d2[k]) for k in range(len(s))]) - G, G]  # fmt: skip
    return np.polynomial.chebyshev.chebfit(x, np.hstack(cols), degree)


def _chebyshev(coef, x):
    """The columns of the Chebyshev series (coefficients in rows) at x, by Clenshaw's recurrence."""
    out = []
    for j in range(coef.shape[1]):
        b1 = b2 = 0.0
        for i in range(coef.shape[0] - 1, 0, -1):
            b1, b2 = coef[i, j] + 2.0 * x * b1 - b2, b1
        out.append(coef[0, j] + x * b1 - b2)
    return out


def solve(model: pin.Model, path, velocity, acceleration, jerk, effort=None, n: int = 300,
          degree: int = 30) -> Reference:  # fmt: skip
    """The minimum on n intervals (module docstring), checked and slowed until it holds.

    One phase per smooth piece of the path (its knots are nodes), each with intervals of equal length in
    time, as many as its share of a rough time estimate (the path speed at its velocity, curvature and
    jerk limit curves).
    """
    import casadi as ca

    start = time.perf_counter()
    dof = len(velocity)
    torque = effort is not None
    knots = np.unique(np.clip(path.knots(), 0.0, 1.0))
    coefs = [_piece_data(model, path, lo, hi, degree, torque) for lo, hi in zip(knots[:-1], knots[1:])]
    # the intervals of each piece: its share of sum ds / sd_max, sd_max from the velocity, acceleration and
    # jerk limits with the path derivatives alone, plus the rests' (a jerk-limited start and stop)
    est = []
    for (lo, hi), cf in zip(zip(knots[:-1], knots[1:]), coefs):
        x = np.linspace(-1.0, 1.0, 201)
        d = np.maximum(np.abs(np.array(_chebyshev(cf, x))), 1e-300)  # a joint that does not move: no cap
        cap = np.min([velocity[:, None] / d[:dof], np.sqrt(acceleration[:, None] / d[dof : 2 * dof]),
                      np.cbrt(jerk[:, None] / d[2 * dof : 3 * dof])], axis=(0, 1))  # fmt: skip
        est.append(float(np.mean(1.0 / cap)) * (hi - lo))
    rest = 0.25 * sum(est) / len(est)  # starting and stopping take time where the path speed is small
    est[0] += rest
    est[-1] += rest
    counts = np.maximum(4, np.round(n * np.array(est) / sum(est)).astype(int))
    N = int(counts.sum())
    Tp = ca.MX.sym("T", len(counts))
    S, P, R, C = ca.MX.sym("s", N + 1), ca.MX.sym("sd", N + 1), ca.MX.sym("sdd", N + 1), ca.MX.sym("c", N)
    h = ca.vertcat(*[ca.repmat(Tp[p] / counts[p], int(counts[p]), 1) for p in range(len(counts))])
    eq = [S[1:] - (S[:-1] + h * P[:-1] + h**2 / 2 * R[:-1] + h**3 / 6 * C),
          P[1:] - (P[:-1] + h * R[:-1] + h**2 / 2 * C), R[1:] - (R[:-1] + h * C)]  # fmt: skip
    half = h / 2
    Sm = S[:-1] + half * P[:-1] + half**2 / 2 * R[:-1] + half**3 / 6 * C
    Pm, Rm = P[:-1] + half * R[:-1] + half**2 / 2 * C, R[:-1] + half * C

    def limits(cols, p, r, c):
        out = []
        for j in range(dof):
            d1, d2, d3 = cols[j], cols[dof + j], cols[2 * dof + j]
            out += [d1 * p / velocity[j], (d1 * r + d2 * p**2) / acceleration[j],
                    (d1 * c + 3 * d2 * p * r + d3 * p**3) / jerk[j]]  # fmt: skip
            if torque:
                A, B, G = cols[3 * dof + j], cols[4 * dof + j], cols[5 * dof + j]
                out.append((A * r + B * p**2 + G) / effort[j])
        return out

    # one point: the piece's Chebyshev series at x, then the limits there (mapped over the points of a piece)
    xs, ps, rs, cs = ca.SX.sym("x"), ca.SX.sym("p"), ca.SX.sym("r"), ca.SX.sym("c")
    K = ca.SX.sym("K", degree + 1, coefs[0].shape[1])
    point = ca.Function("point", [xs, ps, rs, cs, K], [ca.vertcat(*limits(_chebyshev(K, xs), ps, rs, cs))])
    rows = []
    first = 0
    for p, (cf, m) in enumerate(zip(coefs, counts)):
        lo, hi = knots[p], knots[p + 1]
        idx = slice(first, first + int(m))
        nxt = slice(first + 1, first + int(m) + 1)
        F = point.map(int(m))
        Km = ca.repmat(ca.DM(cf), 1, int(m))

        def local(sv, lo=lo, hi=hi):
            return ca.transpose(2.0 * (sv - lo) / (hi - lo) - 1.0)

        # every node with the jerk of the interval after it and of the one before it (its own piece's data),
        # every middle of an interval
        for sv, pv, rv in ((S[idx], P[idx], R[idx]), (S[nxt], P[nxt], R[nxt]), (Sm[idx], Pm[idx], Rm[idx])):
            rows.append(ca.vec(F(local(sv), ca.transpose(pv), ca.transpose(rv), ca.transpose(C[idx]), Km)))
        first += int(m)
    g = ca.vertcat(*eq, *rows)
    n_eq = 3 * N
    solver = ca.nlpsol("reference", "ipopt", {"x": ca.vertcat(Tp, S, P, R, C), "f": ca.sum1(Tp), "g": g},
                       {"ipopt.print_level": 0, "print_time": 0, "ipopt.sb": "yes", "ipopt.tol": 1e-10,
                        "ipopt.max_iter": 3000, "ipopt.mu_strategy": "adaptive"})  # fmt: skip
    # start: the quintic s = 10 x^3 - 15 x^4 + 6 x^5 over 1.5 times the estimate (infeasible, IPOPT's job)
    T0 = 1.5 * sum(est)
    bounds = np.concatenate([[0], np.cumsum(counts)])
    tn = np.concatenate([np.linspace(0.0, 1.0, int(m) + 1)[:-1] * e + sum(est[:p]) for p, (m, e) in
                         enumerate(zip(counts, est))] + [[sum(est)]]) / sum(est)  # fmt: skip
    x = tn
    s0, p0 = x**3 * (10 - 15 * x + 6 * x * x), 30 * x**2 * (1 - x) ** 2 / T0
    r0 = 60 * x * (1 - x) * (1 - 2 * x) / T0**2
    c0 = np.diff(r0) / np.diff(x * T0)
    lbx = np.concatenate([np.full(len(counts), 1e-4), np.zeros(N + 1), np.zeros(N + 1), np.full(2 * N + 1, -np.inf)])
    ubx = np.concatenate([np.full(len(counts), np.inf), np.ones(N + 1), np.full(3 * N + 2, np.inf)])
    o = len(counts)
    for b, kn in zip(bounds, knots):  # the knots are nodes
        lbx[o + b] = ubx[o + b] = kn
        s0[b] = kn
    for i in (o + N + 1, o + 2 * N + 1, o + 2 * N + 2, o + 3 * N + 2):  # rest at both ends
        lbx[i] = ubx[i] = 0.0
    n_g = int(g.numel())
    res = solver(x0=np.concatenate([np.array(est) * T0 / sum(est), s0, p0, r0, c0]), lbx=lbx, ubx=ubx,
                 lbg=np.concatenate([np.zeros(n_eq), -np.ones(n_g - n_eq)]),
                 ubg=np.concatenate([np.zeros(n_eq), np.ones(n_g - n_eq)]))  # fmt: skip
    status = solver.stats()["return_status"]
    if status not in ("Solve_Succeeded", "Solved_To_Acceptable_Level"):
        raise RuntimeError(f"the reference NLP did not converge: {status}")
    v = np.asarray(res["x"], dtype=float).ravel()
    hv = np.repeat(v[:o] / counts, counts)
    law = CubicLaw(np.concatenate([[0.0], np.cumsum(hv)]), v[o : o + N + 1], v[o + N + 1 : o + 2 * N + 2],
                   v[o + 2 * N + 2 : o + 3 * N + 3], v[o + 3 * N + 3 :])  # fmt: skip
    Tn = law.duration
    k = 1.0
    for _ in range(20):  # slow down uniformly until the dense check holds
        r = dense_ratios(model, path, law, velocity, acceleration, jerk, effort)
        if max(r.values()) <= 1.0:
            break
        need = max(r["velocity"], math.sqrt(r["acceleration"]), r["jerk"] ** (1 / 3),
                   math.sqrt(r.get("torque", 0.0)), 1.0 + 1e-9)  # fmt: skip
        law, k = law.scaled(need), k * need
    else:
        raise RuntimeError("the reference could not be slowed into its limits")
    return Reference(law.duration, Tn, k, time.perf_counter() - start, law, r)
