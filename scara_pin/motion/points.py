"""Taught points: named joint configurations, as a teach pendant records them, and their file.

A taught point is a NAME and the joint values ``q`` the robot had when it was recorded: ``q`` is the point
(it fixes the elbow branch and the J4 turn, which a pose alone does not). Its tool pose (x, y, z, yaw of the
tool frame in the base frame, Pinocchio's FK at ``q``) is written beside it for reading, and checked on
reading when present: a file taught on another robot (other lengths, other zero offsets) is refused
instead of silently moving elsewhere.

The points file comes in two formats, chosen by the file's extension (``.yaml``/``.yml`` or ``.csv``);
both are SI (m, rad), written at full precision (``repr``, so a point reads back bit for bit):

YAML::

    # scara-pin points file: q is the point [rad, m]; pose = tool frame in the base frame at q [m, rad]
    format: scara-pin points 1
    robot: s1
    base: base
    tool: tool0
    points:
    - name: P1
      q: [0.3, 0.9, 0.02, -0.5]
      pose: [0.0964..., 0.1556..., 0.08, 0.7]

    (a hand-written file may give values with xacro's unit tags, ``!degrees 30``, ``!millimeters 20``,
    and may leave out ``pose``, ``format``, ``robot``, ``base`` and ``tool``).

CSV (``#`` lines are comments; the header names the columns; the pose columns are optional)::

    # scara-pin points file: robot=s1 base=base tool=tool0 units=m,rad
    name,q1,q2,q3,q4,x,y,z,yaw
    P1,0.3,0.9,0.02,-0.5,0.0964...,0.1556...,0.08,0.7

Names: a letter, then up to 31 letters, digits, ``_``, ``-`` or ``.`` (``P1``, ``pick_2``, ``home``);
case-sensitive, unique in a file. At most :data:`scara_pin.limits.MAX_POINTS` points, and the file at most
:data:`scara_pin.limits.MAX_POINTS_BYTES` bytes.
"""

from __future__ import annotations

import csv
import io
import math
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError, brief
from ..limits import MAX_POINTS, MAX_POINTS_BYTES, check_input_file, read_text
from ..units import number_text

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = [
    "FORMAT",
    "POSE_TOL",
    "PointSet",
    "TaughtPoint",
    "check_point_name",
    "parse_points",
    "points_format",
    "read_points",
    "write_points",
]

FORMAT = "scara-pin points 1"
"""The ``format:`` value of a YAML points file (and the first comment of a CSV one)."""

POSE_TOL = 1e-6
"""[m, rad] how far a point's written pose may be from the FK of its q on the robot reading it: the pose is
written at full precision, so only another robot (or a hand edit) breaks it."""

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_.\-]{0,31}", re.ASCII)
_POSE_NAMES = ("x", "y", "z", "yaw")


def check_point_name(name: object) -> str:
    """``name`` if it is a valid point name (see the module docstring), else an :class:`InvalidInputError`."""
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise InvalidInputError(f"point name {brief(name, 44)} must be a letter then up to 31 letters, digits, _, - "
                                "or . (e.g. P1, pick_2)")  # fmt: skip
    return name


