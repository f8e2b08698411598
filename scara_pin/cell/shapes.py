"""The shapes of a cell: boxes, cylinders, spheres and meshes, placed in a frame, as coal geometries.

A :class:`Shape` is URDF's ``<geometry>`` with its ``<origin>``: ``xyz`` is the shape's centre (a mesh's
origin), ``rpy`` its orientation (fixed-axis roll, pitch, yaw as in URDF, ``R = Rz(yaw) Ry(pitch)
Rx(roll)``); a box is ``size = (x, y, z)`` (full edges), a cylinder ``(radius, length)`` along its own z
axis, centred, a sphere ``(radius,)``. A mesh holds its triangles (vertices already scaled, in metres).

Every number is checked here, where the shape is made: finite, sizes > 0 and at most :data:`MAX_SIZE`,
positions within :data:`MAX_POSITION`, at most :data:`~scara_pin.limits.MAX_CELL_TRIANGLES` triangles.
Distances are coal's (``coal.Box``, ``coal.Cylinder``, ``coal.Sphere``; a closed convex mesh is its hull, a
``coal.Convex``, a solid, whatever its winding or scale sign; an open mesh a ``BVHModelOBBRSS`` of its triangles,
a surface: see :mod:`scara_pin.cell.scene`, which refuses a closed mesh that is not convex).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError

__all__ = ["KINDS", "MAX_POSITION", "MAX_SIZE", "MIN_SIZE", "Shape", "hull", "rpy_matrix"]

KINDS = ("box", "cylinder", "sphere", "mesh")
"""The shapes a cell may hold."""
MAX_SIZE = 100.0
"""[m] the largest edge, radius or length of a shape (a cell is a few metres across)."""
MIN_SIZE = 1e-6
"""[m] the smallest one (below, coal's tolerances dominate the distance)."""
MAX_POSITION = 1000.0
"""[m] the largest coordinate of a shape's centre in the robot's base frame."""
_SIZE_NAMES = {"box": ("x", "y", "z"), "cylinder": ("radius", "length"), "sphere": ("radius",)}
_HULL_POINTS = 20_000
"""Points whose hull is built as they are (more: snapped to a grid first, :func:`hull`)."""
_CONVEX_TOL = 1e-6
"""A closed mesh whose volume is within this fraction of its convex hull's is convex (its hull is then the solid
checked: it holds the mesh, so a distance to it is never larger than to the mesh)."""


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """URDF's rotation of (roll, pitch, yaw): ``Rz(yaw) Ry(pitch) Rx(roll)``."""
    return np.asarray(pin.rpy.rpyToMatrix(float(rpy[0]), float(rpy[1]), float(rpy[2])))


@dataclass(frozen=True, eq=False)
class Shape:
    """A primitive or a mesh, placed in a frame.

    Attributes:
        kind: ``"box"``, ``"cylinder"``, ``"sphere"`` or ``"mesh"``.
        size: box (x, y, z) full edges; cylinder (radius, length); sphere (radius,); mesh () [m].
        xyz: (3,) the centre (a mesh's origin) in the frame [m].
        rpy: (3,) roll, pitch, yaw [rad].
        vertices: (N, 3) a mesh's vertices in its own frame, scale applied [m]; None for a primitive.
        faces: (M, 3) a mesh's triangles (vertex indices); None for a primitive.
        source: a mesh's file as the user named it ("" for a primitive).
        what: how to name the shape in messages ("obstacle post", "the carried part").
    """

    kind: str
    size: tuple[float, ...]
    xyz: np.ndarray
    rpy: np.ndarray
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    source: str = ""
    what: str = "shape"
    rotation: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InvalidInputError(f"{self.what}: shape {str(self.kind)[:40]!r} must be one of {', '.join(KINDS)}")
        xyz = _finite_vector(self.what, "xyz", self.xyz, 3, MAX_POSITION)
        rpy = _finite_vector(self.what, "rpy", self.rpy, 3, 1e3)
        object.__setattr__(self, "xyz", xyz)
        object.__setattr__(self, "rpy", rpy)
        object.__setattr__(self, "rotation", rpy_matrix(rpy))
        if self.kind == "mesh":
            self._check_mesh()
            return
        names = _SIZE_NAMES[self.kind]
        if len(self.size) != len(names):
            raise InvalidInputError(f"{self.what}: a {self.kind} has {len(names)} size value(s) "
                                    f"({', '.join(names)}), got {len(self.size)}")  # fmt: skip
        sizes = []
        for name, value in zip(names, self.size):
            v = float(value)
            if not (math.isfinite(v) and MIN_SIZE <= v <= MAX_SIZE):
                raise InvalidInputError(f"{self.what}: {self.kind} {name} {v:.6g} m must be finite, in "
                                        f"[{MIN_SIZE:g}, {MAX_SIZE:g}] m")  # fmt: skip
            sizes.append(v)
        object.__setattr__(self, "size", tuple(sizes))

    def _check_mesh(self) -> None:
        from ..limits import MAX_CELL_TRIANGLES, check_count

        if self.vertices is None or self.faces is None:
            raise InvalidInputError(f"{self.what}: a mesh needs its vertices and faces")
        v = np.asarray(self.vertices, dtype=float)
        f = np.asarray(self.faces)
        check_count(f"triangles of {self.what}", len(f), MAX_CELL_TRIANGLES)
        if v.ndim != 2 or v.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3 or not len(f):
            raise InvalidInputError(f"{self.what}: the mesh holds no triangles")
        if not np.isfinite(v).all() or np.abs(v).max() > MAX_SIZE:
            raise InvalidInputError(f"{self.what}: mesh vertices must be finite and within {MAX_SIZE:g} m of its "
                                    "origin (scale applied)")  # fmt: skip
        if f.min() < 0 or f.max() >= len(v):
            raise InvalidInputError(f"{self.what}: a mesh triangle names a vertex that does not exist")
        if float(np.ptp(v, axis=0).max()) < MIN_SIZE:
            raise InvalidInputError(f"{self.what}: the mesh is smaller than {MIN_SIZE:g} m (scale?)")
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "faces", f.astype(np.int64))
        object.__setattr__(self, "size", ())

    # ------------------------------------------------------------------ placement and geometry
    def placement(self) -> pin.SE3:
        """``frameMshape``: the shape's placement in its frame."""
        return pin.SE3(self.rotation, self.xyz)

    def grown(self, by: float) -> Shape:
        """The shape made ``by`` [m] larger all round, holding every point within ``by`` of it.

        A box's edges + 2 by, a cylinder's radius + by and length + 2 by, a sphere's radius + by: exact on the
        faces, a little more at a box's and a cylinder's edges and corners (sound, never short).

        Raises:
            InvalidInputError: a mesh (no sound growth of any triangle soup), or ``by`` < 0.
        """
        if not (math.isfinite(by) and by >= 0.0):
            raise InvalidInputError(f"{self.what}: a growth of {by!r} m must be finite and >= 0")
        if by == 0.0:
            return self
        if self.kind == "mesh":
            raise InvalidInputError(f"{self.what}: a mesh takes the cell's margin (a margin of its own needs a box, a "
                                    "cylinder or a sphere)")  # fmt: skip
        if self.kind == "box":
            size: tuple[float, ...] = tuple(v + 2.0 * by for v in self.size)
        elif self.kind == "cylinder":
            size = (self.size[0] + by, self.size[1] + 2.0 * by)
        else:
            size = (self.size[0] + by,)
        return Shape(self.kind, size, self.xyz, self.rpy, what=self.what)

    def moved(self, frameMshape: pin.SE3, what: str | None = None) -> Shape:
        """The same shape placed at ``frameMshape * self.placement()`` (e.g. a carried box put down)."""
        M = frameMshape * self.placement()
        rpy = np.asarray(pin.rpy.matrixToRpy(M.rotation))
        return Shape(self.kind, self.size, M.translation.copy(), rpy, self.vertices, self.faces, self.source,
                     what or self.what)  # fmt: skip

    def geometry(self, *, solid: bool = False) -> Any:
        """The coal collision geometry (a new object).

        A mesh: its hull when it is closed and convex (a solid), else the bounding-volume tree of its triangles (a
        surface); with ``solid``, its hull whatever it is (the carried part: a part held is a solid, and its hull
        holds it, so no collision is missed; a query on a hull costs microseconds where one on a tree of 199,000
        triangles cost 0.2 s).
        """
        if self.kind == "box":
            return coal.Box(*self.size)
        if self.kind == "cylinder":
            return coal.Cylinder(self.size[0], self.size[1])
        if self.kind == "sphere":
            return coal.Sphere(self.size[0])
        assert self.vertices is not None and self.faces is not None  # noqa: S101 - checked in __post_init__
        if solid or self.convex:  # a closed convex mesh is its own hull: GJK on it (a solid, signed distances, fast)
            return hull(self.vertices)
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(self.faces), len(self.vertices))
        bvh.addVertices(self.vertices)
        bvh.addTriangles(self.faces)
        bvh.endModel()
        return bvh

    @property
    def convex(self) -> bool:
        """A mesh that is closed and convex: its distances are taken on its hull, a solid (:meth:`closure`)."""
        return self.kind != "mesh" or self.closure() == (True, True)

    @property
    def closed(self) -> bool:
        """A mesh whose triangles enclose a volume (each edge shared by exactly two), or any primitive."""
        return self.kind != "mesh" or self.closure()[0]

    def closure(self) -> tuple[bool, bool]:
        """(closed, convex) of a mesh, whatever the order of its triangles' vertices (its winding) and its scale's sign.

        Closed: watertight once shared vertices are merged (trimesh). Convex: closed, and its volume is its convex
        hull's (the winding made consistent first, so an inverted or mirrored mesh, ``scale: -1``, is the same
        solid: it was taken for a hollow surface, and a robot inside a closed crate for clear). A primitive is both.
        """
        if self.kind != "mesh":
            return (True, True)
        found = self.__dict__.get("_closure")
        if found is None:
            import trimesh

            with warnings.catch_warnings(), np.errstate(all="ignore"):  # trimesh divides by a zero volume
                warnings.simplefilter("ignore")
                mesh = trimesh.Trimesh(self.vertices, self.faces, process=True)
                closed = bool(mesh.is_watertight)
                convex = False
                if closed:
                    if not mesh.is_winding_consistent:
                        trimesh.repair.fix_winding(mesh)
                    volume = abs(float(mesh.volume))
                    hull = float(mesh.convex_hull.volume)
                    convex = bool(volume > 0.0 and volume >= hull * (1.0 - _CONVEX_TOL))
            found = (closed, convex)
            object.__setattr__(self, "_closure", found)
        return found

    def corners(self) -> np.ndarray:
        """(k, 3) points whose convex hull holds the shape, in its frame (the box around it; a mesh's vertices)."""
        if self.kind == "mesh":
            assert self.vertices is not None  # noqa: S101
            local = self.vertices
        else:
            if self.kind == "box":
                half = np.array(self.size) / 2.0
            elif self.kind == "cylinder":
                half = np.array([self.size[0], self.size[0], self.size[1] / 2.0])
            else:
                half = np.full(3, self.size[0])
            local = half * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        return local @ self.rotation.T + self.xyz

    @property
    def triangles(self) -> int:
        """The number of triangles (0 for a primitive)."""
        return 0 if self.faces is None else len(self.faces)

    def describe(self) -> str:
        """A short description: ``cylinder r 0.02 m, length 0.2 m at (0.306, -0.052, -0.1)``."""
        at = ", ".join(f"{v:.6g}" for v in self.xyz)
        if self.kind == "mesh":
            return f"mesh {self.source} ({self.triangles} triangles) at ({at})"
        sizes = ", ".join(f"{n} {v:.6g}" for n, v in zip(_SIZE_NAMES[self.kind], self.size))
        return f"{self.kind} {sizes} m at ({at})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (a mesh by its file and triangle count)."""
        out: dict[str, Any] = {"shape": self.kind, "xyz": self.xyz.tolist(), "rpy": self.rpy.tolist()}
        if self.kind == "mesh":
            out.update(file=self.source, triangles=self.triangles)
        else:
            out.update(dict(zip(_SIZE_NAMES[self.kind], self.size)))
        return out


