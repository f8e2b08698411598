#!/usr/bin/env python
"""Benchmark: a sweep in this process against a local Dask cluster of 1, 2, ... workers (every core there is).

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_sweep.py [--variants N] [--workers W]``);
reported, not enforced (tests/test_sweep.py checks that the rows are the same; this measures what they cost).
The sweep: docs/examples/tray/frames.yaml (the tray's first two places in a frame, then home: 2 jumps and a straight
move to plan, about 1 s a variant on an idle core), its base moved over a grid of N placements in x (millimetres).

1. Serial: ``sweep(spec, workers=0)``, after one variant planned to warm the process (imports, the robot).
2. For W = 1 .. the cores: a ``LocalCluster`` of W single-threaded worker processes with the sweep's quiet settings
   (its start-up timed apart), each worker warmed (the package imported, the robot made, one variant planned).
3. Rounds (``--rounds``, 3 by default): in each, the serial sweep, then the same sweep on every cluster, and on
   the largest with ``--per-task`` variants a task (4 by default), one after the other, so that each round's runs
   share the machine's state; a round gives the speed-up T0 / T_W and the parallel efficiency per worker
   T0 / (W T_W) (the issue's promise: >= 0.85), and with W = 1 Dask's overhead per variant (T_1 - T0) / N against
   a variant's planning time T0 / N (< 5 %). The medians over the rounds are printed, and beside them the mean
   planning time a row reports (its own clock, in the worker): when the workers slow each other down (two planners
   on two cores beside the scheduler and this process), it grows with W, and that part of a lost efficiency is the
   machine's, not Dask's. One more cluster of 1 worker runs with Dask's default worker settings instead of the quiet
   ones (:data:`scara_pin.sweep.QUIET`): what quieting them is worth.
4. Dask's own cost: 2,000 trivial tasks through the 1-worker cluster at once (the scheduler's tasks per second),
   and a row's bytes in Parquet (the serial rows copied to about 10,000, every key and number made distinct).

Machines shared with other work give noisy numbers: the load average is printed before and after. This process
runs with one BLAS / OpenMP thread (set before numpy is imported), as Dask's workers do: the serial figure is one
core's.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):  # one core, as Dask's workers have
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
JOB = REPO / "docs" / "examples" / "tray" / "frames.yaml"


def _spec(folder: Path, n: int) -> Path:
    path = folder / "sweep.yaml"
    path.write_text(f"job: {JOB}\nvary:\n  base.xyz: {{from: [-40, 0, 0], to: [40, 0, 0], steps: [{n}, 1, 1]}}\n")
    return path


def _warm(client: object, spec_path: Path) -> None:
    """Every worker: the package imported, the robot made, one variant planned (what a long sweep amortizes)."""
    from scara_pin.sweep import load_spec, recipe_of, run_variant

    spec = load_spec(spec_path)
    recipe, first = recipe_of(spec), next(spec.variants())
    client.run(run_variant, recipe, first)  # type: ignore[attr-defined]


def _defaults_client(stack: contextlib.ExitStack) -> object:
    """A 1-worker local cluster with Dask's default worker settings (profiler, ticks, memory trimming): the quiet
    settings' effect."""
    import logging

    from distributed import Client, LocalCluster

    cluster = stack.enter_context(LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                               dashboard_address=":0", silence_logs=logging.ERROR))  # fmt: skip
    return stack.enter_context(Client(cluster, set_as_default=False))


def _trivial() -> None:
    return None


