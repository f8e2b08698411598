"""Calibration data that lie (issue 30, items 2 and 3) and calibration without a tracker (issue 31, item 7).

The truth: the ``default`` robot with its target 50 mm off J4's axis (``--set tool_x=0.05``) and every joint
origin perturbed by the test's own edit, measured by yourdfpy (:mod:`calibration_truth`), 10 um of noise.
Each lie of the issue is written into a measurement file and given to ``scara-pin calibrate``: refused with
exit code 2 and one line saying what the data look like, nothing written; or, where it can be legitimate,
calibrated with a warning on stderr.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from calibration_truth import Tracker, perturbed_everywhere, write_csv
from scipy.spatial.transform import Rotation

from scara_pin import load_robot
from scara_pin.calibration import CalibrationOptions, Loss, Measurements, calibrate
from scara_pin.cli import main

DATA = Path(__file__).parent / "data"
ROBOT = ["--robot", "default", "--set", "tool_x=0.05"]
NOISE = 1e-5
N = 40


@pytest.fixture(scope="module")
def nominal():
    return load_robot("default", {"tool_x": 0.05})


@pytest.fixture(scope="module")
def truth(nominal, tmp_path_factory):
    return Tracker(perturbed_everywhere(nominal.urdf, np.random.default_rng(30)), tmp_path_factory.mktemp("truth"))


@pytest.fixture(scope="module")
def data(nominal, truth):
    """40 poses inside the limits, measured with 10 um of noise; and 100 fresh poses with their true positions."""
    rng = np.random.default_rng(31)
    lo, hi = np.array(nominal.limits.lower), np.array(nominal.limits.upper)
    q = rng.uniform(lo, hi, (N, 4))
    p, _ = truth(q)
    fresh = rng.uniform(lo, hi, (100, 4))
    return q, p + rng.normal(0.0, NOISE, p.shape), fresh, truth(fresh)[0]


def run(argv: list[str], capsys) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def refused(rc: int, err: str, out_file: Path) -> bool:
    return rc == 2 and err.startswith("error: ") and err.count("\n") == 1 and not out_file.exists()


def model_error(robot, fresh: np.ndarray, p_true: np.ndarray) -> float:
    """The RMS error [m] of a robot's (or a URDF file's) tool positions at the fresh poses."""
    robot = load_robot(urdf=robot) if isinstance(robot, Path) else robot
    return math.sqrt(np.mean((np.array([robot.tool_placement(x).translation for x in fresh]) - p_true) ** 2))


# ------------------------------------------------------------------------------------------ issue 30, item 2
DEG = np.array([180 / math.pi, 180 / math.pi, 1.0, 180 / math.pi])


@pytest.mark.parametrize(("case", "message"), [
    ("positions in mm", "the measured positions are 1001 times the model's: millimetres? x, y, z must be in metres"),
    ("positions 1e11", "times the model's: x, y, z must be in metres"),
    ("readings in degrees", "the joint readings look like degrees"),
    ("a 33 deg offset: readings outside the limits", "rows have readings outside the joint limits (line "),
    ("one pose repeated 60 times", "60 rows hold 1 distinct pose (rows with the same readings measure one pose "
     "again) for 18 identifiable parameters"),
    ("12 poses measured 5 times", "60 rows hold 12 distinct poses (rows with the same readings measure one pose "
     "again) for 18 identifiable parameters"),
])  # fmt: skip
def test_data_that_cannot_be_right_are_refused(tmp_path, capsys, data, case, message) -> None:
    q, p, _, _ = data
    if case == "positions in mm":
        p = p * 1000.0
    elif case == "positions 1e11":
        p = np.full_like(p, 1e11)
    elif case == "readings in degrees":
        q = q * DEG
    elif case.startswith("a 33 deg offset"):
        q = q.copy()
        q[:, 0] += math.radians(33.0)  # an encoder zero 33 deg off: the readings run past joint1's upper limit
    elif case == "one pose repeated 60 times":
        q, p = np.repeat(q[:1], 60, axis=0), p[:1] + np.random.default_rng(1).normal(0.0, NOISE, (60, 3))
    else:
        q, p = np.repeat(q[:12], 5, axis=0), np.repeat(p[:12], 5, axis=0)
    csv, out = write_csv(tmp_path / "m.csv", q, p), tmp_path / "c.urdf"
    rc, _, err = run(["calibrate", *ROBOT, "--measurements", str(csv), "--out", str(out)], capsys)
    assert refused(rc, err, out) and message in err, err


def test_another_robots_joint_column_is_refused(tmp_path, capsys, data) -> None:
    """4-joint data on a 3-joint arm: the q4 column was ignored; now it is refused, naming it."""
    q, p, _, _ = data
    csv, out = write_csv(tmp_path / "m.csv", q, p), tmp_path / "c.urdf"
    rc, _, err = run(["calibrate", "--urdf", str(DATA / "three_joint" / "arm3_rrp.urdf"), "--tool", "end_effector",
                      "--measurements", str(csv), "--out", str(out)], capsys)  # fmt: skip
    assert refused(rc, err, out) and "column q4: the file has readings of more joints than the robot's 3" in err, err


def test_readings_just_outside_narrow_limits_are_refused_or_accepted_with_a_warning(tmp_path, capsys, nominal,
                                                                                    truth) -> None:  # fmt: skip
    """A controller whose joint2 runs 0.05 rad past the URDF's limits: refused by default, naming a line; used
    with --allow-outside-limits, with a warning."""
    rng = np.random.default_rng(32)
    lo, hi = np.array(nominal.limits.lower), np.array(nominal.limits.upper)
    q = rng.uniform(lo, hi, (N, 4))
    q[:3, 1] = hi[1] + 0.05  # rows 1 .. 3: lines 2 .. 4
    p, _ = truth(q)
    csv, out = write_csv(tmp_path / "m.csv", q, p + rng.normal(0.0, NOISE, p.shape)), tmp_path / "c.urdf"
    argv = ["calibrate", *ROBOT, "--measurements", str(csv), "--out", str(out), "--folds", "0"]
    rc, _, err = run(argv, capsys)
    assert refused(rc, err, out) and "3 of 40 rows have readings outside the joint limits (line 2: joint2 = " in err
    assert "--allow-outside-limits" in err
    rc, stdout, err = run([*argv, "--allow-outside-limits"], capsys)
    assert rc == 0 and out.exists() and "residual after" in stdout
    assert err.startswith("warning: 3 of 40 rows have readings outside the joint limits"), err


def test_a_large_nominal_error_is_warned_about(tmp_path, capsys, data) -> None:
    """The measured target's 50 mm offset left out of the robot: calibrated (the tool offset is an error it
    identifies), with a warning naming the likely cause."""
    q, p, _, _ = data
    csv, out = write_csv(tmp_path / "m.csv", q, p), tmp_path / "c.urdf"
    rc, stdout, err = run(["calibrate", "--robot", "default", "--measurements", str(csv), "--out", str(out),
                           "--folds", "0", "--json"], capsys)  # fmt: skip
    doc = json.loads(stdout)
    assert rc == 0 and "warning: the nominal model misses the measured positions by" in err and "tool_x" in err, err
    assert doc["warnings"] and 0.5 <= doc["after"]["rms"] / NOISE <= 1.2
    assert abs(doc["parameters"][[x["name"] for x in doc["parameters"]].index("tool0.x")]["value"] - 0.05) < 2e-3


def test_cross_validation_holds_out_poses_not_rows(nominal, truth) -> None:
    """30 poses measured twice: both rows of a pose are held out together (one prediction for both)."""
    rng = np.random.default_rng(33)
    q = np.repeat(rng.uniform(nominal.limits.lower, nominal.limits.upper, (30, 4)), 2, axis=0)
    p = truth(q)[0] + rng.normal(0.0, NOISE, (60, 3))
    res = calibrate(nominal, Measurements(q, p))
    assert res.distinct == 30 and len(res.measurements) == 60
    predicted = res.cross_validation.residuals + p  # each row's held-out prediction
    assert np.abs(predicted[0::2] - predicted[1::2]).max() <= 1e-12  # one fit predicted both rows of a pose
    assert 0.8 <= res.cross_validation.held_out.rms / NOISE <= 1.5


# ------------------------------------------------------------------------------------------ issue 30, item 3
def test_three_rows_off_by_50_mm_are_left_out_by_default(tmp_path, capsys, nominal, data) -> None:
    q, p, fresh, p_fresh = data
    p = p.copy()
    bad = [5, 17, 30]
    p[bad, 0] += 0.05
    csv, out = write_csv(tmp_path / "m.csv", q, p, comment="three targets slipped"), tmp_path / "c.urdf"
    argv = ["calibrate", *ROBOT, "--measurements", str(csv), "--out", str(out), "--folds", "0"]
    rc, stdout, err = run(argv, capsys)
    lines = [i + 3 for i in bad]  # a comment line, the header, then row 0 on line 3
    assert rc == 0 and err == ""
    assert [int(x) for x in re.findall(r"outlier: line (\d+): 0.0(?:49|50)\d* m off", stdout)] == lines, stdout
    assert re.search(r"largest standardised residual: [\d.]+ at line \d+", stdout)
    assert model_error(out, fresh, p_fresh) <= NOISE < 1e-3 < model_error(nominal, fresh, p_fresh)
    # the linear loss keeps them: a worse model, and a warning naming the lines
    rc, stdout, err = run([*argv, "--loss", "linear"], capsys)
    assert rc == 0 and "outlier:" not in stdout
    assert err.startswith("warning: 3 row(s) are off by more than 5 robust standard deviations: "
                          + ", ".join(f"line {n} (" for n in lines[:1])), err  # fmt: skip
    assert all(f"line {n} (" in err for n in lines) and "the default loss (soft_l1) leaves them out" in err
    assert model_error(out, fresh, p_fresh) > 50 * NOISE


@pytest.mark.parametrize("column", [0, 4])  # q1 typed as 0, x typed as 0
def test_one_value_typed_as_zero_is_an_outlier_named_by_its_line(tmp_path, capsys, data, column) -> None:
    q, p, fresh, p_fresh = data
    table = np.column_stack([q, p])
    table[11, column] = 0.0
    csv, out = write_csv(tmp_path / "m.csv", table[:, :4], table[:, 4:]), tmp_path / "c.urdf"
    rc, stdout, err = run(["calibrate", *ROBOT, "--measurements", str(csv), "--out", str(out), "--folds", "0",
                           "--json"], capsys)  # fmt: skip
    doc = json.loads(stdout)
    assert rc == 0 and [o["where"] for o in doc["outliers"]] == ["line 13"]  # header on line 1, row 11 on 13
    assert doc["outliers"][0]["standardised"] > 100
    assert doc["largest_standardised"]["value"] < 5 and doc["largest_standardised"]["where"].startswith("line ")
    assert model_error(out, fresh, p_fresh) <= NOISE


def test_standardised_residual_is_the_leave_one_out_prediction_error(nominal, data) -> None:
    """The largest standardised residual against its definition through a refit without the row:
    ``r^T (I - H)^-1 r = r . e``, ``e`` the row's residual predicted by the fit without it."""
    q, p, _, _ = data
    p = p.copy()
    p[7] += [4e-5, -3e-5, 3e-5]  # a few sigmas off: the largest
    options = CalibrationOptions(folds=0, loss=Loss.LINEAR)
    res = calibrate(nominal, Measurements(q, p), options)
    big = res.largest_standardised
    assert big is not None and big.row == 7 and big.where == "row 8" and not res.outliers
    keep = np.arange(N) != 7
    without = calibrate(nominal, Measurements(q[keep], p[keep]), options)
    e = without.predict(q[7:8])[0] - p[7]
    r = res.residuals_after[7]
    assert math.sqrt(r @ e) / res.sigma == pytest.approx(big.standardised, rel=1e-3)
    assert 3.0 < big.standardised < 8.0


