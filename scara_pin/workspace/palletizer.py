"""The palletizer's reach envelope in its arm plane: exact boundary arcs, area, extents, membership.

In the arm plane (the vertical plane of the turret, turned by q1) the tool point is at

    r = r0 + a2 sin q2 + a3 sin theta3,   z = z0 + a2 cos q2 + a3 cos theta3,
    r0 = a1 + a4,   z0 = d1 + d2 + d5,

(r the signed distance from the waist axis, forwards positive), over the box of joint limits
q2 in [lo2, hi2], theta3 in [lo3, hi3]. The boundary of the image of a box lies on the images of its
edges and of the critical set, det d(r, z)/d(q2, theta3) = -a2 a3 sin(theta3 - q2) = 0. All are circle
arcs, written ``c + R (sin phi, cos phi)`` with ``phi`` measured from the vertical like the joints:

- q2 fixed at a limit: centre the elbow, radius a3, phi = theta3 over its range;
- theta3 fixed at a limit: centre r0 + a3 e(theta3), radius a2, phi = q2 over its range;
- stretched (theta3 = q2): centre the shoulder, radius a2 + a3, phi over the common range;
- folded (theta3 = q2 + pi): centre the shoulder, radius |a2 - a3|.

Every candidate arc is split at its intersections with the others; a piece is on the boundary when a
point just outside it on one side is reachable and on the other side is not (membership by the planar
law-of-cosines solution with the joint limits, :func:`reachable`). The area follows from Green's
theorem over the boundary pieces, each traversed with the region on its left.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..kinematics.palletizer import PalletizerGeometry
from ..kinematics.planar2r import Reach, nearest_turn

__all__ = ["ArmPlaneEnvelope", "EnvelopeArc", "arm_plane_envelope", "plot_envelope", "reachable"]

_TWO_PI = 2.0 * math.pi
_TANGENT = 1e-12
"""Relative tolerance of a tangency between two candidate circles (the stretched circle touches the
theta3-limit arcs at theta3 = q2: exactly in theory, within rounding in floating point)."""
_PROBE = 1e-7
"""[m] distance of the membership probes from a candidate piece (far above rounding, far below features)."""


@dataclass(frozen=True)
class EnvelopeArc:
    """One boundary arc ``c + R (sin phi, cos phi)``, phi from ``start`` to ``start + sweep``.

    Attributes:
        center: (r, z) of the centre [m]. radius: [m]. start, sweep: [rad], sweep > 0.
        limit: what bounds the region there: ``joint2_lower``, ``joint2_upper``, ``joint3_lower``,
            ``joint3_upper``, ``stretched`` or ``folded``.
        inside_toward_center: the region lies on the centre's side of the arc.
    """

    center: tuple[float, float]
    radius: float
    start: float
    sweep: float
    limit: str
    inside_toward_center: bool

    def points(self, n: int = 64) -> np.ndarray:
        """(n, 2) points (r, z) along the arc, ends included [m]."""
        phi = self.start + np.linspace(0.0, self.sweep, n)
        return np.column_stack([self.center[0] + self.radius * np.sin(phi), self.center[1] + self.radius * np.cos(phi)])

    def extreme_points(self) -> list[tuple[float, float]]:
        """The arc's ends and its points of extreme r or z (phi a multiple of pi/2 inside the arc)."""
        phis = [self.start, self.start + self.sweep]
        k = math.ceil(self.start / (0.5 * math.pi))
        while k * 0.5 * math.pi < self.start + self.sweep:
            phis.append(k * 0.5 * math.pi)
            k += 1
        c, R = self.center, self.radius
        return [(c[0] + R * math.sin(p), c[1] + R * math.cos(p)) for p in phis]

    def green(self) -> float:
        """The arc's term of the area integral 1/2 (r dz - z dr), traversed with the region on its left."""
        cx, cy = self.center
        R = self.radius
        a, b = self.start, self.start + self.sweep
        if self.inside_toward_center:  # phi grows clockwise: the region on the left means decreasing phi
            a, b = b, a
        return 0.5 * (-R * R * (b - a) + R * cx * (math.cos(b) - math.cos(a)) - R * cy * (math.sin(b) - math.sin(a)))


