"""Exact plan-view workspace of a SCARA under any J1/J2 limits, and the nearest edge along a ray.

The region. With theta = phi1 + beta1 (heading of arm 1) and gamma the elbow angle (angle from arm 1 to
arm 2, see :mod:`scara_pin.kinematics.scara`), the wrist axis point (the J4 axis) is

    W(theta, gamma) = A1 + l1 e(theta) + l2 e(theta + gamma),     e(a) = (cos a, sin a),

and the joint limits make (theta, gamma) a rectangle [t_lo, t_hi] x [g_lo, g_hi]. The reachable region is
the image of that rectangle. It is compact and connected (the image of a connected set), so it has one
outer loop and possibly holes; it never comes in two pieces. Its boundary lies in the images of

- the rectangle's J1 edges (theta = t_lo or t_hi, gamma sweeping): arcs of radius l2 centred on the elbow
  positions A1 + l1 e(theta);
- its J2 edges (gamma = g_lo or g_hi, theta sweeping): arcs centred on A1 of radius
  r(gamma) = sqrt(l1^2 + l2^2 + 2 l1 l2 cos gamma), at angles theta + psi(gamma),
  psi = atan2(l2 sin gamma, l1 + l2 cos gamma);
- the singular lines (det dW/d(theta, gamma) = l1 l2 sin gamma = 0): gamma = 0 (stretched, r = l1 + l2) and
  gamma = pi (folded, r = |l1 - l2|), when the elbow range contains them (mod 2 pi).

A J1 range of 2 pi or more (or infinite limits) leaves only circles about A1 (an annulus, no side arcs);
an elbow range of 2 pi or more makes the J1 edges whole circles. This is the arm of
:mod:`scara_pin.kinematics.planar2r` over a box with a RELATIVE second joint (gamma): the candidate arcs,
their splitting at mutual intersections (exact from the joint parameters where known), the side test with
the exact membership, the merging, the loops (outer loop counterclockwise, holes clockwise) and the exact
area by Green's theorem are those of the package's one arc engine, :mod:`scara_pin.workspace.arcs`; here
they get their labels (:class:`Limit`, named by the joint and its q limit) and, with ``yaw``, an offset.

:meth:`Workspace.contains` is the closed-form IK's test, independent of the arcs (the engine's
``ArmBox.contains``): r = |W - A1| gives |gamma| by the half-angle law of cosines; each elbow sign gives
gamma and theta, and the point is inside when gamma and theta each have a 2 pi-equivalent within the limits
(tolerance ``LIMIT_TOL`` = 1e-10 rad on the joints and ``REACH_TOL`` = 1e-10 m on the reach, the IK's own).

Which point. The region is that of the wrist axis point. The shipped robots have no plan-view tool offset,
so it is also the tool point's. With a tool offset t from the wrist axis, the tool point is
W + R(alpha) t with alpha = yaw - yaw0 (:mod:`scara_pin.kinematics.scara`); at a FIXED yaw, with J4 free to take any
turn (a J4 range of at least 2 pi, so that J4 never cuts the region), the tool point region is the wrist
region translated by R(yaw - yaw0) t: pass ``yaw`` to :func:`workspace` to get it. Without a yaw (or with
J4 limited to less than a turn) only the wrist axis region is defined here.

Vertical: z = z0 + s3 q3 with q3 in the J3 stroke gives ``z_range``; the region is the same at every z.

Ray query (digest S5). From a start point inside the region along a direction (plan view, or with a
vertical component: the J3 stroke then stops the ray too), the ray start + u d (|d| = 1, u >= 0) meets
each boundary arc's circle where |s + u d - c| = R; an intersection counts when its angle on the circle lies
within the arc (a tolerance of ``EDGE_TOL`` m along the arc). The nearest one with u > ``EDGE_TOL`` is
the edge. Documented edge cases:

- a start outside the region (beyond the joint tolerances) or outside the z stroke raises
  :class:`OutsideWorkspaceError`;
- a start on the edge (within ``EDGE_TOL`` = 1e-9 m of a boundary arc or a stroke end): when the
  direction points out of the region across that arc, the answer is the start itself at distance 0;
  otherwise that arc is ignored and the answer is the next edge along the ray. At a corner, the answer is
  0 as soon as the direction points out across either arc (conservative at a reflex corner);
- a ray that only grazes a boundary arc (tangent) stops there (conservative: the jog stops on the edge).
"""

from __future__ import annotations

import enum
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError, ParameterError
from ..kinematics.planar2r import LIMIT_TOL
from ..kinematics.scara import NEAR_PARALLEL_TOL, ScaraGeometry
from ..summary import Summarized
from ..units import SI, DisplayUnits, decimals_for, format_number
from .arcs import SIDE_OFFSET, ArmBox, JointRange, Role, box_region

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = [
    "EDGE_TOL",
    "SIDE_OFFSET",
    "Arc",
    "Limit",
    "OutsideWorkspaceError",
    "RayBatch",
    "RayHit",
    "Workspace",
    "plot_workspace",
    "workspace",
]

