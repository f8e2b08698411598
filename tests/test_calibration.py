"""Kinematic calibration (scara_pin.calibration, ``scara-pin calibrate``), against a synthetic truth.

The truth is a shipped robot whose URDF this test perturbs itself (its own XML edit: link lengths, zero
offsets, axis tilts, base and tool offsets) and simulates with Pinocchio; the truth of each rotation error is
the rotation vector of the written rpy, by scipy (a second library). Calibrated URDFs are read back by
Pinocchio and yourdfpy.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from calibration_truth import write_csv
from scipy.spatial.transform import Rotation

from scara_pin import InvalidInputError, load_robot, robot_from_urdf
from scara_pin.calibration import (
    CalibrationOptions,
    ChainModel,
    Loss,
    MeasurementFrame,
    Measurements,
    ParameterStatus,
    calibrate,
    plan_experiment,
    structural_count,
    yaml_overlay,
)
from scara_pin.cli import main

DATA = Path(__file__).parent / "data"
NOISE = 1e-5  # [m] 10 um per coordinate
D = math.radians
TOOL = {"tool_x": 0.05}  # the measured target 50 mm off the J4 axis (a calibration bracket), else J4 is unseen
SCALE = 1.0002  # the quill's true stroke per unit of reading
# URDF joint -> (xyz added [m], rotation vector of the origin [rad], written as rpy by scipy); only identifiable
# errors (the report's base set): x, y of the rotation vector tilt a joint, z turns its zero
IDENTIFIABLE = {
    "joint1": ((0.3e-3, -0.2e-3, 0.4e-3), (D(0.1), D(-0.15), D(0.5))),  # base offset, J1 tilt, J1 zero offset
    "joint2": ((1e-3, 0.0, 0.0), (D(0.2), D(0.1), D(-0.4))),  # l1 + 1 mm, J2 tilt and zero offset
    "joint3": ((-0.8e-3, 0.0, 0.0), (D(-0.1), D(0.2), 0.0)),  # l2 - 0.8 mm, quill tilt
    "joint4": ((0.0, 0.0, 0.0), (D(0.05), D(-0.1), D(0.3))),  # J4 tilt and zero offset
    "flange-tool0_fixed_joint": ((0.5e-3, 0.0, 0.0), None),  # tool offset
}
# errors no measurement of the tool position separates (the quill's zero offset, lateral offsets, heights)
HIDDEN = {
    "joint2": ((1e-3, 0.4e-3, -0.3e-3), (D(0.2), D(0.1), D(-0.4))),
    "joint3": ((-0.8e-3, -0.2e-3, 0.6e-3), (D(-0.1), D(0.2), D(0.1))),
    "flange-tool0_fixed_joint": ((0.5e-3, 0.3e-3, -0.2e-3), None),
}


def perturbed(urdf: str, errors: dict) -> str:
    """The URDF with each named joint's origin xyz moved and its rotation written as rpy (the test's own edit)."""
    root = ET.fromstring(urdf)
    for j in root.findall("joint"):
        if j.get("name") in errors:
            dxyz, rpy = errors[j.get("name")]
            o = j.find("origin")
            xyz = np.array([float(v) for v in o.get("xyz").split()]) + dxyz
            o.set("xyz", " ".join(repr(float(v)) for v in xyz))
            if rpy is not None:
                o.set("rpy", " ".join(repr(float(v)) for v in Rotation.from_rotvec(rpy).as_euler("xyz")))
    return ET.tostring(root, encoding="unicode")


def truth_values(errors: dict) -> dict[str, float]:
    """The errors' true values in the report's names (the nonzero ones)."""
    out = {"joint3.scale": SCALE - 1.0}
    for joint, (dxyz, w) in errors.items():
        name = "tool0" if joint.startswith("flange") else joint
        for axis, v in zip("xyz", dxyz):
            out[f"{name}.{axis}"] = v
        if w is not None:
            out[f"{name}.rx"], out[f"{name}.ry"] = w[0], w[1]
            out[f"{name}.offset" if joint != "joint3" else f"{name}.rz"] = w[2]
    return {k: v for k, v in out.items() if v != 0.0}


def simulate(truth, n: int, rng: np.random.Generator, noise: float = 0.0, q3: float | None = None):
    """n poses inside the limits: the readings (quill reading = stroke / SCALE) and the true positions + noise."""
    lo, hi = np.array(truth.limits.lower), np.array(truth.limits.upper)
    q = rng.uniform(lo, hi, (n, truth.dof))
    if q3 is not None:
        q[:, 2] = q3
    p = np.array([truth.tool_placement(x).translation for x in q]) + rng.normal(0.0, noise, (n, 3))
    yaw = np.array([truth.tool_pose(x)[3] for x in q])
    readings = q.copy()
    readings[:, 2] /= SCALE
    return readings, p, yaw, q


@pytest.fixture(scope="module")
def nominal():
    return load_robot("default", TOOL)


@pytest.fixture(scope="module")
def truth(nominal):
    return robot_from_urdf(perturbed(nominal.urdf, IDENTIFIABLE))


@pytest.fixture(scope="module")
def exact(nominal, truth):
    """Noise-free: 40 poses."""
    readings, p, yaw, q = simulate(truth, 40, np.random.default_rng(1))
    return calibrate(nominal, Measurements(readings, p)), (readings, p, yaw, q)


@pytest.fixture(scope="module")
def noisy(nominal, truth):
    """10 um of Gaussian noise on 50 poses (seeded)."""
    readings, p, yaw, q = simulate(truth, 50, np.random.default_rng(11), NOISE)
    return calibrate(nominal, Measurements(readings, p)), (readings, p, yaw, q)


# ------------------------------------------------------------------------------------------ the error model
@pytest.mark.parametrize("frame", list(MeasurementFrame))
@pytest.mark.parametrize("yaw", [False, True])
def test_jacobian_equals_central_differences(nominal, frame, yaw) -> None:
    chain = ChainModel.from_robot(nominal, frame=frame, yaw=yaw)
    rng = np.random.default_rng(3)
    qpin = chain.pinocchio_q(rng.uniform(nominal.limits.lower, nominal.limits.upper, (5, 4)))
    theta = rng.normal(0.0, 0.01, chain.size)
    device0 = pin.SE3(pin.exp3(np.array([0.3, -0.2, 1.0])), np.array([1.0, 2.0, 0.5]))
    _, J = chain.predict(theta, qpin, device0)
    h = 1e-6
    for k in range(chain.size):
        e = np.zeros(chain.size)
        e[k] = h
        up, _ = chain.predict(theta + e, qpin, device0, jacobian=False)
        down, _ = chain.predict(theta - e, qpin, device0, jacobian=False)
        assert np.abs(J[:, k] - ((up - down) / (2 * h)).ravel()).max() < 1e-7, chain.parameters[k].name


@pytest.mark.parametrize(("frame", "yaw", "expected"), [
    # 4 moving origins x 6 (zero offsets included) + the quill's scale + the tool's 6 = 31 candidates; not
    # separable: per revolute joint a turn about and a slide along its axis (3 x 2), per prismatic joint the 3
    # slides and the turn about its axis (4); not measured: the tool's 3 rotations (2 with the yaw)
    (MeasurementFrame.BASE, False, 31 - 6 - 4 - 3),
    (MeasurementFrame.BASE, True, 31 - 6 - 4 - 2),
    # the device's 6 more, and the device placement absorbs J1's origin (6)
    (MeasurementFrame.DEVICE, False, 31 + 6 - 6 - 6 - 4 - 3),
])  # fmt: skip
def test_structural_count_is_the_gauge_count(nominal, frame, yaw, expected) -> None:
    assert structural_count(ChainModel.from_robot(nominal, frame=frame, yaw=yaw)) == expected


# ------------------------------------------------------------------------------------------ synthetic truth
def test_noise_free_truth_is_recovered(nominal, truth, exact) -> None:
    res, (readings, p, _, _) = exact
    assert res.after.max <= 1e-9  # the measurements reproduced [m]
    assert res.before.max > 1e-3  # (the errors were millimetres)
    want = truth_values(IDENTIFIABLE)
    for name, value in want.items():
        est = res.parameter(name)
        assert est.status is ParameterStatus.IDENTIFIED, name
        assert abs(est.value - value) <= 1e-8, (name, est.value, value)
    # every error the test did not make is zero, identified or fixed
    for est in res.parameters:
        if est.name not in want:
            assert abs(est.value) <= 1e-8, est.name
    fresh_readings, fresh_p, _, _ = simulate(truth, 30, np.random.default_rng(2))
    assert np.abs(res.predict(fresh_readings) - fresh_p).max() <= 1e-9


def test_measured_yaw_identifies_one_more_error(nominal, truth, exact) -> None:
    """With the yaw measured, the tool's rotation about its axis joins: 19 errors, still exact."""
    _, (readings, p, yaw, _) = exact
    res = calibrate(nominal, Measurements(readings, p, yaw), CalibrationOptions(folds=0))
    assert len(res.identified) == 19 and res.after.max <= 1e-9 and res.after.yaw_max <= 1e-9
    for name, value in truth_values(IDENTIFIABLE).items():
        assert abs(res.parameter(name).value - value) <= 1e-8, name


