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
  its limit is found in closed form and the motion slowed by it (``_torque_stretch``: a few 1e-6
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

import enum
import logging
import math
import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import as_positive, as_vector
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..kinematics.validate import pose_error
from ..limits import MAX_SAMPLES, check_count
from ..summary import Summarized
from ..units import SI, DisplayUnits
from .payload import Payload, PayloadLike, as_payload, with_payload
from .polynomial import PolynomialPiece
from .trajectory import Trajectory, line_optimal_duration
from .verify import (
    ENDPOINT_TOL,
    TOLERANCE,
    VERIFY_RATE,
    Clearance,
    LimitViolation,
    jerk_vector,
    limits_in_force,
    state_ratios,
    static_load,
    static_overload,
    verify,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..cell import Cell, Scene
    from ..description import JointLimits
    from ..model import RobotModel
    from ..symbolic import SymbolicModel
    from ..units import DisplayUnits
    from .avoid import DistanceRow, Rows

__all__ = [
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

logger = logging.getLogger(__name__)

STANDARD_RISE = 0.025
"""[m] the vertical stroke of the standard cycle, and the default rise of a jump."""
STANDARD_CLEARANCE = 0.005
"""[m] the default clearance radius R: within R of an endpoint (horizontally) the tool may be low."""
CLEARANCE_TOL = 1e-6
"""[m] how far below z_top (outside both circles), or above the ceiling, the verified tool may be."""
BINDING = 0.999
"""A limit is binding on a leg where its ratio reaches this."""
_CHECK_POINTS = 32
"""Points checked inside every interval for the refinement (besides the polynomial extrema)."""
_REFINE_RATIO = 1e-7
"""Relative excess (torque, tool speed) above which a constraint is added inside an interval."""
_REFINE_GEOMETRY = 2e-7
"""[m] excess of the clearance or the ceiling above which a constraint is added inside an interval."""
_TIE_VELOCITY = 1e-4
"""Weight of the mean squared joint velocity over its limit (relative to the duration over ``t_scale``): among
the minimum-time motions (the time is unique, the path is not: the joints that do not bind can move in many
ways) the calmest: the quill brakes at once after the lift, holds, and comes down as late as it can (the
lowest single-hump arch), the elbow and the wrist move smoothly; its effect on the time is below 1e-9 relative
on the standard cycle."""
_TIE_SMOOTH = 1e-6
"""Weight of the mean squared scaled control: then the smoothest controls of the joints that do not bind."""
_LAZY = ("torque",)
"""Constraint families left out of the first solve (the torque is costly to differentiate and rarely binds):
once one comes within _NEAR of its limit anywhere, it is constrained at every node (both sides) and re-solved.
(Only on the intervals near the limit, as before, the solutions moved the excess from interval to interval
until the refinements ran out: 1.06 to 3.6 times the torque limit with large acceleration limits.)"""
_NEAR = 0.02
_NODES = -1
"""The interval index of a :class:`_Point` that stands for every node (both sides) of its family."""
_STRETCH_POINTS = 256
"""Points per interval where ``_torque_stretch`` samples the torque."""
_QUANTITIES = ("velocity", "acceleration", "jerk", "torque", "tool speed")


class Phase(enum.Enum):
    """A phase of a jump; the value is its name in reports."""

    LIFT = "lift"
    TRAVERSE = "traverse"
    DESCEND = "descend"


class JumpError(InfeasibleError):
    """The jump could not be planned: the solver failed or found the constraints infeasible (exit code 3).

    Attributes:
        status: IPOPT's return status (``Infeasible_Problem_Detected``, ``Maximum_Iterations_Exceeded``, ...),
            or ``VerificationFailed`` when the verification of a solution failed.
        reason: the sentence.
    """

    def __init__(self, status: str, reason: str) -> None:
        self.status = status
        self.reason = reason
        super().__init__(f"jump move: {reason} [{status}]")


@dataclass(frozen=True)
class JumpOptions:
    """Options of :func:`jump_move`.

    Attributes:
        intervals: (lift, traverse, descend) interval counts; None: (10, 14, 10) under acceleration control,
            (16, 24, 16) with a jerk limit (within 0.1 % of the converged minimum on the standard cycle), the
            traverse's doubled with a tool-speed limit.
        tolerance: IPOPT's convergence tolerance (scaled problem).
        max_iterations: per solve.
        refinements: at most this many re-solves with constraints added inside intervals.
        avoid_iterations: with a cell, at most this many more re-solves for the obstacle distances
            (re-linearised each time, :mod:`~scara_pin.motion.avoid`).
    """

    intervals: tuple[int, int, int] | None = None
    tolerance: float = 1e-10
    max_iterations: int = 3000
    refinements: int = 6
    avoid_iterations: int = 40

    def __post_init__(self) -> None:
        if self.intervals is not None:
            n = tuple(self.intervals)
            if len(n) != 3 or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) and 1 <= v <= 500
                                      for v in n):  # fmt: skip
                raise ParameterError("intervals", self.intervals, "must be 3 integers in [1, 500]")
            object.__setattr__(self, "intervals", tuple(int(v) for v in n))
        as_positive("tolerance", self.tolerance)
        for name in ("max_iterations", "refinements", "avoid_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 0 <= v <= 100_000:
                raise ParameterError(name, v, "must be an integer in [0, 100000]")


@dataclass(frozen=True)
class SolverStats:
    """How the solution was found.

    Attributes:
        status: IPOPT's return status of the last solve (``Solve_Succeeded``).
        iterations: IPOPT iterations, all solves.
        solves: the number of solves (1 + refinements done).
        intervals: (lift, traverse, descend) interval counts.
        variables, constraints: the size of the last problem.
        seconds: wall time of the planning (transcription, solves, reconstruction, verification) [s].
    """

    status: str
    iterations: int
    solves: int
    intervals: tuple[int, int, int]
    variables: int
    constraints: int
    seconds: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"solver": "ipopt (casadi)", "status": self.status, "iterations": self.iterations,
                "solves": self.solves, "intervals": list(self.intervals), "variables": self.variables,
                "constraints": self.constraints, "seconds": self.seconds}  # fmt: skip


@dataclass(frozen=True)
class LowerBound:
    """A duration no motion of the move can beat, and why (module docstring).

    Attributes:
        duration: [s].
        joint: the joint whose own minimum it is.
        reason: how it was obtained (a sentence).
    """

    duration: float
    joint: str
    reason: str

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"duration": self.duration, "joint": self.joint, "reason": self.reason}


