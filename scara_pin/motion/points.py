"""Taught points: named joint configurations, as a teach pendant records them, and their file.

A taught point is a NAME and the joint values ``q`` the robot had when it was recorded: ``q`` is the point
(it fixes the elbow branch and the J4 turn, which a pose alone does not). Its tool pose (x, y, z, yaw of the
tool frame in the base frame, Pinocchio's FK at ``q``) is written beside it for reading, and checked on
reading when present: a file taught on another robot (other lengths, other zero offsets) is refused
instead of silently moving elsewhere.

A POSE POINT (:class:`PosePoint`, Epson SPEL+'s ``XY(x, y, z, u) /R``) is a NAME and a tool pose: ``xyz`` and
``yaw``, the elbow branch ``hand`` (``right`` or ``left``; a palletizer's ``up`` or ``down``) and ``turns``, the
J4 turn (the wrist's angle within pi of 2 pi turns; 0 by default), optionally in a named ``frame`` (a job's
frames: SPEL+'s ``Local``; without one, the cell's world frame, which is the robot's base unless a job places
the robot). Its joint values are the closed-form IK of the pose on that branch at that turn
(:meth:`PosePoint.solve`): the same configuration on every robot of the same geometry, and the point moves with
its frame. A pose point of a frame is only a job's (:mod:`scara_pin.job`): elsewhere (``traj --through``, the
pendant, ``check --cell``) a points file's pose points are in the base frame.

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

    - name: T11                    # a pose point (YAML files only)
      xyz: [0.22, -0.06, -0.1]
      yaw: 0.5
      hand: right
      turns: 0                     # optional (0: the wrist within pi of 0)
      frame: tray                  # optional: a frame of the job that uses the file

Names: a letter, then up to 31 letters, digits, ``_``, ``-`` or ``.`` (``P1``, ``pick_2``, ``home``);
case-sensitive, unique in a file. At most :data:`scara_pin.limits.MAX_POINTS` points, and the file at most
:data:`scara_pin.limits.MAX_POINTS_BYTES` bytes.
"""

from __future__ import annotations

