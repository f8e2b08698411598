"""Closed-form inverse kinematics (scara_pin.kinematics.scara), checked against independent routes.

Expected values never come from the code under test:

- Pinocchio forward kinematics (``robot.tool_pose``) of every returned solution must give the target;
- the configuration a target was made from (FK of a seeded random q) must be among the solutions;
- for robots generated from the yaml/xacro description, the whole solution set is enumerated in this file
  by the textbook law of cosines (acos, two elbow signs) and every 2 pi-equivalent inside the limits;
- hand-written URDFs modelled on real robots (real-scara-models.md) carry their own forward kinematics
  written here as plan-view closed forms;
- branch labels come from the sign of the cross product (elbow - shoulder) x (wrist - elbow) of Pinocchio
  frame placements, counterclockwise seen from above being ``right``;
- reason messages are checked for the numbers behind them (r, r_min, the joint value, the tilt).

Tolerances: pose 1e-9 m / 1e-9 rad (POSE_TOL); joint values 1e-9 rad / m (Q_TOL), except within
|sin(elbow angle)| < 1e-6 of the stretched/folded singularity where the IK is ill-conditioned (a target
1 ulp inside the outer circle moves the elbow by ~sqrt(2 ulp / l): up to ~1e-7 rad, Q_TOL_SINGULAR);
fixture FK checks 1e-12. Randomness is seeded (numpy default_rng) and hypothesis is derandomized.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import scara_pin
from scara_pin import Robot, UrdfError, load_robot, robot_from_urdf
from scara_pin.kinematics.scara import IKStatus, NotScaraError, ScaraGeometry, branch_of, solve
from scara_pin.kinematics.scara_batch import solve_batch

POSE_TOL = 1e-9
Q_TOL = 1e-9
Q_TOL_SINGULAR = 1e-6
TOL_FK = 1e-12
TWO_PI = 2.0 * math.pi
DATA = Path(__file__).parent / "data"
D = math.radians


# ============================================================================== independent helpers
def solve_all(geo: ScaraGeometry, target: Any, **kwargs: Any) -> Any:
    """Every solution, each turn of each joint inside the limits listed on its own (``all_turns=True``).

    The tests below compare the whole solution set with an enumeration written here; the one-solution-per-
    branch answer (turns nearest a reference, with turn ranges) is tested in tests/test_turns.py.
    """
    return solve(geo, target, all_turns=True, **kwargs)


def wrap(a: float) -> float:
    return (a + math.pi) % TWO_PI - math.pi


def pose_error(robot: Robot, q: np.ndarray, target: np.ndarray) -> float:
    """max(|dp|, |d yaw|) between Pinocchio FK of q and the target."""
    pose = robot.tool_pose(q)
    e = pose - np.asarray(target, dtype=float)
    e[3] = wrap(e[3])
    return float(np.abs(e).max())


def turns(value: float, lo: float, hi: float, tol: float = 1e-9) -> list[float]:
    """Every value + 2 pi k inside [lo, hi] (within tol), by brute force over k."""
    return [value + k * TWO_PI for k in range(-6, 7) if lo - tol <= value + k * TWO_PI <= hi + tol]


def n_turns(value: float, lo: float, hi: float) -> int:
    """How many value + 2 pi k lie in [lo, hi], by the floor/ceil formula."""
    return max(0, math.floor((hi - value) / TWO_PI) - math.ceil((lo - value) / TWO_PI) + 1)


def numbers(text: str) -> list[float]:
    return [float(s) for s in re.findall(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?", text)]


def mentions(text: str, value: float, tol: float) -> bool:
    return any(abs(n - value) <= tol for n in numbers(text))


def match_count(solutions: list[np.ndarray], expected: list[np.ndarray], tol: float) -> bool:
    """Whether the two lists are the same configurations (a bijection within tol)."""
    if len(solutions) != len(expected):
        return False
    left = list(expected)
    for q in solutions:
        hits = [i for i, e in enumerate(left) if np.abs(q - e).max() <= tol]
        if len(hits) != 1:
            return False
        left.pop(hits[0])
    return not left


def closest(solutions: list[np.ndarray], q: np.ndarray) -> float:
    return min((float(np.abs(s - q).max()) for s in solutions), default=math.inf)


def limits(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    model = robot.model
    return np.asarray(model.lowerPositionLimit, dtype=float), np.asarray(model.upperPositionLimit, dtype=float)


# ---------------------------------------------------------- the xacro robot's kinematics, written here
# The description (urdf/scara_macro.xacro): joint1, joint2, joint4 about +z, the quill q3 moves DOWN;
# tool0 at (tool_x, tool_y, tool_z) in the flange frame, yaw = q1 + q2 + q4 + tool_yaw.
def xacro_fk(p: dict[str, float], q: np.ndarray) -> np.ndarray:
    q1, q2, q3, q4 = q
    psi = q1 + q2 + q4
    tx, ty = p["tool_x"], p["tool_y"]
    x = p["l1"] * math.cos(q1) + p["l2"] * math.cos(q1 + q2) + math.cos(psi) * tx - math.sin(psi) * ty
    y = p["l1"] * math.sin(q1) + p["l2"] * math.sin(q1 + q2) + math.sin(psi) * tx + math.cos(psi) * ty
    z = p["d1"] + p["d2"] + p["d3"] + p["tool_z"] - q3
    return np.array([x, y, z, wrap(psi + p["tool_yaw"])])


def xacro_ik(p: dict[str, float], lo: np.ndarray, hi: np.ndarray, target: np.ndarray) -> list[tuple[np.ndarray, str]]:
    """Every solution by the law of cosines (acos): (q, branch) with branch from sign(sin q2)."""
    x, y, z, yaw = target
    psi = yaw - p["tool_yaw"]
    wx = x - (math.cos(psi) * p["tool_x"] - math.sin(psi) * p["tool_y"])
    wy = y - (math.sin(psi) * p["tool_x"] + math.cos(psi) * p["tool_y"])
    l1, l2 = p["l1"], p["l2"]
    c2 = (wx * wx + wy * wy - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    q3 = p["d1"] + p["d2"] + p["d3"] + p["tool_z"] - z
    if abs(c2) > 1 or not lo[2] - 1e-9 <= q3 <= hi[2] + 1e-9:
        return []
    out = []
    for sign in (1.0, -1.0):
        q2 = sign * math.acos(c2)
        q1 = math.atan2(wy, wx) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
        for a in turns(q1, lo[0], hi[0]):
            for b in turns(q2, lo[1], hi[1]):
                for c in turns(psi - a - b, lo[3], hi[3]):
                    out.append((np.array([a, b, q3, c]), "right" if math.sin(b) > 0 else "left"))
    return out


def cross_label(robot: Robot, q: np.ndarray, shoulder: str, elbow: str, wrist: str) -> float:
    """z of (elbow - shoulder) x (wrist - elbow) from Pinocchio frame placements (> 0: counterclockwise)."""
    s = robot.frame_placement(q, shoulder).translation
    e = robot.frame_placement(q, elbow).translation
    w = robot.frame_placement(q, wrist).translation
    a, b = e - s, w - e
    return float(a[0] * b[1] - a[1] * b[0])


def elbow_sin(robot: Robot, q: np.ndarray, shoulder: str, elbow: str, wrist: str) -> float:
    s = robot.frame_placement(q, shoulder).translation
    e = robot.frame_placement(q, elbow).translation
    w = robot.frame_placement(q, wrist).translation
    a, b = (e - s)[:2], (w - e)[:2]
    return float((a[0] * b[1] - a[1] * b[0]) / (np.linalg.norm(a) * np.linalg.norm(b)))


@pytest.fixture(scope="module")
def default() -> Robot:
    return load_robot("default")


# ============================================================================== random robots (hypothesis)
@st.composite
def robot_overrides(draw: st.DrawFn) -> dict[str, float]:
    """Random geometry (tool offset away from the J4 axis) and random joint limits."""

    def f(lo: float, hi: float) -> float:
        return draw(st.floats(lo, hi, allow_nan=False, allow_infinity=False))

    tool_r, tool_a = f(0.01, 0.1), f(-math.pi, math.pi)
    mode = draw(st.sampled_from(["symmetric", "asymmetric", "positive", "negative", "beyond_pi", "around_pi"]))
    if mode == "symmetric":
        a = f(30, 170)
        j2 = (-a, a)
    elif mode == "asymmetric":
        j2 = (-f(10, 170), f(10, 170))
    elif mode == "positive":  # 0 excluded: no stretched arm
        a = f(5, 150)
        j2 = (a, a + f(10, 175 - a))
    elif mode == "negative":
        a = f(5, 150)
        j2 = (-a - f(10, 175 - a), -a)
    elif mode == "beyond_pi":
        j2 = (-f(100, 300), f(181, 300))
    else:  # a range around the folded arm that excludes 0
        j2 = (f(100, 170), f(190, 300))
    j3_lo = f(-0.2, 0.0)
    return {
        "l1": f(0.05, 0.6),
        "l2": f(0.05, 0.6),
        "d1": f(-0.1, 0.3),
        "d2": f(-0.1, 0.1),
        "d3": f(-0.2, 0.1),
        "tool_x": tool_r * math.cos(tool_a),
        "tool_y": tool_r * math.sin(tool_a),
        "tool_z": f(-0.1, 0.1),
        "tool_yaw": f(-math.pi, math.pi),
        "joint1_lower": D(-f(30, 180)),
        "joint1_upper": D(f(30, 180)),
        "joint2_lower": D(j2[0]),
        "joint2_upper": D(j2[1]),
        "joint3_lower": j3_lo,
        "joint3_upper": j3_lo + f(0.01, 0.3),
        "joint4_lower": D(-f(10, 400)),
        "joint4_upper": D(f(10, 400)),
    }


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(overrides=robot_overrides(), seed=st.integers(0, 2**32 - 1))
def test_fk_of_ik_on_random_robots(overrides: dict[str, float], seed: int) -> None:
    robot = load_robot("default", overrides)
    geo = robot.kinematics.geometry
    p = dict(robot.parameters.values)
    lo, hi = limits(robot)
    rng = np.random.default_rng(seed)
    for q in rng.uniform(lo, hi, size=(60, 4)):
        target = robot.tool_pose(q)
        # the closed form written above is the robot (fixture check of the independent route)
        e = xacro_fk(p, q) - target
        e[3] = wrap(e[3])
        assert np.abs(e).max() <= TOL_FK
        res = solve_all(geo, target)
        assert res.status is IKStatus.OK, (q, res.message)
        sols = [s.q for s in res.solutions]
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL
            assert np.all(s.q >= lo) and np.all(s.q <= hi), s.q
            if not s.singular:
                assert s.branch == ("right" if math.sin(s.q[1]) > 0 else "left")
        sin_g = abs(math.sin(q[1]))
        tol = Q_TOL if sin_g >= 1e-6 else Q_TOL_SINGULAR
        assert closest(sols, q) <= tol, (q, sols)
        if sin_g >= 1e-6:  # the whole set, from the acos enumeration
            expected = xacro_ik(p, lo, hi, target)
            assert match_count(sols, [e for e, _ in expected], Q_TOL), (q, sols, expected)


# ============================================================================== hand-written real-robot URDFs
def _link(name: str) -> str:
    return f'<link name="{name}"/>'


def _joint(name: str, kind: str, parent: str, child: str, xyz: str, lim: tuple[float, float],
           axis: str = "0 0 1", rpy: str = "0 0 0", velocity: str = "0.5") -> str:  # fmt: skip
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
        f'<limit lower="{lim[0]!r}" upper="{lim[1]!r}" velocity="{velocity}" effort="10"/></joint>'
    )


def _fixed(parent: str, child: str, xyz: str, rpy: str) -> str:
    return (
        f'<joint name="{parent}-{child}" type="fixed"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/></joint>'
    )


def _robot(name: str, body: list[str]) -> str:
    return f'<?xml version="1.0"?>\n<robot name="{name}">\n  ' + "\n  ".join(body) + "\n</robot>\n"


PI = repr(math.pi)
LINKS = [_link(n) for n in ("base_link", "base", "arm1", "arm2", "quill", "flange", "tool0")]


def rot(a: float, v: tuple[float, float]) -> np.ndarray:
    return np.array([math.cos(a) * v[0] - math.sin(a) * v[1], math.sin(a) * v[0] + math.cos(a) * v[1]])


def yk400xe_y(tilt: dict[str, str] | None = None) -> str:
    """Yamaha YK400XE-like: l1 0.225, l2 0.175 stretched along +y at q = 0, z offsets 0.140 / 0.0478,
    tool drop 0.068, J3 modelled as -0.150..0 (axis +z), placeholder velocity 0.5; tool 40/15 mm off J4."""
    rpy = {"j1": "0 0 0", "j2": "0 0 0", "j3": "0 0 0", "j4": "0 0 0", **(tilt or {})}
    return _robot("yk400xe_y", LINKS + [
        _fixed("base_link", "base", "0 0 0", "0 0 0"),
        _joint("j1", "revolute", "base", "arm1", "0 0 0.140", (D(-132), D(132)), rpy=rpy["j1"]),
        _joint("j2", "revolute", "arm1", "arm2", "0 0.225 0", (D(-150), D(150)), rpy=rpy["j2"]),
        _joint("j3", "prismatic", "arm2", "quill", "0 0.175 0.0478", (-0.150, 0.0), rpy=rpy["j3"]),
        _joint("j4", "revolute", "quill", "flange", "0 0 -0.068", (D(-360), D(360)), rpy=rpy["j4"]),
        _fixed("flange", "tool0", "0.04 0.015 -0.02", f"{PI} 0 0.5"),
    ])  # fmt: skip


def yk400xe_y_fk(q: np.ndarray) -> np.ndarray:
    q1, q2, q3, q4 = q
    psi = q1 + q2 + q4
    xy = rot(q1, (0, 0.225)) + rot(q1 + q2, (0, 0.175)) + rot(psi, (0.04, 0.015))
    return np.array([xy[0], xy[1], 0.140 + 0.0478 + q3 - 0.068 - 0.02, wrap(psi + 0.5)])


def yk400xe_rpy() -> str:
    """The same arm written with joint1's origin turned by yaw = pi/2 and the offsets along x."""
    return _robot("yk400xe_rpy", LINKS + [
        _fixed("base_link", "base", "0 0 0", "0 0 0"),
        _joint("j1", "revolute", "base", "arm1", "0 0 0.140", (D(-132), D(132)), rpy=f"0 0 {math.pi / 2!r}"),
        _joint("j2", "revolute", "arm1", "arm2", "0.225 0 0", (D(-150), D(150))),
        _joint("j3", "prismatic", "arm2", "quill", "0.175 0 0.0478", (-0.150, 0.0)),
        _joint("j4", "revolute", "quill", "flange", "0 0 -0.068", (D(-360), D(360))),
        _fixed("flange", "tool0", "0.04 0.015 -0.02", f"{PI} 0 0.5"),
    ])  # fmt: skip


