"""Warm starts of the jump in a cell: straight, over, around (:mod:`~scara_pin.motion.jump.cell`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...cell.sweep import clear_mask
from ..trajectory import line_optimal_duration

if TYPE_CHECKING:
    from ...cell import Scene
    from ...model import RobotModel

_PATH_SAMPLES = 40
"""Samples of each joint line of a warm-start candidate checked against the cell."""


SLACK = 0.001
"""[m] a warm start counts as clear when its sampled joint lines keep the margin plus this."""


_RAISED_AROUND = 2
"""Heights above the traverse height (in steps of _STEP) at which AROUND candidates are also tried."""


_STEP = 0.005
"""[m] the step of the heights and offsets tried by the candidates."""


MAX_OFFSET = 0.4
"""[m] the largest plan-view offset of an AROUND candidate's via point."""


_MAX_RAISE = 1.0
"""[m] how far an OVER candidate raises the traverse when no prismatic joint bounds it (a palletizer's arm lifts
the tool by turning: the raise stops where the IK fails, or here)."""


SECOND_WITHIN = 1.3
"""The second candidate is solved too when its joint lines take at most this times the best's."""


@dataclass(frozen=True)
class Candidate:
    """A warm start: joint waypoints A, above A, [via], above B, B, and how it goes.

    Attributes:
        way: ``"straight"``, ``"over"``, ``"left"`` or ``"right"`` (``"left, raised"``: above the traverse height).
        waypoints: (n, dof) joint waypoints; the lift is the first segment, the descent the last.
        duration: [s] the time of its joint lines, each from rest to rest.
        clearance: [m] its smallest distance to the cell (checked along the lines).
    """

    way: str
    waypoints: np.ndarray
    duration: float
    clearance: float


def line_samples(waypoints: np.ndarray) -> np.ndarray:
    """Points along the joint lines between consecutive waypoints (_PATH_SAMPLES per line, ends included)."""
    s = np.linspace(0.0, 1.0, _PATH_SAMPLES)[:, None]
    return np.concatenate([w0 + s * (w1 - w0) for w0, w1 in zip(waypoints[:-1], waypoints[1:])])


def score(scene: Scene, waypoints: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray) -> tuple[float, float]:
    """(duration of the joint lines from rest to rest [s], their clearance [m]).

    The clearance is the smallest distance along them minus the margin and :data:`SLACK`: >= 0 when the lines
    clear the cell between their samples too.
    """
    t = sum(line_optimal_duration(a, b, velocity, acceleration) for a, b in zip(waypoints[:-1], waypoints[1:])
            if not np.array_equal(a, b))  # fmt: skip
    d = scene.minimum_array(line_samples(waypoints))
    return float(t), float(d.min(initial=math.inf)) - scene.margin - SLACK


def _clears(scene: Scene, waypoints: np.ndarray) -> bool:
    """Whether :func:`score`'s clearance of these joint lines is >= 0.

    Without the exact distance of every pair at every sample (:func:`~scara_pin.cell.sweep.clear_mask`'s filters
    first): the scans try many ways that do not clear.
    """
    return bool(clear_mask(scene, line_samples(waypoints), margin=scene.margin + SLACK).all())


def _ik(robot: RobotModel, pose: np.ndarray, near: np.ndarray) -> np.ndarray | None:
    res = robot.ik(pose)
    sol = res.nearest(near, branch=robot.branch_of(near)) if res.success else None
    return None if sol is None else np.array(sol.q, dtype=float)


def candidates(
    scene: Scene,
    qA: np.ndarray,
    qB: np.ndarray,
    tops: tuple[np.ndarray, np.ndarray],
    A: np.ndarray,
    B: np.ndarray,
    z_top: float,
    ceiling: float | None,
    velocity: np.ndarray,
    acceleration: np.ndarray,
) -> list[Candidate]:
    """Warm starts for the jump in the cell (module docstring).

    The straight one when it is clear; else the clear ones, fastest first; else (none clears) every one tried,
    the least colliding first.
    """
    robot = scene.robot
    straight = np.array([qA, tops[0], tops[1], qB])
    t, clear = score(scene, straight, velocity, acceleration)
    first = Candidate("straight", straight, t, clear)
    if clear >= 0.0:
        return [first]
    found = [first]
    # OVER: the traverse raised until the joint lines clear
    top = stroke_top(robot, tops[0])
    z_max = z_top + _MAX_RAISE if top is None else robot.tool_pose(top)[2]
    if ceiling is not None:
        z_max = min(z_max, ceiling)
    raised = {z_top: tops}  # traverse height -> the configurations above A and B there
    z = z_top + _STEP
    while z <= z_max + 1e-12:
        ta = _ik(robot, np.array([A[0], A[1], z, A[3]]), tops[0])
        tb = _ik(robot, np.array([B[0], B[1], z, B[3]]), tops[1])
        if ta is None or tb is None:
            break
        if len(raised) < 1 + _RAISED_AROUND:
            raised[z] = (ta, tb)
        way = np.array([qA, ta, tb, qB])
        if _clears(scene, way):
            found.append(Candidate("over", way, *score(scene, way, velocity, acceleration)))
            break
        z += _STEP
    # AROUND: a via point beside the first collision of the straight lines, moved out on either side, at the
    # traverse height and a little above it (around one obstacle and over a lower one)
    samples = line_samples(straight)
    D = scene.minimum_array(samples) - scene.margin
    hit = int(np.argmax(D < 0.0))
    p = robot.tool_pose(samples[hit])
    u = B[:2] - A[:2]
    u = u / np.linalg.norm(u)
    normal = np.array([-u[1], u[0]])
    base = A[:2] + u * float(np.clip((p[:2] - A[:2]) @ u, 0.0, np.linalg.norm(B[:2] - A[:2])))
    yaw = float(A[3] + (B[3] - A[3]) * 0.5)
    for k, (zv, (ta, tb)) in enumerate(raised.items()):
        if k and any(c.clearance >= 0.0 for c in found):
            break  # a way clears already: raised AROUND scans only when nothing else does
        step = _STEP if k == 0 else 2.0 * _STEP  # the raised scans are coarser: they only add ways
        for side, sign in (("left", 1.0), ("right", -1.0)):
            offset = step
            while offset <= MAX_OFFSET:
                xy = base + sign * offset * normal
                via = _ik(robot, np.array([xy[0], xy[1], zv, yaw]), (ta + tb) / 2.0)
                if via is not None:
                    way = np.array([qA, ta, via, tb, qB])
                    if _clears(scene, way):
                        found.append(Candidate(side if k == 0 else f"{side}, raised", way,
                                               *score(scene, way, velocity, acceleration)))  # fmt: skip
                        break
                offset += step
    clear_ones = sorted((c for c in found if c.clearance >= 0.0), key=lambda c: c.duration)
    if not clear_ones:  # none clears: every one tried, the least colliding first (the planner may still find a way)
        return sorted(found, key=lambda c: -c.clearance)
    return clear_ones


def stroke_top(robot: RobotModel, q: np.ndarray) -> np.ndarray | None:
    """``q`` with the joint that moves the tool up (a SCARA's quill) at the end of its range that raises the tool.

    None when that joint is not prismatic (a palletizer raises the tool by turning its arms).
    """
    J = robot.task_jacobian(q)[2]
    out = q.copy()
    j = int(np.argmax(np.abs(J)))
    if robot.joint_kinds[j] != "length":
        return None
    out[j] = robot.limits.upper[j] if J[j] > 0 else robot.limits.lower[j]
    return out
