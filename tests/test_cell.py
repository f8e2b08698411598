"""The cell's geometry layer (scara_pin.cell): files, the robot's collision model, distances and their derivatives.

Independent routes for every expected value:

- distances: closed forms written here from the URDF's numbers of the default robot (link1 and link2 boxes
  of half-width = half-height 0.04 / 0.03 along the arm, a quill of radius 0.01 rising 0.25 m above a flange
  of radius 0.025 and thickness 0.01, the tool at z = -0.05 - q3; arm frames from the closed-form FK
  l1 = l2 = 0.2 m) against obstacles placed at random (seeded): sphere-sphere-like (sphere against the
  flange's axis when it is above the flange), sphere-box, box-box (axis-aligned), parallel cylinders, a vertical
  post against a box (two vertical prisms) — to 1e-9 m;
- the derivative dd/dq: central finite differences of the distance itself;
- the self-collision pairs: the kinematic tree written here (which link hangs on which).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from scara_pin import InvalidInputError, load_robot
from scara_pin.cell import Cell, InCollisionError, Obstacle, Shape, load_cell, parse_cell, scene
from scara_pin.cli import main

TOL = 1e-9  # [m] coal's distances against the closed forms
MARGIN = 0.002
EXAMPLE = """\
margin: 0.002              # smallest distance kept [m]
obstacles:
  - name: post
    shape: cylinder
    radius: 0.02
    length: 0.20
    xyz: [0.306, -0.052, -0.10]
    rpy: [0, 0, 0]
carried:
  shape: box
  size: [0.04, 0.04, 0.03]
  xyz: [0, 0, 0.015]