EDGE_TOL = 1e-9
"""[m] a ray start this close to the edge is on it; arc ranges are widened by this much for ray hits."""

_TWO_PI = 2.0 * math.pi


class OutsideWorkspaceError(InvalidInputError):
    """A ray start (or another point that must be reachable) is outside the workspace.

    Attributes:
        point: the offending point [m].
        reason: why it is outside (which joint or stroke rule it breaks).
    """

    def __init__(self, point: Sequence[float], reason: str) -> None:
        self.point = tuple(float(v) for v in point)
        self.reason = reason
        shown = ", ".join(f"{v:.9g}" for v in self.point)
        super().__init__(f"start point ({shown}) is outside the workspace: {reason}")


class Limit(enum.Enum):
    """Which joint limit (or singular pose) makes a boundary arc or stops a ray.

    ``J1_LOWER``: J1 at its lower limit with J2 sweeping; ``J2_UPPER``: J2 at its upper limit with J1
    sweeping; ``OUTER``: the arm stretched (elbow angle 0) with J1 sweeping; ``FOLDED``: the arm folded
    (elbow angle pi) with J1 sweeping; ``J3_LOWER``/``J3_UPPER``: the ends of the vertical stroke (rays only).
    Lower/upper refer to the joint value q (not to the angle in the plane, which a -z axis reverses).
    """

    OUTER = "outer"
    FOLDED = "folded"
    J1_LOWER = "joint1_lower"
    J1_UPPER = "joint1_upper"
    J2_LOWER = "joint2_lower"
    J2_UPPER = "joint2_upper"
    J3_LOWER = "joint3_lower"
    J3_UPPER = "joint3_upper"


# label priority when two candidate arcs lie on the same circle (a J2 limit at exactly 0 is the outer arc)
_PRIORITY = {Limit.OUTER: 0, Limit.FOLDED: 1, Limit.J2_LOWER: 2, Limit.J2_UPPER: 3, Limit.J1_LOWER: 4,
             Limit.J1_UPPER: 5}  # fmt: skip


@dataclass(frozen=True)
class Arc:
    """One boundary arc: the points center + radius e(a) for a from ``start`` counterclockwise by ``sweep``.

    Attributes:
        center: (x, y) [m].
        radius: [m], > 0.
        start: start angle [rad], in [0, 2 pi).
        sweep: counterclockwise extent [rad], in (0, 2 pi] (2 pi: a whole circle).
        limit: the joint limit that produces it.
        description: a sentence naming the joints and values, e.g. "joint1 at its upper limit 132 deg,
            joint2 sweeping".
        region_inside: True when the region lies on the centre's side of the arc (convex side outward);
            the loops traverse such an arc counterclockwise, the others clockwise.
    """

    center: tuple[float, float]
    radius: float
    start: float
    sweep: float
    limit: Limit
    description: str
    region_inside: bool

    @property
    def end(self) -> float:
        """End angle [rad] (start + sweep, may exceed 2 pi)."""
        return self.start + self.sweep

    def point(self, angle: float) -> tuple[float, float]:
        """The point of the circle at ``angle`` [rad]."""
        return (self.center[0] + self.radius * math.cos(angle), self.center[1] + self.radius * math.sin(angle))

    def points(self, n: int) -> np.ndarray:
        """(n, 2) points evenly spaced along the arc, both ends included."""
        a = self.start + np.linspace(0.0, self.sweep, n)
        return np.column_stack((self.center[0] + self.radius * np.cos(a), self.center[1] + self.radius * np.sin(a)))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready description."""
        return {
            "center": list(self.center),
            "radius": self.radius,
            "start_angle": self.start,
            "end_angle": self.end,
            "limit": self.limit.value,
            "description": self.description,
            "region_inside": self.region_inside,
        }


@dataclass(frozen=True)
class RayHit:
    """The edge met along a ray.

    Attributes:
        point: the edge point, (x, y) or (x, y, z) as the start was given [m].
        distance: the distance from the start along the (unit) direction [m]; 0 when the start is on the
            edge and the direction leaves the region there.
        limit: what stops the ray.
        arc: index of the stopping arc in ``Workspace.arcs``, or -1 for the J3 stroke.
        description: the stopping arc's (or stroke end's) description.
    """

    point: tuple[float, ...]
    distance: float
    limit: Limit
    arc: int
    description: str

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready description."""
        return {"point": list(self.point), "distance": self.distance, "limit": self.limit.value,
                "arc": self.arc, "description": self.description}  # fmt: skip


@dataclass(frozen=True)
class RayBatch:
    """Answers of :meth:`Workspace.ray_batch` for N rays.

    Attributes:
        points: (N, 2) or (N, 3) edge points [m].
        distance: (N,) distances [m].
        arc: (N,) index of the stopping arc, -1 for the J3 stroke.
        limit: (N,) :class:`Limit` values as strings (``Limit(value)`` gives the enum).
    """

    points: np.ndarray
    distance: np.ndarray
    arc: np.ndarray
    limit: np.ndarray


