"""Jog to the edge (S5's teach-pendant use).

A straight tool move along a direction that ends exactly on the workspace edge (or a margin before it),
at rest, planned before moving.

The edge is found with the exact workspace (:meth:`scara_pin.workspace.Workspace.ray`); the move is a
straight Cartesian line (:func:`scara_pin.motion.paths.cartesian_path`: one elbow branch, J4 continuous,
yaw constant) followed with the quintic time law, so that velocity AND acceleration are zero at both
ends, stretched in time just enough to respect every joint velocity and acceleration limit. The time
law scales exactly (velocities as 1/k, accelerations as 1/k^2 for k times slower), so the duration is
found in one step from a trial run and then verified.

In a cell (``cell=``), the jog also stops before contact: the straight line ends where a checked pair (a link
or the carried part against an obstacle, or two links) first comes to the cell's margin, found by
:func:`scara_pin.cell.sweep.first_contact` (conservative advancement on coal's distances, then bisection: the
stop is clear of the margin by 0 to 1e-9 m), whichever comes first, the edge or the contact. A jog that starts
closer than the margin is refused (:class:`~scara_pin.cell.InCollisionError`, exit code 2) naming the pair.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import as_limit_vector
from .._typing import ArrayLike
from ..errors import InfeasibleError, ParameterError
from ..model import RobotModel
from ..workspace.scara import Limit, RayHit, Workspace, workspace
from .trajectory import Trajectory, cartesian_path, joint_pose, timed

if TYPE_CHECKING:
    from ..cell import Cell, PairDistance

__all__ = ["JogResult", "edge_workspace", "jog_to_edge"]

CHECK_RATE = 10_000.0
"""[Hz] sampling rate of the limit check of a jog (ten times the 1 kHz promise)."""
CONTACT_ROOM = 1e-9
"""[m or rad] in a cell, a jog shorter than this before contact is refused (no room to move); a pendant's step
(:mod:`~scara_pin.motion.manual`) does not move (``AT_EDGE``)."""
SINGULAR_EDGE_GAP = 1e-6
"""[m] in a cell, the contact is looked for up to this short of a singular edge (the line cannot end on it)."""


@dataclass(frozen=True, eq=False, kw_only=True)
class JogResult:
    """A planned jog.

    Attributes:
        trajectory: the joint trajectory, from rest at the start to rest at the end.
        hit: the edge met along the ray (what stops the jog without a cell, or beyond the contact).
        start_pose, end_pose: tool (x, y, z, yaw) at both ends [m, rad].
        distance: the length travelled [m] (the edge distance minus the margin, or up to the contact).
        ratio: the worst |qd|/vmax, |qdd|/amax of the trajectory sampled at CHECK_RATE (<= 1).
        contact: in a cell, the pair at the margin where the jog stops before the edge (its distance at the
            end), else None.
        margin: [m] the cell's margin (0 without a cell).
    """

    trajectory: Trajectory
    hit: RayHit
    start_pose: np.ndarray
    end_pose: np.ndarray
    distance: float
    ratio: float
    contact: PairDistance | None = None
    margin: float = 0.0

    @property
    def stopped_by(self) -> str:
        """What stops the jog: ``stopped 2 mm from post (link2)``, or the edge's description."""
        c = self.contact
        if c is None:
            return f"{self.hit.description} [{self.hit.limit.value}]"
        return f"stopped {c.distance * 1e3:.6g} mm from {c.pair.b} ({c.pair.a})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI units)."""
        out: dict[str, Any] = {"hit": self.hit.to_dict(), "start_pose": self.start_pose.tolist(),
                               "end_pose": self.end_pose.tolist(), "distance": self.distance,
                               "duration": self.trajectory.duration, "q_end": self.trajectory.q_end.tolist(),
                               "limit_ratio": self.ratio, "stopped_by": "edge" if self.contact is None else "cell"}
        if self.contact is not None:
            out["contact"] = {**self.contact.to_dict(), "margin": self.margin}
        return out


