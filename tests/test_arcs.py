"""The one arc engine on both kinds of joint box, against independent routes written here.

The SCARA's plan-view region (box on theta1 and the RELATIVE elbow angle gamma) and the palletizer's
arm-plane envelope (box on the ABSOLUTE angles q2, theta3) are both images of a joint box under a planar
two-link arm, built by :mod:`scara_pin.workspace.arcs`. Checked here through the public APIs
(:func:`scara_pin.workspace.scara.workspace`, :func:`scara_pin.workspace.palletizer.arm_plane_envelope`):

- area: against the integral over the slices of the plane at a fixed elbow angle: with g the elbow angle,
  the wrist radius rho has rho^2 = l1^2 + l2^2 + 2 l1 l2 cos g, so the area is the integral over g in
  [0, pi] of l1 l2 sin g times the angular measure of the region on that circle about the shoulder; the
  measure is computed here in closed form (each elbow sign gives the shoulder angles the box allows,
  shifted by the angle from link 1 to the wrist; the length of their union on the circle), and the
  integral by adaptive quadrature (scipy.integrate.quad) between the integrand's jumps and kinks, to 1e-9 m^2
  (found: ~1e-15 m^2);
- boundary: at points of every arc, 1e-6 m to the region's side is reached and 1e-6 m to the other side
  is not, by a membership written here (textbook acos, both elbows, the limits modulo 2 pi);
- FK samples of the joint box (its edges and its stretched/folded lines included) from the forward map
  written here (for the shipped palletizer checked against its URDF through Pinocchio first) lie inside the
  arcs (even-odd crossings written here) or within 1e-9 m of an arc, and every arc point has a sample
  within 2 mm: the arcs bound the image, no more and no less;
- loops close: each arc's end, traversed with the region on its left, is another arc's start to 1e-12 m.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pytest
from scipy.integrate import IntegrationWarning, quad
from scipy.optimize import brentq
from scipy.spatial import cKDTree

from scara_pin import load_robot
from scara_pin.kinematics.palletizer import PalletizerGeometry
from scara_pin.kinematics.scara import ScaraGeometry
from scara_pin.workspace.palletizer import arm_plane_envelope
from scara_pin.workspace.scara import workspace

TWO_PI = 2 * math.pi
D = math.radians


@dataclass(frozen=True)
class Case:
    """A joint box in the test's own terms, and the region the package built for it.

    Attributes:
        l1, l2: link lengths [m]; origin: the shoulder (x, y) [m].
        first: theta1's range [rad] (None: a full turn); second: gamma's (relative) or theta2's range.
        relative: whether the second joint is the elbow angle gamma.
        arcs: the package's boundary arcs as rows (cx, cy, R, start, sweep, region_inside) with points
            c + R (cos a, sin a), in the test's (x, y) frame.
        area: the package's area [m^2].
        samples: (N, 2) points of the image from forward kinematics (box edges included).
    """

    l1: float
    l2: float
    origin: tuple[float, float]
    first: tuple[float, float] | None
    second: tuple[float, float] | None
    relative: bool
    arcs: np.ndarray
    area: float
    samples: np.ndarray


def box_grid(
    lo1: float, hi1: float, lo2: float, hi2: float, n: int, rng: np.random.Generator
) -> tuple[np.ndarray, ...]:
    """n uniform joint pairs in the box plus n points on each of its four edges."""
    a, b = rng.uniform(lo1, hi1, n), rng.uniform(lo2, hi2, n)
    e1, e2 = rng.uniform(lo1, hi1, n), rng.uniform(lo2, hi2, n)
    q1 = np.concatenate((a, e1, e1, np.full(n, lo1), np.full(n, hi1)))
    q2 = np.concatenate((b, np.full(n, lo2), np.full(n, hi2), e2, e2))
    return q1, q2


def scara_case(l1: float, l2: float, j1: tuple[float, float], j2: tuple[float, float], *,
               signs: tuple[float, float] = (1.0, 1.0), a1: tuple[float, float] = (0.0, 0.0), beta1: float = 0.0,
               bend: float = 0.0) -> Case:  # fmt: skip
    """A SCARA with J1/J2 limits in degrees; theta = s1 q1 + beta1, gamma = s2 q2 + bend."""
    u1 = (l1 * math.cos(beta1), l1 * math.sin(beta1))
    u2 = (l2 * math.cos(beta1 + bend), l2 * math.sin(beta1 + bend))
    lo, hi = (D(j1[0]), D(j2[0])), (D(j1[1]), D(j2[1]))
    geo = ScaraGeometry(
        revolute=(0, 1, 3), prismatic=2, names=("joint1", "joint2", "joint3", "joint4"),
        signs=(signs[0], signs[1], -1.0, 1.0), a1=a1, u1=u1, u2=u2, tool=(0.0, 0.0), z0=0.1, yaw0=0.0,
        R0=np.eye(3), lower=(lo[0], lo[1], 0.0, -7.0), upper=(hi[0], hi[1], 0.2, 7.0),
    )  # fmt: skip
    ws = workspace(geo)
    arcs = np.array([(*a.center, a.radius, a.start, a.sweep, a.region_inside) for a in ws.arcs])
    t = sorted((signs[0] * lo[0] + beta1, signs[0] * hi[0] + beta1))
    g = sorted((signs[1] * lo[1] + bend, signs[1] * hi[1] + bend))
    # the forward map, written here: rotations of the links' zero-pose vectors
    q1, q2 = box_grid(lo[0], hi[0], lo[1], hi[1], 40_000, np.random.default_rng(1))
    p1, p2 = signs[0] * q1, signs[0] * q1 + signs[1] * q2
    x = a1[0] + u1[0] * np.cos(p1) - u1[1] * np.sin(p1) + u2[0] * np.cos(p2) - u2[1] * np.sin(p2)
    y = a1[1] + u1[0] * np.sin(p1) + u1[1] * np.cos(p1) + u2[0] * np.sin(p2) + u2[1] * np.cos(p2)
    first = None if t[1] - t[0] >= TWO_PI else (t[0], t[1])
    second = None if g[1] - g[0] >= TWO_PI else (g[0], g[1])
    samples = np.vstack((np.column_stack((x, y)), critical_samples(l1, l2, a1, t, second, True)))
    return Case(l1, l2, a1, first, second, True, arcs, ws.area, samples)


def critical_samples(l1: float, l2: float, origin: tuple[float, float], t: tuple[float, float] | list[float],
                     second: tuple[float, float] | None, relative: bool) -> np.ndarray:  # fmt: skip
    """Image points of the box's singular lines (stretched gamma = 0, folded gamma = pi), theta1 over t."""
    theta1 = np.random.default_rng(3).uniform(t[0], t[1], 40_000)
    out = []
    for gamma in (0.0, math.pi):
        ok = in_range(np.full(len(theta1), gamma) if relative else theta1 + gamma, second)
        th = theta1[ok]
        out.append(np.column_stack((origin[0] + l1 * np.cos(th) + l2 * np.cos(th + gamma),
                                    origin[1] + l1 * np.sin(th) + l2 * np.sin(th + gamma))))  # fmt: skip
    return np.vstack(out)


