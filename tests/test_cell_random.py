"""Random cells built around a clear reference motion (tests/cell_random.py; issue 37): each is solved, verified
and certified, and no slower than the reference's own time-optimal timing (the reference is clear in the cell, so
the cell's fastest jump is no slower than it). Two seeds here; two hundred in benchmarks/bench_cell_random.py."""

from __future__ import annotations

import pytest
from cell_random import MARGIN, random_cell

from scara_pin import load_robot
from scara_pin.motion.jump import jump_move
from scara_pin.motion.verify import DISTANCE_TOL

SEEDS = (2, 4)  # two here (a detour carrying a part, a free one: the suite's time); two hundred in the benchmark


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


@pytest.mark.parametrize("seed", SEEDS)
def test_a_random_cell_around_a_clear_motion_is_solved_no_slower_than_it(robot, seed):
    drawn = random_cell(robot, seed)
    move = jump_move(robot, drawn.A, drawn.B, cell=drawn.cell)
    assert move.duration <= drawn.reference.duration * (1.0 + 1e-6), drawn.describe()
    assert move.distance.certified.certified and move.distance.bound >= MARGIN - DISTANCE_TOL
