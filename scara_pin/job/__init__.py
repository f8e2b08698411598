"""Jobs: programs of moves over taught points and pallets, timed as fast as the limits allow (docs/job.md).

A job sits above the motion layer: it names taught points (the pendant's points file) and pallets (grids of
places from taught corners), and runs steps (jumps, straight moves, joint moves, dwells, speed and
acceleration percentages, loops, and a gripper's picks and places) that :func:`plan_job` plans move by move
with the package's planners, each verified at 10 kHz, in the job's cell with the boxes placed so far.
``Job.load(path).plan(robot)`` gives the table, the total and the trajectory.
"""

from .job import Job, load_job
from .loading import FORMAT, read_job
from .pallets import Order, Pallet
from .planning import PlannedMove, Planner, Source, plan_job, plan_move, scaled_limits
from .results import JobResult, PlacedBox, PlanningStats, StepResult
from .spec import Carry, JobSpec
from .steps import Dwell, Grip, GripKind, JumpShape, Move, MoveKind, Program, Target, parse_target

__all__ = [
    "FORMAT",
    "Carry",
    "Dwell",
    "Grip",
    "GripKind",
    "Job",
    "JobSpec",
    "JobResult",
    "JumpShape",
    "Move",
    "MoveKind",
    "Order",
    "Pallet",
    "PlacedBox",
    "PlannedMove",
    "Planner",
    "PlanningStats",
    "Program",
    "Source",
    "StepResult",
    "Target",
    "load_job",
    "read_job",
    "parse_target",
    "plan_job",
    "plan_move",
    "scaled_limits",
]
