"""The error model of a serial chain: what may be wrong with a robot's description, and its effect on a measurement.

The chain runs from the robot's ``base`` frame through its moving joints to the tool frame (the measured
target). Its candidate errors, in the order the identification keeps them when two cannot be separated
(:mod:`scara_pin.calibration.identify`):

- ``device`` (with :attr:`MeasurementFrame.DEVICE` only): the placement of the base in the measuring
  device's frame, 3 translations [m] and 3 rotations [rad] (``device.x`` .. ``device.rz``);
- ``offsets``: each revolute joint's zero offset [rad] (``jointN.offset``: the true angle is the reading
  plus the offset);
- ``origins``: each moving joint's origin placement (the URDF ``<origin>``): 3 translations [m] added to
  its ``xyz`` (``jointN.x``, ``.y``, ``.z``, in the parent link's frame, as ``xyz`` is written) and the
  rotations [rad] about the axes of the joint frame other than the joint's own axis (the tilts,
  ``jointN.rx``, ``.ry``, ...; a prismatic joint also turns about its own axis, ``jointN.rz``);
- ``tool``: the tool frame's fixed joint (the measured target on the flange): 3 translations (its ``xyz``)
  and 3 rotations;
- ``scale``: each prismatic joint's relative scale error [1] (``jointN.scale``: the true stroke is
  ``(1 + scale)`` times the reading), last: fitted only when the poses separate it from every other error
  (a quill that never moves leaves it fixed, a height error being the likelier).

Each moving joint's origin thus gets a full placement error (6 numbers, the joint zero offset being the
rotation about its own axis): a complete, POE-style parameterisation of a serial chain, made minimal by the
identification, which keeps the combinations the measurements separate. A rotation error ``w`` of an
origin multiplies its nominal rotation on the right, ``R = R0 exp(B w)`` (``B``: the basis of the joint
frame listed above), so that the calibrated ``<origin>`` is ``xyz + dp`` and the ``rpy`` of ``R``: the
calibrated URDF carries every error except the prismatic scale (URDF has no joint scale).

The prediction of a measurement is Pinocchio's forward kinematics on a copy of the model whose joint
placements (and tool frame) carry the errors; its Jacobian with respect to every error is analytic: a
translation ``dp`` of an origin moves the tool by ``R_parent dp``; a rotation ``dphi`` (world axes) of an
origin at ``c`` moves it by ``dphi x (p - c)`` and turns it by ``dphi``, with ``dphi = R_origin Jr(B w) B dw``
(``Jr``: the right Jacobian of SO(3), Pinocchio's ``Jexp3``); a prismatic scale moves it by the joint's
axis times the reading. The yaw ``atan2(R[1, 0], R[0, 0])`` of the tool's x axis ``x`` turns by
``(-x0 x2, -x1 x2, x0^2 + x1^2) . dphi / (x0^2 + x1^2)``.
"""

from __future__ import annotations

import enum
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError
from ..model import RobotModel

__all__ = [
    "ALL_GROUPS",
    "ChainModel",
    "ErrorParameter",
    "Group",
    "MeasurementFrame",
    "Origin",
    "ParameterKind",
    "kabsch",
    "read_triple",
    "rotation_basis",
]


class Group(enum.Enum):
    """A family of candidate errors (``--model`` names them)."""

    DEVICE = "device"
    OFFSETS = "offsets"
    SCALE = "scale"
    ORIGINS = "origins"
    TOOL = "tool"


ALL_GROUPS: frozenset[Group] = frozenset({Group.OFFSETS, Group.SCALE, Group.ORIGINS, Group.TOOL})
"""The error groups fitted by default (``device`` follows from the measurement frame)."""


class MeasurementFrame(enum.Enum):
    """The frame the measured positions are expressed in."""

    BASE = "base"
    """The robot's ``base`` frame (the controller's coordinates)."""
    DEVICE = "device"
    """The measuring device's own frame: its placement relative to the base is identified too."""


