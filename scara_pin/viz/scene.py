"""The robot as a meshcat scene: its tree of joint nodes, its meshes, and the overlays and the cell drawn on it.

:class:`MeshcatScene` builds it in a meshcat visualizer whose :class:`~scara_pin.viz.window.Window` sends to the
live viewer's server or only records; :func:`recorded_scene` fills a recorded scene with what a page shows. The
inputs are checked here (:func:`checked_motion`, :func:`tool_path`).
"""

from __future__ import annotations

import functools
import logging
import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..description.placeholders import PLACEHOLDER_SIZE
from ..errors import InvalidInputError
from ..limits import MAX_FRAMES, check_count
from .page import SHARE_GEOMETRY
from .window import Window, html_page, load_meshcat

if TYPE_CHECKING:
    from ..cell import Cell
    from ..cell.shapes import Shape
    from ..model import RobotModel

__all__ = ["CARRIED_COLOR", "CELL_NODE", "DEFAULT_FPS", "OBSTACLE_COLOR", "OVERLAYS", "PATH_COLOR", "ROBOT_NODE",
           "WORKSPACE_COLOR", "MeshcatScene", "checked_motion", "draw_meshes", "recorded_scene",
           "tool_path"]  # fmt: skip

log = logging.getLogger(__name__)

ROBOT_NODE = "robot"
"""The robot's node under meshcat's root: visuals in ``/meshcat/robot/visuals/<geometry>``, the tool frame's
triad in ``/meshcat/robot/frames/<tool frame>``."""

OVERLAYS = "overlays"  # the node of what is drawn over the robot: /meshcat/overlays/<name>
DEFAULT_FPS = 30
PATH_COLOR = 0x1E90FF  # dodger blue: the tool path
WORKSPACE_COLOR = 0x2E8B57  # sea green: the workspace boundary
_GRID_COLOR = 0x8C96A0  # grey blue: the floor grid
OBSTACLE_COLOR = 0x6A5ACD
"""Slate blue: a cell's obstacles (drawn three-quarters opaque)."""
CARRIED_COLOR = 0x20B2AA
"""Light sea green: the part the tool carries."""
_CELL_OPACITY = 0.75
CELL_NODE = "cell"
"""The cell's obstacles are under ``/meshcat/cell/<obstacle>``; the carried part is under the tool's joint node,
``<joint node>/cell_carried``, so it moves with the robot."""


def _tree_visualizer(robot: RobotModel, paths: list[str]) -> Any:
    """Pinocchio's ``MeshcatVisualizer`` (its geometry and mesh loaders), with tree node names.

    Each geometry's node is under its joint's node of the scene tree (``<joint path>/visuals/<geometry>``),
    instead of one flat group.
    """
    from pinocchio.visualize import MeshcatVisualizer

    class _TreeVisualizer(MeshcatVisualizer):  # type: ignore[misc]
        def getViewerNodeName(self, geometry_object: Any, geometry_type: Any) -> str:  # noqa: N802 - Pinocchio's
            group = "visuals" if geometry_type == pin.GeometryType.VISUAL else "collisions"
            return f"{paths[geometry_object.parentJoint]}/{group}/{geometry_object.name}"

    return _TreeVisualizer(robot.model, robot.collision_model, robot.visual_model)


def _resample(times: np.ndarray, qs: np.ndarray, fps: int) -> tuple[np.ndarray, np.ndarray]:
    """The motion on a grid of ``fps`` frames per second: (frame numbers, (F, 4) joint values).

    Joint values are interpolated linearly between samples; the last frame is the last sample.
    """
    if not (isinstance(fps, int) and 1 <= fps <= 1000):
        raise InvalidInputError(f"fps is {fps!r}; it must be a whole number of frames per second in [1, 1000]")
    duration = float(times[-1] - times[0])
    check_count(f"animation frames ({duration:.6g} s at {fps} fps)", duration * fps + 2.0, MAX_FRAMES,
                "shorten the motion")  # fmt: skip
    n = int(math.floor(duration * fps + 1e-9))
    frames = np.arange(n + 1, dtype=float)
    if duration * fps - n > 1e-9:
        frames = np.append(frames, duration * fps)
    grid = times[0] + frames / fps
    q = np.column_stack([np.interp(grid, times, qs[:, j]) for j in range(qs.shape[1])])
    return frames, q


