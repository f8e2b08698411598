"""Real robots, round 3 (issue 29 items 1-4): the default tool, chains of mimics, off-chain mimics, palletizers.

Fixtures in ``tests/data/round3`` were written for these tests, modelled on the structure of public
descriptions (never copied): an MG400-like tree (a levelling joint right after j3, a parallelogram drawn with
rods, one a mimic of a mimic, a rod leaf written last, no tool0), a Magician-like arm (a relative forearm
horizontal at q = 0, a two-joint levelling chain, a gripper whose second jaw mimics the first), and
scara-pin's own palletizer with its levelling joint moved after joint3.

Truth from independent routes: each arm's forward kinematics written below from the fixture's numbers (the
levelled flange makes them short), Pinocchio's own refusal of the raw text, the shipped palletizer's model
(a different joint order for the same machine), and a raster of the arm plane swept by FK for the envelope.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from quirks import assert_pose, run, texts

from scara_pin import load_robot, robot_from_urdf
from scara_pin.errors import UrdfError
from scara_pin.lint import Severity, check_urdf, check_urdf_file
from scara_pin.viz.tree import joint_nodes
from scara_pin.workspace.palletizer import arm_plane_envelope

ROUND3 = Path(__file__).resolve().parent / "data" / "round3"
MG400 = ROUND3 / "mg400_like.urdf"
MAGICIAN = ROUND3 / "magician_like.urdf"
LEVEL_AFTER_J3 = ROUND3 / "palletizer_level_after_j3.urdf"
SHIPPED = Path(__file__).resolve().parent / "data" / "palletizer.urdf"
FK_TOL = 1e-12  # [m, rad] the model against the closed form written here
IK_TOL = 1e-9  # [m, rad] FK(IK(p)) against p


def mg400_pose(q: np.ndarray) -> np.ndarray:
    """The MG400-like fixture: the big arm 0.175 from vertical, the forearm 0.175 from horizontal (j3 absolute:
    its levelling joint takes j2 back), the flange level: shoulder (0.0435, 0.228), flange (+0.066, +0.031),
    shaft 0.07 down."""
    q1, q2, q3, q5 = q  # each a number, or a row of many configurations (q: (4, n))
    r = 0.0435 + 0.175 * np.sin(q2) + 0.175 * np.cos(q3) + 0.066
    z = 0.109 + 0.119 + 0.175 * np.cos(q2) - 0.175 * np.sin(q3) + 0.031 - 0.07
    return np.array([r * np.cos(q1), r * np.sin(q1), z, q1 + q5])


def magician_pose(q: np.ndarray) -> np.ndarray:
    """The Magician-like fixture: the rear arm 0.135 from vertical, the forearm 0.147 at q2 + q3 from horizontal
    (q3 measured from the rear arm), the end effector level 0.06 ahead and 0.028 down; the base 0.131305 up."""
    q1, q2, q3, q4 = q  # each a number, or a row of many configurations (q: (4, n))
    r = 0.135 * np.sin(q2) + 0.147 * np.cos(q2 + q3) + 0.06
    z = 0.131305 + 0.135 * np.cos(q2) - 0.147 * np.sin(q2 + q3) - 0.028
    return np.array([r * np.cos(q1), r * np.sin(q1), z, q1 + q4])


def rot_y(a: float) -> np.ndarray:
    return pin.utils.rotate("y", a)


def rot_z(a: float) -> np.ndarray:
    return pin.utils.rotate("z", a)


def random_qs(robot, n: int, seed: int) -> np.ndarray:  # type: ignore[no-untyped-def]
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    return np.random.default_rng(seed).uniform(lo, hi, (n, robot.dof))


# ====================================================================== item 1: the leaf the arm ends in
@pytest.mark.parametrize(("path", "tool", "why", "others"), [
    (MG400, "mg400_end_effector_shaft", "its name says end_effector", ["mg400_link4_3 (3)", "mg400_link4_2 (1)"]),
    (MAGICIAN, "magician_link_gripper_core", "the hand of the fingers magician_joint_prismatic_l", []),
])  # fmt: skip
def test_default_tool_is_where_the_arm_ends(path: Path, tool: str, why: str, others: list[str],
                                            capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """Not the parallelogram's rod leaf (MG400), not a gripper jaw (Magician): the end of the 4 free joints."""
    robot = load_robot(urdf=path)
    assert robot.tool_frame == tool and robot.dof == 4
    report = check_urdf_file(path)
    assert report.tool_frame == tool and "tool-ambiguous" not in report.codes()
    (note,) = report.find("tool-frame")
    assert "the most free joints, 4" in note.message and why in note.message
    for other in others:
        assert other in note.message
    q = np.array([0.3, 0.2, 0.4, -0.5])
    rc, out, err = run(capsys, ["fk", "--urdf", str(path), *texts(q)])
    assert rc == 0 and err.count("info:") in (1, 2) and f"no tool0 frame: {tool} is taken" in err
    assert (mg400_pose if path == MG400 else magician_pose)(q)[:3] == pytest.approx(robot.tool_pose(q)[:3], abs=FK_TOL)