allow: [[link1, base_link]]
"""


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


def _frames(q):
    """(elbow (2,), tool (3,), arm angles) of the default robot in closed form."""
    a1, a12 = q[0], q[0] + q[1]
    elbow = 0.2 * np.array([math.cos(a1), math.sin(a1)])
    tool = np.array([*(elbow + 0.2 * np.array([math.cos(a12), math.sin(a12)])), -0.05 - q[2]])
    return elbow, tool, (a1, a12)


def _box_point(p, centre, angle, half):
    """Distance from point p (3,) to a box turned by ``angle`` about z, half sides ``half``."""
    c, s = math.cos(angle), math.sin(angle)
    d = p - centre
    local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]])
    return float(np.linalg.norm(np.maximum(np.abs(local) - half, 0.0)))


def _cyl_point(p, bottom, radius, height):
    """Distance from point p to a vertical cylinder standing on ``bottom`` (3,)."""
    rho = math.hypot(p[0] - bottom[0], p[1] - bottom[1])
    dz = max(bottom[2] - p[2], p[2] - bottom[2] - height, 0.0)
    return math.hypot(max(rho - radius, 0.0), dz)


def _obstacle(shape, size, xyz, name="o"):
    return Obstacle(name, Shape(shape, size, np.asarray(xyz, dtype=float), np.zeros(3)))


def _distance(robot, q, cell, a, b):
    """The distance of link ``a`` (all its shapes) to ``b``."""
    return min(p.distance for p in robot.distances(q, cell).pairs if (p.pair.a, p.pair.b) == (a, b))


# link2's collision shapes (URDF): a box from the elbow up to 5 mm short of the flange's edge (0.2 - 0.025 - 0.005
# = 0.17 m long, half width and height 0.03) and its end, from there to the quill's axis, only from 5 mm above the
# flange's top at the top of the stroke (z = 0.01 + 0.005) up to the arm's top (z = 0.03)
LINK2_BODY, LINK2_END = 0.17, (0.015, 0.03)


# ---------------------------------------------------------------------------------------------- closed forms
def test_sphere_against_the_links(robot, rng):
    """A sphere against the flange (cylinder), link1 and link2 (boxes): point-to-shape distance minus radius."""
    for _ in range(25):
        q = rng.uniform([-2.0, -2.4, -0.04, -3.0], [2.0, 2.4, 0.09, 3.0])
        elbow, tool, (a1, a12) = _frames(q)
        c = np.array([rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), rng.uniform(-0.2, 0.2)])
        r = rng.uniform(0.005, 0.03)
        cell = Cell((_obstacle("sphere", (r,), c, "ball"),), MARGIN)
        flange = _cyl_point(c, tool, 0.025, 0.01) - r
        link1 = _box_point(c, np.array([*(elbow / 2), 0.0]), a1, np.array([0.1, 0.04, 0.04])) - r
        mid2 = elbow + (LINK2_BODY / 2) * np.array([math.cos(a12), math.sin(a12)])
        body = _box_point(c, np.array([*mid2, 0.0]), a12, np.array([LINK2_BODY / 2, 0.03, 0.03])) - r
        mid_end = elbow + (0.1 + LINK2_BODY / 2) * np.array([math.cos(a12), math.sin(a12)])
        half_end = np.array([(0.2 - LINK2_BODY) / 2, 0.03, (LINK2_END[1] - LINK2_END[0]) / 2])
        end = _box_point(c, np.array([*mid_end, sum(LINK2_END) / 2]), a12, half_end) - r
        link2 = min(body, end)
        for name, expected in (("flange", flange), ("link1", link1), ("link2", link2)):
            if expected > 1e-4:  # separated: the closed form is the distance (inside, coal gives a depth)
                assert _distance(robot, q, cell, name, "ball") == pytest.approx(expected, abs=TOL), name


def test_parallel_cylinders_and_prisms(robot, rng):
    """A vertical post against the quill and the flange (parallel cylinders) and link2 (two vertical prisms)."""
    checked = 0
    for _ in range(40):
        q = rng.uniform([-2.0, -2.4, -0.04, -3.0], [2.0, 2.4, 0.09, 3.0])
        elbow, tool, (a1, a12) = _frames(q)
        x, y, rp = rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), rng.uniform(0.005, 0.03)
        lo, hi = sorted(rng.uniform(-0.3, 0.3, 2))
        cell = Cell((_obstacle("cylinder", (rp, hi - lo), (x, y, (lo + hi) / 2), "post"),), MARGIN)
        rho = math.hypot(tool[0] - x, tool[1] - y)

        def prisms(plan, z0, z1, lo=lo, hi=hi):  # two vertical prisms: plan gap and height gap
            gap = max(lo - z1, z0 - hi, 0.0)
            return math.hypot(max(plan, 0.0), gap)

        quill = prisms(rho - 0.01 - rp, tool[2], tool[2] + 0.25)
        flange = prisms(rho - 0.025 - rp, tool[2], tool[2] + 0.01)
        c, s = math.cos(a12), math.sin(a12)
        d = np.array([x, y]) - (elbow + (LINK2_BODY / 2) * np.array([c, s]))
        local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
        body = prisms(float(np.linalg.norm(np.maximum(np.abs(local) - [LINK2_BODY / 2, 0.03], 0.0))) - rp, -0.03, 0.03)
        d = np.array([x, y]) - (elbow + (0.1 + LINK2_BODY / 2) * np.array([c, s]))
        local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
        end = prisms(float(np.linalg.norm(np.maximum(np.abs(local) - [(0.2 - LINK2_BODY) / 2, 0.03], 0.0))) - rp,
                     *LINK2_END)
        link2 = min(body, end)
        for name, expected in (("quill", quill), ("flange", flange), ("link2", link2)):
            if expected > 1e-4:
                checked += 1
                assert _distance(robot, q, cell, name, "post") == pytest.approx(expected, abs=TOL), name
    assert checked > 60


def test_box_against_the_carried_box(robot, rng):
    """An axis-aligned box against the carried box (yaw 0: axis-aligned too): the per-axis gaps' norm."""
    for _ in range(25):
        q = np.array([rng.uniform(-1.0, 1.0), rng.uniform(0.5, 2.0), rng.uniform(-0.04, 0.09), 0.0])
        q[3] = -(q[0] + q[1])  # tool yaw 0: the carried box is axis-aligned
        _, tool, _ = _frames(q)
        carried = Shape("box", (0.04, 0.04, 0.03), np.array([0.0, 0.0, 0.015]), np.zeros(3))
        centre = tool + np.array([0.0, 0.0, -0.015])  # tool0's z points down: +0.015 in the tool is 15 mm lower
        c = centre + rng.uniform([-0.2, -0.2, -0.1], [0.2, 0.2, 0.1])
        size = rng.uniform(0.01, 0.1, 3)
        cell = Cell((_obstacle("box", tuple(size), c, "crate"),), MARGIN, carried)
        gaps = np.maximum(np.abs(c - centre) - (size / 2 + np.array([0.02, 0.02, 0.015])), 0.0)
        expected = float(np.linalg.norm(gaps))
        if expected > 1e-4:
            assert _distance(robot, q, cell, "carried", "crate") == pytest.approx(expected, abs=TOL)


