"""A palletizer's geometry read from its loaded model: arms, zero offsets, signs, the third joint's reference.

The closed form (:mod:`scara_pin.kinematics.palletizer`) works in S2's canonical coordinates; a file's
joints are each one canonical coordinate turned and shifted, ``t_i = s_i q_i + c_i``. Files differ in the
order of their joints (the levelling joint before or after the small arm's: the same kinematics), their
zero pose (a small arm horizontal at q = 0, as the Dobot MG400's and Magician's), their third joint's
reference (the small arm's angle from the vertical, or from the big arm: ``relative``) and their axes'
directions. All of it is read here from the model's forward kinematics, not from the order of the joints:

- the waist's sign from its axis (up: +1); the arm plane's forward direction ``f``, horizontal and normal
  to the big arm's axis, towards the tool at q = 0 (its heading is c1);
- in the arm plane (r = p . f, z), turning the third joint alone (q2 = 0) moves the tool on a circle of
  radius a3 about the elbow (the flange is level, so the tool's offset from the wrist is constant): its
  points at q3 = 0, pi/2, pi give the elbow, a3, the small arm's angle from the vertical at q = 0 and s3;
- turning the big arm alone (q3 = 0) moves the tool about the shoulder. If the third joint is absolute the
  small arm keeps its direction, and the elbow (the tool less a3 times the small arm's direction) draws a
  circle of radius a2 about the shoulder; if it is relative the whole arm turns as one body about the
  shoulder, whose centre is then the midpoint of the tool at q2 = 0 and pi. Both readings are tried: the
  one whose closed form reproduces the model at 8 seeded random configurations (to ``FK_TOL``) is kept.

The shoulder's (r, z) in that circle is the canonical (r0, h0): the tool's place with both arms of zero
length, so ``r = r0 + a2 sin(q2) + a3 sin(theta3)`` and ``z = h0 + a2 cos(q2) + a3 cos(theta3)``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from .palletizer import FK_TOL, NotPalletizerError, PalletizerGeometry, forward
from .planar2r import wrap

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = ["LENGTH_TOL", "SNAP_TOL", "read"]

LENGTH_TOL = 1e-9
"""[m] an arm shorter than this has no length (the closed form divides by it)."""
SNAP_TOL = 1e-12
"""[rad] a zero offset this close to a multiple of pi/2 is that multiple (the rest is FK's rounding)."""
_QUARTER = 0.5 * math.pi


def _snapped(angle: float) -> float:
    """``angle`` [rad], or the multiple of pi/2 within SNAP_TOL of it (a zero pose as drawn: exactly)."""
    k = round(angle / _QUARTER)
    return k * _QUARTER if abs(angle - k * _QUARTER) <= SNAP_TOL else angle


def _angle(d: np.ndarray) -> float:
    """The angle of (r, z) from the vertical, positive towards +r (forwards) [rad]."""
    return math.atan2(float(d[0]), float(d[1]))


def _turn_sign(before: np.ndarray, after: np.ndarray, name: str, robot: RobotModel) -> float:
    """+1 or -1: the way a quarter turn of a joint turns the point from ``before`` to ``after`` (about 0)."""
    turn = wrap(_angle(after) - _angle(before))
    if abs(abs(turn) - _QUARTER) > 1e-6:
        raise NotPalletizerError(f"robot {robot.name!r}: turning {name} by 90 deg turns the tool by "
                                 f"{math.degrees(turn):.6g} deg in the arm plane, not 90: not a palletizer's "
                                 "parallel arm joints")  # fmt: skip
    return 1.0 if turn > 0 else -1.0


def read(robot: RobotModel) -> PalletizerGeometry:
    """The palletizer's geometry from the robot's model (module docstring).

    Raises:
        NotPalletizerError: an arm without length, joints that do not turn the tool in the arm plane, or a
            closed form that departs from the model (the smallest departure of the two readings, named).
    """
    from ..chain import palletizer_layout

    names = robot.joint_names
    axes = robot.axes
    if robot.dof != 4 or not palletizer_layout(axes):
        raise NotPalletizerError(f"robot {robot.name!r} ({', '.join(names)}) has not a palletizer's layout (a "
                                 "vertical waist, two parallel horizontal arm joints, a vertical flange): not a "
                                 "palletizer")  # fmt: skip
    fk = robot.tool_pose
    f = np.cross(axes[1].axis, [0.0, 0.0, 1.0])
    f[2] = 0.0
    f /= np.linalg.norm(f)  # the big arm's axis is horizontal (palletizer_layout): f is a unit vector
    p0 = fk(np.zeros(4))
    if float(f @ p0[:3]) < 0.0:  # forwards: towards the tool
        f = -f

    def plane(q2: float, q3: float) -> np.ndarray:
        p = fk(np.array([0.0, q2, q3, 0.0]))
        return np.array([float(p[:3] @ f), float(p[2])])

    t0, ta, tb = plane(0.0, 0.0), plane(0.0, _QUARTER), plane(0.0, math.pi)
    elbow, a3 = (t0 + tb) / 2.0, float(np.linalg.norm(t0 - tb)) / 2.0
    if a3 <= LENGTH_TOL:
        raise NotPalletizerError(f"robot {robot.name!r}: turning {names[2]} does not move the tool: the small arm "
                                 f"({names[2]} to the wrist) has no length")  # fmt: skip
    s3 = _turn_sign(t0 - elbow, ta - elbow, names[2], robot)
    alpha3 = _snapped(_angle(t0 - elbow))
    s1 = 1.0 if axes[0].axis[2] > 0 else -1.0
    s4 = 1.0 if axes[3].axis[2] > 0 else -1.0
    c1 = math.atan2(float(f[1]), float(f[0]))
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    bMs = data.oMf[robot.base_id].actInv(data.oMi[model.getJointId(names[1])]).translation
    limits, cont = robot.limits, tuple(robot.continuous)
    worst: tuple[float, str] = (math.inf, "")
    for relative in (False, True):
        if relative:  # the whole arm turns about the shoulder
            u0, ua, ub = plane(0.0, 0.0), plane(_QUARTER, 0.0), plane(math.pi, 0.0)
        else:  # the elbow turns about the shoulder; the small arm keeps its direction
            e = a3 * np.array([math.sin(alpha3), math.cos(alpha3)])
            u0, ua, ub = plane(0.0, 0.0) - e, plane(_QUARTER, 0.0) - e, plane(math.pi, 0.0) - e
        shoulder = (u0 + ub) / 2.0
        a2 = float(np.linalg.norm(elbow - shoulder))
        if a2 <= LENGTH_TOL:
            worst = min(worst, (math.inf, f"turning {names[1]} does not move the elbow: the big arm ({names[1]} "
                                          f"to {names[2]}) has no length"))  # fmt: skip
            continue
        s2 = _turn_sign(u0 - shoulder, ua - shoulder, names[1], robot)
        alpha2 = _snapped(_angle(elbow - shoulder))
        signs = (s1, s2, s3, s4)
        offsets = (c1, alpha2, alpha3 - alpha2 if relative else alpha3, 0.0)
        lower, upper = [], []
        for i in range(4):
            ends = sorted(signs[i] * v + offsets[i] for v in (limits.lower[i], limits.upper[i]))
            lower.append(-math.inf if cont[i] else ends[0])
            upper.append(math.inf if cont[i] else ends[1])
        geo = PalletizerGeometry(
            r0=float(shoulder[0]), h0=float(shoulder[1]), a2=a2, a3=a3, tool_yaw=float(p0[3]) - c1,
            lower=tuple(lower), upper=tuple(upper),  # type: ignore[arg-type]
            shoulder=(float(bMs @ f), float(bMs[2])), continuous=cont,
            R0=robot.tool_placement(np.zeros(4)).rotation.copy(), signs=signs, offsets=offsets,
            relative=relative, names=names,  # type: ignore[arg-type]
        )  # fmt: skip
        err, at = _departure(geo, robot)
        if err <= FK_TOL:
            return geo
        worst = min(worst, (err, f"the palletizer's closed form departs from the model by {err:.3g} at q = "
                                 f"{np.round(at, 6).tolist()} (a2 = {a2:.9g}, a3 = {a3:.9g} m read from the "
                                 f"model, {names[2]} read as {'relative' if relative else 'absolute'})"))  # fmt: skip
    raise NotPalletizerError(f"robot {robot.name!r}: {worst[1]}")


def _departure(geo: PalletizerGeometry, robot: RobotModel) -> tuple[float, np.ndarray]:
    """The largest difference of the closed form from the model [m, rad] at 8 seeded configurations, and where."""
    rng = np.random.default_rng(0)
    worst = (0.0, np.zeros(4))
    for q in rng.uniform(-math.pi, math.pi, (8, 4)):
        err = np.abs(forward(geo, q) - robot.tool_pose(q))
        err[3] = abs(wrap(float(err[3])))
        if err.max() > worst[0]:
            worst = (float(err.max()), q)
    return worst
