"""The SCARA without a wrist (two revolute joints and a prismatic one, ``robot.dof == 3``).

:class:`Scara3Kinematics` reads the 4-joint SCARA geometry with a virtual continuous wrist on the tool
point, so the closed form, branches, turns and workspace are the SCARA's (:mod:`scara_kinematics
<scara_pin.kinematics.scara_kinematics>`), and drops that wrist from what it returns.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import as_vector
from ..errors import InvalidInputError, ParameterError
from ..ik_results import BatchIKResult, IKResult
from . import scara
from .polish import polish_batch, row_solver, solve_refined
from .scara_batch import solve_batch
from .targets import check_magnitude, nearest_q

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel
from .scara_kinematics import ScaraKinematics

__all__ = ["Scara3Kinematics"]


class Scara3Kinematics(ScaraKinematics):
    """A SCARA without a wrist: two revolute joints and a prismatic one, in any order (``robot.dof == 3``).

    Its geometry is :meth:`ScaraGeometry.without_wrist <scara_pin.kinematics.scara.ScaraGeometry.without_wrist>`:
    the 4-joint geometry with a virtual continuous wrist (index 3) on the tool point, so that the closed
    form, the branches, the turns and the workspace are the SCARA's, unchanged. Targets are (x, y, z) of
    the tool point in the base frame: the tool's yaw is not free (it follows q1 and q2), and a 4th value
    is refused. Solutions and batches hold 3 joint values; the virtual wrist's is dropped.

    Attributes (as :class:`ScaraKinematics`'s):
        geometry: the geometry read from the model (with its virtual wrist).
        robot: the robot, for refinement when its axes are near-parallel (else None).
    """

    dof: int = 3

    @classmethod
    def from_robot(cls, robot: RobotModel) -> Scara3Kinematics:
        """Read the geometry from the robot's model; NotScaraError names what is not SCARA-like."""
        return cls(scara.ScaraGeometry.without_wrist(robot), robot)

    # ------------------------------------------------------------------------- 3 <-> 4 joint values
    def _target4(self, target: Any) -> tuple[float, float, float, float]:
        """(x, y, z, yaw0) of a 3-value target: the virtual wrist absorbs the yaw."""
        size = np.size(target) if not hasattr(target, "homogeneous") else 16
        if size != 3:
            raise InvalidInputError(
                "this SCARA has 3 joints and no wrist: the tool's yaw follows q1 and q2 and cannot be chosen; "
                "give the target as x, y, z (3 values)"
            )
        x, y, z = (float(v) for v in as_vector("target", target, 3))
        check_magnitude((x, y, z))
        return x, y, z, self.geometry.yaw0

    @staticmethod
    def _ref4(reference: ArrayLike | None) -> np.ndarray | None:
        if reference is None:
            return None
        ref = np.asarray(reference, dtype=float)
        if ref.ndim == 2:
            if ref.shape[1] != 3:
                raise ParameterError("reference", f"array of shape {ref.shape}", "must be 3 values or (N, 3)")
            return np.column_stack([ref, np.zeros(len(ref))])
        return np.append(as_vector("reference", reference, 3), 0.0)

    def _drop(self, res: IKResult, xyz: tuple[float, float, float]) -> IKResult:
        sols = tuple(replace(s, q=s.q[:3].copy(), turns=s.turns[:3]) for s in res.solutions)
        return replace(res, target=np.array(xyz), solutions=sols, continuous=res.continuous[:3])

    # ------------------------------------------------------------------------- the protocol
    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """Every branch's solution of the tool point (x, y, z) (see :func:`scara_pin.kinematics.scara.solve`)."""
        geo = self.geometry
        t4 = self._target4(target)
        ref4 = self._ref4(reference)

        def seeds(xyz: np.ndarray) -> IKResult:
            t = (float(xyz[0]), float(xyz[1]), float(xyz[2]), t4[3])
            return self._drop(scara.solve(self._seeds, t, branch=branch, reference=ref4), t[:3])

        res = seeds(np.array(t4[:3])) if self.robot is None else solve_refined(self.robot, geo, seeds, np.array(t4[:3]))
        return res.expand(geo.lower[:3], geo.upper[:3]) if all_turns and res.success else res

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """The solution nearest ``reference`` (3 values; weighted joint space); NoSolutionError if none."""
        if self.robot is not None:
            return nearest_q(self.solve(target, branch=branch, reference=reference), reference, weights, branch, 3)
        w = np.append(np.ones(3) if weights is None else as_vector("weights", weights, 3), 0.0)  # the wrist: nothing
        q = scara.solve_nearest(self.geometry, self._target4(target), self._ref4(reference), weights=w, branch=branch)
        return q[:3].copy()

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """One solution per row of (N, 3) targets (x, y, z): ``.q`` (N, 3), ``.status``, ``.branch``."""
        T = np.asarray(targets, dtype=float)
        if T.ndim != 2 or T.shape[1] != 3:
            raise ParameterError("targets", f"array of shape {T.shape}", "must have shape (N, 3): x, y, z "
                                 "(a SCARA without a wrist cannot choose the yaw)")  # fmt: skip
        T4 = np.column_stack([T, np.full(len(T), self.geometry.yaw0)])
        ref4 = self._ref4(reference)
        if branch != "nearest":
            res = solve_batch(self.geometry, T4, branch=branch, reference=ref4)
            out = BatchIKResult(res.q[:, :3].copy(), res.status, res.branch, res.status_enum, res.branches)
        else:  # each branch, then the nearer one in the 3 joints (the virtual wrist's turn counts for nothing)
            ref3 = np.zeros(3) if ref4 is None else (ref4[:3] if ref4.ndim == 1 else ref4[:, :3])
            right = solve_batch(self.geometry, T4, branch="right", reference=ref4)
            left = solve_batch(self.geometry, T4, branch="left", reference=ref4)
            d_r = np.where(right.status == 0, ((right.q[:, :3] - ref3) ** 2).sum(axis=1), np.inf)
            d_l = np.where(left.status == 0, ((left.q[:, :3] - ref3) ** 2).sum(axis=1), np.inf)
            take = d_l < d_r
            status = np.where(take | ((right.status != 0) & (left.status == 0)), left.status, right.status)
            q = np.where(take[:, None], left.q[:, :3], right.q[:, :3])
            out = BatchIKResult(q, status, np.where(take, left.branch, right.branch), right.status_enum, right.branches)
        if self.robot is None:
            return out
        return polish_batch(self.robot, self.geometry, T, out, row_solver(self, T, reference, branch))

