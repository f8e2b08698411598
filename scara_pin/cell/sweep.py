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
times the step, the bound taken at the first of up to 64 samples evaluated at once and checked at the last as
above), its exact distance checked at every one (a sample below the margin is bisected as above), until it is
:data:`SLIDE_BAND` clear; from then on it is followed conservatively like every other pair. The samples go as far
as the other pairs' conservative steps allow, so these are still followed without a gap.
Only such a pair could dip below the margin between two samples and come back unseen: a smooth distance
(curvature radius r of the shapes' relative motion) dips at most ``SLIDE_STEP**2 / (8 r)`` between samples,
1.25e-7 m for r = 1 cm; a straight translation of convex shapes (a jog along x, y or z beside a post or a
wall) cannot dip at all (the distance is then convex along the line).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ..errors import ScaraError

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from .scene import PairDistance, Scene

__all__ = [
    "BOUND_GROWTH",
    "CONTACT_TOL",
    "MAX_STEPS",
    "SLIDE_BAND",
    "SLIDE_STEP",
    "Contact",
    "JointPath",
    "clear_mask",
    "first_contact",
    "joint_motion",
    "joint_placements",
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
SLIDE_STEP = 1e-4
"""[m] the samples of such a pair: at most this much motion of its shapes between two (by its speed bound)."""
_BATCH = 64
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
class _Bounds:
    """Shapes that hold each geometry of a scene, in its joint's frame (the world's for joint 0).

    Per geometry (index into the scene's ``GeometryModel``): its joint, a bounding sphere (centre, radius) and a
    bounding capsule (segment ends, radius), both from coal's local bounding box: the sphere around the box, the
    capsule along its longest side with the radius of its cross-section's diagonal (a cylinder's or a
    sphere's own axis and radius).
    """

    joint: np.ndarray  # (g,)
    center: np.ndarray  # (g, 3)
    radius: np.ndarray  # (g,)
    end0: np.ndarray  # (g, 3)
    end1: np.ndarray  # (g, 3)
    capsule: np.ndarray  # (g,)

    @property
    def moving(self) -> np.ndarray:
        """The indices of the geometries on a joint (not fixed to the world)."""
        return np.flatnonzero(self.joint > 0)


_BOUNDS: weakref.WeakKeyDictionary[Scene, _Bounds] = weakref.WeakKeyDictionary()
"""Each scene's bounding shapes, made once."""


def _bounds(scene: Scene) -> _Bounds:
    cached = _BOUNDS.get(scene)
    if cached is not None:
        return cached
    import coal

    gm = scene.geometry_model
    joint, center, radius, end0, end1, capsule = [], [], [], [], [], []
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
    out = _Bounds(np.array(joint, dtype=int), np.array(center).reshape(-1, 3), np.array(radius),
                  np.array(end0).reshape(-1, 3), np.array(end1).reshape(-1, 3), np.array(capsule))  # fmt: skip
    _BOUNDS[scene] = out
    return out


# ---------------------------------------------------------------------------------------------- many configurations
def clear_mask(scene: Scene, Q: ArrayLike) -> np.ndarray:
    """(n,) whether each configuration (row of ``Q``) has every checked pair at least the margin apart.

    Pairs whose bounding capsules are farther apart than the margin are clear without a distance query (module
    docstring); the others get coal's exact distance, pair by pair, and a configuration already found in
    collision is not asked again. A pair of two shapes fixed to the world (the robot's base and an obstacle) is
    asked once: its distance is the same at every configuration (a sleeve around the base column, a mesh, cost
    0.65 ms a configuration: ``workspace --cell`` ran past 400 s).
    """
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n = len(Q)
    ok = np.ones(n, dtype=bool)
    if not scene.pairs or n == 0:
        return ok
    b = _bounds(scene)
    R, p = joint_placements(scene.robot, Q)
    Rg, pg = R[:, b.joint], p[:, b.joint]  # (n, g, 3, 3), (n, g, 3): each geometry's joint (joint 0: identity)
    e0 = np.einsum("ngab,gb->nga", Rg, b.end0) + pg
    e1 = np.einsum("ngab,gb->nga", Rg, b.end1) + pg
    margin = scene.margin
    for pair in scene.pairs:
        i, j = pair.first, pair.second
        if b.joint[i] == 0 and b.joint[j] == 0:  # two shapes fixed to the world: one distance for every row
            if scene.distance_array(Q[:1], pairs=[pair.index])[0, 0] < margin:
                ok[:] = False
            continue
        gap = segment_distance(e0[:, i], e1[:, i], e0[:, j], e1[:, j]) - b.capsule[i] - b.capsule[j]
        rows = np.flatnonzero((gap <= margin) & ok)
        if len(rows):
            rows = rows[_near_boxes(scene, pair, R[rows], p[rows], margin)]
        if len(rows):
            d = scene.distance_array(Q[rows], pairs=[pair.index])[:, 0]
            ok[rows[d < margin]] = False
    return ok


def _near_boxes(scene: Scene, pair: Any, R: np.ndarray, p: np.ndarray, margin: float) -> np.ndarray:
    """(n,) which rows may bring ``pair`` within the margin, by the distance between its two shapes' bounding boxes.

    For a pair with a mesh that is a surface (a coal bounding-volume tree: about 70 us a query near it, up to a few
    ms inside its bounding box, where its bounding capsule is a poor bound: a sleeve's capsule fills the sleeve's
    hole): each shape's local bounding box, placed at each row (``R``, ``p``: the joints' placements), bounded by the
    world-aligned box of its corners; the distance between the two boxes is a lower bound of the pair's, and a row
    where it is at least the margin is clear. Vectorised over the rows. Other pairs: every row is kept.
    """
    import coal

    gm = scene.geometry_model
    objs = (gm.geometryObjects[pair.first], gm.geometryObjects[pair.second])
    if not any(isinstance(o.geometry, coal.BVHModelBase) for o in objs):
        return np.ones(len(R), dtype=bool)
    lows, highs = [], []
    for o in objs:
        box = o.geometry.aabb_local  # computed by _bounds
        lo, hi = np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        local = corners @ np.asarray(o.placement.rotation).T + np.asarray(o.placement.translation)  # in its joint
        j = int(o.parentJoint)
        world = np.einsum("nab,kb->nka", R[:, j], local) + p[:, j][:, None, :]  # (n, 8, 3)
        lows.append(world.min(axis=1))
        highs.append(world.max(axis=1))
    gap = np.maximum(np.maximum(lows[1] - highs[0], lows[0] - highs[1]), 0.0)
    return np.linalg.norm(gap, axis=1) < margin  # type: ignore[no-any-return]


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
    from ..symbolic import symbolic_model

    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n, nj = len(Q), robot.model.njoints
    if n == 0:
        return np.empty((0, nj, 3, 3)), np.empty((0, nj, 3))
    # column i * nj + j: oMi[j] at row i
    F = np.asarray(symbolic_model(robot).joint_frames.map(n)(Q.T)).reshape(12, n, nj)
    R = F[:9].reshape(3, 3, n, nj, order="F").transpose(2, 3, 0, 1)  # each rotation stored column by column
    p = F[9:].transpose(1, 2, 0)
    return np.ascontiguousarray(R), np.ascontiguousarray(p)


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
    import pinocchio as pin

    robot = scene.robot
    model = robot.model
    data = model.createData()
    b = _bounds(scene)
    moving = b.moving
    margin = scene.margin
    n_pairs = len(scene.pairs)
    if n_pairs == 0:
        return None
    first = np.array([p.first for p in scene.pairs])
    second = np.array([p.second for p in scene.pairs])
    convert = robot.to_pinocchio_q if robot.has_continuous else None

    def at(s: float) -> tuple[np.ndarray, np.ndarray]:
        q, dq = path.evaluate(np.array([s]), 1)[:2]
        return q[0], dq[0]

    def gaps(q: np.ndarray) -> np.ndarray:
        return scene.distance_array(q[None, :])[0] - margin

    # per geometry: |q'| . (speed of its sphere's centre, angular speed); per pair: both shapes' bounds
    def pair_speeds(q: np.ndarray, dq: np.ndarray, g: np.ndarray) -> np.ndarray:
        pin.computeJointJacobians(model, data, convert(q) if convert else q)
        lin = np.zeros(len(b.joint))
        rot = np.zeros(len(b.joint))
        adq = np.abs(dq[: robot.dof])
        for k in moving.tolist():
            j, c = int(b.joint[k]), b.center[k]
            J = pin.getJointJacobian(model, data, j, pin.WORLD)
            M = data.oMi[j]
            p = M.rotation @ c + M.translation
            v, w = J[:3, : robot.dof], J[3:, : robot.dof]
            lin[k] = adq @ np.linalg.norm(v + np.cross(w.T, p).T, axis=0)
            rot[k] = adq @ np.linalg.norm(w, axis=0)
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
