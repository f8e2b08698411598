"""The jump in a cell's warm starts and rows (scara_pin.motion.jump.candidates, .rows) where a palletizing job
needs them, and the palletizer's wrist housing, whose collision shape must leave room for the part under the flange.

Independent routes:

- the rows the verifier's grid needs: a flange passing a post so that the distance dips below the margin only
  between two of the dense check's points, the distance written in closed form here (the default robot's planar
  FK, l1 = l2 = 0.2 m; flange radius 25 mm and a vertical post: centre distance minus the radii);
- OVER for a robot that lifts by turning: the raised traverse's height from the FK of its waypoints, against the
  wall's top written here;
- the wrist housing: coal's distance from the wrist's collision cylinder to a box hung 1 mm under the flange face
  equals the flange's thickness plus 1 mm (urdf/config/palletizer: 40 mm), the housing ending on the flange.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from scara_pin import load_robot
from scara_pin.cell import Cell, Obstacle, Shape, scene
from scara_pin.motion.jump.candidates import candidates
from scara_pin.motion.jump.rows import CHECK_POINTS, CONVERGED, Rows
from scara_pin.motion.polynomial import PolynomialPiece

MARGIN = 0.002
FLANGE, POST = 0.025, 0.01  # [m] the default robot's flange radius (its URDF), the post's


def planar(q: np.ndarray) -> np.ndarray:
    """The default robot's tool in plan view (base frame): l1 = l2 = 0.2 m."""
    a, b = q[..., 0], q[..., 0] + q[..., 1]
    return np.stack([0.2 * np.cos(a) + 0.2 * np.cos(b), 0.2 * np.sin(a) + 0.2 * np.sin(b)], -1)


def test_a_dip_between_the_checked_points_gets_a_row_where_the_certificate_finds_it() -> None:
    robot = load_robot("default")
    q0, q1 = np.array([-0.7, 1.6, 0.05, 0.0]), np.array([0.9, 1.2, 0.05, 0.0])  # tool at z = -0.10 m throughout
    star = 0.5 + 0.5 / CHECK_POINTS  # halfway between two checked points
    p = planar(q0 + star * (q1 - q0))
    tangent = planar(q0 + (star + 1e-6) * (q1 - q0)) - planar(q0 + (star - 1e-6) * (q1 - q0))
    normal = np.array([-tangent[1], tangent[0]]) / np.linalg.norm(tangent)
    centre = p + normal * (FLANGE + POST + MARGIN - 0.0005)  # 0.5 mm inside the margin at its closest
    post = Obstacle("post", Shape("cylinder", (POST, 0.025), np.array([*centre, -0.1075]), np.zeros(3)))
    s = np.linspace(0.0, 1.0, 100_001)
    d = np.linalg.norm(planar(q0 + s[:, None] * (q1 - q0)) - centre, axis=1) - FLANGE - POST  # closed form
    coarse = np.arange(CHECK_POINTS) / CHECK_POINTS
    d_coarse = np.linalg.norm(planar(q0 + coarse[:, None] * (q1 - q0)) - centre, axis=1) - FLANGE - POST
    # the dip hides between the checked points, which come within 5 mm of the margin (FINE_WITHIN)
    assert d.min() < MARGIN - 0.0004 and MARGIN < d_coarse.min() < MARGIN + 0.005
    piece = PolynomialPiece(np.array([0.0, 1.0]), np.stack([q0, q1 - q0])[None])
    rows = Rows(scene(robot, Cell((post,), MARGIN)), None)
    _, worst = rows.check(piece)
    assert worst >= -CONVERGED  # the dense check sees nothing
    accel = 2.0 * np.array(robot.limits.acceleration)  # a bound of |qdd| (this piece's is 0)
    found = rows.fine(piece, accel)
    assert len(found) == 1
    row = found[0]
    assert rows.scene.pairs[row.pair].label == "flange - post"
    assert abs(row.sigma - s[np.argmin(d)]) <= 1e-4  # at the dip (within 10 kHz over 1 s of the closed form's minimum)
    assert rows.fine(piece, accel) == found  # asked again: the same row (not yet added)
    rows.add(found)
    assert rows.fine(piece, accel) == []  # added once


def test_a_robot_that_lifts_by_turning_gets_its_traverse_raised_over_a_wall() -> None:
    robot = load_robot("palletizer")
    A, B = np.array([0.0, 1.75, 0.48, 0.0]), np.array([1.85, 0.0, 0.324, 0.0])
    wall_top = 0.65
    wall = Obstacle("wall", Shape("box", (0.2, 3.0, wall_top), np.array([1.1, 1.1, wall_top / 2]),
                                  np.array([0.0, 0.0, np.pi / 4])))  # fmt: skip  # along x + y = 2.2: across the way
    sc = scene(robot, Cell((wall,), MARGIN))
    mid = (np.asarray(robot.limits.lower) + np.asarray(robot.limits.upper)) / 2
    qA, qB = robot.ik_nearest(A, mid), robot.ik_nearest(B, mid)
    z_top = max(A[2], B[2]) + 0.025
    tops = (robot.ik_nearest(np.array([*A[:2], z_top, A[3]]), qA),
            robot.ik_nearest(np.array([*B[:2], z_top, B[3]]), qB))
    lim = robot.limits
    found = candidates(sc, qA, qB, tops, A, B, z_top, None, np.array(lim.velocity), np.array(lim.acceleration))
    over = [c for c in found if c.way == "over"]
    assert over and over[0].clearance >= 0.0, [(c.way, c.clearance) for c in found]
    z = [robot.tool_pose(w)[2] for w in over[0].waypoints[1:-1]]
    assert min(z) > wall_top  # the tool is the arm's lowest point: raised above the wall
    assert min(z) < wall_top + 0.5  # raised step by step, not to the top of the reach


def test_the_palletizer_s_wrist_housing_ends_on_the_flange() -> None:
    robot = load_robot("palletizer")
    model = robot.model
    gm = pin.buildGeomFromUrdfString(model, robot.urdf, pin.GeometryType.COLLISION)
    data, gd = model.createData(), gm.createData()
    q = np.array([0.3, 0.5, 1.4, -0.7])
    pin.updateGeometryPlacements(model, data, gm, gd, q)
    pin.updateFramePlacement(model, data, robot.tool_id)
    hung = data.oMf[robot.tool_id] * pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.001 + 0.075]))  # tool0's z is down
    box = coal.Box(0.2, 0.3, 0.15)
    request = coal.DistanceRequest()
    request.gjk_tolerance = request.epa_tolerance = 1e-10
    found = {}
    for i, o in enumerate(gm.geometryObjects):
        found[o.name.rsplit("_", 1)[0]] = coal.distance(o.geometry, coal.Transform3s(gd.oMg[i].rotation,
                                                        gd.oMg[i].translation), box,
                                                        coal.Transform3s(hung.rotation, hung.translation), request,
                                                        coal.DistanceResult())  # fmt: skip
    assert found["flange"] == pytest.approx(0.001, abs=1e-9)
    assert found["wrist"] == pytest.approx(0.040 + 0.001, abs=1e-9)  # it reached 37.5 mm below the flange face
