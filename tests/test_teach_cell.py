"""The teach pendant in a cell (`scara-pin teach --cell`, TeachSession(cell=)): jogs stop at the margin and say
what stopped them, go-tos into the cell are refused, and the page draws the cell (one real-browser test).

Expected stops come from closed forms written here, independent of the package's cell code: a short vertical
post under the links against the default robot's flange (a vertical cylinder of radius 0.025 m from the tool point
up 0.01 m, in its URDF). The post (z from -0.3 to -0.07 m) overlaps the flange in height and stays 30 mm below the
links (z >= -0.04 m); the quill (radius 0.01 m, coaxial, above the flange) is farther: the flange is the closest
shape, and its distance to the post is the plan distance of the tool point to the post's axis minus both radii. A
jog stops where that plan distance is ``rp + 0.025 + margin``. Tool positions are Pinocchio's frame placements
computed here (tests/pendant_page.py).
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from browser import next_frames, slate_pixels
from pendant_page import pin_placement, readout, resolution, teach_process

import scara_pin as sp
from scara_pin.cell import Cell, InCollisionError, Obstacle, Shape
from scara_pin.cell.sweep import CONTACT_TOL
from scara_pin.cli import main
from scara_pin.motion.manual import JogMotion
from scara_pin.viz.teach import CONTROL_PERIOD, JogAxis, JogFrame, StopKind, TeachSession

FLANGE_R = 0.025  # the default robot's flange: a vertical cylinder from the tool point up 0.01 m (URDF)
MARGIN = 0.002
POST = np.array([0.35, -0.1])  # the post's axis (plan) [m]
RP = 0.02  # its radius [m]
R = RP + FLANGE_R + MARGIN  # the tool point's plan distance to the post's axis at the stop
POST_YAML = f"""margin: {MARGIN}
obstacles:
  - {{name: post, shape: cylinder, radius: {RP}, length: 0.23, xyz: [{POST[0]}, {POST[1]}, -0.185]}}
