"""Pictures of a job: its timeline, the cell and the growing stack, and a page that plays it.

:func:`plot_job` draws three panels over the job's time: the steps (a band per move, coloured by kind, its
target written when there is room; the dwells, picks and places left blank), then each joint's |velocity| /
limit and |acceleration| / limit, where the limit is the one the step ran under (the robot's times the step's
``speed`` or ``accel`` percentage). A move that is as fast as its limits allow touches 1 somewhere; a step
boundary is a thin grey line on every panel. A job in a cell, or one that places boxes, gets a plan view and a
side view above them: the tool path (orange while the tool holds the part, blue while empty), the cell's
obstacles and the boxes placed, numbered in the order placed. The side view looks along the base axis the boxes
(or the tool path) spread least along: the stack's rows and layers side by side.

:func:`job_page` writes the viewer page (:func:`~scara_pin.viz.meshcat.export_html`'s) that plays the job, with
the cell drawn by :func:`~scara_pin.viz.meshcat.draw_cell`: the obstacles, the part on the tool while it is held
and each box from the moment it is placed (the page's player shows a node only over its time spans:
``motion.shown``, ``[{path, spans: [[from, to], ...]}]``).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..description import JOINT_NAMES
from ..units import SI, DisplayUnits
from .plots import COLORS, LIMIT_GID, finish, hull, new_figure, shape_points

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..cell import Shape
    from ..job.results import JobResult
    from ..model import RobotModel

__all__ = ["BOX_COLOR", "CARRYING_COLOR", "EMPTY_COLOR", "KIND_COLORS", "OBSTACLE_COLOR", "job_page", "plot_job",
           "untangle"]

KIND_COLORS = {"jump": "#9ec5e8", "move": "#f5c48a", "go": "#b9dfa8"}
"""The band colour of each kind of move."""
_MAX_POINTS = 200_000
"""Samples drawn per curve at most (a long job is drawn at a lower rate)."""
_RATE = 1000.0
"""[Hz] the drawing rate of a job short enough."""
_PATH_RATE = 200.0
"""[Hz] the tool path's samples in the plan and side views (and the page's)."""
CARRYING_COLOR = "tab:orange"
"""The tool path while the tool holds the part."""
EMPTY_COLOR = "tab:blue"
"""The tool path while the tool is empty."""
OBSTACLE_COLOR = "0.78"
"""The cell's obstacles (grey)."""
BOX_COLOR = "#d9a066"
"""The boxes placed (cardboard)."""
_PAGE_BOX = (0.85, 0.63, 0.40)
"""The boxes on the page (cardboard, as :data:`BOX_COLOR`), RGB in [0, 1]."""


