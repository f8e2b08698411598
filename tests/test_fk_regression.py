"""Forward kinematics and Jacobians of the Pinocchio model, checked against independent routes.

Every expected value is computed here, without Pinocchio and without scara_pin's kinematics:

- the standard D-H table of source S1 and the modified (Craig) D-H table of source S3, written as
  products of 4 x 4 matrices in this file (numpy only), generalised with the robot's parameters;
- yourdfpy's forward kinematics on the very same URDF text (a second URDF parser);
- central finite differences of the forward kinematics (for the Jacobians);
- closed forms (manipulability l1 l2 |sin q2|, the quill's pure vertical motion, the zero poses of S1/S4).

Tolerances (absolute): positions 1e-12 m, rotation matrices 1e-12 elementwise; finite-difference
Jacobians 1e-8 (h = 1e-6: truncation ~h^2 = 1e-12, round-off ~eps / h = 2e-10); quantities that are
exact by construction (a prismatic joint moving along z) 1e-15.

Each check runs on the ``default`` (S4) robot, the ``s1`` robot and a seeded random geometry that sets
every kinematic parameter (including a tool offset and a tool yaw), so that no term can hide behind a zero.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from scara_pin import Robot, load_robot

N_DH = 1000  # random configurations per robot for the D-H comparisons
N_URDF = 250  # random configurations per robot for the yourdfpy comparison
N_JAC = 200  # random configurations per robot for the Jacobian checks
H = 1e-6  # finite-difference step [rad] or [m]
TOL = 1e-12  # position [m] and rotation-matrix elementwise tolerance
TOL_FD = 1e-8  # finite-difference Jacobian tolerance
TOL_EXACT = 1e-15  # tolerance of quantities that are exact by construction

ROBOTS = ["default", "s1", "random"]


def random_geometry(seed: int) -> dict[str, float]:
    """Every kinematic parameter drawn at random (seeded), as overrides of the ``default`` robot."""
    rng = np.random.default_rng(seed)
    return {
        "base_height": float(rng.uniform(0.2, 0.6)),
        "d1": float(rng.uniform(-0.1, 0.3)),
        "l1": float(rng.uniform(0.1, 0.6)),
        "d2": float(rng.uniform(-0.1, 0.1)),
        "l2": float(rng.uniform(0.1, 0.6)),
        "d3": float(rng.uniform(-0.2, 0.1)),
        "tool_x": float(rng.uniform(-0.05, 0.05)),
        "tool_y": float(rng.uniform(-0.05, 0.05)),
        "tool_z": float(rng.uniform(-0.05, 0.05)),
        "tool_yaw": float(rng.uniform(-math.pi, math.pi)),
    }


RANDOM_GEOMETRY = random_geometry(seed=41)


@pytest.fixture(scope="module")
def robot_random() -> Robot:
    return load_robot("default", RANDOM_GEOMETRY)


@pytest.fixture(params=ROBOTS)
def robot(request: pytest.FixtureRequest) -> Robot:
    return request.getfixturevalue(f"robot_{request.param}")


def configurations(robot: Robot, n: int, seed: int) -> np.ndarray:
    """``n`` seeded random configurations within the limits, after the hard cases: zero, lower, upper."""
    lower = np.array(robot.limits.lower)
    upper = np.array(robot.limits.upper)
    rng = np.random.default_rng(seed)
    hard = np.vstack([np.clip(np.zeros(4), lower, upper), lower, upper])
    return np.vstack([hard, rng.uniform(lower, upper, size=(n, 4))])


# ---------------------------------------------------------------------------- elementary transforms
def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1]])


def trans(x: float, y: float, z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


def dh_standard(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Standard D-H link transform Rz(theta) Tz(d) Tx(a) Rx(alpha), in its textbook closed form."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_modified(alpha: float, a: float, d: float, theta: float) -> np.ndarray:
    """Modified (Craig) D-H link transform Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i), closed form."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [ct, -st, 0.0, a],
            [st * ca, ct * ca, -sa, -sa * d],
            [st * sa, ct * sa, ca, ca * d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def chain(rows: list[np.ndarray]) -> np.ndarray:
    T = np.eye(4)
    for A in rows:
        T = T @ A
    return T


# ---------------------------------------------------------------------------- the two D-H conventions
# S1 (standard D-H, (theta, d, a, alpha)), generalised with our parameters; frame 0 = `base`:
#   1: (q1,      d1,      l1, 0)
#   2: (q2,      d2,      l2, pi)    alpha2 = pi turns z2 DOWN (S1 has d2 = 0)
#   3: (0,       q3 - d3, 0,  0)     z2 points down: S1's q3 is ours (quill down), our d3 is measured up
#   4: (-q4,     0,       0,  0)     S1's q4 turns about the downward z3: q4_S1 = -q4_ours
# S1's frame 4 has z down, like tool0; our flange (z up) is frame4 * Rx(pi), and tool0 is the flange
# times T(tool_x, tool_y, tool_z) Rz(tool_yaw) Rx(pi) (URDF rpy = (pi, 0, tool_yaw)). For `s1` (no tool
# offset) the table is S1's own and tool0 IS frame 4 (checked separately below).
def s1_frame4(p: dict[str, float], q: np.ndarray) -> np.ndarray:
    return chain(
        [
            dh_standard(q[0], p["d1"], p["l1"], 0.0),
            dh_standard(q[1], p["d2"], p["l2"], math.pi),
            dh_standard(0.0, q[2] - p["d3"], 0.0, 0.0),
            dh_standard(-q[3], 0.0, 0.0, 0.0),
        ]
    )


def tool_from_flange(p: dict[str, float]) -> np.ndarray:
    return trans(p["tool_x"], p["tool_y"], p["tool_z"]) @ rot_z(p["tool_yaw"]) @ rot_x(math.pi)


def s1_tool0(p: dict[str, float], q: np.ndarray) -> np.ndarray:
    return s1_frame4(p, q) @ rot_x(math.pi) @ tool_from_flange(p)


# S3 (modified D-H, (alpha_{i-1}, a_{i-1}, d_i, theta_i)), exactly S3's table; frame 0 = `base`:
#   1: (0, 0,  0,     q1)
#   2: (0, l1, 0,     q2)
#   3: (0, l2, q3_S3, 0)      all z axes up: q3_S3 is the flange height above `base`,
#                              q3_S3 = (d1 + d2 + d3) - q3_ours
#   4: (0, 0,  0,     q4)     q4_S3 = q4_ours
# S3's frame 4 is upright and IS our flange; tool0 = frame4 * T(tool) Rz(tool_yaw) Rx(pi).
def s3_frame4(p: dict[str, float], q: np.ndarray) -> np.ndarray:
    q3_s3 = p["d1"] + p["d2"] + p["d3"] - q[2]
    return chain(
        [
            dh_modified(0.0, 0.0, 0.0, q[0]),
            dh_modified(0.0, p["l1"], 0.0, q[1]),
            dh_modified(0.0, p["l2"], q3_s3, 0.0),
            dh_modified(0.0, 0.0, 0.0, q[3]),
        ]
    )


def s3_tool0(p: dict[str, float], q: np.ndarray) -> np.ndarray:
    return s3_frame4(p, q) @ tool_from_flange(p)


def assert_transforms_close(actual: np.ndarray, expected: np.ndarray, qs: np.ndarray, what: str) -> None:
    """Compare stacks of 4 x 4 transforms: positions and rotation matrices at ``TOL``; name the worst q."""
    pos_err = np.abs(actual[:, :3, 3] - expected[:, :3, 3]).max(axis=1)
    rot_err = np.abs(actual[:, :3, :3] - expected[:, :3, :3]).max(axis=(1, 2))
    bottom = np.abs(actual[:, 3] - np.array([0, 0, 0, 1.0])).max()
    assert bottom == 0.0, f"{what}: not homogeneous transforms"
    for name, err in (("position [m]", pos_err), ("rotation", rot_err)):
        i = int(np.argmax(err))
        assert err[i] <= TOL, (
            f"{what}: {name} error {err[i]:.3e} > {TOL:g} at q = {qs[i].tolist()}\n"
            f"actual =\n{actual[i]}\nexpected =\n{expected[i]}"
        )


def pinocchio_tool0(robot: Robot, qs: np.ndarray) -> np.ndarray:
    return np.array([robot.tool_placement(q).homogeneous for q in qs])


# ---------------------------------------------------------------------------- FK vs D-H
@pytest.mark.parametrize("robot_name", ROBOTS)
def test_tool0_equals_standard_dh_product_s1(robot_name: str, request: pytest.FixtureRequest) -> None:
    robot: Robot = request.getfixturevalue(f"robot_{robot_name}")
    p = dict(robot.parameters.values)
    qs = configurations(robot, N_DH, seed=101)
    expected = np.array([s1_tool0(p, q) for q in qs])
    assert_transforms_close(pinocchio_tool0(robot, qs), expected, qs, f"{robot_name}: tool0 vs S1 standard D-H")


@pytest.mark.parametrize("robot_name", ROBOTS)
def test_tool0_equals_modified_dh_product_s3(robot_name: str, request: pytest.FixtureRequest) -> None:
    robot: Robot = request.getfixturevalue(f"robot_{robot_name}")
    p = dict(robot.parameters.values)
    qs = configurations(robot, N_DH, seed=102)
    expected = np.array([s3_tool0(p, q) for q in qs])
    assert_transforms_close(pinocchio_tool0(robot, qs), expected, qs, f"{robot_name}: tool0 vs S3 modified D-H")


def test_s1_robot_tool0_is_s1_dh_frame4_exactly_as_published(robot_s1: Robot) -> None:
    """The ``s1`` robot with S1's own table (d1 = 0.1, l1 = 0.05, l2 = 0.15, q4_S1 = -q4), no extra transform."""
    qs = configurations(robot_s1, 200, seed=103)
    expected = np.array(
        [
            chain(
                [
                    dh_standard(q[0], 0.100, 0.050, 0.0),
                    dh_standard(q[1], 0.0, 0.150, math.pi),
                    dh_standard(0.0, q[2], 0.0, 0.0),
                    dh_standard(-q[3], 0.0, 0.0, 0.0),
                ]
            )
            for q in qs
        ]
    )
    assert_transforms_close(pinocchio_tool0(robot_s1, qs), expected, qs, "s1: tool0 vs S1 frame 4")


def test_universe_placement_adds_the_base_height(robot: Robot) -> None:
    """Pinocchio's world is base_link: oMtool0 = Tz(base_height) * (the S3 chain from `base`)."""
    p = dict(robot.parameters.values)
    qs = configurations(robot, 100, seed=104)
    actual = np.array([robot.frame_placement(q, "tool0", relative_to="universe").homogeneous for q in qs])
    expected = np.array([trans(0, 0, p["base_height"]) @ s3_tool0(p, q) for q in qs])
    assert_transforms_close(actual, expected, qs, "oMtool0 vs Tz(base_height) * S3 chain")


def test_s1_closed_form_of_the_digest(robot_s1: Robot) -> None:
    """S1's corrected closed form: x = l1 c1 + l2 c12, y = l1 s1 + l2 s12, z = d1 - q3, yaw = q1 + q2 + q4."""
    qs = configurations(robot_s1, 200, seed=105)
    l1, l2, d1 = 0.050, 0.150, 0.100
    for q in qs:
        x, y, z, yaw = robot_s1.tool_pose(q)
        assert abs(x - (l1 * math.cos(q[0]) + l2 * math.cos(q[0] + q[1]))) <= TOL
        assert abs(y - (l1 * math.sin(q[0]) + l2 * math.sin(q[0] + q[1]))) <= TOL
        assert abs(z - (d1 - q[2])) <= TOL
        assert abs(math.remainder(yaw - (q[0] + q[1] + q[3]), 2 * math.pi)) <= TOL, q


# ---------------------------------------------------------------------------- FK vs yourdfpy
URDF_FRAMES = ("link1", "link2", "quill", "flange", "tool0")


def test_fk_equals_yourdfpy(robot: Robot) -> None:
    yourdfpy = pytest.importorskip("yourdfpy")
    # get_transform needs the scene graph; load_meshes=False keeps it cheap (no mesh files here anyway)
    urdf = yourdfpy.URDF.load(io.StringIO(robot.urdf), build_scene_graph=True, load_meshes=False)
    assert list(urdf.actuated_joint_names) == ["joint1", "joint2", "joint3", "joint4"]
    qs = configurations(robot, N_URDF, seed=106)
    for reference, relative_to in (("base", None), ("base_link", "universe")):
        for frame in URDF_FRAMES:
            actual, expected = [], []
            for q in qs:
                urdf.update_cfg({f"joint{i + 1}": float(v) for i, v in enumerate(q)})
                expected.append(urdf.get_transform(frame, reference))
                actual.append(robot.frame_placement(q, frame, relative_to=relative_to).homogeneous)
            assert_transforms_close(
                np.array(actual), np.array(expected), qs, f"{frame} in {reference}: Pinocchio vs yourdfpy"
            )


# ---------------------------------------------------------------------------- Jacobians
def wrap(angle: float) -> float:
    return math.remainder(angle, 2 * math.pi)


def fd_tool_pose(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Central differences of (x, y, z, yaw) w.r.t. q; the yaw difference is wrapped to (-pi, pi]."""
    J = np.empty((4, 4))
    for j in range(4):
        dq = np.zeros(4)
        dq[j] = H
        plus, minus = robot.tool_pose(q + dq), robot.tool_pose(q - dq)
        J[:3, j] = (plus[:3] - minus[:3]) / (2 * H)
        J[3, j] = wrap(plus[3] - minus[3]) / (2 * H)
    return J


def fd_world_twist(robot: Robot, q: np.ndarray, frame: str) -> np.ndarray:
    """Central differences of a frame's placement in the world: rows (dp/dq; omega from dR/dq R^T)."""
    J = np.empty((6, 4))
    R = robot.frame_placement(q, frame, relative_to="universe").rotation
    for j in range(4):
        dq = np.zeros(4)
        dq[j] = H
        plus = robot.frame_placement(q + dq, frame, relative_to="universe")
        minus = robot.frame_placement(q - dq, frame, relative_to="universe")
        J[:3, j] = (plus.translation - minus.translation) / (2 * H)
        W = (plus.rotation - minus.rotation) / (2 * H) @ R.T  # skew(omega) up to O(h^2)
        J[3:, j] = (W[2, 1], W[0, 2], W[1, 0])
    return J


def test_task_jacobian_equals_finite_differences_of_tool_pose(robot: Robot) -> None:
    qs = configurations(robot, N_JAC, seed=107)
    worst = 0.0
    for q in qs:
        err = np.abs(robot.task_jacobian(q) - fd_tool_pose(robot, q)).max()
        assert err <= TOL_FD, f"task Jacobian vs FD: error {err:.3e} at q = {q.tolist()}"
        worst = max(worst, err)
    assert worst > 0.0  # FD is never exact: a zero error would mean both sides are the same computation


@pytest.mark.parametrize("frame", ["tool0", "flange", "link2"])
def test_frame_jacobian_local_world_aligned_equals_finite_differences(robot: Robot, frame: str) -> None:
    qs = configurations(robot, N_JAC // 2, seed=108)
    for q in qs:
        J = robot.frame_jacobian(q, frame, reference="local_world_aligned")
        assert J.shape == (6, 4)
        err = np.abs(J - fd_world_twist(robot, q, frame)).max()
        assert err <= TOL_FD, f"{frame}: LOCAL_WORLD_ALIGNED Jacobian vs FD: error {err:.3e} at q = {q.tolist()}"


def test_angular_rows_and_yaw_row(robot: Robot) -> None:
    """All axes vertical: omega = (0, 0, q1' + q2' + q4'); the task Jacobian's yaw row is omega_z's row."""
    qs = configurations(robot, N_JAC, seed=109)
    for q in qs:
        J = robot.frame_jacobian(q)  # tool0, LOCAL_WORLD_ALIGNED
        np.testing.assert_allclose(J[3:], [[0, 0, 0, 0], [0, 0, 0, 0], [1, 1, 0, 1]], rtol=0, atol=TOL_EXACT)
        np.testing.assert_allclose(robot.task_jacobian(q)[3], J[5], rtol=0, atol=TOL_EXACT)


def test_manipulability_closed_form(robot: Robot) -> None:
    """|det J| = l1 l2 |sin q2| (a tool offset adds the same column to q1, q2 and q4: det unchanged)."""
    p = robot.parameters.values
    qs = configurations(robot, N_JAC, seed=110)
    for q in qs:
        expected = p["l1"] * p["l2"] * abs(math.sin(q[1]))
        assert abs(robot.manipulability(q) - expected) <= 1e-13, q
    assert robot.manipulability(np.array([0.3, 0.0, 0.01, -0.2])) <= 1e-15  # stretched arm: singular


# ---------------------------------------------------------------------------- the prismatic quill
def test_quill_moves_tool0_straight_down_by_q3(robot: Robot) -> None:
    lo, hi = robot.limits.lower[2], robot.limits.upper[2]
    qs = configurations(robot, N_DH, seed=111)
    q3b = np.random.default_rng(112).uniform(lo, hi, size=len(qs))
    for q, q3 in zip(qs, q3b):
        qb = q.copy()
        qb[2] = q3
        dq = q3 - q[2]
        a, b = robot.tool_placement(q), robot.tool_placement(qb)
        dp = b.translation - a.translation
        assert abs(dp[0]) <= TOL and abs(dp[1]) <= TOL, (q.tolist(), dq, dp)
        assert abs(dp[2] - (-dq)) <= TOL, (q.tolist(), dq, dp)
        assert np.abs(b.rotation - a.rotation).max() <= TOL_EXACT, (q.tolist(), dq)


def test_quill_column_of_task_jacobian(robot: Robot) -> None:
    for q in configurations(robot, N_JAC, seed=113):
        np.testing.assert_allclose(robot.task_jacobian(q)[:, 2], [0, 0, -1, 0], rtol=0, atol=TOL_EXACT)


# ---------------------------------------------------------------------------- zero poses from the sources
def test_zero_pose_default_is_s4(robot_default: Robot) -> None:
    """S4: arms 200 + 200 mm, tool origin 50 mm below the reference plane: (400, 0, -50 mm, 0)."""
    np.testing.assert_allclose(robot_default.tool_pose(np.zeros(4)), [0.400, 0.0, -0.050, 0.0], rtol=0, atol=TOL)
    R = robot_default.tool_placement(np.zeros(4)).rotation
    np.testing.assert_allclose(R, np.diag([1.0, -1.0, -1.0]), rtol=0, atol=TOL)  # tool0's z points down


def test_zero_pose_s1(robot_s1: Robot) -> None:
    """S1 at q = 0: x = l1 + l2 = 0.2 m, y = 0, z = d1 = 0.1 m, yaw 0, tool z down (alpha2 = pi)."""
    np.testing.assert_allclose(robot_s1.tool_pose(np.zeros(4)), [0.2, 0.0, 0.1, 0.0], rtol=0, atol=TOL)
    R = robot_s1.tool_placement(np.zeros(4)).rotation
    np.testing.assert_allclose(R, np.diag([1.0, -1.0, -1.0]), rtol=0, atol=TOL)
