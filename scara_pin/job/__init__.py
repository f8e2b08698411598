"""Jobs: programs of moves over taught points and pallets, timed as fast as the limits allow (docs/job.md).

A job sits above the motion layer: it names taught points (the pendant's points file, joint or pose points, and
pose points written in the job, in its frames) and pallets (grids of places from taught corners), and runs steps
(jumps, straight moves, joint moves, dwells, speed and acceleration percentages, loops, and a gripper's picks and
places) that :func:`plan_job` plans move by move with the package's planners, each verified at 10 kHz, in the
job's cell with the boxes placed so far. ``Job.load(path).plan(robot)`` gives the table, the total and the
trajectory; ``job.replace(...)`` and ``job.with_frame(...)`` a variant; the plan cache (:mod:`.cache`) re-plans
only the moves that changed.
"""

from .cache import PlanStore
from .frames import BASE, WORLD, Frame, FrameTree
from .job import Job, load_job
from .loading import FORMAT, KEYS, read_job
from .overrides import Override, parse_override
from .pallets import Order, Pallet
from .planning import PlannedMove, Planner, Source, plan_job, plan_move, scaled_limits
from .results import JobResult, LimitShare, PlacedBox, PlanningStats, StepResult
from .spec import Carry, JobSpec
from .steps import Dwell, Grip, GripKind, JumpShape, Move, MoveKind, Program, StepKind, Target, parse_target

__all__ = [
    "BASE",
    "FORMAT",
    "KEYS",
    "WORLD",
    "Carry",
    "Dwell",
    "Frame",
    "FrameTree",
    "Grip",
    "GripKind",
    "Job",
    "JobResult",
    "JobSpec",
    "JumpShape",
    "LimitShare",
    "Move",
    "MoveKind",
    "Order",
    "Override",
    "Pallet",
    "PlacedBox",
    "PlanStore",
    "PlannedMove",
    "Planner",
    "PlanningStats",
    "Program",
    "Source",
    "StepKind",
    "StepResult",
    "Target",
    "load_job",
    "parse_override",
    "parse_target",
    "plan_job",
    "plan_move",
    "read_job",
    "scaled_limits",
]
