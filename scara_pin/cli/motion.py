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
    Units,
    _acceleration,
    _add_acceleration,
    _add_robot_options,
    _add_units,
    _fmt,
    _joint_arg,
    _load,
    _needs_wrist,
    _number,
    _pose_to_q,
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

    logging.getLogger("toppra").setLevel(logging.WARNING)
    units = Units(args.deg, args.mm)
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
    mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2
    pose_from = _read_pose(args.from_pose, units, "--from-pose", robot.dof) if args.from_pose else None
    pose_to = _read_pose(args.to_pose, units, "--to-pose", robot.dof) if args.to_pose else None
    q_from = _joint_arg(robot, args.from_q, units, "--from") if args.from_q else None
    q_to = _joint_arg(robot, args.to_q, units, "--to") if args.to_q else None
    tool_speed = None
    if args.tool_speed is not None:
        if not args.tool_speed > 0:
            raise ParameterError("--tool-speed", args.tool_speed, "must be > 0")
        tool_speed = args.tool_speed / units.length
    if args.linear and robot.kind != "scara":
        raise InvalidInputError(f"traj --linear is SCARA-only for now; robot {robot.name!r} is a {robot.kind} "
                                "(joint-space --duration and TOPP-RA timing work)")  # fmt: skip
    if args.arch and not args.linear and robot.kind == "scara":
        return _traj_arch(args, robot, units, pose_from, pose_to, q_from)
    if args.arch:
        raise InvalidInputError("--arch is a SCARA move on its own (not with --linear)" if args.linear
                                else f"traj --arch is SCARA-only; robot {robot.name!r} is a {robot.kind}")
    payload = _payload(args, units)
    if payload.mass and not args.torque:
        raise InvalidInputError("--payload changes only the torques: give --torque too")
    if payload.mass:
        from ..motion.payload import with_payload

        robot = with_payload(robot, payload)
    if args.plot and robot.kind != "scara":
        raise InvalidInputError(f"traj --plot is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
    if args.linear:
        first = pose_from if q_from is None else tr.joint_pose(robot, q_from)
        assert first is not None  # --from or --from-pose, checked above
        poses = [first]
        poses += [tr.joint_pose(robot, v) for v in vias]
        last = pose_to if q_to is None else tr.joint_pose(robot, q_to)
        assert last is not None  # --to or --to-pose, checked above
        poses.append(last)
        path = tr.cartesian_path(robot, poses, start=q_from, end=q_to)
        if args.duration is not None:
            traj, method = tr.timed(path, args.duration), "straight line, quintic time law"
        else:
            from ..motion.timing import time_optimal

            traj = time_optimal(robot, path, tool_speed=tool_speed, torque=args.torque)
            method = "straight line, time-optimal (TOPP-RA)"
    else:
        if q_from is None:
            q_from = _pose_to_q(robot, pose_from, mid, "--from-pose")  # type: ignore[arg-type]
        if q_to is None:
            q_to = _pose_to_q(robot, pose_to, vias[-1] if vias else q_from, "--to-pose")  # type: ignore[arg-type]
        waypoints = [q_from, *vias, q_to]
        lim = robot.limits
        if args.duration is not None:
            if vias:
                traj, method = tr.timed(tr.joint_path(robot, waypoints), args.duration), "joint spline, quintic law"
            else:
                traj, method = tr.quintic(q_from, q_to, args.duration), "joint quintic (jtraj)"
        elif not vias and tool_speed is None and not args.torque:
            traj, method = tr.trapezoidal(q_from, q_to, lim.velocity, lim.acceleration), "joint line, time-optimal"
        else:
            from ..motion.timing import time_optimal

            traj = time_optimal(robot, waypoints, tool_speed=tool_speed, torque=args.torque)
            method = "joint path, time-optimal (TOPP-RA)"
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
        out = Path(args.out)
        (traj.to_json if out.suffix.lower() == ".json" else traj.to_csv)(out, rate=args.rate)
        outputs["trajectory"] = str(out)
    if args.setpoints:
        motor = None
        if args.gear or args.steps_per_rev or args.screw_lead is not None:
            if not (args.gear and args.steps_per_rev and args.screw_lead is not None):
                raise InvalidInputError("motor steps need --gear G1..G4, --steps-per-rev S1..S4 and --screw-lead L")
            motor = tr.MotorUnits.from_drive(
                [_number("--gear", g) for g in args.gear],
                [_number("--steps-per-rev", v) for v in args.steps_per_rev],
                _number("--screw-lead", args.screw_lead) / units.length,
                prismatic=robot.joint_kinds.index("length"),
            )
        delays = [_number("--delays", d) for d in args.delays] if args.delays else None
        rate = args.setpoint_rate if args.setpoint_rate is not None else args.rate
        sp = traj.setpoints(rate, delays=delays, motor=motor)
        write_atomic(Path(args.setpoints), sp.csv_text())
        outputs["setpoints"] = args.setpoints
    if args.plot:
        from ..viz.plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot)
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
    print(f"duration  {traj.duration:.9g} s", file=text)
    print(f"from      {_fmt(traj.q_start)}  [SI]", file=text)
    print(f"to        {_fmt(traj.q_end)}  [SI]", file=text)
    print(f"limits    worst |v|/vmax {ratios.velocity:.6f}, |a|/amax {ratios.acceleration:.6f} "
          "(exact for joint-line laws, else sampled)", file=text)  # fmt: skip
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}", file=text)
    return 0


