"""What every robot kind's inverse kinematics returns: solutions, results with reasons, batches.

A solution is one joint configuration per elbow branch: each revolute joint at the turn (q + 2 pi k)
nearest the reference, with the range of turns that also fit the joint's limits (``turns``). The full
Cartesian product of those turns is a list only on request (:meth:`IKResult.expand`, capped at
``MAX_SOLUTIONS``): a joint with placeholder limits of +/-1e6 rad has 300,000 turns.
"""

from __future__ import annotations

import enum
import itertools
import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from .errors import InvalidInputError
from .summary import Summarized

if TYPE_CHECKING:
    from ._typing import ArrayLike
    from .units import DisplayUnits

__all__ = ["MAX_SOLUTIONS", "BatchBranch", "BatchIKResult", "IKResult", "IKSolution", "joint_distance", "result_of"]

MAX_SOLUTIONS = 100_000
"""The most solutions :meth:`IKResult.expand` lists (``ik --all-turns``); beyond it: InvalidInputError."""

_TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class IKSolution:
    """One joint configuration reaching the target.

    Attributes:
        q: joint values in URDF order [rad, m], each revolute joint at the turn nearest the reference.
        branch: the elbow branch (SCARA ``right``/``left``, palletizer ``up``/``down``).
        singular: on the stretched/folded boundary where the two branches are one solution.
        turns: per joint, (k_min, k_max): q_j + 2 pi k for k in that range also fits the limits
            (k_min <= 0 <= k_max); (0, 0) for a prismatic joint; None for a continuous joint (every turn).
    """

    q: np.ndarray
    branch: str
    singular: bool = False
    turns: tuple[tuple[int, int] | None, ...] = ()

    def matches(self, branch: str) -> bool:
        """Whether this solution belongs to ``branch`` (``"all"`` or a branch name)."""
        return branch == "all" or self.branch == branch or self.singular

    def distance(self, q: ArrayLike) -> float:
        """max_i |q_i - (self.q_i + 2 pi k_i)| over the turns k_i this solution stands for (the nearest one).

        How far ``q`` is from being one of this solution's configurations [rad or m].
        """
        d = np.asarray(q, dtype=float) - self.q
        out = 0.0
        for i, t in enumerate(self.turns or ((0, 0),) * len(d)):
            k = round(float(d[i]) / _TWO_PI)
            if t is not None:
                k = min(max(k, t[0]), t[1])
            out = max(out, abs(float(d[i]) - _TWO_PI * k))
        return out

    @property
    def count(self) -> int | None:
        """How many configurations this solution stands for (its turns multiplied); None if unbounded."""
        n = 1
        for t in self.turns:
            if t is None:
                return None
            n *= t[1] - t[0] + 1
        return n


def joint_distance(q: np.ndarray, reference: np.ndarray, weights: np.ndarray, continuous: tuple[bool, ...]) -> float:
    """sum_i w_i (q_i - ref_i)^2, the difference wrapped to [-pi, pi) on continuous joints."""
    d = q - reference
    for i, c in enumerate(continuous):
        if c:
            d[i] = math.remainder(d[i], _TWO_PI)
    return float(np.dot(d * d, weights))


