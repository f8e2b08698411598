"""Real robots, round 2 (issue 21): geared (mimic) joints, one arm of a two-arm tree, stray xacro in a URDF.

Fixtures in ``tests/data/quirks`` were written for these tests (never copied from vendor packages), each with
the quirk of a public description: a wrist geared to the shoulder by ``<mimic multiplier="1" offset="1"/>``
(3 degrees of freedom), a two-arm tree (two R-R-P-R arms on one column, duAro-shaped), a plain URDF with one
unused ``<xacro:property>``.

Truth from independent routes: the closed form of each chain written below from the fixture's numbers, and
Pinocchio's own model of the whole file (``mimic=True``, every joint in its q) for FK and for the drawn
geometry of the locked arm.
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
from scara_pin.errors import ParameterError, UrdfError
from scara_pin.lint import CheckStatus, check_urdf_file

QUIRKS = Path(__file__).resolve().parent / "data" / "quirks"
MIMIC = QUIRKS / "mimic_wrist_scara.urdf"
TWO_ARM = QUIRKS / "two_arm_scara.urdf"
STRAY = QUIRKS / "stray_xacro_property.urdf"
TOL = 1e-9  # [m, rad] the bar for exact kinematics


def wrapped(a: float) -> float:
    return math.remainder(a, 2 * math.pi)


def pin_pose(model: pin.Model, frame: str, q_full: np.ndarray) -> np.ndarray:
    """(x, y, z, yaw) of a frame in Pinocchio's own model of the whole file (root = base_link here)."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q_full)
    M = data.oMf[model.getFrameId(frame)]
    return np.array([*M.translation, math.atan2(M.rotation[1, 0], M.rotation[0, 0])])


# ------------------------------------------------------------------------------------------ the geared wrist
MIMIC_LIMITS = ((-2.5, 2.5), (-2.6, 2.6), (0.0, 0.3))


def mimic_closed_form(q: np.ndarray) -> np.ndarray:
    """tool0 of the mimic fixture: arms 0.6 and 0.5 m, lift down from z 0.4 + 0.05 - 0.05 - 0.02, the wrist
    geared to arm1 (wrist = arm1 + 1), tool0 turned 0.5 rad on it."""
    q1, q2, q3 = q
    x = 0.6 * math.cos(q1) + 0.5 * math.cos(q1 + q2)
    y = 0.6 * math.sin(q1) + 0.5 * math.sin(q1 + q2)
    return np.array([x, y, 0.38 - q3, q1 + q2 + (q1 + 1.0) + 0.5])


def test_a_geared_wrist_is_not_a_degree_of_freedom() -> None:
    robot = load_robot(urdf=MIMIC)
    assert robot.dof == 3 and robot.joint_names == ("arm1", "arm2", "lift")
    (g,) = robot.geared
    assert (g.name, g.source_name, g.multiplier, g.offset, g.kind) == ("wrist_joint", "arm1", 1.0, 1.0, "angle")
    assert (g.lower, g.upper) == (-4.0, 4.0)
    assert robot.kinematics.dof == 3  # the SCARA without a wrist: the tool point's x, y, z


def test_geared_fk_agrees_with_the_closed_form_and_pinocchio() -> None:
    robot = load_robot(urdf=MIMIC)
    model = pin.buildModelFromXML(MIMIC.read_text(), mimic=True)
    rng = np.random.default_rng(21)
    for _ in range(50):
        q = np.array([rng.uniform(lo, hi) for lo, hi in MIMIC_LIMITS])
        got = robot.tool_pose(q)
        assert_pose(got, mimic_closed_form(q))
        assert_pose(got, pin_pose(model, "tool0", q))
        assert robot.geared[0].value(q) == pytest.approx(q[0] + 1.0, abs=1e-15)


def test_geared_ik_solves_the_free_joints() -> None:
    robot = load_robot(urdf=MIMIC)
    rng = np.random.default_rng(22)
    for _ in range(100):
        q = np.array([rng.uniform(lo, hi) for lo, hi in MIMIC_LIMITS])
        target = mimic_closed_form(q)[:3]
        res = robot.ik(target)
        assert res.success, res.message
        for sol in res.solutions:
            assert np.abs(mimic_closed_form(sol.q)[:3] - target).max() <= TOL
            assert all(lo - 1e-12 <= v <= hi + 1e-12 for v, (lo, hi) in zip(sol.q, MIMIC_LIMITS))
        assert min(float(np.abs(sol.q - q).max()) for sol in res.solutions) <= TOL


