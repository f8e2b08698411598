"""A robot moving in its cell: where a path first comes to the margin, and which of many configurations are clear.

Both rest on shapes that hold each geometry of the scene (the robot's links, the carried part, the
obstacles), fixed to its joint and made from coal's local bounding box: a SPHERE (centre ``c``, radius
``rho``: the box's half-diagonal) and a CAPSULE (a segment along the box's longest side, the radius of its
cross-section's diagonal).

**Clear configurations** (:func:`clear_mask`): every joint placed at every configuration at once
(:func:`joint_placements`: the robot's symbolic model evaluated on numbers), then, pair by pair, a pair whose
capsules are more than the margin apart (segment distance minus both radii, :func:`segment_distance`) is clear
without asking coal; every other pair's exact distance is coal's
(:meth:`Scene.distance_array <scara_pin.cell.Scene.distance_array>`). A configuration is clear when every checked
pair is at least the margin apart.

**First contact along a path** (:func:`first_contact`): a joint path ``q(s)``, ``s`` in [0, 1], with its
derivative ``q'(s)``. A point p of a geometry moves, per unit of s, at

    |dp/ds| = |sum_i q'_i (v_i + w_i x p)| <= sum_i |q'_i| (|v_i + w_i x c| + |w_i| (rho + e)),

(v_i, w_i) the world Jacobian's column of joint i at the world origin, the sum over the joints that carry the
geometry, and ``e`` how far the sphere's centre moves during the step (at most the gap, below). A pair's
distance then changes at most at ``V`` = the sum of its two shapes' bounds (an obstacle does not move), so
while its gap to the margin is ``g``, the step ``ds = g / V`` cannot bring it below the margin: conservative
advancement. The steps shrink as the gap closes (geometrically, when the pair approaches head-on); the
first ``s`` where a pair reaches the margin is then bracketed (a probe a little beyond the step, predicted from
the closest pair's rate of approach, :meth:`Scene.gradients <scara_pin.cell.Scene.gradients>`) and found by
bisection on coal's distance until the gap at the stop is in [0, :data:`CONTACT_TOL`] m.

The bound holds for the q' of the start of each step; a step after which the bound grew by more than
:data:`BOUND_GROWTH` is kept only if every pair's gap also allows it at the larger of its bounds at the step's two
ends, else taken again at half the length, so a path whose q' changes fast (near a singularity, or at the
corners of a joint polyline) is followed in small steps where a pair is near.

**Starting at the margin.** Conservative advancement cannot follow a pair that starts AT the margin and does
not approach (a jog that stopped at a post, then moves along it or turns the flange beside it): its steps are
its gap over its speed, and the gap stays about zero (a vertical move beside a vertical post keeps it exactly
constant), so the steps shrink to nothing. A pair that starts less than :data:`SLIDE_BAND` above the margin is
therefore followed by samples instead: its steps are :data:`SLIDE_STEP` of its shapes' motion (its speed bound
times the step, the bound taken at the first of up to 256 samples evaluated at once and checked at the last as
above, within :data:`BOUND_GROWTH` of it), its exact distance checked at every one (a sample below the margin is
bisected as above), until it is :data:`SLIDE_BAND` clear; from then on it is followed conservatively like every
other pair. The samples go as far as the other pairs' conservative steps allow, so these are still followed
without a gap. Between two samples at or above the margin, a distance that changes at most at its speed bound
is at least the margin less half the motion between them, ``BOUND_GROWTH * SLIDE_STEP / 2`` = 22 micrometres:
what a jog certifies for a pair it starts at the margin (every other pair, and this one once clear, keeps the
whole margin). A finer step would certify less slack at the price of more samples: 1.6 um (the verifier's 1e-6 m)
took 100,000 distance queries for a jog of 45 mm and a turn of 3 rad beside a post, 6.5 s.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import coal
import numpy as np

from ..errors import ScaraError

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from .scene import PairDistance, Scene

__all__ = [
    "BOUND_GROWTH",
    "BoundingShapes",
    "CONTACT_TOL",
    "MAX_STEPS",
    "SLIDE_BAND",
    "SLIDE_STEP",
    "Contact",
    "JointPath",
    "clear_mask",
    "pair_masks",
    "first_contact",
    "bounding_shapes",
    "geometry_speeds",
    "joint_motion",
    "joint_placements",
    "pair_joints",
    "segment_distance",
]

CONTACT_TOL = 1e-9
"""[m] the gap to the margin left at a contact found by :func:`first_contact` (the stop is clear by 0 to this)."""
BOUND_GROWTH = 1.1
"""A step is taken again at half its length when the speed bound at its end exceeds the start's by this factor."""
MAX_STEPS = 200_000
"""Conservative steps along one path before giving up (an internal error: the bound is never that slow)."""
SLIDE_BAND = 1e-4
"""[m] a pair that starts less than this above the margin is followed by samples until it is this clear (module
docstring: "Starting at the margin")."""
SLIDE_STEP = 4e-5
"""[m] the samples of such a pair: at most this much motion of its shapes between two (by its speed bound), so that
it is certified within ``BOUND_GROWTH * SLIDE_STEP / 2`` = 22 um of the margin between them (module docstring)."""
_BATCH = 256
"""Samples of a pair at the margin taken at once (one path evaluation, one distance query per sample)."""
_SAFETY = 0.9
"""The fraction of the conservative step taken (rounding, and q' changing within the step)."""
_MIN_STEP = 1e-15
"""The smallest step in s [-] (below, the path parameter's rounding)."""


