"""A motion certified clear between its samples (scara_pin.cell.certify, issue 37 item 3).

Independent routes:

- the speed bound's columns: Pinocchio's own joint Jacobians (``getJointJacobian``) at random configurations, on
  the three shipped robots (the palletizer's mimic joints included), with a carried part;
- a collision planted between two samples: two spheres of 1 um radius (the carried one at tool0, the obstacle where
  tool0 is half-way between two 10 kHz samples), margin 0; their distance there is written in closed form from
  Pinocchio's FK (|p - c| - 2 r), and at the two samples around it too: clear at both, overlapping between;
- a foil 1 um thick: which side of its plane the carried sphere is on, by Pinocchio's FK at a dense grid (the
  sign must never change while it is within the foil's extent);
- the certificate is a lower bound: coal called here at 200 kHz around the closest approach of a planned motion.
"""

from __future__ import annotations

import math

import coal
import numpy as np
import pinocchio as pin
import pytest

from scara_pin import load_robot
from scara_pin.cell import Cell, Obstacle, Shape, scene
from scara_pin.cell.sweep import bounding_shapes, geometry_speeds
from scara_pin.cli import main
from scara_pin.motion.jump import jump_move
from scara_pin.motion.verify import DISTANCE_TOL, VERIFY_RATE, LimitViolation, verify

FROM = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])
TO = FROM + np.array([0.0, 0.305, 0.0, 0.0])
MICRON = 1e-6


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


@pytest.mark.parametrize("name", ["default", "s1", "palletizer"])
def test_the_speed_bound_is_built_from_pinocchios_jacobian_columns(name):
    robot = load_robot(name)
    carried = Shape("box", (0.04, 0.05, 0.03), np.array([0.0, 0.01, 0.02]), np.zeros(3))
    post = Obstacle("post", Shape("cylinder", (0.02, 0.6), np.array([0.3, -0.05, 0.0]), np.zeros(3)))
    sc = scene(robot, Cell((post,), 0.002, carried))
    rng = np.random.default_rng(11)
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    Q = lo + (hi - lo) * rng.random((6, robot.dof))
    dQ = rng.normal(size=(6, robot.dof))
    lin, rot = geometry_speeds(sc, Q, np.abs(dQ))
    b = bounding_shapes(sc)
    model, data = robot.model, robot.model.createData()
    for n in range(len(Q)):
        pin.computeJointJacobians(model, data, robot.to_pinocchio_q(Q[n]))
        for k in b.moving.tolist():
            j = int(b.joint[k])
            J = pin.getJointJacobian(model, data, j, pin.WORLD)
            c = data.oMi[j].act(b.center[k])
            v, w = J[:3, : robot.dof], J[3:, : robot.dof]
            assert lin[n, k] == pytest.approx(np.abs(dQ[n]) @ np.linalg.norm(v + np.cross(w.T, c).T, axis=0), abs=1e-12)
            assert rot[n, k] == pytest.approx(np.abs(dQ[n]) @ np.linalg.norm(w, axis=0), abs=1e-12)


BELOW = np.array([0.0, 0.0, 0.05])  # the tiny carried sphere, 50 mm under the flange (tool0's z points down)


def _point(robot, q):
    """Where the tiny carried sphere is at q (Pinocchio's FK of tool0)."""
    return robot.tool_placement(q).act(BELOW)


def _tiny_spheres_cell(robot, move, t_star):
    """A 1 um sphere carried under tool0 and one where it is at t_star; margin 0."""
    p = _point(robot, move.trajectory.sample(np.array([t_star]))[0][0])
    carried = Shape("sphere", (MICRON,), BELOW, np.zeros(3))
    return Cell((Obstacle("speck", Shape("sphere", (MICRON,), p.copy(), np.zeros(3))),), 0.0, carried), p


def test_a_collision_between_two_samples_is_caught(robot):
    move = jump_move(robot, FROM, TO)
    k = int(0.5 * move.duration * VERIFY_RATE)
    t_star = (k + 0.5) / VERIFY_RATE  # half-way between two samples of the verifier's grid
    cell, c = _tiny_spheres_cell(robot, move, t_star)
    # closed form from Pinocchio's FK: clear at the two samples around it, overlapping between (margin 0)
    for t in (k / VERIFY_RATE, (k + 1) / VERIFY_RATE):
        p = _point(robot, move.trajectory.sample(np.array([t]))[0][0])
        assert np.linalg.norm(p - c) - 2 * MICRON > 10 * MICRON
    found = verify(robot, move.trajectory, scene=scene(robot, cell))
    assert found.clearance.distance > 0.0  # no sample sees it
    with pytest.raises(LimitViolation, match=r"between the verified samples: carried - speck -0\.00[12]\d* mm apart"):
        found.check_clearance()
    t, _, low = found.clearance.certified.lowest
    assert k / VERIFY_RATE < t < (k + 1) / VERIFY_RATE and low <= -MICRON


def test_a_free_motion_is_certified_with_few_distances(robot):
    move = jump_move(robot, FROM, TO)
    post = Obstacle("post", Shape("cylinder", (0.01, 0.6), np.array([0.20, -0.25, 0.0]), np.zeros(3)))
    found = verify(robot, move.trajectory, scene=scene(robot, Cell((post,), 0.002)))
    cert = found.clearance.certified
    assert cert.certified and cert.bound >= 0.002 - DISTANCE_TOL and cert.evaluations < 2_000


