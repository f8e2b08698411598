"""Closed-form inverse kinematics of a SCARA, one target at a time, on the geometry read from the model.

The geometry (read once from the loaded model) and its symbols are
:mod:`scara_pin.kinematics.scara_geometry`'s: p_xy(q) = A1 + R(phi1) [u1 + R(phi2) [u2 + R(phi4) t]],
z(q) = z0 + s3 q3, yaw(q) = yaw0 + phi1 + phi2 + phi4.

Inverse: the yaw fixes alpha = phi1 + phi2 + phi4, hence the wrist point W = p - R(alpha) t - A1; the
planar two-link arm (:mod:`scara_pin.kinematics.planar2r`, the one place the law of cosines is solved)
gives the elbow angle gamma = phi2 + beta2 - beta1 and the heading theta1 = phi1 + beta1 of arm 1 for
each elbow branch; the wrist takes the rest, phi4 = alpha - phi1 - phi2.

Branches (as on industrial controllers' lefty/righty arms):
    ``right``: the elbow turns counterclockwise seen from above (sin gamma > 0), like a human right arm
    seen from above, elbow out to the right; for +z joint axes and a zero pose with both arms
    stretched, q2 > 0. ``left``: the mirror image (sin gamma < 0). On the stretched (gamma = 0) or folded
    (gamma = pi) boundary the two coincide; such a solution is reported once, labelled ``right`` for
    gamma = 0 and ``left`` for gamma = pi, and matches either branch filter.

Turns: each branch is ONE solution, every revolute joint at its 2 pi turn nearest the reference (default
q = 0; chosen per joint, in O(1) whatever the range), with the range of turns that also fit
(:class:`~scara_pin.ik_results.IKSolution`); :meth:`IKResult.expand` lists every turn on request.
Continuous joints take the turn nearest the reference (distances wrapped).

Limits and rounding: a joint within ``LIMIT_TOL`` outside a limit is clamped onto it. Near the stretched
and folded circles the joint angles are ill-conditioned (a target rounded to the last bit moves them by
up to ~1e-7 rad, :meth:`~scara_pin.kinematics.planar2r.Planar2R.wobble`): a joint that rounding alone puts
outside its limit by less than that is put ON the limit and the other angles re-solved with it fixed (the
position still reached to ``REACH_TOL``), so configurations with a joint on its limit come back.

Two entry points here: :func:`solve` (the solutions of one target, as objects, with the reason when there
is none) and :func:`solve_nearest` (the one solution nearest a reference, as a new array: what a controller
needs between consecutive points); N targets vectorised with numpy:
:func:`scara_pin.kinematics.scara_batch.solve_batch`.
"""

from __future__ import annotations

import math
from operator import itemgetter
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError, NoSolutionError
from ..ik_results import IKResult, result_of
from .planar2r import (
    FREE_R,
    LIMIT_TOL,
    REACH_TOL,
    SINGULAR,
    Reach,
    free_angle,
    turn_edge,
    wrap,
)
from .scara_geometry import (
    BRANCHES,
    EXACT_TILT,
    NEAR_PARALLEL_TOL,
    YAW_POSE_TOL,
    IKStatus,
    NotScaraError,
    ScaraGeometry,
    branch_of,
)
from .targets import parse_target, reference_floats, weight_floats

if TYPE_CHECKING:
    from .._typing import ArrayLike

__all__ = [
    "EXACT_TILT",
    "LIMIT_TOL",
    "NEAR_PARALLEL_TOL",
    "REACH_TOL",
    "YAW_POSE_TOL",
    "IKStatus",
    "NotScaraError",
    "ScaraGeometry",
    "branch_of",
    "solve",
    "solve_nearest",
]

_PI = math.pi
_atan2, _sin, _cos, _sqrt, _isfinite = math.atan2, math.sin, math.cos, math.sqrt, math.isfinite

_STAGE = {IKStatus.J2_LIMIT: 1, IKStatus.J1_LIMIT: 2, IKStatus.J4_LIMIT: 3}
"""How far a branch got before it failed: the later the stage, the more telling the reason."""


# ------------------------------------------------------------------------------------------ scalar core
_Branch = tuple[str, bool, list[float], list[tuple[int, int] | None]]
"""(label, singular, q in q order, turns per joint) of one solution."""
_Failure = tuple[IKStatus, str]
_LimitFailure = tuple[IKStatus, tuple[str, int, float]]
"""A branch's joint-limit failure: (status, (branch label, joint index, joint value)), worded when needed."""


