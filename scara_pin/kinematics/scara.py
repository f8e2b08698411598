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

Three entry points: :func:`solve` (every solution of one target, as objects, with the reason when there
is none), :func:`solve_nearest` (the one solution nearest to a reference configuration, as a controller
needs it between consecutive points; its regular case runs in the compiled ``scara_pin._speedups``), and
:func:`solve_batch` (N targets, vectorised with numpy).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, overload

import numpy as np
import pinocchio as pin

from .. import _fast
from .._checks import _vector
from ..errors import InvalidInputError, NoSolutionError, ParameterError, UrdfError

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import Robot
    from .palletizer import PalletizerIKStatus

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
    "solve_nearest",
]

REACH_TOL = 1e-10
"""[m] a target this close outside a reach circle is solved on it (absorbs rounding)."""
LIMIT_TOL = 1e-10
"""[rad or m] a joint value this close outside a limit is clamped onto it."""
SNAP_TOL = 8 * 2.0**-52
"""A wrist radius within SNAP_TOL (l1 + l2) of the stretched or folded circle, a few rounding errors, is
taken as on it: the sampled q = 0 elbow then comes back exactly, not as two branches 3e-8 rad apart."""
FREE_R = 1e-12
"""[m] a wrist this close to the shoulder axis (possible when l1 = l2) leaves the shoulder angle free."""
SINGULAR_GAMMA = 1e-12
"""[rad] an elbow angle this close to 0 or pi is stretched/folded: the two branches are one solution."""
YAW_POSE_TOL = 1e-9
"""[rad] the largest tilt of a target rotation still taken as a pure yaw."""
PARALLEL_TOL = 1e-6
"""[rad] the largest angle between a joint axis and the base z axis for a SCARA."""

_TWO_PI = 2.0 * math.pi
_PI = math.pi
_BRANCHES = ("all", "left", "right")
# bound once for the per-target hot path of solve()
_atan2, _sin, _cos, _sqrt = math.atan2, math.sin, math.cos, math.sqrt
_ceil, _isfinite = math.ceil, math.isfinite
_array = np.array
_F64 = np.dtype(np.float64)
_new = object.__new__


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