"""
ARTIFACTS = Path(__file__).resolve().parent / "artifacts"


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def post_cell(margin: float = MARGIN) -> Cell:
    post = Obstacle("post", Shape("cylinder", (RP, 0.23), np.array([*POST, -0.185]), np.zeros(3)))
    return Cell((post,), margin)


def start_q(robot: sp.Robot, x: float, y: float, z: float = -0.1, yaw: float = 0.0) -> np.ndarray:
    q = robot.ik(np.array([x, y, z, yaw])).nearest(np.zeros(4)).q
    np.testing.assert_allclose(pin_placement(robot, q).translation, [x, y, z], rtol=0, atol=1e-12)
    return q  # type: ignore[no-any-return]


def tool(robot: sp.Robot, q: np.ndarray) -> np.ndarray:
    """The tool point in the base frame (Pinocchio, computed here)."""
    return np.asarray(pin_placement(robot, q).translation, dtype=float)


def to_post(robot: sp.Robot, q: np.ndarray) -> float:
    """The tool point's plan distance to the post's axis [m]."""
    return float(np.linalg.norm(tool(robot, q)[:2] - POST))


def line_circle(p0: np.ndarray, u: np.ndarray, c: np.ndarray, radius: float) -> float:
    """The smallest t >= 0 with |p0 + t u - c| = radius (|u| = 1, p0 outside the circle)."""
    w = p0 - c
    b = float(w @ u)
    return -b - math.sqrt(b * b - (float(w @ w) - radius**2))


def assert_stopped_at_the_post(robot: sp.Robot, reply: Any, moved: bool = True) -> None:
    """Stopped with the flange at the margin of the post: the closed-form distance within [R, R + CONTACT_TOL]."""
    assert reply.status == "STOPPED" and reply.moved == moved, (reply.status, reply.message)
    assert reply.reason is not None and reply.reason.kind is StopKind.OBSTACLE and reply.limit == "post"
    assert reply.message == "stopped 0.002 m from post (flange)"
    assert reply.contact is not None and (reply.contact.pair.a, reply.contact.pair.b) == ("flange", "post")
    d = to_post(robot, reply.q)
    assert R - 1e-12 <= d <= R + CONTACT_TOL + 1e-12, d - R
    np.testing.assert_allclose(reply.pose[:3], tool(robot, reply.q), rtol=0, atol=1e-12)


# ------------------------------------------------------------------------------------------ jogs stop at the margin
def test_a_base_frame_step_toward_a_post_stops_at_the_margin(robot) -> None:
    q0 = start_q(robot, 0.25, -0.12)
    session = TeachSession(robot, q0, cell=post_cell())
    reply = session.jog(JogAxis.X, 0.2)  # 200 mm asked; the post is in the way
    assert_stopped_at_the_post(robot, reply)
    p0 = tool(robot, q0)
    u = np.array([1.0, 0.0])
    travel = line_circle(p0[:2], u, POST, R)
    end = tool(robot, reply.q)
    # on the line, before the closed-form stop by at most what the contact tolerance allows (the gap grows along -u
    # at the rate u . n >= 0.9 here), never past it
    np.testing.assert_allclose(end, [*(p0[:2] + reply.travelled * u), p0[2]], rtol=0, atol=1e-12)
    assert travel - 2 * CONTACT_TOL <= reply.travelled <= travel + 1e-12
    assert reply.requested == 0.2 and reply.to_json()["contact"]["b"] == "post"


def test_a_tool_frame_step_and_a_joint_step_stop_at_the_margin(robot) -> None:
    # the tool frame at yaw 0.6 rad: its x axis (Pinocchio's, here) points at the post from 0.1 m away, 10 mm aside
    yaw = 0.6
    q_probe = start_q(robot, 0.25, -0.15, yaw=yaw)
    x_axis = np.asarray(pin_placement(robot, q_probe).rotation[:, 0])
    assert abs(x_axis[2]) < 1e-12
    u = x_axis[:2] / np.linalg.norm(x_axis[:2])
    side = np.array([-u[1], u[0]])
    p0 = POST - 0.1 * u + 0.01 * side
    q0 = start_q(robot, *p0, yaw=yaw)
    session = TeachSession(robot, q0, cell=post_cell())
    reply = session.jog(JogAxis.X, 0.2, JogFrame.TOOL)
    assert_stopped_at_the_post(robot, reply)
    travel = line_circle(p0, u, POST, R)
    np.testing.assert_allclose(tool(robot, reply.q)[:2], p0 + reply.travelled * u, rtol=0, atol=1e-12)
    assert travel - 3 * CONTACT_TOL <= reply.travelled <= travel + 1e-12

    # J1 alone: the tool circles the J1 axis at radius rho; the stop is where |tool - post| = R (law of cosines)
    q1 = start_q(robot, 0.22, -0.25)
    session = TeachSession(robot, q1, cell=post_cell())
    reply = session.jog_joint("joint1", 1.0)
    assert_stopped_at_the_post(robot, reply)
    t1 = tool(robot, q1)[:2]
    rho, dist, phi = float(np.linalg.norm(t1)), float(np.linalg.norm(POST)), math.atan2(POST[1], POST[0])
    theta = phi - math.acos((rho**2 + dist**2 - R**2) / (2 * rho * dist))  # approaching the post from below
    turned = theta - math.atan2(t1[1], t1[0])
    assert turned - 1e-8 <= reply.travelled <= turned + 1e-12  # never past the closed-form stop
    np.testing.assert_allclose(reply.q, q1 + np.array([reply.travelled, 0.0, 0.0, 0.0]), rtol=0, atol=1e-15)


def test_a_step_from_the_stretched_arm_stops_at_the_margin(robot) -> None:
    """On the outer edge (arm stretched) the closed form's joint rates have no bound: the move's first micrometre
    goes through its IK solutions, the rest by the closed form, and it stops with the flange at the margin (closed
    form), on the line. The step out to the edge ends there the same way (its last micrometre)."""
    post = np.array([0.30, 0.01])
    cell = Cell((Obstacle("post", Shape("cylinder", (RP, 0.23), np.array([*post, -0.185]), np.zeros(3))),), MARGIN)
    session = TeachSession(robot, start_q(robot, 0.36, 0.01), cell=cell)
    edge = session.jog(JogAxis.X, 0.2)
    assert edge.status == "STOPPED" and edge.reason is not None and edge.reason.kind is StopKind.WORKSPACE
    assert abs(np.linalg.norm(tool(robot, edge.q)[:2]) - 0.4) < 1e-9  # l1 + l2: the stretched arm
    reply = session.jog(JogAxis.X, -0.2)
    assert reply.status == "STOPPED" and reply.message == "stopped 0.002 m from post (flange)", reply.message
    end = tool(robot, reply.q)
    assert R - 1e-12 <= float(np.linalg.norm(end[:2] - post)) <= R + CONTACT_TOL + 1e-12
    assert abs(end[1] - 0.01) < 1e-12 and abs(end[2] + 0.1) < 1e-12
    x_edge = math.sqrt(0.4**2 - 0.01**2)  # the stretched arm at y = 0.01
    assert reply.travelled == pytest.approx(x_edge - (post[0] + R), abs=2 * CONTACT_TOL)


@pytest.mark.parametrize("held", ["x", "joint1"])
def test_a_held_jog_stops_at_the_margin(robot, held: str) -> None:
    """Held at 100 %: x of the base frame from (0.25, -0.1) toward the post's axis, or J1 from (0.22, -0.25)."""
    q0 = start_q(robot, 0.25, -0.1) if held == "x" else start_q(robot, 0.22, -0.25)
    session = TeachSession(robot, q0, cell=post_cell())
    now = 100.0
    session.hold(JogMotion(1, axis=JogAxis.X) if held == "x" else JogMotion(1, joint=0), 1.0, now)
    seen = []
    while session.holding and len(seen) < 50:
        now += CONTROL_PERIOD
        session.alive(now)
        session.tick(now)
        seen.append(to_post(robot, session.q))
    assert not session.holding and len(seen) < 50
    assert min(seen) >= R - 1e-12  # no period ends closer than the margin
    state = session.state()  # how it ended stays in the state until the next move (a state moves nothing)
    assert_stopped_at_the_post(robot, state, moved=False)
    if held == "x":
        assert state.travelled == pytest.approx(POST[0] - R - 0.25, abs=2e-9)
        np.testing.assert_allclose(tool(robot, state.q)[1:], [POST[1], -0.1], rtol=0, atol=1e-12)
    else:  # J1 alone turned, by what the hold says
        np.testing.assert_allclose(state.q, q0 + np.array([state.travelled, 0.0, 0.0, 0.0]), rtol=0, atol=1e-12)


