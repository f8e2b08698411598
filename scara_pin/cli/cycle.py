"""The ``cycle`` command: the standard SCARA cycle (arch moves), its time, legs and active limits."""

from __future__ import annotations

import argparse
import json
import logging
import math
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError, ParameterError
from ._common import (
    Units,
    _acceleration,
    _add_acceleration,
    _add_robot_options,
    _add_units,
    _load,
    _needs_wrist,
    _num,
    _number,
    _read_pose,
)

if TYPE_CHECKING:
    pass


def _payload(args: argparse.Namespace, units: Units) -> Any:
    from ..motion.payload import Payload

    mass = 0.0 if args.payload is None else _number("--payload", args.payload)
    if mass < 0.0:
        raise ParameterError("--payload", mass, "must be >= 0", "kg")
    com: tuple[float, ...] = (0.0, 0.0, 0.0)
    if args.payload_com is not None:
        com = tuple(units.value(f"--payload-com {n}", v, "length") for n, v in zip("XYZ", args.payload_com))
    return Payload(mass, com)  # type: ignore[arg-type]


def _jerk(args: argparse.Namespace) -> list[float] | None:
    if args.jerk_limit is None:
        return None
    if len(args.jerk_limit) not in (1, 4):
        raise ParameterError("--jerk-limit", " ".join(args.jerk_limit), "must be one number or 4 (one per joint)")
    values = [_number("--jerk-limit", v) for v in args.jerk_limit]
    if not all(v > 0 for v in values):
        raise ParameterError("--jerk-limit", values, "must be > 0", "rad/s^3 or m/s^3")
    return values * 4 if len(values) == 1 else values


def cmd_cycle(args: argparse.Namespace) -> int:
    """The standard cycle: up, across, down and back, time-optimal under the robot's limits."""
    from ..motion.cycle import STANDARD_RISE, STANDARD_SPAN, limits_dict, standard_cycle

    logging.getLogger("toppra").setLevel(logging.WARNING)
    units = Units.from_args(args)
    robot = _load(args, units)
    _needs_wrist(robot, "cycle")
    if not (math.isfinite(args.rate) and args.rate > 0):
        raise ParameterError("--rate", args.rate, "must be a finite number > 0", "Hz")
    # defaults in SI; a typed value in the user's units (the units rule)
    span = STANDARD_SPAN if args.span is None else units.value("--span", args.span, "length")
    rise = STANDARD_RISE if args.rise is None else units.value("--rise", args.rise, "length")
    blend = 0.0 if args.no_blend else (None if args.arch is None else units.value("--arch", args.arch, "length"))
    if args.no_blend and args.arch is not None:
        raise InvalidInputError("--arch and --no-blend exclude each other")
    start = None
    if args.from_pose is not None:
        start = _read_pose(args.from_pose, units, "--from")
    direction = None if args.direction is None else [_number("--direction", d) for d in args.direction]
    _acceleration(robot, args.acceleration, units)  # a URDF file has none: given, or refused
    limits = robot.limits
    jerk = _jerk(args)
    result = standard_cycle(robot, start=start, direction=direction, span=span, rise=rise, blend=blend,
                            payload=_payload(args, units), jerk=jerk, limits=limits)  # fmt: skip
    move = result.move
    outputs: dict[str, str] = {}
    if args.out:
        move.trajectory.save(args.out, rate=args.rate)
        outputs["trajectory"] = str(args.out)
    if args.plot:
        from ..viz.cycle import plot_cycle

        plot_cycle(robot, move, args.plot, limits=limits, title=f"{robot.name}: standard cycle "
                   f"{result.cycle_time:.4g} s, payload {move.payload.mass:g} kg")  # fmt: skip
        outputs["plot"] = args.plot
    if args.json:
        print(json.dumps({
            "robot": robot.name,
            "cycle_time": result.cycle_time,
            "legs": [leg.to_dict() for leg in move.legs],
            "limits": limits_dict(robot, limits, move.jerk),
            "limit_ratios": move.ratios,
            "placement": {"from": result.start.tolist(), "to": result.end.tolist(), "rule": result.placement,
                          "min_manipulability": result.min_manipulability},
            "span": result.span, "rise": result.rise, "blend": result.blend,
            "payload": move.payload.to_dict(),
            "q_start": move.trajectory.q_start.tolist(),
            "outputs": outputs,
            "units": {"length": "m", "angle": "rad", "time": "s"},
        }))  # fmt: skip
        return 0
    print(f"robot       {robot.name}: standard cycle, payload {move.payload.mass:g} kg"
          + (f", jerk limit {move.jerk}" if move.jerk else ""))  # fmt: skip
    n = units.length_name
    print(f"cycle time  {_num(result.cycle_time, 6)} s (up {units.num(result.rise, 'length')}, across "
          f"{units.num(result.span, 'length')}, down and back [{n}]; blend {units.num(result.blend, 'length')} {n})")
    print(f"placement   from {units.fmt(result.start[:3], 'length')} to {units.fmt(result.end[:3], 'length')} {n}: "
          f"{result.placement}")  # fmt: skip
    for leg in move.legs:
        print(f"  {'out ' if leg.move == 0 else 'back'} {leg.name:<11} {leg.duration:9.6f} s   "
              f"{leg.active} of {leg.joint} at {leg.ratio:.4f} of its limit")  # fmt: skip
    for kind, where in outputs.items():
        print(f"wrote       {kind}: {where}")
    return 0


def register(sub: Any) -> None:
    """Add the ``cycle`` command to the ``scara-pin`` subparsers."""
    p = sub.add_parser("cycle", help="the standard SCARA cycle (up 25, across 305, down, back): time, legs, limits")
    g = p.add_argument_group("the cycle (lengths in m, or mm with --mm)")
    g.add_argument("--from", dest="from_pose", nargs=4, metavar="P",
                   help="start pose X Y Z YAW (default: where the robot reaches the cycle best, see docs/motion.md)")
    g.add_argument("--direction", nargs=2, metavar="D", help="traverse direction DX DY (with --from; default 1 0)")
    g.add_argument("--span", metavar="L", help="horizontal stroke (default 0.305 m)")
    g.add_argument("--rise", metavar="H", help="vertical stroke (default 0.025 m)")
    g.add_argument("--arch", metavar="B",
                   help="blend distance at each corner, along each line (default: the whole rise)")
    g.add_argument("--no-blend", action="store_true", help="stop at the corners (three straight lines)")
    g = p.add_argument_group("load and limits")
    g.add_argument("--payload", metavar="KG", help="payload mass at the tool (default 0)")
    g.add_argument("--payload-com", nargs=3, metavar="C", help="payload centre of mass X Y Z in the tool frame")
    g.add_argument("--jerk-limit", nargs="+", metavar="J", help="joint jerk limit, one or 4 (rad/s^3, m/s^3)")
    _add_acceleration(g)
    g = p.add_argument_group("outputs (files in SI units)")
    g.add_argument("--rate", type=float, default=1000.0, metavar="HZ", help="sampling rate of --out (default 1000)")
    g.add_argument("--out", metavar="FILE", help="samples t, q, qd, qdd as CSV (or JSON for *.json), atomically")
    g.add_argument("--plot", metavar="PNG", help="side and plan view of the tool path; joint rates against limits")
    _add_units(p, inputs=True, json_help='print one JSON object {"cycle_time", "legs", "limits", ...}')
    _add_robot_options(p)
    p.set_defaults(func=cmd_cycle)
