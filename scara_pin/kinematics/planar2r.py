"""The planar two-link arm (2R): the one place the law of cosines and the choice of joint turns are written.

Every closed form of the package reduces to this arm: the SCARA in plan view (links l1, l2 from the
shoulder axis to the wrist axis) and the palletizer in its arm plane (big arm a2, small arm a3). With the
wrist point W = (wx, wy) relative to the shoulder, the arm is

    W = l1 e(theta1) + l2 e(theta1 + gamma),     e(a) = (cos a, sin a),

theta1 the heading of link 1 and gamma the elbow angle (from link 1 to link 2, counterclockwise). For
r = |W|, the half-angle form of the law of cosines stays accurate at the stretched (gamma = 0) and folded
(gamma = pi) boundaries, where the textbook acos loses half the digits:

    tan(|gamma| / 2) = sqrt((l1 + l2 - r)(l1 + l2 + r)) / sqrt((r - l1 + l2)(r + l1 - l2)),
    theta1 = atan2(wy, wx) -+ atan2(l2 sin|gamma|, l1 + l2 cos|gamma|)      (elbow +gamma / -gamma).

Tolerances (one set for every caller):

- ``REACH_TOL``: a wrist this close outside the reach circles (|l1 - l2| <= r <= l1 + l2) is solved on them;
- ``SNAP_TOL``: a wrist radius within ``SNAP_TOL (l1 + l2)`` of the stretched or folded circle, a few
  rounding errors, IS on it: the elbow angle is exactly 0 or pi, one solution instead of two twins;
- ``LIMIT_TOL``: a joint value this close outside a limit is clamped onto it;
- ``SINGULAR``: an elbow angle this close to 0 or pi makes the two branches one solution.

Near the boundary circles the elbow angle is ill-conditioned: a radius known to a few ulps fixes gamma only
to about ``sqrt(4 SNAP_TOL) (l1 + l2) / sqrt(l1 l2)`` (1.7e-7 rad for l1 = l2). :meth:`Planar2R.wobble`
gives that bound for a given gamma; callers use it to land a joint exactly on its limit when rounding
alone puts it outside (:meth:`Planar2R.with_link1`, :meth:`with_elbow`, :meth:`with_link2` re-solve the
arm with one angle fixed).

Joint turns. A revolute joint value v is the same joint position as v + 2 pi k. Inside limits [lo, hi]
the turns that fit are k in [k_min, k_max] = [ceil((lo - v) / 2 pi), floor((hi - v) / 2 pi)] (limits
widened by ``LIMIT_TOL``). The turn nearest a reference is chosen PER JOINT in O(1), whatever the range:
k = clip(round((ref - v) / 2 pi), k_min, k_max). A continuous joint (no limits) takes the unclipped k, so
distances to the reference are wrapped.

Scalar functions use :mod:`math` (the per-call paths); ``*_array`` functions are the same formulas for numpy
arrays (the batch paths), with the same order of operations.
"""

from __future__ import annotations

import math
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
    "nearest_turn",
    "nearest_turn_array",
    "turn_edge",
    "turn_range",
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

    def __post_init__(self) -> None:
        if not (math.isfinite(self.l1) and math.isfinite(self.l2) and self.l1 > 0.0 and self.l2 > 0.0):
            raise ValueError(f"link lengths must be finite and > 0 (got {self.l1!r}, {self.l2!r})")
        l12 = self.l1 + self.l2
        object.__setattr__(self, "l12", l12)
        object.__setattr__(self, "d12", abs(self.l1 - self.l2))
        object.__setattr__(self, "_snap", SNAP_TOL * l12)
        # the spread of gamma^2 that a radius within the snap tolerance leaves (see wobble)
        object.__setattr__(self, "_c", 4.0 * SNAP_TOL * l12 * l12 / (self.l1 * self.l2))

    # ------------------------------------------------------------------------------------------ scalar
    def reach(self, r: float) -> int:
        """:class:`Reach` code of a wrist radius ``r`` [m] (within ``REACH_TOL`` counts as inside)."""
        if r > self.l12 + REACH_TOL:
            return Reach.OUT
        if r < self.d12 - REACH_TOL:
            return Reach.IN
        return Reach.OK

    def elbow(self, r: float) -> float:
        """|gamma| in [0, pi] for a wrist radius ``r`` inside the reach (half-angle law of cosines, snapped)."""
        l12, d12, snap = self.l12, self.d12, self._snap
        outer = l12 - r
        if snap > outer:
            outer = 0.0
        inner = r - d12
        if snap > inner:
            inner = 0.0
        return 2.0 * _atan2(_sqrt(outer * (l12 + r)), _sqrt(inner * (r + d12)))

    def lean(self, gamma: float) -> float:
        """atan2(l2 sin gamma, l1 + l2 cos gamma): the angle from link 1 to the wrist point [rad]."""
        return _atan2(self.l2 * _sin(gamma), self.l1 + self.l2 * _cos(gamma))

    def solve(self, wx: float, wy: float) -> tuple[int, float, float, float]:
        """(reach code, r, |gamma|, heading) of a wrist point; theta1 = heading -+ lean(|gamma|).

        Outside the reach (code not OK) gamma and heading are NaN.
        """
        r = _sqrt(wx * wx + wy * wy)
        code = self.reach(r)
        if code:
            return code, r, math.nan, math.nan
        return code, r, self.elbow(r), _atan2(wy, wx)

    def radius(self, gamma: float) -> float:
        """The wrist radius at elbow angle ``gamma``: sqrt(l1^2 + l2^2 + 2 l1 l2 cos gamma) [m]."""
        l1, l2 = self.l1, self.l2
        return _sqrt(max(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * _cos(gamma), 0.0))

    def forward(self, theta1: float, gamma: float) -> tuple[float, float]:
        """The wrist point (x, y) [m] at heading ``theta1`` and elbow ``gamma`` [rad]."""
        s = theta1 + gamma
        return self.l1 * _cos(theta1) + self.l2 * _cos(s), self.l1 * _sin(theta1) + self.l2 * _sin(s)

    def singular(self, gamma: float) -> bool:
        """Whether |gamma| is stretched or folded (the two branches coincide)."""
        g = abs(gamma)
        return g < SINGULAR or math.pi - g < SINGULAR

    def wobble(self, gamma: float) -> float:
        """[rad] how far rounding of the wrist radius may move gamma (and the joint angles) near the boundary.

        gamma^2 is known to about c = 4 SNAP_TOL (l1 + l2)^2 / (l1 l2) near gamma = 0 (and (pi - gamma)^2
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
    def solve_array(self, wx: np.ndarray, wy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`solve` for arrays: (reach codes, r, |gamma|, heading); gamma is NaN outside the reach."""
        r = np.sqrt(wx * wx + wy * wy)
        code = np.where(r > self.l12 + REACH_TOL, Reach.OUT, np.where(r < self.d12 - REACH_TOL, Reach.IN, Reach.OK))
        return code, r, self.elbow_array(r, code), np.arctan2(wy, wx)

    def elbow_array(self, r: np.ndarray, code: np.ndarray | None = None) -> np.ndarray:
        """:meth:`elbow` for an array of radii (NaN where ``code`` is not OK)."""
        l12, d12, snap = self.l12, self.d12, self._snap
        outer = l12 - r
        outer[outer < snap] = 0.0
        inner = r - d12
        inner[inner < snap] = 0.0
        g = 2.0 * np.arctan2(np.sqrt(outer * (l12 + r)), np.sqrt(inner * (r + d12)))
        if code is not None:
            g[code != Reach.OK] = np.nan
        return g

    def lean_array(self, gamma: np.ndarray) -> np.ndarray:
        """:meth:`lean` for arrays."""
        return np.arctan2(self.l2 * np.sin(gamma), self.l1 + self.l2 * np.cos(gamma))

    def wobble_array(self, gamma: np.ndarray) -> np.ndarray:
        """:meth:`wobble` for arrays."""
        g = np.minimum(np.abs(gamma), math.pi - np.abs(gamma))
        return np.sqrt(g * g + self._c) - g


