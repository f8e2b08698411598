#!/usr/bin/env python
"""Benchmark: the jerk-limited time-optimal path timing (scara_pin.motion.jerk) against an independent minimum.

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_jerk.py [--quick]``, about 3 minutes;
``--quick``: a coarser reference, no planning-time runs); reported, not enforced.

(a) **Optimality**, on the SAME path, same limits: ours (``time_optimal_jerk``, the defaults; compute time
    the median of 3 runs, the first of which builds the NLP) against an INDEPENDENT minimum written in
    tests/jerk_reference.py (shared with tests/test_jerk.py): its own transcription (equal intervals in time
    per smooth piece, s free, 240 intervals), its own path data (finite differences of the closed-form IK),
    its own check; its duration is made FEASIBLE by that check (an upper bound of the true minimum). Both
    are then checked by the same independent dense check (q(t) by IK at 100 kHz, finite differences, RNEA):
    the worst ratio is printed. Also: the old moving-average filter method (benchmarks/jerk_fir.py), and for the
    one-joint move ruckig's exact time-optimal profile.
(b) **Discretisation**: ours with 24 to 96 intervals on the standard-cycle arch (duration, compute time).
(c) **Simpler plans** on the standard-cycle arch: the three straight lines with a stop at each corner
    (jerk-limited, same limits), the old filter method.
(d) **Planning time** (benchmarks/bench_cycle.py's clock): ``scara-pin cycle --path lines --jerk-limit 2000``
    at the issue's placement, and the other cycle commands, against ``python -c "import toppra, scara_pin"``,
    5 runs each alternating, medians of wall time and the ratio (target 2 with a jerk limit).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

from scara_pin import load_robot
from scara_pin.motion.cycle import arch_path, cycle_placement
from scara_pin.motion.jerk import JerkOptions, time_optimal_jerk
from scara_pin.motion.paths import cartesian_path
from scara_pin.motion.timing import parameterize
from scara_pin.motion.trajectory import JointLine

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import jerk_reference  # noqa: E402  (the independent reference, shared with the tests)
from jerk_fir import fir_jerk_limited  # noqa: E402  (benchmarks/jerk_fir.py, beside this script: the old filter method)

ISSUE_FROM = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
"""The issue's placement of the standard cycle (``--from ... --direction 0 1``, 305 mm across, 25 mm up)."""
SPAN, RISE = 0.305, 0.025


def timed(f, runs: int = 3):
    times, out = [], None
    for _ in range(runs):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return out, statistics.median(times)


def cases():
    """(label, robot, path, jerk, torque)."""
    d = load_robot("default")
    b = ISSUE_FROM.copy()
    b[1] += SPAN
    s1 = load_robot("s1")
    a1, b1, _ = cycle_placement(s1)
    return [
        ("default: standard-cycle arch (issue placement)", d, arch_path(d, ISSUE_FROM, b, rise=RISE), 2000.0, True),
        ("default: joint line, J1 by 2 rad", d, JointLine(np.array([-1.0, 0.5, 0.05, 0.0]),
                                                          np.array([1.0, 0.5, 0.05, 0.0])), 2000.0, False),
        ("default: tool line, 0.32 m and 0.5 rad of yaw", d,
         cartesian_path(d, [ISSUE_FROM, np.array([0.35, 0.15, -0.05, 0.5])]).segments[0], 2000.0, True),
        ("s1: standard-cycle arch (default placement)", s1, arch_path(s1, a1, b1, rise=RISE),
         np.array([100.0, 100.0, 5.0, 200.0]), True),
    ]  # fmt: skip


