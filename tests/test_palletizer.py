"""The palletizer (S2): coupled URDF (mimic joints), FK against S2's closed form, geometric IK, CLI.

S2's closed form, written here in S2's own joints (q1, q2, q3, q5), q3 relative to the big arm:
    r = a1 + a2 sin q2 + a3 sin(q2 + q3) + a4,   x = r cos q1,   y = r sin q1,
    z = d1 + d2 + a2 cos q2 + a3 cos(q2 + q3) + d5,   yaw = q1 + q5 (+ tool_yaw, 0 here),
with tool0's z axis pointing down. The robot's q is the motor-side vector (q1, q2, theta3 = q2 + q3, q5).
The documented numbers (urdf/config/palletizer/kinematics.yaml) are repeated in GEOMETRY below.

Tolerances: FK and Jacobians 1e-12 (a few rounding errors of terms of size ~2 m); IK solutions 1e-9
(validate's POSE_TOL / Q_TOL).
"""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import scara_pin.kinematics.validate
from scara_pin import ParameterError, Robot, generate_urdf, load_parameters, load_robot, load_urdf
from scara_pin.cli import main
from scara_pin.description import PALLETIZER_PARAMETER_NAMES, PARAMETER_NAMES, parameter_names
from scara_pin.errors import UnknownRobotError
from scara_pin.ik_results import IKResult
from scara_pin.kinematics.numeric import solve_numeric
from scara_pin.kinematics.palletizer import (
    NotPalletizerError,
    PalletizerGeometry,
    PalletizerIKStatus,
    branch_of,
    forward,
    from_s2,
    solve,
    to_s2,
    wrist_pitch,
)
from scara_pin.kinematics.palletizer_model import read as read_palletizer
from scara_pin.kinematics.validate import validate_ik
from scara_pin.workspace import workspace_of

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "urdf" / "config"
GOLDEN = REPO / "tests" / "data" / "palletizer.urdf"
GEOMETRY = {"d1": 0.35, "d2": 0.45, "a1": 0.26, "a2": 0.95, "a3": 1.0, "a4": 0.2, "d5": -0.25}  # [m]
LIMITS_DEG = ((-165, 165), (-40, 85), (10, 150), (-300, 300))  # q1, q2, theta3 (absolute), q4
FK_TOL = 1e-12
IK_TOL = 1e-9


@pytest.fixture(scope="module")
def robot() -> Robot:
    return load_robot("palletizer")


@pytest.fixture(scope="module")
def wide() -> Robot:
    """The palletizer with limits wide enough to reach backwards over the waist (r < 0) and fold."""
    return load_robot("palletizer", {"joint2_lower": -2.5, "joint2_upper": 2.5, "joint3_lower": -3.0,
                                     "joint3_upper": 3.0})  # fmt: skip


def s2_pose(q_s2: np.ndarray) -> np.ndarray:
    """S2's closed form (module docstring) in S2's joints."""
    g = GEOMETRY
    q1, q2, q3, q5 = q_s2
    r = g["a1"] + g["a2"] * math.sin(q2) + g["a3"] * math.sin(q2 + q3) + g["a4"]
    z = g["d1"] + g["d2"] + g["a2"] * math.cos(q2) + g["a3"] * math.cos(q2 + q3) + g["d5"]
    return np.array([r * math.cos(q1), r * math.sin(q1), z, q1 + q5])


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


RX_PI = np.diag([1.0, -1.0, -1.0])


def wrap(a: float) -> float:
    return math.remainder(a, 2 * math.pi)


def limits(robot: Robot) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)


# ====================================================================================== description
def test_parameters_are_the_documented_palletizer_ones() -> None:
    params = load_parameters("palletizer")
    assert params.kind == "palletizer"
    assert tuple(params.values) == PALLETIZER_PARAMETER_NAMES == parameter_names("palletizer")
    for key, value in GEOMETRY.items():
        assert params[key] == value, key
    for j, (lo, hi) in enumerate(LIMITS_DEG):
        assert params.limits.lower[j] == pytest.approx(math.radians(lo), abs=1e-15)
        assert params.limits.upper[j] == pytest.approx(math.radians(hi), abs=1e-15)
    # the reach class claimed in kinematics.yaml: 2.40 m at q2 = 85 deg, theta3 = 90 deg
    reach = GEOMETRY["a1"] + GEOMETRY["a2"] * math.sin(math.radians(85)) + GEOMETRY["a3"] + GEOMETRY["a4"]
    assert 2.0 <= reach <= 3.0 and reach == pytest.approx(2.40, abs=0.01)


