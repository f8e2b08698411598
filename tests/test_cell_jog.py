"""The jog in a cell: it stops where a checked pair reaches the margin (scara_pin.motion.jog, scara-pin jog --cell).

Expected stops come from routes independent of the package's cell code:

- a short vertical post under the links against the flange: the flange (a vertical cylinder of radius 0.025 m
  from the tool point up 0.01 m, default robot's URDF) and the post overlap in height, so their distance is the
  plan distance of the axes minus both radii; the quill (radius 0.01 m, coaxial, above the flange) is farther,
  and the links (z >= -0.04 m) stay 30 mm above the post's top (-0.07 m): the flange is the closest shape, and
  the stop is where the tool's plan distance to the post's axis is ``rp + 0.025 + margin`` (a quadratic);
- a vertical jog down onto a box: the flange's bottom is the tool point, so it stops at ``z = top + margin``;
- a tall post against link2: coal called directly in the test on link2's box (placed by Pinocchio's frame
  placement, its size written here from the URDF) and the post, bisected along the line by the test itself.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cell import Cell, InCollisionError, Obstacle, Shape
from scara_pin.cli import main
from scara_pin.errors import InfeasibleError
from scara_pin.motion.jog import jog_to_edge

FLANGE_R = 0.025
MARGIN = 0.002
POST = (0.35, -0.1, 0.02)  # x, y, radius [m]
LINK2_HALF = (0.085, 0.03, 0.03)  # link2's collision box: half sizes, centred 0.085 m along link2's x (URDF: it ends
# 5 mm short of the flange's edge, 0.2 - 0.025 - 0.005 m from the elbow; the cap over the quill is not near the post)


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def low_post_cell(margin: float = MARGIN) -> Cell:
    x, y, r = POST
    post = Obstacle("post", Shape("cylinder", (r, 0.23), np.array([x, y, -0.185]), np.zeros(3)))  # z -0.3 .. -0.07
    return Cell((post,), margin)


def start_q(robot: sp.Robot, x: float, y: float, z: float = -0.1, yaw: float = 0.0) -> np.ndarray:
    return robot.ik(np.array([x, y, z, yaw])).nearest(np.zeros(4)).q


def line_circle(p0: np.ndarray, u: np.ndarray, c: np.ndarray, radius: float) -> float:
    """The smallest t >= 0 with |p0 + t u - c| = radius (|u| = 1, p0 outside the circle)."""
    w = p0 - c
    b = float(w @ u)
    disc = b * b - (float(w @ w) - radius**2)
    return -b - math.sqrt(disc)


@pytest.mark.parametrize("direction", [(1.0, 0.0), (1.0, 0.25)])
def test_jog_stops_where_the_flange_reaches_the_margin_of_a_post(robot, direction) -> None:
    cell = low_post_cell()
    q0 = start_q(robot, 0.25, -0.12)
    jog = jog_to_edge(robot, q0, direction, cell=cell)
    u = np.array(direction) / np.linalg.norm(direction)
    p0 = robot.tool_pose(q0)[:2]
    travel = line_circle(p0, u, np.array(POST[:2]), POST[2] + FLANGE_R + MARGIN)
    assert jog.contact is not None and (jog.contact.pair.a, jog.contact.pair.b) == ("flange", "post")
    assert jog.stopped_by == "stopped 2 mm from post (flange)"
    end = robot.tool_pose(jog.trajectory.q_end)
    # on the safe side of the closed-form stop, within 1e-9 m of it (the distance grows along -u at rate >= 0.9)
    np.testing.assert_allclose(end[:2], p0 + travel * u, rtol=0, atol=2e-9)
    assert jog.distance <= travel + 1e-15
    assert MARGIN <= jog.contact.distance <= MARGIN + 1e-9
    # every 10 kHz sample: the closed-form flange-post distance at least the margin; at rest at both ends
    t = jog.trajectory.times(10_000.0)
    q, qd, _ = jog.trajectory.sample(t)
    tool = np.array([robot.tool_pose(qk)[:2] for qk in q[::10]])
    plan = np.linalg.norm(tool - np.array(POST[:2]), axis=1) - POST[2] - FLANGE_R
    assert plan.min() >= MARGIN - 1e-12
    assert np.abs(qd[[0, -1]]).max() < 1e-12
    assert jog.ratio <= 1 + 1e-6


def test_a_vertical_jog_stops_above_a_box_by_the_margin(robot) -> None:
    top = -0.12
    box = Obstacle("table", Shape("box", (0.2, 0.2, 0.02), np.array([0.3, 0.0, top - 0.01]), np.zeros(3)))
    q0 = start_q(robot, 0.3, 0.0, z=-0.08)
    jog = jog_to_edge(robot, q0, [0.0, 0.0, -1.0], cell=Cell((box,), MARGIN))
    # the flange and the quill both end at the tool point: either reaches the margin first (the same height)
    assert jog.contact.pair.a in ("flange", "quill") and jog.contact.pair.b == "table"
    end = robot.tool_pose(jog.trajectory.q_end)
    assert top + MARGIN <= end[2] <= top + MARGIN + 1e-9
    assert end[:2] == pytest.approx([0.3, 0.0], abs=1e-12)


def _link2_post_distance(robot: sp.Robot, q: np.ndarray, post: tuple[float, float, float]) -> float:
    import coal

    M = robot.frame_placement(q, "link2")
    box_M = coal.Transform3s(M.rotation, M.rotation @ np.array([LINK2_HALF[0], 0.0, 0.0]) + M.translation)
    post_M = coal.Transform3s(np.eye(3), np.array([post[0], post[1], 0.0]))
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    req.gjk_tolerance = 1e-12
    return float(coal.distance(coal.Box(*(2 * np.array(LINK2_HALF))), box_M, coal.Cylinder(post[2], 0.4), post_M,
                               req, res))  # fmt: skip


def test_jog_stops_before_link2_touches_a_tall_post(robot) -> None:
    post = (0.2, 0.15, 0.02)
    cell = Cell((Obstacle("column", Shape("cylinder", (post[2], 0.4), np.array([post[0], post[1], 0.0]),
                                          np.zeros(3))),), MARGIN)  # fmt: skip
    q0 = start_q(robot, 0.3, 0.05)
    jog = jog_to_edge(robot, q0, [0.0, 1.0], cell=cell)
    assert (jog.contact.pair.a, jog.contact.pair.b) == ("link2", "column")
    assert jog.stopped_by == "stopped 2 mm from column (link2)"
    # the test's own search: the tool on the line x = 0.3, its IK on the start's branch, coal on link2 and the post
    branch = robot.branch_of(q0)

    def gap(y: float) -> float:
        q = robot.ik(np.array([0.3, y, -0.1, 0.0]), branch=branch).nearest(q0).q
        return _link2_post_distance(robot, q, post) - MARGIN

    y = 0.05
    while gap(y + 1e-4) > 0:
        y += 1e-4
    lo, hi = y, y + 1e-4
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gap(mid) > 0 else (lo, mid)
    end = robot.tool_pose(jog.trajectory.q_end)
    assert end[0] == pytest.approx(0.3, abs=1e-12)
    assert end[1] == pytest.approx(lo, abs=1e-8)
    assert end[1] <= lo + 1e-12


def test_jog_from_a_collision_is_refused_naming_the_pair(robot) -> None:
    q0 = start_q(robot, 0.35 - 0.04, -0.1)  # the flange's axis 40 mm from the post's: 5 mm deep
    with pytest.raises(InCollisionError, match=r"jog's start is in collision: flange is 5 mm deep in post") as exc:
        jog_to_edge(robot, q0, [1.0, 0.0], cell=low_post_cell())
    assert exc.value.exit_code == 2
    assert (exc.value.pair.a, exc.value.pair.b) == ("flange", "post")


def test_jog_at_the_margin_towards_the_post_has_no_room(robot) -> None:
    q0 = start_q(robot, POST[0] - POST[2] - FLANGE_R - MARGIN, POST[1])
    with pytest.raises(InfeasibleError, match="no room to jog: flange is at the margin of post"):
        jog_to_edge(robot, q0, [1.0, 0.0], cell=low_post_cell())
    away = jog_to_edge(robot, q0, [-0.3, 1.0], margin=1e-4, cell=low_post_cell())  # away: free to the edge
    assert away.contact is None and away.distance > 0.1


def test_a_cell_that_does_not_block_keeps_the_edge(robot) -> None:
    q0 = [2.0, 1.0, 0.02, 0.2]
    plain = jog_to_edge(robot, q0, [-1.0, 0.0])
    in_cell = jog_to_edge(robot, q0, [-1.0, 0.0], cell=low_post_cell())
    assert in_cell.contact is None and in_cell.stopped_by == plain.stopped_by
    assert in_cell.distance == plain.distance


# ------------------------------------------------------------------------------------------- CLI
def write_cell(tmp_path: Path) -> Path:
    x, y, r = POST
    path = tmp_path / "cell.yaml"
    path.write_text(f"margin: {MARGIN}\nobstacles:\n  - name: post\n    shape: cylinder\n    radius: {r}\n"
                    f"    length: 0.23\n    xyz: [{x}, {y}, -0.185]\n")  # fmt: skip
    return path


def run(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def test_jog_cli_names_the_obstacle_and_the_link(robot, capsys, tmp_path: Path) -> None:
    cell = write_cell(tmp_path)
    q0 = [repr(float(v)) for v in start_q(robot, 0.25, -0.1)]
    rc, out, err = run(capsys, ["jog", "--from", *q0, "--direction", "1", "0", "--cell", str(cell)])
    assert rc == 0, err
    assert f"stop      stopped 2 mm from post (flange), the margin of {cell}" in out
    rc, out, err = run(capsys, ["jog", "--json", "--from", *q0, "--direction", "1", "0", "--cell", str(cell),
                                "--margin", "0.005"])  # fmt: skip
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["stopped_by"] == "cell" and doc["contact"]["b"] == "post" and doc["contact"]["a"] == "flange"
    assert doc["contact"]["margin"] == 0.005
    # --margin is also the cell's: the flange stops 5 mm from the post (the closed form's stop)
    assert doc["end_pose"][0] == pytest.approx(POST[0] - POST[2] - FLANGE_R - 0.005, abs=2e-9)


def test_jog_cli_from_a_collision_exits_2_naming_the_pair(robot, capsys, tmp_path: Path) -> None:
    cell = write_cell(tmp_path)
    q0 = [repr(float(v)) for v in start_q(robot, 0.31, -0.1)]
    rc, _, err = run(capsys, ["jog", "--from", *q0, "--direction", "1", "0", "--cell", str(cell)])
    assert rc == 2
    lines = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1 and "flange is 5 mm deep in post" in lines[0]
