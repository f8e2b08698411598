"""The arc engine: the exact region a planar two-link arm reaches over a box of joint angles.

Both workspaces of the package are such regions. The arm (:class:`~scara_pin.kinematics.planar2r.Planar2R`)
puts its wrist point at

    W = A + l1 e(theta1) + l2 e(theta2),     e(a) = (cos a, sin a),     gamma = theta2 - theta1,

and the joint limits make a box: theta1 in [lo1, hi1], and the second joint in [lo2, hi2] either RELATIVE
(gamma, the elbow angle: the SCARA in plan view) or ABSOLUTE (theta2, the small arm driven through a
parallelogram: the palletizer in its arm plane). A range of 2 pi or more, or an infinite limit, is a full
turn (:class:`JointRange`). The region is the image of the box: compact and connected, so one outer loop
and possibly holes. Its boundary lies on the images of the box's edges and of the singular set
(det dW/d(theta1, theta2) = l1 l2 sin gamma = 0), all circles of three families:

- ``LINK1`` (theta1 = t fixed): centre A + l1 e(t), radius l2, the point at angle theta2;
- ``LINK2`` (theta2 = s fixed): centre A + l2 e(s), radius l1, the point at angle theta1;
- ``ELBOW`` (gamma = g fixed): centre A, radius r(g) = |l1 + l2 e(g)|, the point at angle theta1 + lean(g),
  lean(g) = atan2(l2 sin g, l1 + l2 cos g) (:meth:`Planar2R.lean`).

The candidate arcs (:func:`candidates`) are: theta1 at a limit (LINK1 over the second joint's range); the
second joint at a limit (relative box: ELBOW at g = lo2 or hi2 over theta1's range; absolute box: LINK2
at s = lo2 or hi2 over theta1's range); the stretched circle (ELBOW g = 0) and the folded one (ELBOW
g = pi) over the theta1 where the box allows that elbow angle.

Splitting. Each candidate circle is cut at its crossings with every other one, taken from the joint
parameters where they are known (the configurations that lie on both circles):

- LINK1 t and ELBOW g: (theta1, gamma) = (t, +/-g): angle t +/- g on the LINK1 circle, t +/- lean(g) on
  the ELBOW circle;
- LINK2 s and ELBOW g: (theta1, gamma) = (s -/+ g, +/-g): angle s -/+ g on the LINK2 circle,
  s -/+ (g - lean(g)) on the ELBOW circle;
- LINK1 t and LINK2 s: (theta1, theta2) = (t, s): angle s on the LINK1 circle, t on the LINK2 circle; the
  second crossing is its mirror image in the line of the centres;
- two ELBOW circles are concentric (no crossing); two LINK1 (or two LINK2) circles cross where the general
  circle-circle formula says, circles within ``TANGENT`` (r1 + r2) of tangency touching.

g = 0 and pi are tangencies (a box edge touching the stretched or folded circle), exact here where the
general formula would lose half the digits. Candidates on the same circle (within 1e-12 (l1 + l2)) are one
circle with several labels.

Keeping. A piece is boundary when exactly one of two side points of its midpoint (offset radially by
``SIDE_OFFSET`` (l1 + l2), or a quarter of the distance to the nearest other candidate circle if that is
less) is in the exact set (:meth:`ArmBox.contains` with tol = 0, the closed-form IK's test). It takes the
label of a candidate covering it (the caller's rank decides between coincident candidates; a piece keeps
its neighbour's label while that candidate still covers it), neighbours with the same label and side are
merged (cyclically), and the arcs are chained into loops oriented with the region on the left (outer loop
counterclockwise, holes clockwise). The area is exact by Green's theorem over the arcs: for an arc of
centre c, radius R from angle a by a signed sweep s (b = a + s), the integral of x dy - y dx is
R^2 s + R [c_x (sin b - sin a) - c_y (cos b - cos a)] (:func:`green`).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

import numpy as np

from ..kinematics.planar2r import FREE_R, LIMIT_TOL, Planar2R, fits_array

__all__ = [
    "SIDE_OFFSET",
    "TANGENT",
    "ArmBox",
    "BoundaryArc",
    "BoxRegion",
    "Candidate",
    "Family",
    "JointRange",
    "Role",
    "box_region",
    "candidates",
    "chain",
    "circle_crossings",
    "green",
]

SIDE_OFFSET = 1e-7
"""[-] radial offset (times l1 + l2) of the two side points that decide whether an arc piece is boundary."""
TANGENT = 1e-12
"""[-] (times r1 + r2) two circles this close to tangency touch (rounding must not hide a tangency)."""
_SAME_CIRCLE = 1e-12
"""[-] (times l1 + l2) two candidate circles closer than this are the same circle."""
_CHAIN_TOL = 1e-7
"""[-] (times l1 + l2) arc ends closer than this are joined into a loop."""
_ANGLE_TOL = 1e-13
"""[rad] cut angles closer than this on one circle are one cut."""
_TINY = 1e-12
"""[-] (times l1 + l2) a circle of smaller radius is a point (equal links folded): no arc."""

_TWO_PI = 2.0 * math.pi

L = TypeVar("L")


@dataclass(frozen=True)
class JointRange:
    """An angle range [lo, hi] [rad]; ``full`` when it spans a turn or more (or a limit is infinite)."""

    lo: float
    hi: float
    full: bool

    @classmethod
    def of(cls, lo: float, hi: float) -> JointRange:
        """The range between two angles given in either order."""
        lo, hi = min(lo, hi), max(lo, hi)
        return cls(lo, hi, not (math.isfinite(lo) and math.isfinite(hi) and hi - lo < _TWO_PI))

    @property
    def start(self) -> float:
        """Where an arc swept by this joint starts: ``lo``, or 0 for a full turn."""
        return 0.0 if self.full else self.lo

    @property
    def sweep(self) -> float:
        """The range's extent hi - lo, or 2 pi for a full turn."""
        return _TWO_PI if self.full else self.hi - self.lo

    def fits(self, value: np.ndarray, tol: float) -> np.ndarray:
        """Whether some turn value + 2 pi k lies in [lo - tol, hi + tol], elementwise."""
        return np.ones(np.shape(value), dtype=bool) if self.full else fits_array(value, self.lo, self.hi, tol)

    def contains_angle(self, angle: float) -> bool:
        """Whether some turn of ``angle`` lies in [lo, hi] (exactly, no tolerance)."""
        return self.full or angle + math.ceil((self.lo - angle) / _TWO_PI) * _TWO_PI <= self.hi


