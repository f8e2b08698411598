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
(:class:`~scara_pin.kinematics.results.IKSolution`); :meth:`IKResult.expand` lists every turn on request.
Continuous joints take the turn nearest the reference (distances wrapped).

Limits and rounding: a joint within ``LIMIT_TOL`` outside a limit is clamped onto it. Near the stretched
and folded circles the joint angles are ill-conditioned (a target rounded to the last bit moves them by
up to ~1e-7 rad, :meth:`Planar2R.wobble`): a joint that rounding alone puts outside its limit by less than
that is put ON the limit and the other angles re-solved with it fixed (the position still reached to
``REACH_TOL``), so configurations with a joint on its limit come back.

Three entry points: :func:`solve` (the solutions of one target, as objects, with the reason when there
is none), :func:`solve_nearest` (the one solution nearest a reference, as a new array: what a controller
needs between consecutive points) and :func:`solve_batch` (N targets, vectorised with numpy).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from operator import itemgetter
from typing import TYPE_CHECKING, Any, overload

import numpy as np
import pinocchio as pin

from .._checks import MAGNITUDE_MAX, _floats
from ..errors import InvalidInputError, NoSolutionError, ParameterError, UrdfError
from .planar2r import (
    FREE_R,
    LIMIT_TOL,
    REACH_TOL,
    SINGULAR,
    TWO_PI,
    Planar2R,
    Reach,
    free_angle,
    nearest_turn_array,
    turn_edge,
    turner,
    wrap,
)
from .results import BatchIKResult, IKResult, result_of
from .targets import check_magnitude, parse_target, reference_floats, weight_floats

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import Robot

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
    "solve_batch",
    "solve_nearest",
]

YAW_POSE_TOL = 1e-9
"""[rad] the largest tilt of a target rotation still taken as a pure yaw."""
NEAR_PARALLEL_TOL = 1e-2
"""[rad] the largest angle between a joint axis and the base z axis for a SCARA: beyond EXACT_TILT the
axes are near-parallel (pi written as 3.14 in an rpy) and the closed form's solutions are refined on the
model (:mod:`scara_pin.kinematics.polish`)."""
EXACT_TILT = 1e-12
"""[rad] a model whose axes tilt less than this is solved by the closed form alone (no refinement)."""
BRANCHES = ("right", "left")
"""The SCARA's elbow branches, in the order solutions are listed."""

_PI = math.pi
_atan2, _sin, _cos, _sqrt, _isfinite = math.atan2, math.sin, math.cos, math.sqrt, math.isfinite
_F64 = np.dtype(np.float64)


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
    NOT_REFINED = 8
    """Near-parallel axes: the closed form's seed did not converge on the model, or left its branch."""


