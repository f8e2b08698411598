"""The jump's types: its options, its result, how the limits bind on it, its error (:mod:`~scara_pin.motion.jump`)."""

from __future__ import annotations

import enum
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..._checks import as_positive
from ...errors import InfeasibleError, InvalidInputError, ParameterError
from ...summary import Summarized
from ...units import SI
from ..payload import Payload
from ..polynomial import PolynomialPiece
from ..trajectory import Trajectory

if TYPE_CHECKING:
    from ...cell import Cell
    from ...units import DisplayUnits
    from ..verify import Binding, Clearance

STANDARD_RISE = 0.025
"""[m] the vertical stroke of the standard cycle, and the default rise of a jump."""


STANDARD_CLEARANCE = 0.005
"""[m] the default clearance radius R: within R of an endpoint (horizontally) the tool may be low."""


CLEARANCE_TOL = 1e-6
"""[m] how far below z_top (outside both circles), or above the ceiling, the verified tool may be."""


BINDING = 0.999
"""A limit is binding on a leg where its ratio reaches this."""


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
            (re-linearised each time, :mod:`~scara_pin.motion.jump.rows`).
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


@dataclass(frozen=True, kw_only=True)
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


@dataclass(frozen=True, eq=False, repr=False, kw_only=True)
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
        back = [replace(leg, name=leg.name if leg.name == Phase.TRAVERSE.value else _MIRROR[leg.name], move=1,
                        t_start=2 * T - leg.t_end, t_end=2 * T - leg.t_start)
                for leg in reversed(self.legs)]  # fmt: skip
        traj = Trajectory((piece, piece.reversed()))
        return replace(self, trajectory=traj, legs=self.legs + tuple(back), moves=2)


_MIRROR = {Phase.LIFT.value: Phase.DESCEND.value, Phase.DESCEND.value: Phase.LIFT.value}
