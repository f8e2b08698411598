"""The job users hold: its data (:class:`~scara_pin.job.spec.JobSpec`) read from a file and planned for a robot.

Above the reader and the planner, so that ``Job.load(path).plan(robot)`` reads as it says.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING

from .loading import read_job
from .planning import plan_job
from .spec import JobSpec

if TYPE_CHECKING:
    from ..model import RobotModel
    from .results import JobResult

__all__ = ["Job", "load_job"]


class Job(JobSpec):
    """A job: taught points, pallets and steps, checked (:mod:`~scara_pin.job.loading`). :meth:`load` reads one."""

    @classmethod
    def load(cls, path: str | Path) -> Job:
        """Read and check a job file (:func:`~scara_pin.job.loading.read_job`)."""
        spec = read_job(path)
        return cls(**{f.name: getattr(spec, f.name) for f in fields(spec)})

    def plan(self, robot: RobotModel, *, progress: Callable[[int, int], None] | None = None) -> JobResult:
        """Plan every move of the job for ``robot`` (:func:`~scara_pin.job.planning.plan_job`)."""
        return plan_job(self, robot, progress=progress)


def load_job(path: str | Path) -> Job:
    """Read a job file and check it (:meth:`Job.load`)."""
    return Job.load(path)
