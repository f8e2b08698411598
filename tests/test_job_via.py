"""A job's jump takes via points as hints of its way through the cell (issue 37, item 1: ``via:`` beside ``--via``).

Independent routes: the job's jump is the jump planned alone with the same via configuration
(``jump_move(..., via=)``, what the job must hand the planner), and within 2 % of the column cell's independent
minimum (tests/cell_reference.py, the same column and the same way as tests/test_cell_search.py); the refusals
name the step's line, found in the text here.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cell_reference import Post, minimum_time
from test_job import line_of

from scara_pin import load_robot
from scara_pin.cell import Cell, Obstacle, Shape
from scara_pin.cli import main
from scara_pin.job import Job
from scara_pin.motion.jump import jump_move
from scara_pin.motion.points import PointSet, TaughtPoint, write_points

MARGIN = 0.002
FROM = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
TO = FROM + np.array([0.0, 0.305, 0.0, 0.0])
COLUMN = (0.24, -0.08, 0.01)  # link2 sweeps through it on the direct way (tests/test_cell_search.py)
WAY = np.array([0.17, -0.05, -0.0625, 0.0])  # the tool between the column and the base, at the traverse height


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


def _write(folder: Path, robot, body: str, cell: bool = True) -> Path:
    mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2
    qa = robot.ik_nearest(FROM, mid)
    names = {"a": qa, "b": robot.ik_nearest(TO, qa), "way": robot.ik_nearest(WAY, qa)}
    points = [TaughtPoint.at(robot, n, q) for n, q in names.items()]
    write_points(folder / "points.yaml", PointSet(tuple(points), robot.name, robot.base_frame, robot.tool_frame))
    x, y, r = COLUMN
    (folder / "column.yaml").write_text(f"margin: {MARGIN}\nobstacles:\n  - {{name: column, shape: cylinder, "
                                        f"radius: {r}, length: 0.6, xyz: [{x}, {y}, 0]}}\n")  # fmt: skip
    job = folder / "job.yaml"
    job.write_text(f"format: scara-pin job 1\nrobot: {robot.name}\npoints: points.yaml\n"
                   f"{'cell: column.yaml' if cell else ''}\nstart: a\nsteps:\n{body}")  # fmt: skip
    return job


def test_a_jobs_jump_goes_the_way_its_via_points_give(robot, tmp_path, capsys) -> None:
    job = _write(tmp_path, robot, "  - jump: b\n    via: [way]\n")
    assert main(["job", str(job), "--json", "--no-cache"]) == 0, capsys.readouterr().err
    step = json.loads(capsys.readouterr().out)["steps"][0]
    points = Job.load(job).points
    qa, qb, way = points.q_of("a"), points.q_of("b"), points.q_of("way")
    x, y, r = COLUMN
    cell = Cell((Obstacle("column", Shape("cylinder", (r, 0.6), np.array([x, y, 0.0]), np.zeros(3))),), MARGIN)
    alone = jump_move(robot, robot.tool_pose(qa), robot.tool_pose(qb), start=qa, end=qb, torque=False, cell=cell,
                      via=[way])  # fmt: skip
    assert abs(step["duration"] - alone.duration) <= 1e-9
    ref = minimum_time(robot, FROM, TO, posts=[Post(*COLUMN)], vias=(((0.17, -0.05, -0.0625), (0.2, 0.05, -0.0625)),))
    assert ref * 0.999 <= step["duration"] <= ref * 1.02, (step["duration"], ref)
    assert step["clearance"]["distance"] >= MARGIN - 1e-6


@pytest.mark.parametrize(
    ("body", "message"),
    [
        ("  - jump: b\n    via: [nowhere]\n", "unknown point 'nowhere'"),
        ("  - jump: b\n    via: []\n", "via: is a list of 1 to 16 point names"),
        ("  - jump: b\n    via: way\n", "via"),
        ("  - move: b\n    via: [way]\n", "via"),
    ],
)
def test_a_bad_via_is_refused_at_its_line(robot, tmp_path, capsys, body, message) -> None:
    job = _write(tmp_path, robot, body)
    assert main(["job", str(job), "--no-cache"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and message in err, err
    assert f":{line_of(job, 'via')}" in err or f"line {line_of(job, 'via')}" in err, err


def test_via_points_without_a_cell_are_refused(robot, tmp_path, capsys) -> None:
    job = _write(tmp_path, robot, "  - jump: b\n    via: [way]\n", cell=False)
    assert main(["job", str(job), "--no-cache"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "via points are hints of the way through a cell" in err, err
