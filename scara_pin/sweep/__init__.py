"""Sweeps: one job planned over many variants (robots, placements, speeds) on Dask, the rows in Parquet.

``scara_pin.sweep("sweep.yaml", out="results/")`` (or ``scara-pin sweep sweep.yaml --out results/``) reads a
sweep file (:mod:`~scara_pin.sweep.spec`: the job, the keys it varies and their values), plans every variant as a
task on a Dask cluster (:mod:`~scara_pin.sweep.engine`: local processes, or an existing scheduler) from a recipe
the workers can rebuild (:mod:`~scara_pin.sweep.task`), and keeps each row in a Parquet dataset
(:mod:`~scara_pin.sweep.store`) that a rerun resumes. docs/sweep.md.

The module itself is callable: ``scara_pin.sweep(spec, client=None, ...)`` is :func:`~scara_pin.sweep.run.sweep`.
"""

import sys
import types
from typing import Any

from .engine import QUIET, open_client, run_variants
from .run import recipe_of, sweep
from .spec import FORMAT, RobotRecipe, SweepSpec, Variant, load_spec
from .store import ResultStore, row_schema
from .task import ROW_COLUMNS, STATUSES, Recipe, run_variant

__all__ = [
    "FORMAT",
    "QUIET",
    "ROW_COLUMNS",
    "STATUSES",
    "Recipe",
    "ResultStore",
    "RobotRecipe",
    "SweepSpec",
    "Variant",
    "load_spec",
    "open_client",
    "recipe_of",
    "row_schema",
    "run_variant",
    "run_variants",
    "sweep",
]


class _CallableModule(types.ModuleType):
    """This package, callable: ``scara_pin.sweep(spec, ...)`` runs :func:`sweep` (the issue's spelling)."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return sweep(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
