"""Issue 34 items 8 and 10: one carried part for the job, the pendant and ``check --cell``; obstacles within the
reach never called misplaced; names in the 3-D views; a margin per obstacle.

Truth from the geometry written here: a tray whose top is 20 mm under the lowest the default robot's flange goes
(the quill's stroke from its URDF numbers: tool z = -0.05 - q3, q3 <= 0.1 m) and a part hanging 60 mm under the
flange, so that the part reaches the tray and the bare flange does not.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from scara_pin import Robot
from scara_pin.cli import main
from scara_pin.cli._robot import cell_from_args
from scara_pin.job.loading import read_carry
from scara_pin.viz.teach import TeachSession

TRAY = "margin: 0.002\nobstacles:\n  - {name: tray, shape: box, size: [0.2, 0.2, 0.02], xyz: [0.3, 0.0, -0.2]}\n"
"""A tray whose top (z = -0.19 m) is below the flange's lowest."""
JOB = ("format: scara-pin job 1\nunits: mm,deg\npoints: points.yaml\ncarry: {shape: box, size: [20, 20, 50], xyz: "
       "[0, 0, 35]}\nsteps:\n  - pick: 0.1\n  - jump: P\n  - place: 0.1\n")  # fmt: skip
"""A job whose part, 20 x 20 x 50 mm, hangs from 10 to 60 mm under the flange (its file in mm)."""


@pytest.fixture
def files(tmp_path: Path, robot_default: Robot) -> dict[str, Path]:
    low = robot_default.ik_nearest(np.array([0.3, 0.0, -0.15, 0.0]), np.zeros(4))  # the quill at its bottom
    (tmp_path / "tray.yaml").write_text(TRAY)
    (tmp_path / "job.yaml").write_text(JOB)
    (tmp_path / "points.yaml").write_text(f"points:\n  - {{name: P, q: {low.tolist()}}}\n")
    return {p.stem: p for p in tmp_path.iterdir()}


