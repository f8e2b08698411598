"""``check --cell``: what a cell file does with a robot, as findings (a table of small rules).

Each rule takes the scene (the robot in its cell) and the configurations to look at, and returns findings
(``code``: severity):

- ``cell`` (info): the cell's obstacles, margin, carried part and the number of pairs checked;
- ``self-pair-checked`` / ``self-pair-disabled`` (info): the robot's self-collision pairs, each disabled one with
  its reason (adjacent links, always in contact at every sampled configuration, allowed by the cell:
  :mod:`scara_pin.cell.geometry`);
- ``self-pair-cost`` (info): a checked self pair that comes within the margin somewhere in the joint limits, and
  the range of its joints where it does (a pair that depends on one joint: that joint swept; else the share of
  configurations drawn in the limits): motions there are refused (a flange rising into its arm over the top of the
  stroke, a parallelogram's bars meeting);
- ``obstacle-out-of-reach`` (warning): an obstacle farther than the margin from the robot's REACH ENVELOPE
  (:func:`reach_envelope`) and from its fixed links, and outside the envelope's footprint too (beside the robot,
  not above or below it): no configuration brings any link (or the carried part) near it; a misplaced obstacle
  (another frame; millimetres written as metres when it is farther from the reach than the reach is wide), or
  one that does not matter;
- ``obstacle-beyond-stroke`` (info): an obstacle out of reach but inside the envelope's footprint, above or
  below it: a table or a tray under the lowest the tool goes, a ceiling; never touched (the part the tool
  carries, ``--carry``, goes lower than the bare flange);
- ``home-in-collision`` (warning): the robot at its home (q = 0, or a points file's point ``home``) closer than
  the margin, naming the pair and the distance: every motion from there is refused;
- ``point-in-collision`` (warning): a taught point closer than the margin (name, pair, distance).

The status is ``warnings`` (exit code 4) with any warning, else ``clean`` (0); a cell file that cannot be read
is an error of the command (exit code 2), not a finding here.

**The reach envelope** is a cylinder about the first joint's axis that holds every link's collision geometry
and the carried part at EVERY configuration. Along the chain from the first joint to a geometry's joint, while
every joint turns about an axis parallel to the first one (or slides along it), a rotation keeps each link's
offset's length across the axis and its height along it: the geometry's farthest point from the axis is at most
the sum of the joints' offsets across the axis plus its own extent across (the corners of its bounding box),
and its height is its height at q = 0 moved by the sliding joints' strokes. A chain with any other joint (a
tilted axis, a parallelogram) is bounded by the sum of the offsets' whole lengths both across and along the
axis. The envelope's radius is the largest bound over the geometries, its height range the union of theirs; a
geometry fixed to the base is not in it (it is checked as it stands).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

from .scene import describe

if TYPE_CHECKING:
    from .cell import Cell
    from .scene import Scene

__all__ = ["CellFinding", "CellReport", "Envelope", "check_cell", "reach_envelope"]

AXIS_TOL = 1e-12
"""|sin| of the angle between a joint's axis and the first joint's below which they are parallel."""
MAX_STROKE = 1e3
"""[m] a sliding joint without finite limits is bounded by this stroke in the envelope."""


@dataclass(frozen=True)
class CellFinding:
    """One thing found about a cell.

    Attributes:
        severity: ``"info"`` or ``"warning"``.
        code: a stable identifier (module docstring).
        message: one sentence with the numbers.
        data: JSON-ready details (the pair, the distance, the point's name, ...).
    """

    severity: str
    code: str
    message: str
    data: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"severity": self.severity, "code": self.code, "message": self.message, **self.data}


@dataclass(frozen=True)
class CellReport:
    """The findings on a cell with a robot.

    Attributes:
        source: the cell file.
        findings: in the order of the rules.
        self_pairs: the self-collision pairs (checked, disabled with reasons), JSON-ready.
        envelope: the reach envelope used.
    """

    source: str
    findings: tuple[CellFinding, ...]
    self_pairs: dict[str, Any]
    envelope: Envelope

    @property
    def status(self) -> str:
        """``warnings`` with any warning, else ``clean``."""
        return "warnings" if any(f.severity == "warning" for f in self.findings) else "clean"

    @property
    def exit_code(self) -> int:
        """4 with warnings, else 0."""
        return 4 if self.status == "warnings" else 0

    def codes(self, severity: str | None = None) -> list[str]:
        """The finding codes (of one severity, or all)."""
        return [f.code for f in self.findings if severity is None or f.severity == severity]

    def find(self, code: str) -> list[CellFinding]:
        """The findings with this code."""
        return [f for f in self.findings if f.code == code]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: source, status, exit_code, self_pairs, envelope, findings."""
        return {"source": self.source, "status": self.status, "exit_code": self.exit_code,
                "self_pairs": self.self_pairs, "envelope": self.envelope.to_dict(),
                "findings": [f.to_dict() for f in self.findings]}  # fmt: skip

    def format_text(self) -> str:
        """One line per finding (``file: severity: message [code]``), then the status line."""
        lines = [f"{self.source}: {f.severity}: {f.message} [{f.code}]" for f in self.findings]
        return "\n".join([*lines, f"{self.source}: {self.status}"])


@dataclass(frozen=True)
class Envelope:
    """A cylinder about the first joint's axis holding the robot's moving geometry at every configuration.

    Attributes:
        point: (3,) a point of the axis (the first joint's origin at q = 0) in the robot's base frame [m].
        axis: (3,) the axis, unit, in the base frame.
        radius: [m] across the axis.
        low, high: [m] the height range along the axis, from ``point``.
        exact_chain: every chain is of joints parallel to the first (the tight bound), else the whole lengths.
    """

    point: np.ndarray
    axis: np.ndarray
    radius: float
    low: float
    high: float
    exact_chain: bool

    def describe(self) -> str:
        """In words, for the findings."""
        how = "joints parallel to it" if self.exact_chain else "the whole lengths of the links (a joint not parallel)"
        p, a = (", ".join(f"{v:.6g}" for v in w) for w in (self.point, self.axis))
        return (f"a cylinder about the first joint's axis (through ({p}) m along ({a}) in the base frame) of radius "
                f"{self.radius:.6g} m, from {self.low:.6g} to {self.high:.6g} m along the axis, holding every link and "
                f"the carried part at every configuration (bounded along the chain by {how})")  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"point": self.point.tolist(), "axis": self.axis.tolist(), "radius": self.radius, "low": self.low,
                "high": self.high, "exact_chain": self.exact_chain}  # fmt: skip

    def geometry(self, oMbase: Any) -> tuple[Any, Any]:
        """(coal.Cylinder, coal.Transform3s) of the envelope in the world (``oMbase``: the base frame's placement)."""
        z = self.axis
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
        x /= np.linalg.norm(x)
        R = np.column_stack([x, np.cross(z, x), z])
        centre = self.point + z * 0.5 * (self.low + self.high)
        world = oMbase.rotation @ R, oMbase.act(centre)
        return coal.Cylinder(self.radius, max(self.high - self.low, 1e-9)), coal.Transform3s(*world)


