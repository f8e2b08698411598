"""The SCARA closed form vectorised over N targets (:func:`solve_batch`): one solution per target.

The same formulas as the per-target :func:`scara_pin.kinematics.scara.solve` (the array forms of
:mod:`~scara_pin.kinematics.planar2r`); the rare rows where the arm's ill-conditioning decides a limit, or
the shoulder is free, take that function's route.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..ik_results import BatchIKResult
from .planar2r import (
    FREE_R,
    LIMIT_TOL,
    REACH_TOL,
    TWO_PI,
    nearest_turn_array,
)
from .scara_geometry import BRANCHES, IKStatus, ScaraGeometry
from .targets import batch_inputs

if TYPE_CHECKING:
    from .._typing import ArrayLike

from .scara import solve

__all__ = ["solve_batch"]

# ------------------------------------------------------------------------------------------ batch
_PI = math.pi
_isfinite = math.isfinite
_BATCH_ROWS = 16384
"""Rows per block of :func:`solve_batch` (its arrays stay in the cache)."""
_INV_TWO_PI = 1.0 / TWO_PI


def solve_batch(
    geo: ScaraGeometry,
    targets: ArrayLike,
    *,
    branch: str = "nearest",
    reference: ArrayLike | None = None,
) -> BatchIKResult:
    """The closed form vectorised over N targets: ONE solution per target, no Python loop per target.

    The same formulas as :func:`solve` (:mod:`~scara_pin.kinematics.planar2r`'s array forms): per target the
    solution of the requested branch (``"right"``/``"left"``) or, with ``branch="nearest"``, of the branch
    nearest to the reference, each joint at its turn nearest the reference (default q = 0). The rare rows
    where the arm's ill-conditioning decides a limit, or the shoulder is free, take :func:`solve`'s route.

    Args:
        geo: the robot's geometry.
        targets: (N, 4) array of (x, y, z, yaw) [m, rad], finite, within +/-MAGNITUDE_MAX.
        branch: ``"nearest"``, ``"right"`` or ``"left"``.
        reference: (4,) or (N, 4) reference configuration(s).

    Returns:
        BatchIKResult with (N, 4) q (NaN rows without a solution), (N,) IKStatus codes, (N,) branch signs.
    """
    T, ref = batch_inputs(targets, reference, branch, BRANCHES)
    n = T.shape[0]
    q = np.empty((n, 4))
    status = np.empty(n, dtype=np.int64)
    sign = np.empty(n, dtype=np.int64)
    if n == 0:
        return BatchIKResult(q, status, sign, IKStatus, BRANCHES)
    const = ref.ndim == 1
    work = _BatchWork(geo, min(n, _BATCH_ROWS), branch, ref.tolist() if const else None)
    for start in range(0, n, _BATCH_ROWS):
        stop = min(start + _BATCH_ROWS, n)
        refs = ref if const else ref[start:stop]
        work.block(T[start:stop], refs, q[start:stop], status[start:stop], sign[start:stop])
    return BatchIKResult(q, status, sign, IKStatus, BRANCHES)


class _BatchWork:
    """:func:`solve`'s formulas for one block of rows at a time, every operation into a preallocated array.

    The planar arm is :meth:`Planar2R.solve_array` (the same formulas as the scalar
    :meth:`Planar2R.solve`); each joint's turn is :func:`~scara_pin.kinematics.planar2r.nearest_turn`'s
    k = floor((ref - v) / 2 pi + 1/2), clamped into the limits. Both elbow branches are computed together,
    as the two rows of (2, m) arrays. With one reference for every row the clamp is decided once per joint:
    when [ref - pi, ref + pi] lies inside the limits the nearest turn always fits ("inside": no check); when
    at most one turn can fit and it is the nearest one ("unique": a check, no clamp of k); otherwise k is
    clamped between the first and last turns that fit ("clip"). A check whose answer the block's extremes
    already give (every row inside the stroke, the reach, one elbow turn) is not done row by row. Rows
    without a solution get their status in a second pass over those rows only; the rare rows where the
    arm's ill-conditioning decides a limit, or the shoulder is free, take :func:`solve`'s route.
    """

    def __init__(self, geo: ScaraGeometry, rows: int, branch: str, const_ref: list[float] | None) -> None:
        self.geo = geo
        self.branch = branch
        self.signs = (1, -1) if branch == "nearest" else ((1,) if branch == "right" else (-1,))
        nb = len(self.signs)
        self._f = np.empty((7, rows))  # alpha, wx, wy, r, gamma, heading, the vertical joint
        self._s = np.empty((5, nb, rows))  # the shoulder, elbow and wrist of each branch; lean; scratch
        self._b = np.empty((6, rows), dtype=bool)
        self._ok = np.empty((3, nb, rows), dtype=bool)
        self._mask = np.empty(rows, dtype=np.int64)
        # the elbow value before its offset, s_b (+/-gamma), for each branch
        self._gs = np.array([[sg * geo.signs[geo.revolute[1]]] for sg in self.signs])
        self.const_ref = const_ref
        # elbow angles this close to 0 or pi can make a limit a matter of rounding (wobble > LIMIT_TOL: the
        # wobble is ~c / (2 g) there; twice that margin, the exact test then on those rows only)
        self.near_g = geo.arm._c / LIMIT_TOL
        lo, hi, cont = geo.lower, geo.upper, geo.continuous
        self.modes: dict[int, str] = {}
        for j in geo.revolute:
            mode = "clip"
            if cont[j]:
                mode = "inside"
            elif const_ref is not None:
                ref, margin = const_ref[j], 1e-9
                if lo[j] + margin <= ref - math.pi and ref + math.pi <= hi[j] - margin:
                    mode = "inside"  # the turn nearest to ref is always inside the limits
                elif lo[j] <= ref <= hi[j] and max(ref - lo[j], hi[j] - ref) + LIMIT_TOL < math.pi - margin:
                    mode = "unique"  # no other turn than the nearest can be inside the limits
            self.modes[j] = mode

    def _turn(self, v: np.ndarray, j: int, ref: Any, ok: np.ndarray, S: list[np.ndarray], t_b: np.ndarray,
              span: tuple[float, float] | None = None) -> bool:  # fmt: skip
        """Move v (one row per branch) in place to its turn nearest ``ref`` inside joint j's limits.

        ``ok``: where it fits; ``S``: the scratch rows; ``span``: (min, max) of v when known (a reference
        for every row and mode "inside" or "unique" then). Returns False when every row fits (``ok`` not
        written).
        """
        geo, mode = self.geo, self.modes[j]
        lo, hi = geo.lower[j], geo.upper[j]
        lo_t, hi_t = lo - LIMIT_TOL, hi + LIMIT_TOL
        if span is not None:
            # often one k for the whole block (k = floor((ref + pi - v) / 2 pi) is monotonic in v)
            v_lo, v_hi = span
            if _isfinite(v_lo) and _isfinite(v_hi):
                k = math.floor((ref + _PI - v_hi) * _INV_TWO_PI)
                if k == math.floor((ref + _PI - v_lo) * _INV_TWO_PI):
                    np.add(v, TWO_PI * k, out=v)  # also for k = 0, as the scalar path: -0.0 + 0.0 is 0.0
                    v_lo, v_hi = v_lo + TWO_PI * k, v_hi + TWO_PI * k
                    if mode == "inside" or (lo <= v_lo and v_hi <= hi):
                        return False
                    if lo_t <= v_lo and v_hi <= hi_t:
                        np.clip(v, lo, hi, out=v)
                        return False
                    return self._fit(v, lo, hi, ok, t_b)
        k = S[3]
        if mode == "clip":
            k_min, k_max = S[4], S[5]
            np.subtract(lo_t, v, out=k_min)
            np.multiply(k_min, _INV_TWO_PI, out=k_min)
            np.ceil(k_min, out=k_min)
            np.subtract(hi_t, v, out=k_max)
            np.multiply(k_max, _INV_TWO_PI, out=k_max)
            np.floor(k_max, out=k_max)
            np.less_equal(k_min, k_max, out=ok)
        np.subtract(ref + _PI, v, out=k)  # k = floor((ref + pi - v) / 2 pi), as nearest_turn
        np.multiply(k, _INV_TWO_PI, out=k)
        np.floor(k, out=k)
        if mode == "clip":
            np.maximum(k, k_min, out=k)
            np.minimum(k, k_max, out=k)
        np.multiply(k, TWO_PI, out=k)
        np.add(v, k, out=v)
        if mode == "inside":
            return False
        if mode == "unique":
            return self._fit(v, lo, hi, ok, t_b)
        np.clip(v, lo, hi, out=v)
        return True

    @staticmethod
    def _fit(q: np.ndarray, lo: float, hi: float, ok: np.ndarray, t_b: np.ndarray) -> bool:
        """``ok`` where q is within LIMIT_TOL of [lo, hi]; q clamped onto [lo, hi]."""
        np.greater_equal(q, lo - LIMIT_TOL, out=ok)
        np.less_equal(q, hi + LIMIT_TOL, out=t_b)
        np.logical_and(ok, t_b, out=ok)
        np.clip(q, lo, hi, out=q)
        return True

    def block(self, T: np.ndarray, ref: np.ndarray, q_out: np.ndarray, st_out: np.ndarray, sg_out: np.ndarray) -> None:
        """Solve the rows T (at most the rows given at construction) into q_out, st_out, sg_out."""
        geo = self.geo
        m = len(T)
        nb = len(self.signs)
        f = [a[:m] for a in self._f]
        b = [a[:m] for a in self._b]
        # S[0], S[1], S[2]: shoulder, elbow and wrist, one row per branch; S[3] (wx, wy once the arm is
        # solved), S[4], S[5]: scratch
        Sq = self._s[:, :, :m]
        S = [Sq[0], Sq[1], Sq[2], self._f[1 : 1 + nb, :m], Sq[3], Sq[4]]
        oks = self._ok[:, :, :m]
        ra, rb, rc = geo.revolute
        ip = geo.prismatic
        sgn, lo, hi = geo.signs, geo.lower, geo.upper
        arm = geo.arm
        refs: list[Any] = self.const_ref if self.const_ref is not None else [ref[:, j] for j in range(4)]
        x, y, z, yaw = T[:, 0], T[:, 1], T[:, 2], T[:, 3]
        # vertical joint (the same value on every branch) and the shared failures: stroke, reach
        qp = f[6]  # written to q_out with the other joints (its rows then stay in the cache)
        if sgn[ip] < 0:
            np.subtract(geo.z0, z, out=qp)  # -(z - z0)
        else:
            np.subtract(z, geo.z0, out=qp)
        bad = None  # rows that fail on every branch (None: no such row)
        q_lo, q_hi = qp.min(), qp.max()
        if not (q_lo >= lo[ip] - LIMIT_TOL and q_hi <= hi[ip] + LIMIT_TOL):
            bad = b[0]
            np.less(qp, lo[ip] - LIMIT_TOL, out=bad)
            np.logical_or(bad, np.greater(qp, hi[ip] + LIMIT_TOL, out=b[1]), out=bad)
        if not (q_lo >= lo[ip] and q_hi <= hi[ip]):
            np.clip(qp, lo[ip], hi[ip], out=qp)
        alpha = np.subtract(yaw, geo.yaw0, out=f[0])
        wx, wy = f[1], f[2]
        tx, ty = geo.tool
        if tx or ty:
            ca, sa = np.cos(alpha, out=f[3]), np.sin(alpha, out=f[4])
            np.subtract(x, np.subtract(np.multiply(ca, tx, out=f[5]), np.multiply(sa, ty, out=S[5][0]), out=f[5]),
                        out=wx)  # fmt: skip
            np.subtract(y, np.add(np.multiply(sa, tx, out=f[5]), np.multiply(ca, ty, out=S[5][0]), out=f[5]), out=wy)
            if geo.a1[0] != 0.0:
                np.subtract(wx, geo.a1[0], out=wx)
            if geo.a1[1] != 0.0:
                np.subtract(wy, geo.a1[1], out=wy)
        else:
            np.subtract(x, geo.a1[0], out=wx)
            np.subtract(y, geo.a1[1], out=wy)
        r, gamma, heading, lean, _ = arm.solve_array(wx, wy, out=(f[3], f[4], f[5], S[4][0], S[5][0]))
        r_lo, r_hi = r.min(), r.max()
        if not (r_hi <= arm.l12 + REACH_TOL and r_lo >= geo._radius[0] - REACH_TOL):
            if bad is None:
                bad = b[0]
                np.greater(r, arm.l12 + REACH_TOL, out=bad)
            else:
                np.logical_or(bad, np.greater(r, arm.l12 + REACH_TOL, out=b[1]), out=bad)
            np.logical_or(bad, np.less(r, geo._radius[0] - REACH_TOL, out=b[1]), out=bad)
        # both branches at once: shoulder, elbow and wrist at their turns nearest the reference
        Qa, Qb, Qc = S[0], S[1], S[2]
        for n, sg in enumerate(self.signs):  # theta1 = heading -+ lean
            (np.subtract if sg > 0 else np.add)(heading, lean, out=Qa[n])
        if geo.beta1 != 0.0:
            np.subtract(Qa, geo.beta1, out=Qa)
        if sgn[ra] < 0:
            np.negative(Qa, out=Qa)
        np.multiply(gamma, self._gs, out=Qb)  # s_b (+/-gamma + beta1 - beta2)
        c_b = sgn[rb] * (geo.beta1 - geo.beta2)
        if c_b != 0.0:
            np.add(Qb, c_b, out=Qb)
        g_lo, g_hi = float(gamma.min()), float(gamma.max())
        span = None
        if self.const_ref is not None and self.modes[rb] != "clip":
            # the elbow of a branch spans half a turn: its extremes are those of gamma (v is monotonic in gamma)
            ends = [e + c_b if c_b != 0.0 else e for sg in self._gs[:, 0].tolist() for e in (g_lo * sg, g_hi * sg)]
            span = (min(ends), max(ends))
        ok: np.ndarray | None = None  # where each branch fits (None: everywhere)
        t_ok, t_b = oks[1], oks[2]
        for Q, j in ((Qb, rb), (Qa, ra), (Qc, rc)):
            if j == rc:  # the wrist takes the rest of the yaw
                (np.subtract if sgn[ra] > 0 else np.add)(alpha, Qa, out=Qc)
                (np.subtract if sgn[rb] > 0 else np.add)(Qc, Qb, out=Qc)
                if sgn[rc] < 0:
                    np.negative(Qc, out=Qc)
            if self._turn(Q, j, refs[j], oks[0] if ok is None else t_ok, S, t_b, span if j == rb else None):
                if ok is None:
                    ok = oks[0]
                else:
                    np.logical_and(ok, t_ok, out=ok)
        if bad is not None:
            if ok is None:
                ok = np.logical_not(bad, out=oks[0])
            else:
                np.greater(ok, bad, out=ok)  # ok and not bad
        qo = q_out.view(np.int64)
        if nb == 2:
            # the squared distance of the revolute joints (the vertical one is shared); q - 0 is q
            d, t = S[3], S[4]
            if self.const_ref is not None and refs[ra] == refs[rb] == refs[rc] == 0.0:
                np.einsum("ijk,ijk->jk", Sq[:3], Sq[:3], out=d)  # ((qa qa + qb qb) + qc qc), in one pass
            else:
                for n, (Q, j) in enumerate(((Qa, ra), (Qb, rb), (Qc, rc))):
                    dj = d if n == 0 else t
                    np.subtract(Q, refs[j], out=dj)
                    np.multiply(dj, dj, out=dj)
                    if n:
                        np.add(d, dj, out=d)
            # the second branch where it solves and the first does not or is farther (strictly: first on a tie)
            use = b[2]
            np.less(d[1], d[0], out=use)
            if ok is not None:
                np.greater_equal(use, ok[0], out=use)  # or the first does not solve
                np.logical_and(use, ok[1], out=use)
            # select bit for bit (an exact blend without branches): q0 ^ ((q1 ^ q0) & mask), mask = -1 where use
            mask = self._mask[:m]
            np.negative(use.view(np.uint8), out=mask, dtype=np.int64, casting="unsafe")
            Si = Sq[:3].view(np.int64)
            np.bitwise_xor(Si[:, 1], Si[:, 0], out=Si[:, 1])
            np.bitwise_and(Si[:, 1], mask, out=Si[:, 1])
            for n, j in enumerate((ra, rb, rc)):
                np.bitwise_xor(Si[n, 0], Si[n, 1], out=qo[:, j])
            np.copyto(q_out[:, ip], qp)
            np.bitwise_or(mask, 1, out=sg_out)  # -1 where the second (left) branch, else 1
            solved = None if ok is None else np.logical_or(ok[0], ok[1], out=b[3])
        else:
            for n, j in enumerate((ra, rb, rc)):
                np.copyto(q_out[:, j], S[n][0])
            np.copyto(q_out[:, ip], qp)
            sg_out.fill(self.signs[0])
            solved = None if ok is None else ok[0]
        st_out.fill(0)
        near_failed = None
        if ok is not None:
            # a branch that failed a limit near the stretched/folded circles may be rounding (solve() puts that
            # joint on its limit): such rows take solve()'s route even when the other branch solved
            near = np.less(gamma, self.near_g, out=b[4]) if g_lo < self.near_g else None
            if g_hi > math.pi - self.near_g:
                far = np.greater(gamma, math.pi - self.near_g, out=b[5])
                near = far if near is None else np.logical_or(near, far, out=near)
            # few rows: the exact test of the arm's rounding on them only
            some = np.flatnonzero(near) if near is not None else np.zeros(0, dtype=np.int64)
            if len(some):
                failed_one = ~(ok[0][some] & ok[-1][some])
                if bad is not None:
                    failed_one &= ~bad[some]
                some = some[failed_one]
                near_failed = some[self.geo.arm.wobble_array(gamma[some]) > LIMIT_TOL]
        if (solved is None or solved.all()) and (near_failed is None or not len(near_failed)) and r_lo > FREE_R:
            return
        self._failures(T, ref, m, np.zeros(m, dtype=bool) if bad is None else bad,
                       np.ones(m, dtype=bool) if solved is None else solved, r, gamma, q_out, st_out, sg_out,
                       np.zeros(0, dtype=np.int64) if near_failed is None else near_failed)  # fmt: skip

    def _failures(self, T: np.ndarray, ref: np.ndarray, m: int, bad: np.ndarray, solved: np.ndarray, r: np.ndarray,
                  gamma: np.ndarray, q_out: np.ndarray, st_out: np.ndarray, sg_out: np.ndarray,
                  near_failed: np.ndarray) -> None:  # fmt: skip
        """Statuses of the rows without a solution, and the rare rows :func:`solve` decides."""
        geo = self.geo
        ip = geo.prismatic
        rows = np.flatnonzero(~solved)
        if len(rows):
            # the shared failures, in solve()'s order of precedence; then how far each branch got
            qp_raw = (T[rows, 2] - geo.z0) * geo.signs[ip]
            stroke = (qp_raw < geo.lower[ip] - LIMIT_TOL) | (qp_raw > geo.upper[ip] + LIMIT_TOL)
            rr = r[rows]
            status = np.where(stroke, IKStatus.J3_STROKE, np.where(rr > geo.arm.l12 + REACH_TOL, IKStatus.OUT_OF_REACH,
                              np.where(bad[rows], IKStatus.INSIDE_INNER_LIMIT, IKStatus.J2_LIMIT)))  # fmt: skip
            st_out[rows] = status
            q_out[rows] = np.nan
            sg_out[rows] = 0
            lim = rows[status == IKStatus.J2_LIMIT]  # a joint limit: which one, branch by branch
            if len(lim):
                st_out[lim] = self._limit_status(T[lim], ref if ref.ndim == 1 else ref[lim], gamma[lim])
        else:
            lim = rows
        # rows whose joint-limit failure may be rounding (near stretched/folded), and free shoulders
        rare = set(lim[geo.arm.wobble_array(gamma[lim]) > LIMIT_TOL].tolist()) if len(lim) else set()
        rare |= set(np.flatnonzero((r <= FREE_R) & ~bad).tolist())
        rare |= set(near_failed.tolist())  # one branch failed within the arm's rounding, the other solved
        for i in sorted(rare):
            row_ref = ref if ref.ndim == 1 else ref[i]
            res = solve(geo, T[i], branch="all" if self.branch == "nearest" else self.branch, reference=row_ref)
            best = res.nearest(row_ref) if res.success else None
            if best is None:
                q_out[i], st_out[i], sg_out[i] = np.nan, res.status, 0
            else:
                q_out[i], st_out[i], sg_out[i] = best.q, IKStatus.OK, 1 if best.branch == "right" else -1

    def _limit_status(self, T: np.ndarray, ref: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        """J2_LIMIT, J1_LIMIT or J4_LIMIT of rows that reach but fit no branch: the furthest stage of a branch."""
        geo = self.geo
        ra, rb, rc = geo.revolute
        sgn, lo, hi, cont = geo.signs, geo.lower, geo.upper, geo.continuous
        refs = [ref[j] if ref.ndim == 1 else ref[:, j] for j in range(4)]
        alpha = T[:, 3] - geo.yaw0
        tx, ty = geo.tool
        ca, sa = np.cos(alpha), np.sin(alpha)
        wx = T[:, 0] - (ca * tx - sa * ty) - geo.a1[0]
        wy = T[:, 1] - (sa * tx + ca * ty) - geo.a1[1]
        _, g, heading, lean, _ = geo.arm.solve_array(wx, wy)
        stage = np.zeros(len(T), dtype=np.int64)
        for sg in self.signs:
            qb, okb = nearest_turn_array(sgn[rb] * (sg * g + geo.beta1 - geo.beta2), lo[rb], hi[rb], refs[rb], cont[rb])
            va = sgn[ra] * (heading - sg * lean - geo.beta1)
            qa, oka = nearest_turn_array(va, lo[ra], hi[ra], refs[ra], cont[ra])
            _, okc = nearest_turn_array(sgn[rc] * (alpha - sgn[ra] * qa - sgn[rb] * qb), lo[rc], hi[rc], refs[rc],
                                        cont[rc])  # fmt: skip
            stage = np.maximum(stage, np.where(~okb, 1, np.where(~oka, 2, np.where(~okc, 3, 3))))
        return np.array([IKStatus.J2_LIMIT, IKStatus.J2_LIMIT, IKStatus.J1_LIMIT, IKStatus.J4_LIMIT])[stage]
