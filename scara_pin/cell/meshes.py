"""The meshes of a robot's visuals: found like ROS finds them, read with trimesh, never fetched.

A URDF ``<mesh filename=... scale=...>`` names its file as ``package://pkg/path`` (looked up as
:mod:`scara_pin.description.packages` says: ``--package-path``, the folders above the robot's file,
``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``), ``file:///abs/path``, an absolute path or a path relative to
the robot's file. A mesh file is input like any other (it may come from a stranger). Rules:

- no network: any other scheme (``http://``, ``https://``, ...) is refused;
- no escape: the resolved file (symbolic links followed) must lie inside the package it names, or for
  other names inside one of the package folders searched or the robot file's folder; ``..`` that climbs
  out, and absolute paths elsewhere, are refused;
- regular files only, opened non-blocking and then checked (:func:`scara_pin.limits.open_regular`): a FIFO
  is never waited for;
- bounded bytes, counted AFTER decompression: a ``.dae`` may be a zip (``.zae``) or gzip archive; it is
  opened here, and at most :data:`~scara_pin.limits.MAX_MESH_BYTES` of it are decompressed (trimesh and
  pycollada never see the archive); an archive inside an archive is refused;
- only the mesh file is read: the materials (``.mtl``) and textures a mesh names are not (the viewer draws
  the URDF's colour), so none of them can block, or fill the memory;
- each file is read once, however many visuals name it, and the files of one robot are bounded together:
  at most :data:`~scara_pin.limits.MAX_PAGE_MESH_READ` bytes read and
  :data:`~scara_pin.limits.MAX_PAGE_MESH_BYTES` bytes of triangles kept (the meshes beyond are not drawn);
- STL, DAE (COLLADA) and OBJ are read with trimesh. A COLLADA file's ``<asset><unit meter="...">`` is
  honoured (its vertices are scaled to metres, as assimp and RViz do); STL and OBJ have no unit (metres);
- ``scale`` (the one number grammar of URDF numbers, 1 or 3 finite nonzero values) is checked with the
  geometry it produces: coordinates beyond :data:`MAX_MESH_COORDINATE`, or a mesh that float32 (the
  page's vertex type) collapses to a point, are refused; a mesh more than :data:`LARGE_RATIO` times the
  robot's size, or less than 1 / :data:`SMALL_RATIO` of it, is drawn with a warning (its units are
  probably wrong: a file in millimetres without ``scale="0.001 0.001 0.001"``).

A mesh that is refused, missing or unreadable is reported as one ``warning:`` naming the file (and the
links that name it); the viewer keeps the placeholder box it draws for every mesh
(:func:`scara_pin.description.placeholders.placeholder_urdf`), never failing on it. trimesh catches
``BaseException`` in places: a Ctrl-C or SIGTERM it swallows is raised again right after it returns
(:func:`scara_pin.signals.raise_pending`).

Pinocchio's geometry models of the robot (``robot.visual_model``) are built from
:func:`~scara_pin.description.placeholders.placeholder_urdf` (each mesh a small box at the mesh's origin),
so Pinocchio never reads a mesh file; :func:`visual_meshes` gives the real shapes, under Pinocchio's geometry names.
"""

from __future__ import annotations

import contextlib
import errno
import functools
import gzip
import io
import logging
import math
import os
import re
import xml.etree.ElementTree as ET
import zipfile
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .._checks import number_text
from ..description.mesh_paths import MeshProblem, mesh_file, resolve_mesh
from ..description.placeholders import PLACEHOLDER_SIZE
from ..errors import InvalidInputError
from ..limits import (
    MAX_MESH_BYTES,
    MAX_PAGE_MESH_BYTES,
    MAX_PAGE_MESH_READ,
    MAX_VISUALS,
    OutputIsInputError,
    UnreadableFileError,
    check_count,
    read_bytes,
)
from ..signals import raise_pending

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = [
    "LARGE_RATIO",
    "MAX_MESH_BYTES",
    "MAX_MESH_COORDINATE",
    "MeshProblem",
    "SMALL_RATIO",
    "MeshFile",
    "MeshGeometry",
    "MeshUse",
    "MeshUseError",
    "VisualMesh",
    "check_visual_count",
    "collision_meshes",
    "load_meshes",
    "parse_mesh",
    "read_mesh_file",
    "scaled",
    "resolve_mesh",
    "robot_size",
    "visual_meshes",
]