def plot_job(result: JobResult, path: str | os.PathLike[str] | None = None, *, robot: RobotModel,
             units: DisplayUnits = SI, title: str | None = None) -> Figure:  # fmt: skip
    """The timeline of a planned job (module docstring); written to ``path`` (PNG, SVG, PDF) when given.

    Args:
        result: the planned job.
        path: the file to write, or None.
        robot: the robot it was planned for (its limits).
        units: display units: the plan and side views' lengths (the timeline's axes are times and ratios).
        title: the figure's title (default: the job's file, robot, total and parts per hour).
    """
    traj = result.trajectory
    T = traj.duration
    n = int(min(max(T * _RATE, 2.0), _MAX_POINTS)) + 1
    t = np.linspace(0.0, T, n)
    _, qd, qdd = traj.sample(t)
    steps = result.steps
    starts = np.array([s.t_start for s in steps])
    k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(steps) - 1)
    speed = np.array([1.0 if s.speed is None else s.speed for s in steps])[k]
    accel = np.array([1.0 if s.accel is None else s.accel for s in steps])[k]
    v = np.abs(qd) / (np.asarray(robot.limits.velocity)[None, :] * speed[:, None])
    a = np.abs(qdd) / (np.asarray(robot.limits.acceleration)[None, :] * accel[:, None])
    views = result.cell is not None or bool(result.boxes)
    fig = new_figure(11.0, 11.5 if views else 6.5)
    bottom: Any = fig
    if views:
        parts: Any = fig.subfigures(2, 1, height_ratios=[5.0, 6.5])
        plan, side = parts[0].subplots(1, 2)
        _draw_views(plan, side, result, robot, units)
        bottom = parts[1]
    axes = bottom.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [0.6, 2.0, 2.0]})
    band, ax_v, ax_a = axes
    for s in steps:
        if s.duration <= 0.0:
            continue
        if s.kind in KIND_COLORS:
            band.axvspan(s.t_start, s.t_end, color=KIND_COLORS[s.kind], gid=f"step-{s.kind}")
            if s.duration > 0.025 * T:
                band.text(0.5 * (s.t_start + s.t_end), 0.5, s.target, ha="center", va="center", fontsize=7,
                          rotation=90 if s.duration < 0.06 * T else 0)  # fmt: skip
        for ax in axes:
            ax.axvline(s.t_end, color="0.75", linewidth=0.5)
    band.set_yticks([])
    band.set_ylim(0.0, 1.0)
    band.set_ylabel("steps", rotation=0, ha="right", va="center")
    for kind, color in KIND_COLORS.items():
        band.plot([], [], color=color, linewidth=8, label=kind)
    band.legend(loc="upper right", fontsize=7, ncol=3, frameon=False, bbox_to_anchor=(1.0, 1.55))
    for ax, ratio, what in ((ax_v, v, "velocity"), (ax_a, a, "acceleration")):
        for j in range(ratio.shape[1]):
            ax.plot(t, ratio[:, j], color=COLORS[j % len(COLORS)], linewidth=0.8, label=JOINT_NAMES[j])
        ax.axhline(1.0, color="k", linestyle="--", linewidth=1.0, gid=LIMIT_GID)
        ax.set_ylim(0.0, 1.1)
        ax.set_ylabel(f"|{what}| / limit")
        ax.grid(alpha=0.3)
    ax_v.legend(loc="upper right", fontsize=7, ncol=4)
    ax_a.set_xlabel("time [s]")
    ax_a.set_xlim(0.0, T)
    rate, boxes = result.parts_per_hour, result.boxes_per_hour
    if boxes is not None:
        rate_text = f", {len(result.boxes)} boxes, {boxes:,.0f} boxes per hour"
    else:
        rate_text = f", {result.places} places, {rate:,.0f} parts per hour" if rate is not None else ""
    fig.suptitle(title or f"{result.path.name} on {result.robot}: {T:.4f} s{rate_text}")
    if views:
        untangle(fig, (plan, side))
    return finish(fig, path)


def _tool_path(result: JobResult, robot: RobotModel) -> tuple[np.ndarray, np.ndarray]:
    """(poses (n, 4) of the tool, carrying (n,) bool) every 1 / :data:`_PATH_RATE` s and at every step's ends."""
    traj = result.trajectory
    T = traj.duration
    bounds = [v for s in result.steps for v in (s.t_start, s.t_end)]
    t = np.unique(np.clip(np.concatenate([np.linspace(0.0, T, int(min(T * _PATH_RATE, _MAX_POINTS)) + 2),
                                          bounds]), 0.0, T))  # fmt: skip
    q = traj.sample(t)[0]
    poses = np.array([robot.tool_pose(qk) for qk in q])
    starts = np.array([s.t_start for s in result.steps])
    k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(result.steps) - 1)
    carrying = np.array([s.carrying for s in result.steps])[k]
    return poses, carrying


