"""The planar two-link arm (2R): the one place the law of cosines and the choice of joint turns are written.

Every closed form of the package reduces to this arm: the SCARA in plan view (links l1, l2 from the
shoulder axis to the wrist axis) and the palletizer in its arm plane (big arm a2, small arm a3). With the
wrist point W = (wx, wy) relative to the shoulder, the arm is

    W = l1 e(theta1) + l2 e(theta1 + gamma),     e(a) = (cos a, sin a),

theta1 the heading of link 1 and gamma the elbow angle (from link 1 to link 2, counterclockwise). For
r = |W|, the half-angle form of the law of cosines stays accurate at the stretched (gamma = 0) and folded
(gamma = pi) boundaries, where the textbook acos loses half the digits:

    tan(|gamma| / 2) = sqrt(o) / sqrt(i),    o = (l1 + l2 - r)(l1 + l2 + r),    i = (r - l1 + l2)(r + l1 - l2),
    theta1 = atan2(wy, wx) -+ lean,    lean = atan2(l2 sin|gamma|, l1 + l2 cos|gamma|)    (elbow +/-gamma),

with the lean read from the same square roots, without a sine or cosine (both sides times o + i > 0):
lean = atan2(2 l2 sqrt(o) sqrt(i), (l1 + l2) i + (l1 - l2) o).

Tolerances (one set for every caller):

- ``REACH_TOL``: a wrist this close outside the reach circles (|l1 - l2| <= r <= l1 + l2) is solved on them;
- ``SNAP_TOL``: a wrist radius within ``SNAP_TOL (l1 + l2)`` of the stretched or folded circle, a few
  rounding errors, IS on it: the elbow angle is exactly 0 or pi, one solution instead of two twins;
- ``LIMIT_TOL``: a joint value this close outside a limit is clamped onto it;
- ``SINGULAR``: an elbow angle this close to 0 or pi makes the two branches one solution.

Near the boundary circles the elbow angle is ill-conditioned: a radius known to a few ulps fixes gamma only
to about ``sqrt(64 SNAP_TOL) (l1 + l2) / sqrt(l1 l2)`` (7e-7 rad for l1 = l2). :meth:`Planar2R.wobble`
gives that bound for a given gamma; callers use it to land a joint exactly on its limit when rounding
alone puts it outside (:meth:`Planar2R.with_link1`, :meth:`Planar2R.with_elbow`, :meth:`Planar2R.with_link2`
re-solve the arm with one angle fixed).

Joint turns. A revolute joint value v is the same joint position as v + 2 pi k. Inside limits [lo, hi]
the turns that fit are k in [k_min, k_max] = [ceil((lo - v) / 2 pi), floor((hi - v) / 2 pi)] (limits
widened by ``LIMIT_TOL``). The turn nearest a reference is chosen PER JOINT in O(1), whatever the range:
k = clip(floor((ref + pi - v) / 2 pi), k_min, k_max) (round((ref - v) / 2 pi), ties upwards). A continuous
joint (no limits) takes the unclipped k, so distances to the reference are wrapped.

Scalar functions use :mod:`math` (the per-call paths); ``*_array`` functions are the same formulas for numpy
arrays (the batch paths), with the same order of operations.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = [
    "LIMIT_TOL",
    "REACH_TOL",
    "SINGULAR",
    "SNAP_TOL",
    "Planar2R",
    "Reach",
    "fits_array",
    "free_angle",
    "nearest_turn",
    "nearest_turn_array",
    "turn_edge",
    "turner",
    "wrap",
]

REACH_TOL = 1e-10
"""[m] a wrist this close outside a reach circle is solved on it (absorbs rounding)."""
LIMIT_TOL = 1e-10
"""[rad or m] a joint value this close outside a limit is clamped onto it."""
SNAP_TOL = 8 * 2.0**-52
"""[-] a wrist radius within SNAP_TOL (l1 + l2) of the stretched or folded circle is on it."""
SINGULAR = 1e-12
"""[rad] an elbow angle this close to 0 or pi is stretched/folded: the two branches are one solution."""
FREE_R = 1e-12
"""[m] a wrist this close to the shoulder (possible when l1 = l2) leaves the shoulder angle free."""

TWO_PI = 2.0 * math.pi
_PI = math.pi
_INV_TWO_PI = 1.0 / TWO_PI
_atan2, _sin, _cos, _sqrt, _floor, _ceil = math.atan2, math.sin, math.cos, math.sqrt, math.floor, math.ceil


class Reach:
    """Where a wrist radius lies relative to the reach circles (plain int codes, shared with the batch)."""

    OK = 0
    OUT = 1  # beyond l1 + l2
    IN = 2  # inside |l1 - l2|


def wrap(a: float) -> float:
    """``a`` wrapped to [-pi, pi)."""
    return (a + math.pi) % TWO_PI - math.pi


@dataclass(frozen=True)
class Planar2R:
    """A planar two-link arm with link lengths ``l1`` and ``l2`` [m] (both > 0).

    Attributes:
        l1, l2: link lengths [m].
        l12, d12: l1 + l2 and |l1 - l2| [m].
    """

    l1: float
    l2: float
    l12: float = field(init=False)
    d12: float = field(init=False)
    _snap: float = field(init=False, repr=False)
    _c: float = field(init=False, repr=False)
    _2l2: float = field(init=False, repr=False)
    _dl: float = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.l1) and math.isfinite(self.l2) and self.l1 > 0.0 and self.l2 > 0.0):
            raise ValueError(f"link lengths must be finite and > 0 (got {self.l1!r}, {self.l2!r})")
        l12 = self.l1 + self.l2
        object.__setattr__(self, "l12", l12)
        object.__setattr__(self, "d12", abs(self.l1 - self.l2))
        object.__setattr__(self, "_snap", SNAP_TOL * l12)
        object.__setattr__(self, "_2l2", 2.0 * self.l2)
        object.__setattr__(self, "_dl", self.l1 - self.l2)
        # the spread of gamma^2 that a rounded radius leaves (see wobble): targets computed from coordinates
        # of a few metres carry several ulps of them, hence the generous factor (a rescue is checked anyway)
        object.__setattr__(self, "_c", 64.0 * SNAP_TOL * l12 * l12 / (self.l1 * self.l2))

    # ------------------------------------------------------------------------------------------ scalar
    def lean(self, gamma: float) -> float:
        """atan2(l2 sin gamma, l1 + l2 cos gamma): the angle from link 1 to the wrist point [rad]."""
        return _atan2(self.l2 * _sin(gamma), self.l1 + self.l2 * _cos(gamma))

    def solve(self, wx: float, wy: float) -> tuple[int, float, float, float, float]:
        """(reach code, r, |gamma|, heading, lean) of a wrist point: theta1 = heading -+ lean for +/-|gamma|.

        Outside the reach (code not OK) gamma, heading and lean are NaN.
        """
        r = _sqrt(wx * wx + wy * wy)
        l12, d12, snap = self.l12, self.d12, self._snap
        if r > l12 + REACH_TOL:
            return Reach.OUT, r, math.nan, math.nan, math.nan
        if r < d12 - REACH_TOL:
            return Reach.IN, r, math.nan, math.nan, math.nan
        o = l12 - r
        o = 0.0 if o < snap else o * (l12 + r)
        i = r - d12
        i = 0.0 if i < snap else i * (r + d12)
        so, si = _sqrt(o), _sqrt(i)
        lean = _atan2(so * si * self._2l2, l12 * i + self._dl * o)
        return Reach.OK, r, 2.0 * _atan2(so, si), _atan2(wy, wx), lean

    def radius(self, gamma: float) -> float:
        """The wrist radius at elbow angle ``gamma``: sqrt(l1^2 + l2^2 + 2 l1 l2 cos gamma) [m]."""
        l1, l2 = self.l1, self.l2
        return _sqrt(max(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * _cos(gamma), 0.0))

    def singular(self, gamma: float) -> bool:
        """Whether |gamma| is stretched or folded (the two branches coincide)."""
        g = abs(gamma)
        return g < SINGULAR or math.pi - g < SINGULAR

    def wobble(self, gamma: float) -> float:
        """[rad] how far rounding of the wrist radius may move gamma (and the joint angles) near the boundary.

        gamma^2 is known to about c = 64 SNAP_TOL (l1 + l2)^2 / (l1 l2) near gamma = 0 (and (pi - gamma)^2
        near pi), so gamma to sqrt(g^2 + c) - g with g the distance to the boundary; far from it this is
        below 1e-12 rad.
        """
        g = min(abs(gamma), math.pi - abs(gamma))
        return _sqrt(g * g + self._c) - g

    def with_link1(self, wx: float, wy: float, theta1: float) -> tuple[float, float]:
        """(gamma, residual [m]) with link 1's heading fixed at ``theta1``: the elbow that best reaches W."""
        ex = wx - self.l1 * _cos(theta1)
        ey = wy - self.l1 * _sin(theta1)
        return wrap(_atan2(ey, ex) - theta1), abs(_sqrt(ex * ex + ey * ey) - self.l2)

    def with_elbow(self, wx: float, wy: float, gamma: float) -> tuple[float, float]:
        """(theta1, residual [m]) with the elbow fixed at ``gamma``."""
        bx = self.l1 + self.l2 * _cos(gamma)
        by = self.l2 * _sin(gamma)
        return _atan2(wy, wx) - _atan2(by, bx), abs(_sqrt(wx * wx + wy * wy) - _sqrt(bx * bx + by * by))

    def with_link2(self, wx: float, wy: float, sigma: float) -> tuple[float, float]:
        """(theta1, residual [m]) with link 2's heading fixed at ``sigma`` = theta1 + gamma."""
        ex = wx - self.l2 * _cos(sigma)
        ey = wy - self.l2 * _sin(sigma)
        return _atan2(ey, ex), abs(_sqrt(ex * ex + ey * ey) - self.l1)

    # ------------------------------------------------------------------------------------------ arrays
    def solve_array(
        self, wx: np.ndarray, wy: np.ndarray, out: Sequence[np.ndarray] | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve` for arrays: (r, |gamma|, heading, lean, scratch); the same formulas, in place.

        No reach codes: compare ``r`` with ``l12 + REACH_TOL`` and ``d12 - REACH_TOL`` (outside, the angles
        are those of the nearest boundary circle). ``out``: five float arrays of the rows' length to write
        into (nothing is allocated then).
        """
        r, g, heading, lean, t = (out if out is not None else [np.empty(np.shape(wx)) for _ in range(5)])
        l12, d12, snap = self.l12, self.d12, self._snap
        np.multiply(wx, wx, out=r)
        np.multiply(wy, wy, out=t)
        np.add(r, t, out=r)
        np.sqrt(r, out=r)
        o, i = heading, lean  # scratch until the end
        np.subtract(l12, r, out=o)
        mask = np.less(o, snap)
        np.add(r, l12, out=t)
        np.multiply(o, t, out=o)
        if mask.any():
            np.copyto(o, 0.0, where=mask)
        if d12 != 0.0:
            np.subtract(r, d12, out=i)
            np.less(i, snap, out=mask)
            np.add(r, d12, out=t)
            np.multiply(i, t, out=i)
        else:  # r - 0 and r + 0 are r
            np.less(r, snap, out=mask)
            np.multiply(r, r, out=i)
        snapped = mask.any()
        if snapped:
            np.copyto(i, 0.0, where=mask)
        np.multiply(i, l12, out=t)  # t: the lean's cosine side (l1 + l2) i + (l1 - l2) o
        if self._dl != 0.0:
            np.add(t, np.multiply(o, self._dl, out=g), out=t)
        np.sqrt(o, out=o)
        # sqrt(i) with i = r r (l1 = l2, no row snapped) is r: sqrt(x x) = |x| exactly in binary floating point
        # (S. Boldo, "Stupid is as stupid does: taking the square root of the square of a floating-point
        # number", 2015)
        si = r if d12 == 0.0 and not snapped else np.sqrt(i, out=i)
        np.arctan2(o, si, out=g)
        np.multiply(o, si, out=o)
        np.multiply(o, self._2l2, out=o)
        np.arctan2(o, t, out=lean)
        np.add(g, g, out=g)
        np.arctan2(wy, wx, out=heading)
        return r, g, heading, lean, t

    def wobble_array(self, gamma: np.ndarray) -> np.ndarray:
        """:meth:`wobble` for arrays."""
        g = np.minimum(np.abs(gamma), math.pi - np.abs(gamma))
        return np.sqrt(g * g + self._c) - g


# ---------------------------------------------------------------------------------------------- turns
def turn_edge(value: float, lo: float, hi: float, slack: float) -> float | None:
    """The limit (``lo`` or ``hi``) that a turn of ``value`` misses by at most ``slack``, or None.

    For a value with no turn inside [lo, hi]: the turn just below ``lo`` or just above ``hi`` within
    ``slack`` (rounding put it outside; the caller then puts the joint ON that limit).
    """
    if value - value != 0.0:  # NaN or infinite
        return None
    if value + TWO_PI * _ceil((lo - slack - value) * _INV_TWO_PI) <= lo:
        return lo
    if value + TWO_PI * _floor((hi + slack - value) * _INV_TWO_PI) >= hi:
        return hi
    return None


def turner(lo: float, hi: float, continuous: bool = False) -> Callable[..., tuple[float, int, int] | None]:
    """:func:`nearest_turn` with a joint's limits bound once: ``turn(value, ref, ranges=True)``.

    With ``ranges=False`` (the per-call nearest path) the range of the other turns is not computed when the
    nearest turn fits the limits: (q, 0, 0) then.
    """
    lo_t, hi_t = lo - LIMIT_TOL, hi + LIMIT_TOL

    def turn(value: float, ref: float, ranges: bool = True) -> tuple[float, int, int] | None:
        k = _floor((ref + _PI - value) * _INV_TWO_PI)
        q = value + TWO_PI * k
        if continuous:
            return q, 0, 0
        if not ranges and lo_t <= q <= hi_t:
            return (lo if q < lo else (hi if q > hi else q)), 0, 0
        k_min = _ceil((lo_t - value) * _INV_TWO_PI)
        k_max = _floor((hi_t - value) * _INV_TWO_PI)
        if k_min > k_max:
            return None
        if k < k_min or k > k_max:
            k = k_min if k < k_min else k_max
            q = value + TWO_PI * k
        return (lo if q < lo else (hi if q > hi else q)), k_min - k, k_max - k

    return turn


def nearest_turn(
    value: float, lo: float, hi: float, ref: float, continuous: bool = False
) -> tuple[float, int, int] | None:
    """The turn of ``value`` nearest ``ref`` inside [lo, hi], and the turns that fit relative to it.

    k = floor((ref + pi - value) / 2 pi) clamped into [k_min, k_max] (see the module docstring).

    Returns:
        (q, k_lo, k_hi): q = value + 2 pi k clamped onto [lo, hi] (it may be LIMIT_TOL outside), and
        q + 2 pi k for k in [k_lo, k_hi] (k_lo <= 0 <= k_hi) are the other turns inside the limits; for a
        continuous joint q is the turn nearest ``ref`` and (k_lo, k_hi) = (0, 0) stands for "unbounded".
        None when no turn fits.
    """
    return turner(lo, hi, continuous)(value, ref)


def free_angle(
    lo_a: float, hi_a: float, lo_b: float, hi_b: float, sign: float, offset: float, ref: float,
    continuous_b: bool = False,
) -> float | None:  # fmt: skip
    """A joint angle the geometry leaves free (the wrist on the shoulder axis, l1 = l2), nearest ``ref``.

    The a in [lo_a, hi_a] nearest ``ref`` such that b = sign a + offset (sign +/-1) has a turn inside
    [lo_b, hi_b]; None if none. b + 2 pi k in [lo_b, hi_b] puts a in the interval sign ([lo_b, hi_b] -
    offset) shifted by 2 pi k; the two shifts nearest the reference are the candidates.
    """
    want = min(max(ref, lo_a), hi_a)
    if continuous_b or hi_b - lo_b >= TWO_PI:  # every a has a turn of b inside its limits
        return want
    lo_i, hi_i = sorted((sign * (lo_b - offset), sign * (hi_b - offset)))
    k = _floor((want - hi_i) * _INV_TWO_PI)
    best = None
    for kk in (k, k + 1):
        a, b = max(lo_i + kk * TWO_PI, lo_a), min(hi_i + kk * TWO_PI, hi_a)
        if a <= b:
            v = min(max(want, a), b)
            if best is None or abs(v - want) < abs(best - want):
                best = v
    return best


def fits_array(value: np.ndarray, lo: float, hi: float, tol: float = LIMIT_TOL) -> np.ndarray:
    """Whether some turn value + 2 pi k lies in [lo - tol, hi + tol], elementwise (False for NaN)."""
    return value + TWO_PI * np.ceil((lo - tol - value) * _INV_TWO_PI) <= hi + tol


def nearest_turn_array(
    value: np.ndarray, lo: float, hi: float, ref: np.ndarray | float, continuous: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_turn` for arrays: (q, ok), q clamped onto the limits where ``ok``."""
    if continuous:
        return value + TWO_PI * np.floor((ref + _PI - value) * _INV_TWO_PI), np.ones(value.shape, dtype=bool)
    k_min = np.ceil((lo - LIMIT_TOL - value) * _INV_TWO_PI)
    k_max = np.floor((hi + LIMIT_TOL - value) * _INV_TWO_PI)
    k = np.floor((ref + _PI - value) * _INV_TWO_PI)
    np.maximum(k, k_min, out=k)
    np.minimum(k, k_max, out=k)
    q = value + TWO_PI * k
    np.clip(q, lo, hi, out=q)
    return q, k_min <= k_max