_OK = IKStatus.OK


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
        status: :class:`IKStatus` (:class:`~scara_pin.palletizer.PalletizerIKStatus` for a palletizer).
        message: a sentence with the numbers behind the status.
    """

    target: np.ndarray
    solutions: tuple[IKSolution, ...]
    status: IKStatus | PalletizerIKStatus
    message: str

    @property
    def success(self) -> bool:
        """True when at least one solution exists."""
        return self.status is IKStatus.OK

    def branch(self, branch: str) -> tuple[IKSolution, ...]:
        """The solutions of one branch (``"left"``, ``"right"`` or ``"all"``)."""
        return tuple(s for s in self.solutions if s.matches(branch))

    def nearest(
        self, reference: ArrayLike, weights: ArrayLike | None = None, branch: str = "all"
    ) -> IKSolution | None:
        """The solution nearest to ``reference`` in weighted joint space (sum of w_i (q_i - ref_i)^2).

        Returns ``None`` only when no solution of ``branch`` exists (check ``status``/``message``).
        """
        candidates = self.branch(branch)
        if not candidates:
            return None
        ref = np.asarray(reference, dtype=float)
        w = np.ones(4) if weights is None else np.asarray(weights, dtype=float)
        d = np.array([s.q for s in candidates]) - ref
        t = d * d * w
        # summed left to right, as scara_pin/_speedups.c does, so that both pick the same one on a tie;
        # argmin: the first on a tie
        return candidates[int(np.argmin(t[:, 0] + t[:, 1] + t[:, 2] + t[:, 3]))]


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
    _radius: tuple[float, float] | None = field(init=False, repr=False, compare=False)
    _fast: tuple[Any, ...] = field(init=False, repr=False, compare=False)
    _cparams: bytes = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "l1", math.hypot(*self.u1))
        object.__setattr__(self, "l2", math.hypot(*self.u2))
        object.__setattr__(self, "beta1", math.atan2(self.u1[1], self.u1[0]))
        object.__setattr__(self, "beta2", math.atan2(self.u2[1], self.u2[0]))
        # Everything the solvers need that does not depend on the target, computed once (the geometry is
        # frozen). Limits that make radius_range() fail (infinite) leave it to fail where it did: in solve.
        try:
            radius: tuple[float, float] | None = self._radius_range()
        except (ArithmeticError, TypeError, ValueError):
            radius = None
        object.__setattr__(self, "_radius", radius)
        ra, rb, rc = self.revolute
        ip = self.prismatic
        s, lo, hi = self.signs, self.lower, self.upper
        tol = LIMIT_TOL
        l1, l2 = self.l1, self.l2
        layout = 1 if (ra, rb, rc, ip) == (0, 1, 3, 2) else 0  # 1: q = (shoulder, elbow, prismatic, wrist)
        inner_min = math.nan if radius is None else radius[0] - REACH_TOL
        fast = (
            ra, rb, rc, ip, s[ra], s[rb], s[rc], s[ip],
            lo[ra], hi[ra], lo[rb], hi[rb], lo[rc], hi[rc], lo[ip], hi[ip],
            lo[ra] - tol, hi[ra] + tol, lo[rb] - tol, hi[rb] + tol, lo[rc] - tol, hi[rc] + tol,
            lo[ip] - tol, hi[ip] + tol,
            self.z0, self.yaw0, self.a1[0], self.a1[1], self.tool[0], self.tool[1],
            l1, l2, self.beta1, self.beta2, l1 + l2 + REACH_TOL, l1 + l2, abs(l1 - l2),
            layout, inner_min, self.tool == (0.0, 0.0),
        )  # fmt: skip
        object.__setattr__(self, "_fast", fast)
        # the same numbers for the compiled nearest() (scara_pin/_speedups.c, struct Geometry: this order):
        # fast[:37] is everything from the joint indices to |l1 - l2|
        object.__setattr__(self, "_cparams", b"")

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
        q0 = pin.neutral(model)  # q = 0 (a continuous joint's (cos, sin) = (1, 0))
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
            continuous = jm.nq == 2 and jm.nv == 1 and robot.continuous[j - 1]
            if (jm.nq != 1 and not continuous) or jm.nv != 1:
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
            # continuous joints: the robot's one-turn range [-pi, pi] (see Robot); others: the model's limits
            lower=tuple(robot.limits.lower[j - 1] if robot.continuous[j - 1]
                        else float(model.lowerPositionLimit[model.joints[j].idx_q]) for j in range(1, 5)),
            upper=tuple(robot.limits.upper[j - 1] if robot.continuous[j - 1]
                        else float(model.upperPositionLimit[model.joints[j].idx_q]) for j in range(1, 5)),
        )  # fmt: skip

    # ---------------------------------------------------------------------------------------- derived
    @overload
    def elbow_angle(self, q_elbow: float) -> float: ...

    @overload
    def elbow_angle(self, q_elbow: np.ndarray) -> np.ndarray: ...

    def elbow_angle(self, q_elbow: float | np.ndarray) -> float | np.ndarray:
        """Gamma (angle from arm 1 to arm 2, counterclockwise from above) at an elbow joint value (or array)."""
        return self.signs[self.revolute[1]] * q_elbow + self.beta2 - self.beta1

    def radius_range(self) -> tuple[float, float]:
        """(r_min, r_max) of the wrist axis from the shoulder axis allowed by the elbow's limits [m].

        r(gamma) = sqrt(l1^2 + l2^2 + 2 l1 l2 cos gamma) falls as |gamma| grows to pi, so r_min comes from
        the allowed gamma nearest to pi (mod 2 pi) and r_max from the one nearest to 0.
        """
        if self._radius is not None:
            return self._radius
        return self._radius_range()

    def _radius_range(self) -> tuple[float, float]:
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


def branch_of(geo: ScaraGeometry, q: ArrayLike) -> str:
    """The branch (``"right"``/``"left"``) of a configuration: the sign of sin(gamma); ``right`` at gamma = 0."""
    g = _wrap(geo.elbow_angle(float(q[geo.revolute[1]])))
    if abs(g) < 1e-12:
        return "right"
    return "right" if 0.0 < g < math.pi else "left"


def _wrap(a: float) -> float:
    """A wrapped to [-pi, pi)."""
    return (a + math.pi) % _TWO_PI - math.pi


def _turns(value: float, lo: float, hi: float) -> list[float]:
    """Every value + 2 pi k inside [lo, hi] (values within LIMIT_TOL outside are clamped onto it)."""
    lt, ht = lo - LIMIT_TOL, hi + LIMIT_TOL  # the same numbers as struct Geometry's lt_*, ht_* in _speedups.c
    v = value + _ceil((lt - value) / _TWO_PI) * _TWO_PI
    out = []
    while v <= ht:
        m = lo if lo > v else v
        out.append(hi if hi < m else m)
        v += _TWO_PI
    return out


def solve(
    geo: ScaraGeometry,
    target: ArrayLike | pin.SE3,
    *,
    branch: str = "all",
    reference: ArrayLike | None = None,
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
    # Hot path: plain floats and the math module; numpy only for the arrays the result holds. Every
    # expression below is the one of the straightforward formulation (same operations, same order), so
    # the results are the same to the last bit; only the bookkeeping around them is leaner.
    if branch not in _BRANCHES:
        raise InvalidInputError(f"branch {branch!r} must be 'all', 'left' or 'right'")
    (ra, rb, rc, ip, s_a, s_b, s_c, s_p,
     lo_a, hi_a, lo_b, hi_b, lo_c, hi_c, lo_p, hi_p,
     lt_a, ht_a, lt_b, ht_b, lt_c, ht_c, lt_p, ht_p,
     z0, yaw0, a1x, a1y, tx, ty,
     l1, l2, beta1, beta2, reach, l12, d12,
     layout, inner_min, tool_on_axis) = geo._fast  # fmt: skip
    # a 4-vector of finite floats is read without numpy; anything else goes through _target
    plain = False
    kind = type(target)
    if kind is np.ndarray:
        if target.shape == (4,) and target.dtype is _F64:  # type: ignore[union-attr]
            x, y, z, yaw = target.tolist()  # type: ignore[union-attr]
            plain = _isfinite(x + y + z + yaw)  # else: _target names the culprit
    elif (kind is tuple or kind is list) and len(target) == 4:  # type: ignore[arg-type]
        x, y, z, yaw = target  # type: ignore[misc]
        plain = (type(x) is float and type(y) is float and type(z) is float and type(yaw) is float
                 and _isfinite(x + y + z + yaw))  # fmt: skip
    if plain:
        alpha = yaw - yaw0
    else:
        x, y, z, alpha, tilt = _target(geo, target)
        if tilt > YAW_POSE_TOL:
            return _result(_array([x, y, z, _wrap(alpha + yaw0)]), (), IKStatus.NOT_A_YAW_POSE,
                           f"the target tilts the tool by {math.degrees(tilt):.6g} deg (roll/pitch); "
                           "a SCARA can only turn it about the vertical axis")  # fmt: skip
    pose = _array((x, y, z, (alpha + yaw0 + _PI) % _TWO_PI - _PI))
    # vertical joint
    qp = (z - z0) / s_p
    if not lt_p <= qp <= ht_p:
        return _result(pose, (), IKStatus.J3_STROKE,
                       f"z = {z:.9g} m needs {geo.names[ip]} = {qp:.9g} m, outside its stroke "
                       f"[{lo_p:.9g}, {hi_p:.9g}] m")  # fmt: skip
    m = lo_p if lo_p > qp else qp  # min(max(qp, lo), hi)
    qp = hi_p if hi_p < m else m
    # wrist point and reach
    if tool_on_axis and x and y:  # x - (+/-0.0) = x exactly unless x is a zero (whose sign would change)
        wx = x - a1x
        wy = y - a1y
    else:
        ca, sa = _cos(alpha), _sin(alpha)
        wx = x - (ca * tx - sa * ty) - a1x
        wy = y - (sa * tx + ca * ty) - a1y
    r = _sqrt(wx * wx + wy * wy)  # not math.hypot: the C library's sqrt, as scara_pin/_speedups.c and numpy do
    if r > reach:
        return _result(pose, (), IKStatus.OUT_OF_REACH,
                       f"the wrist axis would be {r:.9g} m from the shoulder axis, beyond the reach "
                       f"l1 + l2 = {l1 + l2:.9g} m")  # fmt: skip
    if r < inner_min:
        return _inside_inner_limit(geo, pose, r, geo.radius_range()[0])
    if inner_min != inner_min:  # NaN: radius_range() fails (infinite limits); let it raise here, as it did
        r_min = geo.radius_range()[0]
        if r < r_min - REACH_TOL:
            return _inside_inner_limit(geo, pose, r, r_min)
    # elbow angle gamma in [0, pi], by the half-angle form (see the module docstring)
    snap = SNAP_TOL * l12
    outer = l12 - r
    if snap > outer:
        outer = 0.0
    outer *= l12 + r
    inner = r - d12
    if snap > inner:
        inner = 0.0
    inner *= r + d12
    gamma = 2.0 * _atan2(_sqrt(outer), _sqrt(inner))
    singular = gamma < SINGULAR_GAMMA or _PI - gamma < SINGULAR_GAMMA
    phi_ref = None
    if reference is not None:
        phi_ref = s_a * float(reference[ra])
    if r > FREE_R:
        # atan2(wy, wx) - atan2(l2 sin g, l1 + l2 cos g) for g = +gamma and g = -gamma (atan2 and sin are
        # odd: the second term changes sign)
        heading = _atan2(wy, wx)
        lean = _atan2(l2 * _sin(gamma), l1 + l2 * _cos(gamma))
    else:  # l1 = l2 and the wrist on the shoulder axis: the shoulder is free
        heading = _free_shoulder(geo, alpha, gamma + beta1 - beta2, phi_ref) + beta1
        lean = 0.0
    if singular:
        elbows: tuple[tuple[float, float, str], ...] = ((gamma, heading - lean, "right" if gamma < 1.0 else "left"),)
    else:
        elbows = ((gamma, heading - lean, "right"), (-gamma, heading + lean, "left"))
    solutions: list[IKSolution] = []
    failures: list[tuple[IKStatus, str]] = []
    for g, theta1, label in elbows:
        if not (branch == "all" or label == branch or singular):
            continue
        phi1 = theta1 - beta1
        phi2 = g + beta1 - beta2
        # every 2 pi-equivalent inside the limits, shoulder and elbow
        va = s_a * phi1
        q_a = _turns(va, lo_a, hi_a)
        vb = s_b * phi2
        q_b = _turns(vb, lo_b, hi_b)
        if not q_b:
            failures.append((IKStatus.J2_LIMIT, f"{label}: {geo.names[rb]} = {_wrap(vb):.9g} rad (+2 pi k) "
                             f"outside [{lo_b:.9g}, {hi_b:.9g}]"))  # fmt: skip
            continue
        if not q_a:
            failures.append((IKStatus.J1_LIMIT, f"{label}: {geo.names[ra]} = {_wrap(va):.9g} rad (+2 pi k) "
                             f"outside [{lo_a:.9g}, {hi_a:.9g}]"))  # fmt: skip
            continue
        found = len(solutions)
        for qa in q_a:
            for qb in q_b:
                # the wrist takes up whatever turns the shoulder and elbow add, to keep alpha
                for qc in _turns(s_c * (alpha - s_a * qa - s_b * qb), lo_c, hi_c):
                    if layout:
                        q = _array((qa, qb, qp, qc))
                    else:
                        q = np.empty(4)
                        q[ra], q[rb], q[rc], q[ip] = qa, qb, qc, qp
                    # IKSolution(q, label, singular) without the frozen dataclass' __init__ (3 x
                    # object.__setattr__): the same object, built in half the time
                    sol = _new(IKSolution)
                    d = sol.__dict__
                    d["q"] = q
                    d["branch"] = label
                    d["singular"] = singular
                    solutions.append(sol)
        if len(solutions) == found:  # no wrist turn inside the limits (checked on the clamped q_a, q_b)
            phi4 = s_c * (alpha - phi1 - phi2)
            failures.append((IKStatus.J4_LIMIT, f"{label}: {geo.names[rc]} = {_wrap(phi4):.9g} rad "
                             f"(+2 pi k) outside [{lo_c:.9g}, {hi_c:.9g}]"))  # fmt: skip
    if solutions:
        return _result(pose, tuple(solutions), _OK, f"{len(solutions)} solution(s)")
    if not failures:  # the requested branch was not tried: cannot happen for 'all'
        return _result(pose, (), IKStatus.J2_LIMIT, f"no {branch} solution")
    order = (IKStatus.J2_LIMIT, IKStatus.J1_LIMIT, IKStatus.J4_LIMIT)  # the later the stage, the closer
    status = max((f[0] for f in failures), key=order.index)
    return _result(pose, (), status, "no solution inside the joint limits: " + "; ".join(f[1] for f in failures))


_nearest_c = _fast.nearest


def solve_nearest(
    geo: ScaraGeometry,
    target: ArrayLike | pin.SE3,
    reference: ArrayLike,
    *,
    weights: ArrayLike | None = None,
    branch: str = "all",
) -> np.ndarray:
    """The one solution nearest to ``reference``: what a controller needs between consecutive points.

    The same answer as ``solve(geo, target, branch=branch, reference=reference).nearest(reference, weights,
    branch).q``: among every solution inside the limits (both branches unless ``branch`` says otherwise,
    every 2 pi turn), the one with the least sum_i w_i (q_i - reference_i)^2; on a tie the first in
    :func:`solve`'s order. The regular case runs in the compiled ``scara_pin._speedups`` when it is built;
    everything else (a free shoulder, SE3 targets, no solution) takes :func:`solve`.

    Args:
        geo: the robot's geometry (``robot.kinematics``).
        target: (x, y, z, yaw) [m, rad], a pin.SE3 or a 4 x 4 pose, as for :func:`solve`.
        reference: 4 joint values [rad, m] (the previous point, say).
        weights: 4 non-negative weights of the joint-space distance (default: all 1).
        branch: ``"all"``, ``"left"`` or ``"right"``.

    Returns:
        np.ndarray: the joint values (a new array).

    Raises:
        NoSolutionError: no solution inside the limits; ``status`` and ``reason`` say why (exit code 3).
        InvalidInputError: a malformed target, reference, weights or branch.
    """
    q = _nearest_c(geo._cparams, target, reference, weights, branch)
    if q is not None:
        return q
    return _nearest_py(geo, target, reference, weights, branch)


def _nearest_py(
    geo: ScaraGeometry, target: object, reference: object, weights: object, branch: str
) -> np.ndarray:
    """:func:`solve_nearest` through :func:`solve` (every case, with the reasons)."""
    ref, w = _reference_weights(reference, weights)
    return _pick_nearest(solve(geo, target, branch=branch, reference=ref), ref, w, branch)  # type: ignore[arg-type]


def _reference_weights(reference: object, weights: object) -> tuple[np.ndarray, np.ndarray]:
    """(reference, weights) as 4 finite floats each (weights >= 0, default 1), or a ParameterError."""
    ref = _vector("reference", reference)
    w = np.ones(4) if weights is None else _vector("weights", weights)
    if (w < 0).any():
        raise ParameterError("weights", w.tolist(), "must be >= 0")
    return ref, w


def _pick_nearest(result: IKResult, ref: np.ndarray, w: np.ndarray, branch: str) -> np.ndarray:
    """The q of ``result``'s solution of ``branch`` nearest to ``ref``, or NoSolutionError with the reason."""
    best = result.nearest(ref, w, branch) if result.success else None
    if best is None:
        raise NoSolutionError(result.status, result.message if not result.success else f"no {branch} solution")
    return best.q.copy()


