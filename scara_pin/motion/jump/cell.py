"""The jump in a cell: each warm start solved with its distance rows until they settle (:mod:`.rows`)."""

from __future__ import annotations

import logging
import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ...cell import describe
from ...cell.sweep import clear_mask
from ...errors import InfeasibleError
from ..polynomial import PolynomialPiece
from ..trajectory import Trajectory, line_optimal_duration
from ..verify import CERTIFY_ACCELERATION, DISTANCE_TOL, verify
from .candidates import SECOND_WITHIN, Candidate, candidates, line_samples, score
from .nlp import Transcription
from .problem import ConstraintPoint, Problem
from .refine import failure, rebuild, solve, violations, warm_start
from .rows import BUFFER, CONVERGED, CONVERGED_TIME, DEEP, NEAR_MISS, RETRY_BUFFER, DistanceRow, Rows
from .search import Search, Way, search
from .types import JumpError, JumpOptions, SolverStats
from .verification import Check, verify_move

if TYPE_CHECKING:
    from ...cell import PairDistance, Scene

log = logging.getLogger(__name__)

def closest(scene: Scene, Q: np.ndarray) -> tuple[int, PairDistance | None]:
    """(the row of ``Q`` where a checked pair comes closest, that pair with its witness points)."""
    i = int(np.argmin(scene.minimum_array(Q)))
    return i, scene.distances(Q[i]).closest


def blocking(scene: Scene, piece: PolynomialPiece) -> str:
    """Which pair comes closest in ``piece`` and where, in words (for a failure message)."""
    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    k = np.repeat(np.arange(n), 4)
    s = np.tile(np.arange(4) / 4.0, n)
    q = piece.local(k, s * h[k], 0)
    i, found = closest(scene, q)
    if found is None:  # pragma: no cover - a scene without pairs plans no rows
        return "no pair"
    return describe(found, scene.margin) + f" at t = {piece.breaks[k[i]] + s[i] * h[k[i]]:.4g} s"


def where_blocked(scene: Scene, cand: Candidate, velocity: np.ndarray, acceleration: np.ndarray) -> str:
    """What blocks a warm start's joint lines most, where and when (the lines timed from rest to rest), in words."""
    Q = line_samples(cand.waypoints)
    i, found = closest(scene, Q)
    if found is None:  # pragma: no cover - a scene without pairs blocks nothing
        return f"{cand.way}: clear"
    per_line = len(Q) // (len(cand.waypoints) - 1)
    line, frac = divmod(i, per_line)
    durations = [line_optimal_duration(a, b, velocity, acceleration) for a, b in zip(cand.waypoints[:-1],
                                                                                      cand.waypoints[1:])]  # fmt: skip
    when = float(sum(durations[:line]) + durations[line] * frac / max(per_line - 1, 1))
    return f"{cand.way}: {describe(found, scene.margin)} at t = {when:.3g} s of its joint lines"


def blocked(scene: Scene, tried: list[Candidate], status: str, found: Search | None, velocity: np.ndarray,
            acceleration: np.ndarray) -> InfeasibleError:  # fmt: skip
    """The error of a jump for which no way clears the cell (exit 3).

    The search's verdict, each way tried and what blocks it first, where and when.
    """
    parts = [where_blocked(scene, c, velocity, acceleration) for c in tried]
    if found is not None and not found.ways:
        verdict = (f"no way through the cell on a lattice of {math.degrees(found.steps[0]):g} deg and "
                   f"{found.steps[1] * 1e3:g} mm steps ({found.valid:,} of {found.nodes:,} configurations at the "
                   f"traverse height clear; {found.why}): a passage narrower than a step is not searched (via points "
                   "give one by hand)")  # fmt: skip
    else:
        verdict = "the local solves from every way found failed"
    return JumpError(status, f"no collision-free motion found within the limits: {verdict}; " + "; ".join(parts))


def infeasible(scene: Scene, piece: PolynomialPiece, status: str) -> InfeasibleError:
    """The error of a jump that found no motion clear of the cell (exit 3), naming the pair that blocks."""
    return JumpError(status, f"no collision-free motion found within the limits: {blocking(scene, piece)}")


class _SameWay(Exception):
    """A solve in progress reached the way of a motion solved already (it would end in that motion again)."""


