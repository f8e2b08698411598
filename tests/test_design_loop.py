"""Issue 34: an integrator's design loop in seconds: pose points in frames, variants without edits, re-planning only
what changed, the steady state, output for the controller, short results.

Truth from independent routes:

- a job of pose points in a frame against the same job of joint points (the pendant's IK of the same poses, the
  frame applied by the test's own rotation): the same total to 1e-9 s;
- a frame moved 80 mm: every place of its pallet 80 mm further, by FK of the program's joint values;
- the cache: the planner's counts (moves planned, reversed, from the cache) of runs the test chooses, the total of
  a cached run equal to the planned one bit for bit, an entry corrupted on disk by the test;
- the steady state: the same job without its way out (a second file), whose total is one period;
- the ROS 2 bag: read back by a second reader (the ``mcap`` package and its ROS 2 decoder; a .db3 by ``sqlite3``
  and that decoder with the message definitions written here), against the CSV at the same rate.
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_job import POSES, write_job

from scara_pin import Robot
from scara_pin.cli import main
from scara_pin.job import Job, StepKind
from scara_pin.job.cache import PlanStore
from scara_pin.motion.trajectory import load_trajectory

YAW = 0.3
"""[rad] the tray frame's turn: the points in it are written in its own axes."""
FRAME = (0.22, -0.06, -0.10)
"""The tray frame's origin: the corner T11."""
STEPS = """start: feeder
pallets:
  tray: {corners: [T11, T12], rows: 1, columns: 2}
steps:
  - for: tray
    do:
      - jump: tray[i]
      - dwell: 0.05
      - jump: feeder
"""


def in_frame(name: str) -> list[float]:
    """The pose ``name`` of test_job's POSES in the tray frame [mm, deg]: the frame's inverse applied by hand."""
    x, y, z, yaw = POSES[name]
    dx, dy = x - FRAME[0], y - FRAME[1]
    c, s = math.cos(YAW), math.sin(YAW)
    return [1e3 * (c * dx + s * dy), 1e3 * (-s * dx + c * dy), 1e3 * (z - FRAME[2]), math.degrees(yaw - YAW)]


def pose_job(folder: Path, tail: str = STEPS) -> Path:
    """The job of pose points: the tray corners in the turned frame, the feeder in the world; mm and deg."""
    origin = ", ".join(repr(v * 1e3) for v in FRAME)
    lines = ["format: scara-pin job 1", "robot: default", "units: mm,deg", "frames:",
             f"  tray: {{xyz: [{origin}], yaw: {math.degrees(YAW)!r}}}", "poses:"]  # fmt: skip
    for name in ("T11", "T12"):
        x, y, z, yaw = in_frame(name)
        lines.append(f"  {name}: {{xyz: [{x!r}, {y!r}, {z!r}], yaw: {yaw!r}, hand: right, frame: tray}}")
    x, y, z, yaw = POSES["feeder"]
    lines.append(f"  feeder: {{xyz: [{x * 1e3!r}, {y * 1e3!r}, {z * 1e3!r}], yaw: {math.degrees(yaw)!r}, hand: right}}")
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "pose.yaml"
    path.write_text("\n".join(lines) + "\n" + tail)
    return path


@pytest.fixture
def planned(robot_default: Robot, tmp_path: Path) -> tuple[Job, object]:
    """The pose job planned once (in this test's own plan cache)."""
    job = Job.load(pose_job(tmp_path))
    return job, job.plan(robot_default)


def test_pose_points_in_a_frame_are_the_joint_points_job(robot_default: Robot, tmp_path: Path,
                                                         planned: tuple[Job, object]) -> None:  # fmt: skip
    job, result = planned
    (tmp_path / "joints").mkdir()
    joints = Job.load(write_job(tmp_path / "joints", STEPS, robot_default))  # the pendant's joint points
    alone = joints.plan(robot_default)
    assert abs(result.total - alone.total) <= 1e-9 and result.places == alone.places == 2  # type: ignore[attr-defined]
    assert [s.kind for s in result.steps] == [StepKind.JUMP, StepKind.DWELL, StepKind.JUMP] * 2  # type: ignore[attr-defined]
    # the frame moved 80 mm along the world's x: one call (or one option, --set frames.tray.xyz=[...])
    moved = job.with_frame("tray", xyz=[FRAME[0] * 1e3 + 80.0, FRAME[1] * 1e3, FRAME[2] * 1e3])
    before, after = job.program(robot_default), moved.program(robot_default)
    for a, b in zip(before.actions, after.actions):
        if getattr(a, "place", None) is not None:
            shift = robot_default.tool_pose(b.q) - robot_default.tool_pose(a.q)  # type: ignore[union-attr]
            assert np.allclose(shift, [0.08, 0.0, 0.0, 0.0], atol=1e-12)
        elif hasattr(a, "q"):
            assert np.array_equal(a.q, b.q)  # type: ignore[union-attr]  # the feeder is not in the frame


