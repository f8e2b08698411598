"""Real robots as users have them (issue 13): tool/base frames, xacro packages, meshes, quirky URDFs.

The fixture ``tests/data/packages/quirky_scara_description`` is a tiny ROS-style package written for these
tests: a xacro using ``$(find)`` and including a ``.gazebo`` file, a ``world`` root, arms drawn along -x,
a continuous wrist, placeholder velocity limits, no ``tool0`` (the last link ``Hand_Base`` after a fixed
joint), a non-unit axis ``0 0 1.2`` and ``package://`` STL meshes in millimetres. The tests copy it into
a temporary folder and write the meshes there (binary STL from trimesh boxes).

Expected poses come from the closed form of that chain written below (not from the toolkit).
"""

from __future__ import annotations

import math
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import trimesh
from browser import next_frames, orange_pixels

from scara_pin import Robot, load_robot
from scara_pin.cell.meshes import MeshProblem, resolve_mesh, visual_meshes
from scara_pin.cli import main
from scara_pin.description.packages import PackagePath
from scara_pin.description.placeholders import PLACEHOLDER_SIZE
from scara_pin.errors import UrdfError
from scara_pin.lint import check_urdf_file

DATA = Path(__file__).resolve().parent / "data"
PACKAGE = "quirky_scara_description"
XACRO = Path("urdf") / "quirky_scara.urdf.xacro"
MESH_EXTENTS = {"base_link": (100.0, 100.0, 300.0), "arm1": (250.0, 60.0, 40.0), "arm2": (200.0, 50.0, 40.0),
                "hand": (40.0, 40.0, 20.0)}  # fmt: skip
"""[mm] the boxes written as the meshes (the URDF scales them by 0.001)."""
MESH_FILES = {"base_link": "base_link.STL", "arm1": "arm1.STL", "arm2": "arm2.STL", "hand": "hand.STL"}
LIMITS = ((-2.5, 2.5), (-2.5, 2.5), (0.0, 0.15), (-math.pi, math.pi))


def closed_form(q: np.ndarray) -> np.ndarray:
    """(x, y, z, yaw) of Hand_Base in world, from the fixture's numbers (arms along -x, quill down)."""
    q1, q2, q3, q4 = q
    yaw = q1 + q2 + q4
    x = -0.25 * math.cos(q1) - 0.2 * math.cos(q1 + q2) + 0.03 * math.cos(yaw)
    y = -0.25 * math.sin(q1) - 0.2 * math.sin(q1 + q2) + 0.03 * math.sin(yaw)
    z = 0.3 + 0.088 - q3 - 0.05 - 0.02
    return np.array([x, y, z, math.atan2(math.sin(yaw), math.cos(yaw))])