def _branches(
    geo: ScaraGeometry, x: float, y: float, z: float, alpha: float, ref: list[float], branch: str,
    turns: bool = True,
) -> tuple[list[_Branch], _Failure | None]:  # fmt: skip
    """The solution of each requested branch, or the reason there is none (the most telling failure).

    ``turns=False`` leaves out the turn ranges (an empty list; the nearest-solution path needs none).
    """
    ra, rb, rc, ip, s_a, s_b, s_c, s_p, lt_p, ht_p, z0, a1x, a1y, tx, ty, r_min_tol, b1, db = geo._k
    lo, hi = geo.lower, geo.upper
    arm = geo.arm
    # vertical joint
    qp = (z - z0) * s_p
    if not lt_p <= qp <= ht_p:
        return [], (IKStatus.J3_STROKE, f"z = {z:.9g} m needs {geo.names[ip]} = {qp:.9g} m, outside its stroke "
                                        f"[{lo[ip]:.9g}, {hi[ip]:.9g}] m")  # fmt: skip
    qp = lo[ip] if qp < lo[ip] else (hi[ip] if qp > hi[ip] else qp)
    # wrist point and the planar arm
    if tx or ty:
        ca, sa = _cos(alpha), _sin(alpha)
        wx = x - (ca * tx - sa * ty) - a1x
        wy = y - (sa * tx + ca * ty) - a1y
    else:
        wx, wy = x - a1x, y - a1y
    code, r, gamma, heading, lean = arm.solve(wx, wy)
    if code == Reach.OUT:
        return [], (IKStatus.OUT_OF_REACH, f"the wrist axis would be {r:.9g} m from the shoulder axis, beyond "
                                           f"the reach l1 + l2 = {arm.l12:.9g} m")  # fmt: skip
    if code == Reach.IN or r < r_min_tol:
        return [], (IKStatus.INSIDE_INNER_LIMIT, _inside_message(geo, r, geo._radius[0]))
    # stretched or folded: the two branches are one configuration, unless equal arms fold (their lean is
    # then +/-pi/2, and the two "twins" differ by pi at the shoulder: both are kept)
    singular = (gamma < SINGULAR or _PI - gamma < SINGULAR) and abs(_sin(lean)) < 1e-9
    if r <= FREE_R:  # l1 = l2 and the wrist on the shoulder axis: the shoulder is free
        heading = _free_shoulder(geo, alpha, gamma + geo.beta1 - geo.beta2, ref[ra]) + geo.beta1
        lean = 0.0  # (the wrist on the shoulder axis: r = 0, no lean)
    if singular:
        elbows: tuple[tuple[float, float, str], ...] = ((gamma, heading - lean, "right" if gamma < 1.0 else "left"),)
    else:
        elbows = ((gamma, heading - lean, "right"), (-gamma, heading + lean, "left"))
    found: list[_Branch] = []
    failures: list[_LimitFailure] = []
    cont = geo.continuous
    turn = geo._turn
    turn_a, turn_b, turn_c = turn[ra], turn[rb], turn[rc]
    ref_a, ref_b, ref_c = ref[ra], ref[rb], ref[rc]
    for g, theta1, label in elbows:
        if branch == "all" or label == branch or singular:
            # the common case inline: every joint has a turn inside its limits (else _joints says why,
            # or puts a joint that rounding alone moved out onto its limit)
            qb = turn_b(s_b * (g - db), ref_b, turns)
            qa = turn_a(s_a * (theta1 - b1), ref_a, turns) if qb is not None else None
            qc = (turn_c(s_c * (alpha - s_a * qa[0] - s_b * qb[0]), ref_c, turns)
                  if qa is not None and qb is not None else None)  # fmt: skip
            if qa is None or qb is None or qc is None:
                out = _joints(geo, wx, wy, alpha, g, theta1, ref, label)
                if len(out) == 2:
                    failures.append(out)  # type: ignore[arg-type]
                    continue
                qa, qb, qc = out
            q = [0.0] * 4
            q[ra], q[rb], q[rc], q[ip] = qa[0], qb[0], qc[0], qp
            k: list[tuple[int, int] | None] = []
            if turns:
                k = [(0, 0)] * 4
                k[ra] = None if cont[ra] else (qa[1], qa[2])
                k[rb] = None if cont[rb] else (qb[1], qb[2])
                k[rc] = None if cont[rc] else (qc[1], qc[2])
            found.append((label, singular, q, k))
    if found:
        return found, None
    worst = max(failures, key=lambda f: _STAGE[f[0]])
    # the sentences are written only now, when no branch solves (the nearest path often drops a failure)
    names = geo.names
    why = [f"{label}: {names[j]} = {wrap(v):.9g} rad (+2 pi k) outside [{lo[j]:.9g}, {hi[j]:.9g}] rad"
           for _, (label, j, v) in failures]  # fmt: skip
    return [], (worst[0], "no solution inside the joint limits: " + "; ".join(why))


