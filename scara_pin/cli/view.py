"""The ``view`` command (meshcat in the browser, or an offline HTML page)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..errors import InvalidInputError
from ..signals import Terminated, handled
from ._joints import check_limits, q_values
from ._options import add_cell_options, add_robot_options, add_units
from ._outputs import check_command_outputs
from ._robot import cell_from_args, robot_from_args
from ._units import Units


def cmd_view(args: argparse.Namespace) -> int:
    """Show the robot in the browser (meshcat): a configuration, a trajectory, the workspace boundary."""
    from ..viz import meshcat as viz

    units = Units.from_args(args)
    check_command_outputs(args, {"--html": args.html})  # before any work: not --traj, --urdf, ...
    robot = robot_from_args(args, units)
    cell = cell_from_args(args, units)
    q = None
    if args.q:
        q = check_limits(robot, q_values(args.q, units), units, warning="%s (shown anyway)")
    times = qs = None
    if args.traj and args.traj.lower().endswith(".json"):  # as `traj --out` writes it
        from ..motion.trajectory import load_samples

        samples = load_samples(args.traj)
        if samples.q.shape[1] != robot.dof:
            raise InvalidInputError(f"{args.traj}: a trajectory of {samples.q.shape[1]} joints; robot {robot.name!r} "
                                    f"has {robot.dof}")  # fmt: skip
        times, qs = samples.t, samples.q
    elif args.traj:
        times, qs = viz.read_trajectory_csv(args.traj, robot.dof)
    polylines = None
    if args.workspace:  # a palletizer: the arm-plane envelope at the waist limits, and its sweep
        from ..viz.inline import workspace_polylines

        polylines = workspace_polylines(robot)
    targets, names = None, None
    if args.points:  # taught points: small frames at their poses, named on the page
        from ..viz.inline import point_poses

        targets, names = point_poses(robot, args.points)
    if args.html:
        viz.export_html(robot, args.html, q=q, times=times, qs=qs, polylines=polylines, targets=targets,
                        title=f"scara-pin: {robot.name}", cell=cell, target_names=names)  # fmt: skip
        print(f"wrote {args.html} (self-contained; open it from disk, no network needed)")
        return 0
    with viz.Viewer(robot, open=args.open) as viewer:
        if polylines is not None:
            viewer.draw_polylines(polylines)
        if cell is not None:
            viewer.draw_cell(cell)
        if targets is not None:
            viewer.draw_targets(targets)
        if times is not None and qs is not None:
            viewer.draw_tool_path(qs)
            viewer.animate(times, qs, loop=True)
        else:
            viewer.display(q if q is not None else robot.default_q)
        try:  # from the line that says so on, Ctrl-C stops the server
            print(f"meshcat viewer: {viewer.url}  (serving on 127.0.0.1 until Ctrl-C)", flush=True)
            viewer.serve()
        except Terminated:  # SIGTERM: exit 143, as README says
            raise
        except KeyboardInterrupt:  # Ctrl-C is how a server is stopped: exit 0
            handled()
            print("stopped", file=sys.stderr)
    return 0


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("view", help="show the robot in the browser (meshcat); --html writes a standalone page")
    p.add_argument("--q", nargs="+", metavar="Q", help="configuration to show, one value per joint (default: zero)")
    p.add_argument("--traj", metavar="FILE",
                   help="animate a trajectory (a `traj --out` CSV, or its JSON: *.json) and draw the tool path")
    p.add_argument("--workspace", action="store_true",
                   help="draw the workspace boundary (SCARA: on the floor; palletizer: its envelope in 3-D)")
    p.add_argument("--html", metavar="FILE", help="write one self-contained HTML page (works offline) and exit")
    p.add_argument("--points", metavar="FILE", help="a points file (of `teach`): each point drawn at its pose as a "
                   "small frame, named on the --html page")  # fmt: skip
    p.add_argument("--open", action="store_true", help="open the page in the web browser")
    add_units(p, json_help=None)
    add_robot_options(p)
    add_cell_options(p, margin=False)
    p.set_defaults(func=cmd_view)