_STAGE = {IKStatus.J2_LIMIT: 1, IKStatus.J1_LIMIT: 2, IKStatus.J4_LIMIT: 3}
"""How far a branch got before it failed: the later the stage, the more telling the reason."""


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
        lower, upper: joint limits in q order (a continuous joint: -inf, inf).
        continuous: per joint in q order, whether it is continuous (no limits).
        arm: the planar two-link arm (l1, l2).
        tilt: the largest angle between a joint axis of the model and the base z axis [rad] (0 for the
            ideal geometry; up to NEAR_PARALLEL_TOL: the closed form seeds a refinement on the model).
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
    continuous: tuple[bool, ...] = (False, False, False, False)
    tilt: float = 0.0
    l1: float = field(init=False)
    l2: float = field(init=False)
    beta1: float = field(init=False)
    beta2: float = field(init=False)
    arm: Planar2R = field(init=False, repr=False, compare=False)
    _radius: tuple[float, float] = field(init=False, repr=False, compare=False)
    _k: tuple[Any, ...] = field(init=False, repr=False, compare=False)
    _turn: tuple[Any, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "l1", math.hypot(*self.u1))
        object.__setattr__(self, "l2", math.hypot(*self.u2))
        object.__setattr__(self, "beta1", math.atan2(self.u1[1], self.u1[0]))
        object.__setattr__(self, "beta2", math.atan2(self.u2[1], self.u2[0]))
        object.__setattr__(self, "arm", Planar2R(self.l1, self.l2))
        for i, name in enumerate(self.names):
            lo, hi = self.lower[i], self.upper[i]
            if self.continuous[i]:
                continue
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise ParameterError(f"limits of {name}", (lo, hi), "must be finite numbers with lower <= upper")
        object.__setattr__(self, "_radius", self._radius_range())
        # the numbers the per-call path reads, unpacked once per call (the geometry is frozen)
        ra, rb, rc = self.revolute
        ip = self.prismatic
        s, lower, upper = self.signs, self.lower, self.upper
        object.__setattr__(self, "_k", (
            ra, rb, rc, ip, s[ra], s[rb], s[rc], s[ip], lower[ip] - LIMIT_TOL, upper[ip] + LIMIT_TOL,
            self.z0, self.a1[0], self.a1[1], self.tool[0], self.tool[1], self._radius[0] - REACH_TOL,
            self.beta1, self.beta2 - self.beta1,
        ))  # fmt: skip
        # each joint's turn choice with its limits bound (planar2r.turner), in q order (None: prismatic)
        object.__setattr__(self, "_turn", tuple(turner(lower[j], upper[j], self.continuous[j]) if j != ip else None
                                                for j in range(4)))  # fmt: skip

    @classmethod
    def from_robot(cls, robot: Robot) -> ScaraGeometry:
        """Read the geometry from a loaded robot; raise :class:`NotScaraError` naming what is wrong.

        Axes up to ``NEAR_PARALLEL_TOL`` from the base z axis are accepted: the geometry is then the ideal
        vertical-axis one read at q = 0 (plan-view positions of the axes), ``tilt`` says how far the model
        departs from it, and :mod:`scara_pin.kinematics.polish` refines the closed form on the model.
        """
        return cls._read(robot, wrist=True)

    @classmethod
    def without_wrist(cls, robot: Robot) -> ScaraGeometry:
        """The geometry of a 3-joint SCARA (two revolute joints and one prismatic, in any order, no wrist).

        It is read as a 4-joint SCARA whose wrist, virtual and continuous, is index 3 of q and turns about
        the tool point (tool offset 0): arm 2 runs from the elbow axis to the tool point. The closed form
        and the workspace then apply unchanged; the virtual wrist's value is the tool's free yaw, dropped
        by :class:`scara_pin.robots.Scara3Kinematics`.
        """
        return cls._read(robot, wrist=False)

    @classmethod
    def _read(cls, robot: Robot, wrist: bool) -> ScaraGeometry:
        model = robot.model
        data = model.createData()
        names = tuple(model.names[j] for j in range(1, model.njoints))
        n = 4 if wrist else 3
        if model.njoints - 1 != n:
            raise NotScaraError(f"a SCARA has {n} joints; this model has {model.njoints - 1}: {', '.join(names)}")
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
        worst = 0.0
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
            if tilt > NEAR_PARALLEL_TOL:
                raise NotScaraError(
                    f"joint {name}'s axis is {math.degrees(tilt):.6g} deg ({tilt:.3g} rad) away from the base z "
                    f"axis (more than {NEAR_PARALLEL_TOL:g} rad): the axes of a SCARA are parallel and vertical"
                )
            worst = max(worst, tilt)
            signs[j - 1] = 1.0 if axis[2] > 0 else -1.0
            kind.append(j - 1)
            points[j - 1] = oMb.actInv(data.oMi[j]).translation
        if len(revolute) != n - 1 or len(prismatic) != 1:
            kinds = ", ".join(f"{n} ({'revolute' if i in revolute else 'prismatic'})" for i, n in enumerate(names))
            raise NotScaraError(f"a SCARA has {n - 1} revolute joints and 1 prismatic joint; this model has {kinds}")
        bMt = oMb.actInv(data.oMf[robot.tool_id])
        if not wrist:  # the virtual wrist: index 3, on the tool point, continuous, +z
            revolute.append(3)
            points[3] = bMt.translation
            signs[3] = 1.0
        ra, rb, rc = revolute
        a1, a2, a4 = points[ra][:2], points[rb][:2], points[rc][:2]
        u1, u2, t = a2 - a1, a4 - a2, bMt.translation[:2] - a4
        wrist_name = names[rc] if wrist else f"the tool point ({robot.tool_frame})"
        for vec, what in ((u1, f"{names[rb]}'s axis coincides with {names[ra]}'s"),
                          (u2, f"{wrist_name} lies on {names[rb]}'s axis")):  # fmt: skip
            if math.hypot(*vec) < 1e-9:
                raise NotScaraError(f"{what}: the arm has no length")
        R0 = bMt.rotation.copy()
        if math.hypot(R0[0, 0], R0[1, 0]) < 1e-6:
            raise NotScaraError("the tool frame's x axis is vertical at q = 0: its yaw is undefined")
        cont = tuple(robot.continuous) + (() if wrist else (True,))
        return cls(
            revolute=(ra, rb, rc),
            prismatic=prismatic[0],
            names=names if wrist else (*names, "(no wrist)"),
            signs=tuple(signs),
            a1=(float(a1[0]), float(a1[1])),
            u1=(float(u1[0]), float(u1[1])),
            u2=(float(u2[0]), float(u2[1])),
            tool=(float(t[0]), float(t[1])),
            z0=float(bMt.translation[2]),
            yaw0=math.atan2(R0[1, 0], R0[0, 0]),
            R0=R0,
            # continuous joints have no limits; others: the model's limits
            lower=tuple(-math.inf if cont[i] else float(model.lowerPositionLimit[model.joints[i + 1].idx_q])
                        for i in range(4)),
            upper=tuple(math.inf if cont[i] else float(model.upperPositionLimit[model.joints[i + 1].idx_q])
                        for i in range(4)),
            continuous=cont,
            tilt=worst,
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
        """(r_min, r_max) of the wrist axis from the shoulder axis allowed by the elbow's limits [m]."""
        return self._radius

    def _radius_range(self) -> tuple[float, float]:
        # r(gamma) falls as |gamma| grows to pi: r_min from the allowed gamma nearest pi, r_max nearest 0
        e = self.revolute[1]
        arm = self.arm
        if self.continuous[e] or self.upper[e] - self.lower[e] >= TWO_PI:
            return arm.d12, arm.l12
        g_lo, g_hi = sorted((self.elbow_angle(self.lower[e]), self.elbow_angle(self.upper[e])))

        def reaches(angle: float) -> bool:  # some angle + 2 pi k inside [g_lo, g_hi]
            return angle + math.ceil((g_lo - angle) / TWO_PI) * TWO_PI <= g_hi

        r_max = arm.l12 if reaches(0.0) else max(arm.radius(g_lo), arm.radius(g_hi))
        r_min = arm.d12 if reaches(math.pi) else min(arm.radius(g_lo), arm.radius(g_hi))
        return r_min, r_max


def branch_of(geo: ScaraGeometry, q: ArrayLike) -> str:
    """The branch (``"right"``/``"left"``) of a configuration: the sign of sin(gamma); ``right`` at gamma = 0."""
    g = wrap(geo.elbow_angle(float(q[geo.revolute[1]])))
    if abs(g) < 1e-12:
        return "right"
    return "right" if 0.0 < g < math.pi else "left"


def wrist_point(geo: ScaraGeometry, x: float, y: float, alpha: float) -> tuple[float, float]:
    """W = p - R(alpha) t - A1: the wrist axis relative to the shoulder axis for a tool at (x, y), yaw0 + alpha."""
    tx, ty = geo.tool
    ca, sa = _cos(alpha), _sin(alpha)
    return x - (ca * tx - sa * ty) - geo.a1[0], y - (sa * tx + ca * ty) - geo.a1[1]


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
    why = [f"{label}: {names[j]} = {wrap(v):.9g} rad (+2 pi k) outside [{lo[j]:.9g}, {hi[j]:.9g}]"
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
    # elbow
    vb = s_b * (gamma - db)
    tb = turn[rb](vb, ref[rb])
    if tb is None:
        s, arm, b2 = geo.signs, geo.arm, geo.beta2
        wob = arm.wobble(gamma)
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
        s, arm, b2 = geo.signs, geo.arm, geo.beta2
        wob = arm.wobble(gamma)
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
        s, arm, b2 = geo.signs, geo.arm, geo.beta2
        wob = arm.wobble(gamma)
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



# ------------------------------------------------------------------------------------------ batch
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
    T = _floats("targets", targets, "must be an (N, 4) array of x, y, z, yaw")
    if T.ndim != 2 or T.shape[1] != 4:
        raise ParameterError("targets", f"array of shape {T.shape}", "must have shape (N, 4): x, y, z, yaw")
    if branch not in ("nearest", *BRANCHES):
        raise InvalidInputError(f"branch {branch!r} must be 'nearest', 'right' or 'left'")
    if T.size and not (T.max() <= MAGNITUDE_MAX and T.min() >= -MAGNITUDE_MAX):  # NaN fails the comparisons
        i = int(np.argmax(~(np.abs(T) <= MAGNITUDE_MAX).all(axis=1)))
        check_magnitude(T[i].tolist())
    ref = np.zeros(4) if reference is None else _floats("reference", reference, "must be 4 values or (N, 4)")
    if ref.shape not in ((4,), (T.shape[0], 4)) or not np.isfinite(ref).all():
        raise ParameterError("reference", f"array of shape {ref.shape}", "must be 4 finite values or (N, 4)")
    n = T.shape[0]
    q = np.empty((n, 4))
    status = np.empty(n, dtype=np.int64)
    sign = np.empty(n, dtype=np.int64)
    if n == 0:
        return BatchIKResult(q, status, sign)
    const = ref.ndim == 1
    work = _BatchWork(geo, min(n, _BATCH_ROWS), branch, ref.tolist() if const else None)
    for start in range(0, n, _BATCH_ROWS):
        stop = min(start + _BATCH_ROWS, n)
        refs = ref if const else ref[start:stop]
        work.block(T[start:stop], refs, q[start:stop], status[start:stop], sign[start:stop])
    return BatchIKResult(q, status, sign)


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
