"""The ``ik`` and ``validate-ik`` commands (scara_pin.cli), called as ``main(argv)`` and in a subprocess.

Every returned configuration is checked against forward kinematics computed here, two ways: the S4 closed
form of the ``default`` robot (l1 = l2 = 0.200 m, z = -0.050 m - q3, yaw = q1 + q2 + q4) and Pinocchio's
FK (``robot.tool_pose``); tolerance 1e-9 m / rad. Branch labels are checked against the sign of sin(q2)
(right: the elbow turns counterclockwise seen from above). Exit codes: 0 ok, 2 invalid input, 3 infeasible.
"""

from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from scara_pin import Robot, load_robot
from scara_pin.cli import main

REPO = Path(__file__).resolve().parents[1]
POSE_TOL = 1e-9
TWO_PI = 2.0 * math.pi
TIMEOUT = 120
HEAVY = ("toppra", "matplotlib", "yourdfpy", "meshcat")


def wrap(a: float) -> float:
    return (a + math.pi) % TWO_PI - math.pi


def s4_pose(q: np.ndarray) -> np.ndarray:
    """The default robot's tool pose, closed form (source S4)."""
    q1, q2, q3, q4 = q
    return np.array([0.2 * math.cos(q1) + 0.2 * math.cos(q1 + q2), 0.2 * math.sin(q1) + 0.2 * math.sin(q1 + q2),
                     -0.05 - q3, wrap(q1 + q2 + q4)])  # fmt: skip


def s4_solutions(target: np.ndarray) -> list[np.ndarray]:
    """Every solution of the default robot (J1 +/-132, J2 +/-150, J4 +/-360 deg), by the law of cosines."""
    x, y, z, yaw = target
    c2 = (x * x + y * y - 0.08) / 0.08
    lim = [(math.radians(-132), math.radians(132)), (math.radians(-150), math.radians(150)), None,
           (-TWO_PI, TWO_PI)]  # fmt: skip
    out = []
    for sign in (1.0, -1.0):
        q2 = sign * math.acos(c2)
        q1 = math.atan2(y, x) - math.atan2(0.2 * math.sin(q2), 0.2 + 0.2 * math.cos(q2))
        if not (lim[0][0] <= q1 <= lim[0][1] and lim[1][0] <= q2 <= lim[1][1]):
            continue
        for k in range(-3, 4):
            q4 = yaw - q1 - q2 + k * TWO_PI
            if lim[3][0] <= q4 <= lim[3][1]:
                out.append(np.array([q1, q2, -0.05 - z, q4]))
    return out


def pose_error(pose: np.ndarray, target: np.ndarray) -> float:
    e = np.asarray(pose, dtype=float) - np.asarray(target, dtype=float)
    e[3] = wrap(e[3])
    return float(np.abs(e).max())


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


@pytest.fixture(scope="module")
def default() -> Robot:
    return load_robot("default")


Q = np.array([0.4, 1.1, 0.03, -0.7])  # a generic configuration of the default robot


def argv_pose(pose: np.ndarray) -> list[str]:
    return [repr(float(v)) for v in pose]


# ============================================================================== one target
def test_ik_json_lists_every_solution(default: Robot, capsys: pytest.CaptureFixture[str]) -> None:
    target = s4_pose(Q)
    rc, out, err = run(capsys, ["ik", *argv_pose(target), "--json", "--all-turns"])
    assert rc == 0 and err == ""
    data = json.loads(out)
    assert {"target", "solutions", "status", "message"} <= set(data)
    assert data["status"] == "OK"
    assert [data["target"][k] for k in ("x", "y", "z", "yaw")] == pytest.approx(target.tolist(), abs=1e-15)
    # q1, q2 in range and q4 in +/-360 deg: per elbow 2 J4 turns (q4 + 2 pi k)
    assert len(data["solutions"]) == 4
    expected = s4_solutions(target)
    assert len(expected) == 4
    for e in expected:
        assert min(np.abs(np.array(s["q"]) - e).max() for s in data["solutions"]) <= 1e-9
    for sol in data["solutions"]:
        assert set(sol) == {"q", "branch", "turns"}
        q = np.array(sol["q"])
        assert pose_error(s4_pose(q), target) <= POSE_TOL
        assert pose_error(default.tool_pose(q), target) <= POSE_TOL
        assert sol["branch"] == ("right" if math.sin(q[1]) > 0 else "left")
    assert {s["branch"] for s in data["solutions"]} == {"right", "left"}
    assert min(np.abs(np.array(s["q"]) - Q).max() for s in data["solutions"]) <= 1e-9


