"""The job file (scara_pin.job): pallets, loops, targets, and every refusal before any planning.

Truth from independent routes: the places of a pallet written here from its corners (pitch vectors for three
corners; rows interpolated first, then along each row, for four), the visiting orders and the SPEL+ numbering
written out by hand, the corners' poses from Pinocchio's FK, the line of each refusal found in the job's text
by the test. "Before any planning" is shown by planners that fail the test if they are called.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from scara_pin import Robot
from scara_pin.cli import main
from scara_pin.errors import InvalidInputError, JobFileError
from scara_pin.job import Job, Order, Pallet, Source
from scara_pin.job import planning as planning_module
from scara_pin.limits import MAX_JOB_DEPTH, MAX_JOB_STEPS
from scara_pin.motion import jump as jump_module
from scara_pin.motion.points import PointSet, TaughtPoint, write_points
from scara_pin.viz.teach import TeachSession

# taught poses on the default robot (x, y, z, yaw) [m, rad]: a feeder, a tray's corners, a home; the yaw of 0.5 rad
# makes the right elbow branch clearly the nearest to mid-range, the one `traj --from-pose` takes (at yaw 0 both tie)
POSES = {
    "feeder": (0.05, -0.30, -0.09, 0.5),
    "T11": (0.22, -0.06, -0.10, 0.5),
    "T12": (0.22, 0.09, -0.10, 0.5),
    "T21": (0.31, -0.06, -0.10, 0.5),
    "T22": (0.31, 0.09, -0.10, 0.5),
    "T13": (0.22, 0.24, -0.10, 0.5),  # on the line T11-T12: collinear with them
    "home": (0.30, 0.0, -0.06, 0.5),
}


def teach(robot: Robot, names: tuple[str, ...] = ("feeder", "T11", "T12", "T21", "T22", "T13", "home")) -> PointSet:
    """The points as the pendant records them: each q the IK solution nearest the middle of the joint ranges."""
    mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2
    points = [TaughtPoint.at(robot, n, robot.ik_nearest(np.array(POSES[n]), mid)) for n in names]
    return PointSet(tuple(points), robot.name, robot.base_frame, robot.tool_frame)


def write_job(folder: Path, body: str, robot: Robot, points: PointSet | None = None) -> Path:
    """``folder/points.yaml`` (taught on ``robot``) and ``folder/job.yaml`` with ``body`` after its header."""
    write_points(folder / "points.yaml", teach(robot) if points is None else points)
    job = folder / "job.yaml"
    job.write_text(f"format: scara-pin job 1\nrobot: {robot.name}\npoints: points.yaml\n{body}")
    return job


def line_of(job: Path, needle: str) -> int:
    """The line (from 1) of the first line of ``job`` that holds ``needle``: found in the text, not by the loader."""
    return next(i for i, text in enumerate(job.read_text().splitlines(), start=1) if needle in text)


@pytest.fixture
def no_planning(monkeypatch: pytest.MonkeyPatch) -> None:
    """Any move planned fails the test: what is refused must be refused before."""

    def planned(*args: object, **kwargs: object) -> None:
        pytest.fail("a move was planned before the refusal")

    monkeypatch.setattr(planning_module, "plan_move", planned)
    monkeypatch.setattr(jump_module, "jump_move", planned)


# ---------------------------------------------------------------------------------------------- pallets
def test_three_corners_make_the_grid_of_their_pitch_vectors() -> None:
    P11, P1C = np.array([0.2, -0.1, -0.1, 0.3]), np.array([0.2, 0.15, -0.08, 0.5])
    PR1 = np.array([0.29, -0.1, -0.1, 0.2])
    pallet = Pallet("tray", ("a", "b", "c"), rows=4, columns=6, layers=2, layer_height=0.15)
    corners = pallet.corner_poses(np.array([P11, P1C, PR1]))
    pitch_c, pitch_r = (P1C - P11) / 5, (PR1 - P11) / 3
    for i in range(1, pallet.places + 1):
        layer, k = divmod(i - 1, 24)
        r, c = divmod(k, 6)
        expected = P11 + c * pitch_c + r * pitch_r + np.array([0, 0, 0.15 * layer, 0])
        assert pallet.pose(corners, i) == pytest.approx(expected, abs=1e-15), i
        assert pallet.place(i) == (r + 1, c + 1, layer + 1)


def test_four_corners_make_the_bilinear_grid() -> None:
    P = np.array([[0.2, -0.1, -0.1, 0.0], [0.2, 0.15, -0.1, 0.0], [0.3, -0.12, -0.1, 0.1], [0.32, 0.16, -0.09, 0.2]])
    pallet = Pallet("tray", ("a", "b", "c", "d"), rows=3, columns=5)
    corners = pallet.corner_poses(P)
    for i in range(1, 16):
        r, c = divmod(i - 1, 5)
        left = P[0] + (P[2] - P[0]) * r / 2  # down the first column, then along the row
        right = P[1] + (P[3] - P[1]) * r / 2
        assert pallet.pose(corners, i) == pytest.approx(left + (right - left) * c / 4, abs=1e-15)
    # a parallelogram's 4th corner gives the 3-corner grid
    flat = P.copy()
    flat[3] = P[1] + P[2] - P[0]
    three = Pallet("t3", ("a", "b", "c"), rows=3, columns=5)
    c3, c4 = three.corner_poses(flat[:3]), pallet.corner_poses(flat)
    for i in range(1, 16):
        assert pallet.pose(c4, i) == pytest.approx(three.pose(c3, i), abs=1e-15)


def test_yaw_turns_the_short_way_and_a_line_takes_two_corners() -> None:
    P = np.array([[0.2, 0.0, -0.1, math.pi - 0.05], [0.2, 0.1, -0.1, -math.pi + 0.05]])  # 0.1 rad apart through pi
    line = Pallet("row", ("a", "b"), rows=1, columns=3)
    corners = line.corner_poses(P)
    yaws = [line.pose(corners, i)[3] for i in (1, 2, 3)]
    assert yaws == pytest.approx([math.pi - 0.05, math.pi, math.pi + 0.05], abs=1e-12)
    assert line.pose(corners, 2)[:3] == pytest.approx([0.2, 0.05, -0.1], abs=1e-15)
    with pytest.raises(InvalidInputError, match="take 2 corners"):
        Pallet("row", ("a", "b", "c"), rows=1, columns=3)
    with pytest.raises(InvalidInputError, match="layer_height"):
        Pallet("stack", ("a", "b", "c"), rows=2, columns=3, layers=2)


def test_orders_and_numbering() -> None:
    pallet = Pallet("p", ("a", "b", "c"), rows=2, columns=3, layers=2, layer_height=0.1)
    assert pallet.order(Order.ROWS) == list(range(1, 13))
    assert pallet.order(Order.COLUMNS) == [1, 4, 2, 5, 3, 6, 7, 10, 8, 11, 9, 12]
    assert pallet.order(Order.SERPENTINE) == [1, 2, 3, 6, 5, 4, 7, 8, 9, 12, 11, 10]
    with pytest.raises(InvalidInputError, match="past the end"):
        pallet.place(13)


@pytest.mark.parametrize(("corners", "needle"), [
    ([[0.2, 0, -0.1, 0], [0.2, 0.1, -0.1, 0], [0.2, 0.2, -0.1, 0]], "collinear"),
    ([[0.2, 0, -0.1, 0], [0.2, 0.1, -0.1, 0], [0.2, 0.1, -0.1, 0]], "same point"),
    ([[0.2, 0, -0.1, 0], [0.2, 0.1, -0.1, 0], [0.3, 0.1, -0.1, 0], [0.3, 0.0, -0.1, 0]], "folds over"),
])  # fmt: skip
def test_corners_that_span_no_grid_are_refused(corners: list[list[float]], needle: str) -> None:
    pallet = Pallet("tray", tuple("abcd"[: len(corners)]), rows=2, columns=2)
    with pytest.raises(InvalidInputError, match=needle):
        pallet.corner_poses(np.array(corners))


# ---------------------------------------------------------------------------------------------- the file
TRAY = """start: feeder
jump: {rise: !millimeters 30}
pallets:
  tray: {corners: [T11, T12, T21], rows: 2, columns: 2}
  stack: {corners: [T11, T12, T21], rows: 2, columns: 2, layers: 2, layer_height: !millimeters 20}
