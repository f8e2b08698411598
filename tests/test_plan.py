"""scara_pin.motion.plan: which method a request gets, and that the trajectory it makes is the right one.

Expected values from closed forms written here: the jtraj quintic 10 x^3 - 15 x^4 + 6 x^5, the
time-optimal synchronised line duration T* = 1/V + V/A (or 2 sqrt(1/A)), FK of the end configuration.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from scara_pin import InvalidInputError, ParameterError, Robot, load_robot
from scara_pin.motion.payload import Payload
from scara_pin.motion.plan import Method, MotionRequest, plan_motion

Q0 = np.array([0.2, 0.6, 0.01, 0.1])
Q1 = np.array([0.9, 1.3, 0.04, -0.4])
POSE_TOL = 1e-9


def _line_duration(robot: Robot, q0: np.ndarray, q1: np.ndarray) -> float:
    dq = np.abs(q1 - q0)
    V = min(v / d for v, d in zip(robot.limits.velocity, dq) if d > 0)
    A = min(a / d for a, d in zip(robot.limits.acceleration, dq) if d > 0)
    return 1.0 / V + V / A if V * V / A < 1.0 else 2.0 * math.sqrt(1.0 / A)


def test_duration_without_via_is_the_jtraj_quintic(robot_default: Robot) -> None:
    plan = plan_motion(robot_default, MotionRequest(start_q=Q0, end_q=Q1, duration=2.0))
    assert plan.method is Method.JOINT_QUINTIC and plan.arch is None
    for t in np.linspace(0.0, 2.0, 11):
        x = t / 2.0
        expected = Q0 + (Q1 - Q0) * (10 * x**3 - 15 * x**4 + 6 * x**5)
        assert np.abs(plan.trajectory.sample(t)[0] - expected).max() <= 1e-12


def test_no_duration_no_via_is_the_time_optimal_line(robot_default: Robot) -> None:
    plan = plan_motion(robot_default, MotionRequest(start_q=Q0, end_q=Q1))
    assert plan.method is Method.JOINT_TRAPEZOID
    assert plan.trajectory.duration == pytest.approx(_line_duration(robot_default, Q0, Q1), rel=1e-12)


def test_vias_and_tool_speed_choose_toppra_or_the_spline(robot_default: Robot) -> None:
    via = (Q0 + Q1) / 2 + np.array([0.1, -0.1, 0.0, 0.0])
    timed = plan_motion(robot_default, MotionRequest(start_q=Q0, end_q=Q1, vias=(via,), duration=3.0))
    assert timed.method is Method.JOINT_SPLINE_QUINTIC and timed.trajectory.duration == pytest.approx(3.0, abs=1e-12)
    optimal = plan_motion(robot_default, MotionRequest(start_q=Q0, end_q=Q1, vias=(via,)))
    assert optimal.method is Method.JOINT_TOPPRA
    slow = plan_motion(robot_default, MotionRequest(start_q=Q0, end_q=Q1, tool_speed=0.05))
    assert slow.method is Method.JOINT_TOPPRA
    for plan in (timed, optimal, slow):  # through the waypoints, from rest to rest
        assert np.abs(plan.trajectory.q_start - Q0).max() <= 1e-9
        assert np.abs(plan.trajectory.q_end - Q1).max() <= 1e-9
    # a tool speed limit makes the move slower than the joint limits alone
    assert slow.trajectory.duration > _line_duration(robot_default, Q0, Q1)


def test_pose_endpoints_are_solved_by_ik(robot_default: Robot) -> None:
    pose = np.array(robot_default.tool_pose(Q1))
    plan = plan_motion(robot_default, MotionRequest(start_q=Q0, end_pose=pose, duration=1.5))
    assert plan.method is Method.JOINT_QUINTIC
    reached = np.array(robot_default.tool_pose(plan.trajectory.q_end))
    assert np.abs(reached[:3] - pose[:3]).max() <= POSE_TOL
    assert abs(math.remainder(reached[3] - pose[3], 2 * math.pi)) <= POSE_TOL


def test_linear_moves_keep_the_tool_on_the_line(robot_default: Robot) -> None:
    p0, p1 = np.array([0.30, -0.05, -0.08, 0.1]), np.array([0.30, 0.12, -0.06, 0.4])
    for duration, method in ((2.0, Method.LINE_QUINTIC), (None, Method.LINE_TOPPRA)):
        plan = plan_motion(robot_default, MotionRequest(start_pose=p0, end_pose=p1, linear=True, duration=duration))
        assert plan.method is method
        traj = plan.trajectory
        for t in np.linspace(0.0, traj.duration, 9):
            p = np.array(robot_default.tool_pose(traj.sample(t)[0]))
            # on the segment: the component of p - p0 across the line is zero
            d = (p1 - p0)[:3] / np.linalg.norm((p1 - p0)[:3])
            off = (p - p0)[:3] - np.dot((p - p0)[:3], d) * d
            assert np.linalg.norm(off) <= 1e-9


def test_arch_returns_the_move(robot_default: Robot) -> None:
    p0, p1 = np.array([0.30, -0.10, -0.09, 0.0]), np.array([0.25, 0.15, -0.09, 0.3])
    plan = plan_motion(robot_default, MotionRequest(start_pose=p0, end_pose=p1, arch=True, path="lines"))
    assert plan.method is Method.ARCH and plan.arch is not None
    assert plan.trajectory is plan.arch.trajectory
    top = max(robot_default.tool_pose(q)[2] for q in plan.trajectory.sample(np.linspace(0, plan.trajectory.duration,
                                                                                         201))[0])  # fmt: skip
    assert top > -0.09 + 0.01  # it lifts


def test_refusals() -> None:
    pal = load_robot("palletizer")
    q0 = (np.array(pal.limits.lower) + np.array(pal.limits.upper)) / 2
    with pytest.raises(InvalidInputError, match="SCARA-only"):
        plan_motion(pal, MotionRequest(start_q=q0, end_q=q0 + 0.1, linear=True))
    with pytest.raises(InvalidInputError, match="SCARA-only"):
        plan_motion(pal, MotionRequest(start_q=q0, end_q=q0 + 0.1, arch=True, path="lines"))
    default = load_robot("default")
    with pytest.raises(InvalidInputError, match="--torque"):
        plan_motion(default, MotionRequest(start_q=Q0, end_q=Q1, payload=Payload(1.0, (0.0, 0.0, 0.0))))
    with pytest.raises(InvalidInputError, match="exactly one start"):
        MotionRequest(start_q=Q0, start_pose=np.zeros(4), end_q=Q1)
    with pytest.raises(InvalidInputError, match="exactly one end"):
        MotionRequest(start_q=Q0)
    with pytest.raises(InvalidInputError, match="straight-leg arch takes no via"):
        MotionRequest(start_pose=np.zeros(4), end_pose=np.ones(4), arch=True, vias=(Q0,), path="lines")
    with pytest.raises(ParameterError, match="duration"):
        MotionRequest(start_q=Q0, end_q=Q1, duration=-1.0)


def test_limits_of_a_request(robot_default: Robot) -> None:
    """``limits`` time a joint move under other limits (a job's speed override); refused where they cannot act."""
    from dataclasses import replace

    lim = robot_default.limits
    half = replace(lim, velocity=tuple(v / 2 for v in lim.velocity))
    d = np.abs(Q1 - Q0)
    v, a = np.array(half.velocity), np.array(half.acceleration)
    one = np.where(d >= v * v / a, d / v + v / a, 2 * np.sqrt(d / a))  # each joint alone, rest to rest
    plan = plan_motion(robot_default, MotionRequest(start_q=Q0, end_q=Q1, limits=half))
    assert plan.method is Method.JOINT_TRAPEZOID
    assert plan.trajectory.duration == pytest.approx(float(np.max(one)), abs=1e-12)
    with pytest.raises(InvalidInputError, match="time-optimal"):
        MotionRequest(start_q=Q0, end_q=Q1, duration=1.0, limits=half)
    with pytest.raises(InvalidInputError, match="straight-leg arch"):
        MotionRequest(start_pose=np.zeros(4), end_pose=np.ones(4), arch=True, path="lines", limits=half)
