"""The kinematics core (issue 12): the planar-2R engine, per-joint turns, and the closed forms built on it.

Expected values come from routes written here, never from the engine under test:

- the textbook law of cosines with ``acos`` and two elbow signs, and the forward 2R sum;
- the turn of a joint nearest a reference by brute force over k in a window, and its turn range by
  stepping one turn out of the limits;
- random SCARA geometries written here as URDF text (arm lengths, zero offsets, tool offsets, limits from
  +/-2.5 rad to +/-1e6 rad, continuous joints); Pinocchio FK of that model is the truth for every solution;
- the palletizer's closed-form FK written here from its yaml parameters.

Tolerances: pose 1e-9 (m, rad); joints 1e-9 where the arm is well-conditioned. Near the stretched/folded
circles a target rounded to the last bit leaves the elbow angle undetermined by about
dr r / (l1 l2 |sin gamma|) (dr a few ulps of the reach), up to ~sqrt(2 (l1 + l2) dr / (l1 l2)) ~ 1e-7 rad at
the circle itself: no solver can return the sampled q to 1e-9 there (every q within that band reaches the
target to 1e-15 m), so the sampled-q check uses that bound, written here from the derivative of r(gamma).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import scara_pin as sp
from scara_pin.cli import main
from scara_pin.errors import InvalidInputError, NoSolutionError, ParameterError
from scara_pin.kinematics.planar2r import LIMIT_TOL, Planar2R, nearest_turn, nearest_turn_array
from scara_pin.kinematics.scara import IKStatus

TWO_PI = 2.0 * math.pi
POSE_TOL = 1e-9
Q_TOL = 1e-9
EPS = 2.0**-52
SETTINGS = settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))


def wrap(a: float) -> float:
    return (a + math.pi) % TWO_PI - math.pi


def pose_error(robot: sp.Robot, q: np.ndarray, target: np.ndarray) -> float:
    e = robot.tool_pose(q) - target
    e[3] = wrap(float(e[3]))
    return float(np.abs(e).max())


# ============================================================================== planar 2R
@SETTINGS
@given(l1=st.floats(0.05, 1.5), l2=st.floats(0.05, 1.5), t1=st.floats(-math.pi, math.pi),
       g=st.floats(-3.1, 3.1))  # fmt: skip
def test_planar2r_against_the_textbook_law_of_cosines(l1: float, l2: float, t1: float, g: float) -> None:
    arm = Planar2R(l1, l2)
    wx = l1 * math.cos(t1) + l2 * math.cos(t1 + g)  # the forward sum, written here
    wy = l1 * math.sin(t1) + l2 * math.sin(t1 + g)
    code, r, gamma, heading, lean = arm.solve(wx, wy)
    assert code == 0 and r == pytest.approx(math.hypot(wx, wy), abs=1e-15)
    c = (r * r - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    if abs(math.sin(g)) > 1e-3:  # well-conditioned: the textbook acos is accurate there
        assert gamma == pytest.approx(math.acos(max(-1.0, min(1.0, c))), abs=1e-9)
        sgn = 1.0 if g > 0 else -1.0
        theta1 = heading - sgn * lean
        assert abs(wrap(theta1 - t1)) <= 1e-9
        assert abs(wrap(sgn * gamma - g)) <= 1e-9
    # the array form is the same formulas: the same numbers, up to numpy's own atan2 (a few ulps from libm's)
    out = arm.solve_array(np.array([wx]), np.array([wy]))
    assert out[0][0] == r  # sqrt is correctly rounded in both
    for a, b in zip((out[1][0], out[2][0], out[3][0]), (gamma, heading, lean)):
        assert abs(a - b) <= 4 * EPS * max(1.0, abs(b)), (a, b)


def test_planar2r_array_equal_links_near_the_shoulder() -> None:
    """l1 = l2: the array form takes sqrt(r r) as r, except on rows that snap to the folded circle (i = 0)."""
    arm = Planar2R(0.2, 0.2)
    wx = np.array([0.0, 1e-17, 3e-16, 1e-9, 0.1, 0.3, 0.4 * (1 - EPS)])
    wy = np.array([0.0, 0.0, 2e-16, -1e-9, 0.05, -0.2, 0.0])
    for rows in (slice(None), slice(3, None)):  # with and without snapped rows in the block
        out = arm.solve_array(wx[rows], wy[rows])
        for k, (x, y) in enumerate(zip(wx[rows].tolist(), wy[rows].tolist())):
            _, r, gamma, heading, lean = arm.solve(x, y)
            assert out[0][k] == r
            for a, b in zip((out[1][k], out[2][k], out[3][k]), (gamma, heading, lean)):
                assert abs(a - b) <= 4 * EPS * max(1.0, abs(b)), (x, y, a, b)


def test_planar2r_snaps_the_stretched_and_folded_circles() -> None:
    arm = Planar2R(0.3, 0.2)
    for r in (0.5, 0.5 * (1 - 2 * EPS), 0.1, 0.1 * (1 + 2 * EPS)):
        assert arm.solve(r, 0.0)[2] in (0.0, math.pi)
    assert arm.solve(0.5 + 5e-11, 0.0)[0] == 0  # within REACH_TOL: on the circle
    assert arm.solve(0.5 + 2e-10, 0.0)[0] == 1  # beyond: OUT
    assert arm.solve(0.1 - 2e-10, 0.0)[0] == 2  # inside |l1 - l2|: IN


# ============================================================================== turns
def brute_turn(value: float, lo: float, hi: float, ref: float) -> float | None:
    """The turn of value nearest ref inside [lo, hi] (widened by LIMIT_TOL), by brute force around ref."""
    k0 = round((ref - value) / TWO_PI)
    best = None
    for k in range(k0 - 3, k0 + 4):
        v = value + TWO_PI * k
        if lo - LIMIT_TOL <= v <= hi + LIMIT_TOL and (best is None or abs(v - ref) < abs(best - ref)):
            best = v
    return best


@SETTINGS
@given(value=st.floats(-50, 50), lo=st.sampled_from([-2.5, -7.0, -1e6, 0.3]), span=st.floats(0.5, 2e6),
       ref_u=st.floats(0, 1))  # fmt: skip
def test_nearest_turn_is_the_nearest_and_its_range_is_exact(value: float, lo: float, span: float, ref_u: float) -> None:
    hi = lo + span
    ref = lo + ref_u * span  # a reference inside the limits: the nearest turn is within a few turns of it
    got = nearest_turn(value, lo, hi, ref)
    want = brute_turn(value, lo, hi, ref)
    if want is None:
        assert got is None
        return
    assert got is not None
    q, k_lo, k_hi = got
    assert abs(q - min(max(want, lo), hi)) <= 1e-9 * max(1.0, abs(q)) and lo <= q <= hi
    assert abs(math.remainder(q - value, TWO_PI)) <= 1e-9 * max(1.0, abs(q))
    # the range: one more turn either way leaves the (widened) limits
    assert q + TWO_PI * k_lo >= lo - LIMIT_TOL - 1e-9 * abs(q) and q + TWO_PI * (k_lo - 1) < lo
    assert q + TWO_PI * k_hi <= hi + LIMIT_TOL + 1e-9 * abs(q) and q + TWO_PI * (k_hi + 1) > hi
    # the array form agrees
    qa, ok = nearest_turn_array(np.array([value]), lo, hi, np.array([ref]))
    assert ok[0] and qa[0] == q


def test_turns_cost_nothing_for_placeholder_limits() -> None:
    """+/-1e6 rad limits (318,000 turns) cost as much as +/-1 rad: the turn is chosen per joint in O(1)."""
    t0 = time.perf_counter()
    for _ in range(1000):
        nearest_turn(0.3, -1e6, 1e6, 0.0)
    assert time.perf_counter() - t0 < 0.5


# ============================================================================== random SCARA geometries
def scara_urdf(l1: float, l2: float, b1: float, b2: float, tool: tuple[float, float], yaw_t: float,
               limits: list[tuple[float, float] | None]) -> str:  # fmt: skip
    """A SCARA written here: J1, J2 revolute about +z, J3 prismatic along -z, J4 revolute about +z; arms at
    zero offsets b1, b2 (their headings at q = 0); the tool offset in the wrist plane; ``None`` limits make a
    continuous joint."""

    def joint(name: str, kind: str, parent: str, child: str, xyz: tuple[float, float, float], axis: str,
              lim: tuple[float, float] | None, rpy: str = "0 0 0") -> str:  # fmt: skip
        if lim is None:
            kind, limit = "continuous", '<limit effort="10" velocity="3"/>'
        else:
            limit = f'<limit lower="{lim[0]!r}" upper="{lim[1]!r}" effort="10" velocity="3"/>'
        x, y, z = xyz
        return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                f'<origin xyz="{x!r} {y!r} {z!r}" rpy="{rpy}"/><axis xyz="{axis}"/>{limit}</joint>')  # fmt: skip

    links = "".join(f'<link name="{n}"/>' for n in ("base_link", "l1", "l2", "quill", "flange", "tool0"))
    return ('<robot name="random_scara">' + links
            + joint("joint1", "revolute", "base_link", "l1", (0.05, -0.02, 0.3), "0 0 1", limits[0])
            + joint("joint2", "revolute", "l1", "l2", (l1 * math.cos(b1), l1 * math.sin(b1), 0.0), "0 0 1", limits[1])
            + joint("joint3", "prismatic", "l2", "quill", (0.0, 0.0, 0.0), "0 0 -1", limits[2])
            + joint("joint4", "revolute", "quill", "flange", (l2 * math.cos(b2), l2 * math.sin(b2), 0.0), "0 0 1",
                    limits[3])
            + f'<joint name="tool_joint" type="fixed"><parent link="flange"/><child link="tool0"/>'
              f'<origin xyz="{tool[0]!r} {tool[1]!r} -0.05" rpy="3.141592653589793 0 {yaw_t!r}"/></joint>'
            + "</robot>")  # fmt: skip


LIMIT_SETS = {
    "narrow": [(-2.5, 2.5), (-2.6, 2.6), (0.0, 0.2), (-2.9, 2.9)],
    "wide": [(-20.0, 20.0), (-2.6, 2.6), (0.0, 0.2), (-40.0, 40.0)],
    "placeholder": [(-1e6, 1e6), (-1e6, 1e6), (0.0, 0.2), (-1e6, 1e6)],
    "continuous": [None, None, (0.0, 0.2), None],
    "elbow_one_side": [(-2.5, 2.5), (0.05, 2.9), (0.0, 0.2), None],
}


@st.composite
def random_scara(draw: st.DrawFn) -> tuple[sp.Robot, dict]:
    g = {
        "l1": draw(st.floats(0.08, 0.6)), "l2": draw(st.floats(0.08, 0.6)),
        "b1": draw(st.sampled_from([0.0, 0.3, -1.2])), "b2": draw(st.sampled_from([0.0, 0.5, 2.0])),
        "tool": draw(st.sampled_from([(0.0, 0.0), (0.04, 0.0), (0.03, -0.02)])),
        "yaw_t": draw(st.sampled_from([0.0, 0.7])),
        "limits": LIMIT_SETS[draw(st.sampled_from(sorted(LIMIT_SETS)))],
    }  # fmt: skip
    robot = sp.robot_from_urdf(scara_urdf(**g), origin="random_scara")
    return robot, g


def sample_q(rng: np.random.Generator, g: dict, kind: str) -> np.ndarray:
    """A configuration: inside the limits (continuous: a few turns), one joint on a limit, or near stretched."""
    q = np.empty(4)
    for j, lim in enumerate(g["limits"]):
        lo, hi = lim if lim is not None else (-3 * TWO_PI, 3 * TWO_PI)
        lo, hi = max(lo, -60.0), min(hi, 60.0)  # placeholder ranges: a sample anywhere is as good
        q[j] = rng.uniform(lo, hi)
    if kind == "on_limit":
        for j in (0, 1, 3):
            lim = g["limits"][j]
            if lim is not None and abs(lim[0]) < 100 and rng.random() < 0.6:
                q[j] = lim[0] if rng.random() < 0.5 else lim[1]
    elif kind == "near_stretched":  # |gamma| in [1e-12, 1e-5]: the elbow angle is gamma = q2 + b2 - b1
        lim = g["limits"][1]
        q2 = g["b1"] - g["b2"] + rng.choice([-1, 1]) * 10 ** rng.uniform(-12, -5)
        if lim is None or lim[0] <= q2 <= lim[1]:
            q[1] = q2
    return q


def singular_tol(g: dict, q: np.ndarray) -> float:
    """The band of elbow angles that one rounding of the reach leaves undetermined (module docstring)."""
    l1, l2 = g["l1"], g["l2"]
    gamma = q[1] + g["b2"] - g["b1"]
    r = math.sqrt(max(l1 * l1 + l2 * l2 + 2 * l1 * l2 * math.cos(gamma), 0.0))
    dr = 16 * EPS * (l1 + l2 + 1.0)  # a few ulps of the reach (coordinates up to ~1 m)
    slope = l1 * l2 * abs(math.sin(gamma)) / max(r, 1e-300)  # dr/dgamma
    band = min(dr / slope if slope > 0 else math.inf, 4 * math.sqrt(2 * (l1 + l2) * dr / (l1 * l2)))
    return Q_TOL + 3 * band  # the shoulder and the wrist move with the elbow


def textbook_branch(g: dict, target: np.ndarray, sign: float, ref: np.ndarray) -> np.ndarray | None:
    """The branch's solution at the turns nearest ``ref``, by acos and brute force over turns (written here)."""
    l1, l2, b1, b2 = g["l1"], g["l2"], g["b1"], g["b2"]
    alpha = target[3] - g["yaw_t"]
    tx, ty = g["tool"]
    wx = target[0] - (math.cos(alpha) * tx - math.sin(alpha) * ty) - 0.05
    wy = target[1] - (math.sin(alpha) * tx + math.cos(alpha) * ty) + 0.02
    c = (wx * wx + wy * wy - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    gamma = sign * math.acos(max(-1.0, min(1.0, c)))
    theta1 = math.atan2(wy, wx) - math.atan2(l2 * math.sin(gamma), l1 + l2 * math.cos(gamma))
    phi1, phi2 = theta1 - b1, gamma + b1 - b2
    values = [phi1, phi2, None, alpha - phi1 - phi2]
    out = np.empty(4)
    out[2] = 0.3 - 0.05 - target[2]  # z = 0.3 - q3 - 0.05 (the tool 0.05 below the flange)
    for j in (0, 1, 3):
        lim = g["limits"][j]
        lo, hi = lim if lim is not None else (-math.inf, math.inf)
        if lim is None:
            out[j] = values[j] + TWO_PI * round((ref[j] - values[j]) / TWO_PI)
        else:
            v = brute_turn(values[j], lo, hi, ref[j])
            if v is None:
                return None
            out[j] = min(max(v, lo), hi)
    return out


@SETTINGS
@given(case=random_scara(), seed=st.integers(0, 2**31), kind=st.sampled_from(["inside", "on_limit", "near_stretched"]))
def test_random_scaras_round_trip(case: tuple[sp.Robot, dict], seed: int, kind: str) -> None:
    robot, g = case
    rng = np.random.default_rng(seed)
    lo = np.array([lim[0] if lim else -math.inf for lim in g["limits"]])
    hi = np.array([lim[1] if lim else math.inf for lim in g["limits"]])
    for _ in range(12):
        q = sample_q(rng, g, kind)
        target = robot.tool_pose(q)
        ref = q + TWO_PI * rng.integers(-2, 3, 4) * np.array([1, 1, 0, 1])  # a reference a few turns away
        finite = np.isfinite(lo) & np.isfinite(hi)
        ref = np.where(finite, np.clip(ref, np.maximum(lo, -1e6), np.minimum(hi, 1e6)), ref)
        res = robot.ik(target, reference=ref)
        assert res.success, (q.tolist(), res.message)
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL, (q.tolist(), s.q.tolist())
            assert np.all(s.q >= lo) and np.all(s.q <= hi), s.q.tolist()
            for j in (0, 1, 3):  # the turn nearest the reference (no other turn of the range is nearer)
                t = s.turns[j]
                if t is not None:
                    assert t[0] <= 0 <= t[1]
                    if t[0] < 0:
                        assert abs(s.q[j] - ref[j]) <= abs(s.q[j] - TWO_PI - ref[j]) + 1e-9
                    if t[1] > 0:
                        assert abs(s.q[j] - ref[j]) <= abs(s.q[j] + TWO_PI - ref[j]) + 1e-9
                else:
                    assert abs(s.q[j] - ref[j]) <= math.pi + 1e-9  # continuous: wrapped
        # the sampled q is among the solutions (at one of a solution's turns; mod 2 pi on continuous joints)
        tol = singular_tol(g, q)
        listed = [s.q.tolist() for s in res.solutions]
        assert min(s.distance(q) for s in res.solutions) <= tol, (kind, q.tolist(), listed)
        # each branch's solution is the textbook one (well-conditioned cases)
        gamma = q[1] + g["b2"] - g["b1"]
        if abs(math.sin(gamma)) > 1e-3 and kind == "inside":
            for s in res.solutions:
                want = textbook_branch(g, target, 1.0 if s.branch == "right" else -1.0, ref)
                assert want is not None and np.abs(s.q - want).max() <= 1e-8, (s.q.tolist(), want)
        # the nearest solution and the batch agree with the solutions listed
        best = res.nearest(ref)
        assert best is not None
        assert np.array_equal(robot.ik_nearest(target, ref), best.q)
        batch = robot.ik_batch(target[None, :], ref)
        assert batch.status[0] == 0 and np.abs(batch.q[0] - best.q).max() <= 1e-12


# ============================================================================== random palletizers
@SETTINGS
@given(a2=st.floats(0.5, 1.5), a3=st.floats(0.5, 1.5), seed=st.integers(0, 2**31),
       near=st.booleans())  # fmt: skip
def test_random_palletizers_round_trip(a2: float, a3: float, seed: int, near: bool) -> None:
    robot = sp.load_robot("palletizer", {"a2": a2, "a3": a3})
    v = robot.parameters.values
    rng = np.random.default_rng(seed)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)

    def fk(q: np.ndarray) -> np.ndarray:  # S2's closed form, written here from the yaml
        r = v["a1"] + a2 * math.sin(q[1]) + a3 * math.sin(q[2]) + v["a4"]
        z = v["d1"] + v["d2"] + a2 * math.cos(q[1]) + a3 * math.cos(q[2]) + v["d5"]
        return np.array([r * math.cos(q[0]), r * math.sin(q[0]), z, q[0] + q[3] + v["tool_yaw"]])

    for _ in range(10):
        q = rng.uniform(lo, hi)
        if near:  # the relative angle theta3 - q2 in [1e-12, 1e-5]: the arm nearly stretched
            q[2] = q[1] + 10 ** rng.uniform(-12, -5)
            if not lo[2] <= q[2] <= hi[2]:
                continue
        target = robot.tool_pose(q)
        e = target - fk(q)
        e[3] = wrap(float(e[3]))
        assert np.abs(e).max() <= 1e-12  # the model is S2's arm
        res = robot.ik(target)
        assert res.success, (q.tolist(), res.message)
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL
            assert np.all(s.q >= lo) and np.all(s.q <= hi)
        rel = q[2] - q[1]
        band = Q_TOL if abs(math.sin(rel)) > 1e-3 else Q_TOL + 4 * math.sqrt(2 * (a2 + a3) * 16 * EPS * 3 / (a2 * a3))
        assert min(s.distance(q) for s in res.solutions) <= band, (q.tolist(), [s.q.tolist() for s in res.solutions])