def test_scara_schema_is_unchanged() -> None:
    assert load_parameters("default").kind == "scara"
    assert parameter_names("scara") == PARAMETER_NAMES
    assert "l1" in PARAMETER_NAMES and "a2" not in PARAMETER_NAMES


@pytest.mark.parametrize(
    ("overrides", "name", "rule"),
    [
        ({"a2": 0.0}, "a2", "must be > 0"),
        ({"a3": -1.0}, "a3", "must be > 0"),
        ({"a1": -0.1}, "a1", ">= 0"),
        ({"d2": 0.0}, "d2", "must be > 0"),
        ({"joint3_lower": 3.0}, "joint3_lower", "must be <"),
        ({"a2": "nan"}, "a2", "must be finite"),
        ({"a2": "1.0); import os"}, "a2", "must be a number"),
        ({"l1": 0.3}, "l1", "is not a parameter"),  # a SCARA name on a palletizer
    ],
)
def test_palletizer_parameters_are_validated(overrides: dict[str, Any], name: str, rule: str) -> None:
    with pytest.raises(ParameterError) as info:
        load_parameters("palletizer", overrides)
    assert info.value.name == name and rule in str(info.value)


def test_scara_refuses_palletizer_names() -> None:
    with pytest.raises(ParameterError, match="is not a parameter"):
        load_parameters("default", {"a2": 1.0})


@pytest.mark.parametrize("kind", ["delta", "42", "[palletizer]"])
def test_unknown_kind_is_refused(tmp_path: Path, kind: str) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(CONFIG / "palletizer", folder)
    path = folder / "kinematics.yaml"
    path.write_text(path.read_text().replace("kind: palletizer", f"kind: {kind}"))
    with pytest.raises(ParameterError) as info:
        load_parameters(folder)
    assert info.value.name.startswith("kind in") and "must be one of scara, palletizer" in str(info.value)


def test_a_scara_file_set_with_a_palletizer_kind_is_refused(tmp_path: Path) -> None:
    folder = tmp_path / "robot"
    shutil.copytree(CONFIG / "default", folder)
    path = folder / "kinematics.yaml"
    path.write_text("kind: palletizer\n" + path.read_text())
    with pytest.raises(ParameterError, match="is not a parameter of kinematics.yaml"):
        load_parameters(folder)


def test_urdf_is_a_tree_with_two_mimic_joints(robot: Robot) -> None:
    root = ET.fromstring(robot.urdf)
    joints = {j.get("name"): j for j in root.iter("joint")}
    children = [j.find("child").get("link") for j in joints.values()]  # type: ignore[union-attr]
    assert len(children) == len(set(children)) == len(root.findall("link")) - 1  # a tree
    mimics = {name: j.find("mimic") for name, j in joints.items() if j.find("mimic") is not None}
    found = {n: (m.get("joint"), float(m.get("multiplier", "nan")), float(m.get("offset", "nan")))
             for n, m in mimics.items() if m is not None}  # fmt: skip
    assert found == {"elbow_level": ("joint2", -1.0, 0.0), "wrist_pitch": ("joint3", -1.0, 0.0)}
    assert robot.model.nq == robot.model.nv == 4
    assert [robot.model.names[i] for i in range(1, robot.model.njoints)] == [
        "joint1", "joint2", "elbow_level", "joint3", "wrist_pitch", "joint4"]  # fmt: skip
    # without mimic support, the passive joints would be independent: 6 DOF (what public models get wrong)
    assert pin.buildModelFromXML(robot.urdf).nq == 6


def test_golden_palletizer_urdf_loads_with_the_same_fk(robot: Robot, rng: np.random.Generator) -> None:
    from_file = load_urdf(GOLDEN)
    # a URDF file has no yaml: its kind is read from the model (a palletizer's layout, the flange kept level)
    assert from_file.model.nq == 4 and from_file.kind == "palletizer"
    for q in rng.uniform(-3, 3, size=(50, 4)):
        assert np.abs(from_file.tool_placement(q).homogeneous - robot.tool_placement(q).homogeneous).max() <= FK_TOL