@dataclass(frozen=True)
class ArmBox:
    """A planar two-link arm at ``origin`` and its box of joint angles (module docstring).

    Attributes:
        origin: A, the shoulder (x, y) [m].
        arm: the links (l1, l2).
        first: theta1's range [rad] (angle of link 1 from the x axis).
        second: the second joint's range [rad]: gamma (``relative``) or theta2.
        relative: whether ``second`` is the elbow angle gamma = theta2 - theta1 (else theta2 itself).
    """

    origin: tuple[float, float]
    arm: Planar2R
    first: JointRange
    second: JointRange
    relative: bool

    def contains(self, x: np.ndarray, y: np.ndarray, tol: float = LIMIT_TOL) -> np.ndarray:
        """Whether wrist points (x, y) are reached inside the box: the closed-form IK's test, elementwise.

        r = |W - A| gives |gamma| by the law of cosines (:meth:`Planar2R.solve_array`); each elbow sign
        gives gamma and theta1 (theta2 = theta1 + gamma), and the point is inside when each joint has a
        2 pi-equivalent within its range. A wrist on the shoulder (possible when l1 = l2, within
        ``FREE_R``) leaves theta1 free: inside when some theta1 in its range puts the second joint in its.

        Args:
            x: x coordinates [m].
            y: y coordinates [m] (the shape of ``x``).
            tol: [rad] and [m] how far outside a joint range or a reach circle still counts as inside
                (default the IK's 1e-10; 0 for the exact set).
        """
        arm, first, second = self.arm, self.first, self.second
        dx, dy = np.asarray(x, dtype=float) - self.origin[0], np.asarray(y, dtype=float) - self.origin[1]
        r, g0, heading, lean, _ = arm.solve_array(dx, dy)
        free = r <= FREE_R
        inside = np.zeros(np.shape(r), dtype=bool)
        for sign in (1.0, -1.0):
            gamma = sign * g0
            theta1 = heading - sign * lean
            if self.relative:
                ok = second.fits(gamma, tol) & (first.fits(theta1, tol) | free)
            else:
                ok = first.fits(theta1, tol) & second.fits(theta1 + gamma, tol)
                if free.any():  # theta1 free: some theta1 in [lo1, hi1] with theta1 + gamma in [lo2, hi2]
                    ok |= free & self._overlap(gamma, tol)
            inside |= ok
        return inside & (r <= arm.l12 + tol) & (r >= arm.d12 - tol)

    def _overlap(self, gamma: np.ndarray, tol: float) -> np.ndarray:
        """Whether [lo2 - gamma, hi2 - gamma] meets [lo1, hi1] modulo 2 pi (absolute box), elementwise."""
        first, second = self.first, self.second
        if first.full or second.full:
            return np.ones(np.shape(gamma), dtype=bool)
        return fits_array(second.lo - gamma, first.lo - (second.hi - second.lo), first.hi, tol)

    def theta1_where(self, gamma: float) -> list[tuple[float, float]]:
        """The theta1 intervals (start, end) [rad] inside the box at elbow angle ``gamma`` (exactly)."""
        first, second = self.first, self.second
        if self.relative or second.full:
            return [(first.start, first.start + first.sweep)] if second.contains_angle(gamma) else []
        b_lo, b_hi = second.lo - gamma, second.hi - gamma
        if first.full:
            return [(b_lo, b_hi)]
        out = []
        for k in range(math.ceil((first.lo - b_hi) / _TWO_PI), math.floor((first.hi - b_lo) / _TWO_PI) + 1):
            a, b = max(first.lo, b_lo + k * _TWO_PI), min(first.hi, b_hi + k * _TWO_PI)
            if a < b:
                out.append((a, b))
        return out