def test_an_unchanged_job_plans_nothing_and_a_moved_place_only_its_moves(
    robot_default: Robot, tmp_path: Path, planned: tuple[Job, object], caplog: pytest.LogCaptureFixture
) -> None:  # fmt: skip
    job, first = planned
    assert (first.stats.planned, first.stats.reversed, first.stats.cached) == (2, 2, 0)  # type: ignore[attr-defined]
    folder = PlanStore.default().folder
    assert folder is not None and stat.S_IMODE(folder.stat().st_mode) == 0o700
    entries = sorted(folder.iterdir())  # the job's four moves
    assert len(entries) == 4 and all(stat.S_IMODE(p.stat().st_mode) == 0o600 for p in entries)
    again = job.plan(robot_default)
    assert (again.stats.planned, again.stats.reversed, again.stats.cached) == (0, 0, 4)
    assert again.total == first.total  # type: ignore[attr-defined]  # bit for bit
    assert [s.binding for s in again.steps] == [s.binding for s in first.steps]  # type: ignore[attr-defined]
    csv_first, csv_again = tmp_path / "first.csv", tmp_path / "again.csv"
    first.trajectory.save(csv_first, kinds=robot_default.joint_kinds)  # type: ignore[attr-defined]
    again.trajectory.save(csv_again, kinds=robot_default.joint_kinds)  # sampled inside: rebuilt from the entries
    assert csv_first.read_bytes() == csv_again.read_bytes()
    # one place moved (the corner T12, 10 mm along the frame's y): only the moves to and from it are planned
    x, y, z, yaw = in_frame("T12")
    variant = job.replace({"poses.T12.xyz": [x, y + 10.0, z]})
    result = variant.plan(robot_default)
    assert (result.stats.planned, result.stats.reversed, result.stats.cached) == (1, 1, 2)
    assert "1 moves planned, 1 jumps reversed, 0 repeated, 2 from the cache" in result.table()
    # an entry corrupted on disk: detected by its digest, warned about, planned again and replaced
    data = bytearray(entries[0].read_bytes())
    data[-10] ^= 0x01
    entries[0].write_bytes(bytes(data))
    with caplog.at_level("WARNING"):
        healed = job.plan(robot_default)
    assert healed.total == first.total  # type: ignore[attr-defined]
    assert healed.stats.cached == 3 and healed.stats.planned + healed.stats.reversed == 1
    assert any("plan cache entry" in r.getMessage() and "digest" in r.getMessage() for r in caplog.records)
    assert job.plan(robot_default).stats.cached == 4  # the entry was replaced
    assert job.plan(robot_default, cache=False).stats.planned == 2  # --no-cache: everything planned again


def test_a_cached_job_runs_without_the_planners(robot_default: Robot, tmp_path: Path) -> None:
    """The rerun's time is the command's start: no planner is imported (CasADi, TOPP-RA, the jump's solver, SciPy's
    linear algebra), nor matplotlib (``import scara_pin`` itself imports Pinocchio and coal)."""
    job = pose_job(tmp_path)
    env = dict(os.environ, SCARA_PIN_CACHE_DIR=str(tmp_path / "cache"))
    script = ("import sys; from scara_pin.cli import main; code = main(sys.argv[1:]); "
              "print(sorted(m for m in ('casadi', 'toppra', 'scipy.linalg', 'scara_pin.motion.jump', 'matplotlib') "
              "if m in sys.modules)); sys.exit(code)")  # fmt: skip
    runs = [subprocess.run([sys.executable, "-c", script, "job", str(job)], capture_output=True, text=True,
                           env=env, timeout=600) for _ in range(2)]  # fmt: skip
    assert [r.returncode for r in runs] == [0, 0], runs[0].stderr
    assert "2 moves planned, 2 jumps reversed, 0 repeated, 0 from the cache" in runs[0].stdout
    assert "0 moves planned, 0 jumps reversed, 0 repeated, 4 from the cache" in runs[1].stdout
    assert runs[1].stdout.strip().splitlines()[-1] == "[]", runs[1].stdout
    assert runs[0].stdout.splitlines()[-3] == runs[1].stdout.splitlines()[-3]  # the same total


