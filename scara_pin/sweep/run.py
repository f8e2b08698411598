"""``sweep(spec)``: every variant of a sweep file planned, the rows on disk and as a ``pandas.DataFrame``."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import ParameterError
from .engine import Progress, open_client, run_variants
from .spec import SweepSpec, load_spec
from .store import ResultStore, row_schema
from .task import Recipe

if TYPE_CHECKING:
    import pandas as pd
    from distributed import Client

__all__ = ["recipe_of", "sweep"]


def recipe_of(spec: SweepSpec) -> Recipe:
    """What every task of ``spec`` gets: the job's path and text, the robots' recipes, the time limit."""
    default = next(iter(spec.robots))
    # the job's absolute path: a worker elsewhere (another folder, another machine on a shared file system) finds
    # the files the job names beside it
    return Recipe(str(spec.job.resolve()), spec.job_text, tuple(spec.robots.items()), default, spec.timeout)


def sweep(spec: SweepSpec | str | os.PathLike[str], client: Client | None = None, *, out: str | Path | None = None,
          workers: int | None = None, scheduler: str | None = None, scheduler_file: str | None = None,
          timeout: float | None = None, batch: int = 256, per_task: int = 1, progress: Progress | None = None,
          pending: list[Any] | None = None) -> pd.DataFrame:  # fmt: skip
    """Plan every variant of a sweep (docs/sweep.md) and return one row per variant, in the sweep's order.

    Args:
        spec: a sweep file, or one read (:func:`~scara_pin.sweep.spec.load_spec`).
        client: a Dask ``distributed.Client`` to run on; None: ``scheduler`` / ``scheduler_file`` /
            ``DASK_SCHEDULER_ADDRESS`` if given, else a local cluster of ``workers`` processes (default: one per
            core), or this process alone with ``workers=0``.
        out: the results folder (Parquet part files); the variants already answered there are not run again.
            None: nothing written.
        workers: the local cluster's worker processes (default: one per core); 0: this process, no Dask.
        scheduler: an existing scheduler's address (``tcp://host:8786``), when ``client`` is None.
        scheduler_file: an existing scheduler's file (``dask scheduler --scheduler-file``), when ``client`` is None.
        timeout: [s] a variant's time limit (replaces the file's ``timeout``).
        batch: rows per part file.
        per_task: variants planned in one task on a cluster (1: a task each; more: fewer tasks for the scheduler of
            a large cluster, a killed worker's batch run again whole; docs/sweep.md).
        progress: called with (variants finished, variants to run) after each.
        pending: if a list, the variants this call runs are put in it before they run (the command line's count).

    Returns:
        A ``pandas.DataFrame``: a column per varied key (as the file spells it), then ``variant``, ``key``,
        ``status``, ``reason``, ``total``, ``parts_per_hour``, ``steady_parts_per_hour``, ``binding``,
        ``binding_share``, ``closest_pair``, ``closest_distance``, ``cell_cost``, ``planning_time``, ``worker``.
    """
    if isinstance(per_task, bool) or not isinstance(per_task, int) or per_task < 1:
        raise ParameterError("per_task", per_task, "must be a whole number >= 1")
    if not isinstance(spec, SweepSpec):
        spec = load_spec(Path(spec))
    recipe = recipe_of(spec)
    if timeout is not None:
        recipe = Recipe(recipe.job, recipe.text, recipe.robots, recipe.default_robot, float(timeout))
    variants = _distinct(spec)
    store = ResultStore(out, row_schema(spec.vary), batch=batch)
    answered = store.answered(v.key for v in variants)
    todo = [v for v in variants if v.key not in answered]
    if pending is not None:
        pending[:] = todo
    if todo:
        if client is not None or workers == 0:
            run_variants(recipe, todo, store, client, progress, per_task)
        else:
            with open_client(workers, scheduler, scheduler_file) as own:
                run_variants(recipe, todo, store, own, progress, per_task)
    return store.rows([v.key for v in variants])


def _distinct(spec: SweepSpec) -> list[Any]:
    """The variants, each content key once (a list that repeats a value makes one variant of it)."""
    seen: set[str] = set()
    out = []
    for v in spec.variants():
        if v.key not in seen:
            seen.add(v.key)
            out.append(v)
    return out