# ====================================================================================== conventions
def test_conversions_between_s2_and_motor_side(rng: np.random.Generator) -> None:
    for q_s2 in rng.uniform(-math.pi, math.pi, size=(1000, 4)):
        q = from_s2(q_s2)
        assert q[0] == q_s2[0] and q[1] == q_s2[1] and q[3] == q_s2[3]
        assert q[2] == q_s2[1] + q_s2[2]  # theta3 = q2 + q3, one rounding
        back = to_s2(q)
        assert np.abs(back - q_s2).max() <= 2.0**-52 * 8  # the rounding of q2 + q3 only
        assert wrist_pitch(q) == -(q_s2[1] + q_s2[2])  # S2's passive q4 = -(q2 + q3)
    # exact on values whose sums are exact (multiples of 1/64 rad)
    for q_s2 in rng.integers(-200, 200, size=(200, 4)) / 64.0:
        assert np.array_equal(to_s2(from_s2(q_s2)), q_s2)
        assert np.array_equal(from_s2(to_s2(q_s2)), q_s2)


def test_conversions_refuse_bad_input() -> None:
    with pytest.raises(ParameterError):
        from_s2([0.0, 1.0, 2.0])
    with pytest.raises(ParameterError):
        to_s2([0.0, math.nan, 0.0, 0.0])


# ====================================================================================== forward kinematics
def test_fk_equals_s2_closed_form_and_flange_stays_level(robot: Robot) -> None:
    rng = np.random.default_rng(7)
    for q_s2 in rng.uniform(-math.pi, math.pi, size=(1000, 4)):
        q = from_s2(q_s2)
        M = robot.tool_placement(q)
        expected = s2_pose(q_s2)
        assert np.abs(M.translation - expected[:3]).max() <= FK_TOL, q_s2.tolist()
        # tool0 = a pure yaw of a z-down frame: R = Rz(q1 + q5) Rx(pi)
        assert np.abs(M.rotation - rz(expected[3]) @ RX_PI).max() <= FK_TOL, q_s2.tolist()
        flange = robot.frame_placement(q, "flange").rotation
        assert np.abs(flange[:, 2] - [0.0, 0.0, 1.0]).max() <= FK_TOL  # the flange z axis stays vertical
        # the passive wrist pitch is S2's q4 = -(q2 + q3): wrist frame in the small arm frame
        wMs = robot.frame_placement(q, "wrist", relative_to="small_arm").rotation
        assert np.abs(wMs - ry(-(q_s2[1] + q_s2[2]))).max() <= FK_TOL
        # the elbow frame stays level: a pure turn about z by q1
        assert np.abs(robot.frame_placement(q, "elbow").rotation - rz(q_s2[0])).max() <= FK_TOL


def test_palletizer_forward_equals_pinocchio(robot: Robot, rng: np.random.Generator) -> None:
    geo = robot.kinematics.geometry
    for q in rng.uniform(-math.pi, math.pi, size=(500, 4)):
        p, e = robot.tool_pose(q), forward(geo, q)
        assert np.abs(p[:3] - e[:3]).max() <= FK_TOL and abs(wrap(p[3] - e[3])) <= FK_TOL


def test_task_jacobian_equals_the_derivative_of_the_closed_form(robot: Robot, rng: np.random.Generator) -> None:
    g = GEOMETRY
    for q in rng.uniform(-math.pi, math.pi, size=(300, 4)):
        q1, q2, t3, _ = q
        r = g["a1"] + g["a2"] * math.sin(q2) + g["a3"] * math.sin(t3) + g["a4"]
        dr = [0.0, g["a2"] * math.cos(q2), g["a3"] * math.cos(t3), 0.0]
        c, s = math.cos(q1), math.sin(q1)
        J = np.array([
            [-r * s, c * dr[1], c * dr[2], 0.0],
            [r * c, s * dr[1], s * dr[2], 0.0],
            [0.0, -g["a2"] * math.sin(q2), -g["a3"] * math.sin(t3), 0.0],
            [1.0, 0.0, 0.0, 1.0],
        ])  # fmt: skip
        assert np.abs(robot.task_jacobian(q) - J).max() <= FK_TOL, q.tolist()
        # the flange never tilts: no angular velocity about x or y from any joint
        J6 = robot.frame_jacobian(q, reference="world")
        assert np.abs(J6[3:5]).max() <= FK_TOL


