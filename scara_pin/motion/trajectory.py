"""Joint and Cartesian paths, time laws, and the :class:`Trajectory` they make (sampling, export, setpoints).

A motion is a geometric path followed by a time law. The path is ``q(s)`` for ``s`` in [0, 1]; the law
is ``s(t)`` for ``t`` in [0, T]; the chain rule gives the joint trajectory

    q(t) = q(s(t)),    qd = q'(s) sd,    qdd = q'(s) sdd + q''(s) sd^2,

with ``'`` a derivative in ``s`` and ``d`` one in ``t``. The paths (:class:`JointLine`,
:class:`JointSpline`, and the straight tool lines of :func:`cartesian_path`) are in :mod:`scara_pin.motion.paths`.

Time laws: :class:`QuinticLaw` (``jtraj``: zero velocity and acceleration at both ends),
:class:`TrapezoidLaw` (bang-coast-bang, time-optimal on a straight joint line), :class:`ProfileLaw`
(piecewise-constant path acceleration between grid points: the exact output of a TOPP-RA profile, see
:mod:`scara_pin.motion.timing`).

A :class:`Trajectory` strings motions together, rest to rest. Outside [0, T] it holds its end positions
(zero velocity and acceleration). It samples at any times, resamples at a fixed rate, exports to CSV and
JSON (and reads them back: between samples a quintic Hermite through q, qd, qdd), and produces
controller setpoints (:meth:`Trajectory.setpoints`): per-axis latency compensation and integer motor
steps. Files are written atomically. Units are SI throughout: [s], [rad] or [m], [rad/s] or [m/s], ...
"""

from __future__ import annotations

import abc
import json
import logging
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import as_limit_vector, as_positive, as_vector
from ..description import JOINT_COUNTS, JOINT_NAMES
from ..errors import InfeasibleError, InvalidInputError, ParameterError
from ..files import write_text_atomic
from ..limits import MAX_SAMPLES, check_count, read_text
from ..summary import Summarized
from .paths import (
    SINGULAR_TOL,
    CartesianPath,
    CartesianSegment,
    GeometricPath,
    JointLine,
    JointSpline,
    PathError,
    cartesian_path,
    joint_path,
    joint_pose,
)

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..units import DisplayUnits

__all__ = [
    "CSV_HEADER",
    "CSV_UNITS",
    "SINGULAR_TOL",
    "CartesianPath",
    "CartesianSegment",
    "GeometricPath",
    "JointLine",
    "JointSpline",
    "MotorUnits",
    "Motion",
    "PathError",
    "ProfileLaw",
    "QuinticLaw",
    "Samples",
    "Setpoints",
    "TimeLaw",
    "Trajectory",
    "TrapezoidLaw",
    "cartesian_path",
    "joint_path",
    "joint_pose",
    "line_optimal_duration",
    "load_samples",
    "load_trajectory",
    "quintic",
    "quintic_min_duration",
    "timed",
    "trapezoidal",
]

logger = logging.getLogger(__name__)

def csv_header(dof: int = 4, kinds: Sequence[str] | None = None) -> tuple[str, ...]:
    """Columns of the trajectory CSV of a robot with ``dof`` joints: t, q1..q<dof>, qd1.., qdd1.. (SI units).

    With ``kinds`` (what each joint value measures: ``"angle"`` or ``"length"``, ``robot.joint_kinds``) each
    name carries its unit: ``t [s]``, ``q1 [rad]``, ``q3 [m]``, ``qd1 [rad/s]``, ``qdd3 [m/s^2]``; the readers
    take both (:func:`~scara_pin.tables.csv_rows`, :data:`CSV_UNITS`).
    """
    if kinds is None:
        return ("t",) + tuple(f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, dof + 1))
    if len(kinds) != dof:
        raise ParameterError("kinds", list(kinds), f"must be {dof} (one per joint)")
    units = [{"angle": "rad", "length": "m"}[k] for k in kinds]
    return ("t [s]",) + tuple(f"{k}{i + 1} [{u}{per}]" for k, per in (("q", ""), ("qd", "/s"), ("qdd", "/s^2"))
                              for i, u in enumerate(units))  # fmt: skip


CSV_UNITS: dict[str, tuple[str, ...]] = {"t": ("s",)} | {
    f"{k}{i}": tuple(f"{u}{per}" for u in ("rad", "m")) for k, per in (("q", ""), ("qd", "/s"), ("qdd", "/s^2"))
    for i in range(1, 5)
}
"""The units a trajectory CSV's column may carry (SI): what :func:`load_trajectory` reads."""


CSV_HEADER: tuple[str, ...] = csv_header(4)
"""Columns of the trajectory CSV: t, q1..q4, qd1..qd4, qdd1..qdd4 (SI units); 3-joint arms: csv_header(3)."""
_FORMAT = "scara-pin/trajectory"
_QUINTIC_PEAK_SD = 1.875
"""max of s'(x) = 30 x^2 (1 - x)^2 on [0, 1], at x = 1/2."""
_QUINTIC_PEAK_SDD = 10.0 / math.sqrt(3.0)
"""max of |s''(x)| = |60 x (1 - x) (1 - 2 x)| on [0, 1], at x = 1/2 -/+ sqrt(3) / 6."""