def _box(geo: ScaraGeometry) -> ArmBox:
    """The arm and its box of joint angles in the plane: theta = s1 q1 + beta1, gamma = elbow_angle(q2)."""
    ra, rb = geo.revolute[0], geo.revolute[1]
    t = JointRange.of(geo.signs[ra] * geo.lower[ra] + geo.beta1, geo.signs[ra] * geo.upper[ra] + geo.beta1)
    g = JointRange.of(geo.elbow_angle(geo.lower[rb]), geo.elbow_angle(geo.upper[rb]))
    return ArmBox(geo.a1, geo.arm, t, g, relative=True)


@dataclass(frozen=True, repr=False, kw_only=True)
class Workspace(Summarized):
    """The exact plan-view region of the wrist axis point (or, with ``yaw``, the tool point at that yaw).

    Attributes:
        geometry: the SCARA geometry (limits included) it was built from.
        arcs: the boundary arcs.
        loops: each closed loop as indices into ``arcs`` in traversal order (region on the left: the outer
            loop counterclockwise, holes clockwise).
        area: [m^2], exact (Green's theorem over the arcs).
        r_min, r_max: smallest and largest distance of the wrist axis from the shoulder axis [m].
        z_range: (z_min, z_max) of the tool from the J3 stroke [m].
        offset: translation of the region from the wrist region: (0, 0), or R(yaw - yaw0) t with ``yaw``.
        yaw: the fixed tool yaw the region is for, or None (wrist axis point) [rad].
        note: what a wrist-only tilt changes (:func:`wrist_tilt_note`), else None.
    """

    geometry: ScaraGeometry
    arcs: tuple[Arc, ...]
    loops: tuple[tuple[int, ...], ...]
    area: float
    r_min: float
    r_max: float
    z_range: tuple[float, float]
    offset: tuple[float, float] = (0.0, 0.0)
    yaw: float | None = None
    note: str | None = None
    _box: ArmBox = field(init=False, repr=False, compare=False)
    _z_limits: tuple[Limit, Limit] = field(init=False, repr=False, compare=False)
    _arc_arrays: tuple[np.ndarray, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # derived once (the workspace is frozen): the plain numbers of the test and the arcs as arrays
        geo = self.geometry
        object.__setattr__(self, "_box", _box(geo))
        up = geo.signs[geo.prismatic] > 0  # the top of the stroke is J3's upper limit
        z_limits = (Limit.J3_LOWER, Limit.J3_UPPER) if up else (Limit.J3_UPPER, Limit.J3_LOWER)
        object.__setattr__(self, "_z_limits", z_limits)
        rows = [(a.center[0], a.center[1], a.radius, a.start, a.sweep, 1.0 if a.region_inside else -1.0)
                for a in self.arcs]  # fmt: skip
        object.__setattr__(self, "_arc_arrays", tuple(np.array(col, dtype=float) for col in zip(*rows, strict=True))
                           if rows else tuple(np.zeros(0) for _ in range(6)))  # fmt: skip

    # --------------------------------------------------------------------------------- membership

    def summary(self, units: DisplayUnits | None = None) -> str:
        """Area, reach, stroke and boundary, lengths in ``units`` (default SI)."""
        u = SI if units is None else units
        L = u.name("length")
        of = ("the wrist axis" if self.yaw is None
              else f"the tool at yaw {u.format(self.yaw, 'angle')} {u.name('angle')}")  # fmt: skip
        return (f"Workspace of {of}: area {u.format(self.area, 'area')} {u.name('area')}, reach "
                f"{u.format(self.r_min, 'length')} to {u.format(self.r_max, 'length')} {L} from the J1 axis, z "
                f"{u.format(self.z_range[0], 'length')} to {u.format(self.z_range[1], 'length')} {L}; "
                f"{len(self.arcs)} boundary arcs in {len(self.loops)} loop(s)"
                + (f"\n  {self.note}" if self.note else ""))  # fmt: skip

    def contains(self, points: Sequence[float] | np.ndarray, *, tol: float = LIMIT_TOL) -> bool | np.ndarray:
        """Whether plan points (x, y) are reachable (the closed-form IK's test).

        Args:
            points: one point (2,) or an (N, 2) array [m]; a third column (z) is ignored.
            tol: how far outside a joint limit [rad] or a reach circle [m] still counts as inside; the
                default is the IK's (``LIMIT_TOL`` = ``REACH_TOL`` = 1e-10); 0 for the exact set.

        Returns:
            a bool for one point, an (N,) bool array for N points.
        """
        P = np.asarray(points, dtype=float)
        one = P.ndim == 1
        P = np.atleast_2d(P)
        if P.shape[1] < 2:
            raise ParameterError("points", f"array of shape {np.shape(points)}", "must be (2,) or (N, 2)")
        out = self._box.contains(P[:, 0] - self.offset[0], P[:, 1] - self.offset[1], tol)
        return bool(out[0]) if one else out

    def contains_by_arcs(self, points: Sequence[float] | np.ndarray) -> np.ndarray:
        """Point-in-region from the boundary arcs alone (even-odd crossings of a ray towards +x), (N,) bool.

        An independent route to :meth:`contains` (used to check the arcs); points on the boundary may go
        either way.
        """
        P = np.atleast_2d(np.asarray(points, dtype=float))
        x, y = P[:, 0], P[:, 1]
        count = np.zeros(len(P), dtype=np.int64)
        for arc in self.arcs:
            cx, cy, R = arc.center[0], arc.center[1], arc.radius
            h2 = R * R - (y - cy) ** 2
            ok = h2 > 0
            h = np.sqrt(np.where(ok, h2, 0.0))
            for sx in (1.0, -1.0):
                xi = cx + sx * h
                ang = np.arctan2(y - cy, xi - cx)
                within = np.mod(ang - arc.start, _TWO_PI) <= arc.sweep
                count += (ok & (xi > x) & within).astype(np.int64)
        return count % 2 == 1

    def distance_to_boundary(self, points: Sequence[float] | np.ndarray) -> np.ndarray:
        """(N,) distance from plan points to the nearest boundary arc [m]."""
        P = np.atleast_2d(np.asarray(points, dtype=float))
        best = np.full(len(P), np.inf)
        for arc in self.arcs:
            dx, dy = P[:, 0] - arc.center[0], P[:, 1] - arc.center[1]
            within = np.mod(np.arctan2(dy, dx) - arc.start, _TWO_PI) <= arc.sweep
            (x0, y0), (x1, y1) = arc.point(arc.start), arc.point(arc.end)
            to_ends = np.minimum(np.hypot(P[:, 0] - x0, P[:, 1] - y0), np.hypot(P[:, 0] - x1, P[:, 1] - y1))
            best = np.minimum(best, np.where(within, np.abs(np.hypot(dx, dy) - arc.radius), to_ends))
        return best

    # --------------------------------------------------------------------------------- rays
    def ray(self, start: ArrayLike, direction: ArrayLike) -> RayHit:
        """The nearest edge along a ray (see the module docstring for starts on the edge).

        Args:
            start: (x, y) or (x, y, z) inside the region [m].
            direction: (dx, dy) or (dx, dy, dz), not zero; normalised here. With a z component the J3
                stroke stops the ray too, and the distance is measured in 3D.

        Returns:
            RayHit.

        Raises:
            OutsideWorkspaceError: the start is outside the region or the stroke.
            ParameterError: malformed or zero direction, or shapes that do not match.
        """
        s = np.asarray(start, dtype=float)
        d = np.asarray(direction, dtype=float)
        if s.shape not in ((2,), (3,)) or d.shape != s.shape:
            raise ParameterError("ray start and direction", f"shapes {s.shape} and {d.shape}",
                                 "must both be (2,) (x, y) or both (3,) (x, y, z)")  # fmt: skip
        batch = self.ray_batch(s[None, :], d[None, :])
        k = int(batch.arc[0])
        limit = Limit(batch.limit[0])
        desc = self.arcs[k].description if k >= 0 else self._z_description(limit)
        return RayHit(tuple(float(v) for v in batch.points[0]), float(batch.distance[0]), limit, k, desc)

    def ray_batch(self, starts: np.ndarray, directions: np.ndarray) -> RayBatch:
        """:meth:`ray` for N rays at once, vectorised with numpy.

        Args:
            starts: (N, 2) or (N, 3) start points [m].
            directions: the same shape; each row not zero.

        Raises:
            OutsideWorkspaceError: some start is outside (the first such one is named).
            ParameterError: malformed input.
        """
        S = np.asarray(starts, dtype=float)
        D = np.asarray(directions, dtype=float)
        if S.ndim != 2 or S.shape[1] not in (2, 3) or D.shape != S.shape:
            raise ParameterError("ray starts and directions", f"shapes {S.shape} and {D.shape}",
                                 "must both be (N, 2) or both (N, 3)")  # fmt: skip
        if not (np.isfinite(S).all() and np.isfinite(D).all()):
            raise ParameterError("ray starts and directions", "non-finite values", "must be finite")
        norm = np.sqrt((D * D).sum(axis=1))
        if (norm == 0).any():
            i = int(np.argmax(norm == 0))
            raise ParameterError("ray direction", D[i].tolist(), "must not be zero")
        D = D / norm[:, None]
        inside = self.contains(S[:, :2])
        if not np.all(inside):
            i = int(np.argmin(inside))
            raise OutsideWorkspaceError(S[i], self._why_outside(S[i, :2]))
        n = len(S)
        best = np.full(n, np.inf)
        which = np.full(n, -2, dtype=np.int64)
        sx, sy = S[:, 0], S[:, 1]
        dx, dy = D[:, 0], D[:, 1]
        plan = np.hypot(dx, dy)  # |d_xy|: u = w / |d_xy| with w the plan distance
        moving = plan > 1e-150
        plan_safe = np.where(moving, plan, 1.0)
        ex, ey = dx / plan_safe, dy / plan_safe  # unit plan direction
        cx_all, cy_all, R_all, st_all, sw_all, sgn_all = self._arc_arrays
        for k in range(len(self.arcs)):
            cx, cy, R, st, sw, sgn = cx_all[k], cy_all[k], R_all[k], st_all[k], sw_all[k], sgn_all[k]
            ox, oy = sx - cx, sy - cy
            # w^2 + 2 b w + c = 0 with b = o.e, c = |o|^2 - R^2 and b^2 - c = R^2 - p^2, p = |o x e| the
            # miss distance: both factored so that grazing rays and starts near the circle keep their digits
            b = ox * ex + oy * ey
            rho = np.hypot(ox, oy)
            c = (rho - R) * (rho + R)
            miss = np.abs(ox * ey - oy * ex)
            disc = (R - miss) * (R + miss)
            hit = moving & (disc >= 0.0)
            root = np.sqrt(np.where(hit, disc, 0.0))
            qq = -(b + np.copysign(root, b))  # stable roots: qq and c / qq
            qq_safe = np.where(qq == 0.0, 1.0, qq)
            u1 = qq / plan_safe
            u2 = np.where(qq == 0.0, 0.0, c / qq_safe) / plan_safe
            tol_ang = EDGE_TOL / R
            for u in (u1, u2):
                hx, hy = ox + u * dx, oy + u * dy
                rel = np.mod(np.arctan2(hy, hx) - st, _TWO_PI)
                on_arc = hit & ((rel <= sw + tol_ang) | (rel >= _TWO_PI - tol_ang))
                ahead = on_arc & (u > EDGE_TOL) & (u < best)
                best = np.where(ahead, u, best)
                which = np.where(ahead, k, which)
            # a start on the edge (within EDGE_TOL of this arc): stop at 0 when the direction leaves the
            # region across the arc (a tangent direction leaves across an arc with the region inside only)
            rel = np.mod(np.arctan2(oy, ox) - st, _TWO_PI)
            on_edge = (np.abs(np.hypot(ox, oy) - R) <= EDGE_TOL) & ((rel <= sw + tol_ang) | (rel >= _TWO_PI - tol_ang))
            leaving = on_edge & (sgn * (ox * dx + oy * dy + sgn * 1e-12 * R) > 0.0)
            best = np.where(leaving, 0.0, best)
            which = np.where(leaving, k, which)
        if S.shape[1] == 3:
            z_lo, z_hi = self.z_range
            z = S[:, 2]
            if ((z < z_lo - EDGE_TOL) | (z > z_hi + EDGE_TOL)).any():
                i = int(np.argmax((z < z_lo - EDGE_TOL) | (z > z_hi + EDGE_TOL)))
                quill = self.geometry.names[self.geometry.prismatic]
                raise OutsideWorkspaceError(S[i], f"z = {z[i]:.9g} m is outside {quill}'s stroke "
                                                  f"[{z_lo:.9g}, {z_hi:.9g}] m")  # fmt: skip
            dz = D[:, 2]
            with np.errstate(divide="ignore", invalid="ignore"):
                uz = np.where(dz > 0, (z_hi - z) / dz, np.where(dz < 0, (z_lo - z) / dz, np.inf))
            uz = np.maximum(uz, 0.0)
            zstop = uz < best
            best = np.where(zstop, uz, best)
            which = np.where(zstop, np.where(dz > 0, -1, -3), which)  # -1: upper end, -3: lower end
        if not np.isfinite(best).all():  # cannot happen for a bounded region and a nonzero direction
            i = int(np.argmax(~np.isfinite(best)))
            raise InvalidInputError(f"the ray from {S[i].tolist()} along {D[i].tolist()} meets no edge")
        points = S + best[:, None] * D
        kinds = np.array([a.limit.value for a in self.arcs] + [self._z_limits[0].value, self._z_limits[1].value])
        limit = kinds[np.where(which >= 0, which, np.where(which == -1, len(self.arcs) + 1, len(self.arcs)))]
        return RayBatch(points, best, np.where(which >= 0, which, -1), limit)

    def _z_description(self, limit: Limit) -> str:
        name = self.geometry.names[self.geometry.prismatic]
        at_top = limit is self._z_limits[1]
        z = self.z_range[1] if at_top else self.z_range[0]
        side = "upper" if limit is Limit.J3_UPPER else "lower"
        return f"{name} at the {side} end of its stroke ({'top' if at_top else 'bottom'}: z = {z:.6g} m)"

    def _why_outside(self, xy: np.ndarray) -> str:
        a1, l12 = self._box.origin, self._box.arm.l12
        r = math.hypot(xy[0] - self.offset[0] - a1[0], xy[1] - self.offset[1] - a1[1])
        if r > l12:
            return f"r = {r:.9g} m from the shoulder axis is beyond the reach l1 + l2 = {l12:.9g} m"
        if r < self.r_min:
            return f"r = {r:.9g} m from the shoulder axis is inside the inner limit r_min = {self.r_min:.9g} m"
        g = self.geometry
        return (f"no {g.names[g.revolute[0]]}/{g.names[g.revolute[1]]} values within their limits reach it "
                f"(r = {r:.9g} m is within [{self.r_min:.9g}, {self.r_max:.9g}] m)")  # fmt: skip

    # --------------------------------------------------------------------------------- export
    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready description (arcs, loops, area, radii, z range)."""
        return {
            "point": "wrist axis" if self.yaw is None else f"tool point at yaw {self.yaw:.9g} rad",
            "offset": list(self.offset),
            "area": self.area,
            "r_min": self.r_min,
            "r_max": self.r_max,
            "z_range": list(self.z_range),
            "arcs": [a.to_dict() for a in self.arcs],
            "loops": [list(loop) for loop in self.loops],
            "note": self.note,
        }


# ------------------------------------------------------------------------------------------ building
def workspace(
    robot: RobotModel | ScaraGeometry,
    *,
    lower: Sequence[float] | None = None,
    upper: Sequence[float] | None = None,
    yaw: float | None = None,
) -> Workspace:
    """Build the exact workspace of a robot.

    Args:
        robot: a :class:`~scara_pin.model.RobotModel` or its :class:`~scara_pin.kinematics.scara.ScaraGeometry`
            (a 3-joint SCARA: the region of its tool point; ``lower``/``upper`` then take 3 values, no yaw).
        lower: lower joint limits in q order replacing the model's (e.g. a software range) [rad, m].
        upper: upper joint limits in q order replacing the model's [rad, m].
        yaw: a fixed tool yaw [rad]: the region is then the tool point's at that yaw (needs J4 to span at
            least 2 pi when the tool is offset from the wrist axis). None: the wrist axis point.

    Returns:
        Workspace.

    Raises:
        ParameterError: limits that are not ordered or not numbers, J1 or J2 limits that leave no range,
            or a yaw with J4 limited to less than a turn and a tool offset.
    """
    geo = robot if isinstance(robot, ScaraGeometry) else robot.kinematics.geometry
    if not isinstance(robot, ScaraGeometry) and robot.dof == 3:  # the virtual wrist (index 3) turns freely
        if yaw is not None:
            raise InvalidInputError("a SCARA without a wrist cannot hold a yaw: its workspace is the tool point's")
        lower = None if lower is None else ([*lower, -math.inf] if len(lower) == 3 else lower)
        upper = None if upper is None else ([*upper, math.inf] if len(upper) == 3 else upper)
    if lower is not None or upper is not None:
        lo = tuple(float(v) for v in (geo.lower if lower is None else lower))
        hi = tuple(float(v) for v in (geo.upper if upper is None else upper))
        if len(lo) != len(geo.lower) or len(hi) != len(geo.upper):
            raise ParameterError("joint limits", f"{len(lo)} and {len(hi)} values", f"must have {len(geo.lower)}")
        # an infinite limit is a joint that turns without end: continuous
        cont = tuple(c or not (math.isfinite(a) and math.isfinite(b)) for c, a, b in zip(geo.continuous, lo, hi))
        if any(math.isnan(v) for v in lo + hi):
            raise ParameterError("joint limits", (lo, hi), "must be numbers")
        geo = replace(geo, lower=lo, upper=hi, continuous=cont)
    for i, name in enumerate(geo.names):
        if math.isnan(geo.lower[i]) or math.isnan(geo.upper[i]) or geo.lower[i] > geo.upper[i]:
            limits = (geo.lower[i], geo.upper[i])
            raise ParameterError(f"limits of {name}", limits, "must be numbers with lower <= upper")
    for i in geo.revolute[:2]:
        if not geo.upper[i] > geo.lower[i]:
            limits = (geo.lower[i], geo.upper[i])
            raise ParameterError(f"limits of {geo.names[i]}", limits, "must span a range (else the region has no area)")
    offset = (0.0, 0.0)
    if yaw is not None and not math.isfinite(yaw):
        raise ParameterError("yaw", yaw, "must be a finite number", "rad")
    note = wrist_tilt_note(geo)
    if yaw is not None and note is not None and math.hypot(*geo.tool) > TOOL_ON_AXIS:
        raise InvalidInputError(f"no fixed-yaw region of the tool point: {note}")
    if yaw is not None and math.hypot(*geo.tool) > 0.0:
        rc = geo.revolute[2]
        if not geo.upper[rc] - geo.lower[rc] >= _TWO_PI:
            raise ParameterError(
                f"range of {geo.names[rc]}", geo.upper[rc] - geo.lower[rc],
                "must span at least 2 pi for a fixed-yaw tool point region (the J4 limit would cut it)", "rad",
            )  # fmt: skip
        al = float(yaw) - geo.yaw0
        tx, ty = geo.tool
        offset = (math.cos(al) * tx - math.sin(al) * ty, math.sin(al) * tx + math.cos(al) * ty)
    box = _box(geo)
    region = box_region(box, _labels(geo))
    arcs = [Arc(a.center, a.radius, a.start, a.sweep, a.label[0], a.label[1], a.region_inside) for a in region.arcs]
    if offset != (0.0, 0.0):  # a translation: the loops and the area stay
        arcs = [replace(a, center=(a.center[0] + offset[0], a.center[1] + offset[1])) for a in arcs]
    # (radius_range() needs finite elbow limits; a full elbow turn reaches every radius of the annulus)
    r_min, r_max = (box.arm.d12, box.arm.l12) if box.second.full else geo.radius_range()
    ip = geo.prismatic
    zs = sorted((geo.z0 + geo.signs[ip] * geo.lower[ip], geo.z0 + geo.signs[ip] * geo.upper[ip]))
    return Workspace(geometry=geo, arcs=tuple(arcs), loops=region.loops, area=region.area, r_min=r_min, r_max=r_max,
                     z_range=(zs[0], zs[1]), offset=offset, yaw=yaw, note=note)  # fmt: skip


TOOL_ON_AXIS = 1e-9
"""[m] a tool point this close to the wrist axis (plan view) lies on it."""


def wrist_tilt_note(geo: ScaraGeometry) -> str | None:
    """What a wrist-only tilt (beyond NEAR_PARALLEL_TOL) changes in the workspace; None without one.

    The joints that carry the wrist point are (near-)vertical, so the region of the point of the wrist axis at
    the tool's height does not depend on the wrist: it is the region computed. A tool point on that axis has
    this region exactly; off it by d, it circles the axis in a plane tilted by the wrist's tilt tau (its height
    varies by +/- d sin tau as the wrist turns), so no fixed-yaw region of it is given.
    """
    tau = geo.wrist_tilt
    if tau <= NEAR_PARALLEL_TOL:
        return None
    name = geo.names[geo.revolute[2]]
    d = math.hypot(*geo.tool)
    head = (f"{name}'s axis is {math.degrees(tau):.3g} deg ({tau:.3g} rad) from vertical (the wrist alone): the "
            f"region is that of the point of {name}'s axis at the tool's height, which {name} does not "
            "move")  # fmt: skip
    if d <= TOOL_ON_AXIS:
        return f"{head}; the tool point lies on that axis: it is the tool point's region ({name} only tilts the tool)"
    return (f"{head}; the tool point is {d:.4g} m off that axis and circles it in a plane tilted by "
            f"{math.degrees(tau):.3g} deg (its height varies by +/-{d * math.sin(tau) * 1000:.3g} mm as {name} turns): "
            "a fixed-yaw region of the tool point is not given")  # fmt: skip


def _labels(geo: ScaraGeometry) -> dict[Role, tuple[tuple[Limit, str], int]]:
    """Each candidate role's (Limit, description) and rank: the joint limit it is, named in q (not angle) terms.

    An axis pointing down (sign -1) turns the lower end of the angle range into the joint's upper limit.
    """
    ra, rb = geo.revolute[0], geo.revolute[1]
    n1, n2 = geo.names[ra], geo.names[rb]
    out: dict[Role, tuple[tuple[Limit, str], int]] = {}
    for j, roles, limits, other in ((ra, (Role.FIRST_LO, Role.FIRST_HI), (Limit.J1_LOWER, Limit.J1_UPPER), n2),
                                    (rb, (Role.SECOND_LO, Role.SECOND_HI), (Limit.J2_LOWER, Limit.J2_UPPER), n1)):
        for role, lower_q in zip(roles, (geo.signs[j] > 0, geo.signs[j] < 0), strict=True):
            limit = limits[0] if lower_q else limits[1]
            deg = math.degrees(geo.lower[j] if lower_q else geo.upper[j])
            text = f"{geo.names[j]} at its {'lower' if lower_q else 'upper'} limit {deg:.6g} deg, {other} sweeping"
            out[role] = ((limit, text), _PRIORITY[limit])
    out[Role.STRETCHED] = ((Limit.OUTER, f"outer: arm stretched ({n2} at elbow angle 0), {n1} sweeping"),
                           _PRIORITY[Limit.OUTER])
    out[Role.FOLDED] = ((Limit.FOLDED, f"inner: arm folded ({n2} at elbow angle 180 deg), {n1} sweeping"),
                        _PRIORITY[Limit.FOLDED])
    return out  # fmt: skip


# ------------------------------------------------------------------------------------------ picture
def plot_workspace(
    ws: Workspace,
    path: str | os.PathLike[str] | None = None,
    *,
    q: Sequence[float] | None = None,
    ray: tuple[Sequence[float], Sequence[float]] | None = None,
    units: DisplayUnits = SI,
    robot_name: str | None = None,
    dpi: int = 120,
    arm: bool = True,
) -> Figure:
    """The region in plan view: filled, arcs coloured by their limit, the arm at ``q``, a ray and its hit.

    Args:
        ws: the workspace.
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        q: a joint configuration (q order) to draw the arm at; default the limits' midpoints (finite ones).
        ray: (start, direction) of a ray to draw with its edge point [m].
        units: the length unit of the axes (``DisplayUnits("mm")`` for millimetres).
        robot_name: named in the title.
        dpi: resolution of a written PNG.
        arm: draw the arm (at ``q``).

    Returns:
        the matplotlib Figure.
    """
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MPath
    from matplotlib.ticker import FuncFormatter

    from ..files import finish, new_figure  # object-oriented: no pyplot; written atomically

    colours = {Limit.OUTER: "tab:blue", Limit.FOLDED: "tab:purple", Limit.J1_LOWER: "tab:red",
               Limit.J1_UPPER: "tab:orange", Limit.J2_LOWER: "tab:green", Limit.J2_UPPER: "tab:olive"}  # fmt: skip
    fig = new_figure(7, 7, layout=None)
    ax = fig.add_subplot()
    L, n = units.scale("length"), units.name("length")
    verts: list[np.ndarray] = []
    codes: list[int] = []
    for loop in ws.loops:
        pts = []
        for i in loop:
            a = ws.arcs[i]
            seg = a.points(max(8, int(a.sweep * 90)))
            pts.append(seg if a.region_inside else seg[::-1])
        v = np.vstack(pts)
        verts.append(v)
        codes += [int(MPath.MOVETO)] + [int(MPath.LINETO)] * (len(v) - 2) + [int(MPath.CLOSEPOLY)]
    if verts:
        ax.add_patch(PathPatch(MPath(np.vstack(verts), codes), facecolor="lightsteelblue", alpha=0.5, lw=0))
    seen: set[Limit] = set()
    for a in ws.arcs:
        xy = a.points(max(8, int(a.sweep * 90)))
        ax.plot(xy[:, 0], xy[:, 1], color=colours[a.limit], lw=2.0,
                label=a.description if a.limit not in seen else None)  # fmt: skip
        seen.add(a.limit)
    geo = ws.geometry
    if q is None:
        q = [0.5 * (lo + hi) if math.isfinite(lo + hi) else 0.0 for lo, hi in zip(geo.lower, geo.upper)]
    ra, rb = geo.revolute[0], geo.revolute[1]
    theta = geo.signs[ra] * q[ra] + geo.beta1
    gamma = geo.elbow_angle(q[rb])
    a1 = np.array(geo.a1)
    elbow = a1 + geo.l1 * np.array([math.cos(theta), math.sin(theta)])
    wrist = elbow + geo.l2 * np.array([math.cos(theta + gamma), math.sin(theta + gamma)])
    if arm:
        links = np.vstack((a1, elbow, wrist))
        ax.plot(links[:, 0], links[:, 1], "-o", color="black", lw=3, ms=6, label="arm")
    if arm and ws.offset != (0.0, 0.0):  # the tool point at the region's yaw
        tool = wrist + np.array(ws.offset)
        ax.plot([wrist[0], tool[0]], [wrist[1], tool[1]], "-", color="dimgray", lw=2, label="tool offset")
    if ray is not None:
        start, direction = ray
        hit = ws.ray(start[:2], direction[:2])
        ax.plot([start[0], hit.point[0]], [start[1], hit.point[1]], "--", color="crimson", lw=1.5,
                label=f"ray: {hit.distance * L:.4g} {n} to {hit.limit.value}")  # fmt: skip
        ax.plot(*hit.point[:2], "x", color="crimson", ms=10, mew=2)
        ax.plot(start[0], start[1], "o", color="crimson", ms=5)
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.grid(alpha=0.3)
    # drawn in metres; the ticks read in the unit chosen (m or mm: a power of ten keeps them round)
    ticks = FuncFormatter(lambda v, _: f"{v * L:.6g}")
    ax.xaxis.set_major_formatter(ticks)
    ax.yaxis.set_major_formatter(ticks)
    ax.set_xlabel(f"x [{n}] (base frame)")
    ax.set_ylabel(f"y [{n}]")
    head = f"{robot_name}: " if robot_name else ""
    area = format_number(ws.area * L * L, decimals_for(L * L, 1e-6))  # to 1 mm^2 and 1 um
    radii = ", ".join(format_number(r * L, decimals_for(L, 1e-6)) for r in (ws.r_min, ws.r_max))
    ax.set_title(f"{head}reachable region of the wrist axis\narea {area} {n}$^2$, r in [{radii}] {n}")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=2, fontsize=7, framealpha=0.8)
    return finish(fig, path, dpi, bbox_inches="tight")