def jog_to_edge(
    robot: RobotModel,
    q0: ArrayLike,
    direction: ArrayLike,
    *,
    margin: float = 0.0,
    ws: Workspace | None = None,
    cell: Cell | None = None,
) -> JogResult:
    """Plan a straight jog from configuration ``q0`` along ``direction`` to the workspace edge.

    Args:
        robot: the robot.
        q0: the current configuration (inside the limits).
        direction: (dx, dy) in the base plane, or (dx, dy, dz): then the J3 stroke can stop it too.
        margin: [m] stop this far before the edge (>= 0).
        ws: the workspace, if already built (else built here; with a tool offset, at the current yaw).
        cell: the robot's cell: the jog also stops where a checked pair comes to the cell's margin.

    Returns:
        JogResult.

    Raises:
        OutsideWorkspaceError: the tool is not inside the workspace.
        InCollisionError: in a cell, the start is closer than the cell's margin (exit code 2), naming the pair.
        InfeasibleError: the edge is closer than the margin (no room to move), or it is the stretched or
            folded singularity (outer/inner circle) and no margin was given: a straight line cannot end
            there at rest with finite joint accelerations.
        PathError: the line cannot be followed (e.g. a J4 limit on the way).
    """
    q0 = robot.check_q(q0)
    # the stretch below needs every limit: an unknown one (NaN: a URDF file has no acceleration limits)
    # is refused here, never dropped by max()
    as_limit_vector("velocity", robot.limits.velocity, "rad/s or m/s")
    as_limit_vector("acceleration", robot.limits.acceleration, "rad/s^2 or m/s^2")
    if not (math.isfinite(margin) and margin >= 0):
        raise ParameterError("margin", margin, "must be a finite number >= 0", "m")
    d = np.asarray(direction, dtype=float)
    if d.shape not in ((2,), (3,)) or not np.isfinite(d).all() or not np.linalg.norm(d) > 0:
        raise ParameterError("direction", d.tolist(), "must be 2 or 3 finite numbers, not all zero")
    u = d / np.linalg.norm(d)
    pose0 = joint_pose(robot, q0)
    sc = None
    if cell is not None:
        from ..cell import scene

        sc = scene(robot, cell)
        sc.check(q0, "the jog's start")  # exit 2 naming the pair
    if ws is None:
        ws = edge_workspace(robot, float(pose0[3]))
    start = pose0[: len(u)]
    hit = ws.ray(start, u)
    travel = hit.distance - margin
    singular = hit.limit in (Limit.OUTER, Limit.FOLDED) and margin <= 0
    contact = None
    if sc is not None:
        reach = travel - SINGULAR_EDGE_GAP if singular else travel
        if reach > 0:
            contact, travel_c = _contact(robot, sc, q0, pose0, u, reach)
            if contact is not None:
                travel, singular = travel_c, False
    if singular:
        raise InfeasibleError(
            f"the edge {hit.distance:.9g} m ahead is the {'stretched' if hit.limit is Limit.OUTER else 'folded'}-arm "
            "singularity: a straight line cannot end on it at rest with finite joint accelerations "
            "(the elbow angle goes as the square root of the distance left); give a margin, e.g. 1e-4 m"
        )
    if contact is not None and not travel > CONTACT_ROOM:
        raise InfeasibleError(f"no room to jog: {contact.pair.a} is at the margin of {contact.pair.b} already "
                              f"({contact.distance * 1e3:.6g} mm) and the "
                              "direction brings them closer")  # fmt: skip
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
    if contact is not None:  # the pair at the end, as the end configuration has it
        assert sc is not None  # noqa: S101
        contact = sc.distances(traj.q_end).of(contact.pair)
    return JogResult(trajectory=traj, hit=hit, start_pose=pose0, end_pose=end, distance=travel, ratio=ratio,
                     contact=contact, margin=0.0 if sc is None else sc.margin)  # fmt: skip


def _contact(robot: RobotModel, sc: Any, q0: np.ndarray, pose0: np.ndarray, u: np.ndarray, reach: float
             ) -> tuple[PairDistance | None, float]:  # fmt: skip
    """The first contact along the straight line of length ``reach`` from ``pose0``: (pair, travel) or (None, 0)."""
    from ..cell.sweep import first_contact

    end = pose0.copy()
    end[: len(u)] += reach * u
    line = cartesian_path(robot, [pose0, end], start=q0).segments[0]
    found = first_contact(sc, line)
    if found is None:
        return None, 0.0
    return found.closest, found.s * reach


def edge_workspace(robot: RobotModel, yaw: float) -> Workspace:
    """The region a jog's tool point moves in at a constant ``yaw`` [rad].

    The wrist region, or with a plan-view tool offset the tool point's region at that yaw
    (:func:`scara_pin.workspace.workspace`).

    Raises:
        ParameterError: a tool offset with J4 limited to less than a turn (no fixed-yaw region is defined).
    """
    offset = math.hypot(*robot.kinematics.geometry.tool) > 0
    return workspace(robot, yaw=yaw) if offset else workspace(robot)


def _ratios(robot: RobotModel, traj: Trajectory) -> tuple[float, float]:
    t = traj.times(CHECK_RATE)
    _, qd, qdd = traj.sample(t)
    lim = robot.limits
    return (float(np.max(np.abs(qd) / np.asarray(lim.velocity))),
            float(np.max(np.abs(qdd) / np.asarray(lim.acceleration))))  # fmt: skip
