"""Robot kinds behind one protocol, and loading a robot with the kinematics of its kind.

A :class:`~scara_pin.model.Robot` is the Pinocchio model (FK, frames, Jacobians); what it knows of inverse
kinematics is one object of the :class:`~scara_pin.model.Kinematics` protocol, built here from the loaded
model by its kind:

- :class:`ScaraKinematics`: the SCARA closed form (:mod:`scara_pin.kinematics.scara`), its plan-view
  workspace (:mod:`scara_pin.workspace.scara`); on near-parallel axes (pi written as 3.14) its solutions
  are refined on the model (:mod:`scara_pin.kinematics.polish`);
- :class:`Scara3Kinematics`: a SCARA without a wrist (3 joints, ``robot.dof == 3``): the same closed form
  and workspace on its geometry read with a virtual wrist on the tool point, targets (x, y, z);
- :class:`PalletizerKinematics`: the palletizer's (:mod:`scara_pin.kinematics.palletizer`), its arm-plane
  envelope (:mod:`scara_pin.workspace.palletizer`).

Both read their geometry from the model, so the URDF is the single source of truth.
"""

from __future__ import annotations

import enum
import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .description import RobotParameters
from .errors import InvalidInputError, NoSolutionError, ParameterError
from .kinematics import palletizer, scara
from .kinematics.polish import polish_batch, seed_geometry, solve_refined
from .kinematics.results import BatchIKResult, IKResult
from .model import Kinematics, Robot, pose_from_placement

if TYPE_CHECKING:
    from ._typing import ArrayLike
    from .workspace.palletizer import ArmPlaneEnvelope
    from .workspace.scara import Workspace

__all__ = [
    "PalletizerKinematics",
    "Scara3Kinematics",
    "ScaraKinematics",
    "kinematics_for",
    "load_robot",
    "load_urdf",
    "robot_from_urdf",
]


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
    robot: Robot | None

    def __init__(self, geometry: scara.ScaraGeometry, robot: Robot | None = None) -> None:
        self.geometry = geometry
        self.robot = robot if geometry.tilt > scara.EXACT_TILT else None
        self._seeds = seed_geometry(geometry) if self.robot is not None else geometry
        if self.robot is None and type(self) is ScaraKinematics:  # the per-call path: one call less
            self.nearest = functools.partial(scara.solve_nearest, geometry)  # type: ignore[method-assign]

    @classmethod
    def from_robot(cls, robot: Robot) -> ScaraKinematics:
        """Read the geometry from the robot's model; NotScaraError names what is not SCARA-like."""
        return cls(scara.ScaraGeometry.from_robot(robot), robot)

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve` (refined on the model when its axes are near-parallel)."""
        if self.robot is None:
            return scara.solve(self.geometry, target, branch=branch, reference=reference, all_turns=all_turns)
        from .kinematics.targets import parse_target, placement_matrix

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
        return _nearest_of(self.solve(target, branch=branch, reference=reference), reference, weights, branch, 4)

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.scara.solve_batch` (refined row by row when near-parallel)."""
        # near-parallel: seeds from the ideal arm with the widened limits (as solve's); the polish enforces
        # the model's own limits
        res = scara.solve_batch(self._seeds, targets, branch=branch, reference=reference)
        if self.robot is None:
            return res
        T = np.asarray(targets, dtype=float)
        return polish_batch(self.robot, self.geometry, T, res, _row_solver(self, T, reference, branch))

    def branch_of(self, q: ArrayLike) -> str:
        """:func:`scara_pin.kinematics.scara.branch_of`."""
        return scara.branch_of(self.geometry, q)

    def workspace(self, **kwargs: Any) -> Workspace:
        """:func:`scara_pin.workspace.scara.workspace` (keyword arguments as there)."""
        from .workspace.scara import workspace  # on first use: `scara-pin fk` does not need it

        return workspace(self.geometry, **kwargs)


POSE_TILT_FACTOR = 8.0
"""A placement target of a near-parallel robot tilting up to this many times its axes' tilt is solved (its
roll/pitch then checked); beyond, it is NOT_A_YAW_POSE at once."""


def _with_rotation(robot: Robot, res: IKResult, rotation: np.ndarray) -> IKResult:
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


class PalletizerKinematics:
    """The palletizer's kinematics (see :mod:`scara_pin.kinematics.palletizer`).

    Attributes:
        geometry: the geometry read from the model.
    """

    kind: str = "palletizer"
    branches: tuple[str, ...] = palletizer.BRANCHES
    status: type[enum.IntEnum] = palletizer.PalletizerIKStatus
    geometry: palletizer.PalletizerGeometry

    def __init__(self, geometry: palletizer.PalletizerGeometry) -> None:
        self.geometry = geometry

    @classmethod
    def from_robot(cls, robot: Robot) -> PalletizerKinematics:
        """Read the geometry from the robot's model; NotPalletizerError says where it departs."""
        return cls(palletizer.PalletizerGeometry.from_robot(robot))

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve`."""
        return palletizer.solve(self.geometry, target, branch=branch, reference=reference, all_turns=all_turns)

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve_nearest`."""
        return palletizer.solve_nearest(self.geometry, target, reference, weights=weights, branch=branch)

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve_batch`."""
        return palletizer.solve_batch(self.geometry, targets, branch=branch, reference=reference)

    def branch_of(self, q: ArrayLike) -> str:
        """:func:`scara_pin.kinematics.palletizer.branch_of`."""
        return palletizer.branch_of(q)

    def workspace(self) -> ArmPlaneEnvelope:
        """:func:`scara_pin.workspace.palletizer.arm_plane_envelope`."""
        from .workspace.palletizer import arm_plane_envelope  # on first use

        return arm_plane_envelope(self.geometry)


