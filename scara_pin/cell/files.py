"""Cell files: YAML (the cell format), or a URDF / xacro of fixed links whose ``<collision>`` are the obstacles.

**YAML** (SI units; everything in the robot's ``base`` frame; the ``format`` line is optional)::

    format: scara-pin cell 1
    margin: 0.002              # smallest distance kept between the robot (and what it carries) and any obstacle [m]
    obstacles:
      - name: post
        shape: cylinder        # box (size) | cylinder (radius, length) | sphere (radius) | mesh (file, scale)
        radius: 0.02
        length: 0.20
        xyz: [0.306, -0.052, -0.10]   # the shape's centre (a mesh's origin)
        rpy: [0, 0, 0]                # its orientation, as URDF's (optional)
        margin: 0.02           # optional: keep 20 mm from this one (more than the cell's margin; not a mesh)
      - name: fixture
        shape: mesh
        file: fixture.stl      # relative to the cell file; STL, DAE or OBJ (read as the viewer reads meshes)
        scale: 0.001           # one number or three (optional)
        xyz: [0.3, 0.2, -0.15]
    carried:                   # optional: what the tool holds, in the TOOL frame; it collides too
      shape: box
      size: [0.04, 0.04, 0.03]
      xyz: [0, 0, 0.015]       # tool0's z points down, out of the flange: +z is below the flange
    allow: [[link1, base_link]]   # optional: pairs of names never checked (links, obstacles, carried)

The file is read by the package's one bounded yaml loader (alias bombs refused at
:data:`~scara_pin.limits.MAX_YAML_NODES`); numbers follow the command line's grammar (``1e-3`` is a number;
``0x1``, ``1_000`` or ``1:30`` are refused); xacro's unit tags are read (``!degrees 90``). Errors name the
file and the line.

**URDF or xacro** (for ROS users): a ``<robot>`` whose links are joined by ``fixed`` joints; its root link
is the robot's ``base`` frame, and every ``<collision>`` of every link is an obstacle named after its link
(``<link>`` for the first, ``<link>_<i>`` for the next ones). A xacro file is expanded as the robot's are
(its expressions run: load files you trust), ``package://`` meshes looked up the same way. A cell URDF holds
no margin, carried part or allowed pairs: :func:`load_cell` takes them as arguments.

Every file is sized before it is read (:data:`~scara_pin.limits.MAX_CELL_BYTES`); obstacles and
triangles are capped (:data:`~scara_pin.limits.MAX_CELL_OBSTACLES`, :data:`~scara_pin.limits.MAX_CELL_TRIANGLES`)
before any geometry is built; meshes are read by :func:`scara_pin.cell.meshes.load_meshes` (each file once, its
bytes and triangles sized before it is parsed; a mesh cannot leave the cell file's folder).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

from ..description.yaml_units import load_yaml, yaml_line
from ..errors import InvalidInputError, UrdfError
from ..limits import MAX_CELL_BYTES, MAX_CELL_OBSTACLES, check_count, check_input_file, read_text
from .cell import DEFAULT_MARGIN, Cell, Obstacle, check_name
from .shapes import KINDS, Shape

if TYPE_CHECKING:
    from ..description.packages import PackagePath

__all__ = ["FORMAT", "load_cell", "parse_cell"]

FORMAT = "scara-pin cell 1"
"""The ``format`` line of a YAML cell file."""
_TOP_KEYS = ("format", "margin", "obstacles", "carried", "allow")
_SHAPE_KEYS = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",), "mesh": ("file",)}
_OPTIONAL = {"box": (), "cylinder": (), "sphere": (), "mesh": ("scale",)}
_Meshes = dict[Path, Any]
"""The cell's mesh files, read and parsed once each: resolved path -> :class:`~scara_pin.cell.meshes.MeshGeometry`."""


