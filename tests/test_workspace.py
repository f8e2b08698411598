"""The exact workspace against independent routes.

Truth comes from (a) dense seeded joint-space sampling of the forward map written here,
(b) Monte Carlo area with the closed-form reachability test, (c) ``ik.solve``, and (d) marching +
bisection along rays with ``contains``. Tolerances: 1e-9 m for on-boundary and ray distances (the
joint-space tolerances of the reachability test are 1e-10), 3 sigma for Monte Carlo areas.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from scara_pin import InvalidInputError, ParameterError, Robot, ScaraError
from scara_pin.kinematics.scara import IKStatus, ScaraGeometry, solve
from scara_pin.workspace.scara import Limit, OutsideWorkspaceError, Workspace, plot_workspace, workspace

D = math.radians


def make_geo(
    l1: float,
    l2: float,
    j1: tuple[float, float],
    j2: tuple[float, float],
    *,
    signs: tuple[float, float, float, float] = (1.0, 1.0, -1.0, 1.0),
    a1: tuple[float, float] = (0.0, 0.0),
    beta1: float = 0.0,
    bend: float = 0.0,
    tool: tuple[float, float] = (0.0, 0.0),
    j4: float = 2 * math.pi,
) -> ScaraGeometry:
    """A SCARA geometry with J1/J2 limits in degrees (J3 stroke 0..0.2 m, downwards, z0 = 0.1 m)."""
    u1 = (l1 * math.cos(beta1), l1 * math.sin(beta1))
    u2 = (l2 * math.cos(beta1 + bend), l2 * math.sin(beta1 + bend))
    return ScaraGeometry(
        revolute=(0, 1, 3), prismatic=2, names=("joint1", "joint2", "joint3", "joint4"), signs=signs,
        a1=a1, u1=u1, u2=u2, tool=tool, z0=0.1, yaw0=0.0, R0=np.eye(3),
        lower=(D(j1[0]), D(j2[0]), 0.0, -j4), upper=(D(j1[1]), D(j2[1]), 0.2, j4),
    )  # fmt: skip


CASES: dict[str, ScaraGeometry] = {
    # digest S5 with the numbers: J2 range contains 0, four arcs (the inner one in two labels)
    "s5": make_geo(0.325, 0.275, (-132, 132), (-88, 88)),
    "j1_full_turn": make_geo(0.325, 0.275, (-200, 200), (-150, 150)),
    "j2_without_zero": make_geo(0.3, 0.25, (-100, 60), (30, 140)),
    "j2_beyond_pi": make_geo(0.3, 0.25, (-120, 120), (-200, 200)),
    "asymmetric": make_geo(0.2, 0.3, (-30, 170), (-40, 150), signs=(-1.0, 1.0, 1.0, -1.0), a1=(0.05, -0.02),
                           beta1=math.pi / 2, bend=0.3),  # fmt: skip
    "j2_over_a_turn": make_geo(0.3, 0.25, (-45, 45), (-370, 370)),
    "equal_arms_folded": make_geo(0.2, 0.2, (-100, 100), (-190, 190)),
    "c_shaped_ring": make_geo(0.3, 0.2, (-175, 175), (20, 60)),
    "hole": make_geo(0.2, 0.2, (-132, 132), (-150, 150)),
    # a J2 limit at exactly 0 (its arc is the outer circle) and J1 spanning exactly one turn
    "j2_from_zero": make_geo(0.3, 0.25, (-90, 150), (0, 120)),
    "j1_exactly_a_turn": make_geo(0.3, 0.25, (-180, 180), (0, 120)),
    # a J2 limit 1e-4 rad past 0: its circle lies 2e-9 m inside the outer one (not the boundary)
    "j2_just_past_zero": make_geo(0.443, 0.465, (-93, 180), (-45.6, math.degrees(1e-4))),
    # J1 edge arcs tangent to the outer and folded circles, where the generic intersection loses digits
    "tangent_corners": make_geo(0.34, 0.078, (-150, 120), (-200, 200)),
}


@pytest.fixture(scope="module")
def spaces() -> dict[str, Workspace]:
    return {name: workspace(geo) for name, geo in CASES.items()}


def forward(geo: ScaraGeometry, q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Wrist point of joint values, written here from the product of rotations (independent of the module)."""
    phi1, phi2 = geo.signs[geo.revolute[0]] * q1, geo.signs[geo.revolute[1]] * q2
    u1, u2 = np.array(geo.u1), np.array(geo.u2)

    def rot(a: np.ndarray, v: np.ndarray) -> np.ndarray:
        c, s = np.cos(a), np.sin(a)
        return np.column_stack((c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1]))

    return np.array(geo.a1) + rot(phi1, u1[None, :] + rot(phi2, np.broadcast_to(u2, (len(q2), 2))))


