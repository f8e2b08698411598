"""The cell in the viewer (scara_pin.viz.meshcat.draw_cell, `scara-pin view --cell`): the static page and the live one.

Truth from independent routes: the obstacle's axis from its rpy written here (URDF's fixed-axis roll, pitch,
yaw by scipy's Rotation), Pinocchio's frame placement for the carried part, three.js's own matrices read in a
real browser, and the obstacle's colour counted in screenshots with the cell left out as the negative control.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from browser import next_frames, slate_pixels
from scipy.spatial.transform import Rotation

import scara_pin as sp
from scara_pin.cell import Cell, Obstacle, Shape
from scara_pin.cli import main
from scara_pin.viz.meshcat import CARRIED_COLOR, OBSTACLE_COLOR, Viewer, export_html, static_html
from scara_pin.viz.tree import node_paths

ARTIFACTS = Path(__file__).resolve().parent / "artifacts"
Q_AWAY = np.array([2.0, 0.0, 0.0, 0.0])  # the arm turned away from the obstacles
RPY = np.array([0.3, -0.4, 0.5])
CARRIED = Shape("box", (0.04, 0.03, 0.02), np.array([0.0, 0.01, 0.01]), np.array([0.0, 0.0, 0.3]))


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def cell(rpy: np.ndarray = RPY) -> Cell:
    import trimesh

    ico = trimesh.creation.icosphere(subdivisions=1, radius=0.03)
    return Cell(
        (
            Obstacle("post", Shape("cylinder", (0.04, 0.3), np.array([0.3, -0.05, -0.1]), rpy)),
            Obstacle("crate", Shape("box", (0.1, 0.08, 0.06), np.array([0.1, -0.3, -0.12]), np.zeros(3))),
            Obstacle("ball", Shape("sphere", (0.03,), np.array([-0.2, -0.2, -0.1]), np.zeros(3))),
            Obstacle("rock", Shape("mesh", (), np.array([0.25, 0.25, -0.1]), np.zeros(3),
                                   np.asarray(ico.vertices), np.asarray(ico.faces))),  # fmt: skip
        ),
        carried=CARRIED,
    )


def page_commands(text: str) -> list[dict[str, Any]]:
    import base64
    import re

    import umsgpack

    return [umsgpack.unpackb(base64.b64decode(c)) for c in re.findall(r'^"([A-Za-z0-9+/=]+)",?$', text, re.M)]


def last(commands: list[dict[str, Any]], kind: str, path: str) -> dict[str, Any]:
    found = [c for c in commands if c["type"] == kind and c["path"] == path]
    assert found, f"no {kind} at {path}"
    return found[-1]


def matrix(values: Any) -> np.ndarray:
    return np.array(values, dtype=float).reshape(4, 4).T  # meshcat sends column-major


def test_the_page_places_every_obstacle_and_the_carried_part(robot) -> None:
    c = cell()
    commands = page_commands(static_html(robot, q=Q_AWAY, cell=c))
    oMb = robot.frame_placement(Q_AWAY, robot.base_frame, relative_to="universe").homogeneous
    kinds = {"post": "CylinderGeometry", "crate": "BoxGeometry", "ball": "SphereGeometry", "rock": "BufferGeometry"}
    for o in c.obstacles:
        obj = last(commands, "set_object", f"/meshcat/cell/{o.name}")["object"]
        assert obj["geometries"][0]["type"] == kinds[o.name]
        assert obj["materials"][0]["color"] == OBSTACLE_COLOR
        M = matrix(last(commands, "set_transform", f"/meshcat/cell/{o.name}")["matrix"])
        np.testing.assert_allclose(M[:3, 3], (oMb @ np.r_[o.shape.xyz, 1.0])[:3], rtol=0, atol=1e-12)
    # the post's axis: three.js's cylinder runs along its y; node transform x object matrix x (0, 1, 0) is the
    # obstacle's z axis, Rz(yaw) Ry(pitch) Rx(roll) e_z in the base frame (URDF's convention)
    obj = last(commands, "set_object", "/meshcat/cell/post")["object"]
    inner = matrix(obj["object"]["matrix"])
    M = matrix(last(commands, "set_transform", "/meshcat/cell/post")["matrix"])
    axis = (M @ inner)[:3, :3] @ np.array([0.0, 1.0, 0.0])
    expected = oMb[:3, :3] @ Rotation.from_euler("xyz", RPY).as_matrix() @ np.array([0.0, 0.0, 1.0])
    assert abs(abs(axis @ expected) - 1.0) < 1e-12
    geometry = obj["geometries"][0]
    assert geometry["height"] == pytest.approx(0.3) and geometry["radiusTop"] == pytest.approx(0.04)
    # the carried part hangs on the tool's joint node: that node at Q_AWAY times its transform is tool0 * placement
    tool = robot.model.frames[robot.tool_id]
    joint_path = "/meshcat/" + node_paths(robot, "robot")[tool.parentJoint]
    obj = last(commands, "set_object", f"{joint_path}/cell_carried")["object"]
    assert obj["materials"][0]["color"] == CARRIED_COLOR
    local = matrix(last(commands, "set_transform", f"{joint_path}/cell_carried")["matrix"])
    oMj = robot.frame_placement(Q_AWAY, tool.name, relative_to="universe").homogeneous @ np.linalg.inv(
        tool.placement.homogeneous)  # fmt: skip
    got = oMj @ local
    want = robot.frame_placement(Q_AWAY, "tool0", relative_to="universe").homogeneous @ CARRIED.placement().homogeneous
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def shot(page: Any, name: str) -> bytes:
    ARTIFACTS.mkdir(exist_ok=True)
    next_frames(page, 4)
    return page.screenshot(path=str(ARTIFACTS / name))  # type: ignore[no-any-return]


AXIS_JS = """(path) => {
    let node = viewer.scene_tree;
    for (const k of path.split("/")) node = (node && node.children[k]) || null;
    if (node === null) return null;
    viewer.scene.updateMatrixWorld(true);
    const mesh = node.object.children.length ? node.object.children[0] : node.object;
    const e = mesh.matrixWorld.elements;  // column-major: the image of three.js's y axis is the second column
    return [e[4], e[5], e[6]];
}"""


def test_static_page_shows_the_cell_in_a_browser(robot, page, tmp_path: Path) -> None:
    with_cell = export_html(robot, tmp_path / "cell.html", q=Q_AWAY, cell=cell())
    without = export_html(robot, tmp_path / "plain.html", q=Q_AWAY)
    page.goto(without.as_uri())
    page.wait_for_function("() => window.scaraSceneCommands > 0")
    plain = slate_pixels(shot(page, "view_no_cell.png"))
    page.goto(with_cell.as_uri())
    page.wait_for_function("() => window.scaraSceneCommands > 0")
    shown = slate_pixels(shot(page, "view_cell.png"))
    assert shown > 2000, f"only {shown} obstacle-coloured pixels"
    assert plain < 0.01 * shown, (plain, shown)
    # three.js's own world matrix: the post's axis (its y axis) is the obstacle's z axis (scene z-up: x, z, -y)
    raw = page.evaluate(AXIS_JS, "meshcat/cell/post")
    assert raw is not None
    x, y, z = raw
    axis = np.array([x, -z, y]) / np.linalg.norm(raw)
    expected = Rotation.from_euler("xyz", RPY).as_matrix()[:, 2]
    assert abs(abs(axis @ expected) - 1.0) < 1e-6
    assert page.errors == []


def test_live_viewer_draws_the_cell(robot, page) -> None:
    with Viewer(robot) as viewer:
        viewer.display(Q_AWAY)
        page.goto(viewer.url)
        page.wait_for_function("() => window.viewer && viewer.connection && viewer.connection.readyState === 1")
        before = slate_pixels(shot(page, "live_no_cell.png"))
        viewer.draw_cell(cell(np.zeros(3)))
        page.wait_for_function("() => viewer.scene_tree.children.meshcat.children.cell !== undefined")
        after = slate_pixels(shot(page, "live_cell.png"))
        viewer.draw_cell(Cell())  # drawing again replaces the cell: none left
        page.wait_for_function("() => { const c = viewer.scene_tree.children.meshcat.children.cell; "
                               "return c === undefined || Object.keys(c.children).length === 0; }")  # fmt: skip
        cleared = slate_pixels(shot(page, "live_cell_cleared.png"))
    assert after > 2000 and before < 0.01 * after and cleared < 0.01 * after, (before, after, cleared)
    assert page.errors == []


def test_view_cli_draws_the_cell(robot, capsys, tmp_path: Path) -> None:
    path = tmp_path / "cell.yaml"
    path.write_text("obstacles:\n  - {name: post, shape: cylinder, radius: 0.04, length: 0.3, xyz: [0.3, 0, -0.1]}\n"
                    "carried: {shape: sphere, radius: 0.01, xyz: [0, 0, 0.01]}\n")  # fmt: skip
    html = tmp_path / "view.html"
    assert main(["view", "--html", str(html), "--cell", str(path)]) == 0
    commands = page_commands(html.read_text())
    assert last(commands, "set_object", "/meshcat/cell/post")["object"]["geometries"][0]["type"] == "CylinderGeometry"
    assert any(c["type"] == "set_object" and c["path"].endswith("/cell_carried") for c in commands)
    bad = tmp_path / "bad.yaml"
    bad.write_text("obstacles:\n  - {name: post, shape: cylinder, radius: .nan, length: 0.3}\n")
    capsys.readouterr()
    assert main(["view", "--html", str(tmp_path / "x.html"), "--cell", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "line 2" in err and not (tmp_path / "x.html").exists()
