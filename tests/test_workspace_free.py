"""The plan-view region reachable without collision (scara_pin.workspace.free, scara-pin workspace --cell --height).

Expected values from closed forms written here (default robot, URDF numbers): at the tool height z = -0.1 m a
short post under the links (top at -0.07 m; the links' lowest point, -0.04 m, is 30 mm above it) is
reached only by the flange (radius 0.025 m) and the quill (radius 0.01 m, coaxial, above it), on either elbow
branch alike: it removes from the free region exactly the grid points whose plan distance to the post's axis
is below ``R = rp + 0.025 + margin``, a disc of area pi R^2; the raster's area is within ``sqrt(2) h 2 pi R``
of it (each grid square counted wrongly lies within h / sqrt(2) of the circle).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cell import Cell, Obstacle, Shape
from scara_pin.cli import main
from scara_pin.errors import InvalidInputError
from scara_pin.workspace.free import free_region

Z = -0.1
MARGIN = 0.002
FLANGE_R = 0.025
POST = (0.225, -0.105, 0.02)


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def post(x: float = POST[0], y: float = POST[1], r: float = POST[2]) -> Obstacle:
    return Obstacle("post", Shape("cylinder", (r, 0.23), np.array([x, y, -0.185]), np.zeros(3)))  # z -0.3 .. -0.07


def test_a_post_makes_a_disc_shaped_hole(robot) -> None:
    h = 0.004
    empty = free_region(robot, Cell((), MARGIN), Z, resolution=h)
    with_post = free_region(robot, Cell((post(),), MARGIN), Z, resolution=h)
    np.testing.assert_array_equal(empty.x, with_post.x)
    np.testing.assert_array_equal(empty.reachable, with_post.reachable)
    R = POST[2] + FLANGE_R + MARGIN
    X, Y = np.meshgrid(empty.x, empty.y)
    rho = np.hypot(X - POST[0], Y - POST[1])
    removed = empty.free & ~with_post.free
    assert not (with_post.free & ~empty.free).any()
    # point by point: removed exactly inside the circle (points within 1e-9 m of it not judged)
    clear_of_edge = np.abs(rho - R) > 1e-9
    np.testing.assert_array_equal(removed[clear_of_edge], (empty.free & (rho < R))[clear_of_edge])
    assert empty.free[rho < R + 2 * h].all()  # the disc lies inside the free region: the hole is all of it
    hole = removed.sum() * h * h
    assert abs(hole - math.pi * R**2) <= math.sqrt(2) * h * 2 * math.pi * R
    assert empty.area - with_post.area == pytest.approx(hole, abs=1e-15)
    # the reachable grid agrees with the exact workspace's area to its own bound (outline length: 2 pi (r_max + r_min))
    ws = empty.workspace
    outline = 2 * math.pi * (ws.r_max + ws.r_min) + 2 * math.pi * 0.2  # circles and the two J1-limit arcs (l2)
    assert abs(empty.reachable_area - ws.area) <= math.sqrt(2) * h * outline


def test_a_carried_bar_turns_to_pass_a_post(robot) -> None:
    """A bar 0.1 m long (along the tool's x) at 60 mm from a post: blocked at yaw 0 (it points at the post: its
    end 10 mm from the axis, inside the 20 mm post), free with the yaw free (turned 90 deg its side is 50 mm from
    the axis, and the flange's edge 15 mm from the post)."""
    bar = Shape("box", (0.1, 0.02, 0.02), np.array([0.0, 0.0, 0.015]), np.zeros(3))  # below the flange (tool z down)
    cell = Cell((post(),), MARGIN, carried=bar)
    h = 0.01
    free = free_region(robot, cell, Z, resolution=h)
    fixed = free_region(robot, cell, Z, resolution=h, yaw=0.0)
    assert free.yaw_free and len(free.yaws) == 12 and not fixed.yaw_free and fixed.yaws == (0.0,)
    i = int(np.argmin(np.abs(free.x - (POST[0] + 0.06))))
    j = int(np.argmin(np.abs(free.y - POST[1])))
    assert abs(free.x[i] - (POST[0] + 0.06)) < 1e-12 and abs(free.y[j] - POST[1]) < 1e-12
    assert free.free[j, i] and not fixed.free[j, i]
    assert not (fixed.free & ~free.free).any()  # yaw 0 is one of the twelve


def test_bad_heights_and_grids_are_refused(robot) -> None:
    cell = Cell((post(),), MARGIN)
    with pytest.raises(InvalidInputError, match="outside the J3 stroke"):
        free_region(robot, cell, 0.3)
    with pytest.raises(InvalidInputError, match="above the cap of 250,000"):
        free_region(robot, cell, Z, resolution=1e-4)
    with pytest.raises(sp.ParameterError):
        free_region(robot, cell, Z, resolution=-1.0)
    with pytest.raises(InvalidInputError, match="4-joint SCARA"):
        free_region(sp.load_robot("palletizer"), cell, Z)


def run(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def test_workspace_cli_json_and_plot(capsys, tmp_path: Path) -> None:
    cell = tmp_path / "cell.yaml"
    x, y, r = POST
    cell.write_text(f"margin: {MARGIN}\nobstacles:\n  - {{name: post, shape: cylinder, radius: {r}, length: 0.23, "
                    f"xyz: [{x}, {y}, -0.185]}}\n")  # fmt: skip
    png = tmp_path / "free.png"
    rc, out, err = run(capsys, ["workspace", "--cell", str(cell), "--height", "-100", "--mm", "--resolution", "10",
                                "--json", "--plot", str(png)])  # fmt: skip
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["height"] == pytest.approx(Z, abs=1e-15) and doc["resolution"] == pytest.approx(0.01, abs=1e-15)
    grid = np.array(doc["grid"]["free"])
    assert grid.shape == (len(doc["grid"]["y"]), len(doc["grid"]["x"])) == (80, 80)
    assert doc["area"] == pytest.approx(grid.sum() * 1e-4, rel=1e-12)
    assert doc["yaw"] == {"free": False, "values": [0.0]}
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rc, out, err = run(capsys, ["workspace", "--cell", str(cell), "--height", "-0.1", "--resolution", "0.01"])
    assert rc == 0, err
    assert "yaw       0 deg at every point" in out and "80 x 80 points 0.01 m apart" in out
    for argv in (["workspace", "--cell", str(cell)], ["workspace", "--height", "-0.1"],
                 ["workspace", "--cell", str(cell), "--height", "-0.1", "--ray", "0.3", "0", "1", "0"]):  # fmt: skip
        rc, _, err = run(capsys, argv)
        assert rc == 2 and len([ln for ln in err.splitlines() if ln.startswith("error:")]) == 1
