"""Real robots, round 4 (issue 39): every real file usable as written.

Fixtures in ``tests/data/round4`` were written for these tests, shaped like the public descriptions the issue
tried (never copied): the MG400-like and duAro-like trees of earlier rounds drawn with ``<material name="">``
(items 1), a vendor's small SCARA whose gripper's second jaw is a ``<mimic>`` of the first, both on the last
arm link, named so that Pinocchio meets the mimic first (item 2), an LS3-like SCARA exported for PyBullet
(meshes named ``/Mesh/Visual/Base.stl``, a continuous J4 without ``<limit>``: items 3 and 5), a lab R P R R
SCARA whose 0.03 m/s lead-screw lift is read from a yaml file, a xacro file of macros only, a 2-joint
"palletizer" (item 4), a file with inverted limits and the shipped palletizer with joint2 continuous (item 6).

Truth from independent routes: each arm's forward kinematics written here from the fixture's numbers,
Pinocchio's own ``buildModelFromUrdf`` / ``buildGeomFromUrdf``, a grid of the plane tested against the
two-link closed form written here for the workspace area, and the shipped palletizer for its variant.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from quirks import assert_pose, run, texts

from scara_pin import load_robot
from scara_pin.cell.meshes import visual_meshes
from scara_pin.errors import UrdfError
from scara_pin.lint import check_urdf_file

DATA = Path(__file__).resolve().parent / "data"
ROUND4 = DATA / "round4"
GRIPPER = ROUND4 / "vendor_gripper_scara.urdf"
MG400 = ROUND4 / "mg400_empty_material.urdf"
DUARO = ROUND4 / "duaro_empty_material.urdf"
LS3 = ROUND4 / "ls3_like" / "ls3_like.urdf"
LAB = ROUND4 / "rprr_lab_description" / "urdf" / "rprr_lab.urdf.xacro"
MACROS = ROUND4 / "macros_only.urdf.xacro"
TWO_JOINTS = ROUND4 / "two_joint_palletizer.urdf"
PALLETIZER_J2 = ROUND4 / "palletizer_j2_continuous.urdf"
ACC = ["--acceleration", "20", "30", "5", "60"]
RNG_SEED = 39


def gripper_pose(q: np.ndarray) -> np.ndarray:
    """The vendor SCARA: J1 at 0.2 m, arms 0.2 and 0.15 m (arm 2 0.04 m higher), the quill q3 down from there, the
    hand 0.03 m below the quill's end."""
    q1, q2, q3, q4 = q
    return np.array([0.2 * np.cos(q1) + 0.15 * np.cos(q1 + q2), 0.2 * np.sin(q1) + 0.15 * np.sin(q1 + q2),
                     0.2 + 0.04 - q3 - 0.03, q1 + q2 + q4])  # fmt: skip


def duaro_upper_pose(q: np.ndarray) -> np.ndarray:
    """The duAro-like upper arm: J1 at 0.9 m, arms 0.4 and 0.36 m, the quill down by q3, J4 0.08 m below."""
    q1, q2, q3, q4 = q
    return np.array([0.4 * np.cos(q1) + 0.36 * np.cos(q1 + q2), 0.4 * np.sin(q1) + 0.36 * np.sin(q1 + q2),
                     0.9 - q3 - 0.08, q1 + q2 + q4])  # fmt: skip


def samples(robot, n: int = 20) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Seeded configurations inside the joint limits (continuous joints: one turn)."""
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    return np.random.default_rng(RNG_SEED).uniform(lo, hi, (n, robot.dof))


def pinocchio_loads(path: Path) -> tuple[pin.Model, int, int]:
    """Pinocchio's own parsers on the file: the model, its visual and collision geometries (the judge)."""
    model = pin.buildModelFromUrdf(str(path))
    visual = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.VISUAL, package_dirs=[str(path.parent)])
    collision = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION, package_dirs=[str(path.parent)])
    return model, visual.ngeoms, collision.ngeoms


