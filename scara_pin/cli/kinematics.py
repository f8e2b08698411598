"""Commands of the kinematics layer: ``fk``, ``jacobian``, ``ik``, ``validate-ik``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InfeasibleError, InvalidInputError, ParameterError, UrdfError
from ..model import pose_from_placement
from ..units import decimals_for, format_number
from ._joints import check_limits, needs_wrist, q_values, read_pose
from ._numbers import integer_type
from ._options import add_cell_options, add_q, add_robot_options, add_units
from ._outputs import check_command_outputs, log
from ._robot import cell_from_args, robot_from_args
from ._units import POSE_KINDS, Q_NAMES, Units

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..robots import Robot


_SI_UNITS = {"length": "m", "angle": "rad"}
"""The ``units`` of every JSON output: SI, whatever --deg/--mm (they scale inputs and text)."""


def cmd_fk(args: argparse.Namespace) -> int:
    """Forward kinematics: the pose of tool0 in the base frame."""
    units = Units.from_args(args)
    robot = robot_from_args(args, units)
    q = check_limits(robot, q_values(args.q, units), units, args.strict)
    M = robot.tool_placement(q)
    pose = pose_from_placement(M)
    if args.json:  # always SI (docs/cli.md: "--json output is always SI")
        out = {
            "robot": robot.name,
            "q": q.tolist(),
            "position": [float(v) for v in pose[:3]],
            "yaw": float(pose[3]),
            "matrix": M.homogeneous.tolist(),
            "frame": robot.tool_frame,
            "reference": robot.base_frame,
            "units": _SI_UNITS,
        }
        if robot.geared:
            out["geared"] = _geared(robot, q)
        print(json.dumps(out))
        return 0
    print(f"robot     {robot.name}: {robot.tool_frame} in {robot.base_frame}")
    print(f"q         {units.fmt(q, units.q)}  [{', '.join(units.names(units.q))}]")
    print(f"position  {units.fmt(pose[:3], 'length')}  [{units.length_name}]")
    print(f"yaw       {units.num(pose[3], 'angle')}  [{units.angle_name}]")
    if robot.geared:
        print(f"geared    {_geared_text(robot, q, units)}")
    # the rotation (no unit) to 1e-9 and the translation in the user's length unit, in aligned columns
    H = M.homogeneous
    cells = [[format_number(v, 9) for v in row[:3]] + [units.num(row[3], "length")] for row in H[:3]]
    cells.append([format_number(v, 9) for v in H[3]])
    width = max(len(c) for row in cells for c in row)
    print(f"matrix    (rotation [-], translation [{units.length_name}])")
    for row in cells:
        print("          [" + ", ".join(c.rjust(width) for c in row) + "]")
    return 0


def cmd_jacobian(args: argparse.Namespace) -> int:
    """The task Jacobian d(x, y, z, yaw)/dq, or Pinocchio's 6 x 4 frame Jacobian."""
    units = Units.from_args(args)
    robot = robot_from_args(args, units)
    q = check_limits(robot, q_values(args.q, units), units, args.strict)
    if args.reference == "task":
        if args.frame is not None:
            raise InvalidInputError("--frame goes with --reference world|local|local_world_aligned")
        J = robot.task_jacobian(q)
        rows = ["x", "y", "z", "yaw"]
        row_kinds: tuple[str, ...] = POSE_KINDS
    else:
        J = robot.frame_jacobian(q, args.frame, args.reference)
        rows = ["vx", "vy", "vz", "wx", "wy", "wz"]
        row_kinds = ("length",) * 3 + ("angle",) * 3
    w = robot.manipulability(q)
    if args.json:  # always SI (docs/cli.md: "--json output is always SI")
        out = {
            "robot": robot.name,
            "q": q.tolist(),
            "reference": args.reference,
            "frame": args.frame or robot.tool_frame,
            "rows": rows,
            "jacobian": J.tolist(),
            "manipulability": w,
            "units": _SI_UNITS,
        }
        print(json.dumps(out))
        return 0
    # J_user[i, j] = J[i, j] * (unit of row i) / (unit of column j), printed to 1e-9 SI in that unit
    ratio = np.array(units.scale(row_kinds))[:, None] / np.array(units.scale(units.q))[None, :]
    cells = [[format_number(v, decimals_for(r)) for v, r in zip(row, rrow)] for row, rrow in zip(J * ratio, ratio)]
    width = max(16, *(len(c) + 2 for row in cells for c in row))
    print(f"robot     {robot.name}: {args.reference} Jacobian of {args.frame or robot.tool_frame}")
    print(f"q         {units.fmt(q, units.q)}  [{', '.join(units.names(units.q))}]")
    heads = [f"d/dq{i + 1} [/{u}]" for i, u in enumerate(units.names(units.q))]
    print("          " + "".join(h.rjust(width) for h in heads))
    for name, unit, row in zip(rows, units.names(row_kinds), cells):
        print(f"{f'{name} [{unit}]':<10}" + "".join(c.rjust(width) for c in row))
    print(f"manipulability sqrt(det(J J^T)) of the task Jacobian (SI): {format_number(w, 9)}")
    return 0


