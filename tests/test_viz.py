"""The browser viewer (scara_pin.viz.meshcat): meshcat server life cycle, static export, and a real headless browser.

Truth comes from independent routes: Pinocchio FK (``robot.frame_placement(q, "tool0", "universe")``)
against the tool frame's world position read from three.js in the page (meshcat's scene is turned by
``rotateX(-pi/2)``: scene (x, y, z) is three.js world (x, z, -y)); the links' orange counted in a
screenshot, with the visuals hidden as the negative control; the operating system's process table and
sockets for the server's life and binding.

Browser tests use Debian's /usr/bin/chromium through Playwright's Python API (see ``tests/browser.py``).
With CI=true they always run (a Chromium that cannot start fails them); elsewhere they are skipped only
when Chromium or Playwright is absent. Screenshots go to ``tests/artifacts/``.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import psutil
import pytest
from browser import next_frames, orange_pixels

from scara_pin import InvalidInputError, Robot, load_robot
from scara_pin.viz.meshcat import (
    ROBOT_NODE,
    Viewer,
    ViewerError,
    export_html,
    read_trajectory_csv,
    static_html,
    tool_path,
)
from scara_pin.viz.tree import node_paths

ARTIFACTS = Path(__file__).resolve().parent / "artifacts"
SERVER_MARK = "scara-pin-meshcat-server"
FPS = 30
Q_A = np.array([0.3, 0.4, 0.02, -0.5])
Q_B = np.array([-1.1, 1.2, 0.04, 1.0])
TIMEOUT = 60


# ------------------------------------------------------------------------------------------ helpers
def alive(pid: int) -> bool:
    """True when the process exists and is not a zombie (an unreaped dead child)."""
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def wait_dead(pid: int, timeout: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if not alive(pid):
            return True
        time.sleep(0.05)
    return not alive(pid)


def our_servers() -> list[psutil.Process]:
    """meshcat servers started from this test process (ours carry its pid), or any meshcat server that
    descends from it."""
    me = os.getpid()
    found = []
    for proc in psutil.process_iter(["pid", "cmdline", "status"]):
        cmd = proc.info["cmdline"] or []
        if proc.info["status"] == psutil.STATUS_ZOMBIE or proc.pid == me:
            continue
        ours = SERVER_MARK in cmd and cmd[cmd.index(SERVER_MARK) + 1 : cmd.index(SERVER_MARK) + 2] == [str(me)]
        meshcat = any("meshcat-server" in c or "meshcat.servers.zmqserver" in c for c in cmd)
        try:
            descends = any(p.pid == me for p in proc.parents())
        except psutil.NoSuchProcess:
            continue
        if ours or (meshcat and descends):
            found.append(proc)
    return found


def fk_tool(robot: Robot, q: np.ndarray) -> np.ndarray:
    return np.array(robot.frame_placement(q, "tool0", relative_to="universe").translation)


def scene_from_three(p: list[float]) -> np.ndarray:
    """three.js world (Y up) -> meshcat scene (z up): inverse of scene.rotateX(-pi/2)."""
    x, y, z = p
    return np.array([x, -z, y])


TOOL_JS = """(path) => {
    let node = viewer.scene_tree;
    for (const k of path.split("/")) node = (node && node.children[k]) || null;
    if (node === null) return null;
    viewer.scene.updateMatrixWorld(true);
    const e = node.object.matrixWorld.elements;
    return [e[12], e[13], e[14]];
}"""


def frame_path(robot: Robot, frame: str = "tool0") -> str:
    """The scene path of a frame's triad: under its joint's node of the tree (robot/joint1/.../frames/tool0)."""
    f = robot.model.frames[robot.model.getFrameId(frame)]
    return f"meshcat/{node_paths(robot, ROBOT_NODE)[f.parentJoint]}/frames/{frame}"

SCENE_MATRIX_JS = (
    "() => { viewer.scene.updateMatrixWorld(true); return Array.from(viewer.scene.matrixWorld.elements); }"
)


def tool_in_page(page: Any, expected: np.ndarray, robot: Robot, timeout: float = 15.0) -> np.ndarray:
    """The tool frame's scene position read from three.js, once it is within 1e-6 m of ``expected``
    (commands reach the page asynchronously) or when time is up (the caller's assertion then fails)."""
    deadline = time.monotonic() + timeout
    pos = None
    while time.monotonic() < deadline:
        raw = page.evaluate(TOOL_JS, frame_path(robot))
        if raw is not None:
            pos = scene_from_three(raw)
            if np.allclose(pos, expected, rtol=0, atol=1e-6):
                return pos
        time.sleep(0.05)
    assert pos is not None, "the page has no tool0 object"
    return pos


def trajectory(robot: Robot, n: int = 31) -> tuple[np.ndarray, np.ndarray]:
    """A motion sampled on the animation's frame times (k / FPS), so frames hold samples exactly."""
    times = np.arange(n) / FPS
    s = times / times[-1]
    blend = (3 * s**2 - 2 * s**3)[:, None]
    qs = Q_A + blend * (Q_B - Q_A)
    return times, qs


def page_data(text: str) -> dict[str, Any]:
    """The pendant panel's data embedded in a page."""
    import json
    import re

    match = re.search(r'<script type="application/json" id="scara-data">(.*?)</script>', text, re.S)
    assert match, "the page has no pendant data"
    return json.loads(match.group(1))  # type: ignore[no-any-return]


def page_commands(text: str) -> list[dict[str, Any]]:
    """The meshcat commands a static page replays (base64 msgpack strings, one per line)."""
    import base64
    import re

    import umsgpack

    return [umsgpack.unpackb(base64.b64decode(c)) for c in re.findall(r'^"([A-Za-z0-9+/=]+)",?$', text, re.M)]


def last_transform(commands: list[dict[str, Any]], path: str) -> np.ndarray:
    matrices = [c["matrix"] for c in commands if c["type"] == "set_transform" and c["path"] == path]
    assert matrices, f"no transform of {path}"
    return np.array(matrices[-1]).reshape(4, 4).T  # meshcat sends column-major


def line_points(commands: list[dict[str, Any]], path: str) -> np.ndarray:
    """(N, 3) vertices of a line object drawn at ``path`` (float32 in the page)."""
    obj = next(c["object"] for c in commands if c["type"] == "set_object" and c["path"] == path)
    position = obj["geometries"][0]["data"]["attributes"]["position"]
    return np.frombuffer(position["array"].data, dtype=np.float32).reshape(-1, 3).astype(float)


# ------------------------------------------------------------------------------------------ fixtures
@pytest.fixture(scope="module")
def robot(robot_s1: Robot) -> Robot:
    return robot_s1


@pytest.fixture
def viewer(robot: Robot) -> Iterator[Viewer]:
    v = Viewer(robot)
    try:
        yield v
    finally:
        v.close()
        assert v.server_pid is not None and wait_dead(v.server_pid), "the viewer's server outlived close()"


def screenshot(page: Any, name: str) -> bytes:
    ARTIFACTS.mkdir(exist_ok=True)
    next_frames(page)
    return page.screenshot(path=str(ARTIFACTS / name))


# ------------------------------------------------------------------------------------------ server life
def test_server_listens_on_loopback_only(viewer: Viewer) -> None:
    assert viewer.url.startswith("http://127.0.0.1:") and viewer.url.endswith("/static/")
    assert viewer.zmq_url.startswith("tcp://127.0.0.1:")
    pid = viewer.server_pid
    assert pid is not None and alive(pid)
    listening = [c for c in psutil.Process(pid).net_connections(kind="inet") if c.status == psutil.CONN_LISTEN]
    ports = {c.laddr.port for c in listening}
    assert int(viewer.url.split(":")[2].split("/")[0]) in ports
    assert int(viewer.zmq_url.rsplit(":", 1)[1]) in ports
    assert {c.laddr.ip for c in listening} == {"127.0.0.1"}, listening


def test_close_stops_the_server_and_is_idempotent(robot: Robot) -> None:
    v = Viewer(robot)
    pid = v.server_pid
    assert pid is not None and alive(pid)
    v.close()
    assert not alive(pid)
    v.close()
    with pytest.raises(ViewerError, match="closed"):
        v.display(Q_A)


def test_context_manager_stops_the_server(robot: Robot) -> None:
    with Viewer(robot) as v:
        pid = v.server_pid
        assert pid is not None and alive(pid)
        v.display(Q_A)
    assert not alive(pid)


def test_serve_blocks_until_the_server_stops(robot: Robot) -> None:
    import threading

    v = Viewer(robot)
    pid = v.server_pid
    assert pid is not None
    killer = threading.Timer(0.5, os.kill, (pid, signal.SIGKILL))  # the server this test started
    killer.start()
    start = time.monotonic()
    with pytest.raises(ViewerError, match="stopped"):
        v.serve(poll=0.05)
    assert 0.4 < time.monotonic() - start < 5
    killer.join()
    assert not alive(pid)
    with pytest.raises(ViewerError, match="closed"):
        v.display(Q_A)


def test_second_viewer_connects_to_a_running_server(viewer: Viewer, robot: Robot) -> None:
    with Viewer(robot, zmq_url=viewer.zmq_url) as other:
        assert other.server_pid is None
        assert other.url == viewer.url
        other.display(Q_B)
    assert viewer.server_pid is not None and alive(viewer.server_pid), "closing a client stopped the server"
    viewer.display(Q_A)  # the owner still talks to it


def test_a_server_that_does_not_answer_is_an_error_not_a_hang(robot: Robot) -> None:
    import socket

    with socket.socket() as s:  # a free port nobody answers on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    start = time.monotonic()
    with pytest.raises(ViewerError, match="did not answer within 0.5 s"):
        Viewer(robot, zmq_url=f"tcp://127.0.0.1:{port}", timeout=0.5)
    assert time.monotonic() - start < 5


CHILD = textwrap.dedent(
    """
    import atexit, sys, time
    import psutil
    from scara_pin import load_robot
    from scara_pin.viz.meshcat import Viewer

    def alive(pid):
        try:
            return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
        except psutil.NoSuchProcess:
            return False

    def report():  # registered first, so atexit runs it AFTER the viewer's own handler (last in, first out)
        print("after-atexit alive", alive(viewer.server_pid), flush=True)

    atexit.register(report)
    viewer = Viewer(load_robot("s1"))
    viewer.display([0.1, 0.2, 0.01, 0.3])
    print("server", viewer.server_pid, flush=True)
    if sys.argv[1] == "sleep":
        time.sleep(60)
    """
)


def test_atexit_stops_the_server() -> None:
    out = subprocess.run(
        [sys.executable, "-c", CHILD, "exit"], capture_output=True, text=True, timeout=TIMEOUT, check=True
    ).stdout
    lines = dict(line.split(" ", 1) for line in out.splitlines())
    pid = int(lines["server"])
    assert lines["after-atexit"] == "alive False", out
    assert wait_dead(pid)


def test_the_server_dies_with_its_parent_even_on_sigkill() -> None:
    child = subprocess.Popen([sys.executable, "-c", CHILD, "sleep"], stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout is not None
        line = child.stdout.readline()
        assert line.startswith("server "), line
        pid = int(line.split()[1])
        assert alive(pid)
        child.send_signal(signal.SIGKILL)
        child.wait(timeout=10)
        assert wait_dead(pid, timeout=5.0), "the meshcat server outlived its killed parent"
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


# ------------------------------------------------------------------------------------------ inputs
def test_read_trajectory_csv(tmp_path: Path) -> None:
    header = ["t"] + [f"{k}{i}" for k in ("q", "qd", "qdd") for i in range(1, 5)]
    times = np.array([0.0, 0.5, 1.25])
    qs = np.array([[0.0, 0.1, 0.0, -0.2], [0.1, 0.2, 0.01, -0.1], [0.2, 0.3, 0.02, 0.0]])
    rows = [",".join(map(repr, [t, *q, *np.zeros(8)])) for t, q in zip(times.tolist(), qs.tolist(), strict=True)]
    path = tmp_path / "traj.csv"
    path.write_text(",".join(header) + "\n" + "\n".join(rows) + "\n", encoding="utf-8")
    t, q = read_trajectory_csv(path)
    np.testing.assert_array_equal(t, times)
    np.testing.assert_array_equal(q, qs)

    path.write_text("t,q1,q2,q4\n0,0,0,0\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match="no column q3"):
        read_trajectory_csv(path)
    path.write_text("t,q1,q2,q3,q4\n0,0,0,0,0\n0.1,0,zero,0,0\n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match="line 3"):
        read_trajectory_csv(path)


def test_bad_motions_and_drawings_are_refused(viewer: Viewer) -> None:
    with pytest.raises(InvalidInputError, match="increase strictly"):
        viewer.animate([0.0, 0.2, 0.2], np.zeros((3, 4)))
    with pytest.raises(InvalidInputError, match="shape"):
        viewer.animate([0.0, 0.1], np.zeros((2, 3)))
    with pytest.raises(InvalidInputError, match="fps"):
        viewer.animate([0.0, 0.1], np.zeros((2, 4)), fps=0)
    with pytest.raises(InvalidInputError, match="finite"):
        viewer.draw_path([[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(InvalidInputError, match="2 numbers"):
        viewer.draw_polylines([np.zeros((5, 4))])  # (x, y) or (x, y, z) points only
    with pytest.raises(InvalidInputError, match="at least 2 points of 3 numbers"):
        viewer.draw_polylines([np.zeros((1, 3))])
    with pytest.raises(InvalidInputError, match="x, y, z, yaw"):
        viewer.draw_targets([[0.1, 0.2, 0.0]])


def test_solver_modules_do_not_import_the_viewer() -> None:
    code = textwrap.dedent(
        """
        import importlib, pkgutil, sys
        import scara_pin
        names = [m.name for m in pkgutil.iter_modules(scara_pin.__path__) if m.name != "viz"]
        for name in names:
            importlib.import_module("scara_pin." + name)
        import scara_pin.viz.meshcat  # meshcat only inside its functions
        print(sorted(names), "meshcat" in sys.modules, "scara_pin.viz.meshcat" in sys.modules)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=TIMEOUT)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().endswith("False True"), out.stdout


# ------------------------------------------------------------------------------------------ static page
def test_export_html_is_atomic_and_self_contained(robot: Robot, tmp_path: Path) -> None:
    times, qs = trajectory(robot)
    path = export_html(robot, tmp_path / "s1.html", times=times, qs=qs)
    text = path.read_text(encoding="utf-8")
    assert 800_000 < len(text) < 3_000_000
    assert "<script src" not in text
    data = page_data(text)
    assert "teach" not in data  # the offline page never calls the server (no request: see the browser test)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s1.html"]  # no temporary file left
    # a failed write leaves the old file as it was
    with pytest.raises(InvalidInputError, match="2 numbers"):
        export_html(robot, path, polylines=[[[0, 0, 0, 0]]])
    assert path.read_text(encoding="utf-8") == text
    with pytest.raises(InvalidInputError, match="does not exist"):
        export_html(robot, tmp_path / "missing" / "x.html")


@pytest.mark.parametrize("name", ["default", "s1", "palletizer"])
def test_static_scene_holds_the_motion_targets_and_workspace(robots: dict[str, Robot], name: str) -> None:
    """The page's data and commands: the player's samples are the motion's (resampled at FPS on sample times
    here, so equal); the tool path is the FK of the samples; a target marker drawn at the FK pose of a q is
    where tool0 is at that q, z axis included; the workspace polyline lies on the floor."""
    robot = robots[name] if name in robots else load_robot(name)
    times, qs = trajectory(robot)
    if name == "palletizer":
        qs = qs + np.array([0.0, 0.0, 1.0, 0.0])  # inside the palletizer's theta3 range
    ring = np.array([[0.2 * math.cos(a), 0.2 * math.sin(a)] for a in np.linspace(0, 2 * math.pi, 60)])
    q_target = qs[7]
    target = robot.tool_pose(q_target)
    text = static_html(robot, times=times, qs=qs, polylines=[ring], targets=[target])
    commands = page_commands(text)
    assert not [c for c in commands if c["type"] == "set_animation"]
    motion = page_data(text)["motion"]
    np.testing.assert_allclose(motion["times"], times, rtol=0, atol=1e-12)
    np.testing.assert_allclose(motion["qs"], qs, rtol=0, atol=1e-12)
    assert motion["loop"] is True
    # the tool path drawn by default is the FK curve (float32 in the page)
    got = np.array([fk_tool(robot, q) for q in qs])
    np.testing.assert_allclose(line_points(commands, "/meshcat/overlays/path"), got, rtol=0, atol=1e-6)

    oMb = robot.frame_placement(qs[0], robot.base_frame, relative_to="universe")
    np.testing.assert_allclose(tool_path(robot, qs) @ oMb.rotation.T + oMb.translation, got, rtol=0, atol=1e-12)
    M = last_transform(commands, "/meshcat/overlays/targets/0")
    np.testing.assert_allclose(M, robot.frame_placement(q_target, "tool0", "universe").homogeneous, rtol=0, atol=1e-12)

    floor = line_points(commands, "/meshcat/overlays/workspace/0")
    np.testing.assert_allclose(floor[:, 2], 0.0, atol=1e-7)
    np.testing.assert_allclose(floor[:, :2], ring + oMb.translation[:2], rtol=0, atol=1e-7)


def chain_placement(commands: list[dict[str, Any]], robot: Robot, frame: str) -> np.ndarray:
    """A frame's placement in the universe composed from the last transforms of the nodes on its path."""
    f = robot.model.frames[robot.model.getFrameId(frame)]
    M = np.eye(4)
    path = ""
    for part in frame_path(robot, frame).split("/")[1:]:
        path = f"{path}/{part}"
        matrices = [c["matrix"] for c in commands if c["type"] == "set_transform" and c["path"] == "/meshcat" + path]
        if matrices:
            M = M @ np.array(matrices[-1]).reshape(4, 4).T
    assert f.parentJoint > 0
    return M


def test_play_steps_in_real_time(viewer: Viewer, robot: Robot) -> None:
    times, qs = trajectory(robot)  # 1 s
    start = time.monotonic()
    viewer.play(times, qs, speed=2.0)
    elapsed = time.monotonic() - start
    assert 0.45 < elapsed < 1.5, elapsed
    M = chain_placement(page_commands(viewer.static_html()), robot, "tool0")
    np.testing.assert_allclose(M, robot.frame_placement(qs[-1], "tool0", "universe").homogeneous, rtol=0, atol=1e-12)


def test_play_and_animate_take_a_trajectory(viewer: Viewer, robot: Robot) -> None:
    """The live viewer as a MeshcatVisualizer user drives it: display(q), play(trajectory), animate(trajectory)."""
    from scara_pin.motion.timing import time_optimal

    traj = time_optimal(robot, [Q_A, Q_B])
    viewer.display(Q_A)
    M = chain_placement(page_commands(viewer.static_html()), robot, "tool0")
    np.testing.assert_allclose(M, robot.frame_placement(Q_A, "tool0", "universe").homogeneous, rtol=0, atol=1e-12)
    start = time.monotonic()
    viewer.play(traj, speed=2.0)
    elapsed = time.monotonic() - start
    assert 0.4 * traj.duration < elapsed < 0.5 * traj.duration + 1.0, (elapsed, traj.duration)
    M = chain_placement(page_commands(viewer.static_html()), robot, "tool0")  # it ends where the trajectory does
    np.testing.assert_allclose(M, robot.frame_placement(Q_B, "tool0", "universe").homogeneous, rtol=0, atol=1e-9)
    viewer.animate(traj, fps=30)  # the browser's animation: frames at 30 fps, the last one q_end
    with pytest.raises(InvalidInputError, match="not both"):
        viewer.play(traj, Q_A[None, :])


# ------------------------------------------------------------------------------------------ real browser
def test_live_page_shows_the_robot_where_pinocchio_puts_it(viewer: Viewer, robot: Robot, page: Any) -> None:
    viewer.display(Q_A)
    viewer.draw_polylines([np.array([[0.2 * math.cos(a), 0.2 * math.sin(a)] for a in np.linspace(0, 2 * math.pi, 60)])])
    page.goto(viewer.url)
    page.wait_for_function("() => window.viewer && viewer.connection && viewer.connection.readyState === 1")

    expected_a = fk_tool(robot, Q_A)
    np.testing.assert_allclose(tool_in_page(page, expected_a, robot), expected_a, rtol=0, atol=1e-6)
    # meshcat's root turn, which the conversion above undoes: three.js world = Rx(-pi/2) scene
    m = np.array(page.evaluate(SCENE_MATRIX_JS)).reshape(4, 4).T
    np.testing.assert_allclose(m[:3, :3], [[1, 0, 0], [0, 0, 1], [0, -1, 0]], atol=1e-12)

    shown = orange_pixels(screenshot(page, "live_robot.png"))
    assert shown > 500, f"only {shown} robot-orange pixels in the live page"
    viewer.visualizer[ROBOT_NODE].set_property("visible", False)  # the whole tree: links and frames
    page.wait_for_function(f"() => viewer.scene_tree.children.meshcat.children.{ROBOT_NODE}.object.visible === false")
    hidden = orange_pixels(screenshot(page, "live_robot_hidden.png"))
    assert hidden < 0.02 * shown, f"{hidden} orange pixels with the robot hidden (vs {shown})"
    viewer.visualizer[ROBOT_NODE].set_property("visible", True)

    # an animation step: another configuration moves the tool accordingly
    viewer.display(Q_B)
    expected_b = fk_tool(robot, Q_B)
    assert np.linalg.norm(expected_b - expected_a) > 0.05
    np.testing.assert_allclose(tool_in_page(page, expected_b, robot), expected_b, rtol=0, atol=1e-6)
    assert orange_pixels(screenshot(page, "live_robot_moved.png")) > 500
    assert page.errors == []


def test_live_animation_follows_the_trajectory(viewer: Viewer, robot: Robot, page: Any) -> None:
    times, qs = trajectory(robot)
    page.goto(viewer.url)
    page.wait_for_function("() => window.viewer && viewer.connection && viewer.connection.readyState === 1")
    viewer.animate(times, qs)
    page.wait_for_function("(d) => Math.abs(viewer.animator.duration - d) < 1e-6", arg=float(times[-1]))
    # played in real time: the browser's clock moves the animation on
    t0 = page.evaluate("() => viewer.animator.actions[0].time")
    time.sleep(0.5)
    t_played = page.evaluate("() => viewer.animator.actions[0].time")
    page.evaluate("() => viewer.animator.pause()")
    for k in (0, 10, 17, len(times) - 1):
        page.evaluate("(t) => viewer.animator.seek(t)", float(times[k]))
        expected = fk_tool(robot, qs[k])
        shown = tool_in_page(page, expected, robot)
        np.testing.assert_allclose(shown, expected, rtol=0, atol=1e-6, err_msg=f"sample {k}")
    assert t0 < t_played, (t0, t_played)
    assert 0.1 < t_played - t0 <= times[-1], (t0, t_played)
    assert page.errors == []


def test_static_page_renders_offline_without_any_request(robot: Robot, page: Any, tmp_path: Path) -> None:
    times, qs = trajectory(robot)
    ring = np.array([[0.2 * math.cos(a), 0.2 * math.sin(a)] for a in np.linspace(0, 2 * math.pi, 60)])
    path = export_html(
        robot, tmp_path / "s1.html", times=times, qs=qs, polylines=[ring], targets=[[0.1, 0.1, 0.0, 0.5]]
    )
    requests: list[str] = []
    blocked: list[str] = []

    def route(r: Any) -> None:
        if r.request.url.startswith("file://"):
            r.continue_()
        else:
            blocked.append(r.request.url)
            r.abort()

    page.route("**/*", route)
    page.on("request", lambda r: requests.append(r.url))
    page.on("websocket", lambda ws: requests.append(ws.url))
    page.goto(path.as_uri())
    page.wait_for_function("() => window.scaraSceneCommands > 0 && window.scaraPlayer")
    assert page.evaluate("() => scaraPlayer.playing()")  # plays at load
    page.evaluate("(t) => scaraPlayer.seek(t)", float(times[-1]))
    expected = fk_tool(robot, qs[-1])
    np.testing.assert_allclose(tool_in_page(page, expected, robot), expected, rtol=0, atol=1e-6)
    shown = orange_pixels(screenshot(page, "static_robot.png"))
    assert shown > 500, f"only {shown} robot-orange pixels in the static page"
    assert requests == [path.as_uri()], requests
    assert blocked == []
    assert page.errors == []


# ------------------------------------------------------------------------------------------ last
def test_no_meshcat_server_is_left_behind() -> None:
    """Runs last in this file: every server the tests above started has been stopped."""
    left = our_servers()
    assert left == [], [(p.pid, p.info["cmdline"]) for p in left]
