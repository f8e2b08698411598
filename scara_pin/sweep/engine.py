"""Where the variants run: in this process, on a local Dask cluster, or on an existing one (docs/sweep.md).

- ``workers=0``: one after the other in the caller's process (no Dask at all): the reference the parallel runs
  are checked against.
- Default: a ``distributed.LocalCluster`` of one single-threaded worker PROCESS per core (the planner holds the
  GIL), with Dask's per-worker housekeeping quieted (:data:`QUIET`: no statistical profiler, slow event-loop and
  system monitors, glibc's memory trimming at 256 MiB instead of 64 KiB): with Dask's defaults a worker spent
  30-40 % of a core beside its task (measured before issue 36; not reproduced on the loaded machine since). The
  workers leave Ctrl-C to the client (:mod:`~scara_pin.sweep.preload`).
- An existing cluster: a scheduler's address (``tcp://host:8786``), its scheduler file (``dask scheduler
  --scheduler-file``; what dask-jobqueue and dask-mpi write), ``DASK_SCHEDULER_ADDRESS``, or a ``Client`` handed
  in: SLURM (dask-jobqueue), Kubernetes (dask-kubernetes) and the rest without code here.

A task is one variant, or ``per_task`` variants in a row (:func:`~scara_pin.sweep.task.run_batch`): on a large
cluster with short variants the scheduler's cost per task (milliseconds) is what batching divides; the price is
that a killed worker's batch runs again whole and its rows reach the client together. The client keeps a bounded
window of tasks in flight (a few per worker thread: 10^6 futures at once would burden the scheduler), writes each
finished row through the store, and resubmits nothing itself: a worker that dies takes its tasks with it and the
scheduler runs them elsewhere (a task whose workers die three times is a ``failed`` row for each of its variants).
Rows are written by the client only, once per key. Ctrl-C writes every finished row, cancels the rest and stops (a
rerun runs what is left).
"""

from __future__ import annotations

import logging
import os
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from ..errors import InvalidInputError
from .task import Recipe, run_batch, run_variant

if TYPE_CHECKING:
    from distributed import Client

    from .spec import Variant
    from .store import ResultStore

__all__ = ["CONNECT_TIMEOUT", "QUIET", "Progress", "cores", "open_client", "run_variants"]

QUIET: dict[str, Any] = {
    "distributed.worker.profile.enabled": False,  # the statistical profiler samples every thread every 10 ms
    "distributed.worker.profile.interval": "1h",
    "distributed.worker.profile.cycle": "2h",
    "distributed.admin.tick.interval": "1s",  # the event loop's health tick (20 ms by default)
    "distributed.admin.tick.limit": "1h",  # a planner holding the GIL for seconds is no news
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": str(256 * 1024 * 1024),
}
"""Dask settings of the sweep's local workers (module docstring); a cluster started elsewhere takes them from its
own configuration (docs/sweep.md gives them as yaml)."""
CONNECT_TIMEOUT = 10.0
"""[s] how long an existing scheduler is waited for before the sweep is refused."""
_IN_FLIGHT_PER_THREAD = 4
_IN_FLIGHT_MIN = 16

Progress = Callable[[int, int], None]
"""Called with (variants finished, variants to run) after each."""


