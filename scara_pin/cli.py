"""The ``scara-pin`` command line.

Conventions shared by every command:

- SI units by default; ``--deg`` gives and prints angles in degrees, ``--mm`` lengths in millimetres.
- Joint vectors are in URDF joint order (joint1..joint4); q3 grows as the quill moves down. A palletizer's
  q is (q1, q2, theta3, q4), four angles, theta3 the small arm's absolute angle (scara_pin.palletizer).
- ``--json`` prints one JSON object on stdout.
- Exit codes: 0 ok, 2 invalid input, 3 infeasible request (unreachable, limits), 1 internal error;
  ``check`` also exits 4 when the URDF is usable but has warnings.
  Errors are one line on stderr starting with ``error:``; warnings start with ``warning:``.

Heavy packages (toppra, matplotlib, yourdfpy, meshcat) are imported only inside the commands that need
them, so ``fk`` starts about as fast as ``import pinocchio``.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import os
import re
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

from .errors import InfeasibleError, InvalidInputError, ParameterError, ScaraError
from .files import write_atomic_with, write_text_atomic

if TYPE_CHECKING:
    import numpy as np

    from ._typing import ArrayLike
    from .model import Robot

__all__ = ["main"]

log = logging.getLogger("scara_pin")

_Q_NAMES = ("q1", "q2", "q3", "q4")
_Q_KINDS = ("angle", "angle", "length", "angle")  # what each joint value measures
_POSE_KINDS = ("length", "length", "length", "angle")  # x, y, z, yaw


class _UsageError(Exception):
    """argparse's complaint, turned into our one-line error and exit code 2."""


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        # negative numbers, e-notation included (-1e-3), are values, not options
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

    def error(self, message: str) -> NoReturn:
        raise _UsageError(message)


class Units:
    """Scale factors from SI to the units the user asked for (``--deg``, ``--mm``)."""

    def __init__(self, deg: bool, mm: bool) -> None:
        self.angle = 180.0 / math.pi if deg else 1.0
        self.length = 1000.0 if mm else 1.0
        self.angle_name = "deg" if deg else "rad"
        self.length_name = "mm" if mm else "m"
        self.q: tuple[str, ...] = _Q_KINDS  # what each joint value measures; _load sets the robot's own

    def scale(self, kinds: Sequence[str]) -> list[float]:
        """Multipliers from SI for a sequence of quantity kinds ("angle" / "length")."""
        return [self.angle if k == "angle" else self.length for k in kinds]

    def names(self, kinds: Sequence[str]) -> list[str]:
        """Unit names for a sequence of quantity kinds."""
        return [self.angle_name if k == "angle" else self.length_name for k in kinds]