def solve_avoiding(prob: Problem, options: JumpOptions, waypoints: np.ndarray, *, buffer: float = BUFFER,
                   seed: tuple[DistanceRow, ...] = (), free: PolynomialPiece | None = None,
                   known: tuple[np.ndarray, ...] = ()) -> tuple[PolynomialPiece, np.ndarray, SolverStats]:  # fmt: skip
    """The jump's solve (the jump's own solve) with the distance rows (module docstring).

    From the warm start ``waypoints``: solve; check densely; add rows; re-set every row's plane; solve again,
    warm-started, until nothing is added, the dense check holds and the duration has settled. A re-solve the
    solver finds infeasible (the planes taken from the last solution conflict) is retried once from the
    last motion that was clear of the cell, with every plane taken there: that motion satisfies them all.
    ``buffer``: the rows keep margin + buffer; ``seed``: rows there from the start (a near miss solved again);
    ``free``: the motion without the cell, whose collisions are rows from the start (a first solve without them
    only finds that motion again); ``known``: motions solved already (``_LADDER`` samples each): a clear solution on
    the way of one of them ends this solve (``_SameWay``), the local solve would find that motion again.

    Returns:
        (piece, phase durations, solver statistics) as ``solve``.

    Raises:
        JumpError: the solver failed, or no motion clear of the cell was found (naming the closest pair).
    """
    scene = prob.scene
    if scene is None:  # pragma: no cover - solve_in_cell gives a problem in its cell
        raise ValueError("solve_avoiding takes a problem in a cell")
    points: tuple[ConstraintPoint, ...] = ()
    warm = warm_start(prob, waypoints)
    rows = Rows(scene, prob.sym, buffer)
    if free is not None:
        rows.add(rows.check(free)[0])
    piece = rebuild(prob, warm[0], warm[2])
    fresh, worst = rows.check(piece)
    rows.add(list(seed) + fresh)
    params = rows.parameters(piece)
    tr = Transcription(prob, points, options, rows.rows, rows)
    x0 = tr.pack(*warm)
    clear = (piece, x0) if worst >= -CONVERGED else None  # the last motion found clear of the cell
    retried = False
    iterations = solves = 0
    duration = math.inf
    last_clear: tuple[PolynomialPiece, np.ndarray, np.ndarray] | None = None  # a solved motion clear of the cell
    near: tuple[PolynomialPiece, np.ndarray] | None = None  # a solved motion within NEAR_MISS of the margin
    while True:
        sol = tr.solve(x0, None, None, params)
        iterations += sol["iterations"]
        solves += 1
        log.debug("jump in a cell: solve %d: %s after %d iterations, %d rows", solves, sol["status"],
                  sol["iterations"], len(rows.rows))  # fmt: skip
        T, _, U = tr.unpack(sol["x"])
        if not sol["success"]:
            if clear is not None and not retried:  # every plane from the last clear motion, which meets them all
                retried = True
                params = rows.parameters(clear[0], rebase=True)
                x0 = clear[1][: tr.n_x]
                continue
            if last_clear is not None or near is not None:  # the planes stopped moving it: the last solved clear
                log.debug("jump in a cell: re-solve %s; keeping the last clear (or nearly clear) solution",
                          sol["status"])  # fmt: skip
                piece, T = (last_clear[0], last_clear[2]) if last_clear is not None else near  # type: ignore[misc]
                break
            if sol["status"] in ("Infeasible_Problem_Detected", "Restoration_Failed", "Maximum_Iterations_Exceeded"):
                raise infeasible(scene, rebuild(prob, T, U) if clear is None else clear[0], sol["status"])
            raise JumpError(sol["status"], failure(sol["status"], options))
        piece = rebuild(prob, T, U)
        new = [p for p in violations(prob, piece, T) if p not in points]
        fresh, worst = rows.check(piece)
        added = rows.add(fresh)
        log.debug("jump in a cell: %.6f s, worst %.3g mm beyond the margin, %d rows added, %d limit points",
                  piece.duration, worst * 1e3, len(fresh), len(new))  # fmt: skip
        if known and worst >= 0.0:
            ladder = piece.evaluate(np.linspace(0.0, piece.duration, _LADDER))[0]
            if any(_same_way(scene, ladder, path, prob.velocity) for path in known):
                raise _SameWay
        params = rows.parameters(piece, None if clear is None else clear[0])
        if worst >= -CONVERGED:
            clear = (piece, sol["x"])
            if not new:
                last_clear = (piece, sol["x"], T)
            retried = False
        if worst >= -NEAR_MISS and not new:
            near = (piece, T)
        settled = worst >= -CONVERGED and abs(piece.duration - duration) <= CONVERGED_TIME * piece.duration
        duration = piece.duration
        if not new and not added and settled:
            # converged: what the certificate of each near pair finds between the checked points
            finer = rows.fine(piece, CERTIFY_ACCELERATION * prob.acceleration)
            if not finer:
                break
            rows.add(finer)
            added = True
            params = rows.parameters(piece, None if clear is None else clear[0])
        if solves > options.refinements + options.avoid_iterations:
            if last_clear is not None or near is not None:
                piece, T = (last_clear[0], last_clear[2]) if last_clear is not None else near  # type: ignore[misc]
                break
            raise infeasible(scene, piece, "Not_Converged")
        # from a motion deep in an obstacle the re-solve struggles: start again from the last clear one
        x0 = clear[1][: tr.n_x] if worst < -DEEP and clear is not None else sol["x"]
        if new or added:
            points = points + tuple(new)
            tr = Transcription(prob, points, options, rows.rows, rows, resolve=True)
    stats = SolverStats(sol["status"], iterations, solves, prob.N, tr.n_x, tr.n_g, 0.0)
    log.debug("jump in a cell: %s", stats)
    return piece, T, stats