@dataclass(frozen=True)
class Binding:
    """A limit that binds on a leg.

    Attributes:
        quantity: "velocity", "acceleration", "jerk", "torque" or "tool speed".
        joint: the joint ("tool" for the tool speed).
        ratio: its largest |value| / limit on the leg.
        share: the fraction of the leg's time it is at >= :data:`BINDING` of the limit.
    """

    quantity: str
    joint: str
    ratio: float
    share: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"quantity": self.quantity, "joint": self.joint, "ratio": self.ratio, "share": self.share}


@dataclass(frozen=True)
class Leg:
    """One leg of a move: its time span and the limit that is active (closest to 1) on it.

    Attributes:
        name: "lift", "traverse", "descend" (jump) or "lift", "blend up", "traverse", "blend down",
            "descend" (straight-leg arch).
        move: index of the move in the cycle (0 out, 1 back).
        t_start, t_end: [s] in the whole trajectory.
        active: the quantity ("velocity", "acceleration", "torque", "jerk") with the largest ratio on it.
        joint: the joint where that ratio is reached.
        ratio: |value| / limit there (1.0: on the limit).
        binding: every limit at >= :data:`BINDING` on the leg, with its share of the leg's time.
        closest: with a cell, the pair that comes closest on the leg and its distance [m].
    """

    name: str
    move: int
    t_start: float
    t_end: float
    active: str
    joint: str
    ratio: float
    binding: tuple[Binding, ...] = ()
    closest: tuple[str, float] | None = None

    @property
    def duration(self) -> float:
        """[s]."""
        return self.t_end - self.t_start

    def line(self, units: DisplayUnits | None = None) -> str:
        """The leg in one line, as ``scara-pin cycle`` prints it.

        Ratios have no unit, times are in s; in a cell, the closest pair's distance is in ``units``' length unit
        (default m).
        """
        binding = ", ".join(f"{bd.quantity} {bd.joint} {100 * bd.share:.0f} %" for bd in self.binding)
        return (f"  {'out ' if self.move == 0 else 'back'} {self.name:<11} {self.duration:9.6f} s   {self.active} of "
                f"{self.joint} at {self.ratio:.4f} of its limit" + (f"; binding: {binding}" if binding else "")
                + self.closest_words(units))  # fmt: skip

    def closest_words(self, units: DisplayUnits | None = None) -> str:
        """``; closest link2 - post 0.002006 m`` for a leg planned in a cell (in ``units``' lengths), else ""."""
        if self.closest is None:
            return ""
        from ..units import SI

        u = SI if units is None else units
        return f"; closest {self.closest[0]} {u.format(self.closest[1], 'length')} {u.name('length')}"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        out = {"name": self.name, "move": self.move, "t_start": self.t_start, "t_end": self.t_end,
               "duration": self.duration, "active_limit": self.active, "joint": self.joint, "ratio": self.ratio,
               "binding": [b.to_dict() for b in self.binding]}  # fmt: skip
        if self.closest is not None:
            out["closest"] = {"pair": self.closest[0], "distance": self.closest[1]}
        return out


