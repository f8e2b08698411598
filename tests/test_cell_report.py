"""``check --cell`` (scara_pin.cell.report and the check command).

Expected values from closed forms of the default robot's URDF (l1 = l2 = 0.2 m; link2 a box 0.2 x 0.06 x 0.06
from the elbow; the flange a cylinder of radius 0.025 m, its bounding box's corner 0.025 sqrt(2) across; the
quill from the tool point up 0.25 m; the tool at z = -0.05 - q3, q3 in [-0.05, 0.1]), the penetration depth of
two axis-aligned boxes (the shortest move that separates them), and coal's distances over sampled configurations.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cell import Cell, Obstacle, Shape, scene
from scara_pin.cell.report import check_cell, reach_envelope
from scara_pin.cli import main

MARGIN = 0.002
CARRIED = Shape("box", (0.04, 0.04, 0.03), np.array([0.0, 0.0, 0.015]), np.zeros(3))  # 0 to 0.03 below the tool


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def sphere(name: str, x: float, y: float, z: float, r: float = 0.01) -> Obstacle:
    return Obstacle(name, Shape("sphere", (r,), np.array([x, y, z]), np.zeros(3)))


def test_reach_envelope_is_the_closed_form_and_holds_the_robot(robot) -> None:
    sc = scene(robot, Cell((), MARGIN, carried=CARRIED))
    env = reach_envelope(sc)
    assert env.exact_chain
    np.testing.assert_allclose(env.point, [0.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(env.axis, [0.0, 0.0, 1.0], atol=1e-12)
    assert env.radius == pytest.approx(0.2 + 0.2 + 0.025 * math.sqrt(2), abs=1e-12)  # the flange's box corner
    assert env.low == pytest.approx(-0.05 - 0.1 - 0.03, abs=1e-12)  # the carried box's bottom, quill down
    assert env.high == pytest.approx(-0.05 + 0.05 + 0.25, abs=1e-12)  # the quill's top, quill up
    # every geometry inside it at sampled configurations (coal: a shape inside the cylinder is at distance <= 0
    # from it, and its bounding box's corners are within the radius and the heights)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = lo + (hi - lo) * np.random.default_rng(5).random((300, 4))
    Q[:4] = np.array([[0, 0, lo[2], 0], [0, 0, hi[2], 0], [1, 0, hi[2], 2], [-1, 0.3, lo[2], -3]])
    import pinocchio as pin

    gm = sc.geometry_model
    gd = gm.createData()
    data = robot.model.createData()
    bMo = robot.data.oMf[robot.base_id].inverse()
    for q in Q:
        pin.updateGeometryPlacements(robot.model, data, gm, gd, q)
        for i, g in enumerate(gm.geometryObjects):
            if g.parentJoint == 0:
                continue
            g.geometry.computeLocalAABB()
            a, b = np.asarray(g.geometry.aabb_local.min_), np.asarray(g.geometry.aabb_local.max_)
            corners = np.array([[x, y, z] for x in (a[0], b[0]) for y in (a[1], b[1]) for z in (a[2], b[2])])
            M = bMo * gd.oMg[i]
            pts = corners @ M.rotation.T + M.translation
            assert np.hypot(pts[:, 0], pts[:, 1]).max() <= env.radius + 1e-12
            assert env.low - 1e-12 <= pts[:, 2].min() and pts[:, 2].max() <= env.high + 1e-12


def test_obstacles_out_of_reach_are_found_and_never_reached(robot) -> None:
    R = 0.4 + 0.025 * math.sqrt(2)
    far = sphere("far", R + MARGIN + 0.01 + 1e-3, 0.0, -0.1)  # 1 mm beyond the envelope and the margin
    near = sphere("near", R + 0.01 - 1e-3, 0.0, -0.1)  # 1 mm inside
    high = sphere("high", 0.2, 0.0, 0.25 + MARGIN + 0.01 + 1e-3)  # above the quill's highest top
    sc = scene(robot, Cell((far, near, high), MARGIN))
    report = check_cell(sc, [("home (q = 0)", np.zeros(4))])
    out = report.find("obstacle-out-of-reach")
    assert [f.data["obstacle"] for f in out] == ["far"]
    above = report.find("obstacle-beyond-stroke")  # above the quill's top, inside the footprint: not misplaced
    assert [(f.severity, f.data["obstacle"]) for f in above] == [("info", "high")]
    assert "high is above the robot's reach" in above[0].message and "millimetres" not in above[0].message
    assert out[0].data["distance"] == pytest.approx(MARGIN + 1e-3, abs=1e-9)
    assert "reach envelope (a cylinder about the first joint's axis" in out[0].message
    assert report.status == "warnings" and report.exit_code == 4
    # sampled configurations never bring "far" or "high" within the margin
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = lo + (hi - lo) * np.random.default_rng(9).random((3000, 4))
    Q[:, 1] = np.clip(Q[:, 1], -0.05, 0.05)  # stretched arms: the farthest reach
    D = sc.distance_array(Q)
    for pair in sc.pairs:
        if pair.b in ("far", "high"):
            assert D[:, pair.index].min() > MARGIN


def test_home_and_points_in_collision_name_the_pair_and_the_depth(robot) -> None:
    # at q = 0 link2's box spans x 0.2 .. 0.37 (it ends 5 mm short of the flange's edge), |y|, |z| <= 0.03; a wall
    # x 0.30 .. 0.32, |y|, |z| <= 0.5 crossing it: the shortest move that separates them is along x,
    # min(0.37 - 0.30, 0.32 - 0.2) = 0.07 m deep (along y or z: 0.53 m); link2's cap over the quill starts at x 0.37
    wall = Obstacle("wall", Shape("box", (0.02, 1.0, 1.0), np.array([0.31, 0.0, 0.0]), np.zeros(3)))
    sc = scene(robot, Cell((wall,), MARGIN))
    report = check_cell(sc, [("home (q = 0)", np.zeros(4)), ("P1", [1.5, 0.5, 0.0, 0.0]), ("P2", [0.0, 0.0, 0.0, 0.0])])
    home = report.find("home-in-collision")
    assert len(home) == 1 and home[0].data["pair"] == ["link2", "wall"]
    assert home[0].data["distance"] == pytest.approx(-0.07, abs=1e-9)
    assert "link2 is 70 mm deep in wall" in home[0].message
    points = report.find("point-in-collision")
    assert [f.data["point"] for f in points] == ["P2"]  # P1 turns the arm away from the wall
    disabled = {tuple(f.data["pair"]): f.data["reason"] for f in report.find("self-pair-disabled")}
    assert disabled[("link1", "link2")] == "adjacent"
    assert ("link2", "flange") in {tuple(f.data["pair"]) for f in report.find("self-pair-checked")}


def test_a_clean_cell_is_clean(robot) -> None:
    report = check_cell(scene(robot, Cell((sphere("ball", 0.3, 0.0, -0.12, 0.02),), MARGIN)), [("home", np.zeros(4))])
    assert report.status == "clean" and report.exit_code == 0 and report.codes("warning") == []


# ------------------------------------------------------------------------------------------------ CLI
def run(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


@pytest.fixture(scope="module")
def urdf(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("urdf") / "default.urdf"
    path.write_text(sp.generate_urdf("default"))
    return path


def test_check_cell_cli(urdf, capsys, tmp_path: Path) -> None:
    cell = tmp_path / "cell.yaml"
    cell.write_text("margin: 0.002\nobstacles:\n"
                    "  - {name: wall, shape: box, size: [0.02, 1.0, 1.0], xyz: [0.31, 0.0, 0.0]}\n"
                    "  - {name: shelf, shape: box, size: [0.2, 0.2, 0.02], xyz: [600, 0, 0]}\n")  # fmt: skip
    points = tmp_path / "points.yaml"
    points.write_text("points:\n  - {name: home, q: [1.5, 0.5, 0.0, 0.0]}\n  - {name: P2, q: [0.0, 0.0, 0.0, 0.0]}\n")
    rc, out, err = run(capsys, ["check", str(urdf), "--cell", str(cell), "--points", str(points)])
    assert rc == 4, err
    assert f"{cell}: warning: obstacle shelf is out of reach" in out
    assert f"{cell}: warning: point P2 is in collision: link2 is 70 mm deep in wall" in out
    assert "home-in-collision" not in out  # the points file's home turns the arm away
    assert out.rstrip().endswith(f"{cell}: warnings")
    rc, out, err = run(capsys, ["check", str(urdf), "--cell", str(cell), "--json"])
    assert rc == 4, err
    doc = json.loads(out)
    assert doc["exit_code"] == 4 and doc["status"] == "clean"  # the URDF's own status; the cell's below
    assert doc["cell"]["status"] == "warnings"
    assert {f["code"] for f in doc["cell"]["findings"]} >= {"home-in-collision", "obstacle-out-of-reach"}
    assert {"pair": ["base_link", "link1"], "reason": "adjacent"} in doc["cell"]["self_pairs"]["disabled"]
    # a bad cell file: exit 2, the file and the line
    bad = tmp_path / "bad.yaml"
    bad.write_text("obstacles:\n  - {name: post, shape: cylinder, radius: -0.02, length: 0.2}\n")
    rc, _, err = run(capsys, ["check", str(urdf), "--cell", str(bad)])
    errors = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert rc == 2 and len(errors) == 1 and f"{bad} line 2" in errors[0] and "post" in errors[0]
    rc, _, err = run(capsys, ["check", str(urdf), "--points", str(points)])
    assert rc == 2 and "go with --cell" in err


def test_a_self_pair_that_touches_in_part_of_its_range_says_which_range_it_costs(robot, tmp_path: Path) -> None:
    """A third-party description of the default robot whose link2 box reaches the quill's axis (as the project's
    did): the flange rises into it over the top of the stroke. Closed form: the flange's top is at -0.05 - q3 + 0.01,
    link2's underside at -0.03, so they are within the 2 mm margin where 0.01 + q3 < 0.002, q3 < -0.008 m."""
    from scara_pin import robot_from_urdf

    shipped = '<origin rpy="0 0 0" xyz="0.085 0 0"/>\n      <geometry>\n        <box size="0.17 0.06 0.06"/>'
    old = '<origin rpy="0 0 0" xyz="0.1 0 0"/>\n      <geometry>\n        <box size="0.2 0.06 0.06"/>'
    urdf = robot.urdf.replace(shipped, old)
    assert urdf != robot.urdf
    third = robot_from_urdf(urdf)
    report = check_cell(scene(third, Cell((sphere("ball", 0.3, 0.0, -0.12, 0.02),), MARGIN)))
    costs = [f for f in report.findings if f.code == "self-pair-cost"]
    assert [f.data["pair"] for f in costs] == [["link2", "flange"]]
    low, high = costs[0].data["ranges"]["joint3"]
    assert low == pytest.approx(-0.05, abs=1e-12) and high == pytest.approx(-0.008, abs=0.15 / 2000)
    assert "joint3 in [-50, -8" in costs[0].message and "motions there are refused" in costs[0].message
    # the shipped robot: its shapes agree with its limits, nothing costs
    assert not [f for f in check_cell(scene(robot, Cell((), MARGIN))).findings if f.code == "self-pair-cost"]
