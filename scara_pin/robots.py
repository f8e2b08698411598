"""Loading a robot with the kinematics of its kind: the package's front door (:func:`load_robot`).

A :class:`~scara_pin.model.Robot` is the Pinocchio model (FK, frames, Jacobians); its inverse kinematics is
the object :func:`scara_pin.kinematics.kinds.kinematics_for` builds for its kind, on first use. The kinds
themselves live in :mod:`scara_pin.kinematics` (``scara_kinematics``, ``scara3_kinematics``,
``palletizer_kinematics``); their names are still importable from here.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .description import RobotParameters
from .errors import InvalidInputError
from .kinematics.kinds import kinematics_for
from .model import Robot

__all__ = [
    "kinematics_for",
    "load_robot",
    "load_urdf",
    "robot_from_urdf",
]

_KINDS = {
    "ScaraKinematics": "scara_kinematics",
    "Scara3Kinematics": "scara3_kinematics",
    "PalletizerKinematics": "palletizer_kinematics",
}


def __getattr__(name: str) -> Any:
    """The kinds' classes, imported on first use (``scara-pin fk`` needs none of them)."""
    if name in _KINDS:
        import importlib

        return getattr(importlib.import_module(f".kinematics.{_KINDS[name]}", __package__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def load_robot(
    robot: str | Path | RobotParameters = "default",
    overrides: Mapping[str, object] | None = None,
    *,
    urdf: str | Path | None = None,
    tool: str | None = None,
    base: str | None = None,
    package_path: Sequence[str | Path] = (),
    lock: Mapping[str, float] | None = None,
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
        lock: joints to fix at a value [rad, m] (:mod:`scara_pin.chain`). Joints not on the chain from the
            root to ``tool`` (the other arm of a two-arm robot) are locked anyway, at 0 unless given here;
            ``robot.locked`` lists them all.

    Raises:
        UrdfError: (exit code 2) among others a ``tool`` or ``base`` that is not a link of the robot.
    """
    kwargs: dict[str, Any] = {"tool_frame": tool, "base_frame": base, "kinematics": kinematics_for}
    if lock:
        kwargs["lock"] = dict(lock)
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
