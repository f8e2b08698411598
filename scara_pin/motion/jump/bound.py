"""The jump's lower bound: what no motion of the move can beat (:mod:`~scara_pin.motion.jump`, "Lower bound")."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ...errors import InvalidInputError
from ..trajectory import line_optimal_duration
from .types import LowerBound

if TYPE_CHECKING:
    from ...model import RobotModel

def quill_joint(robot: RobotModel, q: np.ndarray) -> int | None:
    """The joint that alone moves the tool vertically (a SCARA's quill), or None."""
    if robot.kind != "scara":
        return None
    row = robot.task_jacobian(q)[2]
    moving = np.abs(row) > 1e-12
    return int(np.argmax(moving)) if moving.sum() == 1 else None


def one_dof(
    j: int, d: float, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray | None, exact: bool = True,
    name: str = "",
) -> float:
    """[s] joint j's minimum time from rest to rest over a displacement d >= 0 (ruckig with a jerk limit).

    With ``exact`` False and a jerk limit: the larger of the velocity-and-acceleration time and the time with
    the jerk limit alone, (32 d / j)^(1/3) (both below the exact one; no ruckig call: sizes the work first).
    """
    if d == 0.0:
        return 0.0
    dq = np.zeros(len(velocity))
    dq[j] = d
    va = line_optimal_duration(np.zeros(len(velocity)), dq, velocity, acceleration)  # one joint moves
    if jerk is None:
        return va
    if not exact:
        return max(va, (32.0 * d / float(jerk[j])) ** (1.0 / 3.0))
    from ruckig import InputParameter, Result, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [d]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [velocity[j]], [acceleration[j]], [jerk[j]]
    out = RuckigTrajectory(1)
    try:
        result = Ruckig(1).calculate(inp, out)
    except RuntimeError as exc:  # ruckig raises on limits it cannot handle (e.g. 1e-100)
        raise InvalidInputError(f"ruckig could not time a 1-DOF move of {name or j + 1} ({exc})") from None
    if result not in (Result.Working, Result.Finished):
        raise InvalidInputError(f"ruckig could not time a 1-DOF move of {name or j + 1}: {result}")
    return float(out.duration)


def lower_bound(
    robot: RobotModel,
    q_from: np.ndarray,
    q_to: np.ndarray,
    q_tops: tuple[np.ndarray, np.ndarray],
    velocity: np.ndarray,
    acceleration: np.ndarray,
    jerk: np.ndarray | None = None,
    *,
    exact_jerk: bool = True,
    tool_speed: float | None = None,
) -> LowerBound:
    """The slowest joint's own minimum time for what it must do (module docstring, "Lower bound").

    Args:
        robot: the robot.
        q_from: the configuration at the start pose.
        q_to: the configuration at the end pose.
        q_tops: the configurations at the traverse height above them (the quill's required stroke).
        velocity: per-joint limits [rad/s, m/s].
        acceleration: per-joint limits [rad/s^2, m/s^2].
        jerk: per-joint limits [rad/s^3, m/s^3], or None.
        exact_jerk: the jerk-limited 1-DOF times from ruckig (False: a cheaper, lower bound of them).
        tool_speed: [m/s] a limit of the tool origin's speed, or None (module docstring, "Lower bound").
    """
    quill = quill_joint(robot, q_from)
    names = robot.joint_names
    best = LowerBound(0.0, names[0], "no joint moves")
    kind = "velocity, acceleration and jerk" if jerk is not None else "velocity and acceleration"
    for j in range(robot.dof):
        if j == quill:
            up = abs(q_tops[0][j] - q_from[j])
            down = abs(q_tops[1][j] - q_to[j])
            t = one_dof(j, up, velocity, acceleration, None) + one_dof(j, down, velocity, acceleration, None)
            why = (f"{names[j]} alone, up {up:.6g} m and down {down:.6g} m, each from rest to rest, velocity and "
                   "acceleration limits")  # fmt: skip
        else:
            d = float(q_to[j] - q_from[j])
            t = one_dof(j, abs(d), velocity, acceleration, jerk, exact_jerk, names[j])
            unit = "m" if robot.joint_kinds[j] == "length" else "rad"
            why = f"{names[j]} alone, {abs(d):.6g} {unit} from rest to rest, {kind} limits"
        if t > best.duration:
            best = LowerBound(t, names[j], why)
    if tool_speed is not None:
        a, b = robot.tool_pose(q_from)[:3], robot.tool_pose(q_to)[:3]
        z_top = max(float(np.asarray(robot.tool_pose(q))[2]) for q in q_tops)
        length = math.hypot(float(np.hypot(*(b[:2] - a[:2]))), max(0.0, z_top - a[2]) + max(0.0, z_top - b[2]))
        t = length / tool_speed
        if t > best.duration:
            best = LowerBound(t, "tool", f"the tool alone, at least {length:.6g} m (up to the clearance height and "
                              f"down, straight) at {tool_speed:.6g} m/s")  # fmt: skip
    return best
