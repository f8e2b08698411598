"""The steps of a job, and their expansion into a program: the moves and dwells in the order they run.

A job's ``steps`` (docs/job.md) are settings, moves, dwells and loops:

- ``speed: P`` / ``accel: P`` (one step may hold both): the velocity / acceleration limits of the moves
  that follow are P % of the robot's, 0 < P <= 100 (SPEL+'s ``Speed`` and ``Accel``); they hold until
  changed, inside and after loops alike;
- ``jump: T`` (the time-optimal jump, :func:`~scara_pin.motion.jump.jump_move`; ``rise``,
  ``clearance_radius`` and ``max_height`` beside it override the job's), ``move: T`` (a straight tool
  line, time-optimal), ``go: T`` (a joint move, time-optimal): from where the robot is to target T;
- ``dwell: S``: S seconds at rest (a gripper opening, SPEL+'s ``Wait``);
- ``pick: S`` / ``place: S``: the gripper closes (opens) during S seconds at rest: from a ``pick`` the tool
  holds the job's ``carry`` part, at a ``place`` it leaves it where it is (SPEL+'s ``On``/``Off`` and
  ``Wait``, RAPID's ``SetDO`` and ``WaitTime``); :func:`check_grips` checks the order without a robot;
- ``for: PALLET`` (its places, in ``order``: rows, columns or serpentine) or ``for: N`` (N times), with
  ``do: [steps]`` and the loop variable ``var`` (default ``i``; a nested loop names its own).

A target T is a point of the points file by name (its joint values ARE the point) or a pallet's place,
``PALLET[K]``: K a place number from 1 or a loop variable. A place's joint values are the closed-form IK
of its pose on the branch of the pallet's first corner, each joint at the turn nearest where the robot
is before the move (so J4 never unwinds a turn between neighbouring places).

The expansion (:func:`expand`) unrolls the loops into a :class:`Program` of :class:`Move` and
:class:`Dwell` actions, each with its line in the job file, and solves every place's IK: a place out
of reach is refused (:class:`~scara_pin.errors.JobStepError`, exit 3) before any move is planned.
"""

from __future__ import annotations

import enum
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InfeasibleError, InvalidInputError, JobFileError, JobStepError, NoSolutionError, ScaraError
from .pallets import Order, Pallet

if TYPE_CHECKING:
    from ..model import RobotModel
    from ..motion.points import PointSet

__all__ = [
    "Dwell",
    "Grip",
    "GripKind",
    "JumpShape",
    "Loop",
    "Move",
    "MoveKind",
    "MotionStep",
    "Program",
    "Setting",
    "Step",
    "StepKind",
    "Target",
    "check_grips",
    "expand",
    "located",
    "parse_target",
    "tally",
]

_NAME = r"[A-Za-z][A-Za-z0-9_.\-]{0,31}"
VARIABLE = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,31}", re.ASCII)
"""A loop variable's name."""
_TARGET = re.compile(rf"({_NAME})(?:\[\s*([0-9]{{1,9}}|[A-Za-z_][A-Za-z0-9_]{{0,31}})\s*\])?", re.ASCII)


class MoveKind(enum.StrEnum):
    """A move's kind; the value is its key in a job file (a str: ``MoveKind.JUMP == "jump"``)."""

    JUMP = "jump"
    MOVE = "move"
    GO = "go"


def located(path: Path, line: int | None, exc: ScaraError, what: str = "") -> ScaraError:
    """``exc`` with the job file, the line and ``what`` in front: exit 2 stays 2 (:class:`JobFileError`), 3 stays 3."""
    if isinstance(exc, (JobFileError, JobStepError)):
        return exc
    reason = f"{what}: {exc}" if what else str(exc)
    if isinstance(exc, InfeasibleError):
        return JobStepError(path, line, reason)
    if isinstance(exc, InvalidInputError):
        return JobFileError(path, line, reason)
    return exc


