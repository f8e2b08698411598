"""The jump's NLP: the transcription with interior points and distance rows (:mod:`~scara_pin.motion.jump`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...signals import check_time
from .problem import NODES, ConstraintPoint, Problem, propagate
from .rows import DISTANCE_SCALE, RESOLVE_ITERATIONS, DistanceRow, Rows
from .types import JumpOptions

_TIE_VELOCITY = 1e-4
"""Weight of the mean squared joint velocity over its limit (relative to the duration over ``t_scale``): among
the minimum-time motions (the time is unique, the path is not: the joints that do not bind can move in many
ways) the calmest: the quill brakes at once after the lift, holds, and comes down as late as it can (the
lowest single-hump arch), the elbow and the wrist move smoothly; its effect on the time is below 1e-9 relative
on the standard cycle."""


_TIE_SMOOTH = 1e-6
"""Weight of the mean squared scaled control: then the smoothest controls of the joints that do not bind."""


class Transcription:
    """The NLP of a move with interior points added by the refinement (module docstring).

    Variables (scaled to order 1): the phase durations over ``t_scale``, the node states over
    ``state_scale``, the controls over their limits. At the nodes: the exact integration between them, the
    clearance of each node's phase(s) and the ceiling; the velocity, acceleration (jerk control) and
    joint range as variable bounds, both ends at rest. The torque and the tool speed, and everything
    between nodes, only where the refinement put a point (a node's two sides are sigma = 0 and 1 of its
    intervals).
    """

    def __init__(self, prob: Problem, points: tuple[ConstraintPoint, ...], options: JumpOptions,
                 distance_rows: tuple[DistanceRow, ...] = (), avoid: Rows | None = None,
                 resolve: bool = False) -> None:  # fmt: skip
        import casadi as ca

        self.prob = P = prob
        order, dof, N = P.order, P.robot.dof, P.N
        Nt = sum(N)
        sx = P.state_scale
        T = ca.SX.sym("T", 3)
        X = ca.SX.sym("X", order * dof, Nt + 1)
        U = ca.SX.sym("U", dof, Nt)
        h, rows, Up = self._physical(T, X, U)
        g: list[Any] = []
        lb: list[np.ndarray] = []
        ub: list[np.ndarray] = []

        def add(expr: Any, lo: Any, hi: Any) -> None:
            e = ca.vec(expr)
            n = e.shape[0]
            g.append(e)
            lb.append(np.broadcast_to(np.asarray(lo, dtype=float), (n,)).ravel())
            ub.append(np.broadcast_to(np.asarray(hi, dtype=float), (n,)).ravel())

        nxt = propagate(order, [r[:, :Nt] for r in rows], Up, ca.repmat(h, dof, 1))
        for i in range(order):  # exact integration between nodes
            add((nxt[i] - rows[i][:, 1:]) / ca.repmat(ca.DM(sx[i]), 1, Nt), 0.0, 0.0)
        # between nodes, the joint range and (jerk control) the velocity by the Bernstein control points of the
        # polynomial on each interval: the polynomial stays in their convex hull
        H = ca.repmat(h, dof, 1)
        q0, v0 = rows[0][:, :Nt], rows[1][:, :Nt]
        if order == 2:
            hull = [q0 + v0 * H / 2.0]
        else:
            hull = [q0 + v0 * H / 3.0, q0 + v0 * H * (2.0 / 3.0) + rows[2][:, :Nt] * H * H / 6.0]
        span = ca.repmat(ca.DM(sx[0]), 1, Nt)
        for b in hull:
            add((b - ca.repmat(ca.DM(P.lower), 1, Nt)) / span, np.tile(np.where(P.ranged, 0.0, -np.inf), Nt), np.inf)
            add((b - ca.repmat(ca.DM(P.upper), 1, Nt)) / span, -np.inf, np.tile(np.where(P.ranged, 0.0, np.inf), Nt))
        if order == 3:
            add((v0 + rows[2][:, :Nt] * H / 2.0) / ca.repmat(ca.DM(P.velocity), 1, Nt), -1.0, 1.0)
        scale_z = max(P.z_top - min(P.A[2], P.B[2]), 1e-3)

        def geometry(q: Any, phase: np.ndarray) -> None:
            """The clearance of each column's phase(s) (phase: (n, 3) booleans) and the ceiling."""
            p = P.sym.tool_position.map(q.shape[1])(q)
            for ph, centre in ((0, P.A), (2, P.B)):
                cols = np.nonzero(phase[:, ph])[0].tolist()
                if cols:
                    d2 = (p[0, cols] - centre[0]) ** 2 + (p[1, cols] - centre[1]) ** 2
                    add(d2 / (P.R * P.R), -np.inf, 1.0)
            cols = np.nonzero(phase[:, 1])[0].tolist()
            if cols:
                add((p[2, cols] - P.z_top) / scale_z, 0.0, np.inf)
            if P.max_height is not None:
                add((p[2, :] - P.max_height) / scale_z, -np.inf, 0.0)

        k_nodes = np.arange(Nt + 1)
        cut = (N[0], N[0] + N[1])
        geometry(rows[0], np.column_stack([k_nodes <= cut[0], (k_nodes >= cut[0]) & (k_nodes <= cut[1]),
                                           k_nodes >= cut[1]]))  # fmt: skip
        if P.tool_speed is not None:
            v = P.sym.tool_velocity.map(Nt + 1)(rows[0], rows[1])
            add(ca.sum1(v * v) / P.tool_speed**2, -np.inf, 1.0)
        if P.effort is not None and ConstraintPoint(NODES, 0.0, "torque") in points:  # at every node
            # acceleration control: both sides (each interval's start and end with its own control); jerk: once
            sides = [(slice(0, Nt), Up), (slice(1, Nt + 1), Up)] if order == 2 else [(slice(0, Nt + 1), rows[2])]
            for cols, acc in sides:
                m = cols.stop - cols.start
                tau_ = P.sym.inverse_dynamics.map(m)(rows[0][:, cols], rows[1][:, cols], acc)
                add(tau_ / ca.repmat(ca.DM(P.effort), 1, m), -1.0, 1.0)
        phase_of = P.phase_of()
        for family in ("geometry", "torque", "tool speed"):
            pts = [pt for pt in points if pt.family == family and pt.k != NODES]
            if not pts:
                continue
            ks = [pt.k for pt in pts]
            n = len(ks)
            tau = ca.repmat(h[0, ks] * ca.DM([pt.sigma for pt in pts]).T, dof, 1)
            st = propagate(order, [r[:, ks] for r in rows], Up[:, ks], tau)
            acc = Up[:, ks] if order == 2 else st[2]
            if family == "geometry":
                geometry(st[0], np.eye(3, dtype=bool)[phase_of[ks]])
            elif family == "torque" and P.effort is not None:
                tau_ = P.sym.inverse_dynamics.map(n)(st[0], st[1], acc)
                add(tau_ / ca.repmat(ca.DM(P.effort), 1, n), -1.0, 1.0)
            elif family == "tool speed" and P.tool_speed is not None:
                v = P.sym.tool_velocity.map(n)(st[0], st[1])
                add(ca.sum1(v * v) / P.tool_speed**2, -np.inf, 1.0)
        self.n_rows = len(distance_rows)
        w = ca.vertcat(T, ca.vec(X), ca.vec(U))
        G = ca.vertcat(*g)
        # minimum time; then, as tie-breakers among the minimum-time motions, the lowest arch and smooth controls
        f = (ca.sum1(T) + _TIE_VELOCITY * ca.sumsqr(X[dof : 2 * dof, :]) / (dof * (Nt + 1))
             + _TIE_SMOOTH * ca.sumsqr(U) / (dof * Nt))  # fmt: skip
        nlp = {"x": w, "f": f, "g": G}
        if distance_rows and avoid is not None:
            nlp = self._with_rows(nlp, distance_rows, avoid)
            lb.append(np.zeros(len(distance_rows)))
            ub.append(np.full(len(distance_rows), np.inf))
            G = nlp["g"]
        self.n_x, self.n_g = int(w.shape[0]), int(G.shape[0])
        self.lbg, self.ubg = np.concatenate(lb), np.concatenate(ub)
        lbx_X = np.empty((order * dof, Nt + 1))
        ubx_X = np.empty((order * dof, Nt + 1))
        lbx_X[:dof] = (np.where(P.ranged, P.lower, -np.inf) / sx[0])[:, None]
        ubx_X[:dof] = (np.where(P.ranged, P.upper, np.inf) / sx[0])[:, None]
        lbx_X[dof:] = -1.0
        ubx_X[dof:] = 1.0
        for col, q in ((0, P.qA), (Nt, P.qB)):  # both ends: at the pose, at rest
            lbx_X[:, col] = ubx_X[:, col] = 0.0
            lbx_X[:dof, col] = ubx_X[:dof, col] = q / sx[0]
        self.lbx = np.concatenate([np.full(3, 1e-4), lbx_X.ravel(order="F"), -np.ones(dof * Nt)])
        self.ubx = np.concatenate([np.full(3, 1e4), ubx_X.ravel(order="F"), np.ones(dof * Nt)])
        opts: dict[str, Any] = {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False,
                                "ipopt.tol": options.tolerance, "ipopt.constr_viol_tol": options.tolerance,
                                "ipopt.max_iter": options.max_iterations, "ipopt.mu_strategy": "adaptive"}  # fmt: skip
        if resolve:  # a re-solve from the last solution (obstacle rows re-set): it converges fast or not at all
            opts["ipopt.max_iter"] = min(options.max_iterations, RESOLVE_ITERATIONS)
        self.solver = ca.nlpsol("jump", "ipopt", nlp, opts)
        self.shape = (order, dof, Nt)

    def _physical(self, T: Any, X: Any, U: Any) -> tuple[Any, list[Any], Any]:
        """(interval lengths (1, Nt), state rows [q, qd(, qdd)] (dof, Nt + 1), controls (dof, Nt)) in SI units."""
        import casadi as ca

        P = self.prob
        order, dof, N = P.order, P.robot.dof, P.N
        Nt = sum(N)
        Xp = ca.repmat(ca.DM(P.state_scale.ravel()), 1, Nt + 1) * X
        Up = ca.repmat(ca.DM(P.control_limit), 1, Nt) * U
        h = ca.horzcat(*[ca.repmat(T[p] * (P.t_scale / N[p]), 1, N[p]) for p in range(3)])  # 1 x Nt
        return h, [Xp[i * dof : (i + 1) * dof, :] for i in range(order)], Up

    def _with_rows(self, nlp: dict[str, Any], distance_rows: tuple[DistanceRow, ...], avoid: Rows) -> dict[str, Any]:
        """The NLP with the obstacle rows (:mod:`~scara_pin.motion.jump.rows`) appended to its constraints.

        Each row keeps its pair's first shape beyond a separating plane taken from the last solution: the
        planes are parameters (9 per row), re-set after every solve without rebuilding the problem. The forward
        kinematics of each row's point is written once (mapped over the points), and each pair's separation
        function is called on it.
        """
        import casadi as ca

        P = self.prob
        order, dof = P.order, P.robot.dof
        Nt = sum(P.N)
        w = nlp["x"]
        Pd = ca.SX.sym("Pd", len(distance_rows) * avoid.PARAMETERS)
        nX = order * dof * (Nt + 1)
        h, rows, Up = self._physical(w[:3], ca.reshape(w[3 : 3 + nX], order * dof, Nt + 1),
                                     ca.reshape(w[3 + nX :], dof, Nt))  # fmt: skip
        par = ca.reshape(Pd, avoid.PARAMETERS, len(distance_rows))
        keys = sorted({(r.k, r.sigma) for r in distance_rows})
        where = {key: c for c, key in enumerate(keys)}
        ks = [k for k, _ in keys]
        tau = ca.repmat(h[0, ks] * ca.DM([sg for _, sg in keys]).T, dof, 1)
        qs = propagate(order, [r[:, ks] for r in rows], Up[:, ks], tau)[0]  # dof x points
        frames = P.sym.joint_frames.map(len(keys))(qs)  # 12 x (njoints * points)
        nj = frames.shape[1] // len(keys)
        seps = []
        for i, r in enumerate(distance_rows):
            ja, jb = avoid.joints(r.pair)
            c = where[(r.k, r.sigma)]
            seps.append(avoid.function(r.pair)(frames[:, c * nj + ja], frames[:, c * nj + jb], par[0:3, i],
                                               par[3:6, i], par[6:9, i]))  # fmt: skip
        g_rows = (ca.vertcat(*seps) - (avoid.margin + avoid.buffer)) / DISTANCE_SCALE
        return {"x": w, "f": nlp["f"], "g": ca.vertcat(nlp["g"], g_rows), "p": Pd}

    def solve(self, x0: np.ndarray, lam_x: np.ndarray | None, lam_g: np.ndarray | None,
              params: np.ndarray | None = None) -> dict[str, Any]:  # fmt: skip
        """One IPOPT solve from x0 (and multipliers, when warm-starting); ``params``: the distance rows' (g, c)."""
        kwargs: dict[str, Any] = {"x0": x0, "lbx": self.lbx, "ubx": self.ubx, "lbg": self.lbg, "ubg": self.ubg,
                                  "p": np.zeros(0) if params is None else params}  # fmt: skip
        if lam_x is not None:
            kwargs["lam_x0"] = lam_x
        if lam_g is not None:
            kwargs["lam_g0"] = lam_g
        check_time()  # a sweep's time limit: stopped before a solver call, not in one
        sol = self.solver(**kwargs)
        stats = self.solver.stats()
        return {"x": np.array(sol["x"]).ravel(), "lam_x": np.array(sol["lam_x"]).ravel(),
                "lam_g": np.array(sol["lam_g"]).ravel(), "status": str(stats["return_status"]),
                "success": bool(stats["success"]), "iterations": int(stats["iter_count"])}  # fmt: skip

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(T (3,), states (Nt + 1, order, dof), controls (Nt, dof)) in SI from the scaled variables."""
        order, dof, Nt = self.shape
        P = self.prob
        T = x[:3] * P.t_scale
        X = x[3 : 3 + order * dof * (Nt + 1)].reshape((Nt + 1, order, dof)) * P.state_scale[None]
        U = x[3 + order * dof * (Nt + 1) :].reshape((Nt, dof)) * P.control_limit[None]
        return T, X, U

    def pack(self, T: np.ndarray, X: np.ndarray, U: np.ndarray) -> np.ndarray:
        """The scaled variables of (T, states, controls) in SI."""
        P = self.prob
        return np.concatenate([T / P.t_scale, (X / P.state_scale[None]).ravel(), (U / P.control_limit[None]).ravel()])