def test_unseparable_errors_are_reported_and_fixed(exact) -> None:
    res, _ = exact
    fixed = {p.name: p.reason for p in res.fixed}
    assert fixed["joint2.y"] == "not separable from joint1.offset, joint2.offset"  # l1's lateral offset
    assert fixed["joint3.z"] == "not separable from joint1.z"  # the quill's zero offset: a height
    assert fixed["tool0.rx"] == "no effect on the measurements"  # positions only
    assert all(p.value == 0.0 and p.std == 0.0 for p in res.fixed)
    assert len(res.identified) == res.structural_count == 18


def test_hidden_errors_are_absorbed_exactly(nominal) -> None:
    """Errors no position separates (quill zero offset, lateral offsets) are absorbed: still exact."""
    truth = robot_from_urdf(perturbed(nominal.urdf, {**IDENTIFIABLE, **HIDDEN}))
    readings, p, _, _ = simulate(truth, 40, np.random.default_rng(4))
    res = calibrate(nominal, Measurements(readings, p), CalibrationOptions(folds=0))
    assert res.after.max <= 1e-9
    fresh, fresh_p, _, _ = simulate(truth, 30, np.random.default_rng(5))
    assert np.abs(res.predict(fresh) - fresh_p).max() <= 1e-9


def test_noisy_fit_statistics(truth, noisy) -> None:
    res, _ = noisy
    assert abs(res.after.rms / NOISE - 1.0) <= 0.2  # residual RMS within 20 % of the noise level
    want = truth_values(IDENTIFIABLE)
    for name, value in want.items():
        est = res.parameter(name)
        assert abs(est.value - value) <= 3 * est.std, (name, est.value, value, est.std)
    assert all(p.value == 0.0 for p in res.fixed)  # never fitted to noise
    # held-out poses: the cross-validation and 200 fresh noisy poses, predicted to the noise level
    assert res.cross_validation is not None and abs(res.cross_validation.held_out.rms / NOISE - 1.0) <= 0.25
    fresh, fresh_p, _, _ = simulate(truth, 200, np.random.default_rng(12), NOISE)
    rms = math.sqrt(np.mean((res.predict(fresh) - fresh_p) ** 2))
    assert abs(rms / NOISE - 1.0) <= 0.2


