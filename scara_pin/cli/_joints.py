"""Joint values and tool poses as typed, in SI, and the checks they go through (joint count, limits, a wrist)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ._numbers import number
from ._outputs import log
from ._units import POSE_KINDS, Q_NAMES, Units

if TYPE_CHECKING:
    import numpy as np

    from ..robots import Robot


def q_values(texts: Sequence[str], units: Units, what: str = "") -> list[float]:
    """Joint values as typed (units per --deg/--mm and the robot's joint kinds) in SI, each a finite number."""
    prefix = f"{what} " if what else ""
    if len(texts) != len(units.q):  # never truncated by the zip below
        raise ParameterError(what or "q", " ".join(texts), f"must be {len(units.q)} joint values (got {len(texts)})")
    units.guard([prefix + n for n in Q_NAMES], texts, units.q)
    return [number(prefix + n, t) / sc for n, t, sc in zip(Q_NAMES, texts, units.scale(units.q))]


def check_limits(robot: Robot, values: Sequence[float], units: Units, strict: bool = False,
                 warning: str = "%s (computed anyway; --strict refuses)") -> np.ndarray:
    """``values`` as q; refused if they cannot be computed, each joint outside its limits a warning (or refused)."""
    q = robot.check_q(values)  # a q that cannot be computed is an error, never first a "computed anyway" warning
    outside = robot.outside_limits(q, units=units.display)
    if outside and strict:
        raise InfeasibleError("q outside the joint limits (--strict): " + "; ".join(outside))
    for item in outside:
        log.warning(warning, item)
    return q


def joint_arg(robot: Robot, texts: Sequence[str], units: Units, what: str) -> np.ndarray:
    """A configuration option (``--from``, ``--via``, ...) as typed, in SI; refused outside the joint limits."""
    q = robot.check_q(q_values(texts, units, what))
    outside = robot.outside_limits(q, tol=1e-12, units=units.display)
    if outside:
        raise InfeasibleError(f"{what} is outside the joint limits: " + "; ".join(outside))
    return q


def read_pose(texts: Sequence[str], units: Units, what: str = "target", dof: int = 4) -> list[float]:
    """A tool pose as typed: X Y Z YAW, or X Y Z for a 3-joint SCARA (``dof`` 3: no wrist, no yaw to choose)."""
    if dof == 3:
        if len(texts) == 4:
            raise InvalidInputError(f"this robot has 3 joints and no wrist: the tool's yaw cannot be chosen; "
                                    f"{what} takes X Y Z for such an arm (got 4 values)")  # fmt: skip
        if len(texts) != 3:
            raise ParameterError(what, " ".join(texts), f"must be 3 values X Y Z (got {len(texts)})")
    elif len(texts) != 4:
        raise ParameterError(what, " ".join(texts), f"must be 4 values X Y Z YAW (got {len(texts)})")
    units.guard([f"{what} {n}" for n in ("x", "y", "z", "yaw")], texts, POSE_KINDS)
    return [number(n, t) / sc for n, t, sc in zip(("x", "y", "z", "yaw"), texts, units.scale(POSE_KINDS))]


def needs_wrist(robot: Robot, what: str) -> None:
    """Refuse (exit 2) a command or option that supports 4-joint robots only, for a 3-joint SCARA."""
    if robot.dof != 4:
        kinds = sorted(a.kind for a in robot.axes)
        arm = "a SCARA without a wrist" if kinds == ["prismatic", "revolute", "revolute"] else " and ".join(
            f"{kinds.count(k)} {k}" for k in sorted(set(kinds)))  # fmt: skip
        raise InvalidInputError(f"{what} supports 4-joint robots only; {robot.name!r} has {robot.dof} joints "
                                f"({arm})")  # fmt: skip