# ============================================================================== the reproductions
def test_placeholder_limits_answer_at_once_with_turn_ranges(capsys: pytest.CaptureFixture[str]) -> None:
    """ik with J1 limits of +/-1e6 rad: one solution per branch, the turn range given, in bounded time."""
    argv = ["ik", "--set", "joint1_lower=-1e6", "--set", "joint1_upper=1e6", "0.3", "0.1", "-0.1", "0.5", "--json"]
    t0 = time.perf_counter()
    assert main(argv) == 0
    assert time.perf_counter() - t0 < 5.0
    import json

    data = json.loads(capsys.readouterr().out)
    assert len(data["solutions"]) == 2
    for s in data["solutions"]:
        k_lo, k_hi = s["turns"][0]
        q1 = s["q"][0]
        # the turns that fit [-1e6, 1e6] (written here: floor/ceil of the distance to the limits)
        assert k_lo == math.ceil((-1e6 - q1) / TWO_PI) and k_hi == math.floor((1e6 - q1) / TWO_PI)
    assert main([*argv[:-1], "--all-turns"]) == 2  # 318,000 turns per branch: more than 1e5, refused
    assert "more than 100000" in capsys.readouterr().err


def test_targets_beyond_1e6_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    robot = sp.load_robot("default")
    for bad in ([0.3, 0.1, -0.1, 1e20], [2e6, 0.0, -0.1, 0.0], [0.3, 0.1, math.nan, 0.0]):
        with pytest.raises(ParameterError):
            robot.ik(bad)
        with pytest.raises(ParameterError):
            robot.ik_nearest(bad, np.zeros(4))
        with pytest.raises(ParameterError):
            robot.ik_batch(np.array([bad]))
    assert main(["ik", "0.3", "0.1", "-0.1", "1e20"]) == 2