def _geared(robot: Robot, q: ArrayLike) -> dict[str, float]:
    """The values of the geared (``<mimic>``) joints at ``q`` [rad, m]; a warning for any outside its own limits."""
    out = {}
    for g in robot.geared:
        out[g.name] = value = g.value(q)  # type: ignore[arg-type]
        if g.outside_limits(value):
            log.warning("geared joint %s = %.9g is outside its own URDF limits [%.9g, %.9g] (%s)", g.name, value,
                        g.lower, g.upper, g.describe())  # fmt: skip
    return out


def _geared_text(robot: Robot, q: ArrayLike, units: Units) -> str:
    """``wrist = 1.3 rad (= 1 * arm1 + 1)``, per geared joint, in the user's units."""
    values = _geared(robot, q)
    parts = []
    for g in robot.geared:
        unit = units.angle_name if g.kind == "angle" else units.length_name
        parts.append(f"{g.name} = {units.num(values[g.name], g.kind)} {unit} ({format_number(g.multiplier, 9)} * "
                     f"{g.source_name} + {units.num(g.offset, g.kind)})")  # fmt: skip
    return "; ".join(parts)


def cmd_ik(args: argparse.Namespace) -> int:
    """Inverse kinematics: every joint solution for a tool pose (closed form, or numeric)."""
    units = Units.from_args(args)
    if args.input:  # refused before any work: --output must not be --input (nor a device)
        check_command_outputs(args, {"--output": args.output})
    robot = robot_from_args(args, units)
    if args.input:
        if args.numeric:
            raise InvalidInputError("--numeric goes with one target X Y Z YAW; ik --input (batch) is closed-form only")
        return _ik_batch(args, robot, units)
    if args.input is None and args.output:
        raise InvalidInputError("--output goes with --input (batch mode)")
    target = read_pose(args.target, units, dof=robot.dof)
    near = _near(robot, args.near, units) if args.near else None
    numeric = args.numeric
    if robot.kind == "palletizer":
        if args.branch in ("left", "right"):
            raise InvalidInputError(f"--branch {args.branch} is a SCARA branch; a palletizer's are up and down")
    elif args.branch in ("up", "down"):
        raise InvalidInputError(f"--branch {args.branch} is a palletizer branch; a SCARA's are left and right")
    if args.all_turns and (numeric or near is not None):
        raise InvalidInputError("--all-turns lists every closed-form solution: not with --numeric or --near")
    if not numeric:
        try:
            _ = robot.kinematics  # extracted on first use: refused here if the model is not its kind's
        except UrdfError as exc:  # NotScaraError, NotPalletizerError
            log.warning("closed-form IK refused this robot (%s); using the numeric IK", exc)
            numeric = True
    if numeric and args.branch != "all":  # the numeric IK lands where its seed leads: no branch to choose
        raise InvalidInputError("--branch chooses among the closed form's solutions; the numeric IK follows its "
                                "seed: give --near Q (a configuration on the wanted branch) instead")
    turns: list[Any] = []
    if numeric:
        status, message, qs, branches = _ik_numeric(robot, target, near)
    else:
        # --all-turns: InvalidInputError (exit 2) above MAX_SOLUTIONS, counted before any is built
        result = robot.ik(target, branch=args.branch, reference=near, all_turns=args.all_turns)
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
        turns = [[list(t) if t is not None else None for t in s.turns] for s in sols]
    refused: list[dict[str, Any]] = []
    cell = cell_from_args(args, units)
    if cell is not None:
        qs, branches, turns, refused = _clear_solutions(robot, cell, qs, branches, turns)
        if refused and not qs:
            status = "COLLISION"
            message = "every solution collides: " + "; ".join(f"{r['branch']}: {r['reason']}" for r in refused)
    code = 0 if status == "OK" else 3
    if args.json:  # always SI (docs/cli.md: "--json output is always SI")
        solutions: list[dict[str, Any]] = [{"q": [float(v) for v in q], "branch": b} for q, b in zip(qs, branches)]
        for sol, t in zip(solutions, turns):
            sol["turns"] = t
        if robot.geared:  # the joints that follow (not degrees of freedom): their values at each solution
            for sol, q in zip(solutions, qs):
                sol["geared"] = _geared(robot, q)
        out = {"robot": robot.name, "target": dict(zip(("x", "y", "z", "yaw"), map(float, target))),
               "solutions": solutions, "status": status, "message": message,
               "method": "numeric" if numeric else "closed-form", "units": _SI_UNITS}  # fmt: skip
        if cell is not None:
            out["cell"] = {"file": cell.origin, "margin": cell.margin, "refused": refused}
        print(json.dumps(out))
        return code
    if code:
        raise InfeasibleError(f"{status}: {message}")
    method = "numeric" if numeric else "closed-form"
    print(f"robot     {robot.name}: {method} IK of {robot.tool_frame} in {robot.base_frame}")
    kinds = POSE_KINDS[: len(target)]
    print(f"target    {units.fmt(target, kinds)}  [{', '.join(units.names(kinds))}]")
    print(f"units     q = [{', '.join(units.names(units.q))}]")
    for i, (q, b) in enumerate(zip(qs, branches)):
        extra = ""
        if turns and not args.all_turns and any(t is None or t != [0, 0] for t in turns[i]):
            extra = "  turns " + " ".join(f"{n}:{'any' if t is None else t}" for n, t in zip(Q_NAMES, turns[i])
                                          if t != [0, 0])  # fmt: skip
        print(f"{b:<9} {units.fmt(q, units.q)}{extra}")
        if robot.geared:
            print(f"  geared  {_geared_text(robot, q, units)}")
    for r in refused:
        print(f"{r['branch']:<9} {units.fmt(r['q'], units.q)}  refused: COLLISION, {r['reason']}")
    return 0