@dataclass(frozen=True, eq=False, repr=False)
class JumpMove(Summarized):
    """A verified time-optimal jump (or the cycle out and back) and how its limits are used.

    Attributes:
        trajectory: the trajectory (one :class:`~scara_pin.motion.polynomial.PolynomialPiece` per move).
        pose_from, pose_to: the poses (x, y, z, yaw) of the (first) move [m, rad].
        q_from, q_to: the configurations at them.
        rise, clearance_radius: [m] the clearance asked for; z_top: [m] the height to clear.
        max_height: [m] the ceiling, or None.
        phases: (lift, traverse, descend) durations of the (first) move [s].
        legs: the legs with their times and binding limits.
        ratios: worst verified ratio per quantity ("velocity", "acceleration", "jerk", "torque", "tool speed";
            None where not limited).
        clearance: [m] how far the verified tool came from the allowed region (below z_top while outside
            both circles, or above the ceiling): 0 when kept, never more than 1e-6 m.
        peak: [m] the highest tool z above z_top.
        bulge: [m] the largest horizontal distance of the tool from the straight line A-B in plan view.
        payload: the payload carried; jerk: the jerk limits per joint, or None; tool_speed: [m/s] or None.
        lower_bound: what no motion can beat (per move; the cycle's is twice it).
        stats: how the solver got there.
        moves: 1 (A -> B) or 2 (and back).
        cell: the cell the move was planned in, or None.
        distance: with a cell, the smallest verified distance of its checked pairs, which and when.
    """

    trajectory: Trajectory
    pose_from: np.ndarray
    pose_to: np.ndarray
    q_from: np.ndarray
    q_to: np.ndarray
    rise: float
    clearance_radius: float
    z_top: float
    max_height: float | None
    phases: tuple[float, float, float]
    legs: tuple[Leg, ...]
    ratios: dict[str, float | None]
    clearance: float
    peak: float
    bulge: float
    payload: Payload
    jerk: tuple[float, ...] | None
    tool_speed: float | None
    lower_bound: LowerBound
    stats: SolverStats
    moves: int = 1
    cell: Cell | None = None
    distance: Clearance | None = None

    @property
    def duration(self) -> float:
        """[s]."""
        return self.trajectory.duration

    @property
    def gap(self) -> float:
        """The duration above the lower bound, relative (0.2: 20 % above)."""
        return self.duration / (self.moves * self.lower_bound.duration) - 1.0

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The move in a few lines: its time, the bound, the arch, the legs (lengths in ``units``, default SI)."""
        u = SI if units is None else units
        Ln = u.name("length")
        what = "jump move" if self.moves == 1 else f"jump cycle ({self.moves} moves)"
        return "\n".join([
            f"{what}   {self.duration:.6f} s, {100 * self.gap:.1f} % above its lower bound "
            f"{self.moves * self.lower_bound.duration:.6f} s ({self.lower_bound.reason})",
            f"from {u.format_vector(self.pose_from[:3], 'length')} to {u.format_vector(self.pose_to[:3], 'length')} "
            f"{Ln}, payload {self.payload.mass:g} kg" + (f", jerk limit {list(self.jerk)}" if self.jerk else ""),
            f"arch   up to {u.format(self.z_top + self.peak, 'length')} {Ln} ({u.format(self.peak, 'length')} {Ln} "
            f"above the clearance height), {u.format(self.bulge, 'length')} {Ln} off the straight line in plan view",
            "legs   (binding limits: the share of the leg's time at >= 99.9 % of the limit)",
            *(leg.line(u) for leg in self.legs),
        ])  # fmt: skip

    def and_back(self) -> JumpMove:
        """The move followed by its time reversal (B -> A): the cycle (module docstring, "Return move")."""
        if self.moves != 1:
            raise InvalidInputError("and_back takes a single move")
        piece = self.trajectory.pieces[0]
        if not isinstance(piece, PolynomialPiece):  # pragma: no cover - jump_move makes them
            raise InvalidInputError("and_back needs a jump move")
        T = self.trajectory.duration
        back = [Leg(leg.name if leg.name == Phase.TRAVERSE.value else _MIRROR[leg.name], 1, 2 * T - leg.t_end,
                    2 * T - leg.t_start, leg.active, leg.joint, leg.ratio, leg.binding, leg.closest)
                for leg in reversed(self.legs)]  # fmt: skip
        traj = Trajectory((piece, piece.reversed()))
        return replace(self, trajectory=traj, legs=self.legs + tuple(back), moves=2)


_MIRROR = {Phase.LIFT.value: Phase.DESCEND.value, Phase.DESCEND.value: Phase.LIFT.value}


# ---------------------------------------------------------------------------------------------- the problem
@dataclass(frozen=True, eq=False)
class _Problem:
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
        return 2 if self.jerk is None else 3

    @property
    def control_limit(self) -> np.ndarray:
        return self.acceleration if self.jerk is None else self.jerk

    @property
    def state_scale(self) -> np.ndarray:
        """(order, dof): position, velocity (and acceleration) scales of the variables."""
        rows = [self.velocity * self.t_scale, self.velocity] + ([self.acceleration] if self.jerk is not None else [])
        return np.array(rows)

    def phase_of(self) -> np.ndarray:
        """Phase index of every interval."""
        return np.repeat(np.arange(3), self.N)


@dataclass(frozen=True)
class _Point:
    """A constraint point inside interval ``k`` at fraction ``sigma`` of it, for one family of constraints.

    ``k`` = :data:`_NODES`: the family at every node instead (both sides; a lazy family, :data:`_LAZY`).
    """

    k: int
    sigma: float
    family: str  # "geometry", "torque", "tool speed"


def _propagate(order: int, state: list[Any], u: Any, tau: Any) -> list[Any]:
    """The state after ``tau`` of constant control ``u``, exactly (elementwise: numbers, arrays, CasADi matrices)."""
    if order == 2:
        q, v = state
        return [q + v * tau + u * (tau * tau / 2.0), v + u * tau]
    q, v, a = state
    return [q + v * tau + a * (tau * tau / 2.0) + u * (tau * tau * tau / 6.0), v + a * tau + u * (tau * tau / 2.0),
            a + u * tau]  # fmt: skip


# ---------------------------------------------------------------------------------------------- transcription
class _Transcription:
    """The NLP of a move with interior points added by the refinement (module docstring).

    Variables (scaled to order 1): the phase durations over ``t_scale``, the node states over
    ``state_scale``, the controls over their limits. At the nodes: the exact integration between them, the
    clearance of each node's phase(s) and the ceiling; the velocity, acceleration (jerk control) and
    joint range as variable bounds, both ends at rest. The torque and the tool speed, and everything
    between nodes, only where the refinement put a point (a node's two sides are sigma = 0 and 1 of its
    intervals).
    """

    def __init__(self, prob: _Problem, points: tuple[_Point, ...], options: JumpOptions,
                 distance_rows: tuple[DistanceRow, ...] = (), avoid: Rows | None = None,
                 resolve: bool = False) -> None:  # fmt: skip
        import casadi as ca

        self.prob = P = prob
        order, dof, N = P.order, P.robot.dof, P.N
        Nt = sum(N)
        sx = P.state_scale
        T = ca.SX.sym("T", 3)
        X = ca.SX.sym("X", order * dof, Nt + 1)
        U = ca.SX.sym("U", dof, Nt)
        h, rows, Up = self._physical(T, X, U)
        g: list[Any] = []
        lb: list[np.ndarray] = []
        ub: list[np.ndarray] = []

        def add(expr: Any, lo: Any, hi: Any) -> None:
            e = ca.vec(expr)
            n = e.shape[0]
            g.append(e)
            lb.append(np.broadcast_to(np.asarray(lo, dtype=float), (n,)).ravel())
            ub.append(np.broadcast_to(np.asarray(hi, dtype=float), (n,)).ravel())

        nxt = _propagate(order, [r[:, :Nt] for r in rows], Up, ca.repmat(h, dof, 1))
        for i in range(order):  # exact integration between nodes
            add((nxt[i] - rows[i][:, 1:]) / ca.repmat(ca.DM(sx[i]), 1, Nt), 0.0, 0.0)
        # between nodes, the joint range and (jerk control) the velocity by the Bernstein control points of the
        # polynomial on each interval: the polynomial stays in their convex hull
        H = ca.repmat(h, dof, 1)
        q0, v0 = rows[0][:, :Nt], rows[1][:, :Nt]
        if order == 2:
            hull = [q0 + v0 * H / 2.0]
        else:
            hull = [q0 + v0 * H / 3.0, q0 + v0 * H * (2.0 / 3.0) + rows[2][:, :Nt] * H * H / 6.0]
        span = ca.repmat(ca.DM(sx[0]), 1, Nt)
        for b in hull:
            add((b - ca.repmat(ca.DM(P.lower), 1, Nt)) / span, np.tile(np.where(P.ranged, 0.0, -np.inf), Nt), np.inf)
            add((b - ca.repmat(ca.DM(P.upper), 1, Nt)) / span, -np.inf, np.tile(np.where(P.ranged, 0.0, np.inf), Nt))
        if order == 3:
            add((v0 + rows[2][:, :Nt] * H / 2.0) / ca.repmat(ca.DM(P.velocity), 1, Nt), -1.0, 1.0)
        scale_z = max(P.z_top - min(P.A[2], P.B[2]), 1e-3)

        def geometry(q: Any, phase: np.ndarray) -> None:
            """The clearance of each column's phase(s) (phase: (n, 3) booleans) and the ceiling."""
            p = P.sym.tool_position.map(q.shape[1])(q)
            for ph, centre in ((0, P.A), (2, P.B)):
                cols = np.nonzero(phase[:, ph])[0].tolist()
                if cols:
                    d2 = (p[0, cols] - centre[0]) ** 2 + (p[1, cols] - centre[1]) ** 2
                    add(d2 / (P.R * P.R), -np.inf, 1.0)
            cols = np.nonzero(phase[:, 1])[0].tolist()
            if cols:
                add((p[2, cols] - P.z_top) / scale_z, 0.0, np.inf)
            if P.max_height is not None:
                add((p[2, :] - P.max_height) / scale_z, -np.inf, 0.0)

        k_nodes = np.arange(Nt + 1)
        cut = (N[0], N[0] + N[1])
        geometry(rows[0], np.column_stack([k_nodes <= cut[0], (k_nodes >= cut[0]) & (k_nodes <= cut[1]),
                                           k_nodes >= cut[1]]))  # fmt: skip
        if P.tool_speed is not None:
            v = P.sym.tool_velocity.map(Nt + 1)(rows[0], rows[1])
            add(ca.sum1(v * v) / P.tool_speed**2, -np.inf, 1.0)
        if P.effort is not None and _Point(_NODES, 0.0, "torque") in points:  # at every node
            # acceleration control: both sides (each interval's start and end with its own control); jerk: once
            sides = [(slice(0, Nt), Up), (slice(1, Nt + 1), Up)] if order == 2 else [(slice(0, Nt + 1), rows[2])]
            for cols, acc in sides:
                m = cols.stop - cols.start
                tau_ = P.sym.inverse_dynamics.map(m)(rows[0][:, cols], rows[1][:, cols], acc)
                add(tau_ / ca.repmat(ca.DM(P.effort), 1, m), -1.0, 1.0)
        phase_of = P.phase_of()
        for family in ("geometry", "torque", "tool speed"):
            pts = [pt for pt in points if pt.family == family and pt.k != _NODES]
            if not pts:
                continue
            ks = [pt.k for pt in pts]
            n = len(ks)
            tau = ca.repmat(h[0, ks] * ca.DM([pt.sigma for pt in pts]).T, dof, 1)
            st = _propagate(order, [r[:, ks] for r in rows], Up[:, ks], tau)
            acc = Up[:, ks] if order == 2 else st[2]
            if family == "geometry":
                geometry(st[0], np.eye(3, dtype=bool)[phase_of[ks]])
            elif family == "torque" and P.effort is not None:
                tau_ = P.sym.inverse_dynamics.map(n)(st[0], st[1], acc)
                add(tau_ / ca.repmat(ca.DM(P.effort), 1, n), -1.0, 1.0)
            elif family == "tool speed" and P.tool_speed is not None:
                v = P.sym.tool_velocity.map(n)(st[0], st[1])
                add(ca.sum1(v * v) / P.tool_speed**2, -np.inf, 1.0)
        self.n_rows = len(distance_rows)
        w = ca.vertcat(T, ca.vec(X), ca.vec(U))
        G = ca.vertcat(*g)
        # minimum time; then, as tie-breakers among the minimum-time motions, the lowest arch and smooth controls
        f = (ca.sum1(T) + _TIE_VELOCITY * ca.sumsqr(X[dof : 2 * dof, :]) / (dof * (Nt + 1))
             + _TIE_SMOOTH * ca.sumsqr(U) / (dof * Nt))  # fmt: skip
        nlp = {"x": w, "f": f, "g": G}
        if distance_rows and avoid is not None:
            nlp = self._with_rows(nlp, distance_rows, avoid)
            lb.append(np.zeros(len(distance_rows)))
            ub.append(np.full(len(distance_rows), np.inf))
            G = nlp["g"]
        self.n_x, self.n_g = int(w.shape[0]), int(G.shape[0])
        self.lbg, self.ubg = np.concatenate(lb), np.concatenate(ub)
        lbx_X = np.empty((order * dof, Nt + 1))
        ubx_X = np.empty((order * dof, Nt + 1))
        lbx_X[:dof] = (np.where(P.ranged, P.lower, -np.inf) / sx[0])[:, None]
        ubx_X[:dof] = (np.where(P.ranged, P.upper, np.inf) / sx[0])[:, None]
        lbx_X[dof:] = -1.0
        ubx_X[dof:] = 1.0
        for col, q in ((0, P.qA), (Nt, P.qB)):  # both ends: at the pose, at rest
            lbx_X[:, col] = ubx_X[:, col] = 0.0
            lbx_X[:dof, col] = ubx_X[:dof, col] = q / sx[0]
        self.lbx = np.concatenate([np.full(3, 1e-4), lbx_X.ravel(order="F"), -np.ones(dof * Nt)])
        self.ubx = np.concatenate([np.full(3, 1e4), ubx_X.ravel(order="F"), np.ones(dof * Nt)])
        opts: dict[str, Any] = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False,
                                "ipopt.tol": options.tolerance, "ipopt.constr_viol_tol": options.tolerance,
                                "ipopt.max_iter": options.max_iterations, "ipopt.mu_strategy": "adaptive"}  # fmt: skip
        if resolve:  # a re-solve from the last solution (obstacle rows re-set): it converges fast or not at all
            from .avoid import RESOLVE_ITERATIONS

            opts["ipopt.max_iter"] = min(options.max_iterations, RESOLVE_ITERATIONS)
        self.solver = ca.nlpsol("jump", "ipopt", nlp, opts)
        self.shape = (order, dof, Nt)

    def _physical(self, T: Any, X: Any, U: Any) -> tuple[Any, list[Any], Any]:
        """(interval lengths (1, Nt), state rows [q, qd(, qdd)] (dof, Nt + 1), controls (dof, Nt)) in SI units."""
        import casadi as ca

        P = self.prob
        order, dof, N = P.order, P.robot.dof, P.N
        Nt = sum(N)
        Xp = ca.repmat(ca.DM(P.state_scale.ravel()), 1, Nt + 1) * X
        Up = ca.repmat(ca.DM(P.control_limit), 1, Nt) * U
        h = ca.horzcat(*[ca.repmat(T[p] * (P.t_scale / N[p]), 1, N[p]) for p in range(3)])  # 1 x Nt
        return h, [Xp[i * dof : (i + 1) * dof, :] for i in range(order)], Up

    def _with_rows(self, nlp: dict[str, Any], distance_rows: tuple[DistanceRow, ...], avoid: Rows) -> dict[str, Any]:
        """The NLP with the obstacle rows (:mod:`~scara_pin.motion.avoid`) appended to its constraints.

        Each row keeps its pair's first shape beyond a separating plane taken from the last solution: the
        planes are parameters (9 per row), re-set after every solve without rebuilding the problem. The forward
        kinematics of each row's point is written once (mapped over the points), and each pair's separation
        function is called on it.
        """
        import casadi as ca

        from .avoid import BUFFER, DISTANCE_SCALE

        P = self.prob
        order, dof = P.order, P.robot.dof
        Nt = sum(P.N)
        w = nlp["x"]
        Pd = ca.SX.sym("Pd", len(distance_rows) * avoid.PARAMETERS)
        nX = order * dof * (Nt + 1)
        h, rows, Up = self._physical(w[:3], ca.reshape(w[3 : 3 + nX], order * dof, Nt + 1),
                                     ca.reshape(w[3 + nX :], dof, Nt))  # fmt: skip
        par = ca.reshape(Pd, avoid.PARAMETERS, len(distance_rows))
        keys = sorted({(r.k, r.sigma) for r in distance_rows})
        where = {key: c for c, key in enumerate(keys)}
        ks = [k for k, _ in keys]
        tau = ca.repmat(h[0, ks] * ca.DM([sg for _, sg in keys]).T, dof, 1)
        qs = _propagate(order, [r[:, ks] for r in rows], Up[:, ks], tau)[0]  # dof x points
        frames = P.sym.joint_frames.map(len(keys))(qs)  # 12 x (njoints * points)
        nj = frames.shape[1] // len(keys)
        seps = []
        for i, r in enumerate(distance_rows):
            ja, jb = avoid.joints(r.pair)
            c = where[(r.k, r.sigma)]
            seps.append(avoid.function(r.pair)(frames[:, c * nj + ja], frames[:, c * nj + jb], par[0:3, i],
                                               par[3:6, i], par[6:9, i]))  # fmt: skip
        g_rows = (ca.vertcat(*seps) - (avoid.margin + BUFFER)) / DISTANCE_SCALE
        return {"x": w, "f": nlp["f"], "g": ca.vertcat(nlp["g"], g_rows), "p": Pd}

    def solve(self, x0: np.ndarray, lam_x: np.ndarray | None, lam_g: np.ndarray | None,
              params: np.ndarray | None = None) -> dict[str, Any]:  # fmt: skip
        """One IPOPT solve from x0 (and multipliers, when warm-starting); ``params``: the distance rows' (g, c)."""
        kwargs: dict[str, Any] = {"x0": x0, "lbx": self.lbx, "ubx": self.ubx, "lbg": self.lbg, "ubg": self.ubg,
                                  "p": np.zeros(0) if params is None else params}  # fmt: skip
        if lam_x is not None:
            kwargs["lam_x0"] = lam_x
        if lam_g is not None:
            kwargs["lam_g0"] = lam_g
        sol = self.solver(**kwargs)
        stats = self.solver.stats()
        return {"x": np.array(sol["x"]).ravel(), "lam_x": np.array(sol["lam_x"]).ravel(),
                "lam_g": np.array(sol["lam_g"]).ravel(), "status": str(stats["return_status"]),
                "success": bool(stats["success"]), "iterations": int(stats["iter_count"])}  # fmt: skip

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(T (3,), states (Nt + 1, order, dof), controls (Nt, dof)) in SI from the scaled variables."""
        order, dof, Nt = self.shape
        P = self.prob
        T = x[:3] * P.t_scale
        X = x[3 : 3 + order * dof * (Nt + 1)].reshape((Nt + 1, order, dof)) * P.state_scale[None]
        U = x[3 + order * dof * (Nt + 1) :].reshape((Nt, dof)) * P.control_limit[None]
        return T, X, U

    def pack(self, T: np.ndarray, X: np.ndarray, U: np.ndarray) -> np.ndarray:
        """The scaled variables of (T, states, controls) in SI."""
        P = self.prob
        return np.concatenate([T / P.t_scale, (X / P.state_scale[None]).ravel(), (U / P.control_limit[None]).ravel()])


# ---------------------------------------------------------------------------------------------- the move
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
            stays at least the margin apart (:mod:`~scara_pin.motion.avoid`), the joint path free to go
            around or over.

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
    qA, qB = _endpoints(robot, A, B, start, end, branch)
    scene = None
    if cell is not None:
        from ..cell import scene as make_scene

        scene = make_scene(robot, cell)
        scene.check(qA, "the start (pose_from)")
        scene.check(qB, "the goal (pose_to)")
    tops = (_top(robot, A, z_top, qA, "pose_from", rise), _top(robot, B, z_top, qB, "pose_to", rise))
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
        _holds_still(loaded, (qA, qB, *tops), lim.effort)
    from ..symbolic import symbolic_model

    N = _default_intervals(jv is not None, tool_speed is not None) if options.intervals is None else options.intervals
    lim_all = robot.limits if limits is None else limits
    prob = _Problem(loaded, symbolic_model(loaded), robot, payload, limits, A, B, qA, qB, tops, z_top, R, ceiling,
                    np.array(lim_all.lower), np.array(lim_all.upper), ~np.array(robot.continuous), lim.velocity,
                    lim.acceleration, jv, lim.effort, lim.tool_speed, N, max(bound.duration / 3.0, 1e-3),
                    scene)  # fmt: skip
    if scene is None:
        piece, T, stats = _solve(prob, options)
        traj = Trajectory((piece,))
        check = _verify(prob, traj)
    else:
        piece, T, stats, traj, check = _solve_in_cell(prob, options, scene, ceiling)
    legs = _legs(prob, check, T)
    stats = replace(stats, seconds=time.perf_counter() - t0)
    return JumpMove(traj, A, B, qA, qB, rise, R, z_top, ceiling, (float(T[0]), float(T[1]), float(T[2])), legs,
                    check.ratios, check.clearance_error, check.peak, check.bulge, payload,
                    None if jv is None else tuple(jv.tolist()), lim.tool_speed, bound, stats,
                    cell=cell, distance=check.distance)  # fmt: skip


def _solve_in_cell(prob: _Problem, options: JumpOptions, scene: Scene, ceiling: float | None
                   ) -> tuple[PolynomialPiece, np.ndarray, SolverStats, Trajectory, _Check]:  # fmt: skip
    """The best warm starts around or over the obstacles, each solved and verified; the fastest wins."""
    from .avoid import RESOLVE_ITERATIONS, SECOND_WITHIN, blocked, candidates, solve_avoiding

    found = candidates(scene, prob.qA, prob.qB, prob.q_tops, prob.A, prob.B, prob.z_top, ceiling, prob.velocity,
                       prob.acceleration)  # fmt: skip
    if found[0].clearance < 0.0:  # no way tried clears: one attempt from the least colliding, on a short budget
        short = replace(options, max_iterations=min(options.max_iterations, RESOLVE_ITERATIONS))
        try:
            piece, T, stats = solve_avoiding(prob, short, found[0].waypoints)
            traj = Trajectory((piece,))
            return piece, T, stats, traj, _verify(prob, traj)
        except JumpError as exc:
            raise blocked(scene, found, exc.status) from None
    way = found[0].way.split(",")[0]  # over, left or right
    tries = found[:1] + [c for c in found[1:] if c.way.split(",")[0] != way and c.duration <= SECOND_WITHIN
                         * found[0].duration][:1]  # fmt: skip
    best = None
    error: Exception | None = None
    iterations = 0
    for cand in tries:
        logger.debug("jump in a cell: warm start %s (%.4g s, clearance %.3g m)", cand.way, cand.duration,
                     cand.clearance)  # fmt: skip
        try:
            piece, T, stats = solve_avoiding(prob, options, cand.waypoints)
            traj = Trajectory((piece,))
            check = _verify(prob, traj)
        except JumpError as exc:
            error = exc
            continue
        iterations += stats.iterations
        if best is None or traj.duration < best[3].duration:
            best = (piece, T, stats, traj, check)
    if best is None:
        raise error if error is not None else JumpError("Not_Solved", "no warm start")
    return best[0], best[1], replace(best[2], iterations=iterations), best[3], best[4]


def _given(robot: RobotModel, q: ArrayLike, pose: np.ndarray, name: str) -> np.ndarray:
    """A configuration given for a pose, checked: FK within ENDPOINT_TOL of the pose, inside the limits."""
    qq = np.array(robot.check_q(q), dtype=float)
    err = pose_error(robot, qq, pose)
    if err > ENDPOINT_TOL:
        raise InvalidInputError(f"{name} {np.round(qq, 9).tolist()} puts the tool {err:.3g} m (or rad) from its pose")
    outside = robot.outside_limits(qq)
    if outside:
        raise InvalidInputError(f"{name} {np.round(qq, 9).tolist()} is outside the limits of {', '.join(outside)}")
    return qq


def _endpoints(
    robot: RobotModel, A: np.ndarray, B: np.ndarray, start: ArrayLike | None, end: ArrayLike | None, branch: str | None
) -> tuple[np.ndarray, np.ndarray]:
    """The configurations at A (``start``, or the IK solution nearest mid-range) and at B (``end``, or nearest qA)."""
    mid = (np.array(robot.limits.lower) + np.array(robot.limits.upper)) / 2.0
    if start is not None:
        qA = _given(robot, start, A, "start")
    else:
        res = robot.ik(A)
        sol = res.nearest(mid, branch=branch or "all") if res.success else None
        if sol is None:
            raise InfeasibleError(f"pose_from {A.tolist()} is out of reach: {res.message}")
        qA = sol.q
    if end is not None:
        return np.array(qA, dtype=float), _given(robot, end, B, "end")
    br = branch or robot.branch_of(qA)
    res = robot.ik(B)
    sol = res.nearest(qA, branch=br) if res.success else None
    if sol is None:
        raise InfeasibleError(f"pose_to {B.tolist()} is out of reach on the {br} branch: {res.message}")
    return np.array(qA, dtype=float), np.array(sol.q, dtype=float)


def _top(robot: RobotModel, pose: np.ndarray, z_top: float, near: np.ndarray, name: str, rise: float) -> np.ndarray:
    """The configuration at the traverse height above ``pose`` nearest ``near`` (same branch)."""
    target = np.array([pose[0], pose[1], z_top, pose[3]])
    res = robot.ik(target)
    sol = res.nearest(near, branch=robot.branch_of(near)) if res.success else None
    if sol is None:
        raise InfeasibleError(f"the tool cannot reach the traverse height z_top = {z_top:.6g} m above {name} (rise "
                              f"{rise:.6g} m): {res.message}")  # fmt: skip
    return np.array(sol.q, dtype=float)


# ---------------------------------------------------------------------------------------------- lower bound
def _quill(robot: RobotModel, q: np.ndarray) -> int | None:
    """The joint that alone moves the tool vertically (a SCARA's quill), or None."""
    if robot.kind != "scara":
        return None
    row = robot.task_jacobian(q)[2]
    moving = np.abs(row) > 1e-12
    return int(np.argmax(moving)) if moving.sum() == 1 else None


def _default_intervals(jerk: bool, tool_speed: bool) -> tuple[int, int, int]:
    """(lift, traverse, descend) intervals: 10 / 14 / 10, or 16 / 24 / 16 with a jerk limit.

    A tool-speed limit, which binds along the whole traverse, doubles the traverse's (0.6 % shorter there).
    """
    lift, traverse = (16, 24) if jerk else (10, 14)
    return lift, traverse * (2 if tool_speed else 1), lift


def _holds_still(robot: RobotModel, configurations: tuple[np.ndarray, ...], effort: np.ndarray) -> None:
    """InfeasibleError if the static load (gravity, payload included) at one of them is not below an effort limit."""
    q = np.array(configurations)
    bad = static_overload(static_load(robot, q), effort, robot.joint_names)
    if bad is not None:
        raise InfeasibleError(bad.reason(f"at q = {np.round(q[bad.index], 6).tolist()}"))


def _one_dof(
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
    quill = _quill(robot, q_from)
    names = robot.joint_names
    best = LowerBound(0.0, names[0], "no joint moves")
    kind = "velocity, acceleration and jerk" if jerk is not None else "velocity and acceleration"
    for j in range(robot.dof):
        if j == quill:
            up = abs(q_tops[0][j] - q_from[j])
            down = abs(q_tops[1][j] - q_to[j])
            t = _one_dof(j, up, velocity, acceleration, None) + _one_dof(j, down, velocity, acceleration, None)
            why = (f"{names[j]} alone, up {up:.6g} m and down {down:.6g} m, each from rest to rest, velocity and "
                   "acceleration limits")  # fmt: skip
        else:
            d = float(q_to[j] - q_from[j])
            t = _one_dof(j, abs(d), velocity, acceleration, jerk, exact_jerk, names[j])
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


# ---------------------------------------------------------------------------------------------- solving
def _warm_start(prob: _Problem, waypoints: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint lines A -> above A -> [via points] -> above B -> B, each with the quintic law over its fastest duration.

    The lift is the first line, the descent the last, the traverse the lines between (its nodes evenly spaced
    in time over them).
    """
    order = prob.order
    ends = np.array((prob.qA, prob.q_tops[0], prob.q_tops[1], prob.qB)) if waypoints is None else waypoints
    groups = [ends[:2], ends[1:-1], ends[-2:]]
    T = np.empty(3)
    states: list[np.ndarray] = []
    for p in range(3):
        lines = list(zip(groups[p][:-1], groups[p][1:]))
        durations = np.array([line_optimal_duration(q0, q1, prob.velocity, prob.acceleration) * 1.2
                              if not np.array_equal(q0, q1) else 0.0 for q0, q1 in lines])  # fmt: skip
        T[p] = durations.sum() if durations.sum() > 0.0 else 0.1 * prob.t_scale
        t = np.linspace(0.0, T[p], prob.N[p] + 1)
        starts = np.concatenate([[0.0], np.cumsum(durations)[:-1]])
        rows = [np.zeros((len(t), len(prob.qA))) for _ in range(3)]
        for (q0, q1), t0, d in zip(lines, starts, durations):
            sel = (t >= t0) & (t <= t0 + d) if d > 0.0 else np.zeros(len(t), dtype=bool)
            x = (t[sel] - t0) / d if d > 0.0 else t[sel]
            dq = q1 - q0
            rows[0][sel] = q0 + (x**3 * (10.0 - 15.0 * x + 6.0 * x * x))[:, None] * dq
            if d > 0.0:
                rows[1][sel] = (30.0 * x * x * (1.0 - x) ** 2 / d)[:, None] * dq
                rows[2][sel] = (60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) / d**2)[:, None] * dq
        if not lines or durations.sum() == 0.0:
            rows[0][:] = groups[p][0]
        states.append(np.stack(rows[:order], axis=1)[(1 if p else 0) :])
    X = np.concatenate(states)
    h = np.repeat(T / np.array(prob.N), prob.N)
    U = np.diff(X[:, order - 1], axis=0) / h[:, None]
    return T, X, U


def _solve(prob: _Problem, options: JumpOptions, waypoints: np.ndarray | None = None
           ) -> tuple[PolynomialPiece, np.ndarray, SolverStats]:  # fmt: skip
    """Solve, rebuild exactly, refine where a constraint fails between nodes (module docstring).

    ``waypoints``: the warm start's joint path (default: A, above A, above B, B; :func:`_warm_start`).
    """
    points: tuple[_Point, ...] = ()
    tr = _Transcription(prob, points, options)
    x0 = tr.pack(*_warm_start(prob, waypoints))
    lam_x: np.ndarray | None = None
    lam_g: np.ndarray | None = None
    iterations = solves = 0
    while True:
        sol = tr.solve(x0, lam_x, lam_g)
        iterations += sol["iterations"]
        solves += 1
        if not sol["success"]:
            raise JumpError(sol["status"], _failure(sol["status"], options))
        T, X, U = tr.unpack(sol["x"])
        piece = _rebuild(prob, T, U)
        new = [p for p in _violations(prob, piece, T, points) if p not in points]
        if not new or solves > options.refinements:
            break
        points = points + tuple(new)
        n_old = tr.n_g
        tr = _Transcription(prob, points, options)
        x0, lam_x = sol["x"], sol["lam_x"]
        lam_g = np.concatenate([sol["lam_g"], np.zeros(tr.n_g - n_old)])
    stretch = _torque_stretch(prob, piece)
    if stretch > 1.0:  # the torque bulging over its limit between constraint points: the same motion, slower
        logger.debug("jump: torque between the constraint points: %.9g times slower", stretch)
        piece, T = piece.scaled(stretch), T * stretch
    stats = SolverStats(sol["status"], iterations, solves, prob.N, tr.n_x, tr.n_g, 0.0)
    logger.debug("jump: %s", stats)
    return piece, T, stats


def _failure(status: str, options: JumpOptions) -> str:
    if status == "Infeasible_Problem_Detected":
        return ("no motion meets every constraint together (clearance, ceiling, joint ranges, limits): the solver "
                "found them locally infeasible")  # fmt: skip
    if status == "Maximum_Iterations_Exceeded":
        return f"the solver did not converge in {options.max_iterations} iterations"
    return f"the solver stopped without a solution ({status})"


def _rebuild(prob: _Problem, T: np.ndarray, U: np.ndarray) -> PolynomialPiece:
    """The exact polynomial piece: integrated from rest at A, controls changed (least norm) to end at rest at B."""
    order, dof = prob.order, prob.robot.dof
    h = np.repeat(T / np.array(prob.N), prob.N)
    n = len(h)
    # the end state is linear in the controls: end = Phi_all x0 + sum_k G_k u_k (per joint, same G for all)
    G = np.zeros((order, n))
    for k in range(n):
        e = _propagate(order, [0.0] * order, 1.0, h[k])
        for m in range(k + 1, n):
            e = _propagate(order, e, 0.0, h[m])
        G[:, k] = e
    U = U.copy()
    for _ in range(2):
        X = _integrate(prob, h, U)
        target = np.zeros((order, dof))
        target[0] = prob.qB
        r = target - X[-1]
        U += (G.T @ np.linalg.solve(G @ G.T, r))
    X = _integrate(prob, h, U)
    c = np.empty((n, order + 1, dof))
    for i in range(order):
        c[:, i] = X[:-1, i] / math.factorial(i)
    c[:, order] = U / math.factorial(order)
    return PolynomialPiece(np.concatenate([[0.0], np.cumsum(h)]), c)


def _integrate(prob: _Problem, h: np.ndarray, U: np.ndarray) -> np.ndarray:
    order, dof = prob.order, prob.robot.dof
    X = np.zeros((len(h) + 1, order, dof))
    X[0, 0] = prob.qA
    for k in range(len(h)):
        X[k + 1] = np.array(_propagate(order, list(X[k]), U[k], h[k]))
    return X


def _violations(prob: _Problem, piece: PolynomialPiece, T: np.ndarray, points: tuple[_Point, ...] = ()) -> list[_Point]:
    """The new constraint points (``points``: those already there) of a solution.

    Interior points where a constraint not linear in time fails by more than _REFINE_RATIO (the worst per
    interval); a lazy family near its limit anywhere: at every node (and its interior points only from the
    next round: the nodes alone may be enough).
    """
    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    sigma = np.arange(_CHECK_POINTS + 1) / _CHECK_POINTS  # both ends too: the torque depends on each side's control
    k = np.repeat(np.arange(n), _CHECK_POINTS + 1)
    s = np.tile(sigma, n)
    extra_k, extra_s = _extrema(piece)
    k, s = np.concatenate([k, extra_k]), np.concatenate([s, extra_s])
    tau = piece.breaks[k] + s * h[k]
    q, qd, qdd = piece.evaluate(tau)
    qdd = piece._local(k, s * h[k], 2)  # the interval's own acceleration (not the next one's at its end)
    phase = prob.phase_of()[k]
    excess: dict[str, np.ndarray] = {}
    p = np.array(prob.sym.tool_position.map(len(k))(q.T)).T
    dA = np.hypot(p[:, 0] - prob.A[0], p[:, 1] - prob.A[1]) - prob.R
    dB = np.hypot(p[:, 0] - prob.B[0], p[:, 1] - prob.B[1]) - prob.R
    geo = np.choose(phase, [dA, prob.z_top - p[:, 2], dB])
    if prob.max_height is not None:
        geo = np.maximum(geo, p[:, 2] - prob.max_height)
    excess["geometry"] = geo
    if prob.effort is not None:
        tau_ = np.array(prob.sym.inverse_dynamics.map(len(k))(q.T, qd.T, qdd.T)).T
        excess["torque"] = np.max(np.abs(tau_) / prob.effort, axis=1) - 1.0
    if prob.tool_speed is not None:
        v = np.array(prob.sym.tool_velocity.map(len(k))(q.T, qd.T)).T
        excess["tool speed"] = np.linalg.norm(v, axis=1) / prob.tool_speed - 1.0
    out: list[_Point] = []
    for family, e in excess.items():
        if family in _LAZY and _Point(_NODES, 0.0, family) not in points:
            if float(np.max(e)) > -_NEAR:  # near its limit somewhere: at every node from now on
                out.append(_Point(_NODES, 0.0, family))
            continue
        limit = _REFINE_GEOMETRY if family == "geometry" else _REFINE_RATIO
        bad = e > limit
        for kk in np.unique(k[bad]):
            sel = np.nonzero(bad & (k == kk))[0]
            out.append(_Point(int(kk), float(s[sel[int(np.argmax(e[sel]))]]), family))
    return out


def _torque_stretch(prob: _Problem, piece: PolynomialPiece) -> float:
    """The least k >= 1 with every torque of ``piece`` played k times slower within its limit (module docstring).

    Sampled at :data:`_STRETCH_POINTS` + 1 points of every interval (its own acceleration at both ends).
    With d = tau - g (the dynamic part) and g the static load at a sample, |d / k^2 + g| <= E needs
    k^2 >= d / (E - g) if d > 0, k^2 >= -d / (E + g) if d < 0; a static load at or above the limit cannot be
    helped (1 is returned: the verification says why).
    """
    if prob.effort is None:
        return 1.0
    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    k = np.repeat(np.arange(n), _STRETCH_POINTS + 1)
    s = np.tile(np.arange(_STRETCH_POINTS + 1) / _STRETCH_POINTS, n) * h[k]
    q, qd, qdd = (piece._local(k, s, i) for i in range(3))
    tau = np.array(prob.sym.inverse_dynamics.map(len(k))(q.T, qd.T, qdd.T)).T
    g = np.array(prob.sym.inverse_dynamics.map(len(k))(q.T, 0.0 * qd.T, 0.0 * qdd.T)).T
    d, E = tau - g, prob.effort[None, :]
    if not (np.abs(tau) > E).any() or (np.abs(g) >= E).any():
        return 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        need = np.where(d > 0.0, d / (E - g), np.where(d < 0.0, -d / (E + g), 0.0))
    return float(math.sqrt(max(1.0, float(np.max(need))))) * (1.0 + 1e-12)


def _extrema(piece: PolynomialPiece) -> tuple[np.ndarray, np.ndarray]:
    """(interval, fraction) of every interior extremum of q and qd: the roots of qd and qdd on each interval."""
    c = piece.coefficients
    h = np.diff(piece.breaks)[:, None]
    deg = c.shape[1] - 1
    found = []
    # (constant, linear, quadratic) coefficients of qd, then of qdd, on each interval and joint
    polys = [(c[:, 1], 2.0 * c[:, 2], 3.0 * c[:, 3] if deg == 3 else np.zeros_like(c[:, 1]))]
    if deg == 3:
        polys.append((2.0 * c[:, 2], 6.0 * c[:, 3], np.zeros_like(c[:, 1])))
    with np.errstate(divide="ignore", invalid="ignore"):
        for p0, p1, p2 in polys:
            lin = np.abs(p2) <= 1e-300
            disc = np.sqrt(np.where(lin, np.nan, p1 * p1 - 4.0 * p2 * p0))
            found.append(np.where(lin, -p0 / p1, (-p1 - disc) / (2.0 * p2)))
            found.append(np.where(lin, np.nan, (-p1 + disc) / (2.0 * p2)))
    sigma = np.stack(found) / h[None]  # (roots, intervals, joints)
    keep = np.isfinite(sigma) & (sigma > 0.0) & (sigma < 1.0)
    k = np.broadcast_to(np.arange(len(h))[None, :, None], sigma.shape)
    return k[keep].astype(int), sigma[keep]


# ---------------------------------------------------------------------------------------------- verification
@dataclass(frozen=True, eq=False)
class _Check:
    """What the verification found: the samples (for the legs) and the worst values."""

    t: np.ndarray
    on_grid: np.ndarray
    table: dict[str, np.ndarray]
    ratios: dict[str, float | None]
    clearance_error: float
    peak: float
    bulge: float
    distance: Clearance | None = None


def _verify(prob: _Problem, traj: Trajectory) -> _Check:
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
    if not isinstance(piece, PolynomialPiece):  # pragma: no cover - _solve makes them
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
    ek, es = _extrema(piece)
    grid = np.arange(math.floor(T * VERIFY_RATE + 1e-9) + 1) / VERIFY_RATE
    inner = (b[:-1, None] + dt[:, None] * (np.arange(1, 8) / 8.0)[None, :]).ravel()
    t = np.clip(np.concatenate([grid, inner, b[ek] + es * dt[ek]]), 0.0, T)
    on_grid = np.arange(len(t)) < len(grid)
    q, qd, qdd = traj.sample(t)
    qddd = None if prob.jerk is None else piece.jerk(t)
    ratios = state_ratios(prob.robot, lim, (q, qd, qdd, qddd), prob.jerk)
    table = {quantity.value: r for quantity, r in ratios.items()}
    worst: dict[str, float | None] = {name: None for name in _QUANTITIES}
    for name, value in found.ratios().items():
        worst[name] = value
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
    return _Check(t, on_grid, table, worst, clearance_error, float(np.max(poses[:, 2]) - prob.z_top), bulge,
                  found.clearance)


def _legs(prob: _Problem, check: _Check, T: np.ndarray) -> tuple[Leg, ...]:
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
        legs.append(Leg(phase.value, 0, float(cuts[p]), float(cuts[p + 1]), best[0], who, best[2], tuple(binding),
                        closest))  # fmt: skip
    return tuple(legs)