import csv
import io
import math
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InfeasibleError, InvalidInputError, ParameterError, brief
from ..limits import MAX_POINTS, MAX_POINTS_BYTES, check_input_file, read_text
from ..units import number_text

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = [
    "FORMAT",
    "HANDS",
    "POSE_TOL",
    "Point",
    "PointSet",
    "PosePoint",
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
        """JSON-ready: name, form ``joint``, q, pose (None when unknown) in SI."""
        return {"name": self.name, "form": "joint", "q": [float(v) for v in self.q],
                "pose": None if self.pose is None else [float(v) for v in self.pose]}  # fmt: skip


HANDS = ("right", "left", "up", "down")
"""The elbow branches a pose point may name: a SCARA's ``right``/``left``, a palletizer's ``up``/``down``."""
TURN_TOL = 1e-9
"""[rad] how far past pi from 2 pi turns a pose point's wrist angle may be (the boundary between two turns)."""


@dataclass(frozen=True, eq=False)
class PosePoint:
    """A pose point: a tool pose with its elbow branch and wrist turn (module docstring).

    Attributes:
        name: its name.
        xyz: (3,) the tool frame's origin in ``frame`` [m].
        yaw: the tool's yaw in ``frame`` [rad].
        hand: the elbow branch (:data:`HANDS`; the robot's own branches are checked against it).
        turns: the wrist's turn: q4 within pi of 2 pi ``turns``.
        frame: the frame the pose is in ("" : the world frame, the robot's base unless a job places the robot).
    """

    name: str
    xyz: np.ndarray
    yaw: float
    hand: str
    turns: int = 0
    frame: str = ""

    def __post_init__(self) -> None:
        check_point_name(self.name)
        object.__setattr__(self, "xyz", _finite(f"point {self.name}: xyz", self.xyz, 3))
        yaw = self.yaw
        if isinstance(yaw, bool) or not isinstance(yaw, (int, float)) or not math.isfinite(yaw):
            raise InvalidInputError(f"point {self.name}: yaw {brief(yaw, 40)} must be a finite number [rad]")
        object.__setattr__(self, "yaw", float(yaw))
        if self.hand not in HANDS:
            raise InvalidInputError(f"point {self.name}: hand {brief(self.hand, 40)} must be one of {', '.join(HANDS)} "
                                    "(the elbow branch: SPEL+'s /R, /L)")  # fmt: skip
        turns = self.turns
        if isinstance(turns, bool) or not isinstance(turns, int) or abs(turns) > 1000:
            raise InvalidInputError(f"point {self.name}: turns {brief(turns, 40)} must be a whole number (the wrist's "
                                    "turn) within +/-1000")  # fmt: skip
        if self.frame and not _NAME.fullmatch(self.frame):
            raise InvalidInputError(f"point {self.name}: frame {brief(self.frame, 40)} must be a name")

    @property
    def pose(self) -> np.ndarray:
        """(x, y, z, yaw) in :attr:`frame` [m, rad]."""
        return np.array([*self.xyz, self.yaw])

    @classmethod
    def at(cls, robot: RobotModel, name: str, q: object) -> PosePoint:
        """The pose point of ``robot`` at joint values ``q``: its FK pose, branch and wrist turn (base frame)."""
        values = robot.check_q(q)
        pose = robot.tool_pose(values)
        return cls(name, pose[:3], float(pose[3]), robot.branch_of(values), round(float(values[-1]) / (2 * math.pi)))

    def solve(self, robot: RobotModel, pose: np.ndarray | None = None) -> np.ndarray:
        """The joint values of the point: the closed-form IK on :attr:`hand`, the wrist at :attr:`turns`.

        ``pose``: the pose in the robot's base frame (default: :attr:`pose`); the other joints at the turn nearest 0.

        Raises:
            InvalidInputError: a hand that is not one of the robot's branches.
            InfeasibleError: the pose out of reach on that branch, or no wrist angle of that turn within the limits.
        """
        branches = tuple(robot.kinematics.branches)
        if self.hand not in branches:
            raise InvalidInputError(f"point {self.name}: hand {self.hand} is not a branch of robot {robot.name!r} "
                                    f"({', '.join(branches)})")  # fmt: skip
        target = self.pose if pose is None else np.asarray(pose, dtype=float)
        reference = np.zeros(robot.dof)
        reference[-1] = 2.0 * math.pi * self.turns
        result = robot.ik(target, branch=self.hand, reference=reference)
        best = result.nearest(reference, branch=self.hand) if result.success else None
        shown = ", ".join(f"{v:.6g}" for v in target)
        if best is None:
            raise InfeasibleError(f"point {self.name} at (x, y, z, yaw) = ({shown}) [m, rad] is out of reach on the "
                                  f"{self.hand} branch: {result.message}")  # fmt: skip
        q = np.array(best.q, dtype=float)
        if abs(q[-1] - reference[-1]) > math.pi + TURN_TOL:
            raise InfeasibleError(f"point {self.name}: turns {self.turns} puts the wrist within pi of "
                                  f"{reference[-1]:.6g} rad, outside its limits (the nearest is q4 = {q[-1]:.6g} rad, "
                                  f"turns {round(q[-1] / (2 * math.pi))})")  # fmt: skip
        return q

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: name, form ``pose``, xyz, yaw, pose (x, y, z, yaw), hand, turns, frame (SI)."""
        return {"name": self.name, "form": "pose", "xyz": [float(v) for v in self.xyz], "yaw": self.yaw,
                "pose": [float(v) for v in self.pose], "hand": self.hand, "turns": self.turns,
                "frame": self.frame}  # fmt: skip


Point = TaughtPoint | PosePoint
"""A point of a points file: joint values, or a pose with its branch and turn."""


@dataclass(frozen=True, eq=False)
class PointSet:
    """An ordered set of taught points with unique names (immutable: the edits return a new set).

    Attributes:
        points: the points, in order.
        robot: the robot's name they were taught on ("" when unknown).
        base: the base frame of the poses ("" when unknown).
        tool: the tool frame of the poses ("" when unknown).
    """

    points: tuple[Point, ...] = ()
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

    def __iter__(self) -> Iterator[Point]:
        return iter(self.points)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    @property
    def names(self) -> tuple[str, ...]:
        """The names, in order."""
        return tuple(p.name for p in self.points)

    def __getitem__(self, name: str) -> Point:
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

    def added(self, point: Point) -> PointSet:
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
        moved = replace(point, name=new)
        return replace(self, points=tuple(moved if p.name == old else p for p in self.points))

    def removed(self, name: str) -> PointSet:
        """A copy without point ``name``."""
        self[name]  # noqa: B018 - raises naming the known points when there is none
        return replace(self, points=tuple(p for p in self.points if p.name != name))

    def check(self, robot: RobotModel, origin: str = "points") -> None:
        """Refuse points that do not fit ``robot``.

        Another joint count, a joint value the robot cannot take (beyond +/-1e6 rad or m:
        :meth:`~scara_pin.model.RobotModel.check_q`), or a written pose that is not the FK of its q on this robot
        (beyond :data:`POSE_TOL`; the yaw compared modulo 2 pi); a pose point whose hand is not a branch of the
        robot. The joint limits are not checked here: a pendant shows such a point; a command that moves to it
        refuses it (a pose point's reach is :meth:`resolved`'s).

        Raises:
            InvalidInputError: naming the point and what differs.
        """
        branches = tuple(robot.kinematics.branches)
        for p in self.points:
            if isinstance(p, PosePoint):
                if p.hand not in branches:
                    raise InvalidInputError(f"{origin}: point {p.name}: hand {p.hand} is not a branch of robot "
                                            f"{robot.name!r} ({', '.join(branches)})")  # fmt: skip
                continue
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

    def q_of(self, name: str) -> np.ndarray:
        """The joint values of joint point ``name`` (a pose point's are :meth:`resolved`'s: refused here).

        Raises:
            InvalidInputError: no point of that name, or a pose point.
        """
        point = self[name]
        if isinstance(point, PosePoint):
            raise InvalidInputError(f"point {name} is a pose point: its joint values are the robot's IK of it "
                                    "(PointSet.resolved)")  # fmt: skip
        return point.q

    @property
    def poses(self) -> bool:
        """Whether any point is a pose point."""
        return any(isinstance(p, PosePoint) for p in self.points)

    def resolved(self, robot: RobotModel, to_base: Callable[[PosePoint], np.ndarray] | None = None,
                 origin: str = "points") -> PointSet:  # fmt: skip
        """The set with every pose point replaced by the joint point it is on ``robot`` (:meth:`PosePoint.solve`).

        Args:
            robot: the robot.
            to_base: a pose point's pose in the robot's base frame (a job's frames and base placement); None: a
                pose point is in the base frame, and one of a named frame is refused.
            origin: how to name the set in messages.

        Raises:
            InvalidInputError: a pose point of a frame without ``to_base``, a hand that is not a branch.
            InfeasibleError: a pose point out of reach (naming it).
        """
        out: list[Point] = []
        for p in self.points:
            if isinstance(p, PosePoint):
                if to_base is None and p.frame:
                    raise InvalidInputError(f"{origin}: point {p.name} is in frame {p.frame}: only a job knows its "
                                            "frames (scara-pin job)")  # fmt: skip
                pose = p.pose if to_base is None else to_base(p)
                p = TaughtPoint(p.name, p.solve(robot, pose), np.asarray(pose, dtype=float))
            out.append(p)
        return replace(self, points=tuple(out))

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
            if isinstance(p, PosePoint):
                lines.append(f"  xyz: [{', '.join(repr(float(v)) for v in p.xyz)}]")
                lines += [f"  yaw: {p.yaw!r}", f"  hand: {p.hand}", f"  turns: {p.turns}"]
                if p.frame:
                    lines.append(f"  frame: {p.frame}")
                continue
            lines.append(f"  q: [{', '.join(repr(float(v)) for v in p.q)}]")
            if p.pose is not None:
                lines.append(f"  pose: [{', '.join(repr(float(v)) for v in p.pose)}]")
        return "\n".join(lines) + "\n"

    def to_csv(self) -> str:
        """The CSV points file (full precision, SI; empty pose cells when a pose is unknown).

        Raises:
            InvalidInputError: a pose point (a YAML points file holds them).
        """
        posed = [p.name for p in self.points if isinstance(p, PosePoint)]
        if posed:
            raise InvalidInputError(f"point {posed[0]} is a pose point: a CSV points file holds joint points only; "
                                    "write a .yaml points file")  # fmt: skip
        dof = max((p.q.size for p in self.points if isinstance(p, TaughtPoint)), default=4)
        out = io.StringIO()
        meta = " ".join(f"{k}={v}" for k, v in (("robot", self.robot), ("base", self.base), ("tool", self.tool)) if v)
        out.write(f"# {FORMAT}: {meta + ' ' if meta else ''}units=m,rad\n")
        writer = csv.writer(out, lineterminator="\n")
        writer.writerow(["name", *(f"q{i + 1}" for i in range(dof)), *_POSE_NAMES])
        for p in self.points:
            assert isinstance(p, TaughtPoint)  # noqa: S101 - refused above
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
    points: list[Point] = []
    for i, item in enumerate(items):
        where = _at(items, i)
        if isinstance(item, dict) and "name" in item and "q" not in item and ("xyz" in item or "hand" in item):
            points.append(_pose_point(item, where, i))
            continue
        if not isinstance(item, dict) or "name" not in item or "q" not in item:
            raise InvalidInputError(f"{where}point #{i + 1} must be a mapping with name and q (and optionally pose), "
                                    "or a pose point: name, xyz, yaw, hand (and optionally turns, frame)")  # fmt: skip
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


_POSE_KEYS = ("name", "xyz", "yaw", "hand", "turns", "frame")


def _pose_point(item: dict[str, Any], where: str, i: int) -> PosePoint:
    """A pose point of a YAML points file (SI; unit tags read)."""
    extra = sorted(brief(k, 40) for k in item if k not in _POSE_KEYS)
    if extra:
        raise InvalidInputError(f"{where}point #{i + 1}: unknown key(s) {', '.join(extra[:10])} (a pose point's keys: "
                                f"{', '.join(_POSE_KEYS)})")  # fmt: skip
    missing = [k for k in ("xyz", "yaw", "hand") if k not in item]
    if missing:
        raise InvalidInputError(f"{where}point #{i + 1}: a pose point needs {', '.join(missing)} (keys: "
                                f"{', '.join(_POSE_KEYS)})")  # fmt: skip
    try:
        name = check_point_name(item["name"])
    except InvalidInputError as exc:
        raise InvalidInputError(f"{_at(item, 'name')}{exc}") from None
    xyz = np.array(_yaml_numbers(f"{_at(item, 'xyz')}point {name}: xyz", item["xyz"]))
    yaw = _yaml_numbers(f"{_at(item, 'yaw')}point {name}: yaw", [item["yaw"]])[0]
    frame = item.get("frame", "")
    try:
        return PosePoint(name, xyz, yaw, item["hand"], item.get("turns", 0), frame if frame is not None else "")
    except InvalidInputError as exc:
        raise InvalidInputError(f"{where}{exc}") from None


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
                meta.update(re.findall(r"\b(robot|base|tool)=(\S+)", stripped))
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
