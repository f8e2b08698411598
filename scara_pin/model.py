"""A 4-DOF robot (SCARA or palletizer) loaded into Pinocchio: FK, frame placements and Jacobians.

Conventions (used by every command of the package):

- ``q`` holds the four joint values in URDF joint order, SI units ([rad], and [m] for the quill).
  Passive ``<mimic>`` joints (the palletizer's levelling joints, a wrist geared to the shoulder) are loaded
  as Pinocchio mimic joints: they follow their joint and are not in ``q`` (``Robot.geared``). Joints off the
  chain from the root to the tool (another arm) are locked (``Robot.locked``, :mod:`scara_pin.chain`).
  A URDF ``continuous`` joint (Pinocchio: nq = 2, its (cos q, sin q)) is one angle in ``q`` too: no position
  limit (any finite q), IK solutions presented in [-pi, pi]; :meth:`RobotModel.to_pinocchio_q` /
  :meth:`RobotModel.from_pinocchio_q` convert for raw Pinocchio calls.
- Poses are of ``tool0`` in the robot's ``base`` frame (the controller's reference frame). The yaw is
  ``atan2(R[1, 0], R[0, 0])`` of that rotation: the heading of tool0's x axis in the base plane.
- Pinocchio's world frame (``universe``) is the root link (``base_link``); Jacobians named after
  Pinocchio's reference frames (``WORLD``, ``LOCAL``, ``LOCAL_WORLD_ALIGNED``) are exactly Pinocchio's.
"""

from __future__ import annotations

import enum
import logging
import math
from collections.abc import Callable, Mapping, Sequence
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple, Protocol, Self

import numpy as np
import pinocchio as pin

from ._checks import MAGNITUDE_MAX
from .description import JOINT_COUNTS, JointLimits, RobotParameters, configured
from .errors import InvalidInputError, ParameterError, UrdfError
from .units import HUMAN, DisplayUnits, format_number
from .urdf_rules import (
    FrameChoice,
    JointEdge,
    Mimic,
    UrdfRuleError,
    choose_frames,
    locked_joints,
    mimic_error,
    read_tree,
    resolve_mimics,
    zero_within,
)

if TYPE_CHECKING:
    from ._typing import ArrayLike
    from .chain import GearedJoint, JointAxis, LockedJoint
    from .description.packages import PackagePath
    from .ik_results import BatchIKResult, IKResult

__all__ = ["Kinematics", "KinematicsFactory", "RobotModel", "pose_from_placement"]

_Q_MAX2 = (0.5 * MAGNITUDE_MAX) ** 2
"""The largest sum of squares of q that the cheap input test waves through (NaN and inf never pass)."""
_F64 = np.dtype(np.float64)
_TASK_ROWS = np.array([0, 1, 2, 5])  # x, y, z, wz of a 6-row Jacobian
# bound once for the per-call paths
_forward, _frame_placement, _frame_jacobian = pin.forwardKinematics, pin.updateFramePlacement, pin.computeFrameJacobian
_LWA = pin.LOCAL_WORLD_ALIGNED


class Kinematics(Protocol):
    """What each robot kind provides, read from the loaded model (see :mod:`scara_pin.kinematics.kinds`).

    The robot holds one (``Robot.kinematics``) and knows nothing else of inverse kinematics.
    """

    kind: str
    branches: tuple[str, ...]
    status: type[enum.IntEnum]
    geometry: Any

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """Every branch's solution (its turns nearest ``reference``), or the reason there is none."""
        ...

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """The one solution nearest ``reference``; NoSolutionError when there is none."""
        ...

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *,
              branch: str = "nearest") -> BatchIKResult:  # fmt: skip
        """One solution per row of an (N, 4) array of targets, with status codes."""
        ...

    def branch_of(self, q: ArrayLike) -> str:
        """The branch of a configuration."""
        ...


KinematicsFactory = Callable[["RobotModel"], Kinematics]


def _rerooted(model: pin.Model, baseMo: pin.SE3) -> pin.Model:
    """A copy of ``model`` whose world frame is the frame at ``baseMo.inverse()`` (same joints and frames)."""
    out = pin.Model(model)
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            out.jointPlacements[j] = baseMo * model.jointPlacements[j]
    for f in range(len(model.frames)):
        frame = out.frames[f]
        if frame.parentJoint == 0:
            frame.placement = baseMo * model.frames[f].placement
            out.frames[f] = frame
    return out


_REFERENCES: dict[str, pin.ReferenceFrame] = {
    "world": pin.ReferenceFrame.WORLD,
    "local": pin.ReferenceFrame.LOCAL,
    "local_world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
}


def pose_from_placement(aMb: pin.SE3) -> np.ndarray:
    """The (x, y, z, yaw) of a placement: its translation and ``atan2(R[1, 0], R[0, 0])`` [m, rad]."""
    R = aMb.rotation
    p = aMb.translation
    return np.array([p[0], p[1], p[2], math.atan2(R[1, 0], R[0, 0])])


def _parse_xml(urdf: str, origin: str, checked: bool) -> Any:
    """The parsed document: urdfdom's view of a stranger's file (no namespaces, raw blanks in values), ET's of ours."""
    import xml.etree.ElementTree as ET

    if checked:  # the package's own xacro output
        return ET.fromstring(urdf)
    from xml.parsers.expat import ExpatError

    from ._urdf_checks import parse_urdf_xml

    try:
        return parse_urdf_xml(urdf, lines=False)[0]
    except (ExpatError, ValueError) as exc:
        line, column = getattr(exc, "lineno", None), getattr(exc, "offset", None)
        where = f" at line {line}, column {column + 1}" if line is not None and column is not None else ""
        raise UrdfRuleError("malformed-xml", f"{origin}: malformed XML{where}") from None


