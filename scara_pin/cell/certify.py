"""A motion certified clear of its cell between its samples, not only at them (conservative advancement).

A verifier that checks a motion at 10 kHz sees the distances at its samples; between two samples a thin part
can cross a thin obstacle unseen (a 1 um foil crossed at 1 m/s in 0.1 ms). Here every interval between two
samples gets a LOWER BOUND of every checked pair's distance over the whole interval, from the distances at
its two ends and a bound on how fast they can change.

**Rate of a distance.** Every point of a geometry moves at most at ``lin + rot (rho + e)``
(:func:`~scara_pin.cell.sweep.geometry_speeds`: its bounding sphere's centre speed per joint and its angular
speed, times a bound m of each joint's |qd| over the interval), e the sphere centre's drift during the
interval; a pair's distance changes at most at the sum of its two shapes' bounds (an obstacle does not move).
On an interval [t0, t0 + h] with m_i = max(|qd_i(t0)|, |qd_i(t0 + h)|) + a_i h (a_i a bound of |qdd_i|
between samples) and e <= V h, the bound is

    V <= min over the two ends of (lin + rot rho) / (1 - rot h),

and a distance d(t) with values d0 and d1 at the ends is at least ``min(d0, d1, (d0 + d1 - V h) / 2)`` on
the interval (the two cones from its ends meet there). The smallest over all pairs has the rate of the fastest
pair, so the samples' nearest distances (what the verifier computes anyway) bound the whole motion at once.

**Refinement.** An interval whose bound is below the floor asked for (the margin less the verifier's
tolerance) is taken pair by pair: each pair whose own bound fails is sampled inside the interval, as densely
as its rate and its gaps need (the same V holds on every part of the interval), and each part still failing is
split again. It ends with every part certified, or a sample below the floor (the motion does come that
close between the verifier's samples: a violation, with its time and pair), or the evaluation budget spent
(not certified: refused, never assumed).

What is certified: every checked pair's coal distance stays at least :attr:`Certificate.bound` over the whole
motion, given that each joint's acceleration stays within ``acceleration`` between samples (the verifier
passes twice the joints' limits, which its own samples hold to 1 + 1e-6: a planned trajectory cannot double
its acceleration within one 0.1 ms period without a jerk of 10^4 times its acceleration limit per second).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .scene import Scene
from .sweep import bounding_shapes, geometry_speeds

__all__ = ["BUDGET", "Certificate", "certify"]

BUDGET = 400_000
"""Distance evaluations (one pair at one configuration) a certificate may spend refining before it gives up."""
_MIN_PART = 1e-12
"""[s] the shortest part of an interval refined (below: the time's rounding)."""
_SPLIT = 256
"""The most parts an interval is split into at once (each part still failing is split again)."""


@dataclass(frozen=True)
class Certificate:
    """What :func:`certify` proved of a motion.

    Attributes:
        bound: [m] every checked pair's distance is at least this over the whole motion (-inf: not certified).
        time: [s] where the bound is reached (the start of the weakest part).
        pair: the pair there (its index in the scene), or -1 when no pair is checked.
        lowest: (time [s], pair, distance [m]) of the smallest distance evaluated, the verifier's samples and the
            refinement's (a violation when below the floor).
        certified: the bound reached the floor asked for.
        evaluations: distance evaluations spent refining.
    """

    bound: float
    time: float
    pair: int
    lowest: tuple[float, int, float]
    certified: bool
    evaluations: int


def certify(scene: Scene, sample: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], t: np.ndarray,
            d: np.ndarray, which: np.ndarray, acceleration: np.ndarray, floor: float,
            pairs: list[int] | None = None) -> Certificate:  # fmt: skip
    """A lower bound of every checked pair's distance over a motion (module docstring).

    Args:
        scene: the robot in its cell.
        sample: ``(q, qd) = sample(times)``: the motion's configurations and joint velocities, each (n, dof).
        t: (n,) sorted sample times covering the motion.
        d: (n,) the smallest distance over the checked pairs at each (:meth:`~scara_pin.cell.Scene.nearest_array`).
        which: (n,) that pair.
        acceleration: (dof,) a bound of each joint's |qdd| between samples.
        floor: [m] the distance to certify; a part is refined until its bound reaches it.
        pairs: the pairs certified (their indices; default: every checked pair); ``d`` and ``which`` are then the
            smallest over these.
    """
    t, d, which = np.asarray(t, dtype=float), np.asarray(d, dtype=float), np.asarray(which, dtype=int)
    lowest_i = int(np.argmin(d))
    lowest = (float(t[lowest_i]), int(which[lowest_i]), float(d[lowest_i]))
    if not scene.pairs or len(t) < 2:
        return Certificate(float(d.min(initial=math.inf)), lowest[0], lowest[1], lowest, True, 0)
    idx = np.arange(len(scene.pairs)) if pairs is None else np.asarray(pairs, dtype=int)
    q, qd = sample(t)
    h = np.diff(t)
    speeds = np.maximum(np.abs(qd[:-1]), np.abs(qd[1:])) + np.abs(acceleration)[None, :] * h[:, None]
    V = _pair_rates(scene, q, speeds, h)[:, idx]  # (intervals, pairs certified)
    lb = _cones(d[:-1], d[1:], V.max(axis=1), h)
    bound = lb.copy()
    where = np.where(d[:-1] <= d[1:], which[:-1], which[1:])
    spent = 0
    for k in np.flatnonzero(lb < floor).tolist():
        ends = scene.distance_array(q[k : k + 2], None if pairs is None else idx)  # each pair at both ends
        own = _cones(ends[0], ends[1], V[k], np.full(len(V[k]), h[k]))
        for c in np.flatnonzero(own < floor).tolist():
            p = int(idx[c])
            if spent >= BUDGET:  # not certified: never assumed
                own[c] = -math.inf
                continue
            own[c], found, used = _refine(scene, sample, p, float(t[k]), float(t[k + 1]), float(ends[0, c]),
                                          float(ends[1, c]), float(V[k, c]), floor, BUDGET - spent)  # fmt: skip
            spent += used
            if found[1] < lowest[2]:
                lowest = (found[0], p, found[1])
        bound[k], where[k] = float(own.min()), int(idx[int(np.argmin(own))])
    k = int(np.argmin(bound))
    b = float(bound[k])
    return Certificate(b, float(t[k]), int(where[k]), lowest, b >= floor, spent)


