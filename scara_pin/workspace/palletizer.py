"""The palletizer's reach envelope in its arm plane: exact boundary arcs, area, extents, membership.

In the arm plane (the vertical plane of the turret, turned by q1) the tool point is at

    r = r0 + a2 sin q2 + a3 sin theta3,   z = z0 + a2 cos q2 + a3 cos theta3,
    r0 = a1 + a4,   z0 = d1 + d2 + d5,

(r the signed distance from the waist axis, forwards positive), over the box of joint limits
q2 in [lo2, hi2], theta3 in [lo3, hi3]. In the coordinates of the IK, (x, y) = (z - z0, r - r0), this is
the planar two-link arm (a2, a3) of :mod:`scara_pin.kinematics.planar2r` at the origin with ABSOLUTE joint
angles q2 and theta3, measured from the x axis: the image of a box, computed by the package's one arc
engine (:mod:`scara_pin.workspace.arcs`: candidate arcs, their exact crossings, the side test with the
IK's membership, merging, Green's area). Its arcs are turned back into (r, z) here, written
``c + R (sin phi, cos phi)`` with ``phi`` measured from the vertical like the joints (phi is the engine's
angle from the x axis), each labelled with what bounds the region there:

- q2 fixed at a limit (``joint2_lower``/``joint2_upper``): centre the elbow, radius a3, phi = theta3;
- theta3 fixed at a limit (``joint3_lower``/``joint3_upper``): centre r0 + a3 e(theta3), radius a2, phi = q2;
- ``stretched`` (theta3 = q2): centre the shoulder, radius a2 + a3, phi = q2;
- ``folded`` (theta3 = q2 + pi): centre the shoulder, radius |a2 - a3|.

The angles are S2's canonical ones (:mod:`scara_pin.kinematics.palletizer`): a file whose joints are
turned, shifted or measured from the big arm (``relative``: the box is then the big arm's angle and the
elbow's) is mapped first; the limit labels use the file's joint names and say which of its limits (a
joint turning the other way has its lower limit at the canonical upper end).

The start of an arc is given as the joint angle of its candidate (e.g. theta3 on a q2-limit arc).
Membership (:func:`reachable`) is the planar law-of-cosines solution with the joint limits and the IK's
tolerances.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..kinematics.palletizer import PalletizerGeometry
from ..units import SI, DisplayUnits, decimals_for, format_number
from .arcs import ArmBox, JointRange, Role, box_region, green

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["ArmPlaneEnvelope", "EnvelopeArc", "arm_plane_envelope", "plot_envelope", "reachable"]

_RANKS = {Role.STRETCHED: 0, Role.FOLDED: 1, Role.SECOND_LO: 2, Role.SECOND_HI: 3, Role.FIRST_LO: 4, Role.FIRST_HI: 5}
"""The rank of the engine's candidate roles between coincident candidates (lowest wins)."""
_COLOURS = {Role.STRETCHED: "tab:blue", Role.FOLDED: "tab:purple", Role.SECOND_LO: "tab:red",
            Role.SECOND_HI: "tab:orange", Role.FIRST_LO: "tab:green", Role.FIRST_HI: "tab:olive"}  # fmt: skip


def _labels(geo: PalletizerGeometry) -> dict[Role, tuple[str, int]]:
    """The roles as the file's limits (``joint2_lower``, ...: first joint q2, second theta3 or the elbow)."""
    out = {Role.STRETCHED: ("stretched", 0), Role.FOLDED: ("folded", 1)}
    for j, (lo, hi) in ((1, (Role.FIRST_LO, Role.FIRST_HI)), (2, (Role.SECOND_LO, Role.SECOND_HI))):
        up = geo.signs[j] > 0  # the canonical lower end is the file's lower limit
        out[lo] = (f"{geo.names[j]}_{'lower' if up else 'upper'}", _RANKS[lo])
        out[hi] = (f"{geo.names[j]}_{'upper' if up else 'lower'}", _RANKS[hi])
    return out


