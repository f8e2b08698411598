"""Paths, time laws, the Trajectory object, export and setpoints (scara_pin.motion.trajectory), and the plots.

Expected values come from independent routes: the jtraj closed forms and the synchronised-line optimum
written here, Pinocchio FK for the tool on the line, finite differences for derivatives, the closed-form
IK for where a line fails. Tolerances are stated at each check.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from scara_pin import InfeasibleError, InvalidInputError, ParameterError, Robot
from scara_pin.files import atomic_output
from scara_pin.kinematics.scara import IKStatus, branch_of
from scara_pin.motion.trajectory import (
    CSV_HEADER,
    JointLine,
    MotorUnits,
    PathError,
    Samples,
    cartesian_path,
    joint_path,
    joint_pose,
    line_optimal_duration,
    load_samples,
    load_trajectory,
    quintic,
    quintic_min_duration,
    timed,
    trapezoidal,
)

S1_Q0 = np.zeros(4)
S1_Q1 = np.array([math.pi / 2, math.pi / 3, 0.05, -math.pi])  # S1's 50 mm quill move, in metres
S1_T = 5.0


# ---------------------------------------------------------------------------------------------- S1 jtraj
def test_s1_quintic_boundary_conditions_and_polynomial() -> None:
    tr = quintic(S1_Q0, S1_Q1, S1_T)
    assert tr.duration == S1_T
    q, qd, qdd = tr.sample(np.array([0.0, S1_T]))
    np.testing.assert_allclose(q, [S1_Q0, S1_Q1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)
    np.testing.assert_allclose(qdd, 0.0, atol=1e-12)
    t = np.linspace(0.0, S1_T, 101)
    x = (t / S1_T)[:, None]
    expected = S1_Q0 + (S1_Q1 - S1_Q0) * (10 * x**3 - 15 * x**4 + 6 * x**5)  # jtraj's quintic
    np.testing.assert_allclose(tr.sample(t)[0], expected, rtol=0, atol=1e-12)


def test_s1_quintic_analytic_peaks() -> None:
    tr = quintic(S1_Q0, S1_Q1, S1_T)
    dq = S1_Q1 - S1_Q0
    v_peak = 1.875 * dq / S1_T
    a_peak = (10 / math.sqrt(3)) * dq / S1_T**2
    t_acc = S1_T * (0.5 - math.sqrt(3) / 6)
    # at the analytic instants: 1e-12 relative
    np.testing.assert_allclose(tr.sample(S1_T / 2)[1], v_peak, rtol=1e-12)
    np.testing.assert_allclose(tr.sample(t_acc)[2], a_peak, rtol=1e-12)
    np.testing.assert_allclose(tr.sample(S1_T - t_acc)[2], -a_peak, rtol=1e-12)
    # dense sampling (0.1 ms): the peaks are the maxima, and nowhere exceeded (1e-12 relative)
    t = np.linspace(0.0, S1_T, 50_001)
    _, qd, qdd = tr.sample(t)
    np.testing.assert_array_less(np.abs(qd).max(axis=0), np.abs(v_peak) * (1 + 1e-12) + 1e-300)
    np.testing.assert_array_less(np.abs(qdd).max(axis=0), np.abs(a_peak) * (1 + 1e-12) + 1e-300)
    np.testing.assert_allclose(np.abs(qd).max(axis=0), np.abs(v_peak), rtol=1e-8)
    np.testing.assert_allclose(np.abs(qdd).max(axis=0), np.abs(a_peak), rtol=1e-7)
    assert t[np.argmax(np.abs(qd[:, 0]))] == pytest.approx(S1_T / 2, abs=1e-4)
    assert t[np.argmax(qdd[:, 0])] == pytest.approx(t_acc, abs=1e-4)


def test_quintic_derivatives_match_finite_differences() -> None:
    tr = quintic(S1_Q0, S1_Q1, S1_T)
    t = np.linspace(0.2, 4.8, 24)
    h = 1e-5
    q_p, qd_p, _ = tr.sample(t + h)
    q_m, qd_m, _ = tr.sample(t - h)
    _, qd, qdd = tr.sample(t)
    np.testing.assert_allclose((q_p - q_m) / (2 * h), qd, atol=1e-9)  # central differences: O(h^2)
    np.testing.assert_allclose((qd_p - qd_m) / (2 * h), qdd, atol=1e-9)


def test_quintic_min_duration_touches_a_limit(robot_s1: Robot) -> None:
    v, a = np.array(robot_s1.limits.velocity), np.array(robot_s1.limits.acceleration)
    T = quintic_min_duration(S1_Q0, S1_Q1, v, a)
    assert T < S1_T  # S1's 5 s move is within the s1 robot's limits
    _, qd, qdd = quintic(S1_Q0, S1_Q1, T).sample(np.linspace(0, T, 20_001))
    worst = max(np.max(np.abs(qd) / v), np.max(np.abs(qdd) / a))
    assert worst == pytest.approx(1.0, abs=1e-8)


def test_quintic_refuses_bad_input() -> None:
    with pytest.raises(ParameterError, match="duration"):
        quintic(S1_Q0, S1_Q1, 0.0)
    with pytest.raises(ParameterError, match="finite"):
        quintic(S1_Q0, [0, 0, math.nan, 0], 1.0)
    with pytest.raises(ParameterError, match="4 numbers"):
        quintic(S1_Q0, [0, 0, 0], 1.0)


# ---------------------------------------------------------------------------------------------- trapezoid
def _t_star(dq: np.ndarray, v: np.ndarray, a: np.ndarray) -> float:
    """The synchronised line's optimum, written independently of the package."""
    moving = np.abs(dq) > 0
    V = min(v[moving] / np.abs(dq[moving]))
    A = min(a[moving] / np.abs(dq[moving]))
    return 1 / V + V / A if V * V / A < 1 else 2 * math.sqrt(1 / A)