def test_geared_values_are_reported_by_ik_and_fk(capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.3, -0.5, 0.1])
    xyz = texts(mimic_closed_form(q)[:3])
    rc, out, _ = run(capsys, ["ik", "--urdf", str(MIMIC), *xyz, "--json"])
    doc = json.loads(out)
    assert rc == 0 and doc["method"] == "closed-form" and len(doc["solutions"]) == 2
    for sol in doc["solutions"]:
        assert sol["geared"]["wrist_joint"] == pytest.approx(sol["q"][0] + 1.0, abs=1e-12)
    rc, out, err = run(capsys, ["ik", "--urdf", str(MIMIC), *xyz])
    assert rc == 0 and "refused" not in err and out.count("geared  wrist_joint = ") == 2
    assert "wrist_joint = 1.3 rad (1 * arm1 + 1)" in out  # the sampled q's branch: 0.3 + 1
    rc, out, _ = run(capsys, ["fk", "--urdf", str(MIMIC), "0.3", "-0.5", "0.1", "--units", "deg,m"])
    geared = math.degrees(math.radians(0.3) + 1.0)  # deg: q1 = 0.3 deg, the offset 1 rad in degrees too

    def shown(v: float) -> str:  # the text's resolution in degrees: 1e-7, trailing zeros dropped
        return f"{v:.7f}".rstrip("0").rstrip(".")

    assert rc == 0 and f"wrist_joint = {shown(geared)} deg (1 * arm1 + {shown(math.degrees(1.0))})" in out, out


def test_check_counts_the_free_joints_and_names_the_geared_one() -> None:
    report = check_urdf_file(MIMIC)
    assert report.exit_code in (0, 4) and "joint-count" not in report.codes()
    assert "closed-form-refused" not in report.codes()
    (f,) = report.find("geared")
    assert f.joint == "wrist_joint" and "wrist_joint = 1 * arm1 + 1 rad" in f.message
    assert [j.name for j in report.joints] == ["arm1", "arm2", "lift"]


def test_a_geared_joint_that_moves_the_tool_point_is_refused_with_its_reason(tmp_path: Path) -> None:
    """The tool 5 cm off the geared wrist's axis: the position depends on the geared joint; not the closed form's."""
    path = tmp_path / "offset.urdf"
    path.write_text(MIMIC.read_text().replace('<origin xyz="0 0 -0.02" rpy="0 0 0.5"/>',
                                              '<origin xyz="0.05 0 -0.02" rpy="0 0 0.5"/>'))  # fmt: skip
    robot = load_robot(urdf=path)
    with pytest.raises(UrdfError, match=r"wrist_joint is geared to arm1 .*the tool point is 0.05 m from its axis"):
        _ = robot.kinematics


# ------------------------------------------------------------------------------------------ one arm of two
ARM_LIMITS = {"upper": ((-1.0, 3.0), (-2.6, 2.6), (0.0, 0.15), (-6.28, 6.28)),
              "lower": ((-3.0, 1.0), (-2.6, 2.6), (0.0, 0.15), (-6.28, 6.28))}  # fmt: skip
ARM_Z = {"upper": 0.9, "lower": 0.6}


def arm_closed_form(arm: str, q: np.ndarray) -> np.ndarray:
    """An arm of the two-arm fixture: 0.4 and 0.36 m on the column's axis, quill down from its height - 0.08."""
    q1, q2, q3, q4 = q
    return np.array([0.4 * math.cos(q1) + 0.36 * math.cos(q1 + q2), 0.4 * math.sin(q1) + 0.36 * math.sin(q1 + q2),
                     ARM_Z[arm] - q3 - 0.08, q1 + q2 + q4])  # fmt: skip


def full_q(model: pin.Model, values: dict[str, float]) -> np.ndarray:
    q = pin.neutral(model)
    for name, v in values.items():
        q[model.joints[model.getJointId(name)].idx_q] = v
    return q


