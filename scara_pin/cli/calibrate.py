"""The ``calibrate`` command: identify the robot from measured points, plan the poses, or simulate them.

``--simulate`` measures the poses of a plan on a perturbed copy of the robot: the loop without a tracker.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InvalidInputError
from ..files import outputs_together, write_text_atomic
from ._numbers import integer_type, number_type
from ._options import add_robot_options, add_units
from ._outputs import check_command_outputs, log
from ._robot import robot_from_args
from ._units import Units

_GROUPS = ("offsets", "scale", "origins", "tool")


def _groups(text: str) -> frozenset[Any]:
    """``--model``: ``full`` or a comma-separated list of error groups."""
    from ..calibration.chain import ALL_GROUPS, Group

    if text.strip() == "full":
        return ALL_GROUPS
    names = [t.strip() for t in text.split(",") if t.strip()]
    bad = [n for n in names if n not in _GROUPS]
    if bad or not names:
        raise InvalidInputError(f"--model {text[:80]!r}: give full or a comma-separated list of {', '.join(_GROUPS)}")
    return frozenset(Group(n) for n in names)


def cmd_calibrate(args: argparse.Namespace) -> int:
    """Calibrate from a measurement file, propose the poses to measure (``--plan N``), or simulate them.

    ``--simulate PLAN`` measures the poses of PLAN on a perturbed copy of the robot.
    """
    from ..calibration.chain import MeasurementFrame

    if sum(x is not None for x in (args.measurements, args.plan, args.simulate)) != 1:
        raise InvalidInputError("give --measurements FILE (calibrate), --plan N (the poses to measure) or --simulate "
                                "PLAN (measure them on a perturbed copy of the robot), one of them")  # fmt: skip
    # before any work: each name (the plot's ending too), none on --measurements, --simulate or the robot's files,
    # nor two on one file
    check_command_outputs(args, {"--out": args.out, "--overlay": args.overlay, "--plot": args.plot},
                          figures=("--plot",))  # fmt: skip
    if args.overlay is not None and args.urdf is not None:
        raise InvalidInputError("--overlay writes the yaml parameters of a configured robot (--robot), "
                                "not of a URDF file")  # fmt: skip
    units = Units(args.deg, args.mm)
    groups = _groups(args.model)
    frame = MeasurementFrame(args.frame)
    robot = robot_from_args(args, units)
    if args.plan is not None:
        return _plan(args, robot, groups, frame)
    if args.simulate is not None:
        return _simulate(args, robot, units)
    from ..calibration.fit import CalibrationOptions, calibrate
    from ..calibration.measurements import Measurements
    from ..calibration.results import Loss

    options = CalibrationOptions(groups=groups, frame=frame, loss=Loss(args.loss), f_scale=args.f_scale,
                                 outlier_sigmas=args.outlier_sigmas, yaw_weight=args.yaw_weight, folds=args.folds,
                                 seed=args.seed, accept_outside_limits=args.allow_outside_limits)  # fmt: skip
    measurements = Measurements.from_csv(args.measurements, robot.dof)
    result = calibrate(robot, measurements, options)
    for warning in result.warnings:
        log.warning("%s", warning)
    written: dict[str, str] = {}
    if args.out == "-":
        sys.stdout.write(result.urdf)
        return 0
    overlay = None
    with outputs_together():  # all of them, or none
        if args.out is not None:
            write_text_atomic(Path(args.out), result.urdf)
            written["urdf"] = args.out
        if args.overlay is not None:
            from ..calibration.overlay import yaml_overlay

            overlay = yaml_overlay(result)
            write_text_atomic(Path(args.overlay), overlay.to_yaml())
            written["overlay"] = args.overlay
        if args.plot is not None:
            from ..calibration.plot import plot_residuals

            plot_residuals(result, args.plot)
            written["plot"] = args.plot
    if args.json:
        doc = result.to_dict()
        doc["written"] = written
        if overlay is not None:
            doc["overlay"] = {"values": overlay.values, "unexpressed": list(overlay.unexpressed),
                              "residual": overlay.residual.to_dict()}  # fmt: skip
        print(json.dumps(doc))
        return 0
    print(result.report(units.length_name, units.angle_name, warnings=False))
    if overlay is not None:
        print(f"overlay: {len(overlay.values)} yaml parameter(s) changed; with them alone the residual is rms "
              f"{overlay.residual.rms * units.length:.4g} {units.length_name}")  # fmt: skip
    for what, path in written.items():
        print(f"wrote {path} ({what})")
    return 0


def _plan(args: argparse.Namespace, robot: Any, groups: frozenset[Any], frame: Any) -> int:
    from ..calibration.design import Criterion, plan_experiment

    if args.plot is not None or args.overlay is not None:
        raise InvalidInputError("--plot and --overlay go with --measurements, not --plan")
    plan = plan_experiment(robot, args.plan, criterion=Criterion(args.criterion), yaw=args.yaw, frame=frame,
                           groups=groups, seed=args.seed, candidates=args.candidates)  # fmt: skip
    if args.out not in (None, "-"):
        write_text_atomic(Path(args.out), plan.to_csv())
    if args.json:
        doc = plan.to_dict()
        doc["written"] = {"plan": args.out} if args.out not in (None, "-") else {}
        print(json.dumps(doc))
        return 0
    if args.out in (None, "-"):
        sys.stdout.write(plan.to_csv())
        return 0
    print(f"plan: {len(plan.q)} poses for robot {plan.robot!r}, criterion {plan.criterion.value} (log det "
          f"{plan.log_det:.6g}, smallest singular value {plan.min_sv:.6g}, condition {plan.condition:.6g}); "
          f"{len(plan.identified)} identifiable errors; {plan.candidates} candidates, seed {plan.seed}")  # fmt: skip
    print(f"wrote {args.out}: measure the tool at each pose, replace x, y, z by the measurements, then "
          f"scara-pin calibrate --measurements {args.out}")  # fmt: skip
    return 0


def _simulate(args: argparse.Namespace, robot: Any, units: Units) -> int:
    """``--simulate PLAN``: the plan's poses measured on a perturbed copy of the robot, as a measurement file."""
    from ..calibration.measurements import Measurements
    from ..calibration.simulate import simulate

    if args.plot is not None or args.overlay is not None:
        raise InvalidInputError("--plot and --overlay go with --measurements, not --simulate")
    plan = Measurements.from_csv(args.simulate, robot.dof)
    sim = simulate(robot, plan.q, seed=args.seed, noise=args.noise, yaw=args.yaw or plan.yaw is not None,
                   yaw_weight=args.yaw_weight)  # fmt: skip
    text = sim.to_csv()
    if args.out in (None, "-"):
        sys.stdout.write(text)
        return 0
    write_text_atomic(Path(args.out), text)
    moved = float(np.linalg.norm(sim.measurements.position - plan.position, axis=1).max())
    if args.json:
        print(json.dumps({"robot": sim.robot, "units": {"length": "m", "angle": "rad"}, "poses": len(plan),
                          "seed": sim.seed, "noise": sim.noise, "yaw": sim.measurements.yaw is not None,
                          "errors": {k: {"xyz": dp.tolist(), "rotation": w.tolist()} for k, (dp, w) in
                                     sim.errors.items()},
                          "written": {"measurements": args.out}}))  # fmt: skip
        return 0
    print(f"simulated: {len(plan)} poses of {args.simulate} measured on a copy of robot {sim.robot!r} with every joint "
          f"origin perturbed (seed {sim.seed}; the errors made are in the file's comments), noise {sim.noise:g} m "
          f"per coordinate; the measured positions differ from the plan's by up to {moved * units.length:.4g} "
          f"{units.length_name}")  # fmt: skip
    print(f"wrote {args.out}: calibrate it as a measured file: scara-pin calibrate --measurements {args.out} "
          "--out calibrated.urdf (with the same --robot/--set/--urdf)")  # fmt: skip
    return 0