def _parse_urdf(urdf: str, origin: str, checked: bool, frames: Mapping[str, str | None],
                lock: Mapping[str, float]) -> _Parsed:  # fmt: skip
    """Build a Pinocchio model from URDF text, turning every failure into a clear :class:`UrdfError`.

    ``checked``: the package generated it (its own xacro): the Python pre-checks are skipped. ``frames``: the
    ``tool`` and ``base`` asked for; ``lock``: the joints to lock (a mimic Pinocchio cannot build is locked
    with its source, when that source is locked).
    """
    root = _parse_xml(urdf, origin, checked)
    if root.tag != "robot":
        raise UrdfRuleError("root", f"{origin}: the root element is <{root.tag}>, not <robot>")
    changed = False
    if not checked:
        changed = _check_urdf(urdf, root, origin)
    links, joints = read_tree(root, origin)  # raises on an unusable joint (the rule `check` applies)
    choice = choose_frames(links, joints, tool=frames.get("tool"), base=frames.get("base"), origin=origin)
    # <mimic> joints (passive, coupled) are honoured: Pinocchio makes them mimic joints, outside q
    resolved = resolve_mimics(joints, origin) if any(j.mimic is not None for j in joints) else {}
    unbuilt = {m.joint: m for m in resolved.values() if m.unbuildable is not None}
    if unbuilt:  # locked with their source (a gripper's second jaw, off the arm), else refused
        locked = locked_joints(links, joints, choice.tool, lock, resolved)
        for m in unbuilt.values():
            if m.source not in locked:
                raise mimic_error(m, origin)
    ignored = [j.name for j in joints if j.unnamed_mimic]
    if ignored:
        logging.getLogger("scara_pin").warning(
            "%s: <mimic joint=\"\"> names no joint: ignored, as Pinocchio's parser reads it (%s %s free)", origin,
            ", ".join(ignored[:6]) + (" ..." if len(ignored) > 6 else ""), "is" if len(ignored) == 1 else "are")
    if any(m.via for m in resolved.values()) or unbuilt or ignored:
        _mimics_for_pinocchio(root, resolved, set(unbuilt) | set(ignored))
        changed = True
    if changed:
        import xml.etree.ElementTree as ET

        urdf = ET.tostring(root, encoding="unicode")
    mimic = any(m.unbuildable is None for m in resolved.values())
    try:
        model = pin.buildModelFromXML(urdf, mimic=True) if mimic else pin.buildModelFromXML(urdf)
    except (ValueError, RuntimeError) as exc:
        raise UrdfError(f"{origin}: not a valid URDF: {exc}") from None
    if model.nq == 0:
        raise UrdfRuleError("no-movable-joint",
            f"{origin}: the URDF has no movable joint connected to its root link "
            f"({model.nbodies - 1} bodies, nq = 0): the kinematic tree is empty or disconnected"
        )  # fmt: skip
    return _Parsed(model, urdf, links, joints, choice, unbuilt)


class _Parsed(NamedTuple):
    """What the loader read: the model, the text Pinocchio was given, the tree, the frames, the mimics it left out."""

    model: pin.Model
    text: str
    links: list[str]
    joints: list[JointEdge]
    frames: FrameChoice
    unbuilt: dict[str, Mimic]


def _mimics_for_pinocchio(root: Any, resolved: Mapping[str, Mimic], drop: set[str]) -> None:
    """Each chain of ``<mimic>`` joints composed down to its free joint; the ``<mimic>`` of ``drop`` removed."""
    for el in root.findall("joint"):
        name = el.get("name", "")
        mimic = el.find("mimic")
        if mimic is None:
            continue
        if name in drop:
            el.remove(mimic)
            continue
        m = resolved.get(name)
        if m is not None and m.via:
            mimic.attrib.update(joint=m.source, multiplier=repr(m.multiplier), offset=repr(m.offset))


def _check_urdf(urdf: str, root: Any, origin: str) -> bool:
    """The Python checks of a URDF from elsewhere, before urdfdom sees it (:mod:`scara_pin._urdf_checks`).

    urdfdom's reasons go to the C stderr (capturing them would redirect fd 2, process-wide state): its
    rules are checked first, in Python, so that it only sees documents it accepts; and the rule
    ``scara-pin check`` applies (xacro-not-expanded / xacro-ignored; the text search spares a walk).

    Returns:
        Whether ``root`` was changed: the colours urdfdom would ignore noisily removed (said once here).
    """
    from ._urdf_checks import check_root, check_urdf_tree, second_parents, urdfdom_ignores, xacro_leftovers

    check_root(root, origin)
    leftover = xacro_leftovers(root) if "xacro" in urdf or "$" in urdf else None
    if leftover is not None:
        if leftover[0]:
            raise UrdfRuleError("xacro-not-expanded", f"{origin}: {leftover[1]}")
        logging.getLogger("scara_pin").warning("%s: %s", origin, leftover[1])
    check_urdf_tree(root, origin)
    for link, kept, other, _ in second_parents(root):  # a branch of fixed joints: the same frames twice, harmless
        logging.getLogger("scara_pin").warning("%s: link %r is the child of joints %r and %r: %r is ignored, as "
                                               "urdfdom does (it keeps the last by name)", origin, link, other, kept,
                                               other)  # fmt: skip
    ignored = urdfdom_ignores(root)  # colours urdfdom drops: said here once, not by urdfdom on fd 2
    if ignored:
        shown = ", ".join(ignored[:6]) + (f" and {len(ignored) - 6} more" if len(ignored) > 6 else "")
        logging.getLogger("scara_pin").warning("%s: colours URDF cannot read, ignored (as urdfdom does; a colour is "
                                               "<color rgba=\"r g b a\"/>, each in [0, 1]): %s", origin, shown)
        return True
    return False


_CONTINUOUS = frozenset(("JointModelRUBX", "JointModelRUBY", "JointModelRUBZ", "JointModelRevoluteUnboundedUnaligned"))
"""Pinocchio's continuous (unbounded revolute) joints: nq = 2 (cos, sin), nv = 1."""


