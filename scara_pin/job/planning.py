"""Planning a job: every move through one function, each as fast as the limits allow, each verified at 10 kHz.

:func:`plan_move` is the one function every move of a job goes through:

- ``jump``: the time-optimal jump (:func:`~scara_pin.motion.jump.jump_move`: joint path free over the
  clearance), between the two configurations themselves (their branch and J4 turn);
- ``move``: a straight tool line, time-optimal (TOPP-RA), and ``go``: a joint move, time-optimal
  (:func:`~scara_pin.motion.plan.plan_motion`, which chooses the method);

under the robot's limits with the velocity limits times the ``speed`` fraction and the acceleration
limits times the ``accel`` fraction (SPEL+'s ``Speed`` and ``Accel``), and the effort limits with the
job's payload when the job asks for the torques. Each move is then verified by the package's verifier
(:func:`~scara_pin.motion.verify.verify`: every limit at 10 kHz and at every breakpoint, the endpoints,
rest at both ends); a move it refuses is an error (exit 3), never an output.

**In a cell** (:class:`~scara_pin.cell.Cell`: the job's ``cell`` file, the boxes placed so far, the part in the
tool between a ``pick`` and a ``place``) every move keeps every checked pair at least the cell's margin apart:
a jump is planned around and over the obstacles (``jump_move(..., cell=)``), a straight or joint move's path is
fixed, verified against the cell (:func:`~scara_pin.motion.verify.clear_of`) and refused naming the pair. The
clearance comes from the same verifier at 10 kHz (the planners run it with the cell's scene); a reversed jump is
verified against the cell again. Each ``place`` leaves the part where the tool holds it (the carried shape
moved by ``baseMtool``): an obstacle named ``box1``, ``box2``, ... for every move after it.

Every move is from rest to rest, so a job lasts exactly the sum of its moves and dwells: it is never slower
than its moves planned one by one, because it IS them.

**Same moves, planned once** (:class:`Planner`). A move whose kind, end configurations (bit for bit),
limit fractions, clearance, boxes placed and gripper state are those of a move planned before is that move
again. A jump whose reverse was planned (with the same boxes and gripper state) is that jump played
backwards: under the same symmetric limits and clearance the reversed motion is feasible and as fast as any
(:mod:`~scara_pin.motion.jump`, "Return move"), so a tray job solves one jump per place, not two. The
reversed move is verified like a new one, in its cell too.
"""

from __future__ import annotations

import enum
import logging
import math
import re
import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError, JobFileError, ScaraError
from ..motion.payload import Payload, PayloadLike, as_payload, with_payload
from ..motion.polynomial import PolynomialPiece
from ..motion.trajectory import Piece, Trajectory
from ..signals import check_time, raise_pending
from .cache import FORMAT as CACHE_FORMAT
from .cache import PlanStore, built, cell_digest, decode_trajectory, encode_trajectory, move_key, robot_digest
from .results import JobResult, LimitShare, PlacedBox, PlanningStats, StepResult
from .steps import Dwell, Grip, GripKind, Move, MoveKind, StepKind, located

if TYPE_CHECKING:
    from ..cell import Cell, Obstacle, Shape
    from ..description import JointLimits
    from ..model import RobotModel
    from ..motion.verify import Clearance
    from .spec import JobSpec

__all__ = ["BOX", "STILL", "PlannedMove", "Planner", "Source", "plan_job", "plan_move", "scaled_limits"]

log = logging.getLogger(__name__)

STILL = 1e-12
"""[rad or m] a move whose end configurations differ by no more than this is no motion (the robot is there)."""
BOX = "box{}"
"""The name of the n-th box a job places (``box1``, ``box2``, ...): an obstacle of the cell after its place."""


class Source(enum.Enum):
    """Where a job's move came from; the value is its name in the table and the JSON."""

    PLANNED = "planned"
    SAME = "same as an earlier move"
    REVERSED = "an earlier jump reversed"
    CACHED = "from the cache"
    STILL = "already there"


