"""The plan-view region a SCARA's tool reaches WITHOUT COLLISION at one height, in its cell (a raster).

The exact workspace (:mod:`scara_pin.workspace.scara`) is the region the joint limits allow. In a cell, some
of it is lost: where every way of putting the tool there puts a link (or the carried part) closer than the
margin to an obstacle, or two links closer than the margin to each other. That set has no closed form (the
links sweep over obstacles of any shape), so it is sampled:

- a square grid in the base frame's plan, of spacing ``h`` (the resolution), its points at the centres of the
  grid's squares, covering the workspace's outline;
- at each point (x, y) and the height z, every IK branch (right and left elbow) whose solution is inside the
  joint limits (the closed form, :meth:`Robot.ik_batch <scara_pin.model.RobotModel.ik_batch>`), and the yaws below;
- a point is REACHABLE when some branch and yaw has a solution, FREE when some branch and yaw is also clear of
  the cell: every checked pair at least the margin apart (:func:`scara_pin.cell.sweep.clear_mask`: coal's
  distances, bounding spheres first).

**The yaw.** With a carried part, J4 is free: :data:`YAW_SAMPLES` yaws evenly over a turn are tried and the
point is free when one of them clears (the carried part turns with J4). Without one (the robot's own shapes on
J4 are usually round), one yaw is used, 0 unless given: the result says which.

**Area.** ``area`` is the number of free points times ``h^2``. Each point stands for its square; a square is
counted wrongly only if the region's boundary crosses it, so the error is at most the area of the band of
half-width ``h / sqrt(2)`` around the boundary: ``|area - exact| <= sqrt(2) h P`` for a boundary of length P
(plus the squares along the workspace's own outline). The grid has at most
:data:`~scara_pin.limits.MAX_WORKSPACE_GRID` points, refused before any work.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError, ParameterError
from ..limits import MAX_WORKSPACE_GRID, check_count
from ..units import SI, DisplayUnits
from .scara import Workspace, plot_workspace, workspace

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from ..cell import Cell
    from ..model import RobotModel

__all__ = ["DEFAULT_POINTS", "YAW_SAMPLES", "FreeRegion", "free_region", "plot_free_region"]

YAW_SAMPLES = 12
"""Yaws tried per point with a carried part (30 degrees apart)."""
DEFAULT_POINTS = 200
"""Grid points across the workspace's width when no resolution is given."""


