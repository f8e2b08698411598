"""The parser of ``scara-pin`` (argparse's complaints as :class:`UsageError`) and the options commands share."""

from __future__ import annotations

import argparse
import re
from typing import Any, NoReturn

from ._numbers import number_type


class UsageError(Exception):
    """argparse's complaint, turned into our one-line error and exit code 2."""


class Parser(argparse.ArgumentParser):
    """argparse's parser that reads ``-1e-3`` as a value and raises :class:`UsageError` instead of exiting."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # negative numbers, e-notation included (-1e-3), are values, not options
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


def add_units(
    p: argparse.ArgumentParser, *, deg: bool = True, mm: bool = True, json_help: str | None = "print one JSON object",
    inputs: bool = False,
) -> None:
    """The shared unit and output switches: --deg, --mm, --units (human units; the units rule) and --json."""
    scope = " (inputs and text)" if inputs else ""
    if deg:
        p.add_argument("--deg", action="store_true", help=f"angles in degrees{scope}; with a length typed, give "
                       "--mm too (or --units)")  # fmt: skip
    if mm:
        p.add_argument("--mm", action="store_true", help=f"lengths in millimetres{scope}; with an angle typed, give "
                       "--deg too (or --units)")  # fmt: skip
    kinds = "LENGTH,ANGLE" if deg else "LENGTH"
    p.add_argument("--units", metavar=kinds, help="units of typed and printed values, named explicitly: m or mm, "
                   "rad or deg (e.g. mm,deg or m,deg); a kind left out stays SI; not with --deg/--mm")  # fmt: skip
    if json_help is not None:
        p.add_argument("--json", action="store_true", help=json_help)


def add_robot_options(p: argparse.ArgumentParser, urdf_file: bool = True, set_help: str | None = None) -> None:
    """The group ``robot``: ``--robot``, ``--set`` and, with ``urdf_file``, ``--urdf`` and the frame options.

    ``set_help``: what ``--set`` says it does, for a command whose ``--set`` takes more than the robot's parameters.
    """
    g = p.add_argument_group("robot")
    g.add_argument("--robot", default=None, metavar="NAME|CONFIG_DIR",
                   help="shipped robot name (see `scara-pin robots`) or a folder of yaml files "
                   "(default: default)")  # fmt: skip
    g.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help=set_help or "override a parameter, SI units (e.g. --set l1=0.25); repeatable")  # fmt: skip
    if urdf_file:
        g.add_argument("--urdf", metavar="FILE", help="load this URDF file (or .xacro file, expanded: it runs "
                       "the expressions written in it) instead of a configured robot")  # fmt: skip
        add_frame_options(g)


def add_frame_options(g: Any) -> None:
    """--tool, --base and --package-path (the robot's frames and where its packages are)."""
    g.add_argument("--tool", metavar="FRAME", help="the tool frame (a link; default: tool0 if present, "
                   "else the chain's last link)")  # fmt: skip
    g.add_argument("--base", metavar="FRAME", help="the frame poses are expressed in (a link; default: base "
                   "if present, else the root link)")  # fmt: skip
    g.add_argument("--lock", action="append", metavar="JOINT=VALUE",
                   help="fix a joint at a value [rad or m, SI as --set]; joints not on the chain from the root to "
                   "the tool (another arm) are locked at 0 unless given; repeatable")  # fmt: skip
    g.add_argument("--package-path", action="append", metavar="DIR",
                   help="a folder holding ROS packages (folders with package.xml), for $(find pkg) and "
                   "package://pkg/ in --urdf; repeatable; ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are "
                   "searched too")  # fmt: skip


def add_cell_options(p: argparse.ArgumentParser, *, margin: bool = True) -> None:
    """``--cell FILE`` (obstacles, the carried part, the margin: docs/cell.md) and ``--margin M``."""
    g = p.add_argument_group("cell")
    g.add_argument("--cell", metavar="FILE", help="the robot's cell: obstacles in its base frame, what the tool "
                   "carries, the margin (YAML, or a URDF/xacro of fixed links; docs/cell.md)")  # fmt: skip
    if margin:
        g.add_argument("--margin", type=number_type("--margin"), metavar="M",
                       help="the smallest distance kept to any obstacle [m, or mm with --mm], instead of the "
                       "cell file's")  # fmt: skip
    g.add_argument("--carry", metavar="FILE", help="the part the tool carries: a job file's carry: (or a file holding "
                   "{shape: box, size, xyz}); it collides as the job's part does (docs/job.md)")  # fmt: skip


def add_motion_limits(p: Any) -> None:
    """``--velocity V1 V2 V3 V4`` and ``--acceleration A1 A2 A3 A4`` (one per joint): the joint limits a URDF lacks."""
    p.add_argument("--velocity", nargs="+", metavar="V",
                   help="joint velocity limits [rad/s, m/s; deg/s, mm/s with --deg/--mm], one per joint; instead "
                   "of the robot's (a URDF's continuous joint without <limit> has none)")  # fmt: skip
    p.add_argument("--acceleration", nargs="+", metavar="A",
                   help="joint acceleration limits [rad/s^2, m/s^2; deg/s^2, mm/s^2 with --deg/--mm]; needed "
                   "for a robot loaded from a URDF file (URDF has none); replaces the configured ones")  # fmt: skip


def add_q(p: argparse.ArgumentParser) -> None:
    """The joint values ``Q`` of ``fk`` and ``jacobian``, with the units, ``--strict`` and the robot options."""
    p.add_argument("q", nargs="*", metavar="Q",
                   help="joint values q1 q2 q3 q4 (URDF order; SCARA: q3 > 0 lowers the quill; "
                   "palletizer: q1 q2 theta3 q4, theta3 the small arm's absolute angle)")  # fmt: skip
    add_units(p)
    p.add_argument("--strict", action="store_true", help="refuse (exit 3) a q outside the joint limits")
    add_robot_options(p)
