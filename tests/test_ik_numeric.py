"""Numeric IK (scara_pin.kinematics.numeric) and the cross-validation report (scara_pin.kinematics.validate).

Truth comes from Pinocchio forward kinematics evaluated here: a numeric solution is accepted when FK of its
q is the target to 1e-9 (m and rad), whatever the solver reports; its reported residual must equal the
residual recomputed here; for unreachable targets the residual is bounded below by the distance from the
target to the workspace, a closed form (|r - (l1 + l2)|, or the distance to the stroke).
validate_ik must pass on every shipped robot, and must FAIL when the closed form is perturbed by 1e-6.
Seeded randomness throughout.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import scara_pin
import scara_pin.kinematics.validate
from scara_pin import ParameterError, Robot, load_robot, robot_from_urdf
from scara_pin.kinematics.numeric import NumericIKOptions, NumericIKReason, NumericIKResult, solve_numeric
from scara_pin.kinematics.scara import IKResult, NotScaraError, solve
from scara_pin.kinematics.validate import validate_ik

POSE_TOL = 1e-9
TWO_PI = 2.0 * math.pi
D = math.radians


def wrap(a: float) -> float:
    return (a + math.pi) % TWO_PI - math.pi


def task_error(robot: Robot, q: np.ndarray, target: np.ndarray) -> np.ndarray:
    e = np.asarray(target, dtype=float) - robot.tool_pose(q)
    e[3] = wrap(e[3])
    return e


def limits(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    model = robot.model
    return np.asarray(model.lowerPositionLimit, dtype=float), np.asarray(model.upperPositionLimit, dtype=float)


@pytest.fixture(scope="module")
def shipped() -> dict[str, Robot]:
    return {name: load_robot(name) for name in scara_pin.available_robots()}


def test_the_shipped_robots_are_the_expected_ones(shipped: dict[str, Robot]) -> None:
    assert {"default", "s1"} <= set(shipped)


# ============================================================================== convergence
@pytest.mark.parametrize("name", scara_pin.available_robots())
def test_converges_on_random_reachable_targets(name: str, shipped: dict[str, Robot]) -> None:
    robot = shipped[name]
    lo, hi = limits(robot)
    rng = np.random.default_rng(101)
    for q in rng.uniform(lo, hi, size=(200, 4)):
        target = robot.tool_pose(q)
        res = solve_numeric(robot, target)
        assert isinstance(res, NumericIKResult)
        assert res.success and res.reason is NumericIKReason.CONVERGED, (q.tolist(), res)
        e = task_error(robot, res.q, target)
        assert np.abs(e).max() <= POSE_TOL, (q.tolist(), e)
        assert res.residual == pytest.approx(float(np.linalg.norm(e)), abs=1e-15)
        assert np.all(res.q >= lo) and np.all(res.q <= hi), res.q.tolist()
        assert res.iterations >= 0 and res.starts >= 1


def test_converges_on_a_robot_with_wide_limits_and_a_tool_offset() -> None:
    robot = load_robot("default", {"joint1_lower": D(-300), "joint1_upper": D(300), "joint2_lower": D(20),
                                   "joint2_upper": D(200), "joint4_lower": D(-400), "joint4_upper": D(400),
                                   "tool_x": 0.03, "tool_y": -0.02, "tool_yaw": 0.4})  # fmt: skip
    lo, hi = limits(robot)
    for q in np.random.default_rng(103).uniform(lo, hi, size=(50, 4)):
        target = robot.tool_pose(q)
        res = solve_numeric(robot, target)
        assert res.success, (q.tolist(), res)
        assert np.abs(task_error(robot, res.q, target)).max() <= POSE_TOL
        assert np.all(res.q >= lo) and np.all(res.q <= hi)


def _tilted_urdf() -> str:
    """A SCARA whose elbow axis is tilted by 0.02 rad (beyond near-parallel): the closed form refuses it, the
    numeric IK must not."""
    return load_robot("default").urdf.replace(
        '<joint name="joint2" type="revolute">\n    <parent link="link1"/>\n    <child link="link2"/>\n    '
        '<origin rpy="0 0 0"',
        '<joint name="joint2" type="revolute">\n    <parent link="link1"/>\n    <child link="link2"/>\n    '
        '<origin rpy="0.02 0 0"',
    )


def test_numeric_is_the_fallback_for_a_model_the_closed_form_refuses() -> None:
    urdf = _tilted_urdf()
    assert 'rpy="0.02 0 0"' in urdf  # the fixture really is tilted
    robot = robot_from_urdf(urdf, origin="tilted")
    with pytest.raises(NotScaraError):
        _ = robot.kinematics.geometry
    lo, hi = limits(robot)
    for q in np.random.default_rng(107).uniform(lo, hi, size=(30, 4)):
        target = robot.tool_pose(q)
        res = solve_numeric(robot, target)
        assert res.success, (q.tolist(), res)
        assert np.abs(task_error(robot, res.q, target)).max() <= POSE_TOL


def test_start_on_the_solution_converges_at_once(shipped: dict[str, Robot]) -> None:
    robot = shipped["default"]
    q = np.array([0.3, -1.2, 0.02, 2.0])
    res = solve_numeric(robot, robot.tool_pose(q), q0=q)
    assert res.success and res.starts == 1 and res.iterations <= 4
    assert np.abs(res.q - q).max() <= 1e-9


def test_seeded_and_repeatable(shipped: dict[str, Robot]) -> None:
    robot = shipped["s1"]
    target = robot.tool_pose(np.array([2.5, -2.4, 0.05, 1.0]))
    a = solve_numeric(robot, target, options=NumericIKOptions(seed=4))
    b = solve_numeric(robot, target, options=NumericIKOptions(seed=4))
    assert a.success and np.array_equal(a.q, b.q) and a.iterations == b.iterations and a.starts == b.starts


# ============================================================================== failure is a result, not None
@pytest.mark.parametrize(
    ("target", "bound", "slack"),
    [
        ([1.0, 0.0, -0.05, 0.0], 0.6, 1e-3),  # r = 1.0, reach 0.4: at least 0.6 m away
        ([0.0, -0.7, -0.1, 2.0], 0.3, 1e-3),
        ([0.3, 0.1, 0.5, 0.0], 0.5, 1e-6),  # z = 0.5, the stroke tops out at z = 0: 0.5 m
    ],
    ids=["far_x", "far_y", "above_stroke"],
)
def test_unreachable_target_returns_failure_with_the_residual(
    target: list[float], bound: float, slack: float, shipped: dict[str, Robot]
) -> None:
    robot = shipped["default"]
    res = solve_numeric(robot, target, options=NumericIKOptions(restarts=3))
    assert isinstance(res, NumericIKResult)
    assert res.success is False and res.reason is NumericIKReason.MAX_ITERATIONS
    assert res.starts == 2 + 3
    e = task_error(robot, res.q, np.array(target))
    assert res.residual == pytest.approx(float(np.linalg.norm(e)), abs=1e-12)
    assert bound - 1e-12 <= res.residual <= bound + slack, res.residual  # the workspace distance, closed form
    lo, hi = limits(robot)
    assert np.all(res.q >= lo) and np.all(res.q <= hi)


def test_target_outside_the_joint_limits_fails(shipped: dict[str, Robot]) -> None:
    """Behind the shoulder (J1 +/-132 deg): geometrically at reach, outside the limits."""
    robot = shipped["default"]
    assert solve(robot.kinematics.geometry, [-0.3, 0.0, -0.05, 0.0]).status.name == "J1_LIMIT"
    res = solve_numeric(robot, [-0.3, 0.0, -0.05, 0.0], options=NumericIKOptions(restarts=3))
    assert not res.success and res.residual > 1e-3
    assert res.residual == pytest.approx(float(np.linalg.norm(task_error(robot, res.q, np.array([-0.3, 0, -0.05, 0])))),
                                         abs=1e-12)  # fmt: skip


# ============================================================================== options and inputs
@pytest.mark.parametrize(
    ("field", "value"),
    [("tol", 0.0), ("tol", -1e-9), ("tol", math.nan), ("tol", math.inf), ("damping", 0.0), ("damping", -1.0),
     ("max_iterations", 0), ("max_iterations", -3), ("max_iterations", 2.5), ("restarts", -1), ("restarts", 1.5)],
)  # fmt: skip
def test_options_are_validated(field: str, value: float) -> None:
    with pytest.raises(ParameterError) as info:
        NumericIKOptions(**{field: value})
    assert info.value.name == field
    assert field in str(info.value)


def test_options_are_frozen() -> None:
    opts = NumericIKOptions()
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.tol = 1.0  # type: ignore[misc]


@pytest.mark.parametrize("target", [[0.3, 0.0, 0.0], [0.3, 0.0, math.nan, 0.0], [0.3, 0.0, 0.0, math.inf]])
def test_bad_target_is_refused(target: list[float], shipped: dict[str, Robot]) -> None:
    with pytest.raises(ParameterError):
        solve_numeric(shipped["default"], target)


def test_bad_start_is_refused(shipped: dict[str, Robot]) -> None:
    with pytest.raises(ParameterError):
        solve_numeric(shipped["default"], [0.3, 0.0, -0.05, 0.0], q0=[0.0, 0.0, 0.0])


# ============================================================================== cross-validation report
@pytest.mark.parametrize("name", scara_pin.available_robots())
def test_validate_ik_passes_on_every_shipped_robot(name: str, shipped: dict[str, Robot]) -> None:
    n = 1000
    report = validate_ik(shipped[name], n, seed=2024)
    assert report.ok, report.table()
    assert report.samples == n and report.seed == 2024
    assert report.solutions >= n  # every sampled q has at least itself as a solution
    assert report.fk_fail == report.sample_missing == report.numeric_fail == report.numeric_mismatch == 0
    assert report.worst_pose_error <= 1e-9 and report.worst_sample_distance <= 1e-9
    assert report.worst_numeric_distance <= 1e-9
    assert report.failures == []
    assert report.time_closed > 0 and report.time_numeric > 0
    assert "PASS" in report.table() and "FAIL" not in report.table()


def _perturbed_solve(real: Callable[..., IKResult], delta: float) -> Callable[..., IKResult]:

    def wrapped(*args: Any, **kwargs: Any) -> IKResult:
        res = real(*args, **kwargs)
        sols = tuple(dataclasses.replace(s, q=s.q + delta) for s in res.solutions)
        return dataclasses.replace(res, solutions=sols)

    return wrapped


def test_validate_ik_can_fail_on_a_perturbed_closed_form(
    monkeypatch: pytest.MonkeyPatch, shipped: dict[str, Robot]
) -> None:
    kin = shipped["default"].kinematics
    monkeypatch.setattr(kin, "solve", _perturbed_solve(kin.solve, 1e-6))
    report = validate_ik(shipped["default"], 40, seed=5)
    assert report.ok is False
    assert report.fk_fail > 0 and report.sample_missing == 40
    assert report.worst_pose_error > 1e-7
    assert report.failures and "FAIL" in report.table()


def test_validate_ik_can_fail_on_a_perturbed_numeric_ik(
    monkeypatch: pytest.MonkeyPatch, shipped: dict[str, Robot]
) -> None:
    real = scara_pin.kinematics.validate.solve_numeric

    def shifted(*args: Any, **kwargs: Any) -> NumericIKResult:
        res = real(*args, **kwargs)
        return dataclasses.replace(res, q=res.q + 1e-6)

    monkeypatch.setattr(scara_pin.kinematics.validate, "solve_numeric", shifted)
    report = validate_ik(shipped["s1"], 30, seed=6)
    assert report.ok is False and report.numeric_mismatch == 30 and report.fk_fail == 0


LIFT_FIRST = """<?xml version="1.0"?>
<robot name="lift_first">
  <link name="base_link"/><link name="carriage"/><link name="arm1"/><link name="arm2"/><link name="flange"/>
  <link name="tool0"/>
  <joint name="lift" type="prismatic"><parent link="base_link"/><child link="carriage"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/><limit lower="0" upper="0.145" velocity="0" effort="1"/></joint>
  <joint name="j1" type="revolute"><parent link="carriage"/><child link="arm1"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-2.618" upper="2.618" velocity="0" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="arm1"/><child link="arm2"/>
    <origin xyz="0.3917 0 0"/><axis xyz="0 0 1"/><limit lower="-2.53" upper="2.53" velocity="0" effort="1"/></joint>
  <joint name="j4" type="revolute"><parent link="arm2"/><child link="flange"/>
    <origin xyz="0.2585 0 -0.03"/><axis xyz="0 0 1"/><limit lower="-6.98" upper="6.98" velocity="0" effort="1"/></joint>
  <joint name="tool" type="fixed"><parent link="flange"/><child link="tool0"/>
    <origin xyz="0 0.05 -0.1" rpy="3.141592653589793 0 0"/></joint>
</robot>
"""


@pytest.mark.parametrize("which", ["negative_axes", "lift_first"])
def test_validate_ik_on_hand_written_urdfs(which: str) -> None:
    """The three checks on the default arm with every axis written as -z, and on an ABB IRB 920-like arm
    with the prismatic joint first (the whole arm lifts), velocity limits written as 0 and a tool offset."""
    if which == "negative_axes":
        urdf = load_robot("default").urdf.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 -1"/>')
        assert urdf.count('<axis xyz="0 0 -1"/>') == 4
    else:
        urdf = LIFT_FIRST
    robot = robot_from_urdf(urdf, origin=which)
    report = validate_ik(robot, 200, seed=9)
    assert report.ok, report.table()
    assert report.solutions >= 200
