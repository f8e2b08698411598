"""A job's data: the taught points, pallets, steps and settings a job file holds, checked (docs/job.md).

:mod:`~scara_pin.job.loading` reads a file into a :class:`JobSpec`; :mod:`~scara_pin.job.planning` plans one;
:class:`~scara_pin.job.job.Job`, above both, is the one users hold (``Job.load(path).plan(robot)``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import JobFileError, ScaraError
from ..motion.payload import Payload
from ..summary import Summarized
from ..units import SI, DisplayUnits
from .frames import FrameTree
from .steps import JumpShape, Program, Step, Target, expand, located

if TYPE_CHECKING:
    from ..cell import Shape
    from ..model import RobotModel
    from ..motion.points import PointSet, PosePoint
    from .overrides import Override
    from .pallets import Pallet

__all__ = ["Carry", "JobSpec"]


@dataclass(frozen=True)
class Carry:
    """The part the tool holds between a ``pick`` and a ``place``, in the tool frame (docs/job.md).

    ``tool0``'s z axis points out of the flange (down): a box hanging under the flange has a positive z. By
    default the box's top face is on the flange face (``xyz = (0, 0, size_z / 2)``); a gripper between them
    is not modelled, and its height is the part's z beyond that (the flange must stay the margin away from
    the box it has just left).

    Attributes:
        shape: ``"box"``.
        size: [m] its edges along the tool frame's x, y, z.
        xyz: [m] its centre in the tool frame.
        rpy: [rad] its orientation in the tool frame (URDF's roll, pitch, yaw).
    """

    shape: str
    size: tuple[float, float, float]
    xyz: tuple[float, float, float] | None = None
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if self.xyz is None:
            object.__setattr__(self, "xyz", (0.0, 0.0, self.size[2] / 2.0))

    def part(self) -> Shape:
        """The part as a cell's shape, placed in the tool frame (:class:`~scara_pin.cell.Shape`)."""
        from ..cell import Shape

        return Shape(self.shape, self.size, np.array(self.xyz, dtype=float), np.array(self.rpy, dtype=float),
                     what="the carried part")  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI)."""
        return {"shape": self.shape, "size": list(self.size), "xyz": list(self.xyz or ()), "rpy": list(self.rpy)}


@dataclass(frozen=True, eq=False, kw_only=True, repr=False)
class JobSpec(Summarized):
    """A job's data: taught points, pallets and steps, checked (:mod:`~scara_pin.job.loading` reads one).

    Attributes:
        path: the job file.
        points_file: the points file (resolved relative to the job file), or None (pose points written in the job).
        points: the taught points: joint points, and pose points (the points file's and the job's ``poses:``).
        pallets: the pallets by name.
        steps: the steps.
        robot: the robot's name the job is for, or None.
        start: where the robot is when the job begins, or None (the first move's target).
        jump: every jump's clearance unless a step overrides it.
        torque: respect the effort limits too.
        payload: the payload carried (for the torques).
        cell: the cell file (obstacles), or None.
        carry: what the tool carries, or None.
        actions: the number of moves and dwells the steps expand to.
        dwell: [s] the time of all its dwells: a lower bound of its total, known before any planning.
        lines: the line of each top-level key, and of each pallet (``"pallets.NAME"``).
        frames: the job's frames and the robot's base placement in the cell (:mod:`~scara_pin.job.frames`).
        speed, accel: the job's override: every move's velocity (acceleration) limits times this too, in (0, 1].
        jerk: the joint jerk limits as written (one, or one per joint), in :attr:`units` per joint kind, or None.
        units: the file's lengths and angles (``units:``).
        text: the job file's text (a variant re-reads it, never the file: :meth:`~scara_pin.job.job.Job.replace`).
        overrides: the values replaced at dotted keys before the checks (:mod:`~scara_pin.job.overrides`).
    """

    path: Path
    points_file: Path | None
    points: PointSet
    pallets: Mapping[str, Pallet]
    steps: tuple[Step, ...]
    robot: str | None = None
    start: Target | None = None
    jump: JumpShape = field(default_factory=JumpShape)
    torque: bool = False
    payload: Payload = field(default_factory=Payload)
    cell: Path | None = None
    carry: Carry | None = None
    actions: int = 0
    dwell: float = 0.0
    lines: Mapping[str, int | None] = field(default_factory=dict)
    frames: FrameTree = field(default_factory=lambda: FrameTree({}))
    speed: float = 1.0
    accel: float = 1.0
    jerk: tuple[float, ...] | None = None
    units: DisplayUnits = SI
    text: str = ""
    overrides: tuple[Override, ...] = ()

    def summary(self, units: DisplayUnits | None = None) -> str:
        """A few lines: the file, its robot, points, frames, pallets, steps and options (``repr``)."""
        poses = sum(1 for p in self.points if not hasattr(p, "q"))
        places = sum(p.places for p in self.pallets.values())
        lines = [f"Job {self.path}: robot {self.robot or '(any)'}, {len(self.points)} point(s) ({poses} pose "
                 f"point(s)), {len(self.pallets)} pallet(s) of {places} place(s), {self.actions} moves and dwells"]
        if self.frames.frames or self.frames.moved:
            lines.append(f"  frames {', '.join(self.frames.frames) or 'none'}; base "
                         f"{'placed' if self.frames.moved else 'at the world origin'}")  # fmt: skip
        options = [f"speed {100 * self.speed:g} %" if self.speed != 1.0 else "",
                   f"accel {100 * self.accel:g} %" if self.accel != 1.0 else "",
                   f"jerk {', '.join(f'{v:g}' for v in self.jerk)}" if self.jerk else "",
                   f"cell {self.cell.name}" if self.cell is not None else "", "carry" if self.carry else "",
                   f"{len(self.overrides)} override(s): {', '.join(o.key for o in self.overrides)}"
                   if self.overrides else ""]  # fmt: skip
        if any(options):
            lines.append("  " + "; ".join(o for o in options if o))
        return "\n".join(lines)

    def jerk_limits(self, robot: RobotModel) -> tuple[float, ...] | None:
        """The joint jerk limits of the job on ``robot`` [rad/s^3, m/s^3] (one per joint), or None."""
        if self.jerk is None:
            return None
        values = self.jerk * robot.dof if len(self.jerk) == 1 else self.jerk
        if len(values) != robot.dof:
            raise JobFileError(self.path, self.lines.get("jerk"), f"jerk gives {len(values)} limits; robot "
                               f"{robot.name!r} has {robot.dof} joints")  # fmt: skip
        return tuple(v / self.units.scale(kind) for v, kind in zip(values, robot.joint_kinds))

    def pose_in_base(self, point: PosePoint) -> np.ndarray:
        """A pose point's pose (x, y, z, yaw) in the robot's base frame: through its frame and the base placement."""
        return self.frames.in_base(point.pose, point.frame)

    def program(self, robot: RobotModel) -> Program:
        """The job for ``robot``, expanded (:func:`~scara_pin.job.steps.expand`), every target resolved.

        Raises:
            JobFileError: another robot, points that do not fit it, collinear corners (exit 2).
            JobStepError: a place out of reach (exit 3).
        """
        if self.robot is not None and self.robot != robot.name:
            raise JobFileError(self.path, self.lines.get("robot"), f"the job is for robot {self.robot!r}; this is "
                               f"{robot.name!r}")  # fmt: skip
        origin = f"points file {self.points_file}" if self.points_file is not None else "poses"
        try:
            self.points.check(robot, origin)
            points = self.points.resolved(robot, self.pose_in_base, origin)  # pose points: their IK, in base
        except ScaraError as exc:
            raise located(self.path, self.lines.get("points", self.lines.get("poses")), exc) from None
        return expand(self.steps, robot=robot, points=points, pallets=self.pallets, start=self.start,
                      shape=self.jump, path=self.path, start_line=self.lines.get("start"),
                      pallet_lines={k[8:]: v for k, v in self.lines.items() if k.startswith("pallets.")},
                      speed=self.speed, accel=self.accel)  # fmt: skip
