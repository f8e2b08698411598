"""The SCARA's geometry, read from the Pinocchio model: the numbers every SCARA closed form uses.

Every joint axis is vertical in the ``base`` frame. Rotations about vertical axes commute with vertical
translations, so with the product of exponentials at the zero configuration the tool pose is

    p_xy(q) = A1 + R(phi1) [u1 + R(phi2) [u2 + R(phi4) t]],   z(q) = z0 + s3 q3,
    yaw(q) = yaw0 + phi1 + phi2 + phi4,                          phi_i = s_i q_i,

where A1 is the shoulder axis (first revolute joint), u1 and u2 the plan-view vectors from it to the
elbow axis and from the elbow to the wrist axis (third revolute joint), t the tool point's offset from
the wrist axis, s_i = +/-1 each axis' direction (+z up), and R(phi) a rotation by phi about z; all at
q = 0. The prismatic joint may sit anywhere in the chain. Arm lengths l1 = |u1|, l2 = |u2|; the zero
offsets beta1 = atan2(u1), beta2 = atan2(u2) allow arms that are not stretched along +x at q = 0.

Branches (as on industrial controllers' lefty/righty arms): ``right``: the elbow turns counterclockwise
seen from above (sin gamma > 0, gamma the elbow angle from arm 1 to arm 2), like a human right arm seen
from above, elbow out to the right; ``left``: the mirror image (:func:`branch_of`).

The closed form on this geometry is :mod:`scara_pin.kinematics.scara` (one target) and
:mod:`scara_pin.kinematics.scara_batch` (N targets, vectorised).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, overload

import numpy as np
import pinocchio as pin

from ..errors import ParameterError, UrdfError
from .planar2r import (
    LIMIT_TOL,
    REACH_TOL,
    TWO_PI,
    Planar2R,
    turner,
    wrap,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = [
    "BRANCHES",
    "EXACT_TILT",
    "NEAR_PARALLEL_TOL",
    "WRIST_TILT_MAX",
    "YAW_POSE_TOL",
    "IKStatus",
    "NotScaraError",
    "ScaraGeometry",
    "branch_of",
    "wrist_point",
]

YAW_POSE_TOL = 1e-9
"""[rad] the largest tilt of a target rotation still taken as a pure yaw."""
NEAR_PARALLEL_TOL = 1e-2
"""[rad] the largest angle between a joint axis and the base z axis for a SCARA: beyond EXACT_TILT the
axes are near-parallel (pi written as 3.14 in an rpy) and the closed form's solutions are refined on the
model (:mod:`scara_pin.kinematics.polish`)."""
WRIST_TILT_MAX = 0.1
"""[rad] the largest tilt of the wrist axis alone (the last joint of a 4-joint SCARA; the others within
NEAR_PARALLEL_TOL): a modelling or mounting error such as a vendor file's 1 deg, refined on the model."""
EXACT_TILT = 1e-12
"""[rad] a model whose axes tilt less than this is solved by the closed form alone (no refinement)."""
BRANCHES = ("right", "left")
"""The SCARA's elbow branches, in the order solutions are listed."""