def optimality(quick: bool) -> None:
    n_ref = 120 if quick else 240
    print(f"(a) duration [s] of one move on the same path; compute time [s] in brackets; reference: {n_ref} "
          "intervals; check: worst ratio by the independent dense check")  # fmt: skip
    gaps = []
    for label, robot, path, jerk, torque in cases():
        lim = robot.limits
        v, a = np.array(lim.velocity), np.array(lim.acceleration)
        e = np.array(lim.effort) if torque else None
        jv = np.broadcast_to(np.asarray(jerk, dtype=float), (4,)).copy()
        res, dt = timed(lambda robot=robot, path=path, jerk=jerk, torque=torque: time_optimal_jerk(
            robot, path, jerk, torque=torque))  # fmt: skip
        ours = res.trajectory.pieces[0]
        mine = jerk_reference.dense_ratios(robot.model, path, ours.law, v, a, jv, e)
        ref = jerk_reference.solve(robot.model, path, v, a, jv, e, n=n_ref, degree=24)
        theirs = jerk_reference.dense_ratios(robot.model, path, ref.law, v, a, jv, e)
        base = parameterize(robot, path, torque=torque).trajectory
        old, _ = fir_jerk_limited(robot, base, jerk, torque=torque)
        gap = ours.duration / ref.duration - 1.0
        gaps.append(gap)
        print(f"  {label}")
        print(f"    ours       {ours.duration:.6f} ({dt:.3f})   check {max(mine.values()):.7f}   "
              f"{', '.join(f'{k} {v:.6f}' for k, v in mine.items())}")
        print(f"    reference  {ref.duration:.6f} ({ref.seconds:.1f})   check {max(theirs.values()):.7f}   "
              f"(its NLP {ref.nlp:.6f}, slowed {ref.scale - 1:.2e} by its check)")
        print(f"    gap        {100 * gap:+.2f} %   (old filter method {old.duration:.6f}: "
              f"{100 * (old.duration / ref.duration - 1):+.1f} %; TOPP-RA without jerk {base.duration:.6f})")
        if isinstance(path, JointLine):
            from ruckig import InputParameter, Ruckig
            from ruckig import Trajectory as RuckigTrajectory

            inp = InputParameter(1)
            inp.current_position, inp.target_position = [path.q0[0]], [path.q1[0]]
            inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v[0]], [a[0]], [jv[0]]
            out = RuckigTrajectory(1)
            Ruckig(1).calculate(inp, out)
            print(f"    ruckig     {out.duration:.6f} (exact)   ours {100 * (ours.duration / out.duration - 1):+.3f} %")
    print(f"  median gap {100 * statistics.median(gaps):+.2f} %, largest {100 * max(gaps):+.2f} %")


def discretisation() -> None:
    robot = load_robot("default")
    b = ISSUE_FROM.copy()
    b[1] += SPAN
    path = arch_path(robot, ISSUE_FROM, b, rise=RISE)
    print("(b) ours on the standard-cycle arch by number of intervals: duration [s] (compute time [s], median of 3)")
    for n in (24, 32, 48, 64, 96):
        res, dt = timed(lambda n=n: time_optimal_jerk(robot, path, 2000.0, torque=True,
                                                      options=JerkOptions(intervals=n)))  # fmt: skip
        print(f"  N = {n:3d}: {res.trajectory.duration:.6f} ({dt:.3f}), {res.nlps} NLPs, correction "
              f"{res.correction - 1:.1e}")


def simpler_plans() -> None:
    robot = load_robot("default")
    b = ISSUE_FROM.copy()
    b[1] += SPAN
    path = arch_path(robot, ISSUE_FROM, b, rise=RISE)
    blended = time_optimal_jerk(robot, path, 2000.0, torque=True).trajectory.duration
    corners = time_optimal_jerk(robot, arch_path(robot, ISSUE_FROM, b, rise=RISE, blend=0.0), 2000.0,
                                torque=True).trajectory.duration  # fmt: skip
    old, _ = fir_jerk_limited(robot, parameterize(robot, path, torque=True).trajectory, 2000.0, torque=True)
    print("(c) one move of the standard cycle, jerk 2000 [s]: blended arch (ours), three lines with a stop at each "
          "corner (ours), blended arch by the old filter method")  # fmt: skip
    print(f"  {blended:.6f}   {corners:.6f}   {old.duration:.6f}")


def main() -> int:
    quick = "--quick" in sys.argv
    optimality(quick)
    discretisation()
    simpler_plans()
    if not quick:
        from bench_cycle import planning_time  # the one clock of the cycle commands (benchmarks/bench_cycle.py)

        planning_time(label="(d)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
