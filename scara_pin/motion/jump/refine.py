"""Solving the jump: the warm start, the solves with constraints added inside intervals, the exact rebuild."""

from __future__ import annotations

import logging
import math

import numpy as np

from ..polynomial import PolynomialPiece
from ..trajectory import line_optimal_duration
from .nlp import Transcription
from .problem import NODES, ConstraintPoint, Problem, propagate
from .types import JumpError, JumpOptions, SolverStats

logger = logging.getLogger(__name__)

_CHECK_POINTS = 32
"""Points checked inside every interval for the refinement (besides the polynomial extrema)."""


_REFINE_RATIO = 1e-7
"""Relative excess (torque, tool speed) above which a constraint is added inside an interval."""


_REFINE_GEOMETRY = 2e-7
"""[m] excess of the clearance or the ceiling above which a constraint is added inside an interval."""


_LAZY = ("torque",)
"""Constraint families left out of the first solve (the torque is costly to differentiate and rarely binds):
once one comes within _NEAR of its limit anywhere, it is constrained at every node (both sides) and re-solved.
(Only on the intervals near the limit, as before, the solutions moved the excess from interval to interval
until the refinements ran out: 1.06 to 3.6 times the torque limit with large acceleration limits.)"""


_NEAR = 0.02


_STRETCH_POINTS = 256
"""Points per interval where ``torque_stretch`` samples the torque."""