class JointPath(Protocol):
    """A joint path ``q(s)``, ``s`` in [0, 1]: ``GeometricPath`` of ``scara_pin.motion.paths`` is one."""

    def evaluate(self, s: np.ndarray, order: int = 2) -> tuple[np.ndarray, ...]:
        """(q, q', ...) at the parameters ``s`` (1-D), each (n, dof)."""
        ...


@dataclass(frozen=True)
class Contact:
    """Where a path first comes to the cell's margin.

    Attributes:
        s: the path parameter of the stop (every pair at least the margin apart on [0, s]).
        q: the configuration there.
        closest: the pair that comes to the margin there (its distance within :data:`CONTACT_TOL` above the margin):
            of the pairs below the margin just beyond, the closest. Another pair may be as close (one that slides
            along an obstacle at the margin), but it is not what stops the path.
    """

    s: float
    q: np.ndarray
    closest: PairDistance

    @property
    def stop_text(self) -> str:
        """``post (link2)``: what the robot stopped at, and the robot's shape that came to it."""
        pair = self.closest.pair
        return f"{pair.b} ({pair.a})"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"s": self.s, "q": self.q.tolist(), **self.closest.to_dict()}


@dataclass(frozen=True, eq=False)
class BoundingShapes:
    """Shapes that hold each geometry of a scene, in its joint's frame (the world's for joint 0).

    Per geometry (index into the scene's ``GeometryModel``): its joint, a bounding sphere (centre, radius) and a
    bounding capsule (segment ends, radius), both from coal's local bounding box: the sphere around the box, the
    capsule along its longest side with the radius of its cross-section's diagonal (a cylinder's or a
    sphere's own axis and radius); and that box itself, centred on the sphere's centre (a tighter bound than the
    sphere or the capsule for a long thin table or wall, a flat flange under an arm).
    """

    joint: np.ndarray  # (g,)
    center: np.ndarray  # (g, 3)
    radius: np.ndarray  # (g,)
    end0: np.ndarray  # (g, 3)
    end1: np.ndarray  # (g, 3)
    capsule: np.ndarray  # (g,)
    box_rotation: np.ndarray  # (g, 3, 3): the local bounding box's axes, in the joint's frame (its centre: center)
    box_half: np.ndarray  # (g, 3): its half sides

    @property
    def moving(self) -> np.ndarray:
        """The indices of the geometries on a joint (not fixed to the world)."""
        return np.flatnonzero(self.joint > 0)