def _width(value: object) -> int | None:
    """The number of columns of a 2-D array-like (None for anything else)."""
    shape = getattr(value, "shape", None)
    if shape is None:
        try:
            shape = np.shape(value)  # type: ignore[call-overload]
        except ValueError:  # ragged
            return None
    return int(shape[1]) if len(shape) == 2 else None


def _points(name: str, value: object, dim: int) -> np.ndarray:
    """``value`` as an (N, dim) float array of finite numbers, N >= 2, or raise InvalidInputError."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be an array of points of {dim} numbers") from None
    if arr.ndim != 2 or arr.shape[1] != dim or arr.shape[0] < 2:
        raise InvalidInputError(f"{name} must be at least 2 points of {dim} numbers (got shape {arr.shape})")
    if not np.isfinite(arr).all():
        row = int(np.argwhere(~np.isfinite(arr))[0, 0])
        raise InvalidInputError(f"{name}: point {row} is {arr[row].tolist()}; every value must be finite")
    return arr


def checked_motion(robot: RobotModel, times: object, qs: object,
                   rate: float = DEFAULT_FPS) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Check a sampled motion: (N,) strictly increasing finite times [s] and (N, dof) joint values.

    ``times`` may be a :class:`~scara_pin.motion.trajectory.Trajectory` instead (``qs`` None): it is sampled at
    ``rate`` [Hz], both ends included (the frame count checked against :data:`~scara_pin.limits.MAX_FRAMES`
    before any sample is made).
    """
    from ..motion.trajectory import Trajectory

    n = robot.dof
    if isinstance(times, Trajectory):
        if qs is not None:
            raise InvalidInputError("give a trajectory alone, or times and qs (not both)")
        duration = float(times.duration)
        check_count(f"frames ({duration:.6g} s at {rate:g} fps)", duration * rate + 2.0, MAX_FRAMES)
        t = np.linspace(0.0, duration, max(2, int(math.ceil(duration * rate)) + 1))
        qs = times.sample(t)[0]
        times = t
    elif qs is None:
        raise InvalidInputError(f"give a trajectory, or (N,) times [s] and (N, {n}) joint values qs")
    try:
        t = np.array(times, dtype=float)
        q = np.array(qs, dtype=float)
    except (TypeError, ValueError):
        raise InvalidInputError(f"times and qs must be numbers: (N,) times [s] and (N, {n}) joint values") from None
    if t.ndim != 1 or t.shape[0] < 1:
        raise InvalidInputError(f"times must be a 1-D array of at least one time [s] (got shape {t.shape})")
    if q.shape != (t.shape[0], n):
        raise InvalidInputError(f"qs must have shape ({t.shape[0]}, {n}), one row per time (got {q.shape})")
    if not np.isfinite(t).all():
        raise InvalidInputError("times must be finite")
    steps = np.diff(t)
    if (steps <= 0).any():
        k = int(np.argmax(steps <= 0))
        raise InvalidInputError(f"times must increase strictly: t[{k + 1}] = {t[k + 1]!r} s after t[{k}] = {t[k]!r} s")
    for row in q:
        robot.check_q(row)
    return t, q


def tool_path(robot: RobotModel, qs: object) -> np.ndarray:
    """(N, 3) positions of the tool frame in the base frame [m] along the joint values ``qs`` (N, 4)."""
    q = np.array(qs, dtype=float)
    if q.ndim != 2 or q.shape[1] != robot.dof:
        raise InvalidInputError(f"qs must have shape (N, {robot.dof}) (got {q.shape})")
    return np.array([robot.tool_placement(robot.check_q(row)).translation for row in q])