# ---------------------------------------------------------------------------------------------- time laws
class TimeLaw(abc.ABC):
    """A path parameter law ``s(t)`` on [0, duration], from s = 0 to s = 1, at rest at both ends."""

    duration: float

    @abc.abstractmethod
    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s, sd, sdd) at times ``tau`` in [0, duration] (1-D array)."""

    def scaled(self, k: float) -> TimeLaw:
        """The same law ``k`` times slower: s_k(t) = s(t / k), so sd / k and sdd / k^2."""
        return _ScaledLaw(self, as_positive("k", k))

    def peaks(self) -> tuple[float, float] | None:
        """The exact maxima (max sd, max |sdd|) over [0, duration] in closed form, or None if unknown.

        Limit checks use them instead of samples (a move shorter than a sample period has no sample
        inside it).
        """
        return None

    def times_at(self, s_target: ArrayLike, iterations: int = 60) -> np.ndarray:
        """The times the law reaches the path parameters ``s_target`` (it is monotonic): bisection, all at once."""
        s_target = np.asarray(s_target, dtype=float)
        lo, hi = np.zeros(len(s_target)), np.full(len(s_target), float(self.duration))
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            below = self.evaluate(mid)[0] < s_target
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
        return hi


@dataclass(frozen=True)
class _ScaledLaw(TimeLaw):
    base: TimeLaw
    k: float
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", self.base.duration * self.k)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s, sd, sdd = self.base.evaluate(np.asarray(tau) / self.k)
        return s, sd / self.k, sdd / (self.k * self.k)

    def peaks(self) -> tuple[float, float] | None:  # noqa: D102
        base = self.base.peaks()
        return None if base is None else (base[0] / self.k, base[1] / (self.k * self.k))


@dataclass(frozen=True)
class QuinticLaw(TimeLaw):
    """``s = 10 x^3 - 15 x^4 + 6 x^5``, x = t / T (``jtraj``): zero velocity and acceleration at both ends.

    Evaluated as scipy's quintic Bernstein polynomial with those end conditions
    (``BPoly.from_derivatives``: s = 0, 1 and sd = sdd = 0 at t = 0, T); its control points are
    0, 0, 0, 1, 1, 1. Peak sd = 1.875 / T at T / 2; peak |sdd| = (10 / sqrt(3)) / T^2 at
    x = 1/2 -/+ sqrt(3) / 6.

    Attributes:
        duration: T [s].
    """

    duration: float
    _poly: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        from scipy.interpolate import BPoly

        T = as_positive("duration", self.duration, "s")
        object.__setattr__(self, "duration", T)
        object.__setattr__(self, "_poly", BPoly.from_derivatives([0.0, T], [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        t = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        P = self._poly
        return P(t), P(t, 1), P(t, 2)

    def peaks(self) -> tuple[float, float]:
        """(1.875 / T, (10 / sqrt(3)) / T^2): sd'' = 0 at x = 1/2, sdd' = 0 at x = 1/2 -/+ sqrt(3) / 6."""
        T = self.duration
        return _QUINTIC_PEAK_SD / T, _QUINTIC_PEAK_SDD / (T * T)


@dataclass(frozen=True)
class TrapezoidLaw(TimeLaw):
    """Bang-coast-bang in s: accelerate at A, coast at the peak velocity, decelerate at A; s from 0 to 1.

    The peak is ``min(velocity, sqrt(acceleration))`` (a triangle when the velocity is not reached).

    Attributes:
        velocity: largest path velocity [1/s].
        acceleration: path acceleration [1/s^2].
    """

    velocity: float
    acceleration: float
    duration: float = field(init=False)
    peak: float = field(init=False)
    t_acc: float = field(init=False)

    def __post_init__(self) -> None:
        V = as_positive("velocity", self.velocity, "1/s")
        A = as_positive("acceleration", self.acceleration, "1/s^2")
        peak = min(V, math.sqrt(A))
        t_acc = peak / A
        coast = max(1.0 / peak - peak / A, 0.0)
        object.__setattr__(self, "peak", peak)
        object.__setattr__(self, "t_acc", t_acc)
        object.__setattr__(self, "duration", 2.0 * t_acc + coast)

    @classmethod
    def for_duration(cls, acceleration: float, duration: float) -> TrapezoidLaw:
        """The law of the given duration with acceleration A: peak V solves 1/V + V/A = T.

        Raises:
            InfeasibleError: T < 2 / sqrt(A) (even a triangle at A is slower).
        """
        A = as_positive("acceleration", acceleration, "1/s^2")
        T = as_positive("duration", duration, "s")
        disc = A * A * T * T - 4.0 * A
        if disc < -1e-12 * A * A * T * T:
            raise InfeasibleError(f"duration {T:.9g} s is shorter than the fastest move {2 / math.sqrt(A):.9g} s")
        V = 2.0 * A / (A * T + math.sqrt(max(disc, 0.0)))  # the small root, without cancellation
        return cls(V, A)

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        A, V, ta, T = self.acceleration, self.peak, self.t_acc, self.duration
        t = np.clip(np.asarray(tau, dtype=float), 0.0, T)
        r = T - t
        up, down = t < ta, r < ta
        s = np.where(up, 0.5 * A * t * t, np.where(down, 1.0 - 0.5 * A * r * r, 0.5 * A * ta * ta + V * (t - ta)))
        sd = np.where(up, A * t, np.where(down, A * r, V))
        sdd = np.where(up, A, np.where(down, -A, 0.0))
        return np.minimum(s, 1.0), sd, sdd

    def peaks(self) -> tuple[float, float]:
        """(peak velocity, A): the coast (or triangle top) velocity and the bang acceleration."""
        return self.peak, self.acceleration


