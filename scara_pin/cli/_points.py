"""Taught points as waypoints of ``traj`` and ``cycle`` (``--points FILE``; the file: :mod:`scara_pin.motion.points`).

- ``traj --points FILE --through P1 P2 [P3 ...]``: from the first point's q, through the middle ones (vias),
  to the last one's, with every method of ``traj`` (time-optimal, ``--duration``, ``--linear``, ``--arch``
  between two points).
- ``cycle --points FILE --from-point P1 --to-point P2``: the standard cycle from P1's pose to P2's (the
  traverse direction and span from the two poses, which must share their height and yaw).

The points replace ``--from``/``--via``/``--to`` (and ``--from``/``--direction``/``--span`` of ``cycle``): the
hook writes the points' values into those options at full precision in the command's units, so every check
and method of the command applies to them unchanged. Giving both is refused (exit 2).
"""

from __future__ import annotations

import argparse
import math
from typing import TYPE_CHECKING

from ..errors import InfeasibleError, InvalidInputError
from ._numbers import MIN_NUMBER
from ._units import Units

if TYPE_CHECKING:
    from ..motion.points import PointSet
    from ..robots import Robot

_SAME = 1e-9  # [m, rad] the cycle's two points share their height and yaw to this


def add_points_options(p: argparse.ArgumentParser, command: str) -> None:
    """Add ``--points FILE`` and the point names of ``command``.

    ``traj``: ``--through``; ``cycle``: ``--from-point``, ``--to-point``. Call after the command's other options
    (it records their defaults).
    """
    g = p.add_argument_group("taught points (a points file of `scara-pin teach`: docs/teach-pendant.md)")
    g.add_argument("--points", metavar="FILE", help="points file (.yaml, .yml or .csv) naming joint configurations")
    if command == "traj":
        g.add_argument("--through", nargs="+", metavar="NAME",
                       help="with --points: from the first point, via the middle ones, to the last")  # fmt: skip
    else:
        g.add_argument("--from-point", metavar="NAME", help="with --points: the cycle starts at this point")
        g.add_argument("--to-point", metavar="NAME", help="with --points: the traverse ends at this point's pose")
        # (a command not being run gets a parser stand-in that keeps nothing: no default to record)
        get_default = getattr(p, "get_default", None)
        p.set_defaults(_span_default=None if get_default is None else get_default("span"))


def _load(args: argparse.Namespace, robot: Robot, names: list[str]) -> PointSet:
    """The points file, each named point checked HERE, so that a message names the point and the file.

    The points become option values (--from, ...) afterwards, whose checks would name the options instead.

    Raises:
        InvalidInputError: an unknown name; a file that does not fit the robot (joint count, a value beyond
            +/-1e6, a pose that is not the FK of its q).
        InfeasibleError: a named point outside the joint limits (as a --from outside them, exit 3).
    """
    from ..motion.points import read_points

    points = read_points(args.points, robot).resolved(robot, origin=f"points file {args.points}")  # poses: their IK
    for name in names:
        outside = robot.outside_limits(points.q_of(name), tol=1e-12)  # an unknown name: exit 2 naming the known ones
        if outside:
            raise InfeasibleError(f"points file {args.points}: point {name} is outside the joint limits: "
                                  + "; ".join(outside))  # fmt: skip
    return points


def _text(value: float, scale: float) -> str:
    """A value for an option, at full precision in the command's units (tinier than the grammar's least: 0)."""
    v = float(value) * float(scale)
    return repr(v if abs(v) >= MIN_NUMBER else 0.0)


def use_points(args: argparse.Namespace, robot: Robot, units: Units, command: str) -> None:
    """Replace the endpoint options of ``command`` by the points named on the command line (in place).

    Raises:
        InvalidInputError: ``--points`` without names or names without ``--points``, points given together with
            the options they replace, an unknown name, a file that does not fit the robot, or (``cycle``) two
            points at different heights or yaws.
    """
    if command == "traj":
        names = list(args.through or [])
        if args.points is None:
            if names:
                raise InvalidInputError("--through needs --points FILE (the points file that names them)")
            return
        if len(names) < 2:
            raise InvalidInputError("--points needs --through with at least two point names (from ... to)")
        taken = [flag for flag, value in (("--from", args.from_q), ("--to", args.to_q), ("--via", args.via),
                                          ("--from-pose", args.from_pose), ("--to-pose", args.to_pose)) if value]
        if taken:
            raise InvalidInputError(f"--points --through replaces {', '.join(taken)}: give one or the other")
        points = _load(args, robot, names)
        scale = units.scale(units.q)
        qs = [[_text(v, s) for v, s in zip(points.q_of(n), scale, strict=True)] for n in names]
        args.from_q, args.to_q, args.via = qs[0], qs[-1], qs[1:-1] or None
        return
    names = [n for n in (args.from_point, args.to_point) if n is not None]
    if args.points is None:
        if names:
            raise InvalidInputError("--from-point and --to-point need --points FILE")
        return
    if len(names) != 2:
        raise InvalidInputError("--points needs --from-point NAME and --to-point NAME")
    span_given = args.span != args._span_default
    taken = [flag for flag, given in (("--from", args.from_pose), ("--direction", args.direction),
                                      ("--span", span_given)) if given]  # fmt: skip
    if taken:
        raise InvalidInputError(f"--from-point/--to-point replace {', '.join(taken)}: give one or the other")
    points = _load(args, robot, names)
    a, b = (robot.tool_pose(robot.check_q(points.q_of(n))) for n in names)
    dz, dyaw = float(b[2] - a[2]), math.remainder(float(b[3] - a[3]), 2 * math.pi)
    if abs(dz) > _SAME or abs(dyaw) > _SAME:
        raise InvalidInputError(f"the standard cycle's two ends share one height and yaw; {names[1]} differs from "
                                f"{names[0]} by dz = {dz:.6g} m, dyaw = {dyaw:.6g} rad (traj --arch --points FILE "
                                f"--through {names[0]} {names[1]} moves between any two poses)")  # fmt: skip
    dx, dy = float(b[0] - a[0]), float(b[1] - a[1])
    if math.hypot(dx, dy) <= _SAME:
        raise InvalidInputError(f"points {names[0]} and {names[1]} are at the same place: the cycle needs a traverse")
    L, A = units.length, units.angle
    args.from_pose = [_text(a[0], L), _text(a[1], L), _text(a[2], L), _text(a[3], A)]
    args.direction = [_text(dx, 1.0), _text(dy, 1.0)]
    args.span = _text(math.hypot(dx, dy), L)