def _free_shoulder(geo: ScaraGeometry, alpha: float, phi2: float, phi_ref: float | None) -> float:
    """phi1 for a free shoulder (wrist on its axis).

    It is inside the J1 limits, with a J4 turn inside the J4 limits when there is one, and nearest to the
    reference (``phi_ref``, else 0) among those values.
    """
    ra, _, rc = geo.revolute
    s_a, s_c = geo.signs[ra], geo.signs[rc]
    want = s_a * (phi_ref if phi_ref is not None else 0.0)  # in q1 units
    lo_a, hi_a = geo.lower[ra], geo.upper[ra]
    lo_c, hi_c = geo.lower[rc], geo.upper[rc]
    if hi_c - lo_c >= _TWO_PI:  # any q1 has a wrist turn inside its limits
        return s_a * min(max(want, lo_a), hi_a)
    # q4 = s_c (alpha - phi2 - s_a q1) + 2 pi k in [lo_c, hi_c]  <=>  q1 in an interval shifted by 2 pi k
    c = alpha - phi2
    ends = sorted((s_a * (c - s_c * lo_c), s_a * (c - s_c * hi_c)))
    best = None
    k0 = math.floor((lo_a - ends[1]) / _TWO_PI)
    k1 = math.ceil((hi_a - ends[0]) / _TWO_PI)
    for k in range(k0, k1 + 1):
        a, b = max(ends[0] + k * _TWO_PI, lo_a), min(ends[1] + k * _TWO_PI, hi_a)
        if a <= b:
            v = min(max(want, a), b)
            if best is None or abs(v - want) < abs(best - want):
                best = v
    if best is None:  # no turn fits the wrist: keep J1 nearest the reference; J4_LIMIT follows
        best = min(max(want, lo_a), hi_a)
    return s_a * best