def test_the_derivative_is_the_finite_difference(robot, rng):
    cell = load_cell_text(EXAMPLE)
    sc = scene(robot, cell)
    for _ in range(5):
        q = rng.uniform([-1.5, -2.0, -0.04, -3.0], [1.5, 2.0, 0.09, 3.0])
        d, G = sc.gradients(q)
        eps = 1e-5
        for j in range(4):
            dq = np.zeros(4)
            dq[j] = eps
            fd = (sc.distance_array(q + dq)[0] - sc.distance_array(q - dq)[0]) / (2 * eps)
            assert np.allclose(G[:, j], fd, atol=2e-5), (j, G[:, j] - fd)
        assert np.allclose(d, sc.distance_array(q)[0], atol=1e-12)


def test_witness_points_and_normal(robot):
    q = np.zeros(4)
    cell = Cell((_obstacle("sphere", (0.01,), (0.5, 0.0, -0.045), "ball"),), MARGIN)
    found = [p for p in robot.distances(q, cell).pairs if p.pair.a == "flange"][0]
    # the flange (z from -0.05 to -0.04) faces the sphere's centre with its rim: (0.425, 0, -0.045) in base
    assert found.distance == pytest.approx(0.5 - 0.425 - 0.01, abs=TOL)
    assert found.point_a == pytest.approx([0.425, 0.0, -0.045], abs=1e-9)
    assert found.normal == pytest.approx([1.0, 0.0, 0.0], abs=1e-9)
    assert found.point_b == pytest.approx([0.49, 0.0, -0.045], abs=1e-9)


# ---------------------------------------------------------------------------------------------- pairs
def test_self_pairs_are_chosen_as_the_assistant_does(robot):
    sc = scene(robot, Cell())
    # the tree: base_link - link1 - link2 - quill - flange; adjacent pairs never checked
    disabled = {(a, b): why for a, b, why in sc.self_pairs.disabled}
    assert disabled == {("base_link", "link1"): "adjacent", ("link1", "link2"): "adjacent",
                        ("link2", "quill"): "adjacent", ("quill", "flange"): "adjacent"}  # fmt: skip
    assert set(sc.self_pairs.checked) == {("base_link", "link2"), ("base_link", "quill"), ("base_link", "flange"),
                                          ("link1", "quill"), ("link1", "flange"), ("link2", "flange")}  # fmt: skip


def test_allow_removes_pairs_and_unknown_names_are_refused(robot):
    cell = parse_cell(EXAMPLE + "", "cell.yaml")
    cell = Cell(cell.obstacles, cell.margin, cell.carried, (("link2", "post"), ("quill", "link1")), "cell.yaml")
    labels = {p.label for p in scene(robot, cell).pairs}
    assert "link2 - post" not in labels and "link1 - quill (self)" not in labels and "flange - post" in labels
    bad = Cell(cell.obstacles, cell.margin, None, (("link9", "post"),), "cell.yaml")
    with pytest.raises(InvalidInputError, match="link9"):
        scene(robot, bad)


def test_a_palletizer_parallelogram_is_always_in_contact():
    """The palletizer's links meet at their joints: the pairs in contact at every sample are disabled."""
    pal = load_robot("palletizer")
    sc = scene(pal, Cell())
    reasons = {frozenset((a, b)): why for a, b, why in sc.self_pairs.disabled}
    assert reasons[frozenset(("big_arm", "turret"))] == "adjacent"
    for a, b in sc.self_pairs.checked:  # every pair checked is clear somewhere (q = 0 at least, or a sample)
        assert frozenset((a, b)) not in reasons


# ---------------------------------------------------------------------------------------------- files
def load_cell_text(text: str, tmp: Path | None = None) -> Cell:
    return parse_cell(text, "cell.yaml", tmp)