class Family(enum.Enum):
    """Which circle family a candidate lies on (module docstring)."""

    LINK1 = "link1"
    LINK2 = "link2"
    ELBOW = "elbow"


class Role(enum.Enum):
    """Which part of the box a candidate arc is the image of; the caller names it with its own label."""

    FIRST_LO = "first_lo"  # theta1 at the lower end of its angle range
    FIRST_HI = "first_hi"
    SECOND_LO = "second_lo"  # the second joint at the lower end of its angle range
    SECOND_HI = "second_hi"
    STRETCHED = "stretched"  # gamma = 0
    FOLDED = "folded"  # gamma = pi


@dataclass(frozen=True, kw_only=True)
class Candidate(Generic[L]):
    """An arc that may carry boundary: center + radius e(a) for a from ``start`` by ``sweep`` (<= 2 pi).

    Attributes:
        family, value: its circle: LINK1 at theta1 = value, LINK2 at theta2 = value, ELBOW at
            |gamma| = value in [0, pi].
        label: the caller's name for it; rank: the caller's priority between coincident candidates
            (lowest wins).
    """

    center: tuple[float, float]
    radius: float
    start: float
    sweep: float
    family: Family
    value: float
    label: L
    rank: int


@dataclass(frozen=True)
class BoundaryArc(Generic[L]):
    """A boundary arc: center + radius e(a) for a from ``start`` (in [0, 2 pi)) counterclockwise by ``sweep``.

    Attributes:
        center: (x, y) [m]. radius: [m]. start: [rad] in [0, 2 pi). sweep: [rad] in (0, 2 pi].
        label: the label of the candidate it lies on.
        region_inside: the region lies on the centre's side of the arc.
        param_start: ``start`` as the 2 pi-equivalent at or after the start of its candidate (the joint
            parameter of the arc, for callers that report arcs in joint angles).
    """

    center: tuple[float, float]
    radius: float
    start: float
    sweep: float
    label: L
    region_inside: bool
    param_start: float

    def point(self, angle: float) -> tuple[float, float]:
        """The point of the circle at ``angle`` [rad]."""
        return (self.center[0] + self.radius * math.cos(angle), self.center[1] + self.radius * math.sin(angle))


@dataclass(frozen=True)
class BoxRegion(Generic[L]):
    """The region of an :class:`ArmBox`: its boundary arcs, their loops and its area.

    Attributes:
        arcs: the boundary arcs.
        loops: each closed loop as indices into ``arcs`` in traversal order (region on the left).
        area: [m^2], by Green's theorem over the arcs.
    """

    arcs: tuple[BoundaryArc[L], ...]
    loops: tuple[tuple[int, ...], ...]
    area: float