@dataclass(frozen=True, eq=False)
class PlannedMove:
    """A move of a job, planned and verified.

    Attributes:
        trajectory: the motion (one or more pieces), or None when the robot is already there.
        method: how it was made (:class:`~scara_pin.motion.plan.Method`'s sentence), "" when still.
        binding: the limits at >= 99.9 % of themselves on it, with their share of its time (largest first).
        worst: the quantity and joint closest to its limit (ratio), or None when still.
        lower_bound: [s] what no motion between the same configurations can beat (jumps), or None.
        source: planned, the same as an earlier move, an earlier jump reversed, from the plan cache, or still.
        seconds: [s] the wall time its planning took (0 for a move planned before).
        clearance: in a cell, the smallest verified distance of its checked pairs, which and when (move time).
    """

    trajectory: Trajectory | None
    method: str
    binding: tuple[LimitShare, ...]
    worst: LimitShare | None
    lower_bound: float | None
    source: Source
    seconds: float = 0.0
    clearance: Clearance | None = None

    @property
    def duration(self) -> float:
        """[s] (0 when the robot is already there)."""
        return 0.0 if self.trajectory is None else self.trajectory.duration

    def entry(self) -> dict[str, Any] | None:
        """The plan cache's entry of this move (:mod:`~scara_pin.job.cache`), or None (still, or not storable)."""
        if self.trajectory is None:
            return None
        data = encode_trajectory(self.trajectory)
        if data is None:
            return None
        c = self.clearance
        return {"format": CACHE_FORMAT, "duration": self.trajectory.duration, "method": self.method,
                "binding": [b.to_dict() for b in self.binding],
                "worst": None if self.worst is None else self.worst.to_dict(), "lower_bound": self.lower_bound,
                "clearance": None if c is None else c.to_dict(), "seconds": float(self.seconds),
                "source": self.source.value, "trajectory": data}  # fmt: skip

    @classmethod
    def from_entry(cls, robot: RobotModel, entry: dict[str, Any]) -> PlannedMove:
        """The move a plan cache entry holds (``ValueError``, ``KeyError``, ``TypeError``: not one)."""
        traj = decode_trajectory(robot, entry["trajectory"])
        if traj.duration != float(entry["duration"]):
            raise ValueError(f"its trajectory lasts {traj.duration!r} s, its entry says {entry['duration']!r}")
        clearance = None
        if entry.get("clearance") is not None:
            from ..motion.verify import Clearance

            c = entry["clearance"]
            empty = np.zeros(0)
            where = None if c.get("where") is None else tuple(float(v) for v in c["where"])
            clearance = Clearance(float(c["distance"]), float(c["margin"]), str(c["pair"]), float(c["time"]),
                                  (empty, empty, empty.astype(int)), where)  # type: ignore[arg-type]  # fmt: skip
        worst = None if entry.get("worst") is None else LimitShare.from_dict(entry["worst"])
        bound = entry.get("lower_bound")
        return cls(traj, str(entry["method"]), tuple(LimitShare.from_dict(b) for b in entry["binding"]), worst,
                   None if bound is None else float(bound), Source.CACHED, 0.0, clearance)  # fmt: skip


def scaled_limits(robot: RobotModel, speed: float, accel: float) -> JointLimits:
    """The robot's limits with the velocities times ``speed`` and the accelerations times ``accel`` (in (0, 1])."""
    for name, f in (("speed", speed), ("accel", accel)):
        if not (isinstance(f, (int, float)) and 0.0 < f <= 1.0):
            raise InvalidInputError(f"{name} fraction {f!r} must be in (0, 1]")
    lim = robot.limits
    return replace(lim, velocity=tuple(v * speed for v in lim.velocity),
                   acceleration=tuple(a * accel for a in lim.acceleration), validate=False)  # fmt: skip


