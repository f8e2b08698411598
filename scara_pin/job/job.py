"""The job users hold: its data (:class:`~scara_pin.job.spec.JobSpec`) read from a file and planned for a robot.

Above the reader and the planner, so that ``Job.load(path).plan(robot)`` reads as it says.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .loading import read_job
from .overrides import Override, as_overrides
from .planning import plan_job
from .spec import JobSpec

if TYPE_CHECKING:
    from ..model import RobotModel
    from .cache import PlanStore
    from .results import JobResult

__all__ = ["Job", "load_job"]


class Job(JobSpec):
    """A job: taught points, pallets and steps, checked (:mod:`~scara_pin.job.loading`). :meth:`load` reads one.

    A variant is a new job (:meth:`replace`, :meth:`with_frame`): the file's text read again with values replaced at
    dotted keys, in the file's own grammar and units, and checked as the file is (:mod:`~scara_pin.job.overrides`).
    """

    @classmethod
    def load(cls, path: str | Path, overrides: Mapping[str, Any] | Iterable[Override] | None = None, *,
             text: str | None = None) -> Job:  # fmt: skip
        """Read and check a job file (:func:`~scara_pin.job.loading.read_job`), with ``overrides`` (dotted keys).

        ``text``: the file's text, read before (a sweep's worker gets the job as the client read it); the files it
        names (points, cell) are still read beside ``path``.
        """
        return cls._of(read_job(path, as_overrides(overrides, "Job.load"), text=text))

    @classmethod
    def _of(cls, spec: JobSpec) -> Job:
        return cls(**{f.name: getattr(spec, f.name) for f in fields(spec)})

    def replace(self, values: Mapping[str, Any] | None = None, /, **keys: Any) -> Job:
        """A new job: this one with the values at the given keys replaced, checked as the file is.

        ``job.replace(speed=70, accel=80)`` (top-level keys as keywords); ``job.replace({"frames.tray.xyz": [0.3,
        -0.06, -0.1], "base.yaw": 0.1})`` (dotted keys); ``job.replace(robot="s1")``. Values are in the job file's
        units (its ``units:``; SI by default), as the file would write them. The overrides this job already has
        stay, a key given again takes the new value.

        Raises:
            JobFileError: a value the job file would refuse there (exit 2), naming the key.
        """
        new = as_overrides({**(values or {}), **keys}, "replace")
        kept = tuple(o for o in self.overrides if o.key not in {n.key for n in new})
        return self._of(read_job(self.path, (*kept, *new), text=self.text))

    def with_frame(self, name: str, xyz: Any = None, yaw: float | None = None, parent: str | None = None) -> Job:
        """A new job with frame ``name`` (or ``base``: the robot's) placed elsewhere: ``xyz``, ``yaw``, ``parent``.

        The values are in the job file's units; those not given stay. Every point in the frame moves with it.
        """
        prefix = "base" if name == "base" else f"frames.{name}"
        values = {f"{prefix}.{k}": v for k, v in (("xyz", xyz), ("yaw", yaw), ("parent", parent)) if v is not None}
        if hasattr(xyz, "tolist"):
            values[f"{prefix}.xyz"] = xyz.tolist()
        return self.replace(values)

    def plan(self, robot: RobotModel, *, progress: Callable[[int, int], None] | None = None,
             cache: PlanStore | bool = True) -> JobResult:
        """Plan every move of the job for ``robot`` (:func:`~scara_pin.job.planning.plan_job`; ``cache``: its cache)."""
        return plan_job(self, robot, progress=progress, cache=cache)


def load_job(path: str | Path) -> Job:
    """Read a job file and check it (:meth:`Job.load`)."""
    return Job.load(path)