_BOUNDS: weakref.WeakKeyDictionary[Scene, BoundingShapes] = weakref.WeakKeyDictionary()
"""Each scene's bounding shapes, made once."""


def bounding_shapes(scene: Scene) -> BoundingShapes:
    """The scene's bounding sphere and capsule of each geometry (:class:`BoundingShapes`), made once per scene."""
    cached = _BOUNDS.get(scene)
    if cached is not None:
        return cached
    gm = scene.geometry_model
    joint, center, radius, end0, end1, capsule, box_r = [], [], [], [], [], [], []
    half_sides = []
    for g in gm.geometryObjects:
        geometry = g.geometry
        geometry.computeLocalAABB()
        lo, hi = np.asarray(geometry.aabb_local.min_, float), np.asarray(geometry.aabb_local.max_, float)
        mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        k = int(np.argmax(half))
        along = np.zeros(3)
        along[k] = half[k]
        around = float(np.linalg.norm(np.delete(half, k)))
        if isinstance(geometry, (coal.Cylinder, coal.Capsule)):  # exactly: its axis and radius
            along, around = np.array([0.0, 0.0, float(geometry.halfLength)]), float(geometry.radius)
        elif isinstance(geometry, coal.Sphere):
            along, around = np.zeros(3), float(geometry.radius)
        M = g.placement  # geometry in its joint's frame (joint 0: the world)
        joint.append(int(g.parentJoint))
        center.append(M.act(mid))
        radius.append(float(np.linalg.norm(half)))
        end0.append(M.act(mid - along))
        end1.append(M.act(mid + along))
        capsule.append(around)
        box_r.append(np.asarray(M.rotation, dtype=float))
        half_sides.append(half)
    out = BoundingShapes(np.array(joint, dtype=int), np.array(center).reshape(-1, 3), np.array(radius),
                         np.array(end0).reshape(-1, 3), np.array(end1).reshape(-1, 3), np.array(capsule),
                         np.array(box_r).reshape(-1, 3, 3), np.array(half_sides).reshape(-1, 3))  # fmt: skip
    _BOUNDS[scene] = out
    return out


# ---------------------------------------------------------------------------------------------- many configurations
def clear_mask(scene: Scene, Q: ArrayLike, pairs: list[int] | None = None, margin: float | None = None) -> np.ndarray:
    """(n,) whether each configuration (row of ``Q``) has every checked pair at least the margin apart.

    Pairs whose bounding spheres, capsules or boxes are farther apart than the margin are clear without a distance
    query (:func:`pair_masks`); the others get coal's exact distance, pair by pair, and a configuration already
    found in collision is not asked again. ``pairs``: only these (indices; default every checked pair);
    ``margin``: another distance than the cell's.
    """
    return np.asarray(pair_masks(scene, Q, pairs, margin, want_bound=False)[0].all(axis=1))


