"""Fixed paths and goals checked first (issue 37, item 6; issue 35, class 6 "refused late").

Every fixed path (``move``, ``go``, ``traj --linear/--joint/--through``, whatever its time law) is followed in the
cell before any timing (:func:`scara_pin.motion.plan.check_fixed_path`: conservative advancement on coal's
distances), and every goal of a job, with its fixed paths, is checked before its first move is planned. A straight
move through a post was refused after 39 s (TOPP-RA, then the 10 kHz verifier), a job whose 10th place is in
collision planned 9 jumps first. Expected values come from closed forms written here (the default robot:
l1 = l2 = 0.2 m, tool z = -0.05 - q3, the flange a disc of radius 0.025 m about the tool's axis). The time of the
refusal against ``scara-pin fk 0 0 0 0`` is measured by ``benchmarks/bench_fixed_path.py``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cell import Cell, InCollisionError, Obstacle, Shape
from scara_pin.cli import main
from scara_pin.errors import InfeasibleError
from scara_pin.motion import plan as plan_module
from scara_pin.motion.plan import MotionRequest, check_fixed_path, plan_motion

REPO = Path(__file__).resolve().parents[1]
TRAY = REPO / "docs" / "examples" / "tray"
FROM = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
TO = FROM + np.array([0.0, 0.305, 0.0, 0.0])
MARGIN, R_POST, R_FLANGE = 0.002, 0.02, 0.025
POST_XY = np.array([0.29, 0.0])


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


@pytest.fixture()
def no_timing(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Any planning or timing (``_plan``: TOPP-RA, the trapezoid, the quintic) fails the test: the path's check comes
    first. The list records the calls."""
    calls: list[str] = []

    def refused(*args: object, **kwargs: object) -> None:
        calls.append("timed")
        raise AssertionError("the move was timed before its path was checked")

    monkeypatch.setattr(plan_module, "_plan", refused)
    return calls


def post_cell() -> Cell:
    post = Obstacle("post", Shape("cylinder", (R_POST, 0.6), np.array([*POST_XY, 0.0]), np.zeros(3)))
    return Cell((post,), MARGIN)


def scara_xyz(q: np.ndarray) -> np.ndarray:
    a, b = q[..., 0], q[..., 0] + q[..., 1]
    return np.stack([0.2 * np.cos(a) + 0.2 * np.cos(b), 0.2 * np.sin(a) + 0.2 * np.sin(b), -0.05 - q[..., 2]], -1)


def test_a_straight_line_through_a_post_is_refused_where_the_flange_first_reaches_the_margin(
        robot: sp.Robot, no_timing: list[str]) -> None:  # fmt: skip
    """The line x = 0.2609 m, y from -0.1525 to 0.1525 m: the flange's disc first comes to the margin where the
    tool's plan-view distance to the post's axis is r_post + r_flange + margin (a quadratic in the path parameter,
    the pose linear in it); the place named is the point between the two surfaces on the line of the axes."""
    with pytest.raises(InfeasibleError) as found:
        plan_motion(robot, MotionRequest(start_pose=FROM, end_pose=TO, linear=True, cell=post_cell()))
    message = str(found.value)
    reach = R_POST + R_FLANGE + MARGIN
    dx = POST_XY[0] - FROM[0]
    y_contact = POST_XY[1] - math.sqrt(reach**2 - dx**2)  # coming from negative y
    s = (y_contact - FROM[1]) / (TO[1] - FROM[1])
    away = np.array([FROM[0], y_contact]) - POST_XY
    mid = POST_XY + away / np.linalg.norm(away) * (R_POST + MARGIN / 2)
    assert f"the motion comes closer than the margin: flange - post at {s:.1%} of the path near " in message, message
    shown = [float(v) for v in re.search(r"near \(([-\d.]+), ([-\d.]+), ([-\d.]+)\) mm", message).groups()]  # type: ignore[union-attr]
    assert shown[:2] == pytest.approx(mid * 1e3, abs=0.06), (shown, mid)
    assert "found before any timing" in message and not no_timing


@pytest.mark.parametrize("variant", ["joint line", "quintic", "through a via", "jerk-limited"])
def test_a_joint_path_through_a_post_is_refused_before_any_timing(variant: str, robot: sp.Robot,
                                                                  no_timing: list[str]) -> None:  # fmt: skip
    """The joint line (trapezoid), the same line under a quintic law, a spline through a via, a jerk-limited law:
    one geometric path each, checked before its time law is made. That it does cross the post is checked here from
    the closed-form FK of 2001 points of the path."""
    q0, q1 = robot.ik_nearest(FROM, np.zeros(4)), robot.ik_nearest(TO, np.zeros(4))
    kwargs: dict[str, object] = {}
    if variant == "quintic":
        kwargs["duration"] = 2.0
    elif variant == "through a via":
        kwargs["vias"] = ((q0 + q1) / 2.0 + np.array([0.0, 0.0, 0.01, 0.0]),)
    elif variant == "jerk-limited":
        kwargs["jerk"] = (2000.0,) * 4
    request = MotionRequest(start_q=q0, end_q=q1, cell=post_cell(), **kwargs)  # type: ignore[arg-type]
    path = plan_module._fixed_path(robot, request)[0][0]
    xy = scara_xyz(path.evaluate(np.linspace(0.0, 1.0, 2001), 0)[0])[:, :2]
    assert np.linalg.norm(xy - POST_XY, axis=1).min() < R_POST + R_FLANGE  # the flange's disc overlaps the post
    with pytest.raises(InfeasibleError, match=r"the motion comes closer than the margin: \w+ - post at [\d.]+% of the "
                       r"path .* \(found before any timing\)"):  # fmt: skip
        plan_motion(robot, request)
    assert not no_timing


