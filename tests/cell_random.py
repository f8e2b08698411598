"""Random cells built around a motion known to be clear (issue 37): the generator the suite and the benchmark share.

A cell is drawn from a seed, for the default robot:

- two poses A and B in its reach (0.2 to 0.38 m from J1, within 100 deg of the x axis either way, z from -0.14 to
  -0.06 m, any yaw), at least 8 cm apart in plan view, and half the time a carried box under the flange;
- a REFERENCE motion: the time-optimal jump A -> B without obstacles ("free"), or one bent round a post put on that
  jump's path at half its time, planned in a cell with that post ("detour"); the post is then taken away;
- three to eight obstacles drawn around the reference's tool path (boxes, cylinders, spheres, convex meshes, turned
  at random), each KEPT only when the reference motion stays at least the margin plus 1 mm from it at 2 kHz (the
  millimetre is more than any point of the robot moves in 0.5 ms here, so the reference is clear between those
  samples too).

The reference is a motion clear of the cell, so the cell's fastest jump is no slower than the reference's time:
the planner must find a way (the cell leaves one) and be no slower than it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import trimesh

from scara_pin.cell import Cell, Obstacle, Shape, scene
from scara_pin.motion.jump import JumpMove, jump_move

MARGIN = 0.002
SLACK = 0.001
"""[m] the reference keeps the margin plus this from every obstacle, at 2 kHz."""


@dataclass(frozen=True)
class RandomCell:
    """A cell drawn around a clear reference motion (module docstring)."""

    seed: int
    kind: str
    A: np.ndarray
    B: np.ndarray
    cell: Cell
    reference: JumpMove

    def describe(self) -> str:
        kinds = ", ".join(o.shape.kind for o in self.cell.obstacles)
        carried = "carrying a box" if self.cell.carried is not None else "no part"
        return (f"seed {self.seed} ({self.kind}): {len(self.cell.obstacles)} obstacles ({kinds}), {carried}, "
                f"reference {self.reference.duration:.6f} s")  # fmt: skip


def _pose(rng: np.random.Generator) -> np.ndarray:
    r, a = rng.uniform(0.2, 0.38), math.radians(rng.uniform(-100.0, 100.0))
    return np.array([r * math.cos(a), r * math.sin(a), rng.uniform(-0.14, -0.06), rng.uniform(-math.pi, math.pi)])


def _shape(rng: np.random.Generator, centre: np.ndarray, what: str) -> Shape:
    kind = rng.choice(["box", "cylinder", "sphere", "mesh"])
    rpy = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), rng.uniform(-math.pi, math.pi)])
    if kind == "box":
        return Shape("box", tuple(rng.uniform(0.01, 0.08, 3)), centre, rpy, what=what)
    if kind == "cylinder":
        return Shape("cylinder", (rng.uniform(0.005, 0.03), rng.uniform(0.02, 0.2)), centre, rpy, what=what)
    if kind == "sphere":
        return Shape("sphere", (rng.uniform(0.005, 0.04),), centre, np.zeros(3), what=what)
    hull = trimesh.convex.convex_hull(rng.uniform(-0.03, 0.03, (12, 3)))
    return Shape("mesh", (), centre, rpy, np.asarray(hull.vertices), np.asarray(hull.faces), "hull.stl", what)


def random_cell(robot, seed: int) -> RandomCell:
    """The cell of ``seed`` (module docstring); a seed whose draw cannot be planned is redrawn from the next."""
    for attempt in range(20):
        rng = np.random.default_rng([seed, attempt])
        A, B = _pose(rng), _pose(rng)
        if np.hypot(*(A[:2] - B[:2])) < 0.08:
            continue
        carried = None
        if rng.random() < 0.5:
            size = (rng.uniform(0.02, 0.08), rng.uniform(0.01, 0.03), rng.uniform(0.01, 0.03))
            carried = Shape("box", size, np.array([0.0, 0.0, size[2] / 2 + 0.002]), np.zeros(3), what="the part")
        kind = "detour" if rng.random() < 0.5 else "free"
        try:
            reference = jump_move(robot, A, B, cell=Cell((), MARGIN, carried))
            if kind == "detour":
                q = reference.trajectory.sample(np.array([reference.duration / 2]))[0][0]
                p = robot.tool_pose(q)
                ghost = Obstacle("ghost", Shape("cylinder", (rng.uniform(0.008, 0.02), 0.3),
                                                np.array([p[0], p[1], p[2] - 0.1]), np.zeros(3)))  # fmt: skip
                reference = jump_move(robot, A, B, cell=Cell((ghost,), MARGIN, carried))
        except Exception:  # noqa: BLE001 - an unplannable draw (out of reach, a goal in the robot's way): redraw
            continue
        Q = reference.trajectory.sample(np.arange(0.0, reference.duration, 5e-4))[0]
        tool = np.array([robot.tool_pose(q)[:3] for q in Q])
        obstacles: list[Obstacle] = []
        tries, wanted = 0, int(rng.integers(3, 9))
        while len(obstacles) < wanted and tries < 200:
            tries += 1
            around = tool[rng.integers(len(tool))]
            direction = rng.normal(size=3)
            centre = around + direction / np.linalg.norm(direction) * rng.uniform(0.03, 0.15)
            ob = Obstacle(f"o{len(obstacles)}", _shape(rng, centre, f"obstacle o{len(obstacles)}"))
            if scene(robot, Cell((ob,), MARGIN, carried)).minimum_array(Q).min() >= MARGIN + SLACK:
                obstacles.append(ob)
        if len(obstacles) >= 3:
            return RandomCell(seed, kind, A, B, Cell(tuple(obstacles), MARGIN, carried), reference)
    raise RuntimeError(f"seed {seed}: no plannable draw in 20 attempts")