# ====================================================================== item 1: <material name=""> loads again
@pytest.mark.parametrize("path", [MG400, DUARO], ids=["mg400", "duaro"])
def test_an_empty_material_name_loads_as_in_pinocchio(path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    assert path.read_text().count('<material name="">') >= 8
    _, visuals, _ = pinocchio_loads(path)  # the judge: the model and its visual geometry
    robot = load_robot(urdf=path, tool="upper_link_j4" if path == DUARO else None)
    assert len(robot.visual_model.geometryObjects) == visuals
    report = check_urdf_file(path)
    assert report.exit_code in (0, 4), report.format_text()
    assert not report.find("not-loadable")


def test_the_mg400_with_empty_material_names_end_to_end(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    from test_real_robots3 import mg400_pose

    robot = load_robot(urdf=MG400)
    for q in samples(robot):
        assert_pose(robot.tool_pose(q), mg400_pose(q))
    q = samples(robot)[3]
    rc, out, err = run(capsys, ["fk", "--json", "--urdf", str(MG400), *texts(q)])
    assert rc == 0, err
    assert_pose(np.array([*json.loads(out)["position"], json.loads(out)["yaw"]]), mg400_pose(q))
    target = mg400_pose(q)
    rc, out, err = run(capsys, ["ik", "--json", "--urdf", str(MG400), *texts(target)])
    assert rc == 0, err
    answers = [np.array(s["q"]) for s in json.loads(out)["solutions"]]
    assert any(np.allclose(a, q, atol=1e-9) for a in answers)
    for a in answers:
        assert_pose(mg400_pose(a), target, 1e-9)
    rc, out, err = run(capsys, ["workspace", "--json", "--urdf", str(MG400)])
    assert rc == 0, err
    rc, out, err = run(capsys, ["view", "--urdf", str(MG400), "--html", str(tmp_path / "mg400.html")])
    assert rc == 0, err
    assert (tmp_path / "mg400.html").stat().st_size > 10_000


def test_the_duaro_with_empty_material_names_end_to_end(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot(urdf=DUARO, tool="upper_link_j4")
    for q in samples(robot):
        assert_pose(robot.tool_pose(q), duaro_upper_pose(q))
    rc, out, err = run(capsys, ["cycle", "--urdf", str(DUARO), "--tool", "upper_link_j4", *ACC, "--no-torque",
                                "--json"])  # fmt: skip
    assert rc == 0, err
    assert json.loads(out)["cycle_time"] > 0


# ====================================================================== item 2: the vendor gripper as written
def test_the_vendor_gripper_loads_with_its_mimic_jaw_locked_with_its_source(
    capfd: pytest.CaptureFixture[str]
) -> None:
    text = GRIPPER.read_text()
    with pytest.raises((ValueError, RuntimeError), match="mimic"):
        pin.buildModelFromXML(text, mimic=True)  # Pinocchio's mimic parser meets the mimic before its source
    pin.buildModelFromXML(text)  # its default parser reads the jaws as free joints
    robot = load_robot(urdf=GRIPPER)
    assert robot.tool_frame == "link4" and robot.joint_names == ("arm1_joint", "arm2_joint", "arm3_joint",
                                                                 "arm4_joint")  # fmt: skip
    assert {lj.name: (lj.value, lj.reason) for lj in robot.locked} == {"arm5r_joint": (0.0, "off-chain"),
                                                                       "arm5l_joint": (0.0, "geared")}
    for q in samples(robot):
        assert_pose(robot.tool_pose(q), gripper_pose(q))


def test_lock_of_the_mimic_jaw_locks_both_jaws(capsys: pytest.CaptureFixture[str]) -> None:
    """--lock arm5l_joint=0.01: the source arm5r_joint at the value that gives it (multiplier 1, offset 0)."""
    robot = load_robot(urdf=GRIPPER, lock={"arm5l_joint": 0.01})
    assert {lj.name: (lj.value, lj.reason) for lj in robot.locked} == {"arm5r_joint": (0.01, "asked"),
                                                                       "arm5l_joint": (0.01, "asked")}
    q = np.array([0.3, -0.5, 0.04, 1.0])
    hand = robot.frame_placement(q, "link4")
    for jaw, side in (("jaw_l", 1.0), ("jaw_r", -1.0)):  # each jaw 0.005 + 0.01 off the hand's axis, 0.035 below
        expected = hand.act(np.array([0.0, side * (0.005 + 0.01), -0.035]))
        np.testing.assert_allclose(robot.frame_placement(q, jaw).translation, expected, rtol=0, atol=1e-12)
    rc, out, err = run(capsys, ["fk", "--urdf", str(GRIPPER), "--lock", "arm5l_joint=0.01", *texts(q)])
    assert rc == 0, err
    with pytest.raises(Exception, match=r"within the joint's limits"):
        load_robot(urdf=GRIPPER, lock={"arm5l_joint": 0.5})  # arm5r_joint = 0.5 is outside [0, 0.012]
    with pytest.raises(Exception, match="but arm5r_joint is locked at 0.002"):
        load_robot(urdf=GRIPPER, lock={"arm5l_joint": 0.01, "arm5r_joint": 0.002})


def test_the_vendor_gripper_end_to_end(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """check, fk, ik, workspace, cycle, view: each works on the file as written."""
    report = check_urdf_file(GRIPPER)
    assert report.exit_code in (0, 4), report.format_text()
    (geared,) = report.find("geared")
    assert "locks it with arm5r_joint" in geared.message
    robot = load_robot(urdf=GRIPPER)
    q = samples(robot)[5]
    target = gripper_pose(q)
    rc, out, err = run(capsys, ["fk", "--json", "--urdf", str(GRIPPER), *texts(q)])
    assert rc == 0, err
    doc = json.loads(out)
    assert_pose(np.array([*doc["position"], doc["yaw"]]), target)
    rc, out, err = run(capsys, ["ik", "--json", "--urdf", str(GRIPPER), *texts(target)])
    assert rc == 0, err
    answers = [np.array(s["q"]) for s in json.loads(out)["solutions"]]
    assert any(np.allclose(np.remainder(a - q + np.pi, 2 * np.pi) - np.pi, 0, atol=1e-9) for a in answers)
    for a in answers:
        assert_pose(gripper_pose(a), target, 1e-9)
    rc, out, err = run(capsys, ["workspace", "--json", "--urdf", str(GRIPPER)])
    assert rc == 0, err
    area = json.loads(out)["workspace"]["area"]
    # independent: a grid of the plane, each point tested against the two-link closed form written here
    h = 5e-4
    x, y = np.meshgrid(np.arange(-0.36, 0.36, h) + h / 2, np.arange(-0.36, 0.36, h) + h / 2)
    c2 = (x**2 + y**2 - 0.2**2 - 0.15**2) / (2 * 0.2 * 0.15)
    inside = np.zeros(x.shape, dtype=bool)
    for sign in (1.0, -1.0):
        q2 = sign * np.arccos(np.clip(c2, -1.0, 1.0))
        q1 = np.arctan2(y, x) - np.arctan2(0.15 * np.sin(q2), 0.2 + 0.15 * np.cos(q2))
        q1 = np.remainder(q1 + np.pi, 2 * np.pi) - np.pi
        inside |= (np.abs(c2) <= 1.0) & (np.abs(q1) <= 2.5) & (np.abs(q2) <= 2.6)
    assert area == pytest.approx(inside.sum() * h * h, rel=2e-3)
    rc, out, err = run(capsys, ["cycle", "--json", "--urdf", str(GRIPPER), *ACC])
    assert rc == 0, err
    assert json.loads(out)["joints"] == ["arm1_joint", "arm2_joint", "arm3_joint", "arm4_joint"]
    rc, out, err = run(capsys, ["view", "--urdf", str(GRIPPER), "--html", str(tmp_path / "g.html"), *["--q",
                                *texts(q)]])  # fmt: skip
    assert rc == 0, err
    assert (tmp_path / "g.html").stat().st_size > 500_000  # the offline page, meshcat's script embedded
    drawn = {g.name for g in robot.visual_model.geometryObjects}  # what the page draws: the whole robot
    assert {"jaw_l_0", "jaw_r_0", "link4_0", "base_link_0"} <= drawn


# ====================================================================== item 3: a continuous J4 without <limit>
def test_cycle_on_a_continuous_j4_without_limit_asks_for_velocity(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["cycle", "--urdf", str(LS3), *ACC])
    assert rc == 2 and out == ""
    (line,) = [e for e in err.splitlines() if e.startswith("error:")]
    assert "joint joint_tool_rotate has no velocity limit (no <limit> in the URDF" in line
    assert "give --velocity V1 V2 V3 V4" in line and "joint_3 [m/s]" in line and "joint_tool_rotate [rad/s]" in line
    assert "_velocity is inf" not in line and "rad/s or m/s" not in line
    rc, out, err = run(capsys, ["cycle", "--urdf", str(LS3), *ACC, "--set", "joint_tool_rotate_velocity=34.88"])
    assert rc == 2 and "--velocity and --acceleration" in err  # what the issue tried says what to do instead
    (info,) = check_urdf_file(LS3).find("motion-limits")  # check says before what cycle needs
    assert "--velocity V1 V2 V3 V4" in info.message and "joint_tool_rotate (no <limit>)" in info.message
    assert "--acceleration A1 A2 A3 A4" in info.message


def test_the_python_route_names_the_joint_and_its_unit(capfd: pytest.CaptureFixture[str]) -> None:
    """standard_cycle on the same robot: the joint of the file and rad/s, not an internal joint_tool_rotate_velocity
    in "rad/s or m/s"; a configured robot's limit is still named by its --set parameter, in its joint's unit."""
    import dataclasses

    from scara_pin.errors import ParameterError
    from scara_pin.motion.cycle import standard_cycle

    robot = load_robot(urdf=LS3, acceleration=[20.0, 30.0, 5.0, 60.0])
    with pytest.raises(ParameterError) as info:
        standard_cycle(robot)
    message = str(info.value)
    assert message.startswith("the velocity limit of joint joint_tool_rotate is inf rad/s; it must be finite and > 0")
    assert "load_robot(velocity=...), --velocity" in message and "rad/s or m/s" not in message
    default = load_robot("default")
    with pytest.raises(ParameterError, match=r"^joint3_velocity is 0.0 m/s; it must be finite and > 0"):
        standard_cycle(default, limits=dataclasses.replace(default.limits, velocity=(1.0, 2.0, 0.0, 3.0),
                                                            validate=False))  # fmt: skip


def test_cycle_velocity_in_the_units_rule(capsys: pytest.CaptureFixture[str]) -> None:
    """--velocity beside --acceleration: SI by default, deg/s and mm/s with --mm --deg; jerk too."""
    velocity = [6.5, 11.5, 1.2, 34.88]  # rad/s, rad/s, m/s, rad/s
    rc, out, err = run(capsys, ["cycle", "--json", "--urdf", str(LS3), *ACC, "--velocity", *texts(velocity)])
    assert rc == 0, err
    si = json.loads(out)
    assert si["limits"]["velocity"] == velocity and si["limits"]["effort"][3] is None  # no <limit>: no effort limit
    human = [math.degrees(velocity[0]), math.degrees(velocity[1]), velocity[2] * 1000, math.degrees(velocity[3])]
    acc = [math.degrees(20.0), math.degrees(30.0), 5000.0, math.degrees(60.0)]
    rc, out, err = run(capsys, ["cycle", "--json", "--mm", "--deg", "--urdf", str(LS3), "--acceleration",
                                *texts(acc), "--velocity", *texts(human)])  # fmt: skip
    assert rc == 0, err
    mm_deg = json.loads(out)
    np.testing.assert_allclose(mm_deg["limits"]["velocity"], velocity, rtol=1e-12)
    assert mm_deg["cycle_time"] == pytest.approx(si["cycle_time"], rel=1e-6)
    rc, out, err = run(capsys, ["cycle", "--urdf", str(LS3), *ACC, "--velocity", "6.5", "11.5", "1.2"])
    assert rc == 2 and "must be 4 values, one per joint: joint_1 [rad/s]" in err
    rc, out, err = run(capsys, ["cycle", "--deg", "--urdf", str(LS3), *ACC, "--velocity", *texts(human)])
    assert rc == 2 and "--deg without --mm: --velocity joint_3" in err  # a length typed under --deg alone
    rc, out, err = run(capsys, ["cycle", "--json", "--mm", "--deg", "--jerk-limit", "200000"])
    assert rc == 0, err
    jerk = json.loads(out)["limits"]["jerk"]
    np.testing.assert_allclose(jerk, [math.radians(2e5), math.radians(2e5), 200.0, math.radians(2e5)], rtol=1e-12)


# ====================================================================== item 4: messages
def test_a_xacro_file_of_macros_only_says_it_has_no_link(capsys: pytest.CaptureFixture[str]) -> None:
    report = check_urdf_file(MACROS)
    (f,) = report.find("disconnected")
    assert "the document has no <link>" in f.message and "macros only" in f.message
    assert "cycle" not in f.message and "none (a cycle)" not in report.format_text()
    rc, out, err = run(capsys, ["fk", "--urdf", str(MACROS), "0", "0", "0", "0"])
    assert rc == 2 and "the document has no <link>" in err and "macros only" in err


def test_a_slow_lead_screw_lift_is_information(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot(urdf=LAB, package_path=[ROUND4])
    assert robot.limits.velocity[1] == 0.03  # read from config/joint_limits.yaml by the xacro file
    (f,) = check_urdf_file(LAB, package_dirs=[ROUND4]).find("velocity-implausible")
    assert f.severity.value == "info" and "0.03 m/s" in f.message and "lead-screw" in f.message
    # a value that is a deg/s reading is still a warning (the KR5-like file's 2 deg/s)
    (g,) = check_urdf_file(DATA / "third_party" / "kr5_scara_dh.urdf").find("velocity-implausible")
    assert g.severity.value == "warning" and "2 deg/s" in g.message


def test_a_two_joint_file_counts_joints_as_check_does(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["fk", "--urdf", str(TWO_JOINTS), "0", "0"])
    assert rc == 2
    assert ("this file has 2 movable joints: base_to_torso (continuous), torso_to_arm (revolute)" in err), err
    assert "nq =" not in err and "nv =" not in err
    (f,) = check_urdf_file(TWO_JOINTS).find("joint-count")
    assert "this file has 2" in f.message


# ====================================================================== item 5: meshes written PyBullet's way
def test_pybullet_mesh_paths_are_read_from_the_files_folder(caplog: pytest.LogCaptureFixture,
                                                            capfd: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    assert not Path("/Mesh/Visual/Base.stl").exists()
    robot = load_robot(urdf=LS3)
    with caplog.at_level("WARNING", logger="scara_pin"):
        meshes = {m.link: m for m in visual_meshes(robot)}
    assert set(meshes) == {"Base", "Arm1", "Arm2", "Shaft"}
    assert meshes["Arm1"].path == LS3.parent / "Mesh" / "Visual" / "Arm1.stl"
    # the box written in the STL file: 0.3 x 0.08 x 0.05
    np.testing.assert_allclose(np.ptp(meshes["Arm1"].vertices, axis=0), [0.3, 0.08, 0.05], atol=1e-12)
    assert caplog.text.count("PyBullet's rule") == 4 and "'/Mesh/Visual/Base.stl' does not exist" in caplog.text
    findings = check_urdf_file(LS3).find("mesh-path")
    assert len(findings) == 4 and all("PyBullet's rule" in f.message for f in findings)
    assert not check_urdf_file(LS3).find("mesh-missing")


# ====================================================================== item 6: the two crashes
def test_a_palletizer_with_joint2_continuous_loads(capsys: pytest.CaptureFixture[str]) -> None:
    """The issue's crash: loading told the palletizer by its FK before Robot._q_map was set (internal error).

    Fixed since the Robot split (commit 16d664c: the model attached before its kind is read; at 16d664c^ fk on
    this file says ``internal error (AttributeError: 'Robot' object has no attribute '_q_map')``); kept here as
    the issue's regression test.
    """
    robot = load_robot(urdf=PALLETIZER_J2)
    assert robot.continuous == (False, True, False, False) and robot.kind == "palletizer"
    shipped = load_robot(urdf=DATA / "palletizer.urdf")  # the same machine, joint2 bounded
    for q in samples(shipped):
        assert_pose(robot.tool_pose(q), shipped.tool_pose(q))
    q = samples(shipped)[0]
    rc, out, err = run(capsys, ["fk", "--urdf", str(PALLETIZER_J2), *texts(q)])
    assert rc == 0 and "internal error" not in err, err
    report = check_urdf_file(PALLETIZER_J2)
    assert report.exit_code in (0, 4) and report.find("palletizer"), report.format_text()


def test_the_palletizer_with_joint2_continuous_and_a_bounded_mimic_is_refused_naming_it(
    capfd: pytest.CaptureFixture[str]
) -> None:
    """The single change of the issue (joint2 continuous, its levelling mimic still revolute): Pinocchio's mimic
    parser refuses it too; the toolkit says which joint and what to do."""
    text = PALLETIZER_J2.read_text().replace('<joint name="elbow_level" type="continuous">',
                                              '<joint name="elbow_level" type="revolute">')  # fmt: skip
    with pytest.raises((ValueError, RuntimeError)):
        pin.buildModelFromXML(text, mimic=True)
    with pytest.raises(UrdfError, match="elbow_level .revolute. follows joint2 .continuous.*give elbow_level the type"):
        load_robot(urdf=_written(text))


def _written(text: str) -> Path:
    import tempfile

    path = Path(tempfile.mkdtemp()) / "p.urdf"
    path.write_text(text)
    return path
