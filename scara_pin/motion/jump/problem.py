"""The data of one jump (SI units), its end configurations and the exact integration between nodes."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import InfeasibleError, InvalidInputError
from ...kinematics.validate import pose_error
from ..payload import Payload
from ..verify import ENDPOINT_TOL, static_load, static_overload

if TYPE_CHECKING:
    from ..._typing import ArrayLike
    from ...cell import Scene
    from ...description import JointLimits
    from ...model import RobotModel
    from ...symbolic import SymbolicModel

@dataclass(frozen=True, eq=False, kw_only=True)
class Problem:
    """The data of one move, SI units; ``order`` 2 (acceleration control) or 3 (jerk control)."""

    robot: RobotModel
    sym: SymbolicModel
    base: RobotModel
    payload: Payload
    limits: JointLimits | None
    A: np.ndarray
    B: np.ndarray
    qA: np.ndarray
    qB: np.ndarray
    q_tops: tuple[np.ndarray, np.ndarray]
    z_top: float
    R: float
    max_height: float | None
    lower: np.ndarray
    upper: np.ndarray
    ranged: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray | None
    effort: np.ndarray | None
    tool_speed: float | None
    N: tuple[int, int, int]
    t_scale: float
    scene: Scene | None = None

    @property
    def order(self) -> int:
        """2 (acceleration control) or 3 (jerk control)."""
        return 2 if self.jerk is None else 3

    @property
    def control_limit(self) -> np.ndarray:
        """The limit of the control: the acceleration's, or the jerk's."""
        return self.acceleration if self.jerk is None else self.jerk

    @property
    def state_scale(self) -> np.ndarray:
        """(order, dof): position, velocity (and acceleration) scales of the variables."""
        rows = [self.velocity * self.t_scale, self.velocity] + ([self.acceleration] if self.jerk is not None else [])
        return np.array(rows)

    def phase_of(self) -> np.ndarray:
        """Phase index of every interval."""
        return np.repeat(np.arange(3), self.N)


NODES = -1
"""The interval index of a :class:`ConstraintPoint` that stands for every node (both sides) of its family."""


@dataclass(frozen=True)
class ConstraintPoint:
    """A constraint point inside interval ``k`` at fraction ``sigma`` of it, for one family of constraints.

    ``k`` = :data:`NODES`: the family at every node instead (both sides; a lazy family, ``_LAZY``).
    """

    k: int
    sigma: float
    family: str  # "geometry", "torque", "tool speed"


def propagate(order: int, state: list[Any], u: Any, tau: Any) -> list[Any]:
    """The state after ``tau`` of constant control ``u``, exactly (elementwise: numbers, arrays, CasADi matrices)."""
    if order == 2:
        q, v = state
        return [q + v * tau + u * (tau * tau / 2.0), v + u * tau]
    q, v, a = state
    return [q + v * tau + a * (tau * tau / 2.0) + u * (tau * tau * tau / 6.0), v + a * tau + u * (tau * tau / 2.0),
            a + u * tau]  # fmt: skip


def given(robot: RobotModel, q: ArrayLike, pose: np.ndarray, name: str) -> np.ndarray:
    """A configuration given for a pose, checked: FK within ENDPOINT_TOL of the pose, inside the limits."""
    qq = np.array(robot.check_q(q), dtype=float)
    err = pose_error(robot, qq, pose)
    if err > ENDPOINT_TOL:
        raise InvalidInputError(f"{name} {np.round(qq, 9).tolist()} puts the tool {err:.3g} m (or rad) from its pose")
    outside = robot.outside_limits(qq)
    if outside:
        raise InvalidInputError(f"{name} {np.round(qq, 9).tolist()} is outside the limits of {', '.join(outside)}")
    return qq


def given_via(robot: RobotModel, q: ArrayLike, i: int) -> np.ndarray:
    """A via configuration given as a hint, checked: finite, inside the joint limits."""
    qq = np.array(robot.check_q(q), dtype=float)
    outside = robot.outside_limits(qq)
    if outside:
        raise InvalidInputError(f"via #{i + 1} {np.round(qq, 9).tolist()} is outside the limits of "
                                f"{', '.join(outside)}")
    return qq


def endpoints(
    robot: RobotModel, A: np.ndarray, B: np.ndarray, start: ArrayLike | None, end: ArrayLike | None, branch: str | None
) -> tuple[np.ndarray, np.ndarray]:
    """The configurations at A (``start``, or the IK solution nearest mid-range) and at B (``end``, or nearest qA)."""
    mid = (np.array(robot.limits.lower) + np.array(robot.limits.upper)) / 2.0
    if start is not None:
        qA = given(robot, start, A, "start")
    else:
        res = robot.ik(A)
        sol = res.nearest(mid, branch=branch or "all") if res.success else None
        if sol is None:
            raise InfeasibleError(f"pose_from {A.tolist()} is out of reach: {res.message}")
        qA = sol.q
    if end is not None:
        return np.array(qA, dtype=float), given(robot, end, B, "end")
    br = branch or robot.branch_of(qA)
    res = robot.ik(B)
    sol = res.nearest(qA, branch=br) if res.success else None
    if sol is None:
        raise InfeasibleError(f"pose_to {B.tolist()} is out of reach on the {br} branch: {res.message}")
    return np.array(qA, dtype=float), np.array(sol.q, dtype=float)


def top_configuration(robot: RobotModel, pose: np.ndarray, z_top: float, near: np.ndarray, name: str,
                      rise: float) -> np.ndarray:  # fmt: skip
    """The configuration at the traverse height above ``pose`` nearest ``near`` (same branch)."""
    target = np.array([pose[0], pose[1], z_top, pose[3]])
    res = robot.ik(target)
    sol = res.nearest(near, branch=robot.branch_of(near)) if res.success else None
    if sol is None:
        raise InfeasibleError(f"the tool cannot reach the traverse height z_top = {z_top:.6g} m above {name} (rise "
                              f"{rise:.6g} m): {res.message}")  # fmt: skip
    return np.array(sol.q, dtype=float)


def default_intervals(jerk: bool, tool_speed: bool) -> tuple[int, int, int]:
    """(lift, traverse, descend) intervals: 10 / 14 / 10, or 16 / 24 / 16 with a jerk limit.

    A tool-speed limit, which binds along the whole traverse, doubles the traverse's (0.6 % shorter there).
    """
    lift, traverse = (16, 24) if jerk else (10, 14)
    return lift, traverse * (2 if tool_speed else 1), lift


def holds_still(robot: RobotModel, configurations: tuple[np.ndarray, ...], effort: np.ndarray) -> None:
    """InfeasibleError if the static load (gravity, payload included) at one of them is not below an effort limit."""
    q = np.array(configurations)
    bad = static_overload(static_load(robot, q), effort, robot.joint_names)
    if bad is not None:
        raise InfeasibleError(bad.reason(f"at q = {np.round(q[bad.index], 6).tolist()}"))