@dataclass(frozen=True)
class Target:
    """Where a move goes: a point by name, or a pallet's place (``index`` a number from 1 or a loop variable).

    Attributes:
        name: the point's or the pallet's name.
        index: None for a point; the place number, or the loop variable that holds it.
    """

    name: str
    index: int | str | None = None

    def text(self, env: Mapping[str, int] | None = None) -> str:
        """As written (``tray[i]``), or with the variable's value (``tray[5]``) when ``env`` is given."""
        if self.index is None:
            return self.name
        index = env[self.index] if env is not None and isinstance(self.index, str) else self.index
        return f"{self.name}[{index}]"


def parse_target(text: object) -> Target:
    """A target as written: ``NAME`` or ``PALLET[K]`` (K a place number from 1, or a loop variable)."""
    m = _TARGET.fullmatch(text.strip()) if isinstance(text, str) else None
    if m is None:
        shown = repr(text if not isinstance(text, str) or len(text) <= 40 else text[:40] + "...")
        raise InvalidInputError(f"target {shown} must be a point's name (e.g. feeder) or a pallet's place "
                                "(e.g. tray[3], tray[i])")  # fmt: skip
    index = m.group(2)
    if index is None:
        return Target(m.group(1))
    return Target(m.group(1), int(index) if index.isdigit() else index)


@dataclass(frozen=True)
class JumpShape:
    """The clearance of a jump (:func:`~scara_pin.motion.jump.jump_move`), SI.

    Attributes:
        rise: [m] how high above the higher pose the tool must be away from both; None: the standard
            (:data:`~scara_pin.motion.jump.STANDARD_RISE`).
        clearance_radius: [m] within this of a pose (horizontally) the tool may be lower; None: the standard
            (:data:`~scara_pin.motion.jump.STANDARD_CLEARANCE`).
        max_height: [m] a ceiling for the tool's z, or None.
        via: joint configurations, hints of the jump's way through the cell (the step's ``via:`` points, in
            order; :func:`~scara_pin.motion.jump.jump_move`'s ``via``).
    """

    rise: float | None = None
    clearance_radius: float | None = None
    max_height: float | None = None
    via: tuple[tuple[float, ...], ...] = ()

    def resolved(self) -> tuple[float, float, float | None]:
        """(rise, clearance_radius, max_height) with the standard values for those not given [m]."""
        from ..motion.jump import STANDARD_CLEARANCE, STANDARD_RISE  # the planner's: imported when a jump is planned

        return (STANDARD_RISE if self.rise is None else self.rise,
                STANDARD_CLEARANCE if self.clearance_radius is None else self.clearance_radius, self.max_height)


@dataclass(frozen=True)
class Setting:
    """``speed`` and/or ``accel``: percentages of the limits for the moves that follow (None: unchanged)."""

    speed: float | None
    accel: float | None
    line: int | None = None


@dataclass(frozen=True)
class MotionStep:
    """A move to ``target``; its jump's ``rise``, ``clearance_radius``, ``max_height`` and ``via`` points.

    The three numbers override the job's; ``via`` names the points of the jump's way through the cell (jumps only).
    """

    kind: MoveKind
    target: Target
    line: int | None = None
    rise: float | None = None
    clearance_radius: float | None = None
    max_height: float | None = None
    via: tuple[str, ...] = ()


@dataclass(frozen=True)
class Dwell:
    """``seconds`` at rest where the robot is (a step, and an action of the program).

    Attributes:
        seconds: [s] >= 0.
        line: the line of the step in the job file.
        at: the name of the place the robot rests at (set by the expansion).
    """

    seconds: float
    line: int | None = None
    at: str = ""


class GripKind(enum.StrEnum):
    """What the gripper does; the value is the step's key in a job file (a str: ``GripKind.PICK == "pick"``)."""

    PICK = "pick"
    PLACE = "place"