def yk400xe_rpy_fk(q: np.ndarray) -> np.ndarray:
    q1, q2, q3, q4 = q
    psi = math.pi / 2 + q1 + q2 + q4
    xy = rot(math.pi / 2 + q1, (0.225, 0)) + rot(math.pi / 2 + q1 + q2, (0.175, 0)) + rot(psi, (0.04, 0.015))
    return np.array([xy[0], xy[1], 0.140 + 0.0478 + q3 - 0.068 - 0.02, wrap(psi + 0.5)])


def kr5_negz() -> str:
    """KUKA KR5 SCARA R350-like (a = 0.125, 0.225; d1 = 0.246) with every axis written as -z:
    J1 +/-155, J2 +/-145, J3 0.046..0.200 (down), J4 +/-358 deg; tool 20/-30 mm off J4."""
    return _robot("kr5_negz", LINKS + [
        _fixed("base_link", "base", "0 0 0", "0 0 0"),
        _joint("j1", "revolute", "base", "arm1", "0 0 0.246", (D(-155), D(155)), axis="0 0 -1"),
        _joint("j2", "revolute", "arm1", "arm2", "0.125 0 0", (D(-145), D(145)), axis="0 0 -1"),
        _joint("j3", "prismatic", "arm2", "quill", "0.225 0 0", (0.046, 0.200), axis="0 0 -1"),
        _joint("j4", "revolute", "quill", "flange", "0 0 0", (D(-358), D(358)), axis="0 0 -1"),
        _fixed("flange", "tool0", "0.02 -0.03 -0.01", f"{PI} 0 -0.3"),
    ])  # fmt: skip