def reach_envelope(scene: Scene) -> Envelope:
    """The reach envelope of the robot's moving geometry, carried part included (module docstring)."""
    from .sweep import joint_motion

    robot = scene.robot
    model = robot.model
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    first = 1  # the root's first child: the first joint of the chain
    motion = joint_motion(model.joints[first])
    base = data.oMi[first]
    a = base.rotation @ (motion[1] if motion is not None else np.array([0.0, 0.0, 1.0]))
    a = a / np.linalg.norm(a)
    o = base.translation.copy()
    lo_q, hi_q = _joint_limits(robot)

    def across(v: np.ndarray) -> float:
        return float(np.linalg.norm(v - a * float(v @ a)))

    radius, low, high, exact = 0.0, math.inf, -math.inf, True
    for g in scene.geometry_model.geometryObjects:
        j = int(g.parentJoint)
        if j == 0:
            continue
        chain = []
        k = j
        while k != 0:
            chain.append(k)
            k = model.parents[k]
        chain.reverse()
        # another branch of the tree (chain[0] != first): not parallel, bounded by whole lengths below
        parallel = chain[0] == first and all(_parallel(model, data, i, a) for i in chain)
        corners = _corners(g)  # in joint j's frame
        world = corners @ data.oMi[j].rotation.T  # offsets from joint j's origin, at q = 0
        strokes = [(lo_q[i], hi_q[i]) for i in chain if _is_prismatic(model, i)]
        if parallel:
            r = sum(across(data.oMi[i].translation - data.oMi[model.parents[i]].translation) for i in chain[1:])
            r += max(across(c) for c in world)
            h0 = float((data.oMi[j].translation - o) @ a)
            slide_lo = sum(min(s * lo, s * hi) for lo, hi, s in _signed(model, data, chain, strokes, a))
            slide_hi = sum(max(s * lo, s * hi) for lo, hi, s in _signed(model, data, chain, strokes, a))
            heights = world @ a
            low, high = min(low, h0 + slide_lo + heights.min()), max(high, h0 + slide_hi + heights.max())
        else:
            exact = False
            path = [k for k in chain if k != 0]
            r = sum(float(np.linalg.norm(data.oMi[i].translation - data.oMi[model.parents[i]].translation))
                    for i in path[1:])  # fmt: skip
            r += sum(max(abs(lo), abs(hi)) for lo, hi in strokes)
            r += float(np.linalg.norm(world, axis=1).max())
            h0 = float((data.oMi[path[0]].translation - o) @ a)
            low, high = min(low, h0 - r), max(high, h0 + r)
        radius = max(radius, r)
    if not math.isfinite(low):
        low = high = 0.0
    bMo = robot.data.oMf[robot.base_id].inverse()  # the base frame is fixed to the root
    return Envelope(bMo.act(o), bMo.rotation @ a, radius, low, high, exact)


