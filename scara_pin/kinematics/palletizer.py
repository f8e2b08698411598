"""The double-parallelogram palletizer of source S2: joint conventions, closed-form FK and geometric IK.

Joint vector users see (the model's ``q``, the motor side): ``q = (q1, q2, theta3, q4)`` with

- ``q1``: waist, about the vertical axis [rad];
- ``q2``: big arm, its angle from the vertical, positive leaning forward [rad] (S2's q2);
- ``theta3``: small arm, its ABSOLUTE angle from the vertical [rad]: what the small-arm motor on the
  turret drives through the parallelogram; S2's (relative) small-arm angle is ``q3 = theta3 - q2``;
- ``q4``: flange rotation about the vertical axis [rad] (S2's q5).

S2's passive wrist pitch ``q4_S2 = -(q2 + q3) = -theta3`` is the URDF's ``wrist_pitch`` mimic joint.
:func:`from_s2` and :func:`to_s2` convert between ``q`` and S2's ``(q1, q2, q3, q5)``; each is one
floating-point addition or subtraction per value (exact up to that one rounding).

Forward kinematics (S2, in ``q``; tool0 on the flange axis, its yaw turned by ``tool_yaw``):

    r = a1 + a2 sin q2 + a3 sin theta3 + a4,   x = r cos q1,   y = r sin q1,
    z = d1 + d2 + a2 cos q2 + a3 cos theta3 + d5,   yaw = q1 + q4 + tool_yaw.

**A file's own joints.** Descriptions order and zero their joints their own way: the levelling joint
before or after the small arm's, a small arm horizontal at q = 0 (the Dobot MG400, Magician), its angle
measured from the big arm (relative) rather than from the vertical, an axis along -y. The closed form works
in S2's coordinates, the *canonical* ``t = (phi, q2, theta3, q4)`` (``theta3`` replaced by the elbow angle
``q3 = theta3 - q2`` when the file's third joint is relative, ``relative``), each one joint of the file's
``q`` turned and shifted: ``t_i = s_i q_i + c_i`` (``signs`` +/-1, ``offsets``; q4's offset is in
``tool_yaw``). Limits, turns and references map the same way, so every formula below is S2's.

The geometry is read from the loaded Pinocchio model (:func:`scara_pin.kinematics.palletizer_model.read`), as
the SCARA's is: the tool's path in the arm plane as each arm joint turns gives r0 = a1 + a4,
h0 = d1 + d2 + d5, a2, a3, the signs and zero offsets, and whether the third joint is relative; the closed
form is then checked against the model at random configurations.

Inverse (S2): ``q1 = atan2(y, x)`` (and ``q1 + pi`` with the arm reaching backwards, ``r < 0``);
the shoulder-to-wrist vector in the arm plane ``(h, v) = (r - r0, z - h0)`` is a planar two-link arm
(a2, a3) with angles measured from the vertical (:mod:`scara_pin.kinematics.planar2r`, with
(x, y) = (v, h)), whose law of cosines gives the two elbow branches: ``up`` with ``sin q3 > 0`` (the
elbow above the shoulder-wrist line when the wrist is in front of the shoulder) and ``down`` with ``sin q3 < 0``; then
``q2 = atan2(h, v) - atan2(a3 sin q3, a2 + a3 cos q3)``, ``theta3 = q2 + q3``, ``q4 = yaw - tool_yaw - q1``.
On the stretched (q3 = 0) or folded (q3 = pi) boundary the branches coincide: one solution, flagged
``singular``, labelled ``up`` (q3 = 0) or ``down`` (q3 = pi). Every 2 pi-equivalent of a joint inside
its limits is the same solution: each joint takes its turn nearest the reference, with the range of
turns that fit (as the SCARA's).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from .._checks import as_vector
from ..errors import InvalidInputError, NoSolutionError, ParameterError, UrdfError
from ..ik_results import BatchIKResult, IKResult, result_of
from .planar2r import (
    FREE_R,
    LIMIT_TOL,
    REACH_TOL,
    Planar2R,
    Reach,
    free_angle,
    nearest_turn,
    nearest_turn_array,
    turn_edge,
    wrap,
)
from .targets import batch_inputs, parse_target, reference_floats, weight_floats

if TYPE_CHECKING:
    from .._typing import ArrayLike

__all__ = [
    "BRANCHES",
    "NotPalletizerError",
    "PalletizerGeometry",
    "PalletizerIKStatus",
    "branch_of",
    "forward",
    "from_s2",
    "solve",
    "solve_batch",
    "solve_nearest",
    "to_s2",
    "wrist_pitch",
]

BRANCHES = ("up", "down")
"""The palletizer's elbow branches, in the order solutions are listed."""
YAW_POSE_TOL = 1e-9
"""[rad] the largest tilt of a target rotation still taken as a pure yaw (the flange stays level)."""
FK_TOL = 1e-9
"""[m, rad] the largest difference between the closed-form FK and the model for it to be a palletizer."""