@pytest.mark.parametrize("name", ["default", "s1"])
def test_trapezoid_reaches_t_star_and_never_exceeds_a_limit(robots: dict[str, Robot], name: str) -> None:
    robot = robots[name]
    v, a = np.array(robot.limits.velocity), np.array(robot.limits.acceleration)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    rng = np.random.default_rng(7)
    reached_velocity = 0
    for _ in range(25):
        q0, q1 = rng.uniform(lo, hi), rng.uniform(lo, hi)
        if rng.random() < 0.3:  # short moves: the triangular (velocity not reached) case
            q1 = q0 + 0.02 * (q1 - q0)
        tr = trapezoidal(q0, q1, v, a)
        T_star = _t_star(q1 - q0, v, a)
        assert tr.duration == pytest.approx(T_star, rel=1e-12)
        assert line_optimal_duration(q0, q1, v, a) == pytest.approx(T_star, rel=1e-12)
        t = np.linspace(0.0, tr.duration, 20_001)
        q, qd, qdd = tr.sample(t)
        np.testing.assert_allclose(q[[0, -1]], [q0, q1], atol=1e-12)
        rv = np.abs(qd).max(axis=0) / v
        ra = np.abs(qdd).max(axis=0) / a
        assert rv.max() <= 1 + 1e-12 and ra.max() <= 1 + 1e-12
        assert ra.max() == pytest.approx(1.0, abs=1e-12)  # the binding joint accelerates at its limit
        reached_velocity += rv.max() > 1 - 1e-9
        # synchronised: every joint is at the same fraction of its move at every instant
        frac = (q - q0) / (q1 - q0)
        np.testing.assert_allclose(frac, frac[:, :1] * np.ones((1, 4)), atol=1e-9)
        # T* is the optimum: any shorter duration is refused; a longer one keeps the limits
        with pytest.raises(InfeasibleError):
            trapezoidal(q0, q1, v, a, duration=T_star * (1 - 1e-6))
        slow = trapezoidal(q0, q1, v, a, duration=1.5 * T_star)
        assert slow.duration == pytest.approx(1.5 * T_star, rel=1e-12)
        _, qd_s, qdd_s = slow.sample(np.linspace(0, slow.duration, 5001))
        assert (np.abs(qd_s) <= v * (1 + 1e-12)).all() and (np.abs(qdd_s) <= a * (1 + 1e-12)).all()
        np.testing.assert_allclose(slow.q_end, q1, atol=1e-12)
    assert reached_velocity > 0  # the trapezoidal (velocity-limited) case was exercised


