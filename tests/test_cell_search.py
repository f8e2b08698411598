"""The jump's global search in a cell (scara_pin.motion.jump.search, issue 37 item 1): a way whenever one exists,
a true refusal when none does.

Independent routes:

- the minimum time: tests/cell_reference.py, the tests' own transcription with closed-form kinematics and
  distances (a vertical post against both links and the flange), warm-started from tool via points chosen here;
- no way: the geometry says so in closed form (a wall from near the base to beyond the reach, higher than the links
  and the stroke, between A and B, with J1's range too short to go round the back; a ring of walls around B under
  a ceiling lower than their top);
- the search's structure: which joints a pair's distance depends on, from the kinematic tree (link1 on J1 alone,
  link2 on J1 and J2, the round flange not on J4, a carried box on J4).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from cell_reference import Post, minimum_time

from scara_pin import load_robot
from scara_pin.cell import Cell, Obstacle, Shape, scene
from scara_pin.cli import main
from scara_pin.motion.jump import JumpError, jump_move
from scara_pin.motion.jump.search import _Lattice

FROM = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
TO = FROM + np.array([0.0, 0.305, 0.0, 0.0])
MARGIN = 0.002
COLUMN = (0.24, -0.08, 0.01)  # a tall column link2 sweeps through on the direct way; the tool's path stays clear of it


def _column_cell() -> Cell:
    x, y, r = COLUMN
    return Cell((Obstacle("column", Shape("cylinder", (r, 0.6), np.array([x, y, 0.0]), np.zeros(3))),), MARGIN)


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


@pytest.fixture(scope="module")
def column_move(robot):
    return jump_move(robot, FROM, TO, cell=_column_cell())


def test_a_column_that_link2_would_sweep_through_is_gone_round_within_2_percent(robot, column_move):
    # the way: the elbow folds more and the tool passes between the column and the base (chosen here)
    ref = minimum_time(robot, FROM, TO, posts=[Post(*COLUMN)], vias=(((0.17, -0.05, -0.0625), (0.2, 0.05, -0.0625)),))
    assert column_move.duration <= ref * 1.02, (column_move.duration, ref)
    assert column_move.duration >= ref * 0.999  # the reference is a minimum: nothing is much faster
    assert column_move.distance.bound >= MARGIN - 1e-6


def test_the_search_finds_the_way_the_local_warm_starts_miss(robot):
    from scara_pin.motion.jump.candidates import candidates
    from scara_pin.motion.jump.problem import endpoints, top_configuration
    from scara_pin.motion.jump.search import search

    sc = scene(robot, _column_cell())
    qA, qB = endpoints(robot, FROM, TO, None, None, None)
    z_top = max(FROM[2], TO[2]) + 0.025
    tops = (top_configuration(robot, FROM, z_top, qA, "A", 0.025), top_configuration(robot, TO, z_top, qB, "B", 0.025))
    lim = robot.limits
    local = candidates(sc, qA, qB, tops, FROM, TO, z_top, None, np.array(lim.velocity), np.array(lim.acceleration))
    assert all(c.clearance < 0.0 for c in local)  # over, left, right: none clears (what refused it before)
    found = search(sc, *tops, z_top, None, np.array(lim.velocity))
    assert found.ways and found.ways[0].waypoints[0] == pytest.approx(tops[0]) and found.ways[0].waypoints[-1] == \
        pytest.approx(tops[1])  # fmt: skip


def test_a_pair_depends_only_on_the_joints_between_its_shapes(robot):
    # a ball (a tall post would not care how high the flange is: the quill would drop out of its pairs, rightly)
    post = Obstacle("post", Shape("sphere", (0.02,), np.array([0.3, -0.05, -0.1]), np.zeros(3)))
    carried = Shape("box", (0.08, 0.02, 0.02), np.array([0.0, 0.0, 0.02]), np.zeros(3))
    sc = scene(robot, Cell((post,), MARGIN, carried))
    lattice = _Lattice(sc, robot.ik_nearest(FROM[:4] + [0, 0, 0.025, 0]), robot.ik_nearest(TO[:4] + [0, 0, 0.025, 0]),
                       -0.0625, None, np.array(robot.limits.velocity))  # fmt: skip
    dims = {sc.pairs[k].label: d for k, d in enumerate(lattice.pair_dims)}
    assert dims["link1 - post"] == {0}
    assert dims["link2 - post"] == {0, 1}
    assert dims["flange - post"] == {0, 1, 2}  # a round flange turning on its axis changes no distance
    assert dims["carried - post"] == {0, 1, 2, 3}  # a bar does
    assert dims["link2 - flange (self)"] == {2}  # only the quill moves the flange under the arm's end
    assert lattice.z_dims == [2]  # the quill alone moves the tool up and down


def test_a_wall_across_the_whole_reach_higher_than_the_stroke_is_refused_naming_it(robot):
    # A and B at -75 and +75 deg, 0.3 m from J1; a wall on the plane y = 0 from x = 0.12 (clear of the column) to 0.5
    # (beyond the reach), from z = -0.25 to 0.05 (over the links and the stroke): link1 reaches 0.2 m from J1, so J1
    # cannot cross 0 deg, and going round the back (through 180 deg) is beyond its +-132 deg
    A = np.array([0.3 * math.cos(math.radians(-75)), 0.3 * math.sin(math.radians(-75)), -0.09, 0.0])
    B = np.array([0.3 * math.cos(math.radians(75)), 0.3 * math.sin(math.radians(75)), -0.09, 0.0])
    wall = Obstacle("wall", Shape("box", (0.38, 0.01, 0.3), np.array([0.31, 0.0, -0.1]), np.zeros(3)))
    with pytest.raises(JumpError) as caught:
        jump_move(robot, A, B, cell=Cell((wall,), MARGIN))
    assert caught.value.status == "No_Way"
    assert "no way through the cell on a lattice of" in caught.value.reason and "wall" in caught.value.reason


def test_a_goal_enclosed_under_the_ceiling_is_refused_naming_it(robot):
    # a ring of walls around B (inner half-size 45 mm: the flange at B clears them), their tops at z = -0.05; the
    # ceiling at -0.055 keeps the tool under their tops: no way out of the ring
    x, y = TO[0], TO[1]
    ring = [(0.05, 0.0, (0.01, 0.11, 0.2)), (-0.05, 0.0, (0.01, 0.11, 0.2)), (0.0, 0.05, (0.11, 0.01, 0.2)),
            (0.0, -0.05, (0.11, 0.01, 0.2))]
    walls = tuple(Obstacle(f"wall{i}", Shape("box", size, np.array([x + dx, y + dy, -0.15]), np.zeros(3)))
                  for i, (dx, dy, size) in enumerate(ring))
    with pytest.raises(JumpError) as caught:
        jump_move(robot, FROM, TO, cell=Cell(walls, MARGIN), max_height=-0.055)
    assert caught.value.status == "No_Way" and "wall" in caught.value.reason


def test_traj_arch_takes_via_points_as_hints(robot, tmp_path, capsys, column_move):
    cell = tmp_path / "column.yaml"
    x, y, r = COLUMN
    cell.write_text(f"margin: {MARGIN}\nobstacles:\n  - {{name: column, shape: cylinder, radius: {r}, length: 0.6, "
                    f"xyz: [{x}, {y}, 0]}}\n")  # fmt: skip
    via = robot.ik_nearest(np.array([0.17, -0.05, -0.0625, 0.0]), column_move.q_from)
    argv = ["traj", "--arch", "--from-pose", *map(str, FROM), "--to-pose", *map(str, TO), "--cell", str(cell), "--json"]
    assert main([*argv, "--via", *map(str, via)]) == 0, capsys.readouterr().err
    import json

    out = json.loads(capsys.readouterr().out)
    assert out["duration"] == pytest.approx(column_move.duration, rel=0.02)
    outside = via.copy()
    outside[1] = 4.0  # beyond joint2's 150 deg
    assert main([*argv, "--via", *map(str, outside)]) == 3  # as every joint value out of its limits
    err = capsys.readouterr().err
    assert err.startswith("error: --via #1 is outside the joint limits: joint2 = 4 rad"), err


def test_a_thin_wall_is_passed_over_within_2_percent(robot):
    """The held-out wall: across the traverse, its top 18.5 mm above the clearance height and 4 mm under link1: the
    flange passes over it (the whole stroke is usable: the arm's end sits above the flange at the stroke's top)."""
    from cell_reference import LowBox

    wall = LowBox(0.26, 0.0, 0.15, 0.0025, -0.044)
    cell = Cell((Obstacle("wall", Shape("box", (0.3, 0.005, 0.1), np.array([0.26, 0.0, -0.094]), np.zeros(3))),),
                MARGIN)  # fmt: skip
    move = jump_move(robot, FROM, TO, cell=cell)
    ref = minimum_time(robot, FROM, TO, boxes=[wall], vias=(((0.26, 0.0, -0.04),),))
    assert ref * 0.999 <= move.duration <= ref * 1.02, (move.duration, ref)
    assert move.distance.bound >= MARGIN - 1e-6


def test_a_near_miss_is_refined_not_refused(robot):
    """A carried bar whose motion without the cell passes 10 um inside the margin of a small ball: the jump bends by
    micrometres. The motion without the cell is a lower bound of every motion in it (its own optimum)."""
    carried = Shape("box", (0.1, 0.01, 0.01), np.array([0.0, 0.0, 0.02]), np.zeros(3))
    free = jump_move(robot, FROM, TO)
    q = free.trajectory.sample(np.array([free.duration / 2]))[0][0]
    end = robot.tool_placement(q).act(np.array([0.05, 0.0, 0.02]))  # the bar's end at half time (tool frame x)
    out = robot.tool_placement(q).rotation[:, 0]
    ball = Obstacle("ball", Shape("sphere", (0.005,), end + out * (0.005 + MARGIN - 1e-5), np.zeros(3)))
    move = jump_move(robot, FROM, TO, cell=Cell((ball,), MARGIN, carried))
    assert free.duration <= move.duration <= free.duration * 1.005
    assert move.distance.bound >= MARGIN - 1e-6
