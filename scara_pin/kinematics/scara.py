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
from typing import TYPE_CHECKING, Any, overload

import numpy as np
import pinocchio as pin

from .._checks import MAGNITUDE_MAX
from ..errors import InvalidInputError, NoSolutionError, ParameterError, UrdfError
from .planar2r import (
    FREE_R,
    LIMIT_TOL,
    REACH_TOL,
    TWO_PI,
    Planar2R,
    Reach,
    nearest_turn,
    nearest_turn_array,
    turn_edge,
    wrap,
)
from .results import BatchIKResult, IKResult, IKSolution
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
PARALLEL_TOL = 1e-6
"""[rad] axes this close to the base z axis are vertical for the closed form's purposes (``check``'s rule)."""
NEAR_PARALLEL_TOL = 1e-2
"""[rad] the largest angle between a joint axis and the base z axis for a SCARA: beyond PARALLEL_TOL the
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


def _branches(
    geo: ScaraGeometry, x: float, y: float, z: float, alpha: float, ref: list[float], branch: str
) -> tuple[list[_Branch], _Failure | None]:
    """The solution of each requested branch, or the reason there is none (the most telling failure)."""
    ra, rb, rc = geo.revolute
    ip = geo.prismatic
    lo, hi, names = geo.lower, geo.upper, geo.names
    arm = geo.arm
    # vertical joint
    qp = (z - geo.z0) * geo.signs[ip]
    if not lo[ip] - LIMIT_TOL <= qp <= hi[ip] + LIMIT_TOL:
        return [], (IKStatus.J3_STROKE, f"z = {z:.9g} m needs {names[ip]} = {qp:.9g} m, outside its stroke "
                                        f"[{lo[ip]:.9g}, {hi[ip]:.9g}] m")  # fmt: skip
    qp = lo[ip] if qp < lo[ip] else (hi[ip] if qp > hi[ip] else qp)
    # wrist point and the planar arm
    tx, ty = geo.tool
    if tx or ty:
        ca, sa = _cos(alpha), _sin(alpha)
        wx = x - (ca * tx - sa * ty) - geo.a1[0]
        wy = y - (sa * tx + ca * ty) - geo.a1[1]
    else:
        wx, wy = x - geo.a1[0], y - geo.a1[1]
    code, r, gamma, heading = arm.solve(wx, wy)
    if code == Reach.OUT:
        return [], (IKStatus.OUT_OF_REACH, f"the wrist axis would be {r:.9g} m from the shoulder axis, beyond "
                                           f"the reach l1 + l2 = {arm.l12:.9g} m")  # fmt: skip
    r_min = geo._radius[0]
    if code == Reach.IN or r < r_min - REACH_TOL:
        return [], (IKStatus.INSIDE_INNER_LIMIT, _inside_message(geo, r, r_min))
    singular = arm.singular(gamma)
    wob = arm.wobble(gamma)
    if r > FREE_R:
        lean = arm.lean(gamma)
    else:  # l1 = l2 and the wrist on the shoulder axis: the shoulder is free
        heading = _free_shoulder(geo, alpha, gamma + geo.beta1 - geo.beta2, ref[ra]) + geo.beta1
        lean = 0.0
    if singular:
        elbows: tuple[tuple[float, float, str], ...] = ((gamma, heading - lean, "right" if gamma < 1.0 else "left"),)
    else:
        elbows = ((gamma, heading - lean, "right"), (-gamma, heading + lean, "left"))
    found: list[_Branch] = []
    failures: list[_Failure] = []
    for g, theta1, label in elbows:
        if branch == "all" or label == branch or singular:
            out = _joints(geo, wx, wy, alpha, g, theta1, wob, ref, label)
            if isinstance(out[0], IKStatus):
                failures.append(out)  # type: ignore[arg-type]
                continue
            qa, qb, qc = out  # type: ignore[misc]
            q = [0.0] * 4
            turns: list[tuple[int, int] | None] = [(0, 0)] * 4
            for j, t in ((ra, qa), (rb, qb), (rc, qc)):
                q[j] = t[0]
                turns[j] = None if geo.continuous[j] else (t[1], t[2])
            q[ip] = qp
            found.append((label, singular, q, turns))
    if found:
        return found, None
    if not failures:  # the requested branch was not among the elbows (cannot happen for "all")
        return [], (IKStatus.J2_LIMIT, f"no {branch} solution")
    worst = max(failures, key=lambda f: _STAGE[f[0]])
    return [], (worst[0], "no solution inside the joint limits: " + "; ".join(f[1] for f in failures))


def _joints(
    geo: ScaraGeometry, wx: float, wy: float, alpha: float, gamma: float, theta1: float, wob: float,
    ref: list[float], label: str,
) -> tuple[Any, ...]:  # fmt: skip
    """Shoulder, elbow and wrist of one branch at their turns nearest ``ref`` ((q, k_lo, k_hi) each).

    Or (status, message) when a joint has no turn inside its limits.

    A joint that rounding alone puts outside a limit (by less than ``wob``, the arm's ill-conditioning)
    is put on it and the arm re-solved with that angle fixed.
    """
    ra, rb, rc = geo.revolute
    s, lo, hi, cont, names = geo.signs, geo.lower, geo.upper, geo.continuous, geo.names
    arm, b1, b2 = geo.arm, geo.beta1, geo.beta2
    # elbow
    vb = s[rb] * (gamma + b1 - b2)
    tb = nearest_turn(vb, lo[rb], hi[rb], ref[rb], cont[rb])
    if tb is None:
        edge = turn_edge(vb, lo[rb], hi[rb], wob)
        if edge is not None:
            theta1, miss = arm.with_elbow(wx, wy, geo.elbow_angle(edge))
            tb = nearest_turn(edge, lo[rb], hi[rb], ref[rb]) if miss <= REACH_TOL else None
        if tb is None:
            return IKStatus.J2_LIMIT, f"{label}: {names[rb]} = {wrap(vb):.9g} rad (+2 pi k) outside [{lo[rb]:.9g}, " \
                                      f"{hi[rb]:.9g}]"  # fmt: skip
    # shoulder
    va = s[ra] * (theta1 - b1)
    ta = nearest_turn(va, lo[ra], hi[ra], ref[ra], cont[ra])
    if ta is None:
        edge = turn_edge(va, lo[ra], hi[ra], wob)
        if edge is not None:
            g, miss = arm.with_link1(wx, wy, s[ra] * edge + b1)
            tb = nearest_turn(s[rb] * (g + b1 - b2), lo[rb], hi[rb], ref[rb], cont[rb])
            ta = nearest_turn(edge, lo[ra], hi[ra], ref[ra]) if miss <= REACH_TOL and tb is not None else None
        if ta is None or tb is None:
            return IKStatus.J1_LIMIT, f"{label}: {names[ra]} = {wrap(va):.9g} rad (+2 pi k) outside [{lo[ra]:.9g}, " \
                                      f"{hi[ra]:.9g}]"  # fmt: skip
    # wrist: s_c (alpha - s_a q_a - s_b q_b), whatever turns the shoulder and elbow took
    vc = s[rc] * (alpha - s[ra] * ta[0] - s[rb] * tb[0])
    tc = nearest_turn(vc, lo[rc], hi[rc], ref[rc], cont[rc])
    if tc is None:
        edge = turn_edge(vc, lo[rc], hi[rc], 2.0 * wob)
        if edge is not None:  # the wrist on its limit fixes link 2's heading
            sigma = alpha - s[rc] * edge + b2
            theta1, miss = arm.with_link2(wx, wy, sigma)
            ta = nearest_turn(s[ra] * (theta1 - b1), lo[ra], hi[ra], ref[ra], cont[ra])
            tb = nearest_turn(s[rb] * (sigma - theta1 + b1 - b2), lo[rb], hi[rb], ref[rb], cont[rb])
            if miss <= REACH_TOL and ta is not None and tb is not None:
                tc = nearest_turn(s[rc] * (alpha - s[ra] * ta[0] - s[rb] * tb[0]), lo[rc], hi[rc], ref[rc])
        if tc is None or ta is None or tb is None:
            return IKStatus.J4_LIMIT, f"{label}: {names[rc]} = {wrap(vc):.9g} rad (+2 pi k) outside [{lo[rc]:.9g}, " \
                                      f"{hi[rc]:.9g}]"  # fmt: skip
    return ta, tb, tc


def _free_shoulder(geo: ScaraGeometry, alpha: float, phi2: float, ref_a: float) -> float:
    """phi1 for a free shoulder (wrist on its axis).

    It is inside the J1 limits, with a J4 turn inside the J4 limits when there is one, and nearest to the
    reference among those values.
    """
    ra, _, rc = geo.revolute
    s_a, s_c = geo.signs[ra], geo.signs[rc]
    lo_a, hi_a = geo.lower[ra], geo.upper[ra]
    lo_c, hi_c = geo.lower[rc], geo.upper[rc]
    want = min(max(ref_a, lo_a), hi_a)
    if geo.continuous[rc] or hi_c - lo_c >= TWO_PI:  # any q1 has a wrist turn inside its limits
        return s_a * want
    # q4 = s_c (alpha - phi2 - s_a q1) + 2 pi k in [lo_c, hi_c]  <=>  q1 in an interval shifted by 2 pi k
    c = alpha - phi2
    ends = sorted((s_a * (c - s_c * lo_c), s_a * (c - s_c * hi_c)))
    k = math.floor((want - ends[1]) / TWO_PI)  # the shifted intervals nearest the reference: k and k + 1
    best = None
    for kk in (k, k + 1):
        a, b = max(ends[0] + kk * TWO_PI, lo_a), min(ends[1] + kk * TWO_PI, hi_a)
        if a <= b:
            v = min(max(want, a), b)
            if best is None or abs(v - want) < abs(best - want):
                best = v
    return s_a * (want if best is None else best)  # no turn fits the wrist: J4_LIMIT follows


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
    if failure is not None:
        return IKResult(pose, (), failure[0], failure[1], geo.continuous)
    sols = tuple(IKSolution(np.array(q), label, singular, tuple(turns)) for label, singular, q, turns in found)
    result = IKResult(pose, sols, IKStatus.OK, f"{len(sols)} solution(s)", geo.continuous)
    return result.expand(geo.lower, geo.upper) if all_turns else result


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
    found, failure = _branches(geo, x, y, z, alpha, ref, branch)
    if failure is not None:
        raise NoSolutionError(*failure)
    q = found[0][2]
    if len(found) > 1:
        w = [1.0] * 4 if weights is None else weight_floats(weights)
        other = found[1][2]
        d0 = d1 = 0.0
        for i in range(4):
            e0, e1 = q[i] - ref[i], other[i] - ref[i]
            d0 += w[i] * e0 * e0
            d1 += w[i] * e1 * e1
        if d1 < d0:
            q = other
    elif weights is not None:
        weight_floats(weights)
    return np.array(q)



# ------------------------------------------------------------------------------------------ batch
_BATCH_ROWS = 16384
"""Rows per block of :func:`solve_batch` (its arrays stay in the cache)."""


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
    T = np.asarray(targets, dtype=float)
    if T.ndim != 2 or T.shape[1] != 4:
        raise ParameterError("targets", f"array of shape {T.shape}", "must have shape (N, 4): x, y, z, yaw")
    if branch not in ("nearest", *BRANCHES):
        raise InvalidInputError(f"branch {branch!r} must be 'nearest', 'right' or 'left'")
    bad = ~(np.abs(T) <= MAGNITUDE_MAX).all(axis=1)  # NaN fails the comparison
    if bad.any():
        i = int(np.argmax(bad))
        check_magnitude(T[i].tolist())
    ref = np.zeros(4) if reference is None else np.asarray(reference, dtype=float)
    if ref.shape not in ((4,), (T.shape[0], 4)) or not np.isfinite(ref).all():
        raise ParameterError("reference", f"array of shape {ref.shape}", "must be 4 finite values or (N, 4)")
    n = T.shape[0]
    q = np.empty((n, 4))
    status = np.empty(n, dtype=np.int64)
    sign = np.empty(n, dtype=np.int64)
    for start in range(0, n, _BATCH_ROWS):
        stop = min(start + _BATCH_ROWS, n)
        refs = ref if ref.ndim == 1 else ref[start:stop]
        _block(geo, T[start:stop], refs, branch, q[start:stop], status[start:stop], sign[start:stop])
    return BatchIKResult(q, status, sign)


def _block(geo: ScaraGeometry, T: np.ndarray, ref: np.ndarray, branch: str, q_out: np.ndarray,
           st_out: np.ndarray, sg_out: np.ndarray) -> None:  # fmt: skip
    """Solve one block of rows into q_out, st_out, sg_out (see :func:`solve_batch`)."""
    ra, rb, rc = geo.revolute
    ip = geo.prismatic
    s, lo, hi, cont = geo.signs, geo.lower, geo.upper, geo.continuous
    arm = geo.arm
    refc = [ref[j] if ref.ndim == 1 else ref[:, j] for j in range(4)]
    x, y, z = T[:, 0], T[:, 1], T[:, 2]
    alpha = T[:, 3] - geo.yaw0
    # vertical joint
    qp = (z - geo.z0) * s[ip]
    stroke = (qp < lo[ip] - LIMIT_TOL) | (qp > hi[ip] + LIMIT_TOL)
    np.clip(qp, lo[ip], hi[ip], out=qp)
    # wrist point and the planar arm
    tx, ty = geo.tool
    if tx or ty:
        ca, sa = np.cos(alpha), np.sin(alpha)
        wx = x - (ca * tx - sa * ty) - geo.a1[0]
        wy = y - (sa * tx + ca * ty) - geo.a1[1]
    else:
        wx, wy = x - geo.a1[0], y - geo.a1[1]
    code, r, gamma, heading = arm.solve_array(wx, wy)
    inner = (code == Reach.IN) | ((code == Reach.OK) & (r < geo._radius[0] - REACH_TOL))
    shared = np.where(stroke, IKStatus.J3_STROKE, np.where(code == Reach.OUT, IKStatus.OUT_OF_REACH,
                      np.where(inner, IKStatus.INSIDE_INNER_LIMIT, IKStatus.OK)))  # fmt: skip
    lean = arm.lean_array(gamma)
    wob = arm.wobble_array(gamma)
    signs = (1, -1) if branch == "nearest" else ((1,) if branch == "right" else (-1,))
    best_q = best_st = best_d = None
    for sg in signs:
        g = gamma if sg > 0 else -gamma
        qb, okb = nearest_turn_array(s[rb] * (g + (geo.beta1 - geo.beta2)), lo[rb], hi[rb], refc[rb], cont[rb])
        qa, oka = nearest_turn_array(s[ra] * (heading - sg * lean - geo.beta1), lo[ra], hi[ra], refc[ra], cont[ra])
        qc, okc = nearest_turn_array(s[rc] * (alpha - s[ra] * qa - s[rb] * qb), lo[rc], hi[rc], refc[rc], cont[rc])
        st = np.where(shared != 0, shared, np.where(~okb, IKStatus.J2_LIMIT, np.where(
            ~oka, IKStatus.J1_LIMIT, np.where(~okc, IKStatus.J4_LIMIT, IKStatus.OK))))  # fmt: skip
        Q = np.empty((len(T), 4))
        Q[:, ra], Q[:, rb], Q[:, rc], Q[:, ip] = qa, qb, qc, qp
        if best_q is None or best_st is None:
            best_q, best_st = Q, st
            if len(signs) > 1:
                best_d = np.where(st == 0, ((Q - ref) ** 2).sum(axis=1), np.inf)
            sg_out[:] = sg
            continue
        d = np.where(st == 0, ((Q - ref) ** 2).sum(axis=1), np.inf)
        # the other branch where it is strictly nearer, or where neither solves and it got further
        take = (d < best_d) | ((best_d == np.inf) & (d == np.inf) & (_STAGE_OF[st] > _STAGE_OF[best_st]))
        best_q[take] = Q[take]
        best_st[take] = st[take]
        sg_out[take] = sg
    if best_q is None or best_st is None:  # pragma: no cover - one sign at least
        return
    best_q[best_st != 0] = np.nan
    q_out[:] = best_q
    st_out[:] = best_st
    sg_out[best_st != 0] = 0
    # the rare rows solve() decides: a free shoulder, or a limit within the arm's rounding (see _joints)
    limits = (best_st == IKStatus.J1_LIMIT) | (best_st == IKStatus.J2_LIMIT) | (best_st == IKStatus.J4_LIMIT)
    rare = np.flatnonzero(((code == Reach.OK) & (r <= FREE_R) & (shared == 0)) | (limits & (wob > LIMIT_TOL)))
    for i in rare.tolist():
        row_ref = ref if ref.ndim == 1 else ref[i]
        res = solve(geo, T[i], branch="all" if branch == "nearest" else branch, reference=row_ref)
        best = res.nearest(row_ref) if res.success else None
        if best is None:
            q_out[i], st_out[i], sg_out[i] = np.nan, res.status, 0
        else:
            q_out[i], st_out[i], sg_out[i] = best.q, IKStatus.OK, 1 if best.branch == "right" else -1


_STAGE_OF = np.zeros(len(IKStatus), dtype=np.int64)
_STAGE_OF[[IKStatus.J2_LIMIT, IKStatus.J1_LIMIT, IKStatus.J4_LIMIT]] = [1, 2, 3]
"""Per status code, how far a branch got (as _STAGE)."""
