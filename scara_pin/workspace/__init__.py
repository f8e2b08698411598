"""Workspaces: the SCARA's exact plan-view region and the palletizer's arm-plane envelope."""

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
]
