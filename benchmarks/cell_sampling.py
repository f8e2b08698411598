"""The sampling baseline of ``benchmarks/bench_cell.py``: pyroboplan 1.3.1, then TOPP-RA, checked densely here.

What a MoveIt-, MPlib- or pyroboplan-style user gets in a cell, on the same task as the jump: the default robot
from its own URDF (``robot.urdf``, Pinocchio's collision model of its ``<collision>`` elements), the cell's
obstacles as coal shapes on the world, the same pairs checked (every link against every obstacle, and the
self-collision pairs the package's scene checks), the same margin, the same limits (``robot.limits``: joint
velocity and acceleration) and the same pick-and-place rule, imposed as three segments planned one after
the other:

1. LIFT: the joint line from A to above A (the closed-form IK of A raised to ``z_top = max(zA, zB) + 25 mm``:
   only the quill moves, the tool stays above A);
2. TRAVERSE: pyroboplan's RRT-Connect (bidirectional) from above A to above B in a copy of the model whose
   quill range is cut at the height of ``z_top`` (every sample, node and interpolated point is then at or
   above z_top: the gate), then path shortcutting;
3. DESCENT: the joint line from above B to B.

The joint space sampled is the robot's whole one (J4 too: a SCARA's planning group has its four joints;
the yaw is the same at both ends, and shortcutting removes most of J4's detours). A path-following timing
cannot blend the corner between a vertical lift and a traverse in another joint direction: the motion
comes to rest at the two gates, as the three plans of a MoveIt user do.

**Timing.** Each segment is a cubic spline through its waypoints (``toppra.SplineInterpolator``, chord-length
knots; two waypoints: a line), timed by TOPP-RA (seidel, joint velocity and acceleration constraints,
interpolation discretisation, rest to rest) on a FIXED grid of :data:`GRID` equal steps plus the knots,
with toppra's constant-acceleration parametrizer (exact on a line; its default cubic-spline parametrizer
overshoots the acceleration next to every switch, 1.27x on the lift alone). The output is sampled at
:data:`RATE` and, where a velocity or acceleration exceeds its limit between grid points, played slower by
the smallest factor ``k`` that brings every sampled ratio to 1 (velocities scale by 1/k, accelerations by
1/k^2; the path is unchanged): the motion reported is that valid one, with k reported. For information, the
worst ratios of toppra's defaults (its own grid and parametrizer) are reported too.

**Checks, done here** (:class:`DenseCheck`): every checked pair's distance (coal, through Pinocchio's
``computeDistances``, GJK/EPA tolerances 1e-10 m) at every sample at :data:`RATE`, the joint range, the
limits and the rule (the tool at or above z_top, or within 5 mm of A or of B horizontally). A spline through
the shortcut waypoints may leave the checked polyline (bulge into an obstacle, dip below z_top). So two
traverses are timed and checked for every seed: the spline through the shortcut waypoints, and the spline
through the same polyline resampled every :data:`DENSE_STEP` (it hugs the polyline and slows at its
corners; sometimes faster than the first, which may bulge); the faster VALID one is reported. If neither is
valid, the polyline itself with a rest at each corner (RRT and the shortcutting checked it). The planning
time counts every timing done (and RRT, the shortcutting), not the checks.

**What is corrected, and reported.** pyroboplan 1.3.1's ``shortcut_path`` as shipped (i) drops a point when
it splices (it writes ``q_low`` at ``idx_low`` and then keeps ``path[:idx_low] + path[idx_high - 1:]``: the
segment from ``path[idx_low - 1]`` to ``q_high`` was never checked), (ii) checks without the planner's
distance padding (the requests' ``security_margin`` is reset to 0), and (iii) edits the list it is given.
It is run as shipped (on a copy, same seed, same step) and its output checked densely: how deep it goes is
reported (coal's signed distance: a quill "362 mm deep" in a post is a path through it). The motion timed
comes from :func:`shortcut`, the same algorithm with the splice, the padding and the copy fixed. pyroboplan
draws its samples from numpy's GLOBAL generator (``np.random.seed`` in ``RRTPlanner.reset``): each seed is
set there, and again before each shortcutting.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:
    from scara_pin import Robot
    from scara_pin.cell import Cell

RATE = 10_000.0
"""[Hz] the dense checks."""
GRID = 1000
"""Equal steps of TOPP-RA's fixed grid (the knots are added)."""
STEP = 0.01
"""[rad or m, joint-space norm] pyroboplan's ``max_step_size``: collision checks along every edge (its default is
0.05, about 20 mm of tool travel at full reach; 0.01 is about 4 mm)."""
DENSE_STEP = 0.05
"""[joint-space norm] the spacing of the waypoints of the second try's spline along the polyline."""
CHECK_STEP = 0.001
"""[joint-space norm] the step of the dense check of a polyline (a path, untimed)."""
RULE_RADIUS = 0.005
"""[m] the jump rule: within this of A or B horizontally the tool may be below z_top."""
RISE = 0.025
"""[m] z_top = max(zA, zB) + RISE."""
TOL = 1e-6
"""[m, relative] what counts as kept: distances >= margin - TOL, ratios <= 1 + TOL, the rule missed by <= TOL."""
PLANNER = dict(max_step_size=STEP, max_connection_dist=5.0, rrt_connect=True, bidirectional_rrt=True, rrt_star=False,
               max_planning_time=10.0, fast_return=True, goal_biasing_probability=0.15)  # fmt: skip