def test_unexcited_scale_is_reported_not_fitted(nominal, truth) -> None:
    """The quill never moves: its scale cannot be seen, and is fixed, not fitted to noise."""
    readings, p, _, _ = simulate(truth, 40, np.random.default_rng(6), NOISE, q3=0.05)
    res = calibrate(nominal, Measurements(readings, p), CalibrationOptions(folds=0))
    scale = res.parameter("joint3.scale")
    assert scale.status is ParameterStatus.FIXED and scale.value == 0.0 and "joint1.z" in scale.reason
    # the scale, and a still quill's tilts turn the wrist like the wrist's own tilts: 15 of 18
    assert any("identify 15 of the 18" in n for n in res.notes), res.notes
    assert "joint3.rx" in res.parameter("joint4.rx").reason and "joint3.ry" in res.parameter("joint4.ry").reason


def test_outliers_are_found_with_the_robust_loss(nominal, truth) -> None:
    """The default loss is robust (soft_l1): outliers listed and left out; linear keeps them, with a warning."""
    readings, p, _, _ = simulate(truth, 50, np.random.default_rng(21), NOISE)
    bad = [4, 17, 33]
    p = p.copy()
    p[bad] += [0.004, -0.003, 0.002]  # millimetres off: a slipped target
    plain = calibrate(nominal, Measurements(readings, p), CalibrationOptions(loss=Loss.LINEAR, folds=0))
    robust = calibrate(nominal, Measurements(readings, p), CalibrationOptions(folds=0))
    assert robust.loss is Loss.SOFT_L1 and not plain.outliers
    assert any("row 5 (" in w and "row 18 (" in w and "row 34 (" in w for w in plain.warnings), plain.warnings
    assert [o.row for o in robust.outliers] == bad
    assert [o.where for o in robust.outliers] == ["row 5", "row 18", "row 34"]
    assert all(o.distance > 1e-3 for o in robust.outliers)
    assert abs(robust.after.rms / NOISE - 1.0) <= 0.25 < plain.after.rms / NOISE - 1.0


