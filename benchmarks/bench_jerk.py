"""Jerk-limited time-optimal timing vs ruckig (one joint), the old filter method, and stopping at the corners.

Run: python benchmarks/bench_jerk.py   (prints durations and compute times; medians of 3 runs)
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from scara_pin import load_robot
from scara_pin.motion.cycle import arch_path
from scara_pin.motion.jerk import JerkOptions, time_optimal_jerk
from scara_pin.motion.jerk_fir import fir_jerk_limited
from scara_pin.motion.timing import parameterize
from scara_pin.motion.trajectory import JointLine
from scara_pin.motion.verify import verify


def timed(f):
    times, out = [], None
    for _ in range(3):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return out, statistics.median(times)


def main() -> None:
    robot = load_robot("default")
    J = 2000.0
    p = JointLine(np.array([-1.0, 0.5, 0.05, 0.0]), np.array([1.0, 0.5, 0.05, 0.0]))
    for n in (20, 40, 80):
        res, dt = timed(lambda n=n: time_optimal_jerk(robot, p, J, options=JerkOptions(intervals=n)))
        print(f"J1 2 rad, N={n}: {res.trajectory.duration:.6f} s ({dt:.2f} s to plan)")
    a = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
    b = a.copy()
    b[1] += 0.305
    path = arch_path(robot, a, b, rise=0.025)
    for n in (40, 80):
        res, dt = timed(lambda n=n: time_optimal_jerk(robot, path, J, torque=True, options=JerkOptions(intervals=n)))
        v = verify(robot, res.trajectory, jerk=J, torque=True).check()
        print(f"own arch, N={n}: {res.trajectory.duration:.6f} s, correction {res.correction:.6f}, worst "
              f"{v.worst.quantity.value} {v.worst.ratio:.7f} ({dt:.2f} s to plan)")
    base = parameterize(robot, path, torque=True).trajectory
    old, _ = fir_jerk_limited(robot, base, J, torque=True)
    print(f"own arch, old filter method: {old.duration:.6f} s")
    corners = arch_path(robot, a, b, rise=0.025, blend=0.0)
    res = time_optimal_jerk(robot, corners, J, torque=True)
    print(f"corners (three lines, rest at each): {res.trajectory.duration:.6f} s")


if __name__ == "__main__":
    main()