log = logging.getLogger(__name__)

MAX_MESH_COORDINATE = 1e6
"""[m] largest coordinate of a drawn mesh, scale applied: beyond, no robot part; float32 keeps 0.1 m there."""
LARGE_RATIO = 20.0
"""A mesh more than this many times the robot's size across is drawn with a warning (units?)."""
SMALL_RATIO = 1000.0
"""A mesh less than 1 / this of the robot's size across is drawn with a warning (units?)."""
_FORMATS = {".stl": "stl", ".dae": "dae", ".zae": "dae", ".obj": "obj"}
"""The file endings read, and their kind (``.zae``: a zipped COLLADA file, read like a ``.dae`` that is one)."""
_ZIP, _GZIP = b"PK\x03\x04", b"\x1f\x8b"
_SHOWN_LINKS = 3
"""Links named in one warning (a mesh named by many visuals is one warning)."""


@dataclass(frozen=True)
class MeshGeometry:
    """The triangles of one mesh file, read once whatever the number of visuals naming it.

    Attributes:
        path: the file read.
        vertices: (N, 3) vertices [m], the file's unit applied (COLLADA ``<unit>``), not a visual's scale.
        faces: (M, 3) vertex indices of the triangles.
        unit: [m] the length of one unit of the file (1 unless a COLLADA file says otherwise).
        bytes_read: bytes of the file read (after decompression).
        low: (3,) smallest coordinates of the vertices [m] (set from them).
        high: (3,) largest coordinates of the vertices [m] (set from them).
    """

    path: Path
    vertices: np.ndarray
    faces: np.ndarray
    unit: float = 1.0
    bytes_read: int = 0
    low: np.ndarray = field(init=False, repr=False, compare=False)
    high: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "low", self.vertices.min(axis=0))
        object.__setattr__(self, "high", self.vertices.max(axis=0))

    @property
    def embedded_bytes(self) -> int:
        """Bytes of the triangles in a page: float32 vertices and uint32 indices."""
        return 12 * len(self.vertices) + 12 * len(self.faces)


@dataclass(frozen=True)
class VisualMesh:
    """The shape of one visual of the robot.

    Attributes:
        name: Pinocchio's name of the visual geometry (``<link>_<index of the visual in the link>``).
        link: the link it belongs to.
        filename: the file name as written in the URDF.
        path: the file read.
        geometry: the file's triangles, shared by every visual that names the file.
        scale: the visual's ``scale`` (x, y, z).
    """

    name: str
    link: str
    filename: str
    path: Path
    geometry: MeshGeometry
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)

    @property
    def vertices(self) -> np.ndarray:
        """(N, 3) vertices in the visual's frame, unit and ``scale`` applied [m] (a new array)."""
        return self.geometry.vertices * np.asarray(self.scale)

    @property
    def faces(self) -> np.ndarray:
        """(M, 3) vertex indices of the triangles."""
        return self.geometry.faces


def mesh_scale(text: str | None, filename: str) -> tuple[float, float, float]:
    """A URDF ``<mesh scale="...">``: one number or three (the URDF number grammar), each finite and non-zero."""
    if text is None:
        return (1.0, 1.0, 1.0)
    values = [number_text(v) for v in text.split()]  # the URDF number grammar: no "1_0", no "nan"
    if len(values) == 1:
        values *= 3
    if len(values) != 3 or not all(math.isfinite(v) and v != 0 for v in values):
        raise MeshProblem(f"mesh {filename!r}: scale {text!r} must be 1 or 3 finite nonzero numbers")
    return (values[0], values[1], values[2])