def test_device_frame_is_identified_and_the_urdf_keeps_its_base(nominal, truth) -> None:
    readings, p, _, _ = simulate(truth, 40, np.random.default_rng(8))
    dMb = pin.SE3(Rotation.from_euler("zyx", [40, 2, -1], degrees=True).as_matrix(), np.array([1.5, -0.7, 0.3]))
    res = calibrate(nominal, Measurements(readings, p @ dMb.rotation.T + dMb.translation),
                    CalibrationOptions(frame=MeasurementFrame.DEVICE, folds=0))  # fmt: skip
    assert res.after.max <= 1e-9
    # the device absorbs J1's placement: the base-frame truth is the device's times J1's true origin error
    J1 = [j for j in ET.fromstring(truth.urdf).findall("joint") if j.get("name") == "joint1"][0].find("origin")
    xyz = np.array([float(v) for v in J1.get("xyz").split()])
    dMj1 = dMb * pin.SE3(Rotation.from_rotvec(IDENTIFIABLE["joint1"][1]).as_matrix(), xyz)
    assert np.abs((res.device * pin.SE3(np.eye(3), xyz - IDENTIFIABLE["joint1"][0])).homogeneous
                  - dMj1.homogeneous).max() <= 1e-9  # fmt: skip
    calibrated_j1 = [j for j in ET.fromstring(res.urdf).findall("joint") if j.get("name") == "joint1"][0]
    assert calibrated_j1.find("origin").attrib == {"rpy": "0 0 0", "xyz": "0 0 0.0"}  # the base kept as it was


def test_three_joint_scara(tmp_path) -> None:
    nominal = load_robot(urdf=DATA / "three_joint" / "arm3_rrp.urdf")
    chain = ChainModel.from_robot(nominal)
    names = [o.name for o in chain.origins]
    errors = {names[0]: ((0.2e-3, -0.1e-3, 0.0), None), names[1]: ((0.5e-3, 0.0, 0.0), (D(0.1), 0.0, D(0.3)))}
    truth = robot_from_urdf(perturbed(nominal.urdf, errors))
    rng = np.random.default_rng(9)
    q = rng.uniform(nominal.limits.lower, nominal.limits.upper, (30, 3))
    p = np.array([truth.tool_placement(x).translation for x in q])
    res = calibrate(nominal, Measurements(q, p), CalibrationOptions(folds=0))
    assert res.after.max <= 1e-9
    fresh = rng.uniform(nominal.limits.lower, nominal.limits.upper, (20, 3))
    assert np.abs(res.predict(fresh) - [truth.tool_placement(x).translation for x in fresh]).max() <= 1e-9