def write_meshes(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for key, name in MESH_FILES.items():
        trimesh.creation.box(extents=MESH_EXTENTS[key]).export(folder / name, file_type="stl")


@pytest.fixture
def workspace(tmp_path: Path) -> Path:
    """A folder holding the package (meshes written); returns that folder (a --package-path)."""
    ws = tmp_path / "ws"
    shutil.copytree(DATA / "packages" / PACKAGE, ws / PACKAGE)
    write_meshes(ws / PACKAGE / "meshes")
    return ws


@pytest.fixture
def xacro(workspace: Path) -> Path:
    return workspace / PACKAGE / XACRO


def random_q(rng: np.random.Generator) -> np.ndarray:
    return np.array([rng.uniform(lo, hi) for lo, hi in LIMITS])


# ------------------------------------------------------------------------------------------ frames, FK, IK
def test_xacro_with_find_and_gazebo_include_loads_and_picks_the_frames(xacro: Path) -> None:
    robot = load_robot(urdf=xacro)
    assert robot.tool_frame == "Hand_Base" and robot.base_frame == "world"
    assert robot.frame_note is not None and "Hand_Base" in robot.frame_note and "tool0" in robot.frame_note
    assert robot.continuous == (False, False, False, True)
    assert "<gazebo" in robot.urdf  # the included .gazebo file was expanded into the document
    assert "package://quirky_scara_description/meshes/arm1.STL" in robot.urdf  # kept for the mesh resolver


def test_fk_matches_the_closed_form_and_pinocchio_on_the_file_as_written(xacro: Path) -> None:
    robot = load_robot(urdf=xacro)
    # Pinocchio on the expanded file as written (non-unit axis, world root, fixed joints), raw q vector
    model = pin.buildModelFromXML(robot.urdf)
    data = model.createData()
    tool = model.getFrameId("Hand_Base")
    rng = np.random.default_rng(13)
    for _ in range(50):
        q = random_q(rng)
        expected = closed_form(q)
        got = robot.tool_pose(q)
        np.testing.assert_allclose(got[:3], expected[:3], rtol=0, atol=1e-12)
        assert abs(math.remainder(got[3] - expected[3], 2 * math.pi)) < 1e-12
        q_pin = np.array([q[0], q[1], q[2], math.cos(q[3]), math.sin(q[3])])
        pin.framesForwardKinematics(model, data, q_pin)
        np.testing.assert_allclose(data.oMf[tool].translation, expected[:3], rtol=0, atol=1e-12)


def test_non_unit_axes_are_normalised(xacro: Path, tmp_path: Path) -> None:
    text = load_robot(urdf=xacro).urdf.replace('<axis xyz="0 0 -1"/>', '<axis xyz="0 0 -2.5"/>')
    assert '<axis xyz="0 0 1.2"/>' in text and '<axis xyz="0 0 -2.5"/>' in text
    robot = Robot(text)
    q = np.array([0.4, -0.7, 0.12, 2.0])
    np.testing.assert_allclose(robot.tool_pose(q), closed_form(q), rtol=0, atol=1e-12)


def test_ik_round_trips_at_1e_9(xacro: Path) -> None:
    robot = load_robot(urdf=xacro)
    rng = np.random.default_rng(7)
    for _ in range(100):
        q = random_q(rng)
        result = robot.ik(robot.tool_pose(q))
        assert result.success, result.message
        for s in result.solutions:  # every solution reaches the target
            np.testing.assert_allclose(closed_form(s.q)[:3], closed_form(q)[:3], rtol=0, atol=1e-9)
        gaps = [max(abs(s.q[0] - q[0]), abs(s.q[1] - q[1]), abs(s.q[2] - q[2]),
                    abs(math.remainder(s.q[3] - q[3], 2 * math.pi))) for s in result.solutions]  # fmt: skip
        assert min(gaps) < 1e-9, (q, result)


def test_tool_and_base_frames_can_be_chosen(xacro: Path) -> None:
    q = np.array([0.3, 0.5, 0.1, -0.4])
    wrist = load_robot(urdf=xacro, tool="wrist")
    assert wrist.frame_note is None
    expected = closed_form(q)
    yaw = q[0] + q[1] + q[3]
    expected[0] -= 0.03 * math.cos(yaw)
    expected[1] -= 0.03 * math.sin(yaw)
    expected[2] += 0.02
    np.testing.assert_allclose(wrist.tool_pose(q), expected, rtol=0, atol=1e-12)
    # base = base_link (fixed to world by an identity joint): the same poses; a moving link is refused
    np.testing.assert_allclose(load_robot(urdf=xacro, base="base_link").tool_pose(q), closed_form(q), rtol=0,
                               atol=1e-12)  # fmt: skip
    with pytest.raises(UrdfError, match="'arm1' moves with joint arm1_joint.*fixed links: world, base_link$"):
        load_robot(urdf=xacro, base="arm1")


@pytest.mark.parametrize("option", ["tool", "base"])
def test_an_unknown_frame_is_an_error_naming_it_and_the_links(xacro: Path, option: str) -> None:
    with pytest.raises(UrdfError) as info:
        load_robot(urdf=xacro, **{option: "tool0"})
    message = str(info.value)
    assert "'tool0'" in message and f"--{option}" in message and "Hand_Base" in message and "world" in message


# ------------------------------------------------------------------------------------------ the command line
def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_fk_on_a_xacro_says_the_tool_once(xacro: Path, capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.2, -0.4, 0.05, 1.0])
    code, out, err = run(capsys, "fk", "--urdf", str(xacro), "--json", *map(repr, q.tolist()))
    assert code == 0, err
    assert [ln for ln in err.splitlines()] == [
        "info: no tool0 frame: Hand_Base is taken as the tool (it ends the chain through the most free joints, 4); "
        "--tool FRAME picks another"
    ]
    import json

    doc = json.loads(out)
    assert doc["frame"] == "Hand_Base" and doc["reference"] == "world"
    np.testing.assert_allclose(doc["position"], closed_form(q)[:3], rtol=0, atol=1e-9)


def test_cli_ik_with_tool_option(xacro: Path, capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.2, -0.4, 0.05, 1.0])
    pose = closed_form(q)
    code, out, err = run(capsys, "ik", "--urdf", str(xacro), "--tool", "Hand_Base", "--json", *map(repr, pose.tolist()))
    assert code == 0, err
    assert err == ""  # a tool named on the command line: no notice