def load_cell(
    path: str | Path,
    *,
    margin: float | None = None,
    carried: Shape | None = None,
    allow: tuple[tuple[str, str], ...] = (),
    package_dirs: tuple[str | Path, ...] = (),
) -> Cell:
    """Read a cell file: YAML (``.yaml``, ``.yml``), URDF (``.urdf``) or xacro (``.xacro``).

    Args:
        path: the file.
        margin: [m] overrides the file's margin (a URDF cell has none: default 2 mm).
        carried: what the tool holds (tool frame), overriding the file's ``carried``.
        allow: pairs never checked, added to the file's.
        package_dirs: folders holding packages for ``package://`` and ``$(find pkg)`` (URDF, xacro).

    Raises:
        InvalidInputError: an unreadable, oversized or malformed file, naming the file and the line; a
            shape with a negative or non-finite size, naming the obstacle; more obstacles or triangles than
            the caps.
    """
    path = Path(path)
    name = path.name.lower()
    if name.endswith((".yaml", ".yml")):
        text = read_text(path, "cell file", MAX_CELL_BYTES)
        cell = parse_cell(text, str(path), path.parent)
    elif name.endswith((".urdf", ".xacro")):
        cell = _urdf_cell(path, package_dirs)
    else:
        raise InvalidInputError(f"cell file {path}: the name must end in .yaml, .yml, .urdf or .xacro")
    if carried is not None:
        cell = cell.with_carried(carried)
    if margin is not None:
        cell = cell.with_margin(margin)
    if allow:
        cell = Cell(cell.obstacles, cell.margin, cell.carried, cell.allow + tuple(allow), cell.origin)
    return cell


# ---------------------------------------------------------------------------------------------- YAML
class _Reader:
    """Errors that name the cell file and the line of the value (the shared loader's lines)."""

    def __init__(self, origin: str) -> None:
        self.origin = origin
        self.paths: dict[tuple[Path | None, str], Path] = {}  # the mesh files resolved (one lookup per name)

    def error(self, line: int | None, message: str) -> InvalidInputError:
        return InvalidInputError(f"{self.origin}{'' if line is None else f' line {line}'}: {message}")


def parse_cell(text: str, origin: str = "cell", folder: Path | None = None) -> Cell:
    """A cell from the text of a YAML cell file (module docstring); ``folder`` holds its mesh files.

    The text is read by the package's one bounded yaml loader (:func:`scara_pin.description.yaml_units.load_yaml`:
    alias bombs refused, numbers in the command line's grammar, xacro's unit tags).

    Raises:
        InvalidInputError: malformed YAML or a bad value, naming ``origin`` and the line.
    """
    reader = _Reader(origin)
    top = load_yaml(text, origin)
    if top is None:
        raise InvalidInputError(f"{origin}: the file is empty (a cell is a mapping with 'obstacles')")
    if not isinstance(top, dict):
        raise reader.error(yaml_line(top), "a cell file is a mapping with 'obstacles' (and margin, carried, allow)")
    unknown = [k for k in top if k not in _TOP_KEYS]
    if unknown:
        raise reader.error(yaml_line(top, unknown[0]), f"unknown key {str(unknown[0])[:40]!r} (keys: "
                           f"{', '.join(_TOP_KEYS)})")  # fmt: skip
    if "format" in top and top["format"] != FORMAT:
        raise reader.error(yaml_line(top, "format"), f"format {str(top['format'])[:40]!r} is not {FORMAT!r}")
    margin = DEFAULT_MARGIN
    if "margin" in top:
        margin = _number(reader, top, "margin", "margin")
        if not 0.0 <= margin <= 1.0:
            raise reader.error(yaml_line(top, "margin"), f"margin {margin:.6g} m must be in [0, 1] m")
    obstacles: list[Obstacle] = []
    raw = top.get("obstacles")
    if raw is not None:
        if not isinstance(raw, list):
            raise reader.error(yaml_line(top, "obstacles"), "obstacles must be a list")
        check_count(f"{origin}: obstacles", len(raw), MAX_CELL_OBSTACLES)
    meshes = _meshes(reader, top, folder)  # every mesh file read once, sized before any is parsed
    if raw is not None:
        seen: set[str] = set()
        for i in range(len(raw)):
            o = _obstacle(reader, raw, i, folder, meshes)
            if o.name in seen:
                raise reader.error(o.line, f"obstacle name {o.name!r} is used twice")
            seen.add(o.name)
            obstacles.append(o)
    carried = None
    if top.get("carried") is not None:
        carried = _shape(reader, top, "carried", "the carried part", folder, meshes, named=False)
    allow: list[tuple[str, str]] = []
    if top.get("allow") is not None:
        pairs = top["allow"]
        if not isinstance(pairs, list):
            raise reader.error(yaml_line(top, "allow"), "allow must be a list of pairs of names")
        for i, pair in enumerate(pairs):
            if not isinstance(pair, list) or len(pair) != 2:
                raise reader.error(yaml_line(pairs, i), "allow takes pairs of names: [link1, base_link]")
            allow.append((_name(reader, pair, 0, "allow"), _name(reader, pair, 1, "allow")))
    return Cell(tuple(obstacles), margin, carried, tuple(allow), origin)