def _joints(
    geo: ScaraGeometry, wx: float, wy: float, alpha: float, gamma: float, theta1: float, ref: list[float], label: str
) -> tuple[Any, ...]:
    """Shoulder, elbow and wrist of one branch at their turns nearest ``ref`` ((q, k_lo, k_hi) each).

    Or (status, (branch label, joint index, joint value)) when a joint has no turn inside its limits.

    A joint that rounding alone puts outside a limit (by less than ``wob``, the arm's ill-conditioning)
    is put on it and the arm re-solved with that angle fixed.
    """
    ra, rb, rc, _, s_a, s_b, s_c, _, _, _, _, _, _, _, _, _, b1, db = geo._k
    lo, hi, turn = geo.lower, geo.upper, geo._turn
    s, arm, b2 = geo.signs, geo.arm, geo.beta2
    wob = arm.wobble(gamma)
    # elbow
    vb = s_b * (gamma - db)
    tb = turn[rb](vb, ref[rb])
    if tb is None:
        edge = turn_edge(vb, lo[rb], hi[rb], wob)
        if edge is not None:
            theta1, miss = arm.with_elbow(wx, wy, geo.elbow_angle(edge))
            tb = turn[rb](edge, ref[rb]) if miss <= REACH_TOL else None
        if tb is None:
            return IKStatus.J2_LIMIT, (label, rb, vb)
    # shoulder
    va = s_a * (theta1 - b1)
    ta = turn[ra](va, ref[ra])
    if ta is None:
        edge = turn_edge(va, lo[ra], hi[ra], wob)
        if edge is not None:
            g, miss = arm.with_link1(wx, wy, s[ra] * edge + b1)
            tb = turn[rb](s[rb] * (g + b1 - b2), ref[rb])
            ta = turn[ra](edge, ref[ra]) if miss <= REACH_TOL and tb is not None else None
        if ta is None or tb is None:
            return IKStatus.J1_LIMIT, (label, ra, va)
    # wrist: s_c (alpha - s_a q_a - s_b q_b), whatever turns the shoulder and elbow took
    vc = s_c * (alpha - s_a * ta[0] - s_b * tb[0])
    tc = turn[rc](vc, ref[rc])
    if tc is None:
        edge = turn_edge(vc, lo[rc], hi[rc], 2.0 * wob)
        if edge is not None:  # the wrist on its limit fixes link 2's heading
            sigma = alpha - s[rc] * edge + b2
            theta1, miss = arm.with_link2(wx, wy, sigma)
            ta = turn[ra](s[ra] * (theta1 - b1), ref[ra])
            tb = turn[rb](s[rb] * (sigma - theta1 + b1 - b2), ref[rb])
            if miss <= REACH_TOL and ta is not None and tb is not None:
                tc = turn[rc](s[rc] * (alpha - s[ra] * ta[0] - s[rb] * tb[0]), ref[rc])
        if tc is None or ta is None or tb is None:
            return IKStatus.J4_LIMIT, (label, rc, vc)
    return ta, tb, tc


def _free_shoulder(geo: ScaraGeometry, alpha: float, phi2: float, ref_a: float) -> float:
    """phi1 for a free shoulder (wrist on its axis).

    It is inside the J1 limits, with a J4 turn inside the J4 limits when there is one, and nearest to the
    reference among those values.
    """
    ra, _, rc = geo.revolute
    s_a, s_c = geo.signs[ra], geo.signs[rc]
    lo_a, hi_a = geo.lower[ra], geo.upper[ra]
    # q4 = s_c (alpha - phi2 - s_a q1): sign -s_c s_a, offset s_c (alpha - phi2)
    q1 = free_angle(lo_a, hi_a, geo.lower[rc], geo.upper[rc], -s_c * s_a, s_c * (alpha - phi2), ref_a,
                    geo.continuous[rc])  # fmt: skip
    return s_a * (min(max(ref_a, lo_a), hi_a) if q1 is None else q1)  # no turn fits the wrist: J4_LIMIT follows


def _inside_message(geo: ScaraGeometry, r: float, r_min: float) -> str:
    rb = geo.revolute[1]
    lo, hi = geo.lower, geo.upper
    limited = r_min > geo.arm.d12 + REACH_TOL
    why = (f"the inner limit r_min = {r_min:.9g} m set by {geo.names[rb]}'s limits "
           f"[{math.degrees(lo[rb]):.6g}, {math.degrees(hi[rb]):.6g}] deg" if limited
           else f"|l1 - l2| = {geo.arm.d12:.9g} m")  # fmt: skip
    return f"the wrist axis would be {r:.9g} m from the shoulder axis, inside {why}"