# ------------------------------------------------------------------------------------------ issue 31, item 7
def test_the_loop_without_a_tracker(tmp_path, capsys) -> None:
    """plan -> simulate (a perturbed copy) -> calibrate: the residual at the simulated noise level."""
    plan, measured, out = tmp_path / "plan.csv", tmp_path / "measured.csv", tmp_path / "c.urdf"
    assert run(["calibrate", *ROBOT, "--plan", "30", "--out", str(plan)], capsys)[0] == 0
    rc, stdout, _ = run(["calibrate", *ROBOT, "--simulate", str(plan), "--out", str(measured), "--seed", "4"], capsys)
    assert rc == 0 and f"wrote {measured}: calibrate it as a measured file" in stdout
    text = measured.read_text()
    assert "# scara-pin calibrate --simulate: robot 'default', every joint origin perturbed (seed 4" in text
    assert all(f"#   {j}: xyz " in text for j in ("base_link-base_fixed_joint", "joint1", "joint4",
                                                  "flange-tool0_fixed_joint"))  # fmt: skip
    rc, stdout, _ = run(["calibrate", *ROBOT, "--measurements", str(measured), "--out", str(out), "--json"], capsys)
    doc = json.loads(stdout)
    assert rc == 0 and doc["before"]["rms"] > 1e-4 and 0.5 <= doc["after"]["rms"] / 1e-5 <= 1.2
    # the plan is an input: never written over
    rc, _, err = run(["calibrate", *ROBOT, "--simulate", str(plan), "--out", str(plan)], capsys)
    assert rc == 2 and "is the file --simulate" in err and plan.read_text().startswith("# scara-pin calibrate")