# ====================================================================================== inverse kinematics
def test_ik_finds_every_sample_both_branches(robot: Robot) -> None:
    rng = np.random.default_rng(11)
    lo, hi = limits(robot)
    seen = {"up": 0, "down": 0}
    both = 0
    for q in rng.uniform(lo, hi, size=(1000, 4)):
        target = robot.tool_pose(q)
        res = robot.ik(target)
        assert isinstance(res, IKResult) and res.success, (q.tolist(), res.message)
        assert min(s.distance(q) for s in res.solutions) <= IK_TOL
        for s in res.solutions:
            p = robot.tool_pose(s.q)
            assert np.abs(p[:3] - target[:3]).max() <= IK_TOL and abs(wrap(p[3] - target[3])) <= IK_TOL
            assert np.all(s.q >= lo) and np.all(s.q <= hi)
            assert s.branch == branch_of(s.q) or s.singular
            seen[s.branch] += 1
        both += {s.branch for s in res.solutions} == {"up", "down"}
        assert branch_of(q) in {s.branch for s in res.solutions}
    assert seen["up"] > 100 and seen["down"] > 100 and both > 50, (seen, both)


def test_branch_filter(robot: Robot) -> None:
    target = [1.8, 0.0, 1.6, 0.0]  # reachable on both branches inside the limits
    all_ = robot.ik(target)
    up, down = robot.ik(target, branch="up"), robot.ik(target, branch="down")
    assert {s.branch for s in all_.solutions} == {"up", "down"}
    assert up.solutions and all(s.branch == "up" for s in up.solutions)
    assert down.solutions and all(s.branch == "down" for s in down.solutions)
    assert len(up.solutions) + len(down.solutions) == len(all_.solutions)
    s_up, s_dn = up.solutions[0].q, down.solutions[0].q
    assert math.sin(s_up[2] - s_up[1]) > 0 > math.sin(s_dn[2] - s_dn[1])  # S2's q3 sign
    with pytest.raises(scara_pin.errors.InvalidInputError):
        robot.ik(target, branch="left")


def test_ik_reaches_backwards_over_the_waist(wide: Robot) -> None:
    """With wide limits the arm reaches behind the waist axis (r < 0): q1 = atan2(y, x) + pi."""
    q = np.array([0.3, -1.2, -1.4, 0.0])
    geo = wide.kinematics.geometry
    r = geo.r0 + geo.a2 * math.sin(q[1]) + geo.a3 * math.sin(q[2])
    assert r < 0  # the flange is behind the waist axis
    target = wide.tool_pose(q)
    res = wide.ik(target)
    assert res.success and min(s.distance(q) for s in res.solutions) <= IK_TOL
    assert abs(wrap(math.atan2(target[1], target[0]) - q[0] - math.pi)) <= 1e-12  # the target is behind


def test_validate_on_wide_limits_finds_every_solution(wide: Robot) -> None:
    report = validate_ik(wide, 300, seed=3)
    assert report.ok, report.table()
    assert report.solutions > 300


def _geo(robot: Robot, **limits: tuple[float, float]) -> PalletizerGeometry:
    geo = robot.kinematics.geometry
    lo, hi = list(geo.lower), list(geo.upper)
    for j, (a, b) in limits.items():
        i = int(j[1]) - 1
        lo[i], hi[i] = a, b
    return dataclasses.replace(geo, lower=tuple(lo), upper=tuple(hi))


@pytest.mark.parametrize(
    ("target", "limits", "branch", "status", "words"),
    [
        ([5.0, 0.0, 1.0, 0.0], {}, "all", PalletizerIKStatus.OUT_OF_REACH, "beyond a2 + a3 = 1.95"),
        ("q", {"j2": (0.3, 0.35)}, "up", PalletizerIKStatus.J2_LIMIT, "joint2 = 0.2 rad (up)"),
        ("q", {"j3": (1.5, 2.0)}, "up", PalletizerIKStatus.J3_LIMIT, "joint3 = 1.4 rad (up)"),
        ("q", {"j1": (0.5, 1.0)}, "up", PalletizerIKStatus.J1_LIMIT, "joint1 = 0 rad"),
        ("q", {"j4": (0.5, 1.0)}, "up", PalletizerIKStatus.J4_LIMIT, "joint4 = 0.1 rad"),
    ],
)
def test_reason_codes(robot: Robot, target: Any, limits: dict, branch: str, status: PalletizerIKStatus,
                      words: str) -> None:  # fmt: skip
    q = np.array([0.0, 0.2, 1.4, 0.1])
    tgt = robot.tool_pose(q) if isinstance(target, str) else np.array(target)
    res = solve(_geo(robot, **limits), tgt, branch=branch)
    assert not res.success and res.solutions == ()
    assert res.status is status and words in res.message, res.message
    # the same target without the narrowed limits is solved (the failure is the limit's)
    if isinstance(target, str):
        assert solve(robot.kinematics.geometry, tgt, branch=branch).success