@pytest.mark.parametrize("option", ["--tool", "--base"])
def test_cli_unknown_frame_exits_2_with_one_line(xacro: Path, capsys: pytest.CaptureFixture[str], option: str) -> None:
    code, out, err = run(capsys, "fk", "--urdf", str(xacro), option, "tool_0", "0", "0", "0", "0")
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and err.startswith("error: ") and "'tool_0'" in err and "Hand_Base" in err
    code, out, err = run(capsys, "check", str(xacro), option, "tool_0")
    assert code == 2 and "[frame-missing]" in out and "'tool_0'" in out


@pytest.mark.parametrize("how", ["exc attribute", "context"])
def test_a_missing_package_wrapped_by_any_xacro_exception_is_named(xacro: Path, monkeypatch: pytest.MonkeyPatch,
                                                                   how: str) -> None:  # fmt: skip
    """xacro wraps the finder's PackageNotFoundError (as ``.exc``, or as the exception being handled), and
    xacrodoc 2.0.0 raises its own copy of XacroException, not xacro's: the error names the package anyway."""
    from xacrodoc import XacroDoc, packages

    class OtherXacroException(Exception):  # not xacro.XacroException
        pass

    def raising(*args: Any, **kwargs: Any) -> None:
        missing = packages.PackageNotFoundError("some_missing_description")
        if how == "exc attribute":
            wrapped = OtherXacroException("Package not found")
            wrapped.exc = missing  # type: ignore[attr-defined]
            raise wrapped
        try:
            raise missing
        except packages.PackageNotFoundError:
            raise OtherXacroException("Package not found") from None

    monkeypatch.setattr(XacroDoc, "from_string", raising)
    with pytest.raises(UrdfError) as info:
        PackagePath().expand_xacro(xacro)
    assert "package 'some_missing_description' not found" in str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_missing_package_is_one_line_naming_it(xacro: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    moved = tmp_path / "elsewhere" / "robot.urdf.xacro"
    moved.parent.mkdir()
    shutil.copy(xacro, moved)  # outside its package: $(find quirky_scara_description) has nowhere to look
    code, out, err = run(capsys, "fk", "--urdf", str(moved), "0", "0", "0", "0")
    assert code == 2 and out == ""
    assert len(err.splitlines()) == 1 and f"package '{PACKAGE}' not found" in err and "--package-path" in err
    code, out, err = run(capsys, "check", str(moved))
    assert code == 2 and "[xacro-failed]" in out and PACKAGE in out
    # found through --package-path, ROS_PACKAGE_PATH and AMENT_PREFIX_PATH (prefix/share/<pkg>)
    workspace = xacro.parents[2]
    code, out, err = run(capsys, "fk", "--urdf", str(moved), "--package-path", str(workspace), "0", "0", "0", "0")
    assert code == 0, err
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(workspace))
    assert run(capsys, "fk", "--urdf", str(moved), "0", "0", "0", "0")[0] == 0
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    prefix = tmp_path / "install"
    shutil.copytree(workspace / PACKAGE, prefix / "share" / PACKAGE)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    assert run(capsys, "fk", "--urdf", str(moved), "0", "0", "0", "0")[0] == 0


