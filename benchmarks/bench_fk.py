#!/usr/bin/env python
"""Benchmark: scara-pin's FK / task Jacobian against raw Pinocchio, and the CLI's cold start.

Run with the project's interpreter (``make bench`` or ``.venv/bin/python benchmarks/bench_fk.py``):

- per call: ``Robot.tool_placement(q)`` against ``pin.forwardKinematics`` + ``pin.updateFramePlacement``,
  and ``Robot.task_jacobian(q)`` against ``pin.computeFrameJacobian(..., LOCAL_WORLD_ALIGNED)``, the raw
  calls inline on the robot's own model and data, over 1000 seeded random q within the joint limits. Each
  round times every q once per variant, the package and the raw call taking turns block by block (ABBA),
  so that a drift of the machine's speed hits both; a per-call time is net of the loop's own overhead (the
  same loop with an empty body, timed in the same block, subtracted; reported), the reported time is the
  median over the rounds of the mean per-call time of a round, the ratio that of the two medians.
- cold start: whole-process wall time of ``scara-pin fk 0.1 0.2 0.05 0.3`` (the console script next to
  ``sys.executable``) against ``python -c "import pinocchio"`` with the same interpreter, interleaved,
  bytecode cached in a private temporary folder (see :func:`time_cold_start`; ``--inherit-env`` not to).

Before timing anything it checks that the package computes the same numbers as raw Pinocchio (1e-12),
that it still rejects NaN and wrongly shaped q, and that the CLI prints the same pose, so that a
fast-but-wrong change cannot look good: on any mismatch it says so and exits 1 without timing.
The targets (issue 12: FK and task Jacobian per call <= 2x raw Pinocchio; issue 21: cold start <= 1.3x
``import pinocchio``) are reported "met"/"MISSED", not enforced: missing one does not change the exit code.

Options: ``--quick`` (fewer rounds and runs), ``--json`` (one JSON object on stdout instead of the table),
``--inherit-env`` (cold start in the environment as is).
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

import scara_pin

TARGET_CALL = 2.0  # package / raw Pinocchio, per call (FK, task Jacobian)
TARGET_COLD = 1.3  # cold start of `scara-pin fk` / `python -c "import pinocchio"` (issue 21; issue 12 asked 1.5)
N_Q = 1000
SEED = 0
TOL = 1e-12
FK_ARGS = ("fk", "0.1", "0.2", "0.05", "0.3")
ROUNDS, QUICK_ROUNDS = 15, 5  # per-call rounds
RUNS, QUICK_RUNS = 10, 4  # whole-process runs of each command
BLOCK = 100  # q per interleaving block within a round


class Mismatch(Exception):
    """The package disagrees with raw Pinocchio (or stopped validating its input)."""


# ---------------------------------------------------------------------------------------------- inputs
def random_qs(robot: scara_pin.Robot, n: int, seed: int) -> list[np.ndarray]:
    """``n`` configurations drawn uniformly within the joint limits, each its own contiguous array."""
    rng = np.random.default_rng(seed)
    lower = np.asarray(robot.limits.lower, dtype=float)
    upper = np.asarray(robot.limits.upper, dtype=float)
    return [np.ascontiguousarray(row) for row in rng.uniform(lower, upper, size=(n, lower.size))]


# ---------------------------------------------------------------------------------------------- correctness
def raw_reference(robot: scara_pin.Robot, data: pin.Data, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """baseMtool (4 x 4) and the task Jacobian at ``q``, from raw Pinocchio calls on a separate ``data``.

    The task Jacobian, as documented: rows 1-3 the velocity of tool0's origin in base axes, row 4 the
    angular velocity about base z (Pinocchio's LOCAL_WORLD_ALIGNED Jacobian rotated into base axes).
    """
    model = robot.model
    tool = model.getFrameId(robot.tool_frame)
    base = model.getFrameId(robot.base_frame)
    pin.forwardKinematics(model, data, q)
    oMbase = pin.updateFramePlacement(model, data, base).copy()
    oMtool = pin.updateFramePlacement(model, data, tool).copy()
    J = pin.computeFrameJacobian(model, data, q, tool, pin.LOCAL_WORLD_ALIGNED)
    Rbo = oMbase.rotation.T  # base axes <- world axes
    return oMbase.actInv(oMtool).homogeneous, np.vstack([Rbo @ J[:3], (Rbo @ J[3:])[2]])


def check_correctness(robot: scara_pin.Robot, qs: Sequence[np.ndarray]) -> dict[str, float]:
    """Compare the package with raw Pinocchio on every q; return the largest differences."""
    data = robot.model.createData()  # a separate data: the reference shares nothing with the package's state
    fk_err = jac_err = 0.0
    for q in qs:
        ours_M = robot.tool_placement(q).homogeneous.copy()
        ours_J = np.array(robot.task_jacobian(q), dtype=float)
        ref_M, ref_J = raw_reference(robot, data, q)
        if ours_J.shape != (4, 4):
            raise Mismatch(f"task_jacobian returned shape {ours_J.shape}, not (4, 4)")
        fk_err = max(fk_err, float(np.max(np.abs(ours_M - ref_M))))
        jac_err = max(jac_err, float(np.max(np.abs(ours_J - ref_J))))
        if not (fk_err <= TOL and jac_err <= TOL):  # also catches NaN
            raise Mismatch(f"at q = {q.tolist()}: |FK - raw| = {fk_err:.3g}, |J - raw| = {jac_err:.3g} (> {TOL})")

    bad_inputs = {
        "NaN": np.array([np.nan, 0.0, 0.0, 0.0]),
        "inf": np.array([0.0, 0.0, np.inf, 0.0]),
        "3 values": np.zeros(3),
        "4x1 array": np.zeros((4, 1)),
    }
    for method in (robot.tool_placement, robot.task_jacobian):
        for label, bad in bad_inputs.items():
            try:
                method(bad)
            except scara_pin.ScaraError:
                continue
            except Exception as exc:  # noqa: BLE001 - any other exception is a validation regression
                raise Mismatch(f"{method.__name__}({label}) raised {type(exc).__name__}, not a ScaraError") from None
            raise Mismatch(f"{method.__name__}({label}) was accepted: input validation is gone")
    return {"fk_max_abs_err": fk_err, "jacobian_max_abs_err": jac_err}


def check_cli(script: Path, robot: scara_pin.Robot) -> float:
    """Run ``scara-pin fk ... --json`` once and compare its matrix with raw Pinocchio's."""
    proc = subprocess.run([str(script), *FK_ARGS, "--json"], capture_output=True, text=True, check=False)
    if proc.returncode != 0:
        raise Mismatch(f"`scara-pin {' '.join(FK_ARGS)} --json` exited {proc.returncode}: {proc.stderr.strip()}")
    out = json.loads(proc.stdout)
    q = np.array([float(v) for v in FK_ARGS[1:]])
    ref, _ = raw_reference(robot, robot.model.createData(), q)
    err = float(np.max(np.abs(np.array(out["matrix"], dtype=float) - ref)))
    if not err <= TOL:
        raise Mismatch(f"`scara-pin fk` prints a matrix {err:.3g} away from raw Pinocchio's (> {TOL})")
    return err


# ---------------------------------------------------------------------------------------------- per call
def per_call_loops(robot: scara_pin.Robot) -> dict[str, Callable[[Sequence[np.ndarray]], float]]:
    """One timing loop per variant, each returning the total seconds taken over the given q.

    The raw loops call Pinocchio inline (no Python wrapper of ours), on the robot's own model and data.
    """
    model, data = robot.model, robot.data
    fid = model.getFrameId(robot.tool_frame)
    fk, ufp = pin.forwardKinematics, pin.updateFramePlacement
    cfj, lwa = pin.computeFrameJacobian, pin.LOCAL_WORLD_ALIGNED
    tool_placement, task_jacobian = robot.tool_placement, robot.task_jacobian
    clock = time.perf_counter

    def ours_fk(qs: Sequence[np.ndarray]) -> float:
        t0 = clock()
        for q in qs:
            tool_placement(q)
        return clock() - t0

    def raw_fk(qs: Sequence[np.ndarray]) -> float:
        t0 = clock()
        for q in qs:
            fk(model, data, q)
            ufp(model, data, fid)
        return clock() - t0

    def ours_jac(qs: Sequence[np.ndarray]) -> float:
        t0 = clock()
        for q in qs:
            task_jacobian(q)
        return clock() - t0

    def raw_jac(qs: Sequence[np.ndarray]) -> float:
        t0 = clock()
        for q in qs:
            cfj(model, data, q, fid, lwa)
        return clock() - t0

    def empty(qs: Sequence[np.ndarray]) -> float:
        t0 = clock()
        for _q in qs:
            pass
        return clock() - t0

    return {"ours_fk": ours_fk, "raw_fk": raw_fk, "ours_jac": ours_jac, "raw_jac": raw_jac, "empty": empty}


def time_per_call(robot: scara_pin.Robot, qs: Sequence[np.ndarray], rounds: int) -> dict[str, list[float]]:
    """Mean seconds per call of each variant, one value per round.

    Each round times every variant once over all q. So that a drift of the machine's speed (frequency
    scaling, a neighbour) hits both sides of a comparison alike, a round is interleaved block by block:
    for each block of BLOCK q, the package and the raw call take turns, in an order that alternates
    between blocks and rounds (ABBA). Each value is net of the loop's own overhead: the empty loop over
    the same block, timed in the same block, is subtracted (``empty`` itself is kept as measured).
    """
    loops = per_call_loops(robot)
    pairs = [("ours_fk", "raw_fk"), ("ours_jac", "raw_jac")]
    blocks = [qs[i : i + BLOCK] for i in range(0, len(qs), BLOCK)]
    samples: dict[str, list[float]] = {name: [] for name in loops}
    for fn in loops.values():  # warm-up (caches, first-call costs), not recorded
        fn(qs)
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        for r in range(rounds):
            total = dict.fromkeys(loops, 0.0)
            for b, block in enumerate(blocks):
                empty = loops["empty"](block)
                for pair in pairs if (r + b) % 2 == 0 else pairs[::-1]:
                    for name in pair if (r + b) % 2 == 0 else pair[::-1]:
                        total[name] += loops[name](block) - empty
                total["empty"] += empty
            for name, seconds in total.items():
                samples[name].append(seconds / len(qs))
    finally:
        if gc_was_enabled:
            gc.enable()
    return samples


# ---------------------------------------------------------------------------------------------- cold start
def time_cold_start(script: Path, runs: int, inherit_env: bool) -> dict[str, list[float]]:
    """Whole-process wall times, the two commands interleaved (alternating which goes first).

    Unless ``inherit_env``, both commands run with their bytecode cached in a private temporary
    ``PYTHONPYCACHEPREFIX`` (filled by the warm-up runs), as for any installed package: this keeps a
    ``PYTHONDONTWRITEBYTECODE`` in the caller's environment from charging the package (an editable install,
    which has no ``.pyc`` files of its own) with recompiling its sources on every run, and writes nothing
    into the source tree. The description cache (scara_pin.description.cache) is a private temporary folder
    too: ``ours_cold`` runs with it filled by the warm-up (a robot used before, the usual case),
    ``ours_first`` with it turned off (the first run after an install or an edit of the robot's files).
    """
    commands = {
        "ours_cold": [str(script), *FK_ARGS],
        "ref_cold": [sys.executable, "-c", "import pinocchio"],
        "ours_first": [str(script), *FK_ARGS],
    }
    with tempfile.TemporaryDirectory(prefix="bench-fk-pycache-") as pycache:
        env = dict(os.environ)
        if not inherit_env:
            env.pop("PYTHONDONTWRITEBYTECODE", None)
            env["PYTHONPYCACHEPREFIX"] = pycache
        env["SCARA_PIN_CACHE_DIR"] = os.path.join(pycache, "description-cache")
        env.pop("SCARA_PIN_NO_CACHE", None)

        def run(cmd: list[str], name: str = "") -> float:
            t0 = time.perf_counter()
            extra = {"SCARA_PIN_NO_CACHE": "1"} if name == "ours_first" else {}
            proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env={**env, **extra},
                                  check=False)  # fmt: skip
            elapsed = time.perf_counter() - t0
            if proc.returncode != 0:
                err = proc.stderr.decode(errors="replace").strip()
                raise Mismatch(f"`{' '.join(cmd)}` exited {proc.returncode}: {err}")
            return elapsed

        for name, cmd in commands.items():  # warm-up: file cache, bytecode, the description cache
            run(cmd, name)
        samples: dict[str, list[float]] = {name: [] for name in commands}
        names = list(commands)
        for i in range(runs):
            for name in names if i % 2 == 0 else names[::-1]:
                samples[name].append(run(commands[name], name))
    return samples


