"""Shared plumbing of the command modules: units, number parsing, robot loading, shared options (private)."""

from __future__ import annotations

import argparse
import logging
import math
import re
import sys
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, NoReturn, TypeVar

from .._checks import NUMBER_TEXT
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..limits import MAX_NUMBER
from ..units import DisplayUnits, format_number

if TYPE_CHECKING:
    import numpy as np

    from .._typing import ArrayLike
    from ..robots import Robot

log = logging.getLogger("scara_pin")

_Q_NAMES = ("q1", "q2", "q3", "q4")
_Q_KINDS = ("angle", "angle", "length", "angle")  # what each joint value measures
_POSE_KINDS = ("length", "length", "length", "angle")  # x, y, z, yaw


class _UsageError(Exception):
    """argparse's complaint, turned into our one-line error and exit code 2."""


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # negative numbers, e-notation included (-1e-3), are values, not options
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message: str) -> NoReturn:
        raise _UsageError(message)


class Units:
    """The units of the numbers the user types and reads: ``--mm --deg``, ``--units LENGTH,ANGLE``, or SI.

    The units rule (docs/units.md): typed numbers are SI (m, rad) unless the command line says otherwise;
    ``--mm --deg`` (or ``--units mm,deg``) switches both; ``--units`` names each kind explicitly (``m,deg``,
    ``mm,rad``, ``deg``: the kind left out stays SI). One flag alone, ``--deg`` or ``--mm``, is refused
    (exit 2) as soon as the command reads a typed value of the OTHER kind, which would silently stay SI:
    ``fk --deg 90 0 10 0`` would read q3 = 10 as metres. Text output uses the same units; JSON stays SI.

    Attributes:
        display: the units of the text (:class:`scara_pin.units.DisplayUnits`).
        alone: ``"--deg"`` or ``"--mm"`` when that flag was given without the other (the rule applies).
        q: what each joint value measures (``"angle"``/``"length"``); :func:`_load` sets the robot's own.
    """

    def __init__(self, deg: bool = False, mm: bool = False, *, spec: str | None = None) -> None:
        if spec is not None:
            if deg or mm:
                raise InvalidInputError("give either --units or --deg/--mm, not both")
            self.display = DisplayUnits.parse(spec)
            self.alone: str | None = None
        else:
            self.display = DisplayUnits("mm" if mm else "m", "deg" if deg else "rad")
            self.alone = "--deg" if deg and not mm else "--mm" if mm and not deg else None
        self.angle = self.display.scale("angle")
        self.length = self.display.scale("length")
        self.angle_name = self.display.angle
        self.length_name = self.display.length
        self.q: tuple[str, ...] = _Q_KINDS  # what each joint value measures; _load sets the robot's own

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Units:
        """The units of a parsed command line (its ``--deg``, ``--mm`` and ``--units``, those it has)."""
        return cls(getattr(args, "deg", False), getattr(args, "mm", False), spec=getattr(args, "units", None))

    def scale(self, kinds: Sequence[str]) -> list[float]:
        """Multipliers from SI for a sequence of quantity kinds ("angle" / "length")."""
        return [self.angle if k == "angle" else self.length for k in kinds]

    def names(self, kinds: Sequence[str]) -> list[str]:
        """Unit names for a sequence of quantity kinds."""
        return [self.angle_name if k == "angle" else self.length_name for k in kinds]

    def guard(self, names: Sequence[str], texts: Sequence[str], kinds: Sequence[str]) -> None:
        """Refuse a typed value of the kind a lone ``--deg`` / ``--mm`` leaves in SI (the units rule).

        Raises:
            InvalidInputError: ``--deg`` alone and a length typed, or ``--mm`` alone and an angle typed.
        """
        if self.alone is None:
            return
        other = "length" if self.alone == "--deg" else "angle"
        for name, text, kind in zip(names, texts, kinds):
            if kind == other:
                shown = text.strip()[:40]
                if other == "length":
                    raise InvalidInputError(f"--deg without --mm: {name} = {shown} is a length and would be read "
                                            "in metres; add --mm to type millimetres (or --units deg,m to keep "
                                            "metres)")  # fmt: skip
                raise InvalidInputError(f"--mm without --deg: {name} = {shown} is an angle and would be read in "
                                        "radians; add --deg to type degrees (or --units mm,rad to keep "
                                        "radians)")  # fmt: skip

    def value(self, name: str, text: str, kind: str) -> float:
        """One typed value of a kind ("length" / "angle"), in SI, after the units rule."""
        self.guard((name,), (text,), (kind,))
        return _number(name, text) / (self.angle if kind == "angle" else self.length)

    def fmt(self, values: ArrayLike, kinds: str | Sequence[str], width: int = 0) -> str:
        """SI values as ``[a, b, c]`` in the user's units, rounded to the unit's resolution (scara_pin.units)."""
        return self.display.format_vector(values, kinds, width)  # type: ignore[arg-type]

    def num(self, value: float, kind: str) -> str:
        """One SI value in the user's units, rounded to the unit's resolution (no unit name)."""
        return self.display.format(value, kind)


