"""The ``cycle`` command: the standard SCARA cycle (arch moves), its time, legs and active limits."""

from __future__ import annotations

import argparse
import json
import logging
from typing import Any

from ..errors import InvalidInputError, ParameterError, ScaraError
from ..files import outputs_together
from ._joints import needs_wrist, read_pose
from ._numbers import number, number_type
from ._options import add_cell_options, add_motion_limits, add_robot_options, add_units
from ._outputs import check_command_outputs
from ._points import add_points_options, use_points
from ._robot import cell_from_args, payload_from_args, robot_from_args, with_motion_limits
from ._units import Units, jerk_limits


def cmd_cycle(args: argparse.Namespace) -> int:
    """The standard cycle: up, across, down and back, time-optimal under the robot's limits."""
    from ..motion.cycle import STANDARD_CLEARANCE, STANDARD_RISE, STANDARD_SPAN, CyclePath, limits_dict, standard_cycle

    logging.getLogger("toppra").setLevel(logging.WARNING)
    units = Units.from_args(args)
    check_command_outputs(args, {"--out": args.out, "--plot": args.plot}, figures=("--plot",))  # before any work
    path = CyclePath(args.path)
    if path is CyclePath.JUMP:
        for flag, given in (("--arch", args.arch is not None), ("--no-blend", args.no_blend)):
            if given:
                raise InvalidInputError(f"{flag} shapes the straight-leg arch: it needs --path lines (the jump, the "
                                        "default, has no corners to blend)")  # fmt: skip
    elif args.clearance_radius is not None:
        raise InvalidInputError("--clearance-radius applies to the jump (--path jump): the straight-leg arch lifts "
                                "vertically and blends its corners")  # fmt: skip
    robot = robot_from_args(args, units)
    needs_wrist(robot, "cycle")
    use_points(args, robot, units, "cycle")  # --points FILE --from-point P1 --to-point P2: --from, --direction, --span
    if not args.rate > 0:  # parsed by the one number grammar (number_type): finite, ASCII digits
        raise ParameterError("--rate", args.rate, "must be > 0", "Hz")
    # defaults in SI; a typed value in the user's units (the units rule)
    span = STANDARD_SPAN if args.span is None else units.value("--span", args.span, "length")
    rise = STANDARD_RISE if args.rise is None else units.value("--rise", args.rise, "length")
    blend = 0.0 if args.no_blend else (None if args.arch is None else units.value("--arch", args.arch, "length"))
    if args.no_blend and args.arch is not None:
        raise InvalidInputError("--arch and --no-blend exclude each other")
    radius = (STANDARD_CLEARANCE if args.clearance_radius is None
              else units.value("--clearance-radius", args.clearance_radius, "length"))  # fmt: skip
    ceiling = None if args.max_height is None else units.value("--max-height", args.max_height, "length")
    start = None
    if args.from_pose is not None:
        start = read_pose(args.from_pose, units, "--from")
    direction = None if args.direction is None else [number("--direction", d) for d in args.direction]
    robot = with_motion_limits(args, robot, units)  # a URDF file has none: given, or refused
    limits = robot.limits
    jerk = jerk_limits(args, units)
    cell = cell_from_args(args, units)
    common = {"start": start, "direction": direction, "span": span, "rise": rise,
              "payload": payload_from_args(args, units), "jerk": jerk, "limits": limits, "max_height": ceiling,
              "cell": cell, "torque": not args.no_torque}  # fmt: skip
    if path is CyclePath.JUMP:
        result = standard_cycle(robot, path=path, clearance_radius=radius, **common)  # type: ignore[arg-type]
    else:
        result = standard_cycle(robot, path=path, blend=blend, **common)  # type: ignore[arg-type]
    move = result.move
    outputs: dict[str, str] = {}
    with outputs_together():  # all of them, or none
        if args.out:
            move.trajectory.save(args.out, rate=args.rate)
            outputs["trajectory"] = str(args.out)
        if args.plot:
            from ..viz.cycle import plot_cycle

            plot_cycle(result, args.plot, robot=robot, units=units.display, limits=limits,
                       title=f"{robot.name}: standard cycle ({path.value}) {result.cycle_time:.4g} s, payload "
                       f"{move.payload.mass:g} kg")  # fmt: skip
            outputs["plot"] = args.plot
    compare = _jump_for_comparison(robot, result, common, radius) if path is CyclePath.LINES else None
    bound = result.lower_bound
    if args.json:
        summary: dict[str, Any] = {
            "robot": robot.name,
            "path": path.value,
            "cycle_time": result.cycle_time,
            "lower_bound": None if bound is None else bound.to_dict(),
            "gap": result.gap,
            "legs": [leg.to_dict() for leg in move.legs],
            "limits": limits_dict(robot, limits, move.jerk),
            "limit_ratios": move.ratios,
            "worst": {w.quantity.value: w.to_dict() for w in result.verification.limited()},  # type: ignore[union-attr]
            "placement": {"from": result.start.tolist(), "to": result.end.tolist(), "rule": result.placement,
                          "min_manipulability": result.min_manipulability},
            "span": result.span, "rise": result.rise, "blend": result.blend,
            "clearance_radius": result.clearance_radius, "max_height": result.max_height,
            "payload": move.payload.to_dict(),
            "torque": result.torque,
            "joints": list(robot.joint_names),
            "q_start": move.trajectory.q_start.tolist(),
            "outputs": outputs,
            "units": {"length": "m", "angle": "rad", "time": "s"},
        }  # fmt: skip
        if cell is not None:
            summary["cell"] = cell_summary(cell, move.distance)
        if path is CyclePath.JUMP:
            summary["solver"] = move.stats.to_dict()  # type: ignore[union-attr]
            summary["arch"] = {"peak_above_clearance": move.peak, "bulge": move.bulge,  # type: ignore[union-attr]
                               "clearance_error": move.clearance}  # type: ignore[union-attr]
        else:
            summary["jump_cycle_time"] = compare[0] if compare else None
        print(json.dumps(summary))
        return 0
    print(result.summary(units.display))  # the cycle's text: its repr in SI (CycleResult.summary)
    if cell is not None:
        print(cell_text(cell, move.distance, units))
    if path is CyclePath.LINES:
        if compare is not None:
            slower = 100.0 * (result.cycle_time / compare[0] - 1.0)
            print(f"note        the straight-leg arch is slower: the jump (--path jump, the default) takes "
                  f"{compare[0]:.6g} s under the same limits ({slower:.1f} % less)")
        else:
            print("note        the straight-leg arch is slower than the jump (--path jump, the default)")
    for kind, where in outputs.items():
        print(f"wrote       {kind}: {where}")
    return 0


