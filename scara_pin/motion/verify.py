"""The one verifier of a timed trajectory: every limit ratio, where it peaks, the endpoints and the rest.

Every planner's output (TOPP-RA, the jerk-limited timing, the jump moves, a quintic) is checked here, by
the same formulas, so "the limits hold" means one thing everywhere. :func:`verify` samples the trajectory

- on its own fixed-rate grid ``k / rate`` (:data:`VERIFY_RATE` = 10 kHz by default), padded with three
  samples of rest on each side;
- at the start and end of every piece and just inside them, at :data:`PIECE_POINTS` points of every
  piece (a piece shorter than a sample period is checked too), and at the piece's breakpoints and their
  left sides when it has them (``piece.breakpoints()``: a motion's law's, where its path jerk switches; a
  polynomial piece's own, where its acceleration or jerk switches);

and forms |value| / limit per joint for

- **velocity** and **acceleration** (and the closed-form maxima of a straight joint move's law,
  :meth:`~scara_pin.motion.trajectory.TimeLaw.peaks`, exact between samples);
- **jerk**, two ways: the analytic joint jerk (``q' sddd + 3 q'' sd sdd + q''' sd^3`` of the motions whose
  law has a jerk, ``law.evaluate_jerk``; a polynomial piece's own ``jerk``), and the third differences of
  q on the padded grid, ``(q[k+3] - 3 q[k+2] + 3 q[k+1] - q[k]) / h^3``, a B-spline-weighted mean of the
  true jerk over 3 h (so never above its maximum): it sees every acceleration step, at the pieces' joins
  and at both rests, whatever the law. Its rounding floor ``8 eps max|q| / h^3`` is reported and allowed on top of the
  tolerance (about 2e-6 of a 2000 m/s^3 limit at 10 kHz on a 0.3 m stroke);
- **torque**: Pinocchio's RNEA (gravity included) on the model carrying ``payload``
  (:func:`~scara_pin.motion.payload.with_payload`);
- **tool speed** |J_xyz(q) qd| when limited;

- **clearance**, with a cell (``scene``, :class:`~scara_pin.cell.Scene`): the exact distance (coal) of every
  checked pair at every sample (the grid and the extra times above: both sides of every breakpoint); the
  smallest, its pair and time are :class:`Clearance`, and a distance below the margin by more than
  :data:`DISTANCE_TOL` fails the check;

and, separately, the **endpoints** (|q(0) - q_start|, |q(T) - q_end| when given) and the **rest** at both
ends (|qd| / vmax, and with a jerk limit |qdd| / amax too, at t = 0 and t = T).

The result, :class:`Verification`, is frozen: the worst ratio of each quantity with the time and joint
where it occurs; :meth:`Verification.check` raises :class:`LimitViolation` (exit 3) naming the first
quantity whose ratio exceeds 1 + :data:`TOLERANCE`, or an endpoint or rest beyond its tolerance.

The evaluation of limits is shared with the planners: :func:`state_ratios` (ratios of given states),
:func:`time_scale` (the uniform slow-down that brings the worst ratio to 1: velocity / k, acceleration
and the dynamic torque / k^2, jerk / k^3), :func:`joint_jerk`, :func:`trajectory_jerk`.

Interface stability: :func:`verify`, :class:`Verification`, :class:`Worst`, :class:`Quantity`,
:class:`LimitViolation`, :func:`state_ratios`, :func:`time_scale`, :func:`joint_jerk`,
:func:`trajectory_jerk` and :func:`jerk_vector` keep their signatures (new keyword arguments may be added
with defaults).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple, cast

import numpy as np
import pinocchio as pin

from .._checks import as_limit_vector, as_positive
from ..description import JOINT_NAMES, JointLimits
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..limits import MAX_SAMPLES, check_count
from ..summary import Summarized
from .paths import GeometricPath, JointLine, third_by_differences
from .payload import PayloadLike, with_payload
from .trajectory import Motion, Trajectory

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..cell import Cell, Scene
    from ..cell.certify import Certificate
    from ..model import RobotModel
    from ..units import DisplayUnits

__all__ = [
    "DISTANCE_TOL",
    "ENDPOINT_TOL",
    "PIECE_POINTS",
    "REST_TOL",
    "TOLERANCE",
    "VERIFY_RATE",
    "Binding",
    "Clearance",
    "JointStates",
    "LimitViolation",
    "Quantity",
    "StaticOverload",
    "Verification",
    "Worst",
    "clear_of",
    "jerk_vector",
    "joint_jerk",
    "motion_states",
    "pieces_jerk",
    "path_third_derivative",
    "state_ratios",
    "static_load",
    "static_overload",
    "static_payload",
    "time_scale",
    "torque_coefficients",
    "trajectory_jerk",
    "verify",
]

VERIFY_RATE = 10_000.0
"""[Hz] the default sampling rate of :func:`verify` (ten times the 1 kHz of a controller)."""
TOLERANCE = 1e-6
"""Relative excess of a limit that :meth:`Verification.check` tolerates: a ratio up to 1 + 1e-6 passes."""
DISTANCE_TOL = 1e-6
"""[m] how far below the cell's margin a verified distance may be (the planners keep margin + 1e-6)."""
REST_TOL = 1e-9
"""|qd| / vmax (and |qdd| / amax with a jerk limit) at t = 0 and t = T above which the ends are not at rest."""
ENDPOINT_TOL = 1e-9
"""[rad or m] the largest |q(0) - q_start| and |q(T) - q_end| accepted."""
CERTIFY_ACCELERATION = 2.0
"""The certificate of a motion's clearance (:func:`~scara_pin.cell.certify.certify`) takes each joint's acceleration
between samples to be within this times its limit (the samples themselves hold 1 + :data:`TOLERANCE`)."""
PIECE_POINTS = 65
"""Points checked inside every piece, however short (besides the rate grid)."""
_CHUNK = 50_000
"""Samples evaluated at once (bounds the memory of a long trajectory at a high rate)."""
_LEFT = 1.0 - 1e-9
"""Fraction of an interval where its left limit at the next breakpoint is checked."""


