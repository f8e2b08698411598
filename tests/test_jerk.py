"""The verifier (scara_pin.motion.verify) and the jerk-limited time-optimal timing (scara_pin.motion.jerk).

Independent routes: the quintic law differentiated by hand in the test; torques by Pinocchio's RNEA on a
model the test builds itself with the payload appended as a body (appendBodyToJoint); ruckig's exact
time-optimal jerk-limited profile for one-joint moves; rest and endpoints from the samples.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from scara_pin import load_robot
from scara_pin.errors import InfeasibleError
from scara_pin.motion.payload import Payload
from scara_pin.motion.timing import parameterize
from scara_pin.motion.trajectory import JointLine, quintic
from scara_pin.motion.verify import LimitViolation, Quantity, verify

Q0 = np.array([0.0, 0.1, 0.0, 0.0])
Q1 = np.array([0.5, 0.6, 0.02, 0.3])


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


def _quintic_jerk_peak(T):  # s''' = 60 / T^3 (1 - 6 x + 6 x^2), largest at x = 0 and 1
    x = np.linspace(0.0, 1.0, 100_001)
    return np.max(np.abs(60.0 * (1.0 - 6.0 * x + 6.0 * x * x))) / T**3


def test_verify_quintic_against_the_law_by_hand(robot):
    T = 0.8
    jmax = np.array([80.0, 70.0, 3.0, 40.0])
    v = verify(robot, quintic(Q0, Q1, T), jerk=jmax, q_start=Q0, q_end=Q1)
    dq = np.abs(Q1 - Q0)
    x = np.linspace(0.0, 1.0, 200_001)
    sd = np.max(30 * x**2 * (1 - x) ** 2) / T
    sdd = np.max(np.abs(60 * x - 180 * x**2 + 120 * x**3)) / T**2
    assert v.velocity.ratio == pytest.approx(np.max(dq * sd / robot.limits.velocity), rel=1e-9)
    assert v.acceleration.ratio == pytest.approx(np.max(dq * sdd / robot.limits.acceleration), rel=1e-8)
    # third differences: a local mean of the true jerk, at most its peak, close to it at 10 kHz
    true = dq * _quintic_jerk_peak(T) / jmax
    assert v.jerk_differences.ratio <= np.max(true) * (1 + 1e-9)
    assert v.jerk_differences.ratio == pytest.approx(np.max(true), rel=2e-3)
    assert v.jerk_differences.joint == int(np.argmax(true))
    assert v.jerk is None  # the quintic law has no analytic jerk here
    assert v.start_error == 0.0 and v.end_error == 0.0 and v.rest == 0.0
    assert v.check() is v


def test_verify_names_the_violation(robot):
    T = 0.05  # far too fast
    v = verify(robot, quintic(Q0, Q1, T))
    with pytest.raises(LimitViolation) as err:
        v.check()
    w = err.value.worst
    assert w.quantity is Quantity.VELOCITY and w.joint == v.velocity.joint and w.ratio > 1
    assert "velocity of joint" in str(err.value) and isinstance(err.value, InfeasibleError)
    with pytest.raises(LimitViolation, match="misses its end"):
        verify(robot, quintic(Q0, Q1, 2.0), q_end=Q1 + 1e-6).check()


def test_toppra_profile_has_unbounded_jerk_seen_by_third_differences(robot):
    traj = parameterize(robot, JointLine(Q0, Q1)).trajectory
    v = verify(robot, traj, jerk=1e4)
    # the path acceleration of a TOPP-RA profile steps at its grid points: a step of a (rad/s^2) seen by
    # third differences at h = 1e-4 s is about a / (2 h) -- far beyond any jerk limit
    assert v.jerk_differences.ratio > 10
    with pytest.raises(LimitViolation, match="third differences"):
        v.check()


def test_verify_torque_with_payload_against_an_appended_body(robot):
    mass, com = 3.0, (0.01, 0.0, 0.03)
    traj = quintic(Q0, Q1, 0.6)
    v = verify(robot, traj, torque=True, payload=Payload(mass, com), rate=2000.0)
    model = pin.Model(robot.model)
    frame = model.frames[robot.tool_id]
    model.appendBodyToJoint(frame.parentJoint, pin.Inertia(mass, frame.placement.act(np.array(com)), np.zeros((3, 3))),
                            pin.SE3.Identity())  # fmt: skip
    data = model.createData()
    t = np.arange(0, 1201) / 2000.0
    q, qd, qdd = traj.sample(t)
    tau = np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(t))])
    ratio = np.abs(tau) / np.array(robot.limits.effort)
    assert v.torque.ratio >= ratio.max() - 1e-12
    assert v.torque.ratio == pytest.approx(ratio.max(), rel=1e-3)