def test_trapezoid_refuses_no_motion_and_bad_limits(robot_default: Robot) -> None:
    v, a = robot_default.limits.velocity, robot_default.limits.acceleration
    with pytest.raises(ParameterError, match="nothing to move"):
        trapezoidal(S1_Q1, S1_Q1, v, a)
    with pytest.raises(ParameterError, match="joint2_velocity"):
        trapezoidal(S1_Q0, S1_Q1, (1.0, 0.0, 1.0, 1.0), a)
    with pytest.raises(ParameterError, match="joint1_acceleration"):
        trapezoidal(S1_Q0, S1_Q1, v, (math.nan, 1.0, 1.0, 1.0))


# ---------------------------------------------------------------------------------------------- Cartesian lines
def _random_line(robot: Robot, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A start configuration (away from the singularity) and a line from its pose that is feasible."""
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    while True:
        q0 = rng.uniform(0.7 * lo, 0.7 * hi)
        q0[1] = rng.choice([-1, 1]) * rng.uniform(0.4, 2.2)
        p0 = robot.tool_pose(q0)
        p1 = p0 + np.concatenate([rng.uniform(-0.08, 0.08, 2), rng.uniform(-0.02, 0.02, 1), rng.uniform(-1, 1, 1)])
        try:
            cartesian_path(robot, [p0, p1], start=q0)
        except PathError:
            continue
        return q0, p0, p1


def _line_errors(robot: Robot, q: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> tuple[float, float]:
    """Largest distance of the FK tool points from the line p0-p1 [m], and yaw error vs the position [rad]."""
    P = np.array([robot.tool_pose(x) for x in q])
    d = p1[:3] - p0[:3]
    w = P[:, :3] - p0[:3]
    s = w @ d / (d @ d)
    dist = np.linalg.norm(w - s[:, None] * d, axis=1).max()
    yaw_err = np.abs(np.remainder(P[:, 3] - (p0[3] + s * (p1[3] - p0[3])) + math.pi, 2 * math.pi) - math.pi).max()
    return float(dist), float(yaw_err)


def test_cartesian_line_stays_on_the_line_on_one_branch(robot_default: Robot) -> None:
    robot = robot_default
    geo = robot.kinematics.geometry
    rng = np.random.default_rng(11)
    for _ in range(8):
        q0, p0, p1 = _random_line(robot, rng)
        path = cartesian_path(robot, [p0, p1], start=q0)
        assert path.branch == branch_of(geo, q0)
        tr = timed(path, 0.8)
        t = tr.times(1000.0)
        q = tr.sample(t)[0]
        dist, yaw_err = _line_errors(robot, q, p0, p1)
        assert dist < 1e-9  # [m], Pinocchio FK at every 1 kHz sample
        assert yaw_err < 1e-9  # [rad], the yaw is linear in the position along the line
        assert {branch_of(geo, x) for x in q} == {path.branch}  # the branch never flips
        assert np.abs(np.diff(q, axis=0)).max() < 0.05  # continuous: no 2 pi jump of J4 between samples
        np.testing.assert_allclose(tr.q_start, q0, atol=1e-12)
        end = robot.tool_pose(tr.q_end)
        np.testing.assert_allclose(end[:3], p1[:3], atol=1e-9)
        assert abs(math.remainder(end[3] - p1[3], 2 * math.pi)) < 1e-9


def test_cartesian_checkpoints_n_points_and_max_step(robot_default: Robot) -> None:
    robot = robot_default
    q0, p0, p1 = _random_line(robot, np.random.default_rng(3))
    path = cartesian_path(robot, [p0, p1], start=q0, n=11)
    s, q = path.checkpoints[0]
    np.testing.assert_allclose(s, np.linspace(0, 1, 11), atol=0)
    for sj, qj in zip(s, q):  # S4: p_j = p_0 + j (p* - p_0) / n, solved by IK
        np.testing.assert_allclose(robot.tool_pose(qj), p0 + sj * (p1 - p0), atol=1e-12)
    path = cartesian_path(robot, [p0, p1], start=q0, max_step=0.01, max_yaw_step=10.0)
    s, _ = path.checkpoints[0]
    assert np.diff(s).max() * np.linalg.norm(p1[:3] - p0[:3]) <= 0.01 + 1e-12
    assert np.diff(s).max() * np.linalg.norm(p1[:3] - p0[:3]) > 0.005
    with pytest.raises(InvalidInputError):
        cartesian_path(robot, [p0, p1], start=q0, n=5, max_step=0.01)
    with pytest.raises(ParameterError):
        cartesian_path(robot, [p0, p1], start=q0, n=1)
    with pytest.raises(ParameterError, match="start"):
        cartesian_path(robot, [p0 + [0.01, 0, 0, 0], p1], start=q0)
    with pytest.raises(ParameterError, match="shape"):
        cartesian_path(robot, [p0], start=q0)


def test_cartesian_segment_derivatives_match_finite_differences(robot_default: Robot) -> None:
    q0, p0, p1 = _random_line(robot_default, np.random.default_rng(5))
    seg = cartesian_path(robot_default, [p0, p1], start=q0).segments[0]
    s = np.linspace(0.05, 0.95, 9)
    h = 1e-6
    q, dq, ddq = seg.evaluate(s)
    qp, dqp, _ = seg.evaluate(s + h)
    qm, dqm, _ = seg.evaluate(s - h)
    scale_1 = np.abs(dq).max()
    scale_2 = np.abs(ddq).max() + scale_1
    np.testing.assert_allclose((qp - qm) / (2 * h), dq, atol=1e-7 * scale_1)  # FD error ~ h^2 q''' + eps/h
    np.testing.assert_allclose((dqp - dqm) / (2 * h), ddq, atol=1e-6 * scale_2)  # checks Pinocchio's dJ/dt route


def test_cartesian_via_points(robot_default: Robot) -> None:
    robot = robot_default
    q0 = np.array([0.2, 1.3, 0.02, 0.4])
    p0 = robot.tool_pose(q0)
    poses = [p0, p0 + [-0.06, 0.04, 0.02, 0.5], p0 + [-0.1, -0.05, 0.0, -0.3]]
    path = cartesian_path(robot, poses, start=q0)
    assert len(path.segments) == 2
    tr = timed(path, 1.2)
    assert len(tr.pieces) == 2 and tr.duration == pytest.approx(1.2, rel=1e-12)
    for k in range(2):
        t = np.linspace(tr.starts[k], tr.starts[k + 1], 301)
        dist, yaw_err = _line_errors(robot, tr.sample(t)[0], np.array(poses[k]), np.array(poses[k + 1]))
        assert dist < 1e-9 and yaw_err < 1e-9
    q_via, qd_via, _ = tr.sample(tr.starts[1])
    np.testing.assert_allclose(robot.tool_pose(q_via)[:3], poses[1][:3], atol=1e-9)
    np.testing.assert_allclose(qd_via, 0.0, atol=1e-12)  # the tool stops where the line turns
    q = tr.sample(tr.times(1000.0))[0]
    assert {branch_of(robot.kinematics.geometry, x) for x in q} == {path.branch}


def test_line_leaving_the_workspace_fails_where_the_arm_stretches(robot_default: Robot) -> None:
    robot = robot_default  # l1 + l2 = 0.4 m, tool on the J4 axis: the reach ends at x = 0.4 m
    z = -0.05
    with pytest.raises(PathError) as info:
        cartesian_path(robot, [[0.3, 0.0, z, 0.0], [0.5, 0.0, z, 0.0]])
    err = info.value
    assert err.exit_code == 3
    assert err.s == pytest.approx(0.5, abs=1e-9)  # x = 0.3 + 0.2 s = 0.4
    np.testing.assert_allclose(err.pose, [0.4, 0.0, z, 0.0], atol=1e-9)
    assert "singularity" in err.reason or "OUT_OF_REACH" in err.reason
    # independently: the closed form solves just before, not just after
    assert robot.ik([0.3 + 0.2 * (err.s - 1e-6), 0.0, z, 0.0]).success
    assert robot.ik([0.3 + 0.2 * (err.s + 1e-6), 0.0, z, 0.0]).status is IKStatus.OUT_OF_REACH


def test_line_through_the_inner_limit_fails_at_the_first_unsolvable_point(robot_default: Robot) -> None:
    robot = robot_default
    a, b = np.array([0.25, 0.05, -0.05, 0.0]), np.array([-0.25, 0.05, -0.05, 0.0])
    with pytest.raises(PathError) as info:
        cartesian_path(robot, [a, b], branch="right")
    s = info.value.s
    assert 0.0 < s < 1.0
    np.testing.assert_allclose(info.value.pose, a + s * (b - a), atol=1e-12)
    before = robot.ik(a + (s - 1e-7) * (b - a), branch="right")
    after = robot.ik(a + (s + 1e-7) * (b - a), branch="right")
    assert before.success and before.branch("right")
    assert not after.success  # the wrist enters the annulus excluded by joint2's +/-150 deg
    assert info.value.status in (IKStatus.J2_LIMIT, IKStatus.INSIDE_INNER_LIMIT)


def test_j4_reaching_its_limit_is_a_path_error_not_a_jump(robot_default: Robot) -> None:
    robot = robot_default
    q0 = np.array([0.3, 1.0, 0.02, 6.1])  # J4 0.183 rad below its +360 deg limit
    p0 = robot.tool_pose(q0)
    dyaw_dq4 = robot.task_jacobian(q0)[3, 3]  # +1 or -1: the sign of J4 in the yaw
    turn = 0.6 * np.sign(dyaw_dq4)  # the yaw turn that drives J4 up into its limit
    with pytest.raises(PathError) as info:
        cartesian_path(robot, [p0, p0 + [0, 0, 0, turn]], start=q0)
    s_limit = (robot.limits.upper[3] - q0[3]) / 0.6  # J4 moves 0.6 rad over the line
    assert info.value.s == pytest.approx(s_limit, abs=1e-9)
    assert "joint4" in info.value.reason and "turn" in info.value.reason
    # the other way is fine: J4 moves away from its limit
    cartesian_path(robot, [p0, p0 + [0, 0, 0, -turn]], start=q0)


def test_s4_example_line_starts_at_the_stretched_singularity(robot_default: Robot) -> None:
    # S4's example: from the zero pose (400, 0, -50 mm, 0) to (300, 0, -20 mm, 45 deg); at q = 0 the arm is
    # stretched, so a straight line from there needs infinite joint speed: refused, at s = 0.
    with pytest.raises(PathError) as info:
        cartesian_path(robot_default, [[0.4, 0, -0.05, 0], [0.3, 0, -0.02, math.pi / 4]], start=np.zeros(4))
    assert info.value.s == 0.0 and "singularity" in info.value.reason
    # a millimetre inside the reach it works, on the line
    path = cartesian_path(robot_default, [[0.399, 0, -0.05, 0], [0.3, 0, -0.02, math.pi / 4]])
    q = timed(path, 1.0).sample(np.linspace(0, 1, 501))[0]
    ends = np.array([[0.399, 0, -0.05, 0], [0.3, 0, -0.02, math.pi / 4]])
    assert _line_errors(robot_default, q, ends[0], ends[1])[0] < 1e-9


def test_joint_pose_unwraps_the_yaw_so_lines_end_at_the_joints(robot_default: Robot) -> None:
    robot = robot_default
    qa = np.array([0.9, 1.2, 0.02, 0.9])  # yaw = q1 + q2 + q4 = 3.0 rad
    qb = np.array([1.0, 1.1, 0.03, 1.3])  # 3.4 rad: FK wraps it to 3.4 - 2 pi
    pa, pb = joint_pose(robot, qa), joint_pose(robot, qb)
    assert pb[3] == pytest.approx(3.4, abs=1e-12) and robot.tool_pose(qb)[3] < 0
    assert math.remainder(pb[3] - robot.tool_pose(qb)[3], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    path = cartesian_path(robot, [pa, pb], start=qa, end=qb)  # turns +0.4 rad through pi, not -5.9 rad
    np.testing.assert_allclose(path.q_end, qb, atol=1e-9)
    with pytest.raises(PathError):  # with FK's wrapped yaw the line turns the long way and ends elsewhere
        cartesian_path(robot, [pa, robot.tool_pose(qb)], start=qa, end=qb)


def test_line_ending_on_another_branch_than_requested(robot_default: Robot) -> None:
    robot = robot_default
    q0 = np.array([0.2, 1.2, 0.02, 0.3])
    p0 = robot.tool_pose(q0)
    p1 = p0 + [-0.05, 0.02, 0.0, 0.2]
    path = cartesian_path(robot, [p0, p1], start=q0)
    other = [s for s in robot.ik(p1).solutions if s.branch != path.branch][0].q
    with pytest.raises(PathError, match="requested end") as info:
        cartesian_path(robot, [p0, p1], start=q0, end=other)
    assert info.value.s == 1.0
    cartesian_path(robot, [p0, p1], start=q0, end=path.q_end)  # its own end is accepted


# ---------------------------------------------------------------------------------------------- joint paths
def test_joint_path_checks_waypoints_and_overshoot(robot_default: Robot) -> None:
    robot = robot_default
    assert isinstance(joint_path(robot, [S1_Q0, S1_Q0, [0.1, 0.2, 0.01, 0.3]]), JointLine)  # duplicates merged
    with pytest.raises(ParameterError, match="nothing to move"):
        joint_path(robot, [S1_Q0, S1_Q0])
    with pytest.raises(ParameterError, match="outside"):
        joint_path(robot, [S1_Q0, [3.0, 0, 0, 0]])
    # a spline through the quill's stroke ends overshoots them between waypoints
    with pytest.raises(PathError, match="joint3") as info:
        joint_path(robot, [[0, 0, -0.05, 0], [0.5, 0, 0.1, 0], [1.0, 0, -0.05, 0], [1.5, 0, 0.1, 0]])
    assert 0 < info.value.s < 1
    path = joint_path(robot, [[0, 0, 0, 0], [0.5, 0.3, 0.02, 1], [1.0, -0.2, 0.05, 0.5], [0.2, 0.4, 0.0, -1]])
    np.testing.assert_allclose(path(path.knots()), path.waypoints, atol=1e-12)  # through the waypoints


# ---------------------------------------------------------------------------------------------- trajectory object
def test_sample_is_vectorised_and_holds_outside(robot_default: Robot) -> None:
    tr = quintic(S1_Q0, S1_Q1, 2.0)
    t = np.array([-1.0, 0.0, 0.3, 1.0, 2.0, 2.5])
    q, qd, qdd = tr.sample(t)
    for k, tk in enumerate(t):
        qs, qds, qdds = tr.sample(float(tk))
        np.testing.assert_array_equal(q[k], qs)
        np.testing.assert_array_equal(qd[k], qds)
        np.testing.assert_array_equal(qdd[k], qdds)
    np.testing.assert_array_equal(q[0], S1_Q0)
    np.testing.assert_array_equal(q[-1], S1_Q1)
    assert not qd[[0, -1]].any() and not qdd[[0, -1]].any()
    times = tr.times(300.0)  # 2 s is not a whole number of 1/300 s periods... it is: 600 periods
    assert len(times) == 601 and times[-1] == pytest.approx(2.0)
    times = quintic(S1_Q0, S1_Q1, 1.0005).times(1000.0)
    np.testing.assert_allclose(np.diff(times), 1e-3, rtol=1e-9)
    assert times[0] == 0 and 1.0005 <= times[-1] < 1.0005 + 1e-3


def test_concatenation_requires_continuity() -> None:
    a = quintic(S1_Q0, S1_Q1, 1.0)
    b = quintic(S1_Q1, S1_Q0, 2.0)
    ab = a.then(b)
    assert ab.duration == 3.0
    np.testing.assert_allclose(ab.sample(1.5)[0], b.sample(0.5)[0], atol=1e-15)
    with pytest.raises(ParameterError, match="must start where"):
        a.then(a)


@pytest.mark.parametrize("fmt", ["csv", "json"])
def test_export_round_trip(tmp_path: Path, fmt: str) -> None:
    tr = quintic(S1_Q0, S1_Q1, S1_T)
    out = tmp_path / f"traj.{fmt}"
    getattr(tr, f"to_{fmt}")(out, rate=50.0)
    back = load_trajectory(out)
    a, b = tr.resample(50.0), back.resample(50.0)
    np.testing.assert_array_equal(a.table(), b.table())  # exact: shortest round-trip float text
    assert back.duration == tr.duration
    # between the samples: the quintic Hermite reproduces a quintic exactly (1e-12)
    t = np.linspace(0, S1_T, 777)
    for x, y in zip(tr.sample(t), back.sample(t)):
        np.testing.assert_allclose(x, y, atol=1e-12)
    if fmt == "csv":
        assert out.read_text().splitlines()[0] == ",".join(CSV_HEADER)
        assert CSV_HEADER == ("t", "q1", "q2", "q3", "q4", "qd1", "qd2", "qd3", "qd4", "qdd1", "qdd2", "qdd3", "qdd4")
    else:
        data = json.loads(out.read_text())
        assert data["rate"] == 50.0 and len(data["t"]) == 251
    again = tmp_path / f"again.{fmt}"
    getattr(back, f"to_{fmt}")(again, rate=50.0)
    assert again.read_text() == out.read_text()
    mask = os.umask(0)
    os.umask(mask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~mask


def test_json_duration_is_the_motions_not_the_grids(tmp_path: Path) -> None:
    """A grid whose last sample falls after the end of the motion (T = 1.2345 s at 10 Hz: samples to 1.3 s)
    records the motion's own duration, T itself; read back, the samples keep it."""
    T = 1.2345
    tr = quintic(S1_Q0, S1_Q1, T)
    out = tr.to_json(tmp_path / "t.json", rate=10.0)
    data = json.loads(out.read_text())
    assert data["t"][-1] == pytest.approx(1.3, abs=1e-15) and data["t"][-2] == pytest.approx(1.2, abs=1e-15)
    assert data["duration"] == T
    assert tr.resample(10.0).to_dict()["duration"] == T
    assert load_samples(out).duration == T
    assert np.array_equal(load_samples(out).q[-1], tr.sample(T)[0])  # the last sample holds the end at rest
    # on the grid (1.25 s at 20 Hz): the motion's end is the last sample
    on_grid = quintic(S1_Q0, S1_Q1, 1.25)
    assert json.loads(on_grid.to_json(tmp_path / "v.json", rate=20.0).read_text())["duration"] == 1.25


@pytest.mark.parametrize("duration", [1.2, 1.3000001, -1.0, math.nan, math.inf])
def test_samples_duration_must_lie_in_the_last_interval(duration: float) -> None:
    t = np.array([0.0, 0.6, 1.2, 1.3])
    with pytest.raises(ParameterError, match="last interval"):
        Samples(t, np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4)), duration)
    assert Samples(t, np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4)), 1.25).duration == 1.25
    assert Samples(t, np.zeros((4, 4)), np.zeros((4, 4)), np.zeros((4, 4))).duration == 1.3