@dataclass(frozen=True, eq=False)
class ProfileLaw(TimeLaw):
    """A phase-plane profile: path velocity ``sd_i`` at grid points ``s_i``, constant ``sdd`` between them.

    On segment i: ``u_i = (sd_{i+1}^2 - sd_i^2) / (2 (s_{i+1} - s_i))``, duration
    ``2 (s_{i+1} - s_i) / (sd_i + sd_{i+1})``, and exactly ``sd(t) = sd_i + u_i t``,
    ``s(t) = s_i + sd_i t + u_i t^2 / 2``: the kinematics between grid points are those of the law
    itself, not an interpolation of it.

    Attributes:
        s: (N + 1,) grid, increasing from 0 to 1.
        sd: (N + 1,) path velocities >= 0 [1/s]; sd_i + sd_{i+1} > 0 on every segment.
        t: (N + 1,) times of the grid points [s] (derived).
        u: (N,) path accelerations [1/s^2] (derived).
    """

    s: np.ndarray
    sd: np.ndarray
    t: np.ndarray = field(init=False)
    u: np.ndarray = field(init=False)
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        s = np.array(self.s, dtype=float)
        sd = np.array(self.sd, dtype=float)
        if s.ndim != 1 or s.shape != sd.shape or len(s) < 2:
            raise ParameterError("profile", f"shapes {s.shape}, {sd.shape}", "must be two equal 1-D arrays of >= 2")
        if not (np.isfinite(s).all() and np.isfinite(sd).all()):
            raise ParameterError("profile", "non-finite values", "must be finite")
        ds = np.diff(s)
        if s[0] != 0.0 or s[-1] != 1.0 or not (ds > 0).all():
            raise ParameterError("profile s", f"[{s[0]}, ..., {s[-1]}]", "must increase strictly from 0 to 1")
        if (sd < 0).any():
            raise ParameterError("profile sd", float(sd.min()), "must be >= 0")
        mean = sd[1:] + sd[:-1]
        if not (mean > 0).all():
            k = int(np.argmin(mean))
            raise InfeasibleError(f"the path velocity is zero on a whole segment at s = {s[k]:.9g}: the motion stops")
        dt = 2.0 * ds / mean
        object.__setattr__(self, "s", s)
        object.__setattr__(self, "sd", sd)
        object.__setattr__(self, "t", np.concatenate([[0.0], np.cumsum(dt)]))
        object.__setattr__(self, "u", (sd[1:] ** 2 - sd[:-1] ** 2) / (2.0 * ds))
        object.__setattr__(self, "duration", float(self.t[-1]))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.u) - 1)
        dt = tau - self.t[i]
        u = self.u[i]
        sd = np.maximum(self.sd[i] + u * dt, 0.0)
        s = np.clip(self.s[i] + self.sd[i] * dt + 0.5 * u * dt * dt, self.s[i], self.s[i + 1])
        return s, sd, u

    def scaled(self, k: float) -> ProfileLaw:
        """The same profile ``k`` times slower (sd / k; hence times * k and u / k^2), exactly."""
        return ProfileLaw(self.s, self.sd / as_positive("k", k))


# ---------------------------------------------------------------------------------------------- motions
class Piece(abc.ABC):
    """A part of a trajectory: ``duration`` and (q, qd, qdd) at local times in [0, duration]."""

    duration: float

    @abc.abstractmethod
    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd), each (n, 4), at local times ``tau`` (1-D array)."""

    def breakpoints(self) -> np.ndarray | None:
        """Local times [s] where the motion is only piecewise smooth (the verifier checks both sides), or None."""
        return None


@dataclass(frozen=True, eq=False)
class Motion(Piece):
    """A path followed with a time law: q(t) = path(law(t)) (see the module docstring).

    Attributes:
        path: the geometric path.
        law: the time law.
    """

    path: GeometricPath
    law: TimeLaw
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "duration", float(self.law.duration))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:  # noqa: D102
        s, sd, sdd = self.law.evaluate(tau)
        q, dq, ddq = self.path.evaluate(s, 2)
        return q, dq * sd[:, None], dq * sdd[:, None] + ddq * (sd * sd)[:, None]

    def scaled(self, k: float) -> Motion:
        """The same motion k times slower."""
        return Motion(self.path, self.law.scaled(k))

    def breakpoints(self) -> np.ndarray | None:
        """The law's breakpoints (where its path jerk switches), when it has them."""
        bp = getattr(self.law, "breakpoints", None)
        return None if bp is None else np.asarray(bp(), dtype=float)