def _decompressed(data: bytes, path: Path, filename: str) -> bytes:
    """A COLLADA file's XML: a zip (``.zae``) or gzip archive is opened here, bounded AFTER decompression."""
    if not data.startswith((_ZIP, _GZIP)):
        return data
    try:
        if data.startswith(_ZIP):
            with zipfile.ZipFile(io.BytesIO(data)) as archive:
                names = [n for n in archive.namelist() if n.upper().endswith(".DAE")]
                names.sort(key=lambda n: "MACOSX" in n)  # pycollada's choice: a .dae not under __MACOSX
                if not names:
                    raise MeshProblem(f"mesh {filename!r}: {path} is a zip archive holding no .dae file")
                with archive.open(names[0]) as member:
                    out = member.read(MAX_MESH_BYTES + 1)  # decompressed step by step: never more
        else:
            with gzip.GzipFile(fileobj=io.BytesIO(data)) as member:
                out = member.read(MAX_MESH_BYTES + 1)
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, RuntimeError, NotImplementedError) as exc:
        raise MeshProblem(f"mesh {filename!r}: {path} is a broken archive ({type(exc).__name__}: "
                          f"{' '.join(str(exc).split())[:200]})") from None  # fmt: skip
    if len(out) > MAX_MESH_BYTES:
        raise MeshProblem(f"mesh {filename!r}: {path} holds more than {MAX_MESH_BYTES / 2**20:.0f} MiB once "
                          "decompressed, the cap: not read")  # fmt: skip
    if out.startswith((_ZIP, _GZIP)):
        raise MeshProblem(f"mesh {filename!r}: {path} is an archive inside an archive: not read")
    return out


def _collada_unit(data: bytes, filename: str) -> float:
    """[m] the COLLADA document's unit: ``<COLLADA><asset><unit meter="..."/>`` (1 when absent).

    Only the start of the document is parsed (the ``<asset>``, its first element, per the schema).
    """
    depth = 0
    in_asset = False
    try:
        for event, element in ET.iterparse(io.BytesIO(data), events=("start", "end")):
            tag = element.tag.rsplit("}", 1)[-1] if isinstance(element.tag, str) else ""
            if event == "end":
                depth -= 1
                if depth == 1 and in_asset:
                    return 1.0
                continue
            depth += 1
            if depth == 2:
                if tag != "asset":
                    return 1.0
                in_asset = True
            elif depth == 3 and in_asset and tag == "unit":
                text = element.get("meter", "1")
                unit = number_text(text)
                if not (math.isfinite(unit) and unit > 0):
                    raise MeshProblem(f"mesh {filename!r}: COLLADA <unit meter={text!r}> must be a number > 0")
                return unit
    except ET.ParseError:
        pass  # trimesh's reader says what is wrong with the document
    return 1.0


@functools.cache
def _no_files() -> Any:
    """A trimesh resolver that reads nothing: the materials and textures a mesh names are not read."""
    import trimesh

    class NoFiles(trimesh.resolvers.Resolver):  # type: ignore[misc]
        def __init__(self) -> None:
            pass

        def get(self, key: str) -> bytes:
            raise OSError(f"{key}: scara-pin reads no material or texture file (the URDF's colour is drawn)")

        def write(self, name: str, data: Any) -> None:
            raise OSError("scara-pin writes no file through a mesh reader")

        def namespaced(self, namespace: str) -> Any:
            return self

        def keys(self) -> list[str]:
            return []

    return NoFiles()


@dataclass(frozen=True, eq=False)
class MeshFile:
    """The bytes of one mesh file, read (once) and decompressed, not yet parsed.

    Attributes:
        path: the file read.
        filename: how to name it in messages (as the user wrote it).
        kind: ``"stl"``, ``"dae"`` or ``"obj"``.
        data: its bytes (a zipped or gzipped COLLADA file: decompressed).
        unit: [m] the length of one unit of the file (a COLLADA ``<unit>``; 1 otherwise).
    """

    path: Path
    filename: str
    kind: str
    data: bytes
    unit: float = 1.0

    @property
    def triangles(self) -> int:
        """Triangles the file holds at least, counted from its header or its text WITHOUT parsing it.

        Exact for a binary STL (its header's count, which the file's size confirms) and an ASCII one (its
        ``endfacet`` lines); for an OBJ its face lines (a polygon is at least one triangle); for a COLLADA file the
        ``count`` of its ``<triangles>``, ``<polylist>``, ``<polygons>``, ``<tristrips>`` and ``<trifans>``.
        """
        data = self.data
        if self.kind == "stl":
            if len(data) >= 84:
                n = int.from_bytes(data[80:84], "little")
                if len(data) == 84 + 50 * n:
                    return n
            return data.count(b"endfacet") + data.count(b"ENDFACET")
        if self.kind == "obj":
            return sum(data.count(prefix) for prefix in (b"\nf ", b"\nf\t")) + data.startswith((b"f ", b"f\t"))
        return sum(int(n) for n in _COLLADA_COUNTS.findall(data))