def register(sub: Any) -> None:
    """Add the ``calibrate`` command to the ``scara-pin`` subparsers."""
    from ..limits import MAX_PLAN_POSES

    p = sub.add_parser("calibrate", help="identify the robot from measured tool positions; write the calibrated "
                       "URDF (--plan N: the poses to measure; --simulate PLAN: measure them on a perturbed copy)")
    g = p.add_argument_group("input")
    g.add_argument("--measurements", metavar="CSV", help="measured poses: columns q1..qN (joint readings, SI), x, y, z "
                   "[m] and optionally yaw [rad]; other columns ignored")  # fmt: skip
    g.add_argument("--plan", type=integer_type("--plan", 1, MAX_PLAN_POSES), metavar="N",
                   help="propose N well-conditioned poses to measure (CSV with the nominal x, y, z to replace)")
    g.add_argument("--simulate", metavar="PLAN", help="measure the poses of PLAN (a --plan CSV) on a copy of the robot "
                   "with every joint origin perturbed (seeded by --seed: xyz +/-1 mm, tilts 0.1 deg, zero offsets "
                   "0.5 deg) plus --noise: a measurement file to try the loop without a tracker")  # fmt: skip
    g.add_argument("--noise", type=number_type("--noise"), default=1e-5, metavar="M",
                   help="with --simulate: measurement noise per coordinate [m] (default 1e-5; the yaw's is "
                   "M / --yaw-weight [rad])")  # fmt: skip
    g.add_argument("--allow-outside-limits", action="store_true",
                   help="use readings outside the URDF's joint limits (a warning) instead of refusing them, when the "
                   "controller's limits are wider than the URDF's")  # fmt: skip
    g.add_argument("--frame", choices=("base", "device"), default="base",
                   help="frame of the measured positions: the robot's base (default) or the measuring device's own "
                   "(its placement is identified and reported; the URDF keeps its base)")  # fmt: skip
    g.add_argument("--yaw", action="store_true", help="with --plan: the yaw will be measured too; with --simulate: "
                   "measure it (also when PLAN has a yaw column)")  # fmt: skip
    m = p.add_argument_group("model and fit")
    m.add_argument("--model", default="full", metavar="MODEL",
                   help=f"error groups to identify: full (default) or a comma-separated list of {', '.join(_GROUPS)}")
    m.add_argument("--loss", default="soft_l1", choices=("linear", "soft_l1", "huber", "cauchy", "arctan"),
                   help="least-squares loss: a robust one (soft_l1, the default) finds outliers, lists them and "
                   "leaves them out of the final linear fit; linear keeps every row (outliers named in a warning)")
    m.add_argument("--f-scale", type=number_type("--f-scale"), default=1e-4, metavar="M",
                   help="the robust loss's inlier scale [m] (default 1e-4)")
    m.add_argument("--outlier-sigmas", type=number_type("--outlier-sigmas"), default=5.0, metavar="K",
                   help="an outlier is off by more than K robust standard deviations (default 5)")
    m.add_argument("--yaw-weight", type=number_type("--yaw-weight"), default=0.1, metavar="M_PER_RAD",
                   help="weight of a yaw residual against a position one [m/rad] (position noise / yaw noise; "
                   "default 0.1)")  # fmt: skip
    m.add_argument("--folds", type=integer_type("--folds", 0, 100), default=5, metavar="K",
                   help="k-fold cross-validation on held-out poses (0: none; default 5)")
    m.add_argument("--criterion", default="det", choices=("det", "min-sv"),
                   help="with --plan: maximise the determinant (D-optimal, default) or the smallest singular value "
                   "(E-optimal) of the identification matrix")  # fmt: skip
    m.add_argument("--candidates", type=integer_type("--candidates", 1, 4_000_000), metavar="K",
                   help="with --plan: random candidate poses to choose from (default 20 per pose, 500 .. 4000)")
    m.add_argument("--seed", type=integer_type("--seed", 0, 2**32 - 1), default=0,
                   help="seed of the random poses (plan, structural count), of the folds and of --simulate's errors "
                   "and noise (default 0)")  # fmt: skip
    o = p.add_argument_group("output")
    o.add_argument("--out", metavar="FILE", help="the calibrated URDF (the input's text with the calibrated origins); "
                   "with --plan: the poses (CSV); with --simulate: the measurements (CSV); written atomically; - for "
                   "stdout")  # fmt: skip
    o.add_argument("--overlay", metavar="YAML", help="a configured robot's changed yaml parameters (flat names)")
    o.add_argument("--plot", metavar="PNG", help="each pose's position error before and after")
    add_units(p, inputs=False, json_help="print one JSON object (SI units)")
    add_robot_options(p)
    p.set_defaults(func=cmd_calibrate)
