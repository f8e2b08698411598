"""The shapes of a cell: boxes, cylinders, spheres and meshes, placed in a frame, as coal geometries.

A :class:`Shape` is URDF's ``<geometry>`` with its ``<origin>``: ``xyz`` is the shape's centre (a mesh's
origin), ``rpy`` its orientation (fixed-axis roll, pitch, yaw as in URDF, ``R = Rz(yaw) Ry(pitch)
Rx(roll)``); a box is ``size = (x, y, z)`` (full edges), a cylinder ``(radius, length)`` along its own z
axis, centred, a sphere ``(radius,)``. A mesh holds its triangles (vertices already scaled, in metres).

Every number is checked here, where the shape is made: finite, sizes > 0 and at most :data:`MAX_SIZE`,
positions within :data:`MAX_POSITION`, at most :data:`~scara_pin.limits.MAX_CELL_TRIANGLES` triangles.
Distances are coal's (``coal.Box``, ``coal.Cylinder``, ``coal.Sphere``; a closed convex mesh is its hull, a
``coal.Convex``, a solid; any other mesh a ``BVHModelOBBRSS`` of its triangles, a surface: see
:mod:`scara_pin.cell.scene`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError

if TYPE_CHECKING:
    import pinocchio as pin

__all__ = ["KINDS", "MAX_POSITION", "MAX_SIZE", "MIN_SIZE", "Shape", "rpy_matrix"]

KINDS = ("box", "cylinder", "sphere", "mesh")
"""The shapes a cell may hold."""
MAX_SIZE = 100.0
"""[m] the largest edge, radius or length of a shape (a cell is a few metres across)."""
MIN_SIZE = 1e-6
"""[m] the smallest one (below, coal's tolerances dominate the distance)."""
MAX_POSITION = 1000.0
"""[m] the largest coordinate of a shape's centre in the robot's base frame."""
_SIZE_NAMES = {"box": ("x", "y", "z"), "cylinder": ("radius", "length"), "sphere": ("radius",)}


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """URDF's rotation of (roll, pitch, yaw): ``Rz(yaw) Ry(pitch) Rx(roll)``."""
    import pinocchio as pin

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
        import pinocchio as pin

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
        import pinocchio as pin

        M = frameMshape * self.placement()
        rpy = np.asarray(pin.rpy.matrixToRpy(M.rotation))
        return Shape(self.kind, self.size, M.translation.copy(), rpy, self.vertices, self.faces, self.source,
                     what or self.what)  # fmt: skip

    def geometry(self) -> Any:
        """The coal collision geometry (a new object)."""
        import coal

        if self.kind == "box":
            return coal.Box(*self.size)
        if self.kind == "cylinder":
            return coal.Cylinder(self.size[0], self.size[1])
        if self.kind == "sphere":
            return coal.Sphere(self.size[0])
        assert self.vertices is not None and self.faces is not None  # noqa: S101 - checked in __post_init__
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(self.faces), len(self.vertices))
        bvh.addVertices(self.vertices)
        bvh.addTriangles(self.faces)
        bvh.endModel()
        if self.convex:  # a closed convex mesh is its own hull: GJK on it (a solid, signed distances, fast)
            bvh.buildConvexHull(True, "Qt")
            return bvh.convex
        return bvh

    @property
    def convex(self) -> bool:
        """A mesh that is closed and convex (trimesh's test): its distances are taken on its hull, a solid."""
        if self.kind != "mesh":
            return True
        found = self.__dict__.get("_convex")
        if found is None:
            import trimesh

            mesh = trimesh.Trimesh(self.vertices, self.faces, process=True)
            found = bool(mesh.is_watertight and mesh.is_convex)
            object.__setattr__(self, "_convex", found)
        return bool(found)

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