_COLLADA_COUNTS = re.compile(
    rb"<(?:\w+:)?(?:triangles|polylist|polygons|tristrips|trifans)\b[^>]*?\scount\s*=\s*[\"'](\d{1,12})[\"']"
)
"""A COLLADA primitive's ``count`` attribute (its number of triangles, polygons or strips)."""


def read_mesh_file(path: Path, filename: str) -> MeshFile:
    """The bytes of a mesh file under this module's rules (regular file, bounded after decompression), not parsed.

    Raises:
        MeshProblem: an unknown ending, a missing, unreadable or oversized file, a broken archive.
        OutputIsInputError: the file is an output of the running command.
    """
    kind = _FORMATS.get(path.suffix.lower())
    if kind is None:
        raise MeshProblem(f"mesh {filename!r}: {path.suffix or 'no'} extension: only STL, DAE (ZAE) and OBJ are read")
    try:
        data = read_bytes(path, "mesh", MAX_MESH_BYTES)
    except UnreadableFileError as exc:
        if exc.errno == errno.ENOENT:
            raise MeshProblem(f"mesh {filename!r}: {path} does not exist") from None
        raise MeshProblem(f"mesh {filename!r}: {path} cannot be read ({exc.reason})") from None
    except OutputIsInputError:
        raise
    except InvalidInputError:
        raise MeshProblem(f"mesh {filename!r}: {path} is over the {MAX_MESH_BYTES / 2**20:.0f} MiB read") from None
    unit = 1.0
    if kind == "dae":
        data = _decompressed(data, path, filename)
        unit = _collada_unit(data, filename)
    return MeshFile(path, filename, kind, data, unit)


def parse_mesh(file: MeshFile) -> MeshGeometry:
    """The triangles of a mesh file read by :func:`read_mesh_file` (trimesh; no material or texture is read).

    A vertex that is not finite (NaN, inf, or beyond float32) refuses the file: it is never dropped with its
    triangles (a closed cube would become an open surface).

    Raises:
        MeshProblem: not a mesh of its kind, no triangles, a non-finite vertex.
    """
    import trimesh

    path, filename, kind = file.path, file.filename, file.kind
    try:
        log.debug("reading mesh %s (%d bytes)", path, len(file.data))
        mesh: Any = trimesh.load(io.BytesIO(file.data), file_type=kind, force="mesh", resolver=_no_files(),
                                 skip_materials=True, process=False)  # fmt: skip
        vertices = np.asarray(mesh.vertices, dtype=float)
        faces = np.asarray(mesh.faces, dtype=np.int64)
    except Exception as exc:  # trimesh and its readers raise many kinds of errors on a bad file
        raise_pending()
        raise MeshProblem(f"mesh {filename!r}: {path} cannot be read as {kind.upper()} "
                          f"({type(exc).__name__}: {' '.join(str(exc).split())[:200]})") from None  # fmt: skip
    raise_pending()  # a Ctrl-C or SIGTERM that trimesh swallowed (it catches BaseException)
    if vertices.ndim != 2 or vertices.shape[1:] != (3,) or faces.ndim != 2 or faces.shape[1:] != (3,) \
            or len(faces) == 0 or len(vertices) == 0:  # fmt: skip
        raise MeshProblem(f"mesh {filename!r}: {path} holds no triangles")
    vertices = vertices * file.unit
    if not np.isfinite(vertices.astype(np.float32)).all():
        raise MeshProblem(f"mesh {filename!r}: {path} holds non-finite vertices (NaN, inf, or beyond float32, "
                          "3.4e38)")  # fmt: skip
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshProblem(f"mesh {filename!r}: {path}: a triangle names a vertex that does not exist")
    merged = trimesh.Trimesh(vertices, faces, process=True)  # shared vertices merged, as trimesh.load would
    return MeshGeometry(path, np.asarray(merged.vertices, dtype=float), np.asarray(merged.faces, dtype=np.int64),
                        file.unit, len(file.data))  # fmt: skip


