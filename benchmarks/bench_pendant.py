#!/usr/bin/env python
"""Benchmark: the teach pendant's moves against its control period.

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_pendant.py``): the wall time of one
hold-to-jog period (:func:`scara_pin.motion.manual.hold_advance`, what the server runs every
``CONTROL_PERIOD`` = 50 ms while a button is held) and of one step jog (:func:`jog_step`: a 10 mm step, and a
1 m step that stops on the edge), for the shipped robots, each jog from a fixed start configuration. Each
figure is the median over 7 rounds of the mean of 20 calls; the target (a hold period well under the control
period, here <= 10 ms so that a 2-core machine busy with other work keeps the 20 Hz rate) is reported, not
enforced.

Before timing, it checks that each move keeps the speed rule (no joint above its velocity limit times the
override, the tool origin under 250 mm/s times the override, over the period) so that a fast-but-wrong
change cannot look good: on a breach it says so and exits 1.
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from scara_pin import load_robot
from scara_pin.motion.manual import MANUAL_SPEED, JogAxis, JogFrame, JogMotion, hold_advance, jog_step
from scara_pin.viz.teach import CONTROL_PERIOD

STARTS = {"s1": [0.3, 0.9, 0.02, -0.5], "default": [0.4, 1.0, 0.02, 0.3], "palletizer": [0.3, 0.5, 1.0, 0.2]}
MOTIONS = {
    "x base": JogMotion(1, axis=JogAxis.X),
    "y tool": JogMotion(-1, axis=JogAxis.Y, frame=JogFrame.TOOL),
    "rz": JogMotion(1, axis=JogAxis.YAW),
    "J1": JogMotion(1, joint=0),
}
TARGET = 0.010  # [s]


def timed(call: object, rounds: int = 7, n: int = 20) -> float:
    """Median over ``rounds`` of the mean wall time of ``n`` calls [s]."""
    means = []
    for _ in range(rounds):
        t = time.perf_counter()
        for _ in range(n):
            call()  # type: ignore[operator]
        means.append((time.perf_counter() - t) / n)
    return statistics.median(means)


def main() -> int:
    rows = []
    for name, q in STARTS.items():
        robot = load_robot(name)
        q0 = np.array(q)
        vmax = np.asarray(robot.limits.velocity)
        for label, motion in MOTIONS.items():
            for override in (0.1, 1.0):
                move = hold_advance(robot, q0, motion, CONTROL_PERIOD, override)
                dq = np.abs(move.q - q0) / CONTROL_PERIOD
                dp = np.linalg.norm(robot.tool_placement(move.q).translation - robot.tool_placement(q0).translation)
                too_fast = dp / CONTROL_PERIOD > override * MANUAL_SPEED * (1 + 1e-9)
                if np.any(dq > override * vmax * (1 + 1e-9)) or too_fast:
                    print(f"error: {name} {label} at {override:.0%} breaks the speed rule", file=sys.stderr)
                    return 1
                seconds = timed(lambda r=robot, q=q0, m=motion, o=override: hold_advance(r, q, m, CONTROL_PERIOD, o))
                rows.append((name, f"hold {label} {override:.0%}", seconds))
        for label, step in (("step 10 mm x", 0.01), ("step 1 m x (to the edge)", 1.0)):
            seconds = timed(lambda r=robot, q=q0, s=step: jog_step(r, q, MOTIONS["x base"], s), n=5)
            rows.append((name, label, seconds))
    print(f"{'robot':<11} {'move':<26} {'median':>10}")
    for name, label, seconds in rows:
        mark = "" if not label.startswith("hold") else ("  met" if seconds <= TARGET else "  MISSED")
        print(f"{name:<11} {label:<26} {seconds * 1e3:8.3f} ms{mark}")
    print(f"target: a hold period <= {TARGET * 1e3:.0f} ms (the control period is {CONTROL_PERIOD * 1e3:.0f} ms)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