def kr5_negz_fk(q: np.ndarray) -> np.ndarray:
    q1, q2, q3, q4 = q
    psi = -(q1 + q2 + q4)
    xy = rot(-q1, (0.125, 0)) + rot(-q1 - q2, (0.225, 0)) + rot(psi, (0.02, -0.03))
    return np.array([xy[0], xy[1], 0.246 - q3 - 0.01, wrap(psi - 0.3)])


def kr5_dh_flip() -> str:
    """The KR5 written as its D-H table (alpha = pi on joint2's frame): the axes of joint2, the quill and
    joint4 point down through an rpy flip, not through the axis attribute."""
    return _robot("kr5_dh_flip", LINKS + [
        _fixed("base_link", "base", "0 0 0", "0 0 0"),
        _joint("j1", "revolute", "base", "arm1", "0 0 0.246", (D(-155), D(155))),
        _joint("j2", "revolute", "arm1", "arm2", "0.125 0 0", (D(-145), D(145)), rpy=f"{PI} 0 0"),
        _joint("j3", "prismatic", "arm2", "quill", "0.225 0 0", (0.046, 0.200)),
        _joint("j4", "revolute", "quill", "flange", "0 0 0", (D(-358), D(358))),
        _fixed("flange", "tool0", "0.02 0.03 0.01", "0 0 0.4"),
    ])  # fmt: skip


def kr5_dh_flip_fk(q: np.ndarray) -> np.ndarray:
    # link2 = Rz(q1) T(0.125) Rx(pi) Rz(q2) = ... Rz(q1 - q2) Rx(pi): offsets (a, b, c) map to Rz(q1 - q2)(a, -b, -c)
    q1, q2, q3, q4 = q
    psi = q1 - q2 - q4
    xy = rot(q1, (0.125, 0)) + rot(q1 - q2, (0.225, 0)) + rot(psi, (0.02, -0.03))
    return np.array([xy[0], xy[1], 0.246 - q3 - 0.01, wrap(psi - 0.4)])


def irb920_lift() -> str:
    """ABB IRB 920-like (l1 0.3917, l2 0.2585) with the prismatic joint FIRST (the whole arm lifts), no
    `base` link (poses fall back to the root), velocity limits written as 0 (a quirk of the public files),
    J1 +/-150, J2 +/-145, stroke 0..0.145, J4 +/-400 deg; tool 50 mm off J4, 100 mm below the flange."""
    links = [_link(n) for n in ("base_link", "carriage", "arm1", "arm2", "flange", "tool0")]
    return _robot("irb920_lift", links + [
        _joint("lift", "prismatic", "base_link", "carriage", "0 0 0.2", (0.0, 0.145), velocity="0"),
        _joint("j1", "revolute", "carriage", "arm1", "0 0 0.05", (D(-150), D(150)), velocity="0"),
        _joint("j2", "revolute", "arm1", "arm2", "0.3917 0 0", (D(-145), D(145)), velocity="0"),
        _joint("j4", "revolute", "arm2", "flange", "0.2585 0 -0.03", (D(-400), D(400)), velocity="0"),
        _fixed("flange", "tool0", "0 0.05 -0.1", f"{PI} 0 0"),
    ])  # fmt: skip


def irb920_lift_fk(q: np.ndarray) -> np.ndarray:
    qz, q1, q2, q4 = q
    psi = q1 + q2 + q4
    xy = rot(q1, (0.3917, 0)) + rot(q1 + q2, (0.2585, 0)) + rot(psi, (0, 0.05))
    return np.array([xy[0], xy[1], 0.2 + qz + 0.05 - 0.03 - 0.1, wrap(psi)])


# name: (urdf, closed-form FK, (shoulder, elbow, wrist) frames, elbow index in q, right <=> sign * sin(q_elbow) > 0)
HAND: dict[str, tuple[Callable[[], str], Callable[[np.ndarray], np.ndarray], tuple[str, str, str], int, float]] = {
    "yk400xe_y": (yk400xe_y, yk400xe_y_fk, ("arm1", "arm2", "flange"), 1, 1.0),
    "yk400xe_rpy": (yk400xe_rpy, yk400xe_rpy_fk, ("arm1", "arm2", "flange"), 1, 1.0),
    "kr5_negz": (kr5_negz, kr5_negz_fk, ("arm1", "arm2", "flange"), 1, -1.0),
    "kr5_dh_flip": (kr5_dh_flip, kr5_dh_flip_fk, ("arm1", "arm2", "flange"), 1, -1.0),
    "irb920_lift": (irb920_lift, irb920_lift_fk, ("arm1", "arm2", "flange"), 2, 1.0),
}


@pytest.fixture(scope="module")
def hand_robots() -> dict[str, Robot]:
    return {name: robot_from_urdf(spec[0](), origin=name) for name, spec in HAND.items()}


@pytest.mark.parametrize("name", list(HAND))
def test_hand_urdf_fk_is_the_closed_form(name: str, hand_robots: dict[str, Robot]) -> None:
    """Fixture check: Pinocchio FK of each hand URDF equals the plan-view closed form written above."""
    robot, fk = hand_robots[name], HAND[name][1]
    lo, hi = limits(robot)
    for q in np.random.default_rng(5).uniform(lo, hi, size=(50, 4)):
        e = robot.tool_pose(q) - fk(q)
        e[3] = wrap(e[3])
        assert np.abs(e).max() <= TOL_FK, (q, e)


@pytest.mark.parametrize(
    ("name", "l1", "l2"),
    [("yk400xe_y", 0.225, 0.175), ("yk400xe_rpy", 0.225, 0.175), ("kr5_negz", 0.125, 0.225),
     ("kr5_dh_flip", 0.125, 0.225), ("irb920_lift", 0.3917, 0.2585)],
)  # fmt: skip
def test_hand_urdf_geometry_arm_lengths(name: str, l1: float, l2: float, hand_robots: dict[str, Robot]) -> None:
    geo = hand_robots[name].kinematics.geometry
    assert (geo.l1, geo.l2) == pytest.approx((l1, l2), abs=1e-12)


@pytest.mark.parametrize("name", list(HAND))
def test_hand_urdf_ik_round_trip(name: str, hand_robots: dict[str, Robot]) -> None:
    """250 seeded q per robot: FK(IK) = target at 1e-9, q among the solutions, labels from the geometry."""
    robot = hand_robots[name]
    _, fk, frames, elbow, sign = HAND[name]
    geo = robot.kinematics.geometry
    lo, hi = limits(robot)
    rng = np.random.default_rng(1234)
    seen = set()
    for q in rng.uniform(lo, hi, size=(250, 4)):
        target = fk(q)  # the target from the closed form, not from the code under test
        res = solve_all(geo, target)
        assert res.status is IKStatus.OK, (q, res.message)
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL, (q, s.q)
            assert np.all(s.q >= lo) and np.all(s.q <= hi)
            assert branch_of(geo, s.q) == s.branch
            c = cross_label(robot, s.q, *frames)
            assert s.branch == ("right" if c > 0 else "left"), (s.q, c)
            assert s.branch == ("right" if sign * math.sin(s.q[elbow]) > 0 else "left")
            seen.add(s.branch)
        assert closest([s.q for s in res.solutions], q) <= Q_TOL, (q, [s.q for s in res.solutions])
    assert seen == {"right", "left"}