class _ShareGeometry:
    """The :data:`SHARE_GEOMETRY` command (meshcat's command interface: ``lower()``)."""

    def __init__(self, path: str, source: str) -> None:
        self.path, self.source = path, source

    def lower(self) -> dict[str, str]:
        return {"type": SHARE_GEOMETRY, "path": self.path, "source": self.source}


@functools.cache
def _scaled_mesh_class() -> Any:
    """Meshcat's triangle mesh geometry, with a visual's ``scale`` as the object's matrix.

    The vertices are sent as read (the file's unit applied), so one copy serves visuals of any scale.
    """
    mg = load_meshcat().geometry

    class ScaledMesh(mg.TriangularMeshGeometry):  # type: ignore[misc, name-defined]
        def __init__(self, vertices: np.ndarray, faces: np.ndarray, scale: tuple[float, float, float]) -> None:
            super().__init__(vertices, faces)
            self.scale = scale

        def intrinsic_transform(self) -> np.ndarray:
            return np.diag([*self.scale, 1.0])

    return ScaledMesh


_STAND_IN = (np.eye(3, dtype=np.float32) * PLACEHOLDER_SIZE, np.array([[0, 1, 2]], dtype=np.uint32))
"""The one triangle a sharing visual's object holds until the page gives it the shared geometry."""


def draw_meshes(vis: Any, robot: RobotModel, viz: Any, share: bool) -> None:
    """Set each readable mesh of the robot's visuals (:func:`scara_pin.cell.meshes.visual_meshes`) on its node.

    The scene drew a placeholder box for each mesh at the geometry's node (``viz.getViewerNodeName``, under
    its joint's node); the mesh replaces the box there, in the URDF's colour, its ``scale`` as the object's
    matrix. With ``share`` (a recorded page), a mesh named by several visuals is embedded once
    (:data:`SHARE_GEOMETRY`); else (meshcat's live server) each visual gets a copy, and the copies count
    against :data:`~scara_pin.limits.MAX_PAGE_MESH_BYTES` together.
    """
    from ..cell.meshes import visual_meshes
    from ..limits import MAX_PAGE_MESH_BYTES

    mg = load_meshcat().geometry
    scaled = _scaled_mesh_class()
    visuals = robot.visual_model
    drawn: dict[int, str] = {}  # id of a MeshGeometry -> the node path (lowered) holding its triangles
    sent = 0
    over: dict[str, list[str]] = {}  # the meshes whose copies went over the cap -> the links left as boxes
    for mesh in visual_meshes(robot):
        if not visuals.existGeometryName(mesh.name):
            continue
        geometry_object = visuals.geometryObjects[visuals.getGeometryId(mesh.name)]
        rgba = geometry_object.meshColor
        color = int(rgba[0] * 255) * 65536 + int(rgba[1] * 255) * 256 + int(rgba[2] * 255)
        material = mg.MeshPhongMaterial(color=color, opacity=float(rgba[3]), transparent=float(rgba[3]) < 1.0)
        node = vis[viz.getViewerNodeName(geometry_object, pin.GeometryType.VISUAL)]
        source = drawn.get(id(mesh.geometry)) if share else None
        if source is not None:
            node.set_object(scaled(*_STAND_IN, mesh.scale), material)
            node.window.send(_ShareGeometry(node.path.lower(), source))
            continue
        size = mesh.geometry.embedded_bytes
        if not share and sent + size > MAX_PAGE_MESH_BYTES:
            over.setdefault(mesh.filename, []).append(mesh.link)
            continue
        sent += size
        node.set_object(scaled(mesh.geometry.vertices, mesh.geometry.faces, mesh.scale), material)
        drawn[id(mesh.geometry)] = node.path.lower()
    for filename, links in over.items():
        log.warning("mesh %r: %d of its copies (links %s) would take the meshes sent over %.0f MiB, the cap; drawn "
                    "as %g m boxes", filename, len(links), ", ".join(sorted(set(links))),
                    MAX_PAGE_MESH_BYTES / 2**20, PLACEHOLDER_SIZE)  # fmt: skip