steps:
  - speed: 80
    accel: 60
  - for: tray
    order: columns
    do:
      - jump: tray[i]
        max_height: 0.0
      - dwell: 0.05
      - jump: feeder
  - speed: 50
  - for: 2
    var: k
    do:
      - go: stack[k]
  - move: home
"""


def test_a_job_expands_in_order_with_its_settings(robot_default: Robot, tmp_path: Path) -> None:
    job = Job.load(write_job(tmp_path, TRAY, robot_default))
    assert job.jump.rise == pytest.approx(0.030, abs=1e-15)  # the unit tag read
    assert job.pallets["stack"].layer_height == pytest.approx(0.020, abs=1e-15)
    assert job.actions == 4 * 3 + 2 + 1 and job.dwell == pytest.approx(4 * 0.05, abs=1e-15)
    program = job.program(robot_default)
    assert program.start == "feeder"
    labels = [(a.kind.value, a.target) if hasattr(a, "kind") else ("dwell", a.at) for a in program.actions]
    assert labels[:6] == [("jump", "tray[1]"), ("dwell", "tray[1]"), ("jump", "feeder"), ("jump", "tray[3]"),
                          ("dwell", "tray[3]"), ("jump", "feeder")]  # columns: 1, 3, 2, 4  # fmt: skip
    assert labels[-3:] == [("go", "stack[1]"), ("go", "stack[2]"), ("move", "home")]
    moves = [a for a in program.actions if hasattr(a, "kind")]
    assert {(m.speed, m.accel) for m in moves[:8]} == {(0.8, 0.6)}
    assert {(m.speed, m.accel) for m in moves[8:]} == {(0.5, 0.6)}
    assert moves[0].shape.max_height == 0.0 and moves[1].shape.max_height is None
    assert moves[0].shape.rise == pytest.approx(0.03, abs=1e-15)
    assert program.places == (("tray", 1), ("tray", 3), ("tray", 2), ("tray", 4), ("stack", 1), ("stack", 2))
    # each place's q: on its first corner's branch, at the pose of the grid written here from Pinocchio's FK
    fk = {n: robot_default.tool_pose(job.points[n].q) for n in ("T11", "T12", "T21")}
    for m in moves:
        if m.place is not None:
            pallet, i = m.place
            r, c = divmod(i - 1, 2)
            layer, r = divmod(r, 2)
            want = fk["T11"] + c * (fk["T12"] - fk["T11"]) + r * (fk["T21"] - fk["T11"])
            want[2] += 0.02 * layer if pallet == "stack" else 0.0
            assert robot_default.tool_pose(m.q) == pytest.approx(want, abs=1e-9)
            assert robot_default.branch_of(m.q) == robot_default.branch_of(job.points["T11"].q)


def test_the_start_defaults_to_the_first_target(robot_default: Robot, tmp_path: Path) -> None:
    job = Job.load(write_job(tmp_path, "steps:\n  - jump: home\n  - dwell: 0.1\n", robot_default))
    result = job.plan(robot_default)
    assert [s.planned for s in result.steps] == [Source.STILL.value, ""]
    assert result.total == pytest.approx(0.1, abs=1e-15) and result.steps[0].duration == 0.0


def test_the_pendant_records_pallet_corners_by_name(robot_default: Robot, tmp_path: Path) -> None:
    """A points file the teach pendant saved, its corners recorded by name, is what a job names."""
    file = tmp_path / "points.yaml"
    session = TeachSession(robot_default, points_file=file)
    taught = teach(robot_default)
    for point in taught:
        assert session.set_q(point.q).status == "OK"
        session.record(point.name)
    session.save_points()
    job_file = tmp_path / "job.yaml"
    job_file.write_text("points: points.yaml\npallets:\n  tray: {corners: [T11, T12, T21, T22], rows: 2, columns: 2}\n"
                        "steps:\n  - for: tray\n    do: [{go: 'tray[i]'}]\n")
    program = Job.load(job_file).program(robot_default)
    assert [a.target for a in program.actions] == ["tray[1]", "tray[2]", "tray[3]", "tray[4]"]
    for action, name in zip(program.actions, ("T11", "T12", "T21", "T22")):
        assert action.q == pytest.approx(taught[name].q, abs=1e-9)  # the corners are the taught points


def test_the_documented_example_is_the_issue_s_tray(robot_default: Robot) -> None:
    """docs/examples/tray: a feeder, three corners, 4 x 6 places, 50 ms dwells, a move home (planned by
    benchmarks/bench_job.py); its points are the default robot's (their poses are its FK)."""
    job = Job.load(Path(__file__).resolve().parents[1] / "docs" / "examples" / "tray" / "job.yaml")
    program = job.program(robot_default)
    assert len(program.actions) == job.actions == 4 * 24 + 1
    assert [p[1] for p in program.places] == list(range(1, 25))
    dwells = [a.seconds for a in program.actions if not hasattr(a, "kind")]
    assert dwells == [0.05] * 48