def test_after_a_stop_it_moves_along_and_away_from_the_post_not_into_it(robot) -> None:
    """Stopped at the margin (same y as the post's axis): +x does not move; z (along the post: the distance does not
    change), y (tangent: it grows to sqrt(d0^2 + 0.01^2)), a turn of the flange (a disc about its own axis) and -x
    move the whole step."""
    session = TeachSession(robot, start_q(robot, 0.25, -0.1), cell=post_cell())
    assert_stopped_at_the_post(robot, session.jog(JogAxis.X, 0.1))
    q_stop = session.q
    d0 = to_post(robot, q_stop)
    again = session.jog(JogAxis.X, 0.01)
    assert again.status == "AT_EDGE" and not again.moved and again.reason is not None
    assert again.reason.kind is StopKind.OBSTACLE and again.travelled == 0.0
    assert again.message == "at the margin: 0.002 m from post (flange), and this way comes closer"
    np.testing.assert_array_equal(session.q, q_stop)
    for axis, step, frame in ((JogAxis.Z, 0.01, JogFrame.BASE), (JogAxis.Z, -0.02, JogFrame.BASE),
                              (JogAxis.YAW, math.radians(90), JogFrame.BASE)):  # fmt: skip
        reply = session.jog(axis, step, frame)
        assert reply.status == "OK" and reply.travelled == abs(step), (axis, reply.message)
        assert abs(to_post(robot, reply.q) - d0) <= 1e-12
    reply = session.jog(JogAxis.Y, 0.01)
    assert reply.status == "OK" and to_post(robot, reply.q) == pytest.approx(math.hypot(d0, 0.01), abs=1e-12)
    reply = session.jog(JogAxis.X, -0.01)
    assert reply.status == "OK" and reply.travelled == 0.01