# ============================================================================== refused models
@pytest.mark.parametrize(("joint", "tilt"), [("j1", 0.02), ("j2", 0.02), ("j3", 0.02), ("j4", 0.12)])
def test_tilted_axis_is_not_a_scara(joint: str, tilt: float) -> None:
    """A joint frame tilted (roll) beyond the near-parallel 1e-2 rad (refined up to there:
    tests/test_near_parallel.py), or the wrist alone beyond WRIST_TILT_MAX (0.1 rad; a wrist-only tilt up to
    there is refined: tests/test_chain_quirks.py): the first joint whose axis is off vertical is named, with its
    angle."""
    robot = robot_from_urdf(yk400xe_y({joint: f"{tilt!r} 0 0"}), origin="tilted")
    with pytest.raises(NotScaraError) as info:
        _ = robot.kinematics.geometry
    msg = str(info.value)
    assert re.search(rf"\b{joint}\b", msg), msg
    assert not any(re.search(rf"\b{j}\b", msg) for j in ("j1", "j2", "j3", "j4") if j != joint), msg
    # the angle, accepted in degrees or radians
    assert mentions(msg, math.degrees(tilt), 1e-6) or mentions(msg, tilt, 1e-9), msg


def test_tilt_below_one_microradian_is_accepted() -> None:
    robot = robot_from_urdf(yk400xe_y({"j2": "1e-9 0 0"}), origin="almost")
    assert robot.kinematics.geometry.l1 == pytest.approx(0.225, abs=1e-12)


TWO_JOINTS = _robot("two", [_link(n) for n in ("base_link", "arm1", "tool0")] + [
    _joint("j1", "revolute", "base_link", "arm1", "0 0 0.1", (-1.57, 1.57)),
    _joint("j2", "revolute", "arm1", "tool0", "0.425 0 0", (-1.57, 1.57)),
])  # fmt: skip
FIVE_JOINTS = _robot("five", [_link(n) for n in ("base_link", "a", "b", "c", "d", "tool0")] + [
    _joint("j1", "revolute", "base_link", "a", "0 0 0.1", (-1.0, 1.0)),
    _joint("j2", "revolute", "a", "b", "0.2 0 0", (-1.0, 1.0)),
    _joint("j3", "prismatic", "b", "c", "0.2 0 0", (0.0, 0.1)),
    _joint("j4", "revolute", "c", "d", "0 0 0", (-1.0, 1.0)),
    _joint("j5", "revolute", "d", "tool0", "0 0 0", (-1.0, 1.0), axis="1 0 0"),
])  # fmt: skip
CONTINUOUS_J4 = yk400xe_y().replace('name="j4" type="revolute"', 'name="j4" type="continuous"')
TWO_PRISMATIC = _robot("two_prismatic", [_link(n) for n in ("base_link", "a", "b", "c", "tool0")] + [
    _joint("j1", "revolute", "base_link", "a", "0 0 0.1", (-1.0, 1.0)),
    _joint("j2", "prismatic", "a", "b", "0.2 0 0", (0.0, 0.1), axis="1 0 0"),
    _joint("j3", "prismatic", "b", "c", "0.2 0 0", (0.0, 0.1)),
    _joint("j4", "revolute", "c", "tool0", "0 0 0", (-1.0, 1.0)),
])  # fmt: skip


@pytest.mark.parametrize(
    ("urdf", "needles"),
    [(TWO_JOINTS, ["this file has 2 movable joints", "j1", "j2"]),
     (FIVE_JOINTS, ["this file has 5 movable joints", "j5 (revolute)"])],
    # a continuous joint (nq = 2) is accepted: tests/test_continuous.py; 3 joints (no wrist, the ROS tutorial's
    # RRP arm): tests/test_three_joints.py
    ids=["2_joints", "5_joints"],
)  # fmt: skip
def test_not_four_single_dof_joints_is_refused(urdf: str, needles: list[str]) -> None:
    with pytest.raises(UrdfError) as info:
        robot_from_urdf(urdf, origin="fixture.urdf")
    msg = str(info.value)
    assert "fixture.urdf" in msg
    for needle in needles:
        assert needle in msg, msg


def test_continuous_j4_is_accepted_and_matches_the_closed_form() -> None:
    """A continuous J4 (Pinocchio: nq = 2, cos/sin) loads with a 4-value q; FK is the fixture's closed form
    (1e-12) at any angle, and the closed-form IK presents J4 in [-pi, pi] (more in tests/test_continuous.py)."""
    robot = robot_from_urdf(CONTINUOUS_J4, origin="fixture.urdf")
    assert robot.model.nq == 5 and robot.continuous == (False, False, False, True)
    rng = np.random.default_rng(7)
    for _ in range(50):
        q = np.array([rng.uniform(D(-132), D(132)), rng.uniform(D(-150), D(150)), rng.uniform(-0.15, 0.0),
                      rng.uniform(-3 * math.pi, 3 * math.pi)])  # fmt: skip
        e = robot.tool_pose(q) - yk400xe_y_fk(q)
        e[3] = wrap(e[3])
        assert np.abs(e).max() <= TOL_FK, q
        sols = robot.ik(robot.tool_pose(q)).solutions
        assert sols and all(-math.pi <= s.q[3] <= math.pi for s in sols)
        assert any(np.abs(s.q[:3] - q[:3]).max() <= Q_TOL and abs(wrap(s.q[3] - q[3])) <= Q_TOL for s in sols)


def test_two_prismatic_joints_is_not_a_scara() -> None:
    robot = robot_from_urdf(TWO_PRISMATIC, origin="two")
    with pytest.raises(NotScaraError) as info:
        _ = robot.kinematics.geometry
    assert "j2" in str(info.value)


# ============================================================================== branches
def test_generic_target_has_both_branches_labelled_by_the_geometry(default: Robot) -> None:
    geo = default.kinematics.geometry
    lo, hi = limits(default)
    rng = np.random.default_rng(7)
    n_checked = 0
    for _ in range(200):
        q = rng.uniform(lo * 0.9, hi * 0.9)
        if abs(math.sin(q[1])) < 0.2:
            continue
        target = default.tool_pose(q)
        res = solve_all(geo, target)
        # generic: r well inside the annulus, both elbows inside the symmetric J2 range, J1 has room
        w = math.hypot(*target[:2])
        if not 0.15 < w < 0.38:
            continue
        labels = {s.branch for s in res.solutions}
        right = res.branch("right")
        left = res.branch("left")
        if not (right and left):  # one elbow can be cut off by J1 near its limit; recheck by hand
            assert {b for _, b in xacro_ik(dict(default.parameters.values), lo, hi, target)} == labels
            continue
        n_checked += 1
        assert labels == {"right", "left"}
        for s in res.solutions:
            c = cross_label(default, s.q, "link1", "link2", "quill")
            assert branch_of(geo, s.q) == s.branch == ("right" if c > 0 else "left")
            # default robot: right <=> q2 > 0 (within (-pi, pi))
            assert (s.branch == "right") == (s.q[1] > 0)
            assert (s.branch == "right") == (elbow_sin(default, s.q, "link1", "link2", "quill") > 0)
        assert all(s.branch == "right" for s in right) and all(s.branch == "left" for s in left)
        for branch, subset in (("right", right), ("left", left)):
            alone = solve_all(geo, target, branch=branch)
            assert match_count([s.q for s in alone.solutions], [s.q for s in subset], 0.0)
            assert {s.branch for s in alone.solutions} == {branch}
    assert n_checked >= 50


def test_branch_of_for_elbow_beyond_pi() -> None:
    """q2 = 200 deg is gamma = -160 deg: the elbow turns clockwise: left (sin < 0), whatever q2's sign."""
    robot = load_robot("default", {"joint2_lower": D(-250), "joint2_upper": D(250)})
    geo = robot.kinematics.geometry
    for q2, expected in [(D(200), "left"), (D(-200), "right"), (D(100), "right"), (D(-100), "left")]:
        q = np.array([0.3, q2, 0.0, 0.1])
        c = cross_label(robot, q, "link1", "link2", "quill")
        assert branch_of(geo, q) == expected == ("right" if c > 0 else "left")