def plan_move(
    robot: RobotModel,
    move: Move,
    q_from: np.ndarray,
    *,
    torque: bool = False,
    payload: PayloadLike = None,
    cell: Cell | None = None,
    jerk: tuple[float, ...] | None = None,
) -> PlannedMove:
    """Plan and verify one move of a job from ``q_from`` (module docstring): the one function every move goes through.

    Args:
        robot: a robot with a wrist (4 joints).
        move: the move: its kind, target configuration, limit fractions and (jumps) clearance.
        q_from: where the robot is, at rest [rad, m].
        torque: respect the effort limits too (with ``payload``).
        payload: carried by the tool (torques): a Payload, or a mass [kg] at the tool frame's origin; None: none.
        cell: the obstacles in force (the cell file's, the boxes placed so far) and the part in the tool, or
            None: every checked pair kept the cell's margin apart.
        jerk: joint jerk limits [rad/s^3, m/s^3], one per joint (``cycle --jerk-limit``'s), or None.

    Raises:
        InvalidInputError: the move cannot be made as asked (e.g. a jump between poses closer than twice its
            clearance radius; a start or end in collision, naming the pair; exit 2).
        InfeasibleError: the planner or the verifier refuses it (e.g. a fixed path through an obstacle; exit 3).
    """
    from ..motion.plan import Method, MotionRequest, plan_motion

    q0, q1 = np.asarray(q_from, dtype=float), np.asarray(move.q, dtype=float)
    if float(np.max(np.abs(q1 - q0))) <= STILL:
        return PlannedMove(None, "", (), None, None, Source.STILL)
    t0 = time.perf_counter()
    limits = scaled_limits(robot, move.speed, move.accel)
    payload = as_payload(payload)
    bound = None
    if move.kind is MoveKind.JUMP:
        from ..motion.jump import jump_move

        if move.shape is None:  # pragma: no cover - the expansion gives every jump its shape
            raise InvalidInputError("a jump needs its clearance (rise, clearance_radius)")
        rise, radius, ceiling = move.shape.resolved()
        jump = jump_move(robot, robot.tool_pose(q0), move.pose, rise=rise, clearance_radius=radius,
                         max_height=ceiling, payload=payload, torque=torque, limits=limits, start=q0, end=q1,
                         cell=cell, jerk=jerk, via=move.shape.via)  # fmt: skip
        traj, method, bound, clearance = jump.trajectory, Method.JUMP.value, jump.lower_bound.duration, jump.distance
    elif jerk is not None:  # a fixed path, jerk-limited (plan_motion takes no scaled limits with a jerk limit)
        traj, method, clearance = _jerk_limited(robot, move, q0, q1, limits, jerk, torque, payload, cell)
    else:
        request = MotionRequest(start_q=q0, end_q=q1, linear=move.kind is MoveKind.MOVE, torque=torque,
                                payload=payload if torque else None, limits=limits, cell=cell)  # fmt: skip
        plan = plan_motion(robot, request)
        traj, method, clearance = plan.trajectory, plan.method.value, plan.clearance
    return _checked(robot, traj, method, limits, torque, payload, bound, Source.PLANNED, time.perf_counter() - t0,
                    cell, clearance, jerk)  # fmt: skip


def _jerk_limited(robot: RobotModel, move: Move, q0: np.ndarray, q1: np.ndarray, limits: JointLimits,
                  jerk: tuple[float, ...], torque: bool, payload: Payload, cell: Cell | None
                  ) -> tuple[Trajectory, str, Clearance | None]:  # fmt: skip
    """A straight (``move``) or joint (``go``) move timed jerk-limited time-optimal under the scaled limits."""
    from ..motion.jerk import time_optimal_jerk
    from ..motion.plan import Method
    from ..motion.trajectory import cartesian_path

    loaded = with_payload(robot, payload) if torque and payload.mass else robot
    if move.kind is MoveKind.MOVE:
        path: Any = cartesian_path(robot, [robot.tool_pose(q0), robot.tool_pose(q1)], start=q0, end=q1)
        method = Method.LINE_JERK.value
    else:
        path, method = np.array([q0, q1]), Method.JOINT_JERK.value
    traj = time_optimal_jerk(loaded, path, jerk, torque=torque, limits=limits).trajectory
    clearance = None
    if cell is not None:
        from ..motion.verify import clear_of

        clearance = clear_of(robot, traj, cell)
    return traj, method, clearance


def _checked(robot: RobotModel, traj: Trajectory, method: str, limits: JointLimits, torque: bool, payload: Payload,
             bound: float | None, source: Source, seconds: float, cell: Cell | None = None,
             clearance: Clearance | None = None, jerk: tuple[float, ...] | None = None) -> PlannedMove:  # fmt: skip
    """The move verified at 10 kHz (exit 3 if it fails) with what binds on it.

    In a cell, the clearance the planner's verification found (the same verifier, at 10 kHz, with the cell's
    scene) is kept; without one (a reversed jump) the move is verified against the cell here.
    """
    from ..motion.verify import verify

    sc = None
    if cell is not None and clearance is None:
        from ..cell import scene

        sc = scene(robot, cell)
    found = verify(robot, traj, limits=limits, jerk=jerk, torque=torque, payload=payload, q_start=traj.q_start,
                   q_end=traj.q_end, scene=sc).check()  # fmt: skip
    binding, worst = _binding(robot, traj, limits, torque, payload, jerk)
    return PlannedMove(traj, method, binding, worst, bound, source, seconds,
                       clearance if clearance is not None else found.clearance)  # fmt: skip