# ---------------------------------------------------------------------------------------------- refusals
def _steps(body: str) -> str:
    return "pallets:\n  tray: {corners: [T11, T12, T21], rows: 2, columns: 2}\nsteps:\n" + body


def _nested(depth: int) -> str:
    body, pad = "", "  "
    for level in range(depth):
        body += f"{pad}- for: 2\n{pad}  var: v{level}\n{pad}  do:\n"
        pad += "    "
    return _steps(body + f"{pad}- jump: feeder\n")


CARRY = "carry: {shape: box, size: [0.02, 0.03, 0.015], xyz: [0, 0, 0.0125]}\n"

REFUSED = [
    ("unknown point", _steps("  - jump: feeder\n  - jump: nowhere\n"), "jump: nowhere", "unknown point 'nowhere'"),
    ("past the end", _steps("  - jump: tray[5]\n"), "tray[5]", "index 5 is past the end of pallet tray (4 places"),
    ("variable past the end", _steps("  - for: 6\n    do:\n      - jump: tray[i]\n"), "tray[i]",
     "i runs to 6 (the for at line"),
    ("collinear", "pallets:\n  tray: {corners: [T11, T12, T13], rows: 2, columns: 2}\nsteps:\n  - jump: home\n",
     "tray:", None),
    ("nested too deep", _nested(MAX_JOB_DEPTH + 1), f"var: v{MAX_JOB_DEPTH}",
     f"nested {MAX_JOB_DEPTH + 1} deep, above the cap of {MAX_JOB_DEPTH}"),
    ("too many moves",
     _steps("  - for: 1000\n    do:\n      - for: 11\n        var: j\n        do: [{jump: feeder}]\n"), "- for: 1000",
     f"11,000 moves and dwells, above the cap of {MAX_JOB_STEPS:,}"),
    ("speed 0", _steps("  - speed: 0\n  - jump: feeder\n"), "speed: 0", "speed is 0 %; it must be in (0, 100]"),
    ("speed 150", _steps("  - speed: 150\n  - jump: feeder\n"), "speed: 150", "speed is 150 %"),
    ("accel not a number", _steps("  - accel: fast\n  - jump: feeder\n"), "accel: fast", "accel is 'fast'"),
    ("unknown step", _steps("  - jmup: feeder\n"), "jmup", "unknown step jmup"),
    ("two moves", _steps("  - {jump: feeder, go: home}\n"), "go: home", "one move per step"),
    ("order of a count", _steps("  - for: 2\n    order: rows\n    do: [{dwell: 1}]\n"), "order: rows",
     "order applies to a pallet"),
    ("same variable", _steps("  - for: tray\n    do:\n      - for: 2\n        do: [{go: 'tray[i]'}]\n"),
     "for: 2", "already the enclosing for's"),
    ("unknown variable", _steps("  - go: tray[j]\n"), "tray[j]", "j is no loop variable here"),
    ("a pallet without index", _steps("  - go: tray\n"), "go: tray", "tray is a pallet"),
    ("negative dwell", _steps("  - dwell: -1\n"), "dwell: -1", "dwell is -1 s; it must be >= 0"),
    ("unknown key", "step:\n  - jump: feeder\n", None, "unknown key(s) step"),
    ("not yaml", "steps: [jump: feeder\n", "steps:", "not valid YAML"),
    # palletizing: the gripper's steps and the part (docs/job.md, "Palletizing")
    ("pick without carry", _steps("  - jump: feeder\n  - pick: 0.1\n"), "pick: 0.1", "pick: needs the job's carry:"),
    ("carry without grips", CARRY + _steps("  - jump: feeder\n"), "carry:",
     "carry: is the part the tool holds from a pick: to a place:, and the steps have none"),
    ("place while empty", CARRY + _steps("  - jump: feeder\n  - place: 0.1\n"), "place: 0.1",
     "place: the tool holds no part here"),
    ("picked twice by a loop", CARRY + _steps("  - for: tray\n    do:\n      - pick: 0.1\n      - jump: tray[i]\n"),
     "pick: 0.1", "pick: the tool already holds the part picked at line "),
    ("pick and place in a step", CARRY + _steps("  - {pick: 0.1, place: 0.1}\n"), "pick: 0.1", "one grip per step"),
    ("negative pick", CARRY + _steps("  - pick: -1\n  - place: 0\n"), "pick: -1", "pick is -1 s; it must be >= 0"),
    ("carry not a box", "carry: {shape: cylinder, size: [0.02, 0.03, 0.015]}\n" + _steps("  - pick: 0\n"),
     "cylinder", "carry shape 'cylinder' is not one scara-pin knows (box)"),
    ("carry xyz of 2", "carry: {shape: box, size: [0.02, 0.03, 0.015], xyz: [0, 0]}\n" + _steps("  - pick: 0\n"),
     "xyz: [0, 0]", "xyz is 3 lengths [m]"),
    ("carry size 0", "carry: {shape: box, size: [0.02, 0, 0.015]}\n" + _steps("  - pick: 0\n"), "size:",
     "it must be > 0"),
]