"""pyroboplan's RRT options (its examples' values, RRT-Connect on, the step above); the padding is the margin."""
SHORTCUT_ITERATIONS = 100
"""pyroboplan's default ``max_iters`` of the shortcutting."""


# ---------------------------------------------------------------------------------------------- geometry
class DenseCheck:
    """The robot from its URDF (Pinocchio, coal) in a cell: the planner's collision model and the dense checker.

    Attributes:
        model: Pinocchio's model of ``robot.urdf``.
        planner_gm: the collision model given to pyroboplan (its default coal requests).
        labels: ``link - obstacle`` or ``link - link (self)`` per checked pair.
    """

    def __init__(self, robot: Robot, cell: Cell) -> None:
        from scara_pin.cell import scene

        self.robot = robot
        self.cell = cell
        self.margin = cell.margin
        model = pin.buildModelFromXML(robot.urdf)
        gm = pin.buildGeomFromUrdfString(model, robot.urdf, pin.GeometryType.COLLISION)
        data = model.createData()
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        self.oMb = pin.SE3(data.oMf[model.getFrameId(robot.model.frames[robot.base_id].name)])
        self.tool = model.getFrameId(robot.model.frames[robot.tool_id].name)
        links = [model.frames[g.parentFrame].name for g in gm.geometryObjects]
        n_robot = gm.ngeoms
        for o in cell.obstacles:
            gm.addGeometryObject(pin.GeometryObject(o.name, 0, 0, self.oMb * o.shape.placement(), o.shape.geometry()))
        # the same pairs as the jump: every link against every obstacle; the self pairs the package's scene checks
        self_pairs = {frozenset(p) for p in scene(robot, cell).self_pairs.checked}
        labels = []
        for i in range(n_robot):
            for j in range(n_robot, gm.ngeoms):
                gm.addCollisionPair(pin.CollisionPair(i, j))
                labels.append(f"{links[i]} - {gm.geometryObjects[j].name}")
        for i in range(n_robot):
            for j in range(i + 1, n_robot):
                if frozenset((links[i], links[j])) in self_pairs:
                    gm.addCollisionPair(pin.CollisionPair(i, j))
                    labels.append(f"{links[i]} - {links[j]} (self)")
        found = {frozenset(lab.removesuffix(" (self)").split(" - ")) for lab in labels if lab.endswith("(self)")}
        if found != self_pairs:
            raise RuntimeError(f"self pairs {sorted(map(sorted, self_pairs))} not all found in the URDF's geometry")
        self.model = model
        self.planner_gm = gm
        self.labels = tuple(labels)
        self._gm = pin.GeometryModel(gm)
        self._gd = self._gm.createData()
        for req in self._gd.distanceRequests:
            req.gjk_tolerance = req.epa_tolerance = 1e-10
            req.epa_max_iterations = 1000
            req.enable_signed_distance = True
        self._data = model.createData()

    def distances(self, Q: np.ndarray) -> np.ndarray:
        """(n, pairs) signed distances [m] at each configuration (rows of Q)."""
        out = np.empty((len(Q), len(self.labels)))
        for k, q in enumerate(Q):
            pin.computeDistances(self.model, self._data, self._gm, self._gd, q)
            out[k] = [r.min_distance for r in self._gd.distanceResults]
        return out

    def tool_positions(self, Q: np.ndarray) -> np.ndarray:
        """(n, 3) the tool frame's origin in the robot's base frame [m]."""
        inv = self.oMb.inverse()
        out = np.empty((len(Q), 3))
        for k, q in enumerate(Q):
            pin.framesForwardKinematics(self.model, self._data, q)
            out[k] = inv.act(self._data.oMf[self.tool].translation)
        return out

    def closest(self, Q: np.ndarray) -> tuple[float, str]:
        """(smallest distance [m], its pair) over the configurations."""
        D = self.distances(Q)
        k = int(np.argmin(D.min(axis=0)))
        return float(D[:, k].min()), self.labels[k]


