"""Obstacles in the time-optimal jump: separating planes, re-set after every solve, and warm starts.

The jump (:mod:`~scara_pin.motion.jump`) is solved with every checked pair of the cell
(:class:`~scara_pin.cell.Scene`: the robot's links and the carried part against the obstacles, and the
robot's self-collision pairs) at least ``margin`` apart. A pair's distance (coal's, exact shapes) is not a
CasADi expression, so it enters the NLP through SEPARATING PLANES (sequential convex programming, in the
spirit of TrajOpt, with the robot's kinematics kept exact): a ROW is one pair at one point of the motion (a
node, or a point inside an interval: its state is the interval's polynomial, so the row holds exactly where
it is placed), with a plane taken from coal's witness points and normal at the last solution, fixed to the
second shape's joint (an obstacle's plane is fixed in the cell). The row asks for

    n . (p - x) >= margin + BUFFER   for every point x of the first shape, at the row's configuration,

written with the shape's support function (a box, a cylinder, a sphere: closed form, |x| smoothed as
sqrt(x^2 + eps^2), which only makes the shape look larger by at most eps times its size, ``_SMOOTH``; a
mesh: its witness point) and the forward kinematics of the shape's joint written in CasADi from the model
(:attr:`~scara_pin.symbolic.SymbolicModel.joint_frames`). For a CONVEX second shape the plane
through its witness point supports it, so a row that holds keeps the pair at least the margin apart: the
rows are conservative, exactly as the planes are tangent, and re-setting them at each solution lets the
motion slide along the obstacle until it converges. After each solve:

- every row's plane is re-set at the new solution (only parameters change: the NLP is not rebuilt); a row
  whose pair is in contact there keeps its plane (a penetration's normal says little about the way out),
  or, when new, takes it from the last motion found clear of the cell;
- the motion is checked densely (:data:`CHECK_POINTS` points in every interval, every pair): a row is
  added at every node (:data:`ROW_POINTS`) where a pair comes within :data:`ACTIVATION` of the margin, and,
  per interval and pair closer than the margin, at the worst sample (at its nearest node unless a row is
  there already);

until no row is added, no checked distance is below ``margin`` by more than :data:`CONVERGED` and the
duration changes by less than :data:`CONVERGED_TIME` (relative). A re-solve found infeasible (planes from a
motion in contact that conflict) is retried once from the last motion clear of the cell with all its
planes taken there (that motion satisfies them all). The result then goes through the verifier at 10 kHz
with every pair's exact distance (:func:`~scara_pin.motion.verify.verify`).

**Warm starts.** A local method finds the locally fastest motion around or over an obstacle from where it
starts. The jump's usual warm start (joint lines A -> above A -> above B -> B) is checked against the cell;
when it collides, candidates are made (:func:`candidates`): OVER (the traverse raised until it clears, up to
the stroke or the ceiling) and AROUND on either side (a via point beside the first collision, moved out
until the path clears, at the traverse height, and, when no way clears there, up to two steps above it:
around one obstacle and over a lower one). The clear candidates are ranked by the duration of their joint
lines; the best is solved, and the second when it is another way (over / left / right) and not much slower; the faster
verified motion wins. A concave mesh obstacle is handled by the same rows (its witness points), but the
plane property above holds only locally there.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InfeasibleError
from .trajectory import line_optimal_duration

if TYPE_CHECKING:
    from ..cell import PairDistance, Scene
    from ..model import RobotModel
    from ..symbolic import SymbolicModel
    from .polynomial import PolynomialPiece

__all__ = [
    "ACTIVATION",
    "BUFFER",
    "CHECK_POINTS",
    "CONVERGED",
    "DISTANCE_SCALE",
    "Candidate",
    "DistanceRow",
    "Rows",
    "candidates",
]

log = logging.getLogger(__name__)

DISTANCE_SCALE = 0.01
"""[m] the scale of the distance rows in the NLP (their values over it are of order 1)."""
BUFFER = 1e-6
"""[m] the rows keep margin + BUFFER: the verified distance then stays above margin - 1e-6 between rows."""
ACTIVATION = 0.005
"""[m] a pair within margin + ACTIVATION of each other at a node gets a row there."""
CHECK_POINTS = 16
"""Points checked in every interval after each solve (its start node and 15 inside)."""
ROW_POINTS = (0.0,)
"""Where rows go in an interval (fractions of it; 0 is its start node)."""
CONVERGED = 1e-7
"""[m] the largest shortfall below the margin at the checked points when the iterations stop."""
FINE_WITHIN = 0.005
"""[m] a pair this close to the margin in an interval at the checked points is checked at the verifier's rate there
once the iterations have converged (:meth:`Rows.fine`)."""
CONVERGED_TIME = 1e-6
"""Relative change of the duration between two solves below which the re-setting of the planes has converged."""
DEEP = 0.001
"""[m] a solution this far inside the margin is not re-solved from: the next solve starts from the last clear one."""
RESOLVE_ITERATIONS = 500
"""IPOPT iterations allowed to a re-solve (warm-started from the last solution; the first solve has the jump's)."""
_PATH_SAMPLES = 40
"""Samples of each joint line of a warm-start candidate checked against the cell."""
SLACK = 0.001
"""[m] a warm start counts as clear when its sampled joint lines keep the margin plus this."""
_RAISED_AROUND = 2
"""Heights above the traverse height (in steps of _STEP) at which AROUND candidates are also tried."""
_STEP = 0.005
"""[m] the step of the heights and offsets tried by the candidates."""
_MAX_OFFSET = 0.4
"""[m] the largest plan-view offset of an AROUND candidate's via point."""
_MAX_RAISE = 1.0
"""[m] how far an OVER candidate raises the traverse when no prismatic joint bounds it (a palletizer's arm lifts
the tool by turning: the raise stops where the IK fails, or here)."""
_SMOOTH = 1e-3
"""The eps of the smoothed |x| = sqrt(x^2 + eps^2) in the shapes' supports (at most eps times a size: safe)."""
SECOND_WITHIN = 1.3
"""The second candidate is solved too when its joint lines take at most this times the best's."""


@dataclass(frozen=True)
class DistanceRow:
    """One pair at one point of the motion: interval ``k`` at fraction ``sigma`` (a node is sigma = 0)."""

    k: int
    sigma: float
    pair: int


@dataclass(frozen=True)
class Candidate:
    """A warm start: joint waypoints A, above A, [via], above B, B, and how it goes.

    Attributes:
        way: ``"straight"``, ``"over"``, ``"left"`` or ``"right"`` (``"left, raised"``: above the traverse height).
        waypoints: (n, dof) joint waypoints; the lift is the first segment, the descent the last.
        duration: [s] the time of its joint lines, each from rest to rest.
        clearance: [m] its smallest distance to the cell (checked along the lines).
    """

    way: str
    waypoints: np.ndarray
    duration: float
    clearance: float


class Rows:
    """The distance rows of a jump, their separating planes and the CasADi functions that keep them (module docstring).

    Args:
        scene: the robot in its cell.
        sym: the robot's symbolic model (:func:`~scara_pin.symbolic.symbolic_model`; its joint frames).
    """

    PARAMETERS = 9
    """Per row: the plane's normal and point in the second shape's joint frame, the witness point on the first."""

    def __init__(self, scene: Scene, sym: SymbolicModel) -> None:
        self.scene = scene
        self.sym = sym
        self.margin = scene.margin
        self.rows: tuple[DistanceRow, ...] = ()
        self._index: set[tuple[int, float, int]] = set()
        self._functions: dict[int, Any] = {}
        self._params = np.zeros((0, self.PARAMETERS))
        self._near: set[tuple[int, int]] = set()

    def add(self, new: list[DistanceRow]) -> bool:
        """Add rows not yet present; True if any was."""
        fresh = [r for r in new if (r.k, r.sigma, r.pair) not in self._index]
        for r in fresh:
            self._index.add((r.k, r.sigma, r.pair))
        self.rows = self.rows + tuple(fresh)
        return bool(fresh)

    def joints(self, pair: int) -> tuple[int, int]:
        """(joint of the pair's first shape, joint of its second) in the robot's model (0: the root)."""
        gm = self.scene.geometry_model
        pr = self.scene.pairs[pair]
        return int(gm.geometryObjects[pr.first].parentJoint), int(gm.geometryObjects[pr.second].parentJoint)

    def function(self, pair: int) -> Any:
        """``s = f(Fa, Fb, n, p, w)``: how far the first shape of ``pair`` is beyond the row's plane [m].

        Fa, Fb: the placements (12 values: the rotation column by column, then the translation) of the two
        shapes' joints in the model's world (:attr:`~scara_pin.symbolic.SymbolicModel.joint_frames`).
        The plane (unit normal n, point p) is fixed to the second shape's joint (an obstacle's: the root); w is
        a point fixed to the first shape's joint (its witness point), used where the shape's support is not
        written in closed form (a mesh). The support of a box, a cylinder and a sphere is exact but for the
        smoothing of |x| as sqrt(x^2 + eps^2), which makes it larger (safe) by at most eps times the size.
        """
        f = self._functions.get(pair)
        if f is not None:
            return f
        import casadi as ca
        import coal

        gm = self.scene.geometry_model
        a = gm.geometryObjects[self.scene.pairs[pair].first]
        Fa, Fb = ca.SX.sym("Fa", 12), ca.SX.sym("Fb", 12)
        n_loc, p_loc, w_loc = ca.SX.sym("n", 3), ca.SX.sym("p", 3), ca.SX.sym("w", 3)
        Rb, ob = ca.reshape(Fb[:9], 3, 3), Fb[9:]
        n = Rb @ n_loc
        pb = Rb @ p_loc + ob
        Rj, oj = ca.reshape(Fa[:9], 3, 3), Fa[9:]
        shape = a.geometry
        eps = _SMOOTH

        def sabs(x: Any) -> Any:
            return ca.sqrt(x * x + eps * eps)

        if isinstance(shape, (coal.Box, coal.Cylinder, coal.Sphere)):
            Ra = Rj @ ca.DM(a.placement.rotation)
            c = Rj @ ca.DM(a.placement.translation) + oj
            if isinstance(shape, coal.Box):
                e = np.asarray(shape.halfSide, dtype=float)
                extent = sum(float(e[i]) * sabs(ca.dot(n, Ra[:, i])) for i in range(3))
            elif isinstance(shape, coal.Cylinder):
                cz = ca.dot(n, Ra[:, 2])
                extent = float(shape.radius) * ca.sqrt(1.0 - cz * cz + eps * eps) + float(shape.halfLength) * sabs(cz)
            else:
                extent = float(shape.radius)
        else:  # a mesh or another shape: its witness point
            c = Rj @ w_loc + oj
            extent = 0.0
        value = ca.dot(n, pb - c) - extent
        f = ca.Function(f"separation_{pair}", [Fa, Fb, n_loc, p_loc, w_loc], [value])
        self._functions[pair] = f
        return f

    def parameters(self, piece: PolynomialPiece, clear: PolynomialPiece | None = None, *,
                   rebase: bool = False) -> np.ndarray:  # fmt: skip
        """Each row's plane and witness point from coal's distance at ``piece`` (flattened, 9 per row).

        A row whose pair is in contact at ``piece`` (distance <= 0: the penetration's normal says little about
        the way out) keeps its plane, or, when new, takes it from ``clear``: the last motion found clear there.
        ``rebase``: every plane from ``piece`` (a motion clear of the cell), whatever the rows had.
        """
        import pinocchio as pin

        scene = self.scene
        robot = scene.robot
        gm, gd, model, data = scene.geometry_model, scene._gd, robot.model, scene._data
        old = self._params
        out = np.zeros((len(self.rows), self.PARAMETERS))
        out[: len(old)] = old
        objs = gm.geometryObjects

        def planes(source: PolynomialPiece, idx: list[int], keep_contact: bool) -> list[int]:
            """Fill the rows ``idx`` from ``source``; return those left unset (in contact there)."""
            by_point: dict[tuple[int, float], list[int]] = {}
            for i in idx:
                by_point.setdefault((self.rows[i].k, self.rows[i].sigma), []).append(i)
            h = np.diff(source.breaks)
            left = []
            for (k, sigma), rows in by_point.items():
                q0 = source._local(np.array([k]), np.array([sigma * h[k]]), 0)[0]
                pin.forwardKinematics(model, data, robot.to_pinocchio_q(q0) if robot.has_continuous else q0)
                pin.updateGeometryPlacements(model, data, gm, gd)
                for i in rows:
                    pr = scene.pairs[self.rows[i].pair]
                    res = pin.computeDistance(gm, gd, pr.index)
                    if keep_contact and res.min_distance <= 0.0:
                        left.append(i)
                        continue
                    n = np.asarray(res.normal, dtype=float)
                    n = n / (np.linalg.norm(n) or 1.0)
                    pa, pb = np.asarray(res.getNearestPoint1()), np.asarray(res.getNearestPoint2())
                    Mb = data.oMi[objs[pr.second].parentJoint]
                    Ma = data.oMi[objs[pr.first].parentJoint]
                    out[i, 0:3] = Mb.rotation.T @ n
                    out[i, 3:6] = Mb.actInv(pb)
                    out[i, 6:9] = Ma.actInv(pa)
            return left

        if rebase:
            planes(piece, list(range(len(self.rows))), keep_contact=False)
            self._params = out
            return out.ravel()
        left = planes(piece, list(range(len(self.rows))), keep_contact=True)
        fresh = [i for i in left if i >= len(old)]
        if fresh:
            planes(clear if clear is not None else piece, fresh, keep_contact=False)
        self._params = out
        return out.ravel()

    def check(self, piece: PolynomialPiece) -> tuple[list[DistanceRow], float]:
        """(rows to add, the worst distance minus the margin [m]) from a dense check of ``piece``.

        Rows go on a fixed grid of each interval (:data:`ROW_POINTS`: its start node and points inside), so
        that the set of rows settles after a few solves (the NLP is rebuilt only when rows are added): at
        every grid point where a pair comes within :data:`ACTIVATION` of the margin, and at the grid point
        nearest every sample (of :data:`CHECK_POINTS` per interval) where a pair is below the margin.
        """
        n = len(piece.breaks) - 1
        h = np.diff(piece.breaks)
        sigma = np.arange(CHECK_POINTS) / CHECK_POINTS  # sigma = 0: the node at the start of the interval
        k = np.repeat(np.arange(n), CHECK_POINTS)
        s = np.tile(sigma, n)
        q = piece._local(k, s * h[k], 0)
        D = self.scene.distance_array(q) - self.margin  # (samples, pairs)
        grid = np.array(ROW_POINTS)
        on_grid = np.isin(s, grid)
        nearest = grid[np.argmin(np.abs(s[:, None] - grid[None, :]), axis=1)]
        new: list[DistanceRow] = []
        near = on_grid[:, None] & (D < ACTIVATION)
        near[(k == 0) & (s == 0.0)] = False  # the start node is fixed (checked before planning)
        for i, p in zip(*np.nonzero(near)):
            new.append(DistanceRow(int(k[i]), float(s[i]), int(p)))
        bad = D < -CONVERGED
        for p in np.unique(np.nonzero(bad)[1]):  # per interval and pair, at its worst sample
            for kk in np.unique(k[bad[:, p]]):
                sel = np.nonzero((k == kk) & bad[:, p])[0]
                i = sel[int(np.argmin(D[sel, p]))]
                sg = float(nearest[i])
                if (kk == 0 and sg == 0.0) or (int(kk), sg, int(p)) in self._index:  # a row there does not hold it
                    sg = float(s[i])
                new.append(DistanceRow(int(kk), sg, int(p)))
        q_end = piece._local(np.array([n - 1]), np.array([h[-1]]), 0)
        worst = float(min(D.min(initial=math.inf), float(self.scene.minimum_array(q_end)[0]) - self.margin))
        self._near = {(int(kk), int(p)) for kk, p in zip(*np.nonzero(
            (D < FINE_WITHIN).reshape(n, CHECK_POINTS, -1).any(axis=1)))}  # fmt: skip
        return new, worst

    def fine(self, piece: PolynomialPiece) -> list[DistanceRow]:
        """Rows where the verifier's grid finds a pair below the margin that :meth:`check`'s points missed.

        Only the pairs that came within :data:`FINE_WITHIN` of the margin in an interval at the last
        :meth:`check` are sampled there, at the verifier's rate (:data:`~scara_pin.motion.verify.VERIFY_RATE`);
        each (interval, pair) below the margin by more than :data:`CONVERGED` gets a row at its worst sample.
        Between :meth:`check`'s points, an edge passing an edge (two boxes) can dip below the margin unseen.
        """
        from .verify import VERIFY_RATE

        h = np.diff(piece.breaks)
        new: list[DistanceRow] = []
        for kk, p in sorted(self._near):
            m = max(CHECK_POINTS, math.ceil(h[kk] * VERIFY_RATE) + 1)
            s = np.arange(1, m) / m
            q = piece._local(np.full(len(s), kk), s * h[kk], 0)
            d = self.scene.distance_array(q, [p])[:, 0] - self.margin
            i = int(np.argmin(d))
            if d[i] < -CONVERGED and (kk, float(s[i]), p) not in self._index:
                new.append(DistanceRow(kk, float(s[i]), p))
        return new


# ---------------------------------------------------------------------------------------------- warm starts
def _line_samples(waypoints: np.ndarray) -> np.ndarray:
    """Points along the joint lines between consecutive waypoints (_PATH_SAMPLES per line, ends included)."""
    s = np.linspace(0.0, 1.0, _PATH_SAMPLES)[:, None]
    return np.concatenate([w0 + s * (w1 - w0) for w0, w1 in zip(waypoints[:-1], waypoints[1:])])


def _score(scene: Scene, waypoints: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> tuple[float, float]:
    """(duration of the joint lines from rest to rest [s], their clearance [m]).

    The clearance is the smallest distance along them minus the margin and :data:`SLACK`: >= 0 when the lines
    clear the cell between their samples too.
    """
    t = sum(line_optimal_duration(a, b, velocity, acceleration) for a, b in zip(waypoints[:-1], waypoints[1:])
            if not np.array_equal(a, b))  # fmt: skip
    d = scene.minimum_array(_line_samples(waypoints))
    return float(t), float(d.min(initial=math.inf)) - scene.margin - SLACK


def _ik(robot: RobotModel, pose: np.ndarray, near: np.ndarray) -> np.ndarray | None:
    res = robot.ik(pose)
    sol = res.nearest(near, branch=robot.branch_of(near)) if res.success else None
    return None if sol is None else np.array(sol.q, dtype=float)


def candidates(
    scene: Scene,
    qA: np.ndarray,
    qB: np.ndarray,
    tops: tuple[np.ndarray, np.ndarray],
    A: np.ndarray,
    B: np.ndarray,
    z_top: float,
    ceiling: float | None,
    velocity: np.ndarray,
    acceleration: np.ndarray,
) -> list[Candidate]:
    """Warm starts for the jump in the cell (module docstring).

    The straight one when it is clear; else the clear ones, fastest first; else (none clears) every one tried,
    the least colliding first.
    """
    robot = scene.robot
    straight = np.array([qA, tops[0], tops[1], qB])
    t, clear = _score(scene, straight, velocity, acceleration)
    first = Candidate("straight", straight, t, clear)
    if clear >= 0.0:
        return [first]
    found = [first]
    # OVER: the traverse raised until the joint lines clear
    top = _stroke_top(robot, tops[0])
    z_max = z_top + _MAX_RAISE if top is None else robot.tool_pose(top)[2]
    if ceiling is not None:
        z_max = min(z_max, ceiling)
    raised = {z_top: tops}  # traverse height -> the configurations above A and B there
    z = z_top + _STEP
    while z <= z_max + 1e-12:
        ta = _ik(robot, np.array([A[0], A[1], z, A[3]]), tops[0])
        tb = _ik(robot, np.array([B[0], B[1], z, B[3]]), tops[1])
        if ta is None or tb is None:
            break
        if len(raised) < 1 + _RAISED_AROUND:
            raised[z] = (ta, tb)
        way = np.array([qA, ta, tb, qB])
        t, clear = _score(scene, way, velocity, acceleration)
        if clear >= 0.0:
            found.append(Candidate("over", way, t, clear))
            break
        z += _STEP
    # AROUND: a via point beside the first collision of the straight lines, moved out on either side, at the
    # traverse height and a little above it (around one obstacle and over a lower one)
    samples = _line_samples(straight)
    D = scene.minimum_array(samples) - scene.margin
    hit = int(np.argmax(D < 0.0))
    p = robot.tool_pose(samples[hit])
    u = B[:2] - A[:2]
    u = u / np.linalg.norm(u)
    normal = np.array([-u[1], u[0]])
    base = A[:2] + u * float(np.clip((p[:2] - A[:2]) @ u, 0.0, np.linalg.norm(B[:2] - A[:2])))
    yaw = float(A[3] + (B[3] - A[3]) * 0.5)
    for k, (zv, (ta, tb)) in enumerate(raised.items()):
        if k and any(c.clearance >= 0.0 for c in found):
            break  # a way clears already: raised AROUND scans only when nothing else does
        step = _STEP if k == 0 else 2.0 * _STEP  # the raised scans are coarser: they only add ways
        for side, sign in (("left", 1.0), ("right", -1.0)):
            offset = step
            while offset <= _MAX_OFFSET:
                xy = base + sign * offset * normal
                via = _ik(robot, np.array([xy[0], xy[1], zv, yaw]), (ta + tb) / 2.0)
                if via is not None:
                    way = np.array([qA, ta, via, tb, qB])
                    t, clear = _score(scene, way, velocity, acceleration)
                    if clear >= 0.0:
                        found.append(Candidate(side if k == 0 else f"{side}, raised", way, t, clear))
                        break
                offset += step
    clear_ones = sorted((c for c in found if c.clearance >= 0.0), key=lambda c: c.duration)
    if not clear_ones:  # none clears: every one tried, the least colliding first (the planner may still find a way)
        return sorted(found, key=lambda c: -c.clearance)
    return clear_ones


def _stroke_top(robot: RobotModel, q: np.ndarray) -> np.ndarray | None:
    """``q`` with the joint that moves the tool up (a SCARA's quill) at the end of its range that raises the tool.

    None when that joint is not prismatic (a palletizer raises the tool by turning its arms).
    """
    J = robot.task_jacobian(q)[2]
    out = q.copy()
    j = int(np.argmax(np.abs(J)))
    if robot.joint_kinds[j] != "length":
        return None
    out[j] = robot.limits.upper[j] if J[j] > 0 else robot.limits.lower[j]
    return out


def _closest(scene: Scene, Q: np.ndarray) -> tuple[int, PairDistance | None]:
    """(the row of ``Q`` where a checked pair comes closest, that pair with its witness points)."""
    i = int(np.argmin(scene.minimum_array(Q)))
    return i, scene.distances(Q[i]).closest


def blocking(scene: Scene, piece: PolynomialPiece) -> str:
    """Which pair comes closest in ``piece`` and where, in words (for a failure message)."""
    from ..cell import describe

    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    k = np.repeat(np.arange(n), 4)
    s = np.tile(np.arange(4) / 4.0, n)
    q = piece._local(k, s * h[k], 0)
    i, found = _closest(scene, q)
    if found is None:  # pragma: no cover - a scene without pairs plans no rows
        return "no pair"
    return describe(found, scene.margin) + f" at t = {piece.breaks[k[i]] + s[i] * h[k[i]]:.4g} s"


def blocked(scene: Scene, tried: list[Candidate], status: str) -> InfeasibleError:
    """The error of a jump for which no way around or over clears the cell (exit 3): each way and what blocks it."""
    from ..cell import describe
    from .jump import JumpError

    parts = []
    for c in tried:
        _, found = _closest(scene, _line_samples(c.waypoints))
        if found is not None:
            parts.append(f"{c.way}: {describe(found, scene.margin)}")
    return JumpError(status, "no collision-free motion found within the limits: " + "; ".join(parts)
                     + f"; neither the traverse raised up to the stroke's top nor via points up to {_MAX_OFFSET:g} m "
                     "to either side clear it, and the solver found no way from there")  # fmt: skip


def infeasible(scene: Scene, piece: PolynomialPiece, status: str) -> InfeasibleError:
    """The error of a jump that found no motion clear of the cell (exit 3), naming the pair that blocks."""
    from .jump import JumpError

    return JumpError(status, f"no collision-free motion found within the limits: {blocking(scene, piece)}")


# ---------------------------------------------------------------------------------------------- the iterations
def solve_avoiding(prob: Any, options: Any, waypoints: np.ndarray) -> tuple[PolynomialPiece, np.ndarray, Any]:
    """The jump's solve (the jump's own solve) with the distance rows (module docstring).

    From the warm start ``waypoints``: solve; check densely; add rows; re-set every row's plane; solve again,
    warm-started, until nothing is added, the dense check holds and the duration has settled. A re-solve the
    solver finds infeasible (the planes taken from the last solution conflict) is retried once from the
    last motion that was clear of the cell, with every plane taken there: that motion satisfies them all.

    Returns:
        (piece, phase durations, solver statistics) as ``_solve``.

    Raises:
        JumpError: the solver failed, or no motion clear of the cell was found (naming the closest pair).
    """
    from .jump import JumpError, SolverStats, _failure, _rebuild, _Transcription, _violations, _warm_start

    scene = prob.scene
    points: tuple[Any, ...] = ()
    warm = _warm_start(prob, waypoints)
    rows = Rows(scene, prob.sym)
    piece = _rebuild(prob, warm[0], warm[2])
    fresh, worst = rows.check(piece)
    rows.add(fresh)
    params = rows.parameters(piece)
    tr = _Transcription(prob, points, options, rows.rows, rows)
    x0 = tr.pack(*warm)
    clear = (piece, x0) if worst >= -CONVERGED else None  # the last motion found clear of the cell
    retried = False
    iterations = solves = 0
    duration = math.inf
    last_clear: tuple[PolynomialPiece, np.ndarray, Any] | None = None  # a solved motion clear of the cell
    while True:
        sol = tr.solve(x0, None, None, params)
        iterations += sol["iterations"]
        solves += 1
        log.debug("jump in a cell: solve %d: %s after %d iterations, %d rows", solves, sol["status"],
                  sol["iterations"], len(rows.rows))  # fmt: skip
        T, _, U = tr.unpack(sol["x"])
        if not sol["success"]:
            if clear is not None and not retried:  # every plane from the last clear motion, which meets them all
                retried = True
                params = rows.parameters(clear[0], rebase=True)
                x0 = clear[1][: tr.n_x]
                continue
            if last_clear is not None:  # the planes stopped moving it: the last solved clear motion stands
                log.debug("jump in a cell: re-solve %s; keeping the last clear solution", sol["status"])
                piece, T = last_clear[0], last_clear[2]
                break
            if sol["status"] in ("Infeasible_Problem_Detected", "Restoration_Failed", "Maximum_Iterations_Exceeded"):
                raise infeasible(scene, _rebuild(prob, T, U) if clear is None else clear[0], sol["status"])
            raise JumpError(sol["status"], _failure(sol["status"], options))
        piece = _rebuild(prob, T, U)
        new = [p for p in _violations(prob, piece, T) if p not in points]
        fresh, worst = rows.check(piece)
        added = rows.add(fresh)
        log.debug("jump in a cell: %.6f s, worst %.3g mm beyond the margin, %d rows added, %d limit points",
                  piece.duration, worst * 1e3, len(fresh), len(new))  # fmt: skip
        params = rows.parameters(piece, None if clear is None else clear[0])
        if worst >= -CONVERGED:
            clear = (piece, sol["x"])
            if not new:
                last_clear = (piece, sol["x"], T)
            retried = False
        settled = worst >= -CONVERGED and abs(piece.duration - duration) <= CONVERGED_TIME * piece.duration
        duration = piece.duration
        if not new and not added and settled:
            finer = rows.fine(piece)  # converged: what the verifier's grid would see between the checked points
            if not finer:
                break
            rows.add(finer)
            added = True
            params = rows.parameters(piece, None if clear is None else clear[0])
        if solves > options.refinements + options.avoid_iterations:
            if last_clear is not None:
                piece, T = last_clear[0], last_clear[2]
                break
            raise infeasible(scene, piece, "Not_Converged")
        # from a motion deep in an obstacle the re-solve struggles: start again from the last clear one
        x0 = clear[1][: tr.n_x] if worst < -DEEP and clear is not None else sol["x"]
        if new or added:
            points = points + tuple(new)
            tr = _Transcription(prob, points, options, rows.rows, rows, resolve=True)
    stats = SolverStats(sol["status"], iterations, solves, prob.N, tr.n_x, tr.n_g, 0.0)
    log.debug("jump in a cell: %s", stats)
    return piece, T, stats