def _draw_views(plan: Axes, side: Axes, result: JobResult, robot: RobotModel, units: DisplayUnits = SI) -> None:
    """The plan and side views of the job: obstacles, boxes placed (numbered), the tool path by gripper state.

    Lengths in ``units``. Labels at the same place in a view are one label (``1, 4``: boxes stacked in plan view,
    or in one line of sight in the side view), so that no two are written over each other.
    """
    from matplotlib.patches import Polygon, Rectangle

    k = units.scale("length")
    poses, carrying = _tool_path(result, robot)
    poses = poses * np.array([k, k, k, 1.0])
    shapes: list[tuple[Shape, str, str]] = []
    if result.cell is not None:
        shapes += [(o.shape, OBSTACLE_COLOR, o.name) for o in result.cell.obstacles]
    shapes += [(b.shape, BOX_COLOR, str(k + 1)) for k, b in enumerate(result.boxes)]
    centres = k * np.array([b.shape.xyz for b in result.boxes]) if result.boxes else poses[:, :3]
    across = int(np.argmin(np.ptp(centres[:, :2], axis=0)))  # the side view looks along this base axis
    along = 1 - across
    names = "xy"
    labels: dict[tuple[float, float], list[str]] = {}
    side_labels: dict[tuple[float, float], list[str]] = {}
    for shape, color, name in shapes:
        pts = k * shape_points(shape)
        xyz = k * np.asarray(shape.xyz, dtype=float)
        is_box = color == BOX_COLOR
        edge = "#8b5a2b" if is_box else "0.35"
        plan.add_patch(Polygon(hull(pts[:, :2]), closed=True, facecolor=color, edgecolor=edge, lw=0.8,
                               alpha=0.9 if is_box else 1.0, zorder=2 if is_box else 1))  # fmt: skip
        side.add_patch(Rectangle((pts[:, along].min(), pts[:, 2].min()), float(np.ptp(pts[:, along])),
                                 float(np.ptp(pts[:, 2])), facecolor=color, edgecolor=edge, lw=0.8,
                                 zorder=2 if is_box else 1))  # fmt: skip
        grain = 1e-3 * k  # positions within 1 mm: one label
        key = (round(float(xyz[along]) / grain) * grain, round(float(xyz[2]) / grain) * grain)
        side_labels.setdefault(key, []).append(name)  # one line of sight: "1, 4, 7" (the rows behind each other)
        if is_box:  # boxes stacked on each other share a label: "1, 4"
            key = (round(float(xyz[0]) / grain) * grain, round(float(xyz[1]) / grain) * grain)
            labels.setdefault(key, []).append(name)
        else:  # an obstacle's name inside its top edge, clear of the boxes on it
            plan.annotate(name, (float(xyz[0]), float(pts[:, 1].max())), fontsize=7, ha="center", va="top",
                          xytext=(0, -2), textcoords="offset points", zorder=4)  # fmt: skip
    for ax, found_at in ((plan, labels), (side, side_labels)):
        for (x, y), found in found_at.items():
            ax.annotate(_listed(found), (x, y), fontsize=7, ha="center", va="center", zorder=4, xytext=(0, 0),
                        textcoords="offset points")  # fmt: skip
    for ax, (i, j) in ((plan, (0, 1)), (side, (along, 2))):
        for state, color, label, style in ((False, EMPTY_COLOR, "tool, empty", "--"),
                                           (True, CARRYING_COLOR, "tool, holding the part", "-")):  # fmt: skip
            xy = np.where((carrying == state)[:, None], poses[:, [i, j]], np.nan)
            ax.plot(xy[:, 0], xy[:, 1], color=color, lw=1.2, ls=style, label=label, zorder=3 + int(state))
        ax.autoscale_view()
        ax.grid(alpha=0.3)
    plan.set_aspect("equal", adjustable="datalim")
    what = "the job"
    if result.boxes:  # the side view frames the stack: the boxes and the tool path above them
        pts = k * np.concatenate([shape_points(b.shape) for b in result.boxes])
        lo, hi = pts[:, along].min() - 0.25 * k, pts[:, along].max() + 0.25 * k
        near = (poses[:, along] >= lo) & (poses[:, along] <= hi)
        z_hi = max(float(pts[:, 2].max()), float(poses[near, 2].max(initial=-np.inf))) + 0.1 * k
        side.set_xlim(lo, hi)
        side.set_ylim(0.0 if pts[:, 2].min() >= 0.0 else float(pts[:, 2].min()) - 0.1 * k, z_hi)
        what = "the stack"
    side.set_aspect("equal", adjustable="box")
    plan.plot([0.0], [0.0], "k+", ms=10)
    L = units.length
    plan.set(xlabel=f"x [{L}]", ylabel=f"y [{L}]", title="plan view (J1 axis at +)")
    side.set(xlabel=f"{names[along]} [{L}]", ylabel=f"z [{L}]",
             title=f"side view of {what} (seen along {names[across]})")  # fmt: skip
    plan.legend(fontsize=7, loc="best")