class MeshcatScene:
    """The robot and the overlays in a meshcat visualizer (live or recording).

    The robot is a tree of nodes under ``/meshcat/robot``: one node per joint, nested as the kinematic tree
    (``robot/joint1/joint2/...``), holding Pinocchio's ``liMi`` (see :mod:`scara_pin.viz.tree`); each
    link's geometries in ``<joint node>/visuals/<geometry>`` and the frames' triads in
    ``<joint node>/frames/<frame>``, at their constant placements. Showing a configuration sets the joint
    nodes' transforms only. The floor grid lies at z = 0 of the root link; the camera frames the workspace.
    """

    def __init__(self, robot: RobotModel, window: Window) -> None:
        from ..cell.meshes import check_visual_count
        from .tree import framing, joint_nodes, node_paths

        check_visual_count(robot)  # sized first: each visual is a node and a geometry of the page
        meshcat = load_meshcat()
        self.robot = robot
        self.vis = meshcat.Visualizer(window=window)
        self.joints = joint_nodes(robot, ROBOT_NODE)
        self.paths = node_paths(robot, ROBOT_NODE)
        self.carried_path = f"{self.paths[robot.model.frames[robot.tool_id].parentJoint]}/cell_carried"  # see CELL_NODE
        self.framing = framing(robot)
        self._data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, self._data, pin.neutral(robot.model))
        self.oMb: pin.SE3 = self._data.oMf[robot.base_id].copy()
        # scene size [m]: the robot's reach (axes and markers scale with it)
        self.size = max(0.05, self.framing.reach)
        self.viz = _tree_visualizer(robot, self.paths)
        self.viz.initViewer(viewer=self.vis)
        try:  # an unreadable geometry: the user's file, not a bug
            for geometry in robot.visual_model.geometryObjects:
                self._load_geometry(geometry)
        except (ValueError, RuntimeError, OSError) as exc:
            raise InvalidInputError(f"cannot show the robot's geometry: {' '.join(str(exc).split())}") from None
        # the real meshes in place of their placeholder boxes; a recorded page embeds each mesh once
        draw_meshes(self.vis, robot, self.viz, share=window.zmq_url is None)
        self.frame_paths: dict[str, str] = {}
        for frame_id in (robot.base_id, robot.tool_id):
            self._triad(frame_id, 0.25 * self.size)
        # the tool frame's zero-yaw rotation in the base frame: target markers are Rz(yaw) * R0
        zero = robot.tool_placement(np.zeros(robot.dof))
        yaw0 = math.atan2(zero.rotation[1, 0], zero.rotation[0, 0])
        self.tool_r0 = pin.utils.rotate("z", -yaw0) @ zero.rotation
        self.labels: dict[str, list[dict[str, Any]]] = {}  # the names the page writes over the scene, by group
        self._floor()
        self._camera()
        self.display(robot.default_q)

    def _load_geometry(self, geometry: pin.GeometryObject) -> None:
        """Load one visual geometry (primitive or mesh, by Pinocchio's loader) under its joint's node."""
        from pinocchio.visualize.meshcat_visualizer import applyScalingOnHomegeneousTransform

        self.viz.loadViewerGeometryObject(geometry, pin.GeometryType.VISUAL)
        path = self.viz.getViewerNodeName(geometry, pin.GeometryType.VISUAL)
        matrix = applyScalingOnHomegeneousTransform(geometry.placement.homogeneous, geometry.meshScale)
        self.vis[path].set_transform(matrix)

    def _triad(self, frame_id: int, length: float) -> None:
        """Draw a frame's axes (x red, y green, z blue) under its joint's node."""
        mg = load_meshcat().geometry
        frame = self.robot.model.frames[frame_id]
        path = f"{self.paths[frame.parentJoint]}/frames/{frame.name}"
        self.vis[path].set_object(mg.triad(length))
        self.vis[path].set_transform(frame.placement.homogeneous)
        self.frame_paths[frame.name] = path

    def _floor(self) -> None:
        """A grid on the floor (z = 0 of the root link), sized to the reach, instead of meshcat's 20 m one."""
        mg = load_meshcat().geometry
        cell, half = self.framing.grid_cell, self.framing.grid_half
        ticks = np.arange(-half, half + 0.5 * cell, cell)
        segments = []
        for t in ticks.tolist():
            segments += [[t, -half, 0.0], [t, half, 0.0], [-half, t, 0.0], [half, t, 0.0]]
        geometry = mg.PointsGeometry(np.ascontiguousarray(np.array(segments).T, dtype=np.float32))
        self.vis[f"{OVERLAYS}/floor"].set_object(mg.LineSegments(geometry, mg.LineBasicMaterial(color=_GRID_COLOR)))
        self.vis["/Grid"].set_property("visible", False)
        # meshcat's world axes are 0.5 m long whatever the robot: the base frame's triad shows the axes
        self.vis["/Axes"].set_property("visible", False)
        self.vis["/Background"].set_property("top_color", [0.97, 0.97, 0.98])
        self.vis["/Background"].set_property("bottom_color", [0.72, 0.76, 0.82])

    def _camera(self) -> None:
        """Frame the workspace from the front right, above (:func:`scara_pin.viz.tree.framing`).

        meshcat's orbit controls turn about the origin, so the live viewer's camera is placed to frame the
        workspace seen from there; the pages move the orbit target to the workspace's centre as well.
        """
        from .tree import FIELD_OF_VIEW

        f = self.framing
        target, position = np.array(f.target), np.array(f.position)
        # seen from the origin: the same direction, farther by the target's distance from the origin
        live = position - target
        live = live * (1.0 + float(np.linalg.norm(target)) / float(np.linalg.norm(live)))
        x, y, z = live.tolist()
        # the camera lives in /Cameras/default/rotated, turned by +pi/2 about x: scene (x, y, z) -> (x, z, -y)
        camera = self.vis["/Cameras/default/rotated/<object>"]
        camera.set_property("position", [x, z, -y])
        camera.set_property("fov", FIELD_OF_VIEW)

    def page_data(self) -> dict[str, Any]:
        """What the page's script needs: the joint nodes, the sliders' ranges and units, frames, camera."""
        robot = self.robot
        kinds = robot.joint_kinds
        f = self.framing
        return {
            "robot": robot.name,
            "root": f"meshcat/{ROBOT_NODE}",
            "joints": [
                {
                    "name": j.name,
                    "path": f"meshcat/{j.path}",
                    "kind": j.kind,
                    "axis": list(j.axis),
                    "placement": [x for row in j.placement for x in row],
                    "source": j.source,
                    "multiplier": j.multiplier,
                    "offset": j.offset,
                }
                for j in self.joints
            ],
            "sliders": [
                {
                    "name": j.name,
                    "index": j.source,
                    "lower": robot.limits.lower[j.source],
                    "upper": robot.limits.upper[j.source],
                    "unit": "m" if kinds[j.source] == "length" else "rad",
                    "continuous": robot.continuous[j.source],
                }
                for j in self.joints
                if j.actuated
            ],
            "base": f"meshcat/{self.frame_paths[robot.base_frame]}",
            "tool": f"meshcat/{self.frame_paths[robot.tool_frame]}",
            "base_frame": robot.base_frame,
            "tool_frame": robot.tool_frame,
            "target": list(f.target),
            "camera": list(f.position),
            "labels": [{"group": g, **item} for g, items in self.labels.items() for item in items],
        }

    def page(self, title: str, data: dict[str, Any] | None = None) -> str:
        """The scene as a self-contained page (:func:`~scara_pin.viz.window.html_page`), with the panel's ``data``."""
        return html_page(title, self.vis.window.recorder.commands(), data)

    def display(self, q: object) -> None:
        """Show the robot at the user's joint values ``q``: set every joint node's ``liMi``."""
        self._set_joints(self.vis, self.robot.to_pinocchio_q(q))  # continuous joints: their (cos, sin)

    def _set_joints(self, vis: Any, q_pin: np.ndarray) -> None:
        pin.forwardKinematics(self.robot.model, self._data, q_pin)
        for j in range(1, self.robot.model.njoints):
            vis[self.paths[j]].set_transform(self._data.liMi[j].homogeneous)

    def animation(self, times: np.ndarray, qs: np.ndarray, fps: int) -> Any:
        """Build a meshcat animation of the motion, ``fps`` frames per second.

        Joint values are interpolated linearly between the samples; three.js interpolates between frames.
        """
        meshcat = load_meshcat()
        frames, q = _resample(times, qs, fps)
        anim = meshcat.animation.Animation(default_framerate=fps)
        for frame, row in zip(frames.tolist(), q, strict=True):
            with anim.at_frame(self.vis, frame) as at:
                self._set_joints(at, self.robot.to_pinocchio_q(row))
        return anim

    def _world(self, points_base: np.ndarray) -> np.ndarray:
        """(N, 3) base-frame points -> (N, 3) scene (universe) points."""
        return points_base @ self.oMb.rotation.T + self.oMb.translation

    def _line(self, path: str, points_world: np.ndarray, color: int) -> None:
        mg = load_meshcat().geometry
        geometry = mg.PointsGeometry(np.ascontiguousarray(points_world.T, dtype=np.float32))
        self.vis[path].set_object(mg.Line(geometry, mg.LineBasicMaterial(color=color)))

    def draw_path(self, points: object, name: str, color: int) -> None:
        """Draw a line through (N, 3) points of the base frame [m] as the overlay ``name``."""
        pts = _points("points", points, 3)
        self._line(f"{OVERLAYS}/{name}", self._world(pts), color)

    def draw_targets(self, poses: object, name: str, names: Iterable[str] | None = None) -> None:
        """Target poses as triads oriented as the tool frame would be there: ``Rz(yaw) * R0``.

        ``names``: their labels, written beside them on the page (taught points).
        """
        mg = load_meshcat().geometry
        arr = np.array(poses, dtype=float)
        if arr.ndim == 1:
            arr = arr[None, :]
        if arr.ndim != 2 or arr.shape[1] != 4 or not np.isfinite(arr).all():
            raise InvalidInputError(f"poses must be finite (x, y, z, yaw) rows [m, rad] (got shape {arr.shape})")
        node = self.vis[f"{OVERLAYS}/{name}"]
        node.delete()
        for i, (x, y, z, yaw) in enumerate(arr.tolist()):
            bMt = pin.SE3(pin.utils.rotate("z", yaw) @ self.tool_r0, np.array([x, y, z]))
            node[str(i)].set_object(mg.triad(0.15 * self.size))
            node[str(i)].set_transform((self.oMb * bMt).homogeneous)
        if names is not None:
            texts = [str(n) for n in names]
            if len(texts) != len(arr):
                raise InvalidInputError(f"{len(texts)} names for {len(arr)} poses")
            self.labels[name] = [{"text": t, "xyz": row[:3]} for t, row in zip(texts, arr.tolist())]

    def draw_polylines(self, polylines: Iterable[object], name: str, z: float | None, color: int) -> None:
        """Draw (x, y) polylines at height ``z`` (None: the floor), or (x, y, z) ones; base frame [m]."""
        if isinstance(polylines, np.ndarray) and polylines.ndim == 2:
            polylines = [polylines]
        # (x, y) points, drawn at one height, or (x, y, z) points, drawn as given (base frame)
        checked = [_points(f"polyline {i}", p, 3 if _width(p) == 3 else 2) for i, p in enumerate(polylines)]
        # default height: the floor, z = 0 of the root link, expressed in the base frame
        zb = -float(self.oMb.translation[2]) if z is None else float(z)
        node = self.vis[f"{OVERLAYS}/{name}"]
        node.delete()
        for i, xy in enumerate(checked):
            pts = xy if xy.shape[1] == 3 else np.column_stack([xy, np.full(len(xy), zb)])
            self._line(f"{OVERLAYS}/{name}/{i}", self._world(pts), color)

    def draw_cell(self, cell: Cell) -> None:
        """Draw a cell: its obstacles, and the carried part on the tool (:func:`scara_pin.viz.meshcat.draw_cell`)."""
        mg = load_meshcat().geometry
        self.vis[CELL_NODE].delete()
        self.vis[self.carried_path].delete()
        self.labels[CELL_NODE] = []
        for o in cell.obstacles:
            material = mg.MeshLambertMaterial(color=OBSTACLE_COLOR, opacity=_CELL_OPACITY, transparent=True)
            self.vis[f"{CELL_NODE}/{o.name}"].set_object(_cell_object(o.shape), material)
            self.vis[f"{CELL_NODE}/{o.name}"].set_transform((self.oMb * o.shape.placement()).homogeneous)
            top = float(o.shape.corners()[:, 2].max())  # the name on its top face, in the base frame
            self.labels[CELL_NODE].append({"text": o.name, "xyz": [*map(float, o.shape.xyz[:2]), top]})
        if cell.carried is not None:
            tool = self.robot.model.frames[self.robot.tool_id]
            material = mg.MeshLambertMaterial(color=CARRIED_COLOR, opacity=1.0)
            self.vis[self.carried_path].set_object(_cell_object(cell.carried), material)
            self.vis[self.carried_path].set_transform((tool.placement * cell.carried.placement()).homogeneous)


