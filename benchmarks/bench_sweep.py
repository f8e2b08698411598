#!/usr/bin/env python
"""Benchmark: a sweep in this process against a local Dask cluster of 1, 2, ... workers (every core there is).

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_sweep.py [--variants N] [--workers W]``);
reported, not enforced (tests/test_sweep.py checks that the rows are the same; this measures what they cost).
The sweep: docs/examples/tray/frames.yaml (the tray's first two places in a frame, then home: 2 jumps and a straight
move to plan, about 1 s a variant on an idle core), its base moved over a grid of N placements in x (millimetres).

1. Serial: ``sweep(spec, workers=0)``, after one variant planned to warm the process (imports, the robot).
2. For W = 1 .. the cores: a ``LocalCluster`` of W single-threaded worker processes with the sweep's quiet settings,
   started for its run and closed after it (one cluster alive at a time), each worker warmed before the run is timed
   (the package imported, the robot made, one variant planned; the start-up column includes that warm-up).
3. Rounds (``--rounds``, 3 by default): in each, the serial sweep, then the same sweep on every cluster, and on
   the largest with ``--per-task`` variants a task (4 by default), one after the other, so that each round's runs
   share the machine's state; a round gives the speed-up T0 / T_W and the parallel efficiency per worker
   T0 / (W T_W) (the issue's promise: >= 0.85), and with W = 1 Dask's overhead per variant (T_1 - T0) / N against
   a variant's planning time T0 / N (< 5 %). The medians over the rounds are printed, and beside them the mean
   planning time a row reports (its own clock, in the worker): when the workers slow each other down (two planners
   on two cores beside the scheduler and this process), it grows with W, and that part of a lost efficiency is the
   machine's, not Dask's. One more cluster of 1 worker runs with Dask's default worker settings instead of the quiet
   ones (:data:`scara_pin.sweep.QUIET`): what quieting them is worth. And the same variants through the standard
   library's process pool (spawned, warmed, no Dask), as many processes as the largest cluster's workers: what
   this machine gives that many planners at once, whoever schedules them (a reference, not a way to run sweeps).
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
import math  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

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


def _defaults_client(stack: contextlib.ExitStack) -> Any:
    """A 1-worker local cluster with Dask's default worker settings (profiler, ticks, memory trimming): the quiet
    settings' effect."""
    import logging

    from distributed import Client, LocalCluster

    cluster = stack.enter_context(LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                               dashboard_address=":0", silence_logs=logging.ERROR))  # fmt: skip
    return stack.enter_context(Client(cluster, set_as_default=False))


@contextlib.contextmanager
def _plain_pool(n: int, spec_path: Path) -> object:
    """``n`` spawned processes of the standard library's pool, each warmed as a Dask worker is (a reference only)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from scara_pin.sweep import load_spec, recipe_of

    spec = load_spec(spec_path)
    with ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn")) as pool:
        from scara_pin.sweep import run_variant

        list(pool.map(run_variant, [recipe_of(spec)] * n, [next(spec.variants())] * n))  # each process warmed
        yield pool


def _on_pool(pool: object, spec: object) -> object:
    """The sweep's variants through the plain pool, one a task, as a DataFrame in the sweep's order."""
    import pandas as pd

    from scara_pin.sweep import recipe_of, run_variant

    variants = list(spec.variants())  # type: ignore[attr-defined]
    rows = list(pool.map(run_variant, [recipe_of(spec)] * len(variants), variants))  # type: ignore[attr-defined]
    return pd.DataFrame(rows)


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
        runs = [0, *sizes, -1, -2, -3]  # -1: the largest, --per-task variants a task; -2: Dask's defaults; -3: no Dask
        label = {0: "serial", **{w: f"{w} worker(s)" for w in sizes}, -2: "1 worker, Dask's default settings",
                 -1: f"{sizes[-1]} worker(s), {args.per_task} variants a task",
                 -3: f"{sizes[-1]} plain processes, no Dask (the machine's ceiling)"}  # fmt: skip
        workers_of = {**{w: w for w in sizes}, -1: sizes[-1], -2: 1, -3: sizes[-1]}

        def started(w: int, stack: contextlib.ExitStack) -> object:
            """The run's cluster (or pool), started and warmed; only one is alive at a time (an idle cluster's
            housekeeping would take the measured one's cores)."""
            if w == -3:
                return stack.enter_context(_plain_pool(sizes[-1], spec))
            client = _defaults_client(stack) if w == -2 else stack.enter_context(open_client(workers=workers_of[w]))
            _warm(client, spec)
            return client

        walls: dict[int, list[float]] = {w: [] for w in runs}
        planning: dict[int, list[float]] = {w: [] for w in runs}
        ups: dict[int, list[float]] = {w: [] for w in runs}
        serial = None
        tasks = math.nan
        for r in range(args.rounds):
            for w in runs:
                with contextlib.ExitStack() as stack:
                    begin = time.perf_counter()
                    engine = None if w == 0 else started(w, stack)
                    ups[w].append(time.perf_counter() - begin)  # with the warm-up: a first variant planned
                    start = time.perf_counter()
                    rows = (sweep(spec, workers=0) if w == 0 else _on_pool(engine, loaded) if w == -3 else
                            sweep(spec, engine, per_task=args.per_task if w == -1 else 1))  # fmt: skip
                    walls[w].append(time.perf_counter() - start)
                    if w == 1 and r == 0:
                        k = 2000
                        start = time.perf_counter()
                        engine.gather([engine.submit(_trivial, pure=False) for _ in range(k)])  # type: ignore
                        tasks = k / (time.perf_counter() - start)
                planning[w].append(float(rows["planning_time"].mean()))
                if serial is None:
                    serial = rows
                    assert (serial["status"] == "ok").all(), serial[["status", "reason"]]
                assert (rows["total"].to_numpy() == serial["total"].to_numpy()).all()
            print(f"round {r + 1}: " + ", ".join(f"{label[w]}: {walls[w][-1]:.2f} s" for w in runs), flush=True)
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
            up = "-" if w == 0 else f"{statistics.median(ups[w]):.1f}"
            lines.append(f"| {label[w]} | {up} | {tw:.2f} | {n / tw:.2f} | {speed:.2f} | {eff:.2f} "
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