# ---------------------------------------------------------------------------------------------- turns
def turn_range(value: float, lo: float, hi: float) -> tuple[int, int]:
    """(k_min, k_max): the turns k with value + 2 pi k inside [lo, hi] widened by LIMIT_TOL (empty: k_min > k_max).

    Infinite limits are for continuous joints: call :func:`nearest_turn` with ``continuous=True`` instead.
    """
    return (_ceil((lo - LIMIT_TOL - value) * _INV_TWO_PI), _floor((hi + LIMIT_TOL - value) * _INV_TWO_PI))


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


def nearest_turn(
    value: float, lo: float, hi: float, ref: float, continuous: bool = False
) -> tuple[float, int, int] | None:
    """The turn of ``value`` nearest ``ref`` inside [lo, hi], and the turns that fit relative to it.

    Returns:
        (q, k_lo, k_hi): q = value + 2 pi k clamped onto [lo, hi] (it may be LIMIT_TOL outside), and
        q + 2 pi k for k in [k_lo, k_hi] (k_lo <= 0 <= k_hi) are the other turns inside the limits; for a
        continuous joint q is the turn nearest ``ref`` and (k_lo, k_hi) = (0, 0) stands for "unbounded".
        None when no turn fits.
    """
    if continuous:
        return value + TWO_PI * _floor((ref - value) * _INV_TWO_PI + 0.5), 0, 0
    k_min = _ceil((lo - LIMIT_TOL - value) * _INV_TWO_PI)
    k_max = _floor((hi + LIMIT_TOL - value) * _INV_TWO_PI)
    if k_min > k_max:
        return None
    k = _floor((ref - value) * _INV_TWO_PI + 0.5)
    k = k_min if k < k_min else (k_max if k > k_max else k)
    q = value + TWO_PI * k
    q = lo if q < lo else (hi if q > hi else q)
    return q, k_min - k, k_max - k


def fits_array(value: np.ndarray, lo: float, hi: float, tol: float = LIMIT_TOL) -> np.ndarray:
    """Whether some turn value + 2 pi k lies in [lo - tol, hi + tol], elementwise (False for NaN)."""
    return value + TWO_PI * np.ceil((lo - tol - value) * _INV_TWO_PI) <= hi + tol


def nearest_turn_array(
    value: np.ndarray, lo: float, hi: float, ref: np.ndarray | float, continuous: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_turn` for arrays: (q, ok), q clamped onto the limits where ``ok``."""
    if continuous:
        return value + TWO_PI * np.floor((ref - value) * _INV_TWO_PI + 0.5), np.ones(value.shape, dtype=bool)
    k_min = np.ceil((lo - LIMIT_TOL - value) * _INV_TWO_PI)
    k_max = np.floor((hi + LIMIT_TOL - value) * _INV_TWO_PI)
    k = np.floor((ref - value) * _INV_TWO_PI + 0.5)
    np.maximum(k, k_min, out=k)
    np.minimum(k, k_max, out=k)
    q = value + TWO_PI * k
    np.clip(q, lo, hi, out=q)
    return q, k_min <= k_max