def test_an_end_in_collision_is_exit_2_before_any_timing(robot: sp.Robot, no_timing: list[str]) -> None:
    end = np.array([POST_XY[0], POST_XY[1], FROM[2], 0.0])  # the tool on the post's axis
    with pytest.raises(InCollisionError, match="the end is in collision: .* deep in post"):
        check_fixed_path(robot, MotionRequest(start_pose=FROM, end_pose=end, linear=True, cell=post_cell()))
    assert not no_timing


def test_a_clear_fixed_path_is_still_planned_and_verified(robot: sp.Robot) -> None:
    """The check does not refuse a path that keeps the margin: the plan's verified clearance is at least it."""
    far = Cell((Obstacle("post", Shape("cylinder", (R_POST, 0.6), np.array([0.5, 0.3, 0.0]), np.zeros(3))),), MARGIN)
    plan = plan_motion(robot, MotionRequest(start_pose=FROM, end_pose=TO, linear=True, cell=far))
    assert plan.clearance is not None and plan.clearance.distance >= MARGIN - 1e-9


def test_the_command_refuses_the_move_with_one_line_exit_3(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "post.yaml").write_text("margin: 0.002\nobstacles:\n  - {name: post, shape: cylinder, radius: 0.02, "
                                        "length: 0.6, xyz: [0.29, 0, 0]}\n")  # fmt: skip
    out = tmp_path / "t.csv"
    assert main(["traj", "--linear", "--cell", str(tmp_path / "post.yaml"), "--from-pose", *map(str, FROM),
                 "--to-pose", *map(str, TO), "--out", str(out)]) == 3  # fmt: skip
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: the motion comes closer than the margin: flange - post at ")
    assert not out.exists()


# --------------------------------------------------------------------------------------------- a job's goals
def tray_job(tmp: Path, cell: str, steps: str | None = None) -> Path:
    """The 4 x 6 tray of docs/examples/tray/job.yaml with ``cell:``; ``steps`` replaces its steps."""
    (tmp / "points.yaml").write_bytes((TRAY / "points.yaml").read_bytes())
    (tmp / "cell.yaml").write_text(cell)
    text = (TRAY / "job.yaml").read_text().replace("steps:", "cell: cell.yaml\nsteps:", 1)
    if steps is not None:
        text = text[: text.index("steps:")] + steps
    (tmp / "job.yaml").write_text(text)
    return tmp / "job.yaml"


def line_of(path: Path, needle: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if needle in line)


@pytest.fixture()
def no_jump(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """A jump planned fails the test (the job's goals are checked before any move is planned)."""
    import scara_pin.motion.jump as jump  # the job's planner imports jump_move from there when it plans a jump

    calls: list[str] = []

    def refused(*args: object, **kwargs: object) -> None:
        calls.append("jump")
        raise AssertionError("a jump was planned before the job's goals were checked")

    monkeypatch.setattr(jump, "jump_move", refused)
    return calls


def test_a_job_whose_10th_place_is_in_collision_is_refused_before_any_jump(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], no_jump: list[str]) -> None:  # fmt: skip
    """A pin 2 mm in radius whose top is 1 mm into the flange at tray[10] (row 2, column 4: (0.25, 0.03) m by the
    pallet's corners, z = -0.1 m): 3 mm from the flange at its neighbours, so only tray[10] is in collision."""
    u, v = (4 - 1) / 5, (2 - 1) / 3
    x, y = 0.22 + v * (0.31 - 0.22), -0.06 + u * (0.09 + 0.06)
    assert (x, y) == pytest.approx((0.25, 0.03))
    job = tray_job(tmp_path, f"margin: 0.002\nobstacles:\n  - {{name: pin, shape: cylinder, radius: 0.002, length: "
                             f"0.02, xyz: [{x!r}, {y!r}, -0.109]}}\n")  # fmt: skip
    assert main(["job", str(job)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'jump: tray[i]')}: jump feeder -> tray[10]: the goal "
                          "(tray[10]) is in collision: flange is 1 mm deep in pin"), err  # fmt: skip
    assert not no_jump


def test_a_jobs_straight_move_through_a_post_is_refused_before_any_jump(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], no_jump: list[str]) -> None:  # fmt: skip
    """The tray job's last step, a straight move from the feeder (0.05, -0.3) m home (0.3, 0) m, through a camera post
    on that line; its 48 jumps come first in the file and are not planned."""
    on_line = np.array([0.05, -0.3]) + 0.3 * np.array([0.25, 0.3])
    job = tray_job(tmp_path, f"margin: 0.002\nobstacles:\n  - {{name: camera, shape: cylinder, radius: 0.01, "
                             f"length: 0.4, xyz: [{float(on_line[0])!r}, {float(on_line[1])!r}, 0.0]}}\n")  # fmt: skip
    assert main(["job", str(job)]) == 3
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'move: home')}: move feeder -> home: the motion comes "
                          "closer than the margin: "), err  # fmt: skip
    assert "camera at " in err and "found before any timing" in err
    assert not no_jump