@dataclass(frozen=True, repr=False)
class IKResult(Summarized):
    """The solutions of one target (one per branch, see the module docstring), or the reason there is none.

    Attributes:
        target: (x, y, z, yaw) of the tool frame in the base frame [m, rad].
        solutions: the solutions (empty when ``status`` is not OK), ordered by branch.
        status: the kind's status enum (``OK`` = 0), e.g. :class:`~scara_pin.kinematics.scara.IKStatus`.
        message: a sentence with the numbers behind the status.
        continuous: per joint, whether it is continuous (distances to a reference are wrapped there).
    """

    target: np.ndarray
    solutions: tuple[IKSolution, ...]
    status: enum.IntEnum
    message: str
    continuous: tuple[bool, ...] = ()

    @property
    def success(self) -> bool:
        """True when at least one solution exists."""
        return int(self.status) == 0

    def summary(self, units: DisplayUnits | None = None) -> str:
        """The target, the status and each solution in a line (q in SI: rad, and m for a prismatic joint)."""
        head = f"IKResult {self.status.name} for target {np.round(self.target, 9).tolist()} [m, rad]: {self.message}"
        rows = [f"  {s.branch:<6} q = {np.round(s.q, 9).tolist()}" + (" (singular)" if s.singular else "")
                for s in self.solutions]  # fmt: skip
        return "\n".join([head, *rows])

    def branch(self, branch: str) -> tuple[IKSolution, ...]:
        """The solutions of one branch (or ``"all"``)."""
        return tuple(s for s in self.solutions if s.matches(branch))

    def nearest(self, reference: ArrayLike, weights: ArrayLike | None = None, branch: str = "all") -> IKSolution | None:
        """The solution nearest to ``reference`` (sum of w_i (q_i - ref_i)^2, wrapped on continuous joints).

        Returns ``None`` only when no solution of ``branch`` exists (see ``status``/``message``); the first on
        a tie.
        """
        candidates = self.branch(branch)
        if not candidates:
            return None
        ref = np.asarray(reference, dtype=float)
        w = np.ones(len(ref)) if weights is None else np.asarray(weights, dtype=float)
        cont = self.continuous or (False,) * len(ref)
        d = [joint_distance(s.q, ref, w, cont) for s in candidates]
        return candidates[int(np.argmin(d))]

    @property
    def count(self) -> int | None:
        """How many configurations the solutions stand for, every turn counted; None if unbounded."""
        total = 0
        for s in self.solutions:
            n = s.count
            if n is None:
                return None
            total += n
        return total

    def expand(self, lower: ArrayLike, upper: ArrayLike, limit: int = MAX_SOLUTIONS) -> IKResult:
        """Every turn of every solution as its own solution (continuous joints: the nearest turn only).

        Args:
            lower: the lower joint limits; a turn within LIMIT_TOL outside is clamped onto them.
            upper: the upper joint limits (likewise).
            limit: the most solutions listed.

        Raises:
            InvalidInputError: more than ``limit`` solutions (counted before any is built).
        """
        total = sum(
            math.prod((t[1] - t[0] + 1) if t is not None else 1 for t in s.turns) for s in self.solutions
        )
        if total > limit:
            raise InvalidInputError(
                f"the target has {total} solutions counting every joint turn inside the limits, more than "
                f"{limit} can be listed; the joint limits span many turns (the per-branch answer gives each "
                "joint's turn range)"
            )
        out: list[IKSolution] = []
        for s in self.solutions:
            ranges = [range(t[0], t[1] + 1) if t is not None else range(0, 1) for t in s.turns]
            for ks in itertools.product(*ranges):
                q = np.clip(s.q + _TWO_PI * np.array(ks, dtype=float), lower, upper)
                out.append(replace(s, q=q, turns=tuple(None if t is None else (t[0] - k, t[1] - k)
                                                       for t, k in zip(s.turns, ks))))  # fmt: skip
        return replace(self, solutions=tuple(out))


def result_of(
    pose: np.ndarray, found: list[tuple[str, bool, list[float], list[tuple[int, int] | None]]],
    failure: tuple[enum.IntEnum, str] | None, ok: enum.IntEnum, continuous: tuple[bool, ...],
    lower: ArrayLike, upper: ArrayLike, all_turns: bool,
) -> IKResult:  # fmt: skip
    """An IKResult from a closed form's branches ((label, singular, q, turns) each) or its failure."""
    if failure is not None:
        return IKResult(pose, (), failure[0], failure[1], continuous)
    sols = tuple(IKSolution(np.array(q), label, singular, tuple(turns)) for label, singular, q, turns in found)
    result = IKResult(pose, sols, ok, f"{len(sols)} solution(s)", continuous)
    return result.expand(lower, upper) if all_turns else result


