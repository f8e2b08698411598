"""Obstacles in the time-optimal jump: separating planes (distance rows), re-set after every solve.

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

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ...cell import Scene
    from ...symbolic import SymbolicModel
    from ..polynomial import PolynomialPiece

DISTANCE_SCALE = 0.01
"""[m] the scale of the distance rows in the NLP (their values over it are of order 1)."""


BUFFER = 5e-6
"""[m] the rows keep margin + BUFFER: the motion then keeps the margin between rows too, and its certificate
(:mod:`~scara_pin.cell.certify`) needs few samples where it slides along an obstacle; a near miss is solved again
with a larger buffer (:data:`RETRY_BUFFER`)."""
NEAR_MISS = 1e-5
"""[m] a solved motion this close to the margin (but under it) is kept when the re-solves stop converging: it is
then solved again with a larger buffer (a near miss is refined, not refused)."""
RETRY_BUFFER = 4.0
"""A motion whose certificate still fails after the iterations is solved again with the buffer this many times
larger (and a row where it failed): a near miss is refined, not refused."""
FINE_FLOOR = 5e-7
"""[m] :meth:`Rows.fine` certifies the near pairs down to margin - FINE_FLOOR (the verifier's: margin - 1e-6)."""


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


_SMOOTH = 1e-3
"""The eps of the smoothed |x| = sqrt(x^2 + eps^2) in the shapes' supports (at most eps times a size: safe)."""


@dataclass(frozen=True)
class DistanceRow:
    """One pair at one point of the motion: interval ``k`` at fraction ``sigma`` (a node is sigma = 0)."""

    k: int
    sigma: float
    pair: int


class Rows:
    """The distance rows of a jump, their separating planes and the CasADi functions that keep them (module docstring).

    Args:
        scene: the robot in its cell.
        sym: the robot's symbolic model (:func:`~scara_pin.symbolic.symbolic_model`; its joint frames).
    """

    PARAMETERS = 9
    """Per row: the plane's normal and point in the second shape's joint frame, the witness point on the first."""

    def __init__(self, scene: Scene, sym: SymbolicModel, buffer: float = BUFFER) -> None:
        self.scene = scene
        self.sym = sym
        self.margin = scene.margin
        self.buffer = buffer
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

    def swapped(self, pair: int) -> bool:
        """Whether the pair's plane is fixed to its FIRST shape's joint (and the second shape kept beyond it).

        The plane goes on the shape nearer the root (an obstacle; the ancestor link of a self pair) and the other
        shape's support is kept beyond it: a plane fixed to a flange that turns on its axis would turn with it and
        cut the arm it separates (the distance does not change, the row would).
        """
        gm = self.scene.geometry_model
        pr = self.scene.pairs[pair]
        ja, jb = int(gm.geometryObjects[pr.first].parentJoint), int(gm.geometryObjects[pr.second].parentJoint)
        return jb != 0 and ja in self.scene.robot.model.supports[jb]

    def joints(self, pair: int) -> tuple[int, int]:
        """(joint of the shape kept beyond the plane, joint the plane is fixed to) in the model (0: the root)."""
        gm = self.scene.geometry_model
        pr = self.scene.pairs[pair]
        ja, jb = int(gm.geometryObjects[pr.first].parentJoint), int(gm.geometryObjects[pr.second].parentJoint)
        return (jb, ja) if self.swapped(pair) else (ja, jb)

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
        pr = self.scene.pairs[pair]
        a = gm.geometryObjects[pr.second if self.swapped(pair) else pr.first]
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
        scene = self.scene
        old = self._params
        out = np.zeros((len(self.rows), self.PARAMETERS))
        out[: len(old)] = old

        def planes(source: PolynomialPiece, idx: list[int], keep_contact: bool) -> list[int]:
            """Fill the rows ``idx`` from ``source``; return those left unset (in contact there)."""
            by_point: dict[tuple[int, float], list[int]] = {}
            for i in idx:
                by_point.setdefault((self.rows[i].k, self.rows[i].sigma), []).append(i)
            h = np.diff(source.breaks)
            left = []
            for (k, sigma), rows in by_point.items():
                q0 = source.local(np.array([k]), np.array([sigma * h[k]]), 0)[0]
                for i, w in zip(rows, scene.witnesses(q0, [self.rows[i].pair for i in rows])):
                    if keep_contact and w.distance <= 0.0:
                        left.append(i)
                        continue
                    if self.swapped(self.rows[i].pair):  # the plane on the first shape, facing the second
                        out[i, 0:3] = w.oMa.rotation.T @ -w.normal
                        out[i, 3:6] = w.oMa.actInv(w.point_a)
                        out[i, 6:9] = w.oMb.actInv(w.point_b)
                    else:
                        out[i, 0:3] = w.oMb.rotation.T @ w.normal
                        out[i, 3:6] = w.oMb.actInv(w.point_b)
                        out[i, 6:9] = w.oMa.actInv(w.point_a)
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
        q = piece.local(k, s * h[k], 0)
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
        q_end = piece.local(np.array([n - 1]), np.array([h[-1]]), 0)
        worst = float(min(D.min(initial=math.inf), float(self.scene.minimum_array(q_end)[0]) - self.margin))
        self._near = {(int(kk), int(p)) for kk, p in zip(*np.nonzero(
            (D < FINE_WITHIN).reshape(n, CHECK_POINTS, -1).any(axis=1)))}  # fmt: skip
        return new, worst

    def fine(self, piece: PolynomialPiece, acceleration: np.ndarray) -> list[DistanceRow]:
        """Rows where a pair that came near the margin is not certified clear between :meth:`check`'s points.

        Only the pairs that came within :data:`FINE_WITHIN` of the margin in an interval at the last
        :meth:`check`: each such (interval, pair) is sampled at the verifier's rate
        (:data:`~scara_pin.motion.verify.VERIFY_RATE`) and certified between the samples
        (:func:`~scara_pin.cell.certify.certify`, ``acceleration`` bounding |qdd|) down to margin - :data:`FINE_FLOOR`;
        where it is not, a row goes at its lowest sample (a dip found), or where the certificate is weakest.
        Between :meth:`check`'s points, an edge passing an edge (two boxes) can dip below the margin unseen.
        """
        from ...cell.certify import certify
        from ..verify import VERIFY_RATE

        h = np.diff(piece.breaks)
        floor = self.margin - FINE_FLOOR
        new: list[DistanceRow] = []

        def sample(tt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            q, qd, _ = piece.evaluate(tt)
            return q, qd

        for kk, p in sorted(self._near):
            m = max(CHECK_POINTS, math.ceil(h[kk] * VERIFY_RATE / 5.0) + 1)  # the certificate refines where it must
            tt = piece.breaks[kk] + h[kk] * (np.arange(m + 1) / m)
            d = self.scene.distance_array(sample(tt)[0], [p])[:, 0]
            cert = certify(self.scene, sample, tt, d, np.full(len(tt), p), acceleration, floor, pairs=[p])
            if cert.certified:
                continue
            at = cert.lowest[0] if cert.lowest[2] < floor else cert.time
            sigma = float(np.clip((at - piece.breaks[kk]) / h[kk], 0.0, 1.0))
            if sigma >= 1.0 and kk + 1 < len(h):  # the interval's end is the next one's start node
                row = DistanceRow(kk + 1, 0.0, p)
            else:
                row = DistanceRow(kk, sigma, p)
            if (row.k, row.sigma, row.pair) not in self._index:
                new.append(row)
        return new
