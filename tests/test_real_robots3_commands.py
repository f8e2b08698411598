"""Real robots, round 3 (issue 29 items 5, 6, 8): cycle on robots as written, the file's names, messages.

Fixtures: ``tests/data/round3/rrrp_placeholders.urdf`` (an R R R P SCARA named J1..J4, effort 1 and mass
1 kg everywhere), the MG400-like tree, the shipped palletizer, and variants made here. Expected numbers are
computed here from the fixtures' written values (strokes, heights, masses) or taken from the Python API
on the same inputs (the command line must not change them).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from quirks import run, texts

from scara_pin import JointLimits, load_robot, robot_from_urdf
from scara_pin.errors import UrdfError
from scara_pin.lint import check_urdf_file
from scara_pin.motion.cycle import standard_cycle
from scara_pin.viz.cycle import plot_cycle

ROUND3 = Path(__file__).resolve().parent / "data" / "round3"
RRRP = ROUND3 / "rrrp_placeholders.urdf"
MG400 = ROUND3 / "mg400_like.urdf"
RGB = ROUND3 / "rgb_colours.urdf"
ACC = ["--acceleration", "20", "20", "40", "5"]  # a URDF has none


# ====================================================================== item 5: cycle on robots as written
def test_cycle_places_the_stroke_of_the_prismatic_joint_wherever_it_is(capsys: pytest.CaptureFixture[str]) -> None:
    """R R R P: the stroke is J4's, 0.716 m (not joint 3's 0 m); the default placement at mid-stroke height."""
    rc, out, err = run(capsys, ["cycle", "--urdf", str(RRRP), *ACC, "--no-torque", "--json"])
    assert rc == 0, err
    doc = json.loads(out)
    z_top, z_bottom = 0.9 - 0.05, 0.9 - 0.716 - 0.05  # J1's height, the tool 0.05 below the quill: J4 in [0, 0.716]
    assert doc["placement"]["from"][2] == pytest.approx((z_top + z_bottom) / 2 - 0.025 / 2, abs=1e-9)
    assert doc["torque"] is False and doc["joints"] == ["J1", "J2", "J3", "J4"]
    assert {leg["joint"] for leg in doc["legs"]} <= {"J1", "J2", "J3", "J4"}  # the file's names (item 6)
    assert {leg["active_limit"] for leg in doc["legs"]} <= {"velocity", "acceleration"}


def test_placeholder_efforts_stop_cycle_check_says_so_and_no_torque_runs(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["cycle", "--urdf", str(RRRP), *ACC])
    assert rc == 3 and out == ""
    assert err.startswith("error: the static load on J4 (-9.81) is not below its effort limit 1"), err
    (warning,) = check_urdf_file(RRRP).find("effort-limit")  # what check says before
    weight = 1.0 * 9.81  # the quill's 1 kg: what J4 holds (pinocchio's g = 9.81)
    assert warning.severity.value == "warning" and f"J4 reaches {weight:.4g} N" in warning.message
    assert "effort limit 1 N" in warning.message and "cycle --no-torque" in warning.message
    rc, out, err = run(capsys, ["cycle", "--urdf", str(RRRP), *ACC, "--no-torque"])
    assert rc == 0, err
    assert "effort limits left out (--no-torque): torques not checked" in out.splitlines()[0]
    assert " of J1 at " in out or " of J4 at " in out  # the legs name the file's joints
    assert "joint1" not in out and "joint4" not in out


def test_palletizer_cycle_from_the_command_line(capsys: pytest.CaptureFixture[str]) -> None:
    """--robot palletizer --from --direction: its branch names are up/down, not the SCARA's right/left."""
    pal = load_robot("palletizer")
    start = pal.tool_pose(np.array([0.0, 0.3, 1.6, 0.0]))
    rc, out, err = run(capsys, ["cycle", "--robot", "palletizer", "--from", *texts(start), "--direction", "0", "1",
                                "--json"])  # fmt: skip
    assert rc == 0, err
    doc = json.loads(out)
    api = standard_cycle(pal, start=start, direction=(0.0, 1.0))
    assert doc["cycle_time"] == pytest.approx(api.cycle_time, rel=1e-9)
    assert doc["cycle_time"] >= doc["lower_bound"]["duration"]
    traj = api.move.trajectory
    np.testing.assert_allclose(pal.tool_pose(traj.q_start), start, rtol=0, atol=1e-9)
    np.testing.assert_allclose(doc["placement"]["to"], start + [0.0, 0.305, 0.0, 0.0], rtol=0, atol=1e-12)
    assert pal.branch_of(traj.q_start) == "up"


