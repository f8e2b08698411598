"""PNG pictures of trajectories: joint position, velocity and acceleration against time, and the tool path.

matplotlib is imported inside the functions (its Agg canvas, no pyplot and no global state), so
importing this module costs nothing.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..description import JOINT_NAMES, JointLimits
from ..errors import ParameterError
from ..files import save_figure
from ..motion.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..model import Robot

__all__ = ["plot_trajectory"]

_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
_SHOW_LIMIT = 2.5
"""A limit is drawn inside the panel when it is within this factor of the largest plotted value."""


def plot_trajectory(
    trajectory: Trajectory,
    path: str | os.PathLike[str],
    *,
    robot: Robot | None = None,
    limits: JointLimits | None = None,
    samples: int = 1000,
    title: str | None = None,
    dpi: int = 120,
) -> Path:
    """Write a PNG: q, qd, qdd of the four joints against time, and the tool path given the robot.

    One panel per joint, limits dashed, and, given the robot, the tool path in the base x-y plane with the
    reach circles.

    Limits (``limits``, default ``robot.limits``) are dashed lines in each joint's colour; the legend
    gives their values, and a limit far outside the plotted values (more than 2.5 times the largest)
    stays outside the panel rather than squash the curves. Written atomically.

    Args:
        trajectory: the trajectory.
        path: the PNG file.
        robot: the robot (joint units, limits, and the tool-path panel); optional.
        limits: limits to draw (default: the robot's; none without a robot).
        samples: number of time samples plotted (>= 2).
        title: figure title.
        dpi: resolution.

    Returns:
        the path written.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise ParameterError("samples", samples, "must be an integer >= 2")
    if limits is None and robot is not None:
        limits = robot.limits
    prismatic = robot.joint_kinds.index("length") if robot is not None else 2
    units = ["m" if i == prismatic else "rad" for i in range(4)]
    t = np.linspace(0.0, trajectory.duration, samples)
    q, qd, qdd = trajectory.sample(t)
    fig = Figure(figsize=(13.0, 9.0) if robot is not None else (9.0, 9.0), layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(3, 2, width_ratios=(1.6, 1.0)) if robot is not None else fig.add_gridspec(3, 1)
    def symmetric(v: tuple[float, ...]) -> tuple[tuple[float, ...], tuple[float, ...]]:
        return tuple(-x for x in v), v

    rows = [
        ("position", q, None if limits is None else (limits.lower, limits.upper), ""),
        ("velocity", qd, None if limits is None else symmetric(limits.velocity), "/s"),
        ("acceleration", qdd, None if limits is None else symmetric(limits.acceleration), "/s²"),
    ]
    for r, (what, values, lim, per) in enumerate(rows):
        ax = fig.add_subplot(grid[r, 0])
        top = float(np.max(np.abs(values))) if values.size else 0.0
        lo, hi = float(values.min()), float(values.max())
        span = max(hi - lo, 1e-12, 0.05 * top)
        view = [lo - 0.08 * span, hi + 0.08 * span]
        for j in range(4):
            label = f"{JOINT_NAMES[j]} [{units[j]}{per}]"
            if lim is not None:
                pair = (lim[0][j], lim[1][j])
                shown = [v for v in pair if math.isfinite(v)]
                if shown:
                    label += f", limit ±{pair[1]:.4g}" if r else f", limits [{pair[0]:.4g}, {pair[1]:.4g}]"
                for v in shown:
                    if abs(v) <= _SHOW_LIMIT * max(top, 1e-12):
                        ax.axhline(v, color=_COLORS[j], linestyle="--", linewidth=1.0, alpha=0.8)
                        view = [min(view[0], v - 0.05 * span), max(view[1], v + 0.05 * span)]
            ax.plot(t, values[:, j], color=_COLORS[j], linewidth=1.6, label=label)
        ax.set_ylim(*view)
        ax.set_xlim(0.0, trajectory.duration)
        ax.set_ylabel(f"joint {what}")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="best")
        if r == 2:
            ax.set_xlabel("time t [s]")
    if robot is not None:
        _tool_panel(fig.add_subplot(grid[:, 1]), robot, q)
    fig.suptitle(title or f"trajectory: {trajectory.duration:.4g} s", fontsize=12)
    return save_figure(fig, path, dpi=dpi)


def _tool_panel(ax: Axes, robot: Robot, q: np.ndarray) -> None:
    """The tool path in the base x-y plane, the start and end, and the reach circles."""
    P = np.array([robot.tool_pose(x) for x in q])
    geo = robot.kinematics.geometry
    ring = np.linspace(0.0, 2.0 * math.pi, 361)
    r_min, r_max = geo.radius_range()
    cx, cy = geo.a1
    for r, name in ((r_max, "reach"), (r_min, "inner limit")):
        if r > 0:
            ax.plot(cx + r * np.cos(ring), cy + r * np.sin(ring), "--", color="0.6", linewidth=1.0,
                    label=f"wrist {name} r = {r:.4g} m")
    ax.plot(P[:, 0], P[:, 1], color="black", linewidth=1.8, label="tool path")
    ax.plot(P[0, 0], P[0, 1], "o", color="tab:green", label="start")
    ax.plot(P[-1, 0], P[-1, 1], "s", color="tab:red", label="end")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m] (base frame)")
    ax.set_ylabel("y [m]")
    ax.set_title("tool path (plan view)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