def pair_masks(scene: Scene, Q: ArrayLike, pairs: list[int] | None = None, margin: float | None = None,
               exact: bool = True, want_bound: bool = True) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """(closed (n, k) bool, bound (n, k)): which pair first closes each configuration, and a bound of each distance.

    ``closed[i, k]`` is False where pair k is the first of ``pairs`` found closer than the margin at row i (a row
    already closed is not asked again: its later pairs stay True); ``bound[i, k]`` is a lower bound of pair k's
    distance there, its bounding capsules' (each capsule holds its shape).

    The joint placements are computed once for all the pairs, and only for the geometries they name (an
    obstacle's are fixed); the spheres, the capsules, then the boxes (``_boxes_apart``) spare the exact distance
    where they are apart, and each
    configuration asks coal for its candidate pairs in turn (one placement of the geometries per configuration). A
    pair of two shapes fixed to the world (the robot's base and an obstacle) is asked once: its distance is the
    same at every configuration (a sleeve around the base column, a mesh, cost 0.65 ms a configuration:
    ``workspace --cell`` ran past 400 s). A mesh's bounding box is among the filters: near a surface mesh, coal's
    tree costs up to a few ms a query inside its box, where its capsule bounds it poorly (a sleeve's capsule fills
    the sleeve's hole).
    ``exact=False``: the bound only (the masks all True); ``want_bound=False``: the masks only (the bound +inf).
    """
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n = len(Q)
    chosen = list(scene.pairs) if pairs is None else [scene.pairs[k] for k in pairs]
    masks = np.ones((n, len(chosen)), dtype=bool)
    bound = np.full((n, len(chosen)), np.inf)
    if not chosen or n == 0:
        return masks, bound
    b = bounding_shapes(scene)
    used = sorted({p.first for p in chosen} | {p.second for p in chosen})
    slot = {g: k for k, g in enumerate(used)}
    joint = b.joint[used]
    shape = (n, len(used), 3)
    c, e0, e1 = (np.broadcast_to(x[used], shape).copy() for x in (b.center, b.end0, b.end1))
    axes = np.broadcast_to(b.box_rotation[used], (n, len(used), 3, 3)).copy() if exact else None
    moving = np.flatnonzero(joint > 0)
    if moving.size:
        R, p = joint_placements(scene.robot, Q)
        Rg, pg = R[:, joint[moving]], p[:, joint[moving]]  # (n, m, 3, 3), (n, m, 3)
        for x, local in ((c, b.center), (e0, b.end0), (e1, b.end1)):
            x[:, moving] = np.einsum("ngab,gb->nga", Rg, local[np.asarray(used)[moving]]) + pg
        if axes is not None:
            axes[:, moving] = Rg @ b.box_rotation[np.asarray(used)[moving]]
    margin = scene.margin if margin is None else margin
    ia = np.array([slot[p.first] for p in chosen])
    ib = np.array([slot[p.second] for p in chosen])
    gi, gj = np.array([p.first for p in chosen]), np.array([p.second for p in chosen])
    near = np.ones((n, len(chosen)), dtype=bool)
    if exact:  # the spheres first (cheap): where they are apart, so is the pair
        reach = b.radius[gi] + b.radius[gj] + margin
        d = c[:, ia] - c[:, ib]
        near = np.einsum("nka,nka->nk", d, d) <= reach * reach
    wanted = np.ones_like(near) if not exact or want_bound else near
    rows, cols = np.nonzero(wanted)
    gap = np.full((n, len(chosen)), np.inf)
    gap[rows, cols] = (segment_distance(e0[rows, ia[cols]], e1[rows, ia[cols]], e0[rows, ib[cols]], e1[rows, ib[cols]])
                       - b.capsule[gi[cols]] - b.capsule[gj[cols]])  # fmt: skip
    if not exact or want_bound:
        bound = gap
    if axes is not None:
        near &= gap <= margin
        r, k = np.nonzero(near)  # then the boxes, each grown by the margin: separated on an axis, apart
        apart = _boxes_apart(axes[r, ia[k]], c[r, ia[k]], b.box_half[gi[k]], axes[r, ib[k]], c[r, ib[k]],
                             b.box_half[gj[k]], margin)  # fmt: skip
        near[r[apart], k[apart]] = False
        # a pair of two world-fixed shapes (the robot's base and an obstacle): the same at every configuration, asked
        # once, and only when the filters leave it near
        fixed = np.flatnonzero((b.joint[gi] == 0) & (b.joint[gj] == 0))
        fixed_near = [int(k) for k in fixed if near[0, k]]
        near[:, fixed] = False
        first = scene.first_closer(Q, [p.index for p in chosen], near, margin)
        closed = [k for k in fixed_near if scene.distance_array(Q[:1], pairs=[chosen[k].index])[0, 0] < margin]
        if closed:
            first = np.where((first < 0) | (first > closed[0]), closed[0], first)
        hit = np.flatnonzero(first >= 0)
        masks[hit, first[hit]] = False
    return masks, bound