class ParameterKind(enum.Enum):
    """What one error parameter is."""

    TRANSLATION = "translation"
    ROTATION = "rotation"
    SCALE = "scale"


_UNITS = {ParameterKind.TRANSLATION: "m", ParameterKind.ROTATION: "rad", ParameterKind.SCALE: "1"}


@dataclass(frozen=True)
class ErrorParameter:
    """One candidate error.

    Attributes:
        name: e.g. ``"joint2.x"``, ``"joint1.offset"``, ``"joint3.scale"``, ``"tool0.y"``, ``"device.rz"``.
        group: its family.
        element: the URDF joint whose ``<origin>`` it changes (``"device"`` for the device placement).
        kind: translation, rotation or scale.
        component: 0, 1, 2: which translation (in the parent link's frame) or which rotation (in the
            element's rotation basis); 0 for a scale.
    """

    name: str
    group: Group
    element: str
    kind: ParameterKind
    component: int

    @property
    def unit(self) -> str:
        """``"m"``, ``"rad"`` or ``"1"``."""
        return _UNITS[self.kind]


@dataclass(frozen=True, eq=False, kw_only=True)
class Origin:
    """A URDF joint whose ``<origin>`` carries errors: a moving joint of the chain, or the tool's fixed joint.

    Attributes:
        name: the URDF joint's name.
        label: the parameters' prefix: the joint's name, or the tool frame's for the tool's fixed joint.
        joint: the Pinocchio joint whose placement it is (a moving joint), or the tool frame's parent joint.
        frame: the Pinocchio frame id of the tool (its fixed joint), else -1.
        pre: the placement of the URDF joint's parent link in the frame of Pinocchio's parent joint (the
            fixed joints Pinocchio merged), so that the Pinocchio placement is ``pre * origin``.
        xyz: the nominal ``<origin xyz>`` [m]. R0: its nominal rotation (of ``rpy``).
        rpy: the nominal ``<origin rpy>`` [rad] as read.
        basis: columns: the axes [in the joint frame] of the 3 rotation errors.
        axis: the joint's unit axis in its own frame (zero for the tool).
        prismatic: whether the joint is prismatic.
    """

    name: str
    label: str
    joint: int
    frame: int
    pre: pin.SE3
    xyz: np.ndarray
    R0: np.ndarray
    rpy: np.ndarray
    basis: np.ndarray
    axis: np.ndarray
    prismatic: bool

    @classmethod
    def read(cls, el: ET.Element, placement: pin.SE3, **fields: object) -> Origin:
        """The origin of the URDF joint ``el`` whose Pinocchio placement is ``placement``; ``fields``: the others."""
        xyz, rpy = read_triple(el.find("origin"), "xyz"), read_triple(el.find("origin"), "rpy")
        R0 = pin.rpy.rpyToMatrix(*rpy)
        return cls(xyz=xyz, rpy=rpy, R0=R0, pre=placement * pin.SE3(R0, xyz).inverse(), **fields)  # type: ignore[arg-type]

    def placement(self, dp: np.ndarray, w: np.ndarray) -> pin.SE3:
        """The origin with errors: ``(R0 exp(B w), xyz + dp)``."""
        return pin.SE3(self.R0 @ pin.exp3(self.basis @ w), self.xyz + dp)


_AXIS_LETTERS = "xyz"


def rotation_basis(axis: np.ndarray) -> tuple[np.ndarray, tuple[str, str, str]]:
    """An orthonormal basis whose last column is ``axis`` (a unit vector), and the rotations' suffixes.

    For an axis along a coordinate axis (+ or -), the other two columns are the other coordinate axes (in
    cyclic order) and the suffixes are ``rx``, ``ry``, ``rz`` as they apply; else ``ru``, ``rv``, ``ra``.
    """
    k = int(np.argmax(np.abs(axis)))
    if abs(abs(axis[k]) - 1.0) <= 1e-12:
        i, j = (k + 1) % 3, (k + 2) % 3
        B = np.zeros((3, 3))
        B[i, 0] = B[j, 1] = 1.0
        B[:, 2] = axis
        return B, (f"r{_AXIS_LETTERS[i]}", f"r{_AXIS_LETTERS[j]}", f"r{_AXIS_LETTERS[k]}")
    helper = np.eye(3)[int(np.argmin(np.abs(axis)))]
    u = np.cross(helper, axis)
    u /= np.linalg.norm(u)
    return np.column_stack([u, np.cross(axis, u), axis]), ("ru", "rv", "ra")


