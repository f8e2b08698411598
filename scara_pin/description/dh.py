"""Denavit-Hartenberg tables (yaml) to URDF.

A table lists one row per joint, in either convention (``convention: standard`` or ``modified``):

- standard (Denavit-Hartenberg; Spong, Corke's ``Link``): ``A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``,
  the pose of D-H frame i in frame i - 1; joint i moves about (R) or along (P) the z axis of frame i - 1.
- modified (Craig): ``A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)``; a row's ``alpha`` and ``a``
  are ``alpha_{i-1}`` and ``a_{i-1}``, and joint i moves about (R) or along (P) the z axis of frame i.

In a revolute row ``theta`` is the joint variable (write ``q``) and ``theta_i = q_i + offset``; in a
prismatic row ``d`` is (``q``) and ``d_i = q_i + offset``. The forward kinematics of the table is
``base_T_tool = A_1 A_2 ... A_n T_tool``.

The URDF puts every elementary transform where URDF can hold it exactly (``<origin xyz rpy>`` is
``Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll)``): a row becomes a moving joint whose origin is
``Tz(d) Rz(theta)`` with the offset included (xyz ``0 0 d``, rpy ``0 0 theta``, axis ``0 0 1``) and a fixed
joint holding ``Tx(a) Rx(alpha)`` (xyz ``a 0 0``, rpy ``alpha 0 0``): AFTER the moving joint for standard
D-H, BEFORE it for modified D-H. No angle is ever converted to roll-pitch-yaw, so no rounding beyond a
float's: Pinocchio's FK of the URDF equals the D-H product to ~1e-15.

Frames: ``base_link`` (root) -> ``base`` (D-H frame 0, fixed, identity) -> ... -> ``link<i>`` (D-H frame
i) -> ``tool0`` (``link<n>`` times the optional tool transform). Intermediate links: ``link<i>_z`` (standard:
on joint i's axis, before ``Tx(a_i) Rx(alpha_i)``) and ``link<i>_x`` (modified: after
``Rx(alpha_{i-1}) Tx(a_{i-1})``, before joint i).

Yaml format (units SI and stated; angles may be written with xacro's ``!degrees`` tag, or as ``pi``,
``-pi/2``, ``2*pi/3``; lengths with ``!millimeters``)::

    name: s1_dh
    convention: standard          # or modified
    units: {length: m, angle: rad}
    joints:
      - {name: joint1, type: R, theta: q, d: 0.100, a: 0.050, alpha: 0, offset: 0,
         lower: !degrees -170, upper: !degrees 170, velocity: 3.0, effort: 5.0}
      - ...
    tool: {xyz: [0, 0, 0], rpy: [0, 0, 0]}   # optional: tool0 in the last D-H frame [m, rad]

Every field is validated before any URDF is written; errors are :class:`DHTableError` naming the row,
the joint and the field.
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from ..errors import InvalidInputError, ParameterError, YamlError

__all__ = [
    "CONVENTIONS",
    "DHRow",
    "DHTable",
    "DHTableError",
    "dh_example",
    "dh_examples",
    "dh_to_urdf",
    "load_dh_table",
    "parse_dh_table",
]

CONVENTIONS: tuple[str, ...] = ("standard", "modified")
_TYPES: Mapping[str, str] = {"R": "R", "r": "R", "revolute": "R", "P": "P", "p": "P", "prismatic": "P"}
_NAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,63}$")
_PI_RE = re.compile(r"^\s*([+-])?\s*(?:(\d+(?:\.\d*)?)\s*\*\s*)?pi\s*(?:/\s*(\d+(?:\.\d*)?))?\s*$")
_TOP_KEYS = ("name", "convention", "units", "joints", "tool", "description")
_ROW_KEYS = ("name", "type", "theta", "d", "a", "alpha", "offset", "lower", "upper", "velocity", "effort")
_MAX_ROWS = 64
_MAX_ABS = 1e6


class DHTableError(ParameterError):
    """A D-H table that breaks a rule (exit code 2).

    Attributes:
        row: 1-based row number, or ``None`` for a table-level field.
        field: the field, e.g. ``"alpha"`` or ``"convention"``.
    """

    def __init__(self, origin: str, row: int | None, joint: str | None, field: str, value: object, rule: str) -> None:
        self.row = row
        self.field = field
        where = f"row {row}" + (f" ({joint})" if joint else "") + " " if row is not None else ""
        super().__init__(f"{origin}: {where}{field}", value, rule)


@dataclass(frozen=True)
class DHRow:
    """One D-H row (SI: [m], [rad]; velocity [rad/s] or [m/s]; effort [N m] or [N]).

    Attributes:
        name: the joint's name.
        type: ``"R"`` (revolute: theta = q + offset) or ``"P"`` (prismatic: d = q + offset).
        theta, d: the constant one of the pair (the variable one is stored as 0.0 and unused).
        a, alpha: standard D-H: a_i, alpha_i; modified D-H: a_{i-1}, alpha_{i-1}.
        offset: the joint offset added to q.
        lower, upper, velocity, effort: the joint limits, in q.
    """

    name: str
    type: str
    theta: float
    d: float
    a: float
    alpha: float
    offset: float
    lower: float
    upper: float
    velocity: float
    effort: float

    def __post_init__(self) -> None:
        origin = "DHRow"
        if not isinstance(self.name, str) or not _NAME_RE.match(self.name):
            raise DHTableError(origin, None, None, "name", self.name, "must be letters, digits and _ (not first)")
        if self.type not in ("R", "P"):
            raise DHTableError(origin, None, self.name, "type", self.type, "must be R or P")
        for field in ("theta", "d", "a", "alpha", "offset", "lower", "upper", "velocity", "effort"):
            _number(origin, None, self.name, field, getattr(self, field))
        if not self.lower < self.upper:
            raise DHTableError(origin, None, self.name, "lower", self.lower, f"must be < upper ({self.upper!r})")
        if not (self.velocity > 0 and self.effort > 0):
            raise DHTableError(origin, None, self.name, "velocity and effort", (self.velocity, self.effort),
                               "must be > 0")  # fmt: skip

    def constant_z(self) -> tuple[float, float]:
        """(theta, d) at q = 0, the offset included: the moving joint's origin rotation and height."""
        if self.type == "R":
            return self.offset, self.d
        return self.theta, self.offset


