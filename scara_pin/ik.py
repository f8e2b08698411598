"""Closed-form inverse kinematics of a SCARA, with its geometry read from the Pinocchio model.

Geometry (read once from the loaded model, see :class:`ScaraGeometry`): every joint axis is vertical in
the ``base`` frame. Rotations about vertical axes commute with vertical translations, so with the
product of exponentials at the zero configuration the tool pose is

    p_xy(q) = A1 + R(phi1) [u1 + R(phi2) [u2 + R(phi4) t]],   z(q) = z0 + s3 q3,
    yaw(q) = yaw0 + phi1 + phi2 + phi4,                          phi_i = s_i q_i,

where A1 is the shoulder axis (first revolute joint), u1 and u2 the plan-view vectors from it to the
elbow axis and from the elbow to the wrist axis (third revolute joint), t the tool point's offset from
the wrist axis, s_i = +/-1 each axis' direction (+z up), and R(phi) a rotation by phi about z; all at
q = 0. The prismatic joint may sit anywhere in the chain. Arm lengths l1 = |u1|, l2 = |u2|; the zero
offsets beta1 = atan2(u1), beta2 = atan2(u2) allow arms that are not stretched along +x at q = 0.

Inverse: the yaw fixes alpha = phi1 + phi2 + phi4, hence the wrist point W = p - R(alpha) t; the
triangle (l1, l2, r = |W - A1|) gives the elbow angle gamma (angle from arm 1 to arm 2, counter-
clockwise seen from above) by the half-angle form of the law of cosines, which stays accurate at the
stretched and folded singularities:

    tan(gamma / 2) = sqrt((l1 + l2 - r)(l1 + l2 + r)) / sqrt((r - l1 + l2)(r + l1 - l2)).

Branches (as on industrial controllers' lefty/righty arms):
    ``right``: the elbow turns counterclockwise seen from above (sin gamma > 0), like a human right arm
    seen from above, elbow out to the right; for +z joint axes and a zero pose with both arms
    stretched, q2 > 0. ``left``: the mirror image (sin gamma < 0). On the stretched (gamma = 0) or folded
    (gamma = pi) boundary the two coincide; such a solution is reported once, labelled ``right`` for
    gamma = 0 and ``left`` for gamma = pi, and matches either branch filter.

Every 2 pi-equivalent of the revolute joints inside their limits is a separate solution (a J4 range of
+/-400 deg gives several turns). Tolerances: targets within ``REACH_TOL`` (1e-10 m) outside the reach
circles are solved on the circle; joint values within ``LIMIT_TOL`` (1e-10) outside a limit are clamped
onto it.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from .errors import InvalidInputError, ParameterError, UrdfError

if TYPE_CHECKING:
    from .model import Robot

__all__ = [
    "LIMIT_TOL",
    "REACH_TOL",
    "YAW_POSE_TOL",
    "branch_of",
    "BatchIKResult",
    "IKResult",
    "IKSolution",
    "IKStatus",
    "NotScaraError",
    "ScaraGeometry",
    "solve",
    "solve_batch",
]

REACH_TOL = 1e-10
"""[m] a target this close outside a reach circle is solved on it (absorbs rounding)."""
LIMIT_TOL = 1e-10
"""[rad or m] a joint value this close outside a limit is clamped onto it."""
YAW_POSE_TOL = 1e-9
"""[rad] the largest tilt of a target rotation still taken as a pure yaw."""
PARALLEL_TOL = 1e-6
"""[rad] the largest angle between a joint axis and the base z axis for a SCARA."""

_TWO_PI = 2.0 * math.pi


class NotScaraError(UrdfError):
    """The model is not a SCARA the closed form can solve (the reason names the joint)."""


class IKStatus(enum.IntEnum):
    """Why a target has (or has no) solution. Stable codes: the names are part of the interface."""

    OK = 0
    OUT_OF_REACH = 1
    INSIDE_INNER_LIMIT = 2
    J1_LIMIT = 3
    J2_LIMIT = 4
    J3_STROKE = 5
    J4_LIMIT = 6
    NOT_A_YAW_POSE = 7


@dataclass(frozen=True)
class IKSolution:
    """One joint configuration reaching the target.

    Attributes:
        q: joint values in URDF order [rad, m].
        branch: ``"right"`` or ``"left"`` (see the module docstring).
        singular: on the stretched/folded boundary between the branches.
    """

    q: np.ndarray
    branch: str
    singular: bool = False

    def matches(self, branch: str) -> bool:
        """Whether this solution belongs to ``branch`` (``"all"``, ``"left"`` or ``"right"``)."""
        return branch == "all" or self.branch == branch or self.singular


@dataclass(frozen=True)
class IKResult:
    """Every solution of one target, or the reason there is none.

    Attributes:
        target: (x, y, z, yaw) of the tool frame in the base frame [m, rad].
        solutions: all solutions inside the joint limits (empty when ``status`` is not OK).
        status: :class:`IKStatus`.
        message: a sentence with the numbers behind the status.
    """

    target: np.ndarray
    solutions: tuple[IKSolution, ...]
    status: IKStatus
    message: str

    @property
    def success(self) -> bool:
        """True when at least one solution exists."""
        return self.status is IKStatus.OK

    def branch(self, branch: str) -> tuple[IKSolution, ...]:
        """The solutions of one branch (``"left"``, ``"right"`` or ``"all"``)."""
        return tuple(s for s in self.solutions if s.matches(branch))

    def nearest(
        self, reference: Sequence[float], weights: Sequence[float] | None = None, branch: str = "all"
    ) -> IKSolution | None:
        """The solution nearest to ``reference`` in weighted joint space (sum of w_i (q_i - ref_i)^2).

        Returns ``None`` only when no solution of ``branch`` exists (check ``status``/``message``).
        """
        candidates = self.branch(branch)
        if not candidates:
            return None
        ref = np.asarray(reference, dtype=float)
        w = np.ones(4) if weights is None else np.asarray(weights, dtype=float)
        return min(candidates, key=lambda s: float(w @ (s.q - ref) ** 2))


@dataclass(frozen=True)
class BatchIKResult:
    """Solutions of N targets, one per target (the requested branch, the turn nearest the reference).

    Attributes:
        q: (N, 4) joint values; NaN rows where there is no solution.
        status: (N,) :class:`IKStatus` codes as integers.
        branch: (N,) +1 for right, -1 for left, 0 where there is no solution.
    """

    q: np.ndarray
    status: np.ndarray
    branch: np.ndarray


@dataclass(frozen=True)
class ScaraGeometry:
    """The SCARA geometry read from a Pinocchio model (see the module docstring for the symbols).

    Attributes:
        revolute: indices in q of the shoulder, elbow and wrist joints (chain order).
        prismatic: index in q of the vertical joint.
        names: joint names in q order.
        signs: per q index, +1 when the axis (or the prismatic direction) is base +z, -1 for -z.
        a1: (x, y) of the shoulder axis in the base frame [m].
        u1, u2: plan-view vectors shoulder -> elbow axis and elbow -> wrist axis at q = 0 [m].
        tool: plan-view offset of the tool point from the wrist axis at q = 0 [m].
        z0: tool z at q = 0 [m]. yaw0: tool yaw at q = 0 [rad].
        R0: tool rotation in the base frame at q = 0.
        lower, upper: joint limits in q order.
    """

    revolute: tuple[int, int, int]
    prismatic: int
    names: tuple[str, ...]
    signs: tuple[float, ...]
    a1: tuple[float, float]
    u1: tuple[float, float]
    u2: tuple[float, float]
    tool: tuple[float, float]
    z0: float
    yaw0: float
    R0: np.ndarray
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    l1: float = field(init=False)
    l2: float = field(init=False)
    beta1: float = field(init=False)
    beta2: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "l1", math.hypot(*self.u1))
        object.__setattr__(self, "l2", math.hypot(*self.u2))
        object.__setattr__(self, "beta1", math.atan2(self.u1[1], self.u1[0]))
        object.__setattr__(self, "beta2", math.atan2(self.u2[1], self.u2[0]))

    # ---------------------------------------------------------------------------------------- reading
    @classmethod
    def from_robot(cls, robot: Robot) -> ScaraGeometry:
        """Read the geometry from a loaded robot; raise :class:`NotScaraError` naming what is wrong."""
        model = robot.model
        data = model.createData()
        names = tuple(model.names[j] for j in range(1, model.njoints))
        if model.njoints - 1 != 4:
            raise NotScaraError(f"a SCARA has 4 joints; this model has {model.njoints - 1}: {', '.join(names)}")
        for j in range(2, model.njoints):
            if model.parents[j] != j - 1:
                raise NotScaraError(f"joint {model.names[j]} does not follow {model.names[j - 1]}: not a serial chain")
        tool_parent = model.frames[robot.tool_id].parentJoint
        if tool_parent != model.njoints - 1:
            raise NotScaraError(f"the tool frame {robot.tool_frame!r} is not carried by the last joint {names[-1]}")
        q0 = np.zeros(model.nq)
        pin.computeJointJacobians(model, data, q0)
        pin.updateFramePlacements(model, data)
        oMb = data.oMf[robot.base_id]
        Rbo = oMb.rotation.T
        revolute: list[int] = []
        prismatic: list[int] = []
        signs = [0.0] * 4
        points: dict[int, np.ndarray] = {}
        for j in range(1, model.njoints):
            jm = model.joints[j]
            name = model.names[j]
            if jm.nq != 1 or jm.nv != 1:
                raise NotScaraError(f"joint {name} ({jm.shortname()}) has nq = {jm.nq}, nv = {jm.nv}; "
                                    "a SCARA's joints are single-DOF revolute or prismatic")  # fmt: skip
            col = pin.getJointJacobian(model, data, j, pin.LOCAL_WORLD_ALIGNED)[:, jm.idx_v]
            lin, ang = Rbo @ col[:3], Rbo @ col[3:]
            if np.linalg.norm(lin) < 1e-12 and abs(np.linalg.norm(ang) - 1) < 1e-12:
                axis, kind = ang, revolute
            elif np.linalg.norm(ang) < 1e-12 and abs(np.linalg.norm(lin) - 1) < 1e-12:
                axis, kind = lin, prismatic
            else:
                raise NotScaraError(f"joint {name} ({jm.shortname()}) is neither revolute nor prismatic")
            tilt = math.atan2(math.hypot(axis[0], axis[1]), abs(axis[2]))
            if tilt > PARALLEL_TOL:
                raise NotScaraError(
                    f"joint {name}'s axis is {math.degrees(tilt):.6g} deg away from the base z axis "
                    f"(more than {PARALLEL_TOL:g} rad): the axes of a SCARA are parallel and vertical"
                )
            signs[j - 1] = 1.0 if axis[2] > 0 else -1.0
            kind.append(j - 1)
            points[j - 1] = oMb.actInv(data.oMi[j]).translation
        if len(revolute) != 3 or len(prismatic) != 1:
            kinds = ", ".join(f"{n} ({'revolute' if i in revolute else 'prismatic'})" for i, n in enumerate(names))
            raise NotScaraError(f"a SCARA has 3 revolute joints and 1 prismatic joint; this model has {kinds}")
        bMt = oMb.actInv(data.oMf[robot.tool_id])
        ra, rb, rc = revolute
        a1, a2, a4 = points[ra][:2], points[rb][:2], points[rc][:2]
        u1, u2, t = a2 - a1, a4 - a2, bMt.translation[:2] - a4
        for vec, what in ((u1, f"{names[rb]}'s axis coincides with {names[ra]}'s"),
                          (u2, f"{names[rc]}'s axis coincides with {names[rb]}'s")):  # fmt: skip
            if math.hypot(*vec) < 1e-9:
                raise NotScaraError(f"{what}: the arm has no length")
        R0 = bMt.rotation.copy()
        if math.hypot(R0[0, 0], R0[1, 0]) < 1e-6:
            raise NotScaraError("the tool frame's x axis is vertical at q = 0: its yaw is undefined")
        return cls(
            revolute=(ra, rb, rc),
            prismatic=prismatic[0],
            names=names,
            signs=tuple(signs),
            a1=(float(a1[0]), float(a1[1])),
            u1=(float(u1[0]), float(u1[1])),
            u2=(float(u2[0]), float(u2[1])),
            tool=(float(t[0]), float(t[1])),
            z0=float(bMt.translation[2]),
            yaw0=math.atan2(R0[1, 0], R0[0, 0]),
            R0=R0,
            lower=tuple(float(v) for v in model.lowerPositionLimit),
            upper=tuple(float(v) for v in model.upperPositionLimit),
        )

    # ---------------------------------------------------------------------------------------- derived
    def elbow_angle(self, q_elbow: float) -> float:
        """gamma (angle from arm 1 to arm 2, counterclockwise from above) at an elbow joint value."""
        return self.signs[self.revolute[1]] * q_elbow + self.beta2 - self.beta1

    def radius_range(self) -> tuple[float, float]:
        """(r_min, r_max) of the wrist axis from the shoulder axis allowed by the elbow's limits [m].

        r(gamma) = sqrt(l1^2 + l2^2 + 2 l1 l2 cos gamma) falls as |gamma| grows to pi, so r_min comes from
        the allowed gamma nearest to pi (mod 2 pi) and r_max from the one nearest to 0.
        """
        e = self.revolute[1]
        g_lo, g_hi = sorted((self.elbow_angle(self.lower[e]), self.elbow_angle(self.upper[e])))

        def reaches(angle: float) -> bool:  # some angle + 2 pi k inside [g_lo, g_hi]
            return angle + math.ceil((g_lo - angle) / _TWO_PI) * _TWO_PI <= g_hi

        ends = (math.cos(g_lo), math.cos(g_hi))
        c_max = 1.0 if reaches(0.0) else max(ends)
        c_min = -1.0 if reaches(math.pi) else min(ends)
        l1, l2 = self.l1, self.l2
        r_max = math.sqrt(max(l1 * l1 + l2 * l2 + 2 * l1 * l2 * c_max, 0.0))
        r_min = math.sqrt(max(l1 * l1 + l2 * l2 + 2 * l1 * l2 * c_min, 0.0))
        return r_min, r_max


def branch_of(geo: ScaraGeometry, q: Sequence[float]) -> str:
    """The branch (``"right"``/``"left"``) of a configuration: the sign of sin(gamma); ``right`` at gamma = 0."""
    g = _wrap(geo.elbow_angle(float(q[geo.revolute[1]])))
    if abs(g) < 1e-12:
        return "right"
    return "right" if 0.0 < g < math.pi else "left"


def _wrap(a: float) -> float:
    """a wrapped to [-pi, pi)."""
    return (a + math.pi) % _TWO_PI - math.pi


def _turns(value: float, lo: float, hi: float) -> list[float]:
    """Every value + 2 pi k inside [lo, hi] (values within LIMIT_TOL outside are clamped)."""
    k0 = math.ceil((lo - LIMIT_TOL - value) / _TWO_PI)
    out = []
    v = value + k0 * _TWO_PI
    while v <= hi + LIMIT_TOL:
        out.append(min(max(v, lo), hi))
        v += _TWO_PI
    return out


def _elbow(geo: ScaraGeometry, r: float) -> float:
    """The elbow angle gamma in [0, pi] for a wrist radius r (clamped to the reachable annulus)."""
    l1, l2 = geo.l1, geo.l2
    outer = max(l1 + l2 - r, 0.0) * (l1 + l2 + r)
    inner = max(r - abs(l1 - l2), 0.0) * (r + abs(l1 - l2))
    return 2.0 * math.atan2(math.sqrt(outer), math.sqrt(inner))


def solve(
    geo: ScaraGeometry,
    target: Sequence[float] | np.ndarray | pin.SE3,
    *,
    branch: str = "all",
    reference: Sequence[float] | None = None,
) -> IKResult:
    """Every joint configuration inside the limits that puts the tool at ``target``.

    Args:
        geo: the robot's geometry (``ScaraGeometry.from_robot(robot)``, or ``robot.ik``).
        target: (x, y, z, yaw) of the tool frame in the base frame [m, rad], or its placement as a
            pin.SE3 or a 4 x 4 matrix (refused with NOT_A_YAW_POSE when it tilts more than 1e-9 rad).
        branch: ``"all"``, ``"left"`` or ``"right"``.
        reference: used where a joint is free (r = 0 with l1 = l2: the shoulder angle is the reference's).

    Returns:
        IKResult: all solutions (sorted: right before left, then by q), or the status and its reason.
    """
    if branch not in ("all", "left", "right"):
        raise InvalidInputError(f"branch {branch!r} must be 'all', 'left' or 'right'")
    x, y, z, alpha, tilt = _target(geo, target)
    pose = np.array([x, y, z, _wrap(alpha + geo.yaw0)])
    if tilt > YAW_POSE_TOL:
        return IKResult(pose, (), IKStatus.NOT_A_YAW_POSE,
                        f"the target tilts the tool by {math.degrees(tilt):.6g} deg (roll/pitch); "
                        "a SCARA can only turn it about the vertical axis")  # fmt: skip
    ra, rb, rc = geo.revolute
    ip = geo.prismatic
    s = geo.signs
    lo, hi = geo.lower, geo.upper
    # vertical joint
    qp = (z - geo.z0) / s[ip]
    if not lo[ip] - LIMIT_TOL <= qp <= hi[ip] + LIMIT_TOL:
        return IKResult(pose, (), IKStatus.J3_STROKE,
                        f"z = {z:.9g} m needs {geo.names[ip]} = {qp:.9g} m, outside its stroke "
                        f"[{lo[ip]:.9g}, {hi[ip]:.9g}] m")  # fmt: skip
    qp = min(max(qp, lo[ip]), hi[ip])
    # wrist point and reach
    ca, sa = math.cos(alpha), math.sin(alpha)
    tx, ty = geo.tool
    wx = x - (ca * tx - sa * ty) - geo.a1[0]
    wy = y - (sa * tx + ca * ty) - geo.a1[1]
    r = math.hypot(wx, wy)
    l1, l2 = geo.l1, geo.l2
    if r > l1 + l2 + REACH_TOL:
        return IKResult(pose, (), IKStatus.OUT_OF_REACH,
                        f"the wrist axis would be {r:.9g} m from the shoulder axis, beyond the reach "
                        f"l1 + l2 = {l1 + l2:.9g} m")  # fmt: skip
    r_min, r_max = geo.radius_range()
    if r < r_min - REACH_TOL:
        limited = r_min > abs(l1 - l2) + REACH_TOL
        why = (f"the inner limit r_min = {r_min:.9g} m set by {geo.names[rb]}'s limits "
               f"[{math.degrees(lo[rb]):.6g}, {math.degrees(hi[rb]):.6g}] deg" if limited
               else f"|l1 - l2| = {abs(l1 - l2):.9g} m")  # fmt: skip
        return IKResult(pose, (), IKStatus.INSIDE_INNER_LIMIT,
                        f"the wrist axis would be {r:.9g} m from the shoulder axis, inside {why}")  # fmt: skip
    gamma = _elbow(geo, r)
    singular = gamma < 1e-12 or math.pi - gamma < 1e-12
    elbows = [(gamma, "right"), (-gamma, "left")] if not singular else [
        (gamma, "right" if gamma < 1.0 else "left")]  # fmt: skip
    solutions: list[IKSolution] = []
    failures: list[tuple[IKStatus, str]] = []
    phi_ref = None
    if reference is not None:
        phi_ref = s[ra] * float(reference[ra])
    for g, label in elbows:
        if not (branch == "all" or label == branch or singular):
            continue
        if r > 0.0:
            theta1 = math.atan2(wy, wx) - math.atan2(l2 * math.sin(g), l1 + l2 * math.cos(g))
        else:  # l1 = l2 and the wrist on the shoulder axis: the shoulder is free
            theta1 = (phi_ref if phi_ref is not None else 0.0) + geo.beta1
        phi1 = theta1 - geo.beta1
        phi2 = g + geo.beta1 - geo.beta2
        phi4 = alpha - phi1 - phi2
        q_a = _turns(s[ra] * phi1, lo[ra], hi[ra])
        q_b = _turns(s[rb] * phi2, lo[rb], hi[rb])
        q_c = _turns(s[rc] * phi4, lo[rc], hi[rc])
        if not q_b:
            failures.append((IKStatus.J2_LIMIT, f"{label}: {geo.names[rb]} = {_wrap(s[rb] * phi2):.9g} rad (+2 pi k) "
                             f"outside [{lo[rb]:.9g}, {hi[rb]:.9g}]"))  # fmt: skip
            continue
        if not q_a:
            failures.append((IKStatus.J1_LIMIT, f"{label}: {geo.names[ra]} = {_wrap(s[ra] * phi1):.9g} rad (+2 pi k) "
                             f"outside [{lo[ra]:.9g}, {hi[ra]:.9g}]"))  # fmt: skip
            continue
        if not q_c:
            failures.append((IKStatus.J4_LIMIT, f"{label}: {geo.names[rc]} = {_wrap(s[rc] * phi4):.9g} rad (+2 pi k) "
                             f"outside [{lo[rc]:.9g}, {hi[rc]:.9g}]"))  # fmt: skip
            continue
        for va in q_a:
            for vb in q_b:
                # the wrist takes up whatever turns the shoulder and elbow add, to keep alpha
                for vc in _turns(s[rc] * (alpha - s[ra] * va - s[rb] * vb), lo[rc], hi[rc]):
                    q = np.empty(4)
                    q[ra], q[rb], q[rc], q[ip] = va, vb, vc, qp
                    solutions.append(IKSolution(q, label, singular))
    if solutions:
        return IKResult(pose, tuple(solutions), IKStatus.OK, f"{len(solutions)} solution(s)")
    if not failures:  # the requested branch was not tried: cannot happen for 'all'
        return IKResult(pose, (), IKStatus.J2_LIMIT, f"no {branch} solution")
    order = (IKStatus.J2_LIMIT, IKStatus.J1_LIMIT, IKStatus.J4_LIMIT)  # the later the stage, the closer
    status = max((f[0] for f in failures), key=order.index)
    return IKResult(pose, (), status, "no solution inside the joint limits: " + "; ".join(f[1] for f in failures))


def _target(geo: ScaraGeometry, target: object) -> tuple[float, float, float, float, float]:
    """(x, y, z, alpha, tilt) of a target: alpha = yaw - yaw0 is the turn of the arm, tilt its roll/pitch."""
    if isinstance(target, pin.SE3):
        M = target.homogeneous
    else:
        M = np.asarray(target, dtype=float)
    if M.shape == (4,):
        if not np.isfinite(M).all():
            raise ParameterError("target", M.tolist(), "must be 4 finite numbers (x, y, z, yaw)")
        return float(M[0]), float(M[1]), float(M[2]), float(M[3]) - geo.yaw0, 0.0
    if M.shape != (4, 4) or not np.isfinite(M).all():
        raise ParameterError("target", "array of shape " + str(M.shape), "must be (x, y, z, yaw) or a 4 x 4 pose")
    R = M[:3, :3]
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0:
        raise ParameterError("target rotation", R.round(12).tolist(), "must be a rotation matrix")
    E = R @ geo.R0.T  # a pure yaw of the tool's zero-pose rotation: E = Rz(alpha)
    tilt = math.atan2(math.hypot(E[0, 2], E[1, 2]), E[2, 2])
    return float(M[0, 3]), float(M[1, 3]), float(M[2, 3]), math.atan2(E[1, 0], E[0, 0]), tilt


def solve_batch(
    geo: ScaraGeometry,
    targets: np.ndarray,
    *,
    branch: str = "right",
    reference: np.ndarray | Sequence[float] | None = None,
) -> BatchIKResult:
    """The closed form vectorised over N targets (no Python loop per target).

    For each target it returns ONE solution: of the requested branch (``"right"``/``"left"``), or with
    ``branch="nearest"`` the branch whose solution is nearest to ``reference``; among 2 pi-equivalent
    turns the one nearest to ``reference`` (default: the joint-range midpoints).

    Args:
        geo: the robot's geometry.
        targets: (N, 4) array of (x, y, z, yaw) [m, rad].
        branch: ``"right"``, ``"left"`` or ``"nearest"``.
        reference: (4,) or (N, 4) reference configuration(s).

    Returns:
        BatchIKResult with (N, 4) q, (N,) status codes and (N,) branch signs.
    """
    T = np.asarray(targets, dtype=float)
    if T.ndim != 2 or T.shape[1] != 4:
        raise ParameterError("targets", f"array of shape {T.shape}", "must have shape (N, 4): x, y, z, yaw")
    if branch not in ("right", "left", "nearest"):
        raise InvalidInputError(f"branch {branch!r} must be 'right', 'left' or 'nearest'")
    lo = np.asarray(geo.lower)
    hi = np.asarray(geo.upper)
    ref = (lo + hi) / 2 if reference is None else np.broadcast_to(np.asarray(reference, dtype=float), T.shape)
    if branch == "nearest":
        right = _batch_branch(geo, T, 1.0, ref, lo, hi)
        left = _batch_branch(geo, T, -1.0, ref, lo, hi)
        dr = np.where(right.status == 0, ((right.q - ref) ** 2).sum(axis=1), np.inf)
        dl = np.where(left.status == 0, ((left.q - ref) ** 2).sum(axis=1), np.inf)
        use_left = (dl < dr)[:, None]
        # neither branch solves: report the one that got further (J4 after J1 after J2, as `solve` does)
        stage = np.zeros(len(IKStatus), dtype=np.int64)
        stage[[IKStatus.OK, IKStatus.J2_LIMIT, IKStatus.J1_LIMIT, IKStatus.J4_LIMIT]] = [9, 1, 2, 3]
        status = np.where(stage[left.status] > stage[right.status], left.status, right.status)
        return BatchIKResult(np.where(use_left, left.q, right.q), status,
                             np.where(status == 0, np.where(use_left[:, 0], left.branch, right.branch), 0))  # fmt: skip
    return _batch_branch(geo, T, 1.0 if branch == "right" else -1.0, ref, lo, hi)


def _batch_turn(value: np.ndarray, lo: float, hi: float, ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per element, value + 2 pi k inside [lo, hi] nearest to ref; and whether one exists."""
    k_min = np.ceil((lo - LIMIT_TOL - value) / _TWO_PI)
    k_max = np.floor((hi + LIMIT_TOL - value) / _TWO_PI)
    k = np.clip(np.round((ref - value) / _TWO_PI), k_min, k_max)
    return np.clip(value + k * _TWO_PI, lo, hi), k_min <= k_max


def _batch_branch(
    geo: ScaraGeometry, T: np.ndarray, sign: float, ref: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> BatchIKResult:
    ra, rb, rc = geo.revolute
    ip = geo.prismatic
    s = geo.signs
    l1, l2 = geo.l1, geo.l2
    n = T.shape[0]
    status = np.zeros(n, dtype=np.int64)
    alpha = T[:, 3] - geo.yaw0
    ca, sa = np.cos(alpha), np.sin(alpha)
    tx, ty = geo.tool
    wx = T[:, 0] - (ca * tx - sa * ty) - geo.a1[0]
    wy = T[:, 1] - (sa * tx + ca * ty) - geo.a1[1]
    r = np.hypot(wx, wy)
    outer = np.maximum(l1 + l2 - r, 0.0) * (l1 + l2 + r)
    inner = np.maximum(r - abs(l1 - l2), 0.0) * (r + abs(l1 - l2))
    gamma = sign * 2.0 * np.arctan2(np.sqrt(outer), np.sqrt(inner))
    theta1 = np.arctan2(wy, wx) - np.arctan2(l2 * np.sin(gamma), l1 + l2 * np.cos(gamma))
    phi1 = theta1 - geo.beta1
    phi2 = gamma + (geo.beta1 - geo.beta2)
    q = np.empty((n, 4))
    qa, ok_a = _batch_turn(s[ra] * phi1, lo[ra], hi[ra], ref[..., ra])
    qb, ok_b = _batch_turn(s[rb] * phi2, lo[rb], hi[rb], ref[..., rb])
    qc, ok_c = _batch_turn(s[rc] * (alpha - s[ra] * qa - s[rb] * qb), lo[rc], hi[rc], ref[..., rc])
    qp = (T[:, 2] - geo.z0) / s[ip]
    ok_p = (qp >= lo[ip] - LIMIT_TOL) & (qp <= hi[ip] + LIMIT_TOL)
    q[:, ra], q[:, rb], q[:, rc], q[:, ip] = qa, qb, qc, np.clip(qp, lo[ip], hi[ip])
    r_min, _ = geo.radius_range()
    # the same precedence as the scalar solver (later assignments win)
    status[~ok_c] = IKStatus.J4_LIMIT
    status[~ok_a] = IKStatus.J1_LIMIT
    status[~ok_b] = IKStatus.J2_LIMIT
    status[r < r_min - REACH_TOL] = IKStatus.INSIDE_INNER_LIMIT
    status[r > l1 + l2 + REACH_TOL] = IKStatus.OUT_OF_REACH
    status[~ok_p] = IKStatus.J3_STROKE
    status[~np.isfinite(T).all(axis=1)] = IKStatus.OUT_OF_REACH
    bad = status != 0
    q[bad] = np.nan
    branch = np.where(bad, 0, int(sign))
    return BatchIKResult(q, status, branch)
