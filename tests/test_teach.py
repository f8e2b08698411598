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
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from pendant_page import pin_placement, readout, resolution

from scara_pin import InvalidInputError, Robot, load_robot, load_urdf
from scara_pin.cli import main
from scara_pin.kinematics.scara import NotScaraError
from scara_pin.motion.manual import MANUAL_SPEED, JogMotion
from scara_pin.viz.meshcat import export_html
from scara_pin.viz.teach import (
    CONTROL_PERIOD,
    MAX_STEP_ANGLE,
    MAX_STEP_LENGTH,
    WATCHDOG,
    JogAxis,
    JogFrame,
    Solver,
    StopKind,
    TeachSession,
)
from scara_pin.viz.tree import FIELD_OF_VIEW, framing, joint_nodes
from scara_pin.workspace import workspace

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


@pytest.mark.parametrize("name", NAMES)
def test_tool_frame_jogs_move_along_the_tools_own_axes(shipped: dict[str, Robot], name: str) -> None:
    """Along x, y, z of the tool frame: the origin moves by step * (that axis of R0), R0 kept; about its z: the
    rotation becomes R0 Rz(step). R0 and the expectations from Pinocchio's frame placements, written here."""
    robot = shipped[name]
    q0 = {"s1": Q_S1, "default": np.array([0.4, 1.0, 0.02, 0.3]), "palletizer": np.array([0.3, 0.5, 1.0, 0.2])}[name]
    start = pin_placement(robot, q0)
    for axis, step in ((JogAxis.X, 0.01), (JogAxis.Y, -0.01), (JogAxis.Z, 0.005), (JogAxis.YAW, math.radians(5))):
        session = TeachSession(robot, q0)
        reply = session.jog(axis, step, JogFrame.TOOL)
        assert reply.moved and reply.status == "OK", (axis, reply.status, reply.message)
        end = pin_placement(robot, session.q)
        if axis is JogAxis.YAW:
            np.testing.assert_allclose(end.translation, start.translation, rtol=0, atol=1e-9)
            turned = start.rotation @ pin.rpy.rpyToMatrix(0, 0, step)
            np.testing.assert_allclose(end.rotation, turned, rtol=0, atol=1e-9)
        else:
            expected = start.translation + step * start.rotation[:, axis.value]
            np.testing.assert_allclose(end.translation, expected, rtol=0, atol=1e-9)
            np.testing.assert_allclose(end.rotation, start.rotation, rtol=0, atol=1e-9)


