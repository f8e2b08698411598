#!/usr/bin/env python
"""Benchmark: scara-pin's inverse kinematics against Robotics Toolbox for Python's ``ik_LM`` and raw Pinocchio FK.

How to run. roboticstoolbox-python is a benchmark-only dependency: it lives in its own environment and
never becomes a dependency of scara-pin. ``make bench-ik`` creates that environment (``.venv-bench``) and
runs this script; by hand::

    python3 -m venv .venv-bench
    .venv-bench/bin/pip install roboticstoolbox-python -e .
    .venv-bench/bin/python benchmarks/bench_ik.py          # i.e. `python benchmarks/bench_ik.py` in that venv

With an interpreter that has no roboticstoolbox (``.venv/bin/python benchmarks/bench_ik.py``) the rtb rows
are skipped with a message, the targets against ``ik_LM`` are reported MISSED (not measured) and the rest is
still measured.

What is measured, in ONE run, on the ``default`` robot (l1 = l2 = 0.2 m, no continuous joint) and 1000
seeded reachable targets (x, y, z, yaw) = ``robot.tool_pose(q)`` of q drawn uniformly inside the joint
limits (seed 0), all through the public API:

- raw Pinocchio: one ``pin.framesForwardKinematics(robot.model, data, q)`` per call (``data`` created
  once from the same model), over the 1000 q the targets come from; the yardstick of the ratios below;
- ``robot.ik_nearest(target, q_mid)`` per call: the one closed-form solution nearest to q_mid, the middle
  of the joint ranges, i.e. the q0 that rtb's ``ik_LM`` gets (like ``ik_LM``, one q from one start);
- ``robot.ik(target, reference=q_mid)`` per call (one solution per branch, as result objects; for
  information);
- ``robot.ik_batch(T)`` on N = 10^6 targets (the 1000, tiled), per target: the default call
  (``reference=None``, i.e. q = 0, and ``branch="nearest"``: the solution of either branch nearest to the
  reference), and ``branch="right"`` (one elbow: a target whose right solution is outside the limits has
  none);
- numeric ``scara_pin.kinematics.numeric.solve_numeric(robot, target)`` (default start and options; for
  information);
- rtb: the same SCARA built as an ``rtb.DHRobot`` from standard D-H parameters read from
  ``robot.kinematics.geometry`` (l1, l2, z0; the joint limits); ``ik_LM`` is rtb's C++ Levenberg-Marquardt
  solver, called with q0 = q_mid, ``tol=1e-14`` (its E = e^T e / 2, i.e. |e| < 1.4e-7),
  ``mask=[1, 1, 1, 0, 0, 1]`` (x, y, z and the rotation about z: the 4 DOF), ``joint_limits=True``, on the
  4 x 4 pose ``robot.tool_placement(q).homogeneous`` of each target; once on the ETS built once
  (``dh.ets().ik_LM``: the C++ solver with the least Python in front of it, the reference of the ratios),
  once through ``DHRobot.ik_LM`` (the public route, which rebuilds the ETS and converts the target in
  Python on every call) and once more on the ETS with ``tol=1e-24`` (|e| < 1.4e-12, our accuracy).

Correctness gates, before any timing (on a failure the script says so on stderr and exits 1 untimed):

- ``ik_nearest(t, q_mid)`` equals, to 1e-12 on every target, the solution of
  ``robot.ik(t, reference=q_mid, all_turns=True)`` (every turn of every branch inside the limits) with the
  least sum_i (q_i - q_mid_i)^2, computed here; both must agree on whether a solution exists;
- every row of ``ik_batch(targets)`` (branch nearest) equals ``ik_nearest(t, 0)`` to 1e-12 where both
  solve, and every row of ``ik_batch(targets, branch="right")`` equals ``ik_nearest(t, 0, branch="right")``;
  rows where only one of them solves are counted and reported (not a stop: the gate is "where both solve");
- the timed call on the 10^6 tiled targets returns, row for row, what the call on the 1000 returned (1e-12,
  the same statuses): the blocks of the batch engine change nothing;
- rtb's ``fkine`` equals ``robot.tool_placement`` to 1e-12 on 100 random q (the same robot).

Accuracy, per solver and target: the pose error of the returned q under ``robot.tool_pose`` (max of |dp| [m]
and |d yaw| [rad]); "solved" = an answer within 1e-6 of the target AND inside the joint limits (for
``robot.ik``: a solution exists and every solution is within 1e-6 and inside; for ``ik_nearest``: it returns a
q rather than raising ``NoSolutionError``; for the batch: status 0).

Timing: each round times every per-call variant once over all 1000 targets, each as a plain ``for`` loop
over prepared inputs with the call inline (results dropped, garbage collector off), in an order that
alternates between rounds; then each batch call once, in alternating order. A per-call time is net of the
loop's own overhead (the same loop with an empty body, timed in the same round, subtracted; reported), so
that it is the call alone, as a batch's time per target is. The reported time is the median over the
rounds; a ratio is the ratio of two medians (the machine may be shared: compare within one run). Issue
12's targets (reported, not enforced: the exit code does not change):

- ``ik_nearest`` per call <= 1/5 of ``ik_LM`` (ETS, tol 1e-14) per call, and <= 10x one raw
  ``framesForwardKinematics`` call;
- ``ik_batch`` (default: nearest) per target <= 0.1x one raw ``framesForwardKinematics`` call, and
  >= 20 M targets/s (``branch="right"`` is reported alongside, without a target);

and, kept from the earlier version of this benchmark, ``ik_nearest`` solves 100 % of the (reachable) targets.

Options: ``--quick`` (fewer rounds), ``--json`` (one JSON object instead of the text).
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
from scara_pin.kinematics.numeric import solve_numeric

N_TARGETS = 1000
SEED = 0
N_BATCH = 10**6
ROUNDS, QUICK_ROUNDS = 7, 3
SOLVED_TOL = 1e-6
TOL = 1e-12
RTB_TOL, RTB_TOL_TIGHT = 1e-14, 1e-24
MASK = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 1.0])
TARGET_VS_IK_LM = 1 / 5  # ik_nearest time / ik_LM (ETS) time, at most
TARGET_NEAREST_VS_FFK = 10.0  # ik_nearest time / raw framesForwardKinematics time, at most
TARGET_BATCH_VS_FFK = 0.1  # ik_batch time per target / raw framesForwardKinematics time, at most
TARGET_BATCH_RATE = 20e6  # ik_batch targets per second, at least


class Mismatch(Exception):
    """A correctness gate failed: no timing is meaningful."""


# ---------------------------------------------------------------------------------------------- inputs
def reachable_targets(robot: scara_pin.Robot, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(q, targets): n configurations uniform inside the limits and their (x, y, z, yaw) under Pinocchio FK."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    qs = rng.uniform(lo, hi, size=(n, 4))
    return qs, np.array([robot.tool_pose(q) for q in qs])


def pose_error(robot: scara_pin.Robot, q: np.ndarray | None, target: np.ndarray) -> float:
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
    """(DHRobot, its ETS) of the same SCARA, or the reason rtb is not available; Mismatch if not the same robot."""
    try:
        import roboticstoolbox as rtb
    except ImportError as exc:
        return f"roboticstoolbox is not importable here ({exc}); see the header for the benchmark venv"
    geo = robot.kinematics.geometry
    # The D-H table of the `default` description (tool0 z down, the quill q3 moving down, all revolute
    # axes +z): Rz(q1) Tz(z0) Tx(l1) | Rz(q2) Tx(l2) Rx(pi) | Tz(q3) Rx(pi) | Rz(q4) Rx(pi).
    expected = dict(a1=(0.0, 0.0), tool=(0.0, 0.0), yaw0=0.0, signs=(1.0, 1.0, -1.0, 1.0), revolute=(0, 1, 3),
                    beta1=0.0, beta2=0.0)  # fmt: skip
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
    if not worst <= TOL:
        raise Mismatch(f"rtb fkine differs from scara-pin's tool_placement by {worst:.3g} (> {TOL:g})")
    return dh, dh.ets()


# ---------------------------------------------------------------------------------------------- per call
def per_call(
    robot: scara_pin.Robot, qs: np.ndarray, targets: np.ndarray, rtb: tuple[Any, Any] | None
) -> tuple[dict[str, Callable[[], float]], dict[str, Callable[[], list]]]:
    """(timing loops, collectors), each keyed by variant.

    A timing loop runs the variant once on every target - a plain ``for`` loop over prepared inputs with the
    call inline, results dropped - and returns the seconds taken. A collector returns the answers (for the
    accuracy check; ``None`` for ik_nearest's NoSolutionError).
    """
    model = robot.model
    data = model.createData()
    Q = [np.ascontiguousarray(q) for q in qs]  # each its own contiguous float64 array, as the user passes
    T = [t.copy() for t in targets]
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    mid = (lo + hi) / 2  # q0 of rtb's ik_LM and the reference of ik_nearest
    ffk = pin.framesForwardKinematics
    ik_nearest, ik, no_solution = robot.ik_nearest, robot.ik, scara_pin.NoSolutionError
    clock = time.perf_counter

    def t_ffk() -> float:
        t0 = clock()
        for q in Q:
            ffk(model, data, q)
        return clock() - t0

    def t_nearest() -> float:
        t0 = clock()
        for t in T:
            try:
                ik_nearest(t, mid)
            except no_solution:
                pass
        return clock() - t0

    def t_ik() -> float:
        t0 = clock()
        for t in T:
            ik(t, reference=mid)
        return clock() - t0

    def t_numeric() -> float:
        t0 = clock()
        for t in T:
            solve_numeric(robot, t)
        return clock() - t0

    def t_empty() -> float:
        t0 = clock()
        for _t in T:
            pass
        return clock() - t0

    def c_nearest() -> list:
        out: list[np.ndarray | None] = []
        for t in T:
            try:
                out.append(ik_nearest(t, mid))
            except no_solution:
                out.append(None)
        return out

    loops: dict[str, Callable[[], float]] = {"ffk": t_ffk, "nearest": t_nearest, "ik": t_ik, "numeric": t_numeric}
    collect: dict[str, Callable[[], list]] = {
        "nearest": c_nearest,
        "ik": lambda: [ik(t, reference=mid) for t in T],
        "numeric": lambda: [solve_numeric(robot, t) for t in T],
    }
    if rtb is not None:
        dh, ets = rtb
        M = [robot.tool_placement(q).homogeneous.copy() for q in Q]  # the 4 x 4 pose of each target
        ets_ik, dh_ik = ets.ik_LM, dh.ik_LM

        def rtb_loop(solver: Callable, tol: float) -> Callable[[], float]:
            def run() -> float:
                t0 = clock()
                for m in M:
                    solver(m, q0=mid, tol=tol, mask=MASK, joint_limits=True)
                return clock() - t0

            return run

        def rtb_collect(solver: Callable, tol: float) -> Callable[[], list]:
            return lambda: [solver(m, q0=mid, tol=tol, mask=MASK, joint_limits=True) for m in M]

        for key, solver, tol in (("rtb_ets", ets_ik, RTB_TOL), ("rtb_dh", dh_ik, RTB_TOL),
                                 ("rtb_ets_tight", ets_ik, RTB_TOL_TIGHT)):  # fmt: skip
            loops[key] = rtb_loop(solver, tol)
            collect[key] = rtb_collect(solver, tol)
    loops["empty"] = t_empty
    return loops, collect


def accuracy(robot: scara_pin.Robot, name: str, results: list, targets: np.ndarray) -> dict[str, float]:
    """Max pose error over the answers and the share of targets solved (<= 1e-6 and inside the limits)."""
    worst, solved = 0.0, 0
    for res, t in zip(results, targets, strict=True):
        if name == "ik":
            errs = [pose_error(robot, s.q, t) for s in res.solutions]
            ok = res.success and all(e <= SOLVED_TOL for e in errs) and all(inside(robot, s.q) for s in res.solutions)
        elif name == "nearest":  # a q, or None for NoSolutionError
            errs = [pose_error(robot, res, t)]
            ok = res is not None and errs[0] <= SOLVED_TOL and inside(robot, res)
        else:  # solve_numeric's result, rtb's IKSolution: .q and .success
            errs = [pose_error(robot, res.q, t)]
            ok = bool(res.success) and errs[0] <= SOLVED_TOL and inside(robot, res.q)
        finite = [e for e in errs if math.isfinite(e)]
        worst = max([worst, *finite])
        solved += ok
    return {"max_pose_error": worst, "solved": solved / len(targets)}


# ---------------------------------------------------------------------------------------------- gates
def check_nearest(robot: scara_pin.Robot, results: list, targets: np.ndarray, reference: np.ndarray) -> float:
    """Largest |ik_nearest - brute-force nearest of ``ik(all_turns=True)``| over the targets; Mismatch if > 1e-12.

    The nearest is computed here: the solution with the least sum_i (q_i - ref_i)^2 among every turn of every
    branch inside the limits. Both must answer "no solution" alike (None here for NoSolutionError).
    """
    if any(robot.kinematics.geometry.continuous):
        raise Mismatch("this gate's plain distance assumes no continuous joint (a continuous one wraps)")
    worst = 0.0
    for q, t in zip(results, targets, strict=True):
        sols = robot.ik(t, reference=reference, all_turns=True).solutions
        if (q is None) != (not sols):
            raise Mismatch(f"ik_nearest and ik(all_turns=True) disagree on whether {t.tolist()} has a solution")
        if q is None:
            continue
        d = [float(np.sum((s.q - reference) ** 2)) for s in sols]
        best = sols[int(np.argmin(d))].q
        worst = max(worst, float(np.abs(q - best).max()))
        if not worst <= TOL:
            raise Mismatch(f"ik_nearest({t.tolist()}) is {worst:.3g} away from the nearest of ik(all_turns=True)'s "
                           f"{len(sols)} solutions (> {TOL:g})")  # fmt: skip
    return worst


def check_batch(robot: scara_pin.Robot, res: Any, targets: np.ndarray, branch: str) -> dict[str, Any]:
    """Rows of ik_batch(targets, branch) against ik_nearest(t, 0[, branch="right"]); Mismatch if > 1e-12.

    Returns the largest difference where both solve and the rows where only one of them solves.
    """
    zero = np.zeros(4)
    nearest_branch = "all" if branch == "nearest" else branch
    worst, only_batch, only_nearest = 0.0, [], []
    for i, t in enumerate(targets):
        try:
            q = robot.ik_nearest(t, zero, branch=nearest_branch)
        except scara_pin.NoSolutionError:
            q = None
        batch_ok = int(res.status[i]) == 0
        if batch_ok and q is not None:
            worst = max(worst, float(np.abs(res.q[i] - q).max()))
            if not worst <= TOL:
                raise Mismatch(f"ik_batch(branch={branch!r}) row {i} ({t.tolist()}) is {worst:.3g} away from "
                               f"ik_nearest(t, 0, branch={nearest_branch!r}) (> {TOL:g})")  # fmt: skip
        elif batch_ok:
            only_batch.append(i)
        elif q is not None:
            only_nearest.append(i)
    return {"max_abs_diff": worst, "rows_only_batch_solves": only_batch, "rows_only_nearest_solves": only_nearest}


def check_tiled(small: Any, big: Any, branch: str) -> float:
    """The timed call on the tiled targets returns what the call on the 1000 did, row for row (1e-12)."""
    n = len(small.status)
    idx = np.arange(len(big.status)) % n
    if not np.array_equal(big.status, small.status[idx]):
        raise Mismatch(f"ik_batch(branch={branch!r}) on the {len(big.status):,} tiled targets gives other statuses")
    ok = big.status == 0
    diff = np.abs(big.q[ok] - small.q[idx][ok])
    worst = float(diff.max()) if diff.size else 0.0
    if not worst <= TOL or not np.isnan(big.q[~ok]).all():
        raise Mismatch(f"ik_batch(branch={branch!r}) on the tiled targets differs from the 1000 by {worst:.3g}")
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
def time_rounds(loops: dict[str, Callable[[], float]], batches: dict[str, Callable[[], float]],
                rounds: int) -> dict[str, list[float]]:  # fmt: skip
    """Seconds per call (per target for the batch), one value per round and variant.

    Each round runs every per-call loop once over all targets, in an order that alternates between rounds
    (so that a drift of the machine's speed hits all of them alike), then every batch call once, likewise.
    A per-call value is net of the plain loop's own overhead: the time of the ``empty`` loop (same targets,
    empty body) of the same round is subtracted (``empty`` itself is kept as measured).
    """
    for fn in loops.values():  # warm-up (caches, first-call costs), not recorded
        fn()
    names, bnames = list(loops), list(batches)
    samples: dict[str, list[float]] = {k: [] for k in [*names, *bnames]}
    for r in range(rounds):
        gc.collect()
        gc.disable()
        try:
            seconds = {name: loops[name]() for name in (names if r % 2 == 0 else names[::-1])}
        finally:
            gc.enable()
        for name in names:  # net of the loop's own overhead (the empty loop of the same round)
            net = seconds[name] if name == "empty" else seconds[name] - seconds["empty"]
            samples[name].append(net / N_TARGETS)
        for name in bnames if r % 2 == 0 else bnames[::-1]:
            gc.collect()
            samples[name].append(batches[name]() / N_BATCH)
    return samples


# ---------------------------------------------------------------------------------------------- report
LABELS = {
    "ffk": "raw Pinocchio `pin.framesForwardKinematics(model, data, q)`",
    "nearest": "scara-pin `robot.ik_nearest(T[i], q_mid)`",
    "ik": "scara-pin `robot.ik(T[i], reference=q_mid)` (per branch, objects)",
    "batch_nearest": "scara-pin `robot.ik_batch(T)` (reference None, branch nearest)",
    "batch_right": "scara-pin `robot.ik_batch(T, branch=\"right\")`",
    "numeric": "scara-pin numeric `solve_numeric(robot, T[i])`",
    "rtb_ets": "rtb `ik_LM` (C++) on the ETS, tol 1e-14",
    "rtb_dh": "rtb `DHRobot.ik_LM`, tol 1e-14",
    "rtb_ets_tight": "rtb `ik_LM` (C++) on the ETS, tol 1e-24",
}
ORDER = ["ffk", "nearest", "ik", "batch_nearest", "batch_right", "numeric", "rtb_ets", "rtb_dh", "rtb_ets_tight"]


def fmt_time(seconds: float, per: str) -> str:
    if seconds < 1e-6:
        return f"{seconds * 1e9:.1f} ns/{per}"
    return f"{seconds * 1e6:.2f} µs/{per}"


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help=f"{QUICK_ROUNDS} rounds instead of {ROUNDS}")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the text")
    args = parser.parse_args(argv)
    rounds = QUICK_ROUNDS if args.quick else ROUNDS
    start = time.perf_counter()

    robot = scara_pin.load_robot("default")
    geo = robot.kinematics.geometry
    qs, targets = reachable_targets(robot, N_TARGETS, SEED)
    q_mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2  # as in per_call()
    T_batch = np.ascontiguousarray(targets[np.arange(N_BATCH) % N_TARGETS])
    try:
        rtb = rtb_models(robot)
        rtb_note = None
        if isinstance(rtb, str):
            rtb_note, rtb = rtb, None
        loops, collect = per_call(robot, qs, targets, rtb)
        # accuracy and the gates (one pass, which also warms everything up)
        acc, gates = {}, {}
        for name, fn in collect.items():
            results = fn()
            if name == "nearest":
                gates["ik_nearest_vs_all_turns_max_abs_diff"] = check_nearest(robot, results, targets, q_mid)
            acc[name] = accuracy(robot, name, results, targets)
        for branch in ("nearest", "right"):
            small = robot.ik_batch(targets) if branch == "nearest" else robot.ik_batch(targets, branch=branch)
            gates[f"batch_{branch}_vs_ik_nearest"] = check_batch(robot, small, targets, branch)
            big = robot.ik_batch(T_batch) if branch == "nearest" else robot.ik_batch(T_batch, branch=branch)
            gates[f"batch_{branch}_tiled_max_abs_diff"] = check_tiled(small, big, branch)
            acc[f"batch_{branch}"] = batch_accuracy(robot, small, targets)
            del big
    except Mismatch as exc:
        print(f"error: correctness check failed, no timings reported: {exc}", file=sys.stderr)
        return 1

    ik_batch, clock = robot.ik_batch, time.perf_counter

    def batch_nearest() -> float:
        t0 = clock()
        ik_batch(T_batch)  # the default call: reference=None (q = 0), branch="nearest"
        return clock() - t0

    def batch_right() -> float:
        t0 = clock()
        ik_batch(T_batch, branch="right")
        return clock() - t0

    times = time_rounds(loops, {"batch_nearest": batch_nearest, "batch_right": batch_right}, rounds)
    med = {k: statistics.median(v) for k, v in times.items()}
    ffk, ref = med["ffk"], med.get("rtb_ets")
    rows = []
    for key in ORDER:
        if key not in med:
            continue
        per = "target" if key.startswith("batch") else "call"
        row: dict[str, Any] = {"key": key, "what": LABELS[key], "seconds": med[key], "per": per,
                               "min": min(times[key]), "max": max(times[key]), "vs_ffk": med[key] / ffk}  # fmt: skip
        row.update(acc.get(key, {}))
        if ref is not None and per == "call":
            row["vs_ik_LM"] = med[key] / ref
        rows.append(row)

    checks: list[tuple[str, str, str, bool]] = []
    if ref is not None:
        r = med["nearest"] / ref
        checks.append(("ik_nearest / ik_LM (ETS, C++) per call", f"{r:.3f}x (ik_LM {1 / r:.1f}x slower)",
                       f"<= {TARGET_VS_IK_LM:.2g}x (1/5)", r <= TARGET_VS_IK_LM))  # fmt: skip
    else:
        checks.append(("ik_nearest / ik_LM (ETS, C++) per call", "not measured (no roboticstoolbox here)",
                       f"<= {TARGET_VS_IK_LM:.2g}x (1/5)", False))  # fmt: skip
    r = med["nearest"] / ffk
    checks.append(("ik_nearest / raw framesForwardKinematics per call", f"{r:.2f}x",
                   f"<= {TARGET_NEAREST_VS_FFK:g}x", r <= TARGET_NEAREST_VS_FFK))  # fmt: skip
    r = med["batch_nearest"] / ffk
    checks.append(("ik_batch (nearest) per target / raw framesForwardKinematics per call", f"{r:.3f}x",
                   f"<= {TARGET_BATCH_VS_FFK:g}x", r <= TARGET_BATCH_VS_FFK))  # fmt: skip
    rate = 1.0 / med["batch_nearest"]
    checks.append(("ik_batch (nearest) targets/s", f"{rate / 1e6:.1f} M/s", f">= {TARGET_BATCH_RATE / 1e6:g} M/s",
                   rate >= TARGET_BATCH_RATE))  # fmt: skip
    checks.append(("ik_nearest solved (<= 1e-6, inside limits)", f"{100 * acc['nearest']['solved']:.1f} %", "100 %",
                   acc["nearest"]["solved"] == 1.0))  # fmt: skip
    info = (f"ik_batch branch=right: {1e-6 / med['batch_right']:.1f} M targets/s, "
            f"{med['batch_right'] / ffk:.3f}x raw framesForwardKinematics per target (no target)")  # fmt: skip

    env: dict[str, Any] = {
        "python": platform.python_version(),
        "pinocchio": pin.__version__,
        "numpy": np.__version__,
        "scara_pin": scara_pin.__version__,
        "roboticstoolbox": None,
        "machine": platform.machine(),
        "targets": N_TARGETS,
        "seed": SEED,
        "rounds": rounds,
        "n_batch": N_BATCH,
        "loop_overhead_ns": med["empty"] * 1e9,
        "elapsed_s": None,
    }
    if rtb is not None:
        import roboticstoolbox

        env["roboticstoolbox"] = roboticstoolbox.__version__
    env["elapsed_s"] = time.perf_counter() - start
    if args.json:
        keys = ("check", "value", "target", "met")
        print(json.dumps({"env": env, "rtb_skipped": rtb_note, "gates": {"tol": TOL, "ok": True, **gates},
                          "rows": rows, "checks": [dict(zip(keys, c, strict=True)) for c in checks],
                          "targets_met": all(c[3] for c in checks)}))  # fmt: skip
        return 0

    print(f"scara-pin {env['scara_pin']}, Pinocchio {env['pinocchio']}, numpy {env['numpy']}, "
          f"roboticstoolbox {env['roboticstoolbox'] or '-'}, Python {env['python']} ({env['machine']})")  # fmt: skip
    print(f"robot `default` (l1 = l2 = {geo.l1:g} m); {N_TARGETS} reachable targets (FK of q uniform inside the "
          f"limits, seed {SEED}); median of {rounds} interleaved rounds; "
          f"batch N = {N_BATCH:,} (the targets tiled)")  # fmt: skip
    if rtb_note:
        print(f"rtb: SKIPPED - {rtb_note}")
    else:
        print(f"rtb: DHRobot from D-H, fkine == tool_placement to {TOL:g} on 100 q; ik_LM(q0 = q_mid = middle of "
              "the ranges, mask [1 1 1 0 0 1], joint_limits=True)")  # fmt: skip
    nb, rb = gates["batch_nearest_vs_ik_nearest"], gates["batch_right_vs_ik_nearest"]
    print(f"gates (tol {TOL:g}): ik_nearest(T[i], q_mid) == nearest of ik(all_turns=True) on all {N_TARGETS} "
          f"(max |diff| {gates['ik_nearest_vs_all_turns_max_abs_diff']:.1e}); ik_batch rows == ik_nearest(T[i], 0) "
          f"where both solve (nearest {nb['max_abs_diff']:.1e}, right {rb['max_abs_diff']:.1e}; rows solved by one "
          f"only: nearest {len(nb['rows_only_batch_solves']) + len(nb['rows_only_nearest_solves'])}, right "
          f"{len(rb['rows_only_batch_solves']) + len(rb['rows_only_nearest_solves'])}); tiled N = {N_BATCH:,} == "
          "the 1000 row for row")  # fmt: skip
    print()
    lines = ["| variant | time (median) | min - max | / raw ffk | / ik_LM (ETS) | max pose error | solved |",
             "|---|---:|---:|---:|---:|---:|---:|"]  # fmt: skip
    for row in rows:
        t = fmt_time(row["seconds"], row["per"])
        if row["per"] == "target":
            t += f" ({1 / row['seconds'] / 1e6:.1f} M/s)"
        spread = f"{fmt_time(row['min'], row['per'])} - {fmt_time(row['max'], row['per'])}"
        vs_lm = f"{row['vs_ik_LM']:.3g}" if "vs_ik_LM" in row else "—"
        err = f"{row['max_pose_error']:.1e}" if "max_pose_error" in row else "—"
        solved = f"{100 * row['solved']:.1f} %" if "solved" in row else "—"
        lines.append(f"| {row['what']} | {t} | {spread} | {row['vs_ffk']:.3g} | {vs_lm} | {err} | {solved} |")
    print("\n".join(lines))
    print()
    for name, value, target, met in checks:
        print(f"{'met   ' if met else 'MISSED'} {name}: {value} (target {target})")
    print(f"info   {info}")
    print()
    print(f"notes: every per-call time is net of the plain loop's own overhead ({env['loop_overhead_ns']:.0f} ns/"
          "iteration, subtracted); batch branch=right returns the right elbow only: targets whose right solution is "
          f"outside the limits count as unsolved there. took {env['elapsed_s']:.1f} s")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
