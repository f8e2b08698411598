"""A job's frames: named placements in the cell that carry pose points and pallets (Epson SPEL+'s ``Local``).

A SCARA's poses are (x, y, z, yaw): a frame is a translation ``xyz`` and a turn ``yaw`` about the vertical,
placed in its ``parent`` frame (another frame of the job, or ``world``). Two frames are built in:

- ``world``: the cell's frame. The cell file's obstacles are in it, and so is a pose point that names no frame;
- ``base``: the robot's base frame, placed in ``world`` by the job's ``base: {xyz, yaw}`` (by default the
  same as ``world``: a job without ``base:`` is in the robot's base frame, as before). Joint points are the
  robot's own configurations: they move with it.

A pose ``(p, yaw)`` in frame F is ``(R(yaw_F) p + xyz_F, yaw + yaw_F)`` in F's parent, up to ``world``; the
robot plans in its base frame: ``baseMworld`` applied to every pose point and obstacle. Moving a frame moves
every point in it (and the pallets taught by them); moving ``base`` re-plans the same job and cell with the
robot elsewhere.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError

__all__ = ["BASE", "WORLD", "Frame", "FrameTree"]

WORLD = "world"
"""The cell's frame (the cell file's obstacles, and pose points of no frame)."""
BASE = "base"
"""The robot's base frame, placed in ``world`` by the job's ``base:``."""


@dataclass(frozen=True)
class Frame:
    """A frame of a job: placed in ``parent`` by ``xyz`` [m] and ``yaw`` [rad] about the vertical.

    Attributes:
        xyz: the frame's origin in its parent [m].
        yaw: its turn about the parent's z axis [rad].
        parent: ``world`` or another frame of the job.
    """

    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    parent: str = WORLD

    def __post_init__(self) -> None:
        xyz = tuple(float(v) for v in self.xyz)
        if len(xyz) != 3 or not all(math.isfinite(v) for v in (*xyz, float(self.yaw))):
            raise InvalidInputError(f"a frame is 3 finite lengths xyz [m] and a finite yaw [rad], got {self.xyz!r}, "
                                    f"{self.yaw!r}")  # fmt: skip
        object.__setattr__(self, "xyz", xyz)
        object.__setattr__(self, "yaw", float(self.yaw))

    def apply(self, pose: np.ndarray) -> np.ndarray:
        """A pose (x, y, z, yaw) in this frame, in its parent."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        x, y, z, yaw = (float(v) for v in pose)
        return np.array([c * x - s * y + self.xyz[0], s * x + c * y + self.xyz[1], z + self.xyz[2], yaw + self.yaw])

    def inverse_apply(self, pose: np.ndarray) -> np.ndarray:
        """A pose (x, y, z, yaw) in this frame's parent, in this frame."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        x, y, z = (float(pose[i]) - self.xyz[i] for i in range(3))
        return np.array([c * x + s * y, -s * x + c * y, z, float(pose[3]) - self.yaw])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI)."""
        return {"xyz": list(self.xyz), "yaw": self.yaw, "parent": self.parent}


@dataclass(frozen=True)
class FrameTree:
    """A job's frames and the robot's base placement: poses from any frame to the robot's base frame.

    Attributes:
        frames: the job's frames by name (``world`` and ``base`` are not among them).
        base: the robot's base frame in ``world`` (``parent`` is ``world``).
    """

    frames: Mapping[str, Frame]
    base: Frame = Frame()

    def __post_init__(self) -> None:
        for name, frame in self.frames.items():
            if name in (WORLD, BASE):
                raise InvalidInputError(f"frame {name} is built in: name the job's frames otherwise")
            seen = [name]
            parent = frame.parent
            while parent != WORLD:
                if parent == BASE:
                    break
                if parent not in self.frames:
                    raise InvalidInputError(f"frame {name}: parent {parent!r} is no frame (frames: "
                                            f"{', '.join([WORLD, BASE, *self.frames])})")  # fmt: skip
                if parent in seen:
                    raise InvalidInputError(f"frames {' -> '.join([*seen, parent])}: a frame cannot be its own "
                                            "ancestor")  # fmt: skip
                seen.append(parent)
                parent = self.frames[parent].parent
        if self.base.parent != WORLD:
            raise InvalidInputError("base: the robot's base is placed in world")

    @property
    def moved(self) -> bool:
        """Whether the robot's base is elsewhere than the world frame."""
        return self.base != Frame()

    def in_world(self, pose: np.ndarray, frame: str = "") -> np.ndarray:
        """A pose (x, y, z, yaw) of ``frame`` ("" or ``world``: the world itself) in ``world``."""
        out = np.asarray(pose, dtype=float)
        name = frame or WORLD
        while name != WORLD:
            if name == BASE:
                return self.base.apply(out)
            f = self.frames.get(name)
            if f is None:
                raise InvalidInputError(f"frame {name!r} is not a frame of the job (frames: "
                                        f"{', '.join([WORLD, BASE, *self.frames])})")  # fmt: skip
            out = f.apply(out)
            name = f.parent
        return out

    def in_base(self, pose: np.ndarray, frame: str = "") -> np.ndarray:
        """A pose (x, y, z, yaw) of ``frame`` in the robot's base frame (what the robot plans in)."""
        if (frame or WORLD) == BASE:
            return np.asarray(pose, dtype=float)
        return self.base.inverse_apply(self.in_world(pose, frame))

    def base_M_world(self) -> pin.SE3:
        """``baseMworld``: the world's placement in the robot's base frame (moves the cell's obstacles)."""
        c, s = math.cos(self.base.yaw), math.sin(self.base.yaw)
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return pin.SE3(R, np.array(self.base.xyz)).inverse()
