"""Robot kinds behind one protocol, and loading a robot with the kinematics of its kind.

A :class:`~scara_pin.model.Robot` is the Pinocchio model (FK, frames, Jacobians); what it knows of inverse
kinematics is one object of the :class:`~scara_pin.model.Kinematics` protocol, built here from the loaded
model by its kind:

- :class:`ScaraKinematics`: the SCARA closed form (:mod:`scara_pin.kinematics.scara`), its plan-view
  workspace (:mod:`scara_pin.workspace.scara`);
- :class:`PalletizerKinematics`: the palletizer's (:mod:`scara_pin.kinematics.palletizer`), its arm-plane
  envelope (:mod:`scara_pin.workspace.palletizer`).

Both read their geometry from the model, so the URDF is the single source of truth.
"""

from __future__ import annotations

import enum
import functools
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .description import RobotParameters
from .errors import InvalidInputError
from .kinematics import palletizer, scara
from .model import Kinematics, Robot
from .workspace.palletizer import ArmPlaneEnvelope, arm_plane_envelope
from .workspace.scara import Workspace, workspace

if TYPE_CHECKING:
    import numpy as np

    from ._typing import ArrayLike
    from .kinematics.results import BatchIKResult, IKResult

__all__ = ["PalletizerKinematics", "ScaraKinematics", "kinematics_for", "load_robot", "load_urdf", "robot_from_urdf"]


class ScaraKinematics:
    """The SCARA's kinematics (see :mod:`scara_pin.kinematics.scara`).

    Attributes:
        geometry: the geometry read from the model.
    """

    kind: str = "scara"
    branches: tuple[str, ...] = scara.BRANCHES
    status: type[enum.IntEnum] = scara.IKStatus
    geometry: scara.ScaraGeometry

    def __init__(self, geometry: scara.ScaraGeometry) -> None:
        self.geometry = geometry
        # the per-call path: one call less (a partial is called like the method below)
        self.nearest = functools.partial(scara.solve_nearest, geometry)  # type: ignore[method-assign]

    @classmethod
    def from_robot(cls, robot: Robot) -> ScaraKinematics:
        """Read the geometry from the robot's model; NotScaraError names what is not SCARA-like."""
        return cls(scara.ScaraGeometry.from_robot(robot))

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve`."""
        return scara.solve(self.geometry, target, branch=branch, reference=reference, all_turns=all_turns)

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve_nearest`."""
        return scara.solve_nearest(self.geometry, target, reference, weights=weights, branch=branch)

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve_batch`."""
        return scara.solve_batch(self.geometry, targets, branch=branch, reference=reference)

    def branch_of(self, q: ArrayLike) -> str:
        """:func:`scara_pin.kinematics.scara.branch_of`."""
        return scara.branch_of(self.geometry, q)

    def workspace(self, **kwargs: Any) -> Workspace:
        """:func:`scara_pin.workspace.scara.workspace` (keyword arguments as there)."""
        return workspace(self.geometry, **kwargs)


class PalletizerKinematics:
    """The palletizer's kinematics (see :mod:`scara_pin.kinematics.palletizer`).

    Attributes:
        geometry: the geometry read from the model.
    """

    kind: str = "palletizer"
    branches: tuple[str, ...] = palletizer.BRANCHES
    status: type[enum.IntEnum] = palletizer.PalletizerIKStatus
    geometry: palletizer.PalletizerGeometry

    def __init__(self, geometry: palletizer.PalletizerGeometry) -> None:
        self.geometry = geometry

    @classmethod
    def from_robot(cls, robot: Robot) -> PalletizerKinematics:
        """Read the geometry from the robot's model; NotPalletizerError says where it departs."""
        return cls(palletizer.PalletizerGeometry.from_robot(robot))

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve`."""
        return palletizer.solve(self.geometry, target, branch=branch, reference=reference, all_turns=all_turns)

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve_nearest`."""
        return palletizer.solve_nearest(self.geometry, target, reference, weights=weights, branch=branch)

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve_batch`."""
        return palletizer.solve_batch(self.geometry, targets, branch=branch, reference=reference)

    def branch_of(self, q: ArrayLike) -> str:
        """:func:`scara_pin.kinematics.palletizer.branch_of`."""
        return palletizer.branch_of(q)

    def workspace(self) -> ArmPlaneEnvelope:
        """:func:`scara_pin.workspace.palletizer.arm_plane_envelope`."""
        return arm_plane_envelope(self.geometry)


def kinematics_for(robot: Robot) -> Kinematics:
    """The kinematics object of the robot's kind (``robot.kind``), read from its model."""
    if robot.kind == "palletizer":
        return PalletizerKinematics.from_robot(robot)
    if robot.kind == "scara":
        return ScaraKinematics.from_robot(robot)
    raise InvalidInputError(f"robot {robot.name!r} is of kind {robot.kind!r}: no kinematics for it")


def load_robot(
    robot: str | Path | RobotParameters = "default",
    overrides: Mapping[str, object] | None = None,
    *,
    urdf: str | Path | None = None,
    tool: str | None = None,
    base: str | None = None,
    package_path: Sequence[str | Path] = (),
) -> Robot:
    """Load a robot with the kinematics of its kind: a configured one (name or folder) or a URDF / xacro file.

    Args:
        robot: shipped robot name, config folder, or parameters (ignored when ``urdf`` is given).
        overrides: parameter overrides (flat names), for configured robots only.
        urdf: path of a URDF file, or of a xacro file (``.xacro``), to load instead.
        tool: the tool frame (a link); default ``tool0`` if present, else the chain's last link (then
            ``robot.frame_note`` says so).
        base: the base frame poses are expressed in (a link); default ``base`` if present, else the root.
        package_path: folders holding ROS-style packages, for ``$(find pkg)`` and ``package://pkg/``.

    Raises:
        UrdfError: (exit code 2) among others a ``tool`` or ``base`` that is not a link of the robot.
    """
    kwargs: dict[str, Any] = {"tool_frame": tool, "base_frame": base, "kinematics": kinematics_for}
    if urdf is not None:
        if overrides:
            raise InvalidInputError("parameter overrides apply to configured robots, not to a URDF file")
        return Robot.from_file(urdf, package_dirs=package_path, **kwargs)
    if package_path:
        raise InvalidInputError("--package-path applies to a URDF or xacro file (--urdf), not to a configured robot")
    return Robot.from_config(robot, overrides, **kwargs)


def load_urdf(path: str | Path, **kwargs: Any) -> Robot:
    """Load a 4-joint URDF (or xacro) file with its kinematics; keywords as for :func:`load_robot`."""
    return load_robot(urdf=path, **kwargs)


def robot_from_urdf(urdf: str, **kwargs: Any) -> Robot:
    """A robot from URDF text (generated in memory, say), with its kinematics; keywords as for Robot."""
    return Robot(urdf, kinematics=kinematics_for, **kwargs)
