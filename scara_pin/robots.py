"""The user's robot and the package's front door (:func:`load_robot`): a facade above the layers.

A :class:`~scara_pin.model.RobotModel` is the Pinocchio model (FK, frames, Jacobians, limits, checks); its
inverse kinematics is the object :func:`scara_pin.kinematics.kinds.kinematics_for` builds for its kind, on first
use. :class:`Robot`, what :func:`load_robot` returns, is that model with the conveniences of the layers above it
(as Pinocchio's ``RobotWrapper`` composes model, geometry and viewer): :meth:`Robot.plot` (a stick figure,
:mod:`scara_pin.viz.stick`), :meth:`Robot.distances` (in a cell, :mod:`scara_pin.cell`) and the HTML table a
notebook shows. The package's own code takes the model; a ``Robot`` is one. The kinds live in
:mod:`scara_pin.kinematics` (``scara_kinematics``, ``scara3_kinematics``, ``palletizer_kinematics``); their
names are still importable from here.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .description import JOINT_NAMES, RobotParameters, configured
from .errors import InvalidInputError, ParameterError
from .kinematics.kinds import kinematics_for
from .model import RobotModel

if TYPE_CHECKING:
    from ._typing import ArrayLike
    from .cell import Cell, Distances

__all__ = [
    "Robot",
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


class Robot(RobotModel):
    """A robot as users hold it: the model with a stick figure, its distances in a cell, a notebook's table.

    See the module docstring; everything else is :class:`~scara_pin.model.RobotModel`'s.
    """

    def plot(self, q: object = None, path: str | os.PathLike[str] | None = None, **kwargs: Any) -> Any:
        """The arm at ``q`` as a matplotlib stick figure (a Figure; written to ``path`` when one is given).

        ``robot.plot(q)`` is :func:`scara_pin.viz.stick.plot_robot` (its keywords: ``units``, ``view`` ``"3d"`` /
        ``"top"`` / ``"side"``, ``ax``, ``title``, ``dpi``). matplotlib is imported only when it draws.
        """
        from .viz.stick import plot_robot

        return plot_robot(self, q, path, **kwargs)

    def distances(self, q: ArrayLike, cell: Cell) -> Distances:
        """Every checked pair's distance at ``q`` in ``cell`` (:class:`scara_pin.cell.Distances`), closest first.

        The robot's links (its URDF ``<collision>`` elements) and the cell's carried part against the cell's
        obstacles, and the robot's self-collision pairs (:mod:`scara_pin.cell`); coal's signed distances, witness
        points and normals in the base frame.
        """
        from .cell import scene

        return scene(self, cell).distances(q)

    def _repr_html_(self) -> str:
        """The summary as an HTML table (Jupyter shows it for a robot at the end of a cell)."""
        from html import escape

        head, rows = self.summary()
        cols = ["#", "joint", "type", "lower", "upper", "velocity", "acceleration", "effort"]
        th = "".join(f"<th>{c}</th>" for c in cols)
        body = "".join("<tr>" + "".join(f"<td>{escape(v)}</td>" for v in r) + "</tr>" for r in rows)
        return (f"<div class='scara-pin-robot'><p><b>{escape(head)}</b></p><table><thead><tr>{th}</tr></thead>"
                f"<tbody>{body}</tbody></table></div>")  # fmt: skip


def load_robot(
    robot: str | Path | RobotParameters = "default",
    overrides: Mapping[str, object] | None = None,
    *,
    urdf: str | Path | None = None,
    tool: str | None = None,
    base: str | None = None,
    package_path: Sequence[str | Path] = (),
    lock: Mapping[str, float] | None = None,
    acceleration: Sequence[float] | None = None,
    velocity: Sequence[float] | None = None,
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
        acceleration: joint acceleration limits [rad/s^2, m/s^2], in q order: a URDF file has none; they replace
            a configured robot's (``joint_limits.yaml``; its generated URDF, which holds none, is the same).
        velocity: joint velocity limits [rad/s, m/s], in q order, instead of the URDF's (a continuous joint
            without ``<limit>`` has none) or a configured robot's (its URDF is generated with them).

    Raises:
        UrdfError: (exit code 2) among others a ``tool`` or ``base`` that is not a link of the robot.
    """
    kwargs: dict[str, Any] = {"tool_frame": tool, "base_frame": base, "kinematics": kinematics_for}
    if lock:
        kwargs["lock"] = dict(lock)
    if urdf is not None:
        if overrides:
            raise InvalidInputError("parameter overrides apply to configured robots, not to a URDF file (a URDF "
                                    "robot's limits: --velocity and --acceleration, one value per joint)")
        return Robot.from_file(urdf, package_dirs=package_path, acceleration=acceleration, velocity=velocity,
                               **kwargs)  # fmt: skip
    if package_path:
        raise InvalidInputError("--package-path applies to a URDF or xacro file (--urdf), not to a configured robot")
    if velocity is not None:  # in the generated URDF too
        overrides = {**(overrides or {}), **_per_joint("velocity", velocity)}
    if acceleration is None:
        return Robot.from_config(robot, overrides, **kwargs)
    params, text = configured(robot, overrides)
    params = params.with_overrides(_per_joint("acceleration", acceleration))
    return Robot(text, parameters=params, origin=f"robot {params.name!r}", generated=True, **kwargs)


def _per_joint(name: str, values: Sequence[float]) -> dict[str, float]:
    """A configured robot's parameters ``joint1_velocity``... from one value per joint."""
    if len(values) != len(JOINT_NAMES):
        raise ParameterError(name, list(values), f"must hold {len(JOINT_NAMES)} values, one per joint")
    return {f"{j}_{name}": v for j, v in zip(JOINT_NAMES, values)}


def load_urdf(path: str | Path, **kwargs: Any) -> Robot:
    """Load a 4-joint URDF (or xacro) file with its kinematics; keywords as for :func:`load_robot`."""
    return load_robot(urdf=path, **kwargs)


def robot_from_urdf(urdf: str, **kwargs: Any) -> Robot:
    """A robot from URDF text (generated in memory, say), with its kinematics; keywords as for Robot."""
    return Robot(urdf, kinematics=kinematics_for, **kwargs)
