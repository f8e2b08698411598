"""What planning a job gives: one row per move and dwell, the total time, the parts per hour, the trajectory.

The table (:meth:`JobResult.table`) lists each step with where it starts and ends, its time, and what binds
on it: the limits at >= 99.9 % of themselves (:data:`~scara_pin.motion.jump.BINDING`) and the share of the
step's time they are there, largest first; a move on which none reaches it names the one closest. The
parts per hour count every arrival at a pallet's place (a part picked from or put into it) over the total.
A palletizing job (``carry`` with ``pick`` and ``place`` steps) also gives the boxes it placed, where and when
(:class:`PlacedBox`), the boxes per hour, and in a cell each move's closest pair.

**What the cell costs.** In a cell (the job's obstacles, or the boxes it places) each move is also planned
without the cell (:meth:`~scara_pin.job.planning.Planner.free`): its time in free space is the table's ``free
[s]`` column, and the difference, summed, the cell's cost of the whole job (:attr:`JobResult.cell_cost`).

**Steady state.** The total counts the way in and the way out (a move home after the last part); a cell making
parts runs the loop again and again. One period of the loop (:attr:`JobResult.period`) is the span of the
job's top-level steps that reach the pallet places, from the first to the last of them: the steady-state rate is
3600 x places / period parts per hour (:attr:`JobResult.steady_parts_per_hour`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..motion.verify import Binding
from ..summary import Summarized
from ..units import SI, format_number
from .steps import StepKind

if TYPE_CHECKING:
    from ..cell import Cell, Obstacle, Shape
    from ..motion.trajectory import Trajectory
    from ..motion.verify import Clearance
    from ..units import DisplayUnits

__all__ = ["JobResult", "LimitShare", "PlacedBox", "PlanningStats", "StepResult"]

_ROWS_SHOWN = 6
"""Rows of the table a result's summary shows at each end (its ``repr``; :meth:`JobResult.table` has them all)."""


LimitShare = Binding
"""A limit on a step of a job: its largest |value| / limit there and the share of the step's time at >= 99.9 %
(the jump's :class:`~scara_pin.motion.verify.Binding`, the step as its leg)."""