def _given(name: str, values: Sequence[float], model: pin.Model, dof: int) -> tuple[float, ...]:
    """Limits given per joint of q (``velocity``, ``acceleration``): ``dof`` finite values > 0, or ParameterError."""
    joints = [model.names[j] for j in range(1, model.njoints) if model.joints[j].nv > 0]
    out = tuple(float(v) for v in values)
    if len(out) != dof:
        raise ParameterError(name, list(values), f"must hold {dof} values, one per joint ({', '.join(joints)})")
    for joint, v in zip(joints, out):
        if not (math.isfinite(v) and v > 0.0):
            raise ParameterError(f"{name} of joint {joint}", v, "must be finite and > 0")
    return out


def _continuous_joints(model: pin.Model, origin: str, edges: Mapping[str, JointEdge]) -> tuple[bool, ...]:
    """Per joint of q (nv = 1 each; passive mimic joints, nv = 0, skipped): whether it is continuous.

    Raises:
        UrdfRuleError: (``joint-count``) not 3 or 4 single-DOF joints (:data:`JOINT_COUNTS`; nv = 3 or 4, each
            nq = 1, or nq = 2 for a continuous joint).
    """
    out = []
    ok = model.nv in JOINT_COUNTS
    for j in range(1, model.njoints):
        jm = model.joints[j]
        if jm.nv == 0 and jm.nq == 0:  # a mimic joint: follows its joint, not in q
            continue
        cont = jm.nq == 2 and jm.nv == 1 and jm.shortname() in _CONTINUOUS
        ok = ok and (cont or (jm.nq == 1 and jm.nv == 1))
        out.append(cont)
    if not ok or len(out) != model.nv or model.nq != model.nv + sum(out):
        free = [j for j in range(1, model.njoints) if model.joints[j].nv > 0]

        def kind(j: int) -> str:
            edge = edges.get(model.names[j])
            written = edge.type if edge is not None else model.joints[j].shortname()
            nv = model.joints[j].nv
            return written if nv == 1 else f"{written}: {nv} degrees of freedom"

        listing = ", ".join(f"{model.names[j]} ({kind(j)})" for j in free[:12]) + (" ..." if len(free) > 12 else "")
        raise UrdfRuleError("joint-count", f"{origin}: a SCARA has 4 single-DOF joints (or 3 without a wrist); this "
                            f"file has {len(free)} movable joint{'s' if len(free) != 1 else ''}: {listing or 'none'}")
    return tuple(out)


