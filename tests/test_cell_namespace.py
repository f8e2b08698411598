"""Issue 37, item 5, "one namespace", with the accepted collisions of its list that it closes (inputs that lie, round
4; the foil passed between samples is the certificate's, tests/test_cell_motion.py):

- an obstacle NAMED like a robot link (``flange``) with ``allow: [[flange, link2]]`` switched off the robot's own
  link2 - flange pair (a motion 10 mm through the arm was accepted, exit 0, CSV written): a name is a link, the
  carried part or an obstacle, never two of them;
- a closed mesh with ``scale: -1`` (inverted winding) was a hollow surface: a robot inside a 1 m crate was "clear";
  a closed mesh is a solid whatever its winding or scale sign (convex: its hull), or refused (not convex);
- a carried part running up through the flange, the quill and link2 (a sign slip) was "in contact at every
  sampled configuration (part of the design)" and never checked: it is an error naming the overlap, with the hint
  that tool0's z points down.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cell import Cell, InCollisionError, Obstacle, Shape, load_cell, scene
from scara_pin.cli import main
from scara_pin.errors import InvalidInputError

MOVE = ["--from", "0", "0.1", "0", "0", "--to", "0.5", "0.6", "0.02", "0.3"]


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def box_triangles(size: float, winding: int = 1) -> np.ndarray:
    """(12, 3, 3) the triangles of a cube of edge ``size`` centred at 0, outward (winding 1) or inward (-1).

    Written here from the cube's corners, not by the package's reader.
    """
    h = size / 2
    c = np.array([[x, y, z] for x in (-h, h) for y in (-h, h) for z in (-h, h)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = [c[[a, b, cc]] for a, b, cc, d in quads] + [c[[a, cc, d]] for a, b, cc, d in quads]
    return np.array([t if winding > 0 else t[::-1] for t in tris])


def write_stl(path: Path, triangles: np.ndarray) -> None:
    record = np.zeros(len(triangles), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    record["v"] = triangles
    path.write_bytes(b"\0" * 80 + struct.pack("<I", len(triangles)) + record.tobytes())


# --------------------------------------------------------------------------------------------- names
def test_an_obstacle_named_like_a_link_with_allow_is_refused_and_no_output_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """The issue's case: ``flange`` (an obstacle far away) and ``allow: [[flange, link2]]``: exit 2 naming both the
    obstacle and the link; the CSV is not written (it was, exit 0, the quill 10 mm into link2)."""
    (tmp_path / "cell.yaml").write_text("obstacles:\n  - {name: flange, shape: box, size: [0.1, 0.1, 0.1], "
                                        "xyz: [1, 1, 0]}\nallow: [[flange, link2]]\n")  # fmt: skip
    out = tmp_path / "t.csv"
    # the quill raised into link2: the tool 10 mm above the top of the collision-free stroke (z above -0.042 m)
    assert main(["traj", "--cell", str(tmp_path / "cell.yaml"), "--from", "0", "1", "-0.032", "0", "--to", "0.5",
                 "1", "-0.032", "0", "--out", str(out)]) == 2  # fmt: skip
    error = capsys.readouterr().err.strip()
    assert error.startswith("error: ") and "\n" not in error
    assert "cell.yaml line 2: obstacle 'flange' has the name of a link of robot default (flange)" in error, error
    assert not out.exists()


@pytest.mark.parametrize("name", ["base_link", "link1", "link2", "quill", "flange", "tool0", "base"])
def test_no_obstacle_takes_a_link_name(name: str, robot: sp.Robot) -> None:
    """Every link of the robot, with collision geometry or not (tool0, base): refused at the scene, naming both."""
    cell = Cell((Obstacle(name, Shape("sphere", (0.01,), np.array([1.0, 1.0, 0.0]), np.zeros(3)), 4),),
                origin="c.yaml")  # fmt: skip
    with pytest.raises(InvalidInputError, match=rf"c.yaml line 4: obstacle '{name}' has the name of a link of robot "
                       rf"default \({name}\)"):  # fmt: skip
        scene(robot, cell)


def test_allow_names_resolve_to_one_thing_each(robot: sp.Robot) -> None:
    """With the names apart, ``allow`` switches off exactly the pair it names: an obstacle's, or the robot's own."""
    post = Obstacle("post", Shape("cylinder", (0.02, 0.3), np.array([0.3, 0.0, -0.05]), np.zeros(3)))
    plain = scene(robot, Cell((post,)))
    allowed = scene(robot, Cell((post,), allow=(("post", "link2"), ("link2", "flange"))))
    labels = {p.label for p in plain.pairs} - {p.label for p in allowed.pairs}
    assert labels == {"link2 - post", "link2 - flange (self)"}
    assert ("link2", "flange", "allowed by the cell") in allowed.self_pairs.disabled


# --------------------------------------------------------------------------------------------- closed meshes
@pytest.mark.parametrize(("winding", "scale"), [(1, "1"), (1, "-1"), (-1, "1"), (-1, "[1, 1, -1]"), (1, "[-1, 1, 1]")])
def test_a_closed_mesh_is_a_solid_whatever_its_winding_or_scale_sign(
        winding: int, scale: str, tmp_path: Path, robot: sp.Robot) -> None:  # fmt: skip
    """The issue's crate: a closed 1 m cube around the robot, ``scale: -1`` (and a file wound inward): the robot
    inside it is in collision (it was "clear": a hollow surface), and the distance is the solid's."""
    write_stl(tmp_path / "crate.stl", box_triangles(1.0, winding))
    (tmp_path / "cell.yaml").write_text(f"obstacles:\n  - {{name: crate, shape: mesh, file: crate.stl, scale: {scale}, "
                                        "xyz: [0, 0, 0]}\n")  # fmt: skip
    cell = load_cell(tmp_path / "cell.yaml")
    assert cell.obstacles[0].shape.closure() == (True, True)
    sc = scene(robot, cell)
    with pytest.raises(InCollisionError, match="deep in crate"):
        sc.check(np.zeros(4), "the start")
    # the same crate 1 m away along x: the flange (a disc of radius 0.025 m about x = 0.4 m at q = 0) is
    # 1 - 0.5 - 0.4 - 0.025 m from its face
    (tmp_path / "far.yaml").write_text(f"obstacles:\n  - {{name: crate, shape: mesh, file: crate.stl, scale: {scale}, "
                                       "xyz: [1, 0, 0]}\n")  # fmt: skip
    d = scene(robot, load_cell(tmp_path / "far.yaml")).distances(np.zeros(4)).pairs
    flange = next(p for p in d if p.pair.a == "flange")
    assert flange.distance == pytest.approx(1.0 - 0.5 - 0.4 - 0.025, abs=1e-9)