@dataclass(frozen=True)
class Task:
    """A jump task: endpoints, gates above them and the rule (base frame, SI)."""

    A: np.ndarray
    B: np.ndarray
    qA: np.ndarray
    qB: np.ndarray
    topA: np.ndarray
    topB: np.ndarray
    z_top: float

    def rule_miss(self, P: np.ndarray) -> float:
        """[m] how far the worst tool position is from the allowed region (0 when kept)."""
        dA = np.hypot(P[:, 0] - self.A[0], P[:, 1] - self.A[1]) - RULE_RADIUS
        dB = np.hypot(P[:, 0] - self.B[0], P[:, 1] - self.B[1]) - RULE_RADIUS
        below = self.z_top - P[:, 2]
        return float(max(np.minimum(np.minimum(dA, dB), below).max(), 0.0))


def task(robot: Robot, A: np.ndarray, B: np.ndarray, qA: np.ndarray, qB: np.ndarray) -> Task:
    """The gates above A and B at z_top (closed-form IK nearest the ends: only the quill moves)."""
    z_top = max(A[2], B[2]) + RISE
    tops = []
    for pose, q in ((A, qA), (B, qB)):
        top = np.array(robot.ik(np.array([pose[0], pose[1], z_top, pose[3]])).nearest(q).q, dtype=float)
        if not np.allclose(np.delete(top, 2), np.delete(q, 2), atol=1e-9):
            raise RuntimeError("the gate above an end is not a quill move")
        tops.append(top)
    return Task(A, B, np.asarray(qA, float), np.asarray(qB, float), tops[0], tops[1], float(z_top))


# ---------------------------------------------------------------------------------------------- timing
@dataclass
class Timed:
    """A segment timed by TOPP-RA, played ``k`` times slower (k >= 1)."""

    traj: Any
    waypoints: np.ndarray
    k: float = 1.0

    @property
    def duration(self) -> float:
        return float(self.traj.duration) * self.k

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = np.clip(t / self.k, 0.0, float(self.traj.duration))
        return self.traj(s), self.traj(s, 1) / self.k, self.traj(s, 2) / self.k**2


