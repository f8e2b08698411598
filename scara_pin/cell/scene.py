"""A robot in its cell: the pairs checked and their distances (coal, through Pinocchio's ``GeometryModel``).

The scene is one Pinocchio ``GeometryModel`` on the robot's model: the robot's collision geometry
(:mod:`~scara_pin.cell.geometry`), the carried part on the tool frame, and the obstacles on the root
(placed at ``oMbase * baseMobstacle``). The pairs checked:

- every robot geometry and the carried part against every obstacle;
- the robot's self-collision pairs (:class:`~scara_pin.cell.geometry.SelfPairs`), and the carried part
  against the links that are not adjacent to the tool's link (a carried part in contact with the arm at every
  sample is refused: a sign slip, not the design);
- minus the cell's ``allow`` pairs (by name: links, obstacles, ``carried``: one namespace, an obstacle named like
  a link is refused).

Distances are coal's signed distances between the exact shapes (negative: penetration depth), with
GJK/EPA tolerances of :data:`GJK_TOLERANCE` (coal's default, 1e-6, would leave errors of about 4e-7 m).
Witness points and normals are returned in the robot's ``base`` frame; the normal points from the first
shape of the pair (the robot's) to the second, so moving the second shape along it increases the distance.

The derivative of a pair's distance with respect to q (for the planners) is the normal's component of the
relative velocity of the two witness points: ``dd/dq = n . (J_b(p_b) - J_a(p_a))``, where ``J_x(p)`` is the
Jacobian of the point p fixed to shape x's joint (zero for an obstacle). It holds where the witness points
are unique (two strictly convex shapes, or a face against a vertex), and is a subgradient elsewhere.

A closed convex mesh is its hull (``coal.Convex``): a solid, with signed distances, whatever its winding or scale
sign; a closed mesh that is not convex is refused. An open mesh is a coal bounding-volume tree of its triangles, a
SURFACE; motions are checked densely, so crossing it is always seen. coal's distance to a
bounding-volume tree costs about 2 ms per pair when the tree is far away (10 us near it), so such a pair is
first bounded below by the two shapes' bounding spheres: beyond :data:`FAR` the bound stands for the
distance in :meth:`Scene.distance_array` (the planner and the verifier only compare distances with the
margin and the activation distance, both far below it); nearer, coal's exact distance.
"""

from __future__ import annotations

import math
import warnings
import weakref
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError
from .cell import CARRIED, Cell
from .geometry import SelfPairs, robot_geometry, sample_configurations

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = ["FAR", "GJK_TOLERANCE", "Distances", "InCollisionError", "Pair", "PairDistance", "Scene", "Witness", "scene"]

GJK_TOLERANCE = 1e-10
"""coal's GJK and EPA tolerances used here [m] (distances then agree with closed forms to about 4e-11 m)."""
FAR = 0.05
"""[m] a pair with a non-convex mesh whose bounding spheres are farther apart than this takes that bound as its
distance in :meth:`Scene.distance_array` (not coal's exact one, which costs about 2 ms there)."""
EPA_ITERATIONS = 1000
"""coal's EPA iterations (its default, 64, leaves penetration depths of parallel cylinders wrong)."""
_OVERLAP = 1e-6
"""[m] a carried part deeper than this in a link of the arm at every sampled configuration (the links it is held by
included) is refused: its top face on the flange's face is a contact (0 m), a sign slip in its z is not."""


class InCollisionError(InvalidInputError):
    """A configuration asked for (a start, a goal, a taught point) is closer than the margin (exit code 2).

    Attributes:
        pair: the closest pair, distance: its distance [m], margin: the margin [m].
    """

    def __init__(self, message: str, pair: Pair, distance: float, margin: float) -> None:
        super().__init__(message)
        self.pair = pair
        self.distance = distance
        self.margin = margin


@dataclass(frozen=True)
class Pair:
    """A pair of shapes whose distance is checked.

    Attributes:
        index: its index in the scene's pairs.
        a: the first shape's name: a link of the robot, or ``carried``.
        b: the second's: an obstacle, or a link (self-collision).
        kind: ``"obstacle"`` or ``"self"``.
        first, second: the geometry objects' indices in the scene's ``GeometryModel``.
    """

    index: int
    a: str
    b: str
    kind: str
    first: int
    second: int

    @property
    def label(self) -> str:
        """``link2 - post`` (a link and an obstacle) or ``quill - link1 (self)``."""
        return f"{self.a} - {self.b}" + (" (self)" if self.kind == "self" else "")

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"a": self.a, "b": self.b, "kind": self.kind}