class Quantity(enum.Enum):
    """A limited quantity; the value is its name in messages and JSON."""

    VELOCITY = "velocity"
    ACCELERATION = "acceleration"
    JERK = "jerk"
    JERK_DIFFERENCES = "jerk (third differences)"
    TORQUE = "torque"
    TOOL_SPEED = "tool speed"


_QUANTITY_WORD = {q: "jerk" if q is Quantity.JERK_DIFFERENCES else q.value for q in Quantity}
"""How each quantity is named in a summary (the third differences are the jerk's measure there)."""


@dataclass(frozen=True)
class Worst:
    """The largest |value| / limit of one quantity over the verified samples.

    Attributes:
        quantity: which quantity.
        ratio: |value| / limit (1.0 = on the limit).
        time: [s] where it occurs (a closed-form peak of a law: the start of its piece).
        joint: the joint's index, or None for the tool speed.
        names: the robot's joint names (the file's own).
    """

    quantity: Quantity
    ratio: float
    time: float
    joint: int | None
    names: tuple[str, ...] = JOINT_NAMES

    @property
    def where(self) -> str:
        """``"joint2 at t = 0.1234 s"``."""
        who = "the tool" if self.joint is None else self.names[self.joint]
        return f"{who} at t = {self.time:.6g} s"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"ratio": self.ratio, "time": self.time,
                "joint": None if self.joint is None else self.names[self.joint]}  # fmt: skip


@dataclass(frozen=True)
class Binding:
    """A limit that binds on a leg of a jump, or on a step of a job (its ``LimitShare``).

    Attributes:
        quantity: "velocity", "acceleration", "jerk", "torque" or "tool speed".
        joint: the joint ("tool" for the tool speed).
        ratio: its largest |value| / limit on the leg.
        share: the fraction of the leg's time it is at >= :data:`~scara_pin.motion.jump.BINDING` of the limit.
    """

    quantity: str
    joint: str
    ratio: float
    share: float

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"quantity": self.quantity, "joint": self.joint, "ratio": self.ratio, "share": self.share}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Binding:
        """From :meth:`to_dict`'s (``KeyError``, ``ValueError``: not one)."""
        return cls(str(data["quantity"]), str(data["joint"]), float(data["ratio"]), float(data["share"]))


@dataclass(frozen=True)
class Clearance:
    """The smallest distance between checked pairs of a cell over the verified samples.

    Attributes:
        distance: [m] the smallest (coal's signed distance; negative: penetration).
        margin: [m] the cell's margin.
        pair: the pair's label (``link2 - post``).
        time: [s] where it occurs.
        samples: (t, smallest distance at t, index of that pair) of every verified sample, time-sorted (for
            per-leg reports).
        where: the closest point (between the two shapes' witness points) in the base frame [m], or None.
        certified: the certificate of the whole motion, between the samples too
            (:func:`~scara_pin.cell.certify.certify`; None when not asked for).
        labels: the scene's pair labels, by index (the certificate names pairs by index).
    """

    distance: float
    margin: float
    pair: str
    time: float
    samples: tuple[np.ndarray, np.ndarray, np.ndarray] = field(repr=False, compare=False)
    where: tuple[float, float, float] | None = None
    certified: Certificate | None = field(default=None, repr=False, compare=False)
    labels: tuple[str, ...] = field(default=(), repr=False, compare=False)

    @property
    def bound(self) -> float:
        """[m] every checked pair's distance is at least this over the whole motion.

        The samples' smallest when the motion was not certified.
        """
        return self.distance if self.certified is None else min(self.distance, self.certified.bound)

    def describe(self) -> str:
        """``link2 - post 1.2 mm deep at t = 0.1234 s near (290, -52, 0) mm in base (margin 2 mm)``."""
        how = (f"{-self.distance * 1e3:.4g} mm deep" if -math.inf < self.distance < 0 else "in contact (depth not "
               "computed)" if self.distance < 0 else f"{self.distance * 1e3:.4g} mm apart")  # fmt: skip
        at = "" if self.where is None else " near (" + ", ".join(f"{v * 1e3:.1f}" for v in self.where) + ") mm in base"
        return f"{self.pair} {how} at t = {self.time:.6g} s{at} (margin {self.margin * 1e3:g} mm)"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"distance": self.distance, "margin": self.margin, "pair": self.pair, "time": self.time,
                "where": None if self.where is None else list(self.where), "certified": self.bound}  # fmt: skip