@pytest.mark.parametrize(("arm", "other"), [("upper", "lower"), ("lower", "upper")])
def test_one_arm_of_two_fk_ik_and_the_locked_arm(arm: str, other: str) -> None:
    lock = {f"{other}_joint1": 0.7, f"{other}_joint3": 0.05}
    robot = load_robot(urdf=TWO_ARM, tool=f"{arm}_link_j4", lock=lock)
    assert robot.dof == 4 and robot.joint_names == tuple(f"{arm}_joint{i}" for i in range(1, 5))
    assert {lj.name: lj.value for lj in robot.locked} == {**lock, f"{other}_joint2": 0.0, f"{other}_joint4": 0.0}
    assert robot.lock_note is not None and f"{other}_joint2 = 0" in robot.lock_note
    model = pin.buildModelFromXML(TWO_ARM.read_text(), mimic=True)
    rng = np.random.default_rng(23)
    limits = ARM_LIMITS[arm]
    for _ in range(60):
        q = np.array([rng.uniform(lo, hi) for lo, hi in limits])
        values = {**lock, **{f"{arm}_joint{i + 1}": float(v) for i, v in enumerate(q)}}
        expected = arm_closed_form(arm, q)
        assert_pose(robot.tool_pose(q), expected)
        assert_pose(robot.tool_pose(q), pin_pose(model, f"{arm}_link_j4", full_q(model, values)))
        # the locked arm stays where it was locked, whatever this arm does
        locked_pose = pin_pose(model, f"{other}_link_j4", full_q(model, values))
        assert_pose(pose_of(robot.frame_placement(q, f"{other}_link_j4")), locked_pose)
        res = robot.ik(expected)
        assert res.success, res.message
        for sol in res.solutions:
            assert_pose(arm_closed_form(arm, sol.q), expected, TOL)
            assert all(lo - 1e-12 <= v <= hi + 1e-12 for v, (lo, hi) in zip(sol.q, limits))
        assert min(sol.distance(q) for sol in res.solutions) <= TOL


def pose_of(M: pin.SE3) -> np.ndarray:
    return np.array([*M.translation, math.atan2(M.rotation[1, 0], M.rotation[0, 0])])


def test_the_whole_robot_is_drawn_with_the_locked_arm_at_its_values() -> None:
    """Every visual of the file is in the robot's geometry, placed as Pinocchio places it on the whole model."""
    lock = {"lower_joint1": -0.4, "lower_joint2": 1.1}
    robot = load_robot(urdf=TWO_ARM, tool="upper_link_j4", lock=lock)
    model = pin.buildModelFromXML(TWO_ARM.read_text(), mimic=True)
    geom = pin.buildGeomFromUrdfString(model, TWO_ARM.read_text(), pin.GeometryType.VISUAL)
    q = np.array([0.5, -1.0, 0.1, 2.0])
    values = {**lock, **{f"upper_joint{i + 1}": float(v) for i, v in enumerate(q)}}
    data, gdata = model.createData(), geom.createData()
    pin.framesForwardKinematics(model, data, full_q(model, values))
    pin.updateGeometryPlacements(model, data, geom, gdata)
    ours = robot.visual_model
    odata, ogdata = robot.model.createData(), ours.createData()
    pin.framesForwardKinematics(robot.model, odata, robot.to_pinocchio_q(q))
    pin.updateGeometryPlacements(robot.model, odata, ours, ogdata)
    names = [g.name for g in geom.geometryObjects]
    assert sorted(g.name for g in ours.geometryObjects) == sorted(names) and len(names) == 9
    for i, name in enumerate(names):
        j = ours.getGeometryId(name)
        np.testing.assert_allclose(ogdata.oMg[j].homogeneous, gdata.oMg[i].homogeneous, rtol=0, atol=1e-12)