def test_ik_text_mode(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["ik", *argv_pose(s4_pose(Q)), "--all-turns"])
    assert rc == 0 and err == ""
    rows = [line.split(None, 1) for line in out.splitlines() if line.startswith(("right", "left"))]
    assert len(rows) == 4
    for _label, values in rows:
        q = np.array([float(v) for v in values.strip("[] ").split(",")])
        assert pose_error(s4_pose(q), s4_pose(Q)) <= 1e-7  # text prints 9 significant digits


@pytest.mark.parametrize("branch", ["left", "right"])
def test_ik_branch_filter(branch: str, capsys: pytest.CaptureFixture[str]) -> None:
    target = s4_pose(Q)
    rc, out, _ = run(capsys, ["ik", *argv_pose(target), "--json", "--branch", branch, "--all-turns"])
    assert rc == 0
    sols = json.loads(out)["solutions"]
    assert len(sols) == 2
    for sol in sols:
        q = np.array(sol["q"])
        assert sol["branch"] == branch
        assert (math.sin(q[1]) > 0) == (branch == "right")
        assert pose_error(s4_pose(q), target) <= POSE_TOL


def test_ik_near_returns_only_the_nearest(capsys: pytest.CaptureFixture[str]) -> None:
    target = s4_pose(Q)
    every = s4_solutions(target)
    assert len(every) == 4
    for ref in ([0, 0, 0, 0], [1.0, -1.0, 0.0, 5.0], [-2.0, 2.0, 0.05, -5.0]):
        rc, out, _ = run(capsys, ["ik", *argv_pose(target), "--json", "--near", *map(str, ref)])
        assert rc == 0
        sols = json.loads(out)["solutions"]
        assert len(sols) == 1
        got = np.array(sols[0]["q"])
        best = min(every, key=lambda q: float(((q - np.array(ref)) ** 2).sum()))
        assert np.abs(got - best).max() <= 1e-9
        assert pose_error(s4_pose(got), target) <= POSE_TOL


def test_ik_degrees_and_millimetres(capsys: pytest.CaptureFixture[str]) -> None:
    target = s4_pose(Q)
    args = [repr(float(target[i] * 1000)) for i in range(3)] + [repr(math.degrees(target[3]))]
    rc, out, _ = run(capsys, ["ik", *args, "--deg", "--mm", "--json", "--all-turns"])
    assert rc == 0
    data = json.loads(out)  # --deg/--mm scale the inputs; JSON is always SI
    assert data["units"] == {"length": "m", "angle": "rad"}
    assert data["target"]["x"] == pytest.approx(target[0], abs=1e-12)
    assert data["target"]["yaw"] == pytest.approx(target[3], abs=1e-12)
    assert len(data["solutions"]) == 4
    for sol in data["solutions"]:
        assert pose_error(s4_pose(np.array(sol["q"])), target) <= POSE_TOL
    assert min(abs(s["q"][2] - 0.03) for s in data["solutions"]) <= 1e-12  # q3 = 0.03 m = 30 mm
    rc, out, _ = run(capsys, ["ik", *args, "--deg", "--mm"])  # the text output is in the user's units
    assert rc == 0 and "[deg, deg, mm, deg]" in out


def test_ik_unreachable_json_exit_3(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["ik", "1.0", "0", "-0.05", "0", "--json"])
    assert rc == 3
    data = json.loads(out)
    assert data["status"] == "OUT_OF_REACH" and data["solutions"] == []
    assert "1" in data["message"] and "0.4" in data["message"]


@pytest.mark.parametrize(
    ("target", "status"),
    [(["1.0", "0", "-0.05", "0"], "OUT_OF_REACH"), (["-0.3", "0", "-0.05", "0"], "J1_LIMIT"),
     (["0.3", "0", "0.01", "0"], "J3_STROKE")],
)  # fmt: skip
def test_ik_unreachable_text_is_one_error_line(
    target: list[str], status: str, capsys: pytest.CaptureFixture[str]
) -> None:
    rc, out, err = run(capsys, ["ik", *target])
    assert rc == 3
    assert out == ""
    assert status in one_error_line(err)