@dataclass(frozen=True)
class DHTable:
    """A validated D-H table.

    Attributes:
        name: the robot's name (letters, digits, ``_``).
        convention: ``"standard"`` or ``"modified"``.
        rows: the joints, base to tool.
        tool_xyz, tool_rpy: tool0 in the last D-H frame [m, rad] (URDF origin convention).
    """

    CONVENTIONS: ClassVar[tuple[str, ...]] = CONVENTIONS

    name: str
    convention: str
    rows: tuple[DHRow, ...]
    tool_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tool_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        origin = "DHTable"
        if not isinstance(self.name, str) or not _NAME_RE.match(self.name):
            raise DHTableError(origin, None, None, "name", self.name, "must be letters, digits and _ (not first)")
        if self.convention not in CONVENTIONS:
            raise DHTableError(origin, None, None, "convention", self.convention, "must be standard or modified")
        if not self.rows or not all(isinstance(r, DHRow) for r in self.rows) or len(self.rows) > _MAX_ROWS:
            raise DHTableError(origin, None, None, "rows", len(self.rows), f"must be 1 to {_MAX_ROWS} DHRow")
        for field in ("tool_xyz", "tool_rpy"):
            values = getattr(self, field)
            if len(values) != 3:
                raise DHTableError(origin, None, None, field, values, "must be 3 numbers")
            for v in values:
                _number(origin, None, None, field, v)