def test_the_issue_example_reads(tmp_path):
    path = tmp_path / "cell.yaml"
    path.write_text(EXAMPLE)
    cell = load_cell(path)
    assert cell.margin == 0.002 and [o.name for o in cell.obstacles] == ["post"]
    post = cell.obstacles[0]
    assert post.shape.kind == "cylinder" and post.shape.size == (0.02, 0.2) and post.line == 3
    assert post.shape.xyz.tolist() == [0.306, -0.052, -0.10]
    assert cell.carried is not None and cell.carried.size == (0.04, 0.04, 0.03)
    assert cell.allow == (("link1", "base_link"),)


@pytest.mark.parametrize("text, words", [
    ("obstacles: [\n  - {name: a, shape: box, size: [1, 2]]\n", "line"),  # malformed YAML
    ("obstacles:\n  - name: a\n    shape: box\n    size: [0.1, -0.2, 0.1]\n", "obstacle a: box y -0.2"),
    ("obstacles:\n  - name: a\n    shape: sphere\n    radius: .nan\n", "line 4"),
    ("obstacles:\n  - name: a\n    shape: sphere\n    radius: 0x10\n", "line 4: obstacle a: radius must be a number"),
    ("obstacles:\n  - name: a\n    shape: sphere\n    radius: 1e400\n",
     "line 4: obstacle a: radius inf is not a plain"),
    ("obstacles:\n  - name: a\n    shape: sphere\n    radius: '0.1'\n", "line 4: obstacle a: radius must be a number"),
    ("obstacles:\n  - name: a\n    shape: cone\n", "line 3: obstacle a: shape 'cone' must be one of"),
    ("obstacles:\n  - name: a\n    shape: sphere\n    radius: 0.1\n    colour: red\n",
     "line 5: obstacle a: unknown key"),
    ("obstacles:\n  - {name: a, shape: sphere, radius: 0.1}\n  - {name: a, shape: sphere, radius: 0.1}\n",
     "line 3: obstacle name 'a' is used twice"),
    ("margin: -1\n", "line 1: margin -1 m must be in [0, 1] m"),
    ("obstacles:\n  - {name: 'a b', shape: sphere, radius: 0.1}\n", "line 2"),
    ("obstacles:\n  - {name: a, shape: sphere, radius: 0.1, xyz: [1, 2]}\n", "xyz must be a list of 3 numbers"),
    ("obstacles:\n  - {name: a, shape: sphere, radius: 0.1, xyz: [1e9, 0, 0]}\n", "xyz must be 3 finite numbers"),
    ("walls: []\n", "line 1: unknown key 'walls'"),
    ("format: scara-pin cell 2\n", "is not 'scara-pin cell 1'"),
    ("", "empty"),
])  # fmt: skip
def test_bad_cell_files_name_the_file_and_line(tmp_path, text, words, capsys):
    path = tmp_path / "cell.yaml"
    path.write_text(text)
    with pytest.raises(InvalidInputError) as exc:
        load_cell(path)
    assert str(path) in str(exc.value) and words in str(exc.value), str(exc.value)
    code = main(["ik", "--cell", str(path), "0.3", "0.1", "-0.1", "0.5"])  # the CLI: exit 2, one line
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1 and words in err


def test_an_alias_bomb_is_refused_before_it_expands(tmp_path):
    """9 levels of 9 aliases (9^9 leaves in 500 bytes): refused at the node cap, never expanded."""
    import time

    levels = ["a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    for prev, name in zip("abcdefgh", "bcdefghi"):
        levels.append(f"{name}: &{name} [" + ", ".join([f"*{prev}"] * 9) + "]")
    path = tmp_path / "bomb.yaml"
    path.write_text("\n".join(levels) + "\n")
    t0 = time.perf_counter()
    with pytest.raises(InvalidInputError, match="holds more than"):
        load_cell(path)
    assert time.perf_counter() - t0 < 5.0


def test_caps_are_checked_before_the_work(tmp_path, monkeypatch):
    from scara_pin import limits

    many = "obstacles:\n" + "".join(f"  - {{name: o{i}, shape: sphere, radius: 0.01}}\n" for i in range(501))
    path = tmp_path / "many.yaml"
    path.write_text(many)
    with pytest.raises(InvalidInputError, match="above the cap of 500"):
        load_cell(path)
    assert limits.MAX_CELL_OBSTACLES == 500


def _write_stl(path: Path, subdivisions: int = 3) -> int:
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.05)
    mesh.export(path)
    return len(mesh.faces)