def solve_in_cell(prob: Problem, options: JumpOptions, scene: Scene, ceiling: float | None,
                  hints: tuple[np.ndarray, ...] = ()) -> tuple[PolynomialPiece, np.ndarray, SolverStats, Trajectory,
                                                               Check]:  # fmt: skip
    """The jump in the cell (module docstring of :mod:`scara_pin.motion.jump`, "In a cell").

    The direct warm start when its joint lines clear the cell; else the ways of the global search
    (:mod:`.search`) with the local ones (over, around: :mod:`.candidates`) and the user's via points
    (``hints``, joint configurations between above A and above B): the fastest few solved, each verified, the
    fastest verified kept. A motion a few micrometres under the margin is solved again with a larger buffer
    (:data:`.rows.RETRY_BUFFER`) from a row where it failed.
    """
    vel, acc = prob.velocity, prob.acceleration
    # the fastest motion without the cell bounds every motion in it from below; when it is clear, it is the answer
    piece, T, stats = solve(replace(prob, scene=None), options)
    free, free_piece = piece.duration, piece
    if not hints and float(scene.minimum_array(piece.evaluate(np.linspace(0.0, free, _FREE_CHECK))[0]).min()) \
            >= scene.margin:  # fmt: skip
        traj = Trajectory((piece,))
        try:
            return piece, T, stats, traj, verify_move(prob, traj)
        except JumpError:
            log.debug("jump in a cell: the motion without the cell is not certified clear in it")
    found = candidates(scene, prob.qA, prob.qB, prob.q_tops, prob.A, prob.B, prob.z_top, ceiling, vel, acc)
    hinted = [_hinted(scene, prob, np.array(hints))] if hints else []
    verdict: Search | None = None
    if found[0].way == "straight" and found[0].clearance >= 0.0 and not hinted:
        tries = found[:1]
    else:
        verdict = search(scene, prob.q_tops[0], prob.q_tops[1], prob.z_top, ceiling, vel)
        ways = [_way(scene, prob, w, i) for i, w in enumerate(verdict.ways)]
        tries = hinted + sorted([c for c in found if c.clearance >= 0.0] + ways, key=lambda c: c.duration)
        if not tries:
            raise blocked(scene, [c for c in found if c.way == "straight"] or found[:1], "No_Way", verdict, vel, acc)
    best = None
    error: Exception | None = None
    iterations = failures = 0
    solved: list[np.ndarray] = []
    for cand in tries:
        if best is not None and (len(solved) >= SOLVED_WAYS or cand.duration > SECOND_WITHIN * tries[0].duration
                                 or best[3].duration <= free * (1.0 + CONVERGED_TIME)):  # fmt: skip
            break
        if failures >= FAILED_WAYS:
            break
        if any(_same_way(scene, cand.waypoints, path, prob.velocity) for path in solved):
            log.debug("jump in a cell: warm start %s goes the way of one solved already", cand.way)
            continue
        log.debug("jump in a cell: warm start %s (%.4g s, clearance %.3g m)", cand.way, cand.duration,
                  cand.clearance)  # fmt: skip
        try:
            piece, T, stats, traj, check = _solved(prob, options, cand.waypoints, free_piece, tuple(solved))
        except _SameWay:
            log.debug("jump in a cell: warm start %s reached the way of one solved already", cand.way)
            continue
        except JumpError as exc:
            error = exc
            failures += 1
            continue
        iterations += stats.iterations
        solved.append(piece.evaluate(np.linspace(0.0, piece.duration, _LADDER))[0])
        if best is None or traj.duration < best[3].duration:
            best = (piece, T, stats, traj, check)
    if best is None:
        if isinstance(error, JumpError) and error.status == "VerificationFailed":
            raise error
        raise blocked(scene, tries[:failures] or tries[:1], error.status if isinstance(error, JumpError)
                      else "Not_Solved", verdict, vel, acc) from None  # fmt: skip
    return best[0], best[1], replace(best[2], iterations=iterations), best[3], best[4]


