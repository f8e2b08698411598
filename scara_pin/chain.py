"""The robot's chain in a URDF tree: the joints of ``q``, the geared ones that follow them, the locked ones.

A URDF may hold more joints than the arm's degrees of freedom. :class:`scara_pin.model.RobotModel` keeps in ``q``
only the joints that move the tool freely:

- **geared joints** (URDF ``<mimic joint="J" multiplier="m" offset="c"/>``): Pinocchio loads them as mimic
  joints (``mimic=True``), outside ``q``; their value is ``m * q[J] + c`` (:class:`GearedJoint`);
- **locked joints**: every joint that is not on the chain from the root link to the tool frame (the other
  arm of a two-arm robot, a gripper's fingers), and any joint the user locks, is fixed at a value
  (default 0, or the nearest limit when 0 is outside them; ``lock={"joint": value}`` sets it) by
  Pinocchio's ``buildReducedModel``. The locked parts stay in the model as fixed bodies: the viewer still
  draws the whole robot, at the locked values. A geared joint whose source is locked is locked with it;
  one whose source stays free keeps following it, on the chain or off it (a parallelogram's rods beside
  the arm: drawn, and their frames placed, where the arm puts them). Locking a geared joint locks its
  source at the value that gives it. A geared joint Pinocchio cannot build as a mimic (its source built
  after it: a gripper's second jaw named before the first) is handed to Pinocchio as a plain joint and
  locked with its source, at the value its gearing gives (``unbuilt``).

Lock values are SI (rad, m), as the rest of the robot's description (the CLI's ``--set`` likewise).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .errors import ParameterError, UrdfError
from .urdf_rules import JointEdge, Mimic, UrdfRuleError, mimic_error, zero_within

__all__ = [
    "AXIS_TOL",
    "LEVEL_PROBES",
    "GearedJoint",
    "JointAxis",
    "LockedJoint",
    "flange_pitch",
    "geared_joints",
    "joint_axes",
    "palletizer_layout",
    "reduce_to_chain",
]


@dataclass(frozen=True)
class GearedJoint:
    """A joint that follows another (URDF ``<mimic>``): not a degree of freedom.

    Attributes:
        name: its URDF name.
        source: the index in q of the joint it follows; ``source_name`` that joint's name.
        multiplier, offset: its value is ``multiplier * q[source] + offset`` [rad or m].
        kind: ``"angle"`` (revolute) or ``"length"`` (prismatic).
        lower, upper: its own URDF position limits (None when the file gives none; Pinocchio ignores them:
            the source's limits bound it).
    """

    name: str
    source: int
    source_name: str
    multiplier: float
    offset: float
    kind: str
    lower: float | None = None
    upper: float | None = None

    def value(self, q: Sequence[float]) -> float:
        """Its value at ``q`` [rad or m]."""
        return self.multiplier * float(q[self.source]) + self.offset

    def outside_limits(self, value: float, tol: float = 1e-12) -> bool:
        """Whether ``value`` lies outside its own URDF limits (when it has them)."""
        if self.lower is None or self.upper is None:
            return False
        return not self.lower - tol <= value <= self.upper + tol

    def describe(self) -> str:
        """``wrist = 1 * arm1 + 1 rad``: the gearing in one phrase."""
        unit = "rad" if self.kind == "angle" else "m"
        return f"{self.name} = {self.multiplier:.9g} * {self.source_name} + {self.offset:.9g} {unit}"


@dataclass(frozen=True)
class LockedJoint:
    """A joint fixed at a value (not on the tool's chain, or locked by the user).

    Attributes:
        name: its URDF name.
        value: its locked value [rad or m] (a geared joint: the value its gearing gives).
        reason: ``"off-chain"`` (not between the root and the tool), ``"asked"`` (the user locked it) or
            ``"geared"`` (it follows a locked joint).
    """

    name: str
    value: float
    reason: str


def geared_joints(model: pin.Model, urdf_joints: Mapping[str, JointEdge]) -> tuple[GearedJoint, ...]:
    """The mimic joints of a Pinocchio model, with the q index of the joint each follows.

    Args:
        model: a model built with ``mimic=True``.
        urdf_joints: the URDF's joints as written, by name (their types and limits).
    """
    actuated = [j for j in range(1, model.njoints) if model.joints[j].nv > 0]
    index_of = {model.joints[j].idx_q: i for i, j in enumerate(actuated)}
    out = []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        if jm.nv > 0 or jm.shortname() != "JointModelMimic":
            continue
        mimic = jm.extract()
        source = index_of[jm.idx_q]
        edge = urdf_joints.get(model.names[j])
        out.append(GearedJoint(
            name=model.names[j], source=source, source_name=model.names[actuated[source]],
            multiplier=float(mimic.scaling), offset=float(mimic.offset),
            kind="length" if edge is not None and edge.type == "prismatic" else "angle",
            lower=None if edge is None else edge.lower, upper=None if edge is None else edge.upper,
        ))  # fmt: skip
    return tuple(out)


def _mimic_sources(model: pin.Model) -> dict[int, int]:
    """Mimic joint id -> the id of the joint it follows (the joint owning its configuration index)."""
    owner = {model.joints[j].idx_q: j for j in range(1, model.njoints) if model.joints[j].nv > 0}
    return {j: owner[model.joints[j].idx_q] for j in range(1, model.njoints) if model.joints[j].nv == 0
            and model.joints[j].shortname() == "JointModelMimic"}  # fmt: skip


def _set_q(model: pin.Model, q: np.ndarray, j: int, value: float) -> None:
    """Joint ``j``'s value in Pinocchio's ``q`` (a continuous joint's as its cos, sin)."""
    jm = model.joints[j]
    if jm.nq == 2:
        q[jm.idx_q : jm.idx_q + 2] = (math.cos(value), math.sin(value))
    else:
        q[jm.idx_q] = value


def _asked_values(model: pin.Model, lock: Mapping[str, float], gearing: Mapping[str, tuple[str, float, float]],
                  origin: str) -> dict[str, float]:  # fmt: skip
    """The values of ``lock`` as the free joints take them: a mimic's value locks its source at the value giving it."""
    movable = [model.names[j] for j in range(1, model.njoints)]
    out: dict[str, float] = {}
    for name, raw in lock.items():
        if not model.existJointName(name) or name == "universe":
            shown = ", ".join(movable[:40]) + (" ..." if len(movable) > 40 else "")
            raise UrdfRuleError("lock", f"{origin}: --lock {name[:80]!r}: no movable joint of that name; movable "
                                f"joints: {shown}")  # fmt: skip
        value = float(raw)
        if not math.isfinite(value):
            raise ParameterError(f"--lock {name}", value, "must be finite")
        if name not in gearing:
            out.setdefault(name, value)
            continue
        source, m, c = gearing[name]  # the mimic is locked with its source, at the value that gives it
        if m == 0.0:
            raise ParameterError(f"--lock {name}", value, f"cannot be set: {name} = 0 * {source} + {c:.9g} is the "
                                 f"constant {c:.9g} (lock {source} instead)")  # fmt: skip
        at = (value - c) / m
        given = lock.get(source, out.get(source))
        if given is not None and abs(float(given) - at) > 1e-12 * max(1.0, abs(at)):
            raise ParameterError(f"--lock {name}", value, f"gives {source} = {at:.9g} ({name} = {m:.9g} * {source} + "
                                 f"{c:.9g}), but {source} is locked at {float(given):.9g}")  # fmt: skip
        out[source] = at
    return out


def reduce_to_chain(
    model: pin.Model,
    tool: str,
    lock: Mapping[str, float],
    urdf_joints: Mapping[str, JointEdge],
    origin: str,
    unbuilt: Mapping[str, Mimic] | None = None,
) -> tuple[pin.Model, tuple[LockedJoint, ...]]:
    """The model of the chain from the root to ``tool``, every other joint locked (see the module docstring).

    Args:
        model: the whole robot (mimic joints loaded).
        tool: the tool frame (a link of the model).
        lock: joints to lock and their values [rad, m]; joints off the chain not named here are locked at 0
            (or the nearest limit when 0 is outside them). A mimic joint named here is locked with its source,
            the source at the value that gives the mimic's.
        urdf_joints: the URDF's joints as written, by name (their types and limits).
        origin: how to name the source in error messages.
        unbuilt: the mimics handed to Pinocchio without their ``<mimic>`` (it cannot build them: their source
            comes after them), by name; each is locked with its source, at the value its gearing gives.

    Returns:
        (the model itself when nothing is locked, else the reduced model; the locked joints in model order).

    Raises:
        UrdfRuleError: a locked name that is no movable joint; an unbuilt mimic whose source stays free.
        ParameterError: a lock value that is not finite, or outside the joint's limits (a mimic's: its
            source's value outside the source's limits, or another lock of its source).
    """
    unbuilt = unbuilt or {}
    sources = _mimic_sources(model)
    gearing: dict[str, tuple[str, float, float]] = {m.joint: (m.source, m.multiplier, m.offset)
                                                    for m in unbuilt.values()}  # fmt: skip
    for j, src in sources.items():
        mimic = model.joints[j].extract()
        gearing[model.names[j]] = (model.names[src], float(mimic.scaling), float(mimic.offset))
    asked = _asked_values(model, lock, gearing, origin)
    tool_joint = model.frames[model.getFrameId(tool, pin.FrameType.BODY)].parentJoint
    chain = set(model.supports[tool_joint])
    reasons: dict[int, str] = {}
    for j in range(1, model.njoints):
        name = model.names[j]
        if name in asked:
            reasons[j] = "asked"
        elif j not in chain and name not in gearing:
            reasons[j] = "off-chain"
    for name, (source, _, _) in gearing.items():  # a geared joint goes with its source: locked with it, else follows
        if model.getJointId(source) in reasons:
            reasons[model.getJointId(name)] = "asked" if name in lock else "geared"
        elif name in unbuilt:  # Pinocchio cannot make it follow a free source
            raise mimic_error(unbuilt[name], origin)
    if not reasons:
        return model, ()
    q_ref = pin.neutral(model)
    values: dict[int, float] = {}
    for j in sorted(reasons):
        name = model.names[j]
        if name in gearing:
            continue
        edge = urdf_joints.get(name)
        kind, lower, upper = ("revolute", None, None) if edge is None else (edge.type, edge.lower, edge.upper)
        if name in asked:
            value = asked[name]
            if kind != "continuous" and lower is not None and upper is not None and not lower <= value <= upper:
                via = [m for m, (s, _, _) in gearing.items() if s == name and m in lock]
                what = f"--lock {via[0]} (so {name} = {value:.9g})" if via and name not in lock else f"--lock {name}"
                raise ParameterError(what, lock.get(via[0], value) if via and name not in lock else value,
                                     f"must be within the joint's limits [{lower:g}, {upper:g}]")  # fmt: skip
        else:
            value = 0.0 if kind == "continuous" else zero_within(lower, upper)
        values[j] = value
        _set_q(model, q_ref, j, value)
    for j in sorted(reasons):
        name = model.names[j]
        if name in gearing:
            source, m, c = gearing[name]
            values[j] = m * values[model.getJointId(source)] + c
            if name in unbuilt:  # a free joint in Pinocchio's model: placed where its gearing puts it
                _set_q(model, q_ref, j, values[j])
    ids = sorted(reasons)
    try:
        reduced = pin.buildReducedModel(model, ids, np.asarray(q_ref, dtype=float))
    except (ValueError, RuntimeError) as exc:
        raise UrdfError(f"{origin}: locking {', '.join(model.names[j] for j in ids)} failed in Pinocchio: {exc}") \
            from None  # fmt: skip
    return reduced, tuple(LockedJoint(model.names[j], values[j], reasons[j]) for j in ids)


@dataclass(frozen=True)
class JointAxis:
    """A joint of q as the model places it at q = 0, in the base frame.

    Attributes:
        name: its URDF name; ``index``: its index in q.
        kind: ``"revolute"``, ``"prismatic"``, or ``"other"`` (neither: a screw, say).
        axis: its unit axis (revolute) or direction (prismatic) in the base frame.
        point: its joint frame's origin in the base frame [m].
        tilt: the angle between the axis and the base z axis, either way [rad] (0: vertical, pi/2: horizontal).
    """

    name: str
    index: int
    kind: str
    axis: np.ndarray
    point: np.ndarray
    tilt: float


def joint_axes(model: pin.Model, base_id: int) -> tuple[JointAxis, ...]:
    """The joints of q at q = 0 (their columns of Pinocchio's joint Jacobian, in the base frame's axes).

    Args:
        model: the robot's model (geared joints, nv = 0, are skipped: they are not in q).
        base_id: the id of the base frame.
    """
    data = model.createData()
    pin.computeJointJacobians(model, data, pin.neutral(model))
    pin.updateFramePlacements(model, data)
    oMb = data.oMf[base_id]
    Rbo = oMb.rotation.T
    out: list[JointAxis] = []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        if jm.nv == 0:
            continue
        col = pin.getJointJacobian(model, data, j, pin.LOCAL_WORLD_ALIGNED)[:, jm.idx_v]
        lin, ang = Rbo @ col[:3], Rbo @ col[3:]
        if np.linalg.norm(lin) < 1e-12 and abs(np.linalg.norm(ang) - 1) < 1e-12:
            kind, axis = "revolute", ang
        elif np.linalg.norm(ang) < 1e-12 and abs(np.linalg.norm(lin) - 1) < 1e-12:
            kind, axis = "prismatic", lin
        else:
            kind, axis = "other", ang
        tilt = math.atan2(math.hypot(axis[0], axis[1]), abs(axis[2]))
        out.append(JointAxis(model.names[j], len(out), kind, axis, oMb.actInv(data.oMi[j]).translation.copy(), tilt))
    return tuple(out)


AXIS_TOL = 1e-9
"""[rad] an axis this close to the base z axis is vertical; this close to the base plane, horizontal."""


def palletizer_layout(axes: Sequence[JointAxis]) -> bool:
    """Four revolute joints: a vertical waist, two parallel horizontal arm joints, a vertical flange (at q = 0)."""
    if len(axes) != 4 or any(a.kind != "revolute" for a in axes):
        return False
    vertical = [a.tilt <= AXIS_TOL for a in axes]
    horizontal = [abs(a.tilt - math.pi / 2) <= AXIS_TOL for a in axes]
    parallel = float(np.linalg.norm(np.cross(axes[1].axis, axes[2].axis))) <= AXIS_TOL
    return vertical[0] and horizontal[1] and horizontal[2] and parallel and vertical[3]


LEVEL_PROBES = ((0.3, 0.4, -0.5, 0.2), (-0.6, -0.3, 0.7, 1.1))
"""[rad] configurations at which a palletizer's flange must stay level (besides q = 0)."""


def flange_pitch(tool_placement: Callable[[np.ndarray], pin.SE3], q: Sequence[float]) -> float:
    """The angle between the tool's z axis at ``q`` and at q = 0 [rad] (0 for a flange kept level)."""
    z0 = tool_placement(np.zeros(len(q))).rotation[:, 2]
    z = tool_placement(np.asarray(q, dtype=float)).rotation[:, 2]
    return math.atan2(float(np.linalg.norm(np.cross(z0, z))), float(z0 @ z))