def read_triple(el: ET.Element | None, attr: str) -> np.ndarray:
    """A URDF ``xyz`` / ``rpy`` attribute (absent: zeros); the loader has parsed the file already."""
    text = el.get(attr) if el is not None else None
    if text is None:
        return np.zeros(3)
    values = np.array([float(v) for v in text.split()])
    if values.shape != (3,) or not np.isfinite(values).all():  # (the loader accepted it: never seen)
        raise InvalidInputError(f"joint origin {attr}={text!r} is not 3 finite numbers")
    return values


def kabsch(a: np.ndarray, b: np.ndarray) -> pin.SE3:
    """The rigid placement ``M`` minimising ``sum |M a_i - b_i|^2`` (Kabsch / Umeyama without scale).

    Args:
        a: (n, 3) points [m], n >= 3 not all on one line for a unique answer.
        b: (n, 3) their images [m].
    """
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    H = (a - ca).T @ (b - cb)
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    R = Vt.T @ np.diag([1.0, 1.0, d]) @ U.T
    return pin.SE3(R, cb - R @ ca)


def _skew_rows(v: np.ndarray) -> np.ndarray:
    """(n, 3, 3) skew matrices [v]x of (n, 3) vectors."""
    out = np.zeros((len(v), 3, 3))
    out[:, 0, 1], out[:, 0, 2] = -v[:, 2], v[:, 1]
    out[:, 1, 0], out[:, 1, 2] = v[:, 2], -v[:, 0]
    out[:, 2, 0], out[:, 2, 1] = -v[:, 1], v[:, 0]
    return out


