"""The SCARA kind: the closed form (:mod:`scara_pin.kinematics.scara`) behind the robot's kinematics protocol.

:class:`ScaraKinematics` is what ``robot.kinematics`` is for a 4-joint SCARA (see
:class:`~scara_pin.model.Kinematics`): its geometry read from the model
(:mod:`~scara_pin.kinematics.scara_geometry`), every branch of one target (:mod:`~scara_pin.kinematics.scara`),
the vectorised batch (:mod:`~scara_pin.kinematics.scara_batch`) and the plan-view workspace
(:mod:`scara_pin.workspace.scara`, imported on first use). On near-parallel axes (pi written as 3.14) its
solutions are refined on the model (:mod:`scara_pin.kinematics.polish`).
"""

from __future__ import annotations

import enum
import types
from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..ik_results import BatchIKResult, IKResult
from ..model import pose_from_placement
from . import scara
from .polish import polish_batch, row_solver, seed_geometry, solve_refined
from .scara_batch import solve_batch
from .targets import nearest_q, parse_target, placement_matrix

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = ["POSE_TILT_FACTOR", "ScaraKinematics"]


class ScaraKinematics:
    """The SCARA's kinematics (see :mod:`scara_pin.kinematics.scara`).

    Attributes:
        geometry: the geometry read from the model.
        robot: the robot, whose model refines the solutions when its axes are near-parallel (``geometry.tilt``
            above ``EXACT_TILT``); None: the closed form alone.
    """

    kind: str = "scara"
    dof: int = 4
    branches: tuple[str, ...] = scara.BRANCHES
    status: type[enum.IntEnum] = scara.IKStatus
    geometry: scara.ScaraGeometry
    robot: RobotModel | None

    def __init__(self, geometry: scara.ScaraGeometry, robot: RobotModel | None = None) -> None:
        self.geometry = geometry
        self.robot = robot if geometry.tilt > scara.EXACT_TILT else None
        self._seeds = seed_geometry(geometry) if self.robot is not None else geometry
        if self.robot is None and type(self) is ScaraKinematics:  # the per-call path: one call less
            # solve_nearest bound to the geometry: as fast as functools.partial, and help() shows its own
            # signature and docstring (a partial shows functools.partial's)
            self.nearest = types.MethodType(scara.solve_nearest, geometry)  # type: ignore[method-assign]

    @classmethod
    def from_robot(cls, robot: RobotModel) -> ScaraKinematics:
        """Read the geometry from the robot's model; NotScaraError names what is not SCARA-like."""
        return cls(scara.ScaraGeometry.from_robot(robot), robot)

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve` (refined on the model when its axes are near-parallel)."""
        if self.robot is None:
            return scara.solve(self.geometry, target, branch=branch, reference=reference, all_turns=all_turns)
        geo = self.geometry
        x, y, z, alpha, tilt = parse_target(target, geo.yaw0, geo.R0)
        rotation = None
        task = np.array((x, y, z, alpha + geo.yaw0))
        if tilt > scara.YAW_POSE_TOL:
            # a placement: this model's own poses tilt (roll/pitch) by a few times its axes' tilt
            if tilt > POSE_TILT_FACTOR * geo.tilt + scara.YAW_POSE_TOL:  # the closed form says why
                return scara.solve(geo, target, branch=branch, reference=reference)
            placement = pin.SE3(placement_matrix(target))  # (parse_target checked it: a rotation, 4 x 4)
            rotation = placement.rotation
            task = pose_from_placement(placement)  # the yaw as tool_pose (and the polish) read it from the model
        res = solve_refined(self.robot, geo, lambda t: scara.solve(self._seeds, t, branch=branch, reference=reference),
                            task)  # fmt: skip
        if rotation is not None and res.success:
            res = _with_rotation(self.robot, res, rotation)
        return res.expand(geo.lower, geo.upper) if all_turns and res.success else res

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve_nearest` (refined on the model when near-parallel)."""
        if self.robot is None:
            return scara.solve_nearest(self.geometry, target, reference, weights=weights, branch=branch)
        return nearest_q(self.solve(target, branch=branch, reference=reference), reference, weights, branch, 4)

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.scara_batch.solve_batch` (refined row by row when near-parallel)."""
        # near-parallel: seeds from the ideal arm with the widened limits (as solve's); the polish enforces
        # the model's own limits
        res = solve_batch(self._seeds, targets, branch=branch, reference=reference)
        if self.robot is None:
            return res
        T = np.asarray(targets, dtype=float)
        return polish_batch(self.robot, self.geometry, T, res, row_solver(self, T, reference, branch))

    def branch_of(self, q: ArrayLike) -> str:
        """:func:`scara_pin.kinematics.scara.branch_of`."""
        return scara.branch_of(self.geometry, q)



POSE_TILT_FACTOR = 8.0
"""A placement target of a near-parallel robot tilting up to this many times its axes' tilt is solved (its
roll/pitch then checked); beyond, it is NOT_A_YAW_POSE at once."""


def _with_rotation(robot: RobotModel, res: IKResult, rotation: np.ndarray) -> IKResult:
    """The solutions of ``res`` whose tool rotation is the target's (to YAW_POSE_TOL rad), or NOT_A_YAW_POSE.

    A near-parallel robot reaches a position and yaw with a roll/pitch set by its configuration: of the
    solutions found from (x, y, z, yaw), those with another roll/pitch are not the target's.
    """
    errors = [float(np.linalg.norm(pin.log3(robot.tool_placement(s.q).rotation.T @ rotation))) for s in res.solutions]
    kept = tuple(s for s, e in zip(res.solutions, errors) if e <= scara.YAW_POSE_TOL)
    if kept:
        return replace(res, solutions=kept)
    return replace(res, solutions=(), status=scara.IKStatus.NOT_A_YAW_POSE,
                   message=f"the target's roll/pitch is not one this robot reaches at that position and yaw: the "
                           f"nearest solution's tool rotation is {min(errors):.3g} rad away")  # fmt: skip
