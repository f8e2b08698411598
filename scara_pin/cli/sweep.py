"""The ``sweep`` command: a job planned over many variants on Dask, the rows in a Parquet folder (docs/sweep.md)."""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from typing import Any

from ..errors import InvalidInputError, ParameterError
from ..files import check_outputs
from ._numbers import number_type
from ._outputs import check_command_outputs

_SHOWN = ("total", "parts_per_hour", "steady_parts_per_hour", "binding")


def cmd_sweep(args: argparse.Namespace) -> int:
    """Read the sweep file, plan what is not answered yet in ``--out``, print the counts and the best variants."""
    from ..sweep import load_spec, open_client, sweep

    check_command_outputs(args, {"--plot": args.plot}, figures=("--plot",))
    if args.workers is not None and args.workers < 0:
        raise ParameterError("--workers", args.workers, "must be >= 0 (0: in this process, without Dask)")
    if args.workers and (args.scheduler or args.scheduler_file):
        raise InvalidInputError("--workers starts a local cluster; --scheduler and --scheduler-file use another")
    for name in ("timeout", "connect_timeout"):
        value = getattr(args, name)
        if value is not None and not 0 < value < math.inf:
            raise ParameterError(f"--{name.replace('_', '-')}", value, "must be > 0", "s")
    for name in ("batch", "per_task"):
        if getattr(args, name) < 1:
            raise ParameterError(f"--{name.replace('_', '-')}", getattr(args, name), "must be >= 1")
    spec = load_spec(args.file)
    check_outputs({"--plot": args.plot}, {"the job": [str(spec.job)]}, figures=("--plot",))  # nor over the job
    start = time.perf_counter()
    todo: list[Any] = []
    with _Bar(spec.count) as bar:
        common = {"out": args.out, "timeout": args.timeout, "batch": args.batch, "per_task": args.per_task,
                  "pending": todo, "progress": bar.update}  # fmt: skip
        if args.workers == 0:
            rows = sweep(spec, None, workers=0, **common)
        else:
            with open_client(args.workers, args.scheduler, args.scheduler_file, args.connect_timeout) as client:
                workers = len(client.scheduler_info(n_workers=-1).get("workers", {}))
                link = getattr(client, "dashboard_link", None)
                print(f"dask      {client.scheduler.address}: {workers} worker(s)"
                      f"{f'; dashboard {link}' if link else ''}", file=sys.stderr)  # fmt: skip
                rows = sweep(spec, client, **common)
    seconds = time.perf_counter() - start
    if args.plot:
        from ..job import Job
        from ..viz.sweep import plot_sweep

        plot_sweep(rows, args.plot, columns=spec.columns, units=Job.load(spec.job, text=spec.job_text).units)
    counts = rows["status"].value_counts().to_dict() if len(rows) else {}
    if args.json:
        print(json.dumps({"sweep": str(spec.path), "variants": spec.count, "run": len(todo), "counts": counts,
                          "seconds": seconds, "out": args.out,
                          "best": json.loads(_best(rows, spec.columns, args.best).to_json(orient="records"))}))
        return 0
    print(_report(spec, rows, counts, len(todo), seconds, args))
    return 0


def _best(rows: Any, columns: Any, n: int) -> Any:
    ok = rows[rows["status"] == "ok"]
    return ok.sort_values("parts_per_hour", ascending=False).head(n)[[*columns, *_SHOWN, "key"]]


def _report(spec: Any, rows: Any, counts: dict[str, int], ran: int, seconds: float, args: Any) -> str:
    from ..sweep import STATUSES

    said = ", ".join(f"{counts.get(s, 0)} {s}" for s in STATUSES)
    lines = [f"sweep     {spec.path}: {spec.count:,} variants of {spec.job}",
             f"results   {said}; {ran:,} run now, {len(rows) - ran:,} from earlier runs; {seconds:.3g} s",
             f"written   {args.out}"]  # fmt: skip
    best = _best(rows, spec.columns, args.best)
    if len(best):
        lines.append(f"best      {len(best)} by parts per hour:")
        lines.extend("  " + line for line in best.drop(columns="key").to_string(index=False).splitlines())
    failed = counts.get("failed", 0) + counts.get("timeout", 0)
    if failed:
        first = rows[rows["status"].isin(("failed", "timeout"))].iloc[0]
        lines.append(f"warning   {failed} variant(s) failed or timed out (a rerun runs them again); the first: "
                     f"{first['reason'][:200]}")  # fmt: skip
    if args.plot:
        lines.append(f"wrote     plot: {args.plot}")
    return "\n".join(lines)


class _Bar:
    """A progress bar with its ETA on a terminal (tqdm), nothing otherwise."""

    def __init__(self, total: int) -> None:
        self._bar: Any = None
        self._total = total

    def __enter__(self) -> _Bar:
        if sys.stderr.isatty():
            from tqdm import tqdm

            self._bar = tqdm(total=None, desc="sweep", unit="variant", file=sys.stderr, leave=False)
        return self

    def update(self, done: int, total: int) -> None:
        if self._bar is not None:
            self._bar.total = total
            self._bar.update(done - self._bar.n)

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.close()


def register(sub: Any) -> None:
    """Add the ``sweep`` command to the ``scara-pin`` subparsers."""
    p = sub.add_parser("sweep", help="a job over many variants (robots, placements, speeds) on Dask: a row per "
                       "variant in a Parquet folder, the best printed, a rerun resumes")  # fmt: skip
    p.add_argument("file", metavar="SPEC", help="the sweep file (.yaml: job, vary, samples; docs/sweep.md)")
    p.add_argument("--out", required=True, metavar="FOLDER", help="the results: a folder of Parquet part files "
                   "(made if missing); the variants already answered there are not run again")  # fmt: skip
    g = p.add_argument_group("where the variants run (default: a local cluster, one worker process per core)")
    g.add_argument("--workers", type=int, metavar="N", help="a local cluster of N single-threaded worker processes; "
                   "0: one after the other in this process, without Dask")  # fmt: skip
    g.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler (tcp://host:8786); "
                   "DASK_SCHEDULER_ADDRESS says it too")  # fmt: skip
    g.add_argument("--scheduler-file", metavar="FILE", help="an existing scheduler's file (dask scheduler "
                   "--scheduler-file, dask-jobqueue, dask-mpi)")  # fmt: skip
    g.add_argument("--connect-timeout", type=number_type("--connect-timeout"), default=10.0, metavar="S",
                   help="how long an existing scheduler is waited for (default 10 s)")  # fmt: skip
    g.add_argument("--timeout", type=number_type("--timeout"), metavar="S",
                   help="a variant's time limit (replaces the sweep file's timeout:)")  # fmt: skip
    g.add_argument("--per-task", type=int, default=1, metavar="K",
                   help="variants planned in one task (default 1; more: fewer tasks for a large cluster's scheduler; "
                   "a killed worker's task runs again whole)")  # fmt: skip
    g.add_argument("--batch", type=int, default=256, metavar="N",
                   help="rows per Parquet part file (default 256; a part is also written every 30 s)")  # fmt: skip
    g = p.add_argument_group("outputs")
    g.add_argument("--plot", metavar="PNG", help="parts per hour over the placement grid (a heat map), or a Pareto "
                   "front of parts per hour (.png, .svg, .pdf)")  # fmt: skip
    g.add_argument("--best", type=int, default=5, metavar="K", help="the K best variants printed (default 5)")
    g.add_argument("--json", action="store_true", help="print one JSON object {variants, run, counts, seconds, "
                   "best: [...]}")  # fmt: skip
    p.set_defaults(func=cmd_sweep)
