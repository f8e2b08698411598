#!/usr/bin/env python
"""Benchmark: scara-pin's inverse kinematics against Robotics Toolbox for Python's ``ik_LM``.

How to run. roboticstoolbox-python is a benchmark-only dependency: it lives in its own environment and
never becomes a dependency of scara-pin. ``make bench-ik`` creates that environment (``.venv-bench``) and
runs this script; by hand::

    python3 -m venv .venv-bench
    .venv-bench/bin/pip install roboticstoolbox-python -e .
    .venv-bench/bin/python benchmarks/bench_ik.py          # i.e. `python benchmarks/bench_ik.py` in that venv

With an interpreter that has no roboticstoolbox (``.venv/bin/python benchmarks/bench_ik.py``) the rtb rows
are skipped with a message and scara-pin's own solvers are still measured.

What is measured, in ONE run, on the ``default`` robot (l1 = l2 = 0.2 m) and 1000 seeded reachable targets
(Pinocchio FK of q drawn uniformly inside the joint limits, seed 0):

- closed form nearest ``robot.ik_nearest(target, q_mid)``: the one closed-form solution nearest to q_mid,
  the same q0 that rtb's ``ik_LM`` gets (the middle of the joint ranges), per call - like ``ik_LM``, one q
  from one start; before any timing it must equal the nearest to q_mid of ``solve``'s solutions (1e-12)
  on every target, else the script stops;
- closed form ``scara_pin.kinematics.scara.solve(geo, target)``: every solution inside the limits, as result objects,
  per call (for information);
- batch ``scara_pin.kinematics.scara.solve_batch(geo, T)`` on N = 10^6 targets (the 1000, tiled), per target, with the
  default ``branch="right"`` (one elbow: a target whose right solution is outside the limits has none) and
  with ``branch="nearest"`` (the solution of either branch nearest to the reference);
- numeric ``scara_pin.kinematics.numeric.solve_numeric(robot, target)``: default start and options (tol 1e-12);
- rtb: the same SCARA built as an ``rtb.DHRobot`` from standard D-H parameters read from the package's
  geometry (l1, l2, z0, joint limits); before any timing its ``fkine`` must equal ``Robot.tool_placement``
  to 1e-12 on 100 random q, else the script stops. ``ik_LM`` is rtb's C++ Levenberg-Marquardt solver,
  called with q0 = the middle of the joint ranges, ``tol=1e-14`` (its E = e^T e / 2, i.e. |e| < 1.4e-7),
  ``mask=[1, 1, 1, 0, 0, 1]`` (x, y, z and the rotation about z: the 4 DOF), ``joint_limits=True``; once
  through ``DHRobot.ik_LM`` (the public route, which rebuilds the robot's ETS and converts the target in
  Python on every call) and once through the ETS built once (``robot.ets().ik_LM``: the C++ solver with
  the least Python in front of it, the reference for the ratios); and once more with ``tol=1e-24``
  (|e| < 1.4e-12, the accuracy of ours) for comparison at equal accuracy.

Accuracy, per solver and target: the pose error of the returned q under scara-pin's Pinocchio FK
(max of |dp| [m] and |d yaw| [rad]); "solved" = an answer within 1e-6 of the target AND inside the joint
limits (for ``solve``: a solution exists and every solution returned is within 1e-6; for ``ik_nearest``:
it returns a q rather than raising ``NoSolutionError``, and that q is within 1e-6 and inside the limits).
Timing: each round times every solver once over all targets (a plain loop of calls, results dropped), in
an order that alternates between rounds, and the batch once per branch; the reported time is the median
over the rounds (the machine may be shared: compare within one run). Targets of the
issue (reported, not enforced): closed form single call (``ik_nearest``) <= 1/30 of the time per call of
``ik_LM`` on the ETS with 100 % solved, batch >= 10 million targets/s, numeric <= 5x ik_LM's time with
100 % solved. The header says which route of scara-pin ran: the compiled ``scara_pin._speedups`` or the
pure-Python fallback (no C module built, or ``SCARA_PIN_NO_SPEEDUPS=1``). Options: ``--quick`` (fewer
rounds), ``--json`` (one JSON object instead of the text).
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import platform
import statistics
import sys
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
import pinocchio as pin

import scara_pin
from scara_pin import _fast
from scara_pin.kinematics.numeric import solve_numeric
from scara_pin.kinematics.scara import IKStatus, solve, solve_batch

N_TARGETS = 1000
SEED = 0
N_BATCH = 10**6
ROUNDS, QUICK_ROUNDS = 7, 3
BLOCK = N_TARGETS  # per-call solvers take turns over all targets (smaller blocks: colder caches)
SOLVED_TOL = 1e-6
FK_TOL = 1e-12
RTB_TOL, RTB_TOL_TIGHT = 1e-14, 1e-24
MASK = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 1.0])
TARGET_CLOSED = 30.0  # ik_LM time / closed-form single call (ik_nearest) time, at least
TARGET_BATCH = 10e6  # targets per second, at least
TARGET_NUMERIC = 5.0  # numeric time / ik_LM time, at most


class Mismatch(Exception):
    """The rtb model is not the same robot: no comparison is meaningful."""


# ---------------------------------------------------------------------------------------------- inputs
def reachable_targets(robot: scara_pin.Robot, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(q, targets): n configurations uniform inside the limits and their (x, y, z, yaw) under Pinocchio FK."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    qs = rng.uniform(lo, hi, size=(n, 4))
    return qs, np.array([robot.tool_pose(q) for q in qs])


def pose_error(robot: scara_pin.Robot, q: np.ndarray, target: np.ndarray) -> float:
    """max(|dp|, |d yaw|) between Pinocchio FK of q and the target (inf for a missing q)."""
    if q is None or not np.all(np.isfinite(q)):
        return math.inf
    e = robot.tool_pose(np.asarray(q, dtype=float)) - target
    e[3] = (e[3] + math.pi) % (2 * math.pi) - math.pi
    return float(np.abs(e).max())


def inside(robot: scara_pin.Robot, q: np.ndarray) -> bool:
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    return bool(np.all(q >= lo) and np.all(q <= hi))


# ---------------------------------------------------------------------------------------------- rtb
def rtb_models(robot: scara_pin.Robot) -> tuple[Any, Any] | str:
    """(DHRobot, its ETS) of the same SCARA, or the reason rtb is not available."""
    try:
        import roboticstoolbox as rtb
    except ImportError as exc:
        return f"roboticstoolbox is not importable here ({exc}); see the header for the benchmark venv"
    geo = robot.kinematics
    # The D-H table of the `default` description (tool0 z down, the quill q3 moving down, all revolute
    # axes +z): Rz(q1) Tz(z0) Tx(l1) | Rz(q2) Tx(l2) Rx(pi) | Tz(q3) Rx(pi) | Rz(q4) Rx(pi).
    expected = dict(a1=(0.0, 0.0), tool=(0.0, 0.0), yaw0=0.0, signs=(1.0, 1.0, -1.0, 1.0), revolute=(0, 1, 3))
    for name, value in expected.items():
        if getattr(geo, name) != value:
            raise Mismatch(f"the D-H table here assumes {name} = {value}; this robot has {getattr(geo, name)}")
    lo, hi = robot.limits.lower, robot.limits.upper
    links = [
        rtb.RevoluteDH(d=geo.z0, a=geo.l1, alpha=0.0, qlim=[lo[0], hi[0]]),
        rtb.RevoluteDH(d=0.0, a=geo.l2, alpha=math.pi, qlim=[lo[1], hi[1]]),
        rtb.PrismaticDH(theta=0.0, a=0.0, alpha=math.pi, qlim=[lo[2], hi[2]]),
        rtb.RevoluteDH(d=0.0, a=0.0, alpha=math.pi, qlim=[lo[3], hi[3]]),
    ]
    dh = rtb.DHRobot(links, name=f"{robot.name} (D-H)")
    # the same robot: rtb's FK equals ours on random q
    rng = np.random.default_rng(SEED + 1)
    worst = 0.0
    for q in rng.uniform(np.asarray(lo), np.asarray(hi), size=(100, 4)):
        worst = max(worst, float(np.abs(dh.fkine(q).A - robot.tool_placement(q).homogeneous).max()))
    if not worst <= FK_TOL:
        raise Mismatch(f"rtb fkine differs from scara-pin's tool_placement by {worst:.3g} (> {FK_TOL:g})")
    return dh, dh.ets()


# ---------------------------------------------------------------------------------------------- solvers
def solvers(robot: scara_pin.Robot, targets: np.ndarray, rtb: tuple[Any, Any] | None) -> dict[str, Callable]:
    """name -> f(indices, keep): calls the solver on those targets; returns the results when ``keep``
    (for the accuracy check), else drops each one at once (for timing: a plain loop of calls)."""
    geo = robot.kinematics
    T = [t.copy() for t in targets]
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    mid = (lo + hi) / 2  # q0 of rtb's ik_LM and the reference of ik_nearest
    ik_nearest, no_solution = robot.ik_nearest, scara_pin.NoSolutionError

    def nearest(i: int) -> np.ndarray | None:  # one frame, as the lambdas; no cost unless it raises
        try:
            return ik_nearest(T[i], mid)
        except no_solution:
            return None

    calls: dict[str, Callable[[int], Any]] = {
        "nearest": nearest,
        "closed": lambda i: solve(geo, T[i]),
        "numeric": lambda i: solve_numeric(robot, T[i]),
    }
    if rtb is not None:
        dh, ets = rtb
        M = [_placement(geo, t) for t in T]
        calls["rtb_ets"] = lambda i: ets.ik_LM(M[i], q0=mid, tol=RTB_TOL, mask=MASK, joint_limits=True)
        calls["rtb_dh"] = lambda i: dh.ik_LM(M[i], q0=mid, tol=RTB_TOL, mask=MASK, joint_limits=True)
        calls["rtb_ets_tight"] = lambda i: ets.ik_LM(M[i], q0=mid, tol=RTB_TOL_TIGHT, mask=MASK, joint_limits=True)

    def loop(call: Callable[[int], Any]) -> Callable[[Sequence[int], bool], list | None]:
        def run(idx: Sequence[int], keep: bool = False) -> list | None:
            if keep:
                return [call(i) for i in idx]
            for i in idx:
                call(i)
            return None

        return run

    return {name: loop(call) for name, call in calls.items()}


def _placement(geo: Any, target: np.ndarray) -> np.ndarray:
    """The 4 x 4 tool pose of a target (x, y, z, yaw): rotation Rz(yaw - yaw0) R0 (R0 the tool's at q = 0)."""
    x, y, z, yaw = target
    M = np.eye(4)
    M[:3, :3] = pin.rpy.rpyToMatrix(0.0, 0.0, yaw - geo.yaw0) @ geo.R0
    M[:3, 3] = x, y, z
    return M


def accuracy(robot: scara_pin.Robot, name: str, results: list, targets: np.ndarray) -> dict[str, float]:
    """Max pose error over the answers and the share of targets solved (<= 1e-6 and inside the limits)."""
    worst, solved, answered = 0.0, 0, 0
    for res, t in zip(results, targets, strict=True):
        if name == "closed":
            errs = [pose_error(robot, s.q, t) for s in res.solutions]
            ok = res.status is IKStatus.OK and all(e <= SOLVED_TOL for e in errs)
            ok = ok and all(inside(robot, s.q) for s in res.solutions)
        elif name == "nearest":  # a q, or None for NoSolutionError
            errs = [pose_error(robot, res, t)]
            ok = res is not None and errs[0] <= SOLVED_TOL and inside(robot, res)
        else:
            q = res.q
            errs = [pose_error(robot, q, t)]
            ok = bool(res.success) and errs[0] <= SOLVED_TOL and inside(robot, q)
        if errs and all(math.isfinite(e) for e in errs):
            answered += 1
            worst = max(worst, max(errs))
        solved += ok
    return {"max_pose_error": worst, "solved": solved / len(targets), "answered": answered}


def check_nearest(robot: scara_pin.Robot, results: list, targets: np.ndarray, reference: np.ndarray) -> float:
    """Largest |ik_nearest - the nearest of ``solve``'s solutions| over the targets; Mismatch if > 1e-12.

    Both answer "no solution" alike (None here for ik_nearest's NoSolutionError).
    """
    worst = 0.0
    for q, t in zip(results, targets, strict=True):
        best = solve(robot.kinematics, t, reference=reference).nearest(reference)
        if (q is None) != (best is None):
            raise Mismatch(f"ik_nearest and solve disagree on whether {t.tolist()} has a solution")
        if q is not None:
            worst = max(worst, float(np.abs(q - best.q).max()))
            if not worst <= FK_TOL:
                raise Mismatch(f"ik_nearest({t.tolist()}) is {worst:.3g} away from solve's nearest (> {FK_TOL:g})")
    return worst


def batch_accuracy(robot: scara_pin.Robot, res: Any, targets: np.ndarray) -> dict[str, float]:
    worst, solved = 0.0, 0
    for q, st, t in zip(res.q, res.status, targets, strict=True):
        if st != 0:
            continue
        err = pose_error(robot, q, t)
        worst = max(worst, err)
        solved += err <= SOLVED_TOL and inside(robot, q)
    return {"max_pose_error": worst, "solved": solved / len(targets)}


# ---------------------------------------------------------------------------------------------- timing
def time_rounds(fns: dict[str, Callable], n: int, batch: Callable[[str], float], rounds: int) -> dict[str, list[float]]:
    """Seconds per call (per target for the batch), one value per round and solver.

    Per-call solvers: each round walks the targets block by block (BLOCK targets); in each block every
    solver runs once over the block, in an order that alternates between blocks and rounds, so that a drift
    of the machine's speed hits all of them alike. The batch runs once per round and branch.
    """
    blocks = [range(i, min(i + BLOCK, n)) for i in range(0, n, BLOCK)]
    names = list(fns)
    samples: dict[str, list[float]] = {k: [] for k in [*names, "batch_right", "batch_nearest"]}
    clock = time.perf_counter
    for r in range(rounds):
        total = dict.fromkeys(names, 0.0)
        gc.collect()
        gc.disable()
        try:
            for b, idx in enumerate(blocks):
                order = names if (r + b) % 2 == 0 else names[::-1]
                for name in order:
                    t0 = clock()
                    fns[name](idx)
                    total[name] += clock() - t0
        finally:
            gc.enable()
        for name in names:
            samples[name].append(total[name] / n)
        for branch in ("right", "nearest") if r % 2 == 0 else ("nearest", "right"):
            samples[f"batch_{branch}"].append(batch(branch))
    return samples


# ---------------------------------------------------------------------------------------------- report
LABELS = {
    "nearest": "scara-pin closed form nearest `robot.ik_nearest(T[i], q_mid)`",
    "closed": "scara-pin closed form `solve` (all solutions as objects)",
    "batch_right": "scara-pin batch `solve_batch`, branch=right",
    "batch_nearest": "scara-pin batch `solve_batch`, branch=nearest",
    "numeric": "scara-pin numeric `solve_numeric`",
    "rtb_ets": "rtb `ik_LM` (C++) on the ETS, tol 1e-14",
    "rtb_dh": "rtb `DHRobot.ik_LM`, tol 1e-14",
    "rtb_ets_tight": "rtb `ik_LM` (C++) on the ETS, tol 1e-24",
}


def fmt_time(seconds: float, per: str) -> str:
    if seconds < 1e-6:
        return f"{seconds * 1e9:.0f} ns/{per}"
    return f"{seconds * 1e6:.1f} µs/{per}"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help=f"{QUICK_ROUNDS} rounds instead of {ROUNDS}")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the text")
    args = parser.parse_args(argv)
    rounds, n_batch = (QUICK_ROUNDS if args.quick else ROUNDS), N_BATCH
    start = time.perf_counter()

    robot = scara_pin.load_robot("default")
    geo = robot.kinematics
    _, targets = reachable_targets(robot, N_TARGETS, SEED)
    try:
        rtb = rtb_models(robot)
    except Mismatch as exc:
        print(f"error: {exc}; no timings reported", file=sys.stderr)
        return 1
    rtb_note = None
    if isinstance(rtb, str):
        rtb_note, rtb = rtb, None
    fns = solvers(robot, targets, rtb)
    route = "compiled" if _fast.speedups is not None else "pure Python fallback"
    q_mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2  # as in solvers()

    # accuracy (one pass, which also warms everything up)
    everything = range(N_TARGETS)
    acc, nearest_diff = {}, math.nan
    for name, fn in fns.items():
        results = fn(everything, True)
        if name == "nearest":
            try:
                nearest_diff = check_nearest(robot, results, targets, q_mid)
            except Mismatch as exc:
                print(f"error: {exc}; no timings reported", file=sys.stderr)
                return 1
        acc[name] = accuracy(robot, name, results, targets)
    T_batch = np.ascontiguousarray(targets[np.arange(n_batch) % N_TARGETS])
    for branch in ("right", "nearest"):
        acc[f"batch_{branch}"] = batch_accuracy(robot, solve_batch(geo, targets, branch=branch), targets)

    def batch(branch: str) -> float:
        gc.collect()
        t0 = time.perf_counter()
        solve_batch(geo, T_batch, branch=branch)
        return (time.perf_counter() - t0) / n_batch

    times = time_rounds(fns, N_TARGETS, batch, rounds)
    med = {k: statistics.median(v) for k, v in times.items()}
    ref = med.get("rtb_ets")
    rows = []
    for key in ["nearest", "closed", "batch_right", "batch_nearest", "numeric", "rtb_ets", "rtb_dh", "rtb_ets_tight"]:
        if key not in med:
            continue
        per = "target" if key.startswith("batch") else "call"
        row = {"key": key, "solver": LABELS[key], "seconds": med[key], "per": per, "min": min(times[key]),
               "max": max(times[key]), **acc[key]}  # fmt: skip
        if ref is not None and not key.startswith("batch"):
            row["vs_ik_LM"] = med[key] / ref
        rows.append(row)

    checks = []
    if ref is not None:
        speedup = ref / med["nearest"]
        checks.append(("closed form single call: ik_LM (ETS) time / ik_nearest", f"{speedup:.1f}x",
                       f">= {TARGET_CLOSED:g}x", speedup >= TARGET_CLOSED))  # fmt: skip
        slow = med["numeric"] / ref
        checks.append(("numeric: our time / ik_LM (ETS)", f"{slow:.2f}x", f"<= {TARGET_NUMERIC:g}x",
                       slow <= TARGET_NUMERIC))  # fmt: skip
        checks.append(("closed form single call: ik_LM (DHRobot) time / ik_nearest",
                       f"{med['rtb_dh'] / med['nearest']:.1f}x", f">= {TARGET_CLOSED:g}x",
                       med["rtb_dh"] / med["nearest"] >= TARGET_CLOSED))  # fmt: skip
        checks.append(("numeric: our time / ik_LM (DHRobot)", f"{med['numeric'] / med['rtb_dh']:.2f}x",
                       f"<= {TARGET_NUMERIC:g}x", med["numeric"] / med["rtb_dh"] <= TARGET_NUMERIC))  # fmt: skip
    checks.append(("closed form single call: ik_nearest solved (<= 1e-6, inside limits)",
                   f"{100 * acc['nearest']['solved']:.1f} %", "100 %", acc["nearest"]["solved"] == 1.0))  # fmt: skip
    rate = 1.0 / med["batch_right"]
    checks.append(("batch (branch=right): targets/s", f"{rate / 1e6:.1f} M/s", f">= {TARGET_BATCH / 1e6:g} M/s",
                   rate >= TARGET_BATCH))  # fmt: skip
    checks.append(("numeric: solved (<= 1e-6, inside limits)", f"{100 * acc['numeric']['solved']:.1f} %", "100 %",
                   acc["numeric"]["solved"] == 1.0))  # fmt: skip

    env = {
        "python": platform.python_version(),
        "pinocchio": pin.__version__,
        "numpy": np.__version__,
        "scara_pin": scara_pin.__version__,
        "route": route,
        "roboticstoolbox": None,
        "machine": platform.machine(),
        "targets": N_TARGETS,
        "seed": SEED,
        "rounds": rounds,
        "n_batch": n_batch,
        "elapsed_s": None,
    }
    if rtb is not None:
        import roboticstoolbox

        env["roboticstoolbox"] = roboticstoolbox.__version__
    env["elapsed_s"] = time.perf_counter() - start
    if args.json:
        keys = ("check", "value", "target", "met")
        checks_json = [dict(zip(keys, c, strict=True)) for c in checks]
        print(json.dumps({"env": env, "rtb_skipped": rtb_note, "rows": rows, "checks": checks_json,
                          "ik_nearest_vs_solve_max_abs_diff": nearest_diff}))  # fmt: skip
        return 0

    print(f"scara-pin {env['scara_pin']}, Pinocchio {env['pinocchio']}, numpy {env['numpy']}, "
          f"roboticstoolbox {env['roboticstoolbox'] or '-'}, Python {env['python']} ({env['machine']})")  # fmt: skip
    print(f"scara-pin route: {route} (scara_pin._fast.speedups is {'not ' if _fast.speedups is not None else ''}None)")
    print(f"robot `default` (l1 = l2 = {geo.l1:g} m); {N_TARGETS} reachable targets (FK of q uniform inside the "
          f"limits, seed {SEED}); median of {rounds} interleaved rounds; batch N = {n_batch:,}")  # fmt: skip
    if rtb_note:
        print(f"rtb: SKIPPED - {rtb_note}")
    else:
        print(f"rtb: DHRobot from D-H, fkine == scara-pin FK to {FK_TOL:g} on 100 q; ik_LM(q0 = middle of the ranges, "
              f"mask [1 1 1 0 0 1], joint_limits=True)")  # fmt: skip
    print(f"ik_nearest(T[i], q_mid = the ik_LM q0) == the nearest of solve's solutions on all {N_TARGETS} targets "
          f"(max |diff| {nearest_diff:.1e}; tol {FK_TOL:g})")  # fmt: skip
    print()
    head = "| solver | time (median) | max pose error | solved (≤ 1e-6, in limits) | time / ik_LM (ETS) |"
    lines = [head, "|---|---:|---:|---:|---:|"]
    for row in rows:
        t = fmt_time(row["seconds"], row["per"])
        if row["per"] == "target":
            t += f" ({1 / row['seconds'] / 1e6:.1f} M/s)"
        ratio = f"{row['vs_ik_LM']:.3g}" if "vs_ik_LM" in row else "—"
        lines.append(f"| {row['solver']} | {t} | {row['max_pose_error']:.1e} | {100 * row['solved']:.1f} % | {ratio} |")
    print("\n".join(lines))
    print()
    for name, value, target, met in checks:
        print(f"{'met   ' if met else 'MISSED'} {name}: {value} (target {target})")
    print()
    print("notes: batch branch=right returns the right elbow only; the targets whose right solution is outside "
          "the limits (J1) count as unsolved there - branch=nearest solves all of them. "
          f"took {env['elapsed_s']:.1f} s")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