def _joint_limits(robot: Any) -> tuple[dict[int, float], dict[int, float]]:
    """Per Pinocchio joint index with one q: its (lower, upper) limits, a missing one at +/- MAX_STROKE."""
    model = robot.model
    lo, hi = {}, {}
    for j in range(1, model.njoints):
        i = model.joints[j].idx_v
        if 0 <= i < robot.dof and model.joints[j].nv == 1:
            lower, upper = float(robot.limits.lower[i]), float(robot.limits.upper[i])
            lo[j] = lower if math.isfinite(lower) else -MAX_STROKE
            hi[j] = upper if math.isfinite(upper) else MAX_STROKE
        else:
            lo[j], hi[j] = -MAX_STROKE, MAX_STROKE
    return lo, hi


def _is_prismatic(model: Any, j: int) -> bool:
    from .sweep import joint_motion

    m = joint_motion(model.joints[j])
    return m is not None and m[0] == "P"


def _parallel(model: Any, data: Any, j: int, a: np.ndarray) -> bool:
    """Joint j turns about, or slides along, an axis parallel to ``a`` (at q = 0, so at every q of the chain)."""
    from .sweep import joint_motion

    m = joint_motion(model.joints[j])
    if m is None:
        return False
    axis = data.oMi[j].rotation @ m[1]
    return float(np.linalg.norm(np.cross(axis, a))) <= AXIS_TOL


def _signed(model: Any, data: Any, chain: Sequence[int], strokes: Sequence[tuple[float, float]], a: np.ndarray
            ) -> list[tuple[float, float, float]]:  # fmt: skip
    """(lower, upper, sign of the sliding axis along a) of each sliding joint of the chain."""
    from .sweep import joint_motion

    out = []
    prismatic = [j for j in chain if _is_prismatic(model, j)]
    for j, (lo, hi) in zip(prismatic, strokes):
        m = joint_motion(model.joints[j])
        assert m is not None  # noqa: S101 - prismatic
        out.append((lo, hi, float((data.oMi[j].rotation @ m[1]) @ a)))
    return out


def _corners(g: Any) -> np.ndarray:
    """(8, 3) corners of a geometry's local bounding box, in its joint's frame."""
    geometry = g.geometry
    geometry.computeLocalAABB()
    lo, hi = np.asarray(geometry.aabb_local.min_, float), np.asarray(geometry.aabb_local.max_, float)
    box = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return box @ g.placement.rotation.T + g.placement.translation