class NotPalletizerError(UrdfError):
    """The model does not follow the palletizer's kinematics (the reason says where it departs)."""


class PalletizerIKStatus(enum.IntEnum):
    """Why a target has (or has no) solution. Stable codes: the names are part of the interface."""

    OK = 0
    OUT_OF_REACH = 1  # the wrist is farther than a2 + a3 from the shoulder
    INSIDE_INNER_LIMIT = 2  # the wrist is closer than |a2 - a3| to the shoulder
    J1_LIMIT = 3
    J2_LIMIT = 4
    J3_LIMIT = 5
    J4_LIMIT = 6
    NOT_A_YAW_POSE = 7


# how far a candidate got before it failed (a later failure is the more telling one)
_STAGE = {
    PalletizerIKStatus.OUT_OF_REACH: 0,
    PalletizerIKStatus.INSIDE_INNER_LIMIT: 0,
    PalletizerIKStatus.J2_LIMIT: 1,
    PalletizerIKStatus.J3_LIMIT: 2,
    PalletizerIKStatus.J1_LIMIT: 3,
    PalletizerIKStatus.J4_LIMIT: 4,
}


@dataclass(frozen=True)
class PalletizerGeometry:
    """The palletizer's geometry, read from its model, and its joint limits.

    Attributes:
        r0: a1 + a4, the tool's distance from the waist axis with both arms vertical [m].
        h0: d1 + d2 + d5, the tool's height with both arms of zero length [m].
        a2, a3: big and small arm [m] (> 0).
        tool_yaw: tool0's turn about the flange axis [rad].
        shoulder: (r, z) of the big arm's axis in the arm plane [m] (for pictures).
        lower, upper: position limits of ``q`` (q1, q2, theta3, q4) [rad]; -inf/inf for a continuous joint.
        continuous: per joint, whether it is continuous.
        R0: tool0's rotation in the base frame at q = 0.
        signs, offsets: the file's q in canonical coordinates, ``t_i = signs[i] q_i + offsets[i]`` (module
            docstring); ``lower``/``upper`` are the canonical limits (the file's, mapped).
        relative: the canonical third coordinate is the elbow angle theta3 - q2 (the file's third joint is
            measured from the big arm), not theta3.
        names: the file's joint names (messages).
        arm: the planar two-link arm (a2, a3).
    """

    r0: float
    h0: float
    a2: float
    a3: float
    tool_yaw: float
    lower: tuple[float, float, float, float]
    upper: tuple[float, float, float, float]
    shoulder: tuple[float, float] = (0.0, 0.0)
    continuous: tuple[bool, ...] = (False, False, False, False)
    R0: np.ndarray = field(default_factory=lambda: np.diag([1.0, -1.0, -1.0]))
    signs: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    offsets: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    relative: bool = False
    names: tuple[str, str, str, str] = ("joint1", "joint2", "joint3", "joint4")
    arm: Planar2R = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if any(abs(v) != 1.0 for v in self.signs) or not all(math.isfinite(c) for c in self.offsets):
            raise ParameterError("signs, offsets", (self.signs, self.offsets), "must be +/-1 and finite")
        for name in ("r0", "h0", "a2", "a3", "tool_yaw"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ParameterError(name, value, "must be finite")
        for name in ("a2", "a3"):
            if getattr(self, name) <= 0:
                raise ParameterError(name, getattr(self, name), "must be > 0")
        object.__setattr__(self, "arm", Planar2R(self.a2, self.a3))

    def canonical(self, q: Sequence[float] | np.ndarray) -> list[float]:
        """The file's ``q`` in canonical coordinates ``t`` (module docstring)."""
        return [s * float(v) + c for s, v, c in zip(self.signs, q, self.offsets)]

    def yaw_of(self, q: Sequence[float] | np.ndarray) -> float:
        """The tool's yaw at the file's ``q``, unwrapped: q1 + q4 + tool_yaw in canonical coordinates [rad]."""
        t = self.canonical(q)
        return t[0] + t[3] + self.tool_yaw

    def user(self, t: Sequence[float] | np.ndarray) -> list[float]:
        """Canonical ``t`` as the file's ``q`` (the inverse of :meth:`canonical`)."""
        return [s * (float(v) - c) for s, v, c in zip(self.signs, t, self.offsets)]

    def user_limits(self, i: int) -> tuple[float, float]:
        """The file's limits of joint ``i`` [rad] (-inf/inf for a continuous joint)."""
        a, b = (self.signs[i] * (v - self.offsets[i]) for v in (self.lower[i], self.upper[i]))
        return (a, b) if a <= b else (b, a)

    def outside(self, i: int, t: float, label: str = "") -> str:
        """``joint3 = 1.2 rad (up) (+2 pi k) is outside [lo, hi] rad``: canonical ``t`` as the file's joint ``i``."""
        lo, hi = self.user_limits(i)
        value = wrap(self.signs[i] * (t - self.offsets[i]))
        return (f"{self.names[i]} = {value:.9g} rad{f' ({label})' if label else ''} (+2 pi k) is outside "
                f"[{lo:.9g}, {hi:.9g}] rad")  # fmt: skip


# ------------------------------------------------------------------------------------ conventions
def from_s2(q_s2: Sequence[float]) -> np.ndarray:
    """S2's ``(q1, q2, q3, q5)`` (q3 relative to the big arm) -> ``q = (q1, q2, theta3 = q2 + q3, q5)``."""
    a = as_vector("q_s2", q_s2)
    return np.array([a[0], a[1], a[1] + a[2], a[3]])


def to_s2(q: Sequence[float]) -> np.ndarray:
    """``q = (q1, q2, theta3, q4)`` -> S2's ``(q1, q2, q3 = theta3 - q2, q5 = q4)``."""
    a = as_vector("q", q)
    return np.array([a[0], a[1], a[2] - a[1], a[3]])


def wrist_pitch(q: Sequence[float]) -> float:
    """S2's passive wrist pitch ``q4 = -(q2 + q3) = -theta3`` [rad] at ``q`` (the ``wrist_pitch`` joint)."""
    return -float(as_vector("q", q)[2])


# ------------------------------------------------------------------------------------ kinematics
def forward(geo: PalletizerGeometry, q: ArrayLike) -> np.ndarray:
    """S2's closed-form FK: (x, y, z, yaw) of tool0 in ``base`` at ``q`` (motor side) [m, rad]."""
    q = as_vector("q", q)
    q1, q2, t3, _ = geo.canonical(q)
    if geo.relative:
        t3 += q2
    r = geo.r0 + geo.a2 * math.sin(q2) + geo.a3 * math.sin(t3)
    z = geo.h0 + geo.a2 * math.cos(q2) + geo.a3 * math.cos(t3)
    return np.array([r * math.cos(q1), r * math.sin(q1), z, geo.yaw_of(q)])


def branch_of(q: ArrayLike, geo: PalletizerGeometry | None = None) -> str:
    """``"up"`` when sin(q3) >= 0 (q3 = theta3 - q2, S2's small-arm angle), else ``"down"``.

    ``geo``: the palletizer whose joints ``q`` are (default: S2's own, ``q = (q1, q2, theta3, q4)``).
    """
    a = as_vector("q", q)
    if geo is not None:
        t = geo.canonical(a)
        return "up" if math.sin(t[2] if geo.relative else t[2] - t[1]) >= 0.0 else "down"
    return "up" if math.sin(a[2] - a[1]) >= 0.0 else "down"


_Branch = tuple[str, bool, list[float], list[tuple[int, int] | None]]


def _branches(
    geo: PalletizerGeometry, x: float, y: float, z: float, yaw: float, ref: list[float], branch: str
) -> tuple[list[_Branch], tuple[PalletizerIKStatus, str] | None]:
    """The solutions of the requested branches (reaching forwards, then backwards), or the most telling failure."""
    lo, hi, cont = geo.lower, geo.upper, geo.continuous
    arm = geo.arm
    rho = math.sqrt(x * x + y * y)  # as the batch computes it (np.sqrt of the same sum): the same bits
    if rho <= FREE_R:  # on the waist axis: q1 is free; the reference's, inside the limits
        q1 = ref[0] if cont[0] else min(max(ref[0], lo[0]), hi[0])
        candidates = [(q1, 0.0)]
    else:
        phi = math.atan2(y, x)
        candidates = [(phi, rho), (phi + math.pi, -rho)]  # reaching forwards, and backwards over the waist
    found: list[_Branch] = []
    worst: tuple[int, PalletizerIKStatus, str] = (-1, PalletizerIKStatus.OUT_OF_REACH, "")
    v = z - geo.h0

    def failed(status: PalletizerIKStatus, message: str) -> None:
        nonlocal worst
        if _STAGE[status] > worst[0]:
            worst = (_STAGE[status], status, message)

    for phi, r in candidates:
        code, D, g, heading, lean = arm.solve(v, r - geo.r0)  # the arm plane as (x, y) = (v, h)
        if code == Reach.OUT:
            failed(PalletizerIKStatus.OUT_OF_REACH,
                   f"the wrist would be {D:.9g} m from the shoulder axis, beyond a2 + a3 = {arm.l12:.9g} m")
            continue
        if code == Reach.IN:
            failed(PalletizerIKStatus.INSIDE_INNER_LIMIT,
                   f"the wrist would be {D:.9g} m from the shoulder axis, inside |a2 - a3| = {arm.d12:.9g} m")
            continue
        singular = arm.singular(g) and abs(math.sin(lean)) < 1e-9  # equal arms folded: two configurations
        wob = arm.wobble(g)
        if D <= FREE_R:  # a2 = a3 and the wrist on the shoulder axis, folded: the big arm is free
            free: float | None = ref[1] if cont[1] else min(max(ref[1], lo[1]), hi[1])
            if not geo.relative:  # theta3 = q2 + pi inside its limits too (relative: the elbow alone, at pi)
                free = free_angle(lo[1], hi[1], lo[2], hi[2], 1.0, math.pi, ref[1], cont[2])  # theta3 = q2 + pi
            elbows: list[tuple[float, float, str]] = [(math.pi, ref[1] if free is None else free, "down")]
        elif singular:
            elbows = [(g, heading - lean, "up" if g < 1.0 else "down")]
        else:
            elbows = [(g, heading - lean, "up"), (-g, heading + lean, "down")]
        for q3, q2, label in elbows:
            if not (branch == "all" or label == branch or singular):
                continue
            t2 = nearest_turn(q2, lo[1], hi[1], ref[1], cont[1])
            if t2 is None:  # rounding alone may put it outside: on the limit, the small arm re-solved
                edge = turn_edge(q2, lo[1], hi[1], wob)
                if edge is not None:
                    g2, miss = arm.with_link1(v, r - geo.r0, edge)
                    if miss <= REACH_TOL:
                        q2, q3, t2 = edge, g2, nearest_turn(edge, lo[1], hi[1], ref[1])
            if t2 is None:
                failed(PalletizerIKStatus.J2_LIMIT, geo.outside(1, q2, label))
                continue
            t3 = q3 if geo.relative else q2 + q3  # the elbow angle, or the small arm's from the vertical
            tt3 = nearest_turn(t3, lo[2], hi[2], ref[2], cont[2])
            if tt3 is None:
                edge = turn_edge(t3, lo[2], hi[2], wob)
                if edge is not None:
                    q2b, miss = (arm.with_elbow if geo.relative else arm.with_link2)(v, r - geo.r0, edge)
                    t2b = nearest_turn(q2b, lo[1], hi[1], ref[1], cont[1])
                    if miss <= REACH_TOL and t2b is not None:
                        t2, tt3 = t2b, nearest_turn(edge, lo[2], hi[2], ref[2])
            if tt3 is None:
                failed(PalletizerIKStatus.J3_LIMIT, geo.outside(2, t3, label))
                continue
            t1 = nearest_turn(phi, lo[0], hi[0], ref[0], cont[0])
            if t1 is None:
                failed(PalletizerIKStatus.J1_LIMIT, geo.outside(0, phi))
                continue
            q4 = yaw - geo.tool_yaw - t1[0]
            t4 = nearest_turn(q4, lo[3], hi[3], ref[3], cont[3])
            if t4 is None:
                failed(PalletizerIKStatus.J4_LIMIT, geo.outside(3, q4))
                continue
            ts = (t1, t2, tt3, t4)  # the file's q; its other turns (a joint turned the other way: mirrored)
            found.append((label, singular, geo.user([t[0] for t in ts]),
                          [None if c else ((t[1], t[2]) if sg > 0 else (-t[2], -t[1]))
                           for c, t, sg in zip(cont, ts, geo.signs)]))  # fmt: skip
    if found:
        found.sort(key=lambda b: b[0] != "up")  # up before down (stable: forwards before backwards)
        return found, None
    return [], (worst[1], worst[2])


def _pose(geo: PalletizerGeometry, target: object) -> tuple[float, float, float, float, float]:
    yaw0 = geo.tool_yaw + geo.offsets[0]  # the tool's yaw at q = 0
    x, y, z, alpha, tilt = parse_target(target, yaw0, geo.R0)
    return x, y, z, alpha + yaw0, tilt


def _user_limits(geo: PalletizerGeometry) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The file's lower and upper limits, per joint."""
    lims = [geo.user_limits(i) for i in range(4)]
    return tuple(lo for lo, _ in lims), tuple(hi for _, hi in lims)


def solve(
    geo: PalletizerGeometry,
    target: ArrayLike | pin.SE3,
    *,
    branch: str = "all",
    reference: ArrayLike | None = None,
    all_turns: bool = False,
) -> IKResult:
    """The configurations ``q`` (motor side) that put tool0 at ``target``, each joint at its turn nearest ``reference``.

    Args:
        geo: the palletizer's geometry.
        target: (x, y, z, yaw) of tool0 in ``base`` [m, rad], or its 4 x 4 pose / pin.SE3 (a pure yaw).
        branch: ``"all"``, ``"up"`` or ``"down"``.
        reference: the configuration whose nearest turns are chosen (default q = 0); also fixes q1 when
            the target lies on the waist axis.
        all_turns: list every turn of every joint inside the limits (at most ``MAX_SOLUTIONS``).

    Returns:
        IKResult: the solutions of ``branch`` (up before down; reaching forwards before backwards), or the
        status of the most advanced failure (reach, then J2, J3, J1, J4 limits) with its numbers.
    """
    if branch != "all" and branch not in BRANCHES:
        raise InvalidInputError(f"branch {branch!r} must be one of all, {', '.join(BRANCHES)}")
    x, y, z, yaw, tilt = _pose(geo, target)
    pose = np.array([x, y, z, wrap(yaw)])
    if tilt > YAW_POSE_TOL:
        return IKResult(pose, (), PalletizerIKStatus.NOT_A_YAW_POSE,
                        f"the target's z axis is tilted by {tilt:.3g} rad from the vertical; the palletizer's "
                        "flange stays level", geo.continuous)  # fmt: skip
    found, failure = _branches(geo, x, y, z, yaw, geo.canonical(reference_floats(reference)), branch)
    return result_of(pose, found, failure, PalletizerIKStatus.OK, geo.continuous, *_user_limits(geo), all_turns)


def solve_nearest(
    geo: PalletizerGeometry,
    target: ArrayLike | pin.SE3,
    reference: ArrayLike | None = None,
    *,
    weights: ArrayLike | None = None,
    branch: str = "all",
) -> np.ndarray:
    """The solution nearest to ``reference`` (weighted joint space), as a new array (see the SCARA's).

    Raises:
        NoSolutionError: no solution inside the limits (``status``, ``reason``).
    """
    if branch != "all" and branch not in BRANCHES:
        raise InvalidInputError(f"branch {branch!r} must be one of all, {', '.join(BRANCHES)}")
    x, y, z, yaw, tilt = _pose(geo, target)
    if tilt > YAW_POSE_TOL:
        raise NoSolutionError(PalletizerIKStatus.NOT_A_YAW_POSE, f"the target's z axis is tilted by {tilt:.3g} rad")
    ref = reference_floats(reference)
    found, failure = _branches(geo, x, y, z, yaw, geo.canonical(ref), branch)
    if failure is not None:
        raise NoSolutionError(*failure)
    w = [1.0] * 4 if weights is None else weight_floats(weights)
    best = min(found, key=lambda b: sum(wi * (qi - ri) ** 2 for wi, qi, ri in zip(w, b[2], ref)))
    return np.array(best[2])


def solve_batch(
    geo: PalletizerGeometry, targets: ArrayLike, *, branch: str = "nearest", reference: ArrayLike | None = None
) -> BatchIKResult:
    """One solution per target, vectorised (as the SCARA's :func:`~scara_pin.kinematics.scara_batch.solve_batch`).

    The same formulas as :func:`solve` on arrays (:meth:`Planar2R.solve_array`, the turns by
    :func:`~scara_pin.kinematics.planar2r.nearest_turn_array`): for each target the four candidates (reaching
    forwards or backwards over the waist, elbow up or down) in :func:`solve`'s order, the one nearest the
    reference (default q = 0) kept, or with ``branch="up"``/``"down"`` the nearest of that branch. The rare
    rows :func:`solve` decides alone (a target on the waist axis, a limit within the arm's rounding, rows
    without a solution: their status) take its route.

    Returns:
        BatchIKResult: q (NaN rows without a solution), PalletizerIKStatus codes, branch +1 up / -1 down.
    """
    T, ref = batch_inputs(targets, reference, branch, BRANCHES)
    signs, offsets = np.array(geo.signs), np.array(geo.offsets)
    ref_t = ref * signs + offsets  # canonical
    refs = [ref_t[j] if ref_t.ndim == 1 else ref_t[:, j] for j in range(4)]
    n = len(T)
    lo, hi, cont, arm = geo.lower, geo.upper, geo.continuous, geo.arm
    x, y, z, yaw = T[:, 0], T[:, 1], T[:, 2], T[:, 3]
    rho = np.sqrt(x * x + y * y)
    phi = np.arctan2(y, x)
    v = z - geo.h0
    best_q = np.full((n, 4), np.nan)
    best_d = np.full(n, np.inf)
    sign = np.zeros(n, dtype=np.int64)
    rare = rho <= FREE_R
    for label, sg in (("up", 1.0), ("down", -1.0)):  # solve()'s order: up before down, forwards first
        if branch not in ("nearest", label):
            continue
        for turn_back in (0.0, math.pi):
            r = rho if turn_back == 0.0 else -rho
            D, g, heading, lean, _ = arm.solve_array(v, r - geo.r0)
            reach = (D <= arm.l12 + REACH_TOL) & (D >= arm.d12 - REACH_TOL)
            rare |= reach & (D <= FREE_R)  # a2 = a3, the wrist on the shoulder: the big arm is free (solve's)
            q2, ok2 = nearest_turn_array(heading - sg * lean, lo[1], hi[1], refs[1], cont[1])
            third = sg * g if geo.relative else heading - sg * lean + sg * g  # the elbow, or theta3
            t3, ok3 = nearest_turn_array(third, lo[2], hi[2], refs[2], cont[2])
            q1, ok1 = nearest_turn_array(phi + turn_back, lo[0], hi[0], refs[0], cont[0])
            q4, ok4 = nearest_turn_array(yaw - geo.tool_yaw - q1, lo[3], hi[3], refs[3], cont[3])
            ok = reach & ok1 & ok2 & ok3 & ok4
            # a joint-limit failure near the stretched/folded circles may be rounding: solve() decides those
            rare |= reach & ~ok & (arm.wobble_array(g) > LIMIT_TOL)
            Q = np.column_stack((q1, q2, t3, q4))
            d = np.where(ok, ((Q - ref_t) ** 2).sum(axis=1), np.inf)
            take = d < best_d
            best_q[take], best_d[take], sign[take] = Q[take], d[take], int(sg)
    status = np.where(np.isfinite(best_d), 0, -1).astype(np.int64)
    best_q = (best_q - offsets) * signs  # the file's q
    for i in np.flatnonzero(rare | (status != 0)).tolist():  # their status and reason: solve()'s
        row_ref = ref if ref.ndim == 1 else ref[i]
        res = solve(geo, T[i], branch="all" if branch == "nearest" else branch, reference=row_ref)
        best = res.nearest(row_ref) if res.success else None
        status[i] = int(res.status)
        best_q[i] = np.nan if best is None else best.q
        sign[i] = 0 if best is None else (1 if best.branch == "up" else -1)
    return BatchIKResult(best_q, status, sign, PalletizerIKStatus, BRANCHES)
