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

Inverse (S2): ``q1 = atan2(y, x)`` (and ``q1 + pi`` with the arm reaching backwards, ``r < 0``);
the shoulder-to-wrist vector in the arm plane ``(h, v) = (r - a1 - a4, z - d1 - d2 - d5)``, of length
``D``; the law of cosines on the (a2, a3, D) triangle, in its half-angle form (accurate at the
stretched and folded boundaries),

    tan(|q3| / 2) = sqrt((a2 + a3 - D)(a2 + a3 + D)) / sqrt((D - a2 + a3)(D + a2 - a3)),

gives the two elbow branches: ``up`` with ``sin q3 > 0`` (the elbow above the shoulder-wrist line when
the wrist is in front of the shoulder) and ``down`` with ``sin q3 < 0``; then
``q2 = atan2(h, v) - atan2(a3 sin q3, a2 + a3 cos q3)``, ``theta3 = q2 + q3``, ``q4 = yaw - tool_yaw - q1``.
On the stretched (q3 = 0) or folded (q3 = pi) boundary the branches coincide: one solution, flagged
``singular``, labelled ``up`` (q3 = 0) or ``down`` (q3 = pi). Every 2 pi-equivalent of a joint inside
its limits is a separate solution. Tolerances as the SCARA's (:data:`scara_pin.ik.REACH_TOL`,
:data:`scara_pin.ik.LIMIT_TOL`).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from .._checks import _vector
from ..errors import InvalidInputError, ParameterError, UrdfError
from .scara import REACH_TOL, YAW_POSE_TOL, IKResult, IKSolution, _turns

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import Robot

__all__ = [
    "BRANCHES",
    "NotPalletizerError",
    "PalletizerGeometry",
    "PalletizerIKResult",
    "PalletizerIKStatus",
    "branch_of",
    "forward",
    "from_s2",
    "solve",
    "to_s2",
    "wrist_pitch",
]

BRANCHES = ("all", "up", "down")
"""Branch filters of :func:`solve`."""
FREE_R = 1e-12
"""[m] a target this close to the waist axis leaves q1 free (the reference's q1, else mid-range)."""
_TWO_PI = 2.0 * math.pi


class NotPalletizerError(UrdfError):
    """The robot is not a palletizer described by palletizer parameters (the reason says why)."""


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
class PalletizerIKResult(IKResult):
    """As :class:`scara_pin.ik.IKResult`, with :class:`PalletizerIKStatus` codes and branches up/down."""

    @property
    def success(self) -> bool:
        """True when at least one solution exists."""
        return self.status is PalletizerIKStatus.OK