class StepKind(enum.StrEnum):
    """The kind of a row of a job's table (:class:`~scara_pin.job.results.StepResult`): a move's, a grip's or a dwell.

    Its values are the job file's keys, the same as :class:`MoveKind`'s and :class:`GripKind`'s
    (``StepKind.JUMP == MoveKind.JUMP == "jump"``).
    """

    JUMP = "jump"
    MOVE = "move"
    GO = "go"
    DWELL = "dwell"
    PICK = "pick"
    PLACE = "place"

    @classmethod
    def of(cls, action: Action) -> StepKind:
        """The kind of an action of a program."""
        return cls.DWELL if isinstance(action, Dwell) else cls(action.kind.value)


@dataclass(frozen=True)
class Grip:
    """The gripper closing (``pick``) or opening (``place``) during ``seconds`` at rest (a step, and an action).

    From a pick the tool holds the job's carried part (it collides with the cell, and the payload is carried);
    at a place the part stays where the tool leaves it, an obstacle for every move after it.

    Attributes:
        kind: pick or place.
        seconds: [s] >= 0, at rest.
        line: the line of the step in the job file.
        at: the name of the place the robot rests at (set by the expansion).
    """

    kind: GripKind
    seconds: float
    line: int | None = None
    at: str = ""


@dataclass(frozen=True)
class Loop:
    """``for``: the body once per place of a pallet (``over`` its name) or ``over`` times (a count).

    Attributes:
        over: the pallet's name, or the count.
        var: the loop variable: the place number (a pallet), or 1..count.
        order: the order of a pallet's places.
        body: the steps repeated.
        line: the line of the ``for``.
    """

    over: str | int
    var: str
    order: Order
    body: tuple[Step, ...]
    line: int | None = None


Step = Setting | MotionStep | Dwell | Grip | Loop


def tally(steps: tuple[Step, ...], pallets: Mapping[str, Pallet]) -> tuple[int, float]:
    """(moves and dwells, seconds of dwell) ``steps`` expand to, loops unrolled: counted, never built."""
    n, dwell = 0, 0.0
    for step in steps:
        if isinstance(step, Loop):
            times = step.over if isinstance(step.over, int) else pallets[step.over].places
            inner = tally(step.body, pallets)
            n, dwell = n + times * inner[0], dwell + times * inner[1]
        elif isinstance(step, (Dwell, Grip)):
            n, dwell = n + 1, dwell + step.seconds
        elif not isinstance(step, Setting):
            n += 1
    return n, dwell


def check_grips(steps: tuple[Step, ...], pallets: Mapping[str, Pallet], path: Path, holding: int | None = None
                ) -> int | None:  # fmt: skip
    """The gripper's state after ``steps`` (the line of the pick holding a part, 0 if unknown; None: empty).

    A pick while the tool holds a part, or a place while it holds none, is refused with the step's line. A loop's
    body is followed twice when it runs more than once: the state is one of two, so the second pass sees every
    state a later pass can start from (counted, never unrolled).

    Raises:
        JobFileError: the grip out of order, with its line.
    """
    for step in steps:
        if isinstance(step, Loop):
            times = step.over if isinstance(step.over, int) else pallets[step.over].places
            for _ in range(min(times, 2)):
                holding = check_grips(step.body, pallets, path, holding)
        elif isinstance(step, Grip):
            if step.kind is GripKind.PICK and holding is not None:
                where = f"at line {holding}" if holding else "before"
                raise JobFileError(path, step.line, f"pick: the tool already holds the part picked {where} (a place: "
                                   "comes first)")  # fmt: skip
            if step.kind is GripKind.PLACE and holding is None:
                raise JobFileError(path, step.line, "place: the tool holds no part here (no pick: since the job "
                                   "began or since the last place:)")  # fmt: skip
            holding = (step.line or 0) if step.kind is GripKind.PICK else None
    return holding