def palletizer_case(geo: PalletizerGeometry, pinocchio: bool = False) -> Case:
    """A palletizer; the test's frame is (x, y) = (z - h0, r - r0), where q2 and theta3 are angles from x."""
    env = arm_plane_envelope(geo)
    # an (r, z) arc c + R (sin phi, cos phi) is (c_z - h0, c_r - r0) + R (cos phi, sin phi) in (x, y)
    arcs = np.array([(a.center[1] - geo.h0, a.center[0] - geo.r0, a.radius, a.start, a.sweep, a.inside_toward_center)
                     for a in env.arcs])  # fmt: skip
    ranges = []
    for j in (1, 2):
        lo, hi = geo.lower[j], geo.upper[j]
        ranges.append(None if geo.continuous[j] or not hi - lo < TWO_PI else (lo, hi))
    box = [r if r is not None else (-math.pi, math.pi) for r in ranges]
    q2, t3 = box_grid(box[0][0], box[0][1], box[1][0], box[1][1], 40_000, np.random.default_rng(2))

    def arm_plane(q2: np.ndarray, t3: np.ndarray) -> np.ndarray:
        """(r, z): r = r0 + a2 sin q2 + a3 sin theta3, z = h0 + a2 cos q2 + a3 cos theta3."""
        return np.column_stack((geo.r0 + geo.a2 * np.sin(q2) + geo.a3 * np.sin(t3),
                                geo.h0 + geo.a2 * np.cos(q2) + geo.a3 * np.cos(t3)))  # fmt: skip

    if pinocchio:  # the shipped robot: the formula is its URDF's, through Pinocchio, in the arm plane of q1
        robot = load_robot("palletizer")
        rng = np.random.default_rng(4)
        for q in rng.uniform(robot.limits.lower, robot.limits.upper, (300, 4)):
            x, y, z, _ = robot.tool_pose(q)
            r = x * math.cos(q[0]) + y * math.sin(q[0])
            assert np.abs(arm_plane(q[1:2], q[2:3])[0] - (r, z)).max() < 1e-12
    rz = arm_plane(q2, t3)
    samples = np.vstack((np.column_stack((rz[:, 1] - geo.h0, rz[:, 0] - geo.r0)),
                         critical_samples(geo.a2, geo.a3, (0.0, 0.0), box[0], ranges[1], False)))  # fmt: skip
    return Case(geo.a2, geo.a3, (0.0, 0.0), ranges[0], ranges[1], False, arcs, env.area, samples)