def _with_two_leaves(names: tuple[str, str]) -> str:
    """The MG400-like text with two fixed links hung on the shaft (the shaft is then no longer a leaf)."""
    extra = "".join(f'<link name="{n}"/><joint name="{n}_joint" type="fixed"><parent link="mg400_end_effector_shaft"/>'
                    f'<child link="{n}"/><origin xyz="0 0.0{i + 1} -0.02" rpy="0 0 0"/></joint>'
                    for i, n in enumerate(names))  # fmt: skip
    return MG400.read_text().replace("</robot>", extra + "</robot>")


def test_equal_ends_without_a_name_warn_and_a_name_decides() -> None:
    text = _with_two_leaves(("camera_mount", "suction_cup"))
    report = check_urdf(text)
    (warning,) = report.find("tool-ambiguous")
    assert warning.severity is Severity.WARNING and report.exit_code == 4
    assert "camera_mount and suction_cup each end a chain of 4 free joints" in warning.message
    assert report.tool_frame == "camera_mount"  # equally deep: the first in the file, and said so
    robot = robot_from_urdf(text)
    assert robot.tool_frame == "camera_mount" and "suction_cup ends as many" in (robot.frame_note or "")
    named = check_urdf(_with_two_leaves(("camera_mount", "suction_tcp")))
    assert named.tool_frame == "suction_tcp" and not named.find("tool-ambiguous")
    assert "its name says tcp" in named.find("tool-frame")[0].message


# ====================================================================== item 2: a mimic of a mimic
def plate_placement(q: np.ndarray) -> pin.SE3:
    """mg400_link3_2, the elbow plate: on the rod (0.0045, 0, 0.1415) from link1, 0.175 up the rod turned by q2
    (mg400_j2_2 = q2), turned back by q2 (mg400_j3_2 = -mg400_j2_2): level."""
    q1, q2 = q[0], q[1]
    p = np.array([0.0, 0.0, 0.109]) + rot_z(q1) @ (np.array([0.0045, 0.0, 0.1415]) + rot_y(q2) @ [0.0, 0.0, 0.175])
    return pin.SE3(rot_z(q1), p)


def test_a_mimic_of_a_mimic_is_composed_before_pinocchio() -> None:
    raw = MG400.read_text()
    with pytest.raises((ValueError, RuntimeError)):  # Pinocchio alone takes one level of mimic only
        pin.buildModelFromXML(raw, mimic=True)
    robot = load_robot(urdf=MG400)
    assert robot.urdf == raw  # the file as written is kept; Pinocchio got the composed <mimic>
    geared = {g.name: g for g in robot.geared}
    plate = geared["mg400_j3_2"]
    assert (plate.source_name, plate.multiplier, plate.offset) == ("mg400_j2_1", -1.0, 0.0)
    for q in random_qs(robot, 20, 1):
        got = robot.frame_placement(q, "mg400_link3_2")
        assert got.isApprox(plate_placement(q), FK_TOL), (q, got, plate_placement(q))
    (f,) = [f for f in check_urdf_file(MG400).find("geared") if f.joint == "mg400_j3_2"]
    assert "mg400_j3_2 = -1 * mg400_j2_1 + 0 rad, as the toolkit hands it to Pinocchio" in f.message