def _binding(robot: RobotModel, traj: Trajectory, limits: JointLimits, torque: bool, payload: Payload,
             jerk: tuple[float, ...] | None = None) -> tuple[tuple[LimitShare, ...], LimitShare]:  # fmt: skip
    """The limits at >= :data:`~scara_pin.motion.jump.BINDING` on the 10 kHz grid, with their share of the time."""
    from ..description import JOINT_NAMES
    from ..motion.jump import BINDING
    from ..motion.verify import VERIFY_RATE, limits_in_force, pieces_jerk, state_ratios

    lim = limits_in_force(robot, limits, None, torque)
    loaded = with_payload(robot, payload) if torque else robot
    t = np.append(np.arange(math.floor(traj.duration * VERIFY_RATE) + 1) / VERIFY_RATE, traj.duration)
    states: tuple[np.ndarray, ...] = traj.sample(t)
    if jerk is not None:
        states = (*states, pieces_jerk(traj, t, [built(p) for p in traj.pieces]))
    found, worst = [], LimitShare("velocity", JOINT_NAMES[0], -1.0, 0.0)
    for quantity, r in state_ratios(loaded, lim, states, None if jerk is None else np.asarray(jerk)).items():
        for j in range(r.shape[1]):
            who = "tool" if r.shape[1] == 1 else JOINT_NAMES[j]
            top = float(np.max(r[:, j]))
            if top > worst.ratio:
                worst = LimitShare(quantity.value, who, top, float(np.mean(r[:, j] >= BINDING)))
            if top >= BINDING:
                found.append(LimitShare(quantity.value, who, top, float(np.mean(r[:, j] >= BINDING))))
    found.sort(key=lambda b: -b.share)
    return tuple(found), worst


