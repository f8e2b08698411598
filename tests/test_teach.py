"""The pendant: the scene tree (joint nodes), the framing, the teach session's logic, and real headless Chromium
driving the offline page's sliders and the live `scara-pin teach` page.

Truth from independent routes: Pinocchio's ``liMi`` and FK for the joint nodes; `scara-pin fk --json` for the
page's readout; the FK of the server's q (read from its JSON) for the jogs; a pinhole projection written here
for the framing; the process table and the port for the server's end.
"""

from __future__ import annotations

import json
import math
import re
import signal
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import psutil
import pytest
from sigint import default_sigint

from scara_pin import InvalidInputError, Robot, load_robot
from scara_pin.cli import main
from scara_pin.kinematics.scara import NotScaraError
from scara_pin.viz.meshcat import export_html
from scara_pin.viz.teach import JogAxis, Solver, TeachSession
from scara_pin.viz.tree import FIELD_OF_VIEW, framing, joint_nodes

NAMES = ("s1", "default", "palletizer")
Q_S1 = np.array([0.3, 0.9, 0.02, -0.5])  # inside s1's workspace, 10 mm of x to spare either way


@pytest.fixture(scope="module")
def shipped() -> dict[str, Robot]:
    return {n: load_robot(n) for n in NAMES}


# ------------------------------------------------------------------------------------------ scene tree
@pytest.mark.parametrize("name", NAMES)
def test_joint_nodes_reproduce_pinocchio(shipped: dict[str, Robot], name: str) -> None:
    """Each node's placement times its own motion is Pinocchio's liMi; composed along the tree they give oMi."""
    robot = shipped[name]
    model, data = robot.model, robot.model.createData()
    nodes = joint_nodes(robot, "robot")
    assert [n.name for n in nodes] == list(model.names)[1:]
    rng = np.random.default_rng(16)
    for _ in range(20):
        q = rng.uniform(robot.limits.lower, robot.limits.upper)
        pin.forwardKinematics(model, data, robot.to_pinocchio_q(q))
        world = [pin.SE3.Identity()]
        for j, node in enumerate(nodes, start=1):
            M = node.transform(q)
            np.testing.assert_allclose(M.homogeneous, data.liMi[j].homogeneous, rtol=0, atol=1e-12)
            world.append(world[model.parents[j]] * M)
            np.testing.assert_allclose(world[j].homogeneous, data.oMi[j].homogeneous, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_the_camera_sees_the_whole_workspace(shipped: dict[str, Robot], name: str) -> None:
    """Every frame's origin over a random sample of configurations projects inside the picture (a pinhole
    with the camera's field of view, square picture), and the floor grid is wider than the reach."""
    robot = shipped[name]
    f = framing(robot)
    eye, target = np.array(f.position), np.array(f.target)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    assert forward[2] < -0.3  # looking down at the robot
    half = math.tan(math.radians(FIELD_OF_VIEW) / 2)
    data = robot.model.createData()
    rng = np.random.default_rng(3)
    for _ in range(200):
        q = rng.uniform(robot.limits.lower, robot.limits.upper)
        pin.framesForwardKinematics(robot.model, data, robot.to_pinocchio_q(q))
        for frame in data.oMf:
            d = np.array(frame.translation) - eye
            depth = d @ forward
            assert depth > 0
            assert abs(d @ right) / depth <= half and abs(d @ up) / depth <= half
    assert f.grid_half >= f.reach
    assert 3 <= f.grid_half / f.grid_cell <= 12


# ------------------------------------------------------------------------------------------ session logic
def test_jog_moves_the_tool_by_the_step_and_keeps_the_rest(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    for axis, step in ((JogAxis.X, 0.01), (JogAxis.Y, -0.01), (JogAxis.Z, 0.005), (JogAxis.YAW, math.radians(5))):
        before = robot_s1.tool_pose(session.q)
        reply = session.jog(axis, step)
        assert reply.moved and reply.status == "OK" and reply.solver is Solver.CLOSED_FORM, reply
        after = robot_s1.tool_pose(session.q)
        expected = before.copy()
        expected[axis.value] += step
        np.testing.assert_allclose(after, expected, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(reply.q, session.q)
        np.testing.assert_array_equal(reply.pose, after)


def test_a_refused_jog_leaves_q_unchanged_and_says_why(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    q0 = session.q
    reply = session.jog(JogAxis.X, 1.0)  # 1 m: s1 reaches 0.2 m
    assert not reply.moved
    assert reply.status == "OUT_OF_REACH" and "reach" in reply.message
    np.testing.assert_array_equal(session.q, q0)
    np.testing.assert_array_equal(reply.q, q0)
    reply = session.set_q([0.0, 0.0, 0.5, 0.0])  # joint3 beyond its 0.1 m stroke
    assert not reply.moved and reply.status == "JOINT_LIMIT" and "joint3" in reply.message
    np.testing.assert_array_equal(session.q, q0)


def test_the_branch_selector_picks_the_elbow(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    assert session.state().branch == "right"
    pose = robot_s1.tool_pose(Q_S1)
    reply = session.go_to(pose, branch="left")
    assert reply.moved and reply.branch == "left" and robot_s1.branch_of(session.q) == "left"
    np.testing.assert_allclose(robot_s1.tool_pose(session.q), pose, rtol=0, atol=1e-9)
    assert not np.allclose(session.q, Q_S1)
    with pytest.raises(InvalidInputError, match="branch 'middle'"):
        session.go_to(pose, branch="middle")


def test_page_requests_in_mm_and_deg(robot_s1: Robot) -> None:
    a, b = TeachSession(robot_s1, Q_S1), TeachSession(robot_s1, Q_S1)
    a.handle("jog", {"axis": "yaw", "step": -4.0, "branch": "all"})
    b.jog(JogAxis.YAW, math.radians(-4.0))
    np.testing.assert_array_equal(a.q, b.q)
    target = robot_s1.tool_pose(Q_S1) + np.array([0.003, -0.002, 0.001, 0.1])
    reply = a.handle("goto", {"pose": [target[0] * 1e3, target[1] * 1e3, target[2] * 1e3, math.degrees(target[3])]})
    assert reply.moved
    np.testing.assert_allclose(robot_s1.tool_pose(a.q), target, rtol=0, atol=1e-9)
    for body, match in (({"axis": "q", "step": 1}, "jog axis"), ({"axis": "x", "step": "nan"}, "step"),
                        ({"axis": "x", "step": None}, "step")):  # fmt: skip
        with pytest.raises(InvalidInputError, match=match):
            a.handle("jog", body)
    with pytest.raises(InvalidInputError, match="unknown request"):
        a.handle("delete", {})
    with pytest.raises(InvalidInputError, match="outside the limits"):
        TeachSession(robot_s1, [0.0, 0.0, 0.5, 0.0])


def test_numeric_fallback_where_the_closed_form_refuses(robot_s1: Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    robot = load_robot("s1")

    def refuse(*args: object, **kwargs: object) -> np.ndarray:
        raise NotScaraError("joint2's axis is not parallel to joint1's (test)")

    monkeypatch.setattr(robot, "ik_nearest", refuse)
    session = TeachSession(robot, Q_S1)
    before = robot.tool_pose(session.q)
    reply = session.jog(JogAxis.X, 0.01)
    assert reply.moved and reply.solver is Solver.NUMERIC
    np.testing.assert_allclose(robot.tool_pose(session.q), before + [0.01, 0, 0, 0], rtol=0, atol=1e-9)
    q = session.q
    reply = session.jog(JogAxis.X, 1.0)
    assert not reply.moved and reply.status == "NUMERIC_NO_SOLUTION" and "closed form refuses" in reply.message
    np.testing.assert_array_equal(session.q, q)


# ------------------------------------------------------------------------------------------ browser
def fk_cli(capsys: pytest.CaptureFixture[str], robot: str, q: list[float]) -> np.ndarray:
    assert main(["fk", "--robot", robot, *map(repr, q), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    return np.array([*out["position"], out["yaw"]])


def readout(page: Any) -> np.ndarray:
    text = page.inner_text("#tool-pose")
    values = dict(re.findall(r"(x|y|z|yaw) = (\S+)", text))
    assert set(values) == {"x", "y", "z", "yaw"}, text
    return np.array([float(values[k]) for k in ("x", "y", "z", "yaw")])


SET_SLIDER = """([name, value]) => {
    const input = document.querySelector(`input[type=range][name="${name}"]`);
    input.value = String(value);
    input.dispatchEvent(new Event("input", { bubbles: true }));
    return Number(input.value);
}"""


@pytest.mark.parametrize("name", ["s1", "palletizer"])
def test_offline_sliders_move_the_robot_and_the_readout_is_fk(
    shipped: dict[str, Robot], name: str, page: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = shipped[name]
    path = export_html(robot, tmp_path / "p.html")
    page.goto(path.as_uri())
    page.wait_for_function("() => window.scaraPendant")
    sliders = page.eval_on_selector_all(
        "input[type=range]", "els => els.map(e => [e.name, Number(e.min), Number(e.max), e.step])"
    )
    actuated = [n for n in robot.model.names[1:] if robot.model.joints[robot.model.getJointId(n)].nv == 1]
    assert [s[0] for s in sliders] == actuated
    np.testing.assert_array_equal([s[1] for s in sliders], robot.limits.lower)
    np.testing.assert_array_equal([s[2] for s in sliders], robot.limits.upper)
    assert "joint3 [m]" in page.inner_text("#joint-sliders") or name == "palletizer"
    rng = np.random.default_rng(7)
    for _ in range(3):
        q = rng.uniform(robot.limits.lower, robot.limits.upper)
        got_q = [page.evaluate(SET_SLIDER, [joint, float(v)]) for joint, v in zip(actuated, q, strict=True)]
        expected = fk_cli(capsys, name, got_q)
        shown = readout(page)
        np.testing.assert_allclose(shown[:3], expected[:3], rtol=0, atol=1e-6)
        assert abs(math.remainder(shown[3] - expected[3], 2 * math.pi)) < 1e-6
    assert page.errors == []


def _pids_listening(port: int) -> list[int]:
    return [c.pid for c in psutil.net_connections(kind="inet") if c.laddr.port == port and c.status == "LISTEN"]


def test_live_teach_page_jogs_with_ik(page: Any, robot_s1: Robot) -> None:
    script = Path(sys.executable).parent / "scara-pin"
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "scara_pin.cli"]
    q0 = [repr(float(v)) for v in Q_S1]
    proc = subprocess.Popen([*cmd, "teach", "--robot", "s1", "--port", "0", "--q", *q0],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_sigint)  # fmt: skip
    port = None
    try:
        line = proc.stdout.readline()  # type: ignore[union-attr]
        match = re.search(r"(http://127\.0\.0\.1:(\d+)/)", line)
        assert match, line
        url, port = match.group(1), int(match.group(2))

        def state() -> np.ndarray:
            with urllib.request.urlopen(url + "api/state", timeout=10) as reply:
                return np.array(json.loads(reply.read())["q"])

        assert {ip for ip in (c.laddr.ip for c in psutil.Process(proc.pid).net_connections("inet")
                              if c.status == "LISTEN")} == {"127.0.0.1"}  # fmt: skip
        page.goto(url)
        page.wait_for_function("() => window.scaraReplies >= 1")
        np.testing.assert_array_equal(state(), Q_S1)
        # the live readout is the server's FK at full precision
        np.testing.assert_array_equal(readout(page), robot_s1.tool_pose(Q_S1))

        page.fill("#jog-step", "10")
        page.click("[id='jog-x+']")
        page.wait_for_function("() => window.scaraReplies >= 2")
        q1 = state()
        delta = robot_s1.tool_pose(q1) - robot_s1.tool_pose(Q_S1)
        np.testing.assert_allclose(delta, [0.01, 0.0, 0.0, 0.0], rtol=0, atol=1e-9)
        assert "OK" in page.inner_text("#ik-status")
        shown_q = page.inner_text("#joint-values")
        assert all(repr(float(v)) in shown_q for v in q1), shown_q
        np.testing.assert_array_equal(readout(page), robot_s1.tool_pose(q1))
        # the scene graph moved too: the page's own three.js pose agrees with FK
        scene = np.array(page.evaluate("() => scaraPendant.scenePose()"))
        np.testing.assert_allclose(scene, robot_s1.tool_pose(q1), rtol=0, atol=1e-6)

        page.fill("#jog-step", "1000")  # 1 m along x: out of the workspace
        page.click("[id='jog-x+']")
        page.wait_for_function("() => window.scaraReplies >= 3")
        status = page.inner_text("#ik-status")
        assert "OUT_OF_REACH" in status and "reach" in status, status
        np.testing.assert_array_equal(state(), q1)
        assert page.errors == []
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(timeout=10)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    err = proc.stderr.read()  # type: ignore[union-attr]
    assert code == 0, err
    assert "Traceback" not in err
    assert not psutil.pid_exists(proc.pid) or psutil.Process(proc.pid).status() == psutil.STATUS_ZOMBIE
    assert port is not None and _pids_listening(port) == []
    with socket.socket() as s, pytest.raises(OSError):
        s.settimeout(2)
        s.connect(("127.0.0.1", port))
