#!/usr/bin/env python
"""Benchmark: scara-pin's TOPP-RA timing against the exact optimum and against raw toppra.

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_traj.py``); one run, reported,
not enforced (the exit code is 0 whatever the figures, 1 only if a check fails to run):

(a) optimality: on 50 seeded random straight joint-space lines of the default robot (both ends uniform
    within the joint limits), ``time_optimal`` against the closed-form optimum of the synchronised line,
    T* = 1/V + V/A if V^2/A < 1 else 2 sqrt(1/A) (V = min_i vmax_i/|dq_i|, A = min_i amax_i/|dq_i|).
    Target: gap <= 1e-3 relative.
(b) cost and limits: on 20 seeded random 10-waypoint paths (middle 70 % of the ranges, redrawn when the
    spline overshoots a limit), at the same grid (100 uniform segments plus the knots):
    - ours: ``JointSpline`` + ``parameterize`` (constraint at 5 sub-points per segment, toppra's
      controllable sets and forward pass, exact output, verification at 1 kHz and at the closed-form
      extrema, rescaling);
    - raw toppra: ``SplineInterpolator`` + ``JointVelocityConstraint`` + ``JointAccelerationConstraint``
      + ``TOPPRA(..., solver_wrapper="seidel").compute_trajectory()`` (its spline output).
    Each is timed 7 times per path, alternating which goes first; the per-path figure is the median.
    Target: ours / raw <= 1.3 (median over paths). Then both are sampled at 1 kHz and the worst
    |qd|/vmax, |qdd|/amax reported (ours: target <= 1 + 1e-6).
Imports (toppra ~1.5 s) happen before any timing.
"""

from __future__ import annotations

import math
import statistics
import sys
import time

import numpy as np

from scara_pin import load_robot
from scara_pin.motion.timing import TimingOptions, parameterize
from scara_pin.motion.trajectory import JointSpline, PathError, joint_path

SEED = 0
N_LINES = 50
N_PATHS = 20
N_WAYPOINTS = 10
REPEATS = 7
GRID = 100


def t_star(dq: np.ndarray, v: np.ndarray, a: np.ndarray) -> float:
    dq = np.abs(dq)
    V, A = float(np.min(v / dq)), float(np.min(a / dq))
    return 1 / V + V / A if V * V / A < 1 else 2 * math.sqrt(1 / A)


def ratios_1khz(traj: object, v: np.ndarray, a: np.ndarray, duration: float, order_call: bool) -> float:
    t = np.arange(0.0, duration, 1e-3)
    t = np.append(t, duration)
    if order_call:  # toppra's output: traj(t, order)
        qd, qdd = traj(t, 1), traj(t, 2)  # type: ignore[operator]
    else:
        _, qd, qdd = traj.sample(t)  # type: ignore[attr-defined]
    return float(max(np.max(np.abs(qd) / v), np.max(np.abs(qdd) / a)))