_INTEGER_TEXT = re.compile(r"[+-]?\d+", re.ASCII)
_T = TypeVar("_T")
MIN_NUMBER = 1e-100
"""Smallest magnitude of a non-zero typed number (below it, 1 / x and x * x leave the float range)."""


def _number(name: str, text: str) -> float:
    """The one parser of the numbers users type (arguments, --set values, batch CSV cells).

    Accepted: what a robotics user types, ``0.25``, ``-1.5e-3``, ``+2``, ``.5``, ``3.``, surrounding
    blanks. Refused: ``1_000``, non-ASCII digits, hex, ``nan``, ``inf``, and magnitudes outside
    ``0`` or ``[MIN_NUMBER, MAX_NUMBER]`` (1e-100 .. 1e12).
    """
    stripped = text.strip(" \t") if isinstance(text, str) else ""
    if not NUMBER_TEXT.fullmatch(stripped):
        shown = text if len(text) <= 40 else text[:40] + "..."
        if stripped.lower().lstrip("+-") in ("nan", "inf", "infinity"):
            raise ParameterError(name, shown, "must be finite")
        raise ParameterError(name, shown, "must be a plain number such as 0.25, -3, 1.5e-3 (ASCII digits, "
                             "no _ separators)")  # fmt: skip
    value = float(stripped)
    if not (value == 0.0 or MIN_NUMBER <= abs(value) <= MAX_NUMBER):
        raise ParameterError(name, stripped, f"must be 0 or of magnitude within [{MIN_NUMBER:g}, {MAX_NUMBER:g}]")
    return value


def _integer(name: str, text: str, low: int, high: int) -> int:
    """A typed whole number in ``[low, high]`` (ASCII digits, optional sign)."""
    stripped = text.strip(" \t")
    if not _INTEGER_TEXT.fullmatch(stripped) or len(stripped) > 30:
        raise ParameterError(name, text[:40], "must be a whole number (ASCII digits)")
    value = int(stripped)
    if not low <= value <= high:
        raise ParameterError(name, value, f"must be within [{low}, {high}]")
    return value


def number_type(name: str) -> Callable[[str], float]:
    """An argparse ``type=`` that parses with :func:`_number` (errors become the one-line usage error)."""
    return _argparse_type(lambda text: _number(name, text))


def integer_type(name: str, low: int, high: int) -> Callable[[str], int]:
    """An argparse ``type=`` for a whole number in ``[low, high]``."""
    return _argparse_type(lambda text: _integer(name, text, low, high))


def _argparse_type(parse: Callable[[str], _T]) -> Callable[[str], _T]:
    """``parse`` with its ParameterError as argparse's, which names the option: "argument --rate: got 'x'; it ..."."""

    def parsed(text: str) -> _T:
        try:
            return parse(text)
        except ParameterError as exc:
            raise argparse.ArgumentTypeError(f"got {exc.value!r}; it {exc.rule}") from None

    return parsed


def _jerk(args: argparse.Namespace) -> list[float] | None:
    """``--jerk-limit J`` or ``J1 J2 J3 J4`` [rad/s^3, m/s^3] through the number grammar, or None."""
    if getattr(args, "jerk_limit", None) is None:
        return None
    if len(args.jerk_limit) not in (1, 4):
        raise ParameterError("--jerk-limit", " ".join(args.jerk_limit), "must be one number or 4 (one per joint)")
    values = [_number("--jerk-limit", v) for v in args.jerk_limit]
    if not all(v > 0 for v in values):
        raise ParameterError("--jerk-limit", values, "must be > 0", "rad/s^3 or m/s^3")
    return values * 4 if len(values) == 1 else values