def test_load_refuses_malformed_files(tmp_path: Path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("t,q1\n0,1\n")
    with pytest.raises(InvalidInputError, match="header"):
        load_trajectory(bad)
    good = quintic(S1_Q0, S1_Q1, 1.0).resample(10.0).csv_text().splitlines()
    good[3] = good[3].replace(",", ",x", 1)
    bad.write_text("\n".join(good))
    with pytest.raises(InvalidInputError, match="line 4"):
        load_trajectory(bad)
    (tmp_path / "bad.json").write_text('{"format": "something else"}')
    with pytest.raises(InvalidInputError, match="not a scara-pin"):
        load_trajectory(tmp_path / "bad.json")
    with pytest.raises(InvalidInputError, match="cannot be read"):
        load_trajectory(tmp_path / "missing.csv")
    with pytest.raises(ParameterError, match="increase"):
        Samples(np.array([0.0, 0.0]), np.zeros((2, 4)), np.zeros((2, 4)), np.zeros((2, 4)))


def test_writes_are_atomic(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    tr = quintic(S1_Q0, S1_Q1, 1.0)
    with pytest.raises(InvalidInputError, match="does not exist"):
        tr.to_csv(tmp_path / "nope" / "t.csv")
    assert not (tmp_path / "nope").exists()
    target = tmp_path / "t.csv"
    target.write_text("old content\n")

    def broken_replace(src: object, dst: object) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(InvalidInputError, match="No space left"):
        tr.to_csv(target)
    monkeypatch.undo()
    assert target.read_text() == "old content\n"  # untouched
    with pytest.raises(RuntimeError):
        with atomic_output(target) as tmp:
            tmp.write_text("partial")
            raise RuntimeError("interrupted")
    assert target.read_text() == "old content\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv"]  # no temporary file left


# ---------------------------------------------------------------------------------------------- setpoints
def test_latency_compensation_makes_all_axes_arrive_together() -> None:
    tr = quintic(S1_Q0, S1_Q1, 0.5)
    rate = 1000.0
    n = np.array([1, 2, 3, 4])  # S4: station i receives its command i sigma late; sigma = 1 ms
    sp = tr.setpoints(rate, delays=n / rate)
    assert sp.t[0] == pytest.approx(-4 / rate) and np.allclose(np.diff(sp.t), 1 / rate)
    # simulate the bus: the setpoint sent at t_k reaches axis i at t_k + n_i / rate
    k0 = int(round(-sp.t[0] * rate))
    for k in range(k0, len(sp.t) - 4, 7):  # arrival time t_k + 4 ms, all axes
        t_arr = sp.t[k] + 4 / rate
        received = np.array([sp.q[k + 4 - n[i], i] for i in range(4)])  # what each axis got, arriving at t_arr
        np.testing.assert_allclose(received, tr.sample(t_arr)[0], atol=1e-12)
    # without compensation the late axes lag behind by their delay
    raw = tr.setpoints(rate)
    lag = [abs(raw.q[k, 3] - tr.sample(raw.t[k] + 4 / rate)[0][3]) for k in range(len(raw.t) - 4)]
    assert max(lag) > 1e-3
    with pytest.raises(ParameterError, match="delays"):
        tr.setpoints(rate, delays=[0, -1e-3, 0, 0])


def test_motor_steps_are_integers_without_drift() -> None:
    motor = MotorUnits.from_drive(gear_ratio=(50, 50, 1, 20), steps_per_revolution=(3200, 3200, 800, 1600),
                                  screw_lead=0.01)  # fmt: skip
    cpu = np.array([50 * 3200 / (2 * math.pi), 50 * 3200 / (2 * math.pi), 800 / 0.01, 20 * 1600 / (2 * math.pi)])
    np.testing.assert_allclose(motor.counts_per_unit, cpu, rtol=1e-15)
    # a long slow move: a fraction of a step per 1 ms period on every axis
    tr = quintic(S1_Q0, [0.5, -0.4, 0.03, 1.0], 120.0)
    sp = tr.setpoints(1000.0, motor=motor)
    assert sp.steps is not None and sp.steps.dtype == np.int64 and len(sp.t) == 120_001
    exact = sp.q * cpu
    assert np.abs(sp.steps - exact).max() <= 0.5  # rounded absolute positions
    rebuilt = sp.steps[0] + np.cumsum(sp.increments, axis=0)  # what a drive counting increments reaches
    np.testing.assert_array_equal(rebuilt, sp.steps)
    assert np.abs(rebuilt - exact).max() < 1.0  # cumulative error below one step, over 120 000 periods
    naive = np.rint(exact[0]) + np.cumsum(np.rint(np.diff(exact, axis=0, prepend=exact[:1])), axis=0)
    assert np.abs(naive - exact).max() > 10.0  # rounding the increments instead drifts (the test can fail)
    with pytest.raises(ParameterError):
        MotorUnits((1.0, 0.0, 1.0, 1.0))


# ---------------------------------------------------------------------------------------------- plots, imports
def test_plot_writes_a_png(tmp_path: Path, robot_s1: Robot) -> None:
    from scara_pin.viz.plots import plot_trajectory

    tr = quintic(S1_Q0, S1_Q1, S1_T)
    plot_trajectory(tr, tmp_path / "s1.png", robot=robot_s1, samples=300)
    data = (tmp_path / "s1.png").read_bytes()
    assert len(data) > 10_000 and data[:8] == b"\x89PNG\r\n\x1a\n"
    plot_trajectory(tr, tmp_path / "bare.png", samples=50)
    assert (tmp_path / "bare.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(InvalidInputError):
        plot_trajectory(tr, tmp_path / "missing" / "x.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bare.png", "s1.png"]


def test_importing_the_modules_does_not_import_toppra_or_matplotlib() -> None:
    code = ("import sys, scara_pin.motion.trajectory, scara_pin.motion.timing, scara_pin.viz.plots; "
            "print(sorted(m for m in ('toppra', 'matplotlib', 'scipy') if m in sys.modules))")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
