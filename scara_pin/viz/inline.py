"""The robot in 3-D inside a notebook: meshcat's viewer, self-contained, in the output cell.

:func:`show` returns a :class:`SceneView`; Jupyter displays it (``_repr_html_``) as an iframe holding the
same self-contained page as ``scara-pin view --html`` (:func:`scara_pin.viz.meshcat.static_html`): the
robot at ``q``, joint sliders with the tool pose, and optionally a trajectory to play, the workspace and
the tool path. No server runs and nothing is fetched: the cell keeps working in a saved notebook and in
a static rendering of it. ``SceneView.save(path)`` writes the page to a file.

meshcat is imported inside :func:`show` only: importing this module costs nothing, and no solver module
imports it (the layers: viz sits above model, kinematics, workspace and motion).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import ParameterError
from ..files import write_text_atomic
from ..limits import MAX_FRAMES, check_count
from ..summary import Summarized
from .meshcat import static_html
from .scene import DEFAULT_FPS

if TYPE_CHECKING:
    from ..cell import Cell
    from ..model import RobotModel
    from ..motion.points import PointSet
    from ..motion.trajectory import Trajectory

__all__ = ["SceneView", "point_poses", "show", "workspace_polylines"]


@dataclass(frozen=True, repr=False)
class SceneView(Summarized):
    """A self-contained 3-D page of a robot, shown inline by Jupyter (``repr``: one line, not the page).

    Attributes:
        html: the page (meshcat's viewer script and the scene; about 1 MB).
        height: the height of the inline frame [px].
        title: the page title.
    """

    html: str
    height: int = 480
    title: str = "scara-pin"

    def summary(self, units: object = None) -> str:
        """One line: the title and the page's size (the page itself is ``.html``)."""
        return (f"SceneView {self.title!r}: a self-contained 3-D page of {len(self.html):,} characters (Jupyter shows "
                "it; .save(path) writes it)")  # fmt: skip

    def _repr_html_(self) -> str:
        from html import escape

        return (f'<iframe srcdoc="{escape(self.html, quote=True)}" title="{escape(self.title, quote=True)}" '
                f'style="width: 100%; height: {self.height}px; border: 1px solid #ccc;"></iframe>')  # fmt: skip

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the page to ``path`` (atomically); it opens offline from disk."""
        return write_text_atomic(path, self.html)


def workspace_polylines(robot: RobotModel) -> list[np.ndarray]:
    """The workspace boundary as the viewer draws it.

    A SCARA's boundary arcs on the floor ((M, 2) arrays of x, y [m]); a palletizer's envelope in 3-D ((M, 3)
    arrays: its arm-plane envelope at the waist limits, and the circles its extreme points sweep).
    """
    from ..workspace import Workspace, workspace_of

    ws = workspace_of(robot)
    if not isinstance(ws, Workspace):
        return list(ws.wireframe())
    return [arc.points(max(8, int(math.degrees(arc.sweep)))) for arc in ws.arcs]


def point_poses(robot: RobotModel, points: PointSet | str | os.PathLike[str]) -> tuple[np.ndarray | None, list[str]]:
    """The tool poses (P, 4) of taught points on ``robot`` and their names (a points file is read; pose points solved).

    Returns (None, []) for no points.
    """
    from ..motion.points import PointSet, TaughtPoint, read_points

    found = points if isinstance(points, PointSet) else read_points(Path(points), robot)
    resolved = found.resolved(robot)
    qs = [p.q for p in resolved if isinstance(p, TaughtPoint)]
    if not qs:
        return None, []
    return np.array([robot.tool_pose(q) for q in qs]), [p.name for p in resolved]


def show(
    robot: RobotModel,
    q: Any = None,
    *,
    trajectory: Trajectory | None = None,
    workspace: bool = False,
    height: int = 480,
    loop: bool = True,
    cell: Cell | None = None,
    points: PointSet | str | os.PathLike[str] | None = None,
) -> SceneView:
    """The robot in 3-D, for a notebook cell: ``scara_pin.viz.show(robot, q)`` as the cell's last line.

    Args:
        robot: the robot.
        q: the configuration shown [rad, m] (default: the trajectory's start, else q = 0).
        trajectory: a timed trajectory to play (the page's play / pause and time slider), its tool path drawn.
        workspace: draw the workspace boundary (SCARA: on the floor; palletizer: its envelope in 3-D).
        height: the height of the inline frame [px], 100..4000.
        loop: replay the trajectory forever (else once).
        cell: a cell (:func:`scara_pin.cell.load_cell`): its obstacles drawn and named, the part it carries on the
            tool.
        points: taught points (a :class:`~scara_pin.motion.points.PointSet` or a points file): each drawn as a
            small frame at its pose, named.

    Returns:
        a :class:`SceneView` (Jupyter shows it; ``.save(path)`` writes the page; ``.html`` is the page).

    Raises:
        ParameterError: a ``q`` that is not ``robot.dof`` finite numbers, or a height outside 100..4000.
    """
    if isinstance(height, bool) or not isinstance(height, int) or not 100 <= height <= 4000:
        raise ParameterError("height", height, "must be a whole number of pixels within [100, 4000]")
    times = qs = None
    if trajectory is not None:  # the frame count sized before any sample is made
        check_count(f"animation frames ({trajectory.duration:.6g} s at {DEFAULT_FPS} fps)",
                    trajectory.duration * DEFAULT_FPS + 2.0, MAX_FRAMES)  # fmt: skip
        times = np.linspace(0.0, trajectory.duration, max(2, int(math.ceil(trajectory.duration * DEFAULT_FPS)) + 1))
        qs = trajectory.sample(times)[0]
    polylines = workspace_polylines(robot) if workspace else None
    targets = names = None
    if points is not None:
        targets, names = point_poses(robot, points)
    title = f"scara-pin: {robot.name}"
    page = static_html(robot, q=None if q is None else robot.check_q(q), times=times, qs=qs, polylines=polylines,
                       targets=targets, loop=loop, title=title, cell=cell, target_names=names)  # fmt: skip
    return SceneView(page, height, title)