def _pair_rates(scene: Scene, q: np.ndarray, speeds: np.ndarray, h: np.ndarray) -> np.ndarray:
    """(intervals, pairs): how fast each pair's distance can change on each interval (module docstring)."""
    b = bounding_shapes(scene)
    rates = []
    for ends in (q[:-1], q[1:]):
        lin, rot = geometry_speeds(scene, ends, speeds)
        rates.append((lin, rot))
    rot = np.maximum(rates[0][1], rates[1][1])
    lin = np.minimum(rates[0][0], rates[1][0])
    grow = 1.0 - rot * h[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        geo = np.where(grow > 0.0, (lin + rot * b.radius[None, :]) / grow, np.inf)
    first = np.array([p.first for p in scene.pairs])
    second = np.array([p.second for p in scene.pairs])
    return geo[:, first] + geo[:, second]  # type: ignore[no-any-return]


def _cones(d0: np.ndarray, d1: np.ndarray, rate: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The least a distance can be on an interval of length h, from its ends and the bound of its rate."""
    with np.errstate(invalid="ignore"):
        meet = np.where(np.isfinite(rate), 0.5 * (d0 + d1 - rate * h), -np.inf)
    return np.minimum(np.minimum(d0, d1), meet)  # type: ignore[no-any-return]


def _refine(scene: Scene, sample: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], pair: int, a: float,
            b: float, da: float, db: float, rate: float, floor: float,
            budget: int) -> tuple[float, tuple[float, float], int]:  # fmt: skip
    """(the pair's bound on [a, b], (time, distance) of its smallest sample, evaluations) by splitting the interval.

    Each part still failing is split again; a sample below ``floor`` ends the search there (found: a violation).
    """
    spent = 0
    low = (a, da) if da <= db else (b, db)
    stack = [(a, b, da, db)]
    bound = math.inf
    while stack:
        a0, b0, d0, d1 = stack.pop()
        part = float(_cones(np.array([d0]), np.array([d1]), np.array([rate]), np.array([b0 - a0]))[0])
        if part >= floor:
            bound = min(bound, part)
            continue
        if min(d0, d1) < floor or b0 - a0 <= _MIN_PART or spent >= budget:
            bound = min(bound, part)
            if min(d0, d1) < floor or spent >= budget:
                break
            continue
        gap = d0 + d1 - 2.0 * floor
        n = int(min(_SPLIT, max(2, math.ceil(1.05 * rate * (b0 - a0) / gap))))
        ts = np.linspace(a0, b0, n + 1)
        inner = scene.distance_array(sample(ts[1:-1])[0], [pair])[:, 0]
        spent += len(inner)
        ds = np.concatenate([[d0], inner, [d1]])
        i = int(np.argmin(inner))
        if inner[i] < low[1]:
            low = (float(ts[1 + i]), float(inner[i]))
        stack.extend((float(ts[j]), float(ts[j + 1]), float(ds[j]), float(ds[j + 1])) for j in range(n))
    return bound, low, spent