# ------------------------------------------------------------------------------------------ candidates
def candidates(box: ArmBox, labels: Mapping[Role, tuple[L, int]]) -> list[Candidate[L]]:
    """Every arc that may carry boundary: the box's edges and the stretched/folded circles (module docstring).

    Args:
        box: the arm and its box.
        labels: per :class:`Role`, the caller's (label, rank).
    """
    arm, (ox, oy), first, second = box.arm, box.origin, box.first, box.second
    l1, l2 = arm.l1, arm.l2
    out: list[Candidate[L]] = []
    if not first.full:  # theta1 at a limit, the second joint sweeping: radius l2 about the elbow
        for t, role in ((first.lo, Role.FIRST_LO), (first.hi, Role.FIRST_HI)):
            start = second.start if second.full or not box.relative else t + second.lo
            if second.sweep > 0.0:
                c = (ox + l1 * math.cos(t), oy + l1 * math.sin(t))
                out.append(Candidate(center=c, radius=l2, start=start, sweep=second.sweep, family=Family.LINK1,
                                     value=t, label=labels[role][0], rank=labels[role][1]))  # fmt: skip
    if not second.full and first.sweep > 0.0:  # the second joint at a limit, theta1 sweeping
        for v, role in ((second.lo, Role.SECOND_LO), (second.hi, Role.SECOND_HI)):
            if box.relative:  # radius r(gamma) about the shoulder
                R = arm.radius(v)
                if R <= _TINY * arm.l12:
                    continue
                start = first.start + (0.0 if first.full else arm.lean(v))
                g = abs(math.remainder(v, _TWO_PI))
                out.append(Candidate(center=box.origin, radius=R, start=start, sweep=first.sweep, family=Family.ELBOW,
                                     value=g, label=labels[role][0], rank=labels[role][1]))  # fmt: skip
            else:  # radius l1 about the end of link 2 laid from the shoulder
                c = (ox + l2 * math.cos(v), oy + l2 * math.sin(v))
                out.append(Candidate(center=c, radius=l1, start=first.start, sweep=first.sweep, family=Family.LINK2,
                                     value=v, label=labels[role][0], rank=labels[role][1]))  # fmt: skip
    # the singular circles, at angle theta1 + lean(g): lean = 0 stretched, 0 or pi folded
    for g, R, lean, role in ((0.0, arm.l12, 0.0, Role.STRETCHED),
                             (math.pi, arm.d12, 0.0 if l1 > l2 else math.pi, Role.FOLDED)):  # fmt: skip
        if R <= _TINY * arm.l12:
            continue
        for a, b in box.theta1_where(g):
            if b > a:
                out.append(Candidate(center=box.origin, radius=R, start=a + lean, sweep=b - a, family=Family.ELBOW,
                                     value=g, label=labels[role][0], rank=labels[role][1]))  # fmt: skip
    return out


# ------------------------------------------------------------------------------------------ crossings
def circle_crossings(c1: tuple[float, float], r1: float, c2: tuple[float, float], r2: float) -> list[float]:
    """Angles on circle 1 of its crossings with circle 2, the general formula (a tangency gives one angle twice).

    Circles within ``TANGENT`` (r1 + r2) of tangency touch; concentric circles do not cross.
    """
    dx, dy = c2[0] - c1[0], c2[1] - c1[1]
    d = math.hypot(dx, dy)
    tol = TANGENT * (r1 + r2)
    if d < 1e-15 or d > r1 + r2 + tol or d < abs(r1 - r2) - tol:
        return []
    base = math.atan2(dy, dx)
    h = math.acos(min(1.0, max(-1.0, (d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1))))
    return [base - h, base + h]