# --------------------------------------------------------------------------------------------- reading
def load_dh_table(path: str | Path) -> DHTable:
    """Read and validate a D-H table from a yaml file.

    Raises:
        DHTableError: unreadable file, invalid yaml, or a field that breaks a rule.
    """
    path = Path(path)
    origin = str(path)
    from ..limits import read_text
    from .yaml_units import load_yaml

    try:
        text = read_text(path, "D-H table")  # bounded: /dev/zero or a huge file is refused, not read whole
    except InvalidInputError as exc:
        raise DHTableError(origin, None, None, "file", ParameterError.NOTHING,
                           f"cannot be read ({exc})") from None  # fmt: skip
    try:
        data = load_yaml(text, origin)  # bounded: an alias bomb is refused
    except YamlError as exc:
        where = f" (line {exc.line})" if exc.line is not None else ""
        rule = "is refused" if exc.refused else "must be valid yaml"  # refused: over a cap of the loader
        raise DHTableError(origin, None, None, "yaml", ParameterError.NOTHING,
                           f"{rule}{where}: {exc.problem}") from None  # fmt: skip
    return parse_dh_table(data, origin=origin)


def _number(origin: str, row: int | None, joint: str | None, field: str, raw: object) -> float:
    """A finite float from a number, a unit-tagged number or a pi expression (never evaluated)."""
    if isinstance(raw, str):
        m = _PI_RE.match(raw)
        if m is None:
            raise DHTableError(origin, row, joint, field, raw, "must be a number (or pi, -pi/2, 2*pi/3)")
        sign, factor, divisor = m.groups()
        value = (-1.0 if sign == "-" else 1.0) * float(factor or 1.0) * math.pi / float(divisor or 1.0)
    elif isinstance(raw, bool) or not isinstance(raw, numbers.Real):
        raise DHTableError(origin, row, joint, field, raw, "must be a number")
    else:
        value = float(raw)
    if not math.isfinite(value):
        raise DHTableError(origin, row, joint, field, raw, "must be finite")
    if abs(value) > _MAX_ABS:
        raise DHTableError(origin, row, joint, field, raw, f"must be within +/-{_MAX_ABS:g} (m or rad)")
    return value


def _check_keys(
    origin: str, row: int | None, joint: str | None, data: Mapping[Any, Any], allowed: Sequence[str]
) -> None:
    for key in data:
        if key not in allowed:
            raise DHTableError(origin, row, joint, str(key), ParameterError.NOTHING,
                               f"is not a field here (fields: {', '.join(allowed)})")  # fmt: skip


def _parse_row(origin: str, i: int, raw: object, convention: str) -> DHRow:
    if not isinstance(raw, Mapping):
        raise DHTableError(origin, i, None, "row", raw, "must be a mapping of fields")
    name = raw.get("name")
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise DHTableError(origin, i, None, "name", name if name is not None else ParameterError.NOTHING,
                           "must be given: letters, digits and _ (not first), at most 64")  # fmt: skip
    _check_keys(origin, i, name, raw, _ROW_KEYS)
    kind = raw.get("type")
    if not isinstance(kind, str) or kind not in _TYPES:
        raise DHTableError(origin, i, name, "type", kind if kind is not None else ParameterError.NOTHING,
                           "must be R (revolute) or P (prismatic)")  # fmt: skip
    kind = _TYPES[kind]
    variable = "theta" if kind == "R" else "d"
    values: dict[str, float] = {}
    for field in ("theta", "d", "a", "alpha"):
        if field == variable:
            if raw.get(field, "q") != "q":
                joint_kind = "revolute" if kind == "R" else "prismatic"
                raise DHTableError(origin, i, name, field, raw[field],
                                   f"is the variable of a {joint_kind} row: write q "
                                   "(a constant goes into offset)")  # fmt: skip
            values[field] = 0.0
            continue
        if field not in raw:
            what = "alpha_{i-1}" if field == "alpha" and convention == "modified" else field
            raise DHTableError(origin, i, name, field, ParameterError.NOTHING, f"is required (D-H {what})")
        values[field] = _number(origin, i, name, field, raw[field])
    values["offset"] = _number(origin, i, name, "offset", raw.get("offset", 0.0))
    for field in ("lower", "upper", "velocity", "effort"):
        if field not in raw:
            raise DHTableError(origin, i, name, field, ParameterError.NOTHING, "is required (joint limit)")
        values[field] = _number(origin, i, name, field, raw[field])
    if not values["lower"] < values["upper"]:
        raise DHTableError(origin, i, name, "lower", values["lower"], f"must be < upper ({values['upper']!r})")
    for field in ("velocity", "effort"):
        if values[field] <= 0:
            raise DHTableError(origin, i, name, field, values[field], "must be > 0")
    return DHRow(name=name, type=kind, **values)


