"""Rules of scope: whether the toolkit loads the file, and what kind of arm it is (its closed form's verdict).

Each rule is a function of the :class:`~scara_pin.lint.context.Context`; its code and place in the run are in
:data:`scara_pin.lint.registry.RULES`. They read the robot as :class:`scara_pin.model.RobotModel` loads it and its
kinematics as :func:`scara_pin.kinematics.kinds.kinematics_for` builds them: what they say, the commands do.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from .context import Context
from .report import Severity

__all__ = ["EFFORT_SAMPLES", "closed_form_refused", "effort_limit", "motion_limits", "near_parallel", "not_a_scara",
           "not_loadable", "palletizer"]

EFFORT_SAMPLES = 64
"""Configurations (seeded, uniform in the joint ranges; q = 0 too) at which the static loads are compared with the
effort limits."""


def not_loadable(ctx: Context) -> None:
    """Pinocchio or the toolkit's loader refuses the file (its reason quoted)."""
    error = ctx.loaded[1]
    if error is not None:
        ctx.error("not-loadable", f"the toolkit cannot load it: {error}")


def _what_arm(ctx: Context) -> str | None:
    """What an arm the SCARA closed form refuses is, when its layout says (kinds.what_arm)."""
    from ..kinematics.kinds import what_arm
    from ..kinematics.scara import NotScaraError

    return what_arm(ctx.robot) if isinstance(ctx.kinematics[1], NotScaraError) else None  # type: ignore[arg-type]


def not_a_scara(ctx: Context) -> None:
    """An arm of another layout (an R-R-R arm, a palletizer without its parallelogram): what it is, what applies."""
    what = _what_arm(ctx)
    if what is not None:
        ctx.add(Severity.WARNING, "not-a-scara", what[0].upper() + what[1:])


def closed_form_refused(ctx: Context) -> None:
    """The closed form refuses the model (its own reason); only numeric IK applies."""
    error = ctx.kinematics[1]
    if error is not None and _what_arm(ctx) is None and not ctx.found("axis-tilted"):
        ctx.add(Severity.WARNING, "closed-form-refused", f"the closed-form IK refuses it: {error}; only numeric IK "
                "applies")  # fmt: skip


def palletizer(ctx: Context) -> None:
    """Recognised as a palletizer: its closed form applies."""
    robot, (kinematics, _) = ctx.robot, ctx.kinematics
    if robot is not None and kinematics is not None and robot.kind == "palletizer":
        ctx.add(Severity.INFO, "palletizer", "a palletizer (a waist, two parallel horizontal arm joints, the flange "
                "kept level by <mimic> joints): the palletizer's closed form applies")  # fmt: skip


def near_parallel(ctx: Context) -> None:
    """Axes 1e-6 .. 1e-2 rad from vertical: the tilt, and the error the closed form would make without refinement."""
    from ..kinematics.polish import unrefined_error
    from ..kinematics.scara import EXACT_TILT

    robot, (kinematics, _) = ctx.robot, ctx.kinematics
    if robot is None or kinematics is None or robot.kind == "palletizer":
        return
    tilt = getattr(getattr(kinematics, "geometry", None), "tilt", 0.0)
    if tilt <= EXACT_TILT:
        return
    err = unrefined_error(robot)
    # a tilt that comes with an approximate rpy (3.14) is a typo to fix; one written deliberately (measured,
    # calibrated: scara-pin calibrate writes its origins at full precision) is handled exactly: information
    typo = ctx.found("rpy-approximate", Severity.WARNING)
    sev = Severity.WARNING if err.position >= 1e-6 and typo else Severity.INFO
    yaw = f" and {err.yaw:.3g} rad of yaw" if robot.dof == 4 else ""
    ctx.add(sev, "near-parallel",
            f"the joint axes are up to {tilt:.3g} rad ({math.degrees(tilt):.3g} deg) from the base z axis: "
            f"near-parallel; unrefined, the closed form (ideal vertical axes) would miss the tool pose by up to "
            f"{err.position * 1000:.3g} mm{yaw} (max over {err.samples} sampled configurations, seed {err.seed}); "
            "the toolkit refines every solution on the model as written (Newton, to 1e-9)")


def effort_limit(ctx: Context) -> None:
    """An effort limit that stops torque-limited timing: 0 (a placeholder), or below the static load somewhere."""
    robot = ctx.robot
    if robot is None:
        return
    effort, names = np.array(robot.limits.effort, dtype=float), robot.joint_names
    units = ["N" if k == "length" else "N m" for k in robot.joint_kinds]
    zero = [n for n, e in zip(names, effort) if not e > 0.0]
    if zero:
        ctx.add(Severity.WARNING, "effort-limit", f"{', '.join(zero)}: effort limit 0, a placeholder: torque-limited "
                "timing (cycle, traj --torque) refuses it; cycle --no-torque leaves the efforts out")  # fmt: skip
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    qs = np.vstack([robot.default_q, np.random.default_rng(0).uniform(lo, hi, (EFFORT_SAMPLES, robot.dof))])
    data = robot.model.createData()
    g = np.array([pin.computeGeneralizedGravity(robot.model, data, robot.to_pinocchio_q(q)) for q in qs])
    ratio = np.where(effort > 0.0, np.abs(g) / np.where(effort > 0.0, effort, 1.0), 0.0)
    for j in np.flatnonzero(ratio.max(axis=0) >= 1.0).tolist():
        i = int(np.argmax(ratio[:, j]))
        ctx.add(Severity.WARNING, "effort-limit",
                f"the static load on {names[j]} reaches {abs(g[i, j]):.4g} {units[j]} (the weight it carries, at q = "
                f"{np.round(qs[i], 6).tolist()}) against its effort limit {effort[j]:g} {units[j]}: placeholder "
                "efforts or masses? torque-limited timing (cycle, traj --torque) refuses to move it, the robot "
                "cannot even hold still there; cycle --no-torque leaves the efforts out")  # fmt: skip


def motion_limits(ctx: Context) -> None:
    """What cycle, traj, jog and job will ask for that the file does not give.

    Acceleration limits (URDF has none); the velocity limit of a joint without one (a continuous joint without
    ``<limit>``, a placeholder 0).
    """
    robot = ctx.robot
    if robot is None or robot.parameters is not None:
        return
    names = robot.joint_names
    units = ["m" if k == "length" else "rad" for k in robot.joint_kinds]
    needs = []
    velocity = [(n, v) for n, v in zip(names, robot.limits.velocity) if not (math.isfinite(v) and v > 0.0)]
    if velocity:
        why = ", ".join(f"{n} ({'no <limit>' if math.isinf(v) else f'{v:g} in the file'})" for n, v in velocity)
        needs.append(f"--velocity {' '.join(f'V{i + 1}' for i in range(len(names)))} [" + ", ".join(
            f"{n} {u}/s" for n, u in zip(names, units)) + f"]: no velocity limit for {why}")  # fmt: skip
    if not all(math.isfinite(a) for a in robot.limits.acceleration):
        needs.append(f"--acceleration {' '.join(f'A{i + 1}' for i in range(len(names)))} [" + ", ".join(
            f"{n} {u}/s^2" for n, u in zip(names, units)) + "]: a URDF has no acceleration limits")  # fmt: skip
    if needs:
        ctx.add(Severity.INFO, "motion-limits", "cycle, traj, jog and job need what the file does not give: "
                + "; ".join(needs))