@dataclass(frozen=True)
class PairDistance:
    """The distance of one pair at one configuration.

    Attributes:
        pair: the pair.
        distance: [m] coal's signed distance (negative: penetration depth).
        point_a, point_b: (3,) the witness points on each shape, in the base frame [m].
        normal: (3,) unit vector from a to b, in the base frame.
    """

    pair: Pair
    distance: float
    point_a: np.ndarray
    point_b: np.ndarray
    normal: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {**self.pair.to_dict(), "distance": self.distance, "point_a": self.point_a.tolist(),
                "point_b": self.point_b.tolist(), "normal": self.normal.tolist()}  # fmt: skip


@dataclass(frozen=True)
class Witness:
    """One pair's coal distance with its witness points, normal and joints, in the model's world frame.

    Attributes:
        distance: [m] coal's signed distance.
        normal: (3,) unit vector from the first shape to the second.
        point_a, point_b: (3,) the witness points on each shape [m].
        oMa, oMb: the placements of the joints carrying the two shapes (an obstacle's: the root, identity).
    """

    distance: float
    normal: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    oMa: pin.SE3
    oMb: pin.SE3


@dataclass(frozen=True)
class Distances:
    """Every checked pair's distance at one configuration, closest first.

    Attributes:
        q: the configuration.
        margin: [m] the cell's margin.
        pairs: per pair, closest first.
    """

    q: np.ndarray
    margin: float
    pairs: tuple[PairDistance, ...]

    @property
    def closest(self) -> PairDistance | None:
        """The closest pair (None when nothing is checked)."""
        return self.pairs[0] if self.pairs else None

    @property
    def minimum(self) -> float:
        """[m] the smallest distance (inf when nothing is checked)."""
        return self.pairs[0].distance if self.pairs else math.inf

    @property
    def clear(self) -> bool:
        """Every pair at least the margin apart."""
        return self.minimum >= self.margin

    def of(self, pair: Pair) -> PairDistance:
        """The distance of ``pair`` (a pair the scene checks)."""
        return next(p for p in self.pairs if p.pair.index == pair.index)

    def below(self, distance: float | None = None) -> tuple[PairDistance, ...]:
        """The pairs closer than ``distance`` (default: the margin)."""
        limit = self.margin if distance is None else distance
        return tuple(p for p in self.pairs if p.distance < limit)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"q": self.q.tolist(), "margin": self.margin, "minimum": self.minimum,
                "pairs": [p.to_dict() for p in self.pairs]}  # fmt: skip

    def __repr__(self) -> str:
        c = self.closest
        if c is None:
            return "Distances(no pair checked)"
        return (f"Distances({len(self.pairs)} pairs; closest {c.pair.label} at {c.distance * 1e3:.3f} mm, margin "
                f"{self.margin * 1e3:g} mm)")  # fmt: skip


