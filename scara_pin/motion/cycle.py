"""The standard SCARA cycle, and the straight-leg arch move, timed under velocity, acceleration, torque and jerk limits.

The cycle's moves are, by default, time-optimal JUMPS (:mod:`~scara_pin.motion.jump`: the joint path free
over a clearance, out and back by time reversal). The straight-leg arch below (``path="lines"``) is the
simpler plan, kept for comparison and for controllers that want straight tool legs: it is slower.

**Straight-leg arch** (Epson's JUMP, others' gate or arch motion) from pose A to pose B: lift vertically to the
traverse height ``z_top = max(z_A, z_B) + rise``, move horizontally, descend to B. It is ONE path of
straight tool lines (:class:`~scara_pin.motion.paths.CartesianSegment`, same elbow branch, J4 continuous)
whose two corners are replaced by blends. A blend at a corner C between the incoming unit direction e1
and the outgoing e2 starts ``b`` before C and ends ``b`` after it, ``b = min(blend, lift, D / 2)`` (D the
horizontal distance); it is the quintic Hermite curve

    p(tau) = P0 + H5(tau) (P1 - P0) + 2 b (H1(tau) e1 + H4(tau) e2),    tau in [0, 1],
    P0 = C - b e1, P1 = C + b e2,

with H1, H4, H5 the quintic Hermite basis functions (end velocities 2 b e1 and 2 b e2, end accelerations
zero). Written in the path's arc-length-like parameter (each line its length, each blend 2 b) the tool
path is C2: tangent and curvature are continuous, so the joint accelerations are continuous along the
path and a jerk limit can be met without stopping. The blend stays in the corner's triangle: it never
rises above the traverse height nor passes the lift line (the z and horizontal coordinates are
monotonic on it). The yaw moves in proportion to the horizontal progress (constant while lifting and
descending straight). ``blend = 0`` (``--no-blend``) keeps the corners: three lines, stopping at each.

Timing: :func:`~scara_pin.motion.timing.parameterize` (TOPP-RA, limits verified between grid points, at
1 kHz), torques from Pinocchio's RNEA with the payload added to the tool body of a COPY of the model
(:mod:`~scara_pin.motion.payload`); optionally a joint jerk limit (:mod:`~scara_pin.motion.jerk`).

**Standard cycle** (the figure SCARA datasheets quote, ISO 9283-like conditions): up ``rise`` (25 mm),
across ``span`` (305 mm), down, and back the same way, rest at both ends. Default placement
(:func:`cycle_placement`): the traverse is the chord perpendicular to the arm's direction at the middle of
J1's range, centred on it, at mid-stroke height (the stroke from ``z - rise/2`` to ``z + rise/2`` centred),
at the distance from the J1 axis that MAXIMISES THE SMALLEST MANIPULABILITY |det J| along the chord
(for a SCARA l1 l2 |sin q2|: the elbow stays as far from stretched and folded as the chord allows).
Why: the cycle time depends on the joint speeds the tool speed needs, which blow up near the singular
arm; this is the place the robot reaches best, with symmetric joint motion about J1's middle.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import as_vector
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..summary import Summarized
from ..units import SI, DisplayUnits, format_number
from .jerk import time_optimal_jerk
from .jump import (
    BINDING,
    STANDARD_CLEARANCE,
    STANDARD_RISE,
    JumpMove,
    JumpOptions,
    Leg,
    LowerBound,
    jump_move,
    lower_bound,
)
from .paths import CartesianSegment, GeometricPath, PathError, SegmentedPath, cartesian_path, follow_curve
from .payload import Payload, PayloadLike, as_payload, with_payload
from .timing import TimingOptions, limits_in_force, parameterize
from .trajectory import Motion, Trajectory
from .verify import Quantity, Verification, clear_of, state_ratios, trajectory_jerk, verify

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..cell import Cell
    from ..description import JointLimits
    from ..model import RobotModel
    from .verify import Clearance

__all__ = [
    "STANDARD_CLEARANCE",
    "STANDARD_RISE",
    "STANDARD_SPAN",
    "ArchMove",
    "ArchPath",
    "BlendSegment",
    "CyclePath",
    "CycleResult",
    "Leg",
    "arch_move",
    "arch_path",
    "cycle_placement",
    "limits_dict",
    "standard_cycle",
    "trajectory_jerk",
]

STANDARD_SPAN = 0.305
"""[m] the horizontal stroke of the standard cycle."""
_STEP = 2e-3  # [m] checkpoint spacing along a blend (as cartesian_path's default)
_QUANTITIES = ("velocity", "acceleration", "torque", "jerk")
_NOT_IN_BOUND = (Quantity.TORQUE, Quantity.TOOL_SPEED)
"""The limits the lower bound leaves out (it is the 1-DOF time of each joint under velocity, acceleration and
jerk): the bound line says so when they apply."""

# quintic Hermite basis (coefficients of tau^0..tau^5): H1 (start velocity), H4 (end velocity), H5 (end point)
_H1 = np.array([0.0, 1.0, 0.0, -6.0, 8.0, -3.0])
_H4 = np.array([0.0, 0.0, 0.0, -4.0, 7.0, -3.0])
_H5 = np.array([0.0, 0.0, 0.0, 10.0, -15.0, 6.0])


def _poly(c: np.ndarray, t: np.ndarray, order: int) -> np.ndarray:
    from numpy.polynomial import polynomial as P

    return P.polyval(t, P.polyder(c, order) if order else c)


@dataclass(frozen=True, eq=False)
class BlendSegment(CartesianSegment):
    """A corner blend (module docstring): the quintic from ``corner - b e_in`` to ``corner + b e_out``.

    The yaw is ``pose0[3] + yaw_rate * (p - p0) . horizontal``. ``pose0``/``pose1`` are its end poses.

    Attributes:
        corner: the corner point (x, y, z) [m].
        e_in, e_out: unit directions of the incoming and outgoing lines.
        b: the blend distance along each line [m].
        horizontal: unit horizontal direction of the traverse.
        yaw_rate: [rad/m] yaw per metre of horizontal progress.
    """

    corner: np.ndarray = field(default_factory=lambda: np.zeros(3))
    e_in: np.ndarray = field(default_factory=lambda: np.zeros(3))
    e_out: np.ndarray = field(default_factory=lambda: np.zeros(3))
    b: float = 0.0
    horizontal: np.ndarray = field(default_factory=lambda: np.zeros(3))
    yaw_rate: float = 0.0

    @staticmethod
    def curve(
        corner: np.ndarray, e_in: np.ndarray, e_out: np.ndarray, b: float, horizontal: np.ndarray, yaw0: float,
        yaw_rate: float, s: np.ndarray, order: int = 0,
    ) -> np.ndarray:
        """The blend's pose (order 0) or its order-th derivative in tau, (n, 4)."""
        t = np.asarray(s, dtype=float).ravel()
        p0, p1 = corner - b * e_in, corner + b * e_out
        p = (_poly(_H5, t, order)[:, None] * (p1 - p0) + 2.0 * b * (_poly(_H1, t, order)[:, None] * e_in
             + _poly(_H4, t, order)[:, None] * e_out))  # fmt: skip
        if order == 0:
            p = p + p0
        yaw = yaw_rate * ((p - (p0 if order == 0 else 0.0)) @ horizontal) + (yaw0 if order == 0 else 0.0)
        return np.column_stack([p, yaw])

    def _at(self, s: np.ndarray, order: int) -> np.ndarray:
        return self.curve(self.corner, self.e_in, self.e_out, self.b, self.horizontal, float(self.pose0[3]),
                          self.yaw_rate, s, order)  # fmt: skip

    def poses(self, s: np.ndarray) -> np.ndarray:  # noqa: D102
        return self._at(np.clip(np.asarray(s, dtype=float), 0.0, 1.0), 0)

    def pose_derivatives(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: D102
        return self._at(s, 1), self._at(s, 2)

    def pose_third_derivative(self, s: np.ndarray) -> np.ndarray:  # noqa: D102
        return self._at(s, 3)


@dataclass(frozen=True, eq=False)
class ArchPath(SegmentedPath, GeometricPath):
    """Tool segments (lines and blends) joined into one path q(s), s in [0, 1]; C2 in s across knots.

    Segment k covers ``[bounds[k], bounds[k + 1]]`` with ``bounds`` proportional to the segments' lengths
    (a line its length, a blend 2 b), so d(pose)/ds is continuous at the knots.

    Attributes:
        segments: the segments in order.
        bounds: (len(segments) + 1,) increasing from 0 to 1.
        names: the leg name of each segment ("lift", "blend up", "traverse", "blend down", "descend").
    """

    segments: tuple[CartesianSegment, ...]
    bounds: np.ndarray
    names: tuple[str, ...]

    def knots(self) -> np.ndarray:  # noqa: D102
        return self.bounds.copy()

    @property
    def branch(self) -> str:
        """The elbow branch of every configuration on the path."""
        return self.segments[0].branch

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:  # noqa: D102
        s = np.clip(np.asarray(s, dtype=float).ravel(), 0.0, 1.0)
        idx = np.clip(np.searchsorted(self.bounds, s, side="right") - 1, 0, len(self.segments) - 1)
        out = [np.empty((len(s), 4)) for _ in range(order + 1)]
        for k, seg in enumerate(self.segments):
            sel = idx == k
            if not sel.any():
                continue
            width = self.bounds[k + 1] - self.bounds[k]
            res = seg.evaluate((s[sel] - self.bounds[k]) / width, order)
            for o in range(order + 1):
                out[o][sel] = res[o] / width**o
        return tuple(out)


def arch_path(
    robot: RobotModel,
    pose_from: ArrayLike,
    pose_to: ArrayLike,
    *,
    rise: float = STANDARD_RISE,
    blend: float | None = None,
    start: ArrayLike | None = None,
    end: ArrayLike | None = None,
    branch: str | None = None,
) -> ArchPath | Any:
    """The arch path from ``pose_from`` to ``pose_to`` (module docstring); checked like a straight line.

    Args:
        robot: a SCARA.
        pose_from: (x, y, z, yaw) at the start [m, rad].
        pose_to: (x, y, z, yaw) at the end [m, rad]; the yaw is interpolated as written (no wrap).
        rise: [m] > 0, the traverse height above the higher of the two poses.
        blend: [m] >= 0, the largest blend distance along each line (it is also limited by the lift and
            half the horizontal distance); None: as large as allowed; 0: no blend (stop at the corners).
        start: the configuration at ``pose_from`` (fixes the branch and the J4 turn).
        end: the configuration the path must end at, if given.
        branch: ``"right"`` or ``"left"`` (default: the start's, or ``"right"``).

    Returns:
        An :class:`ArchPath`, or with ``blend = 0`` the :class:`~scara_pin.motion.paths.CartesianPath`
        of the three lines.

    Raises:
        ParameterError: a pose or number is malformed (NaN, infinite, negative).
        InvalidInputError: no horizontal move.
        PathError: the path leaves the workspace or the joint limits, or reaches the singularity.
    """
    A, B = as_vector("pose_from", pose_from), as_vector("pose_to", pose_to)
    rise = _nonneg("rise", rise, strict=True)
    blend = math.inf if blend is None else _nonneg("blend", blend)
    d = B[:2] - A[:2]
    D = float(np.hypot(*d))
    if D < 1e-6:
        raise InvalidInputError(f"the two poses are {D:.3g} m apart horizontally: an arch needs a horizontal move "
                                "(use a straight line, traj --linear, for a vertical one)")  # fmt: skip
    top = max(float(A[2]), float(B[2])) + rise  # the corner points, the blend sizes, the yaw per metre
    u = np.array([d[0] / D, d[1] / D, 0.0])
    b1 = min(blend, top - float(A[2]), D / 2.0)
    b2 = min(blend, top - float(B[2]), D / 2.0)
    yaw_rate = float(B[3] - A[3]) / D
    corners = [A, np.array([*A[:2], top, A[3]]), np.array([*B[:2], top, B[3]]), B]
    lines = cartesian_path(robot, corners, start=start, end=end, branch=branch)
    if blend == 0.0:
        return lines
    z = np.array([0.0, 0.0, 1.0])
    c1, c2 = np.array([*A[:2], top]), np.array([*B[:2], top])
    y1, y2 = float(A[3]) + yaw_rate * b1, float(B[3]) - yaw_rate * b2
    pieces: list[tuple[str, Any]] = []
    if top - A[2] - b1 > 1e-12:
        pieces.append(("lift", (A, np.array([*A[:2], top - b1, A[3]]))))
    pieces.append(("blend up", (c1, z, u, b1, float(A[3]))))
    if D - b1 - b2 > 1e-12:
        pieces.append(("traverse", (np.array([*(c1 + b1 * u), y1]), np.array([*(c2 - b2 * u), y2]))))
    pieces.append(("blend down", (c2, u, -z, b2, y2)))
    if top - B[2] - b2 > 1e-12:
        pieces.append(("descend", (np.array([*B[:2], top - b2, B[3]]), B)))
    segments: list[CartesianSegment] = []
    lengths: list[float] = []
    q = lines.q_start
    for k, (name, data) in enumerate(pieces):
        if name.startswith("blend"):
            corner, e_in, e_out, b, yaw0 = data

            def curve(s: np.ndarray, c: Any = data) -> np.ndarray:
                return BlendSegment.curve(c[0], c[1], c[2], c[3], u, c[4], yaw_rate, s)

            m = max(1, math.ceil(2.0 * b / _STEP))
            _, q_pts, s_ref, q_ref = follow_curve(robot, lines.branch, curve, q, m, k,
                                                  extent=(2.0 * b, abs(yaw_rate) * b))  # fmt: skip
            p0, p1 = curve(np.array([0.0, 1.0]))
            seg: CartesianSegment = BlendSegment(robot, lines.branch, p0, p1, s_ref, q_ref, corner=corner,
                                                 e_in=e_in, e_out=e_out, b=b, horizontal=u,
                                                 yaw_rate=yaw_rate)  # fmt: skip
            lengths.append(2.0 * b)
        else:
            a, bb = data
            sub = cartesian_path(robot, [a, bb], start=q, branch=lines.branch)
            seg = sub.segments[0]
            q_pts = sub.checkpoints[0][1]
            lengths.append(float(np.linalg.norm(bb[:3] - a[:3])))
        segments.append(seg)
        q = q_pts[-1]
    if np.abs(q - lines.q_end).max() > 1e-9:
        raise PathError(f"the blended arch ends at q = {np.round(q, 9).tolist()}, the corner path at "
                        f"{np.round(lines.q_end, 9).tolist()} (another J4 turn)", s=1.0, pose=B, q=q)  # fmt: skip
    bounds = np.concatenate([[0.0], np.cumsum(lengths)])
    bounds /= bounds[-1]
    bounds[-1] = 1.0
    return ArchPath(tuple(segments), bounds, tuple(name for name, _ in pieces))


def _nonneg(name: str, value: object, strict: bool = False) -> float:
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be a number", "m") from None
    if not math.isfinite(v) or v < 0.0 or (strict and v == 0.0):
        raise ParameterError(name, v, "must be finite and " + ("> 0" if strict else ">= 0"), "m")
    return v


# ---------------------------------------------------------------------------------------------- results
@dataclass(frozen=True, eq=False, repr=False)
class ArchMove(Summarized):
    """A timed arch move (or several, joined rest to rest) and how its limits are used.

    Attributes:
        trajectory: the trajectory (one motion per arch, or per line without blends).
        paths: the geometric paths (ArchPath or the corner lines) in order.
        legs: the legs with their times and active limits.
        ratios: worst ratio per quantity ("velocity", "acceleration", "torque", "jerk"; None if not limited).
        payload: the payload carried.
        jerk: the jerk limits per joint, or None.
        distance: with a cell, the smallest verified distance of its checked pairs, which and when.
    """

    trajectory: Trajectory
    paths: tuple[Any, ...]
    legs: tuple[Leg, ...]
    ratios: dict[str, float | None]
    payload: Payload
    jerk: tuple[float, ...] | None
    distance: Clearance | None = None

    @property
    def duration(self) -> float:
        """[s]."""
        return self.trajectory.duration

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The move in a few lines: its time, the worst ratio of each limit, the legs."""
        ratios = ", ".join(f"{k} {v:.4f}" for k, v in self.ratios.items() if v is not None)
        return "\n".join([
            f"straight-leg arch   {self.duration:.6f} s, {len(self.paths)} path(s), payload {self.payload.mass:g} kg"
            + (f", jerk limit {list(self.jerk)}" if self.jerk else ""),
            f"worst |value| / limit: {ratios}",
            "legs   (binding limits: the share of the leg's time at >= 99.9 % of the limit)",
            *(leg.line(units) for leg in self.legs),
        ])  # fmt: skip


class CyclePath(enum.Enum):
    """How the cycle's moves are made; the value is the ``--path`` word."""

    JUMP = "jump"
    LINES = "lines"


@dataclass(frozen=True, eq=False, repr=False, kw_only=True)
class CycleResult(Summarized):
    """The standard cycle: out and back, with its placement (``repr``: ``scara-pin cycle``'s text, in SI).

    Attributes:
        move: the timed cycle (two moves): a :class:`~scara_pin.motion.jump.JumpMove` (``path`` JUMP) or an
            :class:`ArchMove` (``path`` LINES).
        start, end: the poses at the ends of the traverse (x, y, z, yaw) [m, rad].
        span, rise, blend: the strokes and the blend distance used [m] (blend 0: none; the jump has none).
        placement: how the placement was chosen (a sentence), and its smallest manipulability.
        min_manipulability: the smallest |det J| along the traverse at the start height.
        path: the kind of move.
        clearance_radius: [m] R of the jump (None for the straight-leg arch, which lifts vertically).
        max_height: [m] the ceiling, or None.
        lower_bound: what no cycle under these limits can beat (twice a move's bound, see
            :func:`~scara_pin.motion.jump.lower_bound`).
        robot_name: the robot's name.
        verification: the whole cycle verified (:func:`~scara_pin.motion.verify.verify`: the worst ratio of each
            limit that applies, with its joint and time), or None.
        torque: whether the effort limits were respected (False: left out, ``torque=False``).
    """

    move: ArchMove | JumpMove
    start: np.ndarray
    end: np.ndarray
    span: float
    rise: float
    blend: float
    placement: str
    min_manipulability: float
    path: CyclePath = CyclePath.LINES
    clearance_radius: float | None = None
    max_height: float | None = None
    lower_bound: LowerBound | None = None
    robot_name: str = ""
    verification: Verification | None = None
    torque: bool = True

    @property
    def cycle_time(self) -> float:
        """[s] out and back."""
        return self.move.duration

    @property
    def gap(self) -> float | None:
        """The cycle time above the lower bound, relative (0.2: 20 % above)."""
        return None if self.lower_bound is None else self.cycle_time / self.lower_bound.duration - 1.0

    def summary(self, units: DisplayUnits | None = None) -> str:
        """What ``scara-pin cycle`` prints, lengths in ``units`` (default SI).

        The time, the bound (and the limits it leaves out), the worst ratio of each limit that applies, the
        placement, the arch and the legs.
        """
        u = SI if units is None else units
        move, bound, Ln = self.move, self.lower_bound, u.name("length")
        timing = "jerk-limited time-optimal timing" if move.jerk else "TOPP-RA timing"
        what = ("jump (time-optimal, joint path free)" if self.path is CyclePath.JUMP
                else f"straight-leg arch (lines and blends, {timing})")  # fmt: skip
        lines = [f"robot       {self.robot_name}: standard cycle, {what}, payload {move.payload.mass:g} kg"
                 + (f", jerk limit {list(move.jerk)}" if move.jerk else "")
                 + ("" if self.torque else "; effort limits left out (--no-torque): torques not checked")]  # fmt: skip
        shape = (f"; clearance radius {u.format(self.clearance_radius or 0.0, 'length')} {Ln})"
                 if self.path is CyclePath.JUMP else f"; blend {u.format(self.blend, 'length')} {Ln})")  # fmt: skip
        lines.append(f"cycle time  {format_number(self.cycle_time, 6)} s (up {u.format(self.rise, 'length')}, across "
                     f"{u.format(self.span, 'length')}, down and back [{Ln}]" + shape)  # fmt: skip
        check = self.verification
        if bound is not None:
            left = [] if check is None else [w.quantity.value for w in check.limited() if w.quantity in _NOT_IN_BOUND]
            unused = f"; not the {' and '.join(left)} limits" if left else ""
            lines.append(f"bound       {format_number(bound.duration, 6)} s ({bound.reason}{unused}): no cycle under "
                         f"these limits is faster; this one is {100 * (self.gap or 0.0):.1f} % above it")  # fmt: skip
        if check is not None:
            binding = [w.quantity.value for w in check.limited() if w.ratio >= BINDING]
            lines.append(f"limits      worst |value| / limit: {check.ratio_text()}; "
                         + (f"binding: {', '.join(binding)}" if binding else "none binds"))  # fmt: skip
        lines.append(f"placement   from {u.format_vector(self.start[:3], 'length')} to "
                     f"{u.format_vector(self.end[:3], 'length')} {Ln}: {self.placement}")  # fmt: skip
        if isinstance(move, JumpMove):
            st = move.stats
            lines.append(f"arch        up to {u.format(move.z_top + move.peak, 'length')} {Ln} "
                         f"({u.format(move.peak, 'length')} {Ln} above the clearance height), "
                         f"{u.format(move.bulge, 'length')} {Ln} off the straight line in plan view; solved in "
                         f"{st.seconds:.3g} s ({st.iterations} IPOPT iterations, {st.solves} solve(s))")  # fmt: skip
        lines.append("legs        (binding limits: the share of the leg's time at >= 99.9 % of the limit)")
        lines += [leg.line(units) for leg in move.legs]
        return "\n".join(lines)


# ---------------------------------------------------------------------------------------------- timing
def arch_move(
    robot: RobotModel,
    poses: ArrayLike,
    *,
    rise: float = STANDARD_RISE,
    blend: float | None = None,
    payload: PayloadLike = None,
    jerk: float | ArrayLike | None = None,
    torque: bool = True,
    limits: JointLimits | None = None,
    start: ArrayLike | None = None,
    branch: str | None = None,
    options: TimingOptions | None = None,
    tool_speed: float | None = None,
) -> ArchMove:
    """Time-optimal arch moves through ``poses`` (rest at each), under the robot's limits.

    Args:
        robot: a SCARA.
        poses: (m, 4) poses, m >= 2: an arch from each to the next, the robot at rest at each.
        rise: [m] the traverse height above the higher pose (:func:`arch_path`).
        blend: [m] the largest blend distance (:func:`arch_path`; 0: stop at the corners).
        payload: carried by the tool (torques): a :class:`~scara_pin.motion.payload.Payload` or a mass [kg];
            default none.
        jerk: joint jerk limit [rad/s^3, m/s^3], one or four numbers; None: not limited.
        torque: respect the effort limits (RNEA with the payload).
        limits: limits instead of ``robot.limits`` (a URDF file has no accelerations: give them here).
        start: the configuration at ``poses[0]`` (fixes branch and J4 turn).
        branch: ``"right"`` or ``"left"``.
        options: TOPP-RA grid and verification options.
        tool_speed: [m/s] a limit of the tool origin's speed (not with ``jerk``), or None.

    Raises:
        ParameterError, InvalidInputError: bad input (exit 2); PathError, TimingError: infeasible (exit 3).
    """
    payload = as_payload(payload)
    if tool_speed is not None and jerk is not None:
        raise InvalidInputError("the straight-leg arch takes a tool-speed limit or a jerk limit, not both")
    P = np.asarray(poses, dtype=float)
    if P.ndim != 2 or P.shape[1] != 4 or P.shape[0] < 2:
        raise ParameterError("poses", f"shape {P.shape}", "must be (m, 4) with m >= 2")
    lim = limits_in_force(robot, limits, None, torque)  # refuses NaN (a URDF's missing accelerations) up front
    loaded = with_payload(robot, payload)
    paths: list[Any] = []
    q = None if start is None else np.asarray(start, dtype=float)
    for k in range(P.shape[0] - 1):
        path = arch_path(robot, P[k], P[k + 1], rise=rise, blend=blend, start=q, branch=branch)
        paths.append(path)
        q, branch = path.q_end, path.branch
    jv = None
    if jerk is not None:  # the jerk-limited timing of the same paths (its own start: no TOPP-RA profile needed)
        traj = time_optimal_jerk(loaded, paths, jerk, torque=torque, limits=limits).trajectory
        jv = tuple(float(v) for v in np.broadcast_to(np.asarray(jerk, dtype=float), (4,)))
    else:
        pieces: list[Motion] = []
        # the blends' curvature changes fast: 128 verified points per grid segment (besides 1 kHz) keep the
        # acceleration between verified points within 1e-6 of its limit (16 left 2.9e-5 at 400 kHz; 128: 8e-7)
        options = options if options is not None else TimingOptions(check_subdivisions=128)
        for path in paths:
            res = parameterize(loaded, path, torque=torque, limits=limits, options=options, tool_speed=tool_speed)
            pieces.extend(p for p in res.trajectory.pieces if isinstance(p, Motion))
        traj = Trajectory(tuple(pieces))
    legs, ratios = _legs(loaded, traj, paths, lim, None if jv is None else np.array(jv))
    return ArchMove(traj, tuple(paths), legs, ratios, payload, jv)


def _legs(
    robot: RobotModel, traj: Trajectory, paths: list[Any], lim: Any, jerk: np.ndarray | None, rate: float = 1000.0
) -> tuple[tuple[Leg, ...], dict[str, float | None]]:
    """Legs (time spans) and, per leg, the most used limit, from a dense sampling (rate and 8 per 1/rate)."""
    spans: list[tuple[str, int, float, float]] = []
    t0 = 0.0
    motions = [p for p in traj.pieces if isinstance(p, Motion)]
    mi = 0
    for move, path in enumerate(paths):
        if isinstance(path, ArchPath):
            m = motions[mi]
            cuts = [0.0, *m.law.times_at(path.bounds[1:-1], 80).tolist(), m.duration]
            spans += [(name, move, t0 + cuts[k], t0 + cuts[k + 1]) for k, name in enumerate(path.names)]
            t0 += m.duration
            mi += 1
        else:
            for name in ("lift", "traverse", "descend"):
                m = motions[mi]
                spans.append((name, move, t0, t0 + m.duration))
                t0 += m.duration
                mi += 1
    legs: list[Leg] = []
    worst: dict[str, float | None] = {k: None for k in _QUANTITIES}
    for name, move, ta, tb in spans:
        n = max(16, int(math.ceil((tb - ta) * rate * 8)))
        t = np.linspace(ta, tb, n + 1)
        ratio = _ratio_table(robot, traj, t, lim, jerk)
        best = ("velocity", 0, -1.0)
        for qty, r in ratio.items():
            j = int(np.argmax(r.max(axis=0)))
            val = float(r[:, j].max())
            prev = worst[qty]
            worst[qty] = val if prev is None else max(prev, val)
            if val > best[2]:
                best = (qty, j, val)
        legs.append(Leg(name=name, move=move, t_start=float(ta), t_end=float(tb), active=best[0],
                        joint=robot.joint_names[best[1]], ratio=best[2]))
    return tuple(legs), worst


def _ratio_table(robot: RobotModel, traj: Trajectory, t: np.ndarray, lim: Any,
                 jerk: np.ndarray | None) -> dict[str, Any]:  # fmt: skip
    """|value| / limit per sample and joint, per quantity."""
    q, qd, qdd = traj.sample(t)
    qddd = None if jerk is None else trajectory_jerk(traj, t)
    return {k.value: v for k, v in state_ratios(robot, lim, (q, qd, qdd, qddd), jerk).items()}


# ---------------------------------------------------------------------------------------------- the cycle
def cycle_placement(
    robot: RobotModel, span: float = STANDARD_SPAN, rise: float = STANDARD_RISE, branch: str | None = None, n: int = 160
) -> tuple[np.ndarray, np.ndarray, float]:
    """The default placement of the standard cycle (module docstring): (start pose, end pose, min |det J|).

    Candidates: the chords of length ``span`` perpendicular to the arm's direction at the middle of
    J1's range (the elbow at 0), centred on it, at ``n`` distances d from the J1 axis; at each, 41 points of
    the chord at the start height are solved (closed-form IK, ``branch``, default the first, nearest the
    middle of the ranges) and scored by the smallest manipulability |det J|. The best d wins. The joints are
    the closed form's reading of the model (:class:`~scara_pin.kinematics.scara_geometry.ScaraGeometry`):
    the vertical stroke is that of the prismatic joint wherever it sits in q.

    Raises:
        InvalidInputError: ``span`` is longer than the diameter of the reach circle (no chord fits), or
            ``rise`` is not below the vertical stroke.
        UrdfError: the SCARA closed form refuses the robot (its reason: ``NotScaraError``).
        InfeasibleError: no candidate chord is reachable within the joint limits.
    """
    geo = robot.kinematics.geometry  # the closed form's reading; its refusal names the real reason
    branch = branch or robot.kinematics.branches[0]
    elbow, quill = geo.revolute[1], geo.prismatic
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    mid = (lo + hi) / 2.0
    q_stretched = mid.copy()
    q_stretched[elbow] = 0.0 if lo[elbow] <= 0.0 <= hi[elbow] else mid[elbow]
    centre = robot.tool_pose(q_stretched)
    reach = float(np.hypot(centre[0], centre[1]))
    if span >= 2.0 * reach:
        raise InvalidInputError(f"span {span:.6g} m is beyond the reach: the tool reaches {reach:.6g} m from the J1 "
                                f"axis, so no chord longer than {2 * reach:.6g} m fits")  # fmt: skip
    radial = centre[:2] / reach
    tangent = np.array([-radial[1], radial[0]])
    z_ends = [robot.tool_pose(np.where(np.arange(robot.dof) == quill, end, mid))[2] for end in (lo, hi)]
    z_lo, z_hi = min(z_ends), max(z_ends)  # the quill at either end of its stroke (its axis up or down)
    if rise >= z_hi - z_lo:
        raise InvalidInputError(f"rise {rise:.6g} m is beyond the vertical stroke {z_hi - z_lo:.6g} m of "
                                f"{robot.joint_names[quill]}")  # fmt: skip
    z = 0.5 * (z_lo + z_hi) - rise / 2.0
    yaw = 0.0
    u = np.linspace(-0.5, 0.5, 41) * span
    best = (-1.0, 0.0)
    for d in np.linspace(0.0, reach, n + 2)[1:-1]:
        pts = d * radial[None, :] + u[:, None] * tangent[None, :]
        score = math.inf
        for x, y in pts:
            res = robot.ik([x, y, z, yaw], branch=branch, reference=mid)
            sol = res.nearest(mid, branch=branch) if res.success else None
            if sol is None:
                score = -1.0
                break
            score = min(score, robot.manipulability(sol.q))
        if score > best[0]:
            best = (score, float(d))
    if best[0] <= 0.0:
        raise InfeasibleError(f"no chord of {span:.6g} m perpendicular to the arm at mid J1 range is reachable "
                              f"on the {branch} branch at z = {z:.6g} m")  # fmt: skip
    d = best[1]
    a = np.array([*(d * radial - 0.5 * span * tangent), z, yaw])
    b = np.array([*(d * radial + 0.5 * span * tangent), z, yaw])
    return a, b, best[0]


def standard_cycle(
    robot: RobotModel,
    *,
    start: ArrayLike | None = None,
    direction: ArrayLike | None = None,
    span: float = STANDARD_SPAN,
    rise: float = STANDARD_RISE,
    blend: float | None = None,
    payload: PayloadLike = None,
    jerk: float | ArrayLike | None = None,
    limits: JointLimits | None = None,
    branch: str | None = None,
    options: TimingOptions | None = None,
    path: CyclePath | str = CyclePath.JUMP,
    clearance_radius: float = STANDARD_CLEARANCE,
    max_height: float | None = None,
    jump_options: JumpOptions | None = None,
    cell: Cell | None = None,
    torque: bool = True,
) -> CycleResult:
    """The standard cycle: up ``rise``, across ``span``, down, and back the same way (rest at both ends).

    Args:
        robot: a SCARA (the palletizer too with ``path`` JUMP and an explicit ``start``).
        start: the start pose (x, y, z, yaw) [m, rad]; default :func:`cycle_placement`.
        direction: (dx, dy) of the traverse; with ``start`` (default: perpendicular to the arm direction
            at mid J1 range).
        span: [m] > 0, the horizontal stroke.
        rise: [m] > 0, the vertical stroke.
        blend: [m] >= 0, largest blend distance of the straight-leg arch (None: as large as allowed, i.e.
            the whole rise; 0: none); LINES only.
        payload: carried by the tool (the torque limits apply with it, unless ``torque`` is False): a
            :class:`~scara_pin.motion.payload.Payload` or a mass [kg].
        jerk: joint jerk limit, one or four numbers, or None.
        limits: limits instead of ``robot.limits``.
        branch: the elbow branch (the robot's branch names: ``right``/``left`` for a SCARA, ``up``/``down`` for
            a palletizer); default: the default placement's first, a given start's nearest the mid-range.
        options: TOPP-RA grid and verification options (LINES).
        path: JUMP (the default: :func:`~scara_pin.motion.jump.jump_move` out, its time reversal back) or
            LINES (the straight-leg arch, :func:`arch_move`: slower).
        clearance_radius: [m] R of the jump (JUMP).
        max_height: [m] a ceiling for the tool's z (JUMP; LINES: refused below the traverse height).
        jump_options: the jump's grid and solver options (JUMP).
        cell: obstacles, the carried part and the margin (:mod:`scara_pin.cell`): the jump plans around and over
            them; the straight-leg arch (LINES) is verified against them and refused if it comes closer than
            the margin (naming the pair, when and where).
        torque: respect the effort limits (default); False leaves them out (placeholder efforts in a URDF).

    Raises:
        ParameterError: bad input (exit 2); so is InvalidInputError.
        InfeasibleError: the robot cannot do it (PathError, TimingError, JumpError; exit 3).
    """
    path = CyclePath(path)
    span = _nonneg("span", span, strict=True)
    rise = _nonneg("rise", rise, strict=True)
    if path is CyclePath.JUMP and blend is not None:
        raise InvalidInputError("a blend distance applies to the straight-leg arch (path lines), not to the jump")
    if robot.kind != "scara" and (path is CyclePath.LINES or start is None):
        raise InvalidInputError(f"robot {robot.name!r} is a {robot.kind}: its cycle needs the jump (path jump) and "
                                "a start pose (--from; the default placement and the straight-leg arch are "
                                "SCARA-only)")  # fmt: skip
    if start is None and direction is not None:
        raise InvalidInputError("--direction needs --from (the start pose)")
    if start is None:
        a, b, wmin = cycle_placement(robot, span, rise, branch)
        why = ("chord perpendicular to the arm at mid J1 range, centred on it, at mid-stroke height, at the distance "
               "from the J1 axis that maximises the smallest manipulability |det J| along it")  # fmt: skip
    else:
        a = as_vector("start", start)
        dvec = np.array([1.0, 0.0]) if direction is None else as_vector("direction", direction, 2)
        norm = float(np.hypot(*dvec))
        if norm == 0.0:
            raise ParameterError("direction", dvec.tolist(), "must not be zero")
        b = a.copy()
        b[:2] += span * dvec / norm
        why = "given by --from and --direction"
        wmin = math.nan
    if path is CyclePath.JUMP:
        out = jump_move(robot, a, b, rise=rise, clearance_radius=clearance_radius, max_height=max_height,
                        payload=payload, jerk=jerk, torque=torque, limits=limits, branch=branch,
                        options=jump_options, cell=cell)  # fmt: skip
        move: ArchMove | JumpMove = out.and_back()
        bound = LowerBound(2.0 * out.lower_bound.duration, out.lower_bound.joint,
                           out.lower_bound.reason + ", out and back")  # fmt: skip
        used = 0.0
    else:
        if max_height is not None and max_height < max(a[2], b[2]) + rise:
            raise InfeasibleError(f"max_height {max_height:.6g} m is below the traverse height "
                                  f"{max(a[2], b[2]) + rise:.6g} m")  # fmt: skip
        move = arch_move(robot, np.array([a, b, a]), rise=rise, blend=blend, payload=payload, jerk=jerk,
                         torque=torque, limits=limits, branch=branch, options=options)  # fmt: skip
        used = 0.0 if blend == 0.0 else min(math.inf if blend is None else blend, rise, span / 2.0)
        bound = _lines_bound(robot, move, a, b, rise, limits, jerk)
        if cell is not None:
            move = replace(move, distance=clear_of(robot, move.trajectory, cell))
    if wmin != wmin:  # the smallest manipulability along the traverse of the given placement
        q0 = move.trajectory.q_start
        pts = [np.array([*(a[:2] + f * (b[:2] - a[:2])), a[2], a[3]]) for f in np.linspace(0.0, 1.0, 41)]
        wmin = min(robot.manipulability(robot.ik_nearest(p, q0)) for p in pts)
    check = verify(robot, move.trajectory, limits=limits, jerk=jerk, torque=torque, payload=payload)
    return CycleResult(move=move, start=a, end=b, span=span, rise=rise, blend=used, placement=why,
                       min_manipulability=float(wmin), path=path, max_height=max_height, lower_bound=bound,
                       clearance_radius=clearance_radius if path is CyclePath.JUMP else None, robot_name=robot.name,
                       verification=check, torque=torque)  # fmt: skip


def _lines_bound(
    robot: RobotModel, move: ArchMove, a: np.ndarray, b: np.ndarray, rise: float, limits: JointLimits | None,
    jerk: float | ArrayLike | None,
) -> LowerBound:
    """The cycle's lower bound (the jump's: it holds for any motion) for the straight-leg arch's endpoints."""
    lim = robot.limits if limits is None else limits
    q_a, q_b = move.trajectory.q_start, move.paths[0].q_end
    top = max(a[2], b[2]) + rise
    tops = (robot.ik_nearest(np.array([a[0], a[1], top, a[3]]), q_a),
            robot.ik_nearest(np.array([b[0], b[1], top, b[3]]), q_b))  # fmt: skip
    jv = None if jerk is None else np.broadcast_to(np.asarray(jerk, dtype=float), (4,))
    one = lower_bound(robot, q_a, q_b, tops, np.array(lim.velocity), np.array(lim.acceleration), jv)
    return LowerBound(2.0 * one.duration, one.joint, one.reason + ", out and back")


def limits_dict(robot: RobotModel, limits: JointLimits | None, jerk: tuple[float, ...] | None) -> dict[str, Any]:
    """The limits used, JSON-ready (per joint, SI; null where there is none: a URDF joint without ``<limit>``)."""
    lim = robot.limits if limits is None else limits

    def values(v: tuple[float, ...]) -> list[float | None]:
        return [x if math.isfinite(x) else None for x in v]

    return {"velocity": values(lim.velocity), "acceleration": values(lim.acceleration), "effort": values(lim.effort),
            "jerk": None if jerk is None else list(jerk)}  # fmt: skip