def _result(target: np.ndarray, solutions: tuple[IKSolution, ...], status: IKStatus, message: str) -> IKResult:
    """IKResult(target, solutions, status, message), without the frozen dataclass' __init__."""
    res = _new(IKResult)
    d = res.__dict__
    d["target"] = target
    d["solutions"] = solutions
    d["status"] = status
    d["message"] = message
    return res


def _inside_inner_limit(geo: ScaraGeometry, pose: np.ndarray, r: float, r_min: float) -> IKResult:
    l1, l2 = geo.l1, geo.l2
    rb = geo.revolute[1]
    lo, hi = geo.lower, geo.upper
    limited = r_min > abs(l1 - l2) + REACH_TOL
    why = (f"the inner limit r_min = {r_min:.9g} m set by {geo.names[rb]}'s limits "
           f"[{math.degrees(lo[rb]):.6g}, {math.degrees(hi[rb]):.6g}] deg" if limited
           else f"|l1 - l2| = {abs(l1 - l2):.9g} m")  # fmt: skip
    return _result(pose, (), IKStatus.INSIDE_INNER_LIMIT,
                   f"the wrist axis would be {r:.9g} m from the shoulder axis, inside {why}")  # fmt: skip


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


_BATCH_ROWS = 16384
"""Rows per block of :func:`solve_batch`: its work arrays stay in the cache, and the Python cost of the
(about 100) array operations per block is spread over enough rows."""