@pytest.mark.parametrize(("case", "body", "needle", "reason"), REFUSED, ids=[c[0] for c in REFUSED])
def test_bad_jobs_are_exit_2_with_file_line_and_reason_before_any_planning(
    case: str, body: str, needle: str | None, reason: str | None, robot_default: Robot, tmp_path: Path,
    capsys: pytest.CaptureFixture[str], no_planning: None,
) -> None:  # fmt: skip
    job = write_job(tmp_path, body, robot_default)
    assert main(["job", str(job), "--out", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: {job}"), err
    if needle is not None:
        line = line_of(job, needle) if case != "not yaml" else 5  # the flow sequence left open, found at the end
        line -= case == "nested too deep"  # the for before its var
        assert err[0].startswith(f"error: {job} line {line}: "), err
    assert reason is None or reason in err[0], err
    if case == "collinear":
        assert "collinear" in err[0] and "pallet tray" in err[0]
    if case == "picked twice by a loop":  # the second pass of the loop finds the part of the first still held
        assert err[0].endswith(f"picked at line {line_of(job, 'pick: 0.1')} (a place: comes first)"), err
    assert not (tmp_path / "out.csv").exists()


def test_a_place_out_of_reach_is_exit_3_with_its_line_before_any_planning(
    robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str], no_planning: None
) -> None:  # fmt: skip
    """The 4th layer of a stack 0.05 m apart is at z = -0.10 + 0.15 = 0.05 m, above the quill's stroke (z <= 0)."""
    body = ("pallets:\n  stack: {corners: [T11, T12, T21], rows: 2, columns: 2, layers: 4, layer_height: 0.05}\n"
            "steps:\n  - jump: feeder\n  - go: stack[12]\n  - go: stack[13]\n")  # fmt: skip
    job = write_job(tmp_path, body, robot_default)
    assert main(["job", str(job)]) == 3
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'stack[13]')}: stack[13] at (x, y, z, yaw) = "
                          "(0.22, -0.06, 0.05, 0.5)") and "out of reach" in err, err