@dataclass(frozen=True, eq=False)
class Move:
    """One move of a program, resolved.

    Attributes:
        kind: jump, move or go.
        target: the target's text with the place number (``tray[5]``, ``feeder``).
        place: (pallet, place number) when the target is a pallet's place, else None.
        q: the joint values at the target [rad, m].
        pose: the tool pose at the target (x, y, z, yaw) [m, rad].
        speed, accel: the fractions of the velocity and acceleration limits, in (0, 1].
        shape: the jump's clearance (jumps; None for the others).
        line: the line of the step in the job file.
    """

    kind: MoveKind
    target: str
    place: tuple[str, int] | None
    q: np.ndarray
    pose: np.ndarray
    speed: float
    accel: float
    shape: JumpShape | None
    line: int | None


Action = Move | Dwell | Grip


@dataclass(frozen=True, eq=False)
class Program:
    """A job expanded: where it starts and its actions in order.

    Attributes:
        start: the start's name; start_q: its joint values.
        actions: the moves and dwells.
        places: the (pallet, place number) the moves reach, in order (each arrival counts).
        tops: for each action, the index (from 0) of the job's top-level step it comes from (loops unrolled).
    """

    start: str
    start_q: np.ndarray
    actions: tuple[Action, ...]
    places: tuple[tuple[str, int], ...] = field(default=())
    tops: tuple[int, ...] = field(default=())


@dataclass
class _State:
    q: np.ndarray | None  # None before the first move when no start is given
    at: str
    speed: float = 1.0
    accel: float = 1.0
    override: tuple[float, float] = (1.0, 1.0)  # the job's speed and accel, times every move's


class _Resolver:
    """Targets to joint values: points as taught, places by IK on their first corner's branch."""

    def __init__(self, robot: RobotModel, points: PointSet, pallets: Mapping[str, Pallet],
                 pallet_lines: Mapping[str, int | None], path: Path) -> None:  # fmt: skip
        self.robot, self.points, self.pallets, self.path = robot, points, pallets, path
        self.pallet_lines = pallet_lines
        self._corners: dict[str, np.ndarray] = {}

    def corners(self, name: str) -> np.ndarray:
        """The corner poses of pallet ``name``, checked once (a refusal names the pallet's line)."""
        if name not in self._corners:
            pallet = self.pallets[name]
            poses = np.array([self.robot.tool_pose(self.points.q_of(c)) for c in pallet.corners])
            try:
                self._corners[name] = pallet.corner_poses(poses)
            except InvalidInputError as exc:
                raise JobFileError(self.path, self.pallet_lines.get(name), str(exc)) from None
        return self._corners[name]

    def resolve(self, target: Target, env: Mapping[str, int], near: np.ndarray | None
                ) -> tuple[str, tuple[str, int] | None, np.ndarray, np.ndarray]:  # fmt: skip
        """(text, place or None, q, pose) of ``target`` with the loop variables ``env``, IK nearest ``near``."""
        if target.index is None:
            q = self.points.q_of(target.name)
            return target.name, None, q, self.robot.tool_pose(q)
        index = env[target.index] if isinstance(target.index, str) else target.index
        pallet = self.pallets[target.name]
        pose = pallet.pose(self.corners(target.name), index)  # the index checked again (the loader did)
        first = self.points.q_of(pallet.corners[0])
        text = f"{target.name}[{index}]"
        branch = self.robot.branch_of(first)
        try:
            q = self.robot.ik_nearest(pose, first if near is None else near, branch=branch)
        except NoSolutionError as exc:
            shown = ", ".join(f"{v:.6g}" for v in pose)
            raise InfeasibleError(f"{text} at (x, y, z, yaw) = ({shown}) [m, rad] is out of reach on the {branch} "
                                  f"branch of its first corner {pallet.corners[0]}: {exc.reason}") from None
        return text, (target.name, index), q, pose