class LimitViolation(InfeasibleError):
    """A verified trajectory exceeds a limit, misses an endpoint or does not rest at an end (exit code 3).

    Attributes:
        worst: the violated quantity's worst sample (None for an endpoint or rest failure).
        reason: the sentence.
    """

    def __init__(self, reason: str, worst: Worst | None = None) -> None:
        self.worst = worst
        self.reason = reason
        super().__init__(reason)


@dataclass(frozen=True, repr=False)
class Verification(Summarized):
    """What :func:`verify` found (``repr``: one line per limit checked, its worst ratio and where).

    Attributes:
        duration: [s] of the trajectory.
        rate: [Hz] of the verified grid.
        samples: number of verified sample times.
        velocity, acceleration: the worst joint ratios.
        jerk: the worst analytic joint-jerk ratio (motions whose law has a jerk, polynomial pieces; None
            without a jerk limit or when no piece has one).
        jerk_differences: the worst third-difference jerk ratio (None without a jerk limit).
        jerk_floor: the rounding floor of the third differences, as a ratio (allowed on top of the
            tolerance; 0 without a jerk limit).
        torque: the worst effort ratio (None when not limited).
        tool_speed: the worst tool-speed ratio (None when not limited).
        start_error, end_error: [rad or m] max |q(0) - q_start|, |q(T) - q_end| (None when not given).
        rest: the largest |qd| / vmax at t = 0 and T (and |qdd| / amax with a jerk limit).
        clearance: the smallest distance of the cell's checked pairs (None without a cell).
    """

    duration: float
    rate: float
    samples: int
    velocity: Worst
    acceleration: Worst
    jerk: Worst | None = None
    jerk_differences: Worst | None = None
    jerk_floor: float = 0.0
    torque: Worst | None = None
    tool_speed: Worst | None = None
    start_error: float | None = None
    end_error: float | None = None
    rest: float = 0.0
    clearance: Clearance | None = None
    quantities: tuple[Worst, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        found = (self.velocity, self.acceleration, self.jerk, self.jerk_differences, self.torque, self.tool_speed)
        object.__setattr__(self, "quantities", tuple(w for w in found if w is not None))

    @property
    def worst(self) -> Worst:
        """The quantity with the largest ratio (NaN counts as the largest: an unknown limit passes nothing)."""
        return max(self.quantities, key=lambda w: math.inf if math.isnan(w.ratio) else w.ratio)

    def ratios(self) -> dict[str, float | None]:
        """{quantity name: worst ratio or None}, JSON-ready."""
        found = {w.quantity: w.ratio for w in self.quantities}
        return {q.value: found.get(q) for q in Quantity}

    def limited(self) -> tuple[Worst, ...]:
        """The worst ratio of each limit checked; a limit not given is left out.

        Velocity, acceleration, jerk (the analytic jerk where the motions have one, else the third
        differences), torque, tool speed.
        """
        jerk = self.jerk if self.jerk is not None else self.jerk_differences
        return tuple(w for w in (self.velocity, self.acceleration, jerk, self.torque, self.tool_speed) if w is not None)

    def ratio_text(self) -> str:
        """``velocity 0.9159 (joint1), acceleration 1.0000 (joint1), torque 0.6757 (joint2)``: :meth:`limited`."""
        return ", ".join(f"{_QUANTITY_WORD[w.quantity]} {w.ratio:.4f} ({w.where.split(' at ')[0]})"
                         for w in self.limited())  # fmt: skip

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The verification in a few lines: each limit's worst ratio, where and when (ratios have no unit)."""
        try:
            self.check()
            verdict = "within the limits"
        except LimitViolation as exc:
            verdict = f"NOT within the limits: {exc}"
        lines = [f"Verification of {self.duration:.6g} s at {self.rate:g} Hz ({self.samples} samples): {verdict}"]
        lines += [f"  {_QUANTITY_WORD[w.quantity]:<13} {w.ratio:.6f} of its limit, {w.where}" for w in self.limited()]
        return "\n".join(lines)

    def check(self, tolerance: float = TOLERANCE) -> Verification:
        """Self, if every ratio is <= 1 + ``tolerance`` and the endpoints and rest hold; else raise.

        Raises:
            LimitViolation: naming the quantity, the ratio, the joint and the time.
        """
        for w in self.quantities:
            allowed = 1.0 + tolerance + (self.jerk_floor if w.quantity is Quantity.JERK_DIFFERENCES else 0.0)
            if not w.ratio <= allowed:  # NaN fails
                raise LimitViolation(f"the {w.quantity.value} of {w.where} is {w.ratio:.9g} of its limit "
                                     f"(allowed: {allowed:.9g})", w)  # fmt: skip
        for name, err in (("start", self.start_error), ("end", self.end_error)):
            if err is not None and not err <= ENDPOINT_TOL:
                raise LimitViolation(f"the trajectory misses its {name} by {err:.3g} (rad or m; allowed "
                                     f"{ENDPOINT_TOL:g})")  # fmt: skip
        if not self.rest <= REST_TOL:
            raise LimitViolation(f"the trajectory is not at rest at an end: {self.rest:.3g} of a limit "
                                 f"(allowed {REST_TOL:g})")  # fmt: skip
        return self.check_clearance()

    def check_clearance(self) -> Verification:
        """Self, if no checked pair of the cell came closer than its margin (beyond :data:`DISTANCE_TOL`); else raise.

        Raises:
            LimitViolation: naming the pair, how close, when and where (exit 3).
        """
        c = self.clearance
        if c is not None and not c.distance >= c.margin - DISTANCE_TOL:
            raise LimitViolation(f"the motion comes closer than the margin: {c.describe()}")
        cert = None if c is None else c.certified
        if c is not None and cert is not None and not cert.bound >= c.margin - DISTANCE_TOL:
            t, _, low = cert.lowest
            if low < c.margin - DISTANCE_TOL:
                raise LimitViolation(f"the motion comes closer than the margin between the verified samples: "
                                     f"{c.labels[cert.lowest[1]]} {low * 1e3:.4g} mm apart at t = {t:.9g} s (margin "
                                     f"{c.margin * 1e3:g} mm)")  # fmt: skip
            raise LimitViolation(f"the motion is not certified clear between the verified samples near t = "
                                 f"{cert.time:.6g} s: {c.labels[cert.pair]} could come within "
                                 f"{cert.bound * 1e3:.4g} mm (margin {c.margin * 1e3:g} mm; {cert.evaluations} "
                                 "distances evaluated)")  # fmt: skip
        return self


# ---------------------------------------------------------------------------------------------- limits
@dataclass(frozen=True)
class LimitsInForce:
    velocity: np.ndarray
    acceleration: np.ndarray
    effort: np.ndarray | None
    tool_speed: float | None


def limits_in_force(robot: RobotModel, limits: JointLimits | None, tool_speed: float | None,
                    torque: bool) -> LimitsInForce:  # fmt: skip
    """The limits in force, each refused when NaN, zero, negative or infinite."""
    lim = robot.limits if limits is None else limits
    names = robot.joint_names
    per = ["m" if kind == "length" else "rad" for kind in robot.joint_kinds]  # each joint's unit
    v = as_limit_vector("velocity", lim.velocity, [f"{u}/s" for u in per], names)
    a = as_limit_vector("acceleration", lim.acceleration, [f"{u}/s^2" for u in per], names)
    e = as_limit_vector("effort", lim.effort, ["N" if u == "m" else "N m" for u in per], names,
                        unbounded=True) if torque else None  # inf: no <limit>  # fmt: skip
    vt = None if tool_speed is None else as_positive("tool_speed", tool_speed, "m/s")
    return LimitsInForce(v, a, e, vt)


def jerk_vector(jerk: float | ArrayLike, dof: int = 4) -> np.ndarray:
    """One jerk limit for every joint, or one per joint, as a (dof,) array [rad/s^3 or m/s^3].

    Raises:
        ParameterError: not one number or ``dof``, or one that is not finite and > 0.
    """
    try:
        arr = np.asarray(jerk, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError("jerk limit", jerk, "must be one number or one per joint", "rad/s^3 or m/s^3") from None
    jv = np.full(dof, float(arr)) if arr.ndim == 0 else arr
    if jv.shape != (dof,) or not (np.isfinite(jv).all() and (jv > 0).all()):
        raise ParameterError("jerk limit", arr.tolist(), f"must be one number or {dof}, each finite and > 0",
                             "rad/s^3 or m/s^3")  # fmt: skip
    return jv


def tool_speeds(robot: RobotModel, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """|J_xyz(q) dq| per row."""
    return np.array([np.linalg.norm(robot.task_jacobian(q[k])[:3] @ dq[k]) for k in range(len(q))])


def joint_torques(robot: RobotModel, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Joint efforts (n, dof) by Pinocchio's RNEA, gravity included, row by row."""
    model = robot.model
    data = model.createData()
    if getattr(robot, "has_continuous", False):  # Pinocchio takes a continuous joint's (cos, sin)
        return np.array([pin.rnea(model, data, robot.to_pinocchio_q(q[k]), v[k], a[k]) for k in range(len(q))])
    return np.array([pin.rnea(model, data, q[k], v[k], a[k]) for k in range(len(q))])


class JointStates(NamedTuple):
    """Joint states at n samples, each (n, dof): positions, velocities, accelerations, and jerks or None."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    qddd: np.ndarray | None = None


def state_ratios(
    robot: RobotModel, lim: LimitsInForce, states: JointStates | tuple[Any, ...], jerk: np.ndarray | None = None
) -> dict[Quantity, np.ndarray]:
    """|value| / limit per sample (rows) and joint (columns; one column for the tool speed), per quantity.

    ``states``: (q, qd, qdd) or (q, qd, qdd, qddd). The torque needs ``lim.effort``, the tool speed
    ``lim.tool_speed``, the jerk ``qddd`` and ``jerk``.
    """
    return _ratios(robot, lim, JointStates(*states), jerk)[0]


def _ratios(
    robot: RobotModel, lim: LimitsInForce, states: JointStates, jerk: np.ndarray | None
) -> tuple[dict[Quantity, np.ndarray], np.ndarray | None]:
    """(:func:`state_ratios`, the efforts or None)."""
    q, qd, qdd, qddd = states
    out = {Quantity.VELOCITY: np.abs(qd) / lim.velocity, Quantity.ACCELERATION: np.abs(qdd) / lim.acceleration}
    tau = None
    if lim.effort is not None:
        tau = joint_torques(robot, q, qd, qdd)
        out[Quantity.TORQUE] = np.abs(tau) / lim.effort
    if lim.tool_speed is not None:
        out[Quantity.TOOL_SPEED] = (tool_speeds(robot, q, qd) / lim.tool_speed)[:, None]
    if qddd is not None and jerk is not None:
        out[Quantity.JERK] = np.abs(qddd) / jerk
    return out, tau


@dataclass(frozen=True)
class StaticOverload:
    """A configuration where the static load (gravity, payload included) alone reaches an effort limit.

    No timing helps there (slowing down leaves the static load): the request is infeasible.

    Attributes:
        index: the row of the configuration in the samples given.
        joint: the joint's index.
        load: the static load g [N m or N] (signed).
        limit: the effort limit [N m or N].
        names: the robot's joint names (the file's own).
    """

    index: int
    joint: int
    load: float
    limit: float
    names: tuple[str, ...] = JOINT_NAMES

    def reason(self, where: str = "there") -> str:
        """The sentence, ``where`` saying where the robot is (``"there"``, ``"at q = [...]"``)."""
        return (f"the static load on {self.names[self.joint]} ({self.load:.6g}) is not below its effort limit "
                f"{self.limit:.6g}: the robot cannot even hold still {where}")  # fmt: skip


def static_overload(
    g: np.ndarray, effort: np.ndarray, names: tuple[str, ...] = JOINT_NAMES
) -> StaticOverload | None:
    """The first row of static loads ``g`` (n, dof) with |g| >= ``effort`` on a joint, or None.

    Whatever its sign: a load above the limit cannot be held, and one below it leaves room on both sides
    (E - g > 0 and E + g > 0), which :func:`time_scale` relies on. ``names``: the robot's joint names.
    """
    over = np.abs(g) >= effort
    if not over.any():
        return None
    i, j = np.argwhere(over)[0]
    return StaticOverload(int(i), int(j), float(g[i, j]), float(effort[j]), names)


def static_load(robot: RobotModel, q: np.ndarray) -> np.ndarray:
    """g(q) (n, dof): the joint efforts that hold the robot still (RNEA at rest, gravity and payload)."""
    zero = np.zeros_like(q)
    return joint_torques(robot, q, zero, zero)


def static_payload(robot: RobotModel, q: np.ndarray, limits: JointLimits | None = None) -> float:
    """The largest point mass [kg] at the tool frame's origin that the effort limits hold at rest at every row of q.

    The static load is linear in the mass: ``g(q; m) = g0(q) + m g1(q)`` (``g1`` the load of 1 kg, the
    difference of two :func:`static_load` calls), and ``|g0 + m g1| <= effort`` per joint gives
    ``m <= (effort - sign(g1) g0) / |g1|`` wherever ``g1 != 0``. A SCARA's only loaded joint is the vertical
    quill (constant over q); a palletizer's depends on q: the minimum is over the rows given.

    Args:
        robot: the robot (its model: gravity and the links' masses).
        q: (n, dof) configurations [rad, m].
        limits: limits instead of ``robot.limits`` (their efforts).

    Returns:
        the mass [kg]; 0 when the arm alone already exceeds an effort somewhere; inf when no joint carries it.
    """
    effort = np.asarray((robot.limits if limits is None else limits).effort, dtype=float)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    g0 = static_load(robot, q)
    g1 = static_load(with_payload(robot, 1.0), q) - g0
    carried = np.abs(g1) > 1e-12 * max(1.0, float(np.abs(g0).max()))
    room = np.where(carried, (effort - np.sign(g1) * g0) / np.where(carried, np.abs(g1), 1.0), np.inf)
    return max(0.0, float(room.min()))


def torque_coefficients(robot: RobotModel, q: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> tuple[np.ndarray, ...]:
    """(a, b, g), each (n, dof), of the joint efforts along a path: tau = a(s) sdd + b(s) sd^2 + g(s).

    With q' = d1 and q'' = d2 at the points q: qd = q' sd and qdd = q' sdd + q'' sd^2 in the rigid-body
    dynamics M qdd + C(q, qd) qd + g give ``g = rnea(q, 0, 0)`` (:func:`static_load`),
    ``a = rnea(q, 0, q') - g`` and ``b = rnea(q, q', q'') - g`` (RNEA, gravity and payload in the model).
    """
    zero = np.zeros_like(d1)
    g = static_load(robot, q)
    return joint_torques(robot, q, zero, d1) - g, joint_torques(robot, q, d1, d2) - g, g


def time_scale(
    robot: RobotModel, lim: LimitsInForce, states: JointStates | tuple[Any, ...], jerk: np.ndarray | None = None
) -> tuple[float, dict[Quantity, float]]:
    """(k, worst ratios): the time scale k that brings the worst ratio of these states to exactly 1.

    Slowing a motion k times divides velocities and the tool speed by k, accelerations and the dynamic
    part of the torque (``tau - g(q)``) by k^2, jerks by k^3. So k = max(r_v, sqrt(r_a), cbrt(r_j),
    r_tool, sqrt(|tau - g| / room)) with ``room = E - g`` where ``tau - g > 0``, else ``E + g``; k < 1
    speeds up. ``states`` as in :func:`state_ratios`.

    Raises:
        InfeasibleError: the static load alone reaches an effort limit (:func:`static_overload`: no k helps).
    """
    states = JointStates(*states)
    q = states.q
    r, tau = _ratios(robot, lim, states, jerk)
    worst = {name: float(np.max(v)) if v.size else 0.0 for name, v in r.items()}
    k = max(worst[Quantity.VELOCITY], math.sqrt(worst[Quantity.ACCELERATION]))
    if Quantity.JERK in worst:
        k = max(k, worst[Quantity.JERK] ** (1.0 / 3.0))
    if Quantity.TOOL_SPEED in worst:
        k = max(k, worst[Quantity.TOOL_SPEED])
    if tau is not None and lim.effort is not None and len(q):
        E = lim.effort
        g = static_load(robot, q)
        bad = static_overload(g, E, robot.joint_names)
        if bad is not None:
            raise InfeasibleError(bad.reason())
        dyn = tau - g
        room = np.where(dyn > 0, E - g, E + g)  # |dyn / k^2 + g| <= E  <=>  k^2 >= |dyn| / room, room > 0
        k = max(k, math.sqrt(float(np.max(np.abs(dyn) / room))))
    return k, worst


# ---------------------------------------------------------------------------------------------- jerk
def path_third_derivative(path: GeometricPath, s: np.ndarray) -> np.ndarray:
    """q'''(s), (n, dof): the path's own (``path.evaluate(s, 3)``, exact for the paths of this package).

    A path of another origin that stops at order 2: finite differences of its exact q''
    (:func:`~scara_pin.motion.paths.third_by_differences`).
    """
    s = np.asarray(s, dtype=float).ravel()
    out = path.evaluate(s, 3)
    return out[3] if len(out) > 3 else third_by_differences(path, s)


def has_jerk(piece: object) -> bool:
    """True for a piece with an analytic joint jerk.

    A motion whose law has a path jerk (``law.evaluate_jerk``), or a piece with its own ``jerk(tau)``
    (:class:`~scara_pin.motion.polynomial.PolynomialPiece`).
    """
    if isinstance(piece, Motion):
        return callable(getattr(piece.law, "evaluate_jerk", None))
    return callable(getattr(piece, "jerk", None))


def joint_jerk(motion: Motion, tau: np.ndarray) -> np.ndarray:
    """Joint jerk (n, dof) of a motion at local times ``tau``: q' sddd + 3 q'' sd sdd + q''' sd^3.

    A law with ``evaluate_jerk`` gives its own path jerk sddd; any other law is taken as sddd = 0 between
    its breakpoints (a TOPP-RA profile's jerk is unbounded AT its grid points, which this does not show:
    the third differences of :func:`verify` do).
    """
    return cast(np.ndarray, motion_states(motion, tau).qddd)  # always given by motion_states


def motion_states(motion: Motion, tau: np.ndarray) -> JointStates:
    """(q, qd, qdd, qddd), each (n, dof), of a motion at local times ``tau``, from one evaluation of its path.

    qd = q' sd, qdd = q' sdd + q'' sd^2, qddd = q' sddd + 3 q'' sd sdd + q''' sd^3, the path jerk sddd as
    in :func:`joint_jerk`.
    """
    law = motion.law
    if has_jerk(motion):
        s, sd, sdd, sddd = law.evaluate_jerk(tau)  # type: ignore[attr-defined]
    else:
        s, sd, sdd = law.evaluate(tau)
        sddd = np.zeros_like(s)
    out = motion.path.evaluate(s, 3)
    d3 = out[3] if len(out) > 3 else third_by_differences(motion.path, s)
    q, d1, d2 = out[:3]
    v, a = sd[:, None], sdd[:, None]
    return JointStates(q, d1 * v, d1 * a + d2 * v**2, d1 * sddd[:, None] + 3.0 * d2 * v * a + d3 * v**3)


def trajectory_jerk(traj: Trajectory, t: np.ndarray) -> np.ndarray:
    """Joint jerk (n, dof) of a trajectory of motions at times t (zero at rest outside [0, T]).

    Raises:
        InvalidInputError: a piece is not a motion (imported samples have no jerk of their own).
    """
    if not all(isinstance(p, Motion) for p in traj.pieces):
        raise InvalidInputError("jerk needs a trajectory of motions")
    return pieces_jerk(traj, np.asarray(t, dtype=float))


def pieces_jerk(traj: Trajectory, t: np.ndarray, pieces: list[Any] | None = None, *, motions: bool = True
                ) -> np.ndarray:  # fmt: skip
    """Joint jerk (n, dof) at times t: a motion's (:func:`joint_jerk`), another piece's own ``jerk``, else zero.

    Args:
        traj: the trajectory (its start times).
        t: the times [s].
        pieces: its pieces as built, for a trajectory of stand-ins (the plan cache's); default ``traj.pieces``.
        motions: every motion's jerk; False: only a motion whose law has a path jerk (:func:`has_jerk`).
    """
    out = np.zeros((len(t), traj.dof))
    starts = traj.starts.tolist()
    for start, end, p in zip(starts, starts[1:], traj.pieces if pieces is None else pieces):
        sel = (t >= start) & (t <= end)
        if sel.any() and (has_jerk(p) or (motions and isinstance(p, Motion))):
            tau = t[sel] - start
            out[sel] = joint_jerk(p, tau) if isinstance(p, Motion) else p.jerk(tau)
    return out


# ---------------------------------------------------------------------------------------------- verify
def _exact_peaks(piece: object) -> tuple[np.ndarray, np.ndarray] | None:
    """Per joint (max |qd|, max |qdd|) of a straight joint move under a closed-form law, else None.

    On a :class:`JointLine` q = q0 + s dq: qd = dq sd and qdd = dq sdd, so the maxima are |dq| times the
    law's (:meth:`TimeLaw.peaks`).
    """
    if not (isinstance(piece, Motion) and isinstance(piece.path, JointLine)):
        return None
    peaks = piece.law.peaks()
    if peaks is None:
        return None
    dq = np.abs(piece.path.q1 - piece.path.q0)
    return dq * peaks[0], dq * peaks[1]


def _extra_times(traj: Trajectory) -> np.ndarray:
    """Each piece's ends and just inside them, PIECE_POINTS inside it, its breakpoints and their left sides."""
    parts = []
    for start, piece in zip(traj.starts.tolist(), traj.pieces):
        d = piece.duration
        parts.append(start + np.linspace(0.0, d, PIECE_POINTS))
        parts.append(start + d * np.array([1e-9, _LEFT]))
        b = piece.breakpoints()
        if b is not None:
            parts += [start + b, start + b[:-1] + np.diff(b) * _LEFT]
    return np.concatenate(parts)


class _Worst:
    """Running maxima of |value| / limit per quantity: (ratio, time, joint)."""

    def __init__(self, names: tuple[str, ...] = JOINT_NAMES) -> None:
        self.best: dict[Quantity, tuple[float, float, int | None]] = {}
        self.names = names

    def add(self, quantity: Quantity, ratios: np.ndarray, t: np.ndarray, tool: bool = False) -> None:
        if not ratios.size:
            return
        nan = np.isnan(ratios)
        flat = int(np.argmax(nan)) if nan.any() else int(np.argmax(ratios))
        i, j = divmod(flat, ratios.shape[1])
        value = float(ratios[i, j])
        old = self.best.get(quantity)
        if old is None or math.isnan(value) or value > old[0]:
            self.best[quantity] = (value, float(t[i]), None if tool else j)

    def get(self, quantity: Quantity) -> Worst | None:
        got = self.best.get(quantity)
        return None if got is None else Worst(quantity, *got, self.names)


def verify(
    robot: RobotModel,
    trajectory: Trajectory,
    *,
    limits: JointLimits | None = None,
    jerk: float | ArrayLike | None = None,
    torque: bool = False,
    payload: PayloadLike = None,
    tool_speed: float | None = None,
    rate: float = VERIFY_RATE,
    q_start: ArrayLike | None = None,
    q_end: ArrayLike | None = None,
    scene: Scene | None = None,
) -> Verification:
    """Verify ``trajectory`` against the limits (module docstring); call ``.check()`` on the result to enforce.

    Args:
        robot: the robot (its limits unless ``limits``; its model for the torques and the tool speed).
        trajectory: any trajectory (motions, or imported samples: those have no analytic jerk).
        limits: joint limits instead of ``robot.limits``.
        jerk: joint jerk limit(s) [rad/s^3 or m/s^3], one or one per joint; None: jerk not checked.
        torque: check the effort limits (RNEA, gravity included).
        payload: carried by the tool for the torques: a :class:`~scara_pin.motion.payload.Payload` or a mass
            [kg] (:func:`~scara_pin.motion.payload.with_payload`).
        tool_speed: [m/s] limit of the tool origin's speed, optional.
        rate: [Hz] of the verified grid.
        q_start: the configuration the trajectory must start at, optional.
        q_end: the configuration it must end at, optional.
        scene: a robot in its cell (:func:`scara_pin.cell.scene`): every checked pair's distance at every
            sample, against the cell's margin.

    Raises:
        ParameterError: a limit is NaN, zero, negative or not finite; a bad rate or jerk.
        InvalidInputError: the samples would exceed :data:`~scara_pin.limits.MAX_SAMPLES`.
    """
    rate = as_positive("rate", rate, "Hz")
    lim = limits_in_force(robot, limits, tool_speed, torque)
    dof = trajectory.dof
    jv = None if jerk is None else jerk_vector(jerk, dof)
    loaded = with_payload(robot, payload) if torque else robot
    T = trajectory.duration
    h = 1.0 / rate
    n_grid = math.ceil(T * rate - 1e-9)
    extra = _extra_times(trajectory)
    check_count(f"verified samples ({T:.6g} s at {rate:.6g} Hz)", n_grid + 7.0 + len(extra), MAX_SAMPLES,
                "lower the rate or shorten the motion")  # fmt: skip
    grid = np.arange(-3, n_grid + 4) * h  # three samples of rest on each side (the third differences see the ends)
    times = np.concatenate([grid, np.clip(extra, 0.0, T)])
    worst = _Worst(robot.joint_names)
    q_grid = np.empty((len(grid), dof))
    analytic = jv is not None and any(has_jerk(p) for p in trajectory.pieces)
    nearest = np.empty(len(times)) if scene is not None else None
    nearest_pair = np.zeros(len(times), dtype=int)
    for lo in range(0, len(times), _CHUNK):
        t = times[lo : lo + _CHUNK]
        q, qd, qdd = trajectory.sample(t)
        if scene is not None and nearest is not None and scene.pairs:
            nearest[lo : lo + len(t)], nearest_pair[lo : lo + len(t)] = scene.nearest_array(q)
        inside = lo < len(grid)
        if inside:
            q_grid[lo : lo + len(t)] = q[: max(0, len(grid) - lo)]
        qddd = None
        if analytic:
            sel = (t >= 0.0) & (t <= T)
            qddd = np.zeros_like(q)
            qddd[sel] = pieces_jerk(trajectory, t[sel], motions=False)
        for quantity, r in state_ratios(loaded, lim, (q, qd, qdd, qddd), jv).items():
            worst.add(quantity, r, t, tool=quantity is Quantity.TOOL_SPEED)
    for start, piece in zip(trajectory.starts.tolist(), trajectory.pieces):
        peaks = _exact_peaks(piece)
        if peaks is not None:
            t0 = np.array([start])
            worst.add(Quantity.VELOCITY, (peaks[0] / lim.velocity)[None, :], t0)
            worst.add(Quantity.ACCELERATION, (peaks[1] / lim.acceleration)[None, :], t0)
    floor = 0.0
    if jv is not None:
        d3 = (q_grid[3:] - 3.0 * q_grid[2:-1] + 3.0 * q_grid[1:-2] - q_grid[:-3]) * rate**3
        worst.add(Quantity.JERK_DIFFERENCES, np.abs(d3) / jv, grid[:-3] + 1.5 * h)
        floor = float(np.max(8.0 * np.finfo(float).eps * np.max(np.abs(q_grid), axis=0) * rate**3 / jv))
    ends = np.array([0.0, T])
    _, qd_e, qdd_e = trajectory.sample(ends)
    rest = float(np.max(np.abs(qd_e) / lim.velocity))
    if jv is not None:
        rest = max(rest, float(np.max(np.abs(qdd_e) / lim.acceleration)))
    start_err = end_err = None
    if q_start is not None:
        start_err = float(np.max(np.abs(trajectory.q_start - np.asarray(q_start, dtype=float))))
    if q_end is not None:
        end_err = float(np.max(np.abs(trajectory.q_end - np.asarray(q_end, dtype=float))))
    v, a = worst.get(Quantity.VELOCITY), worst.get(Quantity.ACCELERATION)
    if v is None or a is None:  # pragma: no cover - the grid is never empty
        raise ParameterError("trajectory", "no samples", "must have a duration > 0")
    clearance = None
    if scene is not None and nearest is not None and scene.pairs:
        from ..cell.certify import certify

        within = (times >= 0.0) & (times <= T)
        order = np.argsort(times[within], kind="stable")
        ts, ds, ps = times[within][order], nearest[within][order], nearest_pair[within][order]
        i = int(np.argmin(ds))
        closest = scene.distances(trajectory.sample(np.array([ts[i]]))[0][0]).closest
        where = None if closest is None else tuple(float(v) for v in (closest.point_a + closest.point_b) / 2.0)
        cert = certify(scene, lambda tt: trajectory.sample(tt)[:2], ts, ds, ps, CERTIFY_ACCELERATION * lim.acceleration,
                       scene.margin - DISTANCE_TOL)  # fmt: skip
        clearance = Clearance(float(ds[i]), scene.margin, scene.pairs[int(ps[i])].label, float(ts[i]), (ts, ds, ps),
                              where, cert, tuple(p.label for p in scene.pairs))  # type: ignore[arg-type]
    return Verification(T, rate, len(times), v, a, worst.get(Quantity.JERK), worst.get(Quantity.JERK_DIFFERENCES),
                        floor, worst.get(Quantity.TORQUE), worst.get(Quantity.TOOL_SPEED), start_err, end_err,
                        rest, clearance)  # fmt: skip


def clear_of(robot: RobotModel, trajectory: Trajectory, cell: Cell) -> Clearance | None:
    """The smallest distance of ``cell``'s checked pairs along ``trajectory`` (the 10 kHz verifier's), or an error.

    Raises:
        InCollisionError: the start or the end is closer than the margin (exit 2, naming the pair).
        LimitViolation: the path comes closer than the margin (exit 3, naming the pair, when and where).
    """
    from ..cell import scene

    sc = scene(robot, cell)
    sc.check(trajectory.q_start, "the start")
    sc.check(trajectory.q_end, "the end")
    return verify(robot, trajectory, scene=sc).check_clearance().clearance

