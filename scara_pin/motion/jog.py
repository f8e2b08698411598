"""Jog to the edge (S5's teach-pendant use).

A straight tool move along a direction that ends exactly on the workspace edge (or a margin before it),
at rest, planned before moving.

The edge is found with the exact workspace (:meth:`scara_pin.workspace.Workspace.ray`); the move is a
straight Cartesian line (:func:`scara_pin.motion.paths.cartesian_path`: one elbow branch, J4 continuous,
yaw constant) followed with the quintic time law, so that velocity AND acceleration are zero at both
ends, stretched in time just enough to respect every joint velocity and acceleration limit. The time
law scales exactly (velocities as 1/k, accelerations as 1/k^2 for k times slower), so the duration is
found in one step from a trial run and then verified.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import _limit_vector
from .._typing import ArrayLike
from ..errors import InfeasibleError, ParameterError
from ..model import Robot
from ..workspace.scara import Limit, RayHit, Workspace, workspace
from .trajectory import Trajectory, cartesian_path, joint_pose, timed

__all__ = ["JogResult", "edge_workspace", "jog_to_edge"]

CHECK_RATE = 10_000.0
"""[Hz] sampling rate of the limit check of a jog (ten times the 1 kHz promise)."""


@dataclass(frozen=True, eq=False)
class JogResult:
    """A planned jog.

    Attributes:
        trajectory: the joint trajectory, from rest at the start to rest at the end.
        hit: the edge met along the ray (what stops the jog).
        start_pose, end_pose: tool (x, y, z, yaw) at both ends [m, rad].
        distance: the length travelled [m] (the edge distance minus the margin).
        ratio: the worst |qd|/vmax, |qdd|/amax of the trajectory sampled at CHECK_RATE (<= 1).
    """

    trajectory: Trajectory
    hit: RayHit
    start_pose: np.ndarray
    end_pose: np.ndarray
    distance: float
    ratio: float


def jog_to_edge(
    robot: Robot,
    q0: ArrayLike,
    direction: ArrayLike,
    *,
    margin: float = 0.0,
    ws: Workspace | None = None,
) -> JogResult:
    """Plan a straight jog from configuration ``q0`` along ``direction`` to the workspace edge.

    Args:
        robot: the robot.
        q0: the current configuration (inside the limits).
        direction: (dx, dy) in the base plane, or (dx, dy, dz): then the J3 stroke can stop it too.
        margin: [m] stop this far before the edge (>= 0).
        ws: the workspace, if already built (else built here; with a tool offset, at the current yaw).

    Returns:
        JogResult.

    Raises:
        OutsideWorkspaceError: the tool is not inside the workspace.
        InfeasibleError: the edge is closer than the margin (no room to move), or it is the stretched or
            folded singularity (outer/inner circle) and no margin was given: a straight line cannot end
            there at rest with finite joint accelerations.
        PathError: the line cannot be followed (e.g. a J4 limit on the way).
    """
    q0 = robot.check_q(q0)
    # the stretch below needs every limit: an unknown one (NaN: a URDF file has no acceleration limits)
    # is refused here, never dropped by max()
    _limit_vector("velocity", robot.limits.velocity, "rad/s or m/s")
    _limit_vector("acceleration", robot.limits.acceleration, "rad/s^2 or m/s^2")
    if not (math.isfinite(margin) and margin >= 0):
        raise ParameterError("margin", margin, "must be a finite number >= 0", "m")
    d = np.asarray(direction, dtype=float)
    if d.shape not in ((2,), (3,)) or not np.isfinite(d).all() or not np.linalg.norm(d) > 0:
        raise ParameterError("direction", d.tolist(), "must be 2 or 3 finite numbers, not all zero")
    u = d / np.linalg.norm(d)
    pose0 = joint_pose(robot, q0)
    if ws is None:
        ws = edge_workspace(robot, float(pose0[3]))
    start = pose0[: len(u)]
    hit = ws.ray(start, u)
    travel = hit.distance - margin
    if hit.limit in (Limit.OUTER, Limit.FOLDED) and margin <= 0:
        raise InfeasibleError(
            f"the edge {hit.distance:.9g} m ahead is the {'stretched' if hit.limit is Limit.OUTER else 'folded'}-arm "
            "singularity: a straight line cannot end on it at rest with finite joint accelerations "
            "(the elbow angle goes as the square root of the distance left); give a margin, e.g. 1e-4 m"
        )
    if not travel > 0:
        raise InfeasibleError(
            f"no room to jog: the edge ({hit.description}) is {hit.distance:.9g} m away, margin {margin:.9g} m"
        )
    end = pose0.copy()
    end[: len(u)] += travel * u
    path = cartesian_path(robot, [pose0, end], start=q0)
    # a trial duration, then the exact stretch: velocity ratios scale as 1/k, accelerations as 1/k^2
    trial = timed(path, 1.0)
    rv, ra = _ratios(robot, trial)
    k = max(rv, math.sqrt(ra), 1e-9)
    traj = timed(path, k)
    ratio = max(_ratios(robot, traj))
    if ratio > 1.0 + 1e-9:  # sampling moved a peak: stretch by what is left
        traj = timed(path, k * max(ratio, math.sqrt(ratio)))
        ratio = max(_ratios(robot, traj))
    return JogResult(traj, hit, pose0, end, travel, ratio)


def edge_workspace(robot: Robot, yaw: float) -> Workspace:
    """The region a jog's tool point moves in at a constant ``yaw`` [rad].

    The wrist region, or with a plan-view tool offset the tool point's region at that yaw
    (:func:`scara_pin.workspace.workspace`).

    Raises:
        ParameterError: a tool offset with J4 limited to less than a turn (no fixed-yaw region is defined).
    """
    offset = math.hypot(*robot.kinematics.geometry.tool) > 0
    return workspace(robot, yaw=yaw) if offset else workspace(robot)


def _ratios(robot: Robot, traj: Trajectory) -> tuple[float, float]:
    t = traj.times(CHECK_RATE)
    _, qd, qdd = traj.sample(t)
    lim = robot.limits
    return (float(np.max(np.abs(qd) / np.asarray(lim.velocity))),
            float(np.max(np.abs(qdd) / np.asarray(lim.acceleration))))  # fmt: skip