def test_a_robot_inside_the_crate_is_refused_by_the_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write_stl(tmp_path / "crate.stl", box_triangles(1.0))
    (tmp_path / "cell.yaml").write_text("obstacles:\n  - {name: crate, shape: mesh, file: crate.stl, scale: -1}\n")
    out = tmp_path / "t.csv"
    assert main(["traj", "--cell", str(tmp_path / "cell.yaml"), *MOVE, "--out", str(out)]) == 2
    error = capsys.readouterr().err
    assert "in collision" in error and "crate" in error, error
    assert not out.exists()


def test_a_closed_mesh_that_is_not_convex_is_refused_and_an_open_one_is_a_surface(robot: sp.Robot) -> None:
    """A ball with a dent (one vertex pushed halfway to the centre): closed, not convex, so neither its hull (that
    would fill the dent) nor its surface (a robot inside would be clear) is right: refused, naming the mesh. The
    same triangles less one (open) are a surface, as documented."""
    import trimesh

    ball = trimesh.creation.icosphere(subdivisions=1, radius=0.05)
    vertices = np.array(ball.vertices)
    vertices[0] *= 0.5
    faces = np.array(ball.faces)

    def mesh(f: np.ndarray) -> Shape:
        return Shape("mesh", (), np.array([0.3, 0.3, -0.1]), np.zeros(3), vertices, f, "dent.stl", "obstacle dent")

    assert mesh(faces).closure() == (True, False)
    with pytest.raises(InvalidInputError, match="obstacle dent: mesh dent.stl is closed but not convex"):
        scene(robot, Cell((Obstacle("dent", mesh(faces)),)))
    assert mesh(faces[1:]).closure() == (False, False)
    assert {p.b for p in scene(robot, Cell((Obstacle("dent", mesh(faces[1:])),))).pairs} >= {"dent"}


# --------------------------------------------------------------------------------------------- the carried part
@pytest.mark.parametrize(("size", "xyz", "deep"), [
    ((0.04, 0.04, 0.03), (0.0, 0.0, -0.015), "quill"),  # docs/cell.md's sign slip: inside the flange and the quill
    ((0.02, 0.02, 0.4), (0.0, 0.0, -0.1), "link2"),  # the issue's: up through the flange, the quill and link2
])  # fmt: skip
def test_a_carried_part_through_the_arm_is_an_error_with_the_sign_hint(size: tuple[float, ...], xyz: tuple[float, ...],
                                                                       deep: str, robot: sp.Robot) -> None:  # fmt: skip
    cell = Cell(carried=Shape("box", size, np.array(xyz), np.zeros(3)), origin="cell.yaml")
    with pytest.raises(InvalidInputError) as found:
        scene(robot, cell)
    message = str(found.value)
    assert "the carried part overlaps the arm at every configuration" in message, message
    assert f"deep in {deep}" in message and "z axis points out of the flange (down)" in message, message
    assert f"[{', '.join(f'{v:g}' for v in xyz)}]" in message


def test_a_carried_part_hanging_from_the_flange_is_the_design(robot: sp.Robot) -> None:
    """Its top face ON the flange's face (distance 0: the job's default carry) is a contact, not an overlap; its pairs
    with the links it does not touch at every configuration are checked."""
    sc = scene(robot, Cell(carried=Shape("box", (0.04, 0.04, 0.03), np.array([0.0, 0.0, 0.015]), np.zeros(3))))
    assert ("flange", "carried", "adjacent") in sc.self_pairs.disabled
    assert ("link2", "carried") in sc.self_pairs.checked
    assert not any(r == "always in contact" and "carried" in (a, b) for a, b, r in sc.self_pairs.disabled)