def main() -> int:
    import statistics

    from scara_pin.sweep import open_client, sweep
    from scara_pin.sweep.engine import cores

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variants", type=int, default=24)
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (serial, 1, 2, ... workers)")
    parser.add_argument("--workers", type=int, default=cores(), help="the largest cluster (default: every core)")
    parser.add_argument("--per-task", type=int, default=4, help="also the largest cluster with K variants a task")
    args = parser.parse_args()
    n = args.variants
    folder = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    try:
        spec = _spec(folder, n)
        print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores ({cores()} usable)")
        from scara_pin.sweep import load_spec, recipe_of, run_variant

        loaded = load_spec(spec)
        run_variant(recipe_of(loaded), next(loaded.variants()))  # warm this process
        sizes = list(range(1, args.workers + 1))
        with contextlib.ExitStack() as stack:
            clients, ups = {}, {}
            for w in sizes:
                begin = time.perf_counter()
                clients[w] = stack.enter_context(open_client(workers=w))
                ups[w] = time.perf_counter() - begin
                _warm(clients[w], spec)
            begin = time.perf_counter()
            clients[-2] = _defaults_client(stack)  # -2: one worker with Dask's default settings, not the quiet ones
            ups[-2] = time.perf_counter() - begin
            _warm(clients[-2], spec)
            clients[-1], ups[-1] = clients[sizes[-1]], ups[sizes[-1]]  # -1: the largest, --per-task variants a task
            runs = [0, *sizes, -1, -2]
            label = {0: "serial", **{w: f"{w} worker(s)" for w in sizes}, -2: "1 worker, Dask's default settings",
                     -1: f"{sizes[-1]} worker(s), {args.per_task} variants a task"}  # fmt: skip
            workers_of = {**{w: w for w in sizes}, -1: sizes[-1], -2: 1}
            walls: dict[int, list[float]] = {w: [] for w in runs}
            planning: dict[int, list[float]] = {w: [] for w in runs}
            serial = None
            for r in range(args.rounds):
                for w in runs:
                    start = time.perf_counter()
                    rows = (sweep(spec, workers=0) if w == 0 else
                            sweep(spec, clients[w], per_task=args.per_task if w == -1 else 1))  # fmt: skip
                    walls[w].append(time.perf_counter() - start)
                    planning[w].append(float(rows["planning_time"].mean()))
                    if serial is None:
                        serial = rows
                        assert (serial["status"] == "ok").all(), serial[["status", "reason"]]
                    assert (rows["total"].to_numpy() == serial["total"].to_numpy()).all()
                print(f"round {r + 1}: " + ", ".join(f"{label[w]}: {walls[w][-1]:.2f} s" for w in runs), flush=True)
            k = 2000
            start = time.perf_counter()
            clients[1].gather([clients[1].submit(_trivial, pure=False) for _ in range(k)])
            tasks = k / (time.perf_counter() - start)
        assert serial is not None
        t0s = walls[0]
        t0 = statistics.median(t0s)
        per = t0 / n
        print(f"\n{n} variants of {JOB.relative_to(REPO)} (base.xyz over {n} placements), {args.rounds} rounds")
        header = ("| run | start-up [s] | wall [s] | variants/s | speed-up | efficiency per worker "
                  "| a row's planning time [s] |")
        lines = [header, "|---|---|---|---|---|---|---|",
                 f"| serial (`--workers 0`) | - | {t0:.2f} | {n / t0:.2f} | 1.00 | - "
                 f"| {statistics.median(planning[0]):.3f} |"]  # fmt: skip
        for w in runs[1:]:
            tw = statistics.median(walls[w])
            speed = statistics.median(a / b for a, b in zip(t0s, walls[w]))
            eff = statistics.median(a / (workers_of[w] * b) for a, b in zip(t0s, walls[w]))
            lines.append(f"| {label[w]} | {ups[w]:.1f} | {tw:.2f} | {n / tw:.2f} | {speed:.2f} | {eff:.2f} "
                         f"| {statistics.median(planning[w]):.3f} |")  # fmt: skip
        overhead = statistics.median((b - a) / n for a, b in zip(t0s, walls[1]))
        share = statistics.median((b - a) / a for a, b in zip(t0s, walls[1]))  # of a variant's time, paired
        from scara_pin.sweep import ResultStore, row_schema

        copies = 10_000 // n + 1  # a part file of about 10,000 rows (each key made distinct): bytes per row
        store = ResultStore(folder / "rows", row_schema(loaded.vary), batch=copies * n)
        import numpy as np

        rng = np.random.default_rng(0)
        for row in serial.to_dict("records") * copies:  # every number and key its own, as a sweep's are
            jitter = 1 + 1e-3 * rng.random()
            store.add({**row, "key": rng.bytes(16).hex(), "total": row["total"] * jitter,
                       "parts_per_hour": row["parts_per_hour"] / jitter, "planning_time": rng.random(),
                       "base.xyz": [float(v) + rng.random() for v in row["base.xyz"]]})  # fmt: skip
        store.flush()
        rows_written = copies * n
        size = sum(p.stat().st_size for p in store.parts())
        print("\n" + "\n".join(lines))
        print(f"\nDask's overhead per variant (1 worker against serial): {overhead * 1e3:.1f} ms = "
              f"{100 * share:.1f} % of a variant's {per:.3f} s (medians of the rounds' pairs)")  # fmt: skip
        print(f"trivial tasks through the scheduler, 2,000 at once: {tasks:,.0f} tasks/s "
              f"({1e3 / tasks:.2f} ms a task)")  # fmt: skip
        print(f"Parquet: {size:,} bytes for {rows_written:,} rows in one part file ({size / rows_written:.0f} bytes "
              "a row)")  # fmt: skip
        print(f"load average after: {os.getloadavg()[0]:.2f}")
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