@pytest.mark.parametrize(
    "argv",
    [["ik", "0.3", "0.1", "-0.07"], ["ik", "abc", "0.1", "-0.07", "0"], ["ik", "0.3", "nan", "-0.07", "0"],
     ["ik", "0.3", "0.1", "inf", "0"], ["ik", "0.3", "0.1", "-0.07", "0", "1"], ["ik"],
     ["ik", "0.3", "0.1", "-0.07", "0", "--branch", "up"], ["ik", "0.3", "0.1", "-0.07", "0", "--near", "0", "0"],
     ["ik", "0.3", "0.1", "-0.07", "0", "--near", "0", "0", "x", "0"],
     ["ik", "0.3", "0.1", "-0.07", "0", "--output", "never.csv"]],
    ids=["3_numbers", "abc", "nan", "inf", "5_numbers", "none", "bad_branch", "short_near", "bad_near", "output_alone"],
)  # fmt: skip
def test_ik_bad_input_exits_2(argv: list[str], capsys: pytest.CaptureFixture[str], tmp_path: Path,
                              monkeypatch: pytest.MonkeyPatch) -> None:  # fmt: skip
    monkeypatch.chdir(tmp_path)
    rc, out, err = run(capsys, argv)
    assert rc == 2
    assert out == ""
    one_error_line(err)
    assert list(tmp_path.iterdir()) == []


def test_ik_numeric(default: Robot, capsys: pytest.CaptureFixture[str]) -> None:
    target = s4_pose(Q)
    rc, out, _ = run(capsys, ["ik", *argv_pose(target), "--numeric", "--json"])
    assert rc == 0
    data = json.loads(out)
    assert data["status"] == "OK" and data["method"] == "numeric" and len(data["solutions"]) == 1
    q = np.array(data["solutions"][0]["q"])
    assert pose_error(s4_pose(q), target) <= POSE_TOL
    assert pose_error(default.tool_pose(q), target) <= POSE_TOL
    assert data["solutions"][0]["branch"] == ("right" if math.sin(q[1]) > 0 else "left")
    lo, hi = np.array(default.limits.lower), np.array(default.limits.upper)
    assert np.all(q >= lo) and np.all(q <= hi)


def test_ik_numeric_unreachable_exits_3(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["ik", "1.0", "0", "-0.05", "0", "--numeric", "--json"])
    assert rc == 3
    data = json.loads(out)
    assert data["status"] != "OK" and data["solutions"] == []
    assert "residual" in data["message"]


def test_ik_with_set_overrides(capsys: pytest.CaptureFixture[str]) -> None:
    """--set l1=0.3: the reach grows to 0.5 m; a target at 0.45 m becomes reachable."""
    assert run(capsys, ["ik", "0.45", "0", "-0.05", "0"])[0] == 3
    rc, out, _ = run(capsys, ["ik", "0.45", "0", "-0.05", "0", "--set", "l1=0.3", "--json"])
    assert rc == 0
    for sol in json.loads(out)["solutions"]:
        q1, q2, q3, q4 = sol["q"]
        x = 0.3 * math.cos(q1) + 0.2 * math.cos(q1 + q2)
        y = 0.3 * math.sin(q1) + 0.2 * math.sin(q1 + q2)
        assert abs(x - 0.45) <= POSE_TOL and abs(y) <= POSE_TOL


# ============================================================================== batch CSV
def write_targets(path: Path, rows: list[list[float | str]], header: str = "x,y,z,yaw") -> None:
    path.write_text(header + "\n" + "".join(",".join(str(v) for v in r) + "\n" for r in rows), encoding="utf-8")