@dataclass(frozen=True, eq=False)
class Samples:
    """Sampled joint trajectory: times and q, qd, qdd (SI).

    Attributes:
        t: (n,) increasing times from 0 [s].
        q, qd, qdd: (n, 4) positions, velocities, accelerations.
        duration: the motion's own length [s]: ``t[-1]`` (the default), or a time in (t[-2], t[-1]] when the
            samples are a fixed-rate grid whose last sample falls after the end of the motion (at rest).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    duration: float | None = None

    def __post_init__(self) -> None:
        t = np.array(self.t, dtype=float)
        if t.ndim != 1 or len(t) < 2:
            raise ParameterError("t", f"array of shape {t.shape}", "must be 1-D with at least 2 samples")
        if not np.isfinite(t).all() or t[0] != 0.0 or not (np.diff(t) > 0).all():
            raise ParameterError("t", f"[{t[0]}, ..., {t[-1]}]", "must be finite, start at 0 and increase strictly")
        object.__setattr__(self, "t", t)
        if self.duration is None:
            object.__setattr__(self, "duration", float(t[-1]))
        else:
            T = float(self.duration)
            if not (math.isfinite(T) and t[-2] < T <= t[-1]):
                last = f"({float(t[-2])!r}, {float(t[-1])!r}]"
                raise ParameterError("duration", self.duration, f"must be in {last} (the last interval)", "s")
            object.__setattr__(self, "duration", T)
        dof = np.shape(self.q)[-1] if np.ndim(self.q) == 2 and np.shape(self.q)[-1] in JOINT_COUNTS else 4
        for name in ("q", "qd", "qdd"):
            arr = np.array(getattr(self, name), dtype=float)
            if arr.shape != (len(t), dof):
                raise ParameterError(name, f"array of shape {arr.shape}", f"must have shape ({len(t)}, {dof})")
            if not np.isfinite(arr).all():
                raise ParameterError(name, "non-finite values", "must be finite")
            object.__setattr__(self, name, arr)

    def table(self) -> np.ndarray:
        """(n, 1 + 3 dof) array in :func:`csv_header` order (13 columns for 4 joints)."""
        return np.column_stack([self.t, self.q, self.qd, self.qdd])

    def csv_text(self, kinds: Sequence[str] | None = None) -> str:
        """The CSV text (header, then one row per sample; shortest round-trip float text).

        ``kinds``: what each joint value measures (``robot.joint_kinds``): the header carries the units
        (:func:`csv_header`).
        """
        lines = [",".join(csv_header(self.q.shape[1], kinds))]
        lines += [",".join(map(repr, row)) for row in self.table().tolist()]
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (``format``, ``version``, ``joints``, ``duration``, ``t``, ``q``, ``qd``, ``qdd``)."""
        return {
            "format": _FORMAT,
            "version": 1,
            "units": "SI: s; rad or m; per s; per s^2",
            "joints": list(JOINT_NAMES[: self.q.shape[1]]),
            "duration": self.duration,  # the motion's length (the last sample may be up to one period later)
            "t": self.t.tolist(),
            "q": self.q.tolist(),
            "qd": self.qd.tolist(),
            "qdd": self.qdd.tolist(),
        }

    @classmethod
    def from_table(cls, table: np.ndarray) -> Samples:
        """From an (n, 13) array in :data:`CSV_HEADER` order."""
        table = np.asarray(table, dtype=float)
        return cls(table[:, 0], table[:, 1:5], table[:, 5:9], table[:, 9:13])


@dataclass(frozen=True, eq=False)
class _SampledPiece(Piece):
    """Samples joined by quintic Hermite polynomials (q, qd, qdd matched at every sample).

    A scipy ``BPoly`` (piecewise Bernstein form, evaluated by scipy) whose control points are those
    ``BPoly.from_derivatives`` computes from (q, qd, qdd) at the two ends of each interval of length h:
    p0, p0 + h v0 / 5, p0 + 2 h v0 / 5 + h^2 a0 / 20, and symmetrically from the right end. They are
    formed here for all intervals at once (``from_derivatives`` loops over the intervals in Python: 35 us
    each, over a minute for the 2 million samples a file may hold).
    """

    samples: Samples
    duration: float = field(init=False)
    _poly: Any = field(init=False, repr=False)

    def __post_init__(self) -> None:
        from scipy.interpolate import BPoly

        S = self.samples
        object.__setattr__(self, "duration", float(S.t[-1]))
        h = np.diff(S.t)[:, None]
        p0, v0, a0 = S.q[:-1], S.qd[:-1] * h, S.qdd[:-1] * (h * h)
        p1, v1, a1 = S.q[1:], S.qd[1:] * h, S.qdd[1:] * (h * h)
        c = np.stack([p0, p0 + v0 / 5, p0 + 2 * v0 / 5 + a0 / 20, p1 - 2 * v1 / 5 + a1 / 20, p1 - v1 / 5, p1])
        object.__setattr__(self, "_poly", BPoly(c, S.t))

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        S = self.samples
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        P = self._poly
        q, qd, qdd = P(tau), P(tau, 1), P(tau, 2)
        i = np.clip(np.searchsorted(S.t, tau, side="right") - 1, 0, len(S.t) - 2)
        for j in (i, i + 1):  # at the samples themselves: the stored values, bit for bit
            at = tau == S.t[j]
            q[at], qd[at], qdd[at] = S.q[j[at]], S.qd[j[at]], S.qdd[j[at]]
        return q, qd, qdd