def untangle(fig: Figure, axes: Sequence[Axes], rounds: int = 3) -> None:
    """Move the labels of ``axes`` that would be written over each other apart, up or down by whole line heights.

    The figure is drawn to measure them (their sizes on the page); a label moved keeps its place along the other
    axis. Drawn again until none overlaps (the layout may change as they move), at most ``rounds`` times.
    """
    for _ in range(rounds):
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
        moved = False
        for ax in axes:
            placed: list[Any] = []
            for text in ax.texts:
                box = text.get_window_extent(renderer)
                x0, y0 = getattr(text, "xyann", (0.0, 0.0))
                k = 0
                while any(box.overlaps(p) for p in placed) and k < 40 and hasattr(text, "xyann"):
                    k += 1
                    lines = (k + 1) // 2 * (1 if k % 2 else -1)  # +1, -1, +2, -2, ... line heights
                    text.xyann = (x0, y0 + lines * 1.15 * box.height * 72.0 / fig.dpi)
                    box = text.get_window_extent(renderer)
                    moved = True
                placed.append(box)
        if not moved:
            return


def _listed(names: list[str]) -> str:
    """Labels at one place as one: ``1, 4, 7``; a long list broken every 4 (it stays inside its box)."""
    rows = [", ".join(names[i : i + 4]) for i in range(0, len(names), 4)]
    return ",\n".join(rows)


# ---------------------------------------------------------------------------------------------- the page
def job_page(result: JobResult, robot: RobotModel, path: str | os.PathLike[str], *, rate: float = 200.0,
             units: DisplayUnits | None = None) -> None:
    """The viewer page that plays the job: the cell, the part on the tool while held, each box once placed.

    The cell is drawn by :func:`~scara_pin.viz.meshcat.draw_cell` (the job's obstacles, the boxes placed, the
    part on the tool); the page's player shows each box from the end of its place step and the part while it is
    held (``motion.shown``).

    Args:
        result: the planned job.
        robot: the robot it was planned for.
        path: the HTML file to write (atomically).
        rate: [Hz] the samples handed to the page (it interpolates between them).
        units: the units the page opens in (its switch: mm and deg, or m and rad); None: mm and deg.
    """
    from ..cell import Cell
    from ..files import write_text_atomic
    from .scene import CELL_NODE, recorded_scene

    traj = result.trajectory
    samples = traj.resample(min(rate, 1e5 / max(traj.duration, 1e-9)))
    ends = {s.target: traj.sample(s.t_end)[0] for s in result.steps if s.kind in ("jump", "move", "go")}
    targets = np.array([robot.tool_pose(q) for q in ends.values()]) if ends else None
    boxes = tuple(b.obstacle for b in result.boxes)
    cell = None
    if result.cell is not None or result.boxes or result.carry is not None:
        base = result.cell if result.cell is not None else Cell(origin="the job's boxes")
        cell = base.with_obstacles(boxes).with_carried(result.carry if result.carry is not None else base.carried)
    scene, data = recorded_scene(robot, None, samples.t, samples.q, targets=targets, cell=cell,
                                 target_names=list(ends) if ends else None)  # fmt: skip
    T = traj.duration
    shown: list[dict[str, object]] = []
    for b in result.boxes:
        node = f"{CELL_NODE}/{b.name}"
        scene.vis[node].set_property("color", [*_PAGE_BOX, 0.9])
        scene.vis[node].set_property("visible", False)
        shown.append({"path": f"meshcat/{node}", "spans": [[b.time, T + 1.0]]})
    if result.carry is not None:
        node = scene.carried_path
        scene.vis[node].set_property("color", [*_PAGE_BOX, 1.0])
        scene.vis[node].set_property("visible", False)
        held = [(s.t_start, s.t_end) for s in result.steps if s.carrying or (s.kind == "place")]
        shown.append({"path": f"meshcat/{node}", "spans": [list(span) for span in _merged(held)]})
    if shown and "motion" in data:
        data["motion"]["shown"] = shown
    if units is not None:
        data["units"] = "mm" if units.length == "mm" else "m"
    rate_text = f", {result.boxes_per_hour:,.0f} boxes per hour" if result.boxes else ""
    write_text_atomic(path, scene.page(f"scara-pin job {result.path.name}: {result.total:.4f} s{rate_text}", data))


def _merged(spans: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Touching or overlapping time spans joined."""
    out: list[tuple[float, float]] = []
    for t0, t1 in sorted(spans):
        if out and t0 <= out[-1][1] + 1e-12:
            out[-1] = (out[-1][0], max(out[-1][1], t1))
        else:
            out.append((t0, t1))
    return out