def _knots(waypoints: np.ndarray) -> np.ndarray:
    """Chord-length knots of a joint path."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(waypoints, axis=0), axis=1))])


def time_path(waypoints: np.ndarray, v: np.ndarray, a: np.ndarray, grid: int | None) -> Timed:
    """TOPP-RA (rest to rest) on the spline through the waypoints.

    ``grid``: that many equal steps plus the knots, and toppra's constant-acceleration parametrizer (the path
    acceleration constant between grid points: exact on a straight line); None: toppra's defaults, its own
    grid and its cubic-spline parametrizer (what a first try gets).
    """
    import toppra
    import toppra.algorithm
    import toppra.constraint

    knots = _knots(waypoints)
    path = toppra.SplineInterpolator(knots, waypoints)
    cons = [toppra.constraint.JointVelocityConstraint(v),
            toppra.constraint.JointAccelerationConstraint(
                a, discretization_scheme=toppra.constraint.DiscretizationType.Interpolation)]  # fmt: skip
    points = None if grid is None else np.unique(np.concatenate([np.linspace(0.0, knots[-1], grid + 1), knots]))
    how = None if grid is None else "ParametrizeConstAccel"
    algo = toppra.algorithm.TOPPRA(cons, path, gridpoints=points, solver_wrapper="seidel", parametrizer=how)
    out = algo.compute_trajectory(0, 0)
    if out is None:
        raise RuntimeError("TOPP-RA found no parameterization")
    return Timed(out, waypoints)


def _times(duration: float) -> np.ndarray:
    return np.linspace(0.0, duration, max(int(math.ceil(duration * RATE)), 1) + 1)


def ratios(seg: Timed, v: np.ndarray, a: np.ndarray) -> tuple[float, float]:
    """(worst velocity ratio, worst acceleration ratio) at RATE."""
    _, qd, qdd = seg.sample(_times(seg.duration))
    return float(np.max(np.abs(qd) / v)), float(np.max(np.abs(qdd) / a))


def within_limits(seg: Timed, v: np.ndarray, a: np.ndarray) -> Timed:
    """The segment played slower by the smallest k that brings every sampled ratio to 1.

    The samples move with k (RATE is in the new time), so k is raised until the samples at the new times keep
    the limits too (a few rounds at most).
    """
    for _ in range(50):
        rv, ra = ratios(seg, v, a)
        excess = max(rv, math.sqrt(ra))
        if excess <= 1.0:
            return seg
        seg = Timed(seg.traj, seg.waypoints, seg.k * excess * (1.0 + 1e-9))
    raise RuntimeError(f"the segment still exceeds a limit after 50 slow-downs ({rv:.6g}, {ra:.6g})")


@dataclass
class Motion:
    """Segments played one after the other (each from rest to rest)."""

    segments: list[Timed]

    @property
    def duration(self) -> float:
        return sum(s.duration for s in self.segments)

    @property
    def k(self) -> float:
        return max(s.k for s in self.segments)

    def sample(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at RATE over every segment, both ends of each included."""
        parts = [s.sample(_times(s.duration)) for s in self.segments]
        return tuple(np.concatenate([p[i] for p in parts]) for i in range(3))  # type: ignore[return-value]


@dataclass
class Verdict:
    """A motion checked densely."""

    distance: float
    pair: str
    rule_miss: float
    ratio: float
    range_ok: bool

    def valid(self, margin: float) -> bool:
        return (self.distance >= margin - TOL and self.rule_miss <= TOL and self.ratio <= 1.0 + TOL
                and self.range_ok)  # fmt: skip

    def why(self, margin: float) -> str:
        out = []
        if self.distance < margin - TOL:
            a, b = self.pair.removesuffix(" (self)").split(" - ")
            d = self.distance * 1e3
            how = f"{-d:.1f} mm deep in" if d < 0 else f"{d:.4f} mm from"
            out.append(f"{a} {how} {b}")
        if self.rule_miss > TOL:
            out.append(f"rule missed by {self.rule_miss * 1e3:.2f} mm")
        if self.ratio > 1.0 + TOL:
            out.append(f"limit ratio {self.ratio:.3f}")
        if not self.range_ok:
            out.append("joint range")
        return ", ".join(out) or "valid"


def verify(check: DenseCheck, job: Task, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, v: np.ndarray,
           a: np.ndarray) -> Verdict:  # fmt: skip
    """Distances, the rule, the limits and the joint range at every sample."""
    d, pair = check.closest(q)
    lim = check.robot.limits
    range_ok = bool(np.all(q >= np.array(lim.lower) - 1e-9) and np.all(q <= np.array(lim.upper) + 1e-9))
    ratio = float(max(np.max(np.abs(qd) / v), np.max(np.abs(qdd) / a)))
    return Verdict(d, pair, job.rule_miss(check.tool_positions(q)), ratio, range_ok)


def polyline(waypoints: list[np.ndarray] | np.ndarray, step: float = CHECK_STEP) -> np.ndarray:
    """Points along a joint polyline, at most ``step`` apart (joint-space norm), ends included."""
    W = np.asarray(waypoints, dtype=float)
    out = [W[:1]]
    for w0, w1 in zip(W[:-1], W[1:]):
        n = max(int(math.ceil(np.linalg.norm(w1 - w0) / step)), 1)
        out.append(w0 + np.linspace(0.0, 1.0, n + 1)[1:, None] * (w1 - w0))
    return np.concatenate(out)