def test_joint_jog_moves_one_joint_by_the_step_exactly_and_stops_on_its_limit(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    for j, step in ((0, math.radians(3)), (1, -math.radians(7)), (2, 0.004), (3, math.radians(90))):
        q0 = session.q
        reply = session.jog_joint(j, step)
        assert reply.moved and reply.status == "OK"
        expected = q0.copy()
        expected[j] = q0[j] + step
        np.testing.assert_array_equal(session.q, expected)
    q0 = session.q
    reply = session.jog_joint("joint3", 0.09)  # the stroke ends at 0.1 m: 0.024 m of room
    assert reply.status == "STOPPED" and reply.limit == "joint3_upper" and "joint3's upper limit 0.1" in reply.message
    assert session.q[2] == robot_s1.limits.upper[2] and reply.travelled == pytest.approx(0.1 - q0[2], abs=1e-15)
    np.testing.assert_array_equal(np.delete(session.q, 2), np.delete(q0, 2))
    reply = session.jog_joint(2, 0.001)
    assert not reply.moved and reply.status == "AT_EDGE" and reply.limit == "joint3_upper"


@pytest.mark.parametrize("name", ["s1", "default"])
def test_a_jog_toward_the_edge_ends_on_the_workspace_ray(shipped: dict[str, Robot], name: str) -> None:
    """A 1 m step ends on the point the workspace's own ray gives, named by its limit; a second one does not move."""
    robot = shipped[name]
    q0 = Q_S1 if name == "s1" else np.array([0.4, 1.0, 0.02, 0.3])
    ws = workspace(robot)
    for sign, axis, frame in ((1, JogAxis.X, JogFrame.BASE), (-1, JogAxis.Y, JogFrame.BASE),
                              (-1, JogAxis.X, JogFrame.BASE), (1, JogAxis.Z, JogFrame.BASE),
                              (1, JogAxis.Y, JogFrame.TOOL)):  # fmt: skip
        session = TeachSession(robot, q0)
        start = pin_placement(robot, q0)
        axes = start.rotation if frame is JogFrame.TOOL else np.eye(3)
        u = sign * axes[:, axis.value]
        hit = ws.ray(start.translation, u)
        reply = session.jog(axis, sign * 1.0, frame)
        direction = (sign, axis, frame)
        assert reply.status == "STOPPED" and reply.limit == hit.limit.value, (direction, reply.message)
        assert hit.description in reply.message and reply.travelled == pytest.approx(hit.distance, abs=1e-12)
        np.testing.assert_allclose(pin_placement(robot, session.q).translation, hit.point, rtol=0, atol=1e-9)
        again = session.jog(axis, sign * 0.001, frame)
        assert not again.moved and again.status == "AT_EDGE" and again.limit == hit.limit.value
        np.testing.assert_array_equal(again.q, reply.q)


def test_the_palletizer_stops_on_its_arm_plane_envelope(shipped: dict[str, Robot]) -> None:
    """No ray for the palletizer: the stop is where the IK stops, which must lie on the envelope the arc engine
    draws (distance to its nearest arc circle), inside it, and 1 um beyond it outside."""
    from scara_pin.workspace.palletizer import arm_plane_envelope

    robot = shipped["palletizer"]
    env = arm_plane_envelope(robot.kinematics.geometry)
    for axis, step in ((JogAxis.X, 1.0), (JogAxis.Z, -1.0), (JogAxis.Z, 1.0)):
        session = TeachSession(robot, [0.3, 0.5, 1.0, 0.2])
        for _ in range(4):  # 1 m steps (the largest) until one stops on the edge
            reply = session.jog(axis, step)
            if reply.status != "OK":
                break
        assert reply.status == "STOPPED" and reply.limit, reply.message
        x, y, z, _ = robot.tool_pose(session.q)
        r = math.hypot(x, y)
        gap = min(abs(math.hypot(r - a.center[0], z - a.center[1]) - a.radius) for a in env.arcs)
        assert gap < 1e-9, (axis, step, gap)
        u = np.zeros(3)
        u[axis.value] = math.copysign(1.0, step)
        assert env.contains(r, z)
        beyond = np.array([x, y, z]) + 1e-6 * u
        assert not env.contains(math.hypot(*beyond[:2]), beyond[2])


def test_a_turn_stops_on_j4s_limit_instead_of_unwinding(robot_s1: Robot) -> None:
    q0 = np.array([0.3, 0.9, 0.02, 6.0])  # J4 0.283 rad below its upper limit 2 pi
    session = TeachSession(robot_s1, q0)
    reply = session.jog(JogAxis.YAW, math.radians(90))
    assert reply.status == "STOPPED" and reply.limit == "JOINT_LIMIT" and "joint4" in reply.message, reply.message
    assert session.q[3] == pytest.approx(2 * math.pi, abs=1e-9)
    np.testing.assert_allclose(session.q[:3], q0[:3], rtol=0, atol=1e-12)


def test_a_refused_request_leaves_q_unchanged_and_says_why(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    q0 = session.q
    reply = session.go_to(robot_s1.tool_pose(Q_S1) + [1.0, 0, 0, 0])  # 1 m: s1 reaches 0.2 m
    assert not reply.moved and reply.status == "OUT_OF_REACH" and "reach" in reply.message
    np.testing.assert_array_equal(session.q, q0)
    reply = session.set_q([0.0, 0.0, 0.5, 0.0])  # joint3 beyond its 0.1 m stroke
    assert not reply.moved and reply.status == "JOINT_LIMIT" and "joint3" in reply.message
    np.testing.assert_array_equal(session.q, q0)
    for bad in (0.0, math.nan, math.inf, 2.0, 1e-9, "0.01", True):  # zero, not finite, over 1 m, under 1 um, text
        with pytest.raises(InvalidInputError, match="jog step"):
            session.jog(JogAxis.X, bad)  # type: ignore[arg-type]
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


def test_page_requests_are_si_and_checked(robot_s1: Robot) -> None:
    a, b = TeachSession(robot_s1, Q_S1), TeachSession(robot_s1, Q_S1)
    a.handle("jog", {"axis": "yaw", "frame": "base", "direction": -1, "step": math.radians(4.0)})
    b.jog(JogAxis.YAW, -math.radians(4.0))
    np.testing.assert_array_equal(a.q, b.q)
    a.handle("jog", {"joint": 1, "direction": 1, "step": 0.05})
    b.jog_joint(1, 0.05)
    np.testing.assert_array_equal(a.q, b.q)
    target = robot_s1.tool_pose(Q_S1) + np.array([0.003, -0.002, 0.001, 0.1])
    assert a.handle("goto", {"pose": target.tolist()}).moved
    np.testing.assert_allclose(robot_s1.tool_pose(a.q), target, rtol=0, atol=1e-9)
    q = a.q
    for body, match in (({"axis": "q", "direction": 1, "step": 0.01}, "jog axis"),
                        ({"axis": "x", "direction": 1, "step": -0.005}, "jog step"),
                        ({"axis": "x", "direction": 1, "step": 0}, "jog step"),
                        ({"axis": "x", "direction": 1, "step": math.nan}, "jog step"),
                        ({"axis": "x", "direction": 1, "step": 1e300}, "jog step"),
                        ({"axis": "x", "direction": 1, "step": "10"}, "jog step"),
                        ({"axis": "x", "direction": 2, "step": 0.01}, "direction"),
                        ({"axis": "x", "frame": "world", "direction": 1, "step": 0.01}, "frame"),
                        ({"joint": 7, "direction": 1, "step": 0.01}, "joint 7")):  # fmt: skip
        with pytest.raises(InvalidInputError, match=match):
            a.handle("jog", body)
    with pytest.raises(InvalidInputError, match="speed"):
        a.handle("hold", {"axis": "x", "direction": 1, "speed": 150})
    with pytest.raises(InvalidInputError, match="unknown request"):
        a.handle("delete", {})
    np.testing.assert_array_equal(a.q, q)
    with pytest.raises(InvalidInputError, match="outside the limits"):
        TeachSession(robot_s1, [0.0, 0.0, 0.5, 0.0])


def test_numeric_fallback_where_the_closed_form_refuses(monkeypatch: pytest.MonkeyPatch) -> None:
    robot = load_robot("s1")

    def refuse(*args: object, **kwargs: object) -> np.ndarray:
        raise NotScaraError("joint2's axis is not parallel to joint1's (test)")

    monkeypatch.setattr(robot, "ik_nearest", refuse)
    session = TeachSession(robot, Q_S1)
    before = robot.tool_pose(session.q)
    reply = session.jog(JogAxis.X, 0.005)
    assert reply.moved and reply.solver is Solver.NUMERIC
    np.testing.assert_allclose(robot.tool_pose(session.q), before + [0.005, 0, 0, 0], rtol=0, atol=1e-9)
    q = session.q
    reply = session.go_to(before + [1.0, 0, 0, 0])
    assert not reply.moved and reply.status == "NUMERIC_NO_SOLUTION" and "closed form refuses" in reply.message
    np.testing.assert_array_equal(session.q, q)


# ------------------------------------------------------------------------------------------ hold-to-jog
def period_speeds(robot: Robot, q0: np.ndarray, q1: np.ndarray, dt: float) -> tuple[np.ndarray, float]:
    """|dq| / dt per joint and the tool origin's chord speed over one period, from Pinocchio here."""
    chord = np.linalg.norm(pin_placement(robot, q1).translation - pin_placement(robot, q0).translation)
    return np.abs(q1 - q0) / dt, float(chord / dt)


def test_hold_runs_at_the_override_and_stops_at_once_on_release(robot_s1: Robot) -> None:
    """At 20 %, each period moves the tool along x only, at the fastest speed that keeps every joint under 20 % of
    its velocity limit and the tool under 20 % of 250 mm/s (one of them binding)."""
    session = TeachSession(robot_s1, Q_S1)
    session.hold(JogMotion(1, axis=JogAxis.X), 0.2, now=0.0)
    vmax = np.asarray(robot_s1.limits.velocity)
    q = session.q
    for k in range(1, 5):
        session.alive(k * CONTROL_PERIOD)
        reply = session.tick(k * CONTROL_PERIOD)
        assert reply is not None and reply.moved and reply.status == "OK"
        joints, tool = period_speeds(robot_s1, q, session.q, CONTROL_PERIOD)
        ratio = max(float(np.max(joints / (0.2 * vmax))), tool / (0.2 * MANUAL_SPEED))
        assert 0.99 <= ratio <= 1 + 1e-9, ratio
        step = robot_s1.tool_pose(session.q) - robot_s1.tool_pose(q)
        assert step[0] > 0 and np.all(np.abs(step[1:]) < 1e-12)
        q = session.q
    released = session.release(4 * CONTROL_PERIOD + 0.03)  # between two ticks: nothing moves after it
    assert not released.moved and not released.holding and not session.holding and released.message == "released"
    assert released.reason is not None and released.reason.kind is StopKind.RELEASED and released.status == "OK"
    travelled = np.linalg.norm(pin_placement(robot_s1, q).translation - pin_placement(robot_s1, Q_S1).translation)
    assert released.travelled == pytest.approx(travelled, abs=1e-12)
    np.testing.assert_array_equal(released.q, q)
    assert session.tick(5 * CONTROL_PERIOD) is None and session.tick(1.0) is None
    np.testing.assert_array_equal(session.q, q)


def test_a_held_joint_keeps_its_speed_and_the_tools(robot_s1: Robot) -> None:
    """J1 at 100 %: 3 rad/s would move s1's tool at 0.6 m/s; the manual speed (0.25 m/s) caps it, every period."""
    session = TeachSession(robot_s1, Q_S1)
    session.hold(JogMotion(1, joint=0), 1.0, now=0.0)
    q = session.q
    for k in range(1, 6):
        session.alive(k * CONTROL_PERIOD)
        session.tick(k * CONTROL_PERIOD)
        joints, tool = period_speeds(robot_s1, q, session.q, CONTROL_PERIOD)
        assert np.all(joints <= np.asarray(robot_s1.limits.velocity) * (1 + 1e-9)) and tool <= MANUAL_SPEED * (1 + 1e-9)
        assert tool >= 0.99 * MANUAL_SPEED and np.count_nonzero(session.q - q) == 1  # the cap binds; only J1 moves
        q = session.q


def test_the_watchdog_stops_a_hold_the_page_stopped_confirming(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    session.hold(JogMotion(-1, axis=JogAxis.Y), 0.1, now=0.0)
    session.alive(0.1)  # the last word from the page
    t, moved_until = 0.0, 0.0
    while session.holding:
        t += CONTROL_PERIOD
        before = session.q
        reply = session.tick(t)
        if not np.array_equal(before, session.q):
            moved_until = t
    # it moved, then stopped: "STOPPED" (not a refusal), the watchdog named, how far it went in all
    assert reply is not None and reply.status == "STOPPED" and reply.reason is not None
    assert reply.reason.kind is StopKind.WATCHDOG and "did not confirm the held button for 0.300 s" in reply.message
    assert moved_until <= 0.1 + WATCHDOG and t <= 0.1 + WATCHDOG + CONTROL_PERIOD + 1e-12
    q = session.q
    chord = np.linalg.norm(pin_placement(robot_s1, q).translation - pin_placement(robot_s1, Q_S1).translation)
    assert reply.travelled == pytest.approx(chord, abs=1e-12) and not reply.angle  # a straight line along -y
    assert session.tick(t + 1.0) is None
    np.testing.assert_array_equal(session.q, q)
    for told in (session.alive(t + 1.1), session.release(t + 1.2), session.state(), session.alive(t + 1.3)):
        assert told.status == "STOPPED" and told.reason == reply.reason and told.travelled == reply.travelled
    session.jog(JogAxis.X, 0.001)  # the next move: the hold's end is forgotten
    assert session.alive(t + 1.4).reason is None and session.state().status == "OK"


def test_a_late_tick_waits_for_the_keep_alives(robot_s1: Robot) -> None:
    """The server did not run for 0.35 s (a busy PC): its late tick neither stops the hold (the keep-alives may be
    unread in its socket) nor moves; the next one moves by the time since the last move, at most WATCHDOG. A page
    that is really gone is still stopped, at the first tick on time."""
    session = TeachSession(robot_s1, Q_S1)
    session.hold(JogMotion(1, joint=0), 0.1, now=0.0)
    session.alive(0.04)
    session.tick(0.05)
    one_period = session.q[0] - Q_S1[0]  # J1 turns at a constant rate (the tool's speed caps it at a fixed radius)
    late = session.tick(0.4)
    assert late is not None and late.holding and not late.moved and session.q[0] == Q_S1[0] + one_period
    session.alive(0.41)  # the keep-alive that waited
    session.tick(0.45)
    assert session.holding
    # (each period aims at 99.9 % of the speed cap and lands within 0.1 % of that: manual.py's _AIM)
    assert session.q[0] - Q_S1[0] == pytest.approx(one_period * (1 + WATCHDOG / CONTROL_PERIOD), rel=2e-3)

    gone = TeachSession(robot_s1, Q_S1)
    gone.hold(JogMotion(1, joint=0), 0.1, now=0.0)
    gone.tick(0.05)
    q = gone.q
    assert gone.tick(0.4) is not None and gone.holding  # late: not judged
    reply = gone.tick(0.45)
    assert reply is not None and reply.reason is not None and reply.reason.kind is StopKind.WATCHDOG
    np.testing.assert_array_equal(gone.q, q)  # no move after the last word from the page + WATCHDOG


def test_a_held_jog_ends_on_the_edge(robot_s1: Robot) -> None:
    session = TeachSession(robot_s1, Q_S1)
    start = robot_s1.tool_pose(Q_S1)
    hit = workspace(robot_s1).ray(start[:3], [1.0, 0.0, 0.0])
    session.hold(JogMotion(1, axis=JogAxis.X), 1.0, now=0.0)
    t = 0.0
    while session.holding and t < 5.0:
        t += CONTROL_PERIOD
        session.alive(t)
        reply = session.tick(t)
    assert reply is not None and reply.status == "STOPPED" and reply.limit == hit.limit.value
    assert reply.reason is not None and reply.reason.kind is StopKind.WORKSPACE and hit.description in reply.message
    np.testing.assert_allclose(pin_placement(robot_s1, session.q).translation, hit.point, rtol=0, atol=1e-9)
    assert reply.travelled == pytest.approx(hit.distance, abs=1e-9)  # the whole hold, from start to the edge
    assert session.release(t).reason == reply.reason  # the release of the page then hears why it stopped


THIRD_PARTY = Path(__file__).resolve().parent / "data" / "third_party"


def test_stop_reasons_name_the_joints_as_the_file_does() -> None:
    """A robot whose joints are lift, shoulder, elbow, wrist: the reasons say so (kind, sentence, limit)."""
    robot = load_urdf(THIRD_PARTY / "irb920_like.urdf")
    assert robot.joint_names == ("lift", "shoulder", "elbow", "wrist")
    q0 = np.array([0.05, 0.3, 1.0, 0.2])
    session = TeachSession(robot, q0)
    reply = session.jog_joint("elbow", 3.0)
    upper = robot.limits.upper[2]
    assert reply.reason is not None and reply.reason.kind is StopKind.JOINT_LIMIT and reply.limit == "elbow_upper"
    assert reply.message == f"stopped at elbow's upper limit {upper:.9g} rad" and session.q[2] == upper
    reply = session.jog_joint(2, 0.1)
    assert reply.status == "AT_EDGE" and reply.message == f"elbow is at its upper limit {upper:.9g} rad"
    reply = TeachSession(robot, q0).jog(JogAxis.X, 1.0)
    assert reply.reason is not None and reply.reason.kind is StopKind.WORKSPACE, reply.message
    assert re.search(r"\b(shoulder|elbow)\b", reply.message) and not re.search(r"\bjoint\d", reply.message)


# a length or an angle as a page restates it: "<number> m|rad|deg" or "[a, b] unit"; 0 and "2 pi" need no unit
NUMBER = r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?"
WITH_UNIT = re.compile(rf"(?<![\w.])(?:\[{NUMBER}, {NUMBER}\]|{NUMBER}) (?:m|rad|deg|s)(?![\w/])")
BARE = re.compile(rf"(?<![\w.]){NUMBER}(?![\w.])")


@pytest.mark.parametrize("name", NAMES)
def test_every_quantity_of_a_reason_has_its_unit(shipped: dict[str, Robot], name: str) -> None:
    """The page shows a reason in its own units by its units (manual.py's contract): every number of every stop's
    sentence is "<number> <unit>" (m, rad, deg; s for times). The stops: each joint to both limits, each
    Cartesian axis both ways in both frames to the edge (ray or IK), a second jog at the edge, the watchdog."""
    robot = shipped[name]
    q0 = {"s1": Q_S1, "default": np.array([0.4, 1.0, 0.02, 0.3]), "palletizer": np.array([0.3, 0.5, 1.0, 0.2])}[name]
    reasons = []
    for sign in (1, -1):
        for j in range(robot.dof):
            session = TeachSession(robot, q0)
            step = MAX_STEP_ANGLE if robot.joint_kinds[j] == "angle" else MAX_STEP_LENGTH
            reasons += [session.jog_joint(j, sign * step).reason for _ in range(2)]
        for axis in JogAxis:
            for frame in JogFrame:
                session = TeachSession(robot, q0)
                step = MAX_STEP_ANGLE if axis is JogAxis.YAW else 1.0
                reasons += [session.jog(axis, sign * step, frame).reason for _ in range(2)]
    session = TeachSession(robot, q0)
    session.hold(JogMotion(1, joint=0), 0.1, now=0.0)
    for k in range(1, 8):  # no word from the page
        session.tick(k * CONTROL_PERIOD)
    reasons.append(session.state().reason)
    texts = [r.text for r in reasons if r is not None]
    kinds = {r.kind for r in reasons if r is not None}
    assert {StopKind.JOINT_LIMIT, StopKind.WATCHDOG} <= kinds and kinds & {StopKind.WORKSPACE, StopKind.IK}, kinds
    for text in texts:
        rest = WITH_UNIT.sub("", text).replace("2 pi", "")
        assert [n for n in BARE.findall(rest) if float(n) != 0] == [], text
        assert not re.search(r"\b[A-Z]{2,}_[A-Z_]+\b", text), text  # no status codes: those are the limit's


def test_a_step_shown_to_12_digits_is_the_half_turn(robot_s1: Robot) -> None:
    """180 deg shown in rad is 3.14159265359, a hair over pi: still a valid largest step (pi itself)."""
    session = TeachSession(robot_s1, Q_S1)
    assert float("3.14159265359") > MAX_STEP_ANGLE == math.pi
    reply = session.jog_joint(3, 3.14159265359)
    assert reply.moved and session.q[3] == Q_S1[3] + math.pi and reply.requested == math.pi
    with pytest.raises(InvalidInputError, match="jog step"):
        session.jog_joint(3, 3.1416)
    with pytest.raises(InvalidInputError, match="jog step"):
        session.handle("jog", {"joint": 3, "direction": 1, "step": 3.1416})


def test_points_record_rename_go_to_delete_and_file(robot_s1: Robot, tmp_path: Path) -> None:
    path = tmp_path / "cell.yaml"
    session = TeachSession(robot_s1, Q_S1, points_file=path)
    assert session.record().points is not None and session.points.names == ("P1",)
    session.jog(JogAxis.X, 0.01)
    session.record("pick")
    session.rename("P1", "home")
    with pytest.raises(InvalidInputError, match="exists already"):
        session.record("home")
    assert session.go_to_point("home").moved
    np.testing.assert_array_equal(session.q, Q_S1)
    session.save_points()
    other = TeachSession(robot_s1, points_file=path)
    assert other.points.names == ("home", "pick")
    np.testing.assert_array_equal(other.points["pick"].q, session.points["pick"].q)
    other.delete("pick")
    assert other.points.names == ("home",) and other.load_points().points.names == ("home", "pick")  # type: ignore[union-attr]
    with pytest.raises(InvalidInputError, match="no point named 'P9'"):
        other.go_to_point("P9")
    with pytest.raises(InvalidInputError, match="no points file"):
        TeachSession(robot_s1).save_points()


# ------------------------------------------------------------------------------------------ browser
def fk_cli(capsys: pytest.CaptureFixture[str], robot: str, q: list[float]) -> np.ndarray:
    assert main(["fk", "--robot", robot, *map(repr, q), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    return np.array([*out["position"], out["yaw"]])


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
    assert page.inner_text("#pose-title") == f"{robot.tool_frame} in {robot.base_frame}"
    assert not page.is_visible(".dg.main .close-button")  # meshcat's "Open Controls": hidden unless asked for
    rng = np.random.default_rng(7)
    for units in ("mm", "m"):
        page.check(f"input[name=units][value={units}]")
        for _ in range(2):
            q = rng.uniform(robot.limits.lower, robot.limits.upper)
            got_q = [page.evaluate(SET_SLIDER, [joint, float(v)]) for joint, v in zip(actuated, q, strict=True)]
            expected = fk_cli(capsys, name, got_q)
            shown, shown_units = readout(page)
            assert shown_units == (["mm"] * 3 + ["deg"] if units == "mm" else ["m"] * 3 + ["rad"])
            error = np.abs(shown - expected)
            error[3] = abs(math.remainder(shown[3] - expected[3], 2 * math.pi))
            assert np.all(error <= resolution(shown_units) + 1e-12), (shown, expected)
            sliders_text = page.inner_text("#joint-sliders")
            assert name == "palletizer" or f" {'mm' if units == 'mm' else 'm'}\n" in sliders_text + "\n"
    page.goto(path.as_uri() + "?controls=1")
    page.wait_for_function("() => window.scaraPendant")
    assert page.is_visible(".dg.main .close-button") and page.is_checked("#show-controls")
    assert page.errors == []


def test_the_pose_readout_names_the_real_tool_and_base_frames(tmp_path: Path) -> None:
    robot = load_robot("s1", tool="flange", base="base_link")
    text = export_html(robot, tmp_path / "p.html").read_text()
    assert '<h2 id="pose-title">flange in base_link</h2>' in text and "tool0 in" not in text