def _cell_object(shape: Shape) -> Any:
    """A meshcat geometry of a cell shape, in the shape's own frame."""
    from pinocchio.visualize.meshcat_visualizer import loadPrimitive

    if shape.kind == "mesh":
        assert shape.vertices is not None and shape.faces is not None  # noqa: S101 - a mesh shape has them
        return load_meshcat().geometry.TriangularMeshGeometry(shape.vertices, shape.faces)
    return loadPrimitive(pin.GeometryObject("cell", 0, 0, pin.SE3.Identity(), shape.geometry()))


def recorded_scene(robot: RobotModel, q: object | None = None, times: object | None = None, qs: object | None = None,
                   polylines: Iterable[object] | None = None, path_points: object | None = None,
                   targets: object | None = None, *, draw_tool_path: bool = True, fps: int = DEFAULT_FPS,
                   loop: bool = True, cell: Cell | None = None, target_names: Iterable[str] | None = None
                   ) -> tuple[MeshcatScene, dict[str, Any]]:  # fmt: skip
    """Record a scene for a page (no server) from :func:`~scara_pin.viz.meshcat.export_html`'s arguments; its data too.

    ``target_names``: the targets' names (taught points), written beside them; the cell's obstacles are named too.

    A motion is not a meshcat animation here: the page's player interpolates the joint values (resampled at
    ``fps``) and moves the joints through the same code as the sliders.
    """
    scene = MeshcatScene(robot, Window())
    if (times is None) != (qs is None):
        raise InvalidInputError("times and qs go together: give both or neither")
    data = scene.page_data()
    shown = robot.default_q if q is None else robot.check_q(q)
    if polylines is not None:
        scene.draw_polylines(polylines, "workspace", None, WORKSPACE_COLOR)
    if path_points is not None:
        scene.draw_path(path_points, "path", PATH_COLOR)
    if targets is not None:
        scene.draw_targets(targets, "targets", target_names)
    if cell is not None:
        scene.draw_cell(cell)
    data["labels"] = scene.page_data()["labels"]
    if times is not None:
        t, qq = checked_motion(robot, times, qs)
        if q is None:
            shown = qq[0]
        if path_points is None and draw_tool_path and len(t) >= 2:
            scene.draw_path(tool_path(robot, qq), "path", PATH_COLOR)
        if len(t) >= 2:
            frames, grid = _resample(t, qq, fps)
            data["motion"] = {
                "times": (frames / fps).tolist(),
                "qs": grid.tolist(),
                "loop": bool(loop),
                "play": q is None,
            }
    scene.display(shown)
    data["q"] = [float(v) for v in shown]
    return scene, data
