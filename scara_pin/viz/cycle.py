"""PNG picture of an arch move or cycle: tool path in side and plan view, joint rates against their limits.

Object-oriented matplotlib (a Figure on the Agg canvas, no pyplot, no global state), written atomically.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from .plots import finish

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..description import JointLimits
    from ..model import Robot
    from ..motion.cycle import ArchMove
    from ..motion.jump import JumpMove
    from ..motion.trajectory import Trajectory

__all__ = ["plot_cycle"]

_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
_LEG_COLORS = {"lift": "tab:gray", "blend up": "tab:purple", "traverse": "tab:blue", "blend down": "tab:purple",
               "descend": "tab:gray"}  # fmt: skip


def plot_cycle(
    robot: Robot,
    move: ArchMove | JumpMove,
    path: str | os.PathLike[str] | None = None,
    *,
    limits: JointLimits | None = None,
    title: str | None = None,
    rate: float = 2000.0,
    dpi: int = 110,
) -> Figure:
    """An arch move or cycle: the tool path, and the joint rates against their limits (written given a path).

    Side view (horizontal progress vs z) and plan view (x, y) with the legs coloured (blends in purple);
    for a jump, its clearance: the height z_top (dashed) outside the circles of radius R around the two poses
    (dotted), and the straight line between them in plan view; |qd|/vmax, |qdd|/amax (and |qddd|/jmax with
    a jerk limit) per joint against time, the limit at 1.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    lim = robot.limits if limits is None else limits
    traj = move.trajectory
    t = np.linspace(0.0, traj.duration, max(2, int(traj.duration * rate) + 1))
    q, qd, qdd = traj.sample(t)
    poses = np.array([robot.tool_pose(qk) for qk in q])
    rows = 3 if move.jerk is None else 4
    fig = Figure(figsize=(12.0, 2.8 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    grid = fig.add_gridspec(rows, 2)
    side, plan = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    start = poses[0, :2]
    direction = poses[np.argmax(np.linalg.norm(poses[:, :2] - start, axis=1)), :2] - start
    norm = float(np.linalg.norm(direction)) or 1.0
    progress = (poses[:, :2] - start) @ (direction / norm)
    for leg in move.legs:
        sel = (t >= leg.t_start) & (t <= leg.t_end)
        color = _LEG_COLORS.get(leg.name, "k")
        label = leg.name if leg.move == 0 else None
        side.plot(progress[sel] * 1e3, poses[sel, 2] * 1e3, color=color, lw=2, label=label)
        plan.plot(poses[sel, 0] * 1e3, poses[sel, 1] * 1e3, color=color, lw=2)
    R = getattr(move, "clearance_radius", None)
    if R is not None:  # the jump's clearance: z >= z_top wherever the tool is more than R from both ends
        z_top, end = move.z_top, float(np.hypot(*(move.pose_to[:2] - move.pose_from[:2])))  # type: ignore[union-attr]
        side.plot([R * 1e3, (end - R) * 1e3], [z_top * 1e3] * 2, "k--", lw=1, label="clearance")
        for x in (R, end - R):
            side.axvline(x * 1e3, color="k", ls=":", lw=1)
        angle = np.linspace(0.0, 2.0 * np.pi, 100)
        for pose in (move.pose_from, move.pose_to):  # type: ignore[union-attr]
            plan.plot((pose[0] + R * np.cos(angle)) * 1e3, (pose[1] + R * np.sin(angle)) * 1e3, "k:", lw=1)
        ends = np.array([move.pose_from[:2], move.pose_to[:2]]) * 1e3  # type: ignore[union-attr]
        plan.plot(ends[:, 0], ends[:, 1], "k--", lw=1)
    side.set(xlabel="along the traverse [mm]", ylabel="z [mm]", title="side view (tool path)")
    side.legend(fontsize="small")
    plan.plot([0.0], [0.0], "k+", ms=12)
    plan.set(xlabel="x [mm]", ylabel="y [mm]", title="plan view (J1 axis at +)", aspect="equal")
    quantities = [("|qd| / vmax", np.abs(qd) / np.array(lim.velocity)),
                  ("|qdd| / amax", np.abs(qdd) / np.array(lim.acceleration))]  # fmt: skip
    if move.jerk is not None:
        quantities.append(("|qddd| / jmax", np.abs(_jerk(traj, t)) / np.array(move.jerk)))
    for k, (name, ratio) in enumerate(quantities):
        ax = fig.add_subplot(grid[1 + k, :])
        for j in range(4):
            ax.plot(t, ratio[:, j], color=_COLORS[j], label=robot.joint_names[j])
        ax.axhline(1.0, color="k", ls="--", lw=1)
        for leg in move.legs:
            ax.axvline(leg.t_start, color="0.85", lw=0.8, zorder=0)
        ax.set(ylabel=name, ylim=(0.0, 1.1))
        ax.legend(fontsize="small", ncol=4, loc="upper right")
    ax.set_xlabel("t [s]")
    if title:
        fig.suptitle(title)
    return finish(fig, path, dpi)


def _jerk(traj: Trajectory, t: np.ndarray) -> np.ndarray:
    """Joint jerk at times t: each piece's own (a jump's polynomial), else the motions' chain rule."""
    from ..motion.cycle import trajectory_jerk
    from ..motion.polynomial import PolynomialPiece

    if not all(isinstance(p, PolynomialPiece) for p in traj.pieces):
        return trajectory_jerk(traj, t)
    out = np.zeros((len(t), traj.dof))
    for start, piece in zip(traj.starts.tolist(), traj.pieces):
        sel = (t >= start) & (t <= start + piece.duration)
        out[sel] = piece.jerk(t[sel] - start)  # type: ignore[attr-defined]
    return out