def _clear_solutions(robot: Robot, cell: Any, qs: list[Any], branches: list[str], turns: list[Any]
                     ) -> tuple[list[Any], list[str], list[Any], list[dict[str, Any]]]:  # fmt: skip
    """The solutions clear of ``cell`` (every checked pair at least the margin apart), and the others refused.

    Each refused one: its q, branch, the reason code ``COLLISION``, the closest pair and its distance [m].
    """
    from ..cell import describe, scene

    sc = scene(robot, cell)
    keep: list[int] = []
    refused: list[dict[str, Any]] = []
    for i, (q, b) in enumerate(zip(qs, branches)):
        closest = sc.distances(q).closest
        if closest is not None and closest.distance < sc.margin:
            refused.append({"q": np.asarray(q, dtype=float).tolist(), "branch": b, "status": "COLLISION",
                            "pair": [closest.pair.a, closest.pair.b], "distance": closest.distance,
                            "reason": describe(closest, sc.margin)})  # fmt: skip
        else:
            keep.append(i)
    return [qs[i] for i in keep], [branches[i] for i in keep], [turns[i] for i in keep] if turns else [], refused


def _ik_numeric(robot: Robot, target: Sequence[float], near: np.ndarray | None) -> tuple[str, str, list, list]:
    from ..kinematics.numeric import elbow_sign, solve_numeric

    res = solve_numeric(robot, target, q0=near)
    if not res.success:
        return ("NO_CONVERGENCE", f"numeric IK did not reach the target (residual {res.residual:.3g} after "
                f"{res.iterations} iterations from {res.starts} starts)", [], [])  # fmt: skip
    try:
        branch = robot.branch_of(res.q)
    except UrdfError:  # no closed form for this arm: its elbow's side (elbow+ / elbow-)
        branch = elbow_sign(robot, res.q)
    return "OK", f"converged in {res.iterations} iterations (residual {res.residual:.3g})", [res.q], [branch]


def _near(robot: Robot, texts: Sequence[str], units: Units) -> np.ndarray:
    """``--near``: the reference configuration, checked.

    A joint outside its limits is used as given, with a warning (a reference may lie anywhere, but there
    it is often a unit slip: 50 typed for 0.05 m).
    """
    if len(texts) != robot.dof:
        raise ParameterError("--near", " ".join(texts), f"must be {robot.dof} joint values")
    return check_limits(robot, q_values(texts, units), units,
                        warning="--near: %s (used as given: the solutions nearest to it are returned)")