def test_continuous_reference_a_turn_away_keeps_the_branch() -> None:
    """A reference equal to the sampled q plus 2 pi on continuous joints: the sampled branch comes back."""
    g = {"l1": 0.3, "l2": 0.25, "b1": 0.0, "b2": 0.0, "tool": (0.0, 0.0), "yaw_t": 0.0,
         "limits": LIMIT_SETS["continuous"]}  # fmt: skip
    robot = sp.robot_from_urdf(scara_urdf(**g))
    rng = np.random.default_rng(4)
    for _ in range(200):
        q = np.array([rng.uniform(-3, 3), rng.uniform(0.2, 2.8) * rng.choice([-1, 1]), 0.1, rng.uniform(-3, 3)])
        ref = q + np.array([TWO_PI, -TWO_PI, 0.0, 2 * TWO_PI])
        got = robot.ik_nearest(robot.tool_pose(q), ref)
        assert np.abs(got - ref).max() <= 1e-9, (q.tolist(), got.tolist())  # the same branch, at ref's turns


def test_straight_line_turns_a_continuous_wrist_past_pi() -> None:
    from scara_pin.motion.paths import cartesian_path

    g = {"l1": 0.3, "l2": 0.25, "b1": 0.0, "b2": 0.0, "tool": (0.0, 0.0), "yaw_t": 0.0,
         "limits": [(-2.5, 2.5), (-2.6, 2.6), (0.0, 0.2), None]}  # fmt: skip
    robot = sp.robot_from_urdf(scara_urdf(**g))
    q0 = np.array([0.2, 1.0, 0.1, 2.5])
    p0 = robot.tool_pose(q0)
    p1 = p0 + np.array([0.02, 0.0, 0.0, 1.5])  # the wrist turns from 2.5 + ... past pi
    path = cartesian_path(robot, [p0, p1], start=q0)
    q_end = path.segments[-1].q_ref[-1]
    assert q_end[3] > math.pi and pose_error(robot, q_end, p1) <= 1e-9