def test_a_mesh_obstacle_is_read_and_checked(tmp_path, robot):
    faces = _write_stl(tmp_path / "ball.stl")
    (tmp_path / "cell.yaml").write_text("obstacles:\n  - {name: ball, shape: mesh, file: ball.stl, scale: 2, "
                                        "xyz: [0.6, 0.0, -0.045], rpy: [0.1, 0.2, 0.3]}\n")  # fmt: skip
    cell = load_cell(tmp_path / "cell.yaml")
    assert cell.obstacles[0].shape.triangles == faces
    d = _distance(robot, np.zeros(4), cell, "flange", "ball")
    # an icosphere of radius 0.1 (scaled) is inscribed in the sphere: a little farther than the sphere's 0.075 m,
    # by at most its radius times (1 - cos) of the largest angle from a face's centre to its corners (< 8 deg)
    assert 0.6 - 0.1 - 0.425 <= d <= 0.6 - 0.1 * math.cos(math.radians(8)) - 0.425


def test_the_closest_pair_of_each_sample_is_the_minimum_over_every_pair(tmp_path, robot, rng):
    """Scene.nearest_array (the verifier's per-sample read) against the minimum of every pair's distance, and those
    against coal called here on the scene's own GeometryModel: an open mesh (a bowl: bounded by spheres when far),
    a box and a sphere, the carried part; configurations near and far from them."""
    import coal
    import pinocchio as pin
    import trimesh

    from scara_pin.cell import scene as make_scene

    bowl = trimesh.creation.icosphere(subdivisions=2, radius=0.05)
    bowl.update_faces(bowl.triangles_center[:, 2] < 0.02)  # the cap cut off: an open surface, not a solid
    bowl.export(tmp_path / "bowl.stl")
    (tmp_path / "cell.yaml").write_text(
        "obstacles:\n"
        "  - {name: bowl, shape: mesh, file: bowl.stl, xyz: [0.3, 0.1, -0.12]}\n"
        "  - {name: crate, shape: box, size: [0.05, 0.08, 0.06], xyz: [0.1, -0.3, -0.1], rpy: [0, 0, 0.4]}\n"
        "  - {name: ball, shape: sphere, radius: 0.03, xyz: [-0.25, 0.2, -0.08]}\n"
        "carried: {shape: box, size: [0.02, 0.02, 0.02], xyz: [0, 0, 0.01]}\n")  # fmt: skip
    sc = make_scene(robot, load_cell(tmp_path / "cell.yaml"))
    assert sc._far_pairs, "the bowl is a surface: its pairs are bounded when far"
    Q = rng.uniform(robot.limits.lower, robot.limits.upper, (300, 4))
    D = sc.distance_array(Q)
    d, which = sc.nearest_array(Q)
    np.testing.assert_array_equal(d, D.min(axis=1))
    np.testing.assert_array_equal(D[np.arange(len(Q)), which], d)
    # every pair coal computes exactly (not bounded) against coal's distance called here
    model, data, gm = robot.model, robot.model.createData(), sc.geometry_model
    gd = gm.createData()
    for q, row in zip(Q[:40], D[:40]):
        pin.updateGeometryPlacements(model, data, gm, gd, robot.to_pinocchio_q(q))
        for k, pair in enumerate(sc.pairs):
            a, b = gm.geometryObjects[pair.first], gm.geometryObjects[pair.second]
            request, result = coal.DistanceRequest(), coal.DistanceResult()
            request.gjk_tolerance = 1e-10  # coal's default (1e-6) stops about 1e-8 m short for a box and a cylinder
            exact = coal.distance(a.geometry, gd.oMg[pair.first], b.geometry, gd.oMg[pair.second], request, result)
            if k in sc._far_pairs and row[k] > 0.05:
                assert row[k] <= exact + 1e-12  # a lower bound where far
            elif exact > 0:
                assert row[k] == pytest.approx(exact, abs=1e-9), pair.label


def test_a_mesh_with_too_many_triangles_is_refused(tmp_path, monkeypatch):
    from scara_pin.cell import shapes

    _write_stl(tmp_path / "ball.stl", 4)  # 5120 triangles
    (tmp_path / "cell.yaml").write_text("obstacles:\n  - {name: ball, shape: mesh, file: ball.stl}\n")
    monkeypatch.setattr("scara_pin.limits.MAX_CELL_TRIANGLES", 5000)
    with pytest.raises(InvalidInputError, match="5,120|5120"):
        load_cell(tmp_path / "cell.yaml")
    assert shapes.KINDS


