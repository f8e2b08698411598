"""The `scara-pin traj` command: S1 reproduction end to end, outputs, and its errors and exit codes."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from scara_pin.cli import main


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open(newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


def test_s1_quintic_from_the_command_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out_csv, png = tmp_path / "s1.csv", tmp_path / "s1.png"
    rc, out, err = run(capsys, ["traj", "--robot", "s1", "--deg", "--mm", "--from", "0", "0", "0", "0",
                                "--to", "90", "60", "50", "-180", "--duration", "5",
                                "--out", str(out_csv), "--plot", str(png), "--rate", "1000"])  # fmt: skip
    assert rc == 0, err
    header, data = read_csv(out_csv)
    assert header[:5] == ["t", "q1", "q2", "q3", "q4"]
    t, q, qd, qdd = data[:, 0], data[:, 1:5], data[:, 5:9], data[:, 9:13]
    dq = np.array([math.pi / 2, math.pi / 3, 0.05, -math.pi])
    T = 5.0
    assert len(t) == 5001 and t[-1] == pytest.approx(T, abs=1e-12)
    # S1 with MATLAB's jtraj: q(t) = q0 + dq (10 x^3 - 15 x^4 + 6 x^5), written here independently
    x = t / T
    expected = np.outer(10 * x**3 - 15 * x**4 + 6 * x**5, dq)
    assert np.abs(q - expected).max() < 1e-12
    assert np.abs(qd).max(axis=0) == pytest.approx(1.875 * np.abs(dq) / T, rel=1e-9)
    # the acceleration peak lies between samples: the 1 kHz grid gets within 1e-5 of it
    assert np.abs(qdd).max(axis=0) == pytest.approx(10 / math.sqrt(3) * np.abs(dq) / T**2, rel=1e-5)
    assert np.abs(q[0]).max() == 0 and np.abs(qd[[0, -1]]).max() < 1e-12 and np.abs(qdd[[0, -1]]).max() < 1e-12
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_time_optimal_json_respects_the_limits(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["traj", "--json", "--from", "0.2", "0.5", "0", "0", "--via", "0", "1", "0.02", "1",
                                "--to", "-0.5", "1.5", "0.05", "2"])  # fmt: skip
    assert rc == 0, err
    doc = json.loads(out)
    ratios = doc["limit_ratios"]
    assert max(ratios["velocity"], ratios["acceleration"]) <= 1 + 1e-6
    assert max(ratios["velocity"], ratios["acceleration"]) > 0.99  # time-optimal: some limit is active
    samples = doc["samples"]
    qd = np.array(samples["qd"])
    vmax = np.array([math.radians(420), math.radians(720), 1.1, math.radians(1700)])  # default joint_limits.yaml
    assert (np.abs(qd) <= vmax * (1 + 1e-6)).all()


def test_linear_move_stays_on_the_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    import scara_pin as sp

    out_csv = tmp_path / "line.csv"
    a, b = np.array([0.3, 0.1, -0.1, 0.5]), np.array([0.25, -0.15, -0.05, 0.0])
    rc, _, err = run(capsys, ["traj", "--linear", "--from-pose", *map(str, a), "--to-pose", *map(str, b),
                              "--out", str(out_csv)])  # fmt: skip
    assert rc == 0, err
    _, data = read_csv(out_csv)
    robot = sp.load_robot("default")
    worst = 0.0
    for q in data[::10, 1:5]:
        p = robot.tool_pose(q)[:3]
        d = p - a[:3]
        u = (b - a)[:3] / np.linalg.norm((b - a)[:3])
        worst = max(worst, float(np.linalg.norm(d - (d @ u) * u)))
    assert worst < 1e-9


@pytest.mark.parametrize(
    ("argv", "code", "words"),
    [
        (["--from", "0", "0", "0", "0", "--from-pose", "0.3", "0", "0", "0", "--to", "0", "1", "0", "0"], 2, "either"),
        (["--from", "0", "0", "0", "0"], 2, "--to"),
        (["--from", "0", "0", "0", "0", "--to", "0", "1", "0", "0", "--duration", "-1"], 2, "duration"),
        (["--from", "0", "0", "0", "0", "--to", "0", "1", "0", "0", "--duration", "1", "--optimal"], 2, "exclude"),
        (["--from", "0", "0", "0", "0", "--to", "0", "9", "0", "0"], 3, "joint2"),
        (["--from", "0", "0", "0", "0", "--to", "0", "1", "0", "abc"], 2, "number"),
        (["--from", "0.2", "0.5", "0", "0", "--to", "-0.5", "1.5", "0.05", "2", "--duration", "0.1", "--strict"],
         3, "exceeds"),
        (["--linear", "--from-pose", "0.3", "0.1", "-0.1", "0", "--to-pose", "0.7", "0.1", "-0.1", "0"], 3, ""),
        (["--from", "0", "0", "0", "0", "--to", "0", "1", "0", "0", "--out", "/nonexistent/x.csv"], 2, "cannot"),
    ],
)
def test_errors_and_exit_codes(capsys: pytest.CaptureFixture[str], argv: list[str], code: int, words: str) -> None:
    rc, out, err = run(capsys, ["traj", *argv])
    assert rc == code, err
    lines = [ln for ln in err.splitlines() if ln.startswith("error:")]
    assert len(lines) == 1 and words in lines[0]


def test_too_short_duration_warns_but_computes(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["traj", "--from", "0.2", "0.5", "0", "0", "--to", "-0.5", "1.5", "0.05", "2",
                                "--duration", "0.1"])  # fmt: skip
    assert rc == 0
    assert err.startswith("warning:") and "exceeds a limit" in err


def test_setpoints_in_motor_steps(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    sp_csv = tmp_path / "sp.csv"
    rc, _, err = run(capsys, ["traj", "--from", "0.2", "0.5", "0", "0", "--to", "-0.5", "1.5", "0.05", "2",
                              "--setpoints", str(sp_csv), "--setpoint-rate", "250", "--delays", "0", "0.004", "0.008",
                              "0.012", "--gear", "50", "50", "1", "10", "--steps-per-rev", "3200", "3200", "3200",
                              "3200", "--screw-lead", "0.02"])  # fmt: skip
    assert rc == 0, err
    header, data = read_csv(sp_csv)
    assert header == ["t", "q1", "q2", "q3", "q4", "steps1", "steps2", "steps3", "steps4"]
    assert np.allclose(np.diff(data[:, 0]), 1 / 250)
    counts = np.array([50 * 3200 / (2 * math.pi), 50 * 3200 / (2 * math.pi), 3200 / 0.02, 10 * 3200 / (2 * math.pi)])
    steps = data[:, 5:9]
    assert (steps == np.round(steps)).all()
    assert np.abs(steps - data[:, 1:5] * counts).max() <= 0.5 + 1e-9  # absolute rounding: no drift


def test_json_out_says_the_motions_duration_and_view_plays_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                                              ) -> None:  # fmt: skip
    """`traj --out x.json` records the motion's duration (the one the summary prints), not the end of the
    sample grid; `view --traj x.json` reads it; a file naming a duration outside its last interval is one
    error line (exit 2)."""
    out = tmp_path / "t.json"
    rc, summary, err = run(capsys, ["traj", "--from", "0", "0", "0", "0", "--to", "1", "1", "0.05", "1", "--duration",
                                    "1.2345", "--rate", "10", "--out", str(out), "--json"])  # fmt: skip
    assert rc == 0, err
    data = json.loads(out.read_text())
    assert data["duration"] == json.loads(summary)["duration"] == 1.2345
    assert data["t"][-1] == pytest.approx(1.3, abs=1e-15)
    html = tmp_path / "t.html"
    rc, printed, err = run(capsys, ["view", "--traj", str(out), "--html", str(html)])
    assert rc == 0 and html.is_file(), err
    data["duration"] = 1.05  # before the last interval [1.2, 1.3]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    rc, printed, err = run(capsys, ["view", "--traj", str(bad), "--html", str(tmp_path / "bad.html")])
    assert rc == 2 and printed == "" and len(err.splitlines()) == 1 and "last interval" in err
    assert not (tmp_path / "bad.html").exists()
    data["duration"] = 1.2345
    data["q"] = [row[:3] for row in data["q"]]
    data["qd"] = [row[:3] for row in data["qd"]]
    data["qdd"] = [row[:3] for row in data["qdd"]]
    bad.write_text(json.dumps(data))
    rc, printed, err = run(capsys, ["view", "--traj", str(bad), "--html", str(tmp_path / "bad.html")])
    assert rc == 2 and "3 joints" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("field", ["duration", "t"])
@pytest.mark.parametrize("number", ["1" + "0" * 400, "1" + "0" * 5000], ids=["beyond float", "beyond int digits"])
def test_json_trajectory_with_a_huge_integer_is_one_error_line(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                               field: str, number: str) -> None:  # fmt: skip
    """An integer beyond float's range (OverflowError) or of more digits than Python converts (ValueError) in a
    trajectory file is bad input (exit 2, one line), never an internal error."""
    out = tmp_path / "t.json"
    rc, _, err = run(capsys, ["traj", "--from", "0", "0", "0", "0", "--to", "1", "1", "0.05", "1", "--duration", "1",
                              "--rate", "10", "--out", str(out)])  # fmt: skip
    assert rc == 0, err
    text = out.read_text()
    if field == "duration":
        text = text.replace('"duration": 1.0', f'"duration": {number}', 1)
    else:
        text = text.replace('"t": [0.0,', f'"t": [{number},', 1)
    assert number in text
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    rc, printed, err = run(capsys, ["view", "--traj", str(bad), "--html", str(tmp_path / "bad.html")])
    assert rc == 2 and printed == "" and len(err.splitlines()) == 1 and err.startswith("error:"), err
    assert "internal error" not in err