class Planner:
    """:func:`plan_move` with the job's options, each distinct move planned once (module docstring).

    Args:
        robot: the robot; torque, payload: the job's (with ``carry``, the payload is held from a pick to a
            place only, as RAPID's ``GripLoad``).
        cell: the job's cell (obstacles, margin), or None.
        carry: the part the tool holds between a pick and a place (tool frame), or None.
        jerk: the job's joint jerk limits [rad/s^3, m/s^3], one per joint, or None.
        store: the plan cache (:mod:`~scara_pin.job.cache`), or None: every move planned.

    Attributes:
        stats: how many moves were planned, reused, reversed and read from the cache, and the planning's wall time.
    """

    def __init__(self, robot: RobotModel, *, torque: bool = False, payload: PayloadLike = None,
                 cell: Cell | None = None, carry: Shape | None = None, jerk: tuple[float, ...] | None = None,
                 store: PlanStore | None = None) -> None:  # fmt: skip
        self.robot, self.torque, self.jerk = robot, torque, jerk
        self.payload = as_payload(payload)
        self.cell, self.carry = cell, carry
        if carry is not None and self.cell is None:
            from ..cell import Cell

            self.cell = Cell(origin="the job's boxes")
        self.store = store if store is not None and store.folder is not None else None
        self._robot_key = robot_digest(robot) if self.store is not None else ""
        self._done: dict[Hashable, PlannedMove] = {}
        self._cells: dict[Hashable, Cell] = {}
        self._cell_keys: dict[int, str] = {}
        self.stats = PlanningStats()

    def cell_for(self, placed: tuple[Obstacle, ...], holding: bool) -> Cell | None:
        """The cell in force: the job's obstacles, the boxes ``placed`` so far and, ``holding``, the part held."""
        if self.cell is None:
            return None
        key = (_boxes_key(placed), holding)
        found = self._cells.get(key)
        if found is None:
            found = self.cell.with_obstacles(placed)
            if self.carry is not None:
                found = found.with_carried(self.carry if holding else None)
            self._cells[key] = found
        return found

    def _key(self, move: Move, q_from: np.ndarray, q_to: np.ndarray, state: Hashable) -> Hashable:
        return (move.kind, q_from.tobytes(), q_to.tobytes(), move.speed, move.accel, move.shape, state)

    def _entry_key(self, move: Move, q0: np.ndarray, q1: np.ndarray, cell: Cell | None, payload: Payload) -> str:
        """The plan cache's key of ``move`` from ``q0`` in ``cell`` (:func:`~scara_pin.job.cache.move_key`)."""
        cell_key = self._cell_keys.get(id(cell))
        if cell_key is None:
            cell_key = self._cell_keys[id(cell)] = cell_digest(cell)
        shape = None if move.shape is None else (move.shape.rise, move.shape.clearance_radius, move.shape.max_height,
                                                 move.shape.via)  # fmt: skip
        load = (payload.mass, tuple(payload.com)) if self.torque else None
        return move_key(self._robot_key, move.kind.value, q0, q1, speed=move.speed, accel=move.accel, shape=shape,
                        jerk=self.jerk, torque=self.torque, payload_key=load, cell=cell_key)  # fmt: skip

    def _cached(self, key: str | None) -> PlannedMove | None:
        if key is None or self.store is None:
            return None
        entry = self.store.get(key)
        if entry is None:
            return None
        try:
            return PlannedMove.from_entry(self.robot, entry)
        except (KeyError, TypeError, ValueError, IndexError, ScaraError) as exc:
            log.warning("plan cache entry %s ignored (%s): the move is planned again and the entry replaced",
                        key[:16], " ".join(str(exc).split())[:200])  # fmt: skip
            return None

    def _keep(self, key: str | None, out: PlannedMove) -> None:
        if key is None or self.store is None or out.source in (Source.CACHED, Source.STILL):
            return
        entry = out.entry()
        if entry is not None:
            self.store.put(key, entry)

    def plan(self, move: Move, q_from: np.ndarray, placed: tuple[Obstacle, ...] = (),
             holding: bool = False) -> PlannedMove:  # fmt: skip
        """The move from ``q_from``: planned, or the same (or reversed) move planned before, or the cache's.

        Args:
            move: the move.
            q_from: where the robot is, at rest.
            placed: the boxes placed so far (obstacles).
            holding: the tool holds the job's part.
        """
        q0, q1 = np.asarray(q_from, dtype=float), np.asarray(move.q, dtype=float)
        state = (_boxes_key(placed), holding)
        key = self._key(move, q0, q1, state)
        found = self._done.get(key)
        if found is not None:
            self.stats = replace(self.stats, same=self.stats.same + 1)
            return replace(found, source=Source.SAME if found.trajectory is not None else Source.STILL, seconds=0.0)
        cell = self.cell_for(placed, holding)
        payload = self.payload if self.carry is None or holding else Payload()
        out = self._move(move, q0, q1, cell, payload, state)
        self._done[key] = out
        return out

    def free(self, move: Move, q_from: np.ndarray, holding: bool = False) -> PlannedMove:
        """The same move planned without the cell (the cost column: time in the cell minus this; no via hints)."""
        if move.shape is not None and move.shape.via:
            move = replace(move, shape=replace(move.shape, via=()))
        q0, q1 = np.asarray(q_from, dtype=float), np.asarray(move.q, dtype=float)
        payload = self.payload if self.carry is None or holding else Payload()
        state = ("free", holding)
        key = self._key(move, q0, q1, state)
        found = self._done.get(key)
        if found is None:
            found = self._done[key] = self._move(move, q0, q1, None, payload, state, counted=False)
        return found

    def _move(self, move: Move, q0: np.ndarray, q1: np.ndarray, cell: Cell | None, payload: Payload,
              state: Hashable, counted: bool = True) -> PlannedMove:  # fmt: skip
        """The move from the cache, as an earlier jump reversed, or planned; kept in the cache."""
        t0 = time.perf_counter()
        entry_key = self._entry_key(move, q0, q1, cell, payload) if self.store is not None else None
        out = self._cached(entry_key)
        back = self._done.get(self._key(move, q1, q0, state)) if move.kind is MoveKind.JUMP else None
        if out is not None:
            if counted:
                self.stats = replace(self.stats, cached=self.stats.cached + 1)
        elif back is not None and back.trajectory is not None and back.source is not Source.STILL:
            piece = built(back.trajectory.pieces[0])  # a move read from the cache: its polynomial now
            if not isinstance(piece, PolynomialPiece):  # pragma: no cover - jumps are polynomial pieces
                raise InvalidInputError("a reversed jump needs a polynomial piece")
            limits = scaled_limits(self.robot, move.speed, move.accel)
            out = _checked(self.robot, Trajectory((piece.reversed(),)), back.method, limits, self.torque,
                           payload, back.lower_bound, Source.REVERSED, time.perf_counter() - t0, cell,
                           jerk=self.jerk)  # fmt: skip
            if counted:
                self.stats = replace(self.stats, reversed=self.stats.reversed + 1)
        else:
            out = plan_move(self.robot, move, q0, torque=self.torque, payload=payload, cell=cell, jerk=self.jerk)
            if out.trajectory is not None and counted:
                self.stats = replace(self.stats, planned=self.stats.planned + 1)
            elif out.trajectory is not None:
                self.stats = replace(self.stats, free=self.stats.free + 1)
        self._keep(entry_key, out)
        self.stats = replace(self.stats, seconds=self.stats.seconds + time.perf_counter() - t0)
        return out


