"""Commands of the motion layer: ``traj``, ``jog``."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from typing import Any

from ..errors import InfeasibleError, InvalidInputError, ParameterError, ScaraError
from ..files import outputs_together
from ..units import format_number, format_vector
from ._joints import joint_arg, needs_wrist, read_pose
from ._numbers import number, number_type
from ._options import add_cell_options, add_motion_limits, add_robot_options, add_units
from ._outputs import check_command_outputs, log
from ._points import add_points_options, use_points
from ._robot import cell_from_args, payload_from_args, robot_from_args, with_motion_limits
from ._setpoints import add_setpoint_options, check_setpoint_options, write_setpoints
from ._units import POSE_KINDS, Units, jerk_limits
from .cycle import cell_summary, cell_text


def cmd_traj(args: argparse.Namespace) -> int:
    """A trajectory between configurations or poses: quintic, time-optimal, or a straight tool line."""
    import numpy as np

    from ..motion.plan import MotionRequest, plan_motion

    logging.getLogger("toppra").setLevel(logging.WARNING)
    units = Units.from_args(args)
    check_command_outputs(args, {"--out": args.out, "--setpoints": args.setpoints, "--plot": args.plot},
                          figures=("--plot",))  # before any work  # fmt: skip
    robot = robot_from_args(args, units)
    use_points(args, robot, units, "traj")  # --points FILE --through P1 .. Pn: their q as --from, --via, --to
    for flag in ("linear", "arch", "plot", "payload"):
        if getattr(args, flag, None):
            needs_wrist(robot, f"traj --{flag}")  # 3-joint arms: joint-space trajectories (quintic, TOPP-RA)
    robot = with_motion_limits(args, robot, units)
    if (args.from_q is None) == (args.from_pose is None):
        raise InvalidInputError("give the start as either --from Q1 Q2 Q3 Q4 or --from-pose X Y Z YAW")
    if (args.to_q is None) == (args.to_pose is None):
        raise InvalidInputError("give the end as either --to Q1 Q2 Q3 Q4 or --to-pose X Y Z YAW")
    if args.duration is not None and args.optimal:
        raise InvalidInputError("--duration and --optimal exclude each other")
    if args.duration is not None and not args.duration > 0:
        raise ParameterError("--duration", args.duration, "must be > 0", "s")
    for name, rate in (("--rate", args.rate), ("--setpoint-rate", args.setpoint_rate)):
        if rate is not None and not rate > 0:
            raise ParameterError(name, rate, "must be > 0", "Hz")
    vias = [joint_arg(robot, v, units, f"--via #{i + 1}") for i, v in enumerate(args.via or [])]
    pose_from = read_pose(args.from_pose, units, "--from-pose", robot.dof) if args.from_pose else None
    pose_to = read_pose(args.to_pose, units, "--to-pose", robot.dof) if args.to_pose else None
    q_from = joint_arg(robot, args.from_q, units, "--from") if args.from_q else None
    tool_speed = None
    if args.tool_speed is not None:
        if not args.tool_speed > 0:
            raise ParameterError("--tool-speed", args.tool_speed, "must be > 0")
        units.guard(("--tool-speed",), (f"{args.tool_speed:g}",), ("length",))
        tool_speed = args.tool_speed / units.length
    _arch_options(args)
    if args.arch and not args.linear:
        if args.via and args.path == "lines":
            raise InvalidInputError("--arch --path lines takes no --via (one arch between two poses; the jump takes "
                                    "--via as hints of its way through a cell)")
        if args.duration is not None:
            raise InvalidInputError("--arch is time-optimal: --duration does not apply")
    jerk = jerk_limits(args, units)
    if jerk is not None and robot.dof != 4:
        raise InvalidInputError("--jerk-limit needs a 4-joint robot for now")
    request = MotionRequest(
        start_q=q_from, end_q=joint_arg(robot, args.to_q, units, "--to") if args.to_q else None,
        start_pose=None if pose_from is None else np.array(pose_from),
        end_pose=None if pose_to is None else np.array(pose_to), vias=tuple(vias), duration=args.duration,
        linear=args.linear, arch=args.arch, tool_speed=tool_speed, torque=args.torque,
        payload=payload_from_args(args, units),
        rise=None if args.rise is None else units.value("--rise", args.rise, "length"),
        blend=None if args.blend is None else units.value("--blend", args.blend, "length"),
        jerk=None if jerk is None else tuple(jerk),
        path=args.path or "jump",
        clearance_radius=None if args.clearance_radius is None else units.value("--clearance-radius",
                                                                                 args.clearance_radius, "length"),
        max_height=None if args.max_height is None else units.value("--max-height", args.max_height, "length"),
        cell=cell_from_args(args, units),
    )
    plan = plan_motion(robot, request)
    if plan.arch is not None:
        return _print_arch(args, plan.robot, plan.arch, units, plan.method, tool_speed, request.cell)
    planned, traj, method = plan.robot, plan.trajectory, plan.method.value
    from ..motion.timing import limit_ratios

    ratios = limit_ratios(planned, traj, rate=1000.0, tool_speed=tool_speed, torque=args.torque)
    if not ratios.worst <= 1 + 1e-6:  # NaN (an unknown limit) fails too
        message = (f"the trajectory exceeds a limit: worst ratio {ratios.worst:.6g} (velocity "
                   f"{ratios.velocity:.6g}, acceleration {ratios.acceleration:.6g}); a longer --duration, or "
                   "--optimal, respects them")  # fmt: skip
        if args.strict:
            raise InfeasibleError(message)
        log.warning(message)
    outputs = _write_outputs(args, planned, traj, units, method, tool_speed)
    summary = {
        "robot": planned.name,
        "method": method,
        "duration": traj.duration,
        "q_from": traj.q_start.tolist(),
        "q_to": traj.q_end.tolist(),
        "limit_ratios": {"velocity": ratios.velocity, "acceleration": ratios.acceleration,
                         "tool_speed": ratios.tool_speed, "torque": ratios.torque},  # fmt: skip
        "outputs": outputs,
        "units": {"length": "m", "angle": "rad", "time": "s"},
    }
    if request.cell is not None:
        summary["cell"] = cell_summary(request.cell, plan.clearance)
    if args.json:
        if not args.out:
            summary["samples"] = traj.resample(args.rate).to_dict()
        print(json.dumps(summary))
        return 0
    text = sys.stderr if "-" in outputs.values() else sys.stdout  # stdout carries a file: the summary goes aside
    print(f"robot     {planned.name}: {method}", file=text)
    q_units = ", ".join(units.names(units.q))
    print(f"duration  {format_number(traj.duration, 9)} s", file=text)
    print(f"from      {units.fmt(traj.q_start, units.q)}  [{q_units}]", file=text)
    print(f"to        {units.fmt(traj.q_end, units.q)}  [{q_units}]", file=text)
    print(f"limits    worst |v|/vmax {ratios.velocity:.6f}, |a|/amax {ratios.acceleration:.6f} "
          "(exact for joint-line laws, else sampled)", file=text)  # fmt: skip
    if request.cell is not None:
        print(cell_text(request.cell, plan.clearance, units).replace("cell        ", "cell      ", 1), file=text)
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}", file=text)
    return 0


_ARCH_ONLY = ("rise", "blend", "clearance_radius", "max_height", "path")


def _arch_options(args: argparse.Namespace) -> None:
    """Refuse (exit 2) an option given with a motion kind it does not act on, naming the combination."""
    check_setpoint_options(args)
    if not args.arch:
        for name in _ARCH_ONLY:
            if getattr(args, name) is not None:
                raise InvalidInputError(f"--{name.replace('_', '-')} shapes an arch move: it needs --arch")
        return
    if (args.path or "jump") == "jump":
        if args.blend is not None:
            raise InvalidInputError("--blend shapes the straight-leg arch: it needs --arch --path lines (the jump, "
                                    "the default, has no corners to blend)")  # fmt: skip
    elif args.clearance_radius is not None:
        raise InvalidInputError("--clearance-radius applies to the jump (--path jump): the straight-leg arch "
                                "(--path lines) lifts vertically and blends its corners")  # fmt: skip
    if args.payload is not None and not args.torque:
        raise InvalidInputError("--payload changes only the torques: give --torque too")


def _write_outputs(args: argparse.Namespace, robot: Any, traj: Any, units: Units, law: str,
                   tool_speed: float | None) -> dict[str, str]:  # fmt: skip
    """``--out``, ``--setpoints``, ``--plot`` (the planned ``robot`` carries the payload): what was written, by kind."""
    outputs: dict[str, str] = {}
    with outputs_together():  # all of them, or none
        if args.out:
            traj.save(args.out, rate=args.rate)
            outputs["trajectory"] = str(args.out)
        if args.setpoints:
            write_setpoints(args, robot, traj, units)
            outputs["setpoints"] = args.setpoints
        if args.plot:
            from ..viz.plots import plot_trajectory

            plot_trajectory(traj, args.plot, robot=robot, units=units.display, law=law, torque=args.torque,
                            tool_speed=tool_speed)  # fmt: skip
            outputs["plot"] = args.plot
    return outputs


def _print_arch(args: argparse.Namespace, robot: Any, move: Any, units: Units, method: Any,
                tool_speed: float | None, cell: Any = None) -> int:
    """``traj --arch``: write and print the arch move (the jump, or the straight-leg arch with ``--path lines``)."""
    from ..motion.plan import Method

    traj = move.trajectory
    jump = method is Method.JUMP
    outputs = _write_outputs(args, robot, traj, units, method.value, tool_speed)
    faster = None if jump else _jump_time(robot, move, args, units, tool_speed)
    if args.json:
        summary = {"robot": robot.name, "method": method.value, "path": "jump" if jump else "lines",
                   "duration": traj.duration, "q_from": traj.q_start.tolist(), "q_to": traj.q_end.tolist(),
                   "legs": [leg.to_dict() for leg in move.legs], "limit_ratios": move.ratios,
                   "payload": move.payload.to_dict(), "outputs": outputs,
                   "units": {"length": "m", "angle": "rad", "time": "s"}}  # fmt: skip
        if jump:
            summary.update({"lower_bound": move.lower_bound.to_dict(), "solver": move.stats.to_dict(),
                            "arch": {"z_top": move.z_top, "peak_above_clearance": move.peak, "bulge": move.bulge,
                                     "clearance_error": move.clearance}})  # fmt: skip
        else:
            summary["jump_duration"] = faster
        if cell is not None:
            summary["cell"] = cell_summary(cell, move.distance)
        if not args.out:
            summary["samples"] = traj.resample(args.rate).to_dict()
        print(json.dumps(summary))
        return 0
    text = sys.stderr if "-" in outputs.values() else sys.stdout  # stdout carries a file: the summary goes aside
    print(f"robot     {robot.name}: {method.value}", file=text)
    print(f"duration  {format_number(traj.duration, 9)} s", file=text)
    if jump:
        b, Ln = move.lower_bound, units.length_name
        print(f"bound     {format_number(b.duration, 6)} s ({b.reason}): no move under these limits is faster; this "
              f"one is {100 * move.gap:.1f} % above it", file=text)  # fmt: skip
        print(f"arch      up to {units.num(move.z_top + move.peak, 'length')} {Ln}, {units.num(move.bulge, 'length')} "
              f"{Ln} off the straight line in plan view; solved in {move.stats.seconds:.3g} s", file=text)  # fmt: skip
    for leg in move.legs:
        binding = ", ".join(f"{bd.quantity} {bd.joint} {100 * bd.share:.0f} %" for bd in getattr(leg, "binding", ()))
        print(f"  {leg.name:<11} {leg.duration:9.6f} s   {leg.active} of {leg.joint} at {leg.ratio:.4f} of its limit"
              + (f"; binding: {binding}" if binding else "") + leg.closest_words(units.display), file=text)  # fmt: skip
    if cell is not None:
        print(cell_text(cell, move.distance, units).replace("cell        ", "cell      ", 1), file=text)
    if not jump:
        print("note      the straight-leg arch is slower than the jump (--path jump, the default)"
              + (f", which takes {format_number(faster, 6)} s" if faster is not None else ""), file=text)  # fmt: skip
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}", file=text)
    return 0


def _jump_time(robot: Any, move: Any, args: argparse.Namespace, units: Units, tool_speed: float | None
               ) -> float | None:  # fmt: skip
    """The jump's duration between the same configurations and limits, or None if it cannot be planned."""
    from ..motion.jump import STANDARD_RISE, jump_move

    q0, q1 = move.trajectory.q_start, move.trajectory.q_end
    rise = STANDARD_RISE if args.rise is None else number("--rise", args.rise) / units.length
    ceiling = None if args.max_height is None else number("--max-height", args.max_height) / units.length
    try:
        return jump_move(robot, robot.tool_pose(q0), robot.tool_pose(q1), rise=rise, max_height=ceiling,
                         payload=move.payload, torque=args.torque, tool_speed=tool_speed, start=q0, end=q1,
                         jerk=move.jerk).duration  # fmt: skip
    except ScaraError:
        return None