@dataclass(frozen=True, eq=False, kw_only=True)
class ChainModel:
    """The candidate errors of a robot's chain, its predictions and their analytic Jacobian.

    Build it with :meth:`from_robot`. Parameter vectors hold one value per :attr:`parameters` entry, 0 at
    the nominal description.

    Attributes:
        robot: the nominal robot.
        frame: the measurement frame.
        yaw: whether measurements include the tool's yaw.
        groups: the error groups fitted.
        origins: the URDF joints carrying errors, chain order, the tool's fixed joint last (if any).
        parameters: the candidate errors, in the order the identification prefers them.
        notes: what the model leaves out and why (e.g. a tool frame with no fixed joint to carry its offset).
    """

    robot: RobotModel
    frame: MeasurementFrame
    yaw: bool
    groups: frozenset[Group]
    origins: tuple[Origin, ...]
    parameters: tuple[ErrorParameter, ...]
    notes: tuple[str, ...]
    _slots: dict[str, tuple[int, ...]] = field(repr=False)
    _bMo: pin.SE3 = field(repr=False)
    _scaled: tuple[tuple[int, int], ...] = field(repr=False)

    # ------------------------------------------------------------------------------ construction
    @classmethod
    def from_robot(
        cls,
        robot: RobotModel,
        *,
        frame: MeasurementFrame = MeasurementFrame.BASE,
        yaw: bool = False,
        groups: Iterable[Group] = ALL_GROUPS,
    ) -> ChainModel:
        """The error model of ``robot``'s chain from its ``base`` frame to its tool frame.

        Raises:
            InvalidInputError: a robot with mimic joints (the palletizer's parallelograms: not a serial chain
                of independent joints), a base frame carried by a moving joint, a joint of q that does not
                carry the tool.
        """
        model = robot.model
        groups = frozenset(groups) - {Group.DEVICE}
        if frame is MeasurementFrame.DEVICE:
            groups |= {Group.DEVICE}
        if any(model.joints[j].nv == 0 for j in range(1, model.njoints)) or robot.kind == "palletizer":
            raise InvalidInputError(
                f"robot {robot.name!r} has mimic joints (a palletizer's parallelograms): calibration identifies "
                "serial chains of independent joints (SCARA, 3 or 4 joints) only"
            )
        if model.frames[robot.base_id].parentJoint != 0:
            raise InvalidInputError(f"the base frame {robot.base_frame!r} moves with a joint: measurements need a "
                                    "fixed frame")  # fmt: skip
        tool_joint = model.frames[robot.tool_id].parentJoint
        chain = [int(j) for j in model.supports[tool_joint] if j != 0]
        missing = [model.names[j] for j in range(1, model.njoints) if j not in chain]
        if missing:
            raise InvalidInputError(f"joint(s) {', '.join(missing)} do not carry the tool frame {robot.tool_frame!r}: "
                                    "calibration needs one serial chain from the base to the tool")  # fmt: skip
        root = ET.fromstring(robot.urdf)
        urdf_joints = {el.get("name", ""): el for el in root.findall("joint")}
        origins: list[Origin] = []
        for j in chain:
            el = urdf_joints[model.names[j]]
            axis_el = el.find("axis")
            axis = read_triple(axis_el, "xyz") if axis_el is not None else np.array([1.0, 0.0, 0.0])
            axis = axis / np.linalg.norm(axis)
            prismatic = el.get("type") == "prismatic"
            origins.append(Origin.read(el, model.jointPlacements[j], name=model.names[j], label=model.names[j], joint=j,
                                       frame=-1, basis=np.eye(3) if prismatic else rotation_basis(axis)[0], axis=axis,
                                       prismatic=prismatic))  # fmt: skip
        notes: list[str] = []
        children = {(c.get("link") if (c := el.find("child")) is not None else None): el for el in urdf_joints.values()}
        tool_el = children.get(robot.tool_frame)
        if tool_el is not None and tool_el.get("type") == "fixed":
            origins.append(Origin.read(tool_el, model.frames[robot.tool_id].placement, name=tool_el.get("name", ""),
                                       label=robot.tool_frame, joint=tool_joint, frame=int(robot.tool_id),
                                       basis=np.eye(3), axis=np.zeros(3), prismatic=False))  # fmt: skip
        elif Group.TOOL in groups:
            notes.append(f"the tool frame {robot.tool_frame!r} is the child of a moving joint, with no fixed joint to "
                         "carry a tool offset: the tool group is left out (the target is that joint's frame origin)")
            groups -= {Group.TOOL}
        params, slots = _parameters(origins, groups)
        scaled = tuple((k, int(model.joints[o.joint].idx_q)) for k, o in enumerate(origins) if o.prismatic)
        pin.framesForwardKinematics(model, robot.data, pin.neutral(model))
        bMo = robot.data.oMf[robot.base_id].inverse()
        return cls(robot=robot, frame=frame, yaw=yaw, groups=groups, origins=tuple(origins), parameters=params,
                   notes=tuple(notes), _slots=slots, _bMo=bMo, _scaled=scaled)

    # ------------------------------------------------------------------------------ parameters
    @property
    def length(self) -> float:
        """[m] the chain's length: no tool point of the nominal chain is farther than this from the base.

        The rigid offsets from the base to each joint and to the tool, and the prismatic strokes, added up.
        """
        model = self.robot.model
        joints = [o.joint for o in self.origins if o.frame < 0]
        total = float(np.linalg.norm(self._bMo.act(model.jointPlacements[joints[0]].translation))) if joints else 0.0
        total += sum(float(np.linalg.norm(model.jointPlacements[j].translation)) for j in joints[1:])
        total += float(np.linalg.norm(model.frames[self.robot.tool_id].placement.translation))
        for o in self.origins:
            if o.prismatic:
                iq = int(model.joints[o.joint].idx_q)
                total += max(abs(float(model.lowerPositionLimit[iq])), abs(float(model.upperPositionLimit[iq])))
        return total

    @property
    def size(self) -> int:
        """The number of candidate errors."""
        return len(self.parameters)

    @property
    def rows_per_pose(self) -> int:
        """Equations per measured pose: 3 (x, y, z), 4 with the yaw."""
        return 4 if self.yaw else 3

    def names(self) -> tuple[str, ...]:
        """The parameters' names, in order."""
        return tuple(p.name for p in self.parameters)

    def _split(self, theta: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray], dict[int, float], np.ndarray]:
        """Per origin its (dp, w), per prismatic origin its scale error, and the device's 6 values."""
        dps, ws = [], []
        for o in self.origins:
            dp, w = np.zeros(3), np.zeros(3)
            for k, i in enumerate(self._slots.get(f"{o.name}.t", (-1, -1, -1))):
                if i >= 0:
                    dp[k] = theta[i]
            for k, i in enumerate(self._slots.get(f"{o.name}.r", (-1, -1, -1))):
                if i >= 0:
                    w[k] = theta[i]
            dps.append(dp)
            ws.append(w)
        scales = {k: float(theta[self._slots[f"{o.name}.s"][0]]) for k, o in enumerate(self.origins)
                  if f"{o.name}.s" in self._slots}  # fmt: skip
        device = np.array([theta[i] if i >= 0 else 0.0 for i in self._slots.get("device", (-1,) * 6)])
        return dps, ws, scales, device

    # ------------------------------------------------------------------------------ the model with errors
    def pinocchio_model(self, theta: np.ndarray) -> pin.Model:
        """A copy of the robot's Pinocchio model with the errors ``theta`` in its placements (not the scales)."""
        model = pin.Model(self.robot.model)
        dps, ws, _, _ = self._split(theta)
        for o, dp, w in zip(self.origins, dps, ws):
            M = o.pre * o.placement(dp, w)
            if o.frame < 0:
                model.jointPlacements[o.joint] = M
            else:
                f = model.frames[o.frame]
                f.placement = M
                model.frames[o.frame] = f
        return model

    def calibrated_origins(self, theta: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Per URDF joint carrying errors: its calibrated ``<origin>`` (xyz [m], rpy [rad])."""
        dps, ws, _, _ = self._split(theta)
        out = {}
        for o, dp, w in zip(self.origins, dps, ws):
            M = o.placement(dp, w)
            rpy = o.rpy.copy() if not w.any() else pin.rpy.matrixToRpy(M.rotation)
            out[o.name] = (M.translation.copy(), np.asarray(rpy, dtype=float))
        return out

    def scales(self, theta: np.ndarray) -> dict[str, float]:
        """Per prismatic joint of the chain: its scale ``1 + scale error`` (1 when the scale is not fitted)."""
        _, _, scales, _ = self._split(theta)
        return {o.name: 1.0 + scales.get(k, 0.0) for k, o in enumerate(self.origins) if o.prismatic}

    def device_placement(self, theta: np.ndarray, device0: pin.SE3) -> pin.SE3:
        """``deviceMbase``: the base's placement in the device frame (identity in the base frame)."""
        if self.frame is MeasurementFrame.BASE:
            return pin.SE3.Identity()
        _, _, _, d = self._split(theta)
        return pin.SE3(device0.rotation @ pin.exp3(d[3:]), device0.translation + d[:3])

    def pinocchio_q(self, readings: np.ndarray) -> np.ndarray:
        """(n, nq) Pinocchio configurations of the (n, dof) joint readings (continuous joints as cos, sin)."""
        return np.array([self.robot.to_pinocchio_q(q) for q in readings])

    # ------------------------------------------------------------------------------ predictions
    def predict(self, theta: np.ndarray, qpin: np.ndarray, device0: pin.SE3, *,
                jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:  # fmt: skip
        """The predicted measurements and their Jacobian with respect to ``theta``.

        Args:
            theta: the errors (one per parameter).
            qpin: (n, nq) Pinocchio configurations of the readings (:meth:`pinocchio_q`).
            device0: the nominal device placement ``deviceMbase`` (ignored in the base frame).
            jacobian: compute the Jacobian too.

        Returns:
            (n, 3) positions [m] in the measurement frame, with the yaw [rad] as a 4th column when measured;
            the (n * rows_per_pose, size) Jacobian (rows x, y, z[, yaw] per pose), or None.
        """
        model = self.pinocchio_model(theta)
        data = model.createData()
        dps, ws, scales, dev = self._split(theta)
        n = len(qpin)
        q = qpin.copy()
        for k, iq in self._scaled:
            q[:, iq] *= 1.0 + scales.get(k, 0.0)
        tool_joint = model.frames[self.robot.tool_id].parentJoint
        tool_frame = model.frames[self.robot.tool_id].placement
        no = len(self.origins)
        p = np.empty((n, 3))
        R = np.empty((n, 3, 3))
        Rpar = np.empty((no, n, 3, 3))
        Ror = np.empty((no, n, 3, 3))
        cor = np.empty((no, n, 3))
        axes = np.empty((no, n, 3))
        local = [(o.pre, o.placement(dp, w)) for o, dp, w in zip(self.origins, dps, ws)]
        parents = [int(model.parents[o.joint]) if o.frame < 0 else o.joint for o in self.origins]
        forward = pin.forwardKinematics
        for i in range(n):
            forward(model, data, q[i])
            oMt = data.oMi[tool_joint] * tool_frame
            p[i], R[i] = oMt.translation, oMt.rotation
            if not jacobian:
                continue
            for k, ((pre, M), par) in enumerate(zip(local, parents)):
                oMpar = data.oMi[par] * pre
                oMor = oMpar * M
                Rpar[k, i], Ror[k, i], cor[k, i] = oMpar.rotation, oMor.rotation, oMor.translation
                if self.origins[k].prismatic:
                    axes[k, i] = oMor.rotation @ self.origins[k].axis
        # world -> base -> measurement frame
        dMb = self.device_placement(theta, device0) if self.frame is MeasurementFrame.DEVICE else pin.SE3.Identity()
        dMo = dMb * self._bMo
        A = dMo.rotation
        pm = p @ A.T + dMo.translation
        Rm = A @ R
        out = pm
        if self.yaw:
            out = np.column_stack([pm, np.arctan2(Rm[:, 1, 0], Rm[:, 0, 0])])
        if not jacobian:
            return out, None
        rows = self.rows_per_pose
        J = np.zeros((n, rows, self.size))
        x = Rm[:, :, 0]
        den = x[:, 0] ** 2 + x[:, 1] ** 2
        gyaw = np.column_stack([-x[:, 0] * x[:, 2], -x[:, 1] * x[:, 2], den]) / den[:, None]  # d yaw / d phi (meas.)

        def put(cols: tuple[int, ...], dp_o: np.ndarray, dphi_o: np.ndarray | None) -> None:
            """Columns ``cols`` from world-frame motions (n, 3, c) of the tool point and rotations."""
            for c, i in enumerate(cols):
                if i < 0:
                    continue
                J[:, :3, i] = dp_o[:, :, c] @ A.T
                if self.yaw and dphi_o is not None:
                    J[:, 3, i] = np.einsum("nk,nk->n", gyaw, dphi_o[:, :, c] @ A.T)

        for k, (o, w) in enumerate(zip(self.origins, ws)):
            t_cols = self._slots.get(f"{o.name}.t")
            if t_cols is not None:
                put(t_cols, Rpar[k], None)
            r_cols = self._slots.get(f"{o.name}.r")
            if r_cols is not None:
                G = Ror[k] @ (pin.Jexp3(o.basis @ w) @ o.basis)  # (n, 3, 3): world rotation per unit error
                put(r_cols, -_skew_rows(p - cor[k]) @ G, G)
            s_cols = self._slots.get(f"{o.name}.s")
            if s_cols is not None:
                iq = dict(self._scaled)[k]
                move = (axes[k] * qpin[:, iq, None])[:, :, None]  # d p / d scale
                put(s_cols, move, np.zeros_like(move))
        dev_cols = self._slots.get("device")
        if dev_cols is not None:
            pb = p @ self._bMo.rotation.T + self._bMo.translation
            Jr = pin.Jexp3(dev[3:])
            Rd = dMb.rotation
            for c in range(3):
                if dev_cols[c] >= 0:
                    J[:, c, dev_cols[c]] = 1.0
            G = Rd @ Jr  # rotation per unit error, measurement axes
            dpr = -(Rd @ _skew_rows(pb)) @ Jr  # (n, 3, 3)
            for c in range(3):
                i = dev_cols[3 + c]
                if i < 0:
                    continue
                J[:, :3, i] = dpr[:, :, c]
                if self.yaw:
                    J[:, 3, i] = gyaw @ G[:, c]
        return out, J.reshape(n * rows, self.size)


def _parameters(
    origins: list[Origin], groups: frozenset[Group]
) -> tuple[tuple[ErrorParameter, ...], dict[str, tuple[int, ...]]]:
    """The candidate errors in preference order, and the index of each component's parameter per slot.

    Slots: ``name.t``, ``name.r``, ``name.s`` per origin, ``device``; -1: the component is not a parameter.
    """
    params: list[ErrorParameter] = []
    slots: dict[str, list[int]] = {}

    def add(slot: str, size: int, component: int, p: ErrorParameter) -> None:
        slots.setdefault(slot, [-1] * size)[component] = len(params)
        params.append(p)

    T, Rt, S = ParameterKind.TRANSLATION, ParameterKind.ROTATION, ParameterKind.SCALE
    if Group.DEVICE in groups:
        for c, s in enumerate(("x", "y", "z", "rx", "ry", "rz")):
            add("device", 6, c, ErrorParameter(f"device.{s}", Group.DEVICE, "device", T if c < 3 else Rt, c % 3))
    moving = [o for o in origins if o.frame < 0]
    tool = [o for o in origins if o.frame >= 0]
    if Group.OFFSETS in groups:
        for o in moving:
            if not o.prismatic:
                add(f"{o.name}.r", 3, 2, ErrorParameter(f"{o.label}.offset", Group.OFFSETS, o.name, Rt, 2))
    if Group.ORIGINS in groups:
        for o in moving:
            suffixes = ("rx", "ry", "rz") if o.prismatic else rotation_basis(o.axis)[1]
            for c in range(3):
                add(f"{o.name}.t", 3, c, ErrorParameter(f"{o.label}.{'xyz'[c]}", Group.ORIGINS, o.name, T, c))
            for c in range(3 if o.prismatic else 2):
                add(f"{o.name}.r", 3, c, ErrorParameter(f"{o.label}.{suffixes[c]}", Group.ORIGINS, o.name, Rt, c))
    if Group.TOOL in groups:
        for o in tool:
            for c in range(3):
                add(f"{o.name}.t", 3, c, ErrorParameter(f"{o.label}.{'xyz'[c]}", Group.TOOL, o.name, T, c))
            for c in range(3):
                add(f"{o.name}.r", 3, c, ErrorParameter(f"{o.label}.r{'xyz'[c]}", Group.TOOL, o.name, Rt, c))
    if Group.SCALE in groups:
        for o in moving:
            if o.prismatic:
                add(f"{o.name}.s", 1, 0, ErrorParameter(f"{o.label}.scale", Group.SCALE, o.name, S, 0))
    return tuple(params), {k: tuple(v) for k, v in slots.items()}