def _number(name: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(name, text, "must be a number") from None
    if not math.isfinite(value):
        raise ParameterError(name, text, "must be finite")
    return value


def _parse_sets(items: Sequence[str] | None) -> dict[str, str]:
    overrides: dict[str, str] = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InvalidInputError(f"--set {item!r} must have the form key=value (e.g. l1=0.25)")
        overrides[key.strip()] = value
    return overrides


def _load(args: argparse.Namespace, units: Units | None = None) -> Robot:
    from .model import load_robot

    robot = load_robot(args.robot, _parse_sets(args.set), urdf=args.urdf)
    if units is not None:  # what each joint value measures, read from the model (any joint order)
        units.q = robot.joint_kinds
    return robot


def _read_q(args: argparse.Namespace, units: Units) -> np.ndarray:
    import numpy as np

    if len(args.q) != 4:
        raise ParameterError("q", " ".join(args.q), f"must be 4 joint values (got {len(args.q)})")
    return np.array(_q_values(args.q, units))


def _q_values(texts: Sequence[str], units: Units, what: str = "") -> list[float]:
    """Joint values as typed (units per --deg/--mm and the robot's joint kinds) in SI, each a finite number."""
    prefix = f"{what} " if what else ""
    return [_number(prefix + n, t) / sc for n, t, sc in zip(_Q_NAMES, texts, units.scale(units.q))]


def _check_limits(robot: Robot, q: np.ndarray, strict: bool) -> None:
    outside = robot.outside_limits(q)
    if outside and strict:
        raise InfeasibleError("q outside the joint limits (--strict): " + "; ".join(outside))
    for item in outside:
        log.warning("%s (computed anyway; --strict refuses)", item)


def _fmt(values: ArrayLike) -> str:
    return "[" + ", ".join(f"{v: .9g}" for v in values) + "]"


def _scaled(values: ArrayLike, scale: Sequence[float]) -> list[float]:
    return [float(v) * s for v, s in zip(values, scale)]


# ---------------------------------------------------------------------------------------------- commands
def cmd_robots(args: argparse.Namespace) -> int:
    """List the shipped robot configurations."""
    from .description import available_robots, urdf_dir

    names = available_robots()
    if args.json:
        print(json.dumps({"robots": names, "config_dir": str(urdf_dir() / "config")}))
    else:
        print("\n".join(names))
    return 0


def cmd_urdf(args: argparse.Namespace) -> int:
    """Write the generated URDF (of a configured robot, or of a D-H table) to stdout or, atomically, a file."""
    if args.dh:
        from .dh import dh_to_urdf

        if args.set or args.prefix or args.robot != "default":
            raise InvalidInputError("--dh takes the whole robot from the table: no --robot, --set or --prefix")
        text = dh_to_urdf(Path(args.dh))
    else:
        from .description import generate_urdf

        text = generate_urdf(args.robot, _parse_sets(args.set), prefix=args.prefix)
    if args.output in (None, "-"):
        sys.stdout.write(text)
    else:
        write_atomic(Path(args.output), text)
        print(f"wrote {args.output}", file=sys.stderr)
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    """Lint a SCARA URDF: findings with line numbers; exit 0 clean, 4 warnings, 2 unusable."""
    from .urdf_check import check_urdf_file

    report = check_urdf_file(args.file)
    print(report.to_json() if args.json else report.format_text())
    return int(report.exit_code)


def cmd_fk(args: argparse.Namespace) -> int:
    """Forward kinematics: the pose of tool0 in the base frame."""
    units = Units(args.deg, args.mm)
    robot = _load(args, units)
    q = _read_q(args, units)
    _check_limits(robot, q, args.strict)
    M = robot.tool_placement(q)
    from .model import pose_from_placement

    pose = pose_from_placement(M)
    q_out = _scaled(q, units.scale(units.q))
    pos = [float(v) * units.length for v in pose[:3]]
    yaw = float(pose[3]) * units.angle
    matrix = M.homogeneous.copy()
    matrix[:3, 3] *= units.length
    if args.json:
        out = {
            "robot": robot.name,
            "q": q_out,
            "position": pos,
            "yaw": yaw,
            "matrix": matrix.tolist(),
            "frame": robot.tool_frame,
            "reference": robot.base_frame,
            "units": {"length": units.length_name, "angle": units.angle_name},
        }
        print(json.dumps(out))
        return 0
    print(f"robot     {robot.name}: {robot.tool_frame} in {robot.base_frame}")
    print(f"q         {_fmt(q_out)}  [{', '.join(units.names(units.q))}]")
    print(f"position  {_fmt(pos)}  [{units.length_name}]")
    print(f"yaw       {yaw: .9g}  [{units.angle_name}]")
    print("matrix")
    for row in matrix:
        print("          " + _fmt(row))
    return 0


def cmd_jacobian(args: argparse.Namespace) -> int:
    """The task Jacobian d(x, y, z, yaw)/dq, or Pinocchio's 6 x 4 frame Jacobian."""
    import numpy as np

    units = Units(args.deg, args.mm)
    robot = _load(args, units)
    q = _read_q(args, units)
    _check_limits(robot, q, args.strict)
    if args.reference == "task":
        if args.frame is not None:
            raise InvalidInputError("--frame goes with --reference world|local|local_world_aligned")
        J = robot.task_jacobian(q)
        rows = ["x", "y", "z", "yaw"]
        row_kinds: tuple[str, ...] = _POSE_KINDS
    else:
        J = robot.frame_jacobian(q, args.frame, args.reference)
        rows = ["vx", "vy", "vz", "wx", "wy", "wz"]
        row_kinds = ("length",) * 3 + ("angle",) * 3
    # J_user[i, j] = J[i, j] * (unit of row i) / (unit of column j)
    J = J * np.array(units.scale(row_kinds))[:, None] / np.array(units.scale(units.q))[None, :]
    w = robot.manipulability(q)
    if args.json:
        out = {
            "robot": robot.name,
            "q": _scaled(q, units.scale(units.q)),
            "reference": args.reference,
            "frame": args.frame or robot.tool_frame,
            "rows": rows,
            "jacobian": J.tolist(),
            "manipulability": w,
            "units": {"length": units.length_name, "angle": units.angle_name},
        }
        print(json.dumps(out))
        return 0
    print(f"robot     {robot.name}: {args.reference} Jacobian of {args.frame or robot.tool_frame}")
    print(f"q         {_fmt(_scaled(q, units.scale(units.q)))}  [{', '.join(units.names(units.q))}]")
    print("          " + "".join(f"{n:>16}" for n in ("d/dq1", "d/dq2", "d/dq3", "d/dq4")))
    for name, row in zip(rows, J):
        print(f"{name:<10}" + "".join(f"{v:16.9g}" for v in row))
    print(f"manipulability sqrt(det(J J^T)) of the task Jacobian (SI): {w:.9g}")
    return 0


def _read_pose(texts: Sequence[str], units: Units, what: str = "target") -> list[float]:
    if len(texts) != 4:
        raise ParameterError(what, " ".join(texts), f"must be 4 values X Y Z YAW (got {len(texts)})")
    return [_number(n, t) / sc for n, t, sc in zip(("x", "y", "z", "yaw"), texts, units.scale(_POSE_KINDS))]


def _solutions_json(q_list: Sequence[ArrayLike], branches: Sequence[str], units: Units) -> list[dict]:
    scale = units.scale(units.q)
    return [{"q": _scaled(q, scale), "branch": b} for q, b in zip(q_list, branches)]


def cmd_ik(args: argparse.Namespace) -> int:
    """Inverse kinematics: every joint solution for a tool pose (closed form, or numeric)."""
    units = Units(args.deg, args.mm)
    robot = _load(args, units)
    if args.input:
        return _ik_batch(args, robot, units)
    if args.input is None and args.output:
        raise InvalidInputError("--output goes with --input (batch mode)")
    target = _read_pose(args.target, units)
    near = None
    if args.near:
        near = robot.check_q(_q_values(args.near, units))
    numeric = args.numeric
    if robot.kind == "palletizer":
        if args.branch in ("left", "right"):
            raise InvalidInputError(f"--branch {args.branch} is a SCARA branch; a palletizer's are up and down")
    elif args.branch in ("up", "down"):
        raise InvalidInputError(f"--branch {args.branch} is a palletizer branch; a SCARA's are left and right")
    if not numeric and robot.kind == "scara":
        from .ik import NotScaraError

        try:
            _ = robot.kinematics  # extracted on first use: refused here if the model is not SCARA-like
        except NotScaraError as exc:
            log.warning("closed-form IK refused this robot (%s); using the numeric IK", exc)
            numeric = True
    if numeric:
        status, message, qs, branches = _ik_numeric(robot, target, near)
    else:
        result = robot.ik(target, branch=args.branch, reference=near)
        sols = result.branch(args.branch)
        message = result.message
        if near is not None and sols:
            best = result.nearest(near, branch=args.branch)
            message = f"the nearest of {len(sols)} solution(s) to --near"
            sols = (best,) if best is not None else ()
        status = result.status.name if sols or not result.success else "NO_SOLUTION_IN_BRANCH"
        if result.success and not sols:
            message = f"no {args.branch} solution ({len(result.solutions)} of the other branch)"
        qs, branches = [s.q for s in sols], [s.branch for s in sols]
    scale = units.scale(_POSE_KINDS)
    tgt = dict(zip(("x", "y", "z", "yaw"), _scaled(target, scale)))
    code = 0 if status == "OK" else 3
    if args.json:
        print(json.dumps({"robot": robot.name, "target": tgt, "solutions": _solutions_json(qs, branches, units),
                          "status": status, "message": message, "method": "numeric" if numeric else "closed-form",
                          "units": {"length": units.length_name, "angle": units.angle_name}}))  # fmt: skip
        return code
    if code:
        raise InfeasibleError(f"{status}: {message}")
    method = "numeric" if numeric else "closed-form"
    print(f"robot     {robot.name}: {method} IK of {robot.tool_frame} in {robot.base_frame}")
    print(f"target    {_fmt(list(tgt.values()))}  [{', '.join(units.names(_POSE_KINDS))}]")
    print(f"units     q = [{', '.join(units.names(units.q))}]")
    for q, b in zip(qs, branches):
        print(f"{b:<9} {_fmt(_scaled(q, units.scale(units.q)))}")
    return 0


def _ik_numeric(robot: Robot, target: Sequence[float], near: np.ndarray | None) -> tuple[str, str, list, list]:
    from .ik import NotScaraError
    from .ik_numeric import solve_numeric

    res = solve_numeric(robot, target, q0=near)
    if not res.success:
        return ("NO_CONVERGENCE", f"numeric IK did not reach the target (residual {res.residual:.3g} after "
                f"{res.iterations} iterations from {res.starts} starts)", [], [])  # fmt: skip
    try:
        branch = robot.branch_of(res.q)
    except NotScaraError:
        branch = "unknown"
    return "OK", f"converged in {res.iterations} iterations (residual {res.residual:.3g})", [res.q], [branch]


def _ik_batch(args: argparse.Namespace, robot: Robot, units: Units) -> int:
    """Stream a CSV of targets (x, y, z, yaw) through the vectorised closed form, in bounded memory."""
    import csv

    import numpy as np

    from .ik import IKStatus, solve_batch

    if args.target:
        raise InvalidInputError("give either X Y Z YAW or --input FILE, not both")
    if not args.output:
        raise InvalidInputError("--input needs --output FILE")
    branch = {"all": "nearest", "right": "right", "left": "left"}[args.branch]
    reference = None
    if args.near:
        reference = _q_values(args.near, units)
    if robot.kind != "scara":
        raise InvalidInputError(f"ik --input (batch) is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
    geo = robot.kinematics
    in_path, out_path = Path(args.input), Path(args.output)
    try:
        handle = in_path.open(newline="", encoding="utf-8")
    except OSError as exc:
        raise InvalidInputError(f"cannot read {in_path}: {exc.strerror}") from None
    total = failed = 0
    pose_scale = np.array(units.scale(_POSE_KINDS))
    q_scale = np.array(units.scale(units.q))
    show_progress = sys.stderr.isatty()
    size = max(in_path.stat().st_size, 1)

    def rows_out(writer: Any) -> None:
        nonlocal total, failed
        reader = csv.reader(handle)
        header = next(reader, None)
        if header is None or [h.strip().lower() for h in header[:4]] != ["x", "y", "z", "yaw"]:
            raise InvalidInputError(f"{in_path}: the first row must be the header x,y,z,yaw")
        writer.writerow(["x", "y", "z", "yaw", "q1", "q2", "q3", "q4", "branch", "status"])
        chunk: list[list[float]] = []
        line = 1
        for row in reader:
            line += 1
            if not row or all(not c.strip() for c in row):
                continue
            if len(row) < 4:
                raise InvalidInputError(f"{in_path} line {line}: expected 4 values x,y,z,yaw, got {len(row)}")
            chunk.append([_number(f"{in_path.name} line {line} {n}", c) for n, c in zip("xyz", row[:3])]
                         + [_number(f"{in_path.name} line {line} yaw", row[3])])  # fmt: skip
            if len(chunk) == 65536:
                flush(writer, chunk)
                chunk = []
                if show_progress:
                    print(f"\r{total} targets ({100 * handle.tell() / size:.0f} %)", end="", file=sys.stderr)
        flush(writer, chunk)
        if show_progress:
            print(f"\r{total} targets (100 %)", file=sys.stderr)

    def flush(writer: Any, chunk: list[list[float]]) -> None:
        nonlocal total, failed
        if not chunk:
            return
        T = np.array(chunk) / pose_scale
        res = solve_batch(geo, T, branch=branch, reference=reference)
        names = [IKStatus(c).name for c in range(len(IKStatus))]
        labels = {1: "right", -1: "left", 0: ""}
        for t, q, b, st in zip(T * pose_scale, res.q * q_scale, res.branch, res.status):
            writer.writerow([*(repr(float(v)) for v in t), *("" if math.isnan(v) else repr(float(v)) for v in q),
                             labels[int(b)], names[int(st)]])  # fmt: skip
        total += len(chunk)
        failed += int((res.status != 0).sum())

    with handle:
        write_atomic_with(out_path, lambda f: rows_out(csv.writer(f)))
    print(f"wrote {out_path}: {total} targets, {total - failed} solved, {failed} without solution", file=sys.stderr)
    return 3 if failed else 0


def cmd_validate_ik(args: argparse.Namespace) -> int:
    """Cross-validate the closed-form IK against Pinocchio FK and the numeric IK."""
    from .validate import validate_ik

    if args.samples < 1:
        raise ParameterError("--samples", args.samples, "must be >= 1")
    robot = _load(args)
    report = validate_ik(robot, args.samples, args.seed)
    if args.json:
        out = {k: v for k, v in vars(report).items()}
        out["ok"] = report.ok
        print(json.dumps(out))
    else:
        print(report.table())
    return 0 if report.ok else 1


def _joint_arg(robot: Robot, texts: Sequence[str], units: Units, what: str) -> np.ndarray:
    q = robot.check_q(_q_values(texts, units, what))
    outside = robot.outside_limits(q, tol=1e-12)
    if outside:
        raise InfeasibleError(f"{what} is outside the joint limits: " + "; ".join(outside))
    return q


def _pose_to_q(robot: Robot, pose: ArrayLike, near: np.ndarray, what: str) -> np.ndarray:
    result = robot.ik(pose)
    if not result.success:
        raise InfeasibleError(f"{what} {list(pose)}: {result.status.name}: {result.message}")
    best = result.nearest(near)
    assert best is not None  # success means at least one solution
    return best.q


def cmd_traj(args: argparse.Namespace) -> int:
    """A trajectory between configurations or poses: quintic, time-optimal, or a straight tool line."""
    import numpy as np

    from . import trajectory as tr

    logging.getLogger("toppra").setLevel(logging.WARNING)
    units = Units(args.deg, args.mm)
    robot = _load(args, units)
    if (args.from_q is None) == (args.from_pose is None):
        raise InvalidInputError("give the start as either --from Q1 Q2 Q3 Q4 or --from-pose X Y Z YAW")
    if (args.to_q is None) == (args.to_pose is None):
        raise InvalidInputError("give the end as either --to Q1 Q2 Q3 Q4 or --to-pose X Y Z YAW")
    if args.duration is not None and args.optimal:
        raise InvalidInputError("--duration and --optimal exclude each other")
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise ParameterError("--duration", args.duration, "must be a finite number > 0", "s")
    if not (math.isfinite(args.rate) and args.rate > 0):
        raise ParameterError("--rate", args.rate, "must be a finite number > 0", "Hz")
    vias = [_joint_arg(robot, v, units, f"--via #{i + 1}") for i, v in enumerate(args.via or [])]
    mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2
    pose_from = _read_pose(args.from_pose, units, "--from-pose") if args.from_pose else None
    pose_to = _read_pose(args.to_pose, units, "--to-pose") if args.to_pose else None
    q_from = _joint_arg(robot, args.from_q, units, "--from") if args.from_q else None
    q_to = _joint_arg(robot, args.to_q, units, "--to") if args.to_q else None
    tool_speed = None
    if args.tool_speed is not None:
        tool_speed = _number("--tool-speed", str(args.tool_speed)) / units.length
    if args.linear and robot.kind != "scara":
        raise InvalidInputError(f"traj --linear is SCARA-only for now; robot {robot.name!r} is a {robot.kind} "
                                "(joint-space --duration and TOPP-RA timing work)")  # fmt: skip
    if args.plot and robot.kind != "scara":
        raise InvalidInputError(f"traj --plot is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
    if args.linear:
        first = pose_from if q_from is None else tr.joint_pose(robot, q_from)
        assert first is not None  # --from or --from-pose, checked above
        poses = [first]
        poses += [tr.joint_pose(robot, v) for v in vias]
        last = pose_to if q_to is None else tr.joint_pose(robot, q_to)
        assert last is not None  # --to or --to-pose, checked above
        poses.append(last)
        path = tr.cartesian_path(robot, poses, start=q_from, end=q_to)
        if args.duration is not None:
            traj, method = tr.timed(path, args.duration), "straight line, quintic time law"
        else:
            from .timing import time_optimal

            traj = time_optimal(robot, path, tool_speed=tool_speed, torque=args.torque)
            method = "straight line, time-optimal (TOPP-RA)"
    else:
        if q_from is None:
            q_from = _pose_to_q(robot, pose_from, mid, "--from-pose")  # type: ignore[arg-type]
        if q_to is None:
            q_to = _pose_to_q(robot, pose_to, vias[-1] if vias else q_from, "--to-pose")  # type: ignore[arg-type]
        waypoints = [q_from, *vias, q_to]
        lim = robot.limits
        if args.duration is not None:
            if vias:
                traj, method = tr.timed(tr.joint_path(robot, waypoints), args.duration), "joint spline, quintic law"
            else:
                traj, method = tr.quintic(q_from, q_to, args.duration), "joint quintic (jtraj)"
        elif not vias and tool_speed is None and not args.torque:
            traj, method = tr.trapezoidal(q_from, q_to, lim.velocity, lim.acceleration), "joint line, time-optimal"
        else:
            from .timing import time_optimal

            traj = time_optimal(robot, waypoints, tool_speed=tool_speed, torque=args.torque)
            method = "joint path, time-optimal (TOPP-RA)"
    from .timing import limit_ratios

    ratios = limit_ratios(robot, traj, rate=1000.0, tool_speed=tool_speed, torque=args.torque)
    if ratios.worst > 1 + 1e-6:
        message = (f"the trajectory exceeds a limit: worst ratio {ratios.worst:.6g} (velocity "
                   f"{ratios.velocity:.6g}, acceleration {ratios.acceleration:.6g}); a longer --duration, or "
                   "--optimal, respects them")  # fmt: skip
        if args.strict:
            raise InfeasibleError(message)
        log.warning(message)
    outputs: dict[str, str] = {}
    if args.out:
        out = Path(args.out)
        (traj.to_json if out.suffix.lower() == ".json" else traj.to_csv)(out, rate=args.rate)
        outputs["trajectory"] = str(out)
    if args.setpoints:
        motor = None
        if args.gear or args.steps_per_rev or args.screw_lead is not None:
            if not (args.gear and args.steps_per_rev and args.screw_lead is not None):
                raise InvalidInputError("motor steps need --gear G1..G4, --steps-per-rev S1..S4 and --screw-lead L")
            motor = tr.MotorUnits.from_drive(
                [_number("--gear", g) for g in args.gear],
                [_number("--steps-per-rev", v) for v in args.steps_per_rev],
                _number("--screw-lead", args.screw_lead) / units.length,
                prismatic=robot.kinematics.prismatic,
            )
        delays = [_number("--delays", d) for d in args.delays] if args.delays else None
        sp = traj.setpoints(args.setpoint_rate or args.rate, delays=delays, motor=motor)
        write_atomic(Path(args.setpoints), sp.csv_text())
        outputs["setpoints"] = args.setpoints
    if args.plot:
        from .plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot)
        outputs["plot"] = args.plot
    summary = {
        "robot": robot.name,
        "method": method,
        "duration": traj.duration,
        "q_from": traj.q_start.tolist(),
        "q_to": traj.q_end.tolist(),
        "limit_ratios": {"velocity": ratios.velocity, "acceleration": ratios.acceleration,
                         "tool_speed": ratios.tool_speed, "torque": ratios.torque},  # fmt: skip
        "outputs": outputs,
        "units": {"length": "m", "angle": "rad", "time": "s"},
    }
    if args.json:
        if not args.out:
            summary["samples"] = traj.resample(args.rate).to_dict()
        print(json.dumps(summary))
        return 0
    print(f"robot     {robot.name}: {method}")
    print(f"duration  {traj.duration:.9g} s")
    print(f"from      {_fmt(traj.q_start)}  [SI]")
    print(f"to        {_fmt(traj.q_end)}  [SI]")
    print(f"limits    worst |v|/vmax {ratios.velocity:.6f}, |a|/amax {ratios.acceleration:.6f} (sampled at 1 kHz)")
    for kind, where in outputs.items():
        print(f"wrote     {kind}: {where}")
    return 0


def cmd_workspace(args: argparse.Namespace) -> int:
    """The exact reachable region (arcs, area, radii), a ray query to its edge, and a picture."""
    from .workspace import plot_workspace, workspace

    units = Units(False, args.mm)
    L = units.length
    robot = _load(args, units)
    if robot.kind == "palletizer":
        return _palletizer_workspace(args, robot, units)
    ws = workspace(robot)
    hit = None
    if args.ray:
        start = [_number(n, t) / L for n, t in zip(("x", "y"), args.ray[:2])]
        direction = [_number(n, t) for n, t in zip(("dx", "dy"), args.ray[2:])]
        if (args.z is None) != (args.dz is None):
            raise InvalidInputError("--z and --dz go together (a 3-D ray also meets the J3 stroke)")
        if args.z is not None:
            start.append(_number("--z", args.z) / L)
            direction.append(_number("--dz", args.dz))
        hit = ws.ray(start, direction)
    elif args.z is not None or args.dz is not None:
        raise InvalidInputError("--z/--dz go with --ray")
    if args.plot:
        ray = None if hit is None else (start[:2], direction[:2])
        plot_workspace(ws, args.plot, ray=ray)
    if args.json:
        out: dict[str, Any] = {"robot": robot.name, "units": {"length": "m", "angle": "rad"}}
        if hit is not None:
            out["ray"] = {"start": start, "direction": direction, **hit.to_dict()}
        else:
            out["workspace"] = ws.to_dict()
        if args.plot:
            out["plot"] = args.plot
        print(json.dumps(out))
        return 0
    if hit is not None:
        origin = _fmt([v * L for v in start])
        print(f"robot     {robot.name}: ray from {origin} [{units.length_name}] along {_fmt(direction)}")
        print(f"edge      {_fmt([v * L for v in hit.point])} [{units.length_name}]")
        print(f"distance  {hit.distance * L:.9g} {units.length_name}")
        print(f"stopped by {hit.description} [{hit.limit.value}]")
    else:
        z0, z1 = ws.z_range
        print(f"robot     {robot.name}: reachable region of the wrist axis (= tool point without tool offset)")
        print(f"area      {ws.area * L * L:.9g} {units.length_name}^2")
        print(f"radius    {ws.r_min * L:.9g} .. {ws.r_max * L:.9g} {units.length_name} (from the J1 axis)")
        print(f"z         {z0 * L:.9g} .. {z1 * L:.9g} {units.length_name} (J3 stroke)")
        print(f"boundary  {len(ws.loops)} loop(s) of {len(ws.arcs)} arcs (centre, radius, start..end angle, limit):")
        for i, arc in enumerate(ws.arcs):
            cx, cy = (v * L for v in arc.center)
            print(f"  {i:>2}  ({cx: .6g}, {cy: .6g})  r {arc.radius * L:.6g}  "
                  f"{math.degrees(arc.start):8.3f}..{math.degrees(arc.end):8.3f} deg  {arc.description}")  # fmt: skip
    if args.plot:
        print(f"wrote     {args.plot}")
    return 0


def _palletizer_workspace(args: argparse.Namespace, robot: Robot, units: Units) -> int:
    """The palletizer's reach envelope of tool0 in its arm plane (r from the waist axis, z)."""
    from .palletizer_workspace import arm_plane_envelope, plot_envelope

    if args.ray or args.z is not None or args.dz is not None:
        raise InvalidInputError("--ray/--z/--dz are SCARA-only for now; a palletizer gets its arm-plane envelope")
    env = arm_plane_envelope(robot.palletizer)
    if args.plot:
        plot_envelope(env, args.plot)
    if args.json:
        out: dict[str, Any] = {"robot": robot.name, "units": {"length": "m", "angle": "rad"},
                               "envelope": env.to_dict()}  # fmt: skip
        if args.plot:
            out["plot"] = args.plot
        print(json.dumps(out))
        return 0
    L, name = units.length, units.length_name
    print(f"robot     {robot.name}: reach envelope of {robot.tool_frame} in the arm plane (r from the waist axis, z)")
    print(f"area      {env.area * L * L:.9g} {name}^2")
    print(f"r range   [{env.r_range[0] * L:.9g}, {env.r_range[1] * L:.9g}] {name}")
    print(f"z range   [{env.z_range[0] * L:.9g}, {env.z_range[1] * L:.9g}] {name}")
    print(f"arcs      {len(env.arcs)} (centre, radius [{name}], phi from the vertical [rad])")
    for a in env.arcs:
        print(f"  {a.limit:<13} centre {_fmt([v * L for v in a.center])} radius {a.radius * L:.9g} "
              f"phi [{a.start:.9g}, {a.start + a.sweep:.9g}]")  # fmt: skip
    if args.plot:
        print(f"wrote     {args.plot}")
    return 0


def cmd_jog(args: argparse.Namespace) -> int:
    """Jog to the edge: a straight tool move along a direction, ending at rest on the workspace edge."""
    from .jog import jog_to_edge

    units = Units(args.deg, args.mm)
    robot = _load(args, units)
    if robot.kind != "scara":
        raise InvalidInputError(f"jog is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
    q0 = _joint_arg(robot, args.from_q, units, "--from")
    direction = [_number(f"direction {i + 1}", t) for i, t in enumerate(args.direction)]
    if len(direction) not in (2, 3):
        raise ParameterError("--direction", " ".join(args.direction), "must be DX DY or DX DY DZ")
    margin = _number("--margin", args.margin) / units.length
    jog = jog_to_edge(robot, q0, direction, margin=margin)
    traj = jog.trajectory
    if args.out:
        out = Path(args.out)
        (traj.to_json if out.suffix.lower() == ".json" else traj.to_csv)(out, rate=args.rate)
    if args.plot:
        from .plots import plot_trajectory

        plot_trajectory(traj, args.plot, robot=robot)
    if args.json:
        print(json.dumps({"robot": robot.name, "hit": jog.hit.to_dict(), "start_pose": jog.start_pose.tolist(),
                          "end_pose": jog.end_pose.tolist(), "distance": jog.distance, "duration": traj.duration,
                          "q_end": traj.q_end.tolist(), "limit_ratio": jog.ratio,
                          "units": {"length": "m", "angle": "rad", "time": "s"}}))  # fmt: skip
        return 0
    L = units.length
    print(f"robot     {robot.name}: jog to the edge along {_fmt(direction)}")
    print(f"edge      {jog.hit.description} [{jog.hit.limit.value}]")
    print(f"travel    {jog.distance * L:.9g} {units.length_name} in {traj.duration:.6g} s (at rest at both ends)")
    print(f"end pose  {_fmt([*(v * L for v in jog.end_pose[:3]), jog.end_pose[3]])}  [{units.length_name}, rad]")
    print(f"limits    worst ratio {jog.ratio:.6f} (sampled at 10 kHz)")
    for what in (args.out, args.plot):
        if what:
            print(f"wrote     {what}")
    return 0


def cmd_view(args: argparse.Namespace) -> int:
    """Show the robot in the browser (meshcat): a configuration, a trajectory, the workspace boundary."""
    import numpy as np

    from . import viz

    units = Units(args.deg, args.mm)
    robot = _load(args, units)
    q = None
    if args.q:
        q = robot.check_q(_q_values(args.q, units))
        for item in robot.outside_limits(q):
            log.warning("%s (shown anyway)", item)
    times = qs = None
    if args.traj:
        times, qs = viz.read_trajectory_csv(args.traj)
    polylines = None
    if args.workspace:
        from .workspace import workspace

        if robot.kind != "scara":
            raise InvalidInputError(f"view --workspace is SCARA-only for now; robot {robot.name!r} is a {robot.kind}")
        ws = workspace(robot)
        polylines = [arc.points(max(8, int(math.degrees(arc.sweep)))) for arc in ws.arcs]
    if args.html:
        viz.export_html(robot, args.html, q=q, times=times, qs=qs, polylines=polylines,
                        title=f"scara-pin: {robot.name}")  # fmt: skip
        print(f"wrote {args.html} (self-contained; open it from disk, no network needed)")
        return 0
    with viz.Viewer(robot, open=args.open) as viewer:
        if polylines is not None:
            viewer.draw_polylines(polylines)
        if times is not None and qs is not None:
            viewer.draw_tool_path(qs)
            viewer.animate(times, qs, loop=True)
        else:
            viewer.display(q if q is not None else np.zeros(4))
        print(f"meshcat viewer: {viewer.url}  (serving on 127.0.0.1 until Ctrl-C)", flush=True)
        try:
            viewer.serve()
        except KeyboardInterrupt:
            print("stopped", file=sys.stderr)
    return 0


# ---------------------------------------------------------------------------------------------- plumbing
def write_atomic(path: Path, text: str) -> None:
    """Write a text file atomically (see :mod:`scara_pin.files`)."""
    write_text_atomic(path, text)


def _add_units(
    p: argparse.ArgumentParser, *, deg: bool = True, mm: bool = True, json_help: str | None = "print one JSON object",
    inputs: bool = False,
) -> None:
    """The shared unit and output switches: --deg, --mm (human units) and --json."""
    scope = " (inputs)" if inputs else ""
    if deg:
        p.add_argument("--deg", action="store_true", help=f"angles in degrees{scope}")
    if mm:
        p.add_argument("--mm", action="store_true", help=f"lengths in millimetres{scope}")
    if json_help is not None:
        p.add_argument("--json", action="store_true", help=json_help)


def _add_robot_options(p: argparse.ArgumentParser, urdf_file: bool = True) -> None:
    g = p.add_argument_group("robot")
    g.add_argument("--robot", default="default", metavar="NAME|CONFIG_DIR",
                   help="shipped robot name (see `scara-pin robots`) or a folder of yaml files "
                   "(default: default)")  # fmt: skip
    g.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a parameter, SI units (e.g. --set l1=0.25); repeatable")  # fmt: skip
    if urdf_file:
        g.add_argument("--urdf", metavar="FILE", help="load this URDF file instead of a configured robot")


def _add_q(p: argparse.ArgumentParser) -> None:
    p.add_argument("q", nargs="*", metavar="Q",
                   help="joint values q1 q2 q3 q4 (URDF order; SCARA: q3 > 0 lowers the quill; "
                   "palletizer: q1 q2 theta3 q4, theta3 the small arm's absolute angle)")  # fmt: skip
    _add_units(p)
    p.add_argument("--strict", action="store_true", help="refuse (exit 3) a q outside the joint limits")
    _add_robot_options(p)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``scara-pin``."""
    from . import __version__

    parser = _Parser(
        prog="scara-pin",
        description="Kinematics of SCARA robots from one xacro/URDF description (Pinocchio inside). "
        "SI units unless --deg/--mm; exit codes: 0 ok, 2 invalid input, 3 infeasible, 1 internal error.",
    )
    parser.add_argument("--version", action="version", version=f"scara-pin {__version__}")
    parser.add_argument("-v", "--verbose", action="store_true", help="log details to stderr")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

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
    p.add_argument("file", metavar="FILE.urdf", help="the URDF to check")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("fk", help="forward kinematics: pose of tool0 in the base frame")
    _add_q(p)
    p.set_defaults(func=cmd_fk)

    p = sub.add_parser("jacobian", help="task Jacobian d(x, y, z, yaw)/dq (or a 6 x 4 frame Jacobian)")
    _add_q(p)
    p.add_argument("--reference", default="task", choices=["task", "world", "local", "local_world_aligned"],
                   help="task (4 x 4, default) or a Pinocchio reference frame for the 6 x 4 Jacobian")  # fmt: skip
    p.add_argument("--frame", default=None, help="frame of the 6 x 4 Jacobian (default: tool0)")
    p.set_defaults(func=cmd_jacobian)

    p = sub.add_parser("ik", help="inverse kinematics: every joint solution for a tool pose X Y Z YAW")
    p.add_argument("target", nargs="*", metavar="X Y Z YAW", help="tool0 pose in the base frame")
    p.add_argument("--branch", default="all", choices=["all", "left", "right", "up", "down"],
                   help="elbow branch: a SCARA's right (elbow turns counterclockwise seen from above) or left; "
                   "a palletizer's up (sin q3 > 0, S2's q3) or down; default all")  # fmt: skip
    p.add_argument("--near", nargs=4, metavar="Q", help="return only the solution nearest to this configuration")
    p.add_argument("--numeric", action="store_true", help="use Pinocchio-based numeric IK instead of the closed form")
    p.add_argument("--input", metavar="CSV", help="batch: targets with header x,y,z,yaw (one solution per row)")
    p.add_argument("--output", metavar="CSV", help="batch: joints written here (atomically), with a status column")
    _add_units(p)
    _add_robot_options(p)
    p.set_defaults(func=cmd_ik)

    p = sub.add_parser("traj", help="trajectory: quintic, time-optimal (TOPP-RA) or straight tool line; export, plot")
    g = p.add_argument_group("endpoints (joint values in URDF order, or tool poses X Y Z YAW)")
    g.add_argument("--from", dest="from_q", nargs=4, metavar="Q", help="start configuration")
    g.add_argument("--to", dest="to_q", nargs=4, metavar="Q", help="end configuration")
    g.add_argument("--from-pose", nargs=4, metavar="P", help="start pose (IK: the solution nearest mid-range)")
    g.add_argument("--to-pose", nargs=4, metavar="P", help="end pose (IK: the solution nearest the previous point)")
    g.add_argument("--via", nargs=4, action="append", metavar="Q", help="via configuration (repeatable)")
    g = p.add_argument_group("timing")
    g.add_argument("--duration", type=float, metavar="T",
                   help="quintic time law over T seconds (checked against the limits)")  # fmt: skip
    g.add_argument("--optimal", action="store_true", help="time-optimal under the joint limits (the default)")
    g.add_argument("--linear", action="store_true", help="straight tool line (S4), one elbow branch, J4 continuous")
    g.add_argument("--tool-speed", type=float, metavar="V", help="also limit the tool speed [m/s, or mm/s with --mm]")
    g.add_argument("--torque", action="store_true", help="also respect the effort limits (RNEA, URDF inertias)")
    g.add_argument("--strict", action="store_true", help="refuse (exit 3) a --duration that exceeds a limit")
    g = p.add_argument_group("outputs (files in SI units)")
    g.add_argument("--rate", type=float, default=1000.0, metavar="HZ",
                   help="sampling rate of --out and --json (default 1000)")  # fmt: skip
    g.add_argument("--out", metavar="FILE", help="samples t, q, qd, qdd as CSV (or JSON for *.json), atomically")
    g.add_argument("--plot", metavar="PNG", help="q, qd, qdd against time with limits, and the tool path")
    g.add_argument("--setpoints", metavar="CSV", help="controller setpoints (S4) at --setpoint-rate")
    g.add_argument("--setpoint-rate", type=float, metavar="HZ", help="setpoint rate (default: --rate)")
    g.add_argument("--delays", nargs=4, metavar="S", help="per-axis command latency [s], compensated")
    g.add_argument("--gear", nargs=4, metavar="G", help="gear ratios (motor turns per joint/screw turn)")
    g.add_argument("--steps-per-rev", nargs=4, metavar="N", help="motor steps per motor turn")
    g.add_argument("--screw-lead", metavar="L", help="quill screw travel per turn [m, or mm with --mm]")
    _add_units(p, inputs=True, json_help="print one JSON object (with the samples unless --out)")
    _add_robot_options(p)
    p.set_defaults(func=cmd_traj)

    p = sub.add_parser("workspace", help="exact reachable region (arcs, area, radii); --ray: the edge along a ray")
    p.add_argument("--ray", nargs=4, metavar=("X", "Y", "DX", "DY"), help="start inside the region and plan direction")
    p.add_argument("--z", metavar="Z", help="with --ray: start height (a 3-D ray also meets the J3 stroke)")
    p.add_argument("--dz", metavar="DZ", help="with --ray: vertical direction component")
    p.add_argument("--plot", metavar="PNG", help="picture of the region (arcs coloured by limit; the ray)")
    _add_units(p, deg=False)
    _add_robot_options(p)
    p.set_defaults(func=cmd_workspace)

    p = sub.add_parser("jog", help="jog to the edge: straight tool move ending at rest on the workspace edge")
    p.add_argument("--from", dest="from_q", nargs=4, metavar="Q", required=True, help="current configuration")
    p.add_argument("--direction", nargs="+", metavar="D", required=True, help="DX DY (plan) or DX DY DZ")
    p.add_argument("--margin", default="0", metavar="M", help="stop this far before the edge [m or mm] (default 0)")
    p.add_argument("--rate", type=float, default=1000.0, metavar="HZ", help="sampling rate of --out (default 1000)")
    p.add_argument("--out", metavar="FILE", help="samples as CSV (or JSON for *.json), atomically")
    p.add_argument("--plot", metavar="PNG", help="q, qd, qdd against time and the tool path")
    _add_units(p, inputs=True)
    _add_robot_options(p)
    p.set_defaults(func=cmd_jog)

    p = sub.add_parser("view", help="show the robot in the browser (meshcat); --html writes a standalone page")
    p.add_argument("--q", nargs=4, metavar="Q", help="configuration to show (default: zero)")
    p.add_argument("--traj", metavar="CSV", help="animate a trajectory (a `traj --out` CSV) and draw the tool path")
    p.add_argument("--workspace", action="store_true", help="draw the workspace boundary on the floor")
    p.add_argument("--html", metavar="FILE", help="write one self-contained HTML page (works offline) and exit")
    p.add_argument("--open", action="store_true", help="open the page in the web browser")
    _add_units(p, json_help=None)
    _add_robot_options(p)
    p.set_defaults(func=cmd_view)

    p = sub.add_parser("validate-ik", help="cross-validate closed-form IK against Pinocchio FK and numeric IK")
    p.add_argument("--samples", type=int, default=1000, help="configurations sampled within limits (default 1000)")
    p.add_argument("--seed", type=int, default=0, help="sampling seed (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    _add_robot_options(p)
    p.set_defaults(func=cmd_validate_ik)
    return parser


class _Formatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        return f"{record.levelname.lower()}: {record.getMessage()}"


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``scara-pin`` with ``argv`` (default: ``sys.argv[1:]``) and return the exit code."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(_Formatter())
    log.addHandler(handler)
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except _UsageError as exc:
            print(f"error: {exc} (see scara-pin --help)", file=sys.stderr)
            return 2
        except SystemExit as exc:  # --help, --version
            return exc.code if isinstance(exc.code, int) else 0
        log.setLevel(logging.DEBUG if args.verbose else logging.WARNING)
        func: Callable[[argparse.Namespace], int] | None = getattr(args, "func", None)
        if func is None:
            print("error: no command given (see scara-pin --help)", file=sys.stderr)
            return 2
        return func(args)
    except ScaraError as exc:
        print(f"error: {_one_line(exc)}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader went away (e.g. `| head`): not an error of ours
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except Exception as exc:  # a bug: say so in one line; SCARA_PIN_DEBUG=1 shows the traceback
        if os.environ.get("SCARA_PIN_DEBUG"):
            raise
        print(f"error: internal error ({type(exc).__name__}: {_one_line(exc)}); "
              "please report it; SCARA_PIN_DEBUG=1 shows the traceback", file=sys.stderr)  # fmt: skip
        return 1
    finally:
        log.removeHandler(handler)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