def expand(
    steps: tuple[Step, ...],
    *,
    robot: RobotModel,
    points: PointSet,
    pallets: Mapping[str, Pallet],
    start: Target | None,
    shape: JumpShape,
    path: Path,
    start_line: int | None = None,
    pallet_lines: Mapping[str, int | None] | None = None,
    speed: float = 1.0,
    accel: float = 1.0,
) -> Program:
    """The program of ``steps``: loops unrolled, targets resolved (module docstring).

    Args:
        steps: the job's steps (checked by the loader: names, indices, caps).
        robot: the robot (the points' FK, the places' IK).
        points: the taught points, checked against ``robot``.
        pallets: the pallets by name.
        start: where the robot is when the job begins; None: the first move's target.
        shape: the jumps' clearance unless a step overrides it.
        path: the job file (for the messages).
        start_line: the line of ``start`` in the job file.
        pallet_lines: the line of each pallet in the job file.
        speed: the job's override of the velocity limits: every move's fraction times it, in (0, 1].
        accel: the same for the acceleration limits.

    Raises:
        JobFileError: collinear or coincident corners (exit 2, at the pallet's line).
        JobStepError: a place out of reach (exit 3, at the step's line).
    """
    resolver = _Resolver(robot, points, pallets, pallet_lines or {}, path)
    for name in pallets:  # every pallet's corners checked, used or not
        resolver.corners(name)
    state = _State(None, "", override=(speed, accel))
    if start is not None:
        try:
            state.at, _, state.q, _ = resolver.resolve(start, {}, None)
        except ScaraError as exc:
            raise located(path, start_line, exc) from None
    begin = (state.at, state.q)
    actions: list[Action] = []
    places: list[tuple[str, int]] = []
    tops: list[int] = []
    for top, step in enumerate(steps):
        for action in _unroll((step,), {}, state, resolver, shape, path):
            if isinstance(action, Move):
                if begin[1] is None:  # no start given: the robot starts at the first move's target
                    begin = (action.target, action.q)
                if action.place is not None:
                    places.append(action.place)
            actions.append(action)
            tops.append(top)
    if begin[1] is None:
        raise JobFileError(path, None, "the job has no move: nothing to time")
    return Program(begin[0], np.array(begin[1], dtype=float), tuple(actions), tuple(places), tuple(tops))


def _unroll(steps: tuple[Step, ...], env: dict[str, int], state: _State, resolver: _Resolver, shape: JumpShape,
            path: Path) -> Iterator[Action]:  # fmt: skip
    for step in steps:
        if isinstance(step, Setting):
            state.speed = state.speed if step.speed is None else step.speed / 100.0
            state.accel = state.accel if step.accel is None else step.accel / 100.0
        elif isinstance(step, Dwell):
            yield Dwell(step.seconds, step.line, state.at)
        elif isinstance(step, Grip):
            yield Grip(step.kind, step.seconds, step.line, state.at)
        elif isinstance(step, MotionStep):
            try:
                text, place, q, pose = resolver.resolve(step.target, env, state.q)
            except ScaraError as exc:
                raise located(path, step.line, exc) from None
            jump = None
            if step.kind is MoveKind.JUMP:
                jump = JumpShape(shape.rise if step.rise is None else step.rise,
                                 shape.clearance_radius if step.clearance_radius is None else step.clearance_radius,
                                 shape.max_height if step.max_height is None else step.max_height,
                                 tuple(tuple(map(float, resolver.points.q_of(name))) for name in step.via))  # fmt: skip
            speed, accel = state.speed * state.override[0], state.accel * state.override[1]
            yield Move(step.kind, text, place, q, pose, speed, accel, jump, step.line)
            state.q, state.at = q, text
        else:
            if isinstance(step.over, int):
                values: list[int] = list(range(1, step.over + 1))
            else:
                values = resolver.pallets[step.over].order(step.order)
            for value in values:
                env[step.var] = value
                yield from _unroll(step.body, env, state, resolver, shape, path)
            env.pop(step.var, None)