# ---------------------------------------------------------------------------------------------- report
def metric(name: str, unit: str, scale: float, ours: list[float], ref: list[float], reference: str,
           target: float | None) -> dict:  # fmt: skip
    """Medians (in ``unit``), spread and the ratio of one metric (``target`` None: reported, no target)."""
    mo, mr = statistics.median(ours), statistics.median(ref)
    ratio = mo / mr
    return {
        "metric": name,
        "unit": unit,
        "reference": reference,
        "ours": mo * scale,
        "ref": mr * scale,
        "ours_min": min(ours) * scale,
        "ref_min": min(ref) * scale,
        "ours_max": max(ours) * scale,
        "ref_max": max(ref) * scale,
        "samples": len(ours),
        "ratio": ratio,
        "target": target,
        "met": None if target is None else ratio <= target,
    }


def table(metrics: list[dict]) -> str:
    """A markdown table: metric | ours | reference | ratio | target | met/MISSED."""
    lines = ["| metric | ours | reference | ratio | target | |", "|---|---:|---:|---:|---:|---|"]
    for m in metrics:
        fmt = "{:.2f} µs" if m["unit"] == "us" else "{:.0f} ms"
        lines.append(
            f"| {m['metric']} | {fmt.format(m['ours'])} | {fmt.format(m['ref'])} ({m['reference']}) "
            f"| {m['ratio']:.2f}x | {'' if m['target'] is None else '≤ {:g}x'.format(m['target'])} "
            f"| {'' if m['met'] is None else 'met' if m['met'] else 'MISSED'} |"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").split("\n", 1)[0])
    parser.add_argument("--quick", action="store_true", help=f"{QUICK_ROUNDS} rounds and {QUICK_RUNS} runs")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    parser.add_argument("--inherit-env", action="store_true",
                        help="cold start: run with the environment as is (default: bytecode cached in a private "
                        "PYTHONPYCACHEPREFIX, PYTHONDONTWRITEBYTECODE dropped)")  # fmt: skip
    args = parser.parse_args(argv)
    rounds, runs = (QUICK_ROUNDS, QUICK_RUNS) if args.quick else (ROUNDS, RUNS)

    script = Path(sys.executable).parent / "scara-pin"  # the venv's console script (do not resolve symlinks)
    if not script.exists():
        print(f"error: no console script {script}: install scara-pin into this interpreter's environment",
              file=sys.stderr)  # fmt: skip
        return 1

    start = time.perf_counter()
    robot = scara_pin.load_robot("default")
    qs = random_qs(robot, N_Q, SEED)
    try:
        errors = check_correctness(robot, qs)
        errors["cli_max_abs_err"] = check_cli(script, robot)
        calls = time_per_call(robot, qs, rounds)
        cold = time_cold_start(script, runs, args.inherit_env)
    except Mismatch as exc:
        print(f"error: correctness check failed, no timings reported: {exc}", file=sys.stderr)
        return 1

    metrics = [
        metric("FK `tool_placement(q)`", "us", 1e6, calls["ours_fk"], calls["raw_fk"],
               "forwardKinematics + updateFramePlacement", TARGET_CALL),
        metric("task Jacobian `task_jacobian(q)`", "us", 1e6, calls["ours_jac"], calls["raw_jac"],
               "computeFrameJacobian LWA", TARGET_CALL),
        metric(f"cold start `scara-pin {' '.join(FK_ARGS)}`", "ms", 1e3, cold["ours_cold"], cold["ref_cold"],
               "`python -c 'import pinocchio'`", TARGET_COLD),
        metric(f"first run `scara-pin {' '.join(FK_ARGS)}` (description cache off)", "ms", 1e3, cold["ours_first"],
               cold["ref_cold"], "`python -c 'import pinocchio'`", None),
    ]  # fmt: skip
    env = {
        "python": platform.python_version(),
        "pinocchio": pin.__version__,
        "numpy": np.__version__,
        "scara_pin": scara_pin.__version__,
        "machine": platform.machine(),
        "n_q": N_Q,
        "seed": SEED,
        "rounds": rounds,
        "cold_runs": runs,
        "cold_bytecode": "as inherited" if args.inherit_env else "cached (private PYTHONPYCACHEPREFIX)",
        "loop_overhead_us": statistics.median(calls["empty"]) * 1e6,
        "elapsed_s": time.perf_counter() - start,
    }
    missed = [m["metric"] for m in metrics if m["met"] is False]
    if args.json:
        print(json.dumps({"env": env, "correctness": {"tol": TOL, "ok": True, **errors}, "metrics": metrics,
                          "targets_met": not missed}))  # fmt: skip
        return 0
    print(
        f"scara-pin {env['scara_pin']}, Pinocchio {env['pinocchio']}, numpy {env['numpy']}, "
        f"Python {env['python']} ({env['machine']}); {N_Q} random q (seed {SEED}), median of {rounds} "
        f"interleaved rounds; cold start: median of {runs} interleaved runs, bytecode {env['cold_bytecode']}"
    )
    print(
        f"correctness: package == raw Pinocchio on all {N_Q} q (max |err| FK {errors['fk_max_abs_err']:.1e}, "
        f"Jacobian {errors['jacobian_max_abs_err']:.1e}, CLI {errors['cli_max_abs_err']:.1e}; tol {TOL:g}); "
        "NaN/inf/shape still rejected"
    )
    print()
    print(table(metrics))
    print()
    print(f"targets: {'all met' if not missed else 'MISSED: ' + '; '.join(missed)} "
          f"(loop overhead {env['loop_overhead_us']:.3f} µs/iteration, subtracted on both sides; "
          f"took {env['elapsed_s']:.1f} s)")  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
