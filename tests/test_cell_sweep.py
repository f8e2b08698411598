"""scara_pin.cell.sweep: many configurations at once, and the first contact along a path.

Second routes: coal's capsule distances for the segment distance; Pinocchio's forwardKinematics for the
vectorised joint placements; the scene's exact distances of every pair for the broad phase; closed forms of the
default robot's flange (a vertical cylinder, radius 0.025 m, from the tool point up 0.01 m) for the contacts.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import scara_pin as sp
from scara_pin.cell import Cell, InCollisionError, Obstacle, Shape, scene
from scara_pin.cell.sweep import (
    CONTACT_TOL,
    clear_mask,
    first_contact,
    joint_placements,
    pair_masks,
    segment_distance,
)
from scara_pin.motion.paths import JointLine

FLANGE_R = 0.025
MARGIN = 0.002


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def test_segment_distance_is_coals_capsule_distance() -> None:
    import coal

    rng = np.random.default_rng(7)
    n = 300
    a0, a1, b0, b1 = (rng.uniform(-1, 1, (n, 3)) for _ in range(4))
    a1[:30] = a0[:30]  # points
    b1[20:50] = b0[20:50]
    b1[60:90] = b0[60:90] + 0.7 * (a1[60:90] - a0[60:90])  # parallel segments
    ours = segment_distance(a0, a1, b0, b1)
    r = 1e-3  # capsules (or spheres, for points) of that radius about the segments

    def shape(p0, p1):
        d = p1 - p0
        length = float(np.linalg.norm(d))
        if length == 0.0:
            return coal.Sphere(r), coal.Transform3s(np.eye(3), p0)
        z = d / length
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
        x /= np.linalg.norm(x)
        R = np.column_stack([x, np.cross(z, x), z])
        return coal.Capsule(r, length), coal.Transform3s(R, 0.5 * (p0 + p1))

    for k in range(n):
        req, res = coal.DistanceRequest(), coal.DistanceResult()
        req.gjk_tolerance = 1e-12
        ga, ta = shape(a0[k], a1[k])
        gb, tb = shape(b0[k], b1[k])
        reference = coal.distance(ga, ta, gb, tb, req, res) + 2 * r
        assert ours[k] == pytest.approx(reference, abs=1e-9), k


@pytest.mark.parametrize("name", ["default", "s1", "palletizer"])
def test_joint_placements_are_pinocchios(name) -> None:
    robot = sp.load_robot(name)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = lo + (hi - lo) * np.random.default_rng(3).random((40, robot.dof))
    R, p = joint_placements(robot, Q)
    data = robot.model.createData()
    for i, q in enumerate(Q):
        pin.forwardKinematics(robot.model, data, robot.to_pinocchio_q(q))
        for j in range(robot.model.njoints):
            np.testing.assert_allclose(R[i, j], data.oMi[j].rotation, rtol=0, atol=1e-14)
            np.testing.assert_allclose(p[i, j], data.oMi[j].translation, rtol=0, atol=1e-14)


def busy_cell() -> Cell:
    import trimesh

    tetra = trimesh.creation.icosphere(subdivisions=1, radius=0.04)
    obstacles = (
        Obstacle("post", Shape("cylinder", (0.02, 0.3), np.array([0.25, -0.1, -0.1]), np.zeros(3))),
        Obstacle("tray", Shape("box", (0.1, 0.15, 0.05), np.array([-0.2, 0.1, -0.12]), np.array([0.1, 0.0, 0.4]))),
        Obstacle("ball", Shape("sphere", (0.03,), np.array([0.1, 0.3, -0.1]), np.zeros(3))),
        Obstacle("rock", Shape("mesh", (), np.array([-0.15, -0.25, -0.08]), np.zeros(3),
                               np.asarray(tetra.vertices), np.asarray(tetra.faces))),  # fmt: skip
    )
    carried = Shape("box", (0.06, 0.03, 0.03), np.array([0.0, 0.0, 0.015]), np.zeros(3))
    return Cell(obstacles, MARGIN, carried=carried)


def test_clear_mask_agrees_with_every_pairs_exact_distance(robot) -> None:
    cell = busy_cell()
    sc = scene(robot, cell)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = lo + (hi - lo) * np.random.default_rng(11).random((1500, 4))
    exact = sc.distance_array(Q).min(axis=1) >= MARGIN
    ours = clear_mask(sc, Q)
    assert 0.2 < exact.mean() < 0.9  # both kinds are there
    np.testing.assert_array_equal(ours, exact)


@pytest.mark.parametrize("margin", [0.0, 0.002, 0.03])
def test_pair_masks_close_each_row_at_its_first_pair_closer_than_the_margin(robot, margin) -> None:
    """The prefilters (spheres, capsules, boxes grown by the margin, a rotated tray among them) never clear a pair
    coal finds closer than the margin; each row is closed at the first such pair; the bound is below coal's distance
    (at most 0 where the shapes overlap: coal's depth there is no distance the capsules bound)."""
    sc = scene(robot, busy_cell())
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = lo + (hi - lo) * np.random.default_rng(12).random((800, 4))
    exact = sc.distance_array(Q)
    masks, bound = pair_masks(sc, Q, margin=margin)
    closer = exact < margin
    first = np.where(closer.any(axis=1), closer.argmax(axis=1), -1)
    expected = np.ones_like(masks)
    rows = np.flatnonzero(first >= 0)
    expected[rows, first[rows]] = False
    assert 0 < len(rows) < len(Q)
    np.testing.assert_array_equal(masks, expected)
    assert np.all(np.where(exact >= 0.0, bound <= exact + 1e-9, bound <= 1e-9))


def test_first_contact_of_a_turning_arm_with_a_sphere_is_the_closed_forms(robot) -> None:
    """J1 turns alone: the tool point circles the J1 axis at radius rho; a sphere at the flange's mid-height is
    first at the margin where |tool - centre| = rf + rs + margin (law of cosines)."""
    q0 = np.array([-0.5, 1.2, 0.05, 0.0])  # tool at z = -0.1: the flange's mid-plane -0.095
    tool0 = robot.tool_pose(q0)[:2]
    rho = float(np.linalg.norm(tool0))
    rs, D, phi = 0.02, 0.3, 0.4
    centre = np.array([D * math.cos(phi), D * math.sin(phi), -0.095])
    cell = Cell((Obstacle("ball", Shape("sphere", (rs,), centre, np.zeros(3))),), MARGIN)
    sc = scene(robot, cell)
    q1 = q0 + np.array([1.2, 0.0, 0.0, 0.0])
    found = first_contact(sc, JointLine(q0, q1))
    assert found is not None and (found.closest.pair.a, found.closest.pair.b) == ("flange", "ball")
    R = FLANGE_R + rs + MARGIN
    delta = math.acos((rho**2 + D**2 - R**2) / (2 * rho * D))
    theta = phi - delta  # the tool's polar angle at the stop, approaching from below
    theta0 = math.atan2(tool0[1], tool0[0])
    s_expected = (theta - theta0) / 1.2
    tool = robot.tool_pose(found.q)[:2]
    # the gap grows along the way back at |d gap / ds| = 1.2 rho D sin(delta) / R per unit s
    assert np.linalg.norm(tool - rho * np.array([math.cos(theta), math.sin(theta)])) < 2e-9
    assert found.s == pytest.approx(s_expected, abs=2e-9)
    assert 0.0 <= found.closest.distance - MARGIN <= CONTACT_TOL
    assert found.stop_text == "ball (flange)"


def test_first_contact_finds_a_thin_plate_that_sampling_would_miss(robot) -> None:
    """A plate 0.2 mm thick across the tool's circle: sampled every 2 mm the flange would jump it whole."""
    q0 = np.array([-0.5, 1.2, 0.05, 0.0])
    rho = float(np.linalg.norm(robot.tool_pose(q0)[:2]))
    theta0 = math.atan2(*robot.tool_pose(q0)[1::-1])
    at = theta0 + 0.5  # the plate: radial, at this polar angle, 0.2 mm thick, 0.2 m long (plan), at the flange's height
    plate = Shape("box", (0.2, 0.0002, 0.05), np.array([rho * math.cos(at), rho * math.sin(at), -0.1]),
                  np.array([0.0, 0.0, at]))  # fmt: skip
    sc = scene(robot, Cell((Obstacle("plate", plate),), MARGIN))
    found = first_contact(sc, JointLine(q0, q0 + np.array([1.0, 0.0, 0.0, 0.0])))
    assert found is not None and found.closest.pair.b == "plate"
    # the flange's disc touches the plate's face (half-thickness 0.1 mm) where the tool's distance to the plate's
    # mid-plane, rho sin(at - theta), is rf + 0.0001 + margin
    theta = at - math.asin((FLANGE_R + 0.0001 + MARGIN) / rho)
    rate = rho * math.cos(at - theta)  # d gap / ds there: the stop is before it by at most CONTACT_TOL / rate
    assert theta - theta0 - CONTACT_TOL / rate - 1e-12 <= found.s <= theta - theta0 + 1e-12


def test_first_contact_from_a_collision_and_without_one(robot) -> None:
    q0 = np.array([-0.5, 1.2, 0.05, 0.0])
    tool = robot.tool_pose(q0)
    inside = Cell((Obstacle("ball", Shape("sphere", (0.02,), np.array([tool[0], tool[1], -0.095]), np.zeros(3))),))
    with pytest.raises(InCollisionError, match="flange is .* deep in ball"):
        first_contact(scene(robot, inside), JointLine(q0, q0 + 0.1))
    far = Cell((Obstacle("ball", Shape("sphere", (0.02,), np.array([-0.3, -0.3, -0.3]), np.zeros(3))),))
    assert first_contact(scene(robot, far), JointLine(q0, q0 + np.array([0.5, 0.0, 0.0, 0.0]))) is None


def test_first_contact_follows_a_pair_that_starts_at_the_margin(robot, monkeypatch) -> None:
    """A jog that stopped at a post then moves along it: the flange starts 0.5 nm above the margin (the plan
    distance of the axes, written here) and J3 lowers it beside the vertical post, where its distance does not
    change, onto a floor box: the stop is where the flange's bottom (the tool point) is the margin above the box's
    top. Conservative advancement alone steps by gap / speed there (1e-9 m at a time: it gave up after 200,000
    steps); J4 turning the flange (a disc about its own axis) beside the post is no contact at all."""
    rp, post = 0.02, np.array([0.35, -0.1])
    floor_top = -0.13
    cell = Cell((Obstacle("post", Shape("cylinder", (rp, 0.23), np.array([*post, -0.185]), np.zeros(3))),
                 Obstacle("floor", Shape("box", (0.1, 0.1, 0.05), np.array([0.28, -0.1, floor_top - 0.025]),
                                         np.zeros(3)))), MARGIN)  # fmt: skip
    sc = scene(robot, cell)
    x = post[0] - (rp + FLANGE_R + MARGIN) - 0.5e-9
    q0 = robot.ik(np.array([x, post[1], -0.1, 0.0])).nearest(np.zeros(4)).q
    data = robot.model.createData()

    def tool(q: np.ndarray) -> np.ndarray:  # the tool point in the base frame, from Pinocchio's frames
        pin.framesForwardKinematics(robot.model, data, q)
        frame = robot.model.getFrameId
        return data.oMf[frame(robot.base_frame)].actInv(data.oMf[frame(robot.tool_frame)]).translation.copy()

    assert abs(np.linalg.norm(tool(q0)[:2] - post) - (rp + FLANGE_R + MARGIN + 0.5e-9)) < 1e-12
    calls = []  # configurations whose distances are asked for
    real = type(sc).distance_array
    monkeypatch.setattr(type(sc), "distance_array",
                        lambda self, Q, *a, **k: calls.append(len(np.atleast_2d(Q))) or real(self, Q, *a, **k))
    assert first_contact(sc, JointLine(q0, q0 + np.array([0.0, 0.0, 0.0, 3.0]))) is None  # J4: 3 rad
    assert first_contact(sc, JointLine(q0, q0 + np.array([0.0, 0.0, -0.01, 0.0]))) is None  # J3 up 10 mm
    found = first_contact(sc, JointLine(q0, q0 + np.array([0.0, 0.0, 0.045, 0.0])))  # J3 down 45 mm
    # the floor stops it (the flange and the quill, coaxial, reach the tool point both), not the post it slid along
    assert found is not None and found.closest.pair.b == "floor" and found.closest.pair.a in ("flange", "quill")
    z = tool(found.q)[2]
    assert floor_top + MARGIN <= z <= floor_top + MARGIN + CONTACT_TOL + 1e-12
    assert found.s * 0.045 == pytest.approx(-0.1 - (floor_top + MARGIN), abs=CONTACT_TOL + 1e-12)
    # samples 40 um of motion apart (SLIDE_STEP) for the 3 rad turn and the 45 mm slide: about 4,000 queries, where
    # conservative advancement alone gave up after 200,000 steps
    assert sum(calls) < 6000, sum(calls)