def test_palletizer_is_refused() -> None:
    with pytest.raises(InvalidInputError, match="mimic joints"):
        ChainModel.from_robot(load_robot("palletizer"))


# ------------------------------------------------------------------------------------------ the calibrated URDF
def test_calibrated_urdf_in_pinocchio_and_yourdfpy(tmp_path, exact) -> None:
    import yourdfpy

    res, (readings, p, _, _) = exact
    path = tmp_path / "calibrated.urdf"
    path.write_text(res.urdf)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)
    q_model = res.model_q(readings)
    predicted = res.predict(readings)
    base, tool = model.getFrameId("base"), model.getFrameId("tool0")
    for qm, want in zip(q_model, predicted):
        pin.framesForwardKinematics(model, data, qm)
        assert np.abs(data.oMf[base].actInv(data.oMf[tool]).translation - want).max() <= 1e-12
        urdf.update_cfg(dict(zip(["joint1", "joint2", "joint3", "joint4"], qm)))
        assert np.abs(urdf.get_transform("tool0", "base")[:3, 3] - want).max() <= 1e-12
    assert np.abs(predicted - p).max() <= 1e-9


def test_ik_on_the_calibrated_urdf_reaches_the_measured_positions(tmp_path, exact) -> None:
    res, (readings, p, yaw, q_true) = exact
    path = tmp_path / "calibrated.urdf"
    path.write_text(res.urdf)
    robot = load_robot(urdf=path)
    assert robot.kinematics.geometry.tilt > 1e-3  # near-parallel: the closed form, polished on the model
    for xyz, psi, qt in zip(p, yaw, q_true):
        sol = robot.ik((*xyz, psi))
        assert sol.success  # (the other branch may fall outside a limit)
        for s in sol.solutions:
            assert np.abs(robot.tool_placement(s.q).translation - xyz).max() <= 1e-9
        turns = np.array([1.0, 1.0, 0.0, 1.0]) * 2 * math.pi  # revolute joints: the same angle modulo a turn
        gap = [np.abs(np.where(turns > 0, np.remainder(s.q - qt + math.pi, 2 * math.pi) - math.pi, s.q - qt)).max()
               for s in sol.solutions]  # fmt: skip
        assert min(gap) <= 1e-9  # the true configuration among them


def test_check_is_clean_and_only_the_origins_changed(tmp_path, capsys, exact, nominal) -> None:
    res, _ = exact
    path = tmp_path / "calibrated.urdf"
    path.write_text(res.urdf)
    assert main(["check", str(path)]) == 0, capsys.readouterr().out
    before, after = nominal.urdf.splitlines(), res.urdf.splitlines()
    changed = [(a, b) for a, b in zip(before, after) if a != b]
    assert len(before) == len(after) and len(changed) == 5  # joint1..4 and the tool's joint, nothing else
    assert all(a.strip().startswith("<origin") and b.strip().startswith("<origin") for a, b in changed)


def test_third_party_urdf_keeps_its_comments() -> None:
    src = DATA / "third_party" / "yk400xe_like.urdf"
    nominal = load_robot(urdf=src)
    chain = ChainModel.from_robot(nominal)
    first = chain.origins[0].name
    truth = robot_from_urdf(perturbed(nominal.urdf, {first: ((0.4e-3, 0.0, 0.0), (0.0, 0.0, D(0.2)))}))
    readings, p, _, _ = simulate(truth, 30, np.random.default_rng(10))
    readings[:, 2] *= SCALE  # (this truth has no scale error)
    res = calibrate(nominal, Measurements(readings, p), CalibrationOptions(folds=0))
    assert res.after.max <= 1e-9
    text = src.read_text()
    assert text.count("<!--") == res.urdf.count("<!--") > 0
    diff = [(a, b) for a, b in zip(text.splitlines(), res.urdf.splitlines()) if a != b]
    assert diff and all("<origin" in a and "<origin" in b for a, b in diff)
    from scara_pin.lint import Severity, check_urdf

    def warnings(urdf: str) -> set[str]:
        return {f.code for f in check_urdf(urdf).findings if f.severity is not Severity.INFO}

    assert warnings(res.urdf) == warnings(text) == {"velocity-placeholder"}  # the input's own, no new one