def _parse_sets(items: Sequence[str] | None, option: str = "--set", form: str = "key=value (e.g. l1=0.25)"
                ) -> dict[str, float]:  # fmt: skip
    """``--set KEY=VALUE`` items (or ``option``'s); each value through :func:`_number` (never to xacro as text).

    A key given twice is refused (which one was meant? the last silently winning hid the other).
    """
    overrides: dict[str, float] = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InvalidInputError(f"{option} {item[:80]!r} must have the form {form}")
        parsed = _number(f"{option} {key[:80]}", value)
        if key in overrides:
            raise InvalidInputError(f"{option} {key[:80]} is given twice ({format_number(overrides[key], 9)} and "
                                    f"{format_number(parsed, 9)}); give each once")  # fmt: skip
        overrides[key] = parsed
    return overrides


def _parse_locks(items: Sequence[str] | None) -> dict[str, float]:
    """``--lock JOINT=VALUE`` items (SI, as --set)."""
    return _parse_sets(items, "--lock", "JOINT=VALUE (e.g. lower_j1=0.5)")


_MAX_NAME = 4096
"""Longest --robot name or folder path (the system's PATH_MAX)."""


def _load(args: argparse.Namespace, units: Units | None = None) -> Robot:
    if args.robot is not None and getattr(args, "urdf", None) is not None:
        raise InvalidInputError("give either --robot NAME or --urdf FILE, not both")
    args.robot = "default" if args.robot is None else args.robot
    if len(args.robot) > _MAX_NAME or "\0" in args.robot:
        raise InvalidInputError(f"--robot {args.robot[:40]!r}...: not a robot name nor a folder "
                                f"(longer than {_MAX_NAME} characters or with a NUL)")  # fmt: skip
    if args.urdf is not None:  # a regular file under the size cap, or refused before it is read
        from ..limits import check_input_file

        check_input_file(args.urdf, "URDF")
    robot = _load_robot(args)
    for note in (robot.frame_note, robot.lock_note):  # the tool chosen without a tool0, another arm locked
        if note is not None:
            print(f"info: {note}", file=sys.stderr)
    if units is not None:  # what each joint value measures, read from the model (any joint order)
        units.q = robot.joint_kinds
    return robot


def _load_robot(args: argparse.Namespace, acceleration: Sequence[float] | None = None) -> Robot:
    """:func:`scara_pin.robots.load_robot` with the robot options of ``args`` (``--lock`` read before ``--set``)."""
    from ..robots import load_robot

    locks = _parse_locks(getattr(args, "lock", None))
    return load_robot(args.robot, _parse_sets(args.set), urdf=args.urdf, tool=args.tool, base=args.base,
                      package_path=args.package_path or (), lock=locks, acceleration=acceleration)  # fmt: skip


def _add_acceleration(p: Any) -> None:
    """``--acceleration A1 A2 A3 A4`` (one per joint): the joint acceleration limits (a URDF file has none)."""
    p.add_argument("--acceleration", nargs="+", metavar="A",
                   help="joint acceleration limits [rad/s^2, m/s^2; deg/s^2, mm/s^2 with --deg/--mm]; needed "
                   "for a robot loaded from a URDF file (URDF has none); replaces the configured ones")  # fmt: skip


def _acceleration(args: argparse.Namespace, robot: Robot, units: Units) -> Robot:
    """The robot with the acceleration limits of ``--acceleration``; refuse a robot without any.

    Given, they replace the robot's: the robot of :func:`_load` is loaded again with them
    (``load_robot(acceleration=...)``), the one given is left as it is. Not given: ``robot`` itself.

    Raises:
        InvalidInputError: no acceleration limits known (a URDF file) and none given.
    """
    texts: Sequence[str] | None = args.acceleration
    if texts:
        if len(texts) != len(units.q):
            raise ParameterError("--acceleration", " ".join(texts), f"must be {len(units.q)} values, one per joint")
        units.guard([f"--acceleration {n}" for n in _Q_NAMES], texts, units.q)
        acc = [_number(f"--acceleration {n}", t) / sc for n, t, sc in zip(_Q_NAMES, texts, units.scale(units.q))]
        for name, value in zip(_Q_NAMES, acc):
            if not value > 0:
                raise ParameterError(f"--acceleration {name}", value, "must be > 0")
        return _load_robot(args, acc)
    if not all(math.isfinite(v) for v in robot.limits.acceleration):
        raise InvalidInputError(f"robot {robot.name!r} has no acceleration limits (a URDF file has none): give "
                                "--acceleration with one value per joint [rad/s^2, m/s^2]")  # fmt: skip
    return robot