def test_package_path_that_is_not_a_folder(xacro: Path, capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = run(capsys, "fk", "--urdf", str(xacro), "--package-path", str(tmp_path / "nope"), "0", "0", "0", "0")
    assert code == 2 and "is not a folder" in err and len(err.splitlines()) == 1


def inverted(xacro: Path, tmp_path: Path) -> Path:
    text = load_robot(urdf=xacro).urdf.replace('lower="0" upper="0.15"', 'lower="0.45" upper="0"')
    assert 'lower="0.45" upper="0"' in text
    path = tmp_path / "inverted.urdf"
    path.write_text(text)
    return path


COMMANDS = {
    "fk": ["fk", "0", "0", "0", "0"],
    "jacobian": ["jacobian", "0", "0", "0", "0"],
    "ik": ["ik", "-0.4", "0", "0.3", "0"],
    "validate-ik": ["validate-ik", "--samples", "3"],
    "traj": ["traj", "--from", "0", "0", "0", "0", "--to", "0.1", "0.1", "0", "0", "--duration", "1"],
    "jog": ["jog", "--from", "0", "0", "0", "0", "--direction", "0.01", "0", "0", "0"],
    "workspace": ["workspace"],
    "view": ["view", "--html", "page.html"],
}


@pytest.mark.parametrize("command", COMMANDS)
def test_inverted_limits_exit_2_on_every_command(xacro: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                 monkeypatch: pytest.MonkeyPatch, command: str) -> None:  # fmt: skip
    path = inverted(xacro, tmp_path)
    monkeypatch.chdir(tmp_path)
    argv = COMMANDS[command]
    code, out, err = run(capsys, argv[0], "--urdf", str(path), *argv[1:])
    assert code == 2, (out, err)
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "quill_joint" in err and "lower 0.45 > upper 0" in err and "lower must be below upper" in err
    assert not (tmp_path / "page.html").exists()


def test_check_reports_inverted_limits_with_the_same_rule(xacro: Path, tmp_path: Path) -> None:
    report = check_urdf_file(inverted(xacro, tmp_path))
    assert report.exit_code == 2
    (finding,) = report.find("limits-inverted")
    with pytest.raises(UrdfError) as info:
        Robot.from_file(inverted(xacro, tmp_path))
    assert finding.message in str(info.value)


def third_party() -> list[Path]:
    return sorted((DATA / "third_party").glob("*.urdf"))


@pytest.mark.parametrize("path", third_party(), ids=lambda p: p.name)
@pytest.mark.parametrize("frames", [{}, {"tool": "link4"}, {"base": "base_link"}], ids=["default", "tool", "base"])
def test_check_and_the_loader_agree_on_the_frames(path: Path, frames: dict[str, str]) -> None:
    report = check_urdf_file(path, **frames)
    links = [el.get("name") for el in ET.parse(path).getroot().findall("link")]
    if any(name not in links for name in frames.values()):
        assert report.find("frame-missing") and report.exit_code == 2
        with pytest.raises(UrdfError):
            load_robot(urdf=path, **frames)
        return
    if report.exit_code == 2:  # unusable for another reason (the ROS 3-joint tutorial): the loader refuses too
        with pytest.raises(UrdfError):
            load_robot(urdf=path, **frames)
        return
    robot = load_robot(urdf=path, **frames)
    assert (report.tool_frame, report.base_frame) == (robot.tool_frame, robot.base_frame)
    assert bool(report.find("tool-frame")) == (robot.frame_note is not None)


def test_check_and_the_loader_agree_on_the_xacro(xacro: Path) -> None:
    report = check_urdf_file(xacro)
    robot = load_robot(urdf=xacro)
    assert report.exit_code == 4, report.format_text()  # warnings: placeholder velocities, continuous wrist
    assert (report.tool_frame, report.base_frame) == (robot.tool_frame, robot.base_frame) == ("Hand_Base", "world")
    (note,) = report.find("tool-frame")
    assert note.message == robot.frame_note


# ------------------------------------------------------------------------------------------ meshes
def test_meshes_are_found_read_and_scaled(xacro: Path, caplog: pytest.LogCaptureFixture) -> None:
    robot = load_robot(urdf=xacro)
    meshes = {m.name: m for m in visual_meshes(robot)}
    assert sorted(meshes) == ["Hand_Base_0", "arm1_0", "arm2_0", "base_link_0"]
    for name, key in (("base_link_0", "base_link"), ("arm1_0", "arm1"), ("arm2_0", "arm2"), ("Hand_Base_0", "hand")):
        m = meshes[name]
        extent = m.vertices.max(axis=0) - m.vertices.min(axis=0)
        np.testing.assert_allclose(extent, np.array(MESH_EXTENTS[key]) * 0.001, rtol=1e-6)
        assert len(m.faces) == 12
    assert caplog.records == []
    names = [g.name for g in robot.visual_model.geometryObjects]
    assert sorted(names) == sorted(meshes)  # Pinocchio's names: where the placeholder boxes are


@pytest.mark.parametrize("kind", ["dae", "obj", "stl"])
def test_dae_and_obj_meshes(tmp_path: Path, kind: str) -> None:
    folder = tmp_path / "pkg"
    folder.mkdir()
    (folder / "package.xml").write_text("<package><name>pkg</name></package>")
    trimesh.creation.box(extents=(1.0, 2.0, 3.0)).export(folder / f"part.{kind.upper()}", file_type=kind)
    urdf = (DATA / "third_party" / "irb920_like.urdf").read_text()
    root = ET.fromstring(urdf)
    link = root.find("link")
    assert link is not None
    visual = ET.SubElement(link, "visual")
    ET.SubElement(ET.SubElement(visual, "geometry"), "mesh", filename=f"package://pkg/part.{kind.upper()}",
                  scale="0.01 0.02 0.03")  # fmt: skip
    path = folder / "robot.urdf"
    path.write_text(ET.tostring(root, encoding="unicode"))
    (mesh,) = visual_meshes(Robot.from_file(path))
    np.testing.assert_allclose(mesh.vertices.max(axis=0) - mesh.vertices.min(axis=0), [0.01, 0.04, 0.09], rtol=1e-6)


def test_mesh_paths_never_leave_the_package_folders(workspace: Path, tmp_path: Path) -> None:
    secret = tmp_path / "secret.stl"
    trimesh.creation.box().export(secret, file_type="stl")
    packages = PackagePath((workspace,), workspace / PACKAGE / "urdf")
    ok = resolve_mesh("../meshes/arm1.STL", packages)  # relative, inside the file's own package
    assert ok == (workspace / PACKAGE / "meshes" / "arm1.STL").resolve()
    assert resolve_mesh(f"package://{PACKAGE}/meshes/arm1.STL", packages) == ok
    assert resolve_mesh(f"file://{ok}", packages) == ok
    refused = (f"package://{PACKAGE}/../../secret.stl", "../../../secret.stl", str(secret), f"file://{secret}",
               "http://127.0.0.1:9/x.stl", "https://example.invalid/x.stl", "package://no_such_pkg/x.stl")
    for name in refused:
        with pytest.raises(MeshProblem):
            resolve_mesh(name, packages)
    link = workspace / PACKAGE / "meshes" / "link.stl"  # a symbolic link out of the package is refused too
    link.symlink_to(secret)
    with pytest.raises(MeshProblem, match="leaves its package"):
        resolve_mesh(f"package://{PACKAGE}/meshes/link.stl", packages)


def test_missing_and_broken_meshes_are_warnings_with_a_placeholder(
    xacro: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    meshes = xacro.parents[1] / "meshes"
    (meshes / "hand.STL").unlink()
    (meshes / "arm2.STL").write_bytes(b"solid nothing\nthis is not an stl\n")
    out_html = tmp_path / "page.html"
    code, out, err = run(capsys, "view", "--urdf", str(xacro), "--html", str(out_html))
    assert code == 0, err
    warnings = [ln for ln in err.splitlines() if ln.startswith("warning: ")]
    assert len(warnings) == 2, err
    assert any("hand.STL" in w and "does not exist" in w for w in warnings)
    assert any("arm2.STL" in w and ("cannot be read" in w or "no triangles" in w) for w in warnings)
    assert all(f"{PLACEHOLDER_SIZE:g} m box" in w for w in warnings)
    assert out_html.is_file()


# ------------------------------------------------------------------------------------------ in a real browser
def render(browser: Any, html: Path) -> tuple[int, list[str], int]:
    """(orange pixels, the geometry types of the visuals, page errors) of an offline page."""
    page = browser.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    try:
        page.goto(html.as_uri())
        page.wait_for_function("() => window.scaraSceneCommands > 0")
        next_frames(page)
        # every link's visuals, wherever its joint's node is in the robot's tree
        types = page.evaluate("""() => {
            const out = [];
            const walk = (node) => {
                for (const [name, child] of Object.entries(node.children)) {
                    if (name === "visuals") {
                        for (const [k, v] of Object.entries(child.children)) {
                            const obj = v.children["<object>"] && v.children["<object>"].object;
                            const g = obj && obj.geometry;
                            const n = g && g.attributes.position ? g.attributes.position.count : 0;
                            out.push(k + ":" + (g ? g.type : "none") + ":" + n);
                        }
                    } else if (name !== "<object>") {
                        walk(child);
                    }
                }
            };
            walk(viewer.scene_tree.children.meshcat.children.robot);
            return out.sort();
        }""")  # fmt: skip
        pixels = orange_pixels(page.screenshot())
    finally:
        page.close()
    return pixels, types, len(errors)


def test_the_offline_page_draws_the_meshes(xacro: Path, tmp_path: Path, browser: Any) -> None:
    with_meshes = tmp_path / "meshes.html"
    assert main(["view", "--urdf", str(xacro), "--html", str(with_meshes)]) == 0
    shutil.rmtree(xacro.parents[1] / "meshes")  # the same robot, every mesh missing: placeholder boxes
    without = tmp_path / "placeholders.html"
    assert main(["view", "--urdf", str(xacro), "--html", str(without)]) == 0
    shown, types, errors = render(browser, with_meshes)
    boxes, box_types, box_errors = render(browser, without)
    assert errors == box_errors == 0
    # the meshes: BufferGeometry of 8 vertices (trimesh's box); the placeholders: three.js BoxGeometry
    assert types == ["Hand_Base_0:BufferGeometry:8", "arm1_0:BufferGeometry:8", "arm2_0:BufferGeometry:8",
                     "base_link_0:BufferGeometry:8"], types  # fmt: skip
    assert all(":BoxGeometry:" in t for t in box_types), box_types
    assert shown > 2000 and shown > 5 * boxes, (shown, boxes)
