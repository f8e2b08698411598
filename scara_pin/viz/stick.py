"""The arm as a matplotlib stick figure: ``robot.plot(q)``, for reports and quick looks.

Each joint of the tool's chain is a dot at its origin; straight links join them, from the base frame's
origin to the tool frame, whose axes are drawn as a small triad (x red, y green, z blue). Positions are
Pinocchio's joint placements ``oMi`` and the tool placement, expressed in the robot's base frame (the
package's convention) and shown in ``units``. The figure is a matplotlib Figure on its own Agg canvas (no
pyplot: the caller's backend and figures are untouched); a notebook cell ending with it shows it.

It sits beside the model (it needs only the model's forward kinematics); matplotlib is imported when a
figure is drawn, never at import.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..errors import ParameterError
from ..units import SI, DisplayUnits

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..model import RobotModel

__all__ = ["STICK_GID", "TOOL_GID", "plot_robot", "stick_points"]

STICK_GID = "stick"
"""The ``gid`` of the line joining the joints (tests and tools find it by it)."""
TOOL_GID = "tool-triad"
"""The ``gid`` prefix of the tool frame's axes (``tool-triad-x``, ``-y``, ``-z``)."""
_VIEWS = ("3d", "top", "side")


def stick_points(robot: RobotModel, q: object) -> np.ndarray:
    """(K, 3) points of the stick figure at ``q``, in the base frame [m].

    The base origin, the origin of each joint of the tool's chain (root to tip), the tool frame's origin.
    """
    qv = robot.check_q(q)
    model, data = robot.model, robot.data
    pin.framesForwardKinematics(model, data, robot.to_pinocchio_q(qv))
    base = data.oMf[robot.base_id]
    chain = [j for j in model.supports[model.frames[robot.tool_id].parentJoint] if j > 0]
    points = [np.zeros(3)]
    points += [base.actInv(data.oMi[j]).translation for j in chain]
    points.append(base.actInv(data.oMf[robot.tool_id]).translation)
    return np.array(points)


def plot_robot(
    robot: RobotModel,
    q: object = None,
    path: str | os.PathLike[str] | None = None,
    *,
    units: DisplayUnits = SI,
    view: str = "3d",
    ax: Axes | None = None,
    title: str | None = None,
    dpi: int = 120,
) -> Figure:
    """The arm at ``q`` as a stick figure (module docstring); written to ``path`` when one is given.

    Args:
        robot: the robot.
        q: joint values [rad, m] (default: the middle of each finite joint range, else 0).
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        units: the length unit of the axes (``DisplayUnits("mm")`` for millimetres).
        view: ``"3d"``, ``"top"`` (x, y: plan view) or ``"side"`` (x, z).
        ax: draw into these axes (3-D axes for ``"3d"``) instead of a new figure, e.g. a frame of an animation.
        title: the title (default: the robot's name and q).
        dpi: resolution of a written PNG.

    Returns:
        the Figure drawn on.

    Raises:
        ParameterError: a ``q`` that is not ``robot.dof`` finite numbers, or an unknown ``view``.
    """
    from .plots import finish, new_figure

    if view not in _VIEWS:
        raise ParameterError("view", view, f"must be one of {', '.join(_VIEWS)}")
    if q is None:
        lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
        q = np.where(np.isfinite(lo) & np.isfinite(hi), (lo + hi) / 2.0, 0.0)
    qv = robot.check_q(q)
    k, Ln = units.scale("length"), units.name("length")
    pts = stick_points(robot, qv) * k
    tool = robot.frame_placement(qv, robot.model.frames[robot.tool_id].name)
    size = 0.15 * max(float(np.ptp(pts, axis=0).max()), 1e-3 * k)
    if ax is None:
        fig = new_figure(6.4, 5.6)
        ax = fig.add_subplot(projection="3d" if view == "3d" else None)
    fig = ax.get_figure()  # type: ignore[assignment]
    cols = {"3d": (0, 1, 2), "top": (0, 1), "side": (0, 2)}[view]
    coords: Any = [pts[:, c] for c in cols]
    ax.plot(*coords, "-o", color="0.25", lw=3, ms=7, mfc="tab:orange", gid=STICK_GID)
    for axis, color in zip("xyz", ("tab:red", "tab:green", "tab:blue")):
        tip = pts[-1] + tool.rotation[:, "xyz".index(axis)] * size
        seg: Any = [[pts[-1][c], tip[c]] for c in cols]
        ax.plot(*seg, color=color, lw=2, gid=f"{TOOL_GID}-{axis}")
    names = ("x", "y", "z")
    ax.set_xlabel(f"{names[cols[0]]} [{Ln}]")
    ax.set_ylabel(f"{names[cols[1]]} [{Ln}]")
    if view == "3d":
        ax.set_zlabel(f"z [{Ln}]")  # type: ignore[attr-defined]
        lo, hi = pts.min(axis=0) - size, pts.max(axis=0) + size
        centre, half = (lo + hi) / 2.0, float((hi - lo).max()) / 2.0
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)  # type: ignore[attr-defined]
        ax.set_box_aspect((1.0, 1.0, 1.0))  # type: ignore[arg-type]
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    shown = units.format_vector(qv, robot.joint_kinds)
    ax.set_title(title if title is not None else f"{robot.name} at q = {shown} "
                 f"[{', '.join(units.name(kind) for kind in robot.joint_kinds)}]", fontsize=9)  # fmt: skip
    return finish(fig, path, dpi)  # type: ignore[arg-type]