@dataclass(frozen=True)
class EnvelopeArc:
    """One boundary arc ``c + R (sin phi, cos phi)``, phi from ``start`` to ``start + sweep``.

    Attributes:
        center: (r, z) of the centre [m]. radius: [m]. start, sweep: [rad], sweep > 0.
        limit: what bounds the region there: ``joint2_lower``, ``joint2_upper``, ``joint3_lower``,
            ``joint3_upper`` (with the file's joint names), ``stretched`` or ``folded``.
        role: the engine's role of the arc (:class:`scara_pin.workspace.arcs.Role`).
        inside_toward_center: the region lies on the centre's side of the arc.
    """

    center: tuple[float, float]
    radius: float
    start: float
    sweep: float
    limit: str
    inside_toward_center: bool
    role: Role = Role.STRETCHED

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
        # in (r, z) the arc is c + R e(pi/2 - phi): the engine's term over that angle, phi growing clockwise
        term = green(self.center, self.radius, 0.5 * math.pi - self.start, -self.sweep)
        return -term if self.inside_toward_center else term


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

    def wireframe(self, n: int = 64) -> list[np.ndarray]:
        """The envelope in 3-D, as (M, 3) polylines of tool points (x, y, z) in the base frame [m].

        The boundary arcs in the arm plane at the waist's lower and upper limits (at four waist angles, a
        quarter turn apart, when the waist turns a full turn or more), and the circles the extreme points
        of the envelope (largest r, lowest and highest z) sweep over the waist's range: x = r cos q1,
        y = r sin q1, as the forward kinematics.
        """
        geo = self.geometry
        lo, hi = geo.lower[0], geo.upper[0]
        full = geo.continuous[0] or hi - lo >= 2.0 * math.pi
        planes = [0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi] if full else [lo, hi]
        out = []
        for q1 in planes:
            c, s_ = math.cos(q1), math.sin(q1)
            for arc in self.arcs:
                rz = arc.points(n)
                out.append(np.column_stack([rz[:, 0] * c, rz[:, 0] * s_, rz[:, 1]]))
        sweep = np.linspace(0.0, 2.0 * math.pi, 4 * n + 1) if full else np.linspace(lo, hi, max(2, n))
        pts = [p for a in self.arcs for p in a.extreme_points()]
        for r, z in (max(pts, key=lambda p: p[0]), min(pts, key=lambda p: p[1]), max(pts, key=lambda p: p[1])):
            out.append(np.column_stack([r * np.cos(sweep), r * np.sin(sweep), np.full(len(sweep), z)]))
        return out

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


def _box(geo: PalletizerGeometry) -> ArmBox:
    """The arm (a2, a3) in (x, y) = (z - h0, r - r0) and its box of canonical angles (q2, theta3 or the elbow)."""
    q2, t3 = ((JointRange(-math.pi, math.pi, True) if geo.continuous[j] else JointRange.of(geo.lower[j], geo.upper[j]))
              for j in (1, 2))  # fmt: skip
    return ArmBox((0.0, 0.0), geo.arm, q2, t3, relative=geo.relative)


def reachable(geo: PalletizerGeometry, r: float, z: float) -> bool:
    """Whether some (q2, theta3) inside the limits puts the tool point at (r, z) of the arm plane.

    The planar two-link solution (:mod:`scara_pin.kinematics.planar2r`) of the arm plane, both elbows,
    with the IK's tolerances.
    """
    return bool(_box(geo).contains(np.array([z - geo.h0]), np.array([r - geo.r0]))[0])


