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

The geometry is read from the loaded Pinocchio model (:meth:`PalletizerGeometry.from_robot`), as the
SCARA's is: its forward kinematics at three configurations gives r0 = a1 + a4, h0 = d1 + d2 + d5, a2, a3
and the tool's yaw, and the closed form above is then checked against the model at random configurations.

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

from .._checks import _vector
from ..errors import InvalidInputError, NoSolutionError, ParameterError, UrdfError
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
from .results import BatchIKResult, IKResult, result_of
from .targets import batch_inputs, parse_target, reference_floats, weight_floats

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import Robot

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
    arm: Planar2R = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("r0", "h0", "a2", "a3", "tool_yaw"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ParameterError(name, value, "must be finite")
        for name in ("a2", "a3"):
            if getattr(self, name) <= 0:
                raise ParameterError(name, getattr(self, name), "must be > 0")
        object.__setattr__(self, "arm", Planar2R(self.a2, self.a3))

    @classmethod
    def from_robot(cls, robot: Robot) -> PalletizerGeometry:
        """Read the geometry from the robot's Pinocchio model (forward kinematics at three configurations).

        Raises:
            NotPalletizerError: the model does not follow the closed form (checked at 8 seeded random
                configurations to FK_TOL), or its arms have no length.
        """
        fk = robot.tool_pose
        x0, y0, z0, yaw0 = fk(np.zeros(4)).tolist()
        x2, _, z2, _ = fk(np.array([0.0, 0.5 * math.pi, 0.0, 0.0])).tolist()
        x3, _, _, _ = fk(np.array([0.0, 0.0, 0.5 * math.pi, 0.0])).tolist()
        a2, a3 = x2 - x0, x3 - x0
        if not (a2 > 1e-9 and a3 > 1e-9 and abs(y0) < FK_TOL):
            raise NotPalletizerError(f"robot {robot.name!r}: turning joint2 or joint3 by 90 deg does not move the "
                                     "tool forwards: not a palletizer's arm (q = q1, q2, theta3, q4)")  # fmt: skip
        model = robot.model
        data = model.createData()
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        bMs = data.oMf[robot.base_id].actInv(data.oMi[model.getJointId(robot.joint_names[1])])
        limits = robot.limits
        cont = tuple(robot.continuous)
        geo = cls(
            r0=x0, h0=z0 - a2 - a3, a2=a2, a3=a3, tool_yaw=yaw0,
            lower=tuple(-math.inf if c else v for c, v in zip(cont, limits.lower)),  # type: ignore[arg-type]
            upper=tuple(math.inf if c else v for c, v in zip(cont, limits.upper)),  # type: ignore[arg-type]
            shoulder=(float(bMs.translation[0]), float(bMs.translation[2])),
            continuous=cont,
            R0=robot.tool_placement(np.zeros(4)).rotation.copy(),
        )  # fmt: skip
        rng = np.random.default_rng(0)
        for q in rng.uniform(-math.pi, math.pi, (8, 4)):
            err = np.abs(forward(geo, q) - fk(q))
            err[3] = abs(wrap(float(err[3])))
            if err.max() > FK_TOL:
                raise NotPalletizerError(
                    f"robot {robot.name!r}: the palletizer's closed form departs from the model by {err.max():.3g} "
                    f"at q = {np.round(q, 6).tolist()} (a2 = {a2:.9g}, a3 = {a3:.9g} m read from the model)"
                )
        return geo


# ------------------------------------------------------------------------------------ conventions
def from_s2(q_s2: Sequence[float]) -> np.ndarray:
    """S2's ``(q1, q2, q3, q5)`` (q3 relative to the big arm) -> ``q = (q1, q2, theta3 = q2 + q3, q5)``."""
    a = _vector("q_s2", q_s2)
    return np.array([a[0], a[1], a[1] + a[2], a[3]])


def to_s2(q: Sequence[float]) -> np.ndarray:
    """``q = (q1, q2, theta3, q4)`` -> S2's ``(q1, q2, q3 = theta3 - q2, q5 = q4)``."""
    a = _vector("q", q)
    return np.array([a[0], a[1], a[2] - a[1], a[3]])


def wrist_pitch(q: Sequence[float]) -> float:
    """S2's passive wrist pitch ``q4 = -(q2 + q3) = -theta3`` [rad] at ``q`` (the ``wrist_pitch`` joint)."""
    return -float(_vector("q", q)[2])


# ------------------------------------------------------------------------------------ kinematics
def forward(geo: PalletizerGeometry, q: ArrayLike) -> np.ndarray:
    """S2's closed-form FK: (x, y, z, yaw) of tool0 in ``base`` at ``q`` (motor side) [m, rad]."""
    q1, q2, t3, q4 = _vector("q", q)
    r = geo.r0 + geo.a2 * math.sin(q2) + geo.a3 * math.sin(t3)
    z = geo.h0 + geo.a2 * math.cos(q2) + geo.a3 * math.cos(t3)
    return np.array([r * math.cos(q1), r * math.sin(q1), z, q1 + q4 + geo.tool_yaw])


def branch_of(q: ArrayLike) -> str:
    """``"up"`` when sin(q3) >= 0 (q3 = theta3 - q2, S2's small-arm angle), else ``"down"``."""
    a = _vector("q", q)
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
                failed(PalletizerIKStatus.J2_LIMIT, f"q2 = {wrap(q2):.9g} rad ({label}) (+2 pi k) is outside "
                       f"[{lo[1]:.9g}, {hi[1]:.9g}] rad")  # fmt: skip
                continue
            t3 = q2 + q3
            tt3 = nearest_turn(t3, lo[2], hi[2], ref[2], cont[2])
            if tt3 is None:
                edge = turn_edge(t3, lo[2], hi[2], wob)
                if edge is not None:
                    q2b, miss = arm.with_link2(v, r - geo.r0, edge)
                    t2b = nearest_turn(q2b, lo[1], hi[1], ref[1], cont[1])
                    if miss <= REACH_TOL and t2b is not None:
                        t2, tt3 = t2b, nearest_turn(edge, lo[2], hi[2], ref[2])
            if tt3 is None:
                failed(PalletizerIKStatus.J3_LIMIT, f"theta3 = {wrap(t3):.9g} rad ({label}) (+2 pi k) is outside "
                       f"[{lo[2]:.9g}, {hi[2]:.9g}] rad")  # fmt: skip
                continue
            t1 = nearest_turn(phi, lo[0], hi[0], ref[0], cont[0])
            if t1 is None:
                failed(PalletizerIKStatus.J1_LIMIT, f"q1 = {wrap(phi):.9g} rad (+2 pi k) is outside "
                       f"[{lo[0]:.9g}, {hi[0]:.9g}] rad")  # fmt: skip
                continue
            q4 = yaw - geo.tool_yaw - t1[0]
            t4 = nearest_turn(q4, lo[3], hi[3], ref[3], cont[3])
            if t4 is None:
                failed(PalletizerIKStatus.J4_LIMIT, f"q4 = {wrap(q4):.9g} rad (+2 pi k) is outside "
                       f"[{lo[3]:.9g}, {hi[3]:.9g}] rad")  # fmt: skip
                continue
            ts = (t1, t2, tt3, t4)
            found.append((label, singular, [t[0] for t in ts],
                          [None if c else (t[1], t[2]) for c, t in zip(cont, ts)]))  # fmt: skip
    if found:
        found.sort(key=lambda b: b[0] != "up")  # up before down (stable: forwards before backwards)
        return found, None
    return [], (worst[1], worst[2])


def _pose(geo: PalletizerGeometry, target: object) -> tuple[float, float, float, float, float]:
    x, y, z, alpha, tilt = parse_target(target, geo.tool_yaw, geo.R0)
    return x, y, z, alpha + geo.tool_yaw, tilt


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
    found, failure = _branches(geo, x, y, z, yaw, reference_floats(reference), branch)
    return result_of(pose, found, failure, PalletizerIKStatus.OK, geo.continuous, geo.lower, geo.upper, all_turns)


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
    found, failure = _branches(geo, x, y, z, yaw, ref, branch)
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
    refs = [ref[j] if ref.ndim == 1 else ref[:, j] for j in range(4)]
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
            t3, ok3 = nearest_turn_array(heading - sg * lean + sg * g, lo[2], hi[2], refs[2], cont[2])
            q1, ok1 = nearest_turn_array(phi + turn_back, lo[0], hi[0], refs[0], cont[0])
            q4, ok4 = nearest_turn_array(yaw - geo.tool_yaw - q1, lo[3], hi[3], refs[3], cont[3])
            ok = reach & ok1 & ok2 & ok3 & ok4
            # a joint-limit failure near the stretched/folded circles may be rounding: solve() decides those
            rare |= reach & ~ok & (arm.wobble_array(g) > LIMIT_TOL)
            Q = np.column_stack((q1, q2, t3, q4))
            d = np.where(ok, ((Q - ref) ** 2).sum(axis=1), np.inf)
            take = d < best_d
            best_q[take], best_d[take], sign[take] = Q[take], d[take], int(sg)
    status = np.where(np.isfinite(best_d), 0, -1).astype(np.int64)
    for i in np.flatnonzero(rare | (status != 0)).tolist():  # their status and reason: solve()'s
        row_ref = ref if ref.ndim == 1 else ref[i]
        res = solve(geo, T[i], branch="all" if branch == "nearest" else branch, reference=row_ref)
        best = res.nearest(row_ref) if res.success else None
        status[i] = int(res.status)
        best_q[i] = np.nan if best is None else best.q
        sign[i] = 0 if best is None else (1 if best.branch == "up" else -1)
    return BatchIKResult(best_q, status, sign, PalletizerIKStatus, BRANCHES)
