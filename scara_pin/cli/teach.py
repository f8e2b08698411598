"""The ``teach`` command: the browser as a teach pendant (joint and Cartesian jogs, taught points) on 127.0.0.1."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..signals import Terminated, handled
from ._joints import q_values
from ._numbers import integer_type
from ._options import add_cell_options, add_robot_options, add_units
from ._robot import cell_from_args, robot_from_args
from ._units import Units


def cmd_teach(args: argparse.Namespace) -> int:
    """Serve the teach pendant page until Ctrl-C."""
    from ..viz.teach import TeachServer

    units = Units.from_args(args)
    robot = robot_from_args(args, units)
    q = q_values(args.q, units) if args.q else None
    cell = cell_from_args(args, units)
    server = TeachServer(robot, port=args.port, q=q, points_file=args.points, controls=args.controls, cell=cell)
    try:  # from the line that says so on, Ctrl-C stops the server
        print(f"teach pendant: {server.url}  (serving on 127.0.0.1 until Ctrl-C)", flush=True)
        if cell is not None:
            print(f"cell          {cell.origin}: {len(cell.obstacles)} obstacle(s)"
                  f"{'' if cell.carried is None else ', a carried part'}, margin {units.num(cell.margin, 'length')} "
                  f"{units.length_name}: jogs stop at the margin", flush=True)  # fmt: skip
        if args.open:
            import webbrowser

            webbrowser.open(server.url, new=2)
        server.serve_forever()
    except Terminated:  # SIGTERM: exit 143, as README says
        raise
    except KeyboardInterrupt:  # Ctrl-C is how a server is stopped: exit 0
        handled()
        print("stopped", file=sys.stderr)
    return 0


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("teach", help="teach pendant in the browser: joint and Cartesian jogs, points (127.0.0.1)")
    p.add_argument("--port", type=integer_type("--port", 0, 65535), default=0,
                   help="port on 127.0.0.1 (default 0: a free one)")
    p.add_argument("--q", nargs=4, metavar="Q", help="start configuration (default: zero)")
    p.add_argument("--open", action="store_true", help="open the page in the web browser")
    p.add_argument("--points", metavar="FILE", help="points file (.yaml or .csv) the page saves; read if it exists")
    p.add_argument("--controls", action="store_true", help="show meshcat's own control panel (hidden by default)")
    add_units(p, json_help=None)
    add_robot_options(p)
    add_cell_options(p)
    p.set_defaults(func=cmd_teach)
