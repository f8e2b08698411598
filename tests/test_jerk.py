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


# --------------------------------------------------------------------------------------------- jerk-limited timing
def test_one_joint_move_matches_ruckig(robot):
    """A pure J1 rotation on a joint line: ruckig's time-optimal jerk-limited profile is exact; ours within 0.5 %."""
    from ruckig import InputParameter, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    from scara_pin.motion.jerk import JerkLaw, time_optimal_jerk

    q0, q1 = np.array([-1.0, 0.5, 0.05, 0.0]), np.array([1.0, 0.5, 0.05, 0.0])
    jmax = 2000.0
    res = time_optimal_jerk(robot, JointLine(q0, q1), jmax)
    inp = InputParameter(1)
    inp.current_position, inp.target_position = [q0[0]], [q1[0]]
    inp.max_velocity = [robot.limits.velocity[0]]
    inp.max_acceleration = [robot.limits.acceleration[0]]
    inp.max_jerk = [jmax]
    ref = RuckigTrajectory(1)
    Ruckig(1).calculate(inp, ref)
    T = res.trajectory.duration
    assert ref.duration <= T <= ref.duration * 1.005
    assert isinstance(res.trajectory.pieces[0].law, JerkLaw)
    v = verify(robot, res.trajectory, jerk=jmax, q_start=q0, q_end=q1).check()
    assert v.jerk.ratio > 0.99 and v.velocity.ratio > 0.99  # the limits are used, not a slow motion


@pytest.mark.parametrize("limit", ["1e-9", "1e-100"])
def test_tiny_jerk_limit_refused_before_any_work(limit, capsys):
    """Issue 24 item 7: the implied duration is sized first (here > 2000 s: 2e7 verified samples at 10 kHz)."""
    import resource
    import time

    from scara_pin.cli import main

    start = time.perf_counter()
    code = main(["cycle", "--jerk-limit", limit])
    elapsed = time.perf_counter() - start
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "above the cap of 2,000,000" in err and "jerk" in err
    assert elapsed < 30.0
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss < 2_000_000  # kB: no runaway allocation


def test_traj_jerk_limit_options(capsys):
    from scara_pin.cli import main

    base = ["traj", "--from", "0", "0.1", "0", "0", "--to", "0.5", "0.6", "0.02", "0.3"]
    assert main([*base, "--jerk-limit", "1", "2"]) == 2
    assert "one number or 4" in capsys.readouterr().err
    assert main([*base, "--jerk-limit", "100", "--duration", "2"]) == 2
    assert "--duration does not apply" in capsys.readouterr().err
