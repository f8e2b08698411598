"""Near-parallel axes: the closed form's solutions refined by Newton steps on the model as written.

A URDF whose ``rpy`` writes pi as ``3.14`` (or ``3.14159``) tilts the joint axes by up to 1.6e-3 rad
(2.65e-6 rad): the closed form of :mod:`scara_pin.kinematics.scara`, exact for vertical axes, then misses
the target by about the tilt times the lever arm (a millimetre on a 0.6 m arm). Up to
``NEAR_PARALLEL_TOL`` (1e-2 rad) the closed form, solved on the ideal vertical-axis geometry read from the
model, gives every branch and turn as a seed, and Newton steps on the Pinocchio model polish each one:

    q <- q + J(q)^-1 (x* - f(q)),

with f the task of the tool in the base frame (``robot.tool_pose``: x, y, z, yaw; x, y, z for a
3-joint arm, which has no wrist) and J its square task Jacobian (``robot.task_jacobian``; its yaw row is
the angular velocity about base z, d(yaw)/dq up to O(tilt), so the steps converge linearly at a rate of
about the tilt, a few steps from the closed form's seed). A step that does not reduce the residual is
halved (at most ``HALVINGS`` times).

Each branch's seed is polished on its own, and its result is checked, never silently dropped:

- converged: the residual max |x* - f(q)| (yaw wrapped) reaches ``POLISH_TOL``, else ``NOT_REFINED``;
- the same branch: the elbow's side (:func:`scara_pin.kinematics.scara.branch_of`) is the seed's, unless
  the seed was singular (stretched or folded), else ``NOT_REFINED``;
- inside the limits: a joint outside a limit by more than ``LIMIT_TOL`` fails that branch with the
  limit's status (``J1_LIMIT``, ``J2_LIMIT``, ``J3_STROKE``, ``J4_LIMIT``); within it, it is put on the limit.

The turn ranges are recomputed at the polished q (:func:`~scara_pin.kinematics.planar2r.nearest_turn`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..ik_results import IKResult, IKSolution
from .planar2r import LIMIT_TOL, TWO_PI, nearest_turn
from .scara_geometry import BRANCHES, IKStatus, ScaraGeometry, branch_of, wrist_point

if TYPE_CHECKING:
    from collections.abc import Callable

    from .._typing import ArrayLike
    from ..ik_results import BatchIKResult
    from ..model import RobotModel

__all__ = [
    "HALVINGS",
    "MAX_STEPS",
    "POLISH_TOL",
    "SEED_MARGIN",
    "Refined",
    "UnrefinedError",
    "polish_batch",
    "polish_result",
    "refine",
    "row_solver",
    "seed_geometry",
    "solve_refined",
    "unrefined_error",
]

POLISH_TOL = 1e-10
"""[m, rad] the largest task residual of a polished solution (the kinematics bar is 1e-9)."""
_FINE = 1e-13
"""[m, rad] the residual where the steps stop early (a few ulps of a metre-sized pose)."""
SEED_MARGIN = 20.0
"""The seeds come from the ideal geometry with every limit widened by SEED_MARGIN * tilt [rad or m], and a
target the ideal arm cannot reach is moved radially inside its reach, by tilt * (l1 + l2) then SEED_MARGIN
times that: the model departs from the ideal geometry by about the tilt times a lever, so its solutions near
a limit or the reach circles have seeds; the limits and the reach are then the model's own (checked after
the steps)."""
MAX_STEPS = 30
"""The most Newton steps per seed."""
HALVINGS = 8
"""The most times a step that does not reduce the residual is halved."""


@dataclass(frozen=True)
class Refined:
    """One seed after the Newton steps.

    Attributes:
        q: the joint values reached [rad, m].
        residual: max |x* - f(q)| over the task (yaw wrapped) [m, rad].
        steps: Newton steps taken.
        converged: ``residual <= POLISH_TOL``.
    """

    q: np.ndarray
    residual: float
    steps: int
    converged: bool


def _error(robot: RobotModel, q: np.ndarray, task: np.ndarray) -> np.ndarray:
    e = task - robot.tool_pose(q)[: len(task)]
    if len(task) == 4:
        e[3] = math.remainder(e[3], TWO_PI)
    return e


def refine(robot: RobotModel, seed: np.ndarray, task: np.ndarray) -> Refined:
    """Newton steps on the model from ``seed`` towards ``task``.

    Args:
        robot: the loaded robot (its model as written).
        seed: the starting joint values (the closed form's solution), ``robot.dof`` values.
        task: (x, y, z, yaw) for a 4-joint arm, (x, y, z) for a 3-joint one, in the base frame [m, rad].

    Returns:
        Refined: the q reached and its residual.
    """
    n = len(task)
    q = np.array(seed, dtype=float)
    e = _error(robot, q, task)
    r = float(np.abs(e).max())
    steps = 0
    while r > _FINE and steps < MAX_STEPS:
        J = robot.task_jacobian(q)[:n]
        try:
            dq = np.linalg.solve(J, e)
        except np.linalg.LinAlgError:  # exactly singular: the least-squares step
            dq = np.linalg.lstsq(J, e, rcond=None)[0]
        steps += 1
        for _ in range(HALVINGS + 1):
            q_new = q + dq
            e_new = _error(robot, q_new, task)
            r_new = float(np.abs(e_new).max())
            if r_new < r:
                break
            dq = 0.5 * dq
        else:
            break  # no step reduces the residual: as far as Newton gets
        q, e, r = q_new, e_new, r_new
    return Refined(q, r, steps, r <= POLISH_TOL)


def _limit_status(geo: ScaraGeometry, i: int) -> IKStatus:
    ra, rb, _ = geo.revolute
    if i == geo.prismatic:
        return IKStatus.J3_STROKE
    return IKStatus.J1_LIMIT if i == ra else (IKStatus.J2_LIMIT if i == rb else IKStatus.J4_LIMIT)


def _polish_one(robot: RobotModel, geo: ScaraGeometry, sol: IKSolution, task: np.ndarray
                ) -> IKSolution | tuple[IKStatus, str]:  # fmt: skip
    """The polished solution, or (status, reason) why this branch has none."""
    out = refine(robot, sol.q, task)
    label = sol.branch
    if not out.converged:
        return IKStatus.NOT_REFINED, (f"{label}: Newton on the model did not converge from the closed form's seed "
                                      f"(residual {out.residual:.3g} after {out.steps} steps)")  # fmt: skip
    q = out.q
    if not sol.singular and branch_of(geo, q) != label:
        return IKStatus.NOT_REFINED, f"{label}: the polished seed crossed to the other branch"
    turns: list[tuple[int, int] | None] = []
    for i in range(len(q)):
        lo, hi, cont = geo.lower[i], geo.upper[i], geo.continuous[i]
        v = float(q[i])
        # a revolute joint may take another turn inside its limits (a seed from the widened limits)
        fit = (v, 0, 0) if cont else (nearest_turn(v, lo, hi, v) if i != geo.prismatic
                                      else ((min(max(v, lo), hi), 0, 0) if lo - LIMIT_TOL <= v <= hi + LIMIT_TOL
                                            else None))  # fmt: skip
        if fit is None:
            unit, turn = ("m", "") if i == geo.prismatic else ("rad", " (+2 pi k)")
            return _limit_status(geo, i), (f"{label}: {geo.names[i]} = {v:.9g} {unit}{turn} outside [{lo:.9g}, "
                                           f"{hi:.9g}] {unit} once refined on the model")  # fmt: skip
        q[i] = fit[0]
        turns.append(None if cont else (fit[1], fit[2]))
    return IKSolution(q, label, sol.singular, tuple(turns))


def polish_result(robot: RobotModel, geo: ScaraGeometry, result: IKResult, task: np.ndarray) -> IKResult:
    """Every solution of a closed-form result polished on the model (see the module docstring).

    Args:
        robot: the loaded robot.
        geo: its (ideal) geometry, for the limits and the branch of a configuration.
        result: the closed form's result, solutions of ``len(task)`` joint values.
        task: the target task (x, y, z, yaw) or (x, y, z) [m, rad].

    Returns:
        IKResult: the polished solutions; the branches that failed are named in the message, and when
        none is left the status is the most telling failure (a limit before ``NOT_REFINED``).
    """
    if not result.success:
        return result
    kept: list[IKSolution] = []
    failures: list[tuple[IKStatus, str]] = []
    for sol in result.solutions:
        out = _polish_one(robot, geo, sol, task)
        if isinstance(out, IKSolution):
            kept.append(out)
        else:
            failures.append(out)
    refined = _refined(geo)
    if kept:
        note = "; ".join(f[1] for f in failures)
        message = f"{len(kept)} solution(s), {refined}" + (f"; dropped: {note}" if note else "")
        return replace(result, solutions=tuple(kept), message=message)
    worst = min(failures, key=lambda f: f[0] is IKStatus.NOT_REFINED)
    return replace(result, solutions=(), status=worst[0],
                   message=f"no solution {refined}: " + "; ".join(f[1] for f in failures))  # fmt: skip


def seed_geometry(geo: ScaraGeometry) -> ScaraGeometry:
    """The geometry the seeds come from: ``geo`` with every limit widened by SEED_MARGIN * tilt."""
    m = SEED_MARGIN * geo.tilt
    return replace(geo, lower=tuple(v - m for v in geo.lower), upper=tuple(v + m for v in geo.upper))


def _reach_seed(geo: ScaraGeometry, task: np.ndarray, status: IKStatus, margin: float = SEED_MARGIN) -> np.ndarray:
    """``task`` moved radially about the shoulder axis: its wrist ``margin`` x tilt x (l1 + l2) inside the reach."""
    alpha = float(task[3]) - geo.yaw0 if len(task) == 4 else 0.0
    wx, wy = wrist_point(geo, float(task[0]), float(task[1]), alpha)
    r = math.hypot(wx, wy)
    m = margin * geo.tilt * geo.arm.l12
    r_min, r_max = geo.radius_range()
    want = r_max - m if status is IKStatus.OUT_OF_REACH else min(r_min + m, r_max)
    out = np.array(task, dtype=float)
    if r > 0.0:
        out[0] += wx * (want / r - 1.0)
        out[1] += wy * (want / r - 1.0)
    else:
        out[0] += want
    return out


def _refined(geo: ScaraGeometry) -> str:
    return f"refined on the model (axes up to {geo.tilt:.3g} rad from vertical)"


def solve_refined(robot: RobotModel, geo: ScaraGeometry, seeds: Callable[[np.ndarray], IKResult], task: np.ndarray
                  ) -> IKResult:  # fmt: skip
    """The closed form's seeds, polished on the model (see the module docstring).

    Args:
        robot: the loaded robot.
        geo: its ideal geometry (the true limits).
        seeds: the closed form on :func:`seed_geometry` for a task (every branch, turns nearest the reference).
        task: the target (x, y, z, yaw), or (x, y, z) for a 3-joint arm [m, rad].

    Returns:
        IKResult: as :func:`polish_result`. A target the ideal arm cannot reach is tried from seeds moved
        inside the reach; if the model does not reach it either, the closed form's reason is kept.
    """
    res = seeds(task)
    if res.status in (IKStatus.OUT_OF_REACH, IKStatus.INSIDE_INNER_LIMIT):
        # just inside the reach first (the seeds stay near the target's joints: a joint near its limit keeps
        # its seed), then well inside (where the model's reach departs more); each branch from the first
        # move that gives it
        found: dict[str, IKSolution] = {}
        alt = res
        for margin in (1.0, SEED_MARGIN):
            moved = seeds(_reach_seed(geo, task, IKStatus(res.status), margin))
            out = polish_result(robot, geo, replace(moved, target=res.target), task)
            for sol in out.solutions:
                found.setdefault(sol.branch, sol)
            if out.success and not alt.success:
                alt = out
            if len(found) == len(BRANCHES):  # every branch already: no second move
                break
        if not found:
            return alt if alt.success else res
        sols = tuple(found[b] for b in BRANCHES if b in found)
        if len(sols) == len(alt.solutions):
            return replace(alt, solutions=sols)
        return replace(alt, solutions=sols, message=f"{len(sols)} solution(s), {_refined(geo)} from seeds moved "
                       "inside the ideal arm's reach")  # fmt: skip
    return polish_result(robot, geo, res, task)


def polish_batch(
    robot: RobotModel,
    geo: ScaraGeometry,
    tasks: np.ndarray,
    batch: BatchIKResult,
    solve_row: Callable[[int], tuple[np.ndarray | None, int, int]],
) -> BatchIKResult:
    """A closed-form batch polished row by row (in place; returned for convenience).

    Each solved row is polished from its own seed; a row whose seed fails, or that the ideal closed form
    does not solve (the model may, near a limit or the reach), is solved again by ``solve_row(i)`` (the
    refined single-target route: both branches, the nearest kept), which returns (q or None, status code,
    branch sign).
    """
    for i in range(len(batch.status)):
        if batch.status[i] == 0:
            seed = IKSolution(batch.q[i].copy(), "right" if batch.branch[i] > 0 else "left", False, ())
            out = _polish_one(robot, geo, seed, tasks[i])
            if isinstance(out, IKSolution):
                batch.q[i] = out.q
                continue
        q, status, sign = solve_row(i)
        batch.q[i] = np.nan if q is None else q
        batch.status[i], batch.branch[i] = status, sign
    return batch


@dataclass(frozen=True)
class UnrefinedError:
    """How far the closed form alone (ideal vertical axes, no refinement) misses on the model as written.

    Attributes:
        position: the largest tool position error over the samples' solutions [m].
        yaw: the largest tool yaw error [rad] (0 for a 3-joint arm, whose task has no yaw).
        samples: configurations sampled (uniformly inside the limits; [-pi, pi] for a continuous joint).
        seed: the sampling seed.
    """

    position: float
    yaw: float
    samples: int
    seed: int


def unrefined_error(robot: RobotModel, samples: int = 200, seed: int = 0) -> UnrefinedError:
    """The error the closed form would make on this model without refinement (what ``check`` reports).

    For each sampled q: the tool task f(q) on the model, every solution of the closed form alone (the
    robot's kinematics class built from its geometry without the robot), and the FK error of each.
    """
    kin = robot.kinematics
    raw = type(kin)(kin.geometry)  # type: ignore[call-arg]  # no robot: the closed form alone
    rng = np.random.default_rng(seed)
    lo, hi = np.array(robot.limits.lower, dtype=float), np.array(robot.limits.upper, dtype=float)
    n = robot.dof
    pos = yaw = 0.0
    for q in rng.uniform(lo, hi, size=(samples, n)):
        task = robot.tool_pose(q)[:n]
        res = raw.solve(task)
        for sol in res.solutions:
            e = task - robot.tool_pose(sol.q)[:n]
            pos = max(pos, float(np.linalg.norm(e[:3])))
            if n == 4:
                yaw = max(yaw, abs(math.remainder(float(e[3]), TWO_PI)))
    return UnrefinedError(pos, yaw, samples, seed)


def row_solver(kin: Any, T: np.ndarray, reference: ArrayLike | None, branch: str) -> Any:
    """solve_row(i) for :func:`~scara_pin.kinematics.polish.polish_batch`: row i by ``kin.solve``, nearest kept."""
    ref = None if reference is None else np.asarray(reference, dtype=float)

    def solve_row(i: int) -> tuple[np.ndarray | None, int, int]:
        row_ref = np.zeros(kin.dof) if ref is None else (ref if ref.ndim == 1 else ref[i])
        res = kin.solve(T[i], branch="all" if branch == "nearest" else branch, reference=row_ref)
        best = res.nearest(row_ref) if res.success else None
        if best is None:
            return None, int(res.status) if not res.success else int(IKStatus.NOT_REFINED), 0
        return best.q, 0, 1 if best.branch == "right" else -1

    return solve_row