def warm_start(prob: Problem, waypoints: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint lines A -> above A -> [via points] -> above B -> B, each with the quintic law over its fastest duration.

    The lift is the first line, the descent the last, the traverse the lines between (its nodes evenly spaced
    in time over them).
    """
    order = prob.order
    ends = np.array((prob.qA, prob.q_tops[0], prob.q_tops[1], prob.qB)) if waypoints is None else waypoints
    groups = [ends[:2], ends[1:-1], ends[-2:]]
    T = np.empty(3)
    states: list[np.ndarray] = []
    for p in range(3):
        lines = list(zip(groups[p][:-1], groups[p][1:]))
        durations = np.array([line_optimal_duration(q0, q1, prob.velocity, prob.acceleration) * 1.2
                              if not np.array_equal(q0, q1) else 0.0 for q0, q1 in lines])  # fmt: skip
        T[p] = durations.sum() if durations.sum() > 0.0 else 0.1 * prob.t_scale
        t = np.linspace(0.0, T[p], prob.N[p] + 1)
        starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
        rows = [np.zeros((len(t), len(prob.qA))) for _ in range(3)]
        for (q0, q1), t0, d in zip(lines, starts, durations):
            sel = (t >= t0) & (t <= t0 + d) if d > 0.0 else np.zeros(len(t), dtype=bool)
            x = (t[sel] - t0) / d if d > 0.0 else t[sel]
            dq = q1 - q0
            rows[0][sel] = q0 + (x**3 * (10.0 - 15.0 * x + 6.0 * x * x))[:, None] * dq
            if d > 0.0:
                rows[1][sel] = (30.0 * x * x * (1.0 - x) ** 2 / d)[:, None] * dq
                rows[2][sel] = (60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) / d**2)[:, None] * dq
        if not lines or durations.sum() == 0.0:
            rows[0][:] = groups[p][0]
        states.append(np.stack(rows[:order], axis=1)[(1 if p else 0) :])
    X = np.concatenate(states)
    h = np.repeat(T / np.array(prob.N), prob.N)
    U = np.diff(X[:, order - 1], axis=0) / h[:, None]
    return T, X, U


def solve(prob: Problem, options: JumpOptions, waypoints: np.ndarray | None = None
           ) -> tuple[PolynomialPiece, np.ndarray, SolverStats]:  # fmt: skip
    """Solve, rebuild exactly, refine where a constraint fails between nodes (module docstring).

    ``waypoints``: the warm start's joint path (default: A, above A, above B, B; :func:`warm_start`).
    """
    points: tuple[ConstraintPoint, ...] = ()
    tr = Transcription(prob, points, options)
    x0 = tr.pack(*warm_start(prob, waypoints))
    lam_x: np.ndarray | None = None
    lam_g: np.ndarray | None = None
    iterations = solves = 0
    while True:
        sol = tr.solve(x0, lam_x, lam_g)
        iterations += sol["iterations"]
        solves += 1
        if not sol["success"]:
            raise JumpError(sol["status"], failure(sol["status"], options))
        T, X, U = tr.unpack(sol["x"])
        piece = rebuild(prob, T, U)
        new = [p for p in violations(prob, piece, T, points) if p not in points]
        if not new or solves > options.refinements:
            break
        points = points + tuple(new)
        n_old = tr.n_g
        tr = Transcription(prob, points, options)
        x0, lam_x = sol["x"], sol["lam_x"]
        lam_g = np.concatenate([sol["lam_g"], np.zeros(tr.n_g - n_old)])
    stretch = torque_stretch(prob, piece)
    if stretch > 1.0:  # the torque bulging over its limit between constraint points: the same motion, slower
        logger.debug("jump: torque between the constraint points: %.9g times slower", stretch)
        piece, T = piece.scaled(stretch), T * stretch
    stats = SolverStats(sol["status"], iterations, solves, prob.N, tr.n_x, tr.n_g, 0.0)
    logger.debug("jump: %s", stats)
    return piece, T, stats


def failure(status: str, options: JumpOptions) -> str:
    """IPOPT's return status in words."""
    if status == "Infeasible_Problem_Detected":
        return ("no motion meets every constraint together (clearance, ceiling, joint ranges, limits): the solver "
                "found them locally infeasible")  # fmt: skip
    if status == "Maximum_Iterations_Exceeded":
        return f"the solver did not converge in {options.max_iterations} iterations"
    return f"the solver stopped without a solution ({status})"


def rebuild(prob: Problem, T: np.ndarray, U: np.ndarray) -> PolynomialPiece:
    """The exact polynomial piece: integrated from rest at A, controls changed (least norm) to end at rest at B."""
    order, dof = prob.order, prob.robot.dof
    h = np.repeat(T / np.array(prob.N), prob.N)
    n = len(h)
    # the end state is linear in the controls: end = Phi_all x0 + sum_k G_k u_k (per joint, same G for all)
    G = np.zeros((order, n))
    for k in range(n):
        e = propagate(order, [0.0] * order, 1.0, h[k])
        for m in range(k + 1, n):
            e = propagate(order, e, 0.0, h[m])
        G[:, k] = e
    U = U.copy()
    for _ in range(2):
        X = _integrate(prob, h, U)
        target = np.zeros((order, dof))
        target[0] = prob.qB
        r = target - X[-1]
        U += (G.T @ np.linalg.solve(G @ G.T, r))
    X = _integrate(prob, h, U)
    c = np.empty((n, order + 1, dof))
    for i in range(order):
        c[:, i] = X[:-1, i] / math.factorial(i)
    c[:, order] = U / math.factorial(order)
    return PolynomialPiece(np.concatenate([[0.0], np.cumsum(h)]), c)


def _integrate(prob: Problem, h: np.ndarray, U: np.ndarray) -> np.ndarray:
    order, dof = prob.order, prob.robot.dof
    X = np.zeros((len(h) + 1, order, dof))
    X[0, 0] = prob.qA
    for k in range(len(h)):
        X[k + 1] = np.array(propagate(order, list(X[k]), U[k], h[k]))
    return X


def violations(prob: Problem, piece: PolynomialPiece, T: np.ndarray,
               points: tuple[ConstraintPoint, ...] = ()) -> list[ConstraintPoint]:  # fmt: skip
    """The new constraint points (``points``: those already there) of a solution.

    Interior points where a constraint not linear in time fails by more than _REFINE_RATIO (the worst per
    interval); a lazy family near its limit anywhere: at every node (and its interior points only from the
    next round: the nodes alone may be enough).
    """
    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    sigma = np.arange(_CHECK_POINTS + 1) / _CHECK_POINTS  # both ends too: the torque depends on each side's control
    k = np.repeat(np.arange(n), _CHECK_POINTS + 1)
    s = np.tile(sigma, n)
    extra_k, extra_s = extrema(piece)
    k, s = np.concatenate([k, extra_k]), np.concatenate([s, extra_s])
    tau = piece.breaks[k] + s * h[k]
    q, qd, qdd = piece.evaluate(tau)
    qdd = piece.local(k, s * h[k], 2)  # the interval's own acceleration (not the next one's at its end)
    phase = prob.phase_of()[k]
    excess: dict[str, np.ndarray] = {}
    p = np.array(prob.sym.tool_position.map(len(k))(q.T)).T
    dA = np.hypot(p[:, 0] - prob.A[0], p[:, 1] - prob.A[1]) - prob.R
    dB = np.hypot(p[:, 0] - prob.B[0], p[:, 1] - prob.B[1]) - prob.R
    geo = np.choose(phase, [dA, prob.z_top - p[:, 2], dB])
    if prob.max_height is not None:
        geo = np.maximum(geo, p[:, 2] - prob.max_height)
    excess["geometry"] = geo
    if prob.effort is not None:
        tau_ = np.array(prob.sym.inverse_dynamics.map(len(k))(q.T, qd.T, qdd.T)).T
        excess["torque"] = np.max(np.abs(tau_) / prob.effort, axis=1) - 1.0
    if prob.tool_speed is not None:
        v = np.array(prob.sym.tool_velocity.map(len(k))(q.T, qd.T)).T
        excess["tool speed"] = np.linalg.norm(v, axis=1) / prob.tool_speed - 1.0
    out: list[ConstraintPoint] = []
    for family, e in excess.items():
        if family in _LAZY and ConstraintPoint(NODES, 0.0, family) not in points:
            if float(np.max(e)) > -_NEAR:  # near its limit somewhere: at every node from now on
                out.append(ConstraintPoint(NODES, 0.0, family))
            continue
        limit = _REFINE_GEOMETRY if family == "geometry" else _REFINE_RATIO
        bad = e > limit
        for kk in np.unique(k[bad]):
            sel = np.nonzero(bad & (k == kk))[0]
            out.append(ConstraintPoint(int(kk), float(s[sel[int(np.argmax(e[sel]))]]), family))
    return out


def torque_stretch(prob: Problem, piece: PolynomialPiece) -> float:
    """The least k >= 1 with every torque of ``piece`` played k times slower within its limit (module docstring).

    Sampled at ``_STRETCH_POINTS`` + 1 points of every interval (its own acceleration at both ends).
    With d = tau - g (the dynamic part) and g the static load at a sample, |d / k^2 + g| <= E needs
    k^2 >= d / (E - g) if d > 0, k^2 >= -d / (E + g) if d < 0; a static load at or above the limit cannot be
    helped (1 is returned: the verification says why).
    """
    if prob.effort is None:
        return 1.0
    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    k = np.repeat(np.arange(n), _STRETCH_POINTS + 1)
    s = np.tile(np.arange(_STRETCH_POINTS + 1) / _STRETCH_POINTS, n) * h[k]
    q, qd, qdd = (piece.local(k, s, i) for i in range(3))
    tau = np.array(prob.sym.inverse_dynamics.map(len(k))(q.T, qd.T, qdd.T)).T
    g = np.array(prob.sym.inverse_dynamics.map(len(k))(q.T, 0.0 * qd.T, 0.0 * qdd.T)).T
    d, E = tau - g, prob.effort[None, :]
    if not (np.abs(tau) > E).any() or (np.abs(g) >= E).any():
        return 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        need = np.where(d > 0.0, d / (E - g), np.where(d < 0.0, -d / (E + g), 0.0))
    return float(math.sqrt(max(1.0, float(np.max(need))))) * (1.0 + 1e-12)


def extrema(piece: PolynomialPiece) -> tuple[np.ndarray, np.ndarray]:
    """(interval, fraction) of every interior extremum of q and qd: the roots of qd and qdd on each interval."""
    c = piece.coefficients
    h = np.diff(piece.breaks)[:, None]
    deg = c.shape[1] - 1
    found = []
    # (constant, linear, quadratic) coefficients of qd, then of qdd, on each interval and joint
    polys = [(c[:, 1], 2.0 * c[:, 2], 3.0 * c[:, 3] if deg == 3 else np.zeros_like(c[:, 1]))]
    if deg == 3:
        polys.append((2.0 * c[:, 2], 6.0 * c[:, 3], np.zeros_like(c[:, 1])))
    with np.errstate(divide="ignore", invalid="ignore"):
        for p0, p1, p2 in polys:
            lin = np.abs(p2) <= 1e-300
            disc = np.sqrt(np.where(lin, np.nan, p1 * p1 - 4.0 * p2 * p0))
            found.append(np.where(lin, -p0 / p1, (-p1 - disc) / (2.0 * p2)))
            found.append(np.where(lin, np.nan, (-p1 + disc) / (2.0 * p2)))
    sigma = np.stack(found) / h[None]  # (roots, intervals, joints)
    keep = np.isfinite(sigma) & (sigma > 0.0) & (sigma < 1.0)
    k = np.broadcast_to(np.arange(len(h))[None, :, None], sigma.shape)
    return k[keep].astype(int), sigma[keep]