def read_rows(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with path.open(newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        return list(reader.fieldnames or []), list(reader)


def _targets(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = np.array([-2.2, -2.5, -0.05, -6.0]), np.array([2.2, 2.5, 0.1, 6.0])
    return np.array([s4_pose(q) for q in rng.uniform(lo, hi, size=(n, 4))])


def test_batch_all_reachable_exits_0(default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    T = _targets(200, seed=31)
    src, dst = tmp_path / "targets.csv", tmp_path / "joints.csv"
    write_targets(src, [[repr(float(v)) for v in t] for t in T])
    rc, out, err = run(capsys, ["ik", "--input", str(src), "--output", str(dst)])
    assert rc == 0, err
    header, rows = read_rows(dst)
    assert header == ["x", "y", "z", "yaw", "q1", "q2", "q3", "q4", "branch", "status"]
    assert len(rows) == len(T)
    for t, row in zip(T, rows):
        assert [float(row[k]) for k in ("x", "y", "z", "yaw")] == t.tolist()
        assert row["status"] == "OK" and row["branch"] in ("right", "left")
        q = np.array([float(row[f"q{i}"]) for i in range(1, 5)])
        assert pose_error(s4_pose(q), t) <= POSE_TOL
        assert pose_error(default.tool_pose(q), t) <= POSE_TOL
        assert row["branch"] == ("right" if math.sin(q[1]) > 0 else "left")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["joints.csv", "targets.csv"]


def test_batch_with_failures_exits_3(default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    T = _targets(20, seed=37).tolist()
    bad = {3: ([1.0, 0.0, -0.05, 0.0], "OUT_OF_REACH"), 7: ([0.3, 0.0, 0.01, 0.0], "J3_STROKE"),
           11: ([-0.3, 0.0, -0.05, 0.0], "J1_LIMIT"), 15: ([0.01, 0.0, -0.05, 0.0], "INSIDE_INNER_LIMIT")}  # fmt: skip
    for i, (t, _) in bad.items():
        T.insert(i, t)
    src, dst = tmp_path / "targets.csv", tmp_path / "joints.csv"
    write_targets(src, [[repr(float(v)) for v in t] for t in T])
    rc, _, err = run(capsys, ["ik", "--input", str(src), "--output", str(dst), "--branch", "left"])
    assert rc == 3
    _, rows = read_rows(dst)
    assert len(rows) == len(T)
    failed = sum(row["status"] != "OK" for row in rows)
    assert failed >= len(bad) and f"{failed} without solution" in err
    for i, (t, row) in enumerate(zip(T, rows)):
        if i in bad:
            assert row["status"] == bad[i][1]
            assert [row[f"q{j}"] for j in range(1, 5)] == ["", "", "", ""] and row["branch"] == ""
            continue
        if row["status"] != "OK":  # the left elbow may be cut off by J1: then it says which limit
            assert row["status"] == "J1_LIMIT"
            continue
        q = np.array([float(row[f"q{j}"]) for j in range(1, 5)])
        assert row["branch"] == "left" and math.sin(q[1]) < 0
        assert pose_error(default.tool_pose(q), np.array(t)) <= POSE_TOL


def test_batch_near_and_units(default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    T = _targets(50, seed=41)
    src, dst = tmp_path / "t.csv", tmp_path / "q.csv"
    write_targets(src, [[repr(float(v * 1000)) for v in t[:3]] + [repr(math.degrees(t[3]))] for t in T])
    ref_deg = [10.0, 20.0, 0.0, 0.0]
    rc, _, _ = run(capsys, ["ik", "--input", str(src), "--output", str(dst), "--deg", "--mm",
                            "--near", *map(str, ref_deg)])  # fmt: skip
    assert rc == 0
    _, rows = read_rows(dst)
    ref = np.array([math.radians(10.0), math.radians(20.0), 0.0, 0.0])
    geo_ok = 0
    for t, row in zip(T, rows):
        qd = [float(row[f"q{j}"]) for j in range(1, 5)]
        q = np.array([math.radians(qd[0]), math.radians(qd[1]), qd[2] / 1000, math.radians(qd[3])])
        assert pose_error(s4_pose(q), t) <= POSE_TOL
        # the nearest solution to the reference, among every solution enumerated here
        every = s4_solutions(t)
        best = min(float(((s - ref) ** 2).sum()) for s in every)
        assert float(((q - ref) ** 2).sum()) <= best + 1e-9
        geo_ok += 1
    assert geo_ok == 50


@pytest.mark.parametrize(
    ("content", "needle"),
    [("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n0.3,abc,-0.07,0.2\n", "line 3"),
     ("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n0.3,0.1,-0.07\n", "line 3"),
     ("x,y,z,yaw\n0.3,0.1,nan,0.2\n", "line 2"),
     ("a,b,c,d\n0.3,0.1,-0.07,0.2\n", "header"),
     ("", "header")],
    ids=["abc", "three_values", "nan", "bad_header", "empty"],
)  # fmt: skip
def test_batch_malformed_input_exits_2_without_output(
    content: str, needle: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src, dst = tmp_path / "targets.csv", tmp_path / "joints.csv"
    src.write_text(content, encoding="utf-8")
    rc, out, err = run(capsys, ["ik", "--input", str(src), "--output", str(dst)])
    assert rc == 2
    assert needle in one_error_line(err)
    assert not dst.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["targets.csv"]  # no temporary file left behind


def test_batch_malformed_input_keeps_an_existing_output(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src, dst = tmp_path / "targets.csv", tmp_path / "joints.csv"
    dst.write_text("OLD", encoding="utf-8")
    src.write_text("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n1,2,three,4\n", encoding="utf-8")
    assert run(capsys, ["ik", "--input", str(src), "--output", str(dst)])[0] == 2
    assert dst.read_text(encoding="utf-8") == "OLD"


def test_batch_argument_errors_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    src, dst = tmp_path / "targets.csv", tmp_path / "o.csv"
    src.write_text("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n", encoding="utf-8")
    for argv in (["ik", "--input", str(src)],  # no --output
                 ["ik", "0.3", "0.1", "-0.07", "0.2", "--input", str(src), "--output", str(dst)]):  # fmt: skip
        rc, _, err = run(capsys, argv)
        assert rc == 2, argv
        one_error_line(err)
        assert not dst.exists()


def test_batch_missing_input_file_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, _, err = run(capsys, ["ik", "--input", str(tmp_path / "nope.csv"), "--output", str(tmp_path / "o.csv")])
    assert rc == 2
    one_error_line(err)
    assert not (tmp_path / "o.csv").exists()


# ============================================================================== validate-ik
def test_validate_ik_command_passes(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["validate-ik", "--samples", "200", "--robot", "s1"])
    assert rc == 0, out + err
    assert "PASS" in out and "FAIL" not in out


def test_validate_ik_command_json(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, _ = run(capsys, ["validate-ik", "--samples", "50", "--seed", "3", "--json"])
    assert rc == 0
    data = json.loads(out)
    assert data["ok"] is True and data["samples"] == 50 and data["seed"] == 3 and data["solutions"] >= 50


@pytest.mark.parametrize("samples", ["0", "-5", "abc"])
def test_validate_ik_bad_samples_exit_2(samples: str, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["validate-ik", "--samples", samples])
    assert rc == 2 and out == ""
    one_error_line(err)


# ============================================================================== no heavy imports
def test_ik_does_not_import_heavy_packages(tmp_path: Path) -> None:
    """After main(['ik', ...]) none of toppra, matplotlib, yourdfpy, meshcat is in sys.modules.

    Stub modules of those names are put first on the path so that every one of them is importable in the
    subprocess (the check would see an import even of a package that is not installed here).
    """
    stubs = tmp_path / "stubs"
    stubs.mkdir()
    for name in HEAVY:
        (stubs / name).mkdir()
        (stubs / name / "__init__.py").write_text("", encoding="utf-8")
    src = tmp_path / "t.csv"
    src.write_text("x,y,z,yaw\n0.3,0.1,-0.07,0.2\n", encoding="utf-8")
    runs = [["ik", "0.3", "0.1", "-0.07", "0.2"], ["ik", "0.3", "0.1", "-0.07", "0.2", "--numeric", "--json"],
            ["ik", "--input", str(src), "--output", str(tmp_path / "o.csv")]]  # fmt: skip
    code = textwrap.dedent(f"""
        import importlib.util, sys
        from scara_pin.cli import main
        found = [m for m in {HEAVY!r} if importlib.util.find_spec(m) is None]
        codes = [main(argv) for argv in {runs!r}]
        heavy = sorted(m for m in sys.modules if m.split('.')[0] in {set(HEAVY)!r})
        print('RESULT', codes, heavy, found)
    """)
    env = {"PYTHONPATH": str(stubs), "PATH": "/usr/bin:/bin"}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=TIMEOUT, cwd=REPO,
                          env=env, check=False)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    result = [line for line in proc.stdout.splitlines() if line.startswith("RESULT")]
    assert result == ["RESULT [0, 0, 0] [] []"], proc.stdout + proc.stderr


def test_near_outside_the_limits_is_used_with_a_warning(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    """A --near joint outside its limits (50 typed for a 0.05 m quill, say) is still a reference: the nearest
    solution is returned, and one warning names the joint (single target and batch)."""
    target = s4_pose(Q)
    rc, out, err = run(capsys, ["ik", *argv_pose(target), "--json", "--near", "0", "0", "50", "0"])
    assert rc == 0
    warnings = [line for line in err.splitlines() if line.startswith("warning:")]
    assert len(warnings) == 1 and "--near" in warnings[0] and "joint3 = 50" in warnings[0]
    got = np.array(json.loads(out)["solutions"][0]["q"])
    ref = np.array([0.0, 0.0, 50.0, 0.0])
    best = min(s4_solutions(target), key=lambda q: float(((q - ref) ** 2).sum()))
    assert np.abs(got - best).max() <= 1e-9
    rc, out, err = run(capsys, ["ik", *argv_pose(target), "--near", "0", "0", "0.02", "0"])
    assert rc == 0 and "warning" not in err  # inside the limits: no warning
    targets = tmp_path / "t.csv"
    targets.write_text("x,y,z,yaw\n" + ",".join(map(repr, target.tolist())) + "\n")
    rc, out, err = run(capsys, ["ik", "--input", str(targets), "--output", str(tmp_path / "q.csv"), "--near", "0", "0",
                                "50", "0"])  # fmt: skip
    assert rc == 0 and sum("--near" in line and line.startswith("warning:") for line in err.splitlines()) == 1