class BatchBranch(enum.IntEnum):
    """The codes of :attr:`BatchIKResult.branch`: which elbow branch a row's solution is on.

    ``FIRST`` is the kind's first branch (SCARA ``right``, palletizer ``up``), ``SECOND`` its second (SCARA
    ``left``, palletizer ``down``); ``NONE`` marks a row without a solution.
    """

    FIRST = 1
    SECOND = -1
    NONE = 0


@dataclass(frozen=True)
class BatchIKResult:
    """One solution per target: the requested branch, or the nearest branch, at the turns nearest the reference.

    The arrays stay plain integers (vectorised code compares them at numpy speed); the kind's enums name
    them: ``result.statuses()`` gives each row's status member (``IKStatus.OUT_OF_REACH``, ...),
    ``result.branch_labels()`` each row's branch name, ``result.counts()`` the number of rows per status, and
    ``result.ok`` the rows solved. ``BatchBranch`` names the branch codes.

    Attributes:
        q: (N, 4) joint values; NaN rows where there is no solution.
        status: (N,) status codes as integers: 0 = OK, else the value of the kind's status enum
            (``status_enum``: :class:`~scara_pin.kinematics.scara_geometry.IKStatus` for a SCARA).
        branch: (N,) :class:`BatchBranch` codes: +1 the first branch (SCARA right, palletizer up), -1 the
            second, 0 where there is no solution.
        status_enum: the kind's status enum (None: the codes are not named).
        branches: the kind's branch names, first and second (``("right", "left")``, ``("up", "down")``).
    """

    q: np.ndarray
    status: np.ndarray
    branch: np.ndarray
    status_enum: type[enum.IntEnum] | None = None
    branches: tuple[str, str] = ("right", "left")

    def __len__(self) -> int:
        return len(self.status)

    @property
    def ok(self) -> np.ndarray:
        """(N,) booleans: the rows with a solution."""
        return np.asarray(self.status == 0)

    def statuses(self) -> list[enum.IntEnum]:
        """Each row's status as the kind's enum member (``IKStatus.OK``, ``IKStatus.OUT_OF_REACH``, ...).

        Raises:
            InvalidInputError: the result does not know its kind's enum (``status_enum`` is None).
        """
        if self.status_enum is None:
            raise InvalidInputError("this batch result does not name its status codes (status_enum is None)")
        members = {int(m): m for m in self.status_enum}
        return [members[int(c)] for c in self.status.tolist()]

    def branch_labels(self) -> list[str]:
        """Each row's branch name (``"right"``/``"left"``, ``"up"``/``"down"``), ``""`` where no solution."""
        names = {1: self.branches[0], -1: self.branches[1], 0: ""}
        return [names[int(b)] for b in self.branch.tolist()]

    def counts(self) -> dict[str, int]:
        """The number of rows per status name (``{"OK": 998, "OUT_OF_REACH": 2}``), most frequent first."""
        codes, n = np.unique(self.status, return_counts=True)
        named = {int(m): m.name for m in self.status_enum} if self.status_enum is not None else {}
        pairs = sorted(((named.get(int(c), str(int(c))), int(k)) for c, k in zip(codes, n)), key=lambda p: -p[1])
        return dict(pairs)

    def _repr_html_(self) -> str:
        from html import escape

        return f"<pre>{escape(repr(self))}</pre>"

    def __repr__(self) -> str:
        solved = int(np.count_nonzero(self.branch))
        first = int(np.count_nonzero(self.branch == BatchBranch.FIRST))
        counts = ", ".join(f"{k} {v}" for k, v in self.counts().items())
        return (f"BatchIKResult({len(self)} targets: {counts}; branches {self.branches[0]} {first}, "
                f"{self.branches[1]} {solved - first})")  # fmt: skip
