"""Taught points: the points file (YAML and CSV) and its use as waypoints by ``traj`` and ``cycle``.

Truth from independent routes: Pinocchio's FK computed here (frame placements) for the poses; the
trajectory the command planned, sampled and minimised here (scipy's bounded scalar minimiser), for "reaches
each point"; the hand-written files' values converted here with ``math.radians``.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pendant_page import pin_pose
from scipy.optimize import minimize_scalar

from scara_pin import InvalidInputError, Robot
from scara_pin.cli import main
from scara_pin.limits import MAX_POINTS
from scara_pin.motion import plan as plan_module
from scara_pin.motion.points import PointSet, TaughtPoint, read_points, write_points

Q_S1 = np.array([0.3, 0.9, 0.02, -0.5])


def taught(robot: Robot, rng: np.random.Generator, n: int) -> PointSet:
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    points = PointSet(robot=robot.name, base=robot.base_frame, tool=robot.tool_frame)
    for i in range(n):
        points = points.added(TaughtPoint.at(robot, f"P{i + 1}", rng.uniform(lo, hi)))
    return points


@pytest.mark.parametrize("suffix", [".yaml", ".csv"])
def test_points_round_trip_bit_for_bit(robot_s1: Robot, tmp_path: Path, suffix: str) -> None:
    points = taught(robot_s1, np.random.default_rng(5), 6).renamed("P3", "pick_3").removed("P5")
    path = write_points(tmp_path / f"cell{suffix}", points)
    back = read_points(path, robot_s1)
    assert back.names == ("P1", "P2", "pick_3", "P4", "P6")
    assert (back.robot, back.base, back.tool) == ("s1", "base", "tool0")
    for a, b in zip(points, back, strict=True):
        np.testing.assert_array_equal(a.q, b.q)
        np.testing.assert_array_equal(a.pose, b.pose)
        np.testing.assert_allclose(b.pose, pin_pose(robot_s1, b.q), rtol=0, atol=1e-12)
    assert points.next_name() == "P3"


def test_a_hand_written_yaml_file_with_unit_tags(robot_s1: Robot, tmp_path: Path) -> None:
    path = tmp_path / "hand.yml"
    path.write_text("points:\n- name: home\n  q: [!degrees 30, !degrees -45, !millimeters 20, 0]\n"
                    "- {name: P2, q: [0.1, 0.2, 0.03, 0.4]}\n")  # fmt: skip
    points = read_points(path, robot_s1)
    np.testing.assert_array_equal(points["home"].q, [math.radians(30), math.radians(-45), 0.02, 0.0])
    assert points["home"].pose is None and points.names == ("home", "P2")


BAD = [
    ("cell.yaml", "points:\n- name: 1P\n  q: [0, 0, 0, 0]\n", "point name '1P'"),
    ("cell.yaml", "points:\n- {name: P1, q: [0, 0, 0, 0]}\n- {name: P1, q: [0, 0, 0, 0]}\n", "used twice"),
    ("cell.yaml", "points:\n- {name: P1, q: [0, .nan, 0, 0]}\n", "finite"),
    ("cell.yaml", "points:\n- {name: P1, q: [0, true, 0, 0]}\n", "numbers"),
    ("cell.yaml", "points:\n- {name: P1, q: [0, !degrees ten, 0, 0]}\n", "numbers"),
    ("cell.yaml", "points:\n- {name: P1, q: [0, !degrees 1_0, 0, 0]}\n", "not a plain number"),
    ("cell.yaml", "points:\n- {name: [" + ", ".join(["1"] * 10_000) + "], q: [0, 0, 0, 0]}\n",
     r"line 2: point name \[1, 1, 1, 1, 1, 1, \.\.\.\] must"),  # a big value: shown briefly
    ("cell.yaml", "points:\n- {name: P1}\n", "name and q"),
    ("cell.yaml", "points:\n- {name: P1, q: [0, 0, 0, 0], speed: 3}\n", "unknown key"),
    ("cell.yaml", "format: other 2\npoints: []\n", "format"),
    ("cell.yaml", "points: [\n", "not valid YAML"),
    ("cell.yaml", "points:\n- {name: P1, q: [0.3, 0.9, 0.02, -0.5], pose: [0.2, 0.15, 0.08, 0.7]}\n", "not the FK"),
    ("cell.csv", "name,q1,q2,q3,q4\nP1,0,0,0,nan\n", "not a plain finite number"),
    ("cell.csv", "name,q1,q2,q3,q4\nP1,0,0,0,1_000\n", "not a plain finite number"),
    ("cell.csv", "name,a,b,c,d\nP1,0,0,0,0\n", "header"),
    ("cell.csv", "name,q1,q2,q3,q4\nP1,0,0,0\n", "4 cells"),
    ("cell.csv", "# only a comment\n", "no header"),
    ("cell.txt", "points: []\n", "must end in .yaml"),
]


@pytest.mark.parametrize(("name", "text", "match"), BAD, ids=[f"{i}-{b[2][:14]}" for i, b in enumerate(BAD)])
def test_malformed_points_files_are_refused_naming_the_fault(
    robot_s1: Robot, tmp_path: Path, name: str, text: str, match: str
) -> None:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(InvalidInputError, match=match):
        read_points(path, robot_s1)


def test_points_of_another_robot_and_too_many_points_are_refused(
    robot_s1: Robot, robot_default: Robot, tmp_path: Path
) -> None:
    path = write_points(tmp_path / "s1.yaml", taught(robot_s1, np.random.default_rng(2), 2))
    with pytest.raises(InvalidInputError, match=r"not the FK of its q on robot 'default'.*taught on 's1'"):
        read_points(path, robot_default)
    many = tmp_path / "many.csv"
    many.write_text("name,q1,q2,q3,q4\n" + "".join(f"P{i},0,0,0,0\n" for i in range(MAX_POINTS + 1)))
    with pytest.raises(InvalidInputError, match="above the cap"):
        read_points(many)


# ------------------------------------------------------------------------------------------ traj and cycle
@pytest.fixture
def plans(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """The motion plans ``traj`` makes (the command's own trajectory objects, for sampling here)."""
    made: list[Any] = []
    real = plan_module.plan_motion

    def spy(robot: Robot, request: Any) -> Any:
        made.append(real(robot, request))
        return made[-1]

    monkeypatch.setattr(plan_module, "plan_motion", spy)
    return made


def closest(robot: Robot, traj: Any, position: np.ndarray) -> float:
    """The least distance [m] from ``position`` to the tool along ``traj``: the best 1 kHz sample, then a bounded
    scalar minimisation of the distance around it (scipy, to 1e-14 s)."""
    t = traj.times(1000.0)
    d = [np.linalg.norm(pin_pose(robot, q)[:3] - position) for q in traj.sample(t)[0]]
    k = int(np.argmin(d))
    res = minimize_scalar(lambda s: np.linalg.norm(pin_pose(robot, traj.sample(s)[0])[:3] - position),
                          bounds=(t[max(k - 1, 0)], t[min(k + 1, len(t) - 1)]), method="bounded",
                          options={"xatol": 1e-14})  # fmt: skip
    return float(min(res.fun, d[k]))


@pytest.mark.parametrize("extra", [[], ["--linear"], ["--deg", "--mm", "--duration", "2"]], ids=str)
def test_traj_through_taught_points_reaches_each(
    robot_s1: Robot, tmp_path: Path, plans: list[Any], capsys: pytest.CaptureFixture[str], extra: list[str]
) -> None:
    lo, hi = robot_s1.tool_pose(Q_S1), np.array([0.01, -0.01, 0.005, 0.2])
    points = PointSet(robot="s1")
    for i, pose in enumerate((lo, lo + hi, lo + 2 * hi)):  # a straight line is feasible between these
        points = points.added(TaughtPoint.at(robot_s1, f"P{i + 1}", robot_s1.ik_nearest(pose, Q_S1)))
    path = write_points(tmp_path / "cell.csv", points)
    assert main(["traj", "--robot", "s1", "--points", str(path), "--through", "P1", "P2", "P3", *extra]) == 0
    traj = plans[-1].trajectory
    np.testing.assert_allclose(traj.q_start, points["P1"].q, rtol=0, atol=1e-12)  # the taught branch and turn
    np.testing.assert_allclose(traj.q_end, points["P3"].q, rtol=0, atol=1e-12)
    for p in points:
        assert closest(robot_s1, traj, pin_pose(robot_s1, p.q)[:3]) < 1e-9, p.name
    capsys.readouterr()


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["--through", "P1", "P2"], "--through needs --points"),
        (["--points", "{f}"], "at least two point names"),
        (["--points", "{f}", "--through", "P1", "P2", "--from", "0", "0", "0", "0"], "replaces --from"),
        (["--points", "{f}", "--through", "P1", "nowhere"], "no point named 'nowhere' .points: P1, P2"),
    ],
)
def test_traj_points_misuse_is_exit_2(
    robot_s1: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str], argv: list[str], match: str
) -> None:
    path = write_points(tmp_path / "cell.yaml", taught(robot_s1, np.random.default_rng(1), 2))
    code = main(["traj", "--robot", "s1", *(a.replace("{f}", str(path)) for a in argv)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and err.startswith("error: ")
    assert re.search(match, err), err


def test_cycle_between_two_taught_points(robot_s1: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    a = robot_s1.tool_pose(Q_S1)
    b = a + np.array([-0.02, 0.015, 0.0, 0.0])
    c = a + np.array([0.0, 0.0, 0.01, 0.0])
    points = PointSet(robot="s1")
    for name, pose in (("A", a), ("B", b), ("C", c)):
        points = points.added(TaughtPoint.at(robot_s1, name, robot_s1.ik_nearest(pose, Q_S1)))
    path = write_points(tmp_path / "cell.yaml", points)
    assert main(["cycle", "--robot", "s1", "--points", str(path), "--from-point", "A", "--to-point", "B",
                 "--rise", "0.01", "--json"]) == 0  # fmt: skip
    out = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(out["placement"]["from"], pin_pose(robot_s1, points["A"].q), rtol=0, atol=1e-12)
    np.testing.assert_allclose(out["placement"]["to"], pin_pose(robot_s1, points["B"].q), rtol=0, atol=1e-12)
    for argv, match in ((["--from-point", "A", "--to-point", "C"], "share one height"),
                        (["--from-point", "A", "--to-point", "B", "--span", "0.1"], "replace --span"),
                        (["--from-point", "A"], "--to-point NAME")):  # fmt: skip
        assert main(["cycle", "--robot", "s1", "--points", str(path), *argv]) == 2
        err = capsys.readouterr().err
        assert match in err and err.count("\n") == 1, err


# ------------------------------------------------------------------------------------ issue 30 item 7: numbers
def test_values_in_exponent_notation_read_back(robot_s1: Robot, tmp_path: Path) -> None:
    """repr() writes 1e-05 and -2.5e-07; YAML 1.1 reads those as text (no decimal point), so such a file did not
    read back. The points file's numbers follow the command line's grammar, where they are numbers."""
    q = np.array([1e-05, -2.5e-07, 0.02, 1e-300])
    points = PointSet((TaughtPoint.at(robot_s1, "P1", q),))
    path = write_points(tmp_path / "cell.yaml", points)
    assert "1e-05" in path.read_text()
    back = read_points(path, robot_s1)
    np.testing.assert_array_equal(back["P1"].q, q)
    np.testing.assert_array_equal(back["P1"].pose, points["P1"].pose)


@pytest.mark.parametrize("text", ["0x1", "0b0", "0_1", "0:0.5", "0o7", "1_000.5", "'0.5'", "\uff11", "0.5.1"])
def test_yaml_numbers_outside_the_grammar_are_refused(robot_s1: Robot, tmp_path: Path, text: str) -> None:
    path = tmp_path / "cell.yaml"
    path.write_text(f"points:\n- name: P1\n  q: [0.3, {text}, 0.02, -0.5]\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match=r"line 3: point P1: q must be a list of finite numbers; value 2 is "
                       r".*not a plain number"):  # fmt: skip
        read_points(path, robot_s1)
