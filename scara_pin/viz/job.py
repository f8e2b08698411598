"""The timeline of a job: its steps, and every joint's velocity and acceleration against the limits in force.

:func:`plot_job` draws three panels over the job's time: the steps (a band per move, coloured by kind, its
target written when there is room; the dwells left blank), then each joint's |velocity| / limit and
|acceleration| / limit, where the limit is the one the step ran under (the robot's times the step's
``speed`` or ``accel`` percentage). A move that is as fast as its limits allow touches 1 somewhere; a step
boundary is a thin grey line on every panel.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ..description import JOINT_NAMES
from ..units import SI, DisplayUnits
from .plots import COLORS, LIMIT_GID, finish, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..job.results import JobResult
    from ..model import Robot

__all__ = ["KIND_COLORS", "plot_job"]

KIND_COLORS = {"jump": "#9ec5e8", "move": "#f5c48a", "go": "#b9dfa8"}
"""The band colour of each kind of move."""
_MAX_POINTS = 200_000
"""Samples drawn per curve at most (a long job is drawn at a lower rate)."""
_RATE = 1000.0
"""[Hz] the drawing rate of a job short enough."""


def plot_job(result: JobResult, path: str | os.PathLike[str] | None = None, *, robot: Robot,
             units: DisplayUnits = SI, title: str | None = None) -> Figure:  # fmt: skip
    """The timeline of a planned job (module docstring); written to ``path`` (PNG, SVG, PDF) when given.

    Args:
        result: the planned job.
        path: the file to write, or None.
        robot: the robot it was planned for (its limits).
        units: display units (the timeline's axes are times and ratios: kept for the one plotting signature).
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
    fig = new_figure(11.0, 6.5)
    axes = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [0.6, 2.0, 2.0]})
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
    rate = result.parts_per_hour
    fig.suptitle(title or f"{result.path.name} on {result.robot}: {T:.4f} s"
                 + (f", {result.places} places, {rate:,.0f} parts per hour" if rate is not None else ""))  # fmt: skip
    return finish(fig, path)
