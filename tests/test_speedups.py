"""The compiled hot paths (scara_pin._speedups) against their pure-Python twins, and solve_nearest / ik_nearest.

Independent routes for the expected values:

- ``q_ok``: the rule written here (a 1-D float64 ndarray of 4 values whose squares sum to at most Q_MAX2),
  on crafted good and bad inputs; both the compiled and the Python function must follow it;
- ``task_rows``: numpy fancy indexing of rows 0, 1, 2, 5;
- nearest solution: brute force in this file, the weighted distance of every solution of ``solve`` (checked
  on its own in test_ik.py), plus Pinocchio FK of the answer (pose within 1e-9) and the joint limits;
- the command line gives the same answers with ``SCARA_PIN_NO_SPEEDUPS=1`` (the Python route).

The compiled and the Python route of the nearest solution are the same operations on the same numbers:
they must agree bit for bit, ties included (references exactly halfway between two solutions), and
at the 1e-10 clamping edges of the limits.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_ik import limits, robot_overrides

import scara_pin
from scara_pin import NoSolutionError, ParameterError, Robot, _fast, load_robot
from scara_pin.ik import IKStatus, _nearest_py, solve, solve_nearest

CONTINUOUS = Path(__file__).parent / "data" / "third_party" / "irb920_continuous.urdf"
POSE_TOL = 1e-9
Q_TOL = 1e-9
Q_TOL_SINGULAR = 1e-6

compiled = pytest.mark.skipif(_fast.speedups is None, reason="scara_pin._speedups is not built (no C compiler)")


@pytest.fixture(scope="module")
def default() -> Robot:
    return load_robot("default")


def test_the_compiled_module_is_used_when_built() -> None:
    if _fast.speedups is None:
        pytest.skip("scara_pin._speedups is not built")
    assert _fast.q_ok is _fast.speedups.q_ok
    assert _fast.task_rows is _fast.speedups.task_rows
    assert _fast.speedups.geometry_size() * 8 == len(load_robot("s1").kinematics._cparams)


# ============================================================================== q_ok
big = math.sqrt(_fast.Q_MAX2 / 4)  # 4 values of this size sum exactly to about Q_MAX2
GOOD = {
    "zeros": np.zeros(4),
    "typical": np.array([0.1, -0.2, 0.05, 3.0]),
    "on the bound": np.full(4, big * (1 - 1e-12)),
    "strided view": np.arange(8.0)[::2],
    "negative zero": np.array([-0.0, 0.0, -0.0, 0.0]),
}
BAD = {
    "NaN": np.array([0.1, math.nan, 0.0, 0.0]),
    "inf": np.array([0.0, 0.0, math.inf, 0.0]),
    "-inf": np.array([-math.inf, 0.0, 0.0, 0.0]),
    "too large": np.full(4, big * 1.001),  # still a valid q for check_q: only the fast test says no
    "huge": np.array([2e6, 0.0, 0.0, 0.0]),
    "3 values": np.zeros(3),
    "5 values": np.zeros(5),
    "4x1": np.zeros((4, 1)),
    "1x4": np.zeros((1, 4)),
    "0-d": np.array(1.0),
    "float32": np.zeros(4, dtype=np.float32),
    "big-endian NaN": np.array([math.nan, 0.0, 0.0, 0.0], dtype=">f8" if sys.byteorder == "little" else "<f8"),
    "byte-swapped": np.array([0.1, 0.2, 0.3, 0.4], dtype=">f8" if sys.byteorder == "little" else "<f8"),
    "int": np.zeros(4, dtype=int),
    "bool": np.zeros(4, dtype=bool),
    "complex": np.zeros(4, dtype=complex),
    "object": np.array([0.0, 0.0, 0.0, 0.0], dtype=object),
    "list": [0.0, 0.0, 0.0, 0.0],
    "tuple": (0.0, 0.0, 0.0, 0.0),
    "string": "0000",
    "None": None,
    "ndarray subclass": np.zeros(4).view(type("Sub", (np.ndarray,), {})),
}


def routes(name: str) -> list[Any]:
    """The Python function ``_fast.<name>_py`` and, when built, the compiled ``_speedups.<name>``."""
    out = [pytest.param(getattr(_fast, name + "_py"), id="python")]
    if _fast.speedups is not None:
        out.append(pytest.param(getattr(_fast.speedups, name), id="compiled"))
    return out


@pytest.mark.parametrize("q_ok", routes("q_ok"))
@pytest.mark.parametrize("label", list(GOOD))
def test_q_ok_accepts_plain_moderate_float64_quadruples(q_ok: Any, label: str) -> None:
    assert q_ok(GOOD[label]) is True


@pytest.mark.parametrize("q_ok", routes("q_ok"))
@pytest.mark.parametrize("label", list(BAD))
def test_q_ok_sends_everything_else_to_the_full_check(q_ok: Any, label: str) -> None:
    assert q_ok(BAD[label]) is False


@pytest.mark.parametrize(
    "label", ["NaN", "big-endian NaN", "inf", "huge", "3 values", "4x1", "complex", "string", "None"]
)
@pytest.mark.parametrize("method", ["tool_placement", "task_jacobian", "tool_pose"])
def test_bad_q_still_raises_the_typed_error(default: Robot, method: str, label: str) -> None:
    with pytest.raises(ParameterError):
        getattr(default, method)(BAD[label])


@pytest.mark.parametrize(
    "label", ["list", "tuple", "float32", "int", "strided view", "too large", "ndarray subclass", "byte-swapped"]
)
def test_other_valid_forms_give_the_float64_answer(default: Robot, label: str) -> None:
    q = BAD.get(label, GOOD.get(label))
    ref = np.asarray(q, dtype=float)
    assert np.array_equal(default.tool_placement(q).homogeneous, default.tool_placement(ref).homogeneous)
    assert np.array_equal(default.task_jacobian(q), default.task_jacobian(ref))


# ============================================================================== task_rows
@pytest.mark.parametrize("task_rows", routes("task_rows"))
@pytest.mark.parametrize("layout", ["C", "F", "strided"])
def test_task_rows_are_rows_0_1_2_5(task_rows: Any, layout: str) -> None:
    J = np.random.default_rng(1).normal(size=(6, 9))
    if layout == "F":
        J = np.asfortranarray(J)
    elif layout == "strided":
        J = np.random.default_rng(2).normal(size=(12, 18))[::2, ::2]
    out = task_rows(J)
    assert out.shape == (4, 9)
    assert np.array_equal(out, J[[0, 1, 2, 5]])
    out[0, 0] = 1e9  # a new array, not a view
    assert J[0, 0] != 1e9


@compiled
@pytest.mark.parametrize("bad", [np.zeros((5, 4)), np.zeros(24), np.zeros((6, 4), dtype=np.float32), [[0.0] * 4] * 6])
def test_compiled_task_rows_refuses_other_arrays(bad: Any) -> None:
    with pytest.raises(TypeError):
        _fast.speedups.task_rows(bad)  # type: ignore[union-attr]


# ============================================================================== solve_nearest
def brute_nearest(geo: Any, target: np.ndarray, ref: np.ndarray, w: np.ndarray, branch: str = "all") -> np.ndarray:
    """The solution of least sum w (q - ref)^2 over every solution solve() lists, first on a tie."""
    res = solve(geo, target, branch=branch, reference=ref)
    assert res.success, res.message
    costs = [float(np.sum(w * (s.q - ref) ** 2)) for s in res.solutions if s.matches(branch)]
    return res.solutions[[i for i, s in enumerate(res.solutions) if s.matches(branch)][int(np.argmin(costs))]].q


def pose_error(robot: Robot, q: np.ndarray, target: np.ndarray) -> float:
    e = robot.tool_pose(q) - target
    e[3] = math.remainder(e[3], 2 * math.pi)
    return float(np.abs(e).max())


def check_nearest(robot: Robot, target: np.ndarray, ref: np.ndarray, w: np.ndarray | None, branch: str) -> None:
    geo = robot.kinematics
    lo, hi = limits(robot)
    ww = np.ones(4) if w is None else w
    got = solve_nearest(geo, target, ref, weights=w, branch=branch)
    py = _nearest_py(geo, target, ref, w, branch)
    expected = brute_nearest(geo, target, ref, ww, branch)
    g = robot.kinematics.elbow_angle(float(got[geo.revolute[1]]))
    tol = Q_TOL if abs(math.sin(g)) >= 1e-6 else Q_TOL_SINGULAR
    assert np.abs(got - expected).max() <= tol, (got, expected)
    assert np.array_equal(got, py), (got, py)
    assert pose_error(robot, got, target) <= POSE_TOL
    assert np.all(got >= lo) and np.all(got <= hi)


@settings(max_examples=30, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(overrides=robot_overrides(), seed=st.integers(0, 2**32 - 1))
def test_nearest_is_the_nearest_of_all_solutions_on_random_robots(overrides: dict[str, float], seed: int) -> None:
    robot = load_robot("default", overrides)
    lo, hi = limits(robot)
    rng = np.random.default_rng(seed)
    for k in range(40):
        q = rng.uniform(lo, hi)
        target = robot.tool_pose(q)
        ref = rng.uniform(lo, hi)
        w = None if k % 2 else rng.uniform(0.0, 3.0, size=4)
        branch = ("all", "left", "right")[k % 3]
        if branch != "all" and not solve(robot.kinematics, target, branch=branch).success:
            with pytest.raises(NoSolutionError):
                solve_nearest(robot.kinematics, target, ref, weights=w, branch=branch)
            continue
        check_nearest(robot, target, ref, w, branch)


@pytest.mark.parametrize("robot_name", ["default", "s1"])
def test_nearest_of_the_sampled_q_is_that_q(robot_name: str) -> None:
    """Asked for the solution nearest to the configuration a target came from, IK returns that configuration."""
    robot = load_robot(robot_name)
    lo, hi = limits(robot)
    rng = np.random.default_rng(7)
    worst = 0.0
    for q in rng.uniform(lo, hi, size=(2000, 4)):
        if abs(math.sin(robot.kinematics.elbow_angle(q[1]))) < 1e-6:
            continue
        worst = max(worst, float(np.abs(robot.ik_nearest(robot.tool_pose(q), q) - q).max()))
    assert worst <= Q_TOL


def test_ties_are_broken_alike_by_both_routes(default: Robot) -> None:
    """A reference exactly halfway between two solutions: both routes return the same one (the first)."""
    geo = default.kinematics
    lo, hi = limits(default)
    rng = np.random.default_rng(5)
    checked = 0
    for q in rng.uniform(lo, hi, size=(3000, 4)):
        target = default.tool_pose(q)
        sols = solve(geo, target).solutions
        if len(sols) < 2:
            continue
        i, j = rng.choice(len(sols), 2, replace=False)
        ref = 0.5 * (sols[i].q + sols[j].q)
        got = solve_nearest(geo, target, ref)
        assert np.array_equal(got, _nearest_py(geo, target, ref, None, "all")), (target, ref)
        assert np.array_equal(got, brute_nearest(geo, target, ref, np.ones(4)))
        checked += 1
    assert checked > 2000


@pytest.mark.parametrize("past", [0.0, 0.4e-10, 0.9e-10])
@pytest.mark.parametrize("wrist_past", [0.0, 0.5e-10, 1.5e-10, 3e-10])
def test_limit_edges_are_judged_alike(past: float, wrist_past: float) -> None:
    """J1 up to LIMIT_TOL past its limit (clamped onto it) and J4 past its own: both routes, one answer.

    The wrist is judged on the clamped shoulder value: 1.5e-10 past J4's limit before J1's clamp of 0.9e-10
    is 0.6e-10 past after it, inside LIMIT_TOL: a solution; 3e-10 is outside either way: J4_LIMIT.
    """
    robot = load_robot("default", {"joint1_lower": math.radians(-130), "joint1_upper": math.radians(130),
                                   "joint4_lower": math.radians(-170), "joint4_upper": math.radians(170)})  # fmt: skip
    geo = robot.kinematics
    q = np.array([geo.upper[0] + past, 1.0, 0.0, geo.lower[3] - wrist_past])
    target = robot.tool_pose(q)
    # J4's excess after J1's clamp, which moves it back by `past`; never within 1e-11 of LIMIT_TOL here
    feasible = wrist_past - past <= 1e-10
    res = solve(geo, target)
    assert res.success is feasible, res.message
    if not feasible:
        assert res.status is IKStatus.J4_LIMIT and "joint4" in res.message
        for route in (solve_nearest, _nearest_py):
            with pytest.raises(NoSolutionError) as info:
                route(geo, target, q, None, "all") if route is _nearest_py else route(geo, target, q)
            assert info.value.status is IKStatus.J4_LIMIT
        return
    got = solve_nearest(geo, target, q)
    assert np.array_equal(got, _nearest_py(geo, target, q, None, "all"))
    assert pose_error(robot, got, target) <= POSE_TOL
    assert got[0] == geo.upper[0] and geo.lower[3] <= got[3] <= geo.upper[3]


def test_nearest_reasons_come_from_solve(default: Robot) -> None:
    ref = np.zeros(4)
    cases = {
        IKStatus.OUT_OF_REACH: [0.5, 0.0, -0.05, 0.0],
        IKStatus.J3_STROKE: [0.3, 0.0, 1.0, 0.0],
    }
    for status, target in cases.items():
        with pytest.raises(NoSolutionError) as info:
            default.ik_nearest(np.array(target), ref)
        assert info.value.status is status
        assert info.value.reason == solve(default.kinematics, target).message
        assert info.value.exit_code == 3
        assert str(info.value).startswith(status.name + ": ")


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"reference": [0.0, 0.0, 0.0]}, "reference"),
        ({"reference": [0.0, math.nan, 0.0, 0.0]}, "reference"),
        ({"reference": "abcd"}, "reference"),
        ({"reference": np.zeros(4), "weights": [1.0, -1.0, 1.0, 1.0]}, "weights"),
        ({"reference": np.zeros(4), "weights": [1.0, math.inf, 1.0, 1.0]}, "weights"),
        ({"reference": np.zeros(4), "branch": "up"}, "branch"),
    ],
)
def test_nearest_bad_inputs_raise_typed_errors(default: Robot, kwargs: dict[str, Any], needle: str) -> None:
    with pytest.raises(scara_pin.InvalidInputError, match=needle):
        default.ik_nearest(np.array([0.3, 0.1, -0.05, 0.2]), **kwargs)


@pytest.mark.parametrize(
    "target",
    [
        [0.3, 0.1, -0.05, 0.2],  # a list of floats
        (0.3, 0.1, -0.05, 0.2),  # a tuple
        np.array([0.3, 0.1, -0.05, 0.2], dtype=np.float32).astype(float),
        [0.3, 0.1, -0.05, 1],  # an int among floats: the Python route
        np.array([0.3, 0.1, -0.05, 0.2], dtype=">f8" if sys.byteorder == "little" else "<f8"),  # swapped
    ],
)
def test_nearest_target_forms_agree(default: Robot, target: Any) -> None:
    ref = np.array([0.2, 0.4, 0.0, 0.0])
    expected = brute_nearest(default.kinematics, np.asarray(target, dtype=float), ref, np.ones(4))
    assert np.abs(default.ik_nearest(target, ref) - expected).max() <= Q_TOL


def test_nearest_takes_a_pose_matrix(default: Robot) -> None:
    q = np.array([0.3, -1.1, 0.02, 2.0])
    M = default.tool_placement(q).homogeneous.copy()
    assert np.abs(default.ik_nearest(M, q) - q).max() <= Q_TOL
    M[:3, :3] = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # a roll
    with pytest.raises(NoSolutionError) as info:
        default.ik_nearest(M, q)
    assert info.value.status is IKStatus.NOT_A_YAW_POSE


def test_nearest_free_shoulder_uses_the_reference() -> None:
    """l1 = l2 and the wrist on the shoulder axis: the shoulder takes the reference's angle (Python route)."""
    robot = load_robot("default", {"joint2_lower": -3.2, "joint2_upper": 3.2})
    geo = robot.kinematics
    assert geo.l1 == pytest.approx(geo.l2, abs=1e-15)
    q = np.array([0.7, math.pi - (geo.beta2 - geo.beta1), 0.0, 0.1])
    target = robot.tool_pose(q)
    for shoulder in (0.7, -0.4):
        ref = np.array([shoulder, 3.0, 0.0, 0.0])
        got = robot.ik_nearest(target, ref)
        assert pose_error(robot, got, target) <= POSE_TOL
        assert abs(got[0] - shoulder) <= 1e-9


