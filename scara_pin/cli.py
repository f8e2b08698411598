"""The ``scara-pin`` command line.

Conventions shared by every command:

- SI units by default; ``--deg`` gives and prints angles in degrees, ``--mm`` lengths in millimetres.
- Joint vectors are in URDF joint order (joint1..joint4); q3 grows as the quill moves down.
- ``--json`` prints one JSON object on stdout.
- Exit codes: 0 ok, 2 invalid input, 3 infeasible request (unreachable, limits), 1 internal error.
  Errors are one line on stderr starting with ``error:``; warnings start with ``warning:``.

Heavy packages (toppra, matplotlib, yourdfpy, meshcat) are imported only inside the commands that need
them, so ``fk`` starts about as fast as ``import pinocchio``.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

from .errors import InfeasibleError, InvalidInputError, ParameterError, ScaraError

if TYPE_CHECKING:
    import numpy as np

    from .model import Robot

__all__ = ["main"]

log = logging.getLogger("scara_pin")

_Q_NAMES = ("q1", "q2", "q3", "q4")
_Q_KINDS = ("angle", "angle", "length", "angle")  # what each joint value measures
_POSE_KINDS = ("length", "length", "length", "angle")  # x, y, z, yaw


class _UsageError(Exception):
    """argparse's complaint, turned into our one-line error and exit code 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:
        raise _UsageError(message)


class Units:
    """Scale factors from SI to the units the user asked for (``--deg``, ``--mm``)."""

    def __init__(self, deg: bool, mm: bool) -> None:
        self.angle = 180.0 / math.pi if deg else 1.0
        self.length = 1000.0 if mm else 1.0
        self.angle_name = "deg" if deg else "rad"
        self.length_name = "mm" if mm else "m"

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


def _load(args: argparse.Namespace) -> Robot:
    from .model import load_robot

    return load_robot(args.robot, _parse_sets(args.set), urdf=args.urdf)


def _read_q(args: argparse.Namespace, units: Units) -> np.ndarray:
    import numpy as np

    if len(args.q) != 4:
        raise ParameterError("q", " ".join(args.q), f"must be 4 joint values (got {len(args.q)})")
    scale = units.scale(_Q_KINDS)
    return np.array([_number(n, t) / s for n, t, s in zip(_Q_NAMES, args.q, scale)])


def _check_limits(robot: Robot, q: np.ndarray, strict: bool) -> None:
    outside = robot.outside_limits(q)
    if outside and strict:
        raise InfeasibleError("q outside the joint limits (--strict): " + "; ".join(outside))
    for item in outside:
        log.warning("%s (computed anyway; --strict refuses)", item)


def _fmt(values: Sequence[float]) -> str:
    return "[" + ", ".join(f"{v: .9g}" for v in values) + "]"


def _scaled(values: Sequence[float], scale: Sequence[float]) -> list[float]:
    return [float(v) * s for v, s in zip(values, scale)]


# ---------------------------------------------------------------------------------------------- commands
def cmd_robots(args: argparse.Namespace) -> int:
    """List the shipped robot configurations."""
    from .description import available_robots, urdf_dir

    names = available_robots()
    if args.json:
        print(json.dumps({"robots": names, "config_dir": str(urdf_dir() / "config")}))
    else:
        print("\n".join(names))
    return 0


def cmd_urdf(args: argparse.Namespace) -> int:
    """Write the generated URDF to stdout or, atomically, to a file."""
    from .description import generate_urdf

    text = generate_urdf(args.robot, _parse_sets(args.set), prefix=args.prefix)
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_atomic(Path(args.output), text)
        print(f"wrote {args.output}", file=sys.stderr)
    return 0


def cmd_fk(args: argparse.Namespace) -> int:
    """Forward kinematics: the pose of tool0 in the base frame."""
    units = Units(args.deg, args.mm)
    robot = _load(args)
    q = _read_q(args, units)
    _check_limits(robot, q, args.strict)
    M = robot.tool_placement(q)
    from .model import pose_from_placement

    pose = pose_from_placement(M)
    q_out = _scaled(q, units.scale(_Q_KINDS))
    pos = [float(v) * units.length for v in pose[:3]]
    yaw = float(pose[3]) * units.angle
    matrix = M.homogeneous.copy()
    matrix[:3, 3] *= units.length
    if args.json:
        out = {
            "robot": robot.name,
            "q": q_out,
            "position": pos,
            "yaw": yaw,
            "matrix": matrix.tolist(),
            "frame": robot.tool_frame,
            "reference": robot.base_frame,
            "units": {"length": units.length_name, "angle": units.angle_name},
        }
        print(json.dumps(out))
        return 0
    print(f"robot     {robot.name}: {robot.tool_frame} in {robot.base_frame}")
    print(f"q         {_fmt(q_out)}  [{', '.join(units.names(_Q_KINDS))}]")
    print(f"position  {_fmt(pos)}  [{units.length_name}]")
    print(f"yaw       {yaw: .9g}  [{units.angle_name}]")
    print("matrix")
    for row in matrix:
        print("          " + _fmt(row))
    return 0