# ---------------------------------------------------------------------------------------------- trajectory
@dataclass(frozen=True, eq=False, repr=False)
class Trajectory(Summarized):
    """A joint trajectory made of pieces played one after the other, from rest to rest.

    Attributes:
        pieces: the motions (or imported samples), in order; each starts where the previous ends.
        duration: total duration T [s].
        starts: (len(pieces) + 1,) start time of each piece, then T.
        dof: the number of joints (4, or 3 for a SCARA without a wrist).
    """

    pieces: tuple[Piece, ...]
    duration: float = field(init=False)
    starts: np.ndarray = field(init=False, repr=False)
    dof: int = field(init=False, repr=False)

    def __post_init__(self) -> None:
        pieces = tuple(self.pieces)
        if not pieces or not all(isinstance(p, Piece) for p in pieces):
            raise ParameterError("pieces", self.pieces, "must be a non-empty sequence of motions")
        for k, p in enumerate(pieces):
            if not (math.isfinite(p.duration) and p.duration > 0):
                raise ParameterError(f"piece {k} duration", p.duration, "must be finite and > 0", "s")
        for k in range(len(pieces) - 1):
            end = pieces[k].evaluate(np.array([pieces[k].duration]))[0][0]
            start = pieces[k + 1].evaluate(np.array([0.0]))[0][0]
            if np.abs(end - start).max() > 1e-9:
                rule = f"must start where piece {k} ends, {end.tolist()}"
                raise ParameterError(f"piece {k + 1}", start.tolist(), rule)
        starts = np.concatenate([[0.0], np.cumsum([p.duration for p in pieces])])
        object.__setattr__(self, "pieces", pieces)
        object.__setattr__(self, "starts", starts)
        object.__setattr__(self, "duration", float(starts[-1]))
        object.__setattr__(self, "dof", int(pieces[0].evaluate(np.array([0.0]))[0].shape[1]))

    # --------------------------------------------------------------------------------- sampling

    def summary(self, units: DisplayUnits | None = None) -> str:
        """Duration, pieces (by kind) and the end configurations (q in SI: rad, and m for a prismatic joint)."""
        kinds: dict[str, int] = {}
        for p in self.pieces:
            kinds[type(p).__name__] = kinds.get(type(p).__name__, 0) + 1
        made = ", ".join(f"{n} {k}" for k, n in kinds.items())
        return (f"Trajectory {self.duration:.6f} s, {len(self.pieces)} piece(s) ({made}), {self.dof} joints: q "
                f"{np.round(self.q_start, 9).tolist()} -> {np.round(self.q_end, 9).tolist()}")
    def sample(self, t: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at times ``t`` [s]: (4,) each for a scalar, (n, 4) for an array.

        Before 0 and after T the robot holds the end positions (qd = qdd = 0).
        """
        arr = np.asarray(t, dtype=float)
        tt = np.atleast_1d(arr).ravel()
        if not np.isfinite(tt).all():
            raise ParameterError("t", "non-finite times", "must be finite")
        dof = self.dof
        q = np.empty((len(tt), dof))
        qd = np.zeros((len(tt), dof))
        qdd = np.zeros((len(tt), dof))
        k = np.clip(np.searchsorted(self.starts, tt, side="right") - 1, 0, len(self.pieces) - 1)
        inside = (tt >= 0.0) & (tt <= self.duration)
        # the samples grouped by piece (a stable sort: O(n log n), not a pass over the samples per piece, which a
        # job of thousands of pieces would make quadratic)
        idx = np.nonzero(inside)[0]
        idx = idx[np.argsort(k[idx], kind="stable")]
        cuts = np.searchsorted(k[idx], np.arange(len(self.pieces) + 1))
        for j in np.nonzero(np.diff(cuts))[0]:
            sel = idx[cuts[j] : cuts[j + 1]]
            q[sel], qd[sel], qdd[sel] = self.pieces[j].evaluate(tt[sel] - self.starts[j])
        if not inside.all():
            last = self.pieces[-1]
            q[tt < 0.0] = self.pieces[0].evaluate(np.array([0.0]))[0][0]
            q[tt > self.duration] = last.evaluate(np.array([last.duration]))[0][0]
        if arr.ndim == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    @property
    def q_start(self) -> np.ndarray:
        """Joint values at t = 0."""
        return self.sample(0.0)[0]

    @property
    def q_end(self) -> np.ndarray:
        """Joint values at t = T."""
        return self.sample(self.duration)[0]

    def times(self, rate: float) -> np.ndarray:
        """The fixed-rate grid k / rate, k = 0, 1, ..., through T (the last sample is at or just after T).

        Sized first: the number of samples (at most :data:`~scara_pin.limits.MAX_SAMPLES`), and the grid's
        end, which lies up to one sample period 1 / rate past T: a period longer than both the motion and
        1 s is refused (``rate = 1e-50`` would put the last sample at t = 1e50 s).
        """
        rate = as_positive("rate", rate, "Hz")
        if self.duration > 0 and 1.0 / rate > max(self.duration, 1.0):  # then the grid is [0, 1 / rate]
            raise InvalidInputError(f"a rate of {rate:.6g} Hz samples every {1.0 / rate:.6g} s, longer than the "
                                    f"{self.duration:.6g} s motion and 1 s: its last sample would be at "
                                    f"t = {1.0 / rate:.6g} s; raise the rate")  # fmt: skip
        check_count(f"samples ({self.duration:.6g} s at {rate:.6g} Hz)", self.duration * rate + 1.0, MAX_SAMPLES,
                    "lower the rate or shorten the motion")  # fmt: skip
        n = math.floor(self.duration * rate + 1e-9)
        if n / rate < self.duration * (1 - 1e-12):
            n += 1
        return np.arange(n + 1) / rate

    def resample(self, rate: float) -> Samples:
        """Samples on the fixed-rate grid :meth:`times`."""
        t = self.times(rate)
        return Samples(t, *self.sample(t), duration=min(self.duration, float(t[-1])))

    def scaled(self, k: float) -> Trajectory:
        """The same trajectory ``k`` times slower (velocities / k, accelerations / k^2)."""
        k = as_positive("k", k)
        pieces = []
        for p in self.pieces:
            if not isinstance(p, Motion):
                raise InvalidInputError("only trajectories made of motions (not imported samples) can be rescaled")
            pieces.append(p.scaled(k))
        return Trajectory(tuple(pieces))

    def then(self, other: Trajectory) -> Trajectory:
        """This trajectory followed by ``other`` (which must start where this one ends)."""
        return Trajectory(self.pieces + other.pieces)

    # --------------------------------------------------------------------------------- export
    def to_csv(self, path: str | os.PathLike[str], rate: float = 1000.0, kinds: Sequence[str] | None = None) -> Path:
        """Write the samples at ``rate`` [Hz] as CSV (``kinds``: units in the header), atomically; return the path."""
        text = self.resample(rate).csv_text(kinds)
        return write_text_atomic(Path(path), text)

    def save(self, path: str | os.PathLike[str], rate: float = 1000.0, kinds: Sequence[str] | None = None) -> Path:
        """Write the samples at ``rate`` [Hz]: JSON for a name ending in ``.json``, else CSV; atomically."""
        if Path(path).suffix.lower() == ".json":
            return self.to_json(path, rate=rate)
        return self.to_csv(path, rate=rate, kinds=kinds)

    def to_json(self, path: str | os.PathLike[str], rate: float = 1000.0) -> Path:
        """Write the samples at ``rate`` [Hz] as JSON (see :meth:`Samples.to_dict`), atomically."""
        data = self.resample(rate).to_dict()
        data["rate"] = float(rate)
        return write_text_atomic(Path(path), json.dumps(data) + "\n")

    @classmethod
    def from_samples(cls, samples: Samples) -> Trajectory:
        """A trajectory through samples (quintic Hermite between them: q, qd, qdd matched)."""
        return cls((_SampledPiece(samples),))

    # --------------------------------------------------------------------------------- controller
    def setpoints(
        self, rate: float, *, delays: Sequence[float] | None = None, motor: MotorUnits | None = None
    ) -> Setpoints:
        """Controller setpoints at a fixed rate, with per-axis latency compensation and motor steps.

        Axis i's command reaches its drive ``delays[i]`` late (S4: station i after i sigma), so the
        setpoint sent at time t is ``q_i(t + delays[i])``: every axis then arrives at q(t') at the same
        t'. Sending starts ``max(delays)`` early (rounded up to whole periods): the send times ``t`` may
        be negative (relative to the start of the motion).

        Args:
            rate: setpoint rate [Hz] (controllers use 250 Hz to 1 kHz).
            delays: per-axis command latency [s], >= 0 (default: none).
            motor: conversion to integer motor steps (optional).
        """
        rate = as_positive("rate", rate, "Hz")
        d = np.zeros(self.dof) if delays is None else as_vector("delays", delays, self.dof)
        if (d < 0).any():
            raise ParameterError("delays", d.tolist(), "must be >= 0", "s")
        check_count(f"setpoints ({float(d.max()) + self.duration:.6g} s at {rate:.6g} Hz)",
                    (float(d.max()) + self.duration) * rate + 2.0, MAX_SAMPLES, "lower the rate or the delays")
        lead = math.ceil(float(d.max()) * rate - 1e-9)
        t = np.concatenate([np.arange(-lead, 0) / rate, self.times(rate)])
        q = np.empty((len(t), self.dof))
        shifted: dict[float, np.ndarray] = {}  # one evaluation per distinct delay
        for i, di in enumerate(d.tolist()):
            if di not in shifted:
                shifted[di] = self.sample(t + di)[0]
            q[:, i] = shifted[di][:, i]
        return Setpoints(rate, tuple(d.tolist()), t, q, None if motor is None else motor.counts(q))


def load_trajectory(path: str | os.PathLike[str]) -> Trajectory:
    """Read a trajectory written by :meth:`Trajectory.to_csv` or :meth:`Trajectory.to_json` (by suffix).

    The trajectory passes through every sample: its ``duration`` is the last sample's time, which on a
    fixed-rate grid may be up to one period after the end of the motion (at rest); the motion's own
    duration of a JSON file is :func:`load_samples`'s.

    Raises:
        InvalidInputError: unreadable file, wrong header or format, or bad values (with the line).
    """
    path = Path(path)
    if path.suffix.lower() != ".json":
        from ..tables import read_csv

        table = read_csv(path, CSV_HEADER, exact=True, max_rows=MAX_SAMPLES, units=CSV_UNITS)
        try:
            return Trajectory.from_samples(Samples.from_table(table))
        except ParameterError as exc:
            raise InvalidInputError(f"{path}: {exc}") from None
    return Trajectory.from_samples(load_samples(path))


def load_samples(path: str | os.PathLike[str]) -> Samples:
    """The samples of a JSON trajectory file (:meth:`Trajectory.to_json`), with the motion's duration.

    Raises:
        InvalidInputError: unreadable file, not a trajectory file, or bad values.
    """
    path = Path(path)
    try:
        text = read_text(path, "trajectory")  # bounded: /dev/zero or a huge file is refused, not read whole
    except InvalidInputError as exc:
        raise InvalidInputError(f"{path}: cannot be read ({exc})") from None
    return _samples_from_json(text, str(path))


def _samples_from_json(text: str, origin: str) -> Samples:
    try:
        data = json.loads(text)
    except ValueError as exc:  # JSONDecodeError, or an integer of more digits than Python converts
        raise InvalidInputError(f"{origin}: not JSON: {exc}") from None
    if not isinstance(data, dict) or data.get("format") != _FORMAT:
        raise InvalidInputError(f"{origin}: not a {_FORMAT} file")
    try:
        duration = data.get("duration")  # the motion's length; files of version 1 may hold t[-1] there
        return Samples(np.array(data["t"], dtype=float), np.array(data["q"], dtype=float),
                       np.array(data["qd"], dtype=float), np.array(data["qdd"], dtype=float),
                       None if duration is None else float(duration))  # fmt: skip
    except ParameterError as exc:
        raise InvalidInputError(f"{origin}: {exc}") from None
    except (KeyError, TypeError, ValueError, OverflowError) as exc:  # OverflowError: an integer beyond float
        raise InvalidInputError(f"{origin}: bad trajectory data ({exc})") from None


# ---------------------------------------------------------------------------------------------- setpoints
@dataclass(frozen=True)
class MotorUnits:
    """Conversion of joint values to integer motor steps: ``steps = round(q * counts_per_unit)``.

    Each setpoint rounds the ABSOLUTE position: the error never exceeds half a step and never
    accumulates (increments are differences of rounded absolutes, never rounded themselves).

    Attributes:
        counts_per_unit: per joint [steps/rad] (revolute) or [steps/m] (prismatic).
    """

    counts_per_unit: tuple[float, ...]

    def __post_init__(self) -> None:
        arr = as_limit_vector("counts_per_unit", self.counts_per_unit, "steps per unit")
        object.__setattr__(self, "counts_per_unit", tuple(float(v) for v in arr))

    @classmethod
    def from_drive(
        cls,
        gear_ratio: Sequence[float],
        steps_per_revolution: Sequence[float],
        screw_lead: float,
        prismatic: int = 2,
    ) -> MotorUnits:
        """From the drive train.

        Revolute joints ``gear * steps_per_rev / (2 pi)`` [steps/rad]; the prismatic joint
        ``gear * steps_per_rev / lead`` [steps/m], ``lead`` the screw's travel per turn [m].

        Args:
            gear_ratio: motor turns per joint turn (per screw turn for the prismatic joint).
            steps_per_revolution: motor steps (microsteps) per motor turn.
            screw_lead: [m] travel per screw turn.
            prismatic: index of the prismatic joint in q.
        """
        g = as_limit_vector("gear_ratio", gear_ratio, "")
        spr = as_limit_vector("steps_per_revolution", steps_per_revolution, "")
        lead = as_positive("screw_lead", screw_lead, "m")
        if prismatic not in range(4):
            raise ParameterError("prismatic", prismatic, "must be a joint index 0..3")
        cpu = g * spr / (2.0 * math.pi)
        cpu[prismatic] = g[prismatic] * spr[prismatic] / lead
        return cls(tuple(cpu.tolist()))

    def counts(self, q: np.ndarray) -> np.ndarray:
        """Integer steps (int64) of joint values q (..., 4), rounded from the absolute position."""
        x = np.asarray(q, dtype=float) * np.asarray(self.counts_per_unit)
        if not np.isfinite(x).all() or np.abs(x).max(initial=0.0) > 2.0**62:
            raise ParameterError("motor steps", ParameterError.NOTHING, "would leave the int64 range (|q| x counts "
                                 "per unit > 2^62): check --gear, --steps-per-rev and --screw-lead")  # fmt: skip
        return np.rint(x).astype(np.int64)


@dataclass(frozen=True, eq=False)
class Setpoints:
    """Fixed-rate controller setpoints (see :meth:`Trajectory.setpoints`).

    Attributes:
        rate: [Hz].
        delays: per-axis latency compensated [s].
        t: (n,) send times [s] (negative while the late axes are sent ahead).
        q: (n, 4) commanded joint values; column i is q_i(t + delays[i]).
        steps: (n, 4) int64 motor steps, or None.
    """

    rate: float
    delays: tuple[float, ...]
    t: np.ndarray
    q: np.ndarray
    steps: np.ndarray | None = None

    @property
    def increments(self) -> np.ndarray:
        """(n, 4) int64 step increments per period (first row 0): differences of absolute counts."""
        if self.steps is None:
            raise InvalidInputError("these setpoints have no motor units")
        return np.diff(self.steps, axis=0, prepend=self.steps[:1])

    def csv_text(self) -> str:
        """CSV: t, q1..q4 and, with motor units, steps1..steps4."""
        n = self.q.shape[1]
        head = ["t"] + [f"q{i}" for i in range(1, n + 1)] + ([f"steps{i}" for i in range(1, n + 1)]
                                                            if self.steps is not None else [])  # fmt: skip
        lines = [",".join(head)]
        for k in range(len(self.t)):
            row = [repr(float(self.t[k]))] + [repr(v) for v in self.q[k].tolist()]
            if self.steps is not None:
                row += [str(v) for v in self.steps[k].tolist()]
            lines.append(",".join(row))
        return "\n".join(lines) + "\n"

    def to_csv(self, path: str | os.PathLike[str]) -> Path:
        """Write :meth:`csv_text` atomically."""
        return write_text_atomic(Path(path), self.csv_text())


# ---------------------------------------------------------------------------------------------- constructors
def quintic(q0: ArrayLike, q1: ArrayLike, duration: float) -> Trajectory:
    """``jtraj``: q0 to q1 in ``duration`` with a quintic, zero velocity and acceleration at both ends.

    Each joint: ``q0 + (q1 - q0) (10 x^3 - 15 x^4 + 6 x^5)``, x = t / T; peak velocity
    ``1.875 dq / T`` at T / 2, peak acceleration ``(10 / sqrt(3)) dq / T^2`` at x = 1/2 -/+ sqrt(3)/6.

    Args:
        q0: start [rad, m].
        q1: end [rad, m].
        duration: T [s] > 0.
    """
    line = JointLine(as_vector("q0", q0, None), as_vector("q1", q1, len(q0)))
    return Trajectory((Motion(line, QuinticLaw(duration)),))


def _line_rates(
    q0: ArrayLike, q1: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> tuple[JointLine, float, float]:
    line = JointLine(as_vector("q0", q0, None), as_vector("q1", q1, len(q0)))
    v = as_limit_vector("velocity", velocity, "rad/s or m/s")
    a = as_limit_vector("acceleration", acceleration, "rad/s^2 or m/s^2")
    dq = np.abs(line.q1 - line.q0)
    moving = dq > 0
    if not moving.any():
        raise ParameterError("q1", line.q1.tolist(), "must differ from q0: there is nothing to move")
    V = float(np.min(v[moving] / dq[moving]))
    A = float(np.min(a[moving] / dq[moving]))
    return line, V, A


def quintic_min_duration(
    q0: ArrayLike, q1: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> float:
    """The shortest duration of :func:`quintic` within the limits.

    The peaks 1.875 |dq| / T and (10 / sqrt(3)) |dq| / T^2 reach a limit:
    T = max_i max(1.875 |dq_i| / v_i, sqrt(10 / sqrt(3) |dq_i| / a_i)).
    """
    line = JointLine(as_vector("q0", q0, None), as_vector("q1", q1, len(q0)))
    v = as_limit_vector("velocity", velocity, "rad/s or m/s")
    a = as_limit_vector("acceleration", acceleration, "rad/s^2 or m/s^2")
    dq = np.abs(line.q1 - line.q0)
    return float(max(np.max(_QUINTIC_PEAK_SD * dq / v), np.max(np.sqrt(_QUINTIC_PEAK_SDD * dq / a))))


def line_optimal_duration(
    q0: ArrayLike, q1: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike
) -> float:
    """T*: the shortest duration of the synchronised straight joint move under per-joint limits.

    With s in [0, 1]: V = min_i vmax_i / |dq_i|, A = min_i amax_i / |dq_i|;
    T* = 1/V + V/A if V^2 / A < 1 (the velocity limit is reached), else 2 sqrt(1 / A).
    """
    _, V, A = _line_rates(q0, q1, velocity, acceleration)
    return 1.0 / V + V / A if V * V / A < 1.0 else 2.0 * math.sqrt(1.0 / A)


def trapezoidal(
    q0: ArrayLike,
    q1: ArrayLike,
    velocity: ArrayLike,
    acceleration: ArrayLike,
    duration: float | None = None,
) -> Trajectory:
    """Synchronised point-to-point move: all joints start and stop together, trapezoidal velocity.

    Without ``duration`` it is the time-optimal one (:func:`line_optimal_duration`): the binding joint
    reaches its velocity and/or acceleration limit and no joint exceeds any. With ``duration`` >= T*,
    the same acceleration and a lower coast velocity.

    Args:
        q0: start [rad, m].
        q1: end [rad, m].
        velocity: per-joint velocity limits (> 0).
        acceleration: per-joint acceleration limits (> 0).
        duration: [s], optional.

    Raises:
        ParameterError: bad limits, or q1 == q0.
        InfeasibleError: ``duration`` shorter than T*.
    """
    line, V, A = _line_rates(q0, q1, velocity, acceleration)
    if duration is None:
        law = TrapezoidLaw(V, A)
    else:
        T = as_positive("duration", duration, "s")
        T_opt = line_optimal_duration(q0, q1, velocity, acceleration)
        if T < T_opt * (1 - 1e-12):
            raise InfeasibleError(f"duration {T:.9g} s is shorter than the fastest synchronised move {T_opt:.9g} s")
        law = TrapezoidLaw(V, A) if T <= T_opt * (1 + 1e-12) else TrapezoidLaw.for_duration(A, T)
    return Trajectory((Motion(line, law),))


def timed(path: GeometricPath | CartesianPath, duration: float) -> Trajectory:
    """Follow a path in ``duration`` with the quintic time law (rest to rest, smooth).

    A Cartesian path with via points stops at each: its segments share ``duration`` in proportion to
    their joint-space lengths weighted by 1 / vmax (so all peak at comparable speeds).
    """
    T = as_positive("duration", duration, "s")
    if isinstance(path, GeometricPath):
        return Trajectory((Motion(path, QuinticLaw(T)),))
    if not isinstance(path, CartesianPath):
        raise InvalidInputError(f"cannot time a {type(path).__name__}: give a path")
    v = np.array(path.robot.limits.velocity, dtype=float)
    w = np.where(np.isfinite(v) & (v > 0), 1.0 / v, 1.0)
    lengths = np.array([np.sum(np.max(np.abs(np.diff(seg.q_ref, axis=0)) * w, axis=1)) for seg in path.segments])
    lengths = np.maximum(lengths, 1e-12 * lengths.max(initial=1.0) + 1e-300)
    shares = T * lengths / lengths.sum()
    return Trajectory(tuple(Motion(seg, QuinticLaw(float(Tk))) for seg, Tk in zip(path.segments, shares)))

