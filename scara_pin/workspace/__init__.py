"""Workspaces: the SCARA's exact plan-view region and the palletizer's arm-plane envelope."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from .scara import (
    EDGE_TOL,
    SIDE_OFFSET,
    Arc,
    Limit,
    OutsideWorkspaceError,
    RayBatch,
    RayHit,
    Workspace,
    plot_workspace,
    workspace,
)

if TYPE_CHECKING:
    from ..model import RobotModel
    from .palletizer import ArmPlaneEnvelope

__all__ = [
    "EDGE_TOL",
    "SIDE_OFFSET",
    "Arc",
    "Limit",
    "OutsideWorkspaceError",
    "RayBatch",
    "RayHit",
    "Workspace",
    "plot_workspace",
    "workspace",
    "workspace_of",
]


def workspace_of(robot: RobotModel, **kwargs: Any) -> Workspace | ArmPlaneEnvelope:
    """The reachable region of a robot, by its kind.

    A SCARA (4 or 3 joints): its exact plan-view region (:func:`~scara_pin.workspace.scara.workspace`,
    keyword arguments as there); the palletizer: its arm-plane envelope
    (:func:`~scara_pin.workspace.palletizer.arm_plane_envelope`, which takes none).

    Raises:
        InvalidInputError: keyword arguments for a palletizer.
    """
    if robot.kind == "palletizer":
        if any(v is not None for v in kwargs.values()):
            raise InvalidInputError(f"the palletizer's envelope takes no {', '.join(sorted(kwargs))}")
        from .palletizer import arm_plane_envelope

        return arm_plane_envelope(robot.kinematics.geometry)
    return workspace(robot, **kwargs)
