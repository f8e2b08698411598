"""Real robots, round 2 (issue 21): a wrist-only tilt, arms out of the closed forms' scope, honest messages.

Fixtures in ``tests/data/quirks`` were written for these tests: a SCARA whose J4 axis is 1 deg off vertical
(Dobot M1 Pro-shaped), an R-R-R desktop arm (ultraArm-shaped), a palletizer whose levelling parallelogram is
not modelled (myPalletizer-shaped, no ``<mimic>``).

Truth from independent routes: each chain's forward kinematics written below as a product of elementary
transforms (numpy), and Pinocchio's own model of the file (``mimic=True``).
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
from scara_pin.errors import InvalidInputError, UrdfError
from scara_pin.lint import check_urdf_file
from scara_pin.workspace import workspace

QUIRKS = Path(__file__).resolve().parent / "data" / "quirks"
TILTED = QUIRKS / "tilted_wrist_scara.urdf"
RRR = QUIRKS / "rrr_arm.urdf"
PALLETIZER = QUIRKS / "palletizer_without_mimic.urdf"
TOL = 1e-9  # [m, rad] the bar for exact kinematics
TAU = 0.0174533  # [rad] the tilt written in the tilted fixture (rpy roll of J4's origin)


def T(xyz: tuple[float, float, float] = (0.0, 0.0, 0.0), R: np.ndarray | None = None) -> np.ndarray:
    M = np.eye(4)
    M[:3, 3] = xyz
    if R is not None:
        M[:3, :3] = R
    return M


def Rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def Ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def Rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def pose(M: np.ndarray) -> np.ndarray:
    return np.array([M[0, 3], M[1, 3], M[2, 3], math.atan2(M[1, 0], M[0, 0])])


def pin_tool(text: str, q: np.ndarray, frame: str = "tool0") -> np.ndarray:
    model = pin.buildModelFromXML(text, mimic=True)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId(frame)].homogeneous


def sample(limits: tuple[tuple[float, float], ...], rng: np.random.Generator) -> np.ndarray:
    return np.array([rng.uniform(lo, hi) for lo, hi in limits])


# ------------------------------------------------------------------------------------------ the tilted wrist
TILTED_LIMITS = ((-1.4835, 1.4835), (-2.3562, 2.3562), (0.005, 0.245), (-6.2832, 6.2832))
OFFSET_TOOL = '<origin xyz="0.04 0.01 -0.03" rpy="0 0 0"/>'


def tilted_fk(q: np.ndarray, tool: tuple[float, float, float] = (0.0, 0.0, -0.03)) -> np.ndarray:
    """The tilted fixture: J1 at z 0.2, arm 0.2 (+0.05 up), arm 0.2, the quill down, J4 rolled by TAU."""
    q1, q2, q3, q4 = q
    M = (T((0, 0, 0.2)) @ T(R=Rz(q1)) @ T((0.2, 0, 0.05)) @ T(R=Rz(q2)) @ T((0.2, 0, 0)) @ T((0, 0, -q3))
         @ T((0, 0, -0.05), Rx(TAU)) @ T(R=Rz(q4)) @ T(tool))  # fmt: skip
    return M


@pytest.mark.parametrize("offset", [False, True], ids=["tool-on-axis", "offset-tool"])
def test_a_tilted_wrist_is_solved_on_the_model(offset: bool, tmp_path: Path) -> None:
    text = TILTED.read_text()
    tool = (0.0, 0.0, -0.03)
    if offset:
        text = text.replace('<origin xyz="0 0 -0.03" rpy="0 0 0"/>', OFFSET_TOOL)
        tool = (0.04, 0.01, -0.03)
    path = tmp_path / "tilted.urdf"
    path.write_text(text)
    robot = load_robot(urdf=path)
    geo = robot.kinematics.geometry
    assert geo.wrist_tilt == pytest.approx(TAU, abs=1e-12) and geo.tilt == pytest.approx(TAU, abs=1e-12)
    rng = np.random.default_rng(61)
    for _ in range(60):
        q = sample(TILTED_LIMITS, rng)
        M = tilted_fk(q, tool)
        np.testing.assert_allclose(pin_tool(text, q), M, rtol=0, atol=1e-12)
        target = pose(M)
        assert_pose(robot.tool_pose(q), target)
        res = robot.ik(target)
        assert res.success, res.message
        for sol in res.solutions:
            assert_pose(pose(tilted_fk(sol.q, tool)), target, TOL)
            assert all(lo - 1e-12 <= v <= hi + 1e-12 for v, (lo, hi) in zip(sol.q, TILTED_LIMITS))
        assert min(sol.distance(q) for sol in res.solutions) <= TOL


def test_the_tilted_wrist_workspace_is_the_wrist_points_and_says_what_the_tilt_changes(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    robot = load_robot(urdf=TILTED)
    ws = workspace(robot)
    assert ws.note is not None and "lies on that axis" in ws.note and "1 deg" in ws.note
    rng = np.random.default_rng(62)
    points = np.array([tilted_fk(sample(TILTED_LIMITS, rng))[:2, 3] for _ in range(200)])
    assert ws.contains(points).all()  # every tool point reached is in the region (the tool is on the axis)
    # beyond the reach (arm 1 and, from the FK, the elbow-to-tool vector in line): outside
    r_max = 0.2 + math.hypot(*(tilted_fk(np.zeros(4))[:2, 3] - (0.2, 0.0)))
    assert ws.r_max == pytest.approx(r_max, abs=1e-12) and not ws.contains(np.array([[r_max + 1e-6, 0.0]])).any()
    rc, out, _ = run(capsys, ["workspace", "--urdf", str(TILTED)])
    assert rc == 0 and "note      J4's axis is 1 deg" in out
    # an offset tool: its region at a fixed yaw is what the tilt breaks (its point circles a tilted axis)
    path = tmp_path / "offset.urdf"
    path.write_text(TILTED.read_text().replace('<origin xyz="0 0 -0.03" rpy="0 0 0"/>', OFFSET_TOOL))
    offset = load_robot(urdf=path)
    assert "0.04123 m off that axis" in str(workspace(offset).note)
    with pytest.raises(InvalidInputError, match="no fixed-yaw region of the tool point"):
        workspace(offset, yaw=0.3)
    report = check_urdf_file(TILTED)
    assert report.exit_code == 4 and "axis-tilted" not in report.codes()
    (f,) = report.find("wrist-tilted")
    assert f.joint == "J4" and "1 deg" in f.message


# ------------------------------------------------------------------------------------------ the R-R-R arm
RRR_LIMITS = ((-2.61, 2.61), (-0.3, 1.57), (-0.5, 1.9))


def rrr_fk(q: np.ndarray) -> np.ndarray:
    q1, q2, q3 = q
    return (T((0, 0, 0.1)) @ T(R=Rz(q1)) @ T((0.02, 0, 0.03)) @ T(R=Ry(q2)) @ T((0, 0, 0.135)) @ T(R=Ry(q3))
            @ T((0.147, 0, 0)))  # fmt: skip


def test_an_rrr_arm_says_what_it_is_and_its_numeric_ik_solves_the_tool_point(
    capsys: pytest.CaptureFixture[str],
) -> None:
    robot = load_robot(urdf=RRR)
    text = RRR.read_text()
    rng = np.random.default_rng(63)
    qs = [sample(RRR_LIMITS, rng) for _ in range(20)]
    for q in qs:
        np.testing.assert_allclose(robot.tool_placement(q).homogeneous, rrr_fk(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(pin_tool(text, q), rrr_fk(q), rtol=0, atol=1e-12)
    with pytest.raises(UrdfError, match="it is an R-R-R arm without a wrist"):
        _ = robot.kinematics
    for q in qs[:6]:
        target = rrr_fk(q)[:3, 3]
        rc, out, err = run(capsys, ["ik", "--urdf", str(RRR), *texts(target), "--json"])
        assert rc == 0, err
        assert "R-R-R arm" in err and "using the numeric IK" in err
        (sol,) = json.loads(out)["solutions"]
        got = np.array(sol["q"])
        assert np.abs(rrr_fk(got)[:3, 3] - target).max() <= TOL
        assert all(lo <= v <= hi for v, (lo, hi) in zip(got, RRR_LIMITS))
        assert sol["branch"] == ("elbow+" if math.sin(got[2]) > 0 else "elbow-")
        # the sampled q is the solution nearest to itself (--near seeds the numeric IK there)
        rc, out, _ = run(capsys, ["ik", "--numeric", "--urdf", str(RRR), *texts(target), "--near", *texts(q), "--json"])
        assert rc == 0 and np.abs(np.array(json.loads(out)["solutions"][0]["q"]) - q).max() <= TOL
    rc, out, err = run(capsys, ["ik", "--numeric", "--urdf", str(RRR), "0.2", "0.05", "0.25"])
    assert rc == 0 and "without a wrist" not in err and ("elbow+" in out or "elbow-" in out)
    report = check_urdf_file(RRR)
    assert report.exit_code == 4 and "no-wrist" not in report.codes()
    (f,) = report.find("not-a-scara")
    assert "R-R-R arm" in f.message and "numeric IK" in f.message


# ------------------------------------------------------------------------------------------ palletizer, no mimic
PAL_LIMITS = ((-2.96, 2.96), (-1.0, 1.4), (-0.5, 2.4), (-3.0, 3.0))


def palletizer_fk(q: np.ndarray) -> np.ndarray:
    """As written (no parallelogram): joint3 relative to the big arm, the flange pitching with both."""
    q1, q2, q3, q4 = q
    return (T((0, 0, 0.1315)) @ T(R=Rz(q1)) @ T((0, 0, 0.02)) @ T(R=Ry(q2)) @ T((0, 0, 0.13)) @ T(R=Ry(q3))
            @ T((0.06, 0, 0.13)) @ T(R=Rz(q4)) @ T((0, 0, -0.065)))  # fmt: skip


def with_levelling_mimics(text: str) -> str:
    """What the message says the file lacks: passive joints following joint2 and joint3 by -1."""
    def passive(name: str, parent: str, child: str, follows: str) -> str:
        return (f'<link name="{child}"/><joint name="{name}" type="revolute"><parent link="{parent}"/>'
                f'<child link="{child}"/><origin xyz="0 0 0.13" rpy="0 0 0"/><axis xyz="0 1 0"/>'
                f'<limit lower="-3" upper="3" effort="5" velocity="3"/>'
                f'<mimic joint="{follows}" multiplier="-1" offset="0"/></joint>')  # fmt: skip

    text = text.replace('<parent link="link2"/><child link="link3"/>\n    <origin xyz="0 0 0.13"',
                        '<parent link="link2_level"/><child link="link3"/>\n    <origin xyz="0 0 0"')
    text = text.replace('<parent link="link3"/><child link="link4"/>\n    <origin xyz="0.06 0 0.13"',
                        '<parent link="link3_level"/><child link="link4"/>\n    <origin xyz="0.06 0 0"')
    extra = passive("elbow_level", "link2", "link2_level", "joint2") + passive("wrist_level", "link3",
                                                                              "link3_level", "joint3")
    return text.replace("</robot>", extra + "</robot>")


def test_a_palletizer_without_its_parallelogram_says_why_and_what_it_lacks(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    robot = load_robot(urdf=PALLETIZER)
    text = PALLETIZER.read_text()
    rng = np.random.default_rng(64)
    for _ in range(20):
        q = sample(PAL_LIMITS, rng)
        np.testing.assert_allclose(robot.tool_placement(q).homogeneous, palletizer_fk(q), rtol=0, atol=1e-12)
        np.testing.assert_allclose(pin_tool(text, q), palletizer_fk(q), rtol=0, atol=1e-12)
    assert robot.kind == "scara"  # not recognised as a palletizer
    with pytest.raises(UrdfError, match=r"not recognised as a palletizer: its flange tilts .*\(no <mimic> joint"):
        _ = robot.kinematics
    q = np.array([0.4, 0.3, 0.9, -0.7])
    target = pose(palletizer_fk(q))
    rc, out, err = run(capsys, ["ik", "--urdf", str(PALLETIZER), *texts(target), "--near", *texts(q + 0.05),
                                "--json"])  # fmt: skip
    assert rc == 0 and "not recognised as a palletizer" in err
    (sol,) = json.loads(out)["solutions"]
    assert np.abs(np.array(sol["q"]) - q).max() <= TOL and sol["branch"] == "elbow+"
    assert all(lo <= v <= hi for v, (lo, hi) in zip(sol["q"], PAL_LIMITS))
    assert_pose(pose(palletizer_fk(np.array(sol["q"]))), target, TOL)
    assert check_urdf_file(PALLETIZER).find("not-a-scara")
    # with what the message says it lacks, the file is a palletizer and its closed form applies
    path = tmp_path / "levelled.urdf"
    path.write_text(with_levelling_mimics(text))
    levelled = load_robot(urdf=path)
    assert levelled.kind == "palletizer" and levelled.dof == 4
    for _ in range(40):
        q = sample(((-2.96, 2.96), (-1.0, 1.4), (-0.5, 2.4), (-3.0, 3.0)), rng)
        target = levelled.tool_pose(q)
        res = levelled.ik(target)
        assert res.success, res.message
        for s in res.solutions:
            assert_pose(levelled.tool_pose(s.q), target, TOL)
        assert min(float(np.abs(s.q - q).max()) for s in res.solutions) <= TOL


# ------------------------------------------------------------------------------------------ the listing
def test_the_workspace_listing_leaves_out_sub_micrometre_arcs(capsys: pytest.CaptureFixture[str]) -> None:
    """pi written as 3.14159 shifts the elbow's limits by 2.65e-6 rad: two boundary arcs 0.26 um long, which
    printed as 'a..a deg'. The text leaves them out and says so; --json keeps every arc (the loops close)."""
    path = Path(__file__).resolve().parent / "data" / "near_parallel" / "scara_rpy_3_14159.urdf"
    rc, out, _ = run(capsys, ["workspace", "--urdf", str(path), "--json"])
    arcs = json.loads(out)["workspace"]["arcs"]
    lengths = [a["radius"] * abs(a["end_angle"] - a["start_angle"]) for a in arcs]
    short = [i for i, length in enumerate(lengths) if length < 1e-6]
    assert rc == 0 and len(short) == 2 and all(length > 1e-4 for i, length in enumerate(lengths) if i not in short)
    rc, out, _ = run(capsys, ["workspace", "--urdf", str(path)])
    rows = [line.split() for line in out.splitlines() if line.startswith("  ") and line.split()[0].isdigit()]
    assert [int(r[0]) for r in rows] == [i for i in range(len(arcs)) if i not in short]
    for r in rows:  # 'start.. end deg': the two printed angles differ
        text = " ".join(r)
        start, end = text.split("..")[0].split()[-1], text.split("..")[1].split()[0]
        assert start != end, text
    assert f"({len(short)} arc(s) shorter than 1 um not listed: {', '.join(map(str, short))};" in out


def test_a_stray_property_fixture_is_an_ordinary_scara() -> None:
    """The stray-xacro fixture's kinematics: FK as Pinocchio's model of the file, IK back to a sampled q."""
    stray = QUIRKS / "stray_xacro_property.urdf"
    robot = load_robot(urdf=stray)
    text = stray.read_text()
    limits = ((-2.0, 2.0), (-2.4, 2.4), (0.0, 0.12), (-6.0, 6.0))
    rng = np.random.default_rng(65)
    for _ in range(40):
        q = sample(limits, rng)
        M = (T((0, 0, 0.2)) @ T(R=Rz(q[0])) @ T((0.25, 0, 0)) @ T(R=Rz(q[1])) @ T((0.2, 0, 0)) @ T((0, 0, -q[2]))
             @ T((0, 0, -0.04)) @ T(R=Rz(q[3])))  # fmt: skip
        np.testing.assert_allclose(pin_tool(text, q), M, rtol=0, atol=1e-12)
        target = pose(M)
        res = robot.ik(target)
        assert res.success, res.message
        for sol in res.solutions:
            assert_pose(robot.tool_pose(sol.q), target, TOL)
            assert all(lo - 1e-12 <= v <= hi + 1e-12 for v, (lo, hi) in zip(sol.q, limits))
        assert min(sol.distance(q) for sol in res.solutions) <= TOL


# ------------------------------------------------------------------------------------------ missing meshes
def test_check_reports_the_meshes_the_viewer_cannot_find(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """The quirky package with two of its four meshes written: check names the other two, as view warns."""
    import shutil

    import trimesh

    package = Path(__file__).resolve().parent / "data" / "packages" / "quirky_scara_description"
    ws = tmp_path / "ws"
    shutil.copytree(package, ws / package.name)
    (ws / package.name / "meshes").mkdir()
    for name in ("base_link.STL", "arm1.STL"):  # hand.STL and arm2.STL are not written
        trimesh.creation.box(extents=(10.0, 10.0, 10.0)).export(ws / package.name / "meshes" / name, file_type="stl")
    xacro = ws / package.name / "urdf" / "quirky_scara.urdf.xacro"
    report = check_urdf_file(xacro)
    found = report.find("mesh-missing")
    assert sorted(f.message.split("'")[1].rsplit("/", 1)[1] for f in found) == ["arm2.STL", "hand.STL"]
    assert all("does not exist" in f.message and f.line is not None for f in found)
    assert report.exit_code == 4
    rc, _, err = run(capsys, ["view", "--urdf", str(xacro), "--html", str(tmp_path / "v.html")])
    warned = sorted(w for w in ("arm2.STL", "hand.STL", "arm1.STL", "base_link.STL") if w in err)
    assert rc == 0 and warned == ["arm2.STL", "hand.STL"]  # the viewer warns of the same two
