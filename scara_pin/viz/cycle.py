"""PNG picture of an arch move or cycle: tool path in side and plan view, joint rates against their limits.

Object-oriented matplotlib (a Figure on the Agg canvas, no pyplot, no global state), written atomically.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..units import SI, DisplayUnits
from .plots import COLORS, finish, hull, new_figure, shape_points

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..cell import Cell
    from ..description import JointLimits
    from ..model import RobotModel
    from ..motion.cycle import ArchMove, CycleResult
    from ..motion.jump import JumpMove
    from ..motion.trajectory import Trajectory

__all__ = ["TORQUE_LABEL", "plot_cycle"]

TORQUE_LABEL = "|tau| / effort"
"""The y label of the torque panel (joint torque, or force for the prismatic joint, over its effort limit)."""

_LEG_COLORS = {"lift": "tab:gray", "blend up": "tab:purple", "traverse": "tab:blue", "blend down": "tab:purple",
               "descend": "tab:gray"}  # fmt: skip


def plot_cycle(
    result: CycleResult | ArchMove | JumpMove,
    path: str | os.PathLike[str] | None = None,
    *,
    robot: RobotModel,
    units: DisplayUnits = SI,
    limits: JointLimits | None = None,
    title: str | None = None,
    rate: float = 2000.0,
    dpi: int = 110,
) -> Figure:
    """A cycle or arch move: the tool path, and the joint rates (and torques) against their limits.

    Side view (horizontal progress vs z) and plan view (x, y) with the legs coloured (blends in purple);
    for a jump, its clearance: the height z_top (dashed) outside the circles of radius R around the two poses
    (dotted), and the straight line between them in plan view; |qd|/vmax, |qdd|/amax, |qddd|/jmax (with a
    jerk limit) and |tau|/effort (Pinocchio's RNEA, gravity and the payload included: the cycle always
    respects the effort limits) per joint against time, the limit at 1.

    Args:
        result: a :class:`~scara_pin.motion.cycle.CycleResult` (its move is drawn), or a move.
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        robot: the robot the move was planned for (its model, for the tool path and the torques).
        units: the length unit of the tool path's axes (``DisplayUnits("mm")`` for millimetres).
        limits: the limits the ratios are taken to (default the robot's).
        title: the figure's title.
        rate: [Hz] samples of the trajectory drawn.
        dpi: resolution of a written PNG.
    """
    from ..motion.cycle import CycleResult
    from ..motion.payload import with_payload
    from ..motion.verify import joint_torques

    move = result.move if isinstance(result, CycleResult) else result
    lim = robot.limits if limits is None else limits
    traj = move.trajectory
    t = np.linspace(0.0, traj.duration, max(2, int(traj.duration * rate) + 1))
    q, qd, qdd = traj.sample(t)
    poses = np.array([robot.tool_pose(qk) for qk in q])
    rows = 4 + (move.jerk is not None)  # tool path, velocity, acceleration, (jerk), torque
    fig = new_figure(12.0, 2.8 * rows)
    grid = fig.add_gridspec(rows, 2)
    side, plan = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    k, Ln = units.scale("length"), units.name("length")
    start = poses[0, :2]
    direction = poses[np.argmax(np.linalg.norm(poses[:, :2] - start, axis=1)), :2] - start
    norm = float(np.linalg.norm(direction)) or 1.0
    progress = (poses[:, :2] - start) @ (direction / norm)
    for leg in move.legs:
        sel = (t >= leg.t_start) & (t <= leg.t_end)
        color = _LEG_COLORS.get(leg.name, "k")
        label = leg.name if leg.move == 0 else None
        side.plot(progress[sel] * k, poses[sel, 2] * k, color=color, lw=2, label=label)
        plan.plot(poses[sel, 0] * k, poses[sel, 1] * k, color=color, lw=2)
    R = getattr(move, "clearance_radius", None)
    if R is not None:  # the jump's clearance: z >= z_top wherever the tool is more than R from both ends
        z_top, end = move.z_top, float(np.hypot(*(move.pose_to[:2] - move.pose_from[:2])))  # type: ignore[union-attr]
        side.plot([R * k, (end - R) * k], [z_top * k] * 2, "k--", lw=1, label="clearance")
        for x in (R, end - R):
            side.axvline(x * k, color="k", ls=":", lw=1)
        angle = np.linspace(0.0, 2.0 * np.pi, 100)
        for pose in (move.pose_from, move.pose_to):  # type: ignore[union-attr]
            plan.plot((pose[0] + R * np.cos(angle)) * k, (pose[1] + R * np.sin(angle)) * k, "k:", lw=1)
        ends = np.array([move.pose_from[:2], move.pose_to[:2]]) * k  # type: ignore[union-attr]
        plan.plot(ends[:, 0], ends[:, 1], "k--", lw=1)
    cell = getattr(move, "cell", None)
    if cell is not None:
        _draw_cell(side, plan, cell, start, direction / norm, k)
    side.set(xlabel=f"along the traverse [{Ln}]", ylabel=f"z [{Ln}]", title="side view (tool path)")
    side.legend(fontsize="small")
    plan.plot([0.0], [0.0], "k+", ms=12)
    plan.set(xlabel=f"x [{Ln}]", ylabel=f"y [{Ln}]", title="plan view (J1 axis at +)", aspect="equal")
    quantities = [("|qd| / vmax", np.abs(qd) / np.array(lim.velocity)),
                  ("|qdd| / amax", np.abs(qdd) / np.array(lim.acceleration))]  # fmt: skip
    if move.jerk is not None:
        quantities.append(("|qddd| / jmax", np.abs(_jerk(traj, t)) / np.array(move.jerk)))
    # the cycle always respects the effort limits (a robot's are always known): the loaded arm's efforts, RNEA
    tau = joint_torques(with_payload(robot, move.payload), q, qd, qdd)
    quantities.append((TORQUE_LABEL, np.abs(tau) / np.array(lim.effort)))
    for k, (name, ratio) in enumerate(quantities):
        ax = fig.add_subplot(grid[1 + k, :])
        for j in range(4):
            ax.plot(t, ratio[:, j], color=COLORS[j], label=robot.joint_names[j])
        ax.axhline(1.0, color="k", ls="--", lw=1)
        for leg in move.legs:
            ax.axvline(leg.t_start, color="0.85", lw=0.8, zorder=0)
        ax.set(ylabel=name, ylim=(0.0, 1.1))
        ax.legend(fontsize="small", ncol=4, loc="upper right")
    ax.set_xlabel("t [s]")
    if title:
        fig.suptitle(title)
    return finish(fig, path, dpi)


def _draw_cell(side: Any, plan: Any, cell: Cell, start: np.ndarray, u: np.ndarray, k: float) -> None:
    """The obstacles of a cell, drawn on the cycle's side and plan views.

    In plan view, their outline (the convex hull of the shape's points: a circle for a vertical cylinder or a
    sphere); in the side view, the box they span along the traverse and in z.
    """
    from matplotlib.patches import Polygon, Rectangle

    for i, o in enumerate(cell.obstacles):
        shape = o.shape
        pts = shape_points(shape)
        outline = hull(pts[:, :2])
        label = "obstacles" if i == 0 else None
        plan.add_patch(Polygon(outline * k, closed=True, facecolor="0.75", edgecolor="0.35", lw=1, label=label))
        plan.annotate(o.name, shape.xyz[:2] * k, fontsize="x-small", ha="center", va="center")
        along = (pts[:, :2] - start) @ u
        side.add_patch(Rectangle((along.min() * k, pts[:, 2].min() * k), float(np.ptp(along)) * k,
                                 float(np.ptp(pts[:, 2])) * k, facecolor="0.85", edgecolor="0.35", lw=1, zorder=0,
                                 label=label))  # fmt: skip
    side.autoscale_view()
    plan.autoscale_view()


def _jerk(traj: Trajectory, t: np.ndarray) -> np.ndarray:
    """Joint jerk at times t: each piece's own (a jump's polynomial), else the motions' chain rule."""
    from ..motion.cycle import trajectory_jerk
    from ..motion.polynomial import PolynomialPiece
    from ..motion.verify import pieces_jerk

    if not all(isinstance(p, PolynomialPiece) for p in traj.pieces):
        return trajectory_jerk(traj, t)
    return pieces_jerk(traj, t)
