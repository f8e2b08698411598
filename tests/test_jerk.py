"""The verifier (scara_pin.motion.verify) and the jerk-limited time-optimal timing (scara_pin.motion.jerk).

Independent routes: the quintic law differentiated by hand in the test; torques by Pinocchio's RNEA on a
model the test builds itself with the payload appended as a body (appendBodyToJoint); ruckig's exact
time-optimal jerk-limited profile for one-joint moves (a J1 rotation, a vertical stroke); the minimum of
another transcription with its own path data and its own dense check (tests/jerk_reference.py); the plans
a time-optimal law must not lose to (stopping at the corners, the old filter method); rest and endpoints
from the samples.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

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


def test_static_overload_whatever_the_sign_of_the_motion(robot):
    """A static load above an effort limit is infeasible: time_scale refuses it whichever way the motion pushes
    (it used to see it only where the dynamic part had the sign of the load), and says which joint."""
    from scara_pin.motion.verify import limits_in_force, static_load, time_scale

    q = np.array([[0.3, 0.4, 0.05, 0.0]])
    g = static_load(robot, q)[0]
    j = int(np.argmax(np.abs(g)))
    assert abs(g[j]) > 1.0  # the quill carries its weight
    effort = np.array(robot.limits.effort, dtype=float)
    effort[j] = 0.5 * abs(g[j])
    lim = dataclasses.replace(robot.limits, effort=tuple(effort.tolist()))
    for sign in (1.0, -1.0):  # the dynamic part along the load, then against it
        qdd = np.zeros((1, 4))
        qdd[0, j] = sign * np.sign(g[j]) * 1e-3
        with pytest.raises(InfeasibleError, match=f"static load on joint{j + 1}.*cannot even hold still"):
            time_scale(robot, limits_in_force(robot, lim, None, True), (q, np.zeros((1, 4)), qdd))


def test_verify_sees_a_polynomial_piece_between_its_samples(robot):
    """verify checks every piece's breakpoints on both sides (``Piece.breakpoints``), a polynomial piece's too:
    an acceleration peak at a breakpoint between two 10 kHz samples is found, with the exact jerk there."""
    from scara_pin.motion.polynomial import PolynomialPiece
    from scara_pin.motion.trajectory import Trajectory

    J, tb, t2 = 100.0, 0.01234567, 0.02  # jerk +J then -J: the acceleration J tb peaks at the breakpoint tb
    c = np.zeros((2, 4, 4))
    c[0, 3, 0] = J / 6.0
    c[1, :, 0] = [J * tb**3 / 6.0, J * tb**2 / 2.0, J * tb / 2.0, -J / 6.0]
    traj = Trajectory((PolynomialPiece(np.array([0.0, tb, tb + t2]), c),))
    peak = J * tb
    acc = np.array(robot.limits.acceleration, dtype=float)
    acc[0] = peak / (1.0 + 1e-5)
    lim = dataclasses.replace(robot.limits, acceleration=tuple(acc.tolist()))
    grid = np.arange(0, int((tb + t2) * 1e4) + 1) / 1e4
    assert np.max(np.abs(traj.sample(grid)[2][:, 0])) / acc[0] < 1.0 - 1e-3  # the samples alone miss it
    v = verify(robot, traj, limits=lim, jerk=2 * J)
    assert v.acceleration.ratio == pytest.approx(1.0 + 1e-5, rel=1e-12)
    assert v.acceleration.time == pytest.approx(tb, abs=1e-12)
    assert v.jerk is not None and v.jerk.ratio == pytest.approx(0.5, rel=1e-12)  # the piece's own jerk


# --------------------------------------------------------------------------------------------- jerk-limited timing
ISSUE_FROM = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
"""The issue's placement of the standard cycle: 305 mm across (+y), 25 mm up."""
JERK = 2000.0
RUCKIG_TOL = 1e-3
"""Ours may exceed ruckig's exact minimum by 0.1 % (piecewise-constant path jerk on 48 intervals)."""