def _nearest_of(res: IKResult, reference: ArrayLike | None, weights: ArrayLike | None, branch: str,
                n: int) -> np.ndarray:  # fmt: skip
    """The solution of ``res`` nearest ``reference`` (weighted), as a new array; NoSolutionError if none."""
    from .kinematics.targets import reference_floats, weight_floats

    ref = reference_floats(reference, n)
    w = None if weights is None else weight_floats(weights, n)
    best = res.nearest(ref, w, branch) if res.success else None
    if best is None:
        raise NoSolutionError(res.status, res.message if not res.success else f"no {branch} solution")
    return best.q.copy()


def _row_solver(kin: Any, T: np.ndarray, reference: ArrayLike | None, branch: str) -> Any:
    """solve_row(i) for :func:`~scara_pin.kinematics.polish.polish_batch`: row i by ``kin.solve``, nearest kept."""
    ref = None if reference is None else np.asarray(reference, dtype=float)

    def solve_row(i: int) -> tuple[np.ndarray | None, int, int]:
        row_ref = np.zeros(kin.dof) if ref is None else (ref if ref.ndim == 1 else ref[i])
        res = kin.solve(T[i], branch="all" if branch == "nearest" else branch, reference=row_ref)
        best = res.nearest(row_ref) if res.success else None
        if best is None:
            return None, int(res.status) if not res.success else int(scara.IKStatus.NOT_REFINED), 0
        return best.q, 0, 1 if best.branch == "right" else -1

    return solve_row


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
    def from_robot(cls, robot: Robot) -> Scara3Kinematics:
        """Read the geometry from the robot's model; NotScaraError names what is not SCARA-like."""
        return cls(scara.ScaraGeometry.without_wrist(robot), robot)

    # ------------------------------------------------------------------------- 3 <-> 4 joint values
    def _target4(self, target: Any) -> tuple[float, float, float, float]:
        """(x, y, z, yaw0) of a 3-value target: the virtual wrist absorbs the yaw."""
        from ._checks import _vector
        from .kinematics.targets import check_magnitude

        size = np.size(target) if not hasattr(target, "homogeneous") else 16
        if size != 3:
            raise InvalidInputError(
                "this SCARA has 3 joints and no wrist: the tool's yaw follows q1 and q2 and cannot be chosen; "
                "give the target as x, y, z (3 values)"
            )
        x, y, z = (float(v) for v in _vector("target", target, 3))
        check_magnitude((x, y, z))
        return x, y, z, self.geometry.yaw0

    @staticmethod
    def _ref4(reference: ArrayLike | None) -> np.ndarray | None:
        if reference is None:
            return None
        from ._checks import _vector

        ref = np.asarray(reference, dtype=float)
        if ref.ndim == 2:
            if ref.shape[1] != 3:
                raise ParameterError("reference", f"array of shape {ref.shape}", "must be 3 values or (N, 3)")
            return np.column_stack([ref, np.zeros(len(ref))])
        return np.append(_vector("reference", reference, 3), 0.0)

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
            return _nearest_of(self.solve(target, branch=branch, reference=reference), reference, weights, branch, 3)
        from ._checks import _vector

        w = np.append(np.ones(3) if weights is None else _vector("weights", weights, 3), 0.0)  # the wrist: nothing
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
            res = scara.solve_batch(self.geometry, T4, branch=branch, reference=ref4)
            out = BatchIKResult(res.q[:, :3].copy(), res.status, res.branch)
        else:  # each branch, then the nearer one in the 3 joints (the virtual wrist's turn counts for nothing)
            ref3 = np.zeros(3) if ref4 is None else (ref4[:3] if ref4.ndim == 1 else ref4[:, :3])
            right = scara.solve_batch(self.geometry, T4, branch="right", reference=ref4)
            left = scara.solve_batch(self.geometry, T4, branch="left", reference=ref4)
            d_r = np.where(right.status == 0, ((right.q[:, :3] - ref3) ** 2).sum(axis=1), np.inf)
            d_l = np.where(left.status == 0, ((left.q[:, :3] - ref3) ** 2).sum(axis=1), np.inf)
            take = d_l < d_r
            status = np.where(take | ((right.status != 0) & (left.status == 0)), left.status, right.status)
            q = np.where(take[:, None], left.q[:, :3], right.q[:, :3])
            out = BatchIKResult(q, status, np.where(take, left.branch, right.branch))
        if self.robot is None:
            return out
        return polish_batch(self.robot, self.geometry, T, out, _row_solver(self, T, reference, branch))

    def workspace(self, **kwargs: Any) -> Workspace:
        """:func:`scara_pin.workspace.scara.workspace`: the planar two-link region of the tool point.

        ``lower`` / ``upper`` take 3 values (the joints of q); ``yaw`` does not apply (no wrist).
        """
        if kwargs.get("yaw") is not None:
            raise InvalidInputError("a SCARA without a wrist cannot hold a yaw: its workspace is the tool point's")
        for key, pad in (("lower", -math.inf), ("upper", math.inf)):
            if kwargs.get(key) is not None:
                kwargs[key] = [*kwargs[key], pad] if len(kwargs[key]) == 3 else kwargs[key]
        from .workspace.scara import workspace  # on first use: `scara-pin fk` does not need it

        return workspace(self.geometry, **kwargs)