def joint_samples(geo: ScaraGeometry, n: int, rng: np.random.Generator, edges: int = 0) -> np.ndarray:
    """Wrist points of n uniform (q1, q2) within the limits, plus ``edges`` points on each rectangle edge."""
    ra, rb = geo.revolute[0], geo.revolute[1]
    lo1, hi1, lo2, hi2 = geo.lower[ra], geo.upper[ra], geo.lower[rb], geo.upper[rb]
    q1, q2 = rng.uniform(lo1, hi1, n), rng.uniform(lo2, hi2, n)
    if edges:
        e1, e2 = rng.uniform(lo1, hi1, edges), rng.uniform(lo2, hi2, edges)
        q1 = np.concatenate((q1, e1, e1, np.full(edges, lo1), np.full(edges, hi1)))
        q2 = np.concatenate((q2, np.full(edges, lo2), np.full(edges, hi2), e2, e2))
    return forward(geo, q1, q2)


def box_samples(ws: Workspace, n: int, rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """n uniform points in the reach box around the shoulder, and the box area."""
    g = ws.geometry
    R = g.l1 + g.l2
    return np.array(g.a1) - R + rng.uniform(0.0, 2 * R, (n, 2)), (2 * R) ** 2


# ------------------------------------------------------------------------------------------ region
@pytest.mark.parametrize("name", CASES)
def test_every_joint_sample_is_inside_the_arcs(name: str, spaces: dict[str, Workspace]) -> None:
    ws, geo = spaces[name], CASES[name]
    P = joint_samples(geo, 200_000, np.random.default_rng(1), edges=5_000)
    outside = ~ws.contains_by_arcs(P) & (ws.distance_to_boundary(P) > 1e-9)
    assert outside.sum() == 0, P[outside][:5]
    # the arcs are not bigger than the region: every arc point has a reachable sample nearby
    # (the edge samples are 5000 per edge over at most ~2 m of arc: spacing well below 2 mm)
    arc_points = np.vstack([a.points(400) for a in ws.arcs])
    gap, _ = cKDTree(P).query(arc_points)
    assert gap.max() < 2e-3


@pytest.mark.parametrize("name", CASES)
def test_contains_agrees_with_the_arcs_away_from_the_boundary(name: str, spaces: dict[str, Workspace]) -> None:
    ws = spaces[name]
    B, _ = box_samples(ws, 200_000, np.random.default_rng(2))
    far = ws.distance_to_boundary(B) > 1e-7
    assert far.mean() > 0.99
    assert np.array_equal(ws.contains(B[far]), ws.contains_by_arcs(B[far]))


@pytest.mark.parametrize("name", CASES)
def test_area_matches_monte_carlo(name: str, spaces: dict[str, Workspace]) -> None:
    ws = spaces[name]
    n = 400_000
    B, box = box_samples(ws, n, np.random.default_rng(3))
    f = ws.contains(B).mean()
    sigma = box * math.sqrt(f * (1 - f) / n)
    assert abs(ws.area - f * box) < 3 * sigma, (ws.area, f * box, sigma)


@pytest.mark.parametrize("name", CASES)
def test_loops_are_closed_and_oriented(name: str, spaces: dict[str, Workspace]) -> None:
    ws = spaces[name]
    assert sorted(i for loop in ws.loops for i in loop) == list(range(len(ws.arcs)))
    for loop in ws.loops:
        ends = []
        for i in loop:
            a = ws.arcs[i]
            p0, p1 = np.array(a.point(a.start)), np.array(a.point(a.end))
            ends.append((p0, p1) if a.region_inside else (p1, p0))
        for k in range(len(loop)):
            assert np.linalg.norm(ends[k][1] - ends[(k + 1) % len(loop)][0]) < 1e-11
    # a point just left of each arc's traversal direction is inside, just right is outside (arcs of at
    # least 1 mm: shorter ones sit in corners where the region is thinner than the 1e-6 m offset)
    for a in ws.arcs:
        if a.radius * a.sweep < 1e-3:
            continue
        m = a.start + a.sweep / 2
        inward = -1.0 if a.region_inside else 1.0
        c, r = np.array(a.center), a.radius
        e = np.array([math.cos(m), math.sin(m)])
        assert ws.contains(c + (r + inward * 1e-6) * e)
        assert not ws.contains(c + (r - inward * 1e-6) * e)


@pytest.mark.parametrize("name", CASES)
def test_radii(name: str, spaces: dict[str, Workspace]) -> None:
    ws, geo = spaces[name], CASES[name]
    r = np.hypot(*(joint_samples(geo, 100_000, np.random.default_rng(4), edges=2_000) - geo.a1).T)
    assert r.min() >= ws.r_min - 1e-12 and r.max() <= ws.r_max + 1e-12
    assert r.min() < ws.r_min + 1e-3 and r.max() > ws.r_max - 1e-3
    arc_r = np.hypot(*(np.vstack([a.points(2000) for a in ws.arcs]) - geo.a1).T)
    assert abs(arc_r.max() - ws.r_max) < 1e-9
    if ws.r_min > 0:  # the region touches the circle r = r_min from outside: on its boundary
        assert abs(arc_r.min() - ws.r_min) < 1e-6
    else:  # equal arms folded: the shoulder axis itself is reachable
        assert ws.contains(list(geo.a1))


def test_s5_inner_radius_is_0433() -> None:
    ws = workspace(CASES["s5"])
    l1, l2 = 0.325, 0.275
    assert ws.r_min == pytest.approx(math.sqrt(l1**2 + l2**2 + 2 * l1 * l2 * math.cos(D(88))), abs=1e-12)
    assert abs(ws.r_min - 0.433) < 5e-4  # the issue's number, not the annulus' |l1 - l2| = 0.05
    assert ws.r_max == pytest.approx(0.6, abs=1e-12)
    # S5's four arcs: outer, two radius-l2 arcs about the elbows at the J1 limits, the inner J2 arc
    kinds = sorted(a.limit.value for a in ws.arcs)
    assert kinds == ["joint1_lower", "joint1_upper", "joint2_lower", "joint2_upper", "outer"]
    inner = [a for a in ws.arcs if a.limit in (Limit.J2_LOWER, Limit.J2_UPPER)]
    assert all(a.radius == pytest.approx(ws.r_min, abs=1e-12) and not a.region_inside for a in inner)
    assert len(ws.loops) == 1


def test_full_j1_turn_is_an_annulus() -> None:
    ws = workspace(CASES["j1_full_turn"])
    assert {a.limit for a in ws.arcs} == {Limit.OUTER, Limit.J2_LOWER}
    assert all(a.sweep == 2 * math.pi and a.center == (0.0, 0.0) for a in ws.arcs)
    assert ws.area == pytest.approx(math.pi * (ws.r_max**2 - ws.r_min**2), rel=1e-12)
    assert len(ws.loops) == 2


def test_j2_beyond_pi_reaches_the_folded_circle() -> None:
    ws = workspace(CASES["j2_beyond_pi"])
    assert ws.r_min == pytest.approx(0.05, abs=1e-12)
    assert any(a.limit is Limit.FOLDED and a.radius == pytest.approx(0.05) for a in ws.arcs)


def test_hole() -> None:
    ws = workspace(CASES["hole"])
    assert len(ws.loops) == 2
    assert not ws.contains([0.0, 0.0]) and not ws.contains([-0.05, 0.0])


@pytest.mark.parametrize("name", CASES)
def test_arc_labels_name_the_active_limit(name: str, spaces: dict[str, Workspace]) -> None:
    """At each arc's midpoint the IK has a solution with the labelled joint at the labelled limit."""
    ws, geo = spaces[name], CASES[name]
    ra, rb = geo.revolute[0], geo.revolute[1]
    for a in ws.arcs:
        x, y = a.point(a.start + a.sweep / 2)
        res = solve(geo, (float(x), float(y), 0.5 * sum(ws.z_range), 0.0))
        assert res.status is IKStatus.OK, (a, res.message)
        qs = np.array([s.q for s in res.solutions])
        gamma = np.array([geo.elbow_angle(v) for v in qs[:, rb]])
        wrap = np.abs((gamma + math.pi) % (2 * math.pi) - math.pi)
        check = {
            Limit.J1_LOWER: np.abs(qs[:, ra] - geo.lower[ra]), Limit.J1_UPPER: np.abs(qs[:, ra] - geo.upper[ra]),
            Limit.J2_LOWER: np.abs(qs[:, rb] - geo.lower[rb]), Limit.J2_UPPER: np.abs(qs[:, rb] - geo.upper[rb]),
            Limit.OUTER: wrap, Limit.FOLDED: math.pi - wrap,
        }[a.limit]  # fmt: skip
        assert check.min() < 1e-6, (name, a)


@pytest.mark.parametrize("name", CASES)
def test_contains_agrees_with_ik(name: str, spaces: dict[str, Workspace]) -> None:
    ws, geo = spaces[name], CASES[name]
    B, _ = box_samples(ws, 600, np.random.default_rng(5))
    B = B[ws.distance_to_boundary(B) > 1e-7]
    inside = ws.contains(B)
    assert 0 < inside.sum() < len(B)
    for (x, y), expected in zip(B.tolist(), inside, strict=True):
        status = solve(geo, (x, y, 0.5 * sum(ws.z_range), 0.7)).status
        assert (status is IKStatus.OK) == expected, (x, y, status)


@pytest.mark.parametrize("robot_name", ["default", "s1"])
def test_shipped_robots(robot_name: str, robots: dict[str, Robot]) -> None:
    robot = robots[robot_name]
    ws = workspace(robot)
    geo = robot.kinematics.geometry
    rng = np.random.default_rng(6)
    P = joint_samples(geo, 50_000, rng, edges=1_000)
    assert (ws.contains_by_arcs(P) | (ws.distance_to_boundary(P) <= 1e-9)).all()
    B, box = box_samples(ws, 200_000, rng)
    f = ws.contains(B).mean()
    assert abs(ws.area - f * box) < 3 * box * math.sqrt(f * (1 - f) / len(B))
    assert (ws.r_min, ws.r_max) == geo.radius_range()
    z = [robot.tool_placement(q).translation[2] for q in (geo.lower, geo.upper)]
    assert ws.z_range == pytest.approx(sorted(z), abs=1e-12)
    B = B[ws.distance_to_boundary(B) > 1e-7][:200]
    for x, y in B.tolist():
        ok = solve(geo, (x, y, 0.5 * sum(ws.z_range), 0.0)).status is IKStatus.OK
        assert ok == ws.contains([x, y])


def test_tool_offset_region_at_a_fixed_yaw() -> None:
    geo = make_geo(0.3, 0.25, (-120, 120), (-140, 140), tool=(0.04, -0.03))
    yaw = 0.8
    ws = workspace(geo, yaw=yaw)
    assert ws.offset == pytest.approx((0.04 * math.cos(yaw) + 0.03 * math.sin(yaw),
                                       0.04 * math.sin(yaw) - 0.03 * math.cos(yaw)), abs=1e-15)  # fmt: skip
    B, _ = box_samples(workspace(geo), 400, np.random.default_rng(7))
    B = B + ws.offset
    B = B[ws.distance_to_boundary(B) > 1e-7]
    for x, y in B.tolist():
        assert (solve(geo, (x, y, 0.0, yaw)).status is IKStatus.OK) == ws.contains([x, y])
    with pytest.raises(ParameterError, match="yaw is nan"):
        workspace(geo, yaw=math.nan)
    with pytest.raises(ParameterError, match="joint4"):
        workspace(replace(geo, lower=(*geo.lower[:3], -1.0), upper=(*geo.upper[:3], 1.0)), yaw=yaw)


def test_infinite_limits() -> None:
    """Continuous joints (infinite limits) turn as far as they like: annuli, or whole-circle J1 edges."""
    geo = make_geo(0.3, 0.2, (-100, 100), (-90, 90))
    inf = math.inf
    j1 = workspace(geo, lower=(-inf, -1.0, 0.0, -6.0), upper=(inf, 1.0, 0.2, 6.0))
    r_in = math.sqrt(0.3**2 + 0.2**2 + 2 * 0.3 * 0.2 * math.cos(1.0))
    assert (j1.r_min, j1.r_max) == (pytest.approx(r_in, abs=1e-12), pytest.approx(0.5, abs=1e-12))
    assert j1.area == pytest.approx(math.pi * (0.25 - r_in**2), rel=1e-12)
    both = workspace(geo, lower=(-inf, -inf, 0.0, -6.0), upper=(inf, inf, 0.2, 6.0))
    assert both.area == pytest.approx(math.pi * (0.5**2 - 0.1**2), rel=1e-12)
    j2 = workspace(geo, lower=(-1.0, -inf, 0.0, -6.0), upper=(1.0, inf, 0.2, 6.0))
    B, box = box_samples(j2, 200_000, np.random.default_rng(12))
    f = j2.contains(B).mean()
    assert abs(j2.area - f * box) < 3 * box * math.sqrt(f * (1 - f) / len(B))
    assert {a.limit for a in j2.arcs} == {Limit.OUTER, Limit.FOLDED, Limit.J1_LOWER, Limit.J1_UPPER}


def test_limit_overrides_and_bad_limits() -> None:
    geo = CASES["s5"]
    ws = workspace(geo, lower=(D(-90), D(-88), 0.0, -6.0), upper=(D(90), D(88), 0.2, 6.0))
    assert ws.area < workspace(geo).area
    with pytest.raises(ParameterError, match="joint2"):
        workspace(geo, lower=(0.0, 1.0, 0.0, 0.0), upper=(1.0, 0.5, 0.1, 1.0))
    with pytest.raises(ParameterError, match="joint1 .* no area"):
        workspace(geo, lower=(0.5, -1.0, 0.0, 0.0), upper=(0.5, 1.0, 0.1, 1.0))


def random_geometries(n: int, seed: int) -> list[ScaraGeometry]:
    """Seeded random SCARAs: arm lengths (sometimes equal), J1/J2 ranges from 5 to 420 deg anywhere in
    [-410, 410] deg, either axis sign, shoulder offsets, arms not along +x, a bent zero pose."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        l1, l2 = rng.uniform(0.05, 0.5, 2)
        if rng.random() < 0.15:
            l2 = l1
        c1, w1 = rng.uniform(-180, 180), rng.choice([rng.uniform(5, 360), rng.uniform(300, 420)])
        c2, w2 = rng.uniform(-200, 200), rng.choice([rng.uniform(5, 180), rng.uniform(150, 420)])
        signs = (float(rng.choice([-1, 1])), float(rng.choice([-1, 1])), -1.0, 1.0)
        out.append(make_geo(l1, l2, (c1 - w1 / 2, c1 + w1 / 2), (c2 - w2 / 2, c2 + w2 / 2), signs=signs,
                            a1=(float(rng.uniform(-0.1, 0.1)), float(rng.uniform(-0.1, 0.1))),
                            beta1=float(rng.uniform(-3, 3)), bend=float(rng.uniform(-1, 1))))  # fmt: skip
    return out


@pytest.mark.parametrize("index", range(24))
def test_random_limit_sets(index: int) -> None:
    """Any J1/J2 limits: samples inside, contains = arcs, area = Monte Carlo (4 sigma over 24 sets), rays."""
    geo = random_geometries(24, 11)[index]
    ws = workspace(geo)
    rng = np.random.default_rng(100 + index)
    P = joint_samples(geo, 30_000, rng, edges=1_000)
    assert (ws.contains_by_arcs(P) | (ws.distance_to_boundary(P) <= 1e-9)).all()
    B, box = box_samples(ws, 100_000, rng)
    far = ws.distance_to_boundary(B) > 1e-7
    assert np.array_equal(ws.contains(B[far]), ws.contains_by_arcs(B[far]))
    f = ws.contains(B).mean()
    assert abs(ws.area - f * box) < 4 * box * math.sqrt(f * (1 - f) / len(B)) + 1e-12
    S = joint_samples(geo, 60, rng)
    S = S[ws.distance_to_boundary(S) > 1e-6][:30]  # starts within EDGE_TOL count as on the edge
    ang = rng.uniform(-math.pi, math.pi, len(S))
    Dn = np.column_stack((np.cos(ang), np.sin(ang)))
    hits = ws.ray_batch(S, Dn)
    assert np.abs(hits.distance - march_and_bisect(ws, S, Dn, until=hits.distance + 2e-4)).max() < 1e-9


# ------------------------------------------------------------------------------------------ rays
def march_and_bisect(
    ws: Workspace, S: np.ndarray, Dn: np.ndarray, until: np.ndarray | None = None, step: float = 1e-4
) -> np.ndarray:
    """First exit distance along each unit ray, from ``contains`` alone (and the z stroke for 3D rays).

    March by ``step`` from the start up to ``until`` (per ray; default the reach diameter and more), then
    bisect between the last sample inside and the first outside. No sample outside up to ``until``: inf.
    Passing ``until`` = the answer under test + 2 steps only saves time: a too short answer gives a later
    exit or inf, a too long one an earlier exit.
    """
    g = ws.geometry
    z_lo, z_hi = ws.z_range
    ends = np.full(len(S), 2.5 * (g.l1 + g.l2)) if until is None else np.minimum(until, 2.5 * (g.l1 + g.l2))

    def inside(pts: np.ndarray) -> np.ndarray:
        ok = ws.contains(pts[:, :2], tol=0.0)  # the exact set: no 1e-10 band (it shifts grazing exits)
        if pts.shape[1] == 3:
            ok &= (pts[:, 2] >= z_lo) & (pts[:, 2] <= z_hi)
        return ok

    lo = np.empty(len(S))
    for i in range(len(S)):  # march: the first sample outside brackets the first exit
        u = np.arange(0.0, ends[i] + step, step)
        ok = inside(S[i] + u[:, None] * Dn[i])
        assert ok[0], "the start must be inside"
        lo[i] = u[int(np.argmin(ok)) - 1] if not ok.all() else np.inf
    found = np.isfinite(lo)
    lo = np.where(found, lo, 0.0)
    hi = lo + step
    for _ in range(60):  # bisection, all rays at once
        mid = 0.5 * (lo + hi)
        ok = inside(S + mid[:, None] * Dn)
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    return np.where(found, 0.5 * (lo + hi), np.inf)


@pytest.mark.parametrize("name", CASES)
def test_rays_match_bisection(name: str, spaces: dict[str, Workspace]) -> None:
    ws, geo = spaces[name], CASES[name]
    rng = np.random.default_rng(8)
    n = 200
    S = joint_samples(geo, n, rng)
    ang = rng.uniform(-math.pi, math.pi, n)
    Dn = np.column_stack((np.cos(ang), np.sin(ang)))
    hits = ws.ray_batch(S, Dn)
    expected = march_and_bisect(ws, S, Dn, until=hits.distance + 2e-4)
    assert np.abs(hits.distance - expected).max() < 1e-9
    assert np.abs(hits.points - (S + expected[:, None] * Dn)).max() < 1e-9
    # the hit point is on the labelled arc
    for k, p in zip(hits.arc, hits.points, strict=True):
        a = ws.arcs[k]
        assert abs(math.dist(p, a.center) - a.radius) < 1e-12
        assert ws.distance_to_boundary(p[None, :])[0] < 1e-9
    # the scalar API gives the same answers
    for i in range(0, n, 30):
        hit = ws.ray(S[i], Dn[i])
        assert hit.distance == pytest.approx(hits.distance[i], abs=1e-15)
        assert hit.limit is Limit(hits.limit[i]) and hit.arc == hits.arc[i]
        assert hit.description == ws.arcs[hit.arc].description


@pytest.mark.parametrize("name", CASES)
def test_rays_from_random_edge_points(name: str, spaces: dict[str, Workspace]) -> None:
    """A start on an arc: 0 when the ray leaves there, else the exit seen from a point 1e-7 m further on."""
    ws = spaces[name]
    rng = np.random.default_rng(10)
    n = 60
    # on arcs of at least 1 mm (the shorter ones sit in near-tangent corners thinner than EDGE_TOL)
    long_arcs = [i for i, a in enumerate(ws.arcs) if a.radius * a.sweep >= 1e-3]
    k = rng.choice(long_arcs, n)
    S = np.array([ws.arcs[i].point(ws.arcs[i].start + rng.uniform(0.01, 0.99) * ws.arcs[i].sweep) for i in k])
    ang = rng.uniform(-math.pi, math.pi, n)
    Dn = np.column_stack((np.cos(ang), np.sin(ang)))
    hits = ws.ray_batch(S, Dn)
    step = 1e-7
    leaves = ~ws.contains(S + step * Dn, tol=0.0)
    assert 0 < leaves.sum() < n
    assert (hits.distance[leaves] == 0.0).all() and (hits.arc[leaves] == k[leaves]).all()
    starts, dirs = S[~leaves] + step * Dn[~leaves], Dn[~leaves]
    expected = march_and_bisect(ws, starts, dirs, until=hits.distance[~leaves] + 2e-4) + step
    assert np.abs(hits.distance[~leaves] - expected).max() < 1e-9


@pytest.mark.parametrize("name", ["s5", "asymmetric", "hole"])
def test_rays_with_a_vertical_component(name: str, spaces: dict[str, Workspace]) -> None:
    ws, geo = spaces[name], CASES[name]
    rng = np.random.default_rng(9)
    n = 100
    z_lo, z_hi = ws.z_range
    S = np.column_stack((joint_samples(geo, n, rng), rng.uniform(z_lo, z_hi, n)))
    Dn = rng.normal(size=(n, 3))
    Dn /= np.linalg.norm(Dn, axis=1)[:, None]
    hits = ws.ray_batch(S, Dn)
    expected = march_and_bisect(ws, S, Dn, until=hits.distance + 2e-4)
    assert np.abs(hits.distance - expected).max() < 1e-9
    stroke = hits.arc == -1
    assert 0 < stroke.sum() < n  # both kinds of stop occur
    top = np.abs(hits.points[stroke, 2] - z_hi) < 1e-12
    assert np.array_equal(top, Dn[stroke, 2] > 0)
    # with s3 = -1 z grows as q3 falls: the top of the stroke is J3's lower limit
    top_limit, bottom_limit = ("joint3_upper", "joint3_lower") if geo.signs[2] > 0 else ("joint3_lower", "joint3_upper")
    assert set(hits.limit[stroke][top]) == {top_limit} and set(hits.limit[stroke][~top]) == {bottom_limit}
    up = ws.ray([float(S[0, 0]), float(S[0, 1]), z_lo], [0.0, 0.0, 1.0])
    assert up.distance == pytest.approx(z_hi - z_lo, abs=1e-15) and up.limit is Limit(top_limit)
    assert f"z = {z_hi:.6g} m" in up.description


def test_ray_from_the_edge() -> None:
    ws = workspace(CASES["s5"])
    on_outer = np.array([0.6 * math.cos(0.3), 0.6 * math.sin(0.3)])
    out = ws.ray(on_outer, [math.cos(0.3), math.sin(0.3)])
    assert out.distance == 0.0 and out.limit is Limit.OUTER
    assert out.point == pytest.approx(tuple(on_outer), abs=1e-15)
    # pointing inwards: the next edge, as seen from a point just inside
    d = np.array([-math.cos(0.3), -math.sin(0.3)])
    back = ws.ray(on_outer, d)
    assert back.distance > 0.1 and back.limit in (Limit.J2_LOWER, Limit.J2_UPPER)
    assert back.distance == pytest.approx(march_and_bisect(ws, on_outer[None, :] + 1e-6 * d, d[None, :])[0] + 1e-6,
                                          abs=1e-9)  # fmt: skip
    # the tangent corner (J1 upper limit, J2 = 0): outward or along the common tangent stops at once
    t = D(132)
    corner = [0.6 * math.cos(t), 0.6 * math.sin(t)]
    assert ws.ray(corner, [math.cos(t), math.sin(t)]).distance == 0.0
    assert ws.ray(corner, [-math.sin(t), math.cos(t)]).distance == 0.0
    # the corner (J1 upper, J2 upper): out across the J1 arc stops at once; into the region it does not
    geo = CASES["s5"]
    c = forward(geo, np.array([D(132)]), np.array([D(88)]))[0]
    elbow = 0.325 * np.array([math.cos(t), math.sin(t)])
    out_j1 = (c - elbow) / np.linalg.norm(c - elbow)
    hit = ws.ray(c, out_j1)
    assert hit.distance == 0.0 and hit.limit is Limit.J1_UPPER
    inward = forward(geo, np.array([D(120)]), np.array([D(60)]))[0] - c  # towards a reachable point nearby
    inward /= np.linalg.norm(inward)
    assert ws.contains(c + 1e-4 * inward, tol=0.0)
    hit = ws.ray(c, inward)
    assert hit.distance == pytest.approx(march_and_bisect(ws, (c + 1e-6 * inward)[None], inward[None])[0] + 1e-6,
                                         abs=1e-9)  # fmt: skip


def test_ray_errors() -> None:
    ws = workspace(CASES["s5"])
    with pytest.raises(OutsideWorkspaceError, match="inner limit") as err:
        ws.ray([0.2, 0.0], [1.0, 0.0])
    assert isinstance(err.value, InvalidInputError) and isinstance(err.value, ScaraError)
    assert err.value.point == (0.2, 0.0)
    with pytest.raises(OutsideWorkspaceError, match="beyond the reach"):
        ws.ray([0.7, 0.0], [1.0, 0.0])
    with pytest.raises(OutsideWorkspaceError, match="joint1/joint2"):
        ws.ray([-0.5, 0.0], [1.0, 0.0])  # behind the robot, between the J1 limits
    with pytest.raises(OutsideWorkspaceError, match="joint3's stroke"):
        ws.ray([0.5, 0.0, 0.3], [1.0, 0.0, 0.0])
    with pytest.raises(ParameterError, match="must not be zero"):
        ws.ray([0.5, 0.0], [0.0, 0.0])
    with pytest.raises(ParameterError, match="shapes"):
        ws.ray([0.5, 0.0], [1.0, 0.0, 0.0])
    with pytest.raises(ParameterError, match="finite"):
        ws.ray_batch(np.array([[0.5, np.nan]]), np.array([[1.0, 0.0]]))


def test_to_dict_is_json_ready() -> None:
    import json

    ws = workspace(CASES["s5"])
    data = json.loads(json.dumps(ws.to_dict()))
    assert data["area"] == ws.area and len(data["arcs"]) == len(ws.arcs)
    assert data["arcs"][0]["limit"] == ws.arcs[0].limit.value
    hit = ws.ray([0.5, 0.0], [1.0, 0.0])
    assert json.loads(json.dumps(hit.to_dict()))["distance"] == pytest.approx(0.1, abs=1e-12)


def test_plot_writes_a_png(tmp_path) -> None:  # type: ignore[no-untyped-def]
    ws = workspace(CASES["s5"])
    path = tmp_path / "ws.png"
    plot_workspace(ws, str(path), q=[0.3, 0.6, 0.0, 0.0], ray=([0.5, 0.1], [1.0, 0.4]))
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