def cmd_jog(args: argparse.Namespace) -> int:
    """Jog to the edge: a straight tool move ending at rest on the workspace edge (or before contact: ``--cell``)."""
    from ..motion.jog import jog_to_edge

    units = Units.from_args(args)
    check_command_outputs(args, {"--out": args.out, "--plot": args.plot}, figures=("--plot",))  # before any work
    robot = robot_from_args(args, units)
    if robot.kind != "scara":
        raise InvalidInputError(f"jog is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
    needs_wrist(robot, "jog")
    robot = with_motion_limits(args, robot, units)
    q0 = joint_arg(robot, args.from_q, units, "--from")
    direction = [number(f"direction {i + 1}", t) for i, t in enumerate(args.direction)]
    if len(direction) not in (2, 3):
        raise ParameterError("--direction", " ".join(args.direction), "must be DX DY or DX DY DZ")
    margin = 0.0 if args.margin is None else units.value("--margin", args.margin, "length")
    # --margin is the jog's own (to the edge): the cell keeps its file's margin unless --margin is given
    cell = cell_from_args(argparse.Namespace(cell=args.cell, package_path=args.package_path))
    if cell is not None and args.margin is not None:
        cell = cell.with_margin(margin)
    jog = jog_to_edge(robot, q0, direction, margin=margin, cell=cell)
    traj = jog.trajectory
    if args.out:
        traj.save(args.out, rate=args.rate)
    if args.plot:
        from ..viz.plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot, units=units.display, law="jog to the edge, straight line")
    if args.json:
        print(json.dumps({"robot": robot.name, **jog.to_dict(), "cell": None if cell is None else cell.origin,
                          "units": {"length": "m", "angle": "rad", "time": "s"}}))  # fmt: skip
        return 0
    text = sys.stderr if "-" in (args.out, args.plot) else sys.stdout  # stdout carries a file
    print(f"robot     {robot.name}: jog to the edge along {format_vector(direction, 9)}", file=text)
    if jog.contact is not None:
        print(f"stop      {jog.stopped_by}, the margin of {args.cell}", file=text)
        print(f"edge      beyond: {jog.hit.description} [{jog.hit.limit.value}]", file=text)
    else:
        print(f"edge      {jog.hit.description} [{jog.hit.limit.value}]", file=text)
        if cell is not None:
            print(f"cell      {cell.origin}: no contact before the edge (margin {cell.margin * 1e3:g} mm)", file=text)
    print(f"travel    {units.num(jog.distance, 'length')} {units.length_name} in {format_number(traj.duration, 6)} s "
          "(at rest at both ends)", file=text)  # fmt: skip
    print(f"end pose  {units.fmt(jog.end_pose, POSE_KINDS)}  [{', '.join(units.names(POSE_KINDS))}]", file=text)
    print(f"limits    worst ratio {jog.ratio:.6f} (sampled at 10 kHz)", file=text)
    for what in (args.out, args.plot):
        if what:
            print(f"wrote     {what}", file=text)
    return 0


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("traj", help="trajectory: quintic, time-optimal (TOPP-RA) or straight tool line; export, plot")
    g = p.add_argument_group("endpoints (joint values in URDF order, or tool poses X Y Z YAW; X Y Z without a wrist)")
    g.add_argument("--from", dest="from_q", nargs="+", metavar="Q", help="start configuration")
    g.add_argument("--to", dest="to_q", nargs="+", metavar="Q", help="end configuration")
    g.add_argument("--from-pose", nargs="+", metavar="P", help="start pose (IK: the solution nearest mid-range)")
    g.add_argument("--to-pose", nargs="+", metavar="P", help="end pose (IK: the solution nearest the previous point)")
    g.add_argument("--via", nargs="+", action="append", metavar="Q",
                   help="via configuration (repeatable); with --arch, a hint of the jump's way through the cell")
    g = p.add_argument_group("timing")
    g.add_argument("--duration", type=number_type("--duration"), metavar="T",
                   help="quintic time law over T seconds (checked against the limits)")  # fmt: skip
    g.add_argument("--optimal", action="store_true", help="time-optimal under the joint limits (the default)")
    g.add_argument("--linear", action="store_true", help="straight tool line (S4), one elbow branch, J4 continuous")
    g.add_argument("--tool-speed", type=number_type("--tool-speed"), metavar="V",
                   help="also limit the tool speed [m/s, or mm/s with --mm]")  # fmt: skip
    g.add_argument("--torque", action="store_true", help="also respect the effort limits (RNEA, URDF inertias)")
    g.add_argument("--jerk-limit", nargs="+", metavar="J",
                   help="joint jerk limit, one or 4 (rad/s^3, m/s^3): jerk-limited time-optimal timing")  # fmt: skip
    g.add_argument("--strict", action="store_true", help="refuse (exit 3) a --duration that exceeds a limit")
    g.add_argument("--payload", metavar="KG", help="payload at the tool, for --torque (and --arch) [kg]")
    g.add_argument("--payload-com", nargs=3, metavar="C", help="payload centre of mass X Y Z in the tool frame")
    g = p.add_argument_group("arch (jump) move between --from-pose and --to-pose")
    g.add_argument("--arch", action="store_true",
                   help="jump over a clearance: time-optimal, joint path free (or --path lines)")
    g.add_argument("--path", choices=("jump", "lines"),
                   help="jump (default) or lines: the straight-leg arch, lift, traverse, descend, corners blended "
                   "(slower)")
    g.add_argument("--rise", metavar="H", help="clearance above the higher pose [m, or mm with --mm] "
                   "(default 0.025 m)")  # fmt: skip
    g.add_argument("--clearance-radius", metavar="R",
                   help="jump: within R of an end (horizontally) the tool may be lower (default 0.005 m)")
    g.add_argument("--max-height", metavar="Z", help="a ceiling for the tool's z (base frame)")
    g.add_argument("--blend", metavar="B", help="lines: blend distance at each corner (default: as large as allowed)")
    add_motion_limits(g)
    g = p.add_argument_group("outputs (files in SI units)")
    g.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out and --json (default 1000)")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="samples t, q, qd, qdd as CSV (or JSON for *.json), atomically")
    g.add_argument("--plot", metavar="PNG", help="each joint's q, qd, qdd (and torque with --torque) against "
                   "time with its limits, in the units of --mm/--deg; the tool path and speed (.png, .svg, .pdf)")
    add_setpoint_options(g)
    add_units(p, inputs=True, json_help="print one JSON object (with the samples unless --out)")
    add_robot_options(p)
    add_cell_options(p)
    add_points_options(p, "traj")
    p.set_defaults(func=cmd_traj)
    p = sub.add_parser("jog", help="jog to the edge: straight tool move ending at rest on the workspace edge")
    p.add_argument("--from", dest="from_q", nargs=4, metavar="Q", required=True, help="current configuration")
    p.add_argument("--direction", nargs="+", metavar="D", required=True, help="DX DY (plan) or DX DY DZ")
    p.add_argument("--margin", metavar="M", help="stop this far before the edge [m, or mm with --mm] (default 0); "
                   "with --cell, also the cell's margin (instead of its file's)")
    p.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out (default 1000)")  # fmt: skip
    add_motion_limits(p)
    p.add_argument("--out", metavar="FILE", help="samples as CSV (or JSON for *.json), atomically")
    p.add_argument("--plot", metavar="PNG", help="q, qd, qdd against time and the tool path")
    add_units(p, inputs=True)
    add_robot_options(p)
    add_cell_options(p, margin=False)  # --margin above: the jog's own, and the cell's when given
    p.set_defaults(func=cmd_jog)
