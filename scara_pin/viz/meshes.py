"""The meshes of a robot's visuals: found like ROS finds them, read with trimesh, never fetched.

A URDF ``<mesh filename=... scale=...>`` names its file as ``package://pkg/path`` (looked up as
:mod:`scara_pin.description.packages` says: ``--package-path``, the folders above the robot's file,
``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``), ``file:///abs/path``, an absolute path or a path relative to
the robot's file. Rules:

- no network: any other scheme (``http://``, ``https://``, ...) is refused;
- no escape: the resolved file (symbolic links followed) must lie inside the package it names, or for
  other names inside one of the package folders searched or the robot file's folder; ``..`` that climbs
  out, and absolute paths elsewhere, are refused;
- STL, DAE (COLLADA) and OBJ are read with trimesh; ``scale`` is applied to the vertices.

A mesh that is refused, missing or unreadable is reported as one ``warning:`` naming the file; the viewer
keeps the placeholder box it draws for every mesh
(:func:`scara_pin.description.placeholders.placeholder_urdf`), never failing on it.

Pinocchio's geometry models of the robot (``robot.visual_model``) are built from
:func:`~scara_pin.description.placeholders.placeholder_urdf` (each mesh a small box at the mesh's origin), so Pinocchio
never reads a mesh file; :func:`visual_meshes` gives the real shapes, under Pinocchio's geometry names.
"""

from __future__ import annotations

import logging
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..description.mesh_paths import MeshProblem, resolve_mesh
from ..description.placeholders import PLACEHOLDER_SIZE

if TYPE_CHECKING:
    from ..model import Robot

__all__ = ["MAX_MESH_BYTES", "MeshProblem", "VisualMesh", "resolve_mesh", "visual_meshes"]

log = logging.getLogger(__name__)

MAX_MESH_BYTES = 200 * 1024 * 1024
"""[bytes] a mesh file larger than this is not read (a placeholder is drawn)."""
_FORMATS = {".stl": "stl", ".dae": "dae", ".obj": "obj"}


@dataclass(frozen=True)
class VisualMesh:
    """The shape of one visual of the robot.

    Attributes:
        name: Pinocchio's name of the visual geometry (``<link>_<index of the visual in the link>``).
        link: the link it belongs to.
        filename: the file name as written in the URDF.
        path: the file read.
        vertices: (N, 3) vertices in the visual's frame, ``scale`` applied [m].
        faces: (M, 3) vertex indices of the triangles.
    """

    name: str
    link: str
    filename: str
    path: Path
    vertices: np.ndarray
    faces: np.ndarray


def _scale(text: str | None, filename: str) -> np.ndarray:
    if text is None:
        return np.ones(3)
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) == 1:
        values *= 3
    if len(values) != 3 or not all(math.isfinite(v) and v != 0 for v in values):
        raise MeshProblem(f"mesh {filename!r}: scale {text!r} must be 3 finite nonzero numbers")
    return np.array(values)


def _load(path: Path, filename: str) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of a mesh file, or :class:`MeshProblem`."""
    kind = _FORMATS.get(path.suffix.lower())
    if kind is None:
        raise MeshProblem(f"mesh {filename!r}: {path.suffix or 'no'} extension: only STL, DAE and OBJ are read")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise MeshProblem(f"mesh {filename!r}: {path} cannot be read ({exc.strerror})") from None
    if size > MAX_MESH_BYTES:
        raise MeshProblem(f"mesh {filename!r}: {path} is {size / 2**20:.0f} MiB, over the "
                          f"{MAX_MESH_BYTES / 2**20:.0f} MiB read")  # fmt: skip
    import trimesh

    try:
        with path.open("rb") as handle:
            mesh: Any = trimesh.load(handle, file_type=kind, force="mesh")
        vertices = np.asarray(mesh.vertices, dtype=float)
        faces = np.asarray(mesh.faces, dtype=np.int64)
    except Exception as exc:  # trimesh and its readers raise many kinds of errors on a bad file
        raise MeshProblem(f"mesh {filename!r}: {path} cannot be read as {kind.upper()} "
                          f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]})") from None  # fmt: skip
    if vertices.ndim != 2 or vertices.shape[1:] != (3,) or faces.ndim != 2 or faces.shape[1:] != (3,) \
            or len(faces) == 0 or not np.isfinite(vertices).all():  # fmt: skip
        raise MeshProblem(f"mesh {filename!r}: {path} holds no triangles (or non-finite vertices)")
    return vertices, faces


def _mesh_elements(root: ET.Element) -> list[tuple[str, int, ET.Element, ET.Element]]:
    """(link, index of the visual in the link, the <geometry>, its <mesh>) of every mesh visual."""
    out = []
    for link in root.findall("link"):
        for i, visual in enumerate(link.findall("visual")):
            geometry = visual.find("geometry")
            mesh = geometry.find("mesh") if geometry is not None else None
            if geometry is not None and mesh is not None:
                out.append((link.get("name", ""), i, geometry, mesh))
    return out


def visual_meshes(robot: Robot) -> tuple[VisualMesh, ...]:
    """The meshes of the robot's visuals that can be read; one ``warning`` per one that cannot.

    Names are Pinocchio's geometry names (``robot.visual_model``), where the placeholder boxes are.
    """
    out = []
    for link, index, _geometry, mesh in _mesh_elements(ET.fromstring(robot.urdf)):
        filename = mesh.get("filename", "")
        try:
            if not filename:
                raise MeshProblem(f"a <mesh> of link {link} has no filename")
            scale = _scale(mesh.get("scale"), filename)
            path = resolve_mesh(filename, robot.package_path)
            if not path.is_file():
                raise MeshProblem(f"mesh {filename!r}: {path} does not exist")
            vertices, faces = _load(path, filename)
        except MeshProblem as exc:
            log.warning("%s; link %s is drawn as a %g m box", exc, link, PLACEHOLDER_SIZE)
            continue
        out.append(VisualMesh(f"{link}_{index}", link, filename, path, vertices * scale, faces))
    return tuple(out)