def test_a_missing_mesh_names_the_line(tmp_path):
    (tmp_path / "cell.yaml").write_text("obstacles:\n  - name: ball\n    shape: mesh\n    file: nowhere.stl\n")
    with pytest.raises(InvalidInputError, match=r"line 4: obstacle ball: mesh 'nowhere.stl'"):
        load_cell(tmp_path / "cell.yaml")


URDF_CELL = """<?xml version="1.0"?>
<robot name="cell">
  <link name="floor"/>
  <link name="feeder"><collision><origin xyz="0.1 0 0"/><geometry><box size="0.1 0.2 0.3"/></geometry></collision>
    <collision><origin xyz="0 0 0.5" rpy="0 1.5707963267948966 0"/><geometry><cylinder radius="0.02" length="0.3"/>
    </geometry></collision></link>
  <joint name="floor_feeder" type="fixed"><parent link="floor"/><child link="feeder"/>
    <origin xyz="0.3 0.2 -0.1" rpy="0 0 0.5"/></joint>
</robot>
"""


def test_a_urdf_cell_places_its_collisions_in_the_base_frame(tmp_path):
    path = tmp_path / "cell.urdf"
    path.write_text(URDF_CELL)
    cell = load_cell(path)
    assert [o.name for o in cell.obstacles] == ["feeder", "feeder_1"]
    box, bar = (o.shape for o in cell.obstacles)
    c, s = math.cos(0.5), math.sin(0.5)
    assert box.kind == "box" and box.size == pytest.approx((0.1, 0.2, 0.3))
    assert box.xyz == pytest.approx([0.3 + 0.1 * c, 0.2 + 0.1 * s, -0.1], abs=1e-12)
    assert bar.kind == "cylinder" and bar.xyz == pytest.approx([0.3, 0.2, 0.4], abs=1e-12)
    axis = bar.rotation[:, 2]  # the bar's own z: pitched 90 deg, then turned 0.5 rad
    assert axis == pytest.approx([c, s, 0.0], abs=1e-12)


def test_a_xacro_cell_and_a_moving_joint(tmp_path):
    (tmp_path / "cell.urdf.xacro").write_text(URDF_CELL.replace('<robot name="cell">',
        '<robot name="cell" xmlns:xacro="http://wiki.ros.org/xacro"><xacro:property name="h" value="0.3"/>')
        .replace('size="0.1 0.2 0.3"', 'size="0.1 0.2 ${h}"'))  # fmt: skip
    assert load_cell(tmp_path / "cell.urdf.xacro").obstacles[0].shape.size == pytest.approx((0.1, 0.2, 0.3))
    (tmp_path / "moving.urdf").write_text(URDF_CELL.replace('type="fixed"', 'type="revolute"'))
    with pytest.raises(InvalidInputError, match="fixed joints"):
        load_cell(tmp_path / "moving.urdf")


# ---------------------------------------------------------------------------------------------- ik and check
def test_ik_keeps_the_clear_solutions_and_names_the_pair(tmp_path, capsys):
    (tmp_path / "cell.yaml").write_text("obstacles:\n  - {name: post, shape: cylinder, radius: 0.01, length: 0.6, "
                                        "xyz: [0.12, 0.17, 0.0]}\n")  # fmt: skip
    assert main(["ik", "--json", "--cell", str(tmp_path / "cell.yaml"), "0.3", "0.1", "-0.1", "0.5"]) == 0
    import json

    out = json.loads(capsys.readouterr().out)
    assert [s["branch"] for s in out["solutions"]] == ["right"]
    (refused,) = out["cell"]["refused"]
    assert refused["branch"] == "left" and refused["status"] == "COLLISION" and "post" in refused["pair"]
    assert refused["distance"] < 0


def test_a_start_in_collision_is_refused_naming_the_pair(robot):
    from scara_pin.motion.jump import jump_move

    A = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
    cell = Cell((_obstacle("sphere", (0.01,), A[:3] + [0, 0, 0.005], "ball"),), MARGIN)
    with pytest.raises(InCollisionError, match="the start .* is in collision: .*ball"):
        jump_move(robot, A, A + [0, 0.3, 0, 0], cell=cell)