@dataclass(frozen=True)
class ArmPlaneEnvelope:
    """The reachable region of the tool point in the arm plane.

    Attributes:
        arcs: the boundary arcs.
        area: [m^2]. r_range, z_range: extents of the region [m].
        geometry: the palletizer it belongs to.
    """

    arcs: tuple[EnvelopeArc, ...]
    area: float
    r_range: tuple[float, float]
    z_range: tuple[float, float]
    geometry: PalletizerGeometry

    def contains(self, r: float, z: float) -> bool:
        """Whether the tool point can be at (r, z) in the arm plane inside the joint limits."""
        return reachable(self.geometry, r, z)

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (SI units)."""
        return {
            "plane": "arm (r, z): r from the waist axis along the turret, z above the floor",
            "area": self.area,
            "r_range": list(self.r_range),
            "z_range": list(self.z_range),
            "arcs": [{"limit": a.limit, "center": list(a.center), "radius": a.radius, "start": a.start,
                      "sweep": a.sweep} for a in self.arcs],  # fmt: skip
        }


def _origin(geo: PalletizerGeometry) -> tuple[float, float]:
    return geo.r0, geo.h0


def _fits(value: float, lo: float, hi: float, continuous: bool) -> bool:
    return continuous or nearest_turn(value, lo, hi, value) is not None


def reachable(geo: PalletizerGeometry, r: float, z: float) -> bool:
    """Whether some (q2, theta3) inside the limits puts the tool point at (r, z) of the arm plane.

    The planar two-link solution (:mod:`scara_pin.kinematics.planar2r`) of the arm plane, both elbows,
    with the IK's tolerances.
    """
    arm = geo.arm
    code, _, g, heading, lean = arm.solve(z - geo.h0, r - geo.r0)  # the arm plane as (x, y) = (v, h)
    if code != Reach.OK:
        return False
    lo, hi, cont = geo.lower, geo.upper, geo.continuous
    for q3, q2 in ((g, heading - lean), (-g, heading + lean)):
        if _fits(q2, lo[1], hi[1], cont[1]) and _fits(q2 + q3, lo[2], hi[2], cont[2]):
            return True
    return False


def _candidates(geo: PalletizerGeometry) -> list[tuple[tuple[float, float], float, float, float, str]]:
    """(center, radius, phi0, phi1, limit) of every candidate arc."""
    r0, z0 = _origin(geo)
    a2, a3 = geo.a2, geo.a3
    (lo2, hi2), (lo3, hi3) = ((-math.pi, math.pi) if geo.continuous[j] else (geo.lower[j], geo.upper[j])
                              for j in (1, 2))  # fmt: skip
    hi2, hi3 = min(hi2, lo2 + _TWO_PI), min(hi3, lo3 + _TWO_PI)
    out = []
    for q2, name in ((lo2, "joint2_lower"), (hi2, "joint2_upper")):
        out.append(((r0 + a2 * math.sin(q2), z0 + a2 * math.cos(q2)), a3, lo3, hi3, name))
    for t3, name in ((lo3, "joint3_lower"), (hi3, "joint3_upper")):
        out.append(((r0 + a3 * math.sin(t3), z0 + a3 * math.cos(t3)), a2, lo2, hi2, name))
    for k in range(-2, 3):  # theta3 = q2 + 2 pi k (stretched) and q2 + pi + 2 pi k (folded)
        a, b = max(lo2, lo3 - k * _TWO_PI), min(hi2, hi3 - k * _TWO_PI)
        if a < b:
            out.append(((r0, z0), a2 + a3, a, b, "stretched"))
        a, b = max(lo2, lo3 - math.pi - k * _TWO_PI), min(hi2, hi3 - math.pi - k * _TWO_PI)
        if a < b and a2 != a3:  # folded: the point is shoulder + (a2 - a3) e(q2)
            if a2 > a3:
                out.append(((r0, z0), a2 - a3, a, b, "folded"))
            else:
                off = math.pi + k * _TWO_PI  # as a function of theta3 = q2 + pi + 2 pi k
                out.append(((r0, z0), a3 - a2, a + off, b + off, "folded"))
    return out


def _circle_hits(c1: tuple[float, float], r1: float, c2: tuple[float, float], r2: float) -> list[np.ndarray]:
    d = math.hypot(c2[0] - c1[0], c2[1] - c1[1])
    tol = _TANGENT * (r1 + r2)  # circles this close to tangent touch (rounding must not hide a tangency)
    if d == 0.0 or d > r1 + r2 + tol or d < abs(r1 - r2) - tol:
        return []
    a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = math.sqrt(max(r1 * r1 - a * a, 0.0))
    ex, ey = (c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d
    px, py = c1[0] + a * ex, c1[1] + a * ey
    return [np.array([px - h * ey, py + h * ex]), np.array([px + h * ey, py - h * ex])]


def _phi_on(center: tuple[float, float], p: np.ndarray, phi0: float) -> float:
    """The phi of point p on a circle, as the 2 pi-equivalent at or above phi0."""
    phi = math.atan2(p[0] - center[0], p[1] - center[1])
    return phi + math.ceil((phi0 - phi) / _TWO_PI - 1e-12) * _TWO_PI


def arm_plane_envelope(geo: PalletizerGeometry) -> ArmPlaneEnvelope:
    """The exact reach envelope of the tool point in the arm plane under the q2 and theta3 limits."""
    cands = _candidates(geo)
    arcs: list[EnvelopeArc] = []
    for i, (c, R, phi0, phi1, name) in enumerate(cands):
        cuts = [phi0, phi1]
        for j, (c2, R2, *_rest) in enumerate(cands):
            if j != i:
                for p in _circle_hits(c, R, c2, R2):
                    phi = _phi_on(c, p, phi0)
                    if phi0 < phi < phi1:
                        cuts.append(phi)
        cuts.sort()
        for a, b in zip(cuts[:-1], cuts[1:]):
            if b - a <= 1e-12:
                continue
            m = 0.5 * (a + b)
            n = np.array([math.sin(m), math.cos(m)])
            p = np.array([c[0], c[1]]) + R * n
            outer = reachable(geo, *(p + _PROBE * n))
            inner = reachable(geo, *(p - _PROBE * n))
            if outer != inner:
                arcs.append(EnvelopeArc((float(c[0]), float(c[1])), R, a, b - a, name, inner))
    arcs = _merge(arcs)
    area = sum(a.green() for a in arcs)
    pts = np.array([p for a in arcs for p in a.extreme_points()]) if arcs else np.zeros((1, 2))
    return ArmPlaneEnvelope(tuple(arcs), float(area), (float(pts[:, 0].min()), float(pts[:, 0].max())),
                            (float(pts[:, 1].min()), float(pts[:, 1].max())), geo)  # fmt: skip


def _merge(arcs: list[EnvelopeArc]) -> list[EnvelopeArc]:
    """Join consecutive pieces of the same candidate arc (cut where another arc crossed the interior)."""
    out: list[EnvelopeArc] = []
    for a in arcs:
        last = out[-1] if out else None
        if (last is not None and last.limit == a.limit and last.center == a.center and last.radius == a.radius
                and last.inside_toward_center == a.inside_toward_center
                and abs(last.start + last.sweep - a.start) <= 1e-12):  # fmt: skip
            out[-1] = EnvelopeArc(last.center, last.radius, last.start, last.sweep + a.sweep, a.limit,
                                  a.inside_toward_center)  # fmt: skip
        else:
            out.append(a)
    return out


def plot_envelope(env: ArmPlaneEnvelope, path: str, q: np.ndarray | None = None) -> None:
    """Draw the envelope to a PNG: arcs coloured by their limit, and the arm at ``q`` (default mid-range)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    colours = {"joint2_lower": "tab:green", "joint2_upper": "tab:olive", "joint3_lower": "tab:red",
               "joint3_upper": "tab:orange", "stretched": "tab:blue", "folded": "tab:purple"}  # fmt: skip
    geo = env.geometry
    fig = Figure(figsize=(7, 7))  # object-oriented: no pyplot, no global backend or figure state
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    seen: set[str] = set()
    for a in env.arcs:
        pts = a.points(max(8, int(a.sweep * 90)))
        ax.plot(pts[:, 0], pts[:, 1], color=colours[a.limit], lw=2.0,
                label=None if a.limit in seen else a.limit)  # fmt: skip
        seen.add(a.limit)
    q = (np.asarray(geo.lower) + np.asarray(geo.upper)) / 2 if q is None else np.asarray(q, dtype=float)
    sh = geo.shoulder
    el = (sh[0] + geo.a2 * math.sin(q[1]), sh[1] + geo.a2 * math.cos(q[1]))
    wr = (el[0] + geo.a3 * math.sin(q[2]), el[1] + geo.a3 * math.cos(q[2]))
    tool = (wr[0] + geo.r0 - sh[0], wr[1] + geo.h0 - sh[1])
    chain = np.array([(0.0, 0.0), (0.0, sh[1]), sh, el, wr, (tool[0], wr[1]), tool])
    ax.plot(chain[:, 0], chain[:, 1], "k-o", ms=3, lw=1.5, label="arm (mid-range)")
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlabel("r: from the waist axis [m]")
    ax.set_ylabel("z: above the floor [m]")
    ax.set_title(f"palletizer: tool0 in the arm plane, area {env.area:.5g} m$^2$")
    ax.legend(loc="best", fontsize=8)
    ax.grid(True, alpha=0.3)
    from ..files import atomic_output  # written atomically: never through a symlink, never a device

    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120, bbox_inches="tight")