# Per row, the failures of a branch as the bits of a small code, in the order of precedence of `solve`'s
# checks (a higher bit wins): 0 J4, 1 J1, 2 J2, 3 inside the inner limit, 4 out of reach, 5 J3 stroke.
_BIT_STATUS = (IKStatus.J4_LIMIT, IKStatus.J1_LIMIT, IKStatus.J2_LIMIT, IKStatus.INSIDE_INNER_LIMIT,
               IKStatus.OUT_OF_REACH, IKStatus.J3_STROKE)  # fmt: skip
_CODE_STATUS = np.array([0] + [int(_BIT_STATUS[c.bit_length() - 1]) for c in range(1, 64)], dtype=np.int64)
"""Status of a failure code (the highest bit set)."""
_CODE_NAN = np.where(np.arange(64) == 0, 1.0, np.nan)
"""1 where a code is a solution, NaN where it is not (a factor that turns q into NaN rows)."""
_CODE_INF = np.where(np.arange(64) == 0, 0.0, np.inf)
"""0 where a code is a solution, +inf where it is not (added to a distance)."""
_STAGE = np.zeros(len(IKStatus), dtype=np.int64)
_STAGE[[IKStatus.OK, IKStatus.J2_LIMIT, IKStatus.J1_LIMIT, IKStatus.J4_LIMIT]] = [9, 1, 2, 3]
_CODE_STAGE = _STAGE[_CODE_STATUS]
"""How far `solve` gets with a code: OK, then J4 after J1 after J2 (other failures: 0)."""
_INV_TWO_PI = 1.0 / _TWO_PI


