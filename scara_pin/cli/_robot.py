"""The robot, its accelerations, its cell and its payload, from the command line's options."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError, ParameterError
from ._numbers import number, parse_locks, parse_sets
from ._options import UsageError
from ._units import Q_NAMES, Units

if TYPE_CHECKING:
    from ..robots import Robot

MAX_NAME = 4096
"""Longest --robot name or folder path (the system's PATH_MAX)."""


def robot_from_args(args: argparse.Namespace, units: Units | None = None) -> Robot:
    """The robot of ``--robot`` (default: default) or ``--urdf``, with ``--set``, the frames and ``--lock``.

    Prints the notes of the loaded model (the tool chosen without a tool0, another arm locked) as ``info:``
    lines; sets ``units.q`` to what each of its joint values measures.
    """
    if args.robot is not None and getattr(args, "urdf", None) is not None:
        raise InvalidInputError("give either --robot NAME or --urdf FILE, not both")
    args.robot = "default" if args.robot is None else args.robot
    if len(args.robot) > MAX_NAME or "\0" in args.robot:
        raise InvalidInputError(f"--robot {args.robot[:40]!r}...: not a robot name nor a folder "
                                f"(longer than {MAX_NAME} characters or with a NUL)")  # fmt: skip
    if args.urdf is not None:  # a regular file under the size cap, or refused before it is read
        from ..limits import check_input_file

        check_input_file(args.urdf, "URDF")
    robot = _load(args)
    for note in (robot.frame_note, robot.lock_note):  # the tool chosen without a tool0, another arm locked
        if note is not None:
            print(f"info: {note}", file=sys.stderr)
    if units is not None:  # what each joint value measures, read from the model (any joint order)
        units.q = robot.joint_kinds
    return robot


def _load(args: argparse.Namespace, acceleration: Sequence[float] | None = None) -> Robot:
    """:func:`scara_pin.robots.load_robot` with the robot options of ``args`` (``--lock`` read before ``--set``)."""
    from ..robots import load_robot

    locks = parse_locks(getattr(args, "lock", None))
    return load_robot(args.robot, parse_sets(args.set), urdf=args.urdf, tool=args.tool, base=args.base,
                      package_path=args.package_path or (), lock=locks, acceleration=acceleration)  # fmt: skip


def with_acceleration(args: argparse.Namespace, robot: Robot, units: Units) -> Robot:
    """The robot with the acceleration limits of ``--acceleration``; refuse a robot without any.

    Given, they replace the robot's: the robot of :func:`robot_from_args` is loaded again with them
    (``load_robot(acceleration=...)``), the one given is left as it is. Not given: ``robot`` itself.

    Raises:
        InvalidInputError: no acceleration limits known (a URDF file) and none given.
    """
    texts: Sequence[str] | None = args.acceleration
    if texts:
        if len(texts) != len(units.q):
            raise ParameterError("--acceleration", " ".join(texts), f"must be {len(units.q)} values, one per joint")
        units.guard([f"--acceleration {n}" for n in Q_NAMES], texts, units.q)
        acc = [number(f"--acceleration {n}", t) / sc for n, t, sc in zip(Q_NAMES, texts, units.scale(units.q))]
        for name, value in zip(Q_NAMES, acc):
            if not value > 0:
                raise ParameterError(f"--acceleration {name}", value, "must be > 0")
        return _load(args, acc)
    if not all(math.isfinite(v) for v in robot.limits.acceleration):
        raise InvalidInputError(f"robot {robot.name!r} has no acceleration limits (a URDF file has none): give "
                                "--acceleration with one value per joint [rad/s^2, m/s^2]")  # fmt: skip
    return robot


def cell_from_args(args: argparse.Namespace, units: Units | None = None) -> Any:
    """The cell named by ``--cell`` (with ``--margin``), with the part of ``--carry`` on the tool, or None.

    The margin is in the typed length unit; ``--carry`` alone is a cell of no obstacle holding that part (the
    default margin).
    """
    path = getattr(args, "cell", None)
    margin = getattr(args, "margin", None)
    carry = getattr(args, "carry", None)
    if path is None and carry is None:
        if margin is not None:
            raise UsageError("--margin needs --cell")
        return None
    from ..cell import Cell, load_cell

    if margin is not None and units is not None:
        margin = margin / units.length
    packages = tuple(getattr(args, "package_path", None) or ())
    cell = load_cell(path, margin=margin, package_dirs=packages) if path is not None else None
    if carry is None:
        return cell
    from ..job.loading import read_carry

    part = read_carry(carry).part()
    if cell is None:
        return Cell(margin=Cell().margin if margin is None else margin, carried=part, origin=f"the part of {carry}")
    if cell.carried is not None:
        raise InvalidInputError(f"--carry {carry} and the cell file {path}'s carried: name two parts: give one")
    return cell.with_carried(part)


def payload_from_args(args: argparse.Namespace, units: Units) -> Any:
    """The payload of ``--payload KG`` (default 0) and ``--payload-com X Y Z`` (in the tool frame, typed units)."""
    from ..motion.payload import Payload

    mass = 0.0 if args.payload is None else number("--payload", args.payload)
    if mass < 0.0:
        raise ParameterError("--payload", mass, "must be >= 0", "kg")
    com: tuple[float, ...] = (0.0, 0.0, 0.0)
    if args.payload_com is not None:
        com = tuple(units.value(f"--payload-com {n}", v, "length") for n, v in zip("XYZ", args.payload_com))
    return Payload(mass, com)  # type: ignore[arg-type]