def _boxes_apart(Ra: np.ndarray, ca: np.ndarray, ha: np.ndarray, Rb: np.ndarray, cb: np.ndarray, hb: np.ndarray,
                 margin: float) -> np.ndarray:  # fmt: skip
    """(m,) whether boxes a and b are certainly farther apart than ``margin``; False means "perhaps closer".

    The boxes: axes as columns of R (m, 3, 3), centres c (m, 3), half sides h (m, 3). Apart when separated along
    one of the 15 axes of the separating-axis test with each projection grown by the margin's (``margin |L|``).
    """
    t = cb - ca
    out = np.zeros(len(t), dtype=bool)
    faces = [Ra[:, :, i] for i in range(3)] + [Rb[:, :, i] for i in range(3)]
    edges = [(i, j) for i in range(3) for j in range(3)]
    for L in faces + edges:  # the faces' axes first (most pairs part there), then the edges' on the rest
        rest = np.flatnonzero(~out)
        if not rest.size:
            break
        A, B, h, g, tt = Ra[rest], Rb[rest], ha[rest], hb[rest], t[rest]
        axis = L[rest] if isinstance(L, np.ndarray) else np.cross(A[:, :, L[0]], B[:, :, L[1]])
        ra = np.sum(h * np.abs(np.einsum("mai,ma->mi", A, axis)), axis=1)
        rb = np.sum(g * np.abs(np.einsum("mai,ma->mi", B, axis)), axis=1)
        grown = ra + rb + margin * np.linalg.norm(axis, axis=1) + 1e-12
        out[rest] = np.abs(np.einsum("ma,ma->m", tt, axis)) > grown
    return out


def segment_distance(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray) -> np.ndarray:
    """(n,) distances between segments a0-a1 and b0-b1 (each (n, 3)); a segment may be a point.

    The closest points' parameters (s, t) in [0, 1]^2 by the usual clamped solution (Ericson, *Real-Time
    Collision Detection*, 5.1.9), vectorised.
    """
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    f = np.einsum("ij,ij->i", d2, r)
    c = np.einsum("ij,ij->i", d1, r)
    bb = np.einsum("ij,ij->i", d1, d2)
    tiny = 1e-300
    denom = a * e - bb * bb
    safe_a, safe_e = np.where(a > tiny, a, 1.0), np.where(e > tiny, e, 1.0)
    parallel = denom <= 1e-14 * np.maximum(a * e, tiny)
    s = np.where(parallel | (a <= tiny), 0.0, np.clip((bb * f - c * e) / np.where(parallel, 1.0, denom), 0.0, 1.0))
    t = np.where(e > tiny, (bb * s + f) / safe_e, 0.0)
    low = (t < 0.0) | (e <= tiny)
    high = (t > 1.0) & (e > tiny)
    s = np.where(low, np.where(a > tiny, np.clip(-c / safe_a, 0.0, 1.0), 0.0), s)
    s = np.where(high, np.where(a > tiny, np.clip((bb - c) / safe_a, 0.0, 1.0), 0.0), s)
    t = np.where(low, 0.0, np.where(high, 1.0, t))
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(a0 + d1 * s[:, None] - b0 - d2 * t[:, None], axis=1)  # type: ignore[no-any-return]


_AXIS = {"X": np.array([1.0, 0.0, 0.0]), "Y": np.array([0.0, 1.0, 0.0]), "Z": np.array([0.0, 0.0, 1.0])}
_REVOLUTE = {f"JointModel{k}{a}": a for k in ("R", "RUB") for a in "XYZ"}
_PRISMATIC = {f"JointModelP{a}": a for a in "XYZ"}


def joint_motion(joint: Any) -> tuple[str, np.ndarray] | None:
    """("R" or "P", the unit axis in the joint's frame) of a Pinocchio joint of one degree of freedom, or None."""
    name = joint.shortname()
    if name in _REVOLUTE:
        return "R", _AXIS[_REVOLUTE[name]]
    if name in _PRISMATIC:
        return "P", _AXIS[_PRISMATIC[name]]
    if name in ("JointModelRevoluteUnaligned", "JointModelRevoluteUnboundedUnaligned", "JointModelPrismaticUnaligned"):
        axis = np.asarray(joint.extract().axis, dtype=float)
        return ("P" if "Prismatic" in name else "R"), axis / np.linalg.norm(axis)
    return None