def _load(path: Path, filename: str) -> MeshGeometry:
    """The triangles of a mesh file (rules in the module docstring), or :class:`MeshProblem`."""
    return parse_mesh(read_mesh_file(path, filename))


def robot_size(robot: RobotModel) -> float:
    """[m] the robot's size: the diagonal of the box of its frames' origins at q = 0 (at least 5 cm).

    The yardstick of the meshes' plausibility: the links laid out end to end.
    """
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, pin.neutral(robot.model))
    points = np.array([f.translation for f in data.oMf])
    return max(0.05, float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))))


def _checked_size(geometry: MeshGeometry, scale: tuple[float, float, float], filename: str, size: float) -> str:
    """A warning when the scaled mesh's size is implausible against the robot's (else ""), or MeshProblem."""
    s = np.asarray(scale)
    corners = np.stack([geometry.low * s, geometry.high * s])
    reach = float(np.abs(corners).max())
    if not reach <= MAX_MESH_COORDINATE:
        raise MeshProblem(f"mesh {filename!r}: with scale {' '.join(f'{v:g}' for v in scale)} it reaches "
                          f"{reach:.3g} m from its origin, beyond {MAX_MESH_COORDINATE:g} m: not drawn")  # fmt: skip
    flat = corners.astype(np.float32)
    if np.all(flat[0] == flat[1]):
        raise MeshProblem(f"mesh {filename!r}: with scale {' '.join(f'{v:g}' for v in scale)} it collapses to a "
                          "point in float32 (the page's vertex type): not drawn")  # fmt: skip
    across = float(np.linalg.norm(corners[1] - corners[0]))
    advice = "check its units (a COLLADA <unit>, or scale=\"0.001 0.001 0.001\" for a file in mm)"
    if across > LARGE_RATIO * size:
        return (f"mesh {filename!r} is {across:.4g} m across, {across / size:.3g} times the robot's size "
                f"({size:.3g} m at q = 0): {advice}")  # fmt: skip
    if across * SMALL_RATIO < size:
        return (f"mesh {filename!r} is {across:.3g} m across, 1/{size / across:.3g} of the robot's size "
                f"({size:.3g} m at q = 0): {advice}")  # fmt: skip
    return ""


class _Budget:
    """What the meshes of one robot may cost together (read bytes, kept triangles)."""

    def __init__(self) -> None:
        self.read = 0
        self.kept = 0

    def load(self, path: Path, filename: str) -> MeshGeometry:
        if self.read >= MAX_PAGE_MESH_READ:
            raise MeshProblem(f"mesh {filename!r}: not read: the meshes read for this robot reached "
                              f"{MAX_PAGE_MESH_READ / 2**20:.0f} MiB, the cap")  # fmt: skip
        if self.kept >= MAX_PAGE_MESH_BYTES:
            raise MeshProblem(f"mesh {filename!r}: not read: the meshes kept for this robot reached "
                              f"{MAX_PAGE_MESH_BYTES / 2**20:.0f} MiB of triangles, the cap")  # fmt: skip
        geometry = _load(path, filename)
        self.read += geometry.bytes_read
        if self.kept + geometry.embedded_bytes > MAX_PAGE_MESH_BYTES:
            raise MeshProblem(f"mesh {filename!r}: {geometry.embedded_bytes / 2**20:.1f} MiB of triangles would "
                              f"take this robot's meshes over {MAX_PAGE_MESH_BYTES / 2**20:.0f} MiB, the cap: "
                              "not drawn")  # fmt: skip
        self.kept += geometry.embedded_bytes
        return geometry


def _links(links: list[str]) -> str:
    shown = ", ".join(links[:_SHOWN_LINKS])
    if len(links) > _SHOWN_LINKS:
        return f"links {shown} and {len(links) - _SHOWN_LINKS} more are"
    return f"link {shown} is" if len(links) == 1 else f"links {shown} are"


