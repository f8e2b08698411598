"""The jump's global search: every way through the cell on a lattice in joint space, before any local solve.

The local solve (:mod:`.cell`) finds the fastest motion near its warm start; WHICH way it goes around or over
the obstacles (over a wall, around a post on either side, with the elbow folded, the carried part turned) is
decided here, on a lattice of the joint space that covers the whole traverse, so that a way is found
whenever one exists at the lattice's resolution.

**The lattice.** Each joint that matters is sampled with a step (:data:`STEPS`: 5 deg or 20 mm, then
2.5 deg or 10 mm when no way is found), anchored at the configuration above A; a joint that changes no
distance of the cell and not the tool's height (a SCARA's wrist turning a round flange, without a carried
part) is one value there, and turns from A's to B's along the route. A joint's range is its limits
(a continuous joint, and a wrist: half a turn beyond both ends).

**Valid nodes**: the tool at or above the traverse height z_top (and under a ceiling), and every checked pair of
the scene at least the margin apart. A pair's distance depends only on the joints between its two shapes in
the kinematic tree (an obstacle's on every joint above the robot's shape; link2 and the flange on the quill and
the wrist): each pair is evaluated on the lattice of ITS joints (link1 against a post: one value per J1 step)
by :func:`~scara_pin.cell.sweep.pair_masks` (bounding spheres, capsules, boxes grown by the margin, then coal's
exact distance; the rows whose tool is below z_top are not asked), and the results are combined over the whole
lattice. Every configuration inside the lattice's box is within half a step of a node in each joint, so within
``half = sum(reach_j step_j) / 2`` of motion of it: a pair whose capsule bound is at least the margin plus that
at every node is clear everywhere in the box, and the lines checked below ask only the other pairs.

**Edges** join nodes one step apart along one joint, or along two of the first two joints at once (the arm's
plane); an edge costs the time its joint move would take at the velocity limits, summed over the joints
(the L1 norm: a joint that need not move is not moved). Dijkstra's shortest path (scipy's) from the node above A
to the node above B; the edges of the path found are then checked densely (every 2 mm of motion of any point
of the robot, :data:`EDGE_STEP`) and an edge found blocked is removed and the search repeated (lazy edges).
The path is shortened to a few via points (the longest clear joint line from each point, string pulling).

**Ways.** Each way found is a warm start of the local solve; the next way is searched with the nodes near the
ways found (:data:`APART` steps) made expensive, and kept when it leaves them: another way around.

**Resolution.** When no way exists on the coarse lattice, the fine one is searched; when none exists on the fine
one either, the jump is refused: no way wider than the fine lattice's step exists (a narrower passage may: a
via point, ``via:``, gives the planner a way by hand).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ...cell.sweep import clear_mask, pair_joints, pair_masks
from ...signals import check_time

if TYPE_CHECKING:
    from ...cell import Scene

log = logging.getLogger(__name__)

STEPS = ((math.radians(5.0), 0.02), (math.radians(2.5), 0.01))
"""(angle [rad], length [m]) lattice steps: the coarse search, then the fine one when the coarse finds no way."""
EDGE_STEP = 0.004
"""[m] an edge (and a via line) is checked at samples this far apart in the motion of any point of the robot (the
search gives warm starts: the local solve keeps the margin and the verifier certifies it)."""
APART = 3
"""A second way must leave the nodes within this many steps (in the arm's plane) of the ways found."""
WAYS = 3
"""The most ways returned."""
_COARSER = 6.0
"""A joint whose motion moves the robot's points less than the arm's first joint takes a coarser angle step, in
proportion, up to this times the step (a wrist turning a carried part: 30 deg on the coarse lattice)."""
_CHUNK = 50_000
"""Configurations evaluated at once."""
_LAZY_ROUNDS = 40
"""Edges found blocked and removed before a way is given up."""


@dataclass(frozen=True)
class Way:
    """A way through the cell found on the lattice.

    Attributes:
        waypoints: (n, dof) joint waypoints from above A to above B (both included), shortened to via points.
        cost: [s] its lattice cost (the joint moves at the velocity limits, summed over the joints).
        nodes: its lattice nodes (for the next way's search).
    """

    waypoints: np.ndarray
    cost: float
    nodes: np.ndarray


@dataclass(frozen=True)
class Search:
    """What the search found.

    Attributes:
        ways: the ways, cheapest first (none when the cell leaves no way at the finest resolution).
        steps: (angle [rad], length [m]) of the lattice the ways were found on (or the finest searched).
        nodes: the lattice's size; valid: how many of its nodes are clear.
        why: when no way was found: which checked pairs close the most nodes, in words.
    """

    ways: tuple[Way, ...]
    steps: tuple[float, float]
    nodes: int
    valid: int
    why: str = ""


def search(scene: Scene, top_a: np.ndarray, top_b: np.ndarray, z_top: float, ceiling: float | None,
           velocity: np.ndarray) -> Search:  # fmt: skip
    """The ways from ``top_a`` (above A at the traverse height) to ``top_b`` through the cell (module docstring)."""
    lattice = _Lattice(scene, top_a, top_b, z_top, ceiling, velocity)
    found = Search((), STEPS[-1], 0, 0)
    for steps in STEPS:
        lattice.build(steps)
        ways = lattice.ways()
        found = Search(tuple(ways), steps, lattice.size, int(lattice.valid.sum()), "" if ways else lattice.why())
        log.debug("jump search at %.3g deg / %.3g m: %d nodes, %d clear, %d ways", math.degrees(steps[0]), steps[1],
                  found.nodes, found.valid, len(ways))  # fmt: skip
        if ways:
            break
    return found


class _Lattice:
    """The lattice of one search (module docstring)."""

    def __init__(self, scene: Scene, top_a: np.ndarray, top_b: np.ndarray, z_top: float, ceiling: float | None,
                 velocity: np.ndarray) -> None:  # fmt: skip
        from ...symbolic import symbolic_model

        self.scene = scene
        self.robot = robot = scene.robot
        self.a, self.b = np.asarray(top_a, dtype=float), np.asarray(top_b, dtype=float)
        self.z_top, self.ceiling = z_top, ceiling
        self.velocity = np.asarray(velocity, dtype=float)
        self.sym = symbolic_model(robot)
        dof = robot.dof
        lo, hi = np.array(robot.limits.lower, dtype=float), np.array(robot.limits.upper, dtype=float)
        wide = np.array(robot.continuous) | (hi - lo > 2.0 * math.pi)
        self.lo = np.where(wide, np.maximum(lo, np.minimum(self.a, self.b) - math.pi), lo)
        self.hi = np.where(wide, np.minimum(hi, np.maximum(self.a, self.b) + math.pi), hi)
        self.lo = np.where(np.array(robot.continuous), np.minimum(self.a, self.b) - math.pi, self.lo)
        self.hi = np.where(np.array(robot.continuous), np.maximum(self.a, self.b) + math.pi, self.hi)
        self.length = np.array([k == "length" for k in robot.joint_kinds])
        self.pair_dims = pair_joints(scene, self.lo, self.hi)
        self.z_dims = self._tool_dims()
        used = set(self.z_dims).union(*self.pair_dims) if self.pair_dims else set(self.z_dims)
        self.free = np.array([j not in used for j in range(dof)])  # turns from A's to B's along the route
        self.reach = self._reach()

    # ------------------------------------------------------------------------------------------ structure
    def _tool_dims(self) -> list[int]:
        """The joints that move the tool up or down (a SCARA's quill; a palletizer's arms)."""
        rng = np.random.default_rng(3)
        lo, hi = np.where(np.isfinite(self.lo), self.lo, -math.pi), np.where(np.isfinite(self.hi), self.hi, math.pi)
        Q = lo + (hi - lo) * rng.random((8, self.robot.dof))
        z = self._z(Q)
        out = []
        for j in range(self.robot.dof):
            moved = Q.copy()
            moved[:, j] = lo[j] + (hi[j] - lo[j]) * rng.random(len(Q))
            if np.max(np.abs(self._z(moved) - z)) > 1e-12:
                out.append(j)
        return out

    def _z(self, Q: np.ndarray) -> np.ndarray:
        return np.asarray(self.sym.tool_position.map(len(Q))(Q.T))[2]

    def _reach(self) -> np.ndarray:
        """(dof,) how fast any point of the robot (and the carried part) moves per unit of each joint's motion.

        [m/rad, m/m]: the largest over random configurations (:func:`~scara_pin.cell.sweep.geometry_speeds`), with 10 %
        more.
        """
        from ...cell.sweep import bounding_shapes, geometry_speeds

        rng = np.random.default_rng(7)
        lo, hi = np.where(np.isfinite(self.lo), self.lo, -math.pi), np.where(np.isfinite(self.hi), self.hi, math.pi)
        Q = lo + (hi - lo) * rng.random((64, self.robot.dof))
        radius = bounding_shapes(self.scene).radius
        out = np.zeros(self.robot.dof)
        for j in range(self.robot.dof):
            unit = np.zeros_like(Q)
            unit[:, j] = 1.0
            lin, rot = geometry_speeds(self.scene, Q, unit)
            out[j] = 1.1 * float(np.max(lin + rot * radius[None, :]))
        return out

    # ------------------------------------------------------------------------------------------ the lattice
    def build(self, steps: tuple[float, float]) -> None:
        """The lattice at ``steps`` and which of its nodes are valid (module docstring)."""
        check_time()
        dof = self.robot.dof
        self.axes: list[np.ndarray] = []
        for j in range(dof):
            if self.free[j]:
                self.axes.append(np.array([self.a[j]]))
                continue
            arm = float(self.reach[~self.length].max()) if (~self.length).any() else 1.0
            step = steps[1] if self.length[j] else float(np.clip(steps[0] * arm / self.reach[j], steps[0],
                                                                   _COARSER * steps[0]))
            k0 = math.ceil((self.lo[j] - self.a[j]) / step - 1e-9)
            k1 = math.floor((self.hi[j] - self.a[j]) / step + 1e-9)
            self.axes.append(self.a[j] + step * np.arange(k0, k1 + 1))
        self.shape = tuple(len(x) for x in self.axes)
        self.size = int(np.prod(self.shape))
        valid = np.ones(self.shape, dtype=bool)
        z = self._on_dims(self.z_dims, self._z)
        valid &= z >= self.z_top - 1e-9
        if self.ceiling is not None:
            valid &= z <= self.ceiling + 1e-9
        self.blocked_by: dict[int, int] = {}
        groups: dict[tuple[int, ...], list[int]] = {}
        for k, pair_dims in enumerate(self.pair_dims):
            groups.setdefault(tuple(sorted(pair_dims)), []).append(k)
        # an edge moves any point of the robot at most `reach . step`: between two nodes clear by half that more
        # than the margin it is certainly clear (no check needed)
        half = 0.5 * float(np.sum(self.reach * np.array([x[1] - x[0] if len(x) > 1 else 0.0 for x in self.axes])))
        safe = np.ones(self.shape, dtype=bool)
        self.near_pairs: list[int] = []  # the pairs that come within the margin and half an edge somewhere
        for dims, pairs in groups.items():  # per pair: the nodes it closes first (for the reason of a refusal)
            both = self._on_dims(list(dims), lambda Q, p=pairs, d=dims: self._pairs_where_valid(Q, p, d))
            for col, k in enumerate(pairs):
                ok = both[..., col].astype(bool)
                self.blocked_by[k] = int((~ok & valid).sum())
                valid &= ok
                far = both[..., len(pairs) + col] >= self.scene.margin + half
                safe &= far
                if not far.all():
                    self.near_pairs.append(k)
        self.valid = valid
        self.safe = (safe & valid).ravel()

    def _pairs_where_valid(self, Q: np.ndarray, pairs: list[int], dims: tuple[int, ...]) -> np.ndarray:
        """(n, 2k): :func:`~scara_pin.cell.sweep.pair_masks` of ``pairs`` (masks, then bounds) on a lattice of ``dims``.

        Where the tool's height depends on ``dims`` only, the rows whose tool is below the traverse height (or above
        the ceiling: invalid whatever the pairs) are not asked for coal's distances: their masks are clear, and their
        bounds are the capsules' alone (every node keeps a bound: the lines between nodes rely on it).
        """
        k = len(pairs)
        out = np.ones((len(Q), 2 * k))
        keep = np.ones(len(Q), dtype=bool)
        if self.z_dims and set(self.z_dims) <= set(dims):
            z = self._z(Q)
            keep = z >= self.z_top - 1e-9
            if self.ceiling is not None:
                keep &= z <= self.ceiling + 1e-9
        if keep.any():
            out[keep] = np.hstack(pair_masks(self.scene, Q[keep], pairs))
        if not keep.all():
            out[~keep, k:] = pair_masks(self.scene, Q[~keep], pairs, exact=False)[1]
        return out

    def _on_dims(self, dims: list[int], f: object) -> np.ndarray:
        """``f`` (rows of q -> values) evaluated on the lattice of ``dims`` only, broadcast to the whole lattice."""
        dims = sorted(dims)
        grids = np.meshgrid(*[self.axes[j] for j in dims], indexing="ij") if dims else []
        Q = np.tile(self.a, (int(np.prod([len(self.axes[j]) for j in dims])) if dims else 1, 1))
        for j, g in zip(dims, grids):
            Q[:, j] = g.ravel()
        values = np.concatenate([np.asarray(f(Q[i : i + _CHUNK])) for i in range(0, len(Q), _CHUNK)])  # type: ignore[operator]
        shape = [len(self.axes[j]) if j in dims else 1 for j in range(len(self.axes))]
        extra = values.shape[1:]  # a column per value: broadcast with them
        return np.broadcast_to(values.reshape(shape + list(extra)), self.shape + extra)

    def node(self, q: np.ndarray) -> tuple[int, ...]:
        """The lattice index nearest ``q``."""
        return tuple(int(np.clip(np.rint((q[j] - x[0]) / (x[1] - x[0])) if len(x) > 1 else 0, 0, len(x) - 1))
                     for j, x in enumerate(self.axes))  # fmt: skip

    def q(self, index: tuple[int, ...] | np.ndarray) -> np.ndarray:
        """The configuration of a lattice index."""
        return np.array([self.axes[j][int(i)] for j, i in enumerate(index)])

    # ------------------------------------------------------------------------------------------ the graph
    def _moves(self) -> list[tuple[int, ...]]:
        """The steps an edge makes: one joint, or two of the first two moving joints (the arm's plane)."""
        dof = len(self.shape)
        moving = [j for j in range(dof) if self.shape[j] > 1]
        out = []
        for j in moving:
            d = [0] * dof
            d[j] = 1
            out.append(tuple(d))
        plane = moving[:2]
        if len(plane) == 2:
            for s in (1, -1):
                d = [0] * dof
                d[plane[0]], d[plane[1]] = 1, s
                out.append(tuple(d))
        return out

    def _graph(self, penalty: np.ndarray | None) -> Any:
        """The sparse graph of the valid nodes (edge weights: L1 time; ``penalty`` multiplies a node's edges)."""
        from scipy.sparse import coo_matrix

        flat = self.valid.ravel()
        idx = np.arange(self.size).reshape(self.shape)
        rows, cols, weights = [], [], []
        steps = np.array([x[1] - x[0] if len(x) > 1 else 0.0 for x in self.axes])
        for move in self._moves():
            sl_a = tuple(slice(0, n - m) if m > 0 else slice(-m, n) if m < 0 else slice(None)
                         for n, m in zip(self.shape, move))  # fmt: skip
            sl_b = tuple(slice(m, n) if m > 0 else slice(0, n + m) if m < 0 else slice(None)
                         for n, m in zip(self.shape, move))  # fmt: skip
            a, b = idx[sl_a].ravel(), idx[sl_b].ravel()
            keep = flat[a] & flat[b]
            a, b = a[keep], b[keep]
            ww = np.full(len(a), float(np.sum(np.abs(np.array(move)) * steps / self.velocity)))
            if penalty is not None:
                ww = ww * np.maximum(penalty[a], penalty[b])
            rows.append(a)
            cols.append(b)
            weights.append(ww)
        r, c, w = np.concatenate(rows), np.concatenate(cols), np.concatenate(weights)
        return coo_matrix((w, (r, c)), shape=(self.size, self.size)).tocsr()

    def ways(self) -> list[Way]:
        """Up to :data:`WAYS` ways, each leaving the ones before it (module docstring)."""
        out: list[Way] = []
        penalty = None
        start, goal = self._entry(self.a), self._entry(self.b)
        if start is None or goal is None:
            return out
        for _ in range(WAYS):
            way = self._way(start, goal, penalty)
            if way is None:
                break
            if out and not self._apart(way, out):
                break
            out.append(way)
            penalty = self._penalty(out)
        return sorted(out, key=lambda w: w.cost)

    def _entry(self, q: np.ndarray) -> tuple[int, ...] | None:
        """The valid lattice node nearest ``q`` (above A or B) whose joint line to it is clear, or None.

        The lattice is anchored above A (its node is exactly there); above B falls between nodes, and the nearest one
        may be blocked where a way still starts a step away: the nodes within two steps are tried, nearest first.
        """
        centre = np.array(self.node(q))
        offsets = np.array(np.meshgrid(*[np.arange(-2, 3) if n > 1 else [0] for n in self.shape], indexing="ij"))
        near = centre + offsets.reshape(len(self.shape), -1).T
        near = near[((near >= 0) & (near < np.array(self.shape))).all(axis=1)]
        near = near[self.valid[tuple(near.T)]]
        if not len(near):
            return None
        Q = np.array([self.q(n) for n in near])
        order = np.argsort(np.sum(np.abs(Q - q) / self.velocity, axis=1))
        for lo in range(0, len(order), 8):  # nearest first, a few lines at a time
            batch = order[lo : lo + 8]
            ok = np.flatnonzero(self._clear_lines(np.tile(q, (len(batch), 1)), Q[batch]))
            if len(ok):
                return tuple(int(v) for v in near[batch[ok[0]]])
        return None

    def _way(self, start: tuple[int, ...], goal: tuple[int, ...], penalty: np.ndarray | None) -> Way | None:
        from scipy.sparse.csgraph import dijkstra

        check_time()
        graph = self._graph(penalty)
        s = int(np.ravel_multi_index(start, self.shape))
        g = int(np.ravel_multi_index(goal, self.shape))
        data = graph.data  # type: ignore[attr-defined]
        for _ in range(_LAZY_ROUNDS):
            dist, pred = dijkstra(graph, directed=False, indices=s, return_predecessors=True)
            if not np.isfinite(dist[g]):
                return None
            path = [g]
            while path[-1] != s:
                path.append(int(pred[path[-1]]))
            path.reverse()
            Q = np.array([self.q(np.array(np.unravel_index(k, self.shape))) for k in path])
            checked = [i for i in range(len(path) - 1) if not (self.safe[path[i]] and self.safe[path[i + 1]])]
            bad = [checked[i] for i, ok in enumerate(self._clear_lines(Q[checked], Q[[i + 1 for i in checked]]))
                   if not ok]  # fmt: skip
            if not bad:
                cost = float(np.sum(np.abs(np.diff(Q, axis=0)) / self.velocity))
                return Way(self._shortened(self._with_ends(Q)), cost, np.array(path))
            for i in bad:  # the edge is stored once, from its lower node
                a, b = sorted((path[i], path[i + 1]))
                lo, hi = graph.indptr[a], graph.indptr[a + 1]
                data[lo + int(np.searchsorted(graph.indices[lo:hi], b))] = np.inf
        return None

    def _with_ends(self, Q: np.ndarray) -> np.ndarray:
        """The route from exactly above A to exactly above B; the free joints turning along it."""
        Q = np.vstack([self.a, Q, self.b])
        if self.free.any():
            run = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Q[:, ~self.free], axis=0), axis=1))])
            s = run / run[-1] if run[-1] > 0 else np.linspace(0.0, 1.0, len(Q))
            Q[:, self.free] = self.a[self.free] + s[:, None] * (self.b - self.a)[self.free]
        return Q

    def _clear_line(self, q0: np.ndarray, q1: np.ndarray) -> bool:
        """The joint line q0 -> q1 clear (:meth:`_clear_lines`)."""
        return bool(self._clear_lines(q0[None, :], q1[None, :])[0])

    def _clear_lines(self, Q0: np.ndarray, Q1: np.ndarray) -> np.ndarray:
        """Per joint line Q0[i] -> Q1[i], whether it is clear (all lines at once).

        Clear of the cell at samples every :data:`EDGE_STEP` of any point's motion, the tool kept at or above z_top
        (and under the ceiling).
        """
        if len(Q0) == 0:
            return np.ones(0, dtype=bool)
        n = np.maximum(2, np.ceil(np.abs(Q1 - Q0) @ self.reach / EDGE_STEP).astype(int) + 1)
        owner = np.repeat(np.arange(len(Q0)), n)
        s = np.concatenate([np.linspace(0.0, 1.0, k) for k in n])[:, None]
        Q = Q0[owner] + s * (Q1 - Q0)[owner]
        ok = clear_mask(self.scene, Q, self.near_pairs)
        if self.z_dims:
            z = self._z(Q)
            ok &= z >= self.z_top - 1e-9
            if self.ceiling is not None:
                ok &= z <= self.ceiling + 1e-9
        return np.logical_and.reduceat(ok, np.concatenate([[0], np.cumsum(n)[:-1]]))  # type: ignore[no-any-return]

    def _shortened(self, Q: np.ndarray) -> np.ndarray:
        """Via points: from each point, the farthest point of the route whose joint line to it is clear."""
        out = [Q[0]]
        i = 0
        while i < len(Q) - 1:
            j = len(Q) - 1
            while j > i + 1 and not self._clear_line(Q[i], Q[j]):
                j = i + 1 + (j - i - 1) // 2
            out.append(Q[j])
            i = j
        return np.array(out)

    def _penalty(self, ways: list[Way]) -> np.ndarray:
        """Node weights: :data:`APART` steps around the ways found cost ten times more."""
        near = np.zeros(self.shape, dtype=bool)
        plane = [j for j in range(len(self.shape)) if self.shape[j] > 1][:2]
        for way in ways:
            for k in way.nodes.tolist():
                i = np.unravel_index(k, self.shape)
                sl = tuple(slice(max(0, i[j] - APART), i[j] + APART + 1) if j in plane else slice(None)
                           for j in range(len(self.shape)))  # fmt: skip
                near[sl] = True
        return np.where(near.ravel(), 10.0, 1.0)

    def _apart(self, way: Way, ways: list[Way]) -> bool:
        """Whether ``way`` leaves the nodes near the ways found (another way around)."""
        pen = self._penalty(ways)
        return bool(np.mean(pen[way.nodes] > 1.0) < 0.5)

    def why(self) -> str:
        """The pairs that close the most lattice nodes, in words."""
        if not self.blocked_by:
            return "the tool cannot stay at the traverse height"
        top = sorted(self.blocked_by.items(), key=lambda kv: -kv[1])[:3]
        total = self.size
        return ", ".join(f"{self.scene.pairs[k].label} closes {100.0 * n / total:.2g} %" for k, n in top if n)