def joint_placements(robot: Any, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every joint's placement in the world at each row of ``Q``: (R (n, njoints, 3, 3), p (n, njoints, 3)).

    Pinocchio's ``oMi`` at every row in one call: the robot's symbolic model (:mod:`scara_pin.symbolic`, built
    from the loaded Pinocchio model, mimic joints included) evaluated on numbers, ``joint_frames.map(n)``.
    """
    from ..symbolic import frames_at, symbolic_model

    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n, nj = len(Q), robot.model.njoints
    if n == 0:
        return np.empty((0, nj, 3, 3)), np.empty((0, nj, 3))
    F = frames_at(symbolic_model(robot), Q)  # (n, nj, 12): each rotation column by column, then the translation
    R = F[:, :, :9].reshape(n, nj, 3, 3).transpose(0, 1, 3, 2)
    p = F[:, :, 9:]
    return np.ascontiguousarray(R), np.ascontiguousarray(p)


def geometry_speeds(scene: Scene, Q: np.ndarray, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lin, rot), each (n, g): the speed bound of each geometry's points at each row of ``Q`` (module docstring).

    ``speeds`` (n, dof): a bound of |qd| per joint. With (v_i, w_i) joint i's column of the world Jacobian (every
    Pinocchio joint that follows joint i summed, a mimic with its multiplier), ``lin[k, g] = sum_i speeds_i
    |v_i + w_i x c_g|`` (c_g the centre of geometry g's bounding sphere) and ``rot[k, g] = sum_i speeds_i |w_i|``:
    every point of geometry g moves at most at ``lin + rot (rho_g + e)`` while its sphere's centre stays within e
    of where it is. An obstacle: 0. Pinocchio's ``getJointJacobian`` gives the same columns (the tests).
    """
    from ..symbolic import symbolic_model

    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    speeds = np.broadcast_to(np.abs(np.asarray(speeds, dtype=float)), Q.shape)
    b = bounding_shapes(scene)
    n, g = len(Q), len(b.joint)
    lin, rot = np.zeros((n, g)), np.zeros((n, g))
    if n == 0:
        return lin, rot
    robot = scene.robot
    sym = symbolic_model(robot)
    R, p = joint_placements(robot, Q)  # (n, nj, 3, 3), (n, nj, 3)
    v = np.einsum("njab,jb->nja", R, sym.twists[:, :3])  # each joint's unit twist in the world, at its origin
    w = np.einsum("njab,jb->nja", R, sym.twists[:, 3:])
    supports = robot.model.supports
    for k in b.moving.tolist():
        j0 = int(b.joint[k])
        c = np.einsum("nab,b->na", R[:, j0], b.center[k]) + p[:, j0]
        col_v = np.zeros((n, robot.dof, 3))
        col_w = np.zeros((n, robot.dof, 3))
        for j in list(supports[j0])[1:]:
            i, s = int(sym.sources[j]), float(sym.scalings[j])
            col_v[:, i] += s * (v[:, j] + np.cross(w[:, j], c - p[:, j]))
            col_w[:, i] += s * w[:, j]
        lin[:, k] = np.einsum("ni,ni->n", speeds, np.linalg.norm(col_v, axis=2))
        rot[:, k] = np.einsum("ni,ni->n", speeds, np.linalg.norm(col_w, axis=2))
    return lin, rot


def pair_joints(scene: Scene, lower: np.ndarray | None = None, upper: np.ndarray | None = None) -> list[set[int]]:
    """Per checked pair, the joints of q its distance depends on.

    Those between its two shapes in the kinematic tree (an obstacle's pair: every joint above the robot's shape;
    link2 and the flange: the quill and the wrist), a mimic counted as the joint it follows, less those found not to
    change it at six random configurations within [lower, upper] (default: the limits; an unlimited one: one turn)
    each moved alone to a random value: a round flange turning on its axis, a quill sliding along a tall post.
    """
    from ..symbolic import symbolic_model

    robot = scene.robot
    model = robot.model
    sources = symbolic_model(robot).sources
    lo = np.asarray(robot.limits.lower if lower is None else lower, dtype=float)
    hi = np.asarray(robot.limits.upper if upper is None else upper, dtype=float)
    lo, hi = np.where(np.isfinite(lo), lo, -np.pi), np.where(np.isfinite(hi), hi, np.pi)
    rng = np.random.default_rng(5)
    Q = lo + (hi - lo) * rng.random((6, robot.dof))
    base = scene.distance_array(Q)
    moved = {}
    for j in range(robot.dof):
        Qj = Q.copy()
        Qj[:, j] = lo[j] + (hi[j] - lo[j]) * rng.random(len(Q))
        with np.errstate(invalid="ignore"):  # coal's failed depth (-inf) on both sides: unknown, so moved
            change = np.abs(scene.distance_array(Qj) - base)
        moved[j] = np.max(np.where(np.isnan(change), np.inf, change), axis=0) > 1e-9
    gm = scene.geometry_model
    out = []
    for k, pr in enumerate(scene.pairs):
        ja, jb = int(gm.geometryObjects[pr.first].parentJoint), int(gm.geometryObjects[pr.second].parentJoint)
        between = {int(sources[j]) for j in set(model.supports[ja]) ^ set(model.supports[jb]) if j > 0}
        out.append({j for j in between if moved[j][k]})
    return out


# ---------------------------------------------------------------------------------------------- along a path
def first_contact(scene: Scene, path: JointPath, s_end: float = 1.0) -> Contact | None:
    """The first ``s`` in [0, ``s_end``] where a checked pair comes to the margin along ``path``, or None.

    Args:
        scene: the robot in its cell.
        path: ``q(s)`` with ``q'(s)`` (``evaluate(s, order=1)``).
        s_end: the end of the part of the path looked at.

    Returns:
        None when every pair stays at least the margin apart on [0, ``s_end``]; else the :class:`Contact`
        (module docstring: the stop's gap to the margin is in [0, :data:`CONTACT_TOL`] m).

    Raises:
        InCollisionError: the path starts closer than the margin (exit code 2), naming the pair.
    """
    robot = scene.robot
    b = bounding_shapes(scene)
    margin = scene.margin
    n_pairs = len(scene.pairs)
    if n_pairs == 0:
        return None
    first = np.array([p.first for p in scene.pairs])
    second = np.array([p.second for p in scene.pairs])

    def at(s: float) -> tuple[np.ndarray, np.ndarray]:
        q, dq = path.evaluate(np.array([s]), 1)[:2]
        return q[0], dq[0]

    def gaps(q: np.ndarray) -> np.ndarray:
        return scene.distance_array(q[None, :])[0] - margin

    # per pair: both shapes' speed bounds (geometry_speeds), the spheres' centres moving at most the gap
    def pair_speeds(q: np.ndarray, dq: np.ndarray, g: np.ndarray) -> np.ndarray:
        lin, rot = (x[0] for x in geometry_speeds(scene, q[None, :], np.abs(dq[None, : robot.dof])))
        grow = np.maximum(g, 0.0)
        return (lin[first] + rot[first] * (b.radius[first] + grow)
                + lin[second] + rot[second] * (b.radius[second] + grow))  # fmt: skip

    s = 0.0
    q, dq = at(s)
    g = gaps(q)
    if g.min() < 0.0:
        scene.check(q, "the start")  # raises, naming the pair
    V = pair_speeds(q, dq, g)
    sliding = g < SLIDE_BAND  # pairs that start at the margin: sampled until clear (module docstring)
    for _ in range(MAX_STEPS):
        if s >= s_end:
            return None
        sliding &= g < SLIDE_BAND
        with np.errstate(divide="ignore", invalid="ignore"):
            allowed = np.where(V > 0, g / np.where(V > 0, V, 1.0), np.inf)
            if sliding.any():
                allowed = np.where(sliding, np.maximum(allowed, SLIDE_STEP / V), allowed)
        k = int(np.argmin(allowed))
        step = _SAFETY * float(allowed[k])
        if sliding[k]:  # samples of a pair at the margin, as many at once as the other pairs' steps allow
            others = allowed[~sliding]
            horizon = _SAFETY * float(others.min()) if others.size else np.inf
            n = int(min(max(horizon // step, 1.0), _BATCH))
            while True:
                ss = s + step * np.arange(1, n + 1)
                ss = np.append(ss[ss < s_end], s_end) if ss[-1] >= s_end else ss
                Q, dQ = path.evaluate(ss, 1)[:2]
                G = scene.distance_array(Q) - margin
                below = np.flatnonzero(G.min(axis=1) < 0.0)
                if below.size:
                    i = int(below[0])
                    return _bracketed(scene, at, margin, s if i == 0 else float(ss[i - 1]), float(ss[i]))
                V1 = pair_speeds(Q[-1], dQ[-1], G[-1])
                if V1.max() <= BOUND_GROWTH * V.max() or n == 1:
                    break
                n //= 2
            s, q, dq, g, V = float(ss[-1]), Q[-1], dQ[-1], G[-1], V1
            continue
        if s + 2.0 * step < s_end:  # small steps ahead: a probe where the closest pair would reach the margin
            rate = _rate(scene, q, dq, k)
            if rate < 0.0:
                probe = min(s + 1.5 * float(g[k]) / -rate, s_end)
                if probe > s + step and gaps(at(probe)[0]).min() < 0.0:
                    return _bracketed(scene, at, margin, s, probe)
        step = max(step, _MIN_STEP)
        while True:
            s1 = min(s + step, s_end)
            q1, dq1 = at(s1)
            g1 = gaps(q1)
            if g1.min() < 0.0:  # the bound failed (q' grew within the step): the contact is in (s, s1)
                return _bracketed(scene, at, margin, s, s1)
            V1 = pair_speeds(q1, dq1, g1)
            if V1.max() <= BOUND_GROWTH * V.max() or step <= _MIN_STEP:
                break
            # the bound grew: the step holds if it holds with each pair's larger bound of its two ends (the samples
            # of a pair at the margin are its check: the step is at most one)
            if np.all((step * np.maximum(V, V1) <= g) | sliding):
                break
            step *= 0.5
        s, q, dq, g, V = s1, q1, dq1, g1, V1
    raise ScaraError(f"the contact search took more than {MAX_STEPS} steps (s = {s:.9g}): please report it")


def _rate(scene: Scene, q: np.ndarray, dq: np.ndarray, k: int) -> float:
    """d(distance of pair k)/ds at q moving along dq (:meth:`Scene.gradients`)."""
    _, G = scene.gradients(q, [k])
    return float(G[0] @ dq)


def _bracketed(scene: Scene, at: Any, margin: float, lo: float, hi: float) -> Contact:
    """Bisection on the smallest gap between ``lo`` (clear) and ``hi`` (closer than the margin).

    It stops when a pair below the margin at ``hi`` (one that blocks) is within :data:`CONTACT_TOL` of it at ``lo``:
    the smallest gap of all may be a pair that slides along an obstacle at the margin and blocks nothing.
    """
    blocking = np.flatnonzero(scene.distance_array(at(hi)[0][None, :])[0] < margin)
    if not blocking.size:  # (the caller saw a pair below the margin at hi: the same query, the same answer)
        blocking = np.arange(len(scene.pairs))
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:
            break
        gaps = scene.distance_array(at(mid)[0][None, :])[0] - margin
        if gaps.min() < 0.0:
            hi, blocking = mid, np.flatnonzero(gaps < 0.0)
        else:
            lo = mid
            if gaps[blocking].min() <= CONTACT_TOL:
                break
    q = at(lo)[0]
    found = scene.distances(q)
    stops = set(blocking.tolist())
    return Contact(lo, q, next(p for p in found.pairs if p.pair.index in stops))  # closest first