# ---------------------------------------------------------------------------------------------- the rules
def _summary(scene: Scene, configurations: Sequence[tuple[str, np.ndarray]]) -> list[CellFinding]:
    cell = scene.cell
    carried = "" if cell.carried is None else f", carrying a {cell.carried.describe()}"
    text = (f"{len(cell.obstacles)} obstacle(s), margin {cell.margin * 1e3:g} mm{carried}; {len(scene.pairs)} pairs "
            f"checked ({sum(p.kind == 'obstacle' for p in scene.pairs)} with obstacles, "
            f"{sum(p.kind == 'self' for p in scene.pairs)} between the robot's own shapes)")  # fmt: skip
    return [CellFinding("info", "cell", text, {"obstacles": len(cell.obstacles), "pairs": len(scene.pairs)})]


def _self_pairs(scene: Scene, configurations: Sequence[tuple[str, np.ndarray]]) -> list[CellFinding]:
    out = [CellFinding("info", "self-pair-checked", f"{a} - {b}: checked", {"pair": [a, b]})
           for a, b in scene.self_pairs.checked]  # fmt: skip
    reasons = {"adjacent": "adjacent links (they meet at their joint)",
               "always in contact": "in contact at every sampled configuration (part of the design)",
               "allowed by the cell": "allowed by the cell's allow list"}  # fmt: skip
    out += [CellFinding("info", "self-pair-disabled", f"{a} - {b}: never checked: {reasons.get(r, r)}",
                        {"pair": [a, b], "reason": r}) for a, b, r in scene.self_pairs.disabled]  # fmt: skip
    return out


def _out_of_reach(scene: Scene, configurations: Sequence[tuple[str, np.ndarray]]) -> list[CellFinding]:
    env = reach_envelope(scene)
    base = scene.robot.data.oMf[scene.robot.base_id]
    cylinder, placement = env.geometry(base)
    gm = scene.geometry_model
    fixed = [i for i, g in enumerate(gm.geometryObjects) if g.parentJoint == 0 and not g.name.startswith("obstacle:")]
    column, column_at = replace(env, low=-MAX_STROKE, high=MAX_STROKE).geometry(base)  # the envelope's footprint
    out = []
    for o in scene.cell.obstacles:
        index = gm.getGeometryId(f"obstacle:{o.name}")
        obj = gm.geometryObjects[index]
        M = coal.Transform3s(obj.placement.rotation, obj.placement.translation)
        d = _distance(cylinder, placement, obj.geometry, M)
        near_fixed = [gm.geometryObjects[i].name for i in fixed
                      if _distance(gm.geometryObjects[i].geometry, _transform(gm.geometryObjects[i]), obj.geometry, M)
                      <= scene.margin]  # fmt: skip
        if d <= scene.margin or near_fixed:
            continue
        data = {"obstacle": o.name, "distance": d}
        if _distance(column, column_at, obj.geometry, M) <= scene.margin:  # above or below the reach: not misplaced
            heights = (o.shape.corners() - env.point) @ env.axis  # along the first joint's axis
            where = "below" if float(heights.max()) < env.low else "above"
            lower = (" (a part the tool carries reaches lower than the bare flange: --carry, or the cell's "
                     "carried:)") if where == "below" and scene.cell.carried is None else ""  # fmt: skip
            out.append(CellFinding("info", "obstacle-beyond-stroke",
                                   f"obstacle {o.name} is {where} the robot's reach: {d:.6g} m from its reach "
                                   f"envelope, inside its footprint; no link ever comes within the margin "
                                   f"{scene.margin * 1e3:g} mm of it{lower}", data))  # fmt: skip
            continue
        units = " millimetres as metres?" if d > env.radius else ""
        out.append(CellFinding("warning", "obstacle-out-of-reach",
                               f"obstacle {o.name} is out of reach: {d:.6g} m from the robot's reach envelope "
                               f"({env.describe()}), more than the margin {scene.margin * 1e3:g} mm: no "
                               f"configuration brings it near the robot (misplaced?{units})", data))  # fmt: skip
    return out


def _transform(obj: Any) -> Any:
    return coal.Transform3s(obj.placement.rotation, obj.placement.translation)


def _distance(g1: Any, M1: Any, g2: Any, M2: Any) -> float:
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    return float(coal.distance(g1, M1, g2, M2, req, res))