def arm_plane_envelope(geo: PalletizerGeometry) -> ArmPlaneEnvelope:
    """The exact reach envelope of the tool point in the arm plane under the q2 and theta3 limits."""
    labels = _labels(geo)
    roles = {label: role for role, (label, _) in labels.items()}
    region = box_region(_box(geo), labels)
    arcs = [EnvelopeArc((a.center[1] + geo.r0, a.center[0] + geo.h0), a.radius, a.param_start, a.sweep, a.label,
                        a.region_inside, roles[a.label]) for a in region.arcs]  # fmt: skip
    pts = np.array([p for a in arcs for p in a.extreme_points()]) if arcs else np.zeros((1, 2))
    return ArmPlaneEnvelope(tuple(arcs), float(region.area), (float(pts[:, 0].min()), float(pts[:, 0].max())),
                            (float(pts[:, 1].min()), float(pts[:, 1].max())), geo)  # fmt: skip


def plot_envelope(env: ArmPlaneEnvelope, path: str | os.PathLike[str] | None = None, *, q: np.ndarray | None = None,
                  units: DisplayUnits = SI, robot_name: str | None = None, dpi: int = 120,
                  tool_frame: str = "tool0") -> Figure:  # fmt: skip
    """The envelope in the arm plane: arcs coloured by their limit, and the arm at ``q`` (default mid-range).

    Args:
        env: the envelope.
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        q: the configuration the arm is drawn at (the file's joints) [rad]; default mid-range.
        units: the length unit of the axes (``DisplayUnits("mm")`` for millimetres).
        robot_name: named in the title.
        dpi: resolution of a written PNG.
        tool_frame: the tool frame's name, in the title.

    Returns:
        the matplotlib Figure.
    """
    from matplotlib.ticker import FuncFormatter

    from ..files import finish, new_figure  # object-oriented: no pyplot; written atomically

    geo = env.geometry
    fig = new_figure(7, 7, layout=None)
    ax = fig.add_subplot()
    seen: set[str] = set()
    for a in env.arcs:
        pts = a.points(max(8, int(a.sweep * 90)))
        ax.plot(pts[:, 0], pts[:, 1], color=_COLOURS[a.role], lw=2.0,
                label=None if a.limit in seen else a.limit)  # fmt: skip
        seen.add(a.limit)
    # the arm at q, in canonical angles (the big arm's and the small arm's from the vertical)
    t = (np.asarray(geo.lower) + np.asarray(geo.upper)) / 2 if q is None else np.array(geo.canonical(list(q)))
    a2, a3 = float(t[1]), float(t[2] + t[1] if geo.relative else t[2])
    sh = geo.shoulder
    el = (sh[0] + geo.a2 * math.sin(a2), sh[1] + geo.a2 * math.cos(a2))
    wr = (el[0] + geo.a3 * math.sin(a3), el[1] + geo.a3 * math.cos(a3))
    tool = (wr[0] + geo.r0 - sh[0], wr[1] + geo.h0 - sh[1])
    chain = np.array([(0.0, 0.0), (0.0, sh[1]), sh, el, wr, (tool[0], wr[1]), tool])
    ax.plot(chain[:, 0], chain[:, 1], "k-o", ms=3, lw=1.5, label="arm (mid-range)")
    ax.axhline(0.0, color="grey", lw=0.8)
    ax.set_aspect("equal")
    # drawn in metres; the ticks read in the unit chosen (m or mm: a power of ten keeps them round)
    L, n = units.scale("length"), units.name("length")
    ticks = FuncFormatter(lambda v, _: f"{v * L:.6g}")
    ax.xaxis.set_major_formatter(ticks)
    ax.yaxis.set_major_formatter(ticks)
    ax.set_xlabel(f"r: from the waist axis [{n}]")
    ax.set_ylabel(f"z: above the floor [{n}]")
    area = format_number(env.area * L * L, decimals_for(L * L, 1e-6))  # to 1 mm^2
    ax.set_title(f"{robot_name or 'palletizer'}: {tool_frame} in the arm plane, area {area} {n}$^2$")
    ax.legend(loc="best", fontsize=8)
    ax.grid(True, alpha=0.3)
    return finish(fig, path, dpi, bbox_inches="tight")