def hull(points: np.ndarray) -> Any:
    """The convex hull of ``points`` (a ``coal.Convex``) that holds them all, whatever they are.

    The hull's own vertices are found by qhull (in scipy) and handed to coal. coal keeps at most 255 neighbours per
    vertex of a hull (a finely tessellated ball's pole has more: its hull could not be built, an internal error),
    and a hull of 100,000 vertices costs seconds: more than ``_HULL_POINTS`` points, or a hull coal refuses, are
    snapped to a grid of spacing ``h`` (1/256 of their size, then coarser) first, and the hull of the snapped points
    is inflated by the snap's largest move, ``h sqrt(3) / 2`` (coal's swept-sphere radius): every point is within
    that of a snapped one, so the inflated hull holds the original (a distance to it is never larger). A flat set
    (qhull refuses it; coal would crash on it) is taken as its bounding box, thickened to :data:`MIN_SIZE`.
    """
    from scipy.spatial import ConvexHull, QhullError

    points = np.asarray(points, dtype=float)
    size = float(np.ptp(points, axis=0).max())
    for cells in (0, 256, 64, 16):
        snapped, radius = points, 0.0
        if cells:
            h = size / cells
            index = np.round((points - points.min(axis=0)) / h).astype(np.int64)  # 0 to cells on each axis
            keys = np.unique((index[:, 0] * (cells + 1) + index[:, 1]) * (cells + 1) + index[:, 2])  # one sort of ints
            index = np.column_stack([keys // (cells + 1) ** 2, keys // (cells + 1) % (cells + 1), keys % (cells + 1)])
            snapped = points.min(axis=0) + index * h
            radius = h * math.sqrt(3.0) / 2.0
        elif len(points) > _HULL_POINTS:
            continue
        try:
            corners = snapped[ConvexHull(snapped).vertices]
        except (QhullError, ValueError):  # flat: its box below
            break
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(0, len(corners))
        bvh.addVertices(corners)
        bvh.endModel()
        try:
            bvh.buildConvexHull(True, "Qt")
        except RuntimeError:  # too many neighbours
            continue
        convex = bvh.convex
        if radius:
            convex.setSweptSphereRadius(radius)
        return convex
    low, high = points.min(axis=0) - MIN_SIZE / 2, points.max(axis=0) + MIN_SIZE / 2
    return hull(np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])]))


def _finite_vector(what: str, name: str, value: Any, n: int, bound: float) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{what}: {name} must be {n} numbers") from None
    if arr.shape != (n,):
        raise InvalidInputError(f"{what}: {name} must be {n} numbers, got {arr.size}")
    if not np.isfinite(arr).all() or np.abs(arr).max() > bound:
        raise InvalidInputError(f"{what}: {name} must be {n} finite numbers within +/-{bound:g}")
    return arr