def test_simulated_measurements_are_the_perturbed_copy_the_file_describes(tmp_path, nominal) -> None:
    """The errors simulate() reports, applied by this test's own edit and measured by yourdfpy, give the
    measurements to 1e-9 m without noise; their sizes are within the documented ranges; the noise is as asked."""
    import xml.etree.ElementTree as ET

    from scara_pin.calibration.simulate import simulate

    rng = np.random.default_rng(34)
    q = rng.uniform(nominal.limits.lower, nominal.limits.upper, (50, 4))
    exact = simulate(nominal, q, seed=7, noise=0.0, yaw=True)
    root = ET.fromstring(nominal.urdf)
    for j in root.findall("joint"):
        dp, w = exact.errors[j.get("name")]
        assert np.abs(dp).max() <= 1e-3 and np.abs(w[:2]).max() <= math.radians(0.1) < math.radians(0.5) and \
            abs(w[2]) <= math.radians(0.5)  # fmt: skip
        axis = j.find("axis")
        sign = float(axis.get("xyz").split()[2]) if axis is not None else 1.0  # the turn is about the joint's axis
        o = j.find("origin")
        o.set("xyz", " ".join(repr(float(v) + float(d)) for v, d in zip(o.get("xyz").split(), dp)))
        R = Rotation.from_euler("xyz", [float(v) for v in o.get("rpy", "0 0 0").split()])
        o.set("rpy", " ".join(repr(float(v)) for v in (R * Rotation.from_rotvec([w[0], w[1], sign * w[2]])).as_euler(
            "xyz")))  # fmt: skip
    p, yaw = Tracker(ET.tostring(root, encoding="unicode"), tmp_path)(q)
    assert np.abs(exact.measurements.position - p).max() <= 1e-9
    assert np.abs(exact.measurements.yaw - yaw).max() <= 1e-9
    assert np.array_equal(exact.measurements.q, q)
    noisy = simulate(nominal, np.repeat(q, 20, axis=0), seed=7, noise=1e-5)
    spread = noisy.measurements.position - np.repeat(p, 20, axis=0)
    assert 0.95e-5 <= spread.std() <= 1.05e-5 and abs(spread.mean()) <= 1e-6


