"""The job file: a yaml program of moves over taught points and pallets, read and checked before any planning.

The format (docs/job.md has it beside its SPEL+ and RAPID equivalents)::

    format: scara-pin job 1          # optional; checked when present
    robot: default                   # optional; the robot the job is for (checked against the one planning it)
    points: points.yaml              # the taught points (the pendant's file), relative to this file
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

Values may carry xacro's unit tags (``!millimeters 150``, ``!degrees 90``); lengths are metres, times
seconds. The file is read through the package's one yaml loader
(:func:`~scara_pin.description.yaml_units.load_yaml`, its caps included) and sized first
(:data:`~scara_pin.limits.MAX_JOB_BYTES`); its node tree (composed a second time, never constructed) gives
the line of each value for the messages.

Everything that can be checked without a robot is checked here, each refusal a
:class:`~scara_pin.errors.JobFileError` (exit 2) naming the file, the line and the reason: unknown keys,
steps and points, pallets without enough corners, percentages outside (0, 100], an index past a pallet's
end (a loop variable's whole range checked against it), loops nested deeper than
:data:`~scara_pin.limits.MAX_JOB_DEPTH`, and more moves and dwells than
:data:`~scara_pin.limits.MAX_JOB_STEPS` (counted, never unrolled). With the robot, :meth:`Job.program`
then checks the points (the pendant's poses against the robot's FK), the pallets' corners (collinear,
coincident, folded) and every place's reach.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, NoReturn

from ..errors import InvalidInputError, JobFileError
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
from ..motion.points import PointSet, check_point_name, read_points
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

__all__ = ["FORMAT", "read_job"]

FORMAT = "scara-pin job 1"
"""The ``format:`` value of a job file."""

_KEYS = ("format", "robot", "points", "start", "jump", "torque", "payload", "cell", "carry", "pallets", "steps")
_PALLET_KEYS = ("corners", "rows", "columns", "layers", "layer_height")
_JUMP_KEYS = ("rise", "clearance_radius", "max_height")
_STEP_KINDS = "speed, accel, jump, move, go, dwell, pick, place, for"


class _At:
    """A value of the job file and the line where it is written; :meth:`fail` refuses it, naming the line."""

    def __init__(self, value: Any, path: Path, name: str, line: int | None) -> None:
        self.value, self.path, self.name, self.line = value, path, name, line

    def fail(self, reason: str) -> NoReturn:
        raise JobFileError(self.path, self.line, reason)

    def child(self, key: str | int, name: str | None = None) -> _At:
        """The value at ``key`` of this mapping (or index of this list), with its line (the shared loader's)."""
        from ..description.yaml_units import yaml_line

        label = name if name is not None else (f"{self.name}[{key}]" if isinstance(key, int) else str(key))
        line = yaml_line(self.value, key)
        return _At(self.value[key], self.path, label, self.line if line is None else line)

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


def read_job(path: str | Path) -> JobSpec:
    """Read a job file and check it (module docstring); the points file is read too.

    :func:`~scara_pin.job.job.load_job` gives it as the :class:`~scara_pin.job.job.Job` users hold.

    Raises:
        JobFileError: the file, the line and the reason of the first problem (exit 2).
        InvalidInputError: the file cannot be read (missing, not a regular file, over its cap, not UTF-8).
    """
    from ..description.yaml_units import load_yaml, yaml_line
    from ..errors import YamlError

    path = Path(path)
    text = read_text(check_input_file(path, "job file", MAX_JOB_BYTES), "job file", MAX_JOB_BYTES)
    try:
        data = load_yaml(text, str(path))  # the one bounded loader: every value knows its line
    except YamlError as exc:
        raise JobFileError(path, exc.line, exc.problem if exc.refused else f"not valid YAML ({exc.problem})") from None
    top = _At(data, path, "the job", yaml_line(data))
    entries = top.mapping(_KEYS, required=("points", "steps"))
    lines = {k: at.line for k, at in entries.items()}
    if "format" in entries and entries["format"].value != FORMAT:
        entries["format"].fail(f"format {_shown(entries['format'].value)} is not {FORMAT!r}")
    robot = entries["robot"].text() if "robot" in entries else None
    points_file, points = _points(entries["points"], path)
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
    return JobSpec(path, points_file, points, pallets, steps, robot, start, shape, torque, payload, cell, carry, count,
                   dwell, lines)  # fmt: skip


def _points(at: _At, job: Path) -> tuple[Path, PointSet]:
    file = job.parent / at.text(4096)
    try:
        return file, read_points(file)
    except InvalidInputError as exc:
        at.fail(str(exc))


def _cell(at: _At, job: Path) -> Path:
    file = job.parent / at.text(4096)
    try:
        return check_input_file(file, "cell file", MAX_DOCUMENT_BYTES)
    except InvalidInputError as exc:
        at.fail(str(exc))


def _carry(at: _At) -> Carry:
    keys = at.mapping(("shape", "size", "xyz", "rpy"), required=("shape", "size"))
    if keys["shape"].value != "box":
        keys["shape"].fail(f"carry shape {_shown(keys['shape'].value)} is not one scara-pin knows (box)")
    size = _three(keys["size"], "a box's size is 3 lengths [m] (x, y, z in the tool frame)", lambda v: v > 0, "> 0")
    xyz = _three(keys["xyz"], "xyz is 3 lengths [m] (the part's centre in the tool frame)") if "xyz" in keys else None
    rpy = (_three(keys["rpy"], "rpy is 3 angles [rad] (roll, pitch, yaw in the tool frame)", unit="rad")
           if "rpy" in keys else None)  # fmt: skip
    carry = Carry("box", size, xyz, rpy or (0.0, 0.0, 0.0))
    try:
        carry.part()  # the cell's own checks: sizes and positions within their bounds
    except InvalidInputError as exc:
        at.fail(f"carry: {exc}")
    return carry


def _three(at: _At, what: str, rule: Callable[[float], bool] = math.isfinite, rule_text: str = "a number",
           unit: str = "m") -> tuple[float, float, float]:  # fmt: skip
    values = at.elements()
    if len(values) != 3:
        at.fail(what)
    a, b, c = (v.number(rule, rule_text, unit) for v in values)
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
        values = keys["com"].elements()
        if len(values) != 3:
            keys["com"].fail("com is 3 lengths [m] (x, y, z in the tool frame)")
        com = tuple(v.number(lambda _: True, "a number", "m") for v in values)  # type: ignore[assignment]
    return Payload(mass, com)


def _shape(keys: Mapping[str, _At]) -> dict[str, float]:
    """The jump clearance values among ``keys`` (rise, clearance_radius, max_height), checked, SI."""
    out = {}
    for name in _JUMP_KEYS:
        if name in keys:
            positive = name != "max_height"
            out[name] = keys[name].number((lambda v: v > 0) if positive else (lambda _: True),
                                          "> 0" if positive else "a number", "m")  # fmt: skip
    return out


def _pallet(at: _At, name: str, points: PointSet) -> Pallet:
    try:
        check_point_name(name)
    except InvalidInputError:
        at.fail(f"pallet name {_shown(name)} must be a letter then up to 31 letters, digits, _, - or .")
    if name in points:
        at.fail(f"pallet {name} has the name of a point of the points file: name it otherwise")
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
    height = keys["layer_height"].number(lambda v: v > 0, "> 0", "m") if "layer_height" in keys else 0.0
    try:
        return Pallet(name, tuple(corners), rows, columns, layers, height)
    except InvalidInputError as exc:
        at.fail(str(exc))


def _unknown_point(name: str, points: PointSet) -> str:
    known = ", ".join(points.names[:20]) + (", ..." if len(points) > 20 else "") if len(points) else "none"
    return f"unknown point {name!r} (the points file has: {known})"


def _target(at: _At, points: PointSet, pallets: Mapping[str, Pallet], scope: Mapping[str, _Scope]) -> Target:
    try:
        target = parse_target(at.value)
    except InvalidInputError as exc:
        at.fail(str(exc))
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
        entries = at.mapping((kind.value, *_JUMP_KEYS) if kind is MoveKind.JUMP else (kind.value,))
        target = _target(entries[kind.value], points, pallets, scope)
        return MotionStep(kind, target, line, **_shape(entries))
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
