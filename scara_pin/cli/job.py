"""The ``job`` command: a program of moves over taught points and pallets, timed: table, total, parts per hour."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ..errors import InvalidInputError, ParameterError
from ..files import check_outputs, outputs_together
from ..limits import MAX_SAMPLES, check_count
from ._joints import needs_wrist
from ._numbers import number_type
from ._options import add_motion_limits, add_robot_options, add_units
from ._outputs import check_command_outputs
from ._robot import robot_from_args, with_motion_limits
from ._setpoints import add_setpoint_options, check_setpoint_options, write_setpoints
from ._units import Units

_VIEW_RATE = 200.0
"""[Hz] the samples handed to the viewer page (it interpolates between them)."""


def cmd_job(args: argparse.Namespace) -> int:
    """Plan a job file: every move as fast as the limits allow, verified; print the table or JSON; write outputs."""
    from ..job import Job

    outputs = {"--out": args.out, "--plot": args.plot, "--html": args.html, "--setpoints": args.setpoints}
    check_command_outputs(args, outputs, figures=("--plot",))  # names, stdout, the job file and the robot's
    if not args.rate > 0:  # parsed by the one number grammar: finite, ASCII digits
        raise ParameterError("--rate", args.rate, "must be > 0", "Hz")
    check_setpoint_options(args)
    units = Units.from_args(args)
    overrides, args.set = job_overrides(args)
    job = Job.load(args.file, overrides)
    check_outputs(outputs, {"points": job.points_file, "cell": job.cell})  # the files the job names
    if args.out:  # the dwells alone already take this many samples: refused before the moves are planned
        check_count(f"samples of --out (at least the dwells' {job.dwell:.6g} s at {args.rate:.6g} Hz)",
                    job.dwell * args.rate + 1.0, MAX_SAMPLES, "lower --rate")  # fmt: skip
    if args.robot is None and args.urdf is None and job.robot is not None:
        args.robot = job.robot
    robot = robot_from_args(args, units)
    needs_wrist(robot, "job")
    robot = with_motion_limits(args, robot, units)
    result = _plan(job, robot, not args.no_cache)
    written: dict[str, str] = {}
    with outputs_together():  # all of them, or none
        if args.out:
            _write_trajectory(result, robot, args.out, args.rate)
            written["trajectory"] = args.out
        if args.setpoints:
            write_setpoints(args, robot, result.trajectory, units)
            written["setpoints"] = args.setpoints
        if args.plot:
            from ..viz.job import plot_job

            plot_job(result, args.plot, robot=robot, units=units.display)
            written["plot"] = args.plot
        if args.html:  # the viewer page playing the job: the poses it reaches as small frames, the cell, the boxes
            from ..viz.job import job_page

            job_page(result, robot, args.html, rate=_VIEW_RATE, units=units.display)
            written["page"] = args.html
    if args.json:
        print(json.dumps({**result.to_dict(), "outputs": written}))
        return 0
    text = sys.stderr if "-" in written.values() else sys.stdout  # stdout carries a file: the table goes aside
    print(result.table(None if units.display == Units().display else units.display), file=text)
    for kind, where in written.items():
        print(f"wrote     {kind}: {where}", file=text)
    return 0


def job_overrides(args: argparse.Namespace) -> tuple[list[Any], list[str] | None]:
    """(the job's overrides, the robot's ``--set`` items) from ``--set``, ``--speed``, ``--accel``, ``--jerk``.

    A ``--set`` key whose first name is a key of the job file (``frames.tray.xyz``, ``speed``, ``base.yaw``) is
    the job's (:mod:`scara_pin.job.overrides`); another (``l1=0.25``) is the robot's parameter, as for every
    command.
    """
    from ..job.loading import KEYS
    from ..job.overrides import parse_override

    job: list[Any] = []
    robot: list[str] = []
    for item in args.set or ():
        if item.partition("=")[0].strip().split(".")[0] in KEYS:
            job.append(parse_override(item, "--set"))
        else:
            robot.append(item)
    for name in ("speed", "accel"):
        value = getattr(args, name)
        if value is not None:
            job.append(parse_override(f"{name}={value}", f"--{name}"))
    if args.jerk is not None:
        if len(args.jerk) not in (1, 4):
            raise InvalidInputError("--jerk takes one joint jerk limit, or one per joint (4)")
        text = args.jerk[0] if len(args.jerk) == 1 else "[" + ", ".join(args.jerk) + "]"
        job.append(parse_override(f"jerk={text}", "--jerk"))
    keys = [o.key for o in job]
    twice = sorted({k for k in keys if keys.count(k) > 1})
    if twice:
        raise InvalidInputError(f"{twice[0]} is set twice (--set, --speed, --accel, --jerk): which one is meant?")
    return job, robot or None


def _write_trajectory(result: Any, robot: Any, path: str, rate: float) -> None:
    """``--out``: a ROS 2 bag (``.mcap``, ``.db3``), JSON, or CSV whose header carries the units."""
    from ..motion.rosbag import is_bag, write_bag

    if is_bag(path):
        write_bag(path, result.trajectory, robot.joint_names, rate)
    else:
        result.trajectory.save(path, rate=rate, kinds=robot.joint_kinds)


def _plan(job: Any, robot: Any, cache: bool) -> Any:
    """``job.plan(robot)``, with a progress bar on a terminal (tqdm imported only there: a cached job is quick)."""
    if not sys.stderr.isatty():
        return job.plan(robot, cache=cache)
    from tqdm import tqdm

    with tqdm(total=job.actions, desc="job", unit="step", file=sys.stderr, leave=False) as bar:
        return job.plan(robot, progress=lambda done, total: bar.update(done - bar.n), cache=cache)


def register(sub: Any) -> None:
    """Add the ``job`` command to the ``scara-pin`` subparsers."""
    p = sub.add_parser("job", help="a job file (points, pallets, jumps, moves, dwells, speeds): its time, table, "
                       "parts per hour; trajectory, plot, viewer page")  # fmt: skip
    p.add_argument("file", metavar="JOB", help="the job file (.yaml; the format: docs/job.md)")
    g = p.add_argument_group("variants (the job file's keys and units: docs/job.md, overrides)")
    g.add_argument("--speed", metavar="P",
                   help="every move's velocity limits times P %% too (the job's speed: --set speed=P)")  # fmt: skip
    g.add_argument("--accel", metavar="P",
                   help="every move's acceleration limits times P %% too (--set accel=P)")  # fmt: skip
    g.add_argument("--jerk", nargs="+", metavar="J", help="joint jerk limits, one or one per joint, in the job "
                   "file's units (rad/s^3, m/s^3 by default): every move jerk-limited (--set jerk=J)")  # fmt: skip
    g.add_argument("--no-cache", action="store_true", help="plan every move again: neither read nor write the plan "
                   "cache (SCARA_PIN_NO_CACHE=1 turns it off too)")  # fmt: skip
    g = p.add_argument_group("outputs (files in SI units, written only when the whole job is planned)")
    g.add_argument("--json", action="store_true",
                   help="print one JSON object {total, parts_per_hour, steady_state, cell_cost, boxes, steps: [{kind, "
                   "target, t_start, t_end, binding, clearance, free}], ...}")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="the whole trajectory: t, q, qd, qdd as CSV (units in its header), "
                   "JSON for *.json, or a ROS 2 bag for *.mcap / *.db3 (JointTrajectory, JointState at --rate)")
    g.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out (default 1000)")  # fmt: skip
    g.add_argument("--plot", metavar="PNG", help="the timeline: steps, each joint's velocity and acceleration "
                   "against the limits in force; in a cell, plan and side views of the tool path, the obstacles and "
                   "the boxes placed, in the units of --mm (.png, .svg, .pdf)")  # fmt: skip
    g.add_argument("--html", metavar="HTML", help="a self-contained viewer page that plays the job (with its cell, "
                   "the part while held and the boxes placed)")  # fmt: skip
    add_setpoint_options(g)
    add_units(p, json_help=None)
    add_motion_limits(p)
    add_robot_options(p, set_help="override a value: a key of the job file, in its grammar and units "
                      "(frames.tray.xyz=[0.3, 0, -0.1], base.yaw=0.1, robot=s1), or a robot parameter, SI (l1=0.25); "
                      "repeatable")  # fmt: skip
    p.set_defaults(func=cmd_job)