def test_the_plot_names_rows_by_their_file_line_as_the_report_does(tmp_path, capsys, monkeypatch, data) -> None:
    import scara_pin.files as files

    figures = []
    monkeypatch.setattr(files, "save_figure", lambda fig, path, **kw: figures.append(fig) or Path(path))
    q, p, _, _ = data
    p = p.copy()
    p[[2, 9]] += 0.02
    csv = write_csv(tmp_path / "m.csv", q, p, comment="a comment\nand another")
    rc, stdout, _ = run(["calibrate", *ROBOT, "--measurements", str(csv), "--plot", str(tmp_path / "r.png"),
                         "--folds", "0"], capsys)  # fmt: skip
    assert rc == 0 and re.findall(r"outlier: (line \d+):", stdout) == ["line 6", "line 13"]  # 2 comments, header
    ax = figures[0].axes[0]
    assert "line in the measurement file" in ax.get_xlabel()
    red = [b for b in ax.patches if b.get_facecolor()[:3] == pytest.approx((0.839, 0.153, 0.157), abs=1e-3)]
    assert sorted(round(b.get_x() + b.get_width() / 2 - 0.2) for b in red) == [6, 13]
    grey = [b for b in ax.patches if b.get_facecolor()[:3] == pytest.approx((0.6, 0.6, 0.6), abs=1e-3)]
    assert sorted(round(b.get_x() + b.get_width() / 2 + 0.2) for b in grey) == list(range(4, 4 + N))