def _crossings(arm: Planar2R, a: Candidate[L], b: Candidate[L]) -> list[float]:
    """Angles on a's circle of its crossings with b's, from the joint parameters where known (module docstring)."""
    fa, fb, va, vb = a.family, b.family, a.value, b.value
    if fa is Family.ELBOW and fb is Family.ELBOW:
        return []
    if fa is fb:
        return circle_crossings(a.center, a.radius, b.center, b.radius)
    if fa is Family.LINK1 and fb is Family.ELBOW:
        return [va + vb, va - vb]
    if fa is Family.ELBOW and fb is Family.LINK1:
        psi = arm.lean(va)
        return [vb + psi, vb - psi]
    if fa is Family.LINK2 and fb is Family.ELBOW:
        return [va - vb, va + vb]
    if fa is Family.ELBOW and fb is Family.LINK2:
        d = va - arm.lean(va)
        return [vb - d, vb + d]
    # LINK1 and LINK2: the configuration (theta1, theta2) = (t, s) is on both: angle theta2 on a LINK1
    # circle, theta1 on a LINK2 circle, i.e. b's value; the other crossing is its mirror in the centres' line
    dx, dy = b.center[0] - a.center[0], b.center[1] - a.center[1]
    if math.hypot(dx, dy) < 1e-15:
        return []
    return [vb, 2.0 * math.atan2(dy, dx) - vb]


# ------------------------------------------------------------------------------------------ the region
def box_region(box: ArmBox, labels: Mapping[Role, tuple[L, int]]) -> BoxRegion[L]:
    """The exact region of a box: candidates, split, side-tested, merged, chained, area (module docstring).

    Args:
        box: the arm and its box.
        labels: per :class:`Role`, the caller's (label, rank); the rank decides between coincident
            candidates (lowest wins).
    """
    arcs = _boundary(box, candidates(box, labels))
    loops = chain(arcs, box.arm.l12)
    area = 0.0
    for a in arcs:
        term = green(a.center, a.radius, a.start, a.sweep)
        area += term if a.region_inside else -term
    return BoxRegion(tuple(arcs), loops, area)


def green(center: tuple[float, float], radius: float, start: float, sweep: float) -> float:
    """1/2 the integral of x dy - y dx along center + radius e(a), a from ``start`` by the signed ``sweep``.

    Summed over closed loops with the region on their left, the area of the region [m^2].
    """
    cx, cy, R = center[0], center[1], radius
    end = start + sweep
    return 0.5 * (R * R * sweep + R * (cx * (math.sin(end) - math.sin(start)) - cy * (math.cos(end) - math.cos(start))))


