"""``check FILE.urdf --cell CELL [--points FILE]``: the cell's findings after the URDF's (scara_pin.cell.report)."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from ..robots import load_robot, load_urdf
from ._numbers import parse_locks, parse_sets
from ._options import add_cell_options
from ._robot import cell_from_args

if TYPE_CHECKING:
    from ..lint import CheckReport


def add_check_cell_options(p: argparse.ArgumentParser) -> None:
    """``--cell FILE``, ``--margin M`` and ``--points FILE`` of ``check``."""
    add_cell_options(p)
    p.add_argument("--points", metavar="FILE", help="with --cell: a points file (of `teach`) whose points are "
                   "checked for collision; its point 'home', if any, is the home (else q = 0)")  # fmt: skip


def report_with_cell(args: argparse.Namespace, report: CheckReport) -> int:
    """Print the URDF's report and, with ``--cell``, the cell's; return the command's exit code.

    The cell is checked on the robot the URDF loads into (the same frames, locks and packages); a URDF that
    cannot be loaded leaves the cell unchecked (its findings say why). Exit code: 2 if the URDF is unusable,
    else 4 if either report has warnings, else 0.
    """
    if getattr(args, "cell", None) is None and getattr(args, "carry", None) is None:
        if getattr(args, "points", None) is not None or getattr(args, "margin", None) is not None:
            raise InvalidInputError("--points and --margin of check go with --cell (or --carry)")
        print(report.to_json() if args.json else report.format_text())
        return int(report.exit_code)
    cell_doc: dict[str, Any]
    source = args.cell if args.cell is not None else args.carry
    if report.exit_code == 2:
        cell_doc = {"source": source, "status": "unchecked", "reason": "the URDF is unusable"}
        text = f"{source}: unchecked (the URDF is unusable)"
        code = 2
    else:
        cell_report = _cell_report(args)
        cell_doc, text = cell_report.to_dict(), cell_report.format_text()
        code = max(int(report.exit_code), cell_report.exit_code)
    if args.json:
        doc = report.to_dict()
        doc["cell"] = cell_doc
        doc["exit_code"] = code
        print(json.dumps(doc, indent=2))
    else:
        print(report.format_text())
        print(text)
    return code


def _cell_report(args: argparse.Namespace) -> Any:
    import numpy as np

    from ..cell import scene
    from ..cell.report import check_cell

    if getattr(args, "robot", None) is not None:
        robot = load_robot(args.robot, parse_sets(args.set), tool=args.tool, base=args.base,
                           lock=parse_locks(args.lock))  # fmt: skip
    else:
        robot = load_urdf(args.file, tool=args.tool, base=args.base, package_path=args.package_path or (),
                          lock=parse_locks(args.lock))  # fmt: skip
    cell = cell_from_args(args)
    taught: list[tuple[str, Any]] = []
    home = ("home (q = 0)", np.zeros(robot.dof))
    if args.points is not None:
        from ..motion.points import read_points

        points = read_points(args.points, robot).resolved(robot, origin=f"points file {args.points}")
        for name in points.names:
            if name == "home":
                home = ("home (point home of the points file)", points.q_of(name))
            else:
                taught.append((name, points.q_of(name)))
    return check_cell(scene(robot, cell), [home, *taught], source=args.cell if args.cell is not None else args.carry)
