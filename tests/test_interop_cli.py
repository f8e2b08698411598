"""`scara-pin urdf --dh` and `scara-pin check`: D-H tables in, third-party URDFs linted (exit 0 / 4 / 2)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cli import main
from scara_pin.description.dh import dh_example

THIRD_PARTY = Path(__file__).resolve().parent / "data" / "third_party"


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def dh_standard(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]])


def test_urdf_from_the_s1_dh_table_matches_the_dh_product(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "s1.urdf"
    rc, _, err = run(capsys, ["urdf", "--dh", str(dh_example("s1_dh")), "-o", str(out)])
    assert rc == 0, err
    robot = sp.load_robot(urdf=out)
    rng = np.random.default_rng(7)
    d1, l1, l2 = 0.100, 0.050, 0.150  # S1's table (digest S1)
    for _ in range(200):
        q = rng.uniform(-1, 1, 4) * np.array([2.5, 2.5, 0.05, 3.0]) + np.array([0, 0, 0.05, 0])
        T = (dh_standard(q[0], d1, l1, 0) @ dh_standard(q[1], 0, l2, math.pi) @ dh_standard(0, q[2], 0, 0)
             @ dh_standard(q[3], 0, 0, 0))  # fmt: skip
        M = robot.frame_placement(q, robot.tool_frame)
        assert np.abs(M.translation - T[:3, 3]).max() < 1e-12
        assert np.abs(M.rotation - T[:3, :3]).max() < 1e-12


def test_urdf_dh_refuses_a_bad_table_and_other_options(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(dh_example("s1_dh").read_text().replace("convention: standard", "convention: sideways"))
    rc, _, err = run(capsys, ["urdf", "--dh", str(bad), "-o", str(tmp_path / "x.urdf")])
    assert rc == 2 and err.startswith("error:") and "convention" in err
    assert not (tmp_path / "x.urdf").exists()
    rc, _, err = run(capsys, ["urdf", "--dh", str(dh_example("s1_dh")), "--set", "l1=0.3"])
    assert rc == 2 and "--dh" in err


@pytest.mark.parametrize(
    ("name", "code", "status"),
    [
        ("yk400xe_like.urdf", 4, "warnings"),
        ("kr5_scara_dh.urdf", 4, "warnings"),
        ("ros_rrp_tutorial.urdf", 4, "warnings"),  # 3 joints (no wrist), rpy 3.14: usable
    ],
)
def test_check_exit_codes_and_json(capsys: pytest.CaptureFixture[str], name: str, code: int, status: str) -> None:
    rc, out, err = run(capsys, ["check", "--json", str(THIRD_PARTY / name)])
    assert rc == code, err
    doc = json.loads(out)
    assert doc["status"] == status
    assert doc["findings"] and all({"severity", "code", "message"} <= set(f) for f in doc["findings"])


def test_check_a_generated_robot_is_clean(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    path = tmp_path / "default.urdf"
    path.write_text(sp.generate_urdf("default"))
    rc, out, _ = run(capsys, ["check", str(path)])
    assert rc == 0 and out.rstrip().endswith("clean")


def test_check_reports_the_rpy_approximation_with_its_line(capsys: pytest.CaptureFixture[str]) -> None:
    path = THIRD_PARTY / "ros_rrp_tutorial.urdf"
    rc, out, _ = run(capsys, ["check", str(path)])
    lines = [ln for ln in out.splitlines() if "[rpy-approximate]" in ln]
    assert lines, out
    number = int(lines[0].split(":")[1])
    assert "3.14" in path.read_text().splitlines()[number - 1]  # the line named holds the approximation


def test_human_units_follow_the_joint_kinds_of_the_urdf(capsys: pytest.CaptureFixture[str]) -> None:
    """A SCARA that lifts its whole arm has the prismatic joint FIRST: --deg/--mm must scale q1 as a length
    and q4 as an angle (same pose as the SI call)."""
    path = THIRD_PARTY / "irb920_like.urdf"
    robot = sp.load_robot(urdf=path)
    assert robot.joint_kinds == ("length", "angle", "angle", "angle")
    q_si = [0.05, 0.3, 0.4, -0.5]
    rc, out_si, err = run(capsys, ["fk", "--json", "--urdf", str(path), *map(str, q_si)])
    assert rc == 0, err
    q_human = [q_si[0] * 1000, *(math.degrees(v) for v in q_si[1:])]
    rc, out_h, err = run(capsys, ["fk", "--json", "--deg", "--mm", "--urdf", str(path), *map(str, q_human)])
    assert rc == 0, err
    si, human = json.loads(out_si), json.loads(out_h)  # JSON is always SI: the same answer
    assert np.allclose(human["position"], si["position"], atol=1e-12)
    assert human["yaw"] == pytest.approx(si["yaw"], abs=1e-12)
    assert human["q"] == pytest.approx(q_si, abs=1e-12)
    # and IK reads its target in the same units (the lift in mm), answering in SI
    target = [*(v * 1000 for v in si["position"]), math.degrees(si["yaw"])]
    rc, out, err = run(capsys, ["ik", "--json", "--deg", "--mm", "--urdf", str(path), *map(str, target)])
    assert rc == 0, err
    qs = [s["q"] for s in json.loads(out)["solutions"]]
    assert any(np.allclose(q, q_si, atol=1e-9) for q in qs), qs