_sin, _cos = math.sin, math.cos


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
            ideal geometry; up to NEAR_PARALLEL_TOL: the closed form seeds a refinement on the model; up to
            WRIST_TILT_MAX when only the wrist tilts further).
        wrist_tilt: the wrist axis' own tilt [rad]. Beyond NEAR_PARALLEL_TOL (a wrist-only tilt) the joints
            that carry the wrist point are still (near-)vertical: the wrist point's region does not depend on
            the wrist; the tool's roll/pitch (and an offset tool point's height) do, and the solutions are
            refined on the model.
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
    wrist_tilt: float = 0.0
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
    def from_robot(cls, robot: RobotModel) -> ScaraGeometry:
        """Read the geometry from a loaded robot; raise :class:`NotScaraError` naming what is wrong.

        Axes up to ``NEAR_PARALLEL_TOL`` from the base z axis are accepted: the geometry is then the ideal
        vertical-axis one read at q = 0 (plan-view positions of the axes), ``tilt`` says how far the model
        departs from it, and :mod:`scara_pin.kinematics.polish` refines the closed form on the model.
        """
        return cls._read(robot, wrist=True)

    @classmethod
    def without_wrist(cls, robot: RobotModel) -> ScaraGeometry:
        """The geometry of a 3-joint SCARA (two revolute joints and one prismatic, in any order, no wrist).

        It is read as a 4-joint SCARA whose wrist, virtual and continuous, is index 3 of q and turns about
        the tool point (tool offset 0): arm 2 runs from the elbow axis to the tool point. The closed form
        and the workspace then apply unchanged; the virtual wrist's value is the tool's free yaw, dropped
        by :class:`scara_pin.kinematics.scara3_kinematics.Scara3Kinematics`.
        """
        return cls._read(robot, wrist=False)

    @classmethod
    def _read(cls, robot: RobotModel, wrist: bool) -> ScaraGeometry:
        model = robot.model
        data = model.createData()
        # the joints of q (nv = 1); geared (<mimic>) joints, nv = 0, follow one of them: those between the root
        # and the tool move it; others (a parallelogram's rods beside the arm) only follow
        actuated = [j for j in range(1, model.njoints) if model.joints[j].nv > 0]
        chain = list(model.supports[model.frames[robot.tool_id].parentJoint])[1:]
        geared = [j for j in chain if model.joints[j].nv == 0]
        names = tuple(model.names[j] for j in actuated)
        n = 4 if wrist else 3
        if len(actuated) != n:
            raise NotScaraError(f"a SCARA has {n} joints; this model has {len(actuated)}: {', '.join(names)}")
        off = [j for j in actuated if j not in chain]
        if off:
            raise NotScaraError(f"joint {model.names[off[0]]} does not carry the tool frame {robot.tool_frame!r}: "
                                "not a serial chain")  # fmt: skip
        q0 = pin.neutral(model)  # q = 0 (a continuous joint's (cos, sin) = (1, 0))
        pin.framesForwardKinematics(model, data, q0)
        oMb = data.oMf[robot.base_id]
        bMt = oMb.actInv(data.oMf[robot.tool_id])
        if geared:
            _check_geared(robot, data, geared, actuated, oMb, bMt.translation, wrist)
        revolute: list[int] = []
        prismatic: list[int] = []
        signs = [0.0] * 4
        points: dict[int, np.ndarray] = {}
        worst = wrist_tilt = 0.0
        wrist_axis = np.array([0.0, 0.0, 1.0])
        for ja in robot.axes:
            i, name, axis = ja.index, ja.name, ja.axis
            if ja.kind == "other":
                raise NotScaraError(f"joint {name} ({model.joints[actuated[i]].shortname()}) is neither revolute "
                                    "nor prismatic")  # fmt: skip
            kind = revolute if ja.kind == "revolute" else prismatic
            tilt = ja.tilt
            # the wrist (the last joint, revolute, of a 4-joint SCARA) may tilt further: it moves nothing that
            # carries the wrist point, so only the tool's own attitude (and an offset tool point) depends on it
            is_wrist = wrist and i == n - 1 and kind is revolute
            if tilt > NEAR_PARALLEL_TOL and not (is_wrist and tilt <= WRIST_TILT_MAX):
                limit = f"{WRIST_TILT_MAX:g} rad for the wrist, " if is_wrist else ""
                raise NotScaraError(
                    f"joint {name}'s axis is {math.degrees(tilt):.6g} deg ({tilt:.3g} rad) away from the base z "
                    f"axis (more than {limit}{NEAR_PARALLEL_TOL:g} rad): the axes of a SCARA are parallel and vertical"
                )
            worst = max(worst, tilt)
            if is_wrist:
                wrist_tilt, wrist_axis = tilt, axis
            signs[i] = 1.0 if axis[2] > 0 else -1.0
            kind.append(i)
            points[i] = ja.point
        if len(revolute) != n - 1 or len(prismatic) != 1:
            kinds = ", ".join(f"{n} ({'revolute' if i in revolute else 'prismatic'})" for i, n in enumerate(names))
            raise NotScaraError(f"a SCARA has {n - 1} revolute joints and 1 prismatic joint; this model has {kinds}")
        if not wrist:  # the virtual wrist: index 3, on the tool point, continuous, +z
            revolute.append(3)
            points[3] = bMt.translation
            signs[3] = 1.0
        else:  # the wrist point: the foot of the tool point on the wrist axis (arm 2 carries it, the wrist does not)
            w = revolute[2]
            points[w] = points[w] + wrist_axis * float((bMt.translation - points[w]) @ wrist_axis)
        ra, rb, rc = revolute
        a1, a2, a4 = points[ra][:2], points[rb][:2], points[rc][:2]
        u1, u2, t = a2 - a1, a4 - a2, bMt.translation[:2] - a4
        wrist_name = names[rc] if wrist else f"the tool point ({robot.tool_frame})"
        for vec, what, arm in ((u1, f"{names[rb]}'s axis coincides with {names[ra]}'s", f"arm 1 ({names[ra]} to "
                                f"{names[rb]})"), (u2, f"{wrist_name} lies on {names[rb]}'s axis",
                                f"arm 2 ({names[rb]} to {wrist_name})")):  # fmt: skip
            if math.hypot(*vec) < 1e-9:
                raise NotScaraError(f"{what}: {arm} has no length in plan view")
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
            lower=tuple(-math.inf if cont[i] else float(model.lowerPositionLimit[model.joints[actuated[i]].idx_q])
                        for i in range(4)),
            upper=tuple(math.inf if cont[i] else float(model.upperPositionLimit[model.joints[actuated[i]].idx_q])
                        for i in range(4)),
            continuous=cont,
            tilt=worst,
            wrist_tilt=wrist_tilt,
        )  # fmt: skip

    # ---------------------------------------------------------------------------------------- derived
    @overload
    def elbow_angle(self, q_elbow: float) -> float: ...

    @overload
    def elbow_angle(self, q_elbow: np.ndarray) -> np.ndarray: ...

    def elbow_angle(self, q_elbow: float | np.ndarray) -> float | np.ndarray:
        """Gamma (angle from arm 1 to arm 2, counterclockwise from above) at an elbow joint value (or array)."""
        return self.signs[self.revolute[1]] * q_elbow + self.beta2 - self.beta1

    def yaw_of(self, q: Sequence[float] | np.ndarray) -> float:
        """The tool's yaw at ``q``, unwrapped: yaw0 + phi1 + phi2 + phi4 (equal to FK's modulo 2 pi) [rad]."""
        return self.yaw0 + sum(self.signs[i] * float(q[i]) for i in self.revolute)

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