def test_the_cell_file_is_the_job_s_neighbour_and_is_sized(robot_default: Robot, tmp_path: Path) -> None:
    (tmp_path / "cells").mkdir()
    (tmp_path / "cells" / "cell.yaml").write_text("obstacles: []\n")
    job_file = write_job(tmp_path, "cell: cells/cell.yaml\ncarry: {shape: box, size: [0.2, 0.3, 0.15]}\n"
                         "steps:\n  - jump: feeder\n  - pick: 0.1\n  - jump: home\n  - place: 0\n",
                         robot_default)  # fmt: skip
    job = Job.load(job_file)
    assert job.cell == tmp_path / "cells" / "cell.yaml"  # relative to the job file
    assert job.carry is not None and job.carry.size == (0.2, 0.3, 0.15)
    assert job.carry.xyz == (0.0, 0.0, 0.075)  # by default the box's top face is on the flange face (z down)
    assert [type(s).__name__ for s in job.steps] == ["MotionStep", "Grip", "MotionStep", "Grip"]
    assert job.dwell == 0.1 and job.actions == 4  # a grip is a rest, counted with the dwells
    # the cell file is sized and must be a regular file
    job_file.write_text(job_file.read_text().replace("cells/cell.yaml", "cells"))
    with pytest.raises(JobFileError, match="not a regular file") as info:
        Job.load(job_file)
    assert info.value.line == line_of(job_file, "cell:")


