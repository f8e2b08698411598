"""3-joint SCARAs (R, R, P; no wrist), issue 13: FK, IK of (x, y, z) with both branches, workspace, a trajectory,
view --html, and the CLI's exit codes and messages. Fixtures: tests/data/three_joint/ (continuous J1/J2 with the
prismatic joint last; a lifting column first).

Expected values come from the closed form written here from the fixtures' numbers (not from the package).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from scara_pin.cli import main
from scara_pin.errors import InvalidInputError
from scara_pin.kinematics.scara3_kinematics import Scara3Kinematics
from scara_pin.robots import load_robot
from scara_pin.workspace import workspace_of

DATA = Path(__file__).parent / "data" / "three_joint"
RRP = DATA / "arm3_rrp.urdf"
PRR = DATA / "arm3_prr.urdf"
TOL = 1e-9


def fk_rrp(q: np.ndarray) -> np.ndarray:
    """arm3_rrp.urdf by hand: shoulder at z 0.35, arm 1 (-0.3, 0, 0.02), arm 2 to the tool (-0.25, 0.02, -0.05),
    quill along -z; yaw = q1 + q2."""
    a, b = q[0], q[1]
    x = -0.3 * math.cos(a) + (-0.25 * math.cos(a + b) - 0.02 * math.sin(a + b))
    y = -0.3 * math.sin(a) + (-0.25 * math.sin(a + b) + 0.02 * math.cos(a + b))
    return np.array([x, y, 0.35 + 0.02 - 0.05 - q[2], math.remainder(a + b, 2 * math.pi)])


def fk_prr(q: np.ndarray) -> np.ndarray:
    """arm3_prr.urdf by hand: lift z 0.1 + q1, shoulder +0.2, arms along +y (0.35, then 0.3), tool 0.1 below."""
    a, b = q[1], q[2]
    x = -0.35 * math.sin(a) - 0.3 * math.sin(a + b)
    y = 0.35 * math.cos(a) + 0.3 * math.cos(a + b)
    return np.array([x, y, 0.1 + q[0] + 0.2 - 0.1, math.remainder(a + b, 2 * math.pi)])


CASES = {"rrp": (RRP, fk_rrp, np.array([-4.0, -4.0, 0.0]), np.array([4.0, 4.0, 0.2])),
         "prr": (PRR, fk_prr, np.array([0.0, -2.5, -2.6]), np.array([0.4, 2.5, 2.6]))}  # fmt: skip


@pytest.fixture(scope="module", params=list(CASES))
def case(request: pytest.FixtureRequest) -> tuple:
    path, fk, lo, hi = CASES[request.param]
    return load_robot(urdf=path), fk, lo, hi


def test_loaded_as_three_joints(case: tuple) -> None:
    robot = case[0]
    assert robot.dof == 3 and isinstance(robot.kinematics, Scara3Kinematics)


def test_fk_matches_the_closed_form_written_here(case: tuple) -> None:
    robot, fk, lo, hi = case
    for q in np.random.default_rng(3).uniform(lo, hi, size=(200, 3)):
        got = robot.tool_pose(q)
        want = fk(q)
        assert np.abs(got[:3] - want[:3]).max() <= 1e-12
        assert abs(math.remainder(got[3] - want[3], 2 * math.pi)) <= 1e-12


def test_ik_round_trips_with_both_branches(case: tuple) -> None:
    robot, fk, lo, hi = case
    both = 0
    for q in np.random.default_rng(4).uniform(lo, hi, size=(200, 3)):
        target = fk(q)[:3]
        res = robot.ik(target)
        assert res.success, res.message
        for s in res.solutions:
            assert s.q.shape == (3,) and np.abs(fk(s.q)[:3] - target).max() <= TOL
        assert min(s.distance(q) for s in res.solutions) <= TOL
        branches = {s.branch for s in res.solutions}
        both += branches == {"right", "left"}
        assert robot.branch_of(q) in branches
        near = robot.ik_nearest(target, q)
        assert np.abs(near - q).max() <= TOL
    assert both >= 100  # the mirror elbow fits most of the time


def test_batch(case: tuple) -> None:
    robot, fk, lo, hi = case
    Q = np.random.default_rng(5).uniform(lo, hi, size=(100, 3))
    T = np.array([fk(q)[:3] for q in Q])
    res = robot.ik_batch(T, Q)
    assert (res.status == 0).all() and res.q.shape == (100, 3)
    assert np.abs(res.q - Q).max() <= TOL
    with pytest.raises(InvalidInputError):
        robot.ik_batch(np.column_stack([T, np.zeros(100)]))  # no yaw


def test_a_yaw_is_refused(case: tuple) -> None:
    robot = case[0]
    with pytest.raises(InvalidInputError, match="X Y Z|x, y, z"):
        robot.ik([0.3, 0.2, 0.2, 0.5])


def test_workspace_area_against_monte_carlo(case: tuple) -> None:
    """Area of the plan region vs the fraction of random points the IK solves (brute force, seeded)."""
    robot, fk, lo, hi = case
    ws = workspace_of(robot)
    rng = np.random.default_rng(11)
    n, R = 40000, 0.7
    pts = rng.uniform(-R, R, size=(n, 2))
    z = fk(np.array(lo + hi) / 2)[2]
    inside = sum(robot.ik([p[0], p[1], z]).success for p in pts[:4000])
    area_mc = inside / 4000 * (2 * R) ** 2
    se = (2 * R) ** 2 * math.sqrt(0.25 / 4000)
    assert abs(ws.area - area_mc) <= 4 * se, (ws.area, area_mc)
    # and the region's own membership agrees with the IK on the same points
    agree = np.mean(ws.contains(pts[:4000]) == np.array([robot.ik([p[0], p[1], z]).success for p in pts[:4000]]))
    assert agree >= 0.999


# ------------------------------------------------------------------------------------------ CLI
def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_cli_fk_three_values(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["fk", "--urdf", str(RRP), "--json", "0.1", "0.2", "0.05"])
    assert rc == 0
    doc = json.loads(out)
    assert np.abs(np.array(doc["position"]) - fk_rrp(np.array([0.1, 0.2, 0.05]))[:3]).max() <= 1e-12
    rc, _, err = run(capsys, ["fk", "--urdf", str(RRP), "0.1", "0.2", "0.05", "0"])
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert rc == 2 and len(errors) == 1 and "must be 3 joint values" in errors[0] and "Traceback" not in err


def test_cli_ik_xyz_both_branches_and_yaw_refused(capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.4, 1.1, 0.07])
    target = fk_rrp(q)[:3]
    rc, out, err = run(capsys, ["ik", "--urdf", str(RRP), "--json", *map(repr, target.tolist())])
    assert rc == 0, err
    doc = json.loads(out)
    assert {s["branch"] for s in doc["solutions"]} == {"right", "left"}
    for s in doc["solutions"]:
        assert np.abs(fk_rrp(np.array(s["q"]))[:3] - target).max() <= TOL
    rc, out, err = run(capsys, ["ik", "--urdf", str(RRP), *map(repr, target.tolist()), "0.5"])
    assert rc == 2 and out == ""
    (line,) = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert "takes X Y Z for such an arm" in line and "no wrist" in line
    rc, out, err = run(capsys, ["ik", "--urdf", str(RRP), "9", "0", "0.2"])
    assert rc == 3 and "OUT_OF_REACH" in err


@pytest.mark.parametrize(
    "argv",
    [["validate-ik"], ["jog", "--from", "0", "0", "0", "0", "--direction", "1", "0", "0"],
     ["traj", "--from", "0", "0", "0", "--to", "1", "0.5", "0.1", "--linear"], ["cycle"]],
    ids=["validate-ik", "jog", "traj-linear", "cycle"],
)  # fmt: skip
def test_cli_commands_without_3_joint_support_refuse(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    rc, _, err = run(capsys, [argv[0], "--urdf", str(RRP), *argv[1:]])
    assert rc == 2, err
    lines = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1 and ("3 joints" in lines[0] or "expected 4" in lines[0]), err


def test_cli_workspace(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["workspace", "--urdf", str(PRR), "--json"])
    assert rc == 0
    assert json.loads(out)["workspace"]["area"] == pytest.approx(workspace_of(load_robot(urdf=PRR)).area)


def test_cli_trajectory_three_joints(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """TOPP-RA through a via point and a quintic: 3 columns, the ends hit, within the limits (checked here)."""
    out_csv = tmp_path / "t.csv"
    acc = ["--acceleration", "5", "5", "2"]
    rc, _, err = run(capsys, ["traj", "--urdf", str(RRP), "--from", "0", "0", "0", "--via", "0.5", "0.2", "0.05",
                              "--to", "1", "0.5", "0.1", "--out", str(out_csv), *acc])  # fmt: skip
    assert rc == 0, err
    lines = out_csv.read_text().splitlines()
    assert lines[0] == "t,q1,q2,q3,qd1,qd2,qd3,qdd1,qdd2,qdd3"
    table = np.array([[float(c) for c in ln.split(",")] for ln in lines[1:]])
    assert np.abs(table[0, 1:4]).max() <= 1e-12 and np.abs(table[-1, 1:4] - [1, 0.5, 0.1]).max() <= 1e-9
    vmax = np.array([3.0, 4.0, 0.5])  # the fixture's velocity limits
    assert (np.abs(table[:, 4:7]) <= vmax * (1 + 1e-6)).all()
    assert (np.abs(table[:, 7:10]) <= np.array([5, 5, 2]) * (1 + 1e-3)).all()
    rc, out, err = run(capsys, ["traj", "--urdf", str(RRP), "--from-pose", "0.3", "0.2", "0.2", "--to-pose", "0.2",
                                "-0.3", "0.25", "--duration", "3", "--json", *acc])  # fmt: skip
    assert rc == 0, err
    doc = json.loads(out)
    q_end = np.array(doc["samples"]["q"][-1]) if "samples" in doc else np.array(doc["q"][-1])
    assert np.abs(fk_rrp(q_end)[:3] - [0.2, -0.3, 0.25]).max() <= TOL


def test_cli_view_html(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    page = tmp_path / "arm3.html"
    rc, out, err = run(capsys, ["view", "--urdf", str(PRR), "--html", str(page), "--q", "0.1", "0.2", "0.3"])
    assert rc == 0, err
    text = page.read_text()
    assert text.startswith("<!DOCTYPE html>") or "<html" in text[:200]
    assert len(text) > 1000
    rc, _, err = run(capsys, ["view", "--urdf", str(PRR), "--html", str(page), "--q", "0.1", "0.2", "0.3", "0"])
    assert rc == 2 and "must be 3 joint values" in err


def test_four_values_are_refused_by_a_three_joint_robot() -> None:
    """The per-call paths never take a q of the wrong length (no value silently dropped)."""
    import scara_pin

    robot = scara_pin.load_urdf(Path(__file__).parent / "data" / "three_joint" / "arm3_rrp.urdf")
    for call in (robot.tool_placement, robot.task_jacobian, robot.tool_pose):
        with pytest.raises(scara_pin.ParameterError, match="3 numbers"):
            call(np.zeros(4))