def test_the_steady_state_is_one_period_of_the_loop(robot_default: Robot, tmp_path: Path,
                                                    planned: tuple[Job, object]) -> None:  # fmt: skip
    job, result = planned
    home = STEPS + "  - jump: T11\n"  # a way out after the loop: in the total, not in the period
    with_home = Job.load(pose_job(tmp_path / "home", home)).plan(robot_default)
    assert with_home.total > result.total + 0.1  # type: ignore[attr-defined]
    assert with_home.period == result.total  # type: ignore[attr-defined]  # the loop alone is the other job
    assert with_home.steady_parts_per_hour == pytest.approx(3600.0 * 2 / result.total, rel=1e-15)  # type: ignore
    assert "steady    " in with_home.table() and with_home.to_dict()["steady_state"]["places"] == 2


def test_overrides_are_the_file_s_grammar(robot_default: Robot, tmp_path: Path, planned: tuple[Job, object],
                                          capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    job, _ = planned
    path = job.path
    slow = job.replace(speed=50, accel=80)
    assert {a.speed for a in slow.program(robot_default).actions if hasattr(a, "speed")} == {0.5}
    assert job.replace({"base.yaw": 0.0}).frames == job.frames  # the base where it was
    assert main(["job", str(path), "--speed", "150"]) == 2
    assert capsys.readouterr().err.strip() == (f"error: {path}: --speed: speed is 150 %; it must be in (0, 100] (a "
                                               "percentage of the robot's limits)")  # fmt: skip
    assert main(["job", str(path), "--set", "frames.tray.xyz=[1, 2]"]) == 2
    assert "--set frames.tray.xyz: xyz is 3 lengths [mm]" in capsys.readouterr().err
    assert main(["job", str(path), "--set", "frames.tray.yaw=!degrees 90x"]) == 2  # a unit tag on no number
    assert "--set frames.tray.yaw:" in capsys.readouterr().err
    assert main(["job", str(path), "--set", "robot=s1"]) == 3  # pose points are solved on the robot planning them
    err = capsys.readouterr().err  # s1 (0.2 m of reach) does not reach the tray: said with the point's name
    assert "point T11 at (x, y, z, yaw)" in err and "out of reach on the right branch" in err, err


def test_the_controller_outputs(robot_default: Robot, tmp_path: Path, planned: tuple[Job, object]) -> None:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    job, result = planned
    outs = {ext: tmp_path / f"job.{ext}" for ext in ("csv", "mcap", "db3")}
    setpoints = tmp_path / "setpoints.csv"
    for ext, out in outs.items():  # every move from the cache after the fixture's plan
        extra = ["--setpoints", str(setpoints), "--setpoint-rate", "250"] if ext == "csv" else []
        assert main(["job", str(job.path), "--out", str(out), "--rate", "1000", *extra]) == 0
    header = outs["csv"].read_text().splitlines()[0]
    assert header.startswith("t [s],q1 [rad],q2 [rad],q3 [m],q4 [rad],qd1 [rad/s],")
    assert header.endswith(",qdd3 [m/s^2],qdd4 [rad/s^2]")
    table = np.loadtxt(outs["csv"], delimiter=",", skiprows=1)
    assert load_trajectory(outs["csv"]).duration == pytest.approx(table[-1, 0], abs=1e-12)  # the reader takes it
    assert setpoints.read_text() == result.trajectory.setpoints(250.0).csv_text()  # type: ignore[attr-defined]
    # the bag, read back by the mcap package: one JointTrajectory, one JointState per sample, the URDF's names
    with outs["mcap"].open("rb") as handle:
        reader = make_reader(handle, decoder_factories=[DecoderFactory()])
        messages = [(channel.topic, message.log_time, decoded) for _, channel, message, decoded
                    in reader.iter_decoded_messages()]  # fmt: skip
    plans = [m for topic, _, m in messages if topic == "/joint_trajectory"]
    states = [(t, m) for topic, t, m in messages if topic == "/joint_states"]
    assert len(plans) == 1 and len(states) == len(table)
    names = list(robot_default.joint_names)
    assert list(plans[0].joint_names) == names and all(list(m.name) == names for _, m in states)
    points = plans[0].points
    got = np.array([[p.time_from_start.sec + p.time_from_start.nanosec * 1e-9, *p.positions, *p.velocities,
                     *p.accelerations] for p in points])  # fmt: skip
    assert got.shape == table.shape and np.max(np.abs(got - table)) <= 1e-12
    stamped = np.array([[m.header.stamp.sec + m.header.stamp.nanosec * 1e-9, *m.position, *m.velocity]
                        for _, m in states])  # fmt: skip
    assert np.max(np.abs(stamped - table[:, :9])) <= 1e-12
    assert [t for t, _ in states] == [round(v * 1e9) for v in table[:, 0]]
    # the .db3: its rows decoded by the same second reader, with the message definitions written here
    from mcap.records import Schema

    schema = Schema(id=1, data=JOINT_STATE.encode(), encoding="ros2msg", name="sensor_msgs/msg/JointState")
    decode = DecoderFactory().decoder_for("cdr", schema)
    assert decode is not None
    with sqlite3.connect(outs["db3"]) as db:
        rows = db.execute("SELECT m.timestamp, m.data FROM messages m JOIN topics t ON m.topic_id = t.id "
                          "WHERE t.name = '/joint_states' ORDER BY m.timestamp").fetchall()  # fmt: skip
    assert len(rows) == len(table)
    last = decode(rows[-1][1])
    assert list(last.name) == names and np.max(np.abs(np.array(last.position) - table[-1, 1:5])) <= 1e-12


JOINT_STATE = """std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""
"""sensor_msgs/msg/JointState as ROS 2 Humble and Jazzy define it (common_interfaces), written out here."""


def test_results_are_short_and_say_what_they_are(planned: tuple[Job, object]) -> None:
    _, result = planned
    text = repr(result)
    assert text.startswith("job       ") and "total     " in text and "planning  " in text
    assert len(text) < 2000 and text.count("\n") < 30
    assert result._repr_html_().startswith('<pre class="scara-pin-summary">')  # type: ignore[attr-defined]
    step = result.steps[0]  # type: ignore[attr-defined]
    assert repr(step).startswith("StepResult 1 (line ") and len(repr(step)) < 300
    assert step.kind is StepKind.JUMP and step.kind == "jump" and json.dumps(step.to_dict())
    assert repr(result.stats).startswith("2 moves planned")  # type: ignore[attr-defined]


def test_a_jerk_limit_is_planned_as_the_cycle_plans_it(robot_default: Robot, tmp_path: Path) -> None:
    """``jerk: 2000`` (the job's units: rad/s^3, m/s^3): the jump is ``jump_move(..., jerk=2000)`` alone."""
    from scara_pin.motion.jump import jump_move

    job = Job.load(write_job(tmp_path, "start: feeder\njerk: 2000\nsteps:\n  - jump: T11\n  - go: feeder\n",
                             robot_default))  # fmt: skip
    result = job.plan(robot_default)
    q0, q1 = (job.points.q_of(n) for n in ("feeder", "T11"))
    alone = jump_move(robot_default, robot_default.tool_pose(q0), robot_default.tool_pose(q1), start=q0, end=q1,
                      jerk=2000.0)  # fmt: skip
    step, go = result.steps
    assert abs(step.duration - alone.duration) <= 1e-9
    assert go.method == "joint path, jerk-limited time-optimal"  # verified at 10 kHz with the jerk limit
    assert any(b.quantity == "jerk" for b in step.binding)  # the jerk binds, and the table says it
    free = Job.load(write_job(tmp_path, "start: feeder\nsteps:\n  - jump: T11\n", robot_default)).plan(robot_default)
    assert step.duration > free.total + 1e-3  # the limit costs time


def test_the_job_picture_is_in_the_units_asked_and_its_labels_never_overlap(robot_default: Robot,
                                                                            tmp_path: Path) -> None:  # fmt: skip
    """A 3-row tray of 12 parts left as boxes (as a palletizing job's result): seen from the side, the rows stand in
    one line of sight; every label of both views keeps clear of every other, in mm as in m."""
    from scara_pin.cell import Cell, Obstacle, Shape
    from scara_pin.job.results import JobResult, PlacedBox, PlanningStats, StepResult
    from scara_pin.motion.polynomial import PolynomialPiece
    from scara_pin.motion.trajectory import Trajectory
    from scara_pin.units import HUMAN
    from scara_pin.viz.job import plot_job

    q = robot_default.ik_nearest(np.array([0.25, 0.0, -0.08, 0.0]), np.zeros(4))
    hold = Trajectory((PolynomialPiece(np.array([0.0, 1.0]), q[None, None, :]),))
    boxes = tuple(PlacedBox(f"box{k + 1}", 1, "tray", 1.0, Obstacle(f"box{k + 1}", Shape(
        "box", (0.02, 0.02, 0.01), np.array([0.22 + 0.03 * (k // 4), -0.05 + 0.03 * (k % 4), -0.12]), np.zeros(3))))
        for k in range(12))  # fmt: skip
    step = StepResult(1, 1, StepKind.DWELL, "tray", "tray", 0.0, 1.0, q=tuple(q))
    cell = Cell((Obstacle("post", Shape("cylinder", (0.01, 0.2), np.array([0.3, -0.2, -0.1]), np.zeros(3))),))
    result = JobResult(tmp_path / "job.yaml", "default", (step,), hold, 12, PlanningStats(), boxes, cell)
    files = {}
    for units in (None, HUMAN):
        path = tmp_path / f"job_{'si' if units is None else 'mm'}.png"
        fig = plot_job(result, path, robot=robot_default, **({} if units is None else {"units": units}))
        plan, side = fig.subfigs[0].axes
        renderer = fig.canvas.get_renderer()
        for ax in (plan, side):
            boxes_drawn = [t.get_window_extent(renderer) for t in ax.texts if t.get_text()]
            assert len(boxes_drawn) >= 2
            for i, a in enumerate(boxes_drawn):
                for b in boxes_drawn[i + 1 :]:
                    assert not a.overlaps(b), (ax.get_title(), [t.get_text() for t in ax.texts])
        assert plan.get_xlabel() == ("x [mm]" if units else "x [m]")
        files[units] = path.read_bytes()
        assert any(t.get_text().count(",") >= 2 for t in side.texts)  # the three rows' numbers in one label
    assert files[None] != files[HUMAN]


def test_moving_the_frame_is_one_option_and_the_page_opens_in_the_units_asked(
    robot_default: Robot, tmp_path: Path, planned: tuple[Job, object]
) -> None:  # fmt: skip
    from scara_pin.job import parse_override

    job, _ = planned
    x, y, z = (v * 1e3 for v in FRAME)
    option = Job.load(job.path, [parse_override(f"frames.tray.xyz=[{x + 80.0!r}, {y!r}, {z!r}]")])
    call = job.with_frame("tray", xyz=[x + 80.0, y, z])
    assert [getattr(a, "q", None) is not None and np.array_equal(a.q, b.q)  # type: ignore[union-attr]
            for a, b in zip(option.program(robot_default).actions, call.program(robot_default).actions)
            if hasattr(a, "q")] == [True] * 4  # fmt: skip
    for flags, opened in (([], "m"), (["--mm", "--deg"], "mm")):  # every move from the cache: no planning
        page = tmp_path / f"job{len(flags)}.html"
        assert main(["job", str(job.path), "--html", str(page), *flags]) == 0
        html = page.read_text()
        start = html.index(">", html.index('id="scara-data"')) + 1
        data = json.loads(html[start : html.index("</script>", start)])
        assert data["units"] == opened
        assert {item["text"] for item in data["labels"]} == {"tray[1]", "tray[2]", "feeder"}  # the poses reached


def test_the_pendant_records_either_form(robot_default: Robot, tmp_path: Path) -> None:
    from scara_pin.motion.points import PosePoint, read_points
    from scara_pin.viz.teach import TeachSession

    q = robot_default.ik_nearest(np.array([0.25, 0.1, -0.08, 7.0]), np.array([0.0, 0.0, 0.0, 6.0]))  # a wrist turn
    session = TeachSession(robot_default, q, points_file=tmp_path / "points.yaml")
    session.record("J")
    session.record("P", form="pose")
    session.save_points()
    points = read_points(tmp_path / "points.yaml", robot_default)
    pose = points["P"]
    assert isinstance(pose, PosePoint) and pose.hand == robot_default.branch_of(q) and pose.turns == 1
    assert np.allclose(pose.pose, robot_default.tool_pose(q), atol=1e-12)
    assert np.allclose(pose.solve(robot_default), q, atol=1e-12)  # its IK: the configuration recorded
    assert np.array_equal(points.q_of("J"), q)
    with pytest.raises(Exception, match="CSV points file holds joint points only"):
        session.save_points(tmp_path / "points.csv")