# ============================================================================== 2 pi equivalents
@pytest.mark.parametrize(
    "overrides",
    [
        {"joint4_lower": D(-400), "joint4_upper": D(400)},
        {"joint1_lower": D(-350), "joint1_upper": D(350), "joint4_lower": D(-400), "joint4_upper": D(400)},
        {"joint1_lower": D(-200), "joint1_upper": D(300), "joint2_lower": D(-250), "joint2_upper": D(230),
         "joint4_lower": D(-400), "joint4_upper": D(400), "tool_x": 0.03, "tool_y": -0.02, "tool_yaw": 0.7},
    ],
    ids=["j4_400", "j1_350_j4_400", "j1_j2_j4_wide_tool"],
)  # fmt: skip
def test_every_2pi_equivalent_inside_the_limits_is_a_solution(overrides: dict[str, float]) -> None:
    robot = load_robot("default", overrides)
    geo = robot.kinematics.geometry
    p = dict(robot.parameters.values)
    lo, hi = limits(robot)
    rng = np.random.default_rng(11)
    j4_counts = set()
    for q in rng.uniform(lo, hi, size=(150, 4)):
        if abs(math.sin(q[1])) < 1e-3:
            continue
        target = robot.tool_pose(q)
        res = solve_all(geo, target)
        sols = [s.q for s in res.solutions]
        expected = xacro_ik(p, lo, hi, target)
        # the count from the limits alone: per elbow, (#q1 turns) x (#q2 turns) x (#q4 turns)
        count = 0
        for sign in (1, -1):
            e = [x for x, b in expected if b == ("right" if sign > 0 else "left")]
            if not e:
                continue
            q1, q2, q4 = e[0][0], e[0][1], e[0][3]
            n4 = n_turns(q4, lo[3], hi[3])
            j4_counts.add(n4)
            count += n_turns(q1, lo[0], hi[0]) * n_turns(q2, lo[1], hi[1]) * n4
        assert len(sols) == count == len(expected), (q, len(sols), count)
        assert match_count(sols, [e for e, _ in expected], Q_TOL)
        assert closest(sols, q) <= Q_TOL
    assert {2, 3} <= j4_counts  # 800 deg of J4: both 2 and 3 turns occur


# ============================================================================== reason codes
def test_out_of_reach_gives_r_and_the_reach(default: Robot) -> None:
    target = [0.45 * math.cos(0.3), 0.45 * math.sin(0.3), -0.05, 0.0]
    res = solve_all(default.kinematics.geometry, target)
    assert res.status is IKStatus.OUT_OF_REACH and not res.success and res.solutions == ()
    assert mentions(res.message, 0.45, 1e-9) and mentions(res.message, 0.4, 1e-9), res.message


def test_inside_inner_limit_s5_example() -> None:
    """l1 = 0.325, l2 = 0.275, J2 +/-88 deg: r_min = sqrt(l1^2 + l2^2 + 2 l1 l2 cos 88deg) = 0.433 m."""
    l1, l2, q2max = 0.325, 0.275, D(88)
    robot = load_robot("default", {"l1": l1, "l2": l2, "joint2_lower": -q2max, "joint2_upper": q2max})
    geo = robot.kinematics.geometry
    r_min = math.sqrt(l1**2 + l2**2 + 2 * l1 * l2 * math.cos(q2max))
    assert r_min == pytest.approx(0.433, abs=5e-4)
    assert geo.radius_range() == pytest.approx((r_min, l1 + l2), abs=1e-12)
    res = solve_all(geo, [0.2, 0.0, -0.05, 0.0])
    assert 0.2 > abs(l1 - l2)
    assert res.status is IKStatus.INSIDE_INNER_LIMIT
    assert mentions(res.message, 0.2, 1e-9) and mentions(res.message, r_min, 1e-8), res.message
    assert "joint2" in res.message
    # the boundary itself: 1e-7 m outside r_min solves (q2 near +/-88 deg), 1e-7 m inside does not
    for a in (0.0, 1.1, -2.0):
        ok = solve_all(geo, [(r_min + 1e-7) * math.cos(a), (r_min + 1e-7) * math.sin(a), -0.05, 0.4])
        assert ok.status is IKStatus.OK
        assert all(abs(abs(s.q[1]) - q2max) < 1e-5 for s in ok.solutions)
        bad = solve_all(geo, [(r_min - 1e-7) * math.cos(a), (r_min - 1e-7) * math.sin(a), -0.05, 0.4])
        assert bad.status is IKStatus.INSIDE_INNER_LIMIT


def test_j1_limit_behind_the_robot(default: Robot) -> None:
    res = solve_all(default.kinematics.geometry, [-0.3, 0.0, -0.05, 0.0])
    assert res.status is IKStatus.J1_LIMIT
    # right: q1 = pi - acos(0.125)/2 ... both |q1| = pi - q2/2 with cos q2 = (0.09 - 0.08) / 0.08
    q1 = math.pi - math.acos(0.125) / 2
    assert q1 > D(132)
    assert "joint1" in res.message
    assert mentions(res.message, q1, 1e-7) and mentions(res.message, -q1, 1e-7), res.message
    assert mentions(res.message, D(132), 1e-7), res.message


def test_j2_limit_range_without_zero_near_full_stretch() -> None:
    robot = load_robot("default", {"joint2_lower": D(20), "joint2_upper": D(150)})
    res = solve_all(robot.kinematics.geometry, [0.399, 0.0, -0.05, 0.0])
    assert res.status is IKStatus.J2_LIMIT
    q2 = math.acos((0.399**2 - 0.08) / 0.08)
    assert "joint2" in res.message and mentions(res.message, q2, 1e-7), res.message
    # the same target with J2 +/-150 deg solves
    assert solve_all(load_robot("default").kinematics.geometry, [0.399, 0.0, -0.05, 0.0]).status is IKStatus.OK


def test_j3_stroke(default: Robot) -> None:
    res = solve_all(default.kinematics.geometry, [0.3, 0.0, 0.01, 0.0])
    assert res.status is IKStatus.J3_STROKE
    assert "joint3" in res.message
    for v in (0.01, -0.06, -0.05, 0.1):
        assert mentions(res.message, v, 1e-9), res.message


def test_j4_limit_narrow_range() -> None:
    robot = load_robot("default", {"joint4_lower": D(-10), "joint4_upper": D(10)})
    res = solve_all(robot.kinematics.geometry, [0.3, 0.0, -0.05, math.pi])
    assert res.status is IKStatus.J4_LIMIT
    assert "joint4" in res.message
    q4 = math.pi - math.acos(0.125) / 2  # right: q1 + q2 = +41.4 deg, q4 = 180 - 41.4 deg
    assert mentions(res.message, q4, 1e-7) and mentions(res.message, -q4, 1e-7), res.message
    # a yaw the narrow J4 allows
    ok = solve_all(robot.kinematics.geometry, [0.3, 0.0, -0.05, math.acos(0.125) / 2])
    assert ok.status is IKStatus.OK and all(abs(s.q[3]) <= D(10) for s in ok.solutions)


def _tilted(M: pin.SE3, angle: float, axis: np.ndarray) -> np.ndarray:
    R = pin.exp3(angle * axis / np.linalg.norm(axis))
    out = M.homogeneous.copy()
    out[:3, :3] = R @ out[:3, :3]
    return out


@pytest.mark.parametrize("axis", [np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([1.0, -2.0, 0])])
def test_not_a_yaw_pose(default: Robot, axis: np.ndarray) -> None:
    geo = default.kinematics.geometry
    q = np.array([0.4, 1.1, 0.03, -0.7])
    M = default.tool_placement(q)
    res = solve_all(geo, _tilted(M, 1e-6, axis))
    assert res.status is IKStatus.NOT_A_YAW_POSE and res.solutions == ()
    assert mentions(res.message, math.degrees(1e-6), 1e-9) or mentions(res.message, 1e-6, 1e-12), res.message
    # 1e-11 rad of tilt is rounding: accepted, the same solutions as the 4-vector
    near = solve_all(geo, _tilted(M, 1e-11, axis))
    plain = solve_all(geo, default.tool_pose(q))
    assert near.status is IKStatus.OK
    assert match_count([s.q for s in near.solutions], [s.q for s in plain.solutions], Q_TOL)
    # the pin.SE3 itself and its 4 x 4 matrix
    for target in (M, M.homogeneous):
        res = solve_all(geo, target)
        assert res.status is IKStatus.OK
        assert closest([s.q for s in res.solutions], q) <= Q_TOL
        for s in res.solutions:
            assert pose_error(default, s.q, default.tool_pose(q)) <= POSE_TOL