def _solved(prob: Problem, options: JumpOptions, waypoints: np.ndarray, free: PolynomialPiece | None = None,
            known: tuple[np.ndarray, ...] = ()) -> tuple[PolynomialPiece, np.ndarray, SolverStats, Trajectory,
                                                         Check]:  # fmt: skip
    """One warm start solved and verified (``free``, ``known``: :func:`solve_avoiding`'s).

    A near miss (its certificate fails by micrometres) is solved again with a larger buffer and a row where it failed.
    """
    buffer = BUFFER
    seed: tuple[DistanceRow, ...] = ()
    for attempt in range(2):
        piece, T, stats = solve_avoiding(prob, options, waypoints, buffer=buffer, seed=seed, free=free, known=known)
        traj = Trajectory((piece,))
        try:
            return piece, T, stats, traj, verify_move(prob, traj)
        except JumpError as exc:
            miss = _missed(prob, traj)
            if attempt or miss is None:
                raise exc from None
            log.debug("jump in a cell: a near miss (%s); solved again with a larger buffer", exc.reason)
            buffer, seed = buffer * RETRY_BUFFER, (miss,)
    raise AssertionError("unreachable")  # pragma: no cover


def _missed(prob: Problem, traj: Trajectory) -> DistanceRow | None:
    """Where a verified motion came closer than the margin, as a row of the transcription (None: it failed otherwise).

    Its lowest sample, or its certificate's weakest point.
    """
    scene = prob.scene
    if scene is None:  # pragma: no cover - in a cell only
        return None
    c = verify(prob.base, traj, limits=prob.limits, scene=scene).clearance
    if c is None or c.certified is None or c.bound >= c.margin - DISTANCE_TOL:
        return None
    t, pair = (c.certified.lowest[0], c.certified.lowest[1]) if c.distance >= c.certified.lowest[2] \
        else (c.time, int(np.flatnonzero(np.array(c.labels) == c.pair)[0]))  # fmt: skip
    piece = traj.pieces[0]
    if not isinstance(piece, PolynomialPiece):  # pragma: no cover - jump pieces
        return None
    k = int(np.clip(np.searchsorted(piece.breaks, t, side="right") - 1, 0, len(piece.breaks) - 2))
    h = piece.breaks[k + 1] - piece.breaks[k]
    return DistanceRow(k, float(np.clip((t - piece.breaks[k]) / h, 0.0, 1.0)), pair)


_FREE_CHECK = 400
"""Samples at which the motion without the cell is first checked against it (then verified, certified)."""
SOLVED_WAYS = 2
"""Ways (distinct: ``_same_way``) solved to the end before the fastest is kept."""
FAILED_WAYS = 4
"""Warm starts whose local solve may fail before the jump is given up."""
_LADDER = 24
"""Rungs of the ladder between a warm start and a motion solved already (``_same_way``)."""


def _same_way(scene: Scene, waypoints: np.ndarray, path: np.ndarray, velocity: np.ndarray) -> bool:
    """Whether a warm start goes the way of a solved motion (the local solve would find the same motion again).

    The ladder between them (corresponding points at the same fraction of their joint-space length joined by straight
    joint lines) is clear of the cell: one deforms into the other through free space. Clear here is half the margin:
    the ladder's ends are joint lines between samples of the motions, whose chords cut the corners a motion turns at
    the margin (by 15 um for a post's jump), and a way is a way round or over the obstacles, not the margin's width.
    """
    a, b = _resampled(waypoints, velocity), _resampled(path, velocity)
    s = np.linspace(0.0, 1.0, 12)[None, :, None]
    rungs = (a[:, None, :] + s * (b - a)[:, None, :]).reshape(-1, a.shape[1])
    return bool(clear_mask(scene, rungs, margin=0.5 * scene.margin).all())


def _resampled(points: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """:data:`_LADDER` points along a joint polyline, evenly spaced in its length (each joint over its velocity)."""
    run = np.concatenate([[0.0], np.cumsum(np.sum(np.abs(np.diff(points, axis=0)) / velocity, axis=1))])
    u = np.linspace(0.0, run[-1], _LADDER)
    return np.column_stack([np.interp(u, run, points[:, j]) for j in range(points.shape[1])])


def _way(scene: Scene, prob: Problem, way: Way, i: int) -> Candidate:
    """A way of the search as a warm start (its joint lines from A and to B added)."""
    waypoints = np.vstack([prob.qA, way.waypoints, prob.qB])
    t, clear = score(scene, waypoints, prob.velocity, prob.acceleration)
    return Candidate(f"search {i + 1}", waypoints, t, clear)


def _hinted(scene: Scene, prob: Problem, vias: np.ndarray) -> Candidate:
    """The user's via configurations, in order, as a warm start."""
    waypoints = np.vstack([prob.qA, prob.q_tops[0], vias, prob.q_tops[1], prob.qB])
    t, clear = score(scene, waypoints, prob.velocity, prob.acceleration)
    return Candidate("via", waypoints, t, clear)