def _foil_cell(margin=0.0):
    """A foil 1 um thick across the traverse of FROM -> TO at y = 0 (the plane y = 0, |x - 0.27| < 0.15, z from -0.2 to
    -0.1: under the flange's stroke, in the carried sphere's), and a carried sphere of 1 um radius 50 mm under tool0."""
    foil = Obstacle("foil", Shape("box", (0.3, MICRON, 0.1), np.array([0.27, 0.0, -0.15]), np.zeros(3)))
    carried = Shape("sphere", (MICRON,), BELOW, np.zeros(3))
    return Cell((foil,), margin, carried)


def test_a_straight_line_through_a_1um_foil_is_refused(tmp_path, capsys):
    cell = tmp_path / "foil.yaml"
    cell.write_text("margin: 0\nobstacles:\n  - {name: foil, shape: box, size: [0.3, 0.000001, 0.1], "
                    "xyz: [0.27, 0, -0.15]}\n"
                    "carried: {shape: sphere, radius: 0.000001, xyz: [0, 0, 0.05]}\n")  # fmt: skip
    rc = main(["traj", "--linear", "--from-pose", *map(str, FROM), "--to-pose", *map(str, TO), "--cell", str(cell)])
    err = capsys.readouterr().err
    assert rc == 3 and "carried - foil" in err and err.startswith("error: "), err


def test_a_jump_never_crosses_a_1um_foil(robot):
    """The carried sphere must pass over the foil (it reaches up to z = -0.1) or around it; it never crosses it."""
    cell = _foil_cell()
    try:
        move = jump_move(robot, FROM, TO, cell=cell)
    except Exception as exc:  # refused: the reason names the foil
        assert "foil" in str(exc)
        return
    t = np.linspace(0.0, move.duration, 200_001)
    q = move.trajectory.sample(t)[0]
    p = np.array([_point(robot, x) for x in q])  # 200,001 points: 2 us apart
    cross = np.flatnonzero(np.sign(p[:-1, 1]) != np.sign(p[1:, 1]))  # where it goes to the foil plane's other side
    assert len(cross)
    for i in cross:  # there it is above the foil (by at least its radius, less the tolerance) or beside it
        f = p[i, 1] / (p[i, 1] - p[i + 1, 1])
        x, z = p[i, 0] + f * (p[i + 1, 0] - p[i, 0]), p[i, 2] + f * (p[i + 1, 2] - p[i, 2])
        assert abs(x - 0.27) >= 0.15 + MICRON - DISTANCE_TOL or z >= -0.1 + MICRON - DISTANCE_TOL, (x, z)


def test_the_certificate_is_a_lower_bound_of_every_distance(robot):
    post = Obstacle("post", Shape("cylinder", (0.02, 0.6), np.array([0.306, -0.052, 0.0]), np.zeros(3)))
    cell = Cell((post,), 0.002)
    move = jump_move(robot, FROM, TO, cell=cell)
    cert = move.distance.certified
    assert cert.certified
    # coal called here on Pinocchio's collision model, at 200 kHz around the closest sample
    gm = pin.buildGeomFromUrdfString(robot.model, robot.urdf, pin.GeometryType.COLLISION)
    gd = gm.createData()
    post_g = coal.Cylinder(0.02, 0.6)
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    t0 = move.distance.time
    t = np.clip(np.linspace(t0 - 0.01, t0 + 0.01, 4_001), 0.0, move.duration)
    low = math.inf
    data = robot.model.createData()
    post_M = coal.Transform3s(np.eye(3), robot.data.oMf[robot.base_id].act(np.array([0.306, -0.052, 0.0])))
    for q in move.trajectory.sample(t)[0]:
        pin.updateGeometryPlacements(robot.model, data, gm, gd, q)
        for i, g in enumerate(gm.geometryObjects):
            if gm.geometryObjects[i].parentJoint == 0:
                continue
            M = gd.oMg[i]
            res.clear()
            low = min(low, coal.distance(g.geometry, coal.Transform3s(M.rotation, M.translation), post_g, post_M, req,
                                         res))  # fmt: skip
    assert cert.bound <= low + 1e-9 and low >= 0.002 - DISTANCE_TOL


def test_a_job_move_through_a_1um_foil_is_refused(tmp_path, capsys):
    from test_job import line_of, write_job

    robot = load_robot("default")
    # the straight line feeder (0.05, -0.30) -> T11 (0.22, -0.06) crosses y = -0.18 at x = 0.135: a foil there, 1 um
    # thick, from z = -0.2 to -0.1 (where the carried cube of 2 um, 50 mm under tool0, passes)
    (tmp_path / "cell.yaml").write_text("margin: 0\nobstacles:\n  - {name: foil, shape: box, size: [0.12, 0.000001, "
                                        "0.1], xyz: [0.135, -0.18, -0.15]}\n")  # fmt: skip
    body = ("cell: cell.yaml\ncarry: {shape: box, size: [0.000002, 0.000002, 0.000002], xyz: [0, 0, 0.05]}\n"
            "start: feeder\nsteps:\n"
            "  - pick: 0.01\n  - move: T11\n  - place: 0.01\n")  # fmt: skip
    job = write_job(tmp_path, body, robot)
    rc = main(["job", str(job)])
    err = capsys.readouterr().err.strip()
    assert rc == 3 and err.startswith(f"error: {job} line {line_of(job, 'move: T11')}: move feeder -> T11"), err
    assert "carried - foil" in err