def test_inside_inner_limit(robot: Robot) -> None:
    # no shoulder offsets and a short small arm: both the forward and the backward candidate put the
    # wrist 0.1 m from the shoulder, inside |a2 - a3| = 0.45 m
    geo = dataclasses.replace(robot.kinematics.geometry, r0=0.0, a3=0.5)
    res = solve(geo, [0.1, 0.0, geo.h0, 0.0])
    assert res.status is PalletizerIKStatus.INSIDE_INNER_LIMIT and "inside |a2 - a3| = 0.45 m" in res.message
    # the default robot: the wrist on the shoulder axis forwards, but the backward reach gets further
    res = robot.ik([0.46, 0.0, 0.55, 0.0])
    assert res.status is PalletizerIKStatus.J3_LIMIT and "(down)" in res.message


def test_reason_codes_are_stable() -> None:
    assert [(s.name, int(s)) for s in PalletizerIKStatus] == [
        ("OK", 0), ("OUT_OF_REACH", 1), ("INSIDE_INNER_LIMIT", 2), ("J1_LIMIT", 3), ("J2_LIMIT", 4),
        ("J3_LIMIT", 5), ("J4_LIMIT", 6), ("NOT_A_YAW_POSE", 7)]  # fmt: skip


def test_pose_targets_and_tilt(robot: Robot) -> None:
    q = np.array([0.4, 0.3, 1.2, -0.5])
    M = robot.tool_placement(q)
    for target in (M, M.homogeneous):
        res = robot.ik(target)
        assert res.success and min(s.distance(q) for s in res.solutions) <= IK_TOL
    tilted = M * pin.SE3(pin.utils.rotate("x", 1e-6), np.zeros(3))
    res = robot.ik(tilted)
    assert res.status is PalletizerIKStatus.NOT_A_YAW_POSE and "tilted by 1e-06 rad" in res.message


def test_stretched_arm_is_one_singular_solution(robot: Robot) -> None:
    q = np.array([0.0, 0.6, 0.6, 0.0])  # big and small arm aligned: the wrist at a2 + a3
    res = robot.ik(robot.tool_pose(q))
    assert res.success and len(res.solutions) == 1
    s = res.solutions[0]
    assert s.singular and s.branch == "up" and np.abs(s.q - q).max() <= 1e-7  # sqrt of rounding at the edge
    assert np.abs(robot.tool_pose(s.q) - robot.tool_pose(q)).max() <= IK_TOL


def test_geometry_is_read_from_the_model() -> None:
    """The palletizer's geometry comes from its URDF (FK probes), as the SCARA's: the yaml values come back."""
    v = load_robot("palletizer").parameters.values  # the independent route: the yaml the URDF was made from
    for robot in (load_robot("palletizer"), load_urdf(GOLDEN)):  # a URDF file as well: no yaml needed
        geo = read_palletizer(robot)
        assert geo.a2 == pytest.approx(v["a2"], abs=1e-12) and geo.a3 == pytest.approx(v["a3"], abs=1e-12)
        assert geo.r0 == pytest.approx(v["a1"] + v["a4"], abs=1e-12)
        assert geo.h0 == pytest.approx(v["d1"] + v["d2"] + v["d5"], abs=1e-12)
        assert geo.shoulder == pytest.approx((v["a1"], v["d1"] + v["d2"]), abs=1e-12)
    with pytest.raises(NotPalletizerError, match="not a palletizer"):
        read_palletizer(load_robot("default"))  # a SCARA's joint 2 turns about z