def _ruckig_duration(d, v, a, j):
    """ruckig's exact minimum time of a 1-DOF rest-to-rest move of d (jerk-limited, time-optimal)."""
    from ruckig import InputParameter, Ruckig
    from ruckig import Trajectory as RuckigTrajectory

    inp = InputParameter(1)
    inp.current_position, inp.target_position = [0.0], [d]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    out = RuckigTrajectory(1)
    Ruckig(1).calculate(inp, out)
    return out.duration


@pytest.fixture(scope="module")
def issue_arch(robot):
    from scara_pin.motion.cycle import arch_path

    b = ISSUE_FROM.copy()
    b[1] += 0.305
    return arch_path(robot, ISSUE_FROM, b, rise=0.025), b


def test_one_joint_move_matches_ruckig(robot):
    """A pure J1 rotation on a joint line: ruckig's time-optimal jerk-limited profile is exact; ours within 0.1 %."""
    from scara_pin.motion.jerk import JerkLaw, time_optimal_jerk

    q0, q1 = np.array([-1.0, 0.5, 0.05, 0.0]), np.array([1.0, 0.5, 0.05, 0.0])
    res = time_optimal_jerk(robot, JointLine(q0, q1), JERK)
    ref = _ruckig_duration(2.0, robot.limits.velocity[0], robot.limits.acceleration[0], JERK)
    assert ref <= res.trajectory.duration <= ref * (1 + RUCKIG_TOL)
    assert isinstance(res.trajectory.pieces[0].law, JerkLaw)
    v = verify(robot, res.trajectory, jerk=JERK, q_start=q0, q_end=q1).check()
    assert v.jerk.ratio > 0.99 and v.velocity.ratio > 0.99  # the limits are used, not a slow motion


def test_vertical_stroke_matches_ruckig(robot):
    """A tool line straight down moves the quill alone (a SCARA's z is J3's): ruckig's 1-DOF minimum is exact."""
    from scara_pin.motion.jerk import time_optimal_jerk
    from scara_pin.motion.paths import cartesian_path

    top = np.array([*ISSUE_FROM[:2], -0.01, 0.0])  # J3's stroke is z in [-0.15, 0]: from -0.01 m to -0.11 m
    path = cartesian_path(robot, [top, top - np.array([0.0, 0.0, 0.1, 0.0])])
    q = path.segments[0].evaluate(np.linspace(0.0, 1.0, 101), 0)[0]
    assert np.ptp(q[:, [0, 1, 3]], axis=0).max() < 1e-12  # the premise: one joint moves
    d = abs(q[-1, 2] - q[0, 2])
    assert d == pytest.approx(0.1, abs=1e-12)  # the quill is vertical: 0.1 m of z is 0.1 m of J3
    res = time_optimal_jerk(robot, path, JERK)
    ref = _ruckig_duration(d, robot.limits.velocity[2], robot.limits.acceleration[2], JERK)
    assert ref <= res.trajectory.duration <= ref * (1 + RUCKIG_TOL)
    verify(robot, res.trajectory, jerk=JERK, q_start=q[0], q_end=q[-1]).check()


def test_path_derivatives_against_differences_of_ik(robot, issue_arch):
    """q', q'', q''' of the arch (lines and blends; CasADi, exact) against finite differences of the IK alone."""
    from jerk_reference import derivatives

    path, _ = issue_arch
    s = np.linspace(0.0, 1.0, 301)
    exact = path.evaluate(s, 3)
    fd = derivatives(path, s)
    for k, tol in ((0, 1e-12), (1, 1e-9), (2, 1e-7), (3, 1e-5)):  # relative to the largest value
        assert np.abs(exact[k] - fd[k]).max() <= tol * np.abs(exact[k]).max(), k