def test_yaml_overlay_recovers_yaml_parameters() -> None:
    """Errors the yaml can carry (lengths, heights, the tool offset): the overlay gives the true values."""
    changed = {"l1": 0.2012, "l2": 0.1991, "d1": 0.0007, "tool_x": 0.0505, "tool_y": 0.0, **{}}
    truth = load_robot("default", {**TOOL, **changed})
    nominal = load_robot("default", TOOL)
    rng = np.random.default_rng(13)
    q = rng.uniform(nominal.limits.lower, nominal.limits.upper, (40, 4))
    p = np.array([truth.tool_placement(x).translation for x in q])
    res = calibrate(nominal, Measurements(q, p), CalibrationOptions(folds=0))
    overlay = yaml_overlay(res)
    assert set(overlay.values) == {"l1", "l2", "d1", "tool_x"}
    for k, v in overlay.values.items():
        assert abs(v - changed[k]) <= 1e-9, k
    assert overlay.unexpressed == () and overlay.residual.max <= 1e-9
    assert "l1: 0.201" in overlay.to_yaml()


# ------------------------------------------------------------------------------------------ experiment design
def test_plan_beats_random_poses(nominal) -> None:
    plan = plan_experiment(nominal, 25, seed=3)
    assert np.all(plan.q >= np.array(nominal.limits.lower)) and np.all(plan.q <= np.array(nominal.limits.upper))
    chain = ChainModel.from_robot(nominal)
    kept = [chain.names().index(n) for n in plan.identified]
    rng = np.random.default_rng(14)

    def jacobian(q: np.ndarray) -> np.ndarray:  # (checked against central differences above)
        _, J = chain.predict(np.zeros(chain.size), chain.pinocchio_q(q), pin.SE3.Identity())
        return J[:, kept]

    reference = np.vstack([jacobian(rng.uniform(nominal.limits.lower, nominal.limits.upper, (25, 4)))
                           for _ in range(20)])  # fmt: skip
    scale = np.linalg.norm(reference, axis=0) / math.sqrt(20 * 25)

    def value(q: np.ndarray) -> float:
        W = jacobian(q) / scale
        return float(np.linalg.slogdet(W.T @ W)[1])

    random_best = max(value(rng.uniform(nominal.limits.lower, nominal.limits.upper, (25, 4))) for _ in range(20))
    assert value(plan.q) > random_best
    predicted, _ = chain.predict(np.zeros(chain.size), chain.pinocchio_q(plan.q), pin.SE3.Identity(), jacobian=False)
    assert np.abs(plan.predicted - predicted).max() <= 1e-12


# ------------------------------------------------------------------------------------------ command line
def test_cli_calibrate_writes_the_urdf_overlay_and_plot(tmp_path, capsys, noisy) -> None:
    _, (readings, p, _, _) = noisy
    csv = write_csv(tmp_path / "m.csv", readings, p)
    out, overlay, plot = tmp_path / "c.urdf", tmp_path / "o.yaml", tmp_path / "r.png"
    rc = main(["calibrate", "--robot", "default", "--set", "tool_x=0.05", "--measurements", str(csv), "--out", str(out),
               "--overlay", str(overlay), "--plot", str(plot), "--json", "--folds", "0"])  # fmt: skip
    doc = json.loads(capsys.readouterr().out)
    assert rc == 0 and doc["identified_count"] == 18 and abs(doc["after"]["rms"] / NOISE - 1) <= 0.2
    assert doc["written"] == {"urdf": str(out), "overlay": str(overlay), "plot": str(plot)}
    assert out.read_text() == noisy[0].urdf and plot.stat().st_size > 1000
    assert "l1:" in overlay.read_text()
    assert main(["check", str(out)]) == 0