@dataclass(frozen=True, eq=False, repr=False)
class PlacedBox(Summarized):
    """A box a job's ``place`` left: an obstacle of the cell for every move after it.

    Attributes:
        name: ``box1``, ``box2``, ... in the order placed.
        step: the index of its place step in the table.
        at: where the tool left it (a place's name, ``stack[3]``, or a point's).
        time: [s] when it is left: the end of the place step (the gripper open).
        obstacle: the box, placed in the robot's base frame (the carried part moved by ``baseMtool``).
    """

    name: str
    step: int
    at: str
    time: float
    obstacle: Obstacle

    @property
    def shape(self) -> Shape:
        """The box's shape, in the base frame."""
        return self.obstacle.shape

    def summary(self, units: DisplayUnits | None = None) -> str:
        """One line: the box, where and when it was left."""
        u = units or SI
        return (f"PlacedBox {self.name} at {self.at} (step {self.step}, t = {self.time:.6f} s): centre "
                f"{u.format_vector(self.shape.xyz, 'length')} [{u.length}] in base")  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI): name, step, at, time and the shape (``shape``, sizes, ``xyz``, ``rpy`` in base)."""
        return {"name": self.name, "step": self.step, "at": self.at, "time": self.time, **self.shape.to_dict()}


@dataclass(frozen=True, repr=False)
class PlanningStats(Summarized):
    """How the moves of a job were obtained.

    Attributes:
        planned: moves planned (solved) by the planners.
        same: moves that were a move planned before (same ends, limits, clearance, obstacles).
        reversed: jumps that were a jump planned before, played backwards.
        cached: moves read from the plan cache (:mod:`~scara_pin.job.cache`), planned by an earlier run.
        free: moves planned without the cell for the cost column (not counted above).
        seconds: [s] the wall time of the planning and verification.
    """

    planned: int = 0
    same: int = 0
    reversed: int = 0
    cached: int = 0
    free: int = 0
    seconds: float = 0.0

    def summary(self, units: DisplayUnits | None = None) -> str:
        """One line, as the table's last."""
        free = f" (and {self.free} in free space for the cell's cost)" if self.free else ""
        return (f"{self.planned} moves planned, {self.reversed} jumps reversed, {self.same} repeated, {self.cached} "
                f"from the cache{free}; {self.seconds:.3g} s")  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: the fields, by name."""
        return asdict(self)


@dataclass(frozen=True, eq=False, repr=False)
class StepResult(Summarized):
    """One row of a job's table: a move, a dwell, a pick or a place.

    Attributes:
        index: its number in the program, from 1.
        line: the line of its step in the job file.
        kind: jump, move, go, dwell, pick or place (:class:`~scara_pin.job.steps.StepKind`, a str enum).
        origin: where it starts (a point's name or a place, ``tray[5]``).
        target: where it ends.
        t_start, t_end: [s] in the job.
        place: (pallet, place number) when the target is a pallet's place.
        binding: the limits at >= 99.9 % on it, with their share of its time.
        worst: the limit closest to binding (ratio), or None for a dwell or no motion.
        speed, accel: the fractions of the velocity and acceleration limits of a move.
        planned: how the move was obtained (:class:`~scara_pin.job.planning.Source`'s value), "" for a dwell.
        method: the method of the move (a sentence), "" for a dwell.
        lower_bound: [s] what no motion between the same configurations beats (jumps), or None.
        q: the joint values where the step ends [rad, m]; pose: the tool pose there (x, y, z, yaw) [m, rad].
        carrying: the tool holds the job's part during the move (a pick or place: after it).
        boxes: the boxes the job has placed when the step starts (the obstacles it adds to the cell).
        clearance: in a cell, the move's smallest distance of a checked pair, which and when (from the move's
            start), from the 10 kHz verification; None for a dwell or without a cell.
        box: the box a place step leaves, else None.
        free: [s] in a cell, the same move planned without the cell (the cost column); None otherwise.
        top: the index (from 0) of the job's top-level step this row comes from (loops unrolled).
    """

    index: int
    line: int | None
    kind: StepKind
    origin: str
    target: str
    t_start: float
    t_end: float
    place: tuple[str, int] | None = None
    binding: tuple[LimitShare, ...] = ()
    worst: LimitShare | None = None
    speed: float | None = None
    accel: float | None = None
    planned: str = ""
    method: str = ""
    lower_bound: float | None = None
    q: tuple[float, ...] = ()
    pose: tuple[float, ...] = ()
    carrying: bool = False
    boxes: int = 0
    clearance: Clearance | None = None
    box: PlacedBox | None = None
    free: float | None = None
    top: int = 0

    def __post_init__(self) -> None:
        object.__setattr__(self, "kind", StepKind(self.kind))

    @property
    def duration(self) -> float:
        """[s]."""
        return self.t_end - self.t_start

    @property
    def cell_cost(self) -> float | None:
        """[s] the time the cell adds to this move (its time in the cell minus in free space), or None."""
        return None if self.free is None else self.duration - self.free

    def summary(self, units: DisplayUnits | None = None) -> str:
        """One line: the row of the table."""
        cost = "" if self.cell_cost is None else f" (+{self.cell_cost:.6f} s for the cell)"
        return (f"StepResult {self.index} (line {self.line}): {self.kind} {self.origin} -> {self.target}, "
                f"{self.duration:.6f} s{cost}: {self.binding_text()}")  # fmt: skip

    def binding_text(self) -> str:
        """What binds, as the table says it."""
        if self.kind == "dwell":
            return "dwell"
        if self.kind == "pick":
            return "gripper closes: the tool holds the part"
        if self.kind == "place":
            return f"gripper opens: {self.box.name} left at {self.target}" if self.box is not None else "place"
        if self.worst is None:
            return self.planned  # already there
        if not self.binding:
            return f"none; closest: {self.worst.quantity} {self.worst.joint} at {self.worst.ratio:.3f}"
        return ", ".join(f"{b.quantity} {b.joint} {_percent(b.share)}" for b in self.binding)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI; percentages as percent)."""
        return {
            "index": self.index, "line": self.line, "kind": self.kind, "from": self.origin, "target": self.target,
            "place": None if self.place is None else {"pallet": self.place[0], "index": self.place[1]},
            "t_start": self.t_start, "t_end": self.t_end, "duration": self.duration,
            "binding": [b.to_dict() for b in self.binding],
            "closest_limit": None if self.worst is None else self.worst.to_dict(),
            "speed_percent": None if self.speed is None else 100.0 * self.speed,
            "accel_percent": None if self.accel is None else 100.0 * self.accel,
            "planned": self.planned or None, "method": self.method or None, "lower_bound": self.lower_bound,
            "q": list(self.q), "pose": list(self.pose), "carrying": self.carrying, "boxes_placed": self.boxes,
            "clearance": None if self.clearance is None else {**self.clearance.to_dict(),
                                                              "t": self.t_start + self.clearance.time},
            "box": None if self.box is None else self.box.to_dict(),
            "free": self.free, "cell_cost": self.cell_cost,
        }  # fmt: skip

def _percent(share: float) -> str:
    """A share of time as the table prints it: ``62 %``; ``<1 %`` for a limit touched only for an instant."""
    return "<1 %" if 100.0 * share < 0.5 else f"{100.0 * share:.0f} %"


@dataclass(frozen=True, eq=False, repr=False)
class JobResult(Summarized):
    """A job planned: its steps, time, throughput and trajectory (``repr``: the table's ends and totals).

    Attributes:
        path: the job file.
        robot: the robot's name.
        steps: one row per move and dwell, in order.
        trajectory: the whole job, from rest to rest (its duration is :attr:`total`).
        places: the arrivals at pallet places (the parts made).
        stats: how the moves were obtained.
        boxes: the boxes placed, in order (palletizing jobs).
        cell: the job's cell (its file's obstacles and margin), or None.
        carry: the part the tool holds from a pick to a place (tool frame), or None.
    """

    path: Path
    robot: str
    steps: tuple[StepResult, ...]
    trajectory: Trajectory
    places: int
    stats: PlanningStats
    boxes: tuple[PlacedBox, ...] = ()
    cell: Cell | None = None
    carry: Shape | None = None

    @property
    def total(self) -> float:
        """[s] the job's time: the sum of its moves and dwells."""
        return self.trajectory.duration

    @property
    def parts_per_hour(self) -> float | None:
        """Arrivals at pallet places per hour, or None when the job reaches none."""
        return 3600.0 * self.places / self.total if self.places else None

    @property
    def boxes_per_hour(self) -> float | None:
        """Boxes placed per hour (palletizing jobs), or None when the job places none."""
        return 3600.0 * len(self.boxes) / self.total if self.boxes else None

    @property
    def loop(self) -> tuple[StepResult, StepResult] | None:
        """The first and last rows of one period of the loop (module docstring), or None when no place is reached."""
        tops = {s.top for s in self.steps if s.place is not None}
        if not tops:
            return None
        rows = [s for s in self.steps if min(tops) <= s.top <= max(tops)]
        return rows[0], rows[-1]

    @property
    def period(self) -> float | None:
        """[s] one period of the loop: the time of the top-level steps that reach the places (module docstring)."""
        loop = self.loop
        return None if loop is None else loop[1].t_end - loop[0].t_start

    @property
    def steady_parts_per_hour(self) -> float | None:
        """3600 x places / :attr:`period`: the rate of the loop run again and again, or None without places."""
        period = self.period
        return None if period is None or not period > 0 else 3600.0 * self.places / period

    @property
    def cell_cost(self) -> float | None:
        """[s] what the cell adds to the job: the moves' time in the cell minus in free space; None without a cell."""
        costs = [s.cell_cost for s in self.steps if s.cell_cost is not None]
        return sum(costs) if costs else None

    @property
    def closest(self) -> StepResult | None:
        """In a cell, the move whose clearance is the smallest of the job (None without a cell)."""
        moves = [s for s in self.steps if s.clearance is not None]
        return min(moves, key=lambda s: s.clearance.distance) if moves else None  # type: ignore[union-attr]

    def table(self, units: DisplayUnits | None = None) -> str:
        """The text table: one row per step, then the total and the parts per hour (module docstring).

        Args:
            units: the lengths of the cell line (default: millimetres); times are seconds.
        """
        return "\n".join([*self._rows(self.steps), self._totals(units)])

    def _rows(self, steps: tuple[StepResult, ...]) -> list[str]:
        """The title, the header and the rows of ``steps`` (columns as wide as the whole table's)."""
        wide = max([4, *(len(s.origin) for s in self.steps), *(len(s.target) for s in self.steps)])
        costed = any(s.free is not None for s in self.steps)
        free_head = f"{'free [s]':>9}  " if costed else ""
        head = (f"{'step':>5} {'line':>5}  {'kind':<5}  {'from':<{wide}}  {'to':<{wide}}  {'time [s]':>9}  {free_head}"
                "binds (share of the step's time at >= 99.9 % of the limit)")  # fmt: skip
        lines = [f"job       {self.path} on robot {self.robot}", head]
        for s in steps:
            line = "" if s.line is None else str(s.line)
            free = "" if not costed else (f"{s.free:9.6f}  " if s.free is not None else " " * 11)
            lines.append(f"{s.index:>5} {line:>5}  {s.kind:<5}  {s.origin:<{wide}}  {s.target:<{wide}}  "
                         f"{s.duration:9.6f}  {free}{s.binding_text()}")  # fmt: skip
        return lines

    def _totals(self, units: DisplayUnits | None) -> str:
        """The lines after the rows: total and rates, the steady state, the boxes, the cell, the planning."""

        def length(value: float, fmt: str = ".4g") -> str:
            if units is None:
                return f"{value * 1e3:{fmt}} mm"
            return f"{units.format(value, 'length')} {units.length}"

        rate = self.parts_per_hour
        lines = [f"total     {format_number(self.total, 6)} s"
                 + (f": {self.places} places, {rate:,.1f} parts per hour" if rate is not None else "")]  # fmt: skip
        loop, steady = self.loop, self.steady_parts_per_hour
        if loop is not None and steady is not None:
            lines.append(f"steady    {format_number(self.period or 0.0, 6)} s per period of the loop (steps "
                         f"{loop[0].index}-{loop[1].index}, {self.places} places): {steady:,.1f} parts per hour")
        if self.boxes:
            lines.append(f"boxes     {len(self.boxes)} placed, {self.boxes_per_hour:,.1f} boxes per hour")
        closest, cost = self.closest, self.cell_cost
        if self.cell is not None or cost is not None:
            words = [f"cell      {self.cell.origin if self.cell is not None else 'the boxes'}"]
            if self.cell is not None:
                words.append(f": {len(self.cell.obstacles)} obstacle(s), margin {length(self.cell.margin, 'g')}")
            if cost is not None:
                words.append(f"; costs {cost:.6f} s over the same moves in free space ({100 * cost / self.total:.2f} % "
                             "of the total)")
            if closest is not None and closest.clearance is not None:
                c = closest.clearance
                words.append(f"; closest {c.pair} {length(c.distance)} (step {closest.index}, t = "
                             f"{closest.t_start + c.time:.4f} s)")  # fmt: skip
            lines.append("".join(words))
        lines.append(f"planning  {self.stats.summary()}")
        return "\n".join(lines)

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The table's first and last rows and its totals (:meth:`table` has every row): one screen."""
        n = _ROWS_SHOWN
        if len(self.steps) <= 2 * n:
            return self.table(units)
        rows = [*self._rows(self.steps[:n]), f"  ... ({len(self.steps) - 2 * n} more rows: .table() lists them all)",
                *self._rows(self.steps[-n:])[2:]]  # fmt: skip
        return "\n".join([*rows, self._totals(units)])

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI units)."""
        closest, loop = self.closest, self.loop
        steady = None if loop is None else {"period": self.period, "first_step": loop[0].index,
                                            "last_step": loop[1].index, "places": self.places,
                                            "parts_per_hour": self.steady_parts_per_hour}  # fmt: skip
        return {"job": str(self.path), "robot": self.robot, "total": self.total, "places": self.places,
                "parts_per_hour": self.parts_per_hour, "steady_state": steady, "cell_cost": self.cell_cost,
                "steps": [s.to_dict() for s in self.steps],
                "boxes": [b.to_dict() for b in self.boxes], "boxes_per_hour": self.boxes_per_hour,
                "carry": None if self.carry is None else self.carry.to_dict(),
                "cell": None if self.cell is None else self.cell.to_dict(),
                "closest": None if closest is None else closest.to_dict()["clearance"] | {"step": closest.index},
                "planning": self.stats.to_dict(), "units": {"length": "m", "angle": "rad", "time": "s"}}  # fmt: skip
