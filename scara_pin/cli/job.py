"""The ``job`` command: a program of moves over taught points and pallets, timed: table, total, parts per hour."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ..errors import ParameterError
from ..files import check_outputs
from ..limits import MAX_SAMPLES, check_count
from ._joints import needs_wrist
from ._numbers import number_type
from ._options import add_motion_limits, add_robot_options
from ._outputs import check_command_outputs
from ._robot import robot_from_args, with_motion_limits
from ._units import Units

_VIEW_RATE = 200.0
"""[Hz] the samples handed to the viewer page (it interpolates between them)."""


def cmd_job(args: argparse.Namespace) -> int:
    """Plan a job file: every move as fast as the limits allow, verified; print the table or JSON; write outputs."""
    from ..job import Job

    outputs = {"--out": args.out, "--plot": args.plot, "--html": args.html}
    check_command_outputs(args, outputs, figures=("--plot",))  # names, stdout, the job file and the robot's
    if not args.rate > 0:  # parsed by the one number grammar: finite, ASCII digits
        raise ParameterError("--rate", args.rate, "must be > 0", "Hz")
    job = Job.load(args.file)
    check_outputs(outputs, {"points": job.points_file, "cell": job.cell})  # the files the job names
    if args.out:  # the dwells alone already take this many samples: refused before the moves are planned
        check_count(f"samples of --out (at least the dwells' {job.dwell:.6g} s at {args.rate:.6g} Hz)",
                    job.dwell * args.rate + 1.0, MAX_SAMPLES, "lower --rate")  # fmt: skip
    if args.robot is None and args.urdf is None and job.robot is not None:
        args.robot = job.robot
    units = Units()  # a job's numbers are SI, and so is --acceleration here
    robot = robot_from_args(args, units)
    needs_wrist(robot, "job")
    robot = with_motion_limits(args, robot, units)
    result = _plan(job, robot)
    written: dict[str, str] = {}
    if args.out:
        result.trajectory.save(args.out, rate=args.rate)
        written["trajectory"] = args.out
    if args.plot:
        from ..viz.job import plot_job

        plot_job(result, args.plot, robot=robot)
        written["plot"] = args.plot
    if args.html:
        _page(result, robot, args.html)
        written["page"] = args.html
    if args.json:
        print(json.dumps({**result.to_dict(), "outputs": written}))
        return 0
    text = sys.stderr if "-" in written.values() else sys.stdout  # stdout carries a file: the table goes aside
    print(result.table(), file=text)
    for kind, where in written.items():
        print(f"wrote     {kind}: {where}", file=text)
    return 0


def _plan(job: Any, robot: Any) -> Any:
    """``job.plan(robot)`` with a progress bar on a terminal (tqdm's own test of stderr)."""
    from tqdm import tqdm

    with tqdm(total=job.actions, desc="job", unit="step", file=sys.stderr, disable=None, leave=False) as bar:
        return job.plan(robot, progress=lambda done, total: bar.update(done - bar.n))


def _page(result: Any, robot: Any, path: str) -> None:
    """``--html``: the viewer page playing the job: the poses it reaches as small frames, the cell, the boxes."""
    from ..viz.job import job_page

    job_page(result, robot, path, rate=_VIEW_RATE)


def register(sub: Any) -> None:
    """Add the ``job`` command to the ``scara-pin`` subparsers."""
    p = sub.add_parser("job", help="a job file (points, pallets, jumps, moves, dwells, speeds): its time, table, "
                       "parts per hour; trajectory, plot, viewer page")  # fmt: skip
    p.add_argument("file", metavar="JOB", help="the job file (.yaml; the format: docs/job.md)")
    g = p.add_argument_group("outputs (files in SI units, written only when the whole job is planned)")
    g.add_argument("--json", action="store_true",
                   help="print one JSON object {total, parts_per_hour, boxes_per_hour, boxes, steps: [{kind, target, "
                   "t_start, t_end, binding, clearance}], ...}")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="the whole trajectory: t, q, qd, qdd as CSV (or JSON for *.json)")
    g.add_argument("--rate", type=number_type("--rate"), default=1000.0, metavar="HZ",
                   help="sampling rate of --out (default 1000)")  # fmt: skip
    g.add_argument("--plot", metavar="PNG", help="the timeline: steps, each joint's velocity and acceleration "
                   "against the limits in force; in a cell, plan and side views of the tool path, the obstacles and "
                   "the boxes placed (.png, .svg, .pdf)")  # fmt: skip
    g.add_argument("--html", metavar="HTML", help="a self-contained viewer page that plays the job (with its cell, "
                   "the part while held and the boxes placed)")  # fmt: skip
    add_motion_limits(p)
    add_robot_options(p)
    p.set_defaults(func=cmd_job)