def _traj_arch(args: argparse.Namespace, robot: Any, units: Units, pose_from: Any, pose_to: Any, q_from: Any) -> int:
    """``traj --arch``: the arch (jump) move between two poses (lift, traverse, descend, blended corners)."""
    import numpy as np

    from ..motion import trajectory as tr
    from ..motion.cycle import arch_move

    if args.via:
        raise InvalidInputError("--arch takes no --via (one arch between two poses)")
    if args.duration is not None:
        raise InvalidInputError("--arch is time-optimal: --duration does not apply")
    first = pose_from if q_from is None else tr.joint_pose(robot, q_from)
    last = pose_to if args.to_q is None else tr.joint_pose(robot, _joint_arg(robot, args.to_q, units, "--to"))
    rise = _number("--rise", args.rise) / units.length
    blend = None if args.blend is None else _number("--blend", args.blend) / units.length
    move = arch_move(robot, np.array([first, last], dtype=float), rise=rise, blend=blend, payload=_payload(args, units),
                     torque=args.torque, start=q_from)  # fmt: skip
    traj = move.trajectory
    outputs: dict[str, str] = {}
    if args.out:
        out = Path(args.out)
        (traj.to_json if out.suffix.lower() == ".json" else traj.to_csv)(out, rate=args.rate)
        outputs["trajectory"] = str(out)
    if args.plot:
        from ..viz.cycle import plot_cycle

        plot_cycle(robot, move, args.plot, title=f"{robot.name}: arch move {traj.duration:.4g} s")
        outputs["plot"] = args.plot
    if args.json:
        summary = {"robot": robot.name, "method": "arch (jump) move, time-optimal (TOPP-RA)",
                   "duration": traj.duration, "q_from": traj.q_start.tolist(), "q_to": traj.q_end.tolist(),
                   "legs": [leg.to_dict() for leg in move.legs], "limit_ratios": move.ratios,
                   "payload": move.payload.to_dict(), "outputs": outputs,
                   "units": {"length": "m", "angle": "rad", "time": "s"}}  # fmt: skip
        if not args.out:
            summary["samples"] = traj.resample(args.rate).to_dict()
        print(json.dumps(summary))
        return 0
    print(f"robot     {robot.name}: arch (jump) move, time-optimal (TOPP-RA)")
    print(f"duration  {traj.duration:.9g} s")
    for leg in move.legs:
        print(f"  {leg.name:<11} {leg.duration:9.6f} s   {leg.active} of {leg.joint} at {leg.ratio:.4f} of its limit")
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}")
    return 0


def cmd_jog(args: argparse.Namespace) -> int:
    """Jog to the edge: a straight tool move along a direction, ending at rest on the workspace edge."""
    from ..motion.jog import jog_to_edge

    units = Units(args.deg, args.mm)
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
    margin = _number("--margin", args.margin) / units.length
    jog = jog_to_edge(robot, q0, direction, margin=margin)
    traj = jog.trajectory
    if args.out:
        out = Path(args.out)
        (traj.to_json if out.suffix.lower() == ".json" else traj.to_csv)(out, rate=args.rate)
    if args.plot:
        from ..viz.plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot)
    if args.json:
        print(json.dumps({"robot": robot.name, "hit": jog.hit.to_dict(), "start_pose": jog.start_pose.tolist(),
                          "end_pose": jog.end_pose.tolist(), "distance": jog.distance, "duration": traj.duration,
                          "q_end": traj.q_end.tolist(), "limit_ratio": jog.ratio,
                          "units": {"length": "m", "angle": "rad", "time": "s"}}))  # fmt: skip
        return 0
    L = units.length
    text = sys.stderr if "-" in (args.out, args.plot) else sys.stdout  # stdout carries a file
    print(f"robot     {robot.name}: jog to the edge along {_fmt(direction)}", file=text)
    print(f"edge      {jog.hit.description} [{jog.hit.limit.value}]", file=text)
    print(f"travel    {jog.distance * L:.9g} {units.length_name} in {traj.duration:.6g} s (at rest at both ends)",
          file=text)  # fmt: skip
    print(f"end pose  {_fmt([*(v * L for v in jog.end_pose[:3]), jog.end_pose[3]])}  [{units.length_name}, rad]",
          file=text)  # fmt: skip
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
    g.add_argument("--rise", default="0.025", metavar="H", help="traverse height above the higher pose (0.025 m)")
    g.add_argument("--blend", metavar="B", help="blend distance at each corner (default: as large as allowed)")
    _add_acceleration(g)
    g = p.add_argument_group("outputs (files in SI units)")
    g.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out and --json (default 1000)")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="samples t, q, qd, qdd as CSV (or JSON for *.json), atomically")
    g.add_argument("--plot", metavar="PNG", help="q, qd, qdd against time with limits, and the tool path")
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
    p.add_argument("--margin", default="0", metavar="M", help="stop this far before the edge [m or mm] (default 0)")
    p.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out (default 1000)")  # fmt: skip
    _add_acceleration(p)
    p.add_argument("--out", metavar="FILE", help="samples as CSV (or JSON for *.json), atomically")
    p.add_argument("--plot", metavar="PNG", help="q, qd, qdd against time and the tool path")
    _add_units(p, inputs=True)
    _add_robot_options(p)
    p.set_defaults(func=cmd_jog)