def test_blended_arch_never_slower_than_the_simpler_plans(robot, issue_arch):
    """The issue's 'never slower than the simpler plan', same limits (jerk 2000, torques): the blended arch
    timed here <= the three lines with a stop at each corner, and <= the same arch by the old filter method."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from jerk_fir import fir_jerk_limited  # the old filter method: a benchmark's baseline, not the package's

    from scara_pin.motion.cycle import arch_path
    from scara_pin.motion.jerk import time_optimal_jerk
    from scara_pin.motion.timing import parameterize

    path, b = issue_arch
    blended = time_optimal_jerk(robot, path, JERK, torque=True).trajectory
    verify(robot, blended, jerk=JERK, torque=True).check()
    corners = time_optimal_jerk(robot, arch_path(robot, ISSUE_FROM, b, rise=0.025, blend=0.0), JERK, torque=True)
    assert len(corners.trajectory.pieces) == 3
    old, _ = fir_jerk_limited(robot, parameterize(robot, path, torque=True).trajectory, JERK, torque=True)
    assert blended.duration <= corners.trajectory.duration
    assert blended.duration <= old.duration
    import importlib.util

    assert importlib.util.find_spec("scara_pin.motion.jerk_fir") is None  # a baseline: benchmarks/, not the package


def test_arch_near_an_independent_minimum(robot, issue_arch):
    """One move of the standard cycle (jerk 2000, velocity and acceleration limits) against the minimum computed
    here by another transcription (tests/jerk_reference.py: equal intervals in time, s free, path data by
    finite differences of IK, 60 intervals, made feasible by its own dense check at 100 kHz): ours is not
    slower than it, and both pass the same independent dense check. (At 240 intervals the reference is
    0.7 % below ours: benchmarks/bench_jerk.py.)"""
    import jerk_reference

    from scara_pin.motion.jerk import time_optimal_jerk

    path, _ = issue_arch
    v, a = np.array(robot.limits.velocity), np.array(robot.limits.acceleration)
    jv = np.full(4, JERK)
    ours = time_optimal_jerk(robot, path, JERK).trajectory.pieces[0]
    ref = jerk_reference.solve(robot.model, path, v, a, jv, n=60, degree=16)
    assert max(ref.ratios.values()) <= 1.0  # feasible by its own check
    mine = jerk_reference.dense_ratios(robot.model, path, ours.law, v, a, jv)
    assert max(mine.values()) <= 1.0 + 1e-6
    assert 0.97 * ref.duration <= ours.duration <= ref.duration


def test_reversed_law_is_the_motion_backwards(robot, issue_arch):
    """JerkLaw.reversed: s_r(t) = 1 - s(T - t), sd_r(t) = sd(T - t), sdd_r = -sdd(T - t), jerk c(T - t)."""
    from scara_pin.motion.jerk import JerkLaw

    rng = np.random.default_rng(7)
    t = np.sort(np.concatenate([[0.0], rng.uniform(0.1, 1.0, 12)]))
    t /= t[-1]
    law = JerkLaw.from_jerks(t * 0.4, rng.normal(0.0, 100.0, 12))
    back = law.reversed()
    tau = rng.uniform(0.0, law.duration, 200)
    s, sd, sdd, c = law.evaluate_jerk(law.duration - tau)
    sr, sdr, sddr, cr = back.evaluate_jerk(tau)
    assert back.duration == pytest.approx(law.duration, rel=1e-15)
    for x, y, sign in ((1.0 - s, sr, 1), (sd, sdr, 1), (sdd, sddr, -1), (c, cr, 1)):
        assert np.abs(x - sign * y).max() <= 1e-9 * max(1.0, np.abs(x).max())


def test_lines_cycle_with_a_jerk_limit_needs_no_toppra():
    """The jerk-limited arch is timed without TOPP-RA (its import alone is half the planning budget)."""
    import subprocess
    import sys

    code = ("import sys, numpy as np; from scara_pin import load_robot; "
            "from scara_pin.motion.cycle import standard_cycle; "
            "standard_cycle(load_robot('default'), start=np.array([0.2608695652173913, -0.1525, -0.0875, 0.0]), "
            "direction=(0.0, 1.0), jerk=2000.0, path='lines'); print('toppra' in sys.modules)")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


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
