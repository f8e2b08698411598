"""A job in a cell (scara_pin.job, issue 28 item 3) on the default robot: every move honours the obstacles, the
part held between a pick and a place, and each box placed.

Independent routes for every expected value:

- a job's jump in a cell: the same jump planned alone by ``jump_move(..., cell=)`` (what the job must hand the
  planner), a motion other than the jump without the cell where that one goes through a stake (coal), and never
  faster than it;
- a fixed path through an obstacle: the pair named is the one the test built to be hit (the flange passes through
  a post planted on the straight line; the carried box, hanging 20 mm below the flange, through a block whose top
  is 5 mm below the flange's path), found by the test's own closed-form FK;
- the cache: moves counted by the planner's statistics under states the test chooses;
- what the cell costs: the same jump planned alone without the cell (``jump_move`` without ``cell=``);
- the part left on the flange: its top face on the flange face (the default carry) is 0 mm from the tool's links.

The palletizer's job (the issue's Must-hold) is tests/test_job_palletizer.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from test_job import CARRY, line_of, write_job

from scara_pin import Robot
from scara_pin.cell import Cell, Obstacle, Shape
from scara_pin.cli import main
from scara_pin.job import Job, Planner
from scara_pin.job.steps import Move, MoveKind
from scara_pin.motion.jump import jump_move

MARGIN = 0.002
POST = ("margin: 0.002\nobstacles:\n"
        "  - {name: post, shape: cylinder, radius: 0.01, length: 0.2, xyz: [0.135, -0.18, -0.15]}\n")
"""A post on the straight line from the feeder (0.05, -0.30) to T11 (0.22, -0.06), its top at z = -0.05 m."""


def scara_xyz(q: np.ndarray) -> np.ndarray:
    """Tool position of the default robot from its URDF numbers: l1 = l2 = 0.2 m, z = -0.05 - q3."""
    a, b = q[0], q[0] + q[1]
    return np.array([0.2 * np.cos(a) + 0.2 * np.cos(b), 0.2 * np.sin(a) + 0.2 * np.sin(b), -0.05 - q[2]])


def _json(capsys: pytest.CaptureFixture[str], argv: list[str]) -> dict:
    assert main(argv) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def test_a_jump_in_a_cell_is_the_jump_planned_alone_in_it_and_a_line_through_it_is_refused(
    robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:  # fmt: skip
    (tmp_path / "cell.yaml").write_text(POST)
    body = "cell: cell.yaml\nstart: feeder\nsteps:\n  - jump: T11\n  - jump: feeder\n"
    job = write_job(tmp_path, body, robot_default)
    points = Job.load(job).points
    qf, qt = points["feeder"].q, points["T11"].q
    free = jump_move(robot_default, robot_default.tool_pose(qf), robot_default.tool_pose(qt), start=qf, end=qt,
                     torque=False)  # fmt: skip
    # a second post where the free jump's tool is at half time, its top 10 mm above the tool there: the jump must
    # bend for it (the first post, on the straight line, is for the straight move below)
    mid = [float(v) for v in scara_xyz(free.trajectory.sample(np.array([free.duration / 2]))[0][0])]
    top = mid[2] + 0.01
    (tmp_path / "cell.yaml").write_text(POST + f"  - {{name: stake, shape: cylinder, radius: 0.01, length: 0.2, "
                                        f"xyz: [{mid[0]!r}, {mid[1]!r}, {top - 0.1!r}]}}\n")  # fmt: skip
    out = _json(capsys, ["job", str(job), "--json"])
    there, back = out["steps"]
    post = Obstacle("post", Shape("cylinder", (0.01, 0.2), np.array([0.135, -0.18, -0.15]), np.zeros(3)))
    stake = Obstacle("stake", Shape("cylinder", (0.01, 0.2), np.array([mid[0], mid[1], top - 0.1]), np.zeros(3)))
    alone = jump_move(robot_default, robot_default.tool_pose(qf), robot_default.tool_pose(qt), start=qf, end=qt,
                      torque=False, cell=Cell((post, stake), MARGIN))  # fmt: skip
    assert abs(there["duration"] - alone.duration) <= 1e-9
    # the free jump goes through the stake (coal, at its half time): the jump in the cell is another motion, never
    # faster than the free one (a lower bound of every motion), and may be as fast (the binding joint need not move
    # otherwise: the time-optimal path is not unique)
    q_mid = free.trajectory.sample(np.array([free.duration / 2]))[0][0]
    assert robot_default.distances(q_mid, Cell((stake,), MARGIN)).minimum < 0.0
    assert there["duration"] >= free.duration - 1e-9
    q_cell = alone.trajectory.sample(np.array([free.duration / 2]))[0][0]
    assert np.max(np.abs(q_cell - q_mid)) > 1e-3
    assert there["clearance"]["distance"] >= MARGIN - 1e-6  # every checked pair, the robot's own too
    assert back["planned"] == "an earlier jump reversed" and abs(back["duration"] - there["duration"]) <= 1e-12
    assert back["clearance"] is not None and back["clearance"]["distance"] >= MARGIN - 1e-6  # verified in the cell
    # what the cell costs (issue 34): each move's free-space time is the same jump planned alone without the cell
    for step in (there, back):
        assert abs(step["free"] - free.duration) <= 1e-6
        assert abs(step["cell_cost"] - (alone.duration - free.duration)) <= 1e-6
    assert abs(out["cell_cost"] - 2.0 * (alone.duration - free.duration)) <= 2e-6
    assert out["cell"]["margin"] == MARGIN and [o["name"] for o in out["cell"]["obstacles"]] == ["post", "stake"]
    # a straight line is a fixed path: through the post, refused (exit 3), naming the pair, at the move's line
    job.write_text(job.read_text().replace("  - jump: feeder\n", "  - move: feeder\n"))
    assert main(["job", str(job)]) == 3
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'move: feeder')}: move T11 -> feeder: the motion comes "
                          "closer than the margin: flange - post"), err  # fmt: skip
    # the line does cross the post: its plan-view distance to the post's axis is below the radii (closed form)
    a, b = scara_xyz(qt)[:2], scara_xyz(qf)[:2]
    u = (b - a) / np.linalg.norm(b - a)
    c = np.array([0.135, -0.18]) - a
    assert abs(c[0] * u[1] - c[1] * u[0]) < 0.01 + 0.025


def test_the_part_held_collides_on_a_fixed_path_and_a_part_left_on_the_flange_is_refused(
    robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:  # fmt: skip
    points = write_job(tmp_path, "steps:\n  - jump: feeder\n", robot_default)  # the taught points
    qf, qt = (Job.load(points).points[n].q for n in ("feeder", "T11"))
    # the joint line's middle (its tool point by closed-form FK); z moves linearly with the quill
    mid = [float(v) for v in scara_xyz((qf + qt) / 2.0)]
    # a block whose top is 5 mm under the flange's path there: the flange passes, the box hanging 20 mm under it not
    top = min(float(scara_xyz(qf)[2]), float(scara_xyz(qt)[2])) - 0.005
    (tmp_path / "cell.yaml").write_text(f"margin: {MARGIN}\nobstacles:\n  - {{name: block, shape: box, size: [0.06, "
                                        f"0.06, 0.02], xyz: [{mid[0]!r}, {mid[1]!r}, {top - 0.01!r}]}}\n")  # fmt: skip
    body = "cell: cell.yaml\n" + CARRY + "start: feeder\nsteps:\n  - go: T11\n  - pick: 0.05\n  - go: feeder\n"
    job = write_job(tmp_path, body, robot_default)
    assert main(["job", str(job)]) == 3  # empty there, holding the part back: the second go is refused
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'go: feeder')}: go T11 -> feeder: the motion comes "
                          "closer than the margin: carried - block"), err  # fmt: skip
    # the default carry: the box's top face on the flange face. Left there, the tool's links touch it: refused
    body = ("carry: {shape: box, size: [0.02, 0.03, 0.015]}\nstart: feeder\nsteps:\n  - pick: 0.05\n  - go: T11\n"
            "  - place: 0.05\n  - go: feeder\n")  # fmt: skip
    job = write_job(tmp_path, body, robot_default)
    assert main(["job", str(job)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'place: 0.05')}: the robot after leaving box1 at T11 is "
                          "in collision: ") and " box1 " in err, err  # fmt: skip
    assert err.endswith("(the part must hang more than the margin, 2 mm, below the tool's links: lower it in the tool "
                        "frame, carry: xyz)"), err  # fmt: skip


def test_a_move_is_the_same_move_only_with_the_same_boxes_and_gripper(robot_default: Robot) -> None:
    far = Obstacle("far", Shape("sphere", (0.01,), np.array([0.0, 0.0, -0.5]), np.zeros(3)))
    part = Shape("box", (0.02, 0.03, 0.015), np.array([0.0, 0.0, 0.0125]), np.zeros(3))
    planner = Planner(robot_default, cell=Cell((far,), MARGIN), carry=part)
    q0 = robot_default.ik_nearest(np.array([0.25, -0.1, -0.08, 0.5]), np.array([-1.0, 1.5, 0.03, 0.0]))
    q1 = robot_default.ik_nearest(np.array([0.25, 0.1, -0.08, 0.5]), q0)
    move = Move(MoveKind.GO, "B", None, q1, robot_default.tool_pose(q1), 1.0, 1.0, None, 1)
    q2 = robot_default.ik_nearest(np.array([-0.1, -0.3, -0.08, 0.5]), q0)  # a box left out of the way
    box = Obstacle("box1", part.moved(robot_default.tool_placement(q2), what="box1"))
    first = planner.plan(move, q0)
    assert planner.plan(move, q0).source.value == "same as an earlier move"
    for placed, holding in (((box,), False), ((), True), ((box,), True)):  # another state: planned again
        out = planner.plan(move, q0, placed, holding)
        assert out.source.value == "planned" and out.duration == first.duration  # nothing in the way here
    assert (planner.stats.planned, planner.stats.same) == (4, 1)
    cell = planner.cell_for((box,), True)
    assert cell is not None and [o.name for o in cell.obstacles] == ["far", "box1"] and cell.carried is part
    assert planner.cell_for((), False).carried is None  # type: ignore[union-attr]


def test_the_payload_is_held_from_a_pick_to_a_place(robot_default: Robot) -> None:
    """With a carry, RAPID's GripLoad: the torques see the payload only while the part is held."""
    part = Shape("box", (0.02, 0.03, 0.015), np.array([0.0, 0.0, 0.0125]), np.zeros(3))
    q0 = np.array([0.0, 0.5, 0.03, 0.0])
    q1 = np.array([1.2, -0.5, 0.03, 1.0])
    move = Move(MoveKind.GO, "B", None, q1, robot_default.tool_pose(q1), 1.0, 1.0, None, 1)
    heavy = Planner(robot_default, torque=True, payload=8.0, carry=part)
    bare = Planner(robot_default, torque=True)
    empty, held, none = heavy.plan(move, q0), heavy.plan(move, q0, holding=True), bare.plan(move, q0)
    assert empty.duration == none.duration  # not holding: no payload at all
    assert held.duration > none.duration * 1.01  # 8 kg at the tool: the torques bind