def test_a_chain_of_mimics_composes_multipliers_and_offsets(tmp_path: Path) -> None:
    """wrist = 0.5 gear + 1, gear = 2 arm1 + 0.5 (a passive joint on a branch): wrist = arm1 + 1.25."""
    text = (ROUND3.parent / "quirks" / "mimic_wrist_scara.urdf").read_text()
    text = text.replace('<mimic joint="arm1" multiplier="1" offset="1"/>', '<mimic joint="gear" multiplier="0.5" '
                        'offset="1"/>').replace("</robot>", '<link name="dial"/><joint name="gear" type="revolute">'
                        '<parent link="link1"/><child link="dial"/><axis xyz="0 0 1"/><limit lower="-9" upper="9" '
                        'effort="1" velocity="1"/><mimic joint="arm1" multiplier="2" offset="0.5"/></joint></robot>')
    robot = robot_from_urdf(text)
    (wrist,) = [g for g in robot.geared if g.name == "wrist_joint"]
    assert (wrist.source_name, wrist.multiplier, wrist.offset) == ("arm1", 1.0, 1.25)
    for q in random_qs(robot, 10, 2):  # the tool's yaw: arm1 + arm2 + wrist + the flange's 0.5
        assert math.remainder(robot.tool_pose(q)[3] - (q[0] + q[1] + q[0] + 1.25 + 0.5), 2 * math.pi) \
            == pytest.approx(0.0, abs=FK_TOL)  # fmt: skip