# ---------------------------------------------------------------------------------------------- planning
def shortcut(model: Any, gm: Any, path: list[np.ndarray], margin: float, iterations: int = SHORTCUT_ITERATIONS,
             step: float = STEP) -> list[np.ndarray]:  # fmt: skip
    """pyroboplan's ``shortcut_path`` with its splice, padding and aliasing fixed (module docstring): two random
    points along the path (arc length), joined when the segment between them is clear (checked every ``step``
    with the margin); same random draws as the original."""
    from pyroboplan.core.utils import check_collisions_along_path
    from pyroboplan.planning.path_shortcutting import (
        get_configuration_from_normalized_path_scaling,
        get_normalized_path_scaling,
    )
    from pyroboplan.planning.utils import discretize_joint_space_path

    def clear(q0: np.ndarray, q1: np.ndarray) -> bool:
        return not check_collisions_along_path(model, gm, discretize_joint_space_path([q0, q1], step),
                                               distance_padding=margin)  # fmt: skip

    out = [np.array(q, dtype=float) for q in path]
    if len(out) < 3:
        return out
    changed = True
    for _ in range(iterations):
        if len(out) < 3:
            break
        if changed and len(out) == 3 and clear(out[0], out[2]):
            return [out[0], out[2]]
        changed = False
        scale = get_normalized_path_scaling(out)
        low, high = sorted(np.random.random(2))
        q_low, i_low = get_configuration_from_normalized_path_scaling(out, scale, low)
        q_high, i_high = get_configuration_from_normalized_path_scaling(out, scale, high)
        if i_low == i_high:
            continue
        if clear(q_low, q_high):
            out = out[:i_low] + [q_low, q_high] + out[i_high:]
            changed = True
    return out


@dataclass
class Seed:
    """One seed's result."""

    seed: int
    found: bool
    wall: float = math.nan
    cpu: float = math.nan
    rrt_waypoints: int = 0
    waypoints: int = 0
    shipped: float = math.nan  # smallest distance along the as-shipped shortcut's polyline [m]
    shipped_pair: str = ""
    fixed: float = math.nan  # the same for the corrected shortcut
    default_grid: tuple[float, float] = (math.nan, math.nan)  # worst (velocity, acceleration) ratios, toppra's grid
    fine_grid: tuple[float, float] = (math.nan, math.nan)  # the same on the fixed grid, before the slow-down
    k: float = math.nan
    tries: list[tuple[str, float, Verdict]] = field(default_factory=list)  # (how, duration, verdict) timed
    used: str = ""  # "spline", "dense spline" or "polyline": the motion reported
    duration: float = math.nan  # the valid motion's
    verdict: Verdict | None = None
    notes: list[str] = field(default_factory=list)


def plan_seed(check: DenseCheck, job: Task, seed: int) -> Seed:
    """One seed: plan (timed: wall and CPU), then the checks (not timed)."""
    from pyroboplan.core.utils import check_collisions_along_path
    from pyroboplan.planning.path_shortcutting import shortcut_path
    from pyroboplan.planning.rrt import RRTPlanner, RRTPlannerOptions
    from pyroboplan.planning.utils import discretize_joint_space_path

    lim = check.robot.limits
    v, a = np.array(lim.velocity), np.array(lim.acceleration)
    margin = check.margin
    # the gate: the quill's range cut at z_top (the tool is higher for a SMALLER quill value on a SCARA here)
    gate = pin.Model(check.model)
    z_of = check.tool_positions(np.array([job.topA, job.topA + np.eye(4)[2] * 1e-3]))[:, 2]
    if z_of[1] < z_of[0]:
        gate.upperPositionLimit[2] = job.topA[2]
    else:
        gate.lowerPositionLimit[2] = job.topA[2]
    t0, c0 = time.perf_counter(), time.process_time()
    options = RRTPlannerOptions(**PLANNER, rng_seed=seed, collision_distance_padding=margin)
    planner = RRTPlanner(gate, check.planner_gm, options)
    ends = []
    for q0, q1 in ((job.qA, job.topA), (job.topB, job.qB)):  # the lift and the descent: joint lines, checked
        if check_collisions_along_path(check.model, check.planner_gm, discretize_joint_space_path([q0, q1], STEP),
                                       distance_padding=margin):  # fmt: skip
            return Seed(seed, False, notes=["the lift or descent collides"])
        ends.append([q0, q1])
    rrt = planner.plan(job.topA, job.topB)
    if not rrt:
        return Seed(seed, False, time.perf_counter() - t0, time.process_time() - c0)
    np.random.seed(seed)
    traverse = shortcut(gate, check.planner_gm, rrt, margin)
    W = np.array(traverse)
    segments = [within_limits(time_path(np.array(ends[0]), v, a, GRID), v, a)]
    fine = time_path(W, v, a, GRID)
    segments += [within_limits(fine, v, a), within_limits(time_path(np.array(ends[1]), v, a, GRID), v, a)]
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    out = Seed(seed, True, wall, cpu, len(rrt), len(W))
    out.fine_grid = ratios(fine, v, a)
    out.k = max(s.k for s in segments)
    # -- checks (not timed)
    np.random.seed(seed)
    shipped = shortcut_path(gate, pin.GeometryModel(check.planner_gm), [np.array(q) for q in rrt], max_step_size=STEP)
    out.shipped, out.shipped_pair = check.closest(polyline(shipped))
    out.fixed = check.closest(polyline(W))[0]
    out.default_grid = ratios(time_path(W, v, a, None), v, a)
    spline = Motion(segments)
    # the second try, always, and the polyline if neither is valid (module docstring); planning time includes
    # every timing done
    tries = [("spline", spline, verify(check, job, *spline.sample(), v, a))]
    for used in ("dense spline", "polyline"):
        if used == "polyline" and any(v_.valid(margin) for _, _, v_ in tries):
            break
        t1, c1 = time.perf_counter(), time.process_time()
        if used == "dense spline":
            middle = [within_limits(time_path(polyline(W, DENSE_STEP), v, a, GRID), v, a)]
        else:
            middle = [within_limits(time_path(W[i : i + 2], v, a, GRID), v, a) for i in range(len(W) - 1)]
        motion = Motion([segments[0], *middle, segments[-1]])
        out.wall += time.perf_counter() - t1
        out.cpu += time.process_time() - c1
        tries.append((used, motion, verify(check, job, *motion.sample(), v, a)))
    out.tries = [(name, m.duration, ver) for name, m, ver in tries]
    valid = [t for t in tries if t[2].valid(margin)]
    out.used, motion, out.verdict = min(valid, key=lambda t: t[1].duration) if valid else tries[-1]
    out.duration = motion.duration
    return out