# ------------------------------------------------------------------------------------------ go-tos, the start
def test_go_to_into_or_through_the_post_is_refused_naming_the_pair(robot) -> None:
    below, above = start_q(robot, 0.35, -0.16), start_q(robot, 0.35, -0.04)  # 60 mm either side of the axis
    session = TeachSession(robot, below, cell=post_cell())
    # the target inside the post: the flange is min(rp + rf, post top - flange bottom) = 0.03 m deep
    reply = session.go_to([0.35, -0.1, -0.1, 0.0])
    assert reply.status == "COLLISION" and not reply.moved
    assert reply.message.startswith("the target is in collision: flange is 0.03 m deep in post (margin 0.002 m)")
    # a clear target behind the post: the straight joint move crosses it (sampled here in closed form)
    assert to_post(robot, above) > R + 0.01
    s = np.linspace(0.0, 1.0, 2001)
    assert min(to_post(robot, below + k * (above - below)) for k in s) < R - 0.01
    for reply in (session.go_to(robot.tool_pose(above)), session.set_q(above)):
        assert reply.status == "COLLISION" and not reply.moved, reply.message
        assert re.fullmatch(r"the straight joint move there comes to the margin \(0\.002 m\) of post \((flange|quill)\)"
                            r" \d+% of the way, the tool at x \S+ m, y \S+ m, z -0\.1 m", reply.message), reply.message
        np.testing.assert_array_equal(session.q, below)
    # a taught point there is refused the same way; a clear move is not
    session.set_q(below)
    ok = session.go_to([0.3, -0.2, -0.1, 0.0])
    assert ok.status == "OK" and ok.moved and to_post(robot, ok.q) > R