def test_geometric_ik_agrees_with_numeric_ik(robot: Robot) -> None:
    """The numeric IK on the coupled Pinocchio model lands on a geometric solution of its branch."""
    rng = np.random.default_rng(5)
    lo, hi = limits(robot)
    for q in rng.uniform(lo, hi, size=(200, 4)):
        target = robot.tool_pose(q)
        num = solve_numeric(robot, target)
        assert num.success, q.tolist()
        twins = robot.ik(target, branch=branch_of(num.q)).solutions
        assert min(s.distance(num.q) for s in twins) <= IK_TOL


def test_validate_ik_passes_and_can_fail(robot: Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    report = validate_ik(robot, 1000, seed=2024)
    assert report.ok, report.table()
    assert report.solutions >= 1000 and report.worst_pose_error <= IK_TOL
    real = robot.kinematics.solve

    def shifted(*args: Any, **kwargs: Any) -> IKResult:
        res = real(*args, **kwargs)
        return dataclasses.replace(res, solutions=tuple(dataclasses.replace(s, q=s.q + 1e-6) for s in res.solutions))

    monkeypatch.setattr(robot.kinematics, "solve", shifted)
    bad = validate_ik(robot, 20, seed=1)
    assert not bad.ok and bad.fk_fail > 0 and bad.sample_missing == 20


# ====================================================================================== command line
def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return rc, out, err


def test_cli_fk_matches_s2(capsys: pytest.CaptureFixture[str]) -> None:
    q_s2 = np.array([0.3, 0.25, 1.1, -0.4])
    q = from_s2(q_s2)
    rc, out, _ = run(capsys, ["fk", "--robot", "palletizer", "--json", *map(repr, q.tolist())])
    data = json.loads(out)
    assert rc == 0 and np.abs(np.array(data["position"]) - s2_pose(q_s2)[:3]).max() <= FK_TOL
    assert abs(wrap(data["yaw"] - s2_pose(q_s2)[3])) <= FK_TOL
    # --deg applies to all four joints of a palletizer (theta3 is an angle, not a quill length)
    rc, out, _ = run(capsys, ["fk", "--robot", "palletizer", "--json", "--deg",
                              *map(repr, np.degrees(q).tolist())])  # fmt: skip
    assert rc == 0 and np.abs(np.array(json.loads(out)["position"]) - s2_pose(q_s2)[:3]).max() <= 1e-9


def test_cli_ik(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["ik", "--robot", "palletizer", "--json", "1.8", "0", "1.6", "0"])
    data = json.loads(out)
    assert rc == 0 and data["status"] == "OK" and data["method"] == "closed-form"
    assert sorted(s["branch"] for s in data["solutions"]) == ["down", "up"]
    for s in data["solutions"]:
        assert np.abs(s2_pose(to_s2(s["q"])) - [1.8, 0.0, 1.6, 0.0]).max() <= IK_TOL
    rc, out, _ = run(capsys, ["ik", "--robot", "palletizer", "--json", "--branch", "down", "1.8", "0", "1.6", "0"])
    assert rc == 0 and [s["branch"] for s in json.loads(out)["solutions"]] == ["down"]
    rc, out, err = run(capsys, ["ik", "--robot", "palletizer", "5", "0", "1", "0"])
    assert rc == 3 and err.startswith("error: OUT_OF_REACH")
    rc, out, err = run(capsys, ["ik", "--robot", "palletizer", "--branch", "left", "1.8", "0", "1.6", "0"])
    assert rc == 2 and "up and down" in err
    rc, out, err = run(capsys, ["ik", "--robot", "palletizer", "--numeric", "--json", "1.8", "0", "1.6", "0"])
    data = json.loads(out)
    assert rc == 0 and data["solutions"][0]["branch"] in ("up", "down")


def test_cli_validate_ik(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["validate-ik", "--robot", "palletizer", "--samples", "100", "--json"])
    data = json.loads(out)
    assert rc == 0 and data["ok"] is True and data["robot"] == "palletizer" and data["samples"] == 100


def test_cli_traj_time_optimal(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out_csv = tmp_path / "t.csv"
    rc, out, _ = run(capsys, ["traj", "--robot", "palletizer", "--from-pose", "1.8", "0", "1.6", "0",
                              "--to", "1.0", "0.5", "1.2", "2.0", "--out", str(out_csv), "--json"])  # fmt: skip
    data = json.loads(out)
    assert rc == 0 and data["method"].endswith("time-optimal")
    assert max(data["limit_ratios"]["velocity"], data["limit_ratios"]["acceleration"]) <= 1.0 + 1e-9
    rows = np.loadtxt(out_csv, delimiter=",", skiprows=1)
    assert np.abs(rows[-1, 1:5] - [1.0, 0.5, 1.2, 2.0]).max() <= 1e-9


@pytest.mark.parametrize(
    "argv",
    [
        ["jog", "--robot", "palletizer", "--from", "0", "0.2", "1.4", "0", "--direction", "1", "0"],
        ["traj", "--robot", "palletizer", "--from", "0", "0.2", "1.4", "0", "--to", "0.5", "0.2", "1.4", "0",
         "--linear"],
    ],
)
def test_cli_scara_only_commands_say_so(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    rc, out, err = run(capsys, argv)
    assert rc == 2 and "SCARA-only" in err and "palletizer" in err and out == ""


def test_cli_view_html(capsys: pytest.CaptureFixture[str], tmp_path: Path, robot: Robot) -> None:
    page = tmp_path / "p.html"
    rc, out, _ = run(capsys, ["view", "--robot", "palletizer", "--q", "0.6", "0.35", "1.45", "0", "--html", str(page)])
    assert rc == 0 and page.stat().st_size > 100_000
    # every <visual> of the URDF is in the viewer's geometry model
    assert len(robot.visual_model.geometryObjects) == len(list(ET.fromstring(robot.urdf).iter("visual")))


def test_robots_lists_the_palletizer(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["robots"])
    assert rc == 0 and "palletizer" in out.split()
    assert generate_urdf("palletizer").count("<mimic") == 2
    with pytest.raises(UnknownRobotError):
        load_robot("palletiser")


# ====================================================================================== arm-plane envelope
def test_envelope_area_against_the_rasterised_image_of_the_joint_box(robot: Robot) -> None:
    """Independent route: the closed form maps a fine (q2, theta3) grid onto 5 mm pixels; count them."""
    from scara_pin.workspace.palletizer import arm_plane_envelope

    env = arm_plane_envelope(robot.kinematics.geometry)
    g = GEOMETRY
    lo, hi = limits(robot)
    q2, t3 = np.meshgrid(np.linspace(lo[1], hi[1], 1200), np.linspace(lo[2], hi[2], 1200))
    r = g["a1"] + g["a4"] + g["a2"] * np.sin(q2) + g["a3"] * np.sin(t3)
    z = g["d1"] + g["d2"] + g["d5"] + g["a2"] * np.cos(q2) + g["a3"] * np.cos(t3)
    px = 0.005
    ix, iz = np.floor(r.ravel() / px).astype(np.int64), np.floor(z.ravel() / px).astype(np.int64)
    cells = np.unique((ix - ix.min()) * (iz.max() - iz.min() + 1) + (iz - iz.min()))  # one integer per pixel
    raster = len(cells) * px * px  # over-counts by about half a pixel along the boundary
    perimeter = sum(a.radius * a.sweep for a in env.arcs)
    assert raster - perimeter * px <= env.area <= raster, (env.area, raster)
    assert env.area == pytest.approx(2.9989, abs=1e-4)  # the documented figure of the README/CLI
    # exact extents: the farthest reach is q2 = 85 deg with the small arm horizontal; the top q2 = 0, theta3 = 10 deg
    assert env.r_range[1] == pytest.approx(g["a1"] + g["a4"] + g["a2"] * math.sin(hi[1]) + g["a3"], abs=1e-12)
    assert env.z_range[1] == pytest.approx(g["d1"] + g["d2"] + g["d5"] + g["a2"] + g["a3"] * math.cos(lo[2]),
                                           abs=1e-12)  # fmt: skip
    assert r.min() >= env.r_range[0] - 1e-12 and r.max() <= env.r_range[1] + 1e-12
    assert z.min() >= env.z_range[0] - 1e-12 and z.max() <= env.z_range[1] + 1e-12


def test_envelope_boundary_is_the_edge_of_the_ik(robot: Robot) -> None:
    """On every boundary arc: just inside, the geometric IK solves the pose; just outside, it cannot."""
    from scara_pin.workspace.palletizer import arm_plane_envelope

    env = arm_plane_envelope(robot.kinematics.geometry)
    assert {a.limit for a in env.arcs} >= {"joint2_lower", "joint2_upper", "joint3_lower", "joint3_upper",
                                           "stretched"}  # fmt: skip
    q1 = 0.7
    for arc in env.arcs:
        for phi in arc.start + arc.sweep * np.linspace(0.05, 0.95, 7):
            n = np.array([math.sin(phi), math.cos(phi)])
            p = np.array(arc.center) + arc.radius * n
            inward = -n if arc.inside_toward_center else n
            for step, solvable in ((1e-6, True), (-1e-6, False)):
                r, z = p + step * inward
                res = robot.ik([r * math.cos(q1), r * math.sin(q1), z, 0.0])
                assert res.success is solvable, (arc.limit, phi, step, res.message)


def test_envelope_contains_every_fk_sample(robot: Robot) -> None:
    from scara_pin.workspace.palletizer import arm_plane_envelope

    env = arm_plane_envelope(robot.kinematics.geometry)
    rng = np.random.default_rng(9)
    lo, hi = limits(robot)
    for q in rng.uniform(lo, hi, size=(300, 4)):
        x, y, z, _ = robot.tool_pose(q)
        assert env.contains(x * math.cos(q[0]) + y * math.sin(q[0]), z)
    assert not env.contains(env.r_range[1] + 1e-6, 1.0) and not env.contains(1.0, env.z_range[1] + 1e-6)


def test_cli_workspace(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    png = tmp_path / "w.png"
    rc, out, _ = run(capsys, ["workspace", "--robot", "palletizer", "--json", "--plot", str(png)])
    data = json.loads(out)
    assert rc == 0 and data["envelope"]["area"] == pytest.approx(2.9989, abs=1e-4)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rc, out, err = run(capsys, ["workspace", "--robot", "palletizer", "--ray", "1", "0", "1", "0"])
    assert rc == 2 and "SCARA-only" in err


def test_numeric_ik_sees_the_four_actuated_joints_of_the_coupled_model() -> None:
    """The mimic (levelling) joints are not in q: the numeric IK must turn the flange (joint4) by 2 pi
    turns like any revolute joint, not treat it as a non-revolute joint."""
    from scara_pin.kinematics.numeric import solve_numeric

    robot = load_robot("palletizer")
    q = np.array([0.4, 0.3, 1.6, 2.0])
    target = robot.tool_pose(q)
    target[3] += 2 * math.pi  # the same yaw one turn later: reachable only through a 2 pi-equivalent
    res = solve_numeric(robot, target)
    assert res.success and res.residual < 1e-9
    assert robot.outside_limits(res.q) == []


def test_the_3d_workspace_wireframe_is_the_reach_boundary(tmp_path: Path) -> None:
    """`view --workspace` draws the palletizer's envelope in 3-D: the arm-plane boundary at the waist limits and
    the circles of its extreme points. Every drawn point is a tool point the IK reaches (Pinocchio FK of the
    solution gives it back to 1e-9 m), the planes are at the waist limits, and 1 mm beyond the outermost
    circle nothing is reachable."""
    robot = load_robot("palletizer")
    env = workspace_of(robot)
    lines = env.wireframe(n=24)
    lo, hi = robot.limits.lower[0], robot.limits.upper[0]
    assert hi - lo < 2 * math.pi and len(lines) == 2 * len(env.arcs) + 3
    for k, pts in enumerate(lines):
        assert pts.shape[1] == 3
        if k < 2 * len(env.arcs):  # a boundary arc in the plane of one waist limit
            angle = lo if k < len(env.arcs) else hi
            r = np.hypot(pts[:, 0], pts[:, 1])
            assert np.allclose(np.arctan2(pts[:, 1], pts[:, 0])[r > 1e-9], angle, atol=1e-12)
        for x, y, z in pts[::3]:
            res = robot.ik(np.array([x, y, z, 0.0]))
            assert res.success, (k, x, y, z, res.message)
            assert np.abs(robot.tool_pose(res.solutions[0].q)[:3] - [x, y, z]).max() <= 1e-9
    r_max, z_at = max(((math.hypot(*p[0, :2]), p[0, 2]) for p in lines[-3:]), key=lambda t: t[0])
    for a in np.linspace(lo, hi, 7):
        r = r_max + 1e-3
        assert not robot.ik(np.array([r * math.cos(a), r * math.sin(a), z_at, 0.0])).success
    html = tmp_path / "p.html"
    assert main(["view", "--robot", "palletizer", "--workspace", "--html", str(html)]) == 0 and html.is_file()
