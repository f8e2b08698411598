"""The job file: a yaml program of moves over taught points and pallets, read and checked before any planning.

The format (docs/job.md has it beside its SPEL+ and RAPID equivalents)::

    format: scara-pin job 1          # optional; checked when present
    robot: default                   # optional; the robot the job is for (checked against the one planning it)
    units: mm,deg                    # optional: the lengths and angles of this file (default m, rad)
    points: points.yaml              # the taught points (the pendant's file: joint or pose points, SI)
    frames:                          # optional: frames in the cell (SPEL+'s Local), in their parent (default world)
      tray: {xyz: [220, -60, -100], yaw: 0, parent: world}
    base: {xyz: [0, 0, 0], yaw: 0}   # optional: the robot's base in the cell's world frame
    poses:                           # optional: pose points written here, in a frame (default world)
      T11: {xyz: [0, 0, 0], yaw: 28.6, hand: right, turns: 0, frame: tray}
    speed: 100                       # optional: every move's velocity limits times this % too (the override)
    accel: 100                       # optional: every move's acceleration limits times this % too
    jerk: 2000                       # optional: joint jerk limits, one or one per joint [rad/s^3, m/s^3]
    start: feeder                    # optional: where the robot is when the job begins (default: the first target)
    jump: {rise: 0.025, clearance_radius: 0.005, max_height: 0.0}   # optional: every jump's clearance
    torque: false                    # optional: also respect the effort limits (with payload: the load)
    payload: {mass: 0.5, com: [0, 0, 0.02]}    # optional, with torque: true [kg, m in the tool frame]
    cell: cell.yaml                  # optional: obstacles, every move kept the cell's margin away from them
    carry: {shape: box, size: [0.2, 0.3, 0.15], xyz: [0, 0, 0.095]}  # optional: the part held from pick: to place:
    pallets:
      tray: {corners: [T11, T16, T41], rows: 4, columns: 6}
    steps:
      - speed: 100
      - for: tray
        do:
          - jump: tray[i]
          - dwell: 0.05

With ``carry``, ``pick: S`` and ``place: S`` steps say when the tool holds the part (the gripper closing and
opening during S seconds at rest); each place leaves a box that every later move avoids (docs/job.md,
"Palletizing"). A pick while holding, a place while empty, grips without ``carry`` and ``carry`` without grips
are refused here (:func:`~scara_pin.job.steps.check_grips`).

Lengths are metres and angles radians unless ``units:`` names others (``mm,deg``: then every length and angle
of the file, poses, frames, the base, clearances, the carry, and the jerk limits per joint kind, is in those);
values may carry xacro's unit tags (``!millimeters 150``, ``!degrees 90``), read as written whatever ``units:``
says; times are seconds, ``speed`` and ``accel`` percentages. ``read_job(path, overrides)`` replaces values at
dotted keys before the checks (:mod:`~scara_pin.job.overrides`: ``--set frames.tray.xyz=[...]``). The file is
read through the package's one yaml loader (:func:`~scara_pin.description.yaml_units.load_yaml`, its caps
included) and sized first
(:data:`~scara_pin.limits.MAX_JOB_BYTES`); its node tree (composed a second time, never constructed) gives
the line of each value for the messages.

Everything that can be checked without a robot is checked here, each refusal a
:class:`~scara_pin.errors.JobFileError` (exit 2) naming the file, the line and the reason: unknown keys,
steps and points, pallets without enough corners, percentages outside (0, 100], an index past a pallet's
end (a loop variable's whole range checked against it), loops nested deeper than
:data:`~scara_pin.limits.MAX_JOB_DEPTH`, and more moves and dwells than
:data:`~scara_pin.limits.MAX_JOB_STEPS` (counted, never unrolled). With the robot,
:meth:`~scara_pin.job.spec.JobSpec.program` then checks the points (the pendant's poses against the robot's FK;
pose points solved), the pallets' corners (collinear, coincident, folded) and every place's reach.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn, TypeVar

import numpy as np

from ..description.yaml_units import Tagged, load_yaml, yaml_line
from ..errors import InvalidInputError, JobFileError, ParameterError, YamlError
from ..limits import (
    MAX_DOCUMENT_BYTES,
    MAX_DWELL,
    MAX_JOB_BYTES,
    MAX_JOB_DEPTH,
    MAX_JOB_STEPS,
    check_input_file,
    read_text,
)
from ..motion.payload import Payload
from ..motion.points import PointSet, PosePoint, check_point_name, read_points
from ..units import SI, DisplayUnits
from .frames import BASE, WORLD, Frame, FrameTree
from .overrides import Override, apply_overrides
from .pallets import Order, Pallet
from .spec import Carry, JobSpec
from .steps import (
    VARIABLE,
    Dwell,
    Grip,
    GripKind,
    JumpShape,
    Loop,
    MotionStep,
    MoveKind,
    Setting,
    Step,
    Target,
    check_grips,
    parse_target,
    tally,
)

__all__ = ["FORMAT", "KEYS", "read_carry", "read_job"]

FORMAT = "scara-pin job 1"
"""The ``format:`` value of a job file."""

KEYS = ("format", "robot", "units", "points", "frames", "base", "poses", "speed", "accel", "jerk", "start", "jump",
        "torque", "payload", "cell", "carry", "pallets", "steps")
"""The top-level keys of a job file (an override's first name is one of them)."""
_POSE_KEYS = ("xyz", "yaw", "hand", "turns", "frame")
_PALLET_KEYS = ("corners", "rows", "columns", "layers", "layer_height")
_JUMP_KEYS = ("rise", "clearance_radius", "max_height")
MAX_VIA = 16
"""The most via points of one jump (hints of its way: a few are enough; each one is a warm start's corner)."""
_STEP_KINDS = "speed, accel, jump, move, go, dwell, pick, place, for"
_T = TypeVar("_T")


class _At:
    """A value of the job file and the line where it is written; :meth:`fail` refuses it, naming the line.

    A value an override put there (:mod:`~scara_pin.job.overrides`), or inside one, has no line: its messages name
    the override (``origin``). ``units`` are the file's (its ``units:``): :meth:`length` and :meth:`angle` read in
    them.
    """

    def __init__(self, value: Any, path: Path, name: str, line: int | None, units: DisplayUnits = SI,
                 placed: dict[int, dict[Any, str]] | None = None, origin: str | None = None) -> None:  # fmt: skip
        self.value, self.path, self.name, self.line = value, path, name, line
        self.units, self.placed, self.origin = units, placed or {}, origin

    def fail(self, reason: str) -> NoReturn:
        if self.origin is not None:
            raise JobFileError(self.path, None, f"{self.origin}: {reason}")
        raise JobFileError(self.path, self.line, reason)

    def checked(self, make: Callable[[], _T]) -> _T:
        """``make()``, an InvalidInputError it raises refused here (:meth:`fail`) with its message."""
        try:
            return make()
        except InvalidInputError as exc:
            self.fail(str(exc))

    def child(self, key: str | int, name: str | None = None) -> _At:
        """The value at ``key`` of this mapping (or index of this list), with its line (the shared loader's)."""
        label = name if name is not None else (f"{self.name}[{key}]" if isinstance(key, int) else str(key))
        origin = self.origin or self.placed.get(id(self.value), {}).get(key)
        line = yaml_line(self.value, key)
        return _At(self.value[key], self.path, label, self.line if line is None else line, self.units, self.placed,
                   origin)  # fmt: skip

    def length(self, rule: Callable[[float], bool], what: str) -> float:
        """A length in the file's units [m] (a unit-tagged value as tagged): checked by ``rule`` as written."""
        return self._scaled("length", rule, what)

    def angle(self, rule: Callable[[float], bool], what: str) -> float:
        """An angle in the file's units [rad] (a unit-tagged value as tagged)."""
        return self._scaled("angle", rule, what)

    def _scaled(self, kind: str, rule: Callable[[float], bool], what: str) -> float:
        scale = self.units.scale(kind)
        if isinstance(self.value, Tagged) or scale == 1.0:
            return self.number(rule, what, "m" if kind == "length" else "rad")
        return self.number(rule, what, self.units.name(kind)) / scale

    def mapping(self, keys: tuple[str, ...], required: tuple[str, ...] = ()) -> dict[str, _At]:
        """The entries of a mapping with only ``keys`` (and every ``required`` one)."""
        if not isinstance(self.value, dict):
            self.fail(f"{self.name} must be a mapping ({', '.join(keys)})")
        unknown = [k for k in self.value if k not in keys]
        if unknown:
            where = self.child(unknown[0]) if isinstance(unknown[0], str) else self
            where.fail(f"{self.name}: unknown key(s) {', '.join(sorted(map(str, unknown)))} (keys: {', '.join(keys)})")
        missing = [k for k in required if k not in self.value]
        if missing:
            self.fail(f"{self.name} needs {', '.join(missing)}")
        return {k: self.child(k) for k in self.value}

    def elements(self) -> list[_At]:
        if not isinstance(self.value, list):
            self.fail(f"{self.name} must be a list")
        return [self.child(i) for i in range(len(self.value))]

    def text(self, limit: int = 200) -> str:
        if not isinstance(self.value, str) or not self.value or len(self.value) > limit:
            self.fail(f"{self.name} must be text of 1 to {limit} characters, got {_shown(self.value)}")
        return self.value

    def number(self, rule: Callable[[float], bool], what: str, unit: str = "") -> float:
        v = self.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.fail(f"{self.name} is {_shown(v)}; it must be a number{' [' + unit + ']' if unit else ''}, {what}")
        if not math.isfinite(v) or not rule(float(v)):
            self.fail(f"{self.name} is {_shown(v)}{' ' + unit if unit else ''}; it must be {what}")
        return float(v)

    def whole(self, low: int, high: int) -> int:
        v = self.value
        if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
            self.fail(f"{self.name} is {_shown(v)}; it must be a whole number in [{low:,}, {high:,}]")
        return int(v)

    def boolean(self) -> bool:
        if not isinstance(self.value, bool):
            self.fail(f"{self.name} must be true or false, got {_shown(self.value)}")
        return self.value


def _shown(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:40] + "..."


def read_job(path: str | Path, overrides: Iterable[Override] = (), *, text: str | None = None) -> JobSpec:
    """Read a job file and check it (module docstring); the points file is read too.

    :func:`~scara_pin.job.job.load_job` gives it as the :class:`~scara_pin.job.job.Job` users hold.

    Args:
        path: the job file (names the job in messages; its folder is where its points and cell files are).
        overrides: values replaced at their dotted keys before the checks (:mod:`~scara_pin.job.overrides`).
        text: the job file's text, read before (a variant of a job read once); None: read ``path``.

    Raises:
        JobFileError: the file, the line (or the override) and the reason of the first problem (exit 2).
        InvalidInputError: the file cannot be read (missing, not a regular file, over its cap, not UTF-8).
    """
    path = Path(path)
    if text is None:
        text = read_text(check_input_file(path, "job file", MAX_JOB_BYTES), "job file", MAX_JOB_BYTES)
    try:
        data = load_yaml(text, str(path))  # the one bounded loader: every value knows its line
    except YamlError as exc:
        raise JobFileError(path, exc.line, exc.problem if exc.refused else f"not valid YAML ({exc.problem})") from None
    overrides = tuple(overrides)
    try:
        data, placed = apply_overrides(data, overrides)
    except InvalidInputError as exc:
        raise JobFileError(path, None, str(exc)) from None
    top = _At(data, path, "the job", yaml_line(data), placed=placed)
    if isinstance(data, dict) and "units" in data:
        top.units = _units(top.child("units"))
    entries = top.mapping(KEYS, required=("steps",))
    if "points" not in entries and "poses" not in entries:
        top.fail("the job needs points: (the pendant's points file) or poses: (pose points written here), or both")
    lines = {k: at.line for k, at in entries.items()}
    if "format" in entries and entries["format"].value != FORMAT:
        entries["format"].fail(f"format {_shown(entries['format'].value)} is not {FORMAT!r}")
    robot = entries["robot"].text() if "robot" in entries else None
    points_file, points = _points(entries["points"], path) if "points" in entries else (None, PointSet())
    frames = _frames(entries)
    if "poses" in entries:
        points = _poses(entries["poses"], points)
    _pose_frames(points, frames, entries)
    pallets = {}
    if "pallets" in entries:
        items = entries["pallets"]
        if not isinstance(items.value, dict):
            items.fail("pallets must be a mapping of names to {corners, rows, columns[, layers, layer_height]}")
        for name in items.value:
            at = items.child(name, f"pallet {name}")
            pallets[str(name)] = _pallet(at, str(name), points)
            lines[f"pallets.{name}"] = at.line
    shape = JumpShape(**_shape(entries["jump"].mapping(_JUMP_KEYS))) if "jump" in entries else JumpShape()
    torque = entries["torque"].boolean() if "torque" in entries else False
    payload = _payload(entries["payload"]) if "payload" in entries else Payload()
    if payload.mass and not torque:
        entries["payload"].fail("a payload changes only the torques: set torque: true too")
    cell = _cell(entries["cell"], path) if "cell" in entries else None
    carry = _carry(entries["carry"]) if "carry" in entries else None
    speed = _percent(entries["speed"]) / 100.0 if "speed" in entries else 1.0
    accel = _percent(entries["accel"]) / 100.0 if "accel" in entries else 1.0
    jerk = _jerk(entries["jerk"]) if "jerk" in entries else None
    start = None
    if "start" in entries:
        start = _target(entries["start"], points, pallets, {})
    steps_at = entries["steps"]
    if not isinstance(steps_at.value, list) or not steps_at.value:
        steps_at.fail("steps must be a non-empty list")
    steps = _steps(steps_at, points, pallets, {}, 0)
    count, dwell = tally(steps, pallets)
    _grips(steps, pallets, path, entries)
    if count > MAX_JOB_STEPS:
        steps_at.fail(f"the steps expand to {count:,} moves and dwells, above the cap of {MAX_JOB_STEPS:,} "
                      "(MAX_JOB_STEPS): split the job")  # fmt: skip
    return JobSpec(path=path, points_file=points_file, points=points, pallets=pallets, steps=steps, robot=robot,
                   start=start, jump=shape, torque=torque, payload=payload, cell=cell, carry=carry, actions=count,
                   dwell=dwell, lines=lines, frames=frames, speed=speed, accel=accel, jerk=jerk, units=top.units,
                   text=text, overrides=overrides)  # fmt: skip


def read_carry(path: str | Path) -> Carry:
    """The part a job carries, for the pendant and ``check --cell`` (``--carry FILE``).

    A job file's ``carry:`` (in its ``units:``), or a file that is that mapping itself (``{shape: box, size:
    [...], xyz: [...]}``).

    Raises:
        JobFileError: no carry, or one the job would refuse (the file and the line).
        InvalidInputError: the file cannot be read.
    """
    path = Path(path)
    text = read_text(check_input_file(path, "carry file", MAX_JOB_BYTES), "carry file", MAX_JOB_BYTES)
    try:
        data = load_yaml(text, str(path))
    except YamlError as exc:
        raise JobFileError(path, exc.line, exc.problem if exc.refused else f"not valid YAML ({exc.problem})") from None
    top = _At(data, path, "the file", yaml_line(data))
    if not isinstance(data, dict):
        top.fail("a carry file is a job file with carry:, or the carry itself: {shape: box, size: [x, y, z], xyz: "
                 "[...]}")  # fmt: skip
    if "units" in data:
        top.units = _units(top.child("units"))
    if "shape" in data:
        return _carry(top)
    if "carry" not in data:
        top.fail("no carry: in this file (a job's part: carry: {shape: box, size: [x, y, z], xyz: [...]})")
    return _carry(top.child("carry"))


def _units(at: _At) -> DisplayUnits:
    """``units: mm,deg`` (a text, or a list ``[mm, deg]``): the file's lengths and angles."""
    value = at.value
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        value = ",".join(value)
    if not isinstance(value, str):
        at.fail("units must name a length unit and an angle unit, e.g. units: mm,deg (m or mm; rad or deg)")
    try:
        return DisplayUnits.parse(value)
    except ParameterError:
        at.fail(f"units {_shown(value)} must name units among m, mm (lengths) and rad, deg (angles), e.g. mm,deg")


def _placement(at: _At, keys: tuple[str, ...]) -> dict[str, Any]:
    """``{xyz, yaw[, parent]}`` of a frame or of the base, in the file's units, SI out."""
    entries = at.mapping(keys)
    out: dict[str, Any] = {}
    if "xyz" in entries:
        out["xyz"] = _three(entries["xyz"], "xyz is 3 lengths [{unit}] (x, y, z in the parent frame)", kind="length")
    if "yaw" in entries:
        out["yaw"] = entries["yaw"].angle(math.isfinite, "a number (the turn about the parent's z axis)")
    if "parent" in entries:
        out["parent"] = entries["parent"].text(32)
    return out


def _frames(entries: Mapping[str, _At]) -> FrameTree:
    """The job's ``frames:`` and ``base:`` (module docstring of :mod:`~scara_pin.job.frames`)."""
    frames: dict[str, Frame] = {}
    if "frames" in entries:
        items = entries["frames"]
        if not isinstance(items.value, dict):
            items.fail("frames must be a mapping of names to {xyz, yaw, parent}")
        for name in items.value:
            at = items.child(name, f"frame {name}")
            if not isinstance(name, str) or not VARIABLE.fullmatch(name) or name in (WORLD, BASE):
                at.fail(f"frame name {_shown(name)} must be a letter or _ then letters, digits or _ (not world, base)")
            frames[name] = Frame(**_placement(at, ("xyz", "yaw", "parent")))
    base = Frame(**_placement(entries["base"], ("xyz", "yaw"))) if "base" in entries else Frame()
    try:
        return FrameTree(frames, base)
    except InvalidInputError as exc:
        entries["frames"].fail(str(exc))


def _poses(at: _At, points: PointSet) -> PointSet:
    """``poses:``: pose points written in the job, in its units, each name new to the points file."""
    if not isinstance(at.value, dict) or not at.value:
        at.fail("poses must be a mapping of names to {xyz, yaw, hand[, turns, frame]}")
    for name in at.value:
        item = at.child(name, f"pose {name}")
        _new_name(item, "pose", name, points)
        keys = item.mapping(_POSE_KEYS, required=("xyz", "yaw", "hand"))
        xyz = _three(keys["xyz"], "xyz is 3 lengths [{unit}] (the tool's position in its frame)", kind="length")
        yaw = keys["yaw"].angle(math.isfinite, "a number (the tool's yaw in its frame)")
        turns = keys["turns"].whole(-1000, 1000) if "turns" in keys else 0
        frame = keys["frame"].text(32) if "frame" in keys else ""
        try:
            points = points.added(PosePoint(name, np.array(xyz), yaw, keys["hand"].text(16), turns, frame))
        except InvalidInputError as exc:
            item.fail(str(exc))
    return points


def _new_name(at: _At, what: str, name: Any, points: PointSet) -> None:
    """A pose's or a pallet's name: a point's name (:func:`check_point_name`), none of the points file's."""
    try:
        check_point_name(name)
    except InvalidInputError:
        at.fail(f"{what} name {_shown(name)} must be a letter then up to 31 letters, digits, _, - or .")
    if name in points:
        at.fail(f"{what} {name} has the name of a point of the points file: name it otherwise")


def _pose_frames(points: PointSet, frames: FrameTree, entries: Mapping[str, _At]) -> None:
    """Every pose point's frame is one of the job's (or world, base)."""
    for p in points:
        if isinstance(p, PosePoint) and p.frame and p.frame not in (WORLD, BASE) and p.frame not in frames.frames:
            where = entries["poses"] if "poses" in entries and p.name in entries["poses"].value else entries["points"]
            where.fail(f"point {p.name} is in frame {p.frame}, which the job does not have (frames: "
                       f"{', '.join([WORLD, BASE, *frames.frames])})")  # fmt: skip


def _jerk(at: _At) -> tuple[float, ...]:
    """``jerk: J`` or ``[J1, J2, J3, J4]``: > 0, in the file's units per joint kind (scaled with the robot)."""
    values = at.elements() if isinstance(at.value, list) else [at]
    if len(values) not in (1, 4):
        at.fail("jerk is one number or one per joint (4)")
    return tuple(v.number(lambda x: x > 0, "> 0 (a joint jerk limit)", "per s^3") for v in values)


def _points(at: _At, job: Path) -> tuple[Path, PointSet]:
    file = job.parent / at.text(4096)
    return file, at.checked(lambda: read_points(file))


def _cell(at: _At, job: Path) -> Path:
    file = job.parent / at.text(4096)
    return at.checked(lambda: check_input_file(file, "cell file", MAX_DOCUMENT_BYTES))


def _carry(at: _At) -> Carry:
    keys = at.mapping(("shape", "size", "xyz", "rpy"), required=("shape", "size"))
    if keys["shape"].value != "box":
        keys["shape"].fail(f"carry shape {_shown(keys['shape'].value)} is not one scara-pin knows (box)")
    size = _three(keys["size"], "a box's size is 3 lengths [{unit}] (x, y, z in the tool frame)", lambda v: v > 0,
                  "> 0", kind="length")  # fmt: skip
    xyz = (_three(keys["xyz"], "xyz is 3 lengths [{unit}] (the part's centre in the tool frame)", kind="length")
           if "xyz" in keys else None)  # fmt: skip
    rpy = (_three(keys["rpy"], "rpy is 3 angles [{unit}] (roll, pitch, yaw in the tool frame)", kind="angle")
           if "rpy" in keys else None)  # fmt: skip
    carry = Carry("box", size, xyz, rpy or (0.0, 0.0, 0.0))
    try:
        carry.part()  # the cell's own checks: sizes and positions within their bounds
    except InvalidInputError as exc:
        at.fail(f"carry: {exc}")
    return carry


def _three(at: _At, what: str, rule: Callable[[float], bool] = math.isfinite, rule_text: str = "a number",
           kind: str = "length") -> tuple[float, float, float]:  # fmt: skip
    """Three lengths (or angles) in the file's units, SI out."""
    values = at.elements()
    if len(values) != 3:
        at.fail(what.format(unit=at.units.name(kind)))
    read = _At.length if kind == "length" else _At.angle
    a, b, c = (read(v, rule, rule_text) for v in values)
    return a, b, c


def _grips(steps: tuple[Step, ...], pallets: Mapping[str, Pallet], path: Path, entries: Mapping[str, _At]) -> None:
    """The picks and places in order, and ``carry`` given exactly when there are some (module docstring)."""
    first = _first_grip(steps)
    if first is not None and "carry" not in entries:
        raise JobFileError(path, first.line, f"{first.kind.value}: needs the job's carry: (the part the tool holds, "
                           "e.g. carry: {shape: box, size: [0.2, 0.3, 0.15]})")  # fmt: skip
    if first is None and "carry" in entries:
        entries["carry"].fail("carry: is the part the tool holds from a pick: to a place:, and the steps have none "
                              "(a part held throughout is the cell file's carried:)")  # fmt: skip
    check_grips(steps, pallets, path)


def _first_grip(steps: tuple[Step, ...]) -> Grip | None:
    for step in steps:
        found = _first_grip(step.body) if isinstance(step, Loop) else step if isinstance(step, Grip) else None
        if found is not None:
            return found
    return None


def _payload(at: _At) -> Payload:
    keys = at.mapping(("mass", "com"), required=("mass",))
    mass = keys["mass"].number(lambda v: v >= 0, ">= 0", "kg")
    com = (0.0, 0.0, 0.0)
    if "com" in keys:
        com = _three(keys["com"], "com is 3 lengths [{unit}] (x, y, z in the tool frame)", lambda _: True,
                     kind="length")  # fmt: skip
    return Payload(mass, com)


def _shape(keys: Mapping[str, _At]) -> dict[str, Any]:
    """The jump clearance values among ``keys`` (rise, clearance_radius, max_height), checked, SI."""
    out = {}
    for name in _JUMP_KEYS:
        if name in keys:
            positive = name != "max_height"
            out[name] = keys[name].length((lambda v: v > 0) if positive else (lambda _: True),
                                          "> 0" if positive else "a number")  # fmt: skip
    return out


def _pallet(at: _At, name: str, points: PointSet) -> Pallet:
    _new_name(at, "pallet", name, points)
    keys = at.mapping(_PALLET_KEYS, required=("corners", "rows", "columns"))
    corners = []
    for c in keys["corners"].elements():
        corner = c.text(32)
        if corner not in points:
            c.fail(_unknown_point(corner, points))
        corners.append(corner)
    rows = keys["rows"].whole(1, MAX_JOB_STEPS)
    columns = keys["columns"].whole(1, MAX_JOB_STEPS)
    layers = keys["layers"].whole(1, MAX_JOB_STEPS) if "layers" in keys else 1
    height = keys["layer_height"].length(lambda v: v > 0, "> 0") if "layer_height" in keys else 0.0
    return at.checked(lambda: Pallet(name, tuple(corners), rows, columns, layers, height))


def _via(at: _At, points: PointSet) -> tuple[str, ...]:
    """A jump's ``via:``: names of points (joint or pose), hints of its way through the cell, in order."""
    names = []
    items = at.elements()
    if not 1 <= len(items) <= MAX_VIA:
        at.fail(f"via: is a list of 1 to {MAX_VIA} point names (hints of the jump's way through the cell), "
                f"got {len(items)}")  # fmt: skip
    for item in items:
        name = item.text(32)
        if name not in points:
            item.fail(_unknown_point(name, points))
        names.append(name)
    return tuple(names)


def _unknown_point(name: str, points: PointSet) -> str:
    known = ", ".join(points.names[:20]) + (", ..." if len(points) > 20 else "") if len(points) else "none"
    return f"unknown point {name!r} (the points file has: {known})"


def _target(at: _At, points: PointSet, pallets: Mapping[str, Pallet], scope: Mapping[str, _Scope]) -> Target:
    target = at.checked(lambda: parse_target(at.value))
    if target.index is None:
        if target.name in pallets:
            at.fail(f"{target.name} is a pallet: name one of its places, {target.name}[1] to "
                    f"{target.name}[{pallets[target.name].places}]")  # fmt: skip
        if target.name not in points:
            at.fail(_unknown_point(target.name, points))
        return target
    pallet = pallets.get(target.name)
    if pallet is None:
        known = ", ".join(pallets) or "none"
        at.fail(f"unknown pallet {target.name!r} in {target.text()} (pallets: {known})")
    if isinstance(target.index, int):
        if not 1 <= target.index <= pallet.places:
            at.fail(f"{target.text()}: index {target.index} is past the end of pallet {pallet.name} "
                    f"({pallet.places} places, numbered from 1)")  # fmt: skip
        return target
    loop = scope.get(target.index)
    if loop is None:
        at.fail(f"{target.text()}: {target.index} is no loop variable here "
                f"({', '.join(scope) if scope else 'no enclosing for'})")  # fmt: skip
    if loop.last > pallet.places:
        at.fail(f"{target.text()}: {target.index} runs to {loop.last} (the for at line {loop.line}), past the end "
                f"of pallet {pallet.name} ({pallet.places} places)")  # fmt: skip
    return target


@dataclass(frozen=True)
class _Scope:
    last: int
    line: int | None


def _steps(at: _At, points: PointSet, pallets: Mapping[str, Pallet], scope: Mapping[str, _Scope],
           depth: int) -> tuple[Step, ...]:  # fmt: skip
    out: list[Step] = []
    for item in at.elements():
        item.name = "a step"
        out.append(_step(item, points, pallets, scope, depth))
    return tuple(out)


def _percent(at: _At) -> float:
    return at.number(lambda v: 0.0 < v <= 100.0, "in (0, 100] (a percentage of the robot's limits)", "%")


def _step(at: _At, points: PointSet, pallets: Mapping[str, Pallet], scope: Mapping[str, _Scope],
          depth: int) -> Step:  # fmt: skip
    if not isinstance(at.value, dict) or not at.value:
        at.fail(f"a step is a mapping such as {{jump: P1}}, {{dwell: 0.05}} ({_STEP_KINDS})")
    keys = set(at.value)
    line = at.line
    if "for" in keys:
        return _loop(at, points, pallets, scope, depth)
    moves = [k for k in (m.value for m in MoveKind) if k in keys]
    if len(moves) > 1:
        at.fail(f"one move per step: {', '.join(moves)} in one step")
    if moves:
        kind = MoveKind(moves[0])
        entries = at.mapping((kind.value, *_JUMP_KEYS, "via") if kind is MoveKind.JUMP else (kind.value,))
        target = _target(entries[kind.value], points, pallets, scope)
        via = _via(entries["via"], points) if "via" in entries else ()
        return MotionStep(kind, target, line, **_shape(entries), via=via)
    if "dwell" in keys:
        entries = at.mapping(("dwell",))
        return Dwell(entries["dwell"].number(lambda v: 0 <= v <= MAX_DWELL, f">= 0 and at most {MAX_DWELL:,} (seconds "
                                             "at rest; MAX_DWELL)", "s"), line)  # fmt: skip
    grips = [g for g in GripKind if g.value in keys]
    if grips:
        if len(grips) > 1:
            at.fail("one grip per step: pick and place in one step")
        entries = at.mapping((grips[0].value,))
        rule = f">= 0 and at most {MAX_DWELL:,} (seconds at rest while the gripper acts; MAX_DWELL)"
        seconds = entries[grips[0].value].number(lambda v: 0 <= v <= MAX_DWELL, rule, "s")
        return Grip(grips[0], seconds, line)
    if keys & {"speed", "accel"}:
        entries = at.mapping(("speed", "accel"))
        return Setting(_percent(entries["speed"]) if "speed" in entries else None,
                       _percent(entries["accel"]) if "accel" in entries else None, line)  # fmt: skip
    at.fail(f"unknown step {', '.join(sorted(map(str, keys)))} (steps: {_STEP_KINDS})")


def _loop(at: _At, points: PointSet, pallets: Mapping[str, Pallet], scope: Mapping[str, _Scope],
          depth: int) -> Loop:  # fmt: skip
    if depth + 1 > MAX_JOB_DEPTH:
        at.fail(f"for loops nested {depth + 1} deep, above the cap of {MAX_JOB_DEPTH} (MAX_JOB_DEPTH)")
    entries = at.mapping(("for", "do", "order", "var"), required=("do",))
    over_at = entries["for"]
    over: str | int
    if isinstance(over_at.value, str):
        if over_at.value not in pallets:
            over_at.fail(f"for {_shown(over_at.value)}: no pallet of that name (pallets: {', '.join(pallets) or 'none'}"
                         "); for: N repeats N times")  # fmt: skip
        over = over_at.value
        last = pallets[over].places
    else:
        over = over_at.whole(1, MAX_JOB_STEPS)
        last = over
    var = entries["var"].text(32) if "var" in entries else "i"
    if not VARIABLE.fullmatch(var):
        entries["var"].fail(f"var {_shown(var)} must be a letter or _ then letters, digits or _")
    if var in scope:
        (entries.get("var") or at).fail(f"the loop variable {var} is already the enclosing for's (line "
                                        f"{scope[var].line}): give this one var: j (or another name)")  # fmt: skip
    order = Order.ROWS
    if "order" in entries:
        if isinstance(over, int):
            entries["order"].fail("order applies to a pallet's places; for: N counts 1 to N")
        try:
            order = Order(entries["order"].value)
        except ValueError:
            entries["order"].fail(f"order {_shown(entries['order'].value)} must be one of "
                                  f"{', '.join(o.value for o in Order)}")  # fmt: skip
    body_at = entries["do"]
    if not isinstance(body_at.value, list) or not body_at.value:
        body_at.fail("do must be a non-empty list of steps")
    body = _steps(body_at, points, pallets, {**scope, var: _Scope(last, at.line)}, depth + 1)
    return Loop(over, var, order, body, at.line)
