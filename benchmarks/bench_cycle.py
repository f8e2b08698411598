#!/usr/bin/env python
"""Benchmark: the standard cycle (up 25 mm, across 305 mm, down, back) of the shipped SCARA robots.

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_cycle.py``); reported, not enforced.

(a) compute time: ``parameterize`` (scara-pin's TOPP-RA with the limits verified between grid points)
    against raw toppra (``JointVelocityConstraint`` + ``JointAccelerationConstraint``, its spline output)
    on the SAME blended arch path of the default robot (one move, 100 grid segments), 5 runs each, median.
    Raw toppra's output is also sampled at 1 kHz: its worst limit ratio is reported.
(b) cycle time of ``default`` and ``s1`` against payload 0 / 1 / 2 kg (torque limits apply), with and
    without blending, and with a jerk limit. The palletizer is left out: the straight tool lines the
    cycle is built on use the SCARA closed form (``traj --linear`` is SCARA-only too).
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from scara_pin import load_robot
from scara_pin.motion.cycle import arch_path, cycle_placement, standard_cycle
from scara_pin.motion.payload import Payload
from scara_pin.motion.timing import parameterize

JERK = {"default": [20000.0, 40000.0, 2000.0, 100000.0], "s1": [100.0, 100.0, 5.0, 200.0]}


def raw_toppra(path: object, v: np.ndarray, a: np.ndarray) -> tuple[float, float]:
    import toppra
    import toppra.algorithm
    import toppra.constraint

    cons = [toppra.constraint.JointVelocityConstraint(v), toppra.constraint.JointAccelerationConstraint(a)]
    grid = np.unique(np.concatenate([np.linspace(0, 1, 101), path.knots()]))  # type: ignore[attr-defined]
    out = toppra.algorithm.TOPPRA(cons, path, gridpoints=grid, solver_wrapper="seidel").compute_trajectory(0, 0)
    t = np.append(np.arange(0.0, out.duration, 1e-3), out.duration)
    ratio = max(np.max(np.abs(out(t, 1)) / v), np.max(np.abs(out(t, 2)) / a))
    return out.duration, float(ratio)


def main() -> int:
    import toppra  # noqa: F401 - imported before any timing

    robot = load_robot("default")
    v, a = np.array(robot.limits.velocity), np.array(robot.limits.acceleration)
    A, B, _ = cycle_placement(robot)
    path = arch_path(robot, A, B)
    ours, raw = [], []
    for _ in range(5):
        t0 = time.perf_counter()
        res = parameterize(robot, path)
        ours.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        T_raw, ratio_raw = raw_toppra(path, v, a)
        raw.append(time.perf_counter() - t0)
    T = res.trajectory.duration
    print(f"(a) one arch move, default robot: ours {statistics.median(ours) * 1e3:.0f} ms -> {T:.4f} s "
          f"(worst ratio {res.ratios.worst:.9f}); raw toppra {statistics.median(raw) * 1e3:.0f} ms -> {T_raw:.4f} s "
          f"(worst ratio at 1 kHz {ratio_raw:.4f})")  # fmt: skip
    print("(b) standard cycle time [s] (compute time in brackets)")
    print("robot    payload  blended       no blend      jerk-limited")
    for name in ("default", "s1"):
        r = load_robot(name)
        for mass in (0.0, 1.0, 2.0):
            row = []
            for kw in ({}, {"blend": 0.0}, {"jerk": JERK[name]}):
                t0 = time.perf_counter()
                c = standard_cycle(r, payload=Payload(mass), **kw)  # type: ignore[arg-type]
                row.append(f"{c.cycle_time:.4f} ({time.perf_counter() - t0:.1f})")
            print(f"{name:<8} {mass:4.1f} kg  " + "  ".join(f"{x:<12}" for x in row))
    print(f"jerk limits: {JERK}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