def pal(a2: float, a3: float, q2: tuple[float, float], t3: tuple[float, float],
        continuous: tuple[bool, bool] = (False, False)) -> PalletizerGeometry:  # fmt: skip
    inf = math.inf
    lo = (-2.8, -inf if continuous[0] else D(q2[0]), -inf if continuous[1] else D(t3[0]), -5.0)
    hi = (2.8, inf if continuous[0] else D(q2[1]), inf if continuous[1] else D(t3[1]), 5.0)
    return PalletizerGeometry(r0=0.46, h0=0.55, a2=a2, a3=a3, tool_yaw=0.0, lower=lo, upper=hi,  # type: ignore[arg-type]
                              continuous=(False, *continuous, False))  # fmt: skip


BUILDERS = {
    # relative boxes (SCARA)
    "scara_s5": lambda: scara_case(0.325, 0.275, (-132, 132), (-88, 88)),
    "scara_j2_without_zero": lambda: scara_case(0.3, 0.25, (-100, 60), (30, 140)),
    "scara_j2_beyond_pi": lambda: scara_case(0.3, 0.25, (-120, 120), (-200, 200)),
    "scara_hole_equal_arms": lambda: scara_case(0.2, 0.2, (-132, 132), (-150, 150)),
    "scara_c_ring": lambda: scara_case(0.3, 0.2, (-175, 175), (20, 60)),
    "scara_tangent_corners": lambda: scara_case(0.34, 0.078, (-150, 120), (-200, 200)),
    "scara_j1_full_turn": lambda: scara_case(0.325, 0.275, (-200, 200), (-150, 150)),
    "scara_asymmetric": lambda: scara_case(0.2, 0.3, (-30, 170), (-40, 150), signs=(-1.0, 1.0), a1=(0.05, -0.02),
                                           beta1=math.pi / 2, bend=0.3),  # fmt: skip
    # absolute boxes (palletizer)
    "pal_shipped_pinocchio": lambda: palletizer_case(load_robot("palletizer").kinematics.geometry, pinocchio=True),
    "pal_folded_reached": lambda: palletizer_case(pal(0.95, 0.6, (-140, 140), (-60, 250))),
    "pal_short_big_arm": lambda: palletizer_case(pal(0.5, 1.1, (-60, 120), (-170, 100))),
    "pal_equal_arms": lambda: palletizer_case(pal(0.8, 0.8, (-100, 100), (60, 300))),
    "pal_never_stretched": lambda: palletizer_case(pal(0.9, 0.7, (-20, 40), (70, 160))),
    "pal_q2_continuous": lambda: palletizer_case(pal(0.9, 0.7, (0, 0), (10, 150), continuous=(True, False))),
    "pal_theta3_continuous": lambda: palletizer_case(pal(0.9, 0.7, (-40, 85), (0, 0), continuous=(False, True))),
    "pal_wide_both": lambda: palletizer_case(pal(1.0, 0.75, (-170, 170), (-175, 178))),
}