@dataclass
class CellResult:
    """The seeds of one cell and their summary."""

    name: str
    seeds: list[Seed]
    margin: float

    @property
    def valid(self) -> list[Seed]:
        return [s for s in self.seeds if s.found and s.verdict is not None and s.verdict.valid(self.margin)]

    def median(self) -> float:
        return statistics.median(s.duration for s in self.valid) if self.valid else math.nan

    def best(self) -> float:
        return min((s.duration for s in self.valid), default=math.nan)

    def planning(self) -> tuple[float, float]:
        found = [s for s in self.seeds if s.found]
        if not found:
            return math.nan, math.nan
        return statistics.median(s.wall for s in found), statistics.median(s.cpu for s in found)


def run_cell(robot: Robot, cell: Cell, name: str, A: np.ndarray, B: np.ndarray, qA: np.ndarray, qB: np.ndarray,
             seeds: range) -> CellResult:  # fmt: skip
    """Every seed of one cell, printed as it goes."""
    check = DenseCheck(robot, cell)
    job = task(robot, A, B, qA, qB)
    out = []
    for seed in seeds:
        s = plan_seed(check, job, seed)
        out.append(s)
        if not s.found:
            print(f"    {name:<7} seed {seed}: no path ({'; '.join(s.notes) or 'RRT timed out'})", flush=True)
            continue
        assert s.verdict is not None  # noqa: S101 - set for every path found
        shipped = (f"{s.shipped_pair} {-s.shipped * 1e3:.1f} mm deep" if s.shipped < 0 else
                   f"{s.shipped_pair} {s.shipped * 1e3:.2f} mm")  # fmt: skip
        tries = "; ".join(f"{how} {d:.4f} s {ver.why(cell.margin)}" for how, d, ver in s.tries)
        print(f"    {name:<7} seed {seed}: RRT {s.rrt_waypoints} -> shortcut {s.waypoints} waypoints | as shipped: "
              f"{shipped} | toppra default grid v {s.default_grid[0]:.2f}x a {s.default_grid[1]:.2f}x, fixed "
              f"grid a {s.fine_grid[1]:.4f}x -> slowed {s.k:.4f}x | {tries} => {s.used} {s.duration:.4f} s, min "
              f"{s.verdict.distance * 1e3:.3f} mm | planned in {s.wall:.2f} s wall, {s.cpu:.2f} s CPU", flush=True)
    return CellResult(name, out, cell.margin)
