"""Jobs: programs of moves over taught points and pallets, timed as fast as the limits allow (docs/job.md).

A job sits above the motion layer: it names taught points (the pendant's points file) and pallets (grids of
places from taught corners), and runs steps (jumps, straight moves, joint moves, dwells, speed and
acceleration percentages, loops) that :func:`plan_job` plans move by move with the package's planners,
each verified at 10 kHz. ``Job.load(path).plan(robot)`` gives the table, the total and the trajectory.
"""

from .loading import FORMAT, Carry, Job, load_job
from .pallets import Order, Pallet
from .planning import PlannedMove, Planner, Source, plan_job, plan_move, scaled_limits
from .results import JobResult, PlanningStats, StepResult
from .steps import Dwell, JumpShape, Move, MoveKind, Program, Target, parse_target

__all__ = [
    "FORMAT",
    "Carry",
    "Dwell",
    "Job",
    "JobResult",
    "JumpShape",
    "Move",
    "MoveKind",
    "Order",
    "Pallet",
    "PlannedMove",
    "Planner",
    "PlanningStats",
    "Program",
    "Source",
    "StepResult",
    "Target",
    "load_job",
    "parse_target",
    "plan_job",
    "plan_move",
    "scaled_limits",
]