def test_se3_target_on_a_robot_with_tool_yaw_and_negative_axes(hand_robots: dict[str, Robot]) -> None:
    robot = hand_robots["kr5_negz"]
    q = np.array([0.5, -1.0, 0.1, 2.0])
    M = robot.tool_placement(q)
    res = robot.ik(M)
    assert res.status is IKStatus.OK and closest([s.q for s in res.solutions], q) <= Q_TOL
    tilted = _tilted(M, 1e-6, np.array([0, 1.0, 0]))
    assert solve_all(robot.kinematics.geometry, tilted).status is IKStatus.NOT_A_YAW_POSE


# ============================================================================== the named hard cases (yaml)
def _hard_cases() -> list[dict[str, Any]]:
    return yaml.safe_load((DATA / "ik_hard_cases.yaml").read_text(encoding="utf-8"))["cases"]


def _overrides(raw: dict[str, float] | None) -> dict[str, float]:
    out = {}
    for k, v in (raw or {}).items():
        out[k[: -len("_deg")] if k.endswith("_deg") else k] = D(v) if k.endswith("_deg") else float(v)
    return out


@pytest.mark.parametrize("case", _hard_cases(), ids=lambda c: c["name"])
def test_hard_case(case: dict[str, Any]) -> None:
    robot = load_robot(case["robot"], _overrides(case.get("overrides")))
    target = np.array(case["target"], dtype=float)
    res = solve_all(robot.kinematics.geometry, target)
    assert res.status.name == case["status"], res.message
    lo, hi = limits(robot)
    if case["status"] != "OK":
        assert res.solutions == () and res.message
        return
    assert res.solutions
    for s in res.solutions:
        assert pose_error(robot, s.q, target) <= POSE_TOL
        assert np.all(s.q >= lo) and np.all(s.q <= hi), s.q
    if "n" in case:
        assert len(res.solutions) == case["n"], [s.q for s in res.solutions]
    if "singular" in case:
        assert all(s.singular == case["singular"] for s in res.solutions)
        if case["singular"]:  # the boundary solution matches both branch filters
            assert res.branch("left") == res.branch("right") == res.solutions
    for q in case.get("contains", []):
        assert closest([s.q for s in res.solutions], np.array(q, dtype=float)) <= Q_TOL, q


# ============================================================================== degenerate cases
def test_stretched_targets_on_and_just_outside_the_circle(default: Robot) -> None:
    """Targets exactly at r = l1 + l2 (and 1e-13 beyond): one solution per J4 turn, singular, both filters."""
    geo = default.kinematics.geometry
    lo, hi = limits(default)
    rng = np.random.default_rng(3)
    for a, yaw in rng.uniform([-D(130), -math.pi], [D(130), math.pi], size=(50, 2)):
        for r in (0.4 + 1e-13, 0.4 + 5e-11):
            target = np.array([r * math.cos(a), r * math.sin(a), -0.07, yaw])
            res = solve_all(geo, target)
            assert res.status is IKStatus.OK, res.message
            # q1 = a, q2 = 0, q4 = yaw - a + 2 pi k: one per J4 turn
            assert len(res.solutions) == n_turns(yaw - a, lo[3], hi[3])
            for s in res.solutions:
                assert s.singular and s.q[1] == 0.0
                assert abs(wrap(s.q[0] - a)) <= Q_TOL
                assert pose_error(default, s.q, target) <= POSE_TOL
            assert res.branch("left") == res.branch("right") == res.solutions
        far = solve_all(geo, [(0.4 + 1e-6) * math.cos(a), (0.4 + 1e-6) * math.sin(a), -0.07, yaw])
        assert far.status is IKStatus.OUT_OF_REACH


def test_stretched_targets_from_fk_have_one_solution_per_turn(default: Robot) -> None:
    geo = default.kinematics.geometry
    lo, hi = limits(default)
    rng = np.random.default_rng(1)
    for _ in range(200):
        q = np.array([rng.uniform(lo[0], hi[0]), 0.0, rng.uniform(lo[2], hi[2]), rng.uniform(lo[3], hi[3])])
        target = default.tool_pose(q)
        res = solve_all(geo, target)
        assert res.status is IKStatus.OK
        for s in res.solutions:
            assert pose_error(default, s.q, target) <= POSE_TOL
        assert len(res.solutions) == n_turns(q[3], lo[3], hi[3]), (q.tolist(), target.tolist())
        assert all(s.singular for s in res.solutions)
        assert closest([s.q for s in res.solutions], q) <= Q_TOL


def test_folded_with_j2_beyond_pi_from_fk() -> None:
    l1, l2 = 0.25, 0.125
    robot = load_robot("default", {"l1": l1, "l2": l2, "joint2_lower": D(-200), "joint2_upper": D(200)})
    geo = robot.kinematics.geometry
    lo, hi = limits(robot)
    rng = np.random.default_rng(8)
    for _ in range(100):
        q = np.array([rng.uniform(lo[0], hi[0]), math.pi * rng.choice([-1, 1]), 0.02, rng.uniform(-3, 3)])
        target = robot.tool_pose(q)
        res = solve_all(geo, target)
        assert res.status is IKStatus.OK
        assert math.hypot(*target[:2]) == pytest.approx(l1 - l2, abs=1e-15)
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL
            assert s.branch == "left" or not s.singular
        assert closest([s.q for s in res.solutions], q) <= Q_TOL_SINGULAR
        # q2 = pi and q2 = -pi are both inside +/-200 deg: both appear
        assert {round(float(s.q[1]), 6) for s in res.solutions} >= {round(math.pi, 6), round(-math.pi, 6)}


def test_wrist_on_the_shoulder_axis_uses_the_reference() -> None:
    """l1 = l2, r = 0: J1 is free; the reference's q1 (or 0 without one), every solution reaches the target."""
    robot = load_robot("default", {"joint2_lower": D(-190), "joint2_upper": D(190), "tool_yaw": 0.2})
    geo = robot.kinematics.geometry
    target = np.array([0.0, 0.0, -0.08, 0.9])  # the tool (on the J4 axis) exactly on the J1 axis
    for ref_q1 in (None, 0.7, -1.9):
        ref = None if ref_q1 is None else [ref_q1, 0.5, 0.0, 0.0]
        res = solve_all(geo, target, reference=ref)
        assert res.status is IKStatus.OK, res.message
        for s in res.solutions:
            assert s.q[0] == pytest.approx(0.0 if ref_q1 is None else ref_q1, abs=1e-12)
            assert abs(abs(s.q[1]) - math.pi) <= 1e-12 and s.singular
            assert pose_error(robot, s.q, target) <= POSE_TOL


@pytest.mark.parametrize(
    ("overrides", "reference"),
    [({"joint1_lower": 0.5, "joint1_upper": 2.0}, None), ({}, [3.0, 0.0, 0.0, 0.0])],
    ids=["j1_range_without_zero", "reference_outside_j1"],
)
def test_wrist_on_the_shoulder_axis_with_j1_limits(overrides: dict[str, float], reference: list | None) -> None:
    robot = load_robot("default", {"joint2_lower": D(-190), "joint2_upper": D(190), **overrides})
    lo, hi = limits(robot)
    target = np.array([0.0, 0.0, -0.05, 0.3])
    res = solve_all(robot.kinematics.geometry, target, reference=reference)
    assert res.status is IKStatus.OK, res.message
    for s in res.solutions:
        assert lo[0] <= s.q[0] <= hi[0]
        assert pose_error(robot, s.q, target) <= POSE_TOL


def test_wrist_on_the_shoulder_axis_up_to_rounding_uses_the_reference() -> None:
    robot = load_robot("default", {"joint2_lower": D(-190), "joint2_upper": D(190), "tool_x": 0.02, "tool_yaw": 0.2})
    geo = robot.kinematics.geometry
    for yaw in np.linspace(-3, 3, 61):
        psi = yaw - 0.2
        target = np.array([0.02 * math.cos(psi), 0.02 * math.sin(psi), -0.08, yaw])  # wrist on the J1 axis
        res = solve_all(geo, target, reference=[0.7, 0.5, 0.0, 0.0])
        assert res.status is IKStatus.OK, (target.tolist(), res.message)
        for s in res.solutions:
            assert pose_error(robot, s.q, target) <= POSE_TOL
            assert s.q[0] == pytest.approx(0.7, abs=1e-9), (target.tolist(), s.q.tolist())