@pytest.mark.parametrize(("edit", "words"), [
    (('<mimic joint="mg400_j2_1" multiplier="1" offset="0"/>', '<mimic joint="mg400_j3_2" multiplier="1" offset="0"/>'),
     "the <mimic> joints mg400_j2_2 -> mg400_j3_2 -> mg400_j2_2 follow one another in a loop"),
    (('<mimic joint="mg400_j3_1" multiplier="1" offset="0"/>', '<mimic joint="mg400_j9" multiplier="1" offset="0"/>'),
     "joint mg400_j4_2 follows 'mg400_j9' (<mimic>), which is no joint of the file"),
    (('<mimic joint="mg400_j3_1" multiplier="1" offset="0"/>', '<mimic joint="mg400_j4_3" multiplier="1" offset="0"/>'),
     "joint mg400_j4_2 follows 'mg400_j4_3' (<mimic>), a fixed joint"),
])  # fmt: skip
def test_a_mimic_that_leads_nowhere_is_refused_naming_the_joints(
    edit: tuple[str, str], words: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = MG400.read_text().replace(*edit)
    assert text != MG400.read_text()
    with pytest.raises(UrdfError, match=words.replace("(", r"\(").replace(")", r"\)")):
        robot_from_urdf(text)
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    rc, out, err = run(capsys, ["fk", "--urdf", str(path), "0", "0", "0", "0"])
    assert rc == 2 and out == "" and err.count("\n") == 1 and err.startswith("error: ") and words in err
    report = check_urdf(text, origin="bad.urdf")
    (f,) = report.find("mimic-unresolved")
    assert words in f.message and report.exit_code == 2 and f.line is not None
    assert f.line == 1 + text[: text.index(f'<joint name="{f.joint}"')].count("\n")


# ====================================================================== item 3: mimics off the chain
def rod_placement(q: np.ndarray) -> pin.SE3:
    """mg400_link4_2, the forearm's rod: (0.02, 0, 0.012) from the level plate, turned by q3 (mimic of j3_1)."""
    plate = plate_placement(q)
    return pin.SE3(rot_z(q[0]) @ rot_y(q[2]), plate.translation + plate.rotation @ [0.02, 0.0, 0.012])


def test_mimic_joints_off_the_chain_follow_their_source() -> None:
    robot = load_robot(urdf=MG400)
    assert robot.locked == ()  # nothing locked: the rods follow the arm
    nodes = {n.name: n for n in joint_nodes(robot, "robot")}
    rod = nodes["mg400_j4_2"]
    assert not rod.actuated and rod.source == robot.joint_names.index("mg400_j3_1") and rod.multiplier == 1.0
    for q in random_qs(robot, 20, 3):
        assert robot.frame_placement(q, "mg400_link4_2").isApprox(rod_placement(q), FK_TOL)
        # what the viewer and the pendant draw: the product of the nodes' transforms down to the rod
        world = pin.SE3.Identity()
        for name in ("mg400_j1", "mg400_j2_2", "mg400_j3_2", "mg400_j4_2"):
            world = world * nodes[name].transform(q)
        assert world.isApprox(robot.frame_placement(q, "mg400_link4_2", relative_to="universe"), FK_TOL)
    # a mimic whose source is locked goes with it (the Magician's second jaw)
    magician = load_robot(urdf=MAGICIAN, lock={"magician_joint_prismatic_l": 0.01})
    jaws = {lj.name: (lj.value, lj.reason) for lj in magician.locked}
    assert jaws == {"magician_joint_prismatic_l": (0.01, "asked"), "magician_joint_prismatic_r": (-0.01, "geared")}


# ====================================================================== item 4: palletizers as written
def test_levelling_joint_after_j3_is_the_shipped_palletizer() -> None:
    robot, shipped = load_robot(urdf=LEVEL_AFTER_J3), load_robot(urdf=SHIPPED)
    assert robot.kind == shipped.kind == "palletizer"
    for q in random_qs(shipped, 50, 4):
        assert_pose(robot.tool_pose(q), shipped.tool_pose(q), FK_TOL)
    report = check_urdf_file(LEVEL_AFTER_J3)
    assert report.find("palletizer") and report.exit_code == 0
    _round_trips(robot, 200, 5)


@pytest.mark.parametrize(("path", "pose", "relative"), [(MG400, mg400_pose, False), (MAGICIAN, magician_pose, True)])
def test_palletizers_whose_arm_is_horizontal_at_zero(path: Path, pose, relative: bool,  # type: ignore[no-untyped-def]
                                                     capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """The zero pose (forearm horizontal) and a forearm measured from the rear arm: recognised, one verdict."""
    robot = load_robot(urdf=path)
    assert robot.kind == "palletizer" and robot.kinematics.geometry.relative is relative
    for q in random_qs(robot, 50, 6):
        assert_pose(robot.tool_pose(q), pose(q), FK_TOL)
    _round_trips(robot, 300, 7)
    report = check_urdf_file(path)
    assert report.find("palletizer") and not report.find("closed-form-refused") and not report.find("not-a-scara")
    q = random_qs(robot, 1, 8)[0]
    rc, out, err = run(capsys, ["ik", "--urdf", str(path), "--json", *texts(pose(q))])
    assert rc == 0, err
    # the arm plane's envelope: every FK point of a dense sweep is inside, and its area is the swept raster's
    env = arm_plane_envelope(robot.kinematics.geometry)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    g2, g3 = np.meshgrid(np.linspace(lo[1], hi[1], 700), np.linspace(lo[2], hi[2], 700))
    zero = np.zeros(g2.size)
    pts = pose(np.array([zero, g2.ravel(), g3.ravel(), zero]))[[0, 2]].T  # (n, 2): r, z of every configuration
    assert all(env.contains(r, z) for r, z in pts[::97])
    cell = 1e-3  # [m] the raster's cell: the area of the cells the sweep covers
    ix, iz = np.floor(pts / cell).astype(np.int64).T
    covered = np.unique((ix - ix.min()) * (iz.max() - iz.min() + 1) + (iz - iz.min()))  # one integer per cell
    assert env.area == pytest.approx(len(covered) * cell * cell, rel=0.03)


def _round_trips(robot, n: int, seed: int) -> None:  # type: ignore[no-untyped-def]
    """IK of FK(q): every solution reproduces the target to IK_TOL inside the limits; q itself among them."""
    for q in random_qs(robot, n, seed):
        target = robot.tool_pose(q)
        res = robot.ik(target, reference=q)
        assert res.success, (q, res.message)
        for sol in res.solutions:
            assert_pose(robot.tool_pose(sol.q), target, IK_TOL)
            assert not robot.outside_limits(sol.q, 1e-9)
        assert np.abs(res.nearest(q).q - q).max() <= 1e-7
        assert robot.branch_of(q) == res.nearest(q).branch
        batch = robot.ik_batch(target[None, :], q)
        assert np.abs(batch.q[0] - q).max() <= 1e-7


def test_named_tool_and_locks_every_ik_answer_reaches_its_target() -> None:
    """Must hold: with the tool named and a joint locked, IK answers reproduce their targets on the model."""
    robot = load_robot(urdf=MAGICIAN, tool="magician_link_gripper_core", lock={"magician_joint_prismatic_l": 0.01})
    assert robot.frame_note is None and robot.kind == "palletizer"
    _round_trips(robot, 100, 9)
    mg400 = load_robot(urdf=MG400, tool="mg400_end_effector_shaft")
    _round_trips(mg400, 100, 10)
