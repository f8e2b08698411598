"""Commands about the description: ``robots``, ``urdf``, ``check``."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ..description import available_robots, generate_urdf, urdf_dir
from ..errors import InvalidInputError
from ..files import write_text_atomic
from ..robots import load_robot
from ._numbers import parse_locks, parse_sets
from ._options import add_frame_options, add_robot_options
from ._outputs import check_command_outputs

PAYLOAD_GRID = 7
"""Values per joint of the grid the static payload is the minimum over (7^4 = 2401 configurations)."""


def robot_facts(name: str) -> dict[str, Any]:
    """A shipped robot's kind, reach, stroke and payload [SI], as ``scara-pin robots`` lists them.

    reach: the smallest and largest horizontal distance of the wrist axis (SCARA) or the arm's end
    (palletizer) from the J1 axis [m]; stroke: the tool's vertical travel [m]; payload: the largest point
    mass at the tool that the effort limits hold at rest (:func:`~scara_pin.motion.verify.static_payload`,
    over a grid of the joint ranges; exact for a SCARA, whose only loaded joint is the vertical quill) [kg].
    """
    import numpy as np

    from ..motion.verify import static_payload
    from ..workspace import Workspace, workspace_of

    robot = load_robot(name)
    ws = workspace_of(robot)
    reach = (ws.r_min, ws.r_max) if isinstance(ws, Workspace) else tuple(ws.r_range)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    axes = [np.linspace(a, b, PAYLOAD_GRID) for a, b in zip(lo, hi)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, robot.dof)
    return {"name": name, "kind": robot.kind, "reach": [float(reach[0]), float(reach[1])],
            "stroke": float(ws.z_range[1] - ws.z_range[0]), "payload": static_payload(robot, grid)}  # fmt: skip


def cmd_robots(args: argparse.Namespace) -> int:
    """List the shipped robot configurations: kind, reach, stroke and the payload their effort limits hold."""
    facts = [robot_facts(name) for name in available_robots()]
    if args.json:
        units = {"length": "m", "mass": "kg"}
        names, folder = [f["name"] for f in facts], str(urdf_dir() / "config")
        print(json.dumps({"robots": names, "facts": facts, "config_dir": folder, "units": units}))
        return 0
    print(f"{'robot':<12} {'kind':<11} {'reach [mm]':>15} {'stroke [mm]':>12} {'payload [kg]':>13}")
    for f in facts:
        reach = f"{f['reach'][0] * 1e3:.0f} - {f['reach'][1] * 1e3:.0f}"
        print(f"{f['name']:<12} {f['kind']:<11} {reach:>15} {f['stroke'] * 1e3:>12.0f} {f['payload']:>13.2f}")
    print("reach: of the wrist axis from the J1 axis (palletizer: of the arm's end); stroke: the tool's vertical "
          "travel;\npayload: the largest mass at the tool the effort limits hold at rest (static, no motion); "
          "details: scara-pin workspace --robot NAME")  # fmt: skip
    return 0


def cmd_urdf(args: argparse.Namespace) -> int:
    """Write the generated URDF (of a configured robot, or of a D-H table) to stdout or, atomically, a file."""
    check_command_outputs(args, {"--output": args.output})  # before any work: not --dh nor the robot's yaml
    if args.dh:
        from ..description.dh import dh_to_urdf

        if args.set or args.prefix or args.robot is not None:
            raise InvalidInputError("--dh takes the whole robot from the table: no --robot, --set or --prefix")
        text = dh_to_urdf(Path(args.dh))
    else:
        text = generate_urdf(args.robot or "default", parse_sets(args.set), prefix=args.prefix)
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_text_atomic(Path(args.output), text)
        print(f"wrote {args.output}", file=sys.stderr)
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    """Lint a SCARA URDF: findings with line numbers; exit 0 clean, 4 warnings, 2 unusable (or list the rules)."""
    if args.list_rules:
        from ..lint import RULES, rules_text

        if args.file is not None:
            raise InvalidInputError("--list-rules lists the rules of check: it takes no file")
        if args.json:
            print(json.dumps({"rules": [{"code": r.code, "severity": r.severity.value, "family": r.family,
                                         "summary": r.summary} for r in RULES]}))  # fmt: skip
        else:
            print(rules_text())
        return 0
    from ._check_cell import report_with_cell

    if args.robot is not None:  # a configured robot: its generated URDF (what every command loads)
        from ..lint import check_urdf

        if args.file is not None:
            raise InvalidInputError("give either FILE.urdf or --robot NAME to check, not both")
        text = generate_urdf(args.robot, parse_sets(args.set))
        return report_with_cell(args, check_urdf(text, origin=f"robot {args.robot}", tool=args.tool, base=args.base,
                                                 lock=parse_locks(args.lock)))  # fmt: skip
    if args.set:
        raise InvalidInputError("--set overrides a configured robot's parameters: it goes with --robot")
    if args.file is None:
        raise InvalidInputError("check needs a FILE.urdf, --robot NAME (or --list-rules)")
    from ..lint import check_urdf_file

    report = check_urdf_file(args.file, tool=args.tool, base=args.base, package_dirs=args.package_path or (),
                             lock=parse_locks(args.lock))
    return report_with_cell(args, report)


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("robots", help="list the shipped robots: kind, reach, stroke, payload")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_robots)
    p = sub.add_parser("urdf", help="write the generated URDF of a robot")
    p.add_argument("-o", "--output", metavar="FILE", help="output file (default: stdout); written atomically")
    p.add_argument("--prefix", default="", help="prefix for every link and joint name (letters, digits, _)")
    p.add_argument("--dh", metavar="TABLE.yaml",
                   help="build the URDF from a D-H table (standard or modified; see urdf/examples/)")  # fmt: skip
    add_robot_options(p, urdf_file=False)
    p.set_defaults(func=cmd_urdf)
    p = sub.add_parser("check", help="lint a third-party SCARA URDF: exit 0 clean, 4 warnings, 2 unusable")
    p.add_argument("file", metavar="FILE.urdf", nargs="?", help="the URDF (or .xacro, expanded) to check")
    p.add_argument("--list-rules", action="store_true", help="print the rules of check, one line each, and exit")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    g = p.add_argument_group("robot")
    g.add_argument("--robot", default=None, metavar="NAME|CONFIG_DIR", help="check a configured robot (its generated "
                   "URDF; see `scara-pin robots`) instead of a FILE")  # fmt: skip
    g.add_argument("--set", action="append", metavar="KEY=VALUE", help="with --robot: override a parameter, SI units "
                   "(e.g. --set l1=0.25); repeatable")  # fmt: skip
    add_frame_options(g)
    from ._check_cell import add_check_cell_options

    add_check_cell_options(p)
    p.set_defaults(func=cmd_check)