@pytest.fixture(scope="module")
def cases() -> dict[str, Case]:
    return {name: build() for name, build in BUILDERS.items()}


# ------------------------------------------------------------------------------------------ the test's own routes
def in_range(v: np.ndarray, rng: tuple[float, float] | None) -> np.ndarray:
    """Whether some v + 2 pi k lies in [lo, hi] (None: a full turn)."""
    if rng is None:
        return np.ones(np.shape(v), dtype=bool)
    return np.mod(v - rng[0], TWO_PI) <= rng[1] - rng[0]


def member(case: Case, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Reached inside the box: textbook acos law of cosines, both elbows, limits modulo 2 pi."""
    l1, l2 = case.l1, case.l2
    dx, dy = x - case.origin[0], y - case.origin[1]
    c = (dx * dx + dy * dy - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    g = np.arccos(np.clip(c, -1.0, 1.0))
    out = np.zeros(np.shape(x), dtype=bool)
    for gamma in (g, -g):
        t1 = np.arctan2(dy, dx) - np.arctan2(l2 * np.sin(gamma), l1 + l2 * np.cos(gamma))
        out |= in_range(t1, case.first) & in_range(gamma if case.relative else t1 + gamma, case.second)
    return out & (np.abs(c) <= 1.0)


def circle_measure(intervals: list[tuple[float, float]]) -> float:
    """The length of a union of arcs [a, b] of the circle (angles, b >= a)."""
    segs = []
    for a, b in intervals:
        if b - a >= TWO_PI:
            return TWO_PI
        a0 = a % TWO_PI
        b0 = a0 + (b - a)
        segs += [(a0, b0)] if b0 <= TWO_PI else [(a0, TWO_PI), (0.0, b0 - TWO_PI)]
    total, end = 0.0, -1.0
    for a, b in sorted(segs):
        if b > end:
            total += b - max(a, end)
            end = b
    return total


def slice_measure(case: Case, g: float) -> float:
    """The angular measure of the region on the circle about the shoulder where the elbow angle is +/-g."""
    l1, l2 = case.l1, case.l2
    full = (-math.pi, math.pi)
    intervals = []
    for gamma in (g, -g):
        lean = math.atan2(l2 * math.sin(gamma), l1 + l2 * math.cos(gamma))
        f = case.first or full
        if case.relative:  # theta1 anywhere in its range when gamma fits
            spans = [f] if in_range(np.array(gamma), case.second) else []
        elif case.second is None:
            spans = [f]
        elif case.first is None:  # theta1 takes any turn: theta2's range shifted
            spans = [(case.second[0] - gamma, case.second[1] - gamma)]
        else:  # theta1 in its range with theta1 + gamma in theta2's, for any turn of theta2
            lo, hi = case.second[0] - gamma, case.second[1] - gamma
            spans = [(max(f[0], lo + k * TWO_PI), min(f[1], hi + k * TWO_PI)) for k in range(-4, 5)]
            spans = [(a, b) for a, b in spans if a < b]
        intervals += [(a + lean, b + lean) for a, b in spans]
    return circle_measure(intervals)


def slice_ends(case: Case, sign: float, g: np.ndarray | float) -> list[np.ndarray]:
    """The angles that can end the slice's arcs for the elbow angle sign * g: ends of the spans plus the lean."""
    l1, l2 = case.l1, case.l2
    f = case.first or (-math.pi, math.pi)
    gamma = sign * np.asarray(g, dtype=float)
    lean = np.arctan2(l2 * np.sin(gamma), l1 + l2 * np.cos(gamma))
    ends = [f[0] + 0.0 * gamma, f[1] + 0.0 * gamma]
    if not case.relative and case.second is not None:
        ends += [case.second[0] - gamma, case.second[1] - gamma]
    return [e + lean for e in ends]


def kinks(case: Case) -> list[float]:
    """Elbow angles in (0, pi) where the slice measure may jump or bend.

    Jumps: an elbow limit of the relative box starts or stops a whole slice. Kinks: an end of theta1's range
    meets an end of theta2's shifted by gamma (absolute box), and an end of one elbow's arc meets an end of
    the other's (roots of sin(difference / 2), bracketed on a grid and solved by brentq).
    """
    out: set[float] = set()
    if case.relative and case.second is not None:
        out |= {abs(math.remainder(v, TWO_PI)) for v in case.second}
    elif case.first is not None and case.second is not None:
        out |= {abs(math.remainder(b - a, TWO_PI)) for a in case.first for b in case.second}
    grid = np.linspace(0.0, math.pi, 4001)
    n_ends = len(slice_ends(case, 1.0, 0.0))
    for i in range(n_ends):
        for j in range(n_ends):

            def h(x: float, i: int = i, j: int = j) -> float:
                return float(np.sin(0.5 * (slice_ends(case, 1.0, x)[i] - slice_ends(case, -1.0, x)[j])))

            values = np.sin(0.5 * (slice_ends(case, 1.0, grid)[i] - slice_ends(case, -1.0, grid)[j]))
            for k in np.flatnonzero(np.sign(values[:-1]) * np.sign(values[1:]) < 0):
                out.add(brentq(h, grid[k], grid[k + 1], xtol=1e-15))
    return sorted(v for v in out if 0.0 < v < math.pi)


def polar_area(case: Case) -> tuple[float, float]:
    """(area, quadrature error estimate) in polar coordinates about the shoulder, by the elbow angle.

    With rho^2 = l1^2 + l2^2 + 2 l1 l2 cos g, rho d rho = -l1 l2 sin g dg: the area is the integral over
    g in [0, pi] of l1 l2 sin g times the slice's measure (no acos, no endpoint singularity), piecewise
    between the kinks of the integrand.
    """
    l1, l2 = case.l1, case.l2
    edges = [0.0, *kinks(case), math.pi]
    area = err = 0.0
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        with warnings.catch_warnings():  # asking for 1e-14 on a smooth piece may hit roundoff: err says so
            warnings.simplefilter("ignore", IntegrationWarning)
            part, e = quad(lambda g: l1 * l2 * math.sin(g) * slice_measure(case, g), a, b, limit=200, epsabs=1e-14)
        area, err = area + part, err + e
    return area, err


def arc_points(arcs: np.ndarray, fractions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points along each arc at the fractions of its sweep, their outward unit normals, and the region side."""
    pts, normals, sides = [], [], []
    for cx, cy, R, start, sweep, inside in arcs:
        a = start + sweep * fractions
        n = np.column_stack((np.cos(a), np.sin(a)))
        pts.append(np.array([cx, cy]) + R * n)
        normals.append(n)
        sides.append(np.full(len(a), -1.0 if inside else 1.0))  # the region's side along the normal
    return np.vstack(pts), np.vstack(normals), np.concatenate(sides)


def distance_to_arcs(arcs: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Distance from points to the nearest arc: to the circle within the arc's angles, else to its ends."""
    best = np.full(len(P), np.inf)
    for cx, cy, R, start, sweep, _ in arcs:
        dx, dy = P[:, 0] - cx, P[:, 1] - cy
        within = np.mod(np.arctan2(dy, dx) - start, TWO_PI) <= sweep
        ends = [(cx + R * math.cos(a), cy + R * math.sin(a)) for a in (start, start + sweep)]
        to_ends = np.minimum(*(np.hypot(P[:, 0] - ex, P[:, 1] - ey) for ex, ey in ends))
        best = np.minimum(best, np.where(within, np.abs(np.hypot(dx, dy) - R), to_ends))
    return best


def inside_arcs(arcs: np.ndarray, P: np.ndarray, turn: float = 0.3719) -> np.ndarray:
    """Even-odd count of the arcs crossed by the ray from each point along e(turn).

    The ray leaves at an angle no corner of these regions sits at from a sample (a ray through an arc end
    would count the corner twice or not at all): the frame is turned by -turn and the ray goes towards +x.
    """
    c, s = math.cos(turn), math.sin(turn)
    px, py = c * P[:, 0] + s * P[:, 1], -s * P[:, 0] + c * P[:, 1]
    count = np.zeros(len(P), dtype=np.int64)
    for cx0, cy0, R, start, sweep, _ in arcs:
        cx, cy = c * cx0 + s * cy0, -s * cx0 + c * cy0
        h2 = R * R - (py - cy) ** 2
        h = np.sqrt(np.maximum(h2, 0.0))
        for sx in (1.0, -1.0):
            xi = cx + sx * h
            on = np.mod(np.arctan2(py - cy, xi - cx) - (start - turn), TWO_PI) <= sweep
            count += ((h2 > 0) & (xi > px) & on).astype(np.int64)
    return count % 2 == 1


# ------------------------------------------------------------------------------------------ tests
def test_both_kinds_are_covered(cases: dict[str, Case]) -> None:
    assert {c.relative for c in cases.values()} == {True, False}
    assert any(c.first is None for c in cases.values() if not c.relative)  # a continuous palletizer joint
    assert any(c.second is None for c in cases.values() if not c.relative)


@pytest.mark.parametrize("name", BUILDERS)
def test_area_against_polar_slices(name: str, cases: dict[str, Case]) -> None:
    case = cases[name]
    area, err = polar_area(case)
    assert err < 1e-6  # the quadrature's own (conservative) estimate; the agreement found is ~1e-15
    assert abs(case.area - area) < 1e-9, (case.area, area)


@pytest.mark.parametrize("name", BUILDERS)
def test_arcs_are_the_edge_of_the_reached_set(name: str, cases: dict[str, Case]) -> None:
    case = cases[name]
    long_arcs = case.arcs[case.arcs[:, 2] * case.arcs[:, 4] >= 1e-3]  # shorter ones sit in thin corners
    P, n, side = arc_points(long_arcs, np.linspace(0.1, 0.9, 9))
    step = 1e-6
    into, away = P + (step * side)[:, None] * n, P - (step * side)[:, None] * n
    assert member(case, into[:, 0], into[:, 1]).all()
    assert not member(case, away[:, 0], away[:, 1]).any()


@pytest.mark.parametrize("name", BUILDERS)
def test_arcs_bound_the_forward_image(name: str, cases: dict[str, Case]) -> None:
    case = cases[name]
    S = case.samples
    assert (inside_arcs(case.arcs, S) | (distance_to_arcs(case.arcs, S) <= 1e-9)).all()
    P, _, _ = arc_points(case.arcs, np.linspace(0.0, 1.0, 400))
    gap, _ = cKDTree(S).query(P)
    assert gap.max() < 2e-3


@pytest.mark.parametrize("name", BUILDERS)
def test_loops_close(name: str, cases: dict[str, Case]) -> None:
    """Each arc's end (traversed with the region on its left) is another arc's start, to 1e-12 m."""
    ends = []
    for cx, cy, R, start, sweep, inside in cases[name].arcs:
        a, b = (start, start + sweep) if inside else (start + sweep, start)
        ends.append(((cx + R * math.cos(a), cy + R * math.sin(a)), (cx + R * math.cos(b), cy + R * math.sin(b))))
    heads = np.array([e[0] for e in ends])
    for _, tail in ends:
        assert np.hypot(*(heads - tail).T).min() < 1e-12
