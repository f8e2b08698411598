"""The jump's verification by independent routes, and its legs (:mod:`~scara_pin.motion.jump`, "Output")."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import InvalidInputError
from ...kinematics.validate import pose_error
from ..polynomial import PolynomialPiece
from ..trajectory import Trajectory
from ..verify import (
    ENDPOINT_TOL,
    TOLERANCE,
    VERIFY_RATE,
    Binding,
    Clearance,
    LimitViolation,
    limits_in_force,
    state_ratios,
    verify,
)
from .problem import Problem
from .refine import extrema
from .types import BINDING, CLEARANCE_TOL, JumpError, Leg, Phase

_QUANTITIES = ("velocity", "acceleration", "jerk", "torque", "tool speed")


@dataclass(frozen=True, eq=False)
class Check:
    """What the verification found: the samples (for the legs) and the worst values."""

    t: np.ndarray
    on_grid: np.ndarray
    table: dict[str, np.ndarray]
    ratios: dict[str, float | None]
    clearance_error: float
    peak: float
    bulge: float
    distance: Clearance | None = None


def verify_move(prob: Problem, traj: Trajectory) -> Check:
    """Verify by independent routes (module docstring); JumpError naming what fails.

    1. The package's verifier (:func:`~scara_pin.motion.verify.verify`): Pinocchio at 10 kHz and at every
       breakpoint on both sides (where the velocity peaks under acceleration control and the acceleration
       under jerk control), the piece's exact jerk and the jerk by third differences, the torques with the
       payload, the tool speed, the endpoints and the rest.
    2. The same ratios (:func:`~scara_pin.motion.verify.state_ratios`) inside every interval and at the
       polynomial extrema.
    3. The clearance and the ceiling (Pinocchio's FK), the joint ranges, the end poses.
    """
    piece = traj.pieces[0]
    if not isinstance(piece, PolynomialPiece):  # pragma: no cover - solve makes them
        raise InvalidInputError("the verification takes a polynomial piece")
    lim = limits_in_force(prob.base, prob.limits, prob.tool_speed, prob.effort is not None)
    try:
        found = verify(prob.base, traj, limits=prob.limits, jerk=prob.jerk, torque=prob.effort is not None,
                       payload=prob.payload, tool_speed=prob.tool_speed, q_start=prob.qA, q_end=prob.qB,
                       scene=prob.scene).check()
    except LimitViolation as exc:
        raise JumpError("VerificationFailed", exc.reason) from None
    T = traj.duration
    b = piece.breakpoints()
    dt = np.diff(b)
    ek, es = extrema(piece)
    grid = np.arange(math.floor(T * VERIFY_RATE + 1e-9) + 1) / VERIFY_RATE
    inner = (b[:-1, None] + dt[:, None] * (np.arange(1, 8) / 8.0)[None, :]).ravel()
    t = np.clip(np.concatenate([grid, inner, b[ek] + es * dt[ek]]), 0.0, T)
    on_grid = np.arange(len(t)) < len(grid)
    q, qd, qdd = traj.sample(t)
    qddd = None if prob.jerk is None else piece.jerk(t)
    ratios = state_ratios(prob.robot, lim, (q, qd, qdd, qddd), prob.jerk)
    table = {quantity.value: r for quantity, r in ratios.items()}
    worst: dict[str, float | None] = {**dict.fromkeys(_QUANTITIES), **found.ratios()}
    for name, r in table.items():
        top = float(np.max(r))
        worst[name] = top if worst.get(name) is None else max(top, worst[name] or 0.0)
        if not top <= 1.0 + TOLERANCE:
            i, j = np.unravel_index(int(np.argmax(r)), r.shape)
            who = "the tool" if name == "tool speed" else prob.robot.joint_names[j]
            raise JumpError("VerificationFailed", f"the {name} of {who} reaches {top:.9g} of its limit at t = "
                            f"{float(t[i]):.6g} s (more than 1 + {TOLERANCE:g})")  # fmt: skip
    poses = np.array([prob.robot.tool_pose(qk) for qk in q])
    dA = np.hypot(poses[:, 0] - prob.A[0], poses[:, 1] - prob.A[1]) - prob.R
    dB = np.hypot(poses[:, 0] - prob.B[0], poses[:, 1] - prob.B[1]) - prob.R
    below = np.minimum(np.minimum(np.maximum(dA, 0.0), np.maximum(dB, 0.0)), np.maximum(prob.z_top - poses[:, 2], 0.0))
    if prob.max_height is not None:
        below = np.maximum(below, poses[:, 2] - prob.max_height)
    clearance_error = float(np.max(below))
    if clearance_error > CLEARANCE_TOL:
        where = float(t[int(np.argmax(below))])
        raise JumpError("VerificationFailed", f"the tool misses the clearance (or the ceiling) by "
                        f"{clearance_error:.3g} m near t = {where:.6g} s (more than {CLEARANCE_TOL:g} m)")  # fmt: skip
    lo = np.where(prob.ranged, prob.lower, -np.inf) - ENDPOINT_TOL
    hi = np.where(prob.ranged, prob.upper, np.inf) + ENDPOINT_TOL
    if ((q < lo) | (q > hi)).any():
        i, j = np.argwhere((q < lo) | (q > hi))[0]
        raise JumpError("VerificationFailed", f"{prob.robot.joint_names[j]} leaves its range at t = "
                        f"{float(t[i]):.6g} s (q = {float(q[i, j]):.9g})")  # fmt: skip
    for end, pose, name in ((0, prob.A, "pose_from"), (-1, prob.B, "pose_to")):
        err = pose_error(prob.robot, traj.sample(0.0 if end == 0 else T)[0], pose)
        if err > ENDPOINT_TOL:
            raise JumpError("VerificationFailed", f"the move misses {name} by {err:.3g} m")
    u = prob.B[:2] - prob.A[:2]
    u = u / np.linalg.norm(u)
    bulge = float(np.max(np.abs((poses[:, 0] - prob.A[0]) * u[1] - (poses[:, 1] - prob.A[1]) * u[0])))
    return Check(t, on_grid, table, worst, clearance_error, float(np.max(poses[:, 2]) - prob.z_top), bulge,
                  found.clearance)


def legs_of(prob: Problem, check: Check, T: np.ndarray) -> tuple[Leg, ...]:
    """Per phase: the most used limit and every binding one with its share of the phase's time."""
    cuts = np.concatenate([[0.0], np.cumsum(T)])
    legs = []
    for p, phase in enumerate(Phase):
        sel = (check.t >= cuts[p]) & (check.t <= cuts[p + 1])
        grid = sel & check.on_grid
        best = ("velocity", 0, -1.0)
        binding = []
        for name, table in check.table.items():
            r = table[sel]
            for j in range(r.shape[1]):
                top = float(np.max(r[:, j])) if len(r) else 0.0
                who = "tool" if name == "tool speed" else prob.robot.joint_names[j]
                if top > best[2]:
                    best = (name, j, top)
                if top >= BINDING:
                    share = float(np.mean(table[grid][:, j] >= BINDING)) if grid.any() else 1.0
                    binding.append(Binding(name, who, top, share))
        binding.sort(key=lambda x: -x.share)
        who = "tool" if best[0] == "tool speed" else prob.robot.joint_names[best[1]]
        closest = None
        if check.distance is not None and prob.scene is not None:
            ts, ds, ps = check.distance.samples
            on = (ts >= cuts[p]) & (ts <= cuts[p + 1])
            if on.any():
                i = int(np.argmin(np.where(on, ds, np.inf)))
                closest = (prob.scene.pairs[int(ps[i])].label, float(ds[i]))
        legs.append(Leg(name=phase.value, move=0, t_start=float(cuts[p]), t_end=float(cuts[p + 1]), active=best[0],
                        joint=who, ratio=best[2], binding=tuple(binding), closest=closest))  # fmt: skip
    return tuple(legs)
