"""An independent minimum-time jump of the default robot in a cell of vertical posts and boxes (tests' own).

Nothing here comes from the planner (``scara_pin.motion.jump`` / ``avoid``) or from the package's cell
code: the tool position and the links are written in closed form from the URDF numbers (l1 = l2 = 0.2 m,
links at z = 0 with half-heights 0.04 / 0.03 and half-widths 0.04 / 0.03, a quill of radius 0.01 rising
0.25 m above a flange of radius 0.025 and thickness 0.01, the tool at z = -0.05 - q3), and the distances
to the obstacles in closed form:

- a vertical POST (circle of radius rp in plan, from a bottom to a top height): every robot shape here is a
  vertical prism too (the flange and the quill are vertical cylinders, the arms boxes with a vertical
  side), and the distance between two vertical prisms is ``sqrt(d_plan^2 + d_z^2)``: d_plan the plan
  distance of their sections (``max(rho - rc - rp, 0)`` for two circles, rho the axes' distance;
  ``max(d_rect - rp, 0)`` for a rectangle, d_rect the distance from the post's axis to it), d_z the gap
  between their height ranges (0 when they overlap);
- link2 is a box from the elbow to 5 mm short of the flange's edge (0.17 m long) and its end, from there to the
  quill's axis, from z = 0.015 to 0.03 only (5 mm above the flange's top at the top of the stroke): the robot's own
  self-collision pair the jump could reach, the flange rising into link2's end, keeps the flange's top at z + 0.01
  margin below 0.015;
- a low axis-aligned WALL across the path under the links (long in x: the tool stays within its x extent,
  asserted after the solve): the flange's distance is ``sqrt(max(|y - yc| - hy - r, 0)^2 + max(dz, 0)^2)``
  (dz: the flange's bottom above the wall's top); the quill is above the flange and narrower, and the links
  are more than the margin above the wall (asserted), so they never come closer.

Transcription (different from the planner's): three phases of free durations as the jump rule has them
(lift within R of A horizontally, traverse at or above z_top, descend within R of B), N = (24, 36, 24)
intervals (the planner's default is 10 / 14 / 10), piecewise-constant joint accelerations, the joint
velocity and acceleration limits at the nodes (exact: linear in time), the joint range, the jump rule and
every distance at both ends and at 3 points inside every interval. IPOPT from several warm starts (joint
lines through given tool via points), the fastest kept.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

L1 = L2 = 0.2
LINK_HALF = (0.04, 0.03)  # half-width = half-height of link1's and link2's boxes [m]
LINK2_BODY = 0.17  # link2's box: from the elbow, 0.2 - 0.025 - 0.005 m long [m]
END = (0.015, 0.03)  # link2's end (from LINK2_BODY to the quill's axis): its bottom and top z [m]
FLANGE_R, FLANGE_H = 0.025, 0.01
QUILL_R, QUILL_H = 0.01, 0.25
R_CLEAR = 0.005
RISE = 0.025
INSIDE = (0.25, 0.5, 0.75)  # fractions of each interval where the path constraints are imposed, besides the ends


@dataclass(frozen=True)
class Post:
    """A vertical cylinder from ``bottom`` to ``top`` (default: spanning every link's height)."""

    x: float
    y: float
    radius: float
    bottom: float = -10.0
    top: float = 10.0


@dataclass(frozen=True)
class LowBox:
    """An axis-aligned box under the links: centre (x, y), half sides (hx, hy), top height."""

    x: float
    y: float
    hx: float
    hy: float
    top: float


def fk_points(q):
    """(elbow (2,), tool (3,)) in closed form, for numbers or CasADi expressions (q: 4 values)."""
    import casadi as ca

    c1, s1 = ca.cos(q[0]), ca.sin(q[0])
    c12, s12 = ca.cos(q[0] + q[1]), ca.sin(q[0] + q[1])
    elbow = ca.vertcat(L1 * c1, L1 * s1)
    tool = ca.vertcat(L1 * c1 + L2 * c12, L1 * s1 + L2 * s12, -0.05 - q[2])
    return elbow, tool


def _rect_d2(px, py, ax, ay, bx, by, half):
    """Squared plan distance from (px, py) to the rectangle around segment a-b of half-width ``half``."""
    import casadi as ca

    ux, uy = bx - ax, by - ay
    length = ca.sqrt(ux * ux + uy * uy)
    ux, uy = ux / length, uy / length
    rx, ry = px - ax, py - ay
    u = rx * ux + ry * uy
    v = -rx * uy + ry * ux
    du = ca.fmax(ca.fmax(-u, u - length), 0.0)
    dv = ca.fmax(ca.fabs(v) - half, 0.0)
    return du * du + dv * dv


def distances(q, posts, boxes, margin):
    """Constraint expressions that are >= 0 exactly when every pair is at least ``margin`` apart."""
    import casadi as ca

    elbow, tool = fk_points(q)
    out = []
    z = tool[2]
    body = elbow + (tool[:2] - elbow) * (LINK2_BODY / L2)  # link2's box ends 0.17 m along the arm
    links = ((0.0, 0.0, elbow[0], elbow[1], LINK_HALF[0]), (elbow[0], elbow[1], body[0], body[1], LINK_HALF[1]))
    for p in posts:

        def gap(lo, hi, p=p):
            return ca.fmax(ca.fmax(lo - p.top, p.bottom - hi), 0.0)

        rho = ca.sqrt((tool[0] - p.x) ** 2 + (tool[1] - p.y) ** 2 + 1e-18)
        for rc, h in ((FLANGE_R, FLANGE_H), (QUILL_R, QUILL_H)):
            out.append(ca.fmax(rho - rc - p.radius, 0.0) ** 2 + gap(z, z + h) ** 2 - margin**2)
        for ax, ay, bx, by, half in links:
            d_rect = ca.sqrt(_rect_d2(p.x, p.y, ax, ay, bx, by, half) + 1e-18)
            out.append(ca.fmax(d_rect - p.radius, 0.0) ** 2 + gap(-half, half) ** 2 - margin**2)
        d_end = ca.sqrt(_rect_d2(p.x, p.y, body[0], body[1], tool[0], tool[1], LINK_HALF[1]) + 1e-18)
        out.append(ca.fmax(d_end - p.radius, 0.0) ** 2 + gap(*END) ** 2 - margin**2)  # link2's end
    # the flange under link2's end (a self-collision pair of the robot: the quill slides through the arm's end)
    out.append(END[0] - (tool[2] + FLANGE_H) - margin)
    for b in boxes:  # a wall across the path: the tool stays within its x extent (checked after the solve)
        dy = ca.fmax(ca.fabs(tool[1] - b.y) - b.hy - FLANGE_R, 0.0)
        dz = ca.fmax(tool[2] - b.top, 0.0)
        out.append(dy * dy + dz * dz - margin**2)
    return out


def minimum_time(robot, A, B, posts=(), boxes=(), margin=0.002, vias=((),), N=(16, 24, 16), top=None):
    """The fastest jump A -> B (rest to rest) keeping the jump rule and every distance; (time, q samples).

    Args:
        robot: the default robot (its limits and IK for the warm starts).
        A, B: (x, y, z, yaw) poses.
        posts, boxes: the obstacles.
        margin: [m].
        vias: warm starts, each a tuple of tool via points (x, y, z) between above A and above B.
        N: intervals per phase.
        top: [m] the height of the warm starts' points above A and B (default: the jump rule's z_top).
    """
    import casadi as ca

    lim = robot.limits
    vmax, amax = np.array(lim.velocity), np.array(lim.acceleration)
    lo, hi = np.array(lim.lower), np.array(lim.upper)
    for b in boxes:
        assert b.top + margin < -max(LINK_HALF), "the links would come near the box: not modelled here"
    qA = robot.ik(A).nearest(np.zeros(4)).q
    br = robot.branch_of(qA)
    qB = robot.ik(B).nearest(qA, branch=br).q
    z_top = max(A[2], B[2]) + RISE
    n = sum(N)
    phase = np.repeat([0, 1, 2], N)
    T = ca.SX.sym("T", 3)
    Q = ca.SX.sym("Q", 4, n + 1)
    V = ca.SX.sym("V", 4, n + 1)
    U = ca.SX.sym("U", 4, n)
    g, lbg, ubg = [], [], []

    def add(e, lo_, hi_):
        e = ca.vec(e)
        g.append(e)
        lbg.extend(np.broadcast_to(np.asarray(lo_, dtype=float), (e.shape[0],)).tolist())
        ubg.extend(np.broadcast_to(np.asarray(hi_, dtype=float), (e.shape[0],)).tolist())

    def rule(q, ph):
        _, p = fk_points(q)
        if ph == 0:
            add((p[0] - A[0]) ** 2 + (p[1] - A[1]) ** 2 - R_CLEAR**2, -np.inf, 0.0)
        elif ph == 1:
            add(p[2] - z_top, 0.0, np.inf)
        else:
            add((p[0] - B[0]) ** 2 + (p[1] - B[1]) ** 2 - R_CLEAR**2, -np.inf, 0.0)
        for e in distances(q, posts, boxes, margin):
            add(e, 0.0, np.inf)

    for k in range(n):
        h = T[phase[k]] / N[phase[k]]
        u = U[:, k] * amax
        add(Q[:, k + 1] - (Q[:, k] + h * V[:, k] + h * h / 2 * u), 0.0, 0.0)
        add(V[:, k + 1] - (V[:, k] + h * u), 0.0, 0.0)
        for f in (0.0, *INSIDE):
            qf = Q[:, k] + f * h * V[:, k] + (f * h) ** 2 / 2 * u
            if f > 0.0:
                add(qf, lo, hi)
            if k > 0 or f > 0.0:
                rule(qf, phase[k])
        add(V[:, k] / vmax, -1.0, 1.0)
    w = ca.vertcat(T, ca.vec(Q), ca.vec(V), ca.vec(U))
    lbx = np.concatenate([[1e-3] * 3, np.tile(lo, n + 1), np.tile(-vmax, n + 1), [-1.0] * (4 * n)])
    ubx = np.concatenate([[2.0] * 3, np.tile(hi, n + 1), np.tile(vmax, n + 1), [1.0] * (4 * n)])
    for col, qq in ((0, qA), (n, qB)):
        for j in range(4):
            lbx[3 + 4 * col + j] = ubx[3 + 4 * col + j] = qq[j]
            lbx[3 + 4 * (n + 1) + 4 * col + j] = ubx[3 + 4 * (n + 1) + 4 * col + j] = 0.0
    solver = ca.nlpsol("reference", "ipopt", {"x": w, "f": ca.sum1(T), "g": ca.vertcat(*g)},
                       {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.tol": 1e-9,
                        "ipopt.max_iter": 3000})  # fmt: skip
    best = None
    for via in vias:
        zt = z_top if top is None else top
        tops = [np.array([A[0], A[1], zt, A[3]]), *[np.array([*v, A[3]]) for v in via],
                np.array([B[0], B[1], zt, B[3]])]
        way = [qA]
        for pose in tops:
            way.append(robot.ik(pose).nearest(way[-1], branch=br).q)
        way.append(qB)
        way = np.array(way)
        # joint lines: lift, traverse through the vias, descend; each phase's nodes spread along its lines
        segs = [way[:2], way[1:-1], way[-2:]]
        q0 = [segs[0][0]]
        for p in range(3):
            pts = segs[p]
            s = np.linspace(0.0, len(pts) - 1.0, N[p] + 1)[1:]
            i = np.minimum(np.floor(s).astype(int), len(pts) - 2)
            f = (s - i)[:, None]
            q0.extend(pts[i] * (1 - f) + pts[i + 1] * f)
        q0 = np.array(q0)
        T0 = np.array([0.1, 0.3, 0.1])
        x0 = np.concatenate([T0, q0.ravel(), np.zeros(4 * (n + 1)), np.zeros(4 * n)])
        sol = solver(x0=x0, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
        if not solver.stats()["success"]:
            continue
        x = np.array(sol["x"]).ravel()
        t = float(np.sum(x[:3]))
        qs = x[3 : 3 + 4 * (n + 1)].reshape(n + 1, 4)
        for b in boxes:
            tx = L1 * np.cos(qs[:, 0]) + L2 * np.cos(qs[:, 0] + qs[:, 1])
            assert np.all(np.abs(tx - b.x) <= b.hx), "the tool left the wall's x extent: the wall model does not hold"
        if best is None or t < best[0]:
            best = (t, np.array(sol["x"]).ravel())
    assert best is not None, "no warm start converged"
    return best[0]
