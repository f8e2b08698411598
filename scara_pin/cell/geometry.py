"""The robot's own collision geometry: its links' ``<collision>`` elements, and which pairs of them are checked.

The shapes are the URDF's (Pinocchio's ``GeometryModel`` of the collision elements, coal primitives; meshes
read by :func:`scara_pin.cell.meshes.collision_meshes` and checked as coal's bounding-volume trees).
Each geometry belongs to a link (its name in messages) and moves with a joint.

**Self-collision pairs** are chosen as MoveIt's setup assistant does, automatically:

- pairs of geometries on the same link, or on ADJACENT links (a link and the nearest link above it in the
  tree that has geometry: they touch at their joint by design) are never checked;
- pairs IN CONTACT AT EVERY SAMPLED CONFIGURATION (:data:`SAMPLES` configurations drawn uniformly inside the
  joint limits, seeded, plus q = 0) are never checked: their contact is part of the design (a parallelogram's
  bars, a cable duct modelled as overlapping the arm);
- every other pair of links is checked: a contact there is a real collision.

The choice is a :class:`SelfPairs` (checked and disabled pairs, each disabled one with its reason) that
``scara-pin check --cell`` lists.
"""

from __future__ import annotations

import logging
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = ["SAMPLES", "RobotGeometry", "SelfPairs", "robot_geometry"]

log = logging.getLogger(__name__)

SAMPLES = 300
"""Configurations sampled (uniformly inside the limits, seeded) to find the pairs always in contact."""
_SEED = 20261127
_UNLIMITED = np.pi
"""[rad] the half-range sampled for a joint without finite limits (a continuous joint)."""


@dataclass(frozen=True)
class SelfPairs:
    """Which pairs of the robot's links are checked against each other.

    Attributes:
        checked: (link, link) pairs checked.
        disabled: (link, link, reason) pairs never checked; reason is ``"adjacent"`` or ``"always in contact"``.
    """

    checked: tuple[tuple[str, str], ...]
    disabled: tuple[tuple[str, str, str], ...]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"checked": [list(p) for p in self.checked],
                "disabled": [{"pair": [a, b], "reason": r} for a, b, r in self.disabled]}  # fmt: skip


@dataclass(frozen=True, eq=False)
class RobotGeometry:
    """The robot's collision geometry.

    Attributes:
        model: Pinocchio's collision ``GeometryModel`` on ``robot.model`` (real meshes, not placeholders).
        links: per geometry object, the link it belongs to.
        adjacent: the pairs of geometry indices never checked because they are on the same or adjacent links.
    """

    model: pin.GeometryModel
    links: tuple[str, ...]
    adjacent: frozenset[tuple[int, int]]


_GEOMETRY: weakref.WeakKeyDictionary[RobotModel, RobotGeometry] = weakref.WeakKeyDictionary()
"""Each robot's collision geometry, built once (the entry goes with the robot)."""


def robot_geometry(robot: RobotModel) -> RobotGeometry:
    """The robot's collision geometry (built once per robot; see the module docstring).

    Raises:
        InvalidInputError: a collision mesh cannot be read (distances to it could not be computed).
    """
    cached = _GEOMETRY.get(robot)
    if cached is not None:
        return cached
    from .meshes import collision_meshes

    gm = pin.GeometryModel(robot.collision_model)  # a copy: placeholders replaced below
    meshes = {m.name: m for m in collision_meshes(robot)} if "<mesh" in robot.urdf else {}
    for i, g in enumerate(gm.geometryObjects):
        mesh = meshes.get(g.name)
        if mesh is not None:
            bvh = coal.BVHModelOBBRSS()
            bvh.beginModel(len(mesh.faces), len(mesh.vertices))
            bvh.addVertices(np.asarray(mesh.vertices, dtype=float))
            bvh.addTriangles(np.asarray(mesh.faces, dtype=np.int64))
            bvh.endModel()
            obj = gm.geometryObjects[i]
            obj.geometry = bvh
            obj.meshScale = np.ones(3)
            gm.geometryObjects[i] = obj
    model = robot.model
    links = tuple(model.frames[g.parentFrame].name for g in gm.geometryObjects)
    joints = [g.parentJoint for g in gm.geometryObjects]
    with_geometry = set(joints)

    def geometric_parent(j: int) -> int:
        """The nearest joint above j that carries geometry (0, the root, at the top)."""
        p = model.parents[j]
        while p != 0 and p not in with_geometry:
            p = model.parents[p]
        return int(p)

    adjacent = set()
    for a in range(len(joints)):
        for b in range(a + 1, len(joints)):
            ja, jb = joints[a], joints[b]
            if ja == jb or (ja != 0 and geometric_parent(ja) == jb) or (jb != 0 and geometric_parent(jb) == ja):
                adjacent.add((a, b))
    out = RobotGeometry(gm, links, frozenset(adjacent))
    _GEOMETRY[robot] = out
    return out


def sample_configurations(robot: RobotModel, n: int = SAMPLES, seed: int = _SEED) -> np.ndarray:
    """(n + 1, dof) configurations: q = 0 (clipped into the limits) and n drawn uniformly inside the limits."""
    lo = np.array(robot.limits.lower, dtype=float)
    hi = np.array(robot.limits.upper, dtype=float)
    bad = ~(np.isfinite(lo) & np.isfinite(hi)) | np.array(robot.continuous)
    lo[bad], hi[bad] = -_UNLIMITED, _UNLIMITED
    rng = np.random.default_rng(seed)
    q = lo + (hi - lo) * rng.random((n, robot.dof))
    return np.vstack([np.clip(np.zeros(robot.dof), lo, hi), q])