def _boxes_key(placed: tuple[Obstacle, ...]) -> Hashable:
    """What makes two sets of placed boxes the same: their shapes and placements, bit for bit."""
    return tuple((o.name, o.shape.size, o.shape.xyz.tobytes(), o.shape.rpy.tobytes()) for o in placed)


def _floats(values: np.ndarray) -> tuple[float, ...]:
    return tuple(float(v) for v in values)


def _hold(q: np.ndarray, seconds: float) -> Rest:
    """At rest at ``q`` for ``seconds`` (a dwell, a pick, a place)."""
    return Rest(seconds, np.asarray(q, dtype=float))


@dataclass(frozen=True, eq=False)
class Rest(Piece):
    """At rest at ``q`` for ``duration`` [s]: a piece of a job's trajectory (a dwell, a pick, a place).

    What a polynomial of degree 0 is, without its checks (a job of thousands of dwells builds thousands).

    Attributes:
        duration: [s] > 0.
        q: the joint values held [rad, m].
    """

    duration: float
    q: np.ndarray

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, 0, 0) at every local time."""
        n = np.asarray(tau).size
        return np.tile(self.q, (n, 1)), np.zeros((n, self.q.size)), np.zeros((n, self.q.size))

    def jerk(self, tau: np.ndarray) -> np.ndarray:
        """Zero: at rest."""
        return np.zeros((np.asarray(tau).size, self.q.size))


def plan_job(job: JobSpec, robot: RobotModel, *, progress: Callable[[int, int], None] | None = None,
             cache: PlanStore | bool = True) -> JobResult:
    """Plan every move of ``job`` for ``robot`` (module docstring): the table, the total, the trajectory.

    Everything the job file and the robot can tell is checked first
    (:meth:`~scara_pin.job.spec.JobSpec.program`); then the moves are planned in order, each from where the
    previous one ended. A Ctrl-C (or SIGTERM) swallowed by the solver stops the job after the move it interrupted.

    Args:
        job: the job.
        robot: the robot (4 joints, acceleration limits known).
        progress: called with (actions done, actions) after each move and dwell.
        cache: the plan cache (:mod:`~scara_pin.job.cache`): True, the user's (unless ``SCARA_PIN_NO_CACHE``);
            False: none (every move planned); or a store.

    Raises:
        JobFileError: the job cannot be run as written (exit 2), with the file and line.
        JobStepError: a place out of reach, a move the planner or the verifier refuses (exit 3), with the line.
    """
    if robot.dof != 4:
        raise JobFileError(job.path, None, f"a job needs a wrist (4 joints); robot {robot.name!r} has {robot.dof}")
    program = job.program(robot)
    cell = _job_cell(job)
    places = sum(isinstance(a, Grip) and a.kind is GripKind.PLACE for a in program.actions)
    if places:  # every box placed joins the cell: sized before any move is planned
        from ..limits import MAX_CELL_OBSTACLES, check_count

        try:
            check_count(f"obstacles of the cell (its {0 if cell is None else len(cell.obstacles)} and the {places:,} "
                        "boxes the job places)", places + (0 if cell is None else len(cell.obstacles)),
                        MAX_CELL_OBSTACLES, "split the job")  # fmt: skip
        except ScaraError as exc:
            raise located(job.path, job.lines.get("carry"), exc) from None
    carry = job.carry.part() if job.carry is not None else None
    store = (PlanStore.default() if cache else None) if isinstance(cache, bool) else cache
    planner = Planner(robot, torque=job.torque, payload=job.payload, cell=cell, carry=carry,
                      jerk=job.jerk_limits(robot), store=store)  # fmt: skip
    _check_goals(robot, planner, job, program)  # every goal and fixed path in its cell, before any move is planned
    q, at, t = program.start_q, program.start, 0.0
    pose = robot.tool_pose(q)
    placed: tuple[Obstacle, ...] = ()  # the boxes placed so far: the cell's obstacles for the moves after them
    boxes: list[PlacedBox] = []
    holding = False
    pieces: list[Any] = []
    rows: list[StepResult] = []
    n = len(program.actions)
    for k, action in enumerate(program.actions):
        if isinstance(action, (Dwell, Grip)):
            if action.seconds > 0.0:
                pieces.append(_hold(q, action.seconds))
            box = None
            if isinstance(action, Grip):
                holding = action.kind is GripKind.PICK
                if not holding:
                    box = _place(robot, planner, job, action, k + 1, q, placed, t + action.seconds)
                    placed, boxes = placed + (box.obstacle,), [*boxes, box]
                elif planner.cell is not None:  # the part picked must be clear of the cell where it is picked
                    _clear(robot, planner.cell_for(placed, True), q, job, action, f"the part picked at {at}")
            rows.append(StepResult(k + 1, action.line, StepKind.of(action), at, at, t, t + action.seconds,
                                   q=_floats(q), pose=_floats(pose), carrying=holding and box is None,
                                   boxes=len(placed), box=box, top=program.tops[k]))  # fmt: skip
            t += action.seconds
        else:
            try:
                planned = planner.plan(action, q, placed, holding)
                free = planner.free(action, q, holding) if planner.cell is not None else None
            except ScaraError as exc:
                raise located(job.path, action.line, exc, f"{action.kind.value} {at} -> {action.target}") from None
            if planned.trajectory is not None:
                pieces.extend(planned.trajectory.pieces)
            log.debug("job: line %s: %s %s -> %s: %.6f s (%s)", action.line, action.kind.value, at, action.target,
                      planned.duration, planned.source.value)  # fmt: skip
            rows.append(StepResult(k + 1, action.line, StepKind.of(action), at, action.target, t,
                                   t + planned.duration, action.place, planned.binding, planned.worst,
                                   action.speed, action.accel, planned.source.value, planned.method,
                                   planned.lower_bound, _floats(action.q), _floats(action.pose), holding, len(placed),
                                   planned.clearance, free=None if free is None else free.duration,
                                   top=program.tops[k]))  # fmt: skip
            t += planned.duration
            q, at, pose = np.asarray(action.q, dtype=float), action.target, action.pose
        raise_pending()  # a signal the solver swallowed stops the job here
        check_time()  # and so does a time limit (a sweep's variant)
        if progress is not None:
            progress(k + 1, n)
    if not pieces:
        raise JobFileError(job.path, job.lines.get("steps"), "the job never moves nor dwells: nothing to time")
    return JobResult(job.path, robot.name, tuple(rows), Trajectory(tuple(pieces)), len(program.places), planner.stats,
                     tuple(boxes), cell, carry)  # fmt: skip


def _check_goals(robot: RobotModel, planner: Planner, job: JobSpec, program: Any) -> None:
    """Every goal of the job, and every fixed path (``move``, ``go``), clear of its step's cell BEFORE any planning.

    The program is walked as :func:`plan_job` walks it (the part held from a pick to a place, each box placed an
    obstacle after it): the start, where each part is picked, the robot after each place, each move's target, and
    the geometric path of each ``move`` and ``go`` (:func:`~scara_pin.motion.plan.check_fixed_path`). A job whose
    10th place is in collision planned 9 jumps first; now it is refused at once, naming the step's line.

    Raises:
        JobFileError: a goal in collision (exit 2), at its line.
        JobStepError: a fixed path through an obstacle (exit 3), at its line.
    """
    from ..cell import scene
    from ..motion.plan import MotionRequest, check_fixed_path

    first = planner.cell_for((), False)
    if first is None:
        return
    q = np.asarray(program.start_q, dtype=float)
    at = program.start
    placed: tuple[Obstacle, ...] = ()
    holding = False
    try:
        scene(robot, first).check(q, f"the start of the job ({at})")
    except ScaraError as exc:
        raise located(job.path, job.lines.get("start"), exc) from None
    for k, action in enumerate(program.actions):
        if isinstance(action, Grip):
            holding = action.kind is GripKind.PICK
            if holding:
                _clear(robot, planner.cell_for(placed, True), q, job, action, f"the part picked at {at}")
            else:
                placed = (*placed, _place(robot, planner, job, action, k + 1, q, placed, 0.0).obstacle)
            continue
        if not isinstance(action, Move):
            continue
        cell = planner.cell_for(placed, holding) or first
        target = np.asarray(action.q, dtype=float)
        what = f"{action.kind.value} {at} -> {action.target}"
        try:
            if float(np.max(np.abs(target - q))) > STILL:
                scene(robot, cell).check(target, f"the goal ({action.target})")
                if action.kind is not MoveKind.JUMP:
                    check_fixed_path(robot, MotionRequest(start_q=q, end_q=target, linear=action.kind is MoveKind.MOVE,
                                                          cell=cell))  # fmt: skip
        except ScaraError as exc:
            raise located(job.path, action.line, exc, what) from None
        q, at = target, action.target


def _job_cell(job: JobSpec) -> Cell | None:
    """The job's cell file, read (a refusal names the job's ``cell:`` line too), checked against the job's carry."""
    if job.cell is None:
        return None
    from ..cell import load_cell

    try:
        cell = load_cell(job.cell)
    except ScaraError as exc:
        raise located(job.path, job.lines.get("cell"), exc) from None
    if job.frames.moved:  # the cell file is in the world frame; the robot plans in its base frame, placed by base:
        from ..cell import Obstacle

        bMw = job.frames.base_M_world()
        moved = tuple(Obstacle(o.name, o.shape.moved(bMw), o.line, o.margin) for o in cell.obstacles)
        cell = replace(cell, obstacles=moved)
    if job.carry is not None and cell.carried is not None:
        raise JobFileError(job.path, job.lines.get("carry"), f"the cell file {job.cell} gives a carried part too: in "
                           "a job the part is the job's carry:, held from a pick: to a place: (remove carried: from "
                           "the cell file)")  # fmt: skip
    taken = sorted(o.name for o in cell.obstacles if re.fullmatch(BOX.format(r"\d+"), o.name))
    if job.carry is not None and taken:
        raise JobFileError(job.path, job.lines.get("cell"), f"the cell file {job.cell} has an obstacle named "
                           f"{taken[0]}: {BOX.format(1)}, {BOX.format(2)}, ... name the boxes the job places "
                           "(rename it)")  # fmt: skip
    return cell