def solve_batch(
    geo: ScaraGeometry,
    targets: np.ndarray,
    *,
    branch: str = "right",
    reference: ArrayLike | None = None,
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
    n = T.shape[0]
    q = np.empty((n, 4))
    status = np.empty(n, dtype=np.int64)
    sign = np.empty(n, dtype=np.int64)
    if n == 0:
        return BatchIKResult(q, status, sign)
    # one reference for every row (the default, a (4,) reference or a broadcast one): four numbers
    row_refs = ref.ndim == 2 and ref.strides[0] != 0
    const_ref = None if row_refs else [float(v) for v in (ref if ref.ndim == 1 else ref[0])]
    work = _BatchWork(geo, min(n, _BATCH_ROWS), branch, const_ref)
    for start in range(0, n, _BATCH_ROWS):
        stop = min(start + _BATCH_ROWS, n)
        refs = const_ref if const_ref is not None else list(ref[start:stop].T)
        work.block(T[start:stop], refs, q[start:stop], status[start:stop], sign[start:stop])
    return BatchIKResult(q, status, sign)


class _BatchWork:
    """The closed form of :func:`solve` for arrays, one block of rows at a time, for one call.

    Every operation writes into a preallocated array (``out=``) of the block's length: nothing is
    allocated per block and the data stays in the cache. Changes of formulation, all exact identities:

    - the reach: o = l12^2 - r^2 and i = r^2 - d12^2 (l12 = l1 + l2, d12 = |l1 - l2|) from r^2, without
      the square root, except on the rows near the stretched or folded arm (o or i below 1e-6 l1 l2,
      gamma or pi - gamma below about 1e-3) where `solve`'s (l12 - r)(l12 + r) of r = sqrt(wx^2 + wy^2) is
      used, so that the ill-conditioned elbow angle there is computed from the same numbers;
    - the elbow: tan(gamma / 2) = sqrt(o / i), so tan gamma = 2 sqrt(o i) / (i - o), ONE atan2; and
      (l1 + l2 cos gamma, l2 sin gamma) is, up to the positive factor (i + o), (a, b) with
      a = l12 i + (l1 - l2) o and b = 2 l2 sqrt(o i): no cos/sin of gamma;
    - the shoulder: atan2(wy, wx) - atan2(b, a) is the argument of (wx + j wy)(a - j b), ONE atan2:
      theta1 = atan2(wy a - wx b, wx a + wy b) (mod 2 pi, which the choice of turn absorbs), except
      where the wrist is within 1e-3 l2 of the shoulder axis (only possible when l1 ~ l2; theta1 is free
      at r = 0), where the two-atan2 form of `solve` gives the value, as there;
    - the turn nearest to the reference: with one reference for all rows, when every turn inside the
      limits is within pi of it, that turn is the nearest one (k = round((ref - v) / 2 pi)) and there
      is no clipping of k to do (see ``_turn``);
    - the statuses: the failures of a row as the bits of a small code, read through lookup tables.
    """

    def __init__(self, geo: ScaraGeometry, rows: int, branch: str, const_ref: list[float] | None) -> None:
        self.geo = geo
        self.rows = rows
        self.branch = branch
        ra, rb, rc = geo.revolute
        ip = geo.prismatic
        l1, l2 = geo.l1, geo.l2
        self.r_min = geo.radius_range()[0]
        # reach (squared), and the rows that take the exact route (see the class docstring)
        self.reach2 = (l1 + l2 + REACH_TOL) ** 2
        self.inner2 = (self.r_min - REACH_TOL) ** 2 if self.r_min - REACH_TOL > 0.0 else -1.0
        self.l12_2 = (l1 + l2) ** 2
        self.d12_2 = (l1 - l2) ** 2
        self.delicate = 1e-6 * l1 * l2
        self.axis_rows = abs(l1 - l2) < 1e-3 * l2  # the wrist can come near the shoulder axis
        both = branch == "nearest"
        self._f = np.empty((28 if both else 22, rows))
        self._u = np.empty((12, rows), dtype=np.uint8)
        self._p = np.empty((4, rows), dtype=np.intp)
        self._q = np.empty((2 if both else 1, 4, rows))
        self._zeros = np.zeros(rows)
        self._views = self._make_views(rows)
        lo, hi = geo.lower, geo.upper
        s = geo.signs
        self.sa, self.sb, self.sc, self.sp = s[ra], s[rb], s[rc], s[ip]
        # per revolute joint: (index, limits, widened limits, mode of the turn choice; see _turn)
        self.joints = []
        for j in (ra, rb, rc):
            mode = "clip"
            if const_ref is not None:
                ref, margin = const_ref[j], 1e-9
                if lo[j] + margin <= ref - math.pi and ref + math.pi <= hi[j] - margin:
                    mode = "inside"  # the turn nearest to ref is always inside the limits
                elif lo[j] <= ref <= hi[j] and max(ref - lo[j], hi[j] - ref) + LIMIT_TOL < math.pi - margin:
                    mode = "unique"  # no other turn than the nearest can be inside the limits
            self.joints.append((j, lo[j], hi[j], lo[j] - LIMIT_TOL, hi[j] + LIMIT_TOL, mode))

    def _make_views(self, m: int) -> tuple[Any, ...]:
        return (list(self._f[:, :m]), list(self._u[:, :m]), list(self._p[:, :m]),
                [a[:, :m] for a in self._q], self._zeros[:m])  # fmt: skip

    def block(self, T: np.ndarray, refs: list[Any], q_out: np.ndarray, st_out: np.ndarray, sg_out: np.ndarray) -> None:
        """Solve the rows T (at most ``rows``) into q_out, st_out and sg_out."""
        geo = self.geo
        m = T.shape[0]
        f, u, p, qs, zeros = self._views if m == self.rows else self._make_views(m)
        x, y, z, yaw = T[:, 0], T[:, 1], T[:, 2], T[:, 3]
        l1, l2 = geo.l1, geo.l2
        ip = geo.prismatic
        t = f[5]
        # ------------------------------------------------------------------ shared by both branches
        alpha = yaw if geo.yaw0 == 0.0 else np.subtract(yaw, geo.yaw0, out=f[0])
        tx, ty = geo.tool
        a1x, a1y = geo.a1
        if tx == 0.0 and ty == 0.0:
            wx = x if a1x == 0.0 else np.subtract(x, a1x, out=f[1])
            wy = y if a1y == 0.0 else np.subtract(y, a1y, out=f[2])
        else:
            ca = np.cos(alpha, out=f[3])
            sa = np.sin(alpha, out=f[4])
            wx = np.multiply(ca, tx, out=f[1])  # x - (ca tx - sa ty) - a1x
            np.subtract(wx, np.multiply(sa, ty, out=t), out=wx)
            np.subtract(x, wx, out=wx)
            if a1x != 0.0:
                np.subtract(wx, a1x, out=wx)
            wy = np.multiply(sa, tx, out=f[2])  # y - (sa tx + ca ty) - a1y
            np.add(wy, np.multiply(ca, ty, out=t), out=wy)
            np.subtract(y, wy, out=wy)
            if a1y != 0.0:
                np.subtract(wy, a1y, out=wy)
        r2 = np.multiply(wx, wx, out=f[6])
        np.add(r2, np.multiply(wy, wy, out=t), out=r2)
        o = np.subtract(self.l12_2, r2, out=f[7])
        np.maximum(o, zeros, out=o)
        i = np.subtract(r2, self.d12_2, out=f[8])
        np.maximum(i, zeros, out=i)
        # vertical joint (into the q rows of the branches)
        Q0 = qs[0]
        qp = np.subtract(z, geo.z0, out=Q0[ip])
        if self.sp < 0:
            np.negative(qp, out=qp)
        # the shared failure bits, built Horner-fashion (2 c + bit): J3 stroke, out of reach, inside
        code0, bit = u[0], u[1]
        np.less(qp, geo.lower[ip] - LIMIT_TOL, out=code0.view(bool))
        np.bitwise_or(code0, np.greater(qp, geo.upper[ip] + LIMIT_TOL, out=bit.view(bool)), out=code0)
        np.add(code0, code0, out=code0)
        np.bitwise_or(code0, np.greater(r2, self.reach2, out=bit.view(bool)), out=code0)
        np.add(code0, code0, out=code0)
        np.bitwise_or(code0, np.less(r2, self.inner2, out=bit.view(bool)), out=code0)
        np.clip(qp, geo.lower[ip], geo.upper[ip], out=qp)
        # rows near the stretched or folded arm: r, o, i (and their bits) as `solve` computes them
        free: Sequence[int] = ()
        near = np.less(o, self.delicate, out=u[2].view(bool))
        np.bitwise_or(near, np.less(i, self.delicate, out=bit.view(bool)), out=near)
        axis = None
        if near.any():
            rows = np.flatnonzero(near)
            wxr, wyr = wx[rows], wy[rows]
            r = np.sqrt(wxr * wxr + wyr * wyr)
            l12, d12 = l1 + l2, abs(l1 - l2)
            snap = SNAP_TOL * l12
            o_lin, i_lin = l12 - r, r - d12
            o[rows] = np.where(o_lin < snap, 0.0, o_lin) * (l12 + r)
            i[rows] = np.where(i_lin < snap, 0.0, i_lin) * (r + d12)
            code0[rows] = (code0[rows] & 4) | (r > l12 + REACH_TOL) << 1 | (r < self.r_min - REACH_TOL)
            if self.axis_rows:
                close = r < 1e-3 * l2
                if close.any():
                    axis = rows[close]
                free = rows[r <= FREE_R]
        # elbow and the shoulder's products
        root = np.multiply(o, i, out=f[10])  # 2 sqrt(o i)
        np.multiply(root, 4.0, out=root)
        np.sqrt(root, out=root)
        gamma = np.arctan2(root, np.subtract(i, o, out=t), out=f[11])  # in [0, pi]
        a = np.multiply(i, l1 + l2, out=f[12])
        if l1 != l2:
            np.add(a, np.multiply(o, l1 - l2, out=t), out=a)
        bb = np.multiply(root, l2, out=f[13])
        prods = (np.multiply(wy, a, out=f[14]), np.multiply(wx, bb, out=f[15]),
                 np.multiply(wx, a, out=f[16]), np.multiply(wy, bb, out=f[17]))  # fmt: skip
        shared = (alpha, prods, gamma, axis, code0)
        if self.branch != "nearest":
            sgn = 1 if self.branch == "right" else -1
            code = self._branch(sgn, shared, refs, T, f[18:22], u[3:7], Q0, p[0])
            np.take(_CODE_STATUS, code, out=st_out)
            np.multiply(np.equal(code, 0, out=bit.view(bool)), sgn, out=sg_out)
            np.multiply(Q0, np.take(_CODE_NAN, code, out=t), out=q_out.T)
        else:
            Qr, Ql = qs
            np.copyto(Ql[ip], Qr[ip])
            code_r = self._branch(1, shared, refs, T, f[18:22], u[3:7], Qr, p[0])
            code_l = self._branch(-1, shared, refs, T, f[22:26], u[7:11], Ql, p[1])
            # per row the solution nearest to the reference (squared distance; +inf without a solution)
            dr, dl = f[26], f[27]
            for dist, Qb, code in ((dr, Qr, code_r), (dl, Ql, code_l)):
                np.take(_CODE_INF, code, out=dist)
                for j in range(4):
                    d = np.subtract(Qb[j], refs[j], out=t)
                    np.add(dist, np.multiply(d, d, out=d), out=dist)
            use_left = np.less(dl, dr, out=u[11].view(bool))
            np.copyto(Qr, Ql, where=use_left)
            # neither branch solves: report the one that got further (J4 after J1 after J2, as `solve` does)
            further = np.greater(np.take(_CODE_STAGE, code_l, out=p[2]), np.take(_CODE_STAGE, code_r, out=p[3]),
                                 out=bit.view(bool))  # fmt: skip
            np.copyto(code_r, code_l, where=further)
            np.take(_CODE_STATUS, code_r, out=st_out)
            # branch: -1 where the left one is used, +1 for the right one, 0 without a solution
            np.multiply(use_left, -2, out=sg_out)
            np.add(sg_out, 1, out=sg_out)
            np.multiply(sg_out, np.equal(code_r, 0, out=bit.view(bool)), out=sg_out)
            np.multiply(Qr, np.take(_CODE_NAN, code_r, out=t), out=q_out.T)
        # wrist on the shoulder axis (l1 = l2): the shoulder is free; these rare rows take the scalar route,
        # which picks J1 (and J4) as `solve` does, nearest to the row's reference
        for row in free:
            self._free_row(T[row], [float(refs[j][row]) if np.ndim(refs[j]) else float(refs[j]) for j in range(4)],
                           row, q_out, st_out, sg_out)  # fmt: skip
        # rows with a NaN or an infinity (rare): OUT_OF_REACH, NaN; found through the sum of the block
        if not _isfinite(float(np.add.reduce(T, axis=None))):
            bad = ~np.isfinite(T).all(axis=1)
            st_out[bad] = IKStatus.OUT_OF_REACH
            sg_out[bad] = 0
            q_out[bad] = np.nan

    def _free_row(self, target: np.ndarray, ref: list[float], row: int, q_out: np.ndarray, st_out: np.ndarray,
                  sg_out: np.ndarray) -> None:  # fmt: skip
        """One row with a free shoulder, through `solve` (the nearest solution of the branch to ``ref``)."""
        res = solve(self.geo, target, reference=ref)
        want = "all" if self.branch == "nearest" else self.branch
        best = res.nearest(ref, branch=want) if res.success else None
        if best is None:
            q_out[row] = np.nan
            st_out[row] = res.status if not res.success else IKStatus.J2_LIMIT
            sg_out[row] = 0
            return
        q_out[row] = best.q
        st_out[row] = IKStatus.OK
        sg_out[row] = (1 if best.branch == "right" else -1) if want == "all" else (1 if want == "right" else -1)

    def _branch(self, sgn: int, shared: tuple[Any, ...], refs: list[Any], T: np.ndarray, f: list[np.ndarray],
                u: list[np.ndarray], Q: np.ndarray, code: np.ndarray) -> np.ndarray:  # fmt: skip
        """One elbow branch: its joint values into Q (4, m), its failure code per row into ``code``.

        The joint values are the 2 pi-equivalents nearest to the reference; the code is described at
        ``_CODE_STATUS``.
        """
        geo = self.geo
        alpha, (wya, wxb, wxa, wyb), gamma, axis, code0 = shared
        ja, jb, jc = self.joints
        t1, t2 = f[0], f[1]
        # shoulder: theta1 = atan2(wy a -+ wx b, wx a +- wy b); phi1 = theta1 - beta1
        if sgn > 0:
            np.subtract(wya, wxb, out=t1)
            np.add(wxa, wyb, out=t2)
        else:
            np.add(wya, wxb, out=t1)
            np.subtract(wxa, wyb, out=t2)
        va = np.arctan2(t1, t2, out=f[2])
        if axis is not None:
            va[axis] = _two_atan2_shoulder(geo, sgn, T[axis].T, gamma[axis])
        if geo.beta1 != 0.0:
            np.subtract(va, geo.beta1, out=va)
        if self.sa < 0:
            np.negative(va, out=va)
        # elbow: phi2 = +-gamma + beta1 - beta2
        vb = gamma if sgn * self.sb > 0 else np.negative(gamma, out=f[3])
        if geo.beta1 != geo.beta2:
            vb = np.add(vb, self.sb * (geo.beta1 - geo.beta2), out=f[3])
        bad_a, bad_b, bad_c, scratch = (v.view(bool) for v in u)
        shoulder_fails = _turn(va, ja, refs, Q, bad_a, scratch, t1, t2)
        elbow_fails = _turn(vb, jb, refs, Q, bad_b, scratch, t1, t2)
        # wrist: s_c (alpha - s_a q_a - s_b q_b)
        vc = f[3]
        (np.subtract if self.sa > 0 else np.add)(alpha, Q[ja[0]], out=vc)
        (np.subtract if self.sb > 0 else np.add)(vc, Q[jb[0]], out=vc)
        if self.sc < 0:
            np.negative(vc, out=vc)
        wrist_fails = _turn(vc, jc, refs, Q, bad_c, scratch, t1, t2)
        # the code, Horner-fashion: ((2 code0 + J2) 2 + J1) 2 + J4
        c8 = u[3]
        np.add(code0, code0, out=c8)
        if elbow_fails:
            np.bitwise_or(c8, u[1], out=c8)
        np.add(c8, c8, out=c8)
        if shoulder_fails:
            np.bitwise_or(c8, u[0], out=c8)
        np.add(c8, c8, out=c8)
        if wrist_fails:
            np.bitwise_or(c8, u[2], out=c8)
        np.copyto(code, c8)
        return code


def _turn(value: np.ndarray, joint: tuple[Any, ...], refs: list[Any], Q: np.ndarray, bad: np.ndarray,
          scratch: np.ndarray, k_min: np.ndarray, k_max: np.ndarray) -> bool:  # fmt: skip
    """Per element, value + 2 pi k inside [lo, hi] nearest to the reference, into Q[j]; ``bad`` where none.

    Returns whether ``bad`` was written (a turn always exists in mode "inside").

    Mode "clip" (the general case): k = clip(round((ref - value) / 2 pi), k_min, k_max) with k_min, k_max
    the first and last turn inside the limits widened by LIMIT_TOL, then the result clipped onto the
    limits. With one reference for all rows, when every turn inside the widened limits lies within pi
    of it (mode "unique"), that turn is the nearest one: k = round((ref - value) / 2 pi) needs no clipping,
    and there is none exactly when that turn is outside the widened limits; when moreover the nearest turn
    is always inside (mode "inside": [ref - pi, ref + pi] within the limits), there is nothing to check.
    """
    j, lo, hi, lo_tol, hi_tol, mode = joint
    ref = refs[j]
    out = Q[j]
    if mode == "clip":
        np.subtract(lo_tol, value, out=k_min)
        np.divide(k_min, _TWO_PI, out=k_min)
        np.ceil(k_min, out=k_min)
        np.subtract(hi_tol, value, out=k_max)
        np.divide(k_max, _TWO_PI, out=k_max)
        np.floor(k_max, out=k_max)
        np.greater(k_min, k_max, out=bad)
        np.subtract(ref, value, out=out)
        np.divide(out, _TWO_PI, out=out)
        np.rint(out, out=out)
        np.maximum(out, k_min, out=out)
        np.minimum(out, k_max, out=out)
        np.multiply(out, _TWO_PI, out=out)
        np.add(value, out, out=out)
        np.clip(out, lo, hi, out=out)
        return True
    np.subtract(ref, value, out=out)
    np.multiply(out, _INV_TWO_PI, out=out)
    np.rint(out, out=out)
    np.multiply(out, _TWO_PI, out=out)
    np.add(value, out, out=out)
    if mode == "inside":
        return False
    np.less(out, lo_tol, out=bad)
    np.bitwise_or(bad, np.greater(out, hi_tol, out=scratch), out=bad)
    np.clip(out, lo, hi, out=out)
    return True


def _two_atan2_shoulder(geo: ScaraGeometry, sgn: float, X: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """Shoulder angles of a few rows X (x, y, z, yaw), computed as `solve` does.

    theta1 = atan2(wy, wx) - atan2(l2 sin g, l1 + l2 cos g), with the wrist point and its signed zeros as
    in `solve` (atan2(+-0, +-0) picks the shoulder angle at r = 0).
    """
    alpha = X[3] - geo.yaw0
    ca, sa = np.cos(alpha), np.sin(alpha)
    tx, ty = geo.tool
    wx = X[0] - (ca * tx - sa * ty) - geo.a1[0]
    wy = X[1] - (sa * tx + ca * ty) - geo.a1[1]
    g = sgn * gamma
    return np.arctan2(wy, wx) - np.arctan2(geo.l2 * np.sin(g), geo.l1 + geo.l2 * np.cos(g))