def _needs_wrist(robot: Robot, what: str) -> None:
    """Refuse (exit 2) a command or option that supports 4-joint robots only, for a 3-joint SCARA."""
    if robot.dof != 4:
        kinds = sorted(a.kind for a in robot.axes)
        arm = "a SCARA without a wrist" if kinds == ["prismatic", "revolute", "revolute"] else " and ".join(
            f"{kinds.count(k)} {k}" for k in sorted(set(kinds)))  # fmt: skip
        raise InvalidInputError(f"{what} supports 4-joint robots only; {robot.name!r} has {robot.dof} joints "
                                f"({arm})")  # fmt: skip


def _q_values(texts: Sequence[str], units: Units, what: str = "") -> list[float]:
    """Joint values as typed (units per --deg/--mm and the robot's joint kinds) in SI, each a finite number."""
    prefix = f"{what} " if what else ""
    if len(texts) != len(units.q):  # never truncated by the zip below
        raise ParameterError(what or "q", " ".join(texts), f"must be {len(units.q)} joint values (got {len(texts)})")
    units.guard([prefix + n for n in _Q_NAMES], texts, units.q)
    return [_number(prefix + n, t) / sc for n, t, sc in zip(_Q_NAMES, texts, units.scale(units.q))]


def _check_limits(robot: Robot, values: Sequence[float], units: Units, strict: bool = False,
                  warning: str = "%s (computed anyway; --strict refuses)") -> np.ndarray:
    """``values`` as q; refused if they cannot be computed, each joint outside its limits a warning (or refused)."""
    q = robot.check_q(values)  # a q that cannot be computed is an error, never first a "computed anyway" warning
    outside = robot.outside_limits(q, units=units.display)
    if outside and strict:
        raise InfeasibleError("q outside the joint limits (--strict): " + "; ".join(outside))
    for item in outside:
        log.warning(warning, item)
    return q


def _read_pose(texts: Sequence[str], units: Units, what: str = "target", dof: int = 4) -> list[float]:
    """A tool pose as typed: X Y Z YAW, or X Y Z for a 3-joint SCARA (``dof`` 3: no wrist, no yaw to choose)."""
    if dof == 3:
        if len(texts) == 4:
            raise InvalidInputError(f"this robot has 3 joints and no wrist: the tool's yaw cannot be chosen; "
                                    f"{what} takes X Y Z for such an arm (got 4 values)")  # fmt: skip
        if len(texts) != 3:
            raise ParameterError(what, " ".join(texts), f"must be 3 values X Y Z (got {len(texts)})")
    elif len(texts) != 4:
        raise ParameterError(what, " ".join(texts), f"must be 4 values X Y Z YAW (got {len(texts)})")
    units.guard([f"{what} {n}" for n in ("x", "y", "z", "yaw")], texts, _POSE_KINDS)
    return [_number(n, t) / sc for n, t, sc in zip(("x", "y", "z", "yaw"), texts, units.scale(_POSE_KINDS))]


def _joint_arg(robot: Robot, texts: Sequence[str], units: Units, what: str) -> np.ndarray:
    q = robot.check_q(_q_values(texts, units, what))
    outside = robot.outside_limits(q, tol=1e-12, units=units.display)
    if outside:
        raise InfeasibleError(f"{what} is outside the joint limits: " + "; ".join(outside))
    return q


_INPUT_OPTIONS = ("urdf", "dh", "points", "measurements", "input", "traj", "simulate", "cell", "file")
"""The options that name a file a command reads (those it has)."""


def _input_files(args: argparse.Namespace) -> dict[str, list[str]]:
    """The files a command reads, by option: its input options, and the yaml files of a configured ``--robot``."""
    from ..description import config_files
    from ..errors import UnknownRobotError

    found = {f"--{name}": [value] for name in _INPUT_OPTIONS
             if isinstance(value := getattr(args, name, None), str) and value not in ("", "-")}  # fmt: skip
    robot = getattr(args, "robot", None)
    if "--urdf" not in found and "--dh" not in found and (robot is None or len(robot) <= _MAX_NAME):
        try:
            found["--robot"] = [str(f) for f in config_files(robot or "default")]
        except (UnknownRobotError, ValueError, OSError):  # refused when the robot is loaded
            pass
    return found


def check_command_outputs(args: argparse.Namespace, outputs: dict[str, str | None], figures: Sequence[str] = ()
                          ) -> None:  # fmt: skip
    """The command's outputs, checked BEFORE any work by :func:`scara_pin.files.check_outputs`.

    Each name (no device, folder or missing folder; a plot's ending), at most one on standard output (with
    ``--json``), none the same file as an input of the command (:func:`_input_files`) or as another output.
    """
    from ..files import check_outputs

    stdout = "--json" if getattr(args, "json", False) else None
    check_outputs(outputs, _input_files(args), figures=figures, stdout=stdout)