def test_every_command_works_on_one_arm(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    arm = ["--urdf", str(TWO_ARM), "--tool", "lower_link_j4", "--lock", "upper_joint1=1.2"]
    q = np.array([-0.3, 0.8, 0.05, 0.4])
    rc, out, err = run(capsys, ["fk", *arm, *texts(q), "--json"])
    assert rc == 0 and "upper_joint2 = 0" in err  # the arm's other joints, locked without being asked: said
    pose = np.array([*json.loads(out)["position"], json.loads(out)["yaw"]])
    assert_pose(pose, arm_closed_form("lower", q))
    rc, out, _ = run(capsys, ["ik", *arm, *texts(pose), "--json"])
    assert rc == 0 and min(float(np.abs(np.array(s["q"]) - q).max()) for s in json.loads(out)["solutions"]) <= TOL
    csv, page = tmp_path / "t.csv", tmp_path / "v.html"
    assert run(capsys, ["traj", *arm, "--from", "0", "0.5", "0", "0", "--to", "0.5", "1", "0.1", "1", "--acceleration",
                        "5", "5", "1", "5", "--out", str(csv)])[0] == 0  # fmt: skip
    assert run(capsys, ["cycle", *arm, "--acceleration", "5", "5", "1", "5", "--json"])[0] == 0
    rc, out, _ = run(capsys, ["workspace", *arm, "--json"])
    assert rc == 0 and json.loads(out)["workspace"]["r_max"] == pytest.approx(0.76, abs=1e-12)
    assert run(capsys, ["view", *arm, "--traj", str(csv), "--html", str(page)])[0] == 0
    assert page.stat().st_size > 100_000
    rc, out, _ = run(capsys, ["check", str(TWO_ARM), "--tool", "lower_link_j4", "--lock", "upper_joint1=1.2", "--json"])
    doc = json.loads(out)
    assert rc == 0 and [j["name"] for j in doc["joints"]] == [f"lower_joint{i}" for i in range(1, 5)]


def test_the_teach_session_jogs_one_arm() -> None:
    from scara_pin.viz.teach import JogAxis, TeachSession

    robot = load_robot(urdf=TWO_ARM, tool="upper_link_j4")
    session = TeachSession(robot, np.array([0.5, 1.0, 0.05, 0.0]))
    before = robot.tool_pose(session.q)
    session.jog(JogAxis.X, 0.01)
    after = robot.tool_pose(session.q)
    np.testing.assert_allclose(after - before, [0.01, 0, 0, 0], rtol=0, atol=TOL)


@pytest.mark.parametrize(
    ("lock", "match"),
    [
        ({"nonsense": 0.0}, "no movable joint of that name"),
        ({"lower_joint1": 5.0}, "within the joint's limits"),
        ({"lower_joint1": math.nan}, "must be finite"),
    ],
)
def test_bad_locks_are_refused(lock: dict[str, float], match: str) -> None:
    with pytest.raises((UrdfError, ParameterError), match=match):
        load_robot(urdf=TWO_ARM, tool="upper_link_j4", lock=lock)


def test_bad_lock_on_the_command_line(capsys: pytest.CaptureFixture[str]) -> None:
    for bad in ("upper_joint1", "upper_joint1=abc", "upper_joint1=1e400"):
        rc, _, err = run(capsys, ["fk", "--urdf", str(TWO_ARM), "--tool", "lower_link_j4", "--lock", bad,
                                  "0", "0", "0", "0"])  # fmt: skip
        assert rc == 2 and err.startswith("error: ") and err.count("\n") == 1


# ------------------------------------------------------------------------------------------ stray xacro
def test_a_stray_xacro_property_is_one_rule_for_check_and_the_loaders(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    report = check_urdf_file(STRAY)
    assert report.status is CheckStatus.WARNINGS and report.exit_code == 4
    (f,) = report.find("xacro-ignored")
    assert f.line == 4 and "1 <xacro:property>" in f.message
    rc, out, err = run(capsys, ["fk", "--urdf", str(STRAY), "0", "0", "0", "0"])
    assert rc == 0 and "xacro:property" in err and "position  [0.45, 0, 0.16]" in out
    # a substitution or a macro: a xacro document read as URDF would be another robot: both refuse it
    for old, new in (('xyz="0.25 0 0"', 'xyz="${0.25} 0 0"'),
                     ("<link name=\"tool0\"/>", '<xacro:if value="1"><link name="tool0"/></xacro:if>')):  # fmt: skip
        bad = tmp_path / "bad.urdf"
        bad.write_text(STRAY.read_text().replace(old, new))
        assert check_urdf_file(bad).codes(None)[-1:] == ["xacro-not-expanded"]
        assert check_urdf_file(bad).exit_code == 2
        with pytest.raises(UrdfError, match="this is a xacro document"):
            load_robot(urdf=bad)