def _mesh_elements(root: ET.Element, element: str = "visual") -> list[tuple[str, int, ET.Element, ET.Element]]:
    """(link, index in the link, the <geometry>, its <mesh>) of every mesh ``<visual>`` (or ``<collision>``)."""
    out = []
    for link in root.findall("link"):
        for i, visual in enumerate(link.findall(element)):
            geometry = visual.find("geometry")
            mesh = geometry.find("mesh") if geometry is not None else None
            if geometry is not None and mesh is not None:
                out.append((link.get("name", ""), i, geometry, mesh))
    return out


def check_visual_count(robot: RobotModel) -> int:
    """The number of visuals of the robot, refused above :data:`~scara_pin.limits.MAX_VISUALS` (before any is built).

    Raises:
        InvalidInputError: more visuals than the cap.
    """
    count = sum(len(link.findall("visual")) for link in ET.fromstring(robot.urdf).findall("link"))
    return check_count("visuals of the robot (its <visual> elements, each drawn)", count, MAX_VISUALS,
                       "a page draws at most that many")  # fmt: skip


def visual_meshes(robot: RobotModel) -> tuple[VisualMesh, ...]:
    """The meshes of the robot's visuals that can be read; one ``warning`` per mesh that cannot.

    Names are Pinocchio's geometry names (``robot.visual_model``), where the placeholder boxes are. Each
    file is read once (its :class:`MeshGeometry` is shared by the visuals that name it); the files of the
    robot together are bounded (module docstring). A mesh of implausible size is drawn, with a warning.
    """
    out, problems = _robot_meshes(robot, "visual")
    for message, (links, boxed) in problems.items():
        if boxed:
            log.warning("%s; %s drawn as a %g m box", message, _links(links), PLACEHOLDER_SIZE)
        else:
            log.warning("%s (%s drawn as it is)", message, _links(links))
    return out


def collision_meshes(robot: RobotModel) -> tuple[VisualMesh, ...]:
    """The meshes of the robot's ``<collision>`` elements (names as in ``robot.collision_model``), all of them.

    Read as :func:`visual_meshes` reads visuals, but a collision mesh that cannot be read is an error, not
    a box: distances computed with a stand-in would be wrong.

    Raises:
        InvalidInputError: a collision mesh is missing, refused or unreadable (the message says which and why).
    """
    out, problems = _robot_meshes(robot, "collision")
    for message, (links, boxed) in problems.items():
        if boxed:
            raise InvalidInputError(f"{message}; {_links(links)} without collision geometry: distances to "
                                    "it cannot be computed")  # fmt: skip
        log.warning("%s (%s checked as it is)", message, _links(links))
    return out


def _robot_meshes(robot: RobotModel, element: str) -> tuple[tuple[VisualMesh, ...], dict[str, tuple[list[str], bool]]]:
    """The readable meshes of the robot's ``element`` (``visual`` or ``collision``) and the problems met.

    Returns:
        (meshes, problems): problems maps each message to (the links it concerns, whether the mesh was left out).
    """
    size = robot_size(robot)
    budget = _Budget()
    read: dict[Path, MeshGeometry | MeshProblem] = {}
    problems: dict[str, tuple[list[str], bool]] = {}  # message -> (links, left out)
    out = []
    for link, index, _geometry, mesh in _mesh_elements(ET.fromstring(robot.urdf), element):
        filename = mesh.get("filename", "")
        try:
            if not filename:
                raise MeshProblem(f"a <mesh> of link {link} has no filename")
            scale = mesh_scale(mesh.get("scale"), filename)
            path = mesh_file(filename, robot.package_path)  # the rule `check` applies too
            if path not in read:
                try:
                    read[path] = budget.load(path, filename)
                except MeshProblem as exc:
                    read[path] = exc
            geometry = read[path]
            if isinstance(geometry, MeshProblem):  # the file's problem, said once for every element naming it
                raise MeshProblem(*geometry.args)
            warning = _checked_size(geometry, scale, filename, size)
        except MeshProblem as exc:
            problems.setdefault(str(exc), ([], True))[0].append(link)
            continue
        if warning:
            problems.setdefault(warning, ([], False))[0].append(link)
        out.append(VisualMesh(f"{link}_{index}", link, filename, path, geometry, scale))
    return tuple(out), problems