@pytest.mark.parametrize(("cell", "reason"), [
    ("obstacles: []\ncarried: {shape: box, size: [0.01, 0.01, 0.01], xyz: [0, 0, 0.02]}\n",
     "gives a carried part too: in a job the part is the job's carry:"),
    ("obstacles:\n  - {name: box2, shape: sphere, radius: 0.01, xyz: [1, 1, 1]}\n",
     "has an obstacle named box2: box1, box2, ... name the boxes the job places"),
    ("obstacles:\n  - {name: post, shape: sphere, radius: -0.01, xyz: [1, 1, 1]}\n", "cell.yaml line 2: obstacle post"),
])  # fmt: skip
def test_a_cell_the_job_cannot_use_is_refused_before_any_planning(
    cell: str, reason: str, robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str],
    no_planning: None,
) -> None:  # fmt: skip
    (tmp_path / "cell.yaml").write_text(cell)
    job = write_job(tmp_path, "cell: cell.yaml\n" + CARRY + "steps:\n  - jump: feeder\n  - pick: 0.1\n  - jump: home\n"
                    "  - place: 0\n", robot_default)  # fmt: skip
    assert main(["job", str(job)]) == 2
    err = capsys.readouterr().err.strip()
    needle = "carry:" if "carried" in cell else "cell:"
    assert err.startswith(f"error: {job} line {line_of(job, needle)}: ") and reason in err, err


def test_more_boxes_than_a_cell_may_hold_are_refused_before_any_planning(
    robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str], no_planning: None
) -> None:  # fmt: skip
    from scara_pin.limits import MAX_CELL_OBSTACLES

    (tmp_path / "cell.yaml").write_text("obstacles:\n  - {name: post, shape: sphere, radius: 0.01, xyz: [1, 1, 1]}\n")
    body = (f"cell: cell.yaml\n{CARRY}steps:\n  - jump: feeder\n  - for: {MAX_CELL_OBSTACLES}\n    do: [{{pick: 0}}, "
            "{place: 0}]\n")  # fmt: skip
    job = write_job(tmp_path, body, robot_default)
    assert main(["job", str(job)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (f"error: {job} line {line_of(job, 'carry:')}: obstacles of the cell (its 1 and the "
                   f"{MAX_CELL_OBSTACLES} boxes the job places) would be {MAX_CELL_OBSTACLES + 1}, above the cap of "
                   f"{MAX_CELL_OBSTACLES}; split the job"), err  # fmt: skip


def test_another_robot_and_an_output_over_an_input_are_refused(robot_default: Robot, tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str],
                                                               no_planning: None) -> None:  # fmt: skip
    job = write_job(tmp_path, "steps:\n  - jump: feeder\n", robot_default)
    before = job.read_text()
    assert main(["job", str(job), "--out", str(job)]) == 2
    assert "it would be replaced" in capsys.readouterr().err and job.read_text() == before
    assert main(["job", str(job), "--out", str(tmp_path / "points.yaml")]) == 2  # the points file the job names
    assert "it would be replaced" in capsys.readouterr().err
    assert main(["job", str(job), "--out", str(tmp_path / "a.csv"), "--html", str(tmp_path / "." / "a.csv")]) == 2
    assert "one output would replace the other" in capsys.readouterr().err
    assert main(["job", str(job), "--robot", "s1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'robot:')}: the job is for robot 'default'"), err


def test_an_output_the_dwells_alone_make_too_long_is_refused_before_any_planning(
    robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str], no_planning: None
) -> None:  # fmt: skip
    job = write_job(tmp_path, "steps:\n  - jump: feeder\n  - for: 100\n    do: [{dwell: 10}]\n", robot_default)
    assert main(["job", str(job), "--out", str(tmp_path / "o.csv"), "--rate", "10000"]) == 2
    err = capsys.readouterr().err.strip()
    assert "samples of --out (at least the dwells' 1000 s at 10000 Hz) would be 1e+07, above the cap" in err, err


def test_the_job_file_is_sized_first(tmp_path: Path) -> None:
    from scara_pin.limits import MAX_JOB_BYTES

    big = tmp_path / "big.yaml"
    big.write_bytes(b"#" * (MAX_JOB_BYTES + 1))
    with pytest.raises(InvalidInputError, match=re.escape(f"above the cap of {MAX_JOB_BYTES:,}")):
        Job.load(big)