def _number(reader: _Reader, data: Any, key: Any, what: str) -> float:
    v = data[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise reader.error(yaml_line(data, key), f"{what} must be a number")
    if not math.isfinite(v):
        raise reader.error(yaml_line(data, key), f"{what} {v!r} is not a plain finite number")
    return float(v)


def _numbers(reader: _Reader, data: Any, key: Any, what: str, n: int) -> list[float]:
    v = data[key]
    if not isinstance(v, list) or len(v) != n:
        raise reader.error(yaml_line(data, key), f"{what} must be a list of {n} numbers")
    return [_number(reader, v, i, what) for i in range(n)]


def _name(reader: _Reader, data: Any, key: Any, what: str) -> str:
    try:
        return check_name(data[key], what)
    except InvalidInputError as exc:
        raise reader.error(yaml_line(data, key), str(exc)) from None


def _obstacle(reader: _Reader, items: list[Any], i: int, folder: Path | None, meshes: _Meshes) -> Obstacle:
    item = items[i]
    line = yaml_line(items, i)
    if not isinstance(item, dict):
        raise reader.error(line, "an obstacle is a mapping with name, shape, its sizes and xyz")
    if "name" not in item:
        raise reader.error(line, "an obstacle needs a name")
    name = _name(reader, item, "name", "obstacle name")
    shape = _shape(reader, items, i, f"obstacle {name}", folder, meshes, named=True)
    margin = _number(reader, item, "margin", f"obstacle {name}: margin") if "margin" in item else None
    try:
        return Obstacle(name, shape, line or 0, margin)
    except InvalidInputError as exc:
        raise reader.error(yaml_line(item, "margin"), str(exc)) from None


def _shape(reader: _Reader, parent: Any, key: Any, what: str, folder: Path | None, meshes: _Meshes, *,
           named: bool) -> Shape:  # fmt: skip
    d = parent[key]
    line = yaml_line(parent, key)
    if not isinstance(d, dict):
        raise reader.error(line, f"{what} is a mapping with shape, its sizes and xyz")
    if "shape" not in d:
        raise reader.error(line, f"{what}: no shape (one of {', '.join(KINDS)})")
    kind = d["shape"]
    if kind not in KINDS:
        raise reader.error(yaml_line(d, "shape"), f"{what}: shape {str(kind)[:40]!r} must be one of {', '.join(KINDS)}")
    allowed = ("name", "margin") * named + ("shape", "xyz", "rpy") + _SHAPE_KEYS[kind] + _OPTIONAL[kind]
    for k in d:
        if k not in allowed:
            raise reader.error(yaml_line(d, k), f"{what}: unknown key {str(k)[:40]!r} for a {kind} (keys: "
                               f"{', '.join(allowed)})")  # fmt: skip
    for k in _SHAPE_KEYS[kind]:
        if k not in d:
            raise reader.error(line, f"{what}: a {kind} needs {' and '.join(_SHAPE_KEYS[kind])}")
    xyz = _numbers(reader, d, "xyz", f"{what}: xyz", 3) if "xyz" in d else [0.0, 0.0, 0.0]
    rpy = _numbers(reader, d, "rpy", f"{what}: rpy", 3) if "rpy" in d else [0.0, 0.0, 0.0]
    try:
        if kind == "mesh":
            return _mesh_shape(reader, d, what, folder, xyz, rpy, meshes)
        size = (tuple(_numbers(reader, d, "size", f"{what}: size", 3)) if kind == "box"
                else tuple(_number(reader, d, k, f"{what}: {k}") for k in _SHAPE_KEYS[kind]))  # fmt: skip
        return Shape(kind, size, np.array(xyz), np.array(rpy), what=what)
    except InvalidInputError as exc:
        message = str(exc)
        if message.startswith(reader.origin):
            raise
        raise reader.error(line, message) from None


def _mesh_path(reader: _Reader, d: dict[str, Any], what: str, folder: Path | None) -> Path:
    """The file a mesh shape names, resolved (links followed), inside the cell file's folder; else an error.

    A mesh cannot leave the cell's folder: ``../outside.stl``, an absolute path elsewhere, or a link pointing out
    are refused (as a URDF cell refuses them), naming the line.
    """
    file = d["file"]
    if not isinstance(file, str) or not file or len(file) > 4096 or "\0" in file:
        raise reader.error(yaml_line(d, "file"), f"{what}: file must be a file name")
    found = reader.paths.get((folder, file))
    if found is not None:
        return found
    root = (folder or Path.cwd()).resolve()
    path = (root / file).resolve()
    if path != root and root not in path.parents:
        raise reader.error(yaml_line(d, "file"), f"{what}: mesh {file!r} is outside the cell file's folder {root}: "
                           "not read (a mesh cannot leave the cell's folder)")  # fmt: skip
    reader.paths[(folder, file)] = path
    return path


def _meshes(reader: _Reader, top: dict[Any, Any], folder: Path | None) -> _Meshes:
    """Every mesh file the obstacles and the carried part name, read once each and sized before any is parsed.

    :func:`~scara_pin.cell.meshes.load_meshes`: the files' bytes, then their triangles counted from their headers
    times the shapes naming them, against the cell's caps; then each file parsed once. A shape that is not a
    well-formed mesh is left to the reading of its shape (its own message).
    """
    from .meshes import MeshUse, MeshUseError, load_meshes

    items: list[tuple[Any, Any, str]] = []
    if isinstance(top.get("obstacles"), list):
        for i, item in enumerate(top["obstacles"]):
            name = item.get("name") if isinstance(item, dict) else None
            items.append((top["obstacles"], i, f"obstacle {name}" if isinstance(name, str) else f"obstacle #{i + 1}"))
    if top.get("carried") is not None:
        items.append((top, "carried", "the carried part"))
    uses: list[MeshUse] = []
    lines: dict[int, int | None] = {}
    for parent, key, what in items:
        d = parent[key]
        if isinstance(d, dict) and d.get("shape") == "mesh" and "file" in d:
            uses.append(MeshUse(_mesh_path(reader, d, what, folder), d["file"], what))
            lines[id(uses[-1])] = yaml_line(d, "file")
    if not uses:
        return {}
    try:
        return load_meshes(uses, reader.origin)
    except MeshUseError as exc:
        raise reader.error(lines[id(exc.use)], f"{exc.use.what}: {exc.problem}") from None


def _mesh_shape(reader: _Reader, d: dict[str, Any], what: str, folder: Path | None, xyz: list[float],
                rpy: list[float], meshes: _Meshes) -> Shape:  # fmt: skip
    from .meshes import scaled

    file = d["file"]
    scale = [1.0, 1.0, 1.0]
    if "scale" in d:
        scale = _numbers(reader, d, "scale", f"{what}: scale", 3) if isinstance(d["scale"], list) \
            else [_number(reader, d, "scale", f"{what}: scale")] * 3  # fmt: skip
        if not all(v != 0.0 and abs(v) <= 1e6 for v in scale):
            raise reader.error(yaml_line(d, "scale"), f"{what}: scale must be finite, nonzero numbers")
    vertices, faces = scaled(meshes[_mesh_path(reader, d, what, folder)], scale)
    return Shape("mesh", (), np.array(xyz), np.array(rpy), vertices, faces, file, what)


# ---------------------------------------------------------------------------------------------- URDF, xacro
def _urdf_cell(path: Path, package_dirs: tuple[str | Path, ...]) -> Cell:
    """The obstacles of a URDF or xacro cell: every ``<collision>`` of links joined by fixed joints."""
    import xml.etree.ElementTree as ET

    from ..description.mesh_paths import MeshProblem, mesh_file
    from ..description.packages import PackagePath, read_robot_file
    from ..description.placeholders import placeholder_urdf
    from .meshes import MeshUse, MeshUseError, load_meshes, mesh_scale, scaled

    check_input_file(path, "cell file", MAX_CELL_BYTES)
    packages: PackagePath = PackagePath(tuple(Path(d) for d in package_dirs), path.parent)
    origin = str(path)
    try:
        text = read_robot_file(path, packages)
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise InvalidInputError(f"{origin}: malformed XML at line {exc.position[0]}") from None
    except UrdfError as exc:
        raise InvalidInputError(f"cell {exc}") from None
    if root.tag != "robot":
        raise InvalidInputError(f"{origin}: the root element is <{root.tag}>, not <robot>")
    for joint in root.iter("joint"):
        if joint.get("type") != "fixed":
            raise InvalidInputError(f"{origin}: joint {str(joint.get('name'))[:40]!r} is {joint.get('type')!r}: the "
                                    "links of a cell are joined by fixed joints")  # fmt: skip
    collisions = [(link.get("name", ""), i, c) for link in root.findall("link")
                  for i, c in enumerate(link.findall("collision"))]  # fmt: skip
    check_count(f"{origin}: obstacles (<collision> elements)", len(collisions), MAX_CELL_OBSTACLES)
    uses: dict[str, tuple[MeshUse, tuple[float, float, float]]] = {}
    for link, i, c in collisions:
        mesh = c.find("geometry/mesh")
        if mesh is None:
            continue
        what = f"obstacle {link if i == 0 else f'{link}_{i}'}"
        filename = mesh.get("filename", "")
        try:
            scale = mesh_scale(mesh.get("scale"), filename)
            uses[f"{link}_{i}"] = (MeshUse(mesh_file(filename, packages), filename, what), scale)
        except MeshProblem as exc:
            raise InvalidInputError(f"{origin}: {what}: {exc}") from None
    try:  # every file read once, sized (bytes, triangles from its header) before any is parsed
        read = load_meshes([use for use, _ in uses.values()], origin)
    except MeshUseError as exc:
        raise InvalidInputError(f"{origin}: {exc.use.what}: {exc.problem}") from None
    meshes: dict[str, Shape] = {}
    for key, (use, scale) in uses.items():
        vertices, faces = scaled(read[use.path], scale)
        meshes[key] = Shape("mesh", (), np.zeros(3), np.zeros(3), vertices, faces, use.filename, use.what)
    try:
        model = pin.buildModelFromXML(placeholder_urdf(text))
        geom = pin.buildGeomFromUrdfString(model, placeholder_urdf(text), pin.GeometryType.COLLISION)
    except (ValueError, RuntimeError) as exc:
        raise InvalidInputError(f"{origin}: not a valid URDF: {' '.join(str(exc).split())[:200]}") from None
    obstacles = []
    for g in geom.geometryObjects:
        link = model.frames[g.parentFrame].name
        index = int(g.name.rsplit("_", 1)[1])
        name = link if index == 0 else f"{link}_{index}"
        what = f"obstacle {name}"
        M = g.placement  # relative to the universe: the root link, the robot's base
        rpy = np.asarray(pin.rpy.matrixToRpy(M.rotation))
        if g.name in meshes:
            shape = meshes[g.name].moved(M, what)
        else:
            shape = _primitive(g.geometry, M.translation.copy(), rpy, what)
        obstacles.append(Obstacle(check_name(name, f"{origin}: obstacle"), shape))
    return Cell(tuple(obstacles), DEFAULT_MARGIN, None, (), origin)


def _primitive(geometry: Any, xyz: np.ndarray, rpy: np.ndarray, what: str) -> Shape:
    """A Shape of a coal primitive that Pinocchio built from URDF."""
    if isinstance(geometry, coal.Box):
        return Shape("box", tuple(2.0 * np.asarray(geometry.halfSide)), xyz, rpy, what=what)
    if isinstance(geometry, coal.Cylinder):
        return Shape("cylinder", (float(geometry.radius), 2.0 * float(geometry.halfLength)), xyz, rpy, what=what)
    if isinstance(geometry, coal.Sphere):
        return Shape("sphere", (float(geometry.radius),), xyz, rpy, what=what)
    raise InvalidInputError(f"{what}: a {type(geometry).__name__} is not read in a cell (box, cylinder, sphere, mesh)")
