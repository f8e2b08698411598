"""The robot as a tree of scene nodes (one per joint) and the framing of a scene on the robot's reach.

A joint's node holds the joint's transform relative to its parent's node, Pinocchio's ``liMi``:

    liMi(q) = jointPlacement * motion(axis, value),    value = multiplier * q[source] + offset

where ``motion`` is a rotation about ``axis`` by ``value`` [rad] (revolute) or a translation along ``axis``
by ``value`` [m] (prismatic), ``source`` the index in q of the joint value that drives it (its own, or the
mimicked joint's for a passive ``<mimic>`` joint). Geometries and frames hang under their joint's node with
their constant placements. A browser page moves the robot by applying each joint's own motion to its node:
no kinematics in JavaScript beyond that. :func:`joint_nodes` reads every one of these numbers from the
Pinocchio model (axis and kind from the model's own motion over a unit step of the joint).

No meshcat import here (see :mod:`scara_pin.viz.meshcat`).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = ["Framing", "JointNode", "framing", "joint_nodes", "node_paths"]


@dataclass(frozen=True)
class JointNode:
    """One joint of the scene tree.

    Attributes:
        name: the URDF joint name.
        path: its node's path under the robot's root node (``robot/joint1/joint2``).
        kind: ``"revolute"`` or ``"prismatic"``.
        axis: unit axis in the joint's frame.
        placement: ``jointPlacement`` (the joint frame in its parent joint's frame at value 0), 4x4 row-major.
        source: index in q of the value driving the joint.
        multiplier, offset: value = multiplier * q[source] + offset (1 and 0 for an actuated joint).
        actuated: whether the joint is one of q's (False for a mimic joint).
    """

    name: str
    path: str
    kind: str
    axis: tuple[float, float, float]
    placement: tuple[tuple[float, ...], ...]
    source: int
    multiplier: float
    offset: float
    actuated: bool

    def __post_init__(self) -> None:
        if self.kind not in ("revolute", "prismatic"):
            raise ValueError(f"joint {self.name}: kind {self.kind!r} must be 'revolute' or 'prismatic'")
        if abs(math.hypot(*self.axis) - 1.0) > 1e-9:
            raise ValueError(f"joint {self.name}: axis {self.axis} must be a unit vector")

    def transform(self, q: np.ndarray) -> pin.SE3:
        """``liMi`` at the user's joint values ``q`` (what the page computes for the node)."""
        value = self.multiplier * float(q[self.source]) + self.offset
        axis = np.array(self.axis)
        motion = (
            pin.SE3(pin.exp3(axis * value), np.zeros(3))
            if self.kind == "revolute"
            else pin.SE3(np.eye(3), axis * value)
        )
        return pin.SE3(np.array(self.placement)) * motion


def node_paths(robot: RobotModel, root: str) -> list[str]:
    """The scene path of every Pinocchio joint (index 0, the universe, is ``root``)."""
    model = robot.model
    paths = [root]
    for j in range(1, model.njoints):
        paths.append(f"{paths[model.parents[j]]}/{model.names[j]}")
    return paths


def joint_nodes(robot: RobotModel, root: str) -> tuple[JointNode, ...]:
    """The joints of ``robot`` as scene nodes, in Pinocchio's order (parents before children)."""
    model = robot.model
    data = model.createData()
    paths = node_paths(robot, root)
    # index in Pinocchio's q -> index in the user's q, for the actuated joints (nv = 1)
    actuated = [j for j in range(1, model.njoints) if model.joints[j].nv == 1]
    user_index = {model.joints[j].idx_q: i for i, j in enumerate(actuated)}
    geared = {g.name: g for g in robot.geared}  # read once, by the robot (scara_pin.chain)

    def li_mi(q: np.ndarray) -> list[pin.SE3]:
        pin.forwardKinematics(model, data, robot.to_pinocchio_q(q))
        return [data.liMi[j].copy() for j in range(model.njoints)]

    zero = li_mi(np.zeros(robot.dof))
    out = []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        if jm.nv == 1:
            source, multiplier, offset = user_index[jm.idx_q], 1.0, 0.0
        else:  # a geared (mimic) joint follows the joint that owns its configuration index
            g = geared[model.names[j]]
            source, multiplier, offset = g.source, g.multiplier, g.offset
        step = np.zeros(robot.dof)
        step[source] = 1.0
        # the joint's own motion over a unit step of its source: exp(axis * multiplier)
        motion = pin.log6(zero[j].actInv(li_mi(step)[j]))
        w, v = np.array(motion.angular), np.array(motion.linear)
        kind, vec = ("revolute", w) if np.linalg.norm(w) > 1e-9 else ("prismatic", v)
        axis = vec / multiplier
        axis = axis / np.linalg.norm(axis)
        placement = model.jointPlacements[j].homogeneous
        out.append(
            JointNode(
                name=model.names[j],
                path=paths[j],
                kind=kind,
                axis=(float(axis[0]), float(axis[1]), float(axis[2])),
                placement=tuple(tuple(float(x) for x in row) for row in placement),
                source=source,
                multiplier=multiplier,
                offset=offset,
                actuated=jm.nv == 1,
            )
        )
    return tuple(out)


@dataclass(frozen=True)
class Framing:
    """Where to look at a robot from, in the scene (universe) frame, z up [m].

    Attributes:
        low, high: corners of the box holding every frame of the robot over its joint ranges, and the floor.
        reach: the largest horizontal distance of a frame from the root's z axis.
        target: the point looked at (the box's centre).
        position: the camera's position (a 3/4 view from the front right, from above).
        grid_cell, grid_half: the floor grid's cell and half width (a 1, 2, 5 x 10^k cell).
    """

    low: tuple[float, float, float]
    high: tuple[float, float, float]
    reach: float
    target: tuple[float, float, float]
    position: tuple[float, float, float]
    grid_cell: float
    grid_half: float


FIELD_OF_VIEW = 45.0
"""The camera's vertical field of view [deg] (meshcat's default, 75, distorts a close robot)."""
_FILL = 1.0
"""The bounding sphere's share of the picture's height."""
_VIEW_DIRECTION = np.array([math.cos(math.radians(35)) * math.cos(math.radians(-55)),
                            math.cos(math.radians(35)) * math.sin(math.radians(-55)),
                            math.sin(math.radians(35))])  # fmt: skip
"""From the target to the camera: 35 degrees above the floor, 55 degrees to the right of the x axis."""


def _nice(value: float) -> float:
    """The 1, 2, 5 x 10^k number nearest above ``value``."""
    exponent = math.floor(math.log10(value))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10**exponent >= value * (1 - 1e-12):
            return m * 10**exponent
    return 10.0 ** (exponent + 1)  # pragma: no cover - the loop always returns


def framing(robot: RobotModel, samples: int = 5) -> Framing:
    """Frame the robot's whole workspace: the box of every frame's origin over a grid of joint values.

    ``samples`` values per joint over its range (a continuous joint: one turn), ``samples**4`` configurations.
    The camera distance fits the box's bounding sphere in the vertical field of view.
    """
    model = robot.model
    data = model.createData()
    ranges = [np.linspace(lo, hi, samples) for lo, hi in zip(robot.limits.lower, robot.limits.upper, strict=True)]
    points = [np.zeros(3)]
    for q in itertools.product(*ranges):
        pin.framesForwardKinematics(model, data, robot.to_pinocchio_q(np.array(q)))
        points.extend(np.array(f.translation) for f in data.oMf)
    cloud = np.array(points)
    low, high = cloud.min(axis=0), cloud.max(axis=0)
    low[2] = min(low[2], 0.0)  # the floor (z = 0 of the root link) is in the picture
    reach = max(0.05, float(np.max(np.hypot(cloud[:, 0], cloud[:, 1]))))
    size = max(float(np.linalg.norm(high - low)), 0.1)
    target = (low + high) / 2
    distance = _FILL * 0.5 * size / math.sin(math.radians(FIELD_OF_VIEW) / 2)
    position = target + distance * _VIEW_DIRECTION
    cell = _nice(reach / 4)
    half = cell * math.ceil(1.05 * reach / cell)

    def t3(v: np.ndarray) -> tuple[float, float, float]:
        return (float(v[0]), float(v[1]), float(v[2]))

    return Framing(t3(low), t3(high), reach, t3(target), t3(position), cell, half)