@dataclass(frozen=True, eq=False)
class TaughtPoint:
    """One taught point.

    Attributes:
        name: its name.
        q: the joint values [rad, m] (URDF order): the point itself.
        pose: the tool frame in the base frame at ``q``, (x, y, z, yaw) [m, rad]; None when the file gave none.
    """

    name: str
    q: np.ndarray
    pose: np.ndarray | None = None

    def __post_init__(self) -> None:
        check_point_name(self.name)
        object.__setattr__(self, "q", _finite(f"point {self.name}: q", self.q, None))
        if self.pose is not None:
            object.__setattr__(self, "pose", _finite(f"point {self.name}: pose", self.pose, 4))

    @classmethod
    def at(cls, robot: RobotModel, name: str, q: object) -> TaughtPoint:
        """The point ``name`` at joint values ``q`` of ``robot``, its pose from the robot's FK."""
        values = robot.check_q(q)
        return cls(name, values, np.asarray(robot.tool_pose(values), dtype=float))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: name, q, pose (None when unknown) in SI."""
        return {"name": self.name, "q": [float(v) for v in self.q],
                "pose": None if self.pose is None else [float(v) for v in self.pose]}  # fmt: skip


@dataclass(frozen=True, eq=False)
class PointSet:
    """An ordered set of taught points with unique names (immutable: the edits return a new set).

    Attributes:
        points: the points, in order.
        robot: the robot's name they were taught on ("" when unknown).
        base: the base frame of the poses ("" when unknown).
        tool: the tool frame of the poses ("" when unknown).
    """

    points: tuple[TaughtPoint, ...] = ()
    robot: str = ""
    base: str = ""
    tool: str = ""
    _index: dict[str, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if len(self.points) > MAX_POINTS:
            raise InvalidInputError(f"{len(self.points):,} points: above the cap of {MAX_POINTS:,} points per file")
        index: dict[str, int] = {}
        for i, p in enumerate(self.points):
            if p.name in index:
                raise InvalidInputError(f"point name {p.name!r} is used twice; names must be unique")
            index[p.name] = i
        object.__setattr__(self, "_index", index)

    def __len__(self) -> int:
        return len(self.points)

    def __iter__(self) -> Iterator[TaughtPoint]:
        return iter(self.points)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    @property
    def names(self) -> tuple[str, ...]:
        """The names, in order."""
        return tuple(p.name for p in self.points)

    def __getitem__(self, name: str) -> TaughtPoint:
        """The point named ``name`` (an :class:`InvalidInputError` listing the names when there is none)."""
        try:
            return self.points[self._index[name]]
        except (KeyError, TypeError):
            known = ", ".join(self.names[:20]) + (", ..." if len(self) > 20 else "") if self.points else "none"
            raise InvalidInputError(f"no point named {name!r} (points: {known})") from None

    def next_name(self, prefix: str = "P") -> str:
        """The first free name ``P1``, ``P2``, ... (a pendant's default for a new point)."""
        taken = set(self._index)
        return next(f"{prefix}{i}" for i in range(1, len(self.points) + 2) if f"{prefix}{i}" not in taken)

    def added(self, point: TaughtPoint) -> PointSet:
        """A copy with ``point`` appended (its name must be new)."""
        if point.name in self:
            raise InvalidInputError(f"a point named {point.name!r} exists already; rename or delete it first")
        return replace(self, points=(*self.points, point))

    def renamed(self, old: str, new: str) -> PointSet:
        """A copy with point ``old`` named ``new`` (same place in the order)."""
        point = self[old]
        check_point_name(new)
        if new != old and new in self:
            raise InvalidInputError(f"a point named {new!r} exists already")
        moved = TaughtPoint(new, point.q, point.pose)
        return replace(self, points=tuple(moved if p.name == old else p for p in self.points))

    def removed(self, name: str) -> PointSet:
        """A copy without point ``name``."""
        self[name]  # noqa: B018 - raises naming the known points when there is none
        return replace(self, points=tuple(p for p in self.points if p.name != name))

    def check(self, robot: RobotModel, origin: str = "points") -> None:
        """Refuse points that do not fit ``robot``.

        Another joint count, a joint value the robot cannot take (beyond +/-1e6 rad or m:
        :meth:`~scara_pin.model.RobotModel.check_q`), or a written pose that is not the FK of its q on this robot
        (beyond :data:`POSE_TOL`; the yaw compared modulo 2 pi). The joint limits are not checked here: a
        pendant shows such a point; a command that moves to it refuses it.

        Raises:
            InvalidInputError: naming the point and what differs.
        """
        from ..errors import ParameterError

        for p in self.points:
            if p.q.shape != (robot.dof,):
                raise InvalidInputError(f"{origin}: point {p.name} has {p.q.size} joint values; robot "
                                        f"{robot.name!r} has {robot.dof}")  # fmt: skip
            try:
                q = robot.check_q(p.q)
            except ParameterError as exc:
                raise InvalidInputError(f"{origin}: point {p.name}: {exc}") from None
            if p.pose is None:
                continue
            fk = robot.tool_pose(q)
            error = np.abs(fk - p.pose)
            error[3] = abs(math.remainder(float(fk[3] - p.pose[3]), 2 * math.pi))
            if not float(np.max(error)) <= POSE_TOL:
                k = int(np.argmax(error))
                taught = f" (taught on {self.robot!r})" if self.robot and self.robot != robot.name else ""
                raise InvalidInputError(
                    f"{origin}: point {p.name}'s pose {_POSE_NAMES[k]} = {p.pose[k]:.9g} is not the FK of its q on "
                    f"robot {robot.name!r} ({fk[k]:.9g}, off by {error[k]:.3g}){taught}"
                )

    # ----------------------------------------------------------------- text
    def to_yaml(self) -> str:
        """The YAML points file (full precision, SI)."""
        lines = [
            "# scara-pin points file: q is the point [rad, m, URDF joint order]; pose = the tool frame in the "
            "base frame at q, (x, y, z, yaw) [m, rad], for reading (checked on loading)",
            f"format: {FORMAT}",
            f"robot: {_yaml_text(self.robot)}",
            f"base: {_yaml_text(self.base)}",
            f"tool: {_yaml_text(self.tool)}",
            "points:" + ("" if self.points else " []"),
        ]
        for p in self.points:
            lines.append(f"- name: {p.name}")
            lines.append(f"  q: [{', '.join(repr(float(v)) for v in p.q)}]")
            if p.pose is not None:
                lines.append(f"  pose: [{', '.join(repr(float(v)) for v in p.pose)}]")
        return "\n".join(lines) + "\n"

    def to_csv(self) -> str:
        """The CSV points file (full precision, SI; empty pose cells when a pose is unknown)."""
        dof = max((p.q.size for p in self.points), default=4)
        out = io.StringIO()
        meta = " ".join(f"{k}={v}" for k, v in (("robot", self.robot), ("base", self.base), ("tool", self.tool)) if v)
        out.write(f"# {FORMAT}: {meta + ' ' if meta else ''}units=m,rad\n")
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(["name", *(f"q{i + 1}" for i in range(dof)), *_POSE_NAMES])
        for p in self.points:
            pose = ["" for _ in _POSE_NAMES] if p.pose is None else [repr(float(v)) for v in p.pose]
            writer.writerow([p.name, *(repr(float(v)) for v in p.q), *pose])
        return out.getvalue()

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: robot, base, tool and the points."""
        return {"robot": self.robot, "base": self.base, "tool": self.tool,
                "points": [p.to_dict() for p in self.points]}  # fmt: skip


def _yaml_text(text: str) -> str:
    """A yaml scalar for a frame or robot name: plain when it is safe, else double-quoted (JSON escapes)."""
    import json

    return text if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*", text) else json.dumps(text)


def _finite(what: str, value: object, n: int | None) -> np.ndarray:
    if isinstance(value, (str, bytes, bool)) or (
        isinstance(value, Sequence) and any(isinstance(v, (str, bytes, bool)) for v in value)
    ):
        raise InvalidInputError(f"{what} must be numbers")
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InvalidInputError(f"{what} must be numbers") from None
    if arr.ndim != 1 or (n is not None and arr.size != n) or not 3 <= arr.size <= 4:
        raise InvalidInputError(f"{what} must be {n if n is not None else '3 or 4'} numbers, got shape {arr.shape}")
    if not np.isfinite(arr).all():
        raise InvalidInputError(f"{what} must be finite numbers, got {arr.tolist()}")
    return arr


# ------------------------------------------------------------------------------------------ files
def points_format(path: str | Path) -> str:
    """``"yaml"`` or ``"csv"`` from the file name's extension (an :class:`InvalidInputError` otherwise)."""
    suffix = Path(path).suffix.lower()
    if suffix in (".yaml", ".yml"):
        return "yaml"
    if suffix == ".csv":
        return "csv"
    raise InvalidInputError(f"points file {path}: the name must end in .yaml, .yml or .csv (the format)")


def read_points(path: str | Path, robot: RobotModel | None = None) -> PointSet:
    """Read a points file (YAML or CSV by its extension; see the module docstring).

    Args:
        path: the file.
        robot: when given, the points are checked against it (:meth:`PointSet.check`).

    Raises:
        InvalidInputError: an unreadable, oversized or malformed file (the message names the file, and the
            point or line), duplicate or invalid names, or points that do not fit ``robot``.
    """
    fmt = points_format(path)
    text = read_text(check_input_file(path, "points file", MAX_POINTS_BYTES), "points file", MAX_POINTS_BYTES)
    points = parse_points(text, fmt, f"points file {path}")
    if robot is not None:
        points.check(robot, f"points file {path}")
    return points


def parse_points(text: str, fmt: str, origin: str = "points") -> PointSet:
    """Parse the text of a points file in ``fmt`` (``"yaml"`` or ``"csv"``); ``origin`` names it in errors."""
    try:
        if fmt == "yaml":
            return _parse_yaml(text, origin)
        if fmt == "csv":
            return _parse_csv(text, origin)
    except InvalidInputError as exc:
        message = str(exc)
        if not message.startswith(origin):
            message = f"{origin} {message}" if message.startswith("line ") else f"{origin}: {message}"
        raise InvalidInputError(message) from None
    raise InvalidInputError(f"points format {fmt!r} must be 'yaml' or 'csv'")


def _parse_yaml(text: str, origin: str) -> PointSet:
    from ..description.yaml_units import load_yaml

    tree = load_yaml(text, origin)  # bounded (an alias bomb is refused); a YamlError names the file and line
    if not isinstance(tree, dict) or not isinstance(tree.get("points"), list):
        raise InvalidInputError("a YAML points file is a mapping with a 'points' list")
    unknown = sorted(brief(k, 40) for k in tree if k not in ("format", "robot", "base", "tool", "points"))
    if unknown:
        raise InvalidInputError(f"unknown key(s) {', '.join(unknown[:10])} (keys: format, robot, base, tool, points)")
    if "format" in tree and tree["format"] != FORMAT:
        raise InvalidInputError(f"{_at(tree, 'format')}format {brief(tree['format'])} is not {FORMAT!r}")
    meta = {}
    for key in ("robot", "base", "tool"):
        value = tree.get(key, "")
        if not isinstance(value, str) or len(value) > 200:
            raise InvalidInputError(f"{_at(tree, key)}{key} must be a name (text of at most 200 characters)")
        meta[key] = value
    items = tree["points"]
    if len(items) > MAX_POINTS:
        raise InvalidInputError(f"{len(items):,} points: above the cap of {MAX_POINTS:,} points per file")
    points = []
    for i, item in enumerate(items):
        where = _at(items, i)
        if not isinstance(item, dict) or "name" not in item or "q" not in item:
            raise InvalidInputError(f"{where}point #{i + 1} must be a mapping with name and q (and optionally pose)")
        extra = sorted(brief(k, 40) for k in item if k not in ("name", "q", "pose"))
        if extra:
            raise InvalidInputError(f"{where}point #{i + 1}: unknown key(s) {', '.join(extra[:10])} (keys: name, q, "
                                    "pose)")  # fmt: skip
        try:
            name = check_point_name(item["name"])
        except InvalidInputError as exc:
            raise InvalidInputError(f"{_at(item, 'name')}{exc}") from None
        q = np.array(_yaml_numbers(f"{_at(item, 'q')}point {name}: q", item["q"]))
        pose = item.get("pose")
        if pose is not None:
            pose = np.array(_yaml_numbers(f"{_at(item, 'pose')}point {name}: pose", pose))
        try:
            points.append(TaughtPoint(name, q, pose))
        except InvalidInputError as exc:
            raise InvalidInputError(f"{where}{exc}") from None
    return PointSet(tuple(points), **meta)


def _at(data: object, key: object) -> str:
    """``"line N: "`` for the item ``key`` of yaml data (its line in the file), or ``""`` when unknown."""
    from ..description.yaml_units import yaml_line

    line = yaml_line(data, key)
    return "" if line is None else f"line {line}: "


def _yaml_numbers(what: str, value: object) -> list[float]:
    """A yaml list of numbers, each finite and in the number grammar of the command line, else refused briefly.

    The loader leaves anything outside the grammar as text (``0x1``, ``1_0``, ``0:0.5``, a unit tag on text).
    """
    if not isinstance(value, list):
        raise InvalidInputError(f"{what} must be a list of finite numbers, got {brief(value)}")
    for k, v in enumerate(value):
        if isinstance(v, str):
            why = "not a plain number such as 0.25, -3, 1.5e-3 (ASCII digits; no hex, _ separators or base 60)"
        elif isinstance(v, bool) or not isinstance(v, (int, float)):
            why = "not a number"
        elif math.isinf(v):  # YAML's .inf, or a number beyond the float range (a 400-digit integer)
            raise InvalidInputError(f"{what} must be a list of finite numbers; value {k + 1} is infinite or beyond the "
                                    "float range (about 1.8e308)")  # fmt: skip
        elif math.isnan(v):
            why = "not finite"
        else:
            continue
        raise InvalidInputError(f"{what} must be a list of finite numbers; value {k + 1} is {brief(v, 40)}: {why}")
    return [float(v) for v in value]


def _parse_csv(text: str, origin: str) -> PointSet:
    rows = []
    meta: dict[str, str] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            if number == 1 and stripped.lstrip("# ").startswith(FORMAT):
                for key, value in re.findall(r"\b(robot|base|tool)=(\S+)", stripped):
                    meta[key] = value
            continue
        rows.append((number, line))
    if not rows:
        raise InvalidInputError("no header: a CSV points file starts with name,q1,q2,q3,q4[,x,y,z,yaw]")
    header_line, header_text = rows[0]
    header = [h.strip() for h in next(csv.reader([header_text]))]
    dof = sum(1 for h in header if re.fullmatch(r"q\d", h))
    expected = ["name", *(f"q{i + 1}" for i in range(dof))]
    rest = header[len(expected) :]
    if dof not in (3, 4) or header[: len(expected)] != expected or rest not in ([], list(_POSE_NAMES)):
        raise InvalidInputError(f"line {header_line}: the header must be name,q1,q2,q3,q4 (or name,q1,q2,q3), "
                                f"optionally followed by x,y,z,yaw; got {header_text[:80]!r}")  # fmt: skip
    with_pose = len(header) > len(expected)
    if len(rows) - 1 > MAX_POINTS:
        raise InvalidInputError(f"{len(rows) - 1:,} points: above the cap of {MAX_POINTS:,} points per file")
    points = []
    for number, line in rows[1:]:
        cells = [c.strip() for c in next(csv.reader([line]))]
        if len(cells) != len(header):
            raise InvalidInputError(f"line {number}: {len(cells)} cells; the header has {len(header)}")
        try:
            name = check_point_name(cells[0])
        except InvalidInputError as exc:
            raise InvalidInputError(f"line {number}: {exc}") from None
        q = [_cell(number, name, header[i], cells[i]) for i in range(1, len(expected))]
        pose = None
        if with_pose and any(cells[len(expected):]):
            pose = [_cell(number, name, header[i], cells[i]) for i in range(len(expected), len(header))]
        points.append(TaughtPoint(name, np.array(q), None if pose is None else np.array(pose)))
    return PointSet(tuple(points), **meta)


def _cell(line: int, point: str, column: str, text: str) -> float:
    value = number_text(text)
    if not math.isfinite(value):
        raise InvalidInputError(f"line {line}: point {point}: {column} = {brief(text, 40)} is not a plain finite "
                                "number such as 0.25, -3, 1.5e-3")  # fmt: skip
    return value


def write_points(path: str | Path, points: PointSet) -> Path:
    """Write ``points`` to ``path`` atomically, in the format its extension names (YAML or CSV)."""
    from ..files import write_text_atomic

    fmt = points_format(path)
    return write_text_atomic(path, points.to_yaml() if fmt == "yaml" else points.to_csv())