def test_cli_plan_csv_round_trip(tmp_path, capsys) -> None:
    out = tmp_path / "plan.csv"
    assert main(["calibrate", "--robot", "s1", "--plan", "20", "--criterion", "min-sv", "--out", str(out)]) == 0
    assert "criterion min-sv" in capsys.readouterr().out
    m = Measurements.from_csv(out, 4)
    assert len(m) == 20 and m.yaw is None
    assert main(["calibrate", "--robot", "s1", "--measurements", str(out), "--json", "--folds", "0"]) == 0
    assert json.loads(capsys.readouterr().out)["after"]["max"] <= 1e-12  # the nominal positions: nothing to fix


@pytest.mark.parametrize(("rows", "cell", "message"), [
    (10, None, "10 measured poses for 18 identifiable parameters"),
    (40, "nan", "line 6: q2 = 'nan' is not a plain number"),
    (40, "abc", "line 6: q2 = 'abc' is not a plain number"),
])  # fmt: skip
def test_cli_bad_measurements_exit_2(tmp_path, capsys, noisy, rows, cell, message) -> None:
    _, (readings, p, _, _) = noisy
    csv = write_csv(tmp_path / "m.csv", readings[:rows], p[:rows])
    if cell is not None:
        lines = csv.read_text().splitlines()
        values = lines[5].split(",")
        values[1] = cell
        lines[5] = ",".join(values)
        csv.write_text("\n".join(lines) + "\n")
    out = tmp_path / "c.urdf"
    rc = main(["calibrate", "--robot", "default", "--set", "tool_x=0.05", "--measurements", str(csv),
               "--out", str(out)])  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith("error: ") and err.count("\n") == 1 and message in err, err
    assert not out.exists()


def test_cli_refusals(tmp_path, capsys) -> None:
    for argv, message in [
        (["calibrate", "--robot", "default"], "give --measurements FILE"),
        (["calibrate", "--robot", "default", "--plan", "5"], "5 poses for 16 identifiable parameters"),
        (["calibrate", "--robot", "palletizer", "--plan", "40"], "mimic joints"),
        (["calibrate", "--robot", "default", "--plan", "40", "--model", "links"], "--model 'links'"),
        (["calibrate", "--urdf", str(DATA / "s1.urdf"), "--plan", "40", "--overlay", str(tmp_path / "o.yaml")],
         "configured robot"),
    ]:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("error: ") and err.count("\n") == 1 and message in err, err


def test_urdf_edit_touches_only_the_named_origins() -> None:
    from scara_pin.calibration.urdf_edit import edit_origins

    text = """<robot name="r">
  <transmission name="t1"><joint name="j1"><hardwareInterface>x</hardwareInterface></joint></transmission>
  <link name="a"/><link name="b"/><link name="c"/>
  <!-- <joint name="j1" type="revolute"><origin xyz="9 9 9"/></joint> -->
  <joint name="j1" type="revolute">
    <parent link="a"/><child link="b"/>
    <origin rpy='0 0 0' xyz='0.1 0 0'/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="fixed">
    <parent link="b"/><child link="c"/>
  </joint>
</robot>
"""
    out = edit_origins(text, {"j1": (np.array([0.1001, 0.0, -0.0]), None),
                              "j2": (None, np.array([0.0, 0.0, 0.25]))})  # fmt: skip
    assert """<origin rpy='0 0 0' xyz="0.1001 0.0 0.0"/>""" in out
    assert '<origin xyz="0.0 0.0 0.0" rpy="0.0 0.0 0.25"/>' in out  # a joint without <origin> gets one
    assert out.count("9 9 9") == 1 and "<transmission" in out  # the comment and the transmission untouched
    import difflib

    diff = [d for d in difflib.ndiff(text.splitlines(), out.splitlines()) if d[:2] in ("- ", "+ ")]
    assert [d[:2] for d in diff] == ["- ", "+ ", "+ "], diff  # j1's origin changed, j2's added: nothing else
