"""URDF ``continuous`` joints (Pinocchio: nq = 2, (cos q, sin q), nv = 1) behind a 4-value q.

Fixture: tests/data/third_party/irb920_continuous.urdf, an ABB IRB 920-like SCARA: lift (prismatic, first),
shoulder (continuous), elbow (revolute), wrist (continuous). Independent routes for expected values:

- the plan-view closed form of that file, written here from its numbers (``irb920_fk``);
- its revolute twin: the same text with ``type="revolute"`` and wide limits (nq = 4, no conversion);
- central finite differences of FK for the Jacobian;
- the sampled configuration (continuous angles drawn over +/-3 pi, wrapped into [-pi, pi] here) for IK.

Convention under test: a continuous joint has no position limit (any finite q in FK, never reported as
outside its limits); ``limits.lower/upper`` are -pi/pi for it, the one-turn range IK solutions come in.
Tolerances: FK 1e-12 [m, rad]; Jacobian vs twin 1e-12, vs finite differences (h = 1e-6) 1e-8;
FK(IK(p)) = p and joint values 1e-9 (1e-7 for the joints within |sin(elbow)| < 1e-6 of a singularity).
Randomness is seeded.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import scara_pin
from scara_pin import ParameterError, Robot, UrdfError, robot_from_urdf
from scara_pin.cli import main
from scara_pin.kinematics.numeric import solve_numeric

PATH = Path(__file__).parent / "data" / "third_party" / "irb920_continuous.urdf"
FK_TOL = 1e-12
FD_TOL = 1e-8
IK_TOL = 1e-9
N_FK = 500
TWO_PI = 2.0 * math.pi
ELBOW = math.radians(145.0)  # the elbow's limits in the file: +/-2.530727415391778


def wrap(a: float) -> float:
    """a wrapped into [-pi, pi]."""
    return math.remainder(a, TWO_PI)


def irb920_fk(q: np.ndarray) -> np.ndarray:
    """(x, y, z, yaw) of tool0 in base_link, from the file's numbers: q = (lift, shoulder, elbow, wrist).

    z = 0.2 + lift + 0.05 - 0.03 - 0.1; plan view l1 = 0.3917, l2 = 0.2585, tool (0, 0.05) in the flange;
    tool0 is the flange turned by pi about x, so its x axis heads at a = shoulder + elbow + wrist.
    """
    lift, q1, q2, q3 = (float(v) for v in q)
    a = q1 + q2 + q3
    x = 0.3917 * math.cos(q1) + 0.2585 * math.cos(q1 + q2) - 0.05 * math.sin(a)
    y = 0.3917 * math.sin(q1) + 0.2585 * math.sin(q1 + q2) + 0.05 * math.cos(a)
    return np.array([x, y, 0.2 + lift + 0.05 - 0.03 - 0.1, wrap(a)])


def pose_diff(a: np.ndarray, b: np.ndarray) -> float:
    e = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    e[3] = wrap(e[3])
    return float(np.abs(e).max())


@pytest.fixture(scope="module")
def robot() -> Robot:
    return scara_pin.load_robot(urdf=PATH)


@pytest.fixture(scope="module")
def twin() -> Robot:
    """The same robot with revolute joints (limits +/-100 rad, so that nothing is clipped anywhere)."""
    text = PATH.read_text(encoding="utf-8").replace('type="continuous"', 'type="revolute"')
    text = re.sub(r'lower="-?[0-9.]+" upper="[0-9.]+" velocity="0" effort="(50|5)"',
                  r'lower="-100" upper="100" velocity="0" effort="\1"', text)  # fmt: skip
    assert text.count('lower="-100"') == 2 and 'type="continuous"' not in text
    out = robot_from_urdf(text, origin="twin")
    assert out.model.nq == 4 and not out.has_continuous
    return out


def sample_qs(n: int, seed: int, turns: float = 3.0) -> np.ndarray:
    """Seeded q: lift and elbow inside their limits, the continuous joints over +/- turns * pi."""
    rng = np.random.default_rng(seed)
    span = turns * math.pi
    return np.column_stack([rng.uniform(0.0, 0.145, n), rng.uniform(-span, span, n),
                            rng.uniform(-ELBOW, ELBOW, n), rng.uniform(-span, span, n)])  # fmt: skip


# ============================================================================== model and conventions
def test_loads_with_a_four_value_q(robot: Robot) -> None:
    assert robot.model.nq == 6 and robot.model.nv == 4
    assert robot.continuous == (False, True, False, True) and robot.has_continuous
    assert [robot.model.names[j] for j in range(1, 5)] == ["lift", "shoulder", "elbow", "wrist"]
    lim = robot.limits
    assert lim.lower == (0.0, -math.pi, -2.530727415391778, -math.pi)
    assert lim.upper == (0.145, math.pi, 2.530727415391778, math.pi)
    # velocity and effort: the <limit> tags as written (velocity 0 everywhere, efforts 200/50/30/5)
    assert lim.velocity == (0.0, 0.0, 0.0, 0.0) and lim.effort == (200.0, 50.0, 30.0, 5.0)


def test_conversion_to_and_from_pinocchio_q(robot: Robot) -> None:
    q = np.array([0.1, 4.0, -0.5, -7.0])
    qp = robot.to_pinocchio_q(q)
    expected = [0.1, math.cos(4.0), math.sin(4.0), -0.5, math.cos(-7.0), math.sin(-7.0)]
    assert qp.shape == (6,) and np.abs(qp - expected).max() <= 1e-15
    back = robot.from_pinocchio_q(qp)
    assert np.abs(back - [0.1, wrap(4.0), -0.5, wrap(-7.0)]).max() <= 1e-15
    assert -math.pi <= back[1] <= math.pi and -math.pi <= back[3] <= math.pi
    # Pinocchio's neutral configuration is q = 0
    assert np.array_equal(robot.from_pinocchio_q(pin.neutral(robot.model)), np.zeros(4))


@pytest.mark.parametrize("bad", [[0.0, math.nan, 0.0, 0.0], [0.0, 0.0, math.inf, 0.0], [0.0] * 3, [0.0] * 6, "abcd"])
def test_bad_q_is_refused_with_a_typed_error(robot: Robot, bad: object) -> None:
    for method in (robot.tool_placement, robot.tool_pose, robot.task_jacobian, robot.frame_jacobian,
                   robot.manipulability, robot.to_pinocchio_q):  # fmt: skip
        with pytest.raises(ParameterError):
            method(bad)
    with pytest.raises(ParameterError):
        robot.tool_placement(np.array(bad, dtype=float) if not isinstance(bad, str) else bad)


@pytest.mark.parametrize("bad", [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0, 1.0, math.nan], "x"])
def test_bad_pinocchio_q_is_refused(robot: Robot, bad: object) -> None:
    with pytest.raises(ParameterError):
        robot.from_pinocchio_q(bad)


def test_continuous_joints_have_no_position_limit(robot: Robot) -> None:
    assert robot.outside_limits(np.array([0.1, 10.0, 0.0, -20.0])) == []
    (item,) = robot.outside_limits(np.array([0.2, 10.0, 0.0, -20.0]))
    assert item.startswith("lift = 0.2 outside")  # the URDF name of q1: the lift still has its limits


def test_other_joint_kinds_are_still_refused() -> None:
    # a planar joint (nq = 4, nv = 3) is not a single-DOF joint
    text = PATH.read_text(encoding="utf-8").replace('name="elbow" type="revolute"', 'name="elbow" type="planar"')
    with pytest.raises(UrdfError, match="4 single-DOF joints"):
        robot_from_urdf(text, origin="planar.urdf")


# ============================================================================== forward kinematics
def test_fk_equals_the_closed_form_and_the_revolute_twin(robot: Robot, twin: Robot) -> None:
    qs = sample_qs(N_FK, seed=1)
    assert (np.abs(qs[:, [1, 3]]) > math.pi).any(axis=1).sum() > N_FK / 2  # many angles beyond pi
    for q in qs:
        assert pose_diff(robot.tool_pose(q), irb920_fk(q)) <= FK_TOL, q
        M, Mt = robot.tool_placement(q).homogeneous, twin.tool_placement(q).homogeneous
        assert np.abs(M - Mt).max() <= FK_TOL, q
        for frame in ("arm1", "arm2", "flange"):
            F, Ft = robot.frame_placement(q, frame).homogeneous, twin.frame_placement(q, frame).homogeneous
            assert np.abs(F - Ft).max() <= FK_TOL, (q, frame)


def test_fk_accepts_lists_and_any_finite_angle(robot: Robot) -> None:
    q = [0.05, 1000.0, 0.3, -12345.0]
    assert pose_diff(robot.tool_pose(q), irb920_fk(np.array(q))) <= 1e-9  # cos/sin of 1e4 rad: ~1e-12 each


# ============================================================================== Jacobians
def test_jacobians_equal_the_twin(robot: Robot, twin: Robot) -> None:
    for q in sample_qs(100, seed=2):
        assert np.abs(robot.task_jacobian(q) - twin.task_jacobian(q)).max() <= FK_TOL
        for ref in ("world", "local", "local_world_aligned"):
            J = robot.frame_jacobian(q, "arm2", ref)
            assert J.shape == (6, 4) and np.abs(J - twin.frame_jacobian(q, "arm2", ref)).max() <= FK_TOL
        assert robot.manipulability(q) == pytest.approx(twin.manipulability(q), abs=1e-12)


def test_task_jacobian_equals_finite_differences(robot: Robot) -> None:
    h = 1e-6
    for q in sample_qs(100, seed=3):
        J = robot.task_jacobian(q)
        fd = np.empty((4, 4))
        for j in range(4):
            dq = np.zeros(4)
            dq[j] = h
            d = irb920_fk(q + dq) - irb920_fk(q - dq)
            d[3] = wrap(d[3])
            fd[:, j] = d / (2 * h)
        assert np.abs(J - fd).max() <= FD_TOL, q


def test_trajectory_kinematics_convert_q(robot: Robot, twin: Robot) -> None:
    from scara_pin.motion.paths import _Kinematics

    k, kt = _Kinematics(robot), _Kinematics(twin)
    rng = np.random.default_rng(4)
    for q in sample_qs(30, seed=4):
        v = rng.uniform(-1, 1, 4)
        assert np.abs(k.jacobian(q) - kt.jacobian(q)).max() <= FK_TOL
        assert np.abs(k.jacobian_rate(q, v) - kt.jacobian_rate(q, v)).max() <= FK_TOL


# ============================================================================== inverse kinematics
def test_geometry_uses_the_one_turn_range(robot: Robot) -> None:
    geo = robot.kinematics.geometry
    assert geo.revolute == (1, 2, 3) and geo.prismatic == 0
    # continuous joints have no limits: every turn is theirs (the nearest to the reference is chosen)
    assert geo.lower == (0.0, -math.inf, -2.530727415391778, -math.inf)
    assert geo.upper == (0.145, math.inf, 2.530727415391778, math.inf)
    assert geo.continuous == (False, True, False, True)
    assert geo.l1 == pytest.approx(0.3917, abs=1e-15) and geo.l2 == pytest.approx(0.2585, abs=1e-15)
    r_min, r_max = geo.radius_range()
    gamma = 2.530727415391778  # the elbow's limit: the most folded arm
    assert r_max == pytest.approx(0.3917 + 0.2585, abs=1e-15)
    assert r_min == pytest.approx(math.sqrt(0.3917**2 + 0.2585**2 + 2 * 0.3917 * 0.2585 * math.cos(gamma)), abs=1e-12)


def test_closed_form_round_trip(robot: Robot) -> None:
    qs = sample_qs(300, seed=5)
    for q in qs:
        target = robot.tool_pose(q)
        result = robot.ik(target)
        assert result.success, (q, result.message)
        for s in result.solutions:
            assert pose_diff(robot.tool_pose(s.q), target) <= IK_TOL
            assert -math.pi <= s.q[1] <= math.pi and -math.pi <= s.q[3] <= math.pi
            assert 0.0 <= s.q[0] <= 0.145 and abs(s.q[2]) <= 2.530727415391778
        expected = np.array([q[0], wrap(q[1]), q[2], wrap(q[3])])
        tol = IK_TOL if abs(math.sin(q[2])) > 1e-6 else 1e-7
        assert any(np.abs(s.q - expected).max() <= tol for s in result.solutions), (q, result.solutions)
        # one turn: at most one solution per branch (the right/left pair), no 2 pi-equivalents
        assert len(result.solutions) <= 2


def test_numeric_ik_converges(robot: Robot) -> None:
    for q in sample_qs(20, seed=6):
        target = robot.tool_pose(q)
        res = solve_numeric(robot, target)
        assert res.success, (q, res)
        assert pose_diff(robot.tool_pose(res.q), target) <= IK_TOL
        assert -math.pi <= res.q[1] <= math.pi and -math.pi <= res.q[3] <= math.pi
        # it lands on one of the closed-form solutions
        assert any(np.abs(s.q - res.q).max() <= 1e-7 for s in robot.ik(target).solutions), res.q


# ============================================================================== command line
def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def test_cli_fk(capsys: pytest.CaptureFixture[str]) -> None:
    q = [0.1, 4.0, -0.5, -7.0]
    rc, out, err = run(capsys, ["fk", "--urdf", str(PATH), *map(str, q), "--json", "--strict"])
    assert rc == 0 and err == ""  # angles beyond pi are not outside any limit: no warning, --strict accepts
    data = json.loads(out)
    assert data["q"] == q
    assert pose_diff(np.array([*data["position"], data["yaw"]]), irb920_fk(np.array(q))) <= FK_TOL
    rc, _, err = run(capsys, ["fk", "--urdf", str(PATH), "0.2", "0", "0", "0", "--strict"])
    assert rc == 3 and "lift" in err  # the lift is still limited


def test_cli_ik(capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.07, -4.0, 1.2, 5.5])
    target = irb920_fk(q)
    rc, out, err = run(capsys, ["ik", "--urdf", str(PATH), *(repr(float(v)) for v in target), "--json"])
    assert rc == 0, err
    sols = [np.array(s["q"], dtype=float) for s in json.loads(out)["solutions"]]
    expected = np.array([q[0], wrap(q[1]), q[2], wrap(q[3])])
    assert any(np.abs(s - expected).max() <= IK_TOL for s in sols), sols
    for s in sols:
        assert pose_diff(irb920_fk(s), target) <= IK_TOL


def test_cli_check_now_warns(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["check", str(PATH), "--json"])
    assert rc == 4
    report = json.loads(out)
    codes = {f["code"] for f in report["findings"]}
    assert "continuous-joint" in codes and "not-loadable" not in codes


def test_batch_ik_agrees_with_the_single_target_solver(robot: Robot) -> None:
    from scara_pin.kinematics.scara import IKStatus, branch_of
    from scara_pin.kinematics.scara_batch import solve_batch

    qs = sample_qs(200, seed=8)
    targets = np.array([irb920_fk(q) for q in qs])
    for branch in ("right", "left"):
        batch = solve_batch(robot.kinematics.geometry, targets, branch=branch)
        for k, _q in enumerate(qs):
            mine = [s.q for s in robot.ik(targets[k]).solutions if s.matches(branch)]
            if batch.status[k] != IKStatus.OK.value:
                assert not mine, (k, batch.status[k])
                continue
            qb = batch.q[k]
            assert pose_diff(irb920_fk(qb), targets[k]) <= IK_TOL
            assert -math.pi <= qb[1] <= math.pi and -math.pi <= qb[3] <= math.pi
            assert any(np.abs(qb - m).max() <= 1e-7 for m in mine), (qb, mine)
            assert branch_of(robot.kinematics.geometry, qb) == branch or abs(math.sin(qb[2])) < 1e-6


@pytest.mark.parametrize("q", [[0.05, 0.4, 1.1, math.pi], [0.05, -math.pi, -0.7, 0.3], [0.0, math.pi, 0.5, -math.pi]])
def test_an_angle_of_exactly_pi_is_listed_once(robot: Robot, q: list[float]) -> None:
    """+/-pi, the two ends of the presented range, are the same joint position: one solution, not two."""
    q = np.array(q)
    target = irb920_fk(q)
    sols = robot.ik(target).solutions
    assert len(sols) == 2  # right and left: the elbow is off its singularity
    assert {s.branch for s in sols} == {"right", "left"}
    mine = [s for s in sols if abs(s.q[2] - q[2]) <= IK_TOL]
    assert len(mine) == 1
    assert all(abs(wrap(a - b)) <= IK_TOL for a, b in zip(mine[0].q, q))
    for s in sols:
        assert pose_diff(irb920_fk(s.q), target) <= IK_TOL
    # with a reference, each continuous joint takes its turn nearest to it (a few turns away included)
    for ref in ([0.0, 3.0, q[2], 3.0], [0.0, 3.0 + 4 * math.pi, q[2], -3.0 - 6 * math.pi]):
        (near,) = [s for s in robot.ik(target, reference=ref).solutions if abs(s.q[2] - q[2]) <= IK_TOL]
        for j in (1, 3):
            assert abs(near.q[j] - ref[j]) <= math.pi + 1e-12  # the nearest turn: within half a turn
            assert abs(wrap(near.q[j] - q[j])) <= IK_TOL  # the same joint position as the sample


def test_inverse_dynamics_equals_the_twin(robot: Robot, twin: Robot) -> None:
    """timing's RNEA converts q: torques of the continuous robot = its revolute twin's (1e-9 N m / N),
    both given the same off-axis link masses (the fixture has none)."""
    from scara_pin.motion.verify import joint_torques

    inertial = ('<link name="{0}"><inertial><origin xyz="0.1 0.03 0"/><mass value="{1}"/>'
                '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>')  # fmt: skip

    def massive(r: Robot) -> Robot:
        text = r.urdf
        for name, mass in (("arm1", 4.0), ("arm2", 2.0), ("flange", 0.5)):
            text = text.replace(f'<link name="{name}"/>', inertial.format(name, mass))
        return robot_from_urdf(text, origin="massive")

    m, mt = massive(robot), massive(twin)
    assert m.has_continuous and not mt.has_continuous
    qs = sample_qs(20, seed=9)
    rng = np.random.default_rng(9)
    v, a = rng.uniform(-2, 2, (20, 4)), rng.uniform(-5, 5, (20, 4))
    tau, tau_t = joint_torques(m, qs, v, a), joint_torques(mt, qs, v, a)
    assert np.abs(tau).max() > 1.0  # not a vacuous comparison
    assert np.abs(tau - tau_t).max() <= 1e-9