def cores() -> int:
    """The cores this process may use (its CPU affinity), at least 1."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


@contextmanager
def open_client(workers: int | None = None, scheduler: str | None = None, scheduler_file: str | None = None,
                connect_timeout: float = CONNECT_TIMEOUT) -> Iterator[Client]:  # fmt: skip
    """A Dask client, closed on exit: to an existing scheduler, else to a new local cluster.

    The scheduler: ``scheduler`` (an address), ``scheduler_file``, or ``DASK_SCHEDULER_ADDRESS``; the local cluster:
    ``workers`` single-threaded processes (default: one per core), quieted (:data:`QUIET`).

    Raises:
        InvalidInputError: the scheduler cannot be reached within ``connect_timeout`` (exit 2), an unreadable
            scheduler file, ``workers`` < 1.
    """
    import dask
    from distributed import Client, LocalCluster

    address = scheduler or (None if scheduler_file else os.environ.get("DASK_SCHEDULER_ADDRESS") or None)
    if address or scheduler_file:
        where = f"scheduler {address}" if address else f"scheduler file {scheduler_file}"
        if scheduler_file:
            from ..limits import check_input_file

            check_input_file(scheduler_file, "scheduler file")
        try:
            client = Client(address, scheduler_file=scheduler_file, timeout=f"{connect_timeout}s",
                            set_as_default=False)  # fmt: skip
        except (OSError, TimeoutError, ValueError) as exc:
            raise InvalidInputError(f"cannot reach the {where} within {connect_timeout:g} s: "
                                    f"{' '.join(str(exc).split()) or type(exc).__name__}") from None  # fmt: skip
        try:
            yield client
        finally:
            client.close()
        return
    n = cores() if workers is None else workers
    if n < 1:
        raise InvalidInputError(f"--workers {n}: a local cluster needs at least one worker (0: no Dask, in process)")
    with dask.config.set({**QUIET, "distributed.worker.preload": [*dask.config.get("distributed.worker.preload"),
                                                                   "scara_pin.sweep.preload"]}):  # fmt: skip
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.ERROR)  # fmt: skip
        client = Client(cluster, set_as_default=False)
    try:
        yield client
    finally:
        client.close()
        cluster.close()


def run_variants(recipe: Recipe, variants: list[Variant], store: ResultStore, client: Client | None,
                 progress: Progress | None = None, per_task: int = 1) -> None:  # fmt: skip
    """Run ``variants`` (in this process when ``client`` is None) and add each row to ``store`` as it finishes.

    ``per_task`` variants make one task on a cluster (module docstring).

    Ctrl-C (``KeyboardInterrupt``), SIGTERM or any error (a scheduler lost): the finished rows are written
    (:meth:`ResultStore.flush`), the futures cancelled, and the interruption or error raised again.
    """
    from ..signals import handled

    try:
        if client is None:
            for n, v in enumerate(variants):
                store.add(run_variant(recipe, v))
                if progress is not None:
                    progress(n + 1, len(variants))
        else:
            _on_cluster(recipe, variants, store, client, progress, per_task)
    except BaseException as exc:  # Ctrl-C, SIGTERM (Terminated), a scheduler lost: the finished rows are written
        if isinstance(exc, KeyboardInterrupt):
            import signal

            from ..signals import Terminated

            handled(signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT)  # else the writer refuses
        store.flush()
        raise
    store.flush()


def _on_cluster(recipe: Recipe, variants: list[Variant], store: ResultStore, client: Client,
                progress: Progress | None, per_task: int) -> None:  # fmt: skip
    from distributed import as_completed

    run = uuid.uuid4().hex[:8]  # a task key per run: a result kept from an earlier run of this client is not reused
    todo = iter([variants[k:k + per_task] for k in range(0, len(variants), per_task)])
    of: dict[str, list[Variant]] = {}
    flying = as_completed(loop=client.loop)

    def submit() -> bool:
        batch = next(todo, None)
        if batch is None:
            return False
        future = client.submit(run_batch, recipe, batch, key=f"sweep-{batch[0].key}-{run}", pure=False)
        of[str(future.key)] = batch
        flying.add(future)
        return True

    window = max(_IN_FLIGHT_MIN, _IN_FLIGHT_PER_THREAD * max(1, sum(client.nthreads().values())))
    for _ in range(window):
        if not submit():
            break
    done = 0
    try:
        for future in flying:
            batch = of.pop(str(future.key))
            try:
                rows = future.result()
            except Exception as exc:  # the task never raises: its workers died (KilledWorker), a lost connection
                reason = f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:2000]
                rows = [{**dict(v.values), "variant": v.index, "key": v.key, "status": "failed", "reason": reason,
                         "worker": ""} for v in batch]  # fmt: skip
            future.release()
            for row in rows:
                store.add(row)
            done += len(rows)
            if progress is not None:
                progress(done, len(variants))
            submit()
    except BaseException:
        client.cancel([f for f in flying.futures], force=True)
        raise