@pytest.mark.parametrize("robot_name", ["default", "s1", "s5", "j2_beyond_pi", "kr5_negz", "irb920_lift"])
def test_sampled_q_exactly_on_a_joint_limit_is_found_and_clamped(
    robot_name: str, hand_robots: dict[str, Robot]
) -> None:
    """q with one or more joints exactly on a limit: the solution is found, inside the limits, not lost."""
    if robot_name in hand_robots:
        robot = hand_robots[robot_name]
    elif robot_name == "s5":
        robot = load_robot("default", {"l1": 0.325, "l2": 0.275, "joint2_lower": D(-88), "joint2_upper": D(88)})
    elif robot_name == "j2_beyond_pi":
        robot = load_robot("default", {"joint2_lower": D(-100), "joint2_upper": D(200), "tool_x": 0.04})
    else:
        robot = load_robot(robot_name)
    geo = robot.kinematics.geometry
    lo, hi = limits(robot)
    rng = np.random.default_rng(13)
    for _ in range(60):
        q = rng.uniform(lo, hi)
        on = rng.random(4) < 0.5
        on[rng.integers(4)] = True  # at least one joint on a limit
        q = np.where(on, np.where(rng.random(4) < 0.5, lo, hi), q)
        target = robot.tool_pose(q)
        res = solve_all(geo, target)
        assert res.status is IKStatus.OK, (q.tolist(), res.message)
        for s in res.solutions:
            assert np.all(s.q >= lo) and np.all(s.q <= hi), s.q.tolist()  # clamped: exactly inside
            assert pose_error(robot, s.q, target) <= POSE_TOL
        sin_g = abs(elbow_sin(robot, q, *(("link1", "link2", "quill") if robot_name not in hand_robots
                                            else HAND[robot_name][2])))  # fmt: skip
        tol = Q_TOL if sin_g >= 1e-6 else Q_TOL_SINGULAR
        assert closest([s.q for s in res.solutions], q) <= tol, (q.tolist(), [s.q.tolist() for s in res.solutions])


# ============================================================================== nearest to a reference
def test_nearest_is_the_weighted_minimum() -> None:
    robot = load_robot("default", {"joint1_lower": D(-350), "joint1_upper": D(350), "joint2_lower": D(-200),
                                   "joint2_upper": D(200), "joint4_lower": D(-400),
                                   "joint4_upper": D(400)})  # fmt: skip
    geo = robot.kinematics.geometry
    p = dict(robot.parameters.values)
    lo, hi = limits(robot)
    rng = np.random.default_rng(17)
    for _ in range(100):
        q = rng.uniform(lo, hi)
        if abs(math.sin(q[1])) < 1e-3:
            continue
        target = robot.tool_pose(q)
        res = solve_all(geo, target)
        expected = xacro_ik(p, lo, hi, target)
        assert match_count([s.q for s in res.solutions], [e for e, _ in expected], Q_TOL)
        ref = rng.uniform(lo, hi)
        for w in (None, rng.uniform(0.01, 10, 4), np.array([1.0, 0.0, 0.0, 0.0])):
            ww = np.ones(4) if w is None else w
            for branch in ("all", "right", "left"):
                pool = [e for e, b in expected if branch == "all" or b == branch]
                best = min(float(ww @ (e - ref) ** 2) for e in pool)
                got = res.nearest(ref, None if w is None else list(w), branch=branch)
                assert got is not None and got.matches(branch)
                assert float(ww @ (got.q - ref) ** 2) <= best + 1e-9
                assert closest([e for e in pool], got.q) <= Q_TOL


def test_nearest_is_none_only_without_a_solution(default: Robot) -> None:
    res = solve_all(default.kinematics.geometry, [1.0, 0.0, -0.05, 0.0])
    assert res.nearest([0, 0, 0, 0]) is None
    one_branch = load_robot("default", {"joint2_lower": D(10), "joint2_upper": D(150)})
    res = solve_all(one_branch.kinematics.geometry, [0.3, 0.1, -0.05, 0.0])
    assert res.status is IKStatus.OK
    assert res.nearest([0, 0, 0, 0], branch="left") is None
    assert res.nearest([0, 0, 0, 0], branch="right") is not None


# ============================================================================== batch vs scalar
def _batch_targets(robot: Robot, n: int, seed: int) -> np.ndarray:
    """A seeded mix: FK of q inside and beyond the limits, random boxes (some unreachable), z off the stroke."""
    rng = np.random.default_rng(seed)
    lo, hi = limits(robot)
    mid, half = (lo + hi) / 2, (hi - lo) / 2
    geo = robot.kinematics.geometry
    reach = geo.l1 + geo.l2 + math.hypot(*geo.tool)
    k = n // 4
    q = rng.uniform(mid - 1.3 * half, mid + 1.3 * half, size=(2 * k, 4))
    a = np.array([robot.tool_pose(qq) for qq in q])
    box = np.column_stack([rng.uniform(-1.3 * reach, 1.3 * reach, (n - 2 * k, 2)),
                           rng.uniform(geo.z0 - 0.3, geo.z0 + 0.3, n - 2 * k),
                           rng.uniform(-4, 4, n - 2 * k)])  # fmt: skip
    return np.vstack([a, box])[rng.permutation(n)]


def _batch_robot(name: str, hand_robots: dict[str, Robot]) -> Robot:
    if name == "limited":
        return load_robot("default", {"joint1_lower": D(-100), "joint1_upper": D(60), "joint2_lower": D(20),
                                      "joint2_upper": D(200), "joint4_lower": D(-30), "joint4_upper": D(90),
                                      "tool_x": 0.03, "tool_y": -0.02, "tool_yaw": 0.4})  # fmt: skip
    if name == "wide":
        return load_robot("default", {"joint1_lower": D(-300), "joint1_upper": D(300), "joint4_lower": D(-400),
                                      "joint4_upper": D(400), "tool_x": 0.03})  # fmt: skip
    return hand_robots[name]


@pytest.mark.parametrize(("name", "n"), [("limited", 10_000), ("kr5_negz", 10_000), ("wide", 3_000)])
def test_batch_agrees_with_scalar(name: str, n: int, hand_robots: dict[str, Robot]) -> None:
    robot = _batch_robot(name, hand_robots)
    geo = robot.kinematics.geometry
    T = _batch_targets(robot, n, seed=23)
    lo, hi = limits(robot)
    mid = (lo + hi) / 2
    ref_rows = np.random.default_rng(29).uniform(lo, hi, size=(n, 4))
    runs = {
        "right": (solve_batch(geo, T, branch="right"), mid, "right"),
        "left": (solve_batch(geo, T, branch="left"), mid, "left"),
        "nearest": (solve_batch(geo, T, branch="nearest", reference=ref_rows), ref_rows, "all"),
    }
    statuses: set[int] = set()
    for label, (batch, ref, scalar_branch) in runs.items():
        assert batch.q.shape == (n, 4) and batch.status.shape == (n,) and batch.branch.shape == (n,)
        for i in range(n):
            res = solve_all(geo, T[i], branch=scalar_branch)
            st_b = int(batch.status[i])
            statuses.add(st_b)
            assert st_b == int(res.status), (label, i, T[i].tolist(), IKStatus(st_b).name, res.status.name, res.message)
            r = ref if ref.ndim == 1 else ref[i]
            if st_b != 0:
                assert np.isnan(batch.q[i]).all() and batch.branch[i] == 0
                continue
            pool = res.branch(scalar_branch)
            d = [float(((s.q - r) ** 2).sum()) for s in pool]
            hits = [s for s in pool if np.abs(s.q - batch.q[i]).max() <= Q_TOL]
            assert hits, (label, i, T[i].tolist(), batch.q[i].tolist(), [s.q.tolist() for s in pool])
            assert float(((batch.q[i] - r) ** 2).sum()) <= min(d) + 1e-9, (label, i)  # nearest turn (ties allowed)
            sign = int(batch.branch[i])
            assert sign in (1, -1)
            if label != "nearest":
                assert sign == (1 if label == "right" else -1)
            else:
                assert any(h.singular or h.branch == ("right" if sign > 0 else "left") for h in hits)
    # the mix exercises the failures the robot can have
    expected_codes = {0, 1, 5}
    if name == "limited":  # J2 [20, 200] deg holds the folded arm: no inner limit; J1, J2, J4 all bind
        expected_codes |= {3, 4, 6}
    if name == "kr5_negz":
        expected_codes |= {2}
    assert expected_codes <= statuses, sorted(statuses)