def test_an_obstacle_under_the_reach_is_not_called_misplaced(files: dict[str, Path],
                                                              capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    assert main(["check", "--robot", "default", "--cell", str(files["tray"]), "--json"]) == 0
    findings = json.loads(capsys.readouterr().out)["cell"]["findings"]
    codes = {f["code"]: f for f in findings}
    assert "obstacle-out-of-reach" not in codes  # was: "out of reach (misplaced? millimetres as metres?)"
    below = codes["obstacle-beyond-stroke"]
    assert below["severity"] == "info" and below["obstacle"] == "tray" and "--carry" in below["message"]
    assert below["distance"] == pytest.approx(0.19 - 0.15 - 0.0, abs=0.03)  # under the flange's lowest


def test_the_job_s_part_is_known_to_check_and_to_the_pendant(robot_default: Robot, files: dict[str, Path],
                                                            capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    part = read_carry(files["job"]).part()
    assert part.size == pytest.approx((0.02, 0.02, 0.05)) and part.xyz == pytest.approx([0.0, 0.0, 0.035])
    argv = ["check", "--robot", "default", "--cell", str(files["tray"]), "--carry", str(files["job"]), "--points",
            str(files["points"])]  # fmt: skip
    assert main(argv) == 4
    out = capsys.readouterr().out
    assert "point P is in collision: carried" in out and "tray" in out  # the part, not the flange, reaches the tray
    assert "obstacle-beyond-stroke" not in out  # with the part, the tray is within reach
    # the pendant: the same cell (teach --cell tray.yaml --carry job.yaml); a go-to the bottom is refused for the part
    cell = cell_from_args(argparse.Namespace(cell=str(files["tray"]), carry=str(files["job"]), margin=None))
    assert cell.carried is not None and cell.carried.size == part.size
    q_low = robot_default.ik_nearest(np.array([0.3, 0.0, -0.15, 0.0]), np.zeros(4))
    q_high = robot_default.ik_nearest(np.array([0.3, 0.0, -0.05, 0.0]), np.zeros(4))
    with_part = TeachSession(robot_default, q_high, cell=cell).set_q(q_low)
    assert with_part.status == "COLLISION" and "carried" in with_part.message
    bare = TeachSession(robot_default, q_high, cell=cell.with_carried(None)).set_q(q_low)
    assert bare.status == "OK"


def test_an_obstacle_keeps_its_own_margin(robot_default: Robot, tmp_path: Path) -> None:
    """A post asking for 20 mm in a 2 mm cell: a configuration 10 mm from it (the flange's own distance, measured
    by the scene without the post's margin) is refused, one 25 mm away is clear."""
    from dataclasses import replace

    from scara_pin.cell import Obstacle, load_cell, scene

    path = tmp_path / "post.yaml"
    path.write_text("margin: 0.002\nobstacles:\n  - {name: post, shape: cylinder, radius: 0.02, length: 0.3, "
                    "xyz: [0.3, 0.0, -0.1], margin: 0.02}\n")  # fmt: skip
    cell = load_cell(path)
    assert cell.obstacles[0].margin == 0.02 and cell.margin == 0.002
    post = cell.obstacles[0]
    plain = scene(robot_default, replace(cell, obstacles=(Obstacle("post", post.shape),)))  # the cell's margin only
    own = scene(robot_default, cell)
    rng = np.random.default_rng(34)
    lo, hi = np.array(robot_default.limits.lower), np.array(robot_default.limits.upper)
    Q = lo + (hi - lo) * rng.random((400, 4))
    def to_post(sc: object) -> np.ndarray:  # the distance of every link (and nothing else) to the post
        cols = [p.index for p in sc.pairs if "post" in (p.a, p.b)]  # type: ignore[attr-defined]
        return sc.distance_array(Q)[:, cols].min(axis=1)  # type: ignore[attr-defined]

    d_plain, d_own = to_post(plain), to_post(own)
    near = (d_plain > 0.005) & (d_plain < 0.018)  # outside the cell's margin, inside the post's own
    far = d_plain > 0.03  # the growth is at most 18 mm x sqrt(2) at the post's rims
    assert near.any() and far.any()
    assert (d_own[near] < cell.margin).all() and (d_own[far] >= cell.margin).all()
    close = (d_plain > 0.0) & (d_plain < 0.1)  # exact distances (not depths, nor the far pairs' cap)
    assert np.max(d_own[close] - (d_plain[close] - 0.018)) <= 1e-9  # never short of the post's own margin
    (tmp_path / "tri.stl").write_text("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\n"
                                      "vertex 0 0.1 0\nendloop\nendfacet\nendsolid t\n")  # fmt: skip
    (tmp_path / "mesh.yaml").write_text("obstacles:\n  - {name: m, shape: mesh, file: tri.stl, margin: 0.01}\n")
    with pytest.raises(Exception, match="line 2: obstacle m: a mesh takes the cell's margin"):
        load_cell(tmp_path / "mesh.yaml")


def _page_data(html: str) -> dict:
    start = html.index('id="scara-data"')
    start = html.index(">", start) + 1
    return json.loads(html[start : html.index("</script>", start)])


def test_the_3d_views_name_the_obstacles_and_draw_the_points(robot_default: Robot, files: dict[str, Path],
                                                              tmp_path: Path) -> None:  # fmt: skip
    from scara_pin.cell import load_cell
    from scara_pin.motion.points import read_points
    from scara_pin.viz import show

    view = show(robot_default, cell=load_cell(files["tray"]), points=files["points"])
    labels = {(item["group"], item["text"]): item["xyz"] for item in _page_data(view.html)["labels"]}
    assert labels[("cell", "tray")] == pytest.approx([0.3, 0.0, -0.19])  # on its top face
    q = read_points(files["points"]).q_of("P")
    assert labels[("targets", "P")] == pytest.approx(robot_default.tool_pose(q)[:3].tolist())
    page = tmp_path / "view.html"
    assert main(["view", "--html", str(page), "--cell", str(files["tray"]), "--points", str(files["points"])]) == 0
    assert {item["text"] for item in _page_data(page.read_text())["labels"]} == {"tray", "P"}