def scaled(geometry: MeshGeometry, scale: Any) -> tuple[np.ndarray, np.ndarray]:
    """(vertices, faces) of ``geometry`` scaled by ``scale`` (one number or three, nonzero) [m].

    A scale that mirrors (an odd number of negative factors: ``scale: -1``) reverses each triangle's vertex order, so
    that a closed surface keeps its faces' normals outward: it stays the same solid, mirrored.
    """
    s = np.broadcast_to(np.asarray(scale, dtype=float), (3,))
    faces = geometry.faces if float(np.prod(np.sign(s))) > 0 else geometry.faces[:, ::-1].copy()
    return geometry.vertices * s, faces


@dataclass(frozen=True)
class MeshUse:
    """One shape that names a mesh file (an obstacle, the carried part).

    Attributes:
        path: the file (resolved: two names of one file are one file).
        filename: the name as written.
        what: the shape, for messages (``obstacle fixture``).
    """

    path: Path
    filename: str
    what: str


class MeshUseError(Exception):
    """A mesh file that one of its uses cannot read: the use (the first that names it) and the problem."""

    def __init__(self, use: MeshUse, problem: MeshProblem) -> None:
        super().__init__(str(problem))
        self.use = use
        self.problem = problem


def load_meshes(uses: list[MeshUse], origin: str) -> dict[Path, MeshGeometry]:
    """The triangles of every mesh file the shapes of one cell name: each file read and parsed ONCE, sized first.

    Before any file is parsed: the files' sizes on disk together (``stat``) are at most
    :data:`~scara_pin.limits.MAX_CELL_MESH_BYTES`, and so are their bytes once read (decompressed); then each
    file's triangles are counted from its header or text (:attr:`MeshFile.triangles`, no parsing), times the
    shapes that name it, against :data:`~scara_pin.limits.MAX_CELL_TRIANGLES`. Only then is each file parsed,
    once, whatever the number of shapes naming it (500 obstacles naming one 10 MB STL of 199,000 triangles: the
    file read once, its header's count times 500 refused, nothing parsed).

    Args:
        uses: the shapes naming a mesh, in the cell's order.
        origin: the cell, for messages.

    Raises:
        MeshUseError: a file that cannot be read or parsed, with the first shape naming it.
        InvalidInputError: the bytes or the triangles of the cell's meshes above their caps (counted before parsing).
    """
    from ..limits import MAX_CELL_MESH_BYTES, MAX_CELL_TRIANGLES  # here: read when called (tests lower them)

    first: dict[Path, MeshUse] = {}
    count: dict[Path, int] = {}
    for use in uses:
        first.setdefault(use.path, use)
        count[use.path] = count.get(use.path, 0) + 1
    size = 0
    for path in first:
        with contextlib.suppress(OSError):  # read_mesh_file says what is wrong with it
            size += os.stat(path).st_size
    check_count(f"bytes of the mesh files of {origin} ({len(first)} file(s), on disk)", size, MAX_CELL_MESH_BYTES)
    files: dict[Path, MeshFile] = {}
    read = 0
    triangles = 0
    for path, use in first.items():
        try:
            files[path] = found = read_mesh_file(path, use.filename)
        except MeshProblem as exc:
            raise MeshUseError(use, exc) from None
        read += len(found.data)
        check_count(f"bytes of the mesh files of {origin} (read, decompressed)", read, MAX_CELL_MESH_BYTES)
        triangles += found.triangles * count[path]
        if triangles > MAX_CELL_TRIANGLES:
            names = f"{count[path]:,} shape(s) naming {use.filename} of {found.triangles:,} triangles"
            check_count(f"mesh triangles of {origin} (counted before parsing; {names})", triangles,
                        MAX_CELL_TRIANGLES)  # fmt: skip
    out: dict[Path, MeshGeometry] = {}
    for path, found in files.items():
        try:
            out[path] = parse_mesh(found)
        except MeshProblem as exc:
            raise MeshUseError(first[path], exc) from None
    return out