def _boundary(box: ArmBox, cands: list[Candidate[L]]) -> list[BoundaryArc[L]]:
    """Split the candidates at their crossings, keep the boundary pieces, merge them (module docstring)."""
    scale = box.arm.l12
    groups: list[list[Candidate[L]]] = []  # candidates lying on the same circle
    for c in cands:
        for grp in groups:
            g0 = grp[0]
            if (math.hypot(c.center[0] - g0.center[0], c.center[1] - g0.center[1]) < _SAME_CIRCLE * scale
                    and abs(c.radius - g0.radius) < _SAME_CIRCLE * scale):  # fmt: skip
                grp.append(c)
                break
        else:
            groups.append([c])
    # every group's pieces (start, end, candidates covering the midpoint) and their two side points
    pieces: list[list[tuple[float, float, list[Candidate[L]]]]] = []
    side_x: list[float] = []
    side_y: list[float] = []
    delta = SIDE_OFFSET * scale
    for gi, grp in enumerate(groups):
        center, R = grp[0].center, grp[0].radius
        cuts: list[float] = []
        for c in grp:
            if c.sweep < _TWO_PI:
                cuts += [c.start % _TWO_PI, (c.start + c.sweep) % _TWO_PI]
        for gj, other in enumerate(groups):
            if gj != gi:
                cuts += [a % _TWO_PI for a in _crossings(box.arm, grp[0], other[0])]
        cuts.sort()
        uniq: list[float] = []
        for b in cuts:
            if not uniq or b - uniq[-1] > _ANGLE_TOL:
                uniq.append(b)
        if len(uniq) > 1 and uniq[0] + _TWO_PI - uniq[-1] <= _ANGLE_TOL:
            uniq.pop()
        if not uniq:
            spans = [(0.0, _TWO_PI)]
        else:
            spans = [(uniq[i], uniq[i + 1]) for i in range(len(uniq) - 1)] + [(uniq[-1], uniq[0] + _TWO_PI)]
        mine: list[tuple[float, float, list[Candidate[L]]]] = []
        for s, e in spans:
            m = 0.5 * (s + e)
            covering = [c for c in grp if c.sweep >= _TWO_PI or (m - c.start) % _TWO_PI < c.sweep]
            if not covering:
                continue
            cm, sm = math.cos(m), math.sin(m)
            # side points closer to this circle than to any other candidate circle (nearly coincident
            # circles: a limit just off the stretched or folded pose), tested on the exact set (tol = 0)
            px, py = center[0] + R * cm, center[1] + R * sm
            gap = min((abs(math.hypot(px - o[0].center[0], py - o[0].center[1]) - o[0].radius)
                       for gj, o in enumerate(groups) if gj != gi), default=math.inf)  # fmt: skip
            d = min(delta, 0.25 * gap) if gap > 0.0 else delta
            side_x += [center[0] + (R - d) * cm, center[0] + (R + d) * cm]
            side_y += [center[1] + (R - d) * sm, center[1] + (R + d) * sm]
            mine.append((s, e, covering))
        pieces.append(mine)
    inside = box.contains(np.array(side_x), np.array(side_y), 0.0).tolist()
    arcs: list[BoundaryArc[L]] = []
    k = 0
    for grp, mine in zip(groups, pieces, strict=True):
        center, R = grp[0].center, grp[0].radius
        kept: list[tuple[float, float, Candidate[L], bool]] = []
        for s, e, covering in mine:
            in_in, in_out = inside[k], inside[k + 1]
            k += 2
            if in_in == in_out:
                continue
            # keep the previous piece's label while its candidate still covers (fewer, longer arcs)
            prev = kept[-1][2] if kept and abs(kept[-1][1] - s) < _ANGLE_TOL and kept[-1][3] == in_in else None
            best = prev if prev is not None and prev in covering else min(covering, key=lambda c: c.rank)
            kept.append((s, e, best, in_in))
        # merge neighbours with the same label and side (cyclically)
        merged: list[list[Any]] = []
        for s, e, c, side in kept:
            last = merged[-1] if merged else None
            if last is not None and abs(last[1] - s) < _ANGLE_TOL and last[2].label == c.label and last[3] == side:
                merged[-1][1] = e
            else:
                merged.append([s, e, c, side])
        if len(merged) > 1:
            first, last = merged[0], merged[-1]
            if (abs(last[1] - (first[0] + _TWO_PI)) < _ANGLE_TOL and last[2].label == first[2].label
                    and last[3] == first[3]):  # fmt: skip
                first[0] = last[0]
                first[1] = first[1] + _TWO_PI if first[1] < last[0] else first[1]
                merged.pop()
        for s, e, c, side in merged:
            sweep = min(e - s, _TWO_PI)
            start = 0.0 if sweep >= _TWO_PI else s % _TWO_PI
            param = c.start + (start - c.start) % _TWO_PI
            arcs.append(BoundaryArc(center, R, start, sweep, c.label, side, param))
    return arcs


def chain(arcs: Sequence[BoundaryArc[L]], scale: float) -> tuple[tuple[int, ...], ...]:
    """Order the arcs into closed loops, each arc traversed with the region on its left.

    Args:
        arcs: the boundary arcs.
        scale: the length that sets the joining tolerance (l1 + l2) [m].
    """

    def ends(i: int) -> tuple[tuple[float, float], tuple[float, float]]:
        a = arcs[i]
        p0, p1 = a.point(a.start), a.point(a.start + a.sweep)
        return (p0, p1) if a.region_inside else (p1, p0)

    unused = set(range(len(arcs)))
    loops: list[tuple[int, ...]] = []
    while unused:
        first = min(unused)
        unused.discard(first)
        loop = [first]
        if arcs[first].sweep < _TWO_PI:
            head = ends(first)[0]
            tail = ends(first)[1]
            while math.dist(tail, head) > _CHAIN_TOL * scale:
                nxt = min(unused, key=lambda j: math.dist(ends(j)[0], tail), default=None)
                if nxt is None or math.dist(ends(nxt)[0], tail) > _CHAIN_TOL * scale:
                    break  # an open chain: reported as it is (should not happen)
                unused.discard(nxt)
                loop.append(nxt)
                tail = ends(nxt)[1]
        loops.append(tuple(loop))
    return tuple(loops)
