"""Shared plumbing of the command modules: units, number parsing, robot loading, shared options (private)."""

from __future__ import annotations

import argparse
import logging
import math
import re
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..files import write_text_atomic

if TYPE_CHECKING:
    import numpy as np

    from .._typing import ArrayLike
    from ..model import Robot

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
    """Scale factors from SI to the units the user asked for (``--deg``, ``--mm``)."""

    def __init__(self, deg: bool, mm: bool) -> None:
        self.angle = 180.0 / math.pi if deg else 1.0
        self.length = 1000.0 if mm else 1.0
        self.angle_name = "deg" if deg else "rad"
        self.length_name = "mm" if mm else "m"
        self.q: tuple[str, ...] = _Q_KINDS  # what each joint value measures; _load sets the robot's own

    def scale(self, kinds: Sequence[str]) -> list[float]:
        """Multipliers from SI for a sequence of quantity kinds ("angle" / "length")."""
        return [self.angle if k == "angle" else self.length for k in kinds]

    def names(self, kinds: Sequence[str]) -> list[str]:
        """Unit names for a sequence of quantity kinds."""
        return [self.angle_name if k == "angle" else self.length_name for k in kinds]


def _number(name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(name, text, "must be a number") from None
    if not math.isfinite(value):
        raise ParameterError(name, text, "must be finite")
    return value


def _parse_sets(items: Sequence[str] | None) -> dict[str, str]:
    overrides: dict[str, str] = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InvalidInputError(f"--set {item!r} must have the form key=value (e.g. l1=0.25)")
        overrides[key.strip()] = value
    return overrides


def _load(args: argparse.Namespace, units: Units | None = None) -> Robot:
    from ..robots import load_robot

    robot = load_robot(args.robot, _parse_sets(args.set), urdf=args.urdf, tool=args.tool, base=args.base,
                       package_path=args.package_path or ())  # fmt: skip
    if robot.frame_note is not None:  # the tool chosen without a tool0: said once
        print(f"info: {robot.frame_note}", file=sys.stderr)
    if units is not None:  # what each joint value measures, read from the model (any joint order)
        units.q = robot.joint_kinds
    return robot


def _read_q(args: argparse.Namespace, units: Units) -> np.ndarray:
    import numpy as np

    n = len(units.q)  # the robot's joint count once loaded (_load): 4, or 3 without a wrist
    if len(args.q) != n:
        raise ParameterError("q", " ".join(args.q), f"must be {n} joint values (got {len(args.q)})")
    return np.array(_q_values(args.q, units))


def _needs_wrist(robot: Robot, what: str) -> None:
    """Refuse (exit 2) a command or option that supports 4-joint robots only, for a 3-joint SCARA."""
    if robot.dof != 4:
        raise InvalidInputError(f"{what} supports 4-joint robots only; {robot.name!r} has {robot.dof} joints "
                                "(a SCARA without a wrist)")  # fmt: skip


def _q_values(texts: Sequence[str], units: Units, what: str = "") -> list[float]:
    """Joint values as typed (units per --deg/--mm and the robot's joint kinds) in SI, each a finite number."""
    prefix = f"{what} " if what else ""
    if len(texts) != len(units.q):  # never truncated by the zip below
        raise ParameterError(what or "q", " ".join(texts), f"must be {len(units.q)} joint values (got {len(texts)})")
    return [_number(prefix + n, t) / sc for n, t, sc in zip(_Q_NAMES, texts, units.scale(units.q))]


def _check_limits(robot: Robot, q: np.ndarray, strict: bool) -> None:
    outside = robot.outside_limits(q)
    if outside and strict:
        raise InfeasibleError("q outside the joint limits (--strict): " + "; ".join(outside))
    for item in outside:
        log.warning("%s (computed anyway; --strict refuses)", item)


def _fmt(values: ArrayLike) -> str:
    return "[" + ", ".join(f"{v: .9g}" for v in values) + "]"


def _scaled(values: ArrayLike, scale: Sequence[float]) -> list[float]:
    return [float(v) * s for v, s in zip(values, scale)]


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
    return [_number(n, t) / sc for n, t, sc in zip(("x", "y", "z", "yaw"), texts, units.scale(_POSE_KINDS))]


def _joint_arg(robot: Robot, texts: Sequence[str], units: Units, what: str) -> np.ndarray:
    q = robot.check_q(_q_values(texts, units, what))
    outside = robot.outside_limits(q, tol=1e-12)
    if outside:
        raise InfeasibleError(f"{what} is outside the joint limits: " + "; ".join(outside))
    return q


def _pose_to_q(robot: Robot, pose: ArrayLike, near: np.ndarray, what: str) -> np.ndarray:
    result = robot.ik(pose)
    if not result.success:
        raise InfeasibleError(f"{what} {list(pose)}: {result.status.name}: {result.message}")
    best = result.nearest(near)
    assert best is not None  # success means at least one solution
    return best.q


def write_atomic(path: Path, text: str) -> None:
    """Write a text file atomically (see :mod:`scara_pin.files`)."""
    write_text_atomic(path, text)


def _add_units(
    p: argparse.ArgumentParser, *, deg: bool = True, mm: bool = True, json_help: str | None = "print one JSON object",
    inputs: bool = False,
) -> None:
    """The shared unit and output switches: --deg, --mm (human units) and --json."""
    scope = " (inputs)" if inputs else ""
    if deg:
        p.add_argument("--deg", action="store_true", help=f"angles in degrees{scope}")
    if mm:
        p.add_argument("--mm", action="store_true", help=f"lengths in millimetres{scope}")
    if json_help is not None:
        p.add_argument("--json", action="store_true", help=json_help)


def _add_robot_options(p: argparse.ArgumentParser, urdf_file: bool = True) -> None:
    g = p.add_argument_group("robot")
    g.add_argument("--robot", default="default", metavar="NAME|CONFIG_DIR",
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
    g.add_argument("--package-path", action="append", metavar="DIR",
                   help="a folder holding ROS packages (folders with package.xml), for $(find pkg) and "
                   "package://pkg/ in --urdf; repeatable; ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are "
                   "searched too")  # fmt: skip


def _add_q(p: argparse.ArgumentParser) -> None:
    p.add_argument("q", nargs="*", metavar="Q",
                   help="joint values q1 q2 q3 q4 (URDF order; SCARA: q3 > 0 lowers the quill; "
                   "palletizer: q1 q2 theta3 q4, theta3 the small arm's absolute angle)")  # fmt: skip
    _add_units(p)
    p.add_argument("--strict", action="store_true", help="refuse (exit 3) a q outside the joint limits")
    _add_robot_options(p)