@dataclass(frozen=True)
class PalletizerGeometry:
    """The palletizer's parameters (see ``urdf/config/palletizer/kinematics.yaml``) and joint limits.

    Attributes:
        d1, d2, a1, a2, a3, a4, d5: S2's lengths [m]. tool_yaw: tool0's turn about the flange axis [rad].
        lower, upper: position limits of ``q`` (motor side: q1, q2, theta3, q4) [rad].
    """

    d1: float
    d2: float
    a1: float
    a2: float
    a3: float
    a4: float
    d5: float
    tool_yaw: float
    lower: tuple[float, float, float, float]
    upper: tuple[float, float, float, float]

    def __post_init__(self) -> None:
        for name in ("d1", "d2", "a1", "a2", "a3", "a4", "d5", "tool_yaw"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise ParameterError(name, value, "must be finite")
        for name in ("a2", "a3"):
            if getattr(self, name) <= 0:
                raise ParameterError(name, getattr(self, name), "must be > 0")

    @classmethod
    def from_robot(cls, robot: Robot) -> PalletizerGeometry:
        """The geometry of a robot generated from palletizer parameters (the same yaml as its URDF).

        Raises:
            NotPalletizerError: the robot was not generated from palletizer parameters (a SCARA, or a
                URDF file: this solver reads the yaml, not the model).
        """
        params = robot.parameters
        if params is None or params.kind != "palletizer":
            what = "a URDF file" if params is None else f"a {params.kind} robot"
            raise NotPalletizerError(f"robot {robot.name!r} is {what}: the palletizer IK needs palletizer "
                                     "parameters (kind: palletizer in kinematics.yaml)")  # fmt: skip
        v = params.values
        lim = robot.limits
        return cls(v["d1"], v["d2"], v["a1"], v["a2"], v["a3"], v["a4"], v["d5"], v["tool_yaw"],
                   tuple(lim.lower), tuple(lim.upper))  # type: ignore[arg-type]  # fmt: skip


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
def forward(geo: PalletizerGeometry, q: Sequence[float]) -> np.ndarray:
    """S2's closed-form FK: (x, y, z, yaw) of tool0 in ``base`` at ``q`` (motor side) [m, rad]."""
    q1, q2, t3, q4 = _vector("q", q)
    r = geo.a1 + geo.a2 * math.sin(q2) + geo.a3 * math.sin(t3) + geo.a4
    z = geo.d1 + geo.d2 + geo.a2 * math.cos(q2) + geo.a3 * math.cos(t3) + geo.d5
    return np.array([r * math.cos(q1), r * math.sin(q1), z, q1 + q4 + geo.tool_yaw])


def branch_of(q: ArrayLike) -> str:
    """``"up"`` when sin(q3) >= 0 (q3 = theta3 - q2, S2's small-arm angle), else ``"down"``."""
    a = _vector("q", q)
    return "up" if math.sin(a[2] - a[1]) >= 0.0 else "down"


def _target(geo: PalletizerGeometry, target: object) -> tuple[np.ndarray, float]:
    """The (x, y, z, yaw) of a target and the tilt of its rotation from a pure yaw [rad]."""
    M = target.homogeneous if isinstance(target, pin.SE3) else np.asarray(target, dtype=float)
    if M.shape == (4,):
        if not np.isfinite(M).all():
            raise ParameterError("target", M.tolist(), "must be 4 finite numbers (x, y, z, yaw)")
        return M.astype(float), 0.0
    if M.shape != (4, 4) or not np.isfinite(M).all():
        raise ParameterError("target", "array of shape " + str(M.shape), "must be (x, y, z, yaw) or a 4 x 4 pose")
    R = M[:3, :3]
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0:
        raise ParameterError("target rotation", R.round(12).tolist(), "must be a rotation matrix")
    # tool0's z axis points down: a pure yaw pose has R[:, 2] = (0, 0, -1)
    tilt = math.atan2(math.hypot(R[0, 2], R[1, 2]), -R[2, 2])
    return np.array([M[0, 3], M[1, 3], M[2, 3], math.atan2(R[1, 0], R[0, 0])]), tilt


def solve(
    geo: PalletizerGeometry,
    target: ArrayLike | pin.SE3,
    *,
    branch: str = "all",
    reference: ArrayLike | None = None,
) -> PalletizerIKResult:
    """Every configuration ``q`` (motor side) inside the limits that puts tool0 at ``target``.

    Args:
        geo: the palletizer's geometry.
        target: (x, y, z, yaw) of tool0 in ``base`` [m, rad], or its 4 x 4 pose / pin.SE3 (a pure yaw).
        branch: ``"all"``, ``"up"`` or ``"down"``.
        reference: a configuration; only used to fix q1 when the target lies on the waist axis.

    Returns:
        PalletizerIKResult: the solutions of ``branch`` (up before down, then by q), or the status of
        the most advanced failure of that branch (reach, then J2, J3, J1, J4 limits) with its numbers.
    """
    if branch not in BRANCHES:
        raise InvalidInputError(f"branch {branch!r} must be one of {', '.join(BRANCHES)}")
    pose, tilt = _target(geo, target)
    if tilt > YAW_POSE_TOL:
        return PalletizerIKResult(pose, (), PalletizerIKStatus.NOT_A_YAW_POSE,
                                  f"the target's z axis is tilted by {tilt:.3g} rad from the vertical; "
                                  "the palletizer's flange stays level")  # fmt: skip
    x, y, z, yaw = (float(v) for v in pose)
    lo, hi = geo.lower, geo.upper
    rho = math.hypot(x, y)
    if rho <= FREE_R:
        phi = float(reference[0]) if reference is not None else 0.5 * (lo[0] + hi[0])
        candidates = [(phi, 0.0)]
    else:
        phi = math.atan2(y, x)
        candidates = [(phi, rho), (phi + math.pi, -rho)]  # reaching forwards, and backwards over the waist
    solutions: list[IKSolution] = []
    worst = (-1, PalletizerIKStatus.OUT_OF_REACH, "")
    v = z - geo.d1 - geo.d2 - geo.d5
    a2, a3 = geo.a2, geo.a3
    reach, inner = a2 + a3, abs(a2 - a3)

    def failed(status: PalletizerIKStatus, message: str) -> None:
        nonlocal worst
        if _STAGE[status] > worst[0]:
            worst = (_STAGE[status], status, message)

    for phi, r in candidates:
        h = r - geo.a1 - geo.a4
        D = math.hypot(h, v)
        if D > reach:
            if D > reach + REACH_TOL:
                failed(PalletizerIKStatus.OUT_OF_REACH,
                       f"the wrist would be {D:.9g} m from the shoulder axis, beyond a2 + a3 = {reach:.9g} m")
                continue
            D = reach
        if D < inner:
            if D < inner - REACH_TOL:
                failed(PalletizerIKStatus.INSIDE_INNER_LIMIT,
                       f"the wrist would be {D:.9g} m from the shoulder axis, inside |a2 - a3| = {inner:.9g} m")
                continue
            D = inner
        g = 2.0 * math.atan2(math.sqrt(max((reach - D) * (reach + D), 0.0)),
                             math.sqrt(max((D - a2 + a3) * (D + a2 - a3), 0.0)))  # fmt: skip
        psi = math.atan2(h, v)
        if g == 0.0 or g == math.pi:
            elbows = [(g, "up" if g == 0.0 else "down", True)]
        else:
            elbows = [(g, "up", False), (-g, "down", False)]
        for q3, label, singular in elbows:
            if not (branch == "all" or label == branch or singular):
                continue
            q2 = psi - math.atan2(a3 * math.sin(q3), a2 + a3 * math.cos(q3))
            q2 = (q2 + math.pi) % _TWO_PI - math.pi
            t3 = (q2 + q3 + math.pi) % _TWO_PI - math.pi
            q2s = _turns(q2, lo[1], hi[1])
            if not q2s:
                failed(PalletizerIKStatus.J2_LIMIT,
                       f"q2 = {q2:.9g} rad ({label}) is outside [{lo[1]:.9g}, {hi[1]:.9g}]")
                continue
            t3s = _turns(t3, lo[2], hi[2])
            if not t3s:
                failed(PalletizerIKStatus.J3_LIMIT,
                       f"theta3 = {t3:.9g} rad ({label}) is outside [{lo[2]:.9g}, {hi[2]:.9g}]")
                continue
            q1s = _turns(phi, lo[0], hi[0])
            if not q1s:
                failed(PalletizerIKStatus.J1_LIMIT, f"q1 = {_wrap(phi):.9g} rad (+ 2 pi k) is outside "
                       f"[{lo[0]:.9g}, {hi[0]:.9g}]")  # fmt: skip
                continue
            for q1 in q1s:
                q4s = _turns(yaw - geo.tool_yaw - q1, lo[3], hi[3])
                if not q4s:
                    failed(PalletizerIKStatus.J4_LIMIT, f"q4 = {_wrap(yaw - geo.tool_yaw - q1):.9g} rad (+ 2 pi k) "
                           f"is outside [{lo[3]:.9g}, {hi[3]:.9g}]")  # fmt: skip
                    continue
                for q2v in q2s:
                    for t3v in t3s:
                        for q4 in q4s:
                            solutions.append(IKSolution(np.array([q1, q2v, t3v, q4]), label, singular))
    if solutions:
        solutions.sort(key=lambda s: (s.branch != "up", s.q.tolist()))
        return PalletizerIKResult(pose, tuple(solutions), PalletizerIKStatus.OK, f"{len(solutions)} solution(s)")
    return PalletizerIKResult(pose, (), worst[1], worst[2])


def _wrap(a: float) -> float:
    return (a + math.pi) % _TWO_PI - math.pi