@dataclass(frozen=True, eq=False, kw_only=True)
class FreeRegion:
    """Where the tool reaches without collision at one height (module docstring).

    Attributes:
        workspace: the exact workspace (its outline: the joint limits alone).
        cell: the cell.
        z: [m] the tool's height in the base frame.
        resolution: [m] the grid spacing h.
        x, y: (nx,), (ny,) the grid's coordinates [m] (points at the centres of its squares).
        reachable: (ny, nx) some branch and yaw has an IK solution inside the joint limits (row j: y[j]).
        free: (ny, nx) some such solution is also clear of the cell by its margin.
        yaws: the yaws tried [rad].
        yaw_free: True when the yaw was chosen per point (a carried part), False for one fixed yaw.
    """

    workspace: Workspace
    cell: Cell
    z: float
    resolution: float
    x: np.ndarray
    y: np.ndarray
    reachable: np.ndarray
    free: np.ndarray
    yaws: tuple[float, ...]
    yaw_free: bool

    @property
    def area(self) -> float:
        """[m^2] the free area: free points times h^2."""
        return float(self.free.sum()) * self.resolution**2

    @property
    def reachable_area(self) -> float:
        """[m^2] the reachable area on the same grid (compare with the exact ``workspace.area``)."""
        return float(self.reachable.sum()) * self.resolution**2

    @property
    def yaw_text(self) -> str:
        """How the yaw was chosen, in words."""
        if self.yaw_free:
            return (f"free: the first of {len(self.yaws)} yaws {360 / len(self.yaws):g} deg apart that clears (J4 "
                    "turns the carried part)")  # fmt: skip
        return f"{math.degrees(self.yaws[0]):.6g} deg at every point"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the grid (rows of 0/1 from the lowest y up), the areas and the resolution [SI]."""
        return {
            "height": self.z,
            "resolution": self.resolution,
            "area": self.area,
            "reachable_area": self.reachable_area,
            "workspace_area": self.workspace.area,
            "yaw": {"free": self.yaw_free, "values": list(self.yaws)},
            "grid": {"x": self.x.tolist(), "y": self.y.tolist(),
                     "free": self.free.astype(int).tolist(), "reachable": self.reachable.astype(int).tolist()},
            "cell": self.cell.to_dict(),
        }  # fmt: skip


def free_region(
    robot: RobotModel,
    cell: Cell,
    z: float,
    *,
    resolution: float | None = None,
    yaw: float | None = None,
) -> FreeRegion:
    """The plan-view region the tool reaches at height ``z`` with every checked pair clear (module docstring).

    Args:
        robot: a SCARA with a wrist (4 joints).
        cell: its cell.
        z: [m] the tool's height in the base frame (inside the J3 stroke).
        resolution: [m] the grid spacing (default: the workspace's width / :data:`DEFAULT_POINTS`).
        yaw: [rad] one yaw for every point (default: free with a carried part, else 0).

    Raises:
        InvalidInputError: not a 4-joint SCARA, z outside the stroke, a resolution that is not a positive
            number, or a grid above :data:`~scara_pin.limits.MAX_WORKSPACE_GRID` points.
    """
    from ..cell.scene import scene
    from ..cell.sweep import clear_mask

    if robot.kind != "scara" or robot.dof != 4:
        raise InvalidInputError(f"the collision-free region is for a 4-joint SCARA; robot {robot.name!r} is a "
                                f"{robot.dof}-joint {robot.kind}")  # fmt: skip
    z = float(z)
    if yaw is not None and not math.isfinite(yaw):
        raise ParameterError("yaw", yaw, "must be a finite number", "rad")
    offset = math.hypot(*robot.kinematics.geometry.tool) > 0
    ws = workspace(robot, yaw=0.0 if yaw is None else yaw) if offset and (yaw is not None or cell.carried is None) \
        else workspace(robot)  # fmt: skip
    z0, z1 = ws.z_range
    if not (math.isfinite(z) and z0 - 1e-12 <= z <= z1 + 1e-12):
        raise InvalidInputError(f"height {z:.9g} m is outside the J3 stroke: the tool's z is in [{z0:.6g}, {z1:.6g}] m")
    ax, ay = ws.geometry.a1[0] + ws.offset[0], ws.geometry.a1[1] + ws.offset[1]
    reach = ws.r_max + (math.hypot(*robot.kinematics.geometry.tool) if offset else 0.0)
    h = 2.0 * reach / DEFAULT_POINTS if resolution is None else float(resolution)
    if not (math.isfinite(h) and h > 0):
        raise ParameterError("resolution", h, "must be a finite number > 0", "m")
    n = math.ceil(2.0 * reach / h)
    check_count(f"grid points ({2 * reach:.6g} m across at {h:.6g} m, squared)", float(n) ** 2, MAX_WORKSPACE_GRID,
                "a coarser resolution")  # fmt: skip
    x = ax - 0.5 * n * h + (np.arange(n) + 0.5) * h
    y = ay - 0.5 * n * h + (np.arange(n) + 0.5) * h
    X, Y = np.meshgrid(x, y)
    P = np.column_stack([X.ravel(), Y.ravel()])
    yaw_free = yaw is None and cell.carried is not None
    yaws = tuple(2.0 * math.pi * k / YAW_SAMPLES for k in range(YAW_SAMPLES)) if yaw_free \
        else (0.0 if yaw is None else float(yaw),)  # fmt: skip
    sc = scene(robot, cell)
    reachable = np.zeros(len(P), dtype=bool)
    free = np.zeros(len(P), dtype=bool)
    for a in yaws:
        for branch in ("right", "left"):
            todo = np.flatnonzero(~free)
            if not len(todo):
                break
            targets = np.column_stack([P[todo], np.full(len(todo), z), np.full(len(todo), a)])
            res = robot.ik_batch(targets, branch=branch)
            ok = res.ok
            reachable[todo[ok]] = True
            rows = todo[ok]
            if len(rows):
                free[rows[clear_mask(sc, res.q[ok])]] = True
    return FreeRegion(workspace=ws, cell=cell, z=z, resolution=h, x=x, y=y, reachable=reachable.reshape(n, n),
                      free=free.reshape(n, n), yaws=yaws, yaw_free=yaw_free)  # fmt: skip


# ------------------------------------------------------------------------------------------ picture
def _triangles(cell_shape: Any) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (k, 3) in the base frame, faces) of a cell shape: a mesh's own, a primitive's by trimesh."""
    import trimesh

    s = cell_shape
    if s.kind == "mesh":
        v, f = np.asarray(s.vertices), np.asarray(s.faces)
    else:
        if s.kind == "box":
            m = trimesh.creation.box(extents=s.size)
        elif s.kind == "cylinder":
            m = trimesh.creation.cylinder(radius=s.size[0], height=s.size[1], sections=96)
        else:
            m = trimesh.creation.icosphere(subdivisions=3, radius=s.size[0])
        v, f = np.asarray(m.vertices), np.asarray(m.faces)
    return v @ s.rotation.T + s.xyz, f


def obstacle_outlines(cell: Cell, z: float) -> list[tuple[str, list[np.ndarray], np.ndarray]]:
    """Per obstacle: (name, its section at height z, its plan footprint).

    The section is a list of (2, 2) segments (empty when the obstacle does not cross z); the footprint the convex
    hull of its projection on the plan, (k, 2), closed.
    """
    import trimesh
    from scipy.spatial import ConvexHull

    out = []
    for o in cell.obstacles:
        v, f = _triangles(o.shape)
        mesh = trimesh.Trimesh(v, f, process=False)
        lines = trimesh.intersections.mesh_plane(mesh, plane_normal=[0.0, 0.0, 1.0], plane_origin=[0.0, 0.0, z])
        segments = [np.asarray(seg)[:, :2] for seg in lines]
        xy = v[:, :2]
        try:
            hull = xy[ConvexHull(xy).vertices]
        except Exception:  # noqa: BLE001 - a flat (vertical) shape: its projection is a segment
            hull = xy[[int(np.argmin(xy[:, 0] + xy[:, 1])), int(np.argmax(xy[:, 0] + xy[:, 1]))]]
        out.append((o.name, segments, np.vstack([hull, hull[:1]])))
    return out


def plot_free_region(
    region: FreeRegion,
    path: str | None = None,
    *,
    units: DisplayUnits = SI,
    robot_name: str | None = None,
    dpi: int = 120,
) -> Figure:
    """The free region over the exact workspace outline, the obstacles' sections at the height and footprints.

    Args:
        region: the region.
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        units: the length unit of the axes.
        robot_name: named in the title.
        dpi: resolution of a written PNG.
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from ..files import finish

    fig = plot_workspace(region.workspace, None, units=units, robot_name=robot_name, arm=False)
    ax = fig.axes[0]
    for patch in list(ax.patches):  # the reachable fill gives way to the raster
        patch.remove()
    h = region.resolution
    state = np.where(region.free, 2, np.where(region.reachable, 1, 0)).astype(float)
    state[state == 0] = np.nan
    extent = (region.x[0] - h / 2, region.x[-1] + h / 2, region.y[0] - h / 2, region.y[-1] + h / 2)
    ax.imshow(state, origin="lower", extent=extent, cmap=ListedColormap(["#f4a582", "#92c5de"]), vmin=1, vmax=2,
              interpolation="nearest", zorder=0, alpha=0.9)  # fmt: skip
    handles = [Patch(color="#92c5de", label="free (some branch clear of the cell)"),
               Patch(color="#f4a582", label="reachable, every branch in collision")]  # fmt: skip
    L, name = units.scale("length"), units.name("length")
    for i, (obstacle, segments, hull) in enumerate(obstacle_outlines(region.cell, region.z)):
        ax.plot(hull[:, 0], hull[:, 1], "--", color="dimgray", lw=1.0,
                label="obstacles' footprints (plan)" if i == 0 else None)  # fmt: skip
        if segments:
            ax.add_collection(LineCollection(segments, colors="black", linewidths=2.0))
        cx, cy = hull[:-1].mean(axis=0)
        ax.annotate(obstacle, (cx, cy), fontsize=7, ha="center", va="center")
    ax.plot([], [], "-", color="black", lw=2.0, label=f"sections at z = {region.z * L:.6g} {name}")
    ax.legend(handles=handles + ax.get_legend_handles_labels()[0], loc="upper center", bbox_to_anchor=(0.5, -0.08),
              ncol=2, fontsize=7, framealpha=0.8)  # fmt: skip
    head = f"{robot_name}: " if robot_name else ""
    A = L * L
    ax.set_title(f"{head}reachable without collision at z = {region.z * L:.6g} {name} ({region.cell.origin})\n"
                 f"free {region.area * A:.6g} {name}$^2$ of {region.workspace.area * A:.6g}, grid {h * L:.3g} {name}, "
                 f"margin {region.cell.margin * 1e3:g} mm", fontsize=9)  # fmt: skip
    ax.autoscale_view()
    return finish(fig, path, dpi, bbox_inches="tight")
