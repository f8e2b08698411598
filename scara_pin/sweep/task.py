"""One variant planned: what a worker runs, from a recipe (a ``Robot`` does not pickle), to one row of numbers.

:func:`run_variant` is the task: it lives in the package so that any worker that can import scara_pin can run
it (a function defined in a script would not reach the workers). It gets the job's text and the robot's recipe,
never objects: the worker makes the robot once and keeps it (:func:`robot_of`, a few per process), reads the job
once per text (:func:`job_of`), and plans the variant's job (``Job.replace``) without the plan cache (the results'
keys are the sweep's cache: :mod:`~scara_pin.sweep.store`).

A row (:data:`ROW_COLUMNS`) is what a sweep needs of a :class:`~scara_pin.job.JobResult` (about 200 bytes
against its 10 KiB pickled): the status (``ok``, ``infeasible`` with the reason, ``failed``, ``timeout``), the
total, the parts per hour (and in the steady state), the binding limit, the closest pair in a cell, the planning
time and the worker. An infeasible variant (a place out of reach, a move the planner cannot make) is a row, not a
failure; an invalid one (a value the job file refuses) or a bug is ``failed`` with the reason.

The time limit (:func:`~scara_pin.signals.time_limit`, this task's thread) is checked between the job's steps and
inside a move's planning before each solver call and each search on the lattice: a variant past it stops there and
is ``timeout`` (one call into IPOPT is not interrupted: the overrun is at most one solve).
"""

from __future__ import annotations

import contextlib
import functools
import socket
import sys
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ..errors import InfeasibleError, ScaraError
from ..signals import TimeLimit, time_limit

if TYPE_CHECKING:
    from ..job import Job, JobResult
    from ..model import RobotModel
    from .spec import RobotRecipe, Variant

__all__ = ["ROW_COLUMNS", "STATUSES", "Recipe", "job_of", "robot_of", "row_of", "run_batch", "run_variant"]

STATUSES = ("ok", "infeasible", "failed", "timeout")
"""A row's ``status``: planned; refused by the robot or the planner (the reason says why); an error; too long."""
ROW_COLUMNS = ("variant", "key", "status", "reason", "total", "parts_per_hour", "steady_parts_per_hour", "binding",
               "binding_share", "closest_pair", "closest_distance", "cell_cost", "planning_time", "worker")
"""The columns of a row after the varied keys' (docs/sweep.md, outputs): SI units, seconds and metres."""
_ROBOTS_KEPT = 8
"""Robots one worker keeps made (a sweep varies a few)."""


@dataclass(frozen=True)
class Recipe:
    """What every task of a sweep shares: the job (its file's path and text), the robots' recipes, the time limit.

    Attributes:
        job: the job file's path (its messages name it; its points and cell files are read beside it).
        text: the job file's text, as the client read it.
        robots: the robots' recipes, by the sweep's value.
        default_robot: the robot's value when the sweep does not vary it.
        timeout: [s] a variant's time limit, or None.
    """

    job: str
    text: str
    robots: tuple[tuple[str, RobotRecipe], ...]
    default_robot: str
    timeout: float | None = None


@functools.lru_cache(maxsize=_ROBOTS_KEPT)
def robot_of(recipe: RobotRecipe) -> RobotModel:
    """The robot of a recipe, made once per worker process and kept (the few most recent)."""
    from ..kinematics.kinds import kinematics_for
    from ..model import RobotModel

    if recipe.urdf is not None:
        return RobotModel(recipe.urdf, kinematics=kinematics_for, acceleration=recipe.acceleration)
    return RobotModel.from_config(recipe.folder or recipe.name, kinematics=kinematics_for)


@functools.lru_cache(maxsize=4)
def job_of(path: str, text: str) -> Job:
    """The job read from its text once per worker process (its variants are ``replace``-d from it)."""
    from ..job import Job

    return Job.load(path, text=text)


def run_variant(recipe: Recipe, variant: Variant) -> dict[str, Any]:
    """Plan one variant and return its row (module docstring); never raises for a variant's own problem."""
    start = time.perf_counter()
    values = dict(variant.values)
    row: dict[str, Any] = {**values, "variant": variant.index, "key": variant.key, "status": "ok", "reason": ""}
    steps = [0, 0]  # (steps planned, steps): how far a variant past its time limit got

    def count(done: int, total: int) -> None:
        steps[:] = done, total

    try:
        robots = dict(recipe.robots)
        robot = robot_of(robots[variant.robot if variant.robot is not None else recipe.default_robot])
        overrides = variant.overrides()
        if variant.robot is not None:
            overrides["robot"] = robot.name
        job = job_of(recipe.job, recipe.text).replace(overrides)
        with time_limit(recipe.timeout):
            result = job.plan(robot, progress=count, cache=False)
        row.update(row_of(result))
    except TimeLimit as exc:
        row.update(status="timeout", reason=f"{exc}, {steps[0]} of {steps[1]} moves and dwells planned" if steps[1]
                   else f"{exc}, in its first move")  # fmt: skip
    except InfeasibleError as exc:
        row.update(status="infeasible", reason=_one_line(exc))
    except ScaraError as exc:
        row.update(status="failed", reason=_one_line(exc))
    except Exception as exc:  # a bug: the row says so, the sweep goes on
        row.update(status="failed", reason=f"internal error ({type(exc).__name__}: {_one_line(exc)})")
    row["planning_time"] = time.perf_counter() - start
    row["worker"] = _worker()
    return row


def run_batch(recipe: Recipe, variants: list[Variant]) -> list[dict[str, Any]]:
    """Plan several variants in one task (``per_task``: fewer tasks for the scheduler), a row each, in order."""
    return [run_variant(recipe, v) for v in variants]


def row_of(result: JobResult) -> dict[str, Any]:
    """The numbers of a planned job: total, rates, the binding limit, the closest pair and the cell's cost."""
    shares: dict[str, float] = {}
    for step in result.steps:
        for limit in getattr(step, "binding", ()) or ():
            name = f"{limit.quantity} {limit.joint}"
            shares[name] = shares.get(name, 0.0) + limit.share * step.duration
    binding = max(shares, key=lambda k: shares[k]) if shares else ""
    closest = result.closest
    clearance = None if closest is None else closest.clearance
    return {
        "total": result.total,
        "parts_per_hour": result.parts_per_hour,
        "steady_parts_per_hour": _or_nan(result.steady_parts_per_hour),
        "binding": binding,
        "binding_share": shares[binding] / result.total if binding and result.total > 0 else float("nan"),
        "closest_pair": "" if clearance is None else clearance.pair,
        "closest_distance": float("nan") if clearance is None else clearance.distance,
        "cell_cost": _or_nan(result.cell_cost),
    }


def _or_nan(value: float | None) -> float:
    return float("nan") if value is None else float(value)


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def _worker() -> str:
    """The Dask worker's address, or ``local HOST`` in the caller's process (``--workers 0``)."""
    if "distributed" in sys.modules:
        from distributed import get_worker

        with contextlib.suppress(ValueError):  # not in a worker
            return str(get_worker().address)
    return f"local {socket.gethostname()}"