def _place(robot: RobotModel, planner: Planner, job: JobSpec, action: Grip, index: int, q: np.ndarray,
           placed: tuple[Obstacle, ...], t: float) -> PlacedBox:  # fmt: skip
    """The box a place leaves: the carried part moved by ``baseMtool`` at ``q``, an obstacle from time ``t``."""
    from ..cell import Obstacle

    carry = planner.carry
    if carry is None:  # pragma: no cover - the loader refuses grips without carry
        raise JobFileError(job.path, action.line, "place: needs the job's carry:")
    name = BOX.format(len(placed) + 1)
    box = Obstacle(name, carry.moved(robot.tool_placement(q), what=name))
    out = PlacedBox(name, index, action.at, t, box)
    _clear(robot, planner.cell_for((*placed, box), False), q, job, action, f"the robot after leaving {name} at "
           f"{action.at}", name)  # fmt: skip
    return out


def _clear(robot: RobotModel, cell: Cell | None, q: np.ndarray, job: JobSpec, action: Grip, what: str,
           box: str | None = None) -> None:  # fmt: skip
    """``q`` clear of ``cell`` (exit 2 at the grip's line, naming the pair, otherwise).

    When a link is too close to the ``box`` just left, the message says how to hang the part lower.
    """
    from ..cell import InCollisionError, scene

    if cell is None:  # pragma: no cover - a grip always has the job's cell or the boxes' own
        return
    try:
        scene(robot, cell).check(q, what)
    except InCollisionError as exc:
        hint = ""
        if box is not None and exc.pair.b == box:
            hint = (f" (the part must hang more than the margin, {exc.margin * 1e3:g} mm, below the tool's links: "
                    "lower it in the tool frame, carry: xyz)")  # fmt: skip
        raise JobFileError(job.path, action.line, f"{exc}{hint}") from None

