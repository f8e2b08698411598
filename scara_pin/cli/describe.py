"""Commands about the description: ``robots``, ``urdf``, ``check``."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from ._common import (
    _add_frame_options,
    _add_robot_options,
    _parse_locks,
    _parse_sets,
    check_command_outputs,
    write_atomic,
)

if TYPE_CHECKING:

    pass


def cmd_robots(args: argparse.Namespace) -> int:
    """List the shipped robot configurations."""
    from ..description import available_robots, urdf_dir

    names = available_robots()
    if args.json:
        print(json.dumps({"robots": names, "config_dir": str(urdf_dir() / "config")}))
    else:
        print("\n".join(names))
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
        from ..description import generate_urdf

        text = generate_urdf(args.robot or "default", _parse_sets(args.set), prefix=args.prefix)
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_atomic(Path(args.output), text)
        print(f"wrote {args.output}", file=sys.stderr)
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    """Lint a SCARA URDF: findings with line numbers; exit 0 clean, 4 warnings, 2 unusable."""
    from ..lint import check_urdf_file

    report = check_urdf_file(args.file, tool=args.tool, base=args.base, package_dirs=args.package_path or (),
                             lock=_parse_locks(args.lock))
    print(report.to_json() if args.json else report.format_text())
    return int(report.exit_code)


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("robots", help="list the shipped robots")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_robots)
    p = sub.add_parser("urdf", help="write the generated URDF of a robot")
    p.add_argument("-o", "--output", metavar="FILE", help="output file (default: stdout); written atomically")
    p.add_argument("--prefix", default="", help="prefix for every link and joint name (letters, digits, _)")
    p.add_argument("--dh", metavar="TABLE.yaml",
                   help="build the URDF from a D-H table (standard or modified; see urdf/examples/)")  # fmt: skip
    _add_robot_options(p, urdf_file=False)
    p.set_defaults(func=cmd_urdf)
    p = sub.add_parser("check", help="lint a third-party SCARA URDF: exit 0 clean, 4 warnings, 2 unusable")
    p.add_argument("file", metavar="FILE.urdf", help="the URDF (or .xacro, expanded) to check")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    _add_frame_options(p.add_argument_group("robot"))
    p.set_defaults(func=cmd_check)