def _ik_batch(args: argparse.Namespace, robot: Robot, units: Units) -> int:
    """``ik --input CSV --output CSV``: :func:`scara_pin.kinematics.batch_io.solve_csv`, then one line."""
    from ..kinematics.batch_io import solve_csv

    needs_wrist(robot, "ik --input (batch)")
    if args.target:
        raise InvalidInputError("give either X Y Z YAW or --input FILE, not both")
    if not args.output:
        raise InvalidInputError("--input needs --output FILE")
    summary = solve_csv(robot, args.input, args.output, pose_scale=units.scale(POSE_KINDS),
                        q_scale=units.scale(units.q), branch=None if args.branch == "all" else args.branch,
                        reference=_near(robot, args.near, units) if args.near else None, progress=True)  # fmt: skip
    print(f"wrote {summary.output}: {summary.total} targets, {summary.solved} solved, {summary.failed} without "
          "solution", file=sys.stderr)  # fmt: skip
    return 3 if summary.failed else 0


VALIDATION_FAILED = 5
"""Exit code of ``validate-ik`` when the validation fails (1 stays "internal error")."""
MAX_VALIDATION_SAMPLES = 1_000_000


def cmd_validate_ik(args: argparse.Namespace) -> int:
    """Cross-validate the closed-form IK against Pinocchio FK and the numeric IK."""
    from tqdm import tqdm

    from ..kinematics.validate import validate_ik

    robot = robot_from_args(args)
    needs_wrist(robot, "validate-ik")
    # a progress bar on a terminal only (tqdm's own test of stderr)
    with tqdm(total=args.samples, desc="validate-ik", file=sys.stderr, disable=None, leave=False) as bar:
        report = validate_ik(robot, args.samples, args.seed, progress=bar.update)
    if args.json:
        out = {k: v for k, v in vars(report).items()}
        out["ok"] = report.ok
        print(json.dumps(out))
    else:
        print(report.table())
    return 0 if report.ok else VALIDATION_FAILED


def register(sub: Any) -> None:
    """Add the commands of this module to the ``scara-pin`` subparsers."""
    p = sub.add_parser("fk", help="forward kinematics: pose of the tool frame (tool0; --tool) in the base frame")
    add_q(p)
    p.set_defaults(func=cmd_fk)
    p = sub.add_parser("jacobian", help="task Jacobian d(x, y, z, yaw)/dq (or a 6 x 4 frame Jacobian)")
    add_q(p)
    p.add_argument("--reference", default="task", choices=["task", "world", "local", "local_world_aligned"],
                   help="task (4 x 4, default) or a Pinocchio reference frame for the 6 x 4 Jacobian")  # fmt: skip
    p.add_argument("--frame", default=None, help="frame of the 6 x 4 Jacobian (default: tool0)")
    p.set_defaults(func=cmd_jacobian)
    p = sub.add_parser("ik", help="inverse kinematics: every joint solution for a tool pose X Y Z YAW")
    p.add_argument("target", nargs="*", metavar="X Y Z YAW", help="tool0 pose in the base frame (X Y Z for a "
                   "3-joint SCARA: without a wrist the yaw follows the arm)")  # fmt: skip
    p.add_argument("--branch", default="all", choices=["all", "left", "right", "up", "down"],
                   help="elbow branch: a SCARA's right (elbow turns counterclockwise seen from above) or left; "
                   "a palletizer's up (sin q3 > 0, S2's q3) or down; default all")  # fmt: skip
    p.add_argument("--near", nargs="+", metavar="Q", help="return only the solution nearest to this configuration "
                   "(one value per joint)")  # fmt: skip
    p.add_argument("--numeric", action="store_true", help="use Pinocchio-based numeric IK instead of the closed form")
    p.add_argument("--all-turns", action="store_true",
                   help="list every 2 pi turn of every joint inside the limits as its own solution (at most "
                   "100000; by default one solution per branch, each joint at its turn nearest --near or 0, "
                   "with the range of turns that fit)")  # fmt: skip
    p.add_argument("--input", metavar="CSV", help="batch: targets with header x,y,z,yaw (one solution per row)")
    p.add_argument("--output", metavar="CSV", help="batch: joints written here (atomically), with a status column")
    add_units(p)
    add_robot_options(p)
    add_cell_options(p)
    p.set_defaults(func=cmd_ik)
    p = sub.add_parser("validate-ik", help="cross-validate closed-form IK against Pinocchio FK and numeric IK")
    p.add_argument("--samples", type=integer_type("--samples", 1, MAX_VALIDATION_SAMPLES), default=1000,
                   help=f"configurations sampled within limits, 1..{MAX_VALIDATION_SAMPLES} (default 1000)")
    p.add_argument("--seed", type=integer_type("--seed", 0, 2**63 - 1), default=0,
                   help="sampling seed, >= 0 (default 0)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_robot_options(p)
    p.set_defaults(func=cmd_validate_ik)
