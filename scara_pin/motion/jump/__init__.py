"""Time-optimal jump (arch) moves: from rest at pose A to rest at pose B over a clearance, joint path free.

The task (Epson's JUMP, others' gate or arch motion): the tool leaves A, clears the obstacles between the
two poses and lands on B. Here: the tool must be at least ``rise`` above the higher of the two poses,

    z >= z_top = max(z_A, z_B) + rise,

wherever it is more than ``R`` (``clearance_radius``) horizontally from both A and B; optionally never
above a ceiling ``max_height``; the yaw is held at both ends and free between; the joints respect their
position, velocity, acceleration and, optionally, jerk, effort (with a payload,
:mod:`~scara_pin.motion.payload`) and tool-speed limits. The path in JOINT space is free: the fastest
motion leaves the straight tool line (in plan view it bulges where the elbow stays still and J1 does the
work) and rises above z_top where the quill cannot brake any earlier.

**Transcription** (direct multiple shooting with exact integration). The move has three phases of free
durations T_1, T_2, T_3: LIFT (the tool within R of A horizontally), TRAVERSE (z >= z_top), DESCEND
(within R of B). Phase p has N_p intervals of equal length h_p = T_p / N_p. The control is the joint
acceleration (or, with a jerk limit, the joint jerk), constant on each interval; the states at the nodes
are (q, qd) (or (q, qd, qdd)), linked by the EXACT integrals

    q+ = q + h qd + h^2 / 2 u,  qd+ = qd + h u                                   (acceleration control)
    q+ = q + h qd + h^2 / 2 a + h^3 / 6 j,  qd+ = qd + h a + h^2 / 2 j,  a+ = a + h j       (jerk control)

so the trajectory between nodes is the polynomial itself (:class:`~scara_pin.motion.polynomial.
PolynomialPiece`), not an interpolation. Minimise T_1 + T_2 + T_3 with IPOPT (CasADi, exact Hessians of
the robot's tool position and inverse dynamics written from its Pinocchio model,
:mod:`~scara_pin.symbolic`). Where each bound holds:

- a quantity LINEAR in time on an interval is bounded everywhere on it by its two ends: the velocity and
  acceleration under acceleration control, the acceleration under jerk control; variable bounds at the
  nodes, both ends at rest;
- a POLYNOMIAL one is bounded by the Bernstein control points of its interval (a polynomial stays in their
  convex hull): the joint range (q quadratic or cubic) and, under jerk control, the velocity (quadratic);
  e.g. for q = q0 + v0 t + a0 t^2 / 2 + j t^3 / 6 on [0, h] the points are q0, q0 + v0 h / 3,
  q0 + 2 v0 h / 3 + a0 h^2 / 6, q(h). Slightly conservative where the polynomial peaks inside (0.004 % on
  the jerk-limited s1 cycle);
- the clearance, the ceiling and the tool speed are constraints at the nodes (the clearance of each
  node's phase or phases); the torque, costly to differentiate and seldom binding, is left out of the
  first solve; once it comes within 2 % of a limit anywhere, it is a constraint at every node from then
  on (on both sides of each node under acceleration control, where the control steps);
- then every interval is checked at 33 points and at the polynomial extrema: where the clearance or the
  ceiling is missed by more than 2e-7 m, or the tool speed or the torque exceeded by more than 1e-7
  relative, a constraint is added at that point of that interval (its state is the polynomial of the
  interval's node and control); and the problem is solved again, warm-started, at most
  ``JumpOptions.refinements`` times;
- the torque may still bulge over its limit between two constraint points (a 1e-5 excess 1 ms from the
  nearest point was seen with a 14 kg payload). The rigid-body torque of the motion played ``k`` times
  slower is tau_k(t) = (tau(t/k) - g(q)) / k^2 + g(q) (the velocity enters squared, the acceleration
  once), so the smallest ``k >= 1`` that brings every torque, sampled at 256 points of every interval, to
  its limit is found in closed form and the motion slowed by it (``torque_stretch``: a few 1e-6
  relative at most after the refinement; every other ratio only drops, the path is the same).

Among the minimum-time motions (the time is unique, the path is not: the joints that do not bind can
move in many ways) the objective's small tie-breaking terms (the mean squared joint velocity, then the
smoothness of the controls) pick the calmest: the quill brakes at once after the lift and holds (the lowest
single-hump arch).

**Output.** The states are integrated again from A in floating point with the solved controls, and the
rounding left at B (about the solver's tolerance) is removed by the least-norm change of the controls
that ends exactly at rest at B (the end state is linear in the controls). The result is then verified
by independent routes: the package's verifier (:func:`~scara_pin.motion.verify.verify`:
Pinocchio at 10 kHz and at every breakpoint on both sides, the exact jerk and the jerk by third
differences, the torques with the payload, endpoints, rest), the same ratios inside every interval and at
the polynomial extrema, and the clearance, ceiling,
joint ranges and end poses by Pinocchio's FK; a ratio above 1 + 1e-6, a clearance missed by more than
1e-6 m, an end missed by more than 1e-9 m is an error (:class:`JumpError`), never an output.

**Warm start.** The straight joint lines A -> above A -> above B -> B at z_top (closed-form IK of the two
top poses), each with the quintic law over its synchronised time-optimal duration.

**Return move.** B -> A is the time reversal of A -> B (:meth:`JumpMove.and_back`): the limits are
magnitudes (symmetric), the clearance is symmetric in A and B, and the frictionless rigid-body torque
tau = M(q) qdd + C(q, qd) qd + g(q) is unchanged when qd changes sign (C(q, qd) qd is quadratic in qd),
so the reversed motion is feasible, and optimal (any faster B -> A reversed would beat A -> B).

**Lower bound** (:class:`LowerBound`), proved cheaply: every joint must make its own displacement, so the
move takes at least the slowest joint's 1-DOF minimum time from rest to rest (the closed form of
:func:`~scara_pin.motion.trajectory.line_optimal_duration`; with a jerk limit, ruckig's time-optimal
jerk-limited profile). On a SCARA the quill must also rise to z_top and come back: its up and its down,
each at least the 1-DOF rest-to-rest time (velocity and acceleration limits: at the top of its stroke the
quill is at rest; a jerk limit only adds time). With a tool-speed limit v, the tool must travel from A to B
through the height z_top: at least the length of the straight path A -> X -> B with X on the plane
z = z_top (by reflection, |A - B'| with B' the mirror image of B in that plane), at most v fast. The bound
also sizes the work before any solve (the samples of the verification: a tool speed of 1e-9 m/s is
refused at once, exit 2, instead of running the solver to its iteration limit).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..._checks import as_positive, as_vector
from ...cell import scene as make_scene
from ...errors import InfeasibleError, InvalidInputError
from ...limits import MAX_SAMPLES, check_count
from ..payload import PayloadLike, as_payload, with_payload
from ..trajectory import Trajectory
from ..verify import VERIFY_RATE, Binding, jerk_vector, limits_in_force
from .bound import lower_bound
from .cell import solve_in_cell
from .problem import Problem, default_intervals, endpoints, given_via, holds_still, top_configuration
from .refine import solve
from .types import (
    BINDING,
    CLEARANCE_TOL,
    STANDARD_CLEARANCE,
    STANDARD_RISE,
    JumpError,
    JumpMove,
    JumpOptions,
    Leg,
    LowerBound,
    Phase,
    SolverStats,
)
from .verification import legs_of, verify_move

if TYPE_CHECKING:
    from ..._typing import ArrayLike
    from ...cell import Cell
    from ...description import JointLimits
    from ...model import RobotModel

__all__ = [
    "BINDING",
    "CLEARANCE_TOL",
    "STANDARD_CLEARANCE",
    "STANDARD_RISE",
    "Binding",
    "JumpError",
    "JumpMove",
    "JumpOptions",
    "Leg",
    "LowerBound",
    "Phase",
    "SolverStats",
    "jump_move",
    "lower_bound",
]

def jump_move(
    robot: RobotModel,
    pose_from: ArrayLike,
    pose_to: ArrayLike,
    *,
    rise: float = STANDARD_RISE,
    clearance_radius: float = STANDARD_CLEARANCE,
    max_height: float | None = None,
    payload: PayloadLike = None,
    jerk: float | ArrayLike | None = None,
    torque: bool = True,
    tool_speed: float | None = None,
    limits: JointLimits | None = None,
    start: ArrayLike | None = None,
    end: ArrayLike | None = None,
    branch: str | None = None,
    options: JumpOptions | None = None,
    cell: Cell | None = None,
    via: Sequence[ArrayLike] = (),
) -> JumpMove:
    """The time-optimal jump from rest at ``pose_from`` to rest at ``pose_to`` (module docstring), verified.

    Args:
        robot: a robot with a wrist (4 joints): a SCARA or a palletizer.
        pose_from: (x, y, z, yaw) at the start [m, rad].
        pose_to: (x, y, z, yaw) at the end [m, rad] (the J4 turn nearest the start's).
        rise: [m] > 0, how high above the higher pose the tool must be away from both.
        clearance_radius: [m] > 0, R: within R of a pose (horizontally) the tool may be lower.
        max_height: [m] a ceiling for the tool's z (base frame), or None.
        payload: carried by the tool (torques): a :class:`~scara_pin.motion.payload.Payload` or a mass [kg];
            default none.
        jerk: joint jerk limit [rad/s^3, m/s^3], one or four numbers; None: not limited.
        torque: respect the effort limits (inverse dynamics with the payload).
        tool_speed: [m/s] a limit of the tool origin's speed, or None.
        limits: limits instead of ``robot.limits`` (a URDF file has no accelerations: give them here).
        start: the configuration at ``pose_from`` (fixes the branch and the J4 turn).
        end: the configuration at ``pose_to`` (default: the IK solution nearest the start on its branch).
        branch: the IK branch of both ends ("right"/"left" for a SCARA; default: the start's, or the
            solution nearest the middle of the joint ranges).
        options: grid and solver options.
        cell: obstacles, the carried part and the margin (:class:`~scara_pin.cell.Cell`): every checked pair
            stays at least the margin apart (:mod:`~scara_pin.motion.jump.rows`), the joint path free to go
            around or over (the ways of :mod:`~scara_pin.motion.jump.search`).
        via: hints of the way through the cell: joint configurations the traverse passes near (the local solve
            starts from the joint lines through them, and is free to leave them); each inside the joint limits.

    Raises:
        ParameterError, InvalidInputError: bad input (exit 2), e.g. poses closer than 2 R horizontally; a start
            or goal in collision (:class:`~scara_pin.cell.InCollisionError`, naming the pair).
        InfeasibleError: a pose or the traverse height out of reach, a ceiling below the needed height
            (exit 3); :class:`JumpError` (exit 3): the solver failed, with its reason.
    """
    t0 = time.perf_counter()
    options = JumpOptions() if options is None else options
    if robot.dof != 4:
        raise InvalidInputError(f"a jump move needs a wrist (4 joints); robot {robot.name!r} has {robot.dof}")
    A, B = as_vector("pose_from", pose_from), as_vector("pose_to", pose_to)
    rise = as_positive("rise", rise, "m")
    R = as_positive("clearance_radius", clearance_radius, "m")
    ceiling = None
    if max_height is not None:
        ceiling = float(as_vector("max_height", [max_height], 1)[0])
    payload = as_payload(payload)
    lim = limits_in_force(robot, limits, tool_speed, torque)
    jv = None if jerk is None else jerk_vector(jerk)
    D = float(np.hypot(*(B[:2] - A[:2])))
    if D <= 2.0 * R:
        raise InvalidInputError(f"the poses are {D:.6g} m apart horizontally, not more than twice the clearance "
                                f"radius {R:.6g} m: no clearance applies (a straight move: traj --linear)")  # fmt: skip
    z_top = max(float(A[2]), float(B[2])) + rise
    if ceiling is not None and ceiling < z_top:
        raise InfeasibleError(f"max_height {ceiling:.6g} m is below the height the clearance needs: z_top = "
                              f"{z_top:.6g} m (rise {rise:.6g} m above the higher pose)")  # fmt: skip
    qA, qB = endpoints(robot, A, B, start, end, branch)
    hints = tuple(given_via(robot, v, i) for i, v in enumerate(via))
    if hints and cell is None:
        raise InvalidInputError("via points are hints of the way through a cell: give the cell too")
    scene = None
    if cell is not None:
        scene = make_scene(robot, cell)
        scene.check(qA, "the start (pose_from)")
        scene.check(qB, "the goal (pose_to)")
    tops = (top_configuration(robot, A, z_top, qA, "pose_from", rise),
            top_configuration(robot, B, z_top, qB, "pose_to", rise))
    # size the work before doing it: the cheap bound (no ruckig) already says how many samples it will take
    cheap = lower_bound(robot, qA, qB, tops, lim.velocity, lim.acceleration, jv, exact_jerk=False,
                        tool_speed=lim.tool_speed)  # fmt: skip
    check_count(f"verified samples (at least {cheap.duration:.6g} s at {VERIFY_RATE:g} Hz)",
                2.0 * cheap.duration * VERIFY_RATE, MAX_SAMPLES,
                f"the move takes at least that long under these limits ({cheap.reason}): check the velocity, "
                "acceleration, jerk and tool-speed limits")  # fmt: skip
    bound = lower_bound(robot, qA, qB, tops, lim.velocity, lim.acceleration, jv, tool_speed=lim.tool_speed)
    loaded = with_payload(robot, payload) if torque else robot
    if lim.effort is not None:
        holds_still(loaded, (qA, qB, *tops), lim.effort)
    from ...symbolic import symbolic_model

    N = default_intervals(jv is not None, tool_speed is not None) if options.intervals is None else options.intervals
    lim_all = robot.limits if limits is None else limits
    prob = Problem(robot=loaded, sym=symbolic_model(loaded), base=robot, payload=payload, limits=limits, A=A, B=B,
                   qA=qA, qB=qB, q_tops=tops, z_top=z_top, R=R, max_height=ceiling, lower=np.array(lim_all.lower),
                   upper=np.array(lim_all.upper), ranged=~np.array(robot.continuous), velocity=lim.velocity,
                   acceleration=lim.acceleration, jerk=jv, effort=lim.effort, tool_speed=lim.tool_speed, N=N,
                   t_scale=max(bound.duration / 3.0, 1e-3), scene=scene)  # fmt: skip
    if scene is None:
        piece, T, stats = solve(prob, options)
        traj = Trajectory((piece,))
        check = verify_move(prob, traj)
    else:
        piece, T, stats, traj, check = solve_in_cell(prob, options, scene, ceiling, hints)
    legs = legs_of(prob, check, T)
    stats = replace(stats, seconds=time.perf_counter() - t0)
    return JumpMove(trajectory=traj, pose_from=A, pose_to=B, q_from=qA, q_to=qB, rise=rise, clearance_radius=R,
                    z_top=z_top, max_height=ceiling, phases=(float(T[0]), float(T[1]), float(T[2])), legs=legs,
                    ratios=check.ratios, clearance=check.clearance_error, peak=check.peak, bulge=check.bulge,
                    payload=payload, jerk=None if jv is None else tuple(jv.tolist()), tool_speed=lim.tool_speed,
                    lower_bound=bound, stats=stats, cell=cell, distance=check.distance)  # fmt: skip