@pytest.mark.parametrize(("name", "n"), [("limited", 3_000), ("kr5_negz", 3_000), ("wide", 2_000)])
def test_batch_default_call_is_ik_nearest(name: str, n: int, hand_robots: dict[str, Robot]) -> None:
    """The default call (reference None, i.e. q = 0, branch nearest; the squared distances in one pass): each
    row is ``ik_nearest(t, 0)`` and has its status, also where the elbow of a whole block has one turn."""
    robot = _batch_robot(name, hand_robots)
    geo = robot.kinematics.geometry
    T = _batch_targets(robot, n, seed=31)
    batch = robot.ik_batch(T)
    zero = np.zeros(4)
    for i in range(n):
        res = solve(geo, T[i], reference=zero)
        assert int(batch.status[i]) == int(res.status), (i, T[i].tolist(), res.message)
        if res.success:
            assert np.abs(batch.q[i] - robot.ik_nearest(T[i], zero)).max() <= 1e-12, (i, T[i].tolist())
        else:
            assert np.isnan(batch.q[i]).all() and batch.branch[i] == 0


def test_batch_clamps_an_elbow_rounded_just_past_its_limit() -> None:
    """Every elbow of the block within LIMIT_TOL outside its limits, some beyond them: clamped onto the limit."""
    robot = load_robot("default")
    hi = robot.kinematics.geometry.upper[1]
    T = np.array([robot.tool_pose([0.1, hi + 5e-11, 0.0, 0.2]), robot.tool_pose([-0.3, -hi - 5e-11, 0.05, 0.0])])
    clamped = 0
    for branch in ("nearest", "right", "left"):
        batch = robot.ik_batch(T, branch=branch)
        for i in range(len(T)):
            scalar = "all" if branch == "nearest" else branch
            res = solve(robot.kinematics.geometry, T[i], branch=scalar, reference=np.zeros(4))
            assert int(batch.status[i]) == int(res.status), (branch, i)
            if res.success:
                want = robot.ik_nearest(T[i], branch=scalar)
                assert np.abs(batch.q[i] - want).max() <= 1e-12, (branch, i, batch.q[i].tolist(), want.tolist())
                assert -hi <= batch.q[i, 1] <= hi
                clamped += abs(batch.q[i, 1]) == hi
    assert clamped >= 3


def test_batch_takes_solves_route_for_a_branch_failing_by_rounding_near_stretched() -> None:
    """Near the stretched circle the left elbow misses its limit by less than the arm's rounding while the right
    one solves: solve() puts the left elbow on its limit, and the batch (one reference for all rows) follows."""
    g = 1e-4  # wobble(g) ~ 2e-9 rad
    robot = load_robot("default", {"joint2_lower": -g + 1e-9})
    q = np.array([0.3, g, 0.0, 0.1])
    ref = np.array([0.3 + g, -g, 0.0, 0.1])  # the left branch, nearer
    T = np.array([robot.tool_pose(q), robot.tool_pose([0.2, 1.0, 0.0, 0.0])])
    batch = robot.ik_batch(T, ref)
    for i in range(len(T)):
        want = robot.ik_nearest(T[i], ref)
        assert int(batch.status[i]) == 0 and np.abs(batch.q[i] - want).max() <= 1e-12, (i, batch.q[i], want)
    assert batch.branch[0] == -1 and batch.q[0, 1] == -g + 1e-9
    # and near the folded circle (the right elbow just past its upper limit, the left one inside)
    robot = load_robot("default", {"joint2_lower": -math.pi - g / 2, "joint2_upper": math.pi - g - 1e-9})
    q = np.array([-1.0, math.pi - g, 0.0, 0.1])
    T = np.array([robot.tool_pose(q), robot.tool_pose([0.2, 1.0, 0.0, 0.0])])
    batch = robot.ik_batch(T, q)
    for i in range(len(T)):
        want = robot.ik_nearest(T[i], q)
        assert int(batch.status[i]) == 0 and np.abs(batch.q[i] - want).max() <= 1e-12, (i, batch.q[i], want)


def _hard_case_params() -> list[Any]:
    out = []
    for case in _hard_cases():
        out.append(pytest.param(case, id=case["name"]))
    return out




@pytest.mark.parametrize("case", _hard_case_params())
def test_batch_agrees_with_scalar_on_the_hard_cases(case: dict[str, Any]) -> None:
    robot = load_robot(case["robot"], _overrides(case.get("overrides")))
    geo = robot.kinematics.geometry
    T = np.array([case["target"]], dtype=float)
    for batch_branch, scalar_branch in (("right", "right"), ("left", "left"), ("nearest", "all")):
        batch = solve_batch(geo, T, branch=batch_branch)
        res = solve_all(geo, T[0], branch=scalar_branch)
        assert int(batch.status[0]) == int(res.status), (batch_branch, res.message)
        if res.success:
            assert pose_error(robot, batch.q[0], T[0]) <= POSE_TOL
            assert closest([s.q for s in res.branch(scalar_branch)], batch.q[0]) <= Q_TOL, (batch_branch, batch.q[0])


def test_batch_free_j1_status_agrees_with_scalar() -> None:
    robot = load_robot("default", {"joint2_lower": D(-190), "joint2_upper": D(190), "joint1_lower": -0.5,
                                   "joint1_upper": 0.5})  # fmt: skip
    T = np.array([[0.0, 0.0, -0.05, 0.3]])
    res = solve_all(robot.kinematics.geometry, T[0], reference=[0.2, 0.0, 0.0, 0.0])
    assert res.status is IKStatus.OK  # q1 = 0.2: J1 is free
    batch = solve_batch(robot.kinematics.geometry, T, branch="nearest", reference=[0.2, 0.0, 0.0, 0.0])
    assert int(batch.status[0]) == int(res.status)


def test_batch_validates_its_input(default: Robot) -> None:
    geo = default.kinematics.geometry
    with pytest.raises(scara_pin.ParameterError):
        solve_batch(geo, np.zeros((3, 3)))
    with pytest.raises(scara_pin.InvalidInputError):
        solve_batch(geo, np.zeros((3, 4)), branch="all")
    with pytest.raises(scara_pin.InvalidInputError):
        solve_all(geo, [0.3, 0, -0.05, 0], branch="up")
    with pytest.raises(scara_pin.ParameterError):
        solve_all(geo, [0.3, 0, math.nan, 0])


def test_geometry_is_read_from_the_model(default: Robot) -> None:
    """ScaraGeometry of the default robot vs the yaml numbers (S4: l1 = l2 = 0.2, z0 = -0.05)."""
    geo = ScaraGeometry.from_robot(default)
    assert (geo.l1, geo.l2) == pytest.approx((0.2, 0.2), abs=1e-15)
    assert geo.z0 == pytest.approx(-0.05, abs=1e-15)
    assert geo.revolute == (0, 1, 3) and geo.prismatic == 2
    assert geo.signs == (1.0, 1.0, -1.0, 1.0)
    assert geo.radius_range() == pytest.approx((2 * 0.2 * math.cos(D(75)), 0.4), abs=1e-15)


def test_batch_never_writes_negative_zero_where_the_scalar_writes_zero() -> None:
    """A stretched elbow on the left branch is -gamma = -0.0 before its turn is added; the scalar path adds
    2 pi k (k = 0) and returns 0.0: the batch, alone or with other rows in its block, does the same."""
    robot = load_robot("default")
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    mid = (lo + hi) / 2
    T = np.array([robot.tool_pose(np.array([0.3, 0.0, 0.05, 0.1]))])  # elbow stretched (q2 = 0)
    scalar = robot.ik_nearest(T[0], mid, branch="left")
    for rows in (T, np.vstack([T, [[0.1, 0.1, -0.1, 0.0]]])):
        got = robot.ik_batch(rows, mid, branch="left").q[0]
        assert np.array_equal(got, scalar)
        assert np.array_equal(np.signbit(got), np.signbit(scalar))  # 0.0, not -0.0 (a CSV would print it)