def main() -> int:
    import toppra
    import toppra.algorithm
    import toppra.constraint

    robot = load_robot("default")
    v, a = np.array(robot.limits.velocity), np.array(robot.limits.acceleration)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    opts = TimingOptions(grid_points=GRID)
    rng = np.random.default_rng(SEED)

    # (a) straight lines against T*
    gaps, worst_line = [], 0.0
    for _ in range(N_LINES):
        q0, q1 = rng.uniform(lo, hi), rng.uniform(lo, hi)
        res = parameterize(robot, [q0, q1], options=opts)
        gaps.append(res.trajectory.duration / t_star(q1 - q0, v, a) - 1.0)
        worst_line = max(worst_line, ratios_1khz(res.trajectory, v, a, res.trajectory.duration, False))
    gaps_arr = np.array(gaps)

    # (b) 10-waypoint paths: cost and limits against raw toppra
    mid, half = (lo + hi) / 2, 0.35 * (hi - lo)
    paths = []
    while len(paths) < N_PATHS:
        W = mid + half * rng.uniform(-1, 1, (N_WAYPOINTS, 4))
        try:
            paths.append(joint_path(robot, W))
        except PathError:
            continue
    weights = tuple(1.0 / x for x in v)

    def ours(path: JointSpline) -> object:
        return parameterize(robot, JointSpline(path.waypoints, weights), options=opts).trajectory

    def raw(path: JointSpline, grid: np.ndarray) -> object:
        spline = toppra.SplineInterpolator(path.knots(), path.waypoints)
        cons = [toppra.constraint.JointVelocityConstraint(v), toppra.constraint.JointAccelerationConstraint(a)]
        return toppra.algorithm.TOPPRA(cons, spline, gridpoints=grid, solver_wrapper="seidel").compute_trajectory(0, 0)

    cost, ours_ratio, raw_ratio, dur_ratio, t_ours_all, t_raw_all = [], [], [], [], [], []
    for k, path in enumerate(paths):
        grid = np.unique(np.concatenate([np.linspace(0, 1, GRID + 1), path.knots()]))
        t_o, t_r = [], []
        for r in range(REPEATS):
            order = (0, 1) if (r + k) % 2 == 0 else (1, 0)
            for which in order:
                t0 = time.perf_counter()
                if which == 0:
                    traj_o = ours(path)
                    t_o.append(time.perf_counter() - t0)
                else:
                    traj_r = raw(path, grid)
                    t_r.append(time.perf_counter() - t0)
        mo, mr = statistics.median(t_o), statistics.median(t_r)
        t_ours_all.append(mo)
        t_raw_all.append(mr)
        cost.append(mo / mr)
        ours_ratio.append(ratios_1khz(traj_o, v, a, traj_o.duration, False))  # type: ignore[attr-defined]
        raw_ratio.append(ratios_1khz(traj_r, v, a, traj_r.duration, True))  # type: ignore[attr-defined]
        dur_ratio.append(traj_o.duration / traj_r.duration)  # type: ignore[attr-defined]

    ok = lambda flag: "yes" if flag else "**no**"  # noqa: E731
    print(f"# bench_traj: default robot, seed {SEED}, grid {GRID} segments (+ knots), toppra seidel, "
          f"Python {sys.version.split()[0]}\n")  # fmt: skip
    print("| measure | value | target | met |")
    print("|---|---|---|---|")
    print(f"| (a) {N_LINES} straight lines: duration / T* - 1, max | {gaps_arr.max():.2e} | <= 1e-3 | "
          f"{ok(gaps_arr.max() <= 1e-3)} |")  # fmt: skip
    print(f"| (a) same, mean | {gaps_arr.mean():.2e} | | |")
    print(f"| (a) same, min (below 0 = faster than the optimum) | {gaps_arr.min():.2e} | >= -1e-9 | "
          f"{ok(gaps_arr.min() >= -1e-9)} |")  # fmt: skip
    print(f"| (a) worst limit ratio at 1 kHz | {worst_line:.9f} | <= 1 + 1e-6 | {ok(worst_line <= 1 + 1e-6)} |")
    print(f"| (b) {N_PATHS} paths x {N_WAYPOINTS} waypoints: compute time ours / raw toppra, median | "
          f"{statistics.median(cost):.2f}x | <= 1.3x | {ok(statistics.median(cost) <= 1.3)} |")  # fmt: skip
    print(f"| (b) same, worst path | {max(cost):.2f}x | | |")
    print(f"| (b) median time per path: ours / raw toppra | {1e3 * statistics.median(t_ours_all):.2f} ms / "
          f"{1e3 * statistics.median(t_raw_all):.2f} ms | | |")  # fmt: skip
    print(f"| (b) worst limit ratio at 1 kHz, ours | {max(ours_ratio):.9f} | <= 1 + 1e-6 | "
          f"{ok(max(ours_ratio) <= 1 + 1e-6)} |")  # fmt: skip
    print(f"| (b) worst limit ratio at 1 kHz, raw toppra (spline output) | {max(raw_ratio):.4f} | | |")
    print(f"| (b) median limit ratio at 1 kHz, raw toppra | {statistics.median(raw_ratio):.4f} | | |")
    print(f"| (b) duration ours / raw toppra: median (min - max) | {statistics.median(dur_ratio):.5f} "
          f"({min(dur_ratio):.5f} - {max(dur_ratio):.5f}) | | |")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
