"""The robot, its accelerations, its cell and its payload, from the command line's options."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError, ParameterError
from ..limits import check_input_file
from ._numbers import number, parse_locks, parse_sets
from ._options import UsageError
from ._units import Units

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
        check_input_file(args.urdf, "URDF")
    robot = _load(args)
    for note in (robot.frame_note, robot.lock_note):  # the tool chosen without a tool0, another arm locked
        if note is not None:
            print(f"info: {note}", file=sys.stderr)
    if units is not None:  # what each joint value measures, read from the model (any joint order)
        units.q = robot.joint_kinds
    return robot


def _load(args: argparse.Namespace, acceleration: Sequence[float] | None = None,
          velocity: Sequence[float] | None = None) -> Robot:  # fmt: skip
    """:func:`scara_pin.robots.load_robot` with the robot options of ``args`` (``--lock`` read before ``--set``)."""
    from ..robots import load_robot

    locks = parse_locks(getattr(args, "lock", None))
    return load_robot(args.robot, parse_sets(args.set), urdf=args.urdf, tool=args.tool, base=args.base,
                      package_path=args.package_path or (), lock=locks, acceleration=acceleration,
                      velocity=velocity)  # fmt: skip


_LIMIT_OPTIONS = (("velocity", "/s"), ("acceleration", "/s^2"))


def _per_joint(option: str, texts: Sequence[str], robot: Robot, units: Units, per: str) -> list[float]:
    """``--velocity`` / ``--acceleration`` values: one per joint, in the user's units (the units rule), SI out."""
    names = robot.joint_names
    shown = ", ".join(f"{n} [{u}{per}]" for n, u in zip(names, units.names(units.q)))
    if len(texts) != len(units.q):
        raise ParameterError(f"--{option}", " ".join(texts), f"must be {len(units.q)} values, one per joint: {shown}")
    units.guard([f"--{option} {n}" for n in names], texts, units.q)
    values = [number(f"--{option} {n}", t) / sc for n, t, sc in zip(names, texts, units.scale(units.q))]
    for name, value in zip(names, values):
        if not (math.isfinite(value) and value > 0):
            raise ParameterError(f"--{option} of joint {name}", value, "must be > 0")
    return values


def with_motion_limits(args: argparse.Namespace, robot: Robot, units: Units) -> Robot:
    """The robot with the limits of ``--velocity`` and ``--acceleration``; refuse a robot missing any.

    Given, they replace the robot's: the robot of :func:`robot_from_args` is loaded again with them
    (``load_robot(velocity=..., acceleration=...)``), the one given is left as it is.

    Raises:
        InvalidInputError: a joint without a velocity limit (a URDF's continuous joint without ``<limit>``, or a
            placeholder 0), or no acceleration limits (a URDF file has none), and the option not given: the
            message names each joint, its unit and the option.
    """
    given = {option: _per_joint(option, getattr(args, option), robot, units, per)
             for option, per in _LIMIT_OPTIONS if getattr(args, option, None)}  # fmt: skip
    if given:
        robot = _load(args, given.get("acceleration"), given.get("velocity"))
    names, kinds = robot.joint_names, units.q
    for option, per in _LIMIT_OPTIONS:
        values = getattr(robot.limits, option)
        missing = [(n, v) for n, v in zip(names, values) if not (math.isfinite(v) and v > 0)]
        if not missing:
            continue
        form = " ".join(f"{option[0].upper()}{i + 1}" for i in range(len(names)))
        one = ", ".join(f"{n} [{u}{per}]" for n, u in zip(names, units.names(kinds)))
        if option == "acceleration":
            why = f"robot {robot.name!r} has no acceleration limits (a URDF file has none)"
        else:
            why = "; ".join(f"joint {n} has no velocity limit (" + ("no <limit> in the URDF: a continuous joint may "
                            "omit it" if math.isinf(v) else f"{v:g} in the URDF: a placeholder") + ")"
                            for n, v in missing)  # fmt: skip
        raise InvalidInputError(f"{why}: give --{option} {form}, one per joint: {one}")
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