GEARED_AXIS_TOL = 1e-9
"""[m] the largest plan-view distance of the tool point from a geared joint's vertical axis (it then turns the
tool about its own point: the position stays the SCARA's)."""


def _check_geared(robot: RobotModel, data: pin.Data, geared: list[int], actuated: list[int], oMb: pin.SE3,
                  tool: np.ndarray, wrist: bool) -> None:  # fmt: skip
    """Refuse (NotScaraError) geared joints the closed form cannot take.

    A geared joint (URDF ``<mimic>``) is taken when it only turns the tool about the tool point: a revolute
    joint whose axis is vertical and passes through the tool point, with no revolute joint of q after it
    (so that the tool point stays on its axis). Then the tool's position is that of the SCARA without it,
    and its yaw follows (q1, q2 and the joint it is geared to): a 3-joint SCARA, whose yaw is not chosen. A
    4-joint SCARA chooses its yaw: a geared joint turning the tool would change it; refused.
    """
    model = robot.model
    for j in geared:
        name = model.names[j]
        follows = next(model.names[a] for a in actuated if model.joints[a].idx_q == model.joints[j].idx_q)
        if wrist:
            raise NotScaraError(f"joint {name} is geared to {follows} (<mimic>) and turns the tool: a 4-joint SCARA "
                                "chooses its tool's yaw with its own wrist; the closed form takes no geared joint "
                                "there (only numeric IK applies)")  # fmt: skip
        jd = model.joints[j].createData()  # the joint's own motion subspace, in its frame (its inner joint's)
        model.joints[j].calc(jd, pin.neutral(model))
        S = np.asarray(jd.S).reshape(6)
        if np.linalg.norm(S[:3]) > 1e-12 or abs(np.linalg.norm(S[3:]) - 1) > 1e-12:
            raise NotScaraError(f"joint {name} (geared to {follows} by <mimic>) is not a revolute joint: the "
                                "closed form takes geared joints that turn the tool about its point")  # fmt: skip
        bMj = oMb.actInv(data.oMi[j])
        axis = bMj.rotation @ S[3:]
        tilt = math.atan2(math.hypot(axis[0], axis[1]), abs(axis[2]))
        off = math.hypot(*(tool[:2] - bMj.translation[:2]))
        later = [model.names[a] for a in actuated if a > j and model.joints[a].shortname().startswith("JointModelR")]
        if tilt > EXACT_TILT or off > GEARED_AXIS_TOL or later:
            why = (f"its axis is {math.degrees(tilt):.6g} deg from vertical" if tilt > EXACT_TILT else
                   f"joint {later[0]} turns after it" if later else
                   f"the tool point is {off:.6g} m from its axis")  # fmt: skip
            raise NotScaraError(f"joint {name} is geared to {follows} (<mimic>) and moves the tool point ({why}): "
                                "the closed form takes geared joints that only turn the tool about its point "
                                "(only numeric IK applies)")  # fmt: skip


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