def test_nearest_on_a_wrist_with_several_turns_picks_the_nearest_turn() -> None:
    """J4 over +/-400 deg: the same pose has wrist values 2 pi apart; the reference chooses among them."""
    robot = load_robot("default", {"joint4_lower": math.radians(-400), "joint4_upper": math.radians(400)})
    q = np.array([0.2, 0.9, 0.01, 0.5])
    target = robot.tool_pose(q)
    for k in (-1, 0, 1):
        ref = q + np.array([0.0, 0.0, 0.0, 2 * math.pi * k + 0.3])
        got = robot.ik_nearest(target, ref)
        assert abs(got[3] - (0.5 + 2 * math.pi * k)) <= 1e-9, (k, got)


def test_nearest_weights_change_the_choice(default: Robot) -> None:
    """A reference with the shoulder of the left solution and the elbow of the right one: the weights decide."""
    geo = default.kinematics
    q = np.array([0.3, 1.2, 0.0, 0.4])
    target = default.tool_pose(q)
    sols = solve(geo, target).solutions
    right = next(s.q for s in sols if s.branch == "right")
    left = next(s.q for s in sols if s.branch == "left")
    ref = np.array([left[0], right[1], 0.0, 0.4])
    for w, branch in (([1.0, 0.0, 0.0, 1e-3], "left"), ([0.0, 1.0, 0.0, 1e-3], "right")):
        got = default.ik_nearest(target, ref, weights=w)
        assert default.branch_of(got) == branch
        assert np.abs(got - brute_nearest(geo, target, ref, np.array(w))).max() <= Q_TOL