def _triple(origin: str, field: str, raw: object) -> tuple[float, float, float]:
    if not isinstance(raw, Sequence) or isinstance(raw, str) or len(raw) != 3:
        raise DHTableError(origin, None, None, field, raw, "must be a list of 3 numbers")
    x, y, z = (_number(origin, None, None, f"{field}[{k}]", v) for k, v in enumerate(raw))
    return x, y, z


def parse_dh_table(data: object, *, origin: str = "D-H table") -> DHTable:
    """Validate a D-H table given as yaml data (a mapping, see the module docstring).

    Args:
        data: the parsed yaml.
        origin: how to name the source in error messages (a file name).

    Raises:
        DHTableError: the first broken rule, naming the row, the joint and the field.
    """
    if not isinstance(data, Mapping):
        raise DHTableError(origin, None, None, "table", data, "must be a mapping (name, convention, units, joints)")
    _check_keys(origin, None, None, data, _TOP_KEYS)
    name = data.get("name", "dh_robot")
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise DHTableError(origin, None, None, "name", name, "must be letters, digits and _ (not first), at most 64")
    convention = data.get("convention")
    if convention not in CONVENTIONS:
        raise DHTableError(origin, None, None, "convention",
                           convention if convention is not None else ParameterError.NOTHING,
                           "must be standard or modified")  # fmt: skip
    units = data.get("units")
    if not isinstance(units, Mapping):
        raise DHTableError(origin, None, None, "units", units if units is not None else ParameterError.NOTHING,
                           "must be stated: {length: m, angle: rad} "
                           "(SI; use !degrees or !millimeters tags)")  # fmt: skip
    _check_keys(origin, None, None, units, ("length", "angle"))
    for key, si in (("length", "m"), ("angle", "rad")):
        if units.get(key) != si:
            raise DHTableError(origin, None, None, f"units.{key}",
                               units.get(key, ParameterError.NOTHING),
                               f"must be {si} (SI; convert with the !degrees or !millimeters tags)")  # fmt: skip
    rows_raw = data.get("joints")
    if not isinstance(rows_raw, list) or not rows_raw:
        raise DHTableError(origin, None, None, "joints", rows_raw if rows_raw is not None else ParameterError.NOTHING,
                           "must be a non-empty list of rows")  # fmt: skip
    if len(rows_raw) > _MAX_ROWS:
        raise DHTableError(origin, None, None, "joints", f"{len(rows_raw)} rows", f"must have at most {_MAX_ROWS} rows")
    rows = tuple(_parse_row(origin, i, raw, convention) for i, raw in enumerate(rows_raw, start=1))
    reserved = set(_link_names(len(rows))) | {"base_link-base", f"link{len(rows)}-tool0"}
    seen: dict[str, int] = {}
    for i, row in enumerate(rows, start=1):
        if row.name in seen:
            raise DHTableError(origin, i, row.name, "name", row.name, f"must be unique (row {seen[row.name]} has it)")
        if row.name in reserved:
            raise DHTableError(origin, i, row.name, "name", row.name, "must not be a generated link name")
        seen[row.name] = i
    tool = data.get("tool", {})
    if not isinstance(tool, Mapping):
        raise DHTableError(origin, None, None, "tool", tool, "must be a mapping {xyz: [x, y, z], rpy: [r, p, y]}")
    _check_keys(origin, None, None, tool, ("xyz", "rpy"))
    xyz = _triple(origin, "tool.xyz", tool.get("xyz", [0.0, 0.0, 0.0]))
    rpy = _triple(origin, "tool.rpy", tool.get("rpy", [0.0, 0.0, 0.0]))
    return DHTable(name=name, convention=convention, rows=rows, tool_xyz=xyz, tool_rpy=rpy)


# --------------------------------------------------------------------------------------------- writing
def _link_names(n: int) -> list[str]:
    names = ["base_link", "base", "tool0"]
    for i in range(1, n + 1):
        names += [f"link{i}", f"link{i}_z", f"link{i}_x"]
    return names


def _f(v: float) -> str:
    return repr(float(v))