def test_palletizer_stretched_arm_is_one_exact_solution() -> None:
    robot = sp.load_robot("palletizer")
    q = np.array([0.2, 1.2, 1.2, 0.1])
    res = robot.ik(robot.tool_pose(q))
    assert res.success and len(res.solutions) == 1 and res.solutions[0].singular
    assert res.solutions[0].distance(q) <= 1e-9


def test_q1_on_its_limit_with_a_nearly_stretched_elbow_is_solved() -> None:
    """q1 exactly on a limit, |q2| in 1e-9..1e-6: every target solved, the sampled q among the solutions."""
    robot = sp.load_robot("default")
    lo, hi = robot.limits.lower, robot.limits.upper
    g = {"l1": 0.2, "l2": 0.2, "b1": 0.0, "b2": 0.0}
    rng = np.random.default_rng(7)
    for i in range(400):
        q = np.array([lo[0] if i % 2 else hi[0], rng.choice([-1, 1]) * 10 ** rng.uniform(-9, -6),
                      rng.uniform(lo[2], hi[2]), rng.uniform(lo[3], hi[3])])  # fmt: skip
        target = robot.tool_pose(q)
        res = robot.ik(target, reference=q)
        assert res.success, (q.tolist(), res.status.name, res.message)
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL and lo[0] <= s.q[0] <= hi[0]
        assert min(s.distance(q) for s in res.solutions) <= singular_tol(g, q), (q.tolist(), res.solutions)