@dataclass(eq=False)
class Scene:
    """A robot and a cell: the checked pairs and their distances (module docstring).

    Attributes:
        robot: the robot.
        cell: the cell.
        pairs: the checked pairs.
        self_pairs: the robot's self-collision pairs, checked and disabled.
        margin: [m] the cell's margin.
    """

    robot: RobotModel
    cell: Cell
    pairs: tuple[Pair, ...] = field(init=False)
    self_pairs: SelfPairs = field(init=False)
    margin: float = field(init=False)

    def __post_init__(self) -> None:
        gm, names, n_robot, carried = self._geometry()
        allowed = self._allowed(set(names))
        movers = list(range(n_robot)) + ([carried] if carried is not None else [])
        candidates = [(i, j, "obstacle") for i in movers for j in range(n_robot + (carried is not None), gm.ngeoms)]
        checked_self, disabled = self._self_pairs(gm, names, n_robot, carried)
        pairs: list[Pair] = []
        for i, j, kind in candidates + [(a, b, "self") for a, b in checked_self]:
            na, nb = names[i], names[j]
            if kind == "self" and j == carried:
                na, nb, i, j = nb, na, j, i  # carried first
            if frozenset((na, nb)) not in allowed:
                pairs.append(Pair(len(pairs), na, nb, kind, int(i), int(j)))
        gm.removeAllCollisionPairs()
        for pr in pairs:
            gm.addCollisionPair(pin.CollisionPair(pr.first, pr.second))
        self.pairs = tuple(pairs)
        self._configure(gm)
        checked = [(names[a], names[b]) for a, b in checked_self]
        disabled += [(na, nb, "allowed by the cell") for na, nb in checked if frozenset((na, nb)) in allowed]
        self.self_pairs = SelfPairs(tuple(p for p in checked if frozenset(p) not in allowed), tuple(disabled))
        self.margin = self.cell.margin
        self._names = tuple(names)

    def _geometry(self) -> tuple[pin.GeometryModel, list[str], int, int | None]:
        """(geometry model, each geometry's name, how many are the robot's, the carried part's index or None).

        The robot's collision geometry, the carried part on the tool frame, the obstacles on the root.
        """
        robot, cell = self.robot, self.cell
        geo = robot_geometry(robot)
        gm = pin.GeometryModel(geo.model)
        names = list(geo.links)
        links = {f.name for f in robot.model.frames if f.type == pin.FrameType.BODY} | set(names)
        for o in cell.obstacles:  # one namespace: a name in allow: or in a message stands for one thing
            if o.name in links:
                raise InvalidInputError(f"{cell.origin}{f' line {o.line}' if o.line else ''}: obstacle {o.name!r} has "
                                        f"the name of a link of robot {robot.name} ({o.name}): rename the obstacle "
                                        "(in allow: and in messages a name stands for one thing)")  # fmt: skip
        for what, shape, line in [(f"obstacle {o.name}", o.shape, o.line) for o in cell.obstacles]:
            if shape.closed and not shape.convex:
                raise InvalidInputError(f"{cell.origin}{f' line {line}' if line else ''}: {what}: mesh {shape.source} "
                                        "is closed but not convex: a closed mesh is checked as a solid only when it is "
                                        "convex (its hull), an open one as a surface; give it as convex parts, one "
                                        "obstacle each")  # fmt: skip
        base = robot.data.oMf[robot.base_id]  # fixed to the root (the model keeps it from its neutral FK)
        self._oMbase = pin.SE3(base)
        carried = None
        if cell.carried is not None:
            frame = robot.model.frames[robot.tool_id]
            carried = gm.addGeometryObject(pin.GeometryObject(CARRIED, int(frame.parentJoint), int(robot.tool_id),
                                                              frame.placement * cell.carried.placement(),
                                                              cell.carried.geometry(solid=True)))  # fmt: skip
            names.append(CARRIED)
        for o in cell.obstacles:
            shape = o.keep_out(cell.margin)  # an obstacle asking for more than the margin: checked grown by the rest
            gm.addGeometryObject(pin.GeometryObject(f"obstacle:{o.name}", 0, 0, base * shape.placement(),
                                                    shape.geometry()))  # fmt: skip
            names.append(o.name)
        return gm, names, len(geo.links), carried

    def _allowed(self, known: set[str]) -> set[frozenset[str]]:
        """The cell's ``allow`` pairs, each name a link with collision geometry, ``carried`` or an obstacle."""
        for first, second in self.cell.allow:
            for n in (first, second):
                if n not in known:
                    raise InvalidInputError(f"{self.cell.origin}: allow names {n!r}, neither a link with collision "
                                            f"geometry nor an obstacle (known: {', '.join(sorted(known))})")
        return {frozenset(pair) for pair in self.cell.allow}

    def _self_pairs(self, gm: pin.GeometryModel, names: list[str], n_robot: int,
                    carried: int | None) -> tuple[list[tuple[int, int]], list[tuple[str, str, str]]]:  # fmt: skip
        """(the self pairs checked, those disabled with the reason).

        All but adjacent ones and those in contact at every sampled configuration (module docstring); the carried
        part is adjacent to the links on the tool's joint and its parent.
        """
        model = self.robot.model
        movers = list(range(n_robot)) + ([carried] if carried is not None else [])
        found = {(min(i, j), max(i, j)) if i < n_robot else (j, i) for i in movers for j in range(n_robot)
                 if not (j >= i and i < n_robot)}  # fmt: skip
        adjacent = set(robot_geometry(self.robot).adjacent)
        if carried is not None:
            tool_joint = int(model.frames[self.robot.tool_id].parentJoint)
            adjacent |= {(j, carried) for j in range(n_robot)
                         if gm.geometryObjects[j].parentJoint in (tool_joint, model.parents[tool_joint])}  # fmt: skip
        disabled: list[tuple[str, str, str]] = []
        to_sample = []
        for a, b in sorted(found):
            if names[a] == names[b]:
                continue
            if (a, b) in adjacent:
                disabled.append((names[a], names[b], "adjacent"))
            else:
                to_sample.append((a, b))
        always = self._always_in_contact(gm, to_sample)
        if carried is not None:  # the part held is never "in contact by design" with the arm: a sign slip is an error
            inside = self._always_in_contact(gm, [(j, carried) for j in range(n_robot)], depth=_OVERLAP)
            stuck = sorted(inside | {ab for ab in always if carried in ab})
            if stuck:
                self._carried_overlap(gm, [names[a] for a, _ in stuck], stuck[0][0], carried)
        disabled += [(names[a], names[b], "always in contact") for a, b in to_sample if (a, b) in always]
        return [ab for ab in to_sample if ab not in always], disabled

    def _carried_overlap(self, gm: pin.GeometryModel, links: list[str], link: int, carried: int) -> None:
        """Refuse a carried part in contact with the arm at every sampled configuration (``links``), naming the overlap.

        Its placement is the cell's (tool frame); the depth shown is at q = 0.
        """
        probe = pin.GeometryModel(gm)
        probe.removeAllCollisionPairs()
        probe.addCollisionPair(pin.CollisionPair(link, carried))
        pd = probe.createData()
        q0 = sample_configurations(self.robot, 0)[0]
        pin.computeDistances(self.robot.model, self.robot.model.createData(), probe, pd, self.robot.to_pinocchio_q(q0))
        d = float(pd.distanceResults[0].min_distance)
        depth = f"{-d * 1e3:.3g} mm deep in {links[0]}" if d < 0 else f"touching {links[0]}"
        xyz = ", ".join(f"{v:.6g}" for v in self.cell.carried.xyz) if self.cell.carried is not None else ""
        raise InvalidInputError(f"{self.cell.origin}: the carried part overlaps the arm at every configuration "
                                f"({', '.join(links)}; at q = 0 {depth}): it would never be checked against it. The "
                                f"part is placed in the tool frame, whose z axis points out of the flange (down): a "
                                f"part hanging below the flange has a positive z (its xyz is [{xyz}])")  # fmt: skip

    def _configure(self, gm: pin.GeometryModel) -> None:
        """The geometry data and its distance requests (:data:`GJK_TOLERANCE`, :data:`EPA_ITERATIONS`, fresh guesses).

        The pairs with a mesh that is a surface (a bounding-volume tree) are bounded by their spheres when far.
        """
        self._gm = gm
        self._gd = gm.createData()
        _fresh_guesses(self._gd)
        for req in self._gd.distanceRequests:
            req.gjk_tolerance = GJK_TOLERANCE
            req.epa_tolerance = GJK_TOLERANCE
            req.enable_signed_distance = True
            req.epa_max_iterations = EPA_ITERATIONS
        self._data = self.robot.model.createData()
        objs = gm.geometryObjects
        self._far_pairs = tuple(p.index for p in self.pairs if isinstance(objs[p.second].geometry, coal.BVHModelBase)
                                or isinstance(objs[p.first].geometry, coal.BVHModelBase))  # fmt: skip
        self._spheres = {}
        for i in {k for p in self._far_pairs for k in (self.pairs[p].first, self.pairs[p].second)}:
            geometry = objs[i].geometry
            geometry.computeLocalAABB()
            self._spheres[i] = (np.asarray(geometry.aabb_center, dtype=float).copy(), float(geometry.aabb_radius))

    # ------------------------------------------------------------------ building
    def _always_in_contact(self, gm: pin.GeometryModel, candidates: list[tuple[int, int]],
                           depth: float = 0.0) -> set[tuple[int, int]]:  # fmt: skip
        """The candidate pairs in contact (distance <= -``depth``) at every sampled configuration."""
        if not candidates:
            return set()
        probe = pin.GeometryModel(gm)
        probe.removeAllCollisionPairs()
        for a, b in candidates:
            probe.addCollisionPair(pin.CollisionPair(a, b))
        pd = probe.createData()
        data = self.robot.model.createData()
        alive = set(range(len(candidates)))
        for q in sample_configurations(self.robot):
            pin.computeDistances(self.robot.model, data, probe, pd, self.robot.to_pinocchio_q(q))
            alive = {k for k in alive if pd.distanceResults[k].min_distance <= -depth}
            if not alive:
                break
        return {candidates[k] for k in alive}

    # ------------------------------------------------------------------ distances
    @property
    def geometry_model(self) -> pin.GeometryModel:
        """The scene's Pinocchio ``GeometryModel`` (robot, carried part, obstacles; the checked pairs)."""
        return self._gm

    def distances(self, q: ArrayLike) -> Distances:
        """Every checked pair's distance at ``q`` (witness points and normals in the base frame), closest first."""
        q = self.robot.check_q(q)
        pin.computeDistances(self.robot.model, self._data, self._gm, self._gd, self.robot.to_pinocchio_q(q))
        inv = self._oMbase.inverse()
        out = []
        for p, res in zip(self.pairs, self._gd.distanceResults):
            pa = inv.act(np.asarray(res.getNearestPoint1()))
            pb = inv.act(np.asarray(res.getNearestPoint2()))
            normal = inv.rotation @ np.asarray(res.normal)
            d = _sane(res.min_distance)
            if d == -math.inf:
                pa = pb = np.full(3, np.nan)
            out.append(PairDistance(p, d, pa, pb, normal))
        out.sort(key=lambda d: d.distance)
        return Distances(q, self.margin, tuple(out))

    def distance_array(self, Q: ArrayLike, pairs: ArrayLike | None = None) -> np.ndarray:
        """(n, k) distances of pairs ``pairs`` (default: all, in the scene's order) at each row of ``Q`` [m]."""
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        model, data, gm, gd = self.robot.model, self._data, self._gm, self._gd
        convert = self.robot.to_pinocchio_q if self.robot.has_continuous else None
        if pairs is None:
            out = np.empty((len(Q), len(self.pairs)))
            far = self._far_pairs
            with self._far_pairs_inactive():
                for i, q in enumerate(Q):
                    pin.computeDistances(model, data, gm, gd, convert(q) if convert else q)
                    out[i] = [r.min_distance for r in gd.distanceResults]
                    if out[i].min() < _INSANE:
                        out[i] = [_sane(v) for v in out[i]]
                    for k in far:
                        out[i, k] = self._bounded(k)
            return out
        idx = [int(k) for k in np.asarray(pairs, dtype=int).ravel()]
        out = np.empty((len(Q), len(idx)))
        for i, q in enumerate(Q):
            pin.updateGeometryPlacements(model, data, gm, gd, convert(q) if convert else q)
            for c, k in enumerate(idx):
                out[i, c] = _sane(pin.computeDistance(gm, gd, k).min_distance)
        return out

    def first_closer(self, Q: ArrayLike, pairs: list[int], candidates: np.ndarray, margin: float) -> np.ndarray:
        """(n,) per row of ``Q``: the position in ``pairs`` of the first pair closer than ``margin``, -1 if none.

        Only the pairs marked in ``candidates`` ((n, len(pairs)) bool) are asked, in order, each configuration's
        geometries placed once; rows without a candidate are not placed at all.
        """
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        model, data, gm, gd = self.robot.model, self._data, self._gm, self._gd
        convert = self.robot.to_pinocchio_q if self.robot.has_continuous else None
        out = np.full(len(Q), -1, dtype=int)
        for i in np.flatnonzero(candidates.any(axis=1)):
            q = Q[i]
            pin.updateGeometryPlacements(model, data, gm, gd, convert(q) if convert else q)
            for c in np.flatnonzero(candidates[i]):
                if _sane(pin.computeDistance(gm, gd, pairs[c]).min_distance) < margin:
                    out[i] = c
                    break
        return out

    def minimum_array(self, Q: ArrayLike) -> np.ndarray:
        """(n,) the smallest distance over every checked pair at each row of ``Q`` [m] (see :meth:`nearest_array`)."""
        return self.nearest_array(Q)[0]

    def nearest_array(self, Q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """((n,) distances, (n,) pair indices): the closest checked pair at each row of ``Q`` and its distance [m].

        The row minima of :meth:`distance_array` (the same distances, the bounded ones included), without reading
        every pair's result back into Python: Pinocchio's ``computeDistances`` returns the index of the closest
        pair it computed. No pairs: distances ``inf``, indices ``-1``.
        """
        Q = np.atleast_2d(np.asarray(Q, dtype=float))
        dist = np.full(len(Q), math.inf)
        which = np.full(len(Q), -1, dtype=int)
        if not self.pairs:
            return dist, which
        model, data, gm, gd = self.robot.model, self._data, self._gm, self._gd
        convert = self.robot.to_pinocchio_q if self.robot.has_continuous else None
        results = gd.distanceResults
        far = self._far_pairs
        exact = len(self.pairs) - len(far)
        with self._far_pairs_inactive():
            for i, q in enumerate(Q):
                qp = convert(q) if convert else q
                if exact:
                    k = pin.computeDistances(model, data, gm, gd, qp)
                    dist[i], which[i] = _sane(results[k].min_distance), k
                else:
                    pin.updateGeometryPlacements(model, data, gm, gd, qp)
                for k in far:
                    d = self._bounded(k)
                    if d < dist[i]:
                        dist[i], which[i] = d, k
        return dist, which

    @contextmanager
    def _far_pairs_inactive(self) -> Iterator[None]:
        """The mesh pairs that :meth:`_bounded` answers, off in ``computeDistances`` (it skips inactive pairs)."""
        flags = self._gd.activeCollisionPairs
        for k in self._far_pairs:
            flags[k] = False
        try:
            yield
        finally:
            for k in self._far_pairs:
                flags[k] = True

    def _bounded(self, k: int) -> float:
        """Pair k's distance (placements current): its bounding spheres' beyond :data:`FAR`, else coal's."""
        pr = self.pairs[k]
        (ca, ra), (cb, rb) = self._spheres[pr.first], self._spheres[pr.second]
        Ma, Mb = self._gd.oMg[pr.first], self._gd.oMg[pr.second]
        bound = float(np.linalg.norm(Ma.act(ca) - Mb.act(cb))) - ra - rb
        if bound > FAR:
            return bound
        return _sane(pin.computeDistance(self._gm, self._gd, k).min_distance)

    def gradients(self, q: ArrayLike, pairs: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(d (k,), G (k, dof)): the distances of ``pairs`` (default all) at ``q`` and their derivatives dd/dq.

        See the module docstring for the formula and where it holds.
        """
        q = np.asarray(q, dtype=float)
        model, data, gm, gd = self.robot.model, self._data, self._gm, self._gd
        qp = self.robot.to_pinocchio_q(q) if self.robot.has_continuous else q
        idx = list(range(len(self.pairs))) if pairs is None else [int(k) for k in np.asarray(pairs).ravel()]
        pin.computeJointJacobians(model, data, qp)  # also the joint placements
        pin.updateGeometryPlacements(model, data, gm, gd)
        d = np.empty(len(idx))
        G = np.zeros((len(idx), self.robot.dof))
        jac: dict[int, np.ndarray] = {}

        def point_jacobian(joint: int, p: np.ndarray) -> np.ndarray:
            if joint == 0:
                return np.zeros((3, model.nv))
            J = jac.get(joint)
            if J is None:
                J = jac[joint] = pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
            r = p - data.oMi[joint].translation
            return J[:3] - np.cross(r[None, :], J[3:].T).T  # v_p = v_o + w x r = v_o - r x w

        objs = gm.geometryObjects
        for c, k in enumerate(idx):
            res = pin.computeDistance(gm, gd, k)
            pair = self.pairs[k]
            d[c] = _sane(res.min_distance)
            n = np.asarray(res.normal)
            ja, jb = objs[pair.first].parentJoint, objs[pair.second].parentJoint
            g = n @ (point_jacobian(jb, np.asarray(res.getNearestPoint2()))
                     - point_jacobian(ja, np.asarray(res.getNearestPoint1())))  # fmt: skip
            G[c] = g[: self.robot.dof] if model.nv == self.robot.dof else g
        return d, G

    def witnesses(self, q: np.ndarray, pairs: list[int]) -> list[Witness]:
        """Each of ``pairs`` at ``q`` as the planners' separating planes need it, with its joints' placements.

        In the MODEL's world frame (the root link), where :meth:`distances` gives the base frame.
        """
        model, data, gm, gd = self.robot.model, self._data, self._gm, self._gd
        pin.forwardKinematics(model, data, self.robot.to_pinocchio_q(q) if self.robot.has_continuous else q)
        pin.updateGeometryPlacements(model, data, gm, gd)
        objs = gm.geometryObjects
        out = []
        for k in pairs:
            pr = self.pairs[k]
            res = pin.computeDistance(gm, gd, pr.index)
            n = np.asarray(res.normal, dtype=float)
            points = (np.array(res.getNearestPoint1(), dtype=float), np.array(res.getNearestPoint2(), dtype=float))
            out.append(Witness(float(res.min_distance), n / (np.linalg.norm(n) or 1.0), *points,
                               pin.SE3(data.oMi[objs[pr.first].parentJoint]),
                               pin.SE3(data.oMi[objs[pr.second].parentJoint])))  # fmt: skip
        return out

    def check(self, q: ArrayLike, what: str) -> Distances:
        """The distances at ``q``; :class:`InCollisionError` (exit 2) naming the closest pair if below the margin."""
        found = self.distances(q)
        c = found.closest
        if c is not None and c.distance < self.margin:
            raise InCollisionError(f"{what} is in collision: {describe(c, self.margin)}", c.pair, c.distance,
                                   self.margin)  # fmt: skip
        return found

    def __repr__(self) -> str:
        return (f"Scene({self.robot.name}: {len(self.pairs)} pairs checked, {len(self.cell.obstacles)} obstacle(s), "
                f"margin {self.margin * 1e3:g} mm)")  # fmt: skip


_INSANE = -1e3
"""[m] a distance below this is coal's EPA failing (it returns -DBL_MAX for some deep contacts of a thin cylinder
with a hull): read as -inf, in contact, depth unknown."""


def _sane(d: float) -> float:
    """Coal's signed distance, or -inf where its penetration depth failed (:data:`_INSANE`): in contact all the same."""
    d = float(d)
    return -math.inf if not d >= _INSANE else d


def _fresh_guesses(gd: Any) -> None:
    """No query starts from the last one's GJK guess.

    Pinocchio's requests cache it by default, and EPA started from a stale guess can stop on a wrong face (a
    penetration 30 times too deep was seen: box against cylinder).
    """
    for req in gd.distanceRequests:
        req.gjk_initial_guess = coal.GJKInitialGuess.DefaultGuess
        with warnings.catch_warnings():  # the flag is deprecated, but Pinocchio still sets it
            warnings.simplefilter("ignore", DeprecationWarning)
            req.enable_cached_gjk_guess = False


def describe(found: PairDistance, margin: float, unit: str = "mm") -> str:
    """``link2 and post are 1.2 mm apart (margin 2 mm) near (x, y, z) mm in base``: one pair's distance, in words.

    ``unit="m"``: every length written ``<number> m`` (``0.0012 m``; the point ``near x 0.3 m, y -0.1 m, z -0.1 m``),
    which the teach pendant's page restates in its own units.
    """
    if unit not in ("mm", "m"):
        raise InvalidInputError(f"unit {unit!r} must be 'mm' or 'm'")
    a, b = found.pair.a, found.pair.b
    margin_text = f"{margin:g} m" if unit == "m" else f"{margin * 1e3:g} mm"
    if found.distance == -math.inf:
        return f"{a} is in contact with {b}, its depth not computed (margin {margin_text})"
    mid = (found.point_a + found.point_b) / 2.0
    if unit == "m":
        size, at = (lambda v: f"{v:.3g} m"), ", ".join(f"{k} {v:.6g} m" for k, v in zip("xyz", mid))
        at = f"near {at} in base"
    else:
        size, at = (lambda v: f"{v * 1e3:.3g} mm"), f"near ({', '.join(f'{v * 1e3:.1f}' for v in mid)}) mm in base"
    if found.distance < 0:
        how = f"{a} is {size(-found.distance)} deep in {b}"
    else:
        how = f"{a} and {b} are {size(found.distance)} apart"
    return f"{how} (margin {margin_text}) {at}"


_SCENES: weakref.WeakKeyDictionary[RobotModel, dict[int, tuple[Cell, Scene]]] = weakref.WeakKeyDictionary()
"""Each robot's scenes by cell (at most :data:`_SCENES_PER_ROBOT`); a scene holds its robot, so an entry lasts as long
as the cache keeps it, not the robot."""
_SCENES_PER_ROBOT = 8


def scene(robot: RobotModel, cell: Cell) -> Scene:
    """The scene of ``robot`` in ``cell``, built once per (robot, cell)."""
    cache = _SCENES.setdefault(robot, {})
    hit = cache.get(id(cell))
    if hit is not None and hit[0] is cell:
        return hit[1]
    if len(cache) >= _SCENES_PER_ROBOT:
        cache.clear()
    out = Scene(robot, cell)
    cache[id(cell)] = (cell, out)
    return out