def kinematics_for(robot: Robot) -> Kinematics:
    """The kinematics object of the robot's kind (``robot.kind``) and joint count (``robot.dof``)."""
    if robot.kind == "palletizer":
        return PalletizerKinematics.from_robot(robot)
    if robot.kind == "scara" and robot.dof == 3:
        return Scara3Kinematics.from_robot(robot)
    if robot.kind == "scara":
        return ScaraKinematics.from_robot(robot)
    raise InvalidInputError(f"robot {robot.name!r} is of kind {robot.kind!r}: no kinematics for it")


def load_robot(
    robot: str | Path | RobotParameters = "default",
    overrides: Mapping[str, object] | None = None,
    *,
    urdf: str | Path | None = None,
    tool: str | None = None,
    base: str | None = None,
    package_path: Sequence[str | Path] = (),
) -> Robot:
    """Load a robot with the kinematics of its kind: a configured one (name or folder) or a URDF / xacro file.

    Args:
        robot: shipped robot name, config folder, or parameters (ignored when ``urdf`` is given).
        overrides: parameter overrides (flat names), for configured robots only.
        urdf: path of a URDF file, or of a xacro file (``.xacro``), to load instead.
        tool: the tool frame (a link); default ``tool0`` if present, else the chain's last link (then
            ``robot.frame_note`` says so).
        base: the base frame poses are expressed in (a link); default ``base`` if present, else the root.
        package_path: folders holding ROS-style packages, for ``$(find pkg)`` and ``package://pkg/``.

    Raises:
        UrdfError: (exit code 2) among others a ``tool`` or ``base`` that is not a link of the robot.
    """
    kwargs: dict[str, Any] = {"tool_frame": tool, "base_frame": base, "kinematics": kinematics_for}
    if urdf is not None:
        if overrides:
            raise InvalidInputError("parameter overrides apply to configured robots, not to a URDF file")
        return Robot.from_file(urdf, package_dirs=package_path, **kwargs)
    if package_path:
        raise InvalidInputError("--package-path applies to a URDF or xacro file (--urdf), not to a configured robot")
    return Robot.from_config(robot, overrides, **kwargs)


def load_urdf(path: str | Path, **kwargs: Any) -> Robot:
    """Load a 4-joint URDF (or xacro) file with its kinematics; keywords as for :func:`load_robot`."""
    return load_robot(urdf=path, **kwargs)


def robot_from_urdf(urdf: str, **kwargs: Any) -> Robot:
    """A robot from URDF text (generated in memory, say), with its kinematics; keywords as for Robot."""
    return Robot(urdf, kinematics=kinematics_for, **kwargs)