def cell_summary(cell: Any, distance: Any) -> dict[str, Any]:
    """The ``cell`` object of a command's ``--json``: the file, the margin, the obstacles, the closest pair."""
    return {"file": cell.origin, "margin": cell.margin, "obstacles": [o.name for o in cell.obstacles],
            "carried": None if cell.carried is None else cell.carried.to_dict(),
            "closest": None if distance is None else distance.to_dict()}  # fmt: skip


def cell_text(cell: Any, distance: Any, units: Units) -> str:
    """The ``cell`` line of a command's text: the cell, its margin, and the closest pair of the motion."""
    Ln = units.length_name
    head = (f"cell        {cell.origin}: {len(cell.obstacles)} obstacle(s)"
            + (", carrying a part" if cell.carried is not None else "")
            + f", margin {units.num(cell.margin, 'length')} {Ln}")  # fmt: skip
    if distance is None:
        return head + "; no pair checked"
    return (head + f"; closest {distance.pair} at {units.num(distance.distance, 'length')} {Ln} "
            f"(t = {distance.time:.4f} s)")  # fmt: skip


def _jump_for_comparison(robot: Any, result: Any, common: dict[str, Any], radius: float) -> tuple[float] | None:
    """The jump cycle's time at the same placement and limits, or None if it cannot be planned."""
    from ..motion.cycle import CyclePath, standard_cycle

    kwargs = dict(common, start=result.start, direction=(result.end - result.start)[:2])
    try:
        jump = standard_cycle(robot, path=CyclePath.JUMP, clearance_radius=radius, **kwargs)
    except ScaraError:
        return None
    return (jump.cycle_time,)


def register(sub: Any) -> None:
    """Add the ``cycle`` command to the ``scara-pin`` subparsers."""
    p = sub.add_parser("cycle", help="the standard SCARA cycle (up 25, across 305, down, back): time, legs, limits")
    g = p.add_argument_group("the cycle (lengths in m, or mm with --mm)")
    g.add_argument("--from", dest="from_pose", nargs=4, metavar="P",
                   help="start pose X Y Z YAW (default: where the robot reaches the cycle best, see docs/motion.md)")
    g.add_argument("--direction", nargs=2, metavar="D", help="traverse direction DX DY (with --from; default 1 0)")
    g.add_argument("--span", metavar="L", help="horizontal stroke (default 0.305 m)")
    g.add_argument("--rise", metavar="H", help="vertical stroke (default 0.025 m)")
    g.add_argument("--path", choices=("jump", "lines"), default="jump",
                   help="jump: time-optimal, joint path free (default); lines: the straight-leg arch (slower)")
    g.add_argument("--clearance-radius", metavar="R",
                   help="jump: within R of an end (horizontally) the tool may be below the rise (default 0.005 m)")
    g.add_argument("--max-height", metavar="Z", help="a ceiling for the tool's z (base frame)")
    g.add_argument("--arch", metavar="B",
                   help="lines: blend distance at each corner, along each line (default: the whole rise)")
    g.add_argument("--no-blend", action="store_true", help="lines: stop at the corners (three straight lines)")
    g = p.add_argument_group("load and limits")
    g.add_argument("--payload", metavar="KG", help="payload mass at the tool (default 0)")
    g.add_argument("--payload-com", nargs=3, metavar="C", help="payload centre of mass X Y Z in the tool frame")
    g.add_argument("--jerk-limit", nargs="+", metavar="J", help="joint jerk limit, one or 4 (rad/s^3, m/s^3)")
    g.add_argument("--no-torque", action="store_true",
                   help="leave the effort limits out (a URDF's placeholder efforts); said in the output")
    add_motion_limits(g)
    g = p.add_argument_group("outputs (files in SI units)")
    g.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out (default 1000)")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="samples t, q, qd, qdd as CSV (or JSON for *.json), atomically")
    g.add_argument("--plot", metavar="PNG", help="side and plan view of the tool path; joint rates against limits")
    add_units(p, inputs=True, json_help='print one JSON object {"cycle_time", "legs", "limits", ...}')
    add_robot_options(p)
    add_cell_options(p)
    add_points_options(p, "cycle")
    p.set_defaults(func=cmd_cycle)
