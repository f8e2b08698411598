"""Pictures of trajectories that read at a glance, and the helpers every plot of the package shares.

:func:`plot_trajectory` draws one panel per joint and quantity (position, velocity, acceleration, and the
joint torque when asked), each with its own unit and its own limits, beside the tool path (plan and side
view) and the tool speed. The shared helpers give every figure the same conventions:

- :func:`new_figure`: object-oriented matplotlib (a Figure on the Agg canvas: no pyplot, no global state,
  the caller's backend left alone), so a notebook shows the returned Figure and a script saves it (it and
  :func:`finish` live in :mod:`scara_pin.files`, below the workspace's and the calibration's pictures);
- :func:`quantity_label`: a quantity and its unit, ``"joint1 velocity [deg/s]"``, in the units chosen
  (:class:`scara_pin.units.DisplayUnits`, the ``--deg``/``--mm`` of the command line);
- :func:`draw_limits`: a joint's limits as dashed lines tagged ``gid="limit"``, or a note when a limit lies
  far outside the plotted values (it would squash the curve);
- :func:`finish`: writes the figure (atomically, PNG/SVG/PDF by its ending) only when given a path, and
  returns it.
- :func:`shape_points` and :func:`hull`: a cell shape's outline in plan view (the cycle's and the job's).

matplotlib is imported inside the functions, so importing this module costs nothing.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..description import JointLimits
from ..errors import ParameterError
from ..files import finish, new_figure
from ..motion.trajectory import Trajectory
from ..units import SI, DisplayUnits, decimals_for, format_number

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..cell.shapes import Shape
    from ..model import RobotModel

__all__ = [
    "COLORS",
    "LIMIT_GID",
    "draw_limits",
    "finish",
    "hull",
    "joint_kinds",
    "new_figure",
    "plot_trajectory",
    "quantity_label",
    "rate_unit",
    "shape_points",
]

COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
"""One colour per joint, the same in every plot."""
LIMIT_GID = "limit"
"""The ``gid`` of every limit line (tests and tools find them by it)."""
_SHOW_LIMIT = 2.5
"""A limit is drawn inside a panel when within this factor of the largest plotted magnitude; else noted."""
_DEFAULT_KINDS = ("angle", "angle", "length", "angle")
_QUANTITIES = ("position", "velocity", "acceleration")


def rate_unit(unit: str, order: int) -> str:
    """A unit per second to the ``order``: ``rate_unit("deg", 2) == "deg/s²"``."""
    return unit if order == 0 else f"{unit}/s" if order == 1 else f"{unit}/s{'²³'[order - 2]}"


def quantity_label(what: str, kind: str, units: DisplayUnits = SI, order: int = 0) -> str:
    """``"<what> [<unit>]"`` for a quantity of a kind (``"angle"``, ``"length"``) differentiated ``order`` times."""
    return f"{what} [{rate_unit(units.name(kind), order)}]"


def joint_kinds(robot: RobotModel | None, dof: int) -> tuple[str, ...]:
    """What each joint value measures (the robot's own; without one, a SCARA's: the third joint a length)."""
    return robot.joint_kinds if robot is not None else _DEFAULT_KINDS[:dof]


def draw_limits(ax: Axes, limits: Sequence[float], values: np.ndarray, color: str, scale: float = 1.0,
                unit: str = "") -> list[float]:  # fmt: skip
    """Draw a joint's limits (already in display units when ``scale`` is 1) as dashed lines, ``gid="limit"``.

    A limit within 2.5 times the largest plotted magnitude is drawn and the view widened to show it; one
    farther away is written in the panel's corner instead (``gid="limit-note"``), so that the curve keeps
    the panel. Infinite and NaN limits (unknown) are skipped.

    Args:
        ax: the panel.
        limits: the limit values (e.g. lower and upper, or -vmax and +vmax) [SI].
        values: the plotted values (display units), to size the view.
        color: the joint's colour.
        scale: display value per SI value.
        unit: the display unit, for the note.

    Returns:
        the limits drawn, in display units.
    """
    top = float(np.max(np.abs(values))) if values.size else 0.0
    lo, hi = (float(values.min()), float(values.max())) if values.size else (0.0, 0.0)
    span = max(hi - lo, 0.05 * top, 1e-12)
    view = [lo - 0.08 * span, hi + 0.08 * span]
    drawn, off = [], []
    for v in (s * scale for s in limits if math.isfinite(s)):
        if abs(v) <= _SHOW_LIMIT * max(top, 1e-12):
            ax.axhline(v, color=color, linestyle="--", linewidth=1.0, alpha=0.9, gid=LIMIT_GID)
            view = [min(view[0], v - 0.05 * span), max(view[1], v + 0.05 * span)]
            drawn.append(v)
        else:
            off.append(v)
    if off:
        shown = ", ".join(f"{v:.4g}" for v in off)
        ax.text(0.99, 0.97, f"limit {shown} {unit} (off scale)", transform=ax.transAxes, ha="right", va="top",
                fontsize=7, color=color, gid="limit-note")  # fmt: skip
    ax.set_ylim(*view)
    return drawn


def shape_points(shape: Shape) -> np.ndarray:
    """(k, 3) points of ``shape`` whose convex hull outlines it, in its frame's axes.

    A vertical cylinder's or a sphere's rings (a circle in plan view), else the corners of the box around it
    (:meth:`~scara_pin.cell.Shape.corners`).
    """
    if shape.kind in ("cylinder", "sphere") and abs(shape.rotation[2, 2]) > 1.0 - 1e-9:
        angle = np.linspace(0.0, 2.0 * np.pi, 73)
        r = shape.size[0]
        ring = shape.xyz[:2] + r * np.column_stack([np.cos(angle), np.sin(angle)])
        half = shape.size[1] / 2.0 if shape.kind == "cylinder" else r
        return np.column_stack([np.repeat(ring, 2, axis=0), np.tile([shape.xyz[2] - half, shape.xyz[2] + half],
                                                                    len(ring))])  # fmt: skip
    return shape.corners()


def hull(points: np.ndarray) -> np.ndarray:
    """The convex hull of 2-D points (scipy's Qhull), counterclockwise."""
    from scipy.spatial import ConvexHull

    pts = np.unique(points, axis=0)
    if len(pts) < 3:
        return pts
    return pts[ConvexHull(pts).vertices]


def plot_trajectory(
    trajectory: Trajectory,
    path: str | os.PathLike[str] | None = None,
    *,
    robot: RobotModel | None = None,
    limits: JointLimits | None = None,
    units: DisplayUnits = SI,
    law: str | None = None,
    torque: bool = False,
    tool_speed: float | None = None,
    samples: int = 1000,
    title: str | None = None,
    dpi: int = 120,
) -> Figure:
    """A trajectory at a glance: each joint's q, qd, qdd (and torque) in its own panel with its own limits.

    One row per joint and one column per quantity (position, velocity, acceleration; joint torque or force
    with ``torque``), each panel labelled with its unit in ``units`` and the joint's limits dashed (a limit
    far outside the values is noted in the corner instead). Given the robot, a column on the right shows
    the tool path in plan view (with the reach circles of a SCARA), in side view (height against the
    distance travelled in the plane) and the tool speed |v| against time, its limit dashed when
    ``tool_speed`` is given. The title names the robot and the time law.

    Args:
        trajectory: the trajectory.
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        robot: the robot (joint kinds and limits, tool path, tool speed, torques: the robot's model, with a
            payload if it carries one).
        limits: limits to draw (default: the robot's; none without a robot).
        units: the units of the axes (SI by default; ``DisplayUnits("mm", "deg")`` for ``--mm --deg``).
        law: how the trajectory was timed, for the title (e.g. ``Method.ARCH.value``).
        torque: add the joint torque (force for a prismatic joint) column, from Pinocchio's RNEA; needs the
            robot.
        tool_speed: the tool speed limit to draw [m/s], if any.
        samples: number of time samples plotted (>= 2).
        title: the figure title (default: robot, law and duration).
        dpi: resolution of a written PNG.

    Returns:
        the matplotlib Figure (a notebook shows it; ``fig.savefig`` writes it again anywhere).

    Raises:
        ParameterError: ``samples`` below 2, or ``torque`` without a robot.
    """
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise ParameterError("samples", samples, "must be an integer >= 2")
    if torque and robot is None:
        raise ParameterError("torque", torque, "needs the robot (its model gives the torques)")
    if limits is None and robot is not None:
        limits = robot.limits
    dof = trajectory.dof
    kinds = joint_kinds(robot, dof)
    names = robot.joint_names if robot is not None else tuple(f"joint{j + 1}" for j in range(dof))
    t = np.linspace(0.0, trajectory.duration, samples)
    q, qd, qdd = trajectory.sample(t)
    series: list[tuple[str, np.ndarray, list[tuple[float, ...]] | None, int]] = [
        ("position", q, None if limits is None else [(lo, hi) for lo, hi in zip(limits.lower, limits.upper)], 0),
        ("velocity", qd, None if limits is None else [(-v, v) for v in limits.velocity], 1),
        ("acceleration", qdd, None if limits is None else [(-a, a) for a in limits.acceleration], 2),
    ]
    if torque and robot is not None:
        from ..motion.verify import joint_torques

        tau = joint_torques(robot, q, qd, qdd)
        series.append(("torque", tau, None if limits is None else [(-e, e) for e in limits.effort], -1))
    cols = len(series) + (1 if robot is not None else 0)
    fig = new_figure(3.6 * len(series) + (4.6 if robot is not None else 0.0), 1.0 + 2.1 * dof)
    grid = fig.add_gridspec(dof, cols, width_ratios=[1.0] * len(series) + ([1.25] if robot is not None else []))
    for c, (what, values, lim, order) in enumerate(series):
        for j in range(dof):
            ax = fig.add_subplot(grid[j, c])
            if order >= 0:
                scale, unit = units.scale(kinds[j]), rate_unit(units.name(kinds[j]), order)
            else:  # a revolute joint's torque, a prismatic joint's force: SI
                scale, unit = 1.0, "N·m" if kinds[j] == "angle" else "N"
            shown = values[:, j] * scale
            ax.plot(t, shown, color=COLORS[j % len(COLORS)], linewidth=1.6)
            if lim is not None:
                draw_limits(ax, lim[j], shown, COLORS[j % len(COLORS)], scale, unit)
            ax.set_xlim(0.0, trajectory.duration)
            label = "torque" if order < 0 and kinds[j] == "angle" else "force" if order < 0 else what
            ax.set_ylabel(f"{names[j]} {label} [{unit}]", fontsize=8)
            ax.grid(True, alpha=0.3)
            ax.tick_params(labelsize=7)
            if j == 0:
                ax.set_title(what if order >= 0 else "torque / force", fontsize=10)
            if j == dof - 1:
                ax.set_xlabel("time t [s]", fontsize=8)
    if robot is not None:
        side = grid[:, cols - 1].subgridspec(3, 1, height_ratios=(1.5, 1.0, 1.0))
        _tool_panels(fig, side, robot, t, q, qd, units, tool_speed)
    duration = f"{trajectory.duration:.4g} s"
    head = f"{robot.name}: " if robot is not None else ""
    fig.suptitle(title or f"{head}{law or 'trajectory'}, {duration}", fontsize=12)
    return finish(fig, path, dpi)


def _tool_panels(fig: Figure, grid: Any, robot: RobotModel, t: np.ndarray, q: np.ndarray, qd: np.ndarray,
                 units: DisplayUnits, tool_speed: float | None) -> None:  # fmt: skip
    """The tool path in plan view (with a SCARA's reach circles) and side view, and the tool speed."""
    from ..motion.timing import tool_speeds

    L, n = units.scale("length"), units.name("length")
    P = np.array([robot.tool_pose(x) for x in q])
    plan = fig.add_subplot(grid[0])
    if robot.kind == "scara":
        geo = robot.kinematics.geometry
        ring = np.linspace(0.0, 2.0 * math.pi, 361)
        r_min, r_max = geo.radius_range()
        cx, cy = geo.a1
        for r, what in ((r_max, "reach"), (r_min, "inner limit")):
            if r > 0:
                plan.plot((cx + r * np.cos(ring)) * L, (cy + r * np.sin(ring)) * L, "--", color="0.6", linewidth=1.0,
                          label=f"wrist {what} r = {format_number(r * L, decimals_for(L, 1e-6))} {n}")  # fmt: skip
    plan.plot(P[:, 0] * L, P[:, 1] * L, color="black", linewidth=1.8, label="tool path")
    plan.plot(P[0, 0] * L, P[0, 1] * L, "o", color="tab:green", label="start")
    plan.plot(P[-1, 0] * L, P[-1, 1] * L, "s", color="tab:red", label="end")
    plan.set_aspect("equal", adjustable="datalim")
    plan.set_xlabel(f"x [{n}] (base frame)", fontsize=8)
    plan.set_ylabel(f"y [{n}]", fontsize=8)
    plan.set_title("tool path, plan view", fontsize=10)
    plan.grid(True, alpha=0.3)
    plan.legend(fontsize=7, loc="best")
    side = fig.add_subplot(grid[1])
    along = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(P[:, 0]), np.diff(P[:, 1])))])
    side.plot(along * L, P[:, 2] * L, color="black", linewidth=1.8)
    side.set_xlabel(f"distance travelled in the plane [{n}]", fontsize=8)
    side.set_ylabel(f"z [{n}]", fontsize=8)
    side.set_title("tool path, side view", fontsize=10)
    side.grid(True, alpha=0.3)
    speed = fig.add_subplot(grid[2])
    v = tool_speeds(robot, q, qd) * L
    speed.plot(t, v, color="black", linewidth=1.6)
    if tool_speed is not None:
        draw_limits(speed, (tool_speed,), v, "black", L, rate_unit(n, 1))
    speed.set_xlim(0.0, float(t[-1]))
    speed.set_xlabel("time t [s]", fontsize=8)
    speed.set_ylabel(f"tool speed |v| [{rate_unit(n, 1)}]", fontsize=8)
    speed.set_title("tool speed", fontsize=10)
    speed.grid(True, alpha=0.3)
