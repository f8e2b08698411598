"""The ``teach`` command: the browser as a teach pendant (joint sliders, Cartesian jog with IK) on 127.0.0.1."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ._common import Units, _add_robot_options, _add_units, _load, _q_values


def cmd_teach(args: argparse.Namespace) -> int:
    """Serve the teach pendant page until Ctrl-C."""
    from ..viz.teach import TeachServer

    units = Units.from_args(args)
    robot = _load(args, units)
    q = _q_values(args.q, units) if args.q else None
    server = TeachServer(robot, port=args.port, q=q)
    print(f"teach pendant: {server.url}  (serving on 127.0.0.1 until Ctrl-C)", flush=True)
    if args.open:
        import webbrowser

        webbrowser.open(server.url, new=2)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        print("stopped", file=sys.stderr)
    return 0


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("teach", help="teach pendant in the browser: joint sliders, Cartesian jog with IK (127.0.0.1)")
    p.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default 0: a free one)")
    p.add_argument("--q", nargs=4, metavar="Q", help="start configuration (default: zero)")
    p.add_argument("--open", action="store_true", help="open the page in the web browser")
    _add_units(p, json_help=None)
    _add_robot_options(p)
    p.set_defaults(func=cmd_teach)