def cmd_jacobian(args: argparse.Namespace) -> int:
    """The task Jacobian d(x, y, z, yaw)/dq, or Pinocchio's 6 x 4 frame Jacobian."""
    import numpy as np

    units = Units(args.deg, args.mm)
    robot = _load(args)
    q = _read_q(args, units)
    _check_limits(robot, q, args.strict)
    if args.reference == "task":
        J = robot.task_jacobian(q)
        rows = ["x", "y", "z", "yaw"]
        row_kinds: tuple[str, ...] = _POSE_KINDS
    else:
        J = robot.frame_jacobian(q, args.frame, args.reference)
        rows = ["vx", "vy", "vz", "wx", "wy", "wz"]
        row_kinds = ("length",) * 3 + ("angle",) * 3
    # J_user[i, j] = J[i, j] * (unit of row i) / (unit of column j)
    J = J * np.array(units.scale(row_kinds))[:, None] / np.array(units.scale(_Q_KINDS))[None, :]
    w = robot.manipulability(q)
    if args.json:
        out = {
            "robot": robot.name,
            "q": _scaled(q, units.scale(_Q_KINDS)),
            "reference": args.reference,
            "frame": args.frame or robot.tool_frame,
            "rows": rows,
            "jacobian": J.tolist(),
            "manipulability": w,
            "units": {"length": units.length_name, "angle": units.angle_name},
        }
        print(json.dumps(out))
        return 0
    print(f"robot     {robot.name}: {args.reference} Jacobian of {args.frame or robot.tool_frame}")
    print(f"q         {_fmt(_scaled(q, units.scale(_Q_KINDS)))}  [{', '.join(units.names(_Q_KINDS))}]")
    print("          " + "".join(f"{n:>16}" for n in ("d/dq1", "d/dq2", "d/dq3", "d/dq4")))
    for name, row in zip(rows, J):
        print(f"{name:<10}" + "".join(f"{v:16.9g}" for v in row))
    print(f"manipulability sqrt(det(J J^T)) of the task Jacobian (SI): {w:.9g}")
    return 0


# ---------------------------------------------------------------------------------------------- plumbing
def write_atomic(path: Path, text: str) -> None:
    """Write a text file atomically: a temporary file in the same folder, then a rename.

    An error or Ctrl-C leaves either the old file or none, never a half-written one.
    """
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInputError(f"cannot write {path}: folder {folder} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _add_robot_options(p: argparse.ArgumentParser, urdf_file: bool = True) -> None:
    g = p.add_argument_group("robot")
    g.add_argument("--robot", default="default", metavar="NAME|CONFIG_DIR",
                   help="shipped robot name (see `scara-pin robots`) or a folder of yaml files (default: default)")  # fmt: skip
    g.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a parameter, SI units (e.g. --set l1=0.25); repeatable")  # fmt: skip
    if urdf_file:
        g.add_argument("--urdf", metavar="FILE", help="load this URDF file instead of a configured robot")


def _add_q(p: argparse.ArgumentParser) -> None:
    p.add_argument("q", nargs="*", metavar="Q", help="joint values q1 q2 q3 q4 (URDF order; q3 > 0 lowers the quill)")
    p.add_argument("--deg", action="store_true", help="angles in degrees")
    p.add_argument("--mm", action="store_true", help="lengths in millimetres")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--strict", action="store_true", help="refuse (exit 3) a q outside the joint limits")
    _add_robot_options(p)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``scara-pin``."""
    from . import __version__

    parser = _Parser(
        prog="scara-pin",
        description="Kinematics of SCARA robots from one xacro/URDF description (Pinocchio inside). "
        "SI units unless --deg/--mm; exit codes: 0 ok, 2 invalid input, 3 infeasible, 1 internal error.",
    )
    parser.add_argument("--version", action="version", version=f"scara-pin {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log details to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("robots", help="list the shipped robots")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_robots)

    p = sub.add_parser("urdf", help="write the generated URDF of a robot")
    p.add_argument("-o", "--output", metavar="FILE", help="output file (default: stdout); written atomically")
    p.add_argument("--prefix", default="", help="prefix for every link and joint name (letters, digits, _)")
    _add_robot_options(p, urdf_file=False)
    p.set_defaults(func=cmd_urdf)

    p = sub.add_parser("fk", help="forward kinematics: pose of tool0 in the base frame")
    _add_q(p)
    p.set_defaults(func=cmd_fk)

    p = sub.add_parser("jacobian", help="task Jacobian d(x, y, z, yaw)/dq (or a 6 x 4 frame Jacobian)")
    _add_q(p)
    p.add_argument("--reference", default="task", choices=["task", "world", "local", "local_world_aligned"],
                   help="task (4 x 4, default) or a Pinocchio reference frame for the 6 x 4 frame Jacobian")  # fmt: skip
    p.add_argument("--frame", default=None, help="frame of the 6 x 4 Jacobian (default: tool0)")
    p.set_defaults(func=cmd_jacobian)
    return parser


class _Formatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return f"{record.levelname.lower()}: {record.getMessage()}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``scara-pin`` with ``argv`` (default: ``sys.argv[1:]``) and return the exit code."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(_Formatter())
    log.addHandler(handler)
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except _UsageError as exc:
            print(f"error: {exc} (see scara-pin --help)", file=sys.stderr)
            return 2
        log.setLevel(logging.DEBUG if args.verbose else logging.WARNING)
        func: Callable[[argparse.Namespace], int] | None = getattr(args, "func", None)
        if func is None:
            parser.print_help(sys.stderr)
            return 2
        return func(args)
    except ScaraError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (e.g. `| head`): not an error of ours
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as exc:  # a bug: say so in one line; SCARA_PIN_DEBUG=1 shows the traceback
        if os.environ.get("SCARA_PIN_DEBUG"):
            raise
        print(f"error: internal error ({type(exc).__name__}: {_one_line(exc)}); "
              "please report it; SCARA_PIN_DEBUG=1 shows the traceback", file=sys.stderr)  # fmt: skip
        return 1
    finally:
        log.removeHandler(handler)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
