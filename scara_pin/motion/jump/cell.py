"""The jump in a cell: each warm start solved with its distance rows until they settle (:mod:`.rows`)."""

from __future__ import annotations

import logging
import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ...errors import InfeasibleError
from ..polynomial import PolynomialPiece
from ..trajectory import Trajectory
from .candidates import MAX_OFFSET, SECOND_WITHIN, Candidate, candidates, line_samples
from .nlp import Transcription
from .problem import ConstraintPoint, Problem
from .refine import failure, rebuild, violations, warm_start
from .rows import CONVERGED, CONVERGED_TIME, DEEP, RESOLVE_ITERATIONS, Rows
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
    from ...cell import describe

    n = len(piece.breaks) - 1
    h = np.diff(piece.breaks)
    k = np.repeat(np.arange(n), 4)
    s = np.tile(np.arange(4) / 4.0, n)
    q = piece.local(k, s * h[k], 0)
    i, found = closest(scene, q)
    if found is None:  # pragma: no cover - a scene without pairs plans no rows
        return "no pair"
    return describe(found, scene.margin) + f" at t = {piece.breaks[k[i]] + s[i] * h[k[i]]:.4g} s"


def blocked(scene: Scene, tried: list[Candidate], status: str) -> InfeasibleError:
    """The error of a jump for which no way around or over clears the cell (exit 3): each way and what blocks it."""
    from ...cell import describe

    parts = []
    for c in tried:
        _, found = closest(scene, line_samples(c.waypoints))
        if found is not None:
            parts.append(f"{c.way}: {describe(found, scene.margin)}")
    return JumpError(status, "no collision-free motion found within the limits: " + "; ".join(parts)
                     + f"; neither the traverse raised up to the stroke's top nor via points up to {MAX_OFFSET:g} m "
                     "to either side clear it, and the solver found no way from there")  # fmt: skip


def infeasible(scene: Scene, piece: PolynomialPiece, status: str) -> InfeasibleError:
    """The error of a jump that found no motion clear of the cell (exit 3), naming the pair that blocks."""
    return JumpError(status, f"no collision-free motion found within the limits: {blocking(scene, piece)}")


def solve_avoiding(prob: Problem, options: JumpOptions,
                   waypoints: np.ndarray) -> tuple[PolynomialPiece, np.ndarray, SolverStats]:  # fmt: skip
    """The jump's solve (the jump's own solve) with the distance rows (module docstring).

    From the warm start ``waypoints``: solve; check densely; add rows; re-set every row's plane; solve again,
    warm-started, until nothing is added, the dense check holds and the duration has settled. A re-solve the
    solver finds infeasible (the planes taken from the last solution conflict) is retried once from the
    last motion that was clear of the cell, with every plane taken there: that motion satisfies them all.

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
    rows = Rows(scene, prob.sym)
    piece = rebuild(prob, warm[0], warm[2])
    fresh, worst = rows.check(piece)
    rows.add(fresh)
    params = rows.parameters(piece)
    tr = Transcription(prob, points, options, rows.rows, rows)
    x0 = tr.pack(*warm)
    clear = (piece, x0) if worst >= -CONVERGED else None  # the last motion found clear of the cell
    retried = False
    iterations = solves = 0
    duration = math.inf
    last_clear: tuple[PolynomialPiece, np.ndarray, np.ndarray] | None = None  # a solved motion clear of the cell
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
            if last_clear is not None:  # the planes stopped moving it: the last solved clear motion stands
                log.debug("jump in a cell: re-solve %s; keeping the last clear solution", sol["status"])
                piece, T = last_clear[0], last_clear[2]
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
        params = rows.parameters(piece, None if clear is None else clear[0])
        if worst >= -CONVERGED:
            clear = (piece, sol["x"])
            if not new:
                last_clear = (piece, sol["x"], T)
            retried = False
        settled = worst >= -CONVERGED and abs(piece.duration - duration) <= CONVERGED_TIME * piece.duration
        duration = piece.duration
        if not new and not added and settled:
            finer = rows.fine(piece)  # converged: what the verifier's grid would see between the checked points
            if not finer:
                break
            rows.add(finer)
            added = True
            params = rows.parameters(piece, None if clear is None else clear[0])
        if solves > options.refinements + options.avoid_iterations:
            if last_clear is not None:
                piece, T = last_clear[0], last_clear[2]
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


def solve_in_cell(prob: Problem, options: JumpOptions, scene: Scene, ceiling: float | None
                   ) -> tuple[PolynomialPiece, np.ndarray, SolverStats, Trajectory, Check]:  # fmt: skip
    """The best warm starts around or over the obstacles, each solved and verified; the fastest wins."""
    found = candidates(scene, prob.qA, prob.qB, prob.q_tops, prob.A, prob.B, prob.z_top, ceiling, prob.velocity,
                       prob.acceleration)  # fmt: skip
    if found[0].clearance < 0.0:  # no way tried clears: one attempt from the least colliding, on a short budget
        short = replace(options, max_iterations=min(options.max_iterations, RESOLVE_ITERATIONS))
        try:
            piece, T, stats = solve_avoiding(prob, short, found[0].waypoints)
            traj = Trajectory((piece,))
            return piece, T, stats, traj, verify_move(prob, traj)
        except JumpError as exc:
            raise blocked(scene, found, exc.status) from None
    way = found[0].way.split(",")[0]  # over, left or right
    tries = found[:1] + [c for c in found[1:] if c.way.split(",")[0] != way and c.duration <= SECOND_WITHIN
                         * found[0].duration][:1]  # fmt: skip
    best = None
    error: Exception | None = None
    iterations = 0
    for cand in tries:
        log.debug("jump in a cell: warm start %s (%.4g s, clearance %.3g m)", cand.way, cand.duration,
                     cand.clearance)  # fmt: skip
        try:
            piece, T, stats = solve_avoiding(prob, options, cand.waypoints)
            traj = Trajectory((piece,))
            check = verify_move(prob, traj)
        except JumpError as exc:
            error = exc
            continue
        iterations += stats.iterations
        if best is None or traj.duration < best[3].duration:
            best = (piece, T, stats, traj, check)
    if best is None:
        raise error if error is not None else JumpError("Not_Solved", "no warm start")
    return best[0], best[1], replace(best[2], iterations=iterations), best[3], best[4]
