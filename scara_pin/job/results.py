"""What planning a job gives: one row per move and dwell, the total time, the parts per hour, the trajectory.

The table (:meth:`JobResult.table`) lists each step with where it starts and ends, its time, and what binds
on it: the limits at >= 99.9 % of themselves (:data:`~scara_pin.motion.jump.BINDING`) and the share of the
step's time they are there, largest first; a move on which none reaches it names the one closest. The
parts per hour count every arrival at a pallet's place (a part picked from or put into it) over the total.
A palletizing job (``carry`` with ``pick`` and ``place`` steps) also gives the boxes it placed, where and when
(:class:`PlacedBox`), the boxes per hour, and in a cell each move's closest pair.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..units import format_number

if TYPE_CHECKING:
    from ..cell import Cell, Obstacle, Shape
    from ..motion.jump import Binding
    from ..motion.trajectory import Trajectory
    from ..motion.verify import Clearance

__all__ = ["JobResult", "PlacedBox", "PlanningStats", "StepResult"]


@dataclass(frozen=True, eq=False)
class PlacedBox:
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

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI): name, step, at, time and the shape (``shape``, sizes, ``xyz``, ``rpy`` in base)."""
        return {"name": self.name, "step": self.step, "at": self.at, "time": self.time, **self.shape.to_dict()}


@dataclass(frozen=True)
class PlanningStats:
    """How the moves of a job were obtained.

    Attributes:
        planned: moves planned (solved) by the planners.
        same: moves that were a move planned before (same ends, limits, clearance, obstacles).
        reversed: jumps that were a jump planned before, played backwards.
        seconds: [s] the wall time of the planning and verification.
    """

    planned: int = 0
    same: int = 0
    reversed: int = 0
    seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"planned": self.planned, "same": self.same, "reversed": self.reversed, "seconds": self.seconds}


@dataclass(frozen=True, eq=False)
class StepResult:
    """One row of a job's table: a move or a dwell.

    Attributes:
        index: its number in the program, from 1.
        line: the line of its step in the job file.
        kind: "jump", "move", "go" or "dwell".
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
    """

    index: int
    line: int | None
    kind: str
    origin: str
    target: str
    t_start: float
    t_end: float
    place: tuple[str, int] | None = None
    binding: tuple[Binding, ...] = ()
    worst: Binding | None = None
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

    @property
    def duration(self) -> float:
        """[s]."""
        return self.t_end - self.t_start

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
        }  # fmt: skip

def _percent(share: float) -> str:
    """A share of time as the table prints it: ``62 %``; ``<1 %`` for a limit touched only for an instant."""
    return "<1 %" if 100.0 * share < 0.5 else f"{100.0 * share:.0f} %"


@dataclass(frozen=True, eq=False)
class JobResult:
    """A job planned: its steps, time, throughput and trajectory.

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
    def closest(self) -> StepResult | None:
        """In a cell, the move whose clearance is the smallest of the job (None without a cell)."""
        moves = [s for s in self.steps if s.clearance is not None]
        return min(moves, key=lambda s: s.clearance.distance) if moves else None  # type: ignore[union-attr]

    def table(self) -> str:
        """The text table: one row per step, then the total and the parts per hour (module docstring)."""
        wide = max([4, *(len(s.origin) for s in self.steps), *(len(s.target) for s in self.steps)])
        head = (f"{'step':>5} {'line':>5}  {'kind':<5}  {'from':<{wide}}  {'to':<{wide}}  {'time [s]':>9}  "
                "binds (share of the step's time at >= 99.9 % of the limit)")  # fmt: skip
        lines = [f"job       {self.path} on robot {self.robot}", head]
        for s in self.steps:
            line = "" if s.line is None else str(s.line)
            lines.append(f"{s.index:>5} {line:>5}  {s.kind:<5}  {s.origin:<{wide}}  {s.target:<{wide}}  "
                         f"{s.duration:9.6f}  {s.binding_text()}")  # fmt: skip
        rate = self.parts_per_hour
        lines.append(f"total     {format_number(self.total, 6)} s"
                     + (f": {self.places} places, {rate:,.1f} parts per hour" if rate is not None else ""))  # fmt: skip
        if self.boxes:
            lines.append(f"boxes     {len(self.boxes)} placed, {self.boxes_per_hour:,.1f} boxes per hour")
        closest = self.closest
        if closest is not None and closest.clearance is not None and self.cell is not None:
            c = closest.clearance
            lines.append(f"cell      {self.cell.origin}: {len(self.cell.obstacles)} obstacle(s), margin "
                         f"{self.cell.margin * 1e3:g} mm; closest {c.pair} {c.distance * 1e3:.4g} mm (step "
                         f"{closest.index}, t = {closest.t_start + c.time:.4f} s)")  # fmt: skip
        st = self.stats
        lines.append(f"planning  {st.planned} moves planned, {st.reversed} jumps reversed, {st.same} repeated; "
                     f"{st.seconds:.3g} s")  # fmt: skip
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI units)."""
        closest = self.closest
        return {"job": str(self.path), "robot": self.robot, "total": self.total, "places": self.places,
                "parts_per_hour": self.parts_per_hour, "steps": [s.to_dict() for s in self.steps],
                "boxes": [b.to_dict() for b in self.boxes], "boxes_per_hour": self.boxes_per_hour,
                "carry": None if self.carry is None else self.carry.to_dict(),
                "cell": None if self.cell is None else self.cell.to_dict(),
                "closest": None if closest is None else closest.to_dict()["clearance"] | {"step": closest.index},
                "planning": self.stats.to_dict(), "units": {"length": "m", "angle": "rad", "time": "s"}}  # fmt: skip