def _configurations(scene: Scene, configurations: Sequence[tuple[str, np.ndarray]]) -> list[CellFinding]:
    out = []
    for name, q in configurations:
        found = scene.distances(q)
        c = found.closest
        if c is None or c.distance >= scene.margin:
            continue
        home = name.startswith("home")
        code = "home-in-collision" if home else "point-in-collision"
        what = f"the robot at its {name}" if home else f"point {name}"
        out.append(CellFinding("warning", code, f"{what} is in collision: {describe(c, scene.margin)}",
                               {"point": name, "q": np.asarray(q, float).tolist(), "pair": [c.pair.a, c.pair.b],
                                "distance": c.distance, "below": [[p.pair.a, p.pair.b, p.distance]
                                                                  for p in found.below()]}))  # fmt: skip
    return out


def _self_pair_costs(scene: Scene, configurations: Sequence[tuple[str, np.ndarray]]) -> list[CellFinding]:
    """The checked self pairs that come within the margin somewhere in the joint limits, and the range it costs."""
    from .sweep import pair_joints

    robot = scene.robot
    lo = np.where(np.array(robot.continuous), -math.pi, np.array(robot.limits.lower, dtype=float))
    hi = np.where(np.array(robot.continuous), math.pi, np.array(robot.limits.upper, dtype=float))
    out = []
    for k, dims in enumerate(pair_joints(scene)):
        pair = scene.pairs[k]
        if pair.kind != "self" or not dims:
            continue
        if len(dims) == 1:  # a sweep of that joint (the others change nothing)
            (j,) = dims
            Q = np.tile(np.clip(robot.default_q, lo, hi), (_COST_SAMPLES, 1))
            Q[:, j] = np.linspace(lo[j], hi[j], _COST_SAMPLES)
        else:
            Q = lo + (hi - lo) * np.random.default_rng(9).random((_COST_SAMPLES, robot.dof))
        near = scene.distance_array(Q, [k])[:, 0] < scene.margin
        if not near.any():
            continue
        ranges = {robot.joint_names[j]: [float(Q[near, j].min()), float(Q[near, j].max())] for j in sorted(dims)}
        where = ", ".join(f"{name} in {_shown(robot, name, r)}" for name, r in ranges.items())
        how = "over" if len(dims) == 1 else f"at {100.0 * near.mean():.2g} % of {_COST_SAMPLES} configurations drawn in"
        out.append(CellFinding("info", "self-pair-cost", f"{pair.a} - {pair.b}: within the margin {how} the joint "
                               f"limits, where {where}: motions there are refused",
                               {"pair": [pair.a, pair.b], "share": float(near.mean()), "ranges": ranges}))  # fmt: skip
    return out


_COST_SAMPLES = 2001
"""Configurations a self pair is looked at (a sweep of its one joint, or drawn in the limits) for its cost."""


def _shown(robot: Any, joint: str, r: list[float]) -> str:
    """``[-50, -8.04] mm`` or ``[30.2, 85] deg``: a joint's range in human units."""
    j = robot.joint_names.index(joint)
    if robot.joint_kinds[j] == "length":
        return f"[{r[0] * 1e3:.4g}, {r[1] * 1e3:.4g}] mm"
    return f"[{math.degrees(r[0]):.4g}, {math.degrees(r[1]):.4g}] deg"


RULES = (_summary, _self_pairs, _self_pair_costs, _out_of_reach, _configurations)
"""The rules, in the order their findings are listed."""


def check_cell(scene: Scene, configurations: Sequence[tuple[str, Any]] = (), source: str | None = None
               ) -> CellReport:  # fmt: skip
    """The findings on a robot in its cell (module docstring).

    Args:
        scene: the robot in its cell (:func:`scara_pin.cell.scene`).
        configurations: (name, q) to check: the home first (named ``home ...``), then taught points.
        source: how to name the cell in the report (default: the cell's origin).

    Returns:
        The report; ``exit_code`` 4 with warnings, else 0.
    """
    cell: Cell = scene.cell
    qs = [(name, scene.robot.check_q(q)) for name, q in configurations]
    findings: list[CellFinding] = []
    for rule in RULES:
        findings += rule(scene, qs)
    return CellReport(source or cell.origin, tuple(findings), scene.self_pairs.to_dict(), reach_envelope(scene))