@pytest.mark.parametrize("which", ["palletizer", "continuous"])
def test_nearest_on_a_palletizer_and_a_continuous_robot(which: str) -> None:
    """The robots ik_nearest serves through Robot.ik (the palletizer's closed form; dropped -pi/+pi twins)."""
    robot = load_robot("palletizer") if which == "palletizer" else load_robot(urdf=CONTINUOUS)
    lo, hi = limits(robot) if which == "palletizer" else (np.array(robot.limits.lower), np.array(robot.limits.upper))
    rng = np.random.default_rng(3)
    for q in rng.uniform(lo, hi, size=(50, 4)):
        target = robot.tool_pose(q)
        got = robot.ik_nearest(target, q)
        assert pose_error(robot, got, target) <= POSE_TOL
        assert np.abs(got - q).max() <= 1e-6


def test_the_result_is_a_new_array(default: Robot) -> None:
    target = np.array([0.3, 0.1, -0.05, 0.2])
    a = default.ik_nearest(target, np.zeros(4))
    a[:] = 0.0
    assert np.abs(default.ik_nearest(target, np.zeros(4))).max() > 0.0


# ============================================================================== the Python route, end to end
def test_cli_gives_the_same_answers_without_the_compiled_module(tmp_path: Any) -> None:
    script = [sys.executable, "-m", "scara_pin.cli"]
    runs = {}
    for label, extra in (("compiled", {}), ("python", {"SCARA_PIN_NO_SPEEDUPS": "1"})):
        env = {**os.environ, **extra}
        out = {}
        for cmd in (["fk", "--json", "0.1", "0.2", "0.05", "0.3"], ["jacobian", "--json", "0.1", "0.2", "0.05", "0.3"],
                    ["ik", "--json", "0.3", "0.1", "-0.1", "0.5", "--near", "0", "0", "0", "0"]):  # fmt: skip
            proc = subprocess.run([*script, *cmd], capture_output=True, text=True, env=env, check=False)
            assert proc.returncode == 0, proc.stderr
            out[cmd[0]] = json.loads(proc.stdout)
        proc = subprocess.run([*script, "fk", "0.1", "nan", "0", "0"], capture_output=True, text=True, env=env,
                              check=False)  # fmt: skip
        assert proc.returncode == 2 and proc.stderr.startswith("error:"), proc.stderr
        runs[label] = out
    assert runs["compiled"]["fk"]["matrix"] == runs["python"]["fk"]["matrix"]
    assert runs["compiled"]["jacobian"] == runs["python"]["jacobian"]
    a = np.array([s["q"] for s in runs["compiled"]["ik"]["solutions"]])
    b = np.array([s["q"] for s in runs["python"]["ik"]["solutions"]])
    assert a.shape == b.shape and np.abs(a - b).max() <= Q_TOL