def _add_units(
    p: argparse.ArgumentParser, *, deg: bool = True, mm: bool = True, json_help: str | None = "print one JSON object",
    inputs: bool = False,
) -> None:
    """The shared unit and output switches: --deg, --mm, --units (human units; the units rule) and --json."""
    scope = " (inputs and text)" if inputs else ""
    if deg:
        p.add_argument("--deg", action="store_true", help=f"angles in degrees{scope}; with a length typed, give "
                       "--mm too (or --units)")  # fmt: skip
    if mm:
        p.add_argument("--mm", action="store_true", help=f"lengths in millimetres{scope}; with an angle typed, give "
                       "--deg too (or --units)")  # fmt: skip
    kinds = "LENGTH,ANGLE" if deg else "LENGTH"
    p.add_argument("--units", metavar=kinds, help="units of typed and printed values, named explicitly: m or mm, "
                   "rad or deg (e.g. mm,deg or m,deg); a kind left out stays SI; not with --deg/--mm")  # fmt: skip
    if json_help is not None:
        p.add_argument("--json", action="store_true", help=json_help)


def _add_robot_options(p: argparse.ArgumentParser, urdf_file: bool = True) -> None:
    g = p.add_argument_group("robot")
    g.add_argument("--robot", default=None, metavar="NAME|CONFIG_DIR",
                   help="shipped robot name (see `scara-pin robots`) or a folder of yaml files "
                   "(default: default)")  # fmt: skip
    g.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a parameter, SI units (e.g. --set l1=0.25); repeatable")  # fmt: skip
    if urdf_file:
        g.add_argument("--urdf", metavar="FILE", help="load this URDF file (or .xacro file, expanded: it runs "
                       "the expressions written in it) instead of a configured robot")  # fmt: skip
        _add_frame_options(g)


def _add_frame_options(g: Any) -> None:
    """--tool, --base and --package-path (the robot's frames and where its packages are)."""
    g.add_argument("--tool", metavar="FRAME", help="the tool frame (a link; default: tool0 if present, "
                   "else the chain's last link)")  # fmt: skip
    g.add_argument("--base", metavar="FRAME", help="the frame poses are expressed in (a link; default: base "
                   "if present, else the root link)")  # fmt: skip
    g.add_argument("--lock", action="append", metavar="JOINT=VALUE",
                   help="fix a joint at a value [rad or m, SI as --set]; joints not on the chain from the root to "
                   "the tool (another arm) are locked at 0 unless given; repeatable")  # fmt: skip
    g.add_argument("--package-path", action="append", metavar="DIR",
                   help="a folder holding ROS packages (folders with package.xml), for $(find pkg) and "
                   "package://pkg/ in --urdf; repeatable; ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are "
                   "searched too")  # fmt: skip


def add_cell_options(p: argparse.ArgumentParser, *, margin: bool = True) -> None:
    """``--cell FILE`` (obstacles, the carried part, the margin: docs/cell.md) and ``--margin M``."""
    g = p.add_argument_group("cell")
    g.add_argument("--cell", metavar="FILE", help="the robot's cell: obstacles in its base frame, what the tool "
                   "carries, the margin (YAML, or a URDF/xacro of fixed links; docs/cell.md)")  # fmt: skip
    if margin:
        g.add_argument("--margin", type=number_type("--margin"), metavar="M",
                       help="the smallest distance kept to any obstacle [m, or mm with --mm], instead of the "
                       "cell file's")  # fmt: skip


def cell_from_args(args: argparse.Namespace, units: Units | None = None) -> Any:
    """The cell named by ``--cell`` (with ``--margin``), or None; the margin in the typed length unit."""
    path = getattr(args, "cell", None)
    margin = getattr(args, "margin", None)
    if path is None:
        if margin is not None:
            raise _UsageError("--margin needs --cell")
        return None
    from ..cell import load_cell

    if margin is not None and units is not None:
        margin = margin / units.length
    packages = tuple(getattr(args, "package_path", None) or ())
    return load_cell(path, margin=margin, package_dirs=packages)


def _add_q(p: argparse.ArgumentParser) -> None:
    p.add_argument("q", nargs="*", metavar="Q",
                   help="joint values q1 q2 q3 q4 (URDF order; SCARA: q3 > 0 lowers the quill; "
                   "palletizer: q1 q2 theta3 q4, theta3 the small arm's absolute angle)")  # fmt: skip
    _add_units(p)
    p.add_argument("--strict", action="store_true", help="refuse (exit 3) a q outside the joint limits")
    _add_robot_options(p)