def test_a_start_in_collision_is_refused_naming_the_pair(robot, tmp_path: Path, capsys) -> None:
    inside = start_q(robot, 0.34, -0.1)
    with pytest.raises(InCollisionError, match=r"the pendant's start is in collision: flange is .* deep in post"):
        TeachSession(robot, inside, cell=post_cell())
    cell = tmp_path / "post.yaml"
    cell.write_text(POST_YAML)
    assert main(["teach", "--cell", str(cell), "--q", *map(repr, inside.tolist())]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: the pendant's start is in collision: flange is ") and "deep in post" in err
    assert err.count("\n") == 1 and "Traceback" not in err
    # a cell for a palletizer: refused before the server starts
    assert main(["teach", "--robot", "palletizer", "--cell", str(cell)]) == 2
    assert "4-joint SCARA" in capsys.readouterr().err
    bad = tmp_path / "bad.yaml"
    bad.write_text("obstacles:\n  - {name: post, shape: cylinder, radius: -1, length: 0.3}\n")
    assert main(["teach", "--cell", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {bad}") and "line 2" in err


# ------------------------------------------------------------------------------------------ the page, in Chromium
@pytest.fixture
def cell_server(robot: sp.Robot, tmp_path: Path) -> Iterator[str]:
    """`scara-pin teach --cell post.yaml` at (0.25, -0.1, -0.1) in a subprocess: its URL, once it said the cell."""
    cell = tmp_path / "post.yaml"
    cell.write_text(POST_YAML)
    q0 = start_q(robot, 0.25, -0.1)
    with teach_process("--cell", str(cell), "--q", *map(repr, q0.tolist())) as (url, _, proc):
        said = proc.stdout.readline()  # type: ignore[union-attr]
        assert said == f"cell          {cell}: 1 obstacle(s), margin 0.002 m: jogs stop at the margin\n", said
        yield url


HIDE_CELL = """() => {
    const cell = viewer.scene_tree.children.meshcat.children.cell;
    cell.object.visible = false;
    viewer.set_dirty();
}"""


def test_the_pendant_page_stops_a_jog_at_the_post_and_draws_it(robot, cell_server, page) -> None:
    """In headless Chromium: a base-frame step toward the post stops at the margin, the status says where and what
    (post, flange) in mm, the readout and the server's q agree with the closed form, and the post is drawn (its
    slate-blue pixels, gone when the page hides the cell node)."""
    import json
    import urllib.request

    url = cell_server
    page.set_viewport_size({"width": 1024, "height": 600})
    page.goto(url)
    page.wait_for_function("() => window.scaraReplies >= 1")
    assert page.inner_text("#cell-info") == "cell post.yaml: 1 obstacle(s); every jog stops 2 mm from them (the margin)"
    page.fill("#jog-step", "100")
    before = page.evaluate("() => window.scaraReplies")
    page.click("[id='jog-0+']")  # x +, base frame
    page.wait_for_function("(n) => window.scaraReplies > n", arg=before)
    assert page.inner_text("#ik-status") == "stopped 2 mm from post (flange) \u2014 moved 53 of 100 mm"
    with urllib.request.urlopen(url + "api/state", timeout=10) as answer:  # noqa: S310 - our own 127.0.0.1 server
        state = json.loads(answer.read())
    q = np.array(state["q"])
    assert R - 1e-12 <= to_post(robot, q) <= R + CONTACT_TOL + 1e-12
    shown, units = readout(page)
    expected = np.array([POST[0] - R, POST[1], -0.1, 0.0])
    assert np.all(np.abs(shown - expected) <= resolution(units) + 1e-9), (shown, expected)
    ARTIFACTS.mkdir(exist_ok=True)
    next_frames(page, 4)
    page.screenshot(path=str(ARTIFACTS / "teach_cell.png"))
    panel = page.locator("#pendant").bounding_box()  # the 3-D view only (the panel's links are blue too)
    assert panel is not None
    view = {"x": panel["x"] + panel["width"], "y": 0, "width": 1024 - panel["x"] - panel["width"], "height": 600}
    drawn = slate_pixels(page.screenshot(clip=view))
    page.evaluate(HIDE_CELL)
    next_frames(page, 4)
    hidden = slate_pixels(page.screenshot(clip=view))
    assert drawn > 1000 and hidden < 0.01 * drawn, (drawn, hidden)
    assert page.errors == []


def test_a_step_onto_the_stretched_arm_is_checked_in_few_steps(robot, monkeypatch) -> None:
    """0.4 mm out onto the outer edge, the post far away: near the singularity the joint rates grow without bound
    (and jump at each corner of the last micrometre's joint polyline), yet the far post allows long steps: the
    search asks for few distances (4,480 configurations before it kept a step its gaps allow at either end's bound)."""
    from scara_pin.cell import Scene

    cell = Cell((Obstacle("post", Shape("cylinder", (RP, 0.23), np.array([-0.3, 0.0, -0.185]), np.zeros(3))),))
    session = TeachSession(robot, start_q(robot, 0.3996, 0.0), cell=cell)
    asked = []
    real = Scene.distance_array
    monkeypatch.setattr(Scene, "distance_array",
                        lambda self, Q, *a, **k: asked.append(len(np.atleast_2d(Q))) or real(self, Q, *a, **k))
    reply = session.jog(JogAxis.X, 0.1)
    assert reply.status == "STOPPED" and reply.reason is not None and reply.reason.kind is StopKind.WORKSPACE
    assert abs(tool(robot, reply.q)[0] - 0.4) < 1e-9
    assert sum(asked) < 500, sum(asked)