def dh_to_urdf(table: DHTable | Mapping[str, Any] | str | Path) -> str:
    """The URDF of a D-H table (see the module docstring for the frames).

    Args:
        table: a validated table, yaml data, or the path of a yaml file.

    Returns:
        The URDF document as a string.

    Raises:
        DHTableError: the table breaks a rule.
    """
    import xml.etree.ElementTree as ET

    if isinstance(table, (str, Path)):
        table = load_dh_table(table)
    elif not isinstance(table, DHTable):
        table = parse_dh_table(table)
    robot = ET.Element("robot", name=table.name)
    rows = len(table.rows)
    robot.append(ET.Comment(f" generated by scara_pin.dh from a {table.convention} D-H table ({rows} rows) "))

    def link(name: str) -> None:
        ET.SubElement(robot, "link", name=name)

    def joint(name: str, kind: str, parent: str, child: str, xyz: Sequence[float], rpy: Sequence[float]) -> ET.Element:
        el = ET.SubElement(robot, "joint", name=name, type=kind)
        ET.SubElement(el, "parent", link=parent)
        ET.SubElement(el, "child", link=child)
        ET.SubElement(el, "origin", xyz=" ".join(map(_f, xyz)), rpy=" ".join(map(_f, rpy)))
        return el

    def fixed_x(parent: str, child: str, a: float, alpha: float) -> None:
        link(child)
        joint(f"{parent}-{child}", "fixed", parent, child, (a, 0.0, 0.0), (alpha, 0.0, 0.0))

    def moving(row: DHRow, i: int, parent: str, child: str) -> None:
        theta, d = row.constant_z()
        robot.append(ET.Comment(
            f" D-H row {i}: {'theta = q + ' + _f(row.offset) if row.type == 'R' else 'theta = ' + _f(row.theta)}, "
            f"{'d = q + ' + _f(row.offset) if row.type == 'P' else 'd = ' + _f(row.d)}, "
            f"a = {_f(row.a)}, alpha = {_f(row.alpha)} "
        ))  # fmt: skip
        link(child)
        el = joint(row.name, "revolute" if row.type == "R" else "prismatic", parent, child, (0.0, 0.0, d),
                   (0.0, 0.0, theta))  # fmt: skip
        ET.SubElement(el, "axis", xyz="0 0 1")
        ET.SubElement(el, "limit", lower=_f(row.lower), upper=_f(row.upper), velocity=_f(row.velocity),
                      effort=_f(row.effort))  # fmt: skip

    link("base_link")
    link("base")
    joint("base_link-base", "fixed", "base_link", "base", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    parent = "base"
    for i, row in enumerate(table.rows, start=1):
        if table.convention == "standard":  # A_i = [Rz(theta) Tz(d)] [Tx(a) Rx(alpha)]
            moving(row, i, parent, f"link{i}_z")
            fixed_x(f"link{i}_z", f"link{i}", row.a, row.alpha)
        else:  # A_i = [Rx(alpha_{i-1}) Tx(a_{i-1})] [Rz(theta) Tz(d)]; Rx(alpha) Tx(a) = Tx(a) Rx(alpha)
            fixed_x(parent, f"link{i}_x", row.a, row.alpha)
            moving(row, i, f"link{i}_x", f"link{i}")
        parent = f"link{i}"
    link("tool0")
    joint(f"{parent}-tool0", "fixed", parent, "tool0", table.tool_xyz, table.tool_rpy)
    ET.indent(robot, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


# --------------------------------------------------------------------------------------------- examples
def _examples_dir() -> Path:
    from . import urdf_dir

    return urdf_dir() / "examples"


def dh_examples() -> dict[str, Path]:
    """The shipped example tables by name (``s1_dh``: S1, standard; ``s3_dh``: S3, modified)."""
    return {p.stem: p for p in sorted(_examples_dir().glob("*_dh.yaml"))}


def dh_example(name: str) -> Path:
    """The path of a shipped example table.

    Raises:
        DHTableError: no example of that name.
    """
    examples = dh_examples()
    if name not in examples:
        raise DHTableError("examples", None, None, "name", name, f"must be one of {', '.join(examples)}")
    return examples[name]