# ------------------------------------------------------------------------------------------ entry points
def solve(
    geo: ScaraGeometry,
    target: ArrayLike | pin.SE3,
    *,
    branch: str = "all",
    reference: ArrayLike | None = None,
    all_turns: bool = False,
) -> IKResult:
    """The solutions that put the tool at ``target``: one per elbow branch, each joint's turn nearest ``reference``.

    Args:
        geo: the robot's geometry (``robot.kinematics.geometry``).
        target: (x, y, z, yaw) of the tool frame in the base frame [m, rad], or its placement as a
            pin.SE3 or a 4 x 4 matrix (refused with NOT_A_YAW_POSE when it tilts more than 1e-9 rad).
        branch: ``"all"``, ``"left"`` or ``"right"``.
        reference: the configuration whose nearest turns are chosen (default q = 0); also fixes a free
            shoulder (the wrist on its axis).
        all_turns: list every turn of every joint inside the limits as its own solution (at most
            ``MAX_SOLUTIONS``; InvalidInputError beyond).

    Returns:
        IKResult: the solutions (right before left), or the status and its reason.
    """
    if branch != "all" and branch not in BRANCHES:
        raise InvalidInputError(f"branch {branch!r} must be 'all', 'right' or 'left'")
    x, y, z, alpha, tilt = parse_target(target, geo.yaw0, geo.R0)
    pose = np.array((x, y, z, wrap(alpha + geo.yaw0)))
    if tilt > YAW_POSE_TOL:
        return IKResult(pose, (), IKStatus.NOT_A_YAW_POSE,
                        f"the target tilts the tool by {math.degrees(tilt):.6g} deg (roll/pitch); a SCARA can only "
                        "turn it about the vertical axis", geo.continuous)  # fmt: skip
    found, failure = _branches(geo, x, y, z, alpha, reference_floats(reference), branch)
    return result_of(pose, found, failure, IKStatus.OK, geo.continuous, geo.lower, geo.upper, all_turns)


def solve_nearest(
    geo: ScaraGeometry,
    target: ArrayLike | pin.SE3,
    reference: ArrayLike | None = None,
    *,
    weights: ArrayLike | None = None,
    branch: str = "all",
) -> np.ndarray:
    """The one solution nearest to ``reference``: what a controller needs between consecutive points.

    Among every solution inside the limits (both branches unless ``branch`` says otherwise, every 2 pi
    turn), the one with the least sum_i w_i (q_i - reference_i)^2; right before left on a tie. Each joint's
    nearest turn is chosen on its own, so the cost does not depend on the joint ranges.

    Args:
        geo: the robot's geometry.
        target: (x, y, z, yaw) [m, rad], a pin.SE3 or a 4 x 4 pose, as for :func:`solve`.
        reference: 4 joint values [rad, m] (the previous point, say); default q = 0.
        weights: 4 non-negative weights of the joint-space distance (default: all 1).
        branch: ``"all"``, ``"left"`` or ``"right"``.

    Returns:
        np.ndarray: the joint values (a new array).

    Raises:
        NoSolutionError: no solution inside the limits; ``status`` and ``reason`` say why (exit code 3).
        InvalidInputError: a malformed target, reference, weights or branch.
    """
    if branch != "all" and branch not in BRANCHES:
        raise InvalidInputError(f"branch {branch!r} must be 'all', 'right' or 'left'")
    x, y, z, alpha, tilt = parse_target(target, geo.yaw0, geo.R0)
    if tilt > YAW_POSE_TOL:
        raise NoSolutionError(IKStatus.NOT_A_YAW_POSE, f"the target tilts the tool by {math.degrees(tilt):.6g} deg")
    ref = reference_floats(reference)
    found, failure = _branches(geo, x, y, z, alpha, ref, branch, turns=False)
    if failure is not None:
        raise NoSolutionError(*failure)
    q = found[0][2]
    if len(found) > 1:  # the branches share the vertical joint: its term is the same on both sides, left out
        ra, rb, rc = geo.revolute
        wa, wb, wc = (1.0, 1.0, 1.0) if weights is None else itemgetter(ra, rb, rc)(weight_floats(weights))
        p = found[1][2]
        a, b, c = q[ra] - ref[ra], q[rb] - ref[rb], q[rc] - ref[rc]
        d, e, f = p[ra] - ref[ra], p[rb] - ref[rb], p[rc] - ref[rc]
        if wa * d * d + wb * e * e + wc * f * f < wa * a * a + wb * b * b + wc * c * c:
            q = p
    elif weights is not None:
        weight_floats(weights)
    return np.array(q)
