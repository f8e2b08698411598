"""``--setpoints``: a trajectory's controller setpoints (latency compensation, motor steps), for ``traj`` and ``job``.

One set of options and one writer, so that ``job --setpoints`` writes what ``traj --setpoints`` writes.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import InvalidInputError
from ..files import write_text_atomic
from ._numbers import number, number_type
from ._units import Units

SETPOINT_OPTIONS = ("setpoint_rate", "delays", "gear", "steps_per_rev", "screw_lead")
"""The options that shape the setpoints (refused without ``--setpoints``)."""


def add_setpoint_options(g: Any) -> None:
    """``--setpoints CSV`` and what shapes them: rate, per-axis delays, gears, motor steps, screw lead."""
    g.add_argument("--setpoints", metavar="CSV", help="controller setpoints (S4) at --setpoint-rate")
    g.add_argument("--setpoint-rate", type=number_type("--setpoint-rate"), metavar="HZ",
                   help="setpoint rate (default: --rate)")  # fmt: skip
    g.add_argument("--delays", nargs="+", metavar="S", help="per-axis command latency [s], compensated")
    g.add_argument("--gear", nargs=4, metavar="G", help="gear ratios (motor turns per joint/screw turn)")
    g.add_argument("--steps-per-rev", nargs=4, metavar="N", help="motor steps per motor turn")
    g.add_argument("--screw-lead", metavar="L", help="quill screw travel per turn [m, or mm with --mm]")


def check_setpoint_options(args: argparse.Namespace) -> None:
    """Refuse (exit 2) a setpoint option without ``--setpoints``, naming it."""
    for name in SETPOINT_OPTIONS:
        if getattr(args, name) is not None and not args.setpoints:
            raise InvalidInputError(f"--{name.replace('_', '-')} shapes the controller setpoints: it needs --setpoints")


def write_setpoints(args: argparse.Namespace, robot: Any, traj: Any, units: Units) -> None:
    """``--setpoints``: the controller setpoints of ``traj`` (motor steps, latency compensation), atomically."""
    from ..motion import trajectory as tr

    motor = None
    if args.gear or args.steps_per_rev or args.screw_lead is not None:
        if not (args.gear and args.steps_per_rev and args.screw_lead is not None):
            raise InvalidInputError("motor steps need --gear G1..G4, --steps-per-rev S1..S4 and --screw-lead L")
        motor = tr.MotorUnits.from_drive(
            [number("--gear", g) for g in args.gear],
            [number("--steps-per-rev", v) for v in args.steps_per_rev],
            units.value("--screw-lead", args.screw_lead, "length"),
            prismatic=robot.joint_kinds.index("length"),
        )
    delays = [number("--delays", d) for d in args.delays] if args.delays else None
    rate = args.setpoint_rate if args.setpoint_rate is not None else args.rate
    sp = traj.setpoints(rate, delays=delays, motor=motor)
    write_text_atomic(Path(args.setpoints), sp.csv_text())
