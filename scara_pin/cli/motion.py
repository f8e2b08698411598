"""Commands of the motion layer: ``traj``, ``jog``."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..files import check_output_path
from ._common import (
    _POSE_KINDS,
    Units,
    _acceleration,
    _add_acceleration,
    _add_robot_options,
    _add_units,
    _fmt,
    _joint_arg,
    _load,
    _needs_wrist,
    _num,
    _number,
    _read_pose,
    log,
    number_type,
    write_atomic,
)
from .cycle import _payload

if TYPE_CHECKING:

    pass


def _check_outputs(args: argparse.Namespace, outputs: tuple[str | None, ...]) -> None:
    """Refuse bad output names before any work: devices, folders, and two outputs on stdout."""
    named = [out for out in outputs if out]
    for out in named:
        check_output_path(out)
    if named.count("-") + bool(args.json) > 1:
        raise InvalidInputError("only one output can go to standard output (-), and --json prints there too")


def cmd_traj(args: argparse.Namespace) -> int:
    """A trajectory between configurations or poses: quintic, time-optimal, or a straight tool line."""
    import numpy as np

    from ..motion import trajectory as tr
    from ..motion.cycle import STANDARD_RISE
    from ..motion.plan import MotionRequest, plan_motion

    logging.getLogger("toppra").setLevel(logging.WARNING)
    units = Units.from_args(args)
    _check_outputs(args, (args.out, args.setpoints, args.plot))
    robot = _load(args, units)
    for flag in ("linear", "arch", "plot", "payload"):
        if getattr(args, flag, None):
            _needs_wrist(robot, f"traj --{flag}")  # 3-joint arms: joint-space trajectories (quintic, TOPP-RA)
    _acceleration(robot, args.acceleration, units)
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
    vias = [_joint_arg(robot, v, units, f"--via #{i + 1}") for i, v in enumerate(args.via or [])]
    pose_from = _read_pose(args.from_pose, units, "--from-pose", robot.dof) if args.from_pose else None
    pose_to = _read_pose(args.to_pose, units, "--to-pose", robot.dof) if args.to_pose else None
    q_from = _joint_arg(robot, args.from_q, units, "--from") if args.from_q else None
    tool_speed = None
    if args.tool_speed is not None:
        if not args.tool_speed > 0:
            raise ParameterError("--tool-speed", args.tool_speed, "must be > 0")
        units.guard(("--tool-speed",), (f"{args.tool_speed:g}",), ("length",))
        tool_speed = args.tool_speed / units.length
    if args.arch and not args.linear and robot.kind == "scara":
        if args.via:
            raise InvalidInputError("--arch takes no --via (one arch between two poses)")
        if args.duration is not None:
            raise InvalidInputError("--arch is time-optimal: --duration does not apply")
    request = MotionRequest(
        start_q=q_from, end_q=_joint_arg(robot, args.to_q, units, "--to") if args.to_q else None,
        start_pose=None if pose_from is None else np.array(pose_from),
        end_pose=None if pose_to is None else np.array(pose_to), vias=tuple(vias), duration=args.duration,
        linear=args.linear, arch=args.arch, tool_speed=tool_speed, torque=args.torque, payload=_payload(args, units),
        rise=None if not args.arch else STANDARD_RISE if args.rise is None else units.value("--rise", args.rise,
                                                                                            "length"),
        blend=None if args.blend is None or not args.arch else units.value("--blend", args.blend, "length"),
    )
    plan = plan_motion(robot, request)
    if plan.arch is not None:
        return _print_arch(args, plan.robot, plan.arch, units, tool_speed)
    robot, traj, method = plan.robot, plan.trajectory, plan.method.value
    from ..motion.timing import limit_ratios

    ratios = limit_ratios(robot, traj, rate=1000.0, tool_speed=tool_speed, torque=args.torque)
    if not ratios.worst <= 1 + 1e-6:  # NaN (an unknown limit) fails too
        message = (f"the trajectory exceeds a limit: worst ratio {ratios.worst:.6g} (velocity "
                   f"{ratios.velocity:.6g}, acceleration {ratios.acceleration:.6g}); a longer --duration, or "
                   "--optimal, respects them")  # fmt: skip
        if args.strict:
            raise InfeasibleError(message)
        log.warning(message)
    outputs: dict[str, str] = {}
    if args.out:
        traj.save(args.out, rate=args.rate)
        outputs["trajectory"] = str(args.out)
    if args.setpoints:
        motor = None
        if args.gear or args.steps_per_rev or args.screw_lead is not None:
            if not (args.gear and args.steps_per_rev and args.screw_lead is not None):
                raise InvalidInputError("motor steps need --gear G1..G4, --steps-per-rev S1..S4 and --screw-lead L")
            motor = tr.MotorUnits.from_drive(
                [_number("--gear", g) for g in args.gear],
                [_number("--steps-per-rev", v) for v in args.steps_per_rev],
                units.value("--screw-lead", args.screw_lead, "length"),
                prismatic=robot.joint_kinds.index("length"),
            )
        delays = [_number("--delays", d) for d in args.delays] if args.delays else None
        rate = args.setpoint_rate if args.setpoint_rate is not None else args.rate
        sp = traj.setpoints(rate, delays=delays, motor=motor)
        write_atomic(Path(args.setpoints), sp.csv_text())
        outputs["setpoints"] = args.setpoints
    if args.plot:
        from ..viz.plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot, units=units.display, law=method, torque=args.torque,
                        tool_speed=tool_speed)  # fmt: skip
        outputs["plot"] = args.plot
    summary = {
        "robot": robot.name,
        "method": method,
        "duration": traj.duration,
        "q_from": traj.q_start.tolist(),
        "q_to": traj.q_end.tolist(),
        "limit_ratios": {"velocity": ratios.velocity, "acceleration": ratios.acceleration,
                         "tool_speed": ratios.tool_speed, "torque": ratios.torque},  # fmt: skip
        "outputs": outputs,
        "units": {"length": "m", "angle": "rad", "time": "s"},
    }
    if args.json:
        if not args.out:
            summary["samples"] = traj.resample(args.rate).to_dict()
        print(json.dumps(summary))
        return 0
    text = sys.stderr if "-" in outputs.values() else sys.stdout  # stdout carries a file: the summary goes aside
    print(f"robot     {robot.name}: {method}", file=text)
    q_units = ", ".join(units.names(units.q))
    print(f"duration  {_num(traj.duration)} s", file=text)
    print(f"from      {units.fmt(traj.q_start, units.q)}  [{q_units}]", file=text)
    print(f"to        {units.fmt(traj.q_end, units.q)}  [{q_units}]", file=text)
    print(f"limits    worst |v|/vmax {ratios.velocity:.6f}, |a|/amax {ratios.acceleration:.6f} "
          "(exact for joint-line laws, else sampled)", file=text)  # fmt: skip
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}", file=text)
    return 0


def _print_arch(args: argparse.Namespace, robot: Any, move: Any, units: Units, tool_speed: float | None) -> int:
    """``traj --arch``: write and print the arch (jump) move (lift, traverse, descend, blended corners)."""
    from ..motion.plan import Method

    traj = move.trajectory
    outputs: dict[str, str] = {}
    if args.out:
        traj.save(args.out, rate=args.rate)
        outputs["trajectory"] = str(args.out)
    if args.plot:  # the robot carries the payload: the torques are the loaded arm's
        from ..viz.plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot, units=units.display, law=Method.ARCH.value, torque=args.torque,
                        tool_speed=tool_speed)  # fmt: skip
        outputs["plot"] = args.plot
    if args.json:
        summary = {"robot": robot.name, "method": Method.ARCH.value,
                   "duration": traj.duration, "q_from": traj.q_start.tolist(), "q_to": traj.q_end.tolist(),
                   "legs": [leg.to_dict() for leg in move.legs], "limit_ratios": move.ratios,
                   "payload": move.payload.to_dict(), "outputs": outputs,
                   "units": {"length": "m", "angle": "rad", "time": "s"}}  # fmt: skip
        if not args.out:
            summary["samples"] = traj.resample(args.rate).to_dict()
        print(json.dumps(summary))
        return 0
    print(f"robot     {robot.name}: {Method.ARCH.value}")
    print(f"duration  {_num(traj.duration)} s")
    for leg in move.legs:
        print(f"  {leg.name:<11} {leg.duration:9.6f} s   {leg.active} of {leg.joint} at {leg.ratio:.4f} of its limit")
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}")
    return 0


def cmd_jog(args: argparse.Namespace) -> int:
    """Jog to the edge: a straight tool move along a direction, ending at rest on the workspace edge."""
    from ..motion.jog import jog_to_edge

    units = Units.from_args(args)
    _check_outputs(args, (args.out, args.plot))
    robot = _load(args, units)
    if robot.kind != "scara":
        raise InvalidInputError(f"jog is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
    _needs_wrist(robot, "jog")
    _acceleration(robot, args.acceleration, units)
    q0 = _joint_arg(robot, args.from_q, units, "--from")
    direction = [_number(f"direction {i + 1}", t) for i, t in enumerate(args.direction)]
    if len(direction) not in (2, 3):
        raise ParameterError("--direction", " ".join(args.direction), "must be DX DY or DX DY DZ")
    margin = 0.0 if args.margin is None else units.value("--margin", args.margin, "length")
    jog = jog_to_edge(robot, q0, direction, margin=margin)
    traj = jog.trajectory
    if args.out:
        traj.save(args.out, rate=args.rate)
    if args.plot:
        from ..viz.plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot, units=units.display, law="jog to the edge, straight line")
    if args.json:
        print(json.dumps({"robot": robot.name, "hit": jog.hit.to_dict(), "start_pose": jog.start_pose.tolist(),
                          "end_pose": jog.end_pose.tolist(), "distance": jog.distance, "duration": traj.duration,
                          "q_end": traj.q_end.tolist(), "limit_ratio": jog.ratio,
                          "units": {"length": "m", "angle": "rad", "time": "s"}}))  # fmt: skip
        return 0
    text = sys.stderr if "-" in (args.out, args.plot) else sys.stdout  # stdout carries a file
    print(f"robot     {robot.name}: jog to the edge along {_fmt(direction)}", file=text)
    print(f"edge      {jog.hit.description} [{jog.hit.limit.value}]", file=text)
    print(f"travel    {units.num(jog.distance, 'length')} {units.length_name} in {_num(traj.duration, 6)} s (at rest "
          "at both ends)", file=text)  # fmt: skip
    print(f"end pose  {units.fmt(jog.end_pose, _POSE_KINDS)}  [{', '.join(units.names(_POSE_KINDS))}]", file=text)
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
    g.add_argument("--via", nargs="+", action="append", metavar="Q", help="via configuration (repeatable)")
    g = p.add_argument_group("timing")
    g.add_argument("--duration", type=number_type("--duration"), metavar="T",
                   help="quintic time law over T seconds (checked against the limits)")  # fmt: skip
    g.add_argument("--optimal", action="store_true", help="time-optimal under the joint limits (the default)")
    g.add_argument("--linear", action="store_true", help="straight tool line (S4), one elbow branch, J4 continuous")
    g.add_argument("--tool-speed", type=number_type("--tool-speed"), metavar="V",
                   help="also limit the tool speed [m/s, or mm/s with --mm]")  # fmt: skip
    g.add_argument("--torque", action="store_true", help="also respect the effort limits (RNEA, URDF inertias)")
    g.add_argument("--strict", action="store_true", help="refuse (exit 3) a --duration that exceeds a limit")
    g.add_argument("--payload", metavar="KG", help="payload at the tool, for --torque (and --arch) [kg]")
    g.add_argument("--payload-com", nargs=3, metavar="C", help="payload centre of mass X Y Z in the tool frame")
    g = p.add_argument_group("arch (jump) move between --from-pose and --to-pose")
    g.add_argument("--arch", action="store_true", help="lift, traverse, descend, corners blended (time-optimal)")
    g.add_argument("--rise", metavar="H", help="traverse height above the higher pose [m, or mm with --mm] "
                   "(default 0.025 m)")  # fmt: skip
    g.add_argument("--blend", metavar="B", help="blend distance at each corner (default: as large as allowed)")
    _add_acceleration(g)
    g = p.add_argument_group("outputs (files in SI units)")
    g.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out and --json (default 1000)")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="samples t, q, qd, qdd as CSV (or JSON for *.json), atomically")
    g.add_argument("--plot", metavar="PNG", help="each joint's q, qd, qdd (and torque with --torque) against "
                   "time with its limits, in the units of --mm/--deg; the tool path and speed (.png, .svg, .pdf)")
    g.add_argument("--setpoints", metavar="CSV", help="controller setpoints (S4) at --setpoint-rate")
    g.add_argument("--setpoint-rate", type=number_type("--setpoint-rate"), metavar="HZ",
                   help="setpoint rate (default: --rate)")  # fmt: skip
    g.add_argument("--delays", nargs="+", metavar="S", help="per-axis command latency [s], compensated")
    g.add_argument("--gear", nargs=4, metavar="G", help="gear ratios (motor turns per joint/screw turn)")
    g.add_argument("--steps-per-rev", nargs=4, metavar="N", help="motor steps per motor turn")
    g.add_argument("--screw-lead", metavar="L", help="quill screw travel per turn [m, or mm with --mm]")
    _add_units(p, inputs=True, json_help="print one JSON object (with the samples unless --out)")
    _add_robot_options(p)
    p.set_defaults(func=cmd_traj)
    p = sub.add_parser("jog", help="jog to the edge: straight tool move ending at rest on the workspace edge")
    p.add_argument("--from", dest="from_q", nargs=4, metavar="Q", required=True, help="current configuration")
    p.add_argument("--direction", nargs="+", metavar="D", required=True, help="DX DY (plan) or DX DY DZ")
    p.add_argument("--margin", metavar="M", help="stop this far before the edge [m, or mm with --mm] (default 0)")
    p.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out (default 1000)")  # fmt: skip
    _add_acceleration(p)
    p.add_argument("--out", metavar="FILE", help="samples as CSV (or JSON for *.json), atomically")
    p.add_argument("--plot", metavar="PNG", help="q, qd, qdd against time and the tool path")
    _add_units(p, inputs=True)
    _add_robot_options(p)
    p.set_defaults(func=cmd_jog)