class RobotModel:
    """A 4-joint robot (SCARA or palletizer) in Pinocchio, with its frames and limits.

    Continuous joints (URDF ``continuous``; Pinocchio stores them as (cos q, sin q), nq = 2) are accepted:
    users still see ``q`` as 4 values; :meth:`to_pinocchio_q` / :meth:`from_pinocchio_q` convert. Such a joint
    has no position limit: any finite value is a configuration (FK, Jacobians; ``outside_limits`` never
    names it), and ``limits.lower/upper`` are -pi/pi for it, the one-turn range IK solutions are presented
    in. Its velocity and effort limits are the URDF's ``<limit>`` values as Pinocchio reads them.

    Attributes:
        model: the Pinocchio model (``nv = 4``; ``nq = 4`` plus one per continuous joint).
        data: its Pinocchio data (the methods below overwrite it).
        urdf: the URDF text the model was built from, as written (Pinocchio got it less the colours urdfdom
            ignores, with chains of mimics composed: ``_pinocchio_urdf``).
        name: the robot's name.
        limits: the joint limits; accelerations come from ``joint_limits.yaml`` (URDF has none).
        parameters: the yaml parameters, when the robot was generated from them.
        kind: ``"scara"`` or ``"palletizer"`` (from the parameters; a URDF file is a palletizer when it has
            the palletizer's layout and its flange stays level; else it counts as a SCARA).
        continuous: per joint of q, whether it is a continuous joint; ``has_continuous``: any of them.
        dof: the number of joint values in q, 4 or 3 (a SCARA without a wrist; :data:`JOINT_COUNTS`).
        base_frame, tool_frame: names of the reference frame and of the tool frame (links of the URDF).
        frame_note: the notice when the tool frame was chosen by default without a ``tool0`` (else None).
        geared: the joints that follow another (URDF ``<mimic>``; not in q): :class:`scara_pin.chain.GearedJoint`.
        locked: the joints fixed at a value (another arm's, or asked for): :class:`scara_pin.chain.LockedJoint`;
            ``lock_note``: the notice naming those locked without being asked for (else None).
        package_path: where ``package://`` names (meshes) are looked for (see
            :mod:`scara_pin.description.packages`).
    """

    model: pin.Model
    data: pin.Data
    urdf: str
    name: str
    limits: JointLimits
    parameters: RobotParameters | None
    kind: str
    continuous: tuple[bool, ...]
    dof: int
    has_continuous: bool
    base_frame: str
    tool_frame: str
    frame_note: str | None
    geared: tuple[GearedJoint, ...]
    locked: tuple[LockedJoint, ...]
    lock_note: str | None
    _pinocchio_urdf: str

    def __init__(
        self,
        urdf: str,
        *,
        acceleration: Sequence[float] | None = None,
        velocity: Sequence[float] | None = None,
        parameters: RobotParameters | None = None,
        base_frame: str | None = None,
        tool_frame: str | None = None,
        origin: str = "URDF",
        package_path: PackagePath | None = None,
        kinematics: KinematicsFactory | None = None,
        lock: Mapping[str, float] | None = None,
        generated: bool = False,
    ) -> None:
        """Load URDF text.

        Args:
            urdf: the URDF document.
            acceleration: acceleration limits per joint [rad/s^2 or m/s^2]; URDF has none. Without it
                (a URDF file) they are NaN, meaning unknown: commands that need them ask for them.
            velocity: velocity limits per joint [rad/s or m/s], in q order, instead of the URDF's (a continuous
                joint without ``<limit>`` has none: Pinocchio reads inf; a placeholder 0). A URDF file only.
            parameters: the yaml parameters it was generated from, if any.
            base_frame: the link poses are expressed in; default ``base`` if present, else the root link.
            tool_frame: the tool link; default ``tool0`` if present, else the chain's last link
                (:func:`scara_pin.urdf_rules.choose_frames`, the rule ``scara-pin check`` reports).
            origin: how to name the source in error messages (a file name).
            package_path: where ``package://`` names are looked for (meshes); default: none.
            kinematics: builds the robot's kinematics object from the loaded robot (its kind's; see
                :func:`scara_pin.kinematics.kinds.kinematics_for`, which :func:`scara_pin.load_robot` passes).
            lock: joints to fix, with their values [rad, m] (:mod:`scara_pin.chain`); joints that are not on
                the chain from the root to the tool (another arm) are locked anyway, at 0 by default.
            generated: the URDF is the package's own xacro output (:meth:`from_config`): the checks that keep
                a stranger's file from urdfdom's C-level messages are skipped (urdfdom still refuses a bad one).

        Raises:
            UrdfError: unreadable, invalid or disconnected URDF, not a 4-joint robot, an unusable joint
                (inverted limits, zero axis: :func:`scara_pin.urdf_rules.joint_problem`), or a frame
                asked for that is not a link of the file.
        """
        parsed = _parse_urdf(urdf, origin, generated, {"tool": tool_frame, "base": base_frame}, lock or {})
        model, self._pinocchio_urdf, frames = parsed.model, parsed.text, parsed.frames
        base_frame, tool_frame = frames.base, frames.tool
        edges = {j.name: j for j in parsed.joints}
        # one arm of a multi-arm tree (or with --lock): the other joints fixed, the whole robot still drawn;
        # a model that is the chain alone (every joint moves the tool, none geared: the shipped robots) needs
        # neither (scara_pin.chain is not even imported: `scara-pin fk` starts faster)
        tool_joint = model.frames[model.getFrameId(tool_frame, pin.FrameType.BODY)].parentJoint
        alone = not lock and len(model.supports[tool_joint]) == model.njoints and model.nv == model.njoints - 1
        if alone:
            self.locked, self.geared = (), ()
        else:
            from .chain import geared_joints, reduce_to_chain

            model, self.locked = reduce_to_chain(model, tool_frame, lock or {}, edges, origin, parsed.unbuilt)
        try:
            continuous = _continuous_joints(model, origin, edges)
        except UrdfError as exc:
            if not self.locked:
                raise
            names = ", ".join(lj.name for lj in self.locked[:12]) + (" ..." if len(self.locked) > 12 else "")
            raise UrdfRuleError("joint-count", f"{exc}, once {names} locked (not on the chain {frames.root} -> "
                                f"{tool_frame}, or --lock): --tool picks the link that ends an arm"
                                ) from None  # fmt: skip
        if not alone:
            self.geared = geared_joints(model, edges)
        self.frame_note = frames.note
        off_chain = [lj for lj in self.locked if lj.reason != "asked"]
        self.lock_note = None if not off_chain else (
            f"{len(off_chain)} joint(s) not on the chain {frames.root} -> {tool_frame} locked: "
            + ", ".join(f"{lj.name} = {lj.value:.6g}" for lj in off_chain[:12])
            + (" ..." if len(off_chain) > 12 else "") + " (--lock JOINT=VALUE sets them, rad or m)"
        )  # fmt: skip
        self._package_path = package_path
        self.urdf = urdf
        self.name = model.name
        self.parameters = parameters
        self.base_frame = base_frame
        self.tool_frame = tool_frame
        self.base_id = model.getFrameId(base_frame, pin.FrameType.BODY)
        self.tool_id = model.getFrameId(tool_frame, pin.FrameType.BODY)
        if parameters is not None:
            self.limits = parameters.limits
        else:  # a URDF file: record its limits as written (they may be placeholders; not checked here)
            # per joint in q order; a continuous joint has no position limit: [-pi, pi] (one turn) is the
            # range its IK solutions are presented in (Pinocchio's cos/sin bounds of +/-1.01 mean nothing here)
            iq = [model.joints[j].idx_q for j in range(1, model.njoints) if model.joints[j].nv == 1]
            self.limits = JointLimits(
                lower=tuple(-math.pi if c else float(model.lowerPositionLimit[i]) for i, c in zip(iq, continuous)),
                upper=tuple(math.pi if c else float(model.upperPositionLimit[i]) for i, c in zip(iq, continuous)),
                velocity=tuple(float(v) for v in model.velocityLimit) if velocity is None
                else _given("velocity", velocity, model, len(continuous)),
                acceleration=tuple(math.nan for _ in continuous) if acceleration is None
                else _given("acceleration", acceleration, model, len(continuous)),
                effort=tuple(float(v) for v in model.effortLimit),
                validate=False,
            )
        self.continuous = continuous
        self.dof = len(continuous)
        self.has_continuous = any(continuous)
        self._kinematics_factory = kinematics
        self._attach(model)
        self.kind = parameters.kind if parameters is not None else _urdf_kind(self)

    def _attach(self, model: pin.Model) -> None:
        """Build what the robot computes with from ``model``: its data, the re-rooted copy, the per-call paths."""
        self.model = model
        self.data = model.createData()
        # base is fixed to the root: its placement never changes; keep its inverse for the fast path.
        pin.framesForwardKinematics(model, self.data, pin.neutral(model))
        # A private copy of the model re-rooted at the base frame: its oMf are placements in `base` and its
        # LOCAL_WORLD_ALIGNED Jacobians are in base axes, so the hot paths need no extra products.
        self._base_model = _rerooted(model, self.data.oMf[self.base_id].inverse())
        self._base_data = self._base_model.createData()
        if self.has_continuous:
            # (index in q, index in Pinocchio's q, continuous?) per joint, for the conversion to Pinocchio's q
            iq = [model.joints[j].idx_q for j in range(1, model.njoints) if model.joints[j].nv == 1]
            self._q_map = tuple(zip(range(self.dof), iq, self.continuous))
        # the per-call paths take q as it is when the cheap check passes: 4 plain joints only
        self._slow_q = self.has_continuous or self.dof != 4
        self._per_call = _per_call_paths(self)
        # the closures themselves as the instance's attributes (one call less), unless a subclass overrides them
        if type(self).tool_placement is _ROBOT_TOOL_PLACEMENT:
            self.tool_placement = self._per_call[0]  # type: ignore[method-assign,assignment]
        if type(self).task_jacobian is _ROBOT_TASK_JACOBIAN:
            self.task_jacobian = self._per_call[1]  # type: ignore[method-assign,assignment]

    def with_model(self, model: pin.Model) -> Self:
        """The same robot on ``model``, a Pinocchio model of the same joints and frames (a payload's inertias).

        A new robot of the same class, rebuilt around ``model`` (its data, re-rooted copy and per-call paths
        are its own); what the package caches per robot (collision geometry, scenes, IK objects) is not shared
        with this one.

        Raises:
            InvalidInputError: ``model`` has other joints or frames than this robot's.
        """
        if (model.nq, model.nv, model.njoints, model.nframes) != (self.model.nq, self.model.nv, self.model.njoints,
                                                                   self.model.nframes) \
                or list(model.names) != list(self.model.names):  # fmt: skip
            raise InvalidInputError("with_model takes a model of the same joints and frames as the robot's")
        out = object.__new__(type(self))
        keep = ("_pinocchio_urdf", "locked", "geared", "frame_note", "lock_note", "_package_path", "urdf", "name",
                "parameters", "base_frame", "tool_frame", "base_id", "tool_id", "limits", "continuous", "dof",
                "has_continuous", "_kinematics_factory", "kind")  # fmt: skip
        for name in keep:
            setattr(out, name, getattr(self, name))
        out._attach(model)
        return out

    def tool_placement(self, q: np.ndarray) -> pin.SE3:
        """``baseMtool``: the placement of the tool frame in the base frame, at ``q``.

        Computed on a private copy of the model re-rooted at the base frame (``robot.data`` is not updated).
        An instance calls a closure made for it at load directly (this method is what a subclass overrides,
        and what ``super()`` reaches).
        """
        return self._per_call[0](q)

    def task_jacobian(self, q: np.ndarray) -> np.ndarray:
        """The 4 x 4 Jacobian d(x, y, z, yaw)/dq of the tool pose in the base frame.

        Rows: the tool origin's velocity in base axes, then the yaw rate (the angular velocity about the
        base z axis, which equals d(yaw)/dt while the tool stays level). Called as :meth:`tool_placement`.
        """
        return self._per_call[1](q)

    # ----------------------------------------------------------------- construction helpers
    @classmethod
    def from_config(
        cls,
        robot: str | Path | RobotParameters = "default",
        overrides: Mapping[str, object] | None = None,
        **kwargs: Any,
    ) -> Self:
        """Generate the URDF of a configured robot (see :mod:`scara_pin.description`) and load it.

        Keyword arguments (``tool_frame``, ``base_frame``) are passed to the constructor.
        """
        params, urdf = configured(robot, overrides)  # the description cache: no yaml nor xacro when unchanged
        return cls(urdf, parameters=params, origin=f"robot {params.name!r}", generated=True, **kwargs)

    @classmethod
    def from_file(cls, path: str | Path, *, package_dirs: Sequence[str | Path] = (), **kwargs: Any) -> Self:
        """Load a URDF file, or a xacro file (name ending in ``.xacro``) expanded first.

        ``$(find pkg)`` and ``package://pkg/...`` are resolved in ``package_dirs`` (folders holding packages),
        the folders above the file and ``ROS_PACKAGE_PATH`` / ``AMENT_PREFIX_PATH``
        (:mod:`scara_pin.description.packages`). Expanding a xacro file runs the expressions written in
        it: load only files you trust, as you would run them through ``xacro``. Other keyword arguments
        are as for the constructor.
        """
        from .description.packages import PackagePath, read_robot_file

        path = Path(path)
        packages = PackagePath(tuple(Path(d) for d in package_dirs), path.parent)
        try:
            text = read_robot_file(path, packages)
        except UrdfError:
            if not path.name.endswith(".xacro"):
                raise
            from .description.xacro_sources import expand_with_sources

            expand_with_sources(path, packages)  # fails again, saying where in which file (XacroSourceError)
            raise
        return cls(text, origin=str(path), package_path=packages, **kwargs)

    # ----------------------------------------------------------------- geometry (lazy)
    @property
    def package_path(self) -> PackagePath:
        """Where ``package://`` names (meshes) are looked for (:mod:`scara_pin.description.packages`)."""
        if self._package_path is None:  # made when first asked: `fk` never imports the package resolver
            from .description.packages import PackagePath

            self._package_path = PackagePath()
        return self._package_path

    @cached_property
    def visual_model(self) -> pin.GeometryModel:
        """Visual geometry of the URDF, built on first use; each mesh is a placeholder box.

        Pinocchio never reads a mesh file: :func:`scara_pin.cell.meshes.visual_meshes` reads them (found
        and checked as that module says) under the same geometry names.
        """
        from .description.placeholders import placeholder_urdf

        return pin.buildGeomFromUrdfString(self.model, placeholder_urdf(self._pinocchio_urdf), pin.GeometryType.VISUAL)

    @cached_property
    def collision_model(self) -> pin.GeometryModel:
        """Collision geometry of the URDF, built on first use (meshes as placeholder boxes, as above)."""
        from .description.placeholders import placeholder_urdf

        return pin.buildGeomFromUrdfString(self.model, placeholder_urdf(self._pinocchio_urdf),
                                           pin.GeometryType.COLLISION)  # fmt: skip

    # ----------------------------------------------------------------- a summary for people (repr, notebooks)
    def summary(self) -> tuple[str, list[list[str]]]:
        """The robot at a glance: a headline and one row per joint, in degrees and millimetres.

        Returns:
            (headline, rows): the headline names the robot, its kind, its frames and where the tool is at
            q = 0; each row is ``[#, joint, type, lower, upper, velocity, acceleration, effort]`` (text, units
            included; ``continuous`` joints have no position limits, URDF files no acceleration limits).
        """
        human = HUMAN
        kinds = self.joint_kinds
        rows = []
        for i, name in enumerate(self.joint_names):
            kind = kinds[i]
            unit = human.name(kind)
            sc = human.scale(kind)

            def cell(v: float, per: str = "", sc: float = sc, unit: str = unit) -> str:
                return f"{format_number(v * sc, 3)} {unit}{per}" if math.isfinite(v) else "unknown"

            lim = self.limits
            kind_name = "continuous" if self.continuous[i] else ("prismatic" if kind == "length" else "revolute")
            lower = "-" if self.continuous[i] else cell(lim.lower[i])
            upper = "-" if self.continuous[i] else cell(lim.upper[i])
            effort = f"{format_number(lim.effort[i], 3)} {'N' if kind == 'length' else 'N·m'}"
            rows.append([str(i + 1), name, kind_name, lower, upper, cell(lim.velocity[i], "/s"),
                         cell(lim.acceleration[i], "/s²"), effort])  # fmt: skip
        try:
            x, y, z, yaw = self.tool_pose(np.zeros(self.dof)).tolist()
            at_zero = (f"; {self.tool_frame} at q = 0: ({human.format(x, 'length')}, {human.format(y, 'length')}, "
                       f"{human.format(z, 'length')}) mm, yaw {human.format(yaw, 'angle')} deg")  # fmt: skip
        except (ValueError, TypeError, ParameterError):  # a model whose tool pose cannot be read at q = 0
            at_zero = ""
        head = (f"Robot {self.name!r}: {self.kind}, {self.dof} joints, {self.tool_frame} in {self.base_frame}"
                f"{at_zero}")  # fmt: skip
        return head, rows

    def __repr__(self) -> str:
        head, rows = self.summary()
        table = [["#", "joint", "type", "lower", "upper", "velocity", "acceleration", "effort"], *rows]
        widths = [max(len(r[c]) for r in table) for c in range(len(table[0]))]
        lines = ["  ".join(v.rjust(w) if c >= 3 else v.ljust(w) for c, (v, w) in enumerate(zip(r, widths))).rstrip()
                 for r in table]  # fmt: skip
        return "\n".join([head, *("  " + line for line in lines)])

    # ----------------------------------------------------------------- inverse kinematics (delegated)
    @property
    def kinematics(self) -> Kinematics:
        """The kinematics object of the robot's kind (built on first use by the factory given at load).

        It may be replaced (``robot.kinematics = other``) or reset (``del robot.kinematics``): ``ik_nearest``
        follows.

        Raises:
            UrdfError: no kinematics factory was given, or the kind's closed form refuses the model (e.g.
                ``NotScaraError``, naming the joint).
        """
        kin = self.__dict__.get("_kinematics")
        if kin is None:
            if self._kinematics_factory is None:
                raise UrdfError(
                    f"robot {self.name!r} was loaded without its kinematics: load it with "
                    "scara_pin.load_robot(...) (or pass kinematics=scara_pin.kinematics_for)"
                )
            kin = self.__dict__["_kinematics"] = self._kinematics_factory(self)
        return kin  # type: ignore[no-any-return]

    @kinematics.setter
    def kinematics(self, value: Kinematics) -> None:
        self.__dict__["_kinematics"] = value
        self.__dict__.pop("ik_nearest", None)  # the cached nearest of the previous kinematics

    @kinematics.deleter
    def kinematics(self) -> None:
        self.__dict__.pop("_kinematics", None)
        self.__dict__.pop("ik_nearest", None)

    def ik(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
           all_turns: bool = False) -> IKResult:  # fmt: skip
        """Closed-form IK of the robot's kind: each branch's solution, turns nearest ``reference`` (default 0)."""
        return self.kinematics.solve(target, branch=branch, reference=reference, all_turns=all_turns)

    @cached_property
    def ik_nearest(self) -> Callable[..., np.ndarray]:
        """``ik_nearest(target, reference=None, *, weights=None, branch="all")``: the nearest solution, a new array.

        The closed-form solution nearest ``reference`` (weighted joint space). This attribute is the kind's
        ``nearest`` itself, looked up once (a per-call path).

        Raises:
            NoSolutionError: no solution inside the limits (``status``, ``reason``; exit code 3).
        """
        return self.kinematics.nearest

    def ik_batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
                 ) -> BatchIKResult:  # fmt: skip
        """One closed-form solution per row of (N, 4) targets: ``.q`` (N, 4), ``.status`` (N,), ``.branch``."""
        return self.kinematics.batch(targets, reference, branch=branch)

    def branch_of(self, q: ArrayLike) -> str:
        """The IK branch of a configuration (SCARA: right/left; palletizer: up/down)."""
        return self.kinematics.branch_of(q)

    # ----------------------------------------------------------------- input checks
    def check_q(self, q: object) -> np.ndarray:
        """Return ``q`` as a float array of ``dof`` (4, or 3) finite values, or raise :class:`ParameterError`."""
        n = self.dof
        try:
            arr = np.asarray(q)
        except (TypeError, ValueError):
            raise ParameterError("q", q, f"must be {n} numbers") from None
        if arr.dtype != np.float64:
            if arr.dtype.kind not in "fiu":  # strings, objects, booleans: refused, never converted
                raise ParameterError("q", q, f"must be {n} numbers")
            arr = arr.astype(np.float64)
        if arr.shape != (n,):
            raise ParameterError("q", q, f"must be {n} numbers (got shape {arr.shape})")
        if not all(-MAGNITUDE_MAX <= v <= MAGNITUDE_MAX for v in arr.tolist()):  # NaN fails every comparison
            for joint, value in zip(self.joint_names, arr.tolist()):
                if not math.isfinite(value):
                    raise ParameterError(joint, value, "must be finite")
                if abs(value) > MAGNITUDE_MAX:
                    raise ParameterError(joint, value, f"must be within +/-{MAGNITUDE_MAX:g} (rad or m)")
        return arr

    @cached_property
    def joint_kinds(self) -> tuple[str, ...]:
        """What each value of q measures, in q order: ``"angle"`` (revolute) or ``"length"`` (prismatic).

        Read from the model's actuated joints (mimic joints are not in q), so that human units (degrees,
        millimetres) scale the right values whatever the joint order (a lift joint first, say).
        """
        actuated = [jm for jm in self.model.joints[1:] if jm.nv > 0]
        return tuple("length" if jm.shortname().startswith("JointModelP") else "angle" for jm in actuated)

    @cached_property
    def axes(self) -> tuple[JointAxis, ...]:
        """The joints of q at q = 0 in the base frame: kind, axis, point (:func:`scara_pin.chain.joint_axes`)."""
        from .chain import joint_axes

        return joint_axes(self.model, self.base_id)

    @cached_property
    def joint_names(self) -> tuple[str, ...]:
        """The URDF names of the joints of q, in q order (mimic joints are not in q)."""
        return tuple(self.model.names[j] for j in range(1, self.model.njoints) if self.model.joints[j].nv > 0)

    @property
    def default_q(self) -> np.ndarray:
        """Where the robot rests by default (a page's first pose, the pendant's start), a new array.

        q = 0, each joint whose limits exclude 0 at its nearest limit (:func:`scara_pin.urdf_rules.zero_within`).
        """
        return np.array([0.0 if c else zero_within(lo, hi)
                         for c, lo, hi in zip(self.continuous, self.limits.lower, self.limits.upper)])  # fmt: skip

    def outside_limits(self, q: np.ndarray, tol: float = 0.0, units: DisplayUnits | None = None) -> list[str]:
        """The joints of ``q`` outside their position limits (by more than ``tol``), with values.

        ``units``: the values in these units, named (``joint3 = 0 deg outside [10, 150] deg``); default SI
        without unit names.
        """
        out = []
        for i, joint in enumerate(self.joint_names):
            if self.continuous[i]:  # no position limit
                continue
            lo, hi = self.limits.lower[i], self.limits.upper[i]
            if not lo - tol <= q[i] <= hi + tol:
                if units is None:
                    out.append(f"{joint} = {q[i]:.9g} outside [{lo:.9g}, {hi:.9g}]")
                else:
                    kind = self.joint_kinds[i]
                    out.append(f"{joint} = {units.format(q[i], kind)} {units.name(kind)} outside "
                               f"[{units.format(lo, kind)}, {units.format(hi, kind)}] {units.name(kind)}")  # fmt: skip
        return out

    # ----------------------------------------------------------------- kinematics
    def _valid_q(self, q: Any) -> np.ndarray:
        """``q`` itself when it is obviously valid (4 moderate float64 values, 4 joints), else ``check_q(q)``."""
        if self.dof == 4 and _q_ok(q):
            return q  # type: ignore[no-any-return]
        return self.check_q(q)

    def _pin_q(self, q: object) -> np.ndarray:
        """``q`` as Pinocchio takes it, checked: with continuous joints, converted (:meth:`_valid_pin_q`)."""
        return self._valid_pin_q(q) if self.has_continuous else self._valid_q(q)

    def _valid_pin_q(self, q: object) -> np.ndarray:
        """:meth:`_valid_q` then the conversion to Pinocchio's q (continuous joints as cos, sin)."""
        q = self._valid_q(q)
        out = [0.0] * self.model.nq
        for i, iq, cont in self._q_map:
            v = float(q[i])
            if cont:
                out[iq] = math.cos(v)
                out[iq + 1] = math.sin(v)
            else:
                out[iq] = v
        return np.array(out)

    def to_pinocchio_q(self, q: object) -> np.ndarray:
        """The user's 4 joint values (checked) as Pinocchio's configuration vector (``model.nq`` values).

        A continuous joint's angle q becomes (cos q, sin q); other joints are copied. Without continuous
        joints this is :meth:`check_q`.
        """
        if not self.has_continuous:
            return self.check_q(q)
        return self._valid_pin_q(self.check_q(q))

    def from_pinocchio_q(self, q_pin: object) -> np.ndarray:
        """Pinocchio's configuration vector (``model.nq`` values) as the user's 4 joint values.

        A continuous joint's (cos, sin) becomes ``atan2(sin, cos)``, in [-pi, pi].

        Raises:
            ParameterError: not ``model.nq`` finite numbers.
        """
        try:
            arr = np.asarray(q_pin, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError("q_pin", q_pin, f"must be {self.model.nq} numbers") from None
        if arr.shape != (self.model.nq,) or not np.isfinite(arr).all():
            raise ParameterError("q_pin", q_pin, f"must be {self.model.nq} finite numbers")
        if not self.has_continuous:
            return arr.copy()
        out = np.empty(self.dof)
        for i, iq, cont in self._q_map:
            out[i] = math.atan2(arr[iq + 1], arr[iq]) if cont else arr[iq]
        return out

    def tool_pose(self, q: np.ndarray) -> np.ndarray:
        """(x, y, z, yaw) of the tool frame in the base frame [m, m, m, rad]."""
        return pose_from_placement(self.tool_placement(q))

    def frame_placement(self, q: np.ndarray, frame: str, relative_to: str | None = None) -> pin.SE3:
        """Placement of any frame at ``q``, in the base frame (default) or in frame ``relative_to``.

        ``relative_to="universe"`` gives Pinocchio's ``oMf``.
        """
        q = self.to_pinocchio_q(q)
        fid = self._frame_id(frame)
        ref = self.base_id if relative_to is None else self._frame_id(relative_to)
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[ref].actInv(self.data.oMf[fid])

    def frame_jacobian(
        self, q: np.ndarray, frame: str | None = None, reference: str | pin.ReferenceFrame = "local_world_aligned"
    ) -> np.ndarray:
        """The 6 x 4 Jacobian of a frame (default: the tool), rows (v, omega), as Pinocchio defines it.

        Args:
            q: joint values.
            frame: frame name; the tool frame by default.
            reference: ``"world"``, ``"local"`` or ``"local_world_aligned"`` (or a pin.ReferenceFrame).
        """
        q = self.to_pinocchio_q(q)
        fid = self.tool_id if frame is None else self._frame_id(frame)
        if isinstance(reference, str):
            if reference.lower() not in _REFERENCES:
                raise InvalidInputError(f"reference {reference!r} must be one of {', '.join(_REFERENCES)}")
            reference = _REFERENCES[reference.lower()]
        return pin.computeFrameJacobian(self.model, self.data, q, fid, reference)

    def manipulability(self, q: np.ndarray) -> float:
        """Yoshikawa's manipulability sqrt(det(J J^T)) of the task Jacobian (= |det J| for 4 x 4).

        Without a wrist (3 joints) the task is (x, y, z): the 3 x 3 Jacobian of the tool position.
        """
        return float(abs(np.linalg.det(self.task_jacobian(q)[: self.dof])))

    def _frame_id(self, frame: str) -> int:
        if not self.model.existFrame(frame):
            names = ", ".join(f.name for f in self.model.frames)
            raise InvalidInputError(f"no frame named {frame!r}; frames: {names}")
        return int(self.model.getFrameId(frame))


def _urdf_kind(robot: RobotModel) -> str:
    """``"palletizer"`` for a palletizer's layout whose flange stays level, else ``"scara"``.

    The layout (:func:`scara_pin.chain.palletizer_layout`): a vertical waist, two parallel horizontal arm
    joints, a vertical flange. Level: the tool's z axis keeps its direction at
    :data:`~scara_pin.chain.LEVEL_PROBES` (the levelling parallelogram, modelled by ``<mimic>`` joints). Both
    are read from the geometry, whatever the order of the joints and their zero pose; the palletizer's
    geometry is then read the same way (:mod:`scara_pin.kinematics.palletizer_model`), which says where a
    model departs from its closed form.
    """
    from .chain import AXIS_TOL, LEVEL_PROBES, flange_pitch, palletizer_layout

    if robot.dof != 4 or not palletizer_layout(robot.axes):
        return "scara"
    level = all(flange_pitch(robot.tool_placement, q) <= AXIS_TOL for q in LEVEL_PROBES)
    return "palletizer" if level else "scara"


_ROBOT_TOOL_PLACEMENT = RobotModel.tool_placement
_ROBOT_TASK_JACOBIAN = RobotModel.task_jacobian


def _per_call_paths(robot: RobotModel) -> tuple[Callable[[np.ndarray], pin.SE3], Callable[[np.ndarray], np.ndarray]]:
    """The robot's ``tool_placement`` and ``task_jacobian``, as closures over its model.

    These are the per-call hot paths (a controller calls them at kHz): closures read their model, data and
    frame from cells, where a method pays an attribute lookup on the robot for each, and more once the
    robot's ``__dict__`` has grown (any cached property does that). Each takes q as it is when
    :func:`_q_ok`'s test passes (written inline: a call of it would cost a fifth of FK), else converts it
    with ``robot._pin_q`` (which checks it and raises ParameterError).
    """
    model, data, tool, full = robot._base_model, robot._base_data, robot.tool_id, robot._pin_q
    forward, placement, jacobian, lwa, rows, f64, bound = _forward, _frame_placement, _frame_jacobian, _LWA, \
        _TASK_ROWS, _F64, _Q_MAX2  # fmt: skip

    if robot._slow_q:  # continuous joints (Pinocchio's q differs) or three joints: every q is converted

        def tool_placement(q: np.ndarray) -> pin.SE3:
            """``baseMtool``: the placement of the tool frame in the base frame at ``q`` (``robot.data`` untouched)."""
            forward(model, data, full(q))
            return placement(model, data, tool)

        def task_jacobian(q: np.ndarray) -> np.ndarray:
            """The 4 x 4 Jacobian d(x, y, z, yaw)/dq of the tool pose in the base frame (rows x, y, z, yaw rate)."""
            return jacobian(model, data, full(q), tool, lwa).take(rows, 0)

        return tool_placement, task_jacobian

    def fast_tool_placement(q: np.ndarray) -> pin.SE3:
        """``baseMtool``: the placement of the tool frame in the base frame at ``q`` (``robot.data`` untouched)."""
        try:
            if q.size == 4:  # (an array of many q by mistake is not converted to a list)
                a, b, c, d = q.tolist()
                if a * a + b * b + c * c + d * d <= bound and q.dtype is f64:  # NaN and inf fail
                    forward(model, data, q)
                    return placement(model, data, tool)
        except (AttributeError, TypeError, ValueError):  # not an array, a wrong length, nested values
            pass
        forward(model, data, full(q))  # checked and converted (ParameterError)
        return placement(model, data, tool)

    def fast_task_jacobian(q: np.ndarray) -> np.ndarray:
        """The 4 x 4 Jacobian d(x, y, z, yaw)/dq of the tool pose in the base frame (rows x, y, z, yaw rate)."""
        try:
            if q.size == 4:
                a, b, c, d = q.tolist()
                if a * a + b * b + c * c + d * d <= bound and q.dtype is f64:  # as fast_tool_placement's
                    return jacobian(model, data, q, tool, lwa).take(rows, 0)
        except (AttributeError, TypeError, ValueError):
            pass
        return jacobian(model, data, full(q), tool, lwa).take(rows, 0)

    return fast_tool_placement, fast_task_jacobian


def _q_ok(q: Any) -> bool:
    """True when ``q`` is obviously valid: a 1-D float64 ndarray of 4 values, sum of squares <= _Q_MAX2.

    False only means "run the full check" (``Robot.check_q``); it never lets a bad ``q`` through (NaN and
    inf fail the comparison; a wrong length fails the unpacking).
    """
    if type(q) is np.ndarray and q.dtype is _F64 and q.ndim == 1:  # _F64: native byte order
        try:
            a, b, c, d = q.tolist()
        except (ValueError, TypeError):
            return False
        return a * a + b * b + c * c + d * d <= _Q_MAX2
    return False