def test_fk_imports_no_inverse_kinematics() -> None:
    """`scara-pin fk` loads the model and computes FK: no IK kind, closed form, palletizer or workspace module."""
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        import sys
        from scara_pin.cli import main
        rc = main(["fk", "0.1", "0.2", "0.05", "0.3"])
        loaded = sorted(m for m in sys.modules if m.startswith(("scara_pin.kinematics.", "scara_pin.workspace")))
        print(rc, loaded)
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    rc, loaded = done.stdout.strip().splitlines()[-1].split(" ", 1)
    assert rc == "0"
    assert loaded == "['scara_pin.kinematics.kinds']", loaded


def test_fk_loads_neither_other_commands_nor_the_tree_tools() -> None:
    """Issue 31 item 8: `python -X importtime` showed cli.motion, description.packages, chain and _urdf_checks
    loaded for `fk` of a shipped robot; none is needed there (one command's module, a chain-only model, the
    package's own URDF, no mesh to resolve)."""
    import subprocess
    import sys
    import textwrap

    code = textwrap.dedent("""
        import sys
        from scara_pin.cli import main
        rc = main(["fk", "0.1", "0.2", "0.05", "0.3"])
        print(rc, sorted(m for m in sys.modules if m.startswith("scara_pin")))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    rc, loaded = done.stdout.strip().splitlines()[-1].split(" ", 1)
    assert rc == "0"
    for name in ("scara_pin.cli.motion", "scara_pin.cli.cycle", "scara_pin.cli.calibrate", "scara_pin.cli.describe",
                 "scara_pin.description.packages", "scara_pin.chain", "scara_pin._urdf_checks"):  # fmt: skip
        assert f"'{name}'" not in loaded, name
    assert "'scara_pin.cli.kinematics'" in loaded


def test_no_compiled_twin() -> None:

    root = Path(sp.__file__).parent
    assert not list(root.glob("_speedups*")) and not (root / "_fast.py").exists()
    with pytest.raises(ImportError):
        __import__("scara_pin._speedups")


def test_nearest_refuses_with_the_reason() -> None:
    robot = sp.load_robot("default")
    with pytest.raises(NoSolutionError) as info:
        robot.ik_nearest([0.9, 0.0, -0.1, 0.0], np.zeros(4))
    assert info.value.status is IKStatus.OUT_OF_REACH
    with pytest.raises(InvalidInputError):
        robot.ik_nearest([0.3, 0.1, -0.1, 0.5], np.zeros(4), branch="up")
    assert pin.__version__  # Pinocchio is the C++ layer; the package has none of its own


@pytest.mark.parametrize("branch", ["nearest", "up", "down"])
def test_palletizer_batch_is_the_scalar_route_row_by_row(branch: str) -> None:
    """The vectorised palletizer batch gives, row for row, the scalar solutions' nearest (or their status)."""
    robot = sp.load_robot("palletizer")
    kin = robot.kinematics
    rng = np.random.default_rng(21)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = rng.uniform(lo - 0.3, hi + 0.3, (600, 4))  # some outside the limits: targets without a solution too
    T = np.array([robot.tool_pose(q) for q in Q])
    T[::50, :3] *= 3.0  # out of reach
    for ref in (None, rng.uniform(lo, hi)):
        res = kin.batch(T, ref, branch=branch)
        r = np.zeros(4) if ref is None else ref
        for i, t in enumerate(T):
            one = kin.solve(t, branch="all" if branch == "nearest" else branch, reference=r)
            best = one.nearest(r) if one.success else None
            assert int(res.status[i]) == int(one.status), (i, one.message)
            if best is None:
                assert np.isnan(res.q[i]).all() and res.branch[i] == 0
            else:
                assert np.abs(res.q[i] - best.q).max() <= 1e-12, (i, res.q[i], best.q)
                assert res.branch[i] == (1 if best.branch == "up" else -1)