# ====================================================================== item 6: the file's own names
def test_cycle_plot_and_messages_use_the_files_names_and_units(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot(urdf=RRRP)
    lim = robot.limits
    limits = JointLimits(lim.lower, lim.upper, lim.velocity, (20.0, 20.0, 40.0, 5.0), lim.effort, validate=False)
    result = standard_cycle(robot, torque=False, limits=limits)
    assert result.torque is False
    fig = plot_cycle(result, robot=robot, limits=limits)
    labels = {t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()}
    assert {"J1", "J2", "J3", "J4"} <= labels and not labels & {"joint1", "joint4"}
    assert all(leg.joint in robot.joint_names for leg in result.move.legs)
    # a warning in the units typed: palletizer joint3 is [10, 150] deg
    rc, out, err = run(capsys, ["fk", "--robot", "palletizer", "--mm", "--deg", "0", "0", "0", "0"])
    assert rc == 0 and "warning: joint3 = 0 deg outside [10, 150] deg" in err
    rc, out, err = run(capsys, ["workspace", "--urdf", str(RRRP)])
    assert rc == 0 and "(J4's stroke)" in out and "J3 stroke" not in out


def test_palletizer_messages_name_the_files_joints() -> None:
    robot = load_robot(urdf=MG400)
    res = robot.ik(robot.tool_pose(np.array([0.0, 0.2, 0.4, 0.0])), branch="up", reference=np.zeros(4))
    assert res.success
    far = robot.ik([0.05, 0.0, 0.5, 0.0])  # no configuration reaches it: the reason names no joint1..4
    assert not far.success and "joint2" not in far.message and "q2" not in far.message


# ====================================================================== item 8: messages
def test_check_tool_names_the_chains_joint_count_not_a_locked_joint(tmp_path: Path) -> None:
    """The MG400 with its parallelogram as free joints: --tool's chain has 6 of them; the rods are locked."""
    path = tmp_path / "mg400_free.urdf"
    path.write_text("".join(line for line in MG400.read_text().splitlines(keepends=True) if "<mimic" not in line))
    report = check_urdf_file(path, tool="mg400_end_effector_shaft")
    assert not report.find("not-serial")
    (f,) = report.find("joint-count")
    assert "the chain base_link -> mg400_end_effector_shaft has 6 free joints" in f.message
    assert "3 joint(s) off the chain are locked, not counted" in f.message
    for locked in ("mg400_j2_2", "mg400_j3_2", "mg400_j4_2"):
        assert locked not in f.message


def test_cycle_on_an_arm_without_a_vertical_stroke_gives_the_real_reason(capsys: pytest.CaptureFixture[str]) -> None:
    path = Path(__file__).resolve().parent / "data" / "quirks" / "palletizer_without_mimic.urdf"
    rc, out, cycle_err = run(capsys, ["cycle", "--urdf", str(path), "--acceleration", "10", "10", "10", "10"])
    assert rc == 2 and "stroke" not in cycle_err and "span" not in cycle_err
    rc, out, workspace_err = run(capsys, ["workspace", "--urdf", str(path)])
    assert rc == 2 and cycle_err == workspace_err and "not recognised as a palletizer" in cycle_err


def test_an_arm_without_length_is_named() -> None:
    text = RGB.read_text().replace('<origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>',
                                   '<origin xyz="0 0 0.02" rpy="0 0 0"/><axis xyz="0 0 1"/>')  # fmt: skip
    with pytest.raises(UrdfError, match=r"arm 1 \(shoulder to elbow\) has no length in plan view"):
        _ = robot_from_urdf(text).kinematics


def test_pages_start_inside_the_limits(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A quill whose stroke starts at 10 mm: the page's slider starts there (q = 0 is outside), as does teach."""
    from test_viz import page_data

    from scara_pin.viz.meshcat import static_html

    text = RGB.read_text().replace('<limit lower="0" upper="0.2"', '<limit lower="0.01" upper="0.2"')
    robot = robot_from_urdf(text)
    assert robot.default_q.tolist() == [0.0, 0.0, 0.01, 0.0]
    data = page_data(static_html(robot))
    assert data["q"] == [0.0, 0.0, 0.01, 0.0]
    (slider,) = [s for s in data["sliders"] if s["name"] == "lift"]
    assert slider["lower"] <= data["q"][slider["index"]] <= slider["upper"]
    assert math.isclose(robot.tool_pose(robot.default_q)[2], 0.35 - 0.01, abs_tol=1e-12)
