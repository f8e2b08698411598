"""The ``scara-pin`` command line: outputs against closed forms, exit codes, one-line errors, atomic writes.

Closed forms (planar SCARA, q3 lowers the quill, tool0's z axis down):
    x = l1 cos q1 + l2 cos(q1 + q2),  y = l1 sin q1 + l2 sin(q1 + q2),  z = z0 - q3,  yaw = q1 + q2 + q4
with the documented numbers: default (S4) l1 = l2 = 0.2 m, z0 = -0.05 m; s1 l1 = 0.05, l2 = 0.15, z0 = d1 = 0.1.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from scara_pin import available_robots, generate_urdf, load_parameters
from scara_pin.cli import main

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "urdf" / "config"
GEOMETRY = {"default": (0.2, 0.2, -0.05), "s1": (0.05, 0.15, 0.1)}  # l1, l2, z0 [m]
LIMITS_DEG = {"default": (132, 150), "s1": (170, 150)}  # |q1|, |q2| limits [deg]
HEAVY = ("toppra", "matplotlib", "yourdfpy", "meshcat")
TIMEOUT = 60


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return rc, out, err


def assert_one_error_line(err: str) -> None:
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err


def wrap(angle: float) -> float:
    return math.remainder(angle, 2 * math.pi)


def closed_form_pose(robot: str, q: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """Position, yaw and the homogeneous matrix of tool0 in base [SI]."""
    l1, l2, z0 = GEOMETRY[robot]
    q1, q2, q3, q4 = q
    pos = np.array([l1 * math.cos(q1) + l2 * math.cos(q1 + q2), l1 * math.sin(q1) + l2 * math.sin(q1 + q2), z0 - q3])
    yaw = q1 + q2 + q4
    c, s = math.cos(yaw), math.sin(yaw)
    M = np.eye(4)
    M[:3, :3] = [[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]]  # Rz(yaw) Rx(pi): tool z down
    M[:3, 3] = pos
    return pos, yaw, M


def closed_form_task_jacobian(robot: str, q: np.ndarray) -> np.ndarray:
    l1, l2, _ = GEOMETRY[robot]
    q1, q2 = q[0], q[1]
    s1, c1, s12, c12 = math.sin(q1), math.cos(q1), math.sin(q1 + q2), math.cos(q1 + q2)
    return np.array(
        [
            [-l1 * s1 - l2 * s12, -l2 * s12, 0.0, 0.0],
            [l1 * c1 + l2 * c12, l2 * c12, 0.0, 0.0],
            [0.0, 0.0, -1.0, 0.0],
            [1.0, 1.0, 0.0, 1.0],
        ]
    )


def closed_form_world_jacobian(robot: str, q: np.ndarray) -> np.ndarray:
    """Pinocchio's WORLD Jacobian: the spatial velocity at the origin of base_link (base is above it on z).

    A revolute joint about +z through (px, py) gives v = p x z = (py, -px, 0), omega = z.
    """
    l1, _, _ = GEOMETRY[robot]
    pos, _, _ = closed_form_pose(robot, q)
    p2 = (l1 * math.cos(q[0]), l1 * math.sin(q[0]))
    return np.array(
        [
            [0.0, p2[1], 0.0, pos[1]],
            [0.0, -p2[0], 0.0, -pos[0]],
            [0.0, 0.0, -1.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0, 1.0],
        ]
    )


def random_qs(robot: str, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    a1, a2 = (math.radians(v) for v in LIMITS_DEG[robot])
    return np.column_stack(
        [rng.uniform(-a1, a1, n), rng.uniform(-a2, a2, n), rng.uniform(0.0, 0.09, n), rng.uniform(-3.0, 3.0, n)]
    )


def fk_json(capsys: pytest.CaptureFixture[str], argv: list[str]) -> dict:
    rc, out, err = run(capsys, argv)
    assert rc == 0, err
    assert err == ""
    data = json.loads(out)  # the whole of stdout is one JSON document
    assert isinstance(data, dict)
    return data


# ------------------------------------------------------------------------------------------------- fk
def test_fk_json_against_closed_form(capsys: pytest.CaptureFixture[str]) -> None:
    data = fk_json(capsys, ["fk", "--json", "0.1", "0.2", "0.05", "0.3"])
    assert {"q", "position", "yaw", "matrix"} <= data.keys()
    q = np.array([0.1, 0.2, 0.05, 0.3])
    pos, yaw, M = closed_form_pose("default", q)
    assert data["q"] == pytest.approx(q.tolist(), abs=1e-15)
    assert data["position"] == pytest.approx(pos.tolist(), abs=1e-12)
    assert data["yaw"] == pytest.approx(yaw, abs=1e-12)
    assert np.array(data["matrix"]) == pytest.approx(M, abs=1e-12)
    assert data["units"] == {"length": "m", "angle": "rad"}


@pytest.mark.parametrize("robot", ["default", "s1"])
def test_fk_random_poses_against_closed_form(robot: str, capsys: pytest.CaptureFixture[str]) -> None:
    for q in random_qs(robot, 6, seed=7):
        data = fk_json(capsys, ["fk", "--json", "--robot", robot, "--", *(repr(float(v)) for v in q)])
        pos, yaw, M = closed_form_pose(robot, q)
        assert data["position"] == pytest.approx(pos.tolist(), abs=1e-12)
        assert wrap(data["yaw"] - yaw) == pytest.approx(0.0, abs=1e-12)
        assert np.array(data["matrix"]) == pytest.approx(M, abs=1e-12)


@pytest.mark.parametrize(
    ("flags", "argv_q", "q_si"),
    [
        (["--deg", "--mm"], ["90", "0", "10", "0"], [math.pi / 2, 0.0, 0.010, 0.0]),
        (["--deg", "--mm"], ["30", "-45", "25.5", "100"], [*map(math.radians, (30, -45)), 0.0255, math.radians(100)]),
        (["--units", "deg,m"], ["30", "-45", "0.0255", "100"],
         [*map(math.radians, (30, -45)), 0.0255, math.radians(100)]),
        (["--units", "mm,rad"], ["0.5", "-0.8", "25.5", "1.7"], [0.5, -0.8, 0.0255, 1.7]),
        (["--units", "mm"], ["0.5", "-0.8", "25.5", "1.7"], [0.5, -0.8, 0.0255, 1.7]),
    ],
)
def test_fk_units(flags: list[str], argv_q: list[str], q_si: list[float], capsys: pytest.CaptureFixture[str]) -> None:
    # --deg/--mm scale the inputs; JSON is always SI (docs/cli.md: "--json output is always SI")
    data = fk_json(capsys, ["fk", "--json", *flags, "--", *argv_q])
    pos, yaw, M = closed_form_pose("default", np.array(q_si))
    assert data["units"] == {"length": "m", "angle": "rad"}
    assert data["q"] == pytest.approx(q_si, rel=1e-12, abs=1e-12)
    assert data["position"] == pytest.approx(pos.tolist(), abs=1e-12)
    assert data["yaw"] == pytest.approx(yaw, abs=1e-12)
    matrix = np.array(data["matrix"])
    assert matrix == pytest.approx(M, abs=1e-12)


def test_fk_deg_mm_quarter_turn(capsys: pytest.CaptureFixture[str]) -> None:
    data = fk_json(capsys, ["fk", "--deg", "--mm", "--json", "90", "0", "10", "0"])
    assert data["position"] == pytest.approx([0.0, 0.4, -0.06], abs=1e-12)  # JSON: SI
    assert data["yaw"] == pytest.approx(math.pi / 2, abs=1e-12)
    rc, out, _ = run(capsys, ["fk", "--deg", "--mm", "90", "0", "10", "0"])  # text: the user's units
    line = next(ln for ln in out.splitlines() if ln.startswith("position"))
    assert rc == 0 and line.endswith("[mm]")
    assert [float(v) for v in line.split("[")[1].split("]")[0].split(",")] == pytest.approx([0, 400, -60], abs=1e-9)


def test_fk_text_output(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["fk", "0.1", "0.2", "0.05", "0.3"])
    assert rc == 0 and err == ""
    lines = {line.split()[0]: line for line in out.splitlines() if line.strip()}
    position = [float(v) for v in lines["position"].split("[")[1].split("]")[0].split(",")]
    pos, yaw, _ = closed_form_pose("default", np.array([0.1, 0.2, 0.05, 0.3]))
    assert position == pytest.approx(pos.tolist(), rel=1e-8)
    assert float(lines["yaw"].split()[1]) == pytest.approx(yaw, rel=1e-8)


def test_fk_set_override(capsys: pytest.CaptureFixture[str]) -> None:
    data = fk_json(capsys, ["fk", "--json", "--set", "l1=0.25", "--set", "l2=0.1", "0", "0", "0", "0"])
    assert data["position"] == pytest.approx([0.35, 0.0, -0.05], abs=1e-12)


def test_fk_on_a_urdf_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(generate_urdf("s1"), encoding="utf-8")
    q = np.array([0.4, -1.0, 0.02, 0.5])
    data = fk_json(capsys, ["fk", "--json", "--urdf", str(path), "--", *map(str, q)])
    pos, yaw, _ = closed_form_pose("s1", q)
    assert data["position"] == pytest.approx(pos.tolist(), abs=1e-12)
    assert data["yaw"] == pytest.approx(yaw, abs=1e-12)


def test_fk_with_a_config_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "wide"
    shutil.copytree(CONFIG / "default", folder)
    kin = folder / "kinematics.yaml"
    kin.write_text(kin.read_text(encoding="utf-8").replace("l2: 0.200", "l2: 0.300"), encoding="utf-8")
    data = fk_json(capsys, ["fk", "--json", "--robot", str(folder), "0", "0", "0", "0"])
    assert data["robot"] == "wide"
    assert data["position"] == pytest.approx([0.5, 0.0, -0.05], abs=1e-12)


# ------------------------------------------------------------------------------------------- jacobian
def test_jacobian_json_task(capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.1, 0.2, 0.05, 0.3])
    data = fk_json(capsys, ["jacobian", "--json", *map(str, q)])
    assert data["rows"] == ["x", "y", "z", "yaw"]
    assert data["units"] == {"length": "m", "angle": "rad"}
    assert np.array(data["jacobian"]) == pytest.approx(closed_form_task_jacobian("default", q), abs=1e-12)
    l1, l2, _ = GEOMETRY["default"]
    assert data["manipulability"] == pytest.approx(l1 * l2 * abs(math.sin(q[1])), abs=1e-12)


@pytest.mark.parametrize("robot", ["default", "s1"])
def test_jacobian_random_against_closed_form(robot: str, capsys: pytest.CaptureFixture[str]) -> None:
    for q in random_qs(robot, 4, seed=11):
        data = fk_json(capsys, ["jacobian", "--json", "--robot", robot, "--", *(repr(float(v)) for v in q)])
        assert np.array(data["jacobian"]) == pytest.approx(closed_form_task_jacobian(robot, q), abs=1e-12)


def test_jacobian_units(capsys: pytest.CaptureFixture[str]) -> None:
    q_si = np.array([math.radians(30), math.radians(60), 0.02, math.radians(-10)])
    data = fk_json(capsys, ["jacobian", "--json", "--deg", "--mm", "30", "60", "20", "-10"])
    assert data["units"] == {"length": "m", "angle": "rad"}  # JSON: SI, whatever --deg/--mm
    J = closed_form_task_jacobian("default", q_si)
    assert np.array(data["jacobian"]) == pytest.approx(J, abs=1e-12)
    assert data["jacobian"][2][2] == pytest.approx(-1.0, abs=1e-12)
    assert data["jacobian"][3] == pytest.approx([1.0, 1.0, 0.0, 1.0], abs=1e-12)
    l1, l2, _ = GEOMETRY["default"]
    assert data["manipulability"] == pytest.approx(l1 * l2 * math.sin(math.radians(60)), abs=1e-12)  # SI


@pytest.mark.parametrize("robot", ["default", "s1"])
def test_jacobian_world_reference(robot: str, capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.3, -0.9, 0.04, 1.2])
    data = fk_json(capsys, ["jacobian", "--json", "--robot", robot, "--reference", "world", "--", *map(str, q)])
    assert data["rows"] == ["vx", "vy", "vz", "wx", "wy", "wz"]
    J = np.array(data["jacobian"])
    assert J.shape == (6, 4)
    assert J == pytest.approx(closed_form_world_jacobian(robot, q), abs=1e-12)


@pytest.mark.parametrize("reference", ["local", "local_world_aligned"])
def test_jacobian_other_references_have_six_rows(reference: str, capsys: pytest.CaptureFixture[str]) -> None:
    q = np.array([0.3, -0.9, 0.04, 1.2])
    data = fk_json(capsys, ["jacobian", "--json", "--reference", reference, "--", *map(str, q)])
    J = np.array(data["jacobian"])
    assert J.shape == (6, 4)
    if reference == "local_world_aligned":  # tool point velocity in world axes = the task rows x, y, z
        assert J[:3] == pytest.approx(closed_form_task_jacobian("default", q)[:3], abs=1e-12)
    # every column's angular part is a unit vector (the 3 revolute joints) or zero (the quill)
    assert np.linalg.norm(J[3:], axis=0) == pytest.approx([1.0, 1.0, 0.0, 1.0], abs=1e-12)


def test_jacobian_text_output(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["jacobian", "0", "1.0", "0", "0"])
    assert rc == 0 and err == ""
    rows = {line.split()[0]: line.split()[1:] for line in out.splitlines() if line.split()}
    assert rows["z"][0] == "[m]" and rows["yaw"][0] == "[rad]"  # each row names its unit
    assert [float(v) for v in rows["z"][1:]] == [0.0, 0.0, -1.0, 0.0]
    assert [float(v) for v in rows["yaw"][1:]] == [1.0, 1.0, 0.0, 1.0]


# ------------------------------------------------------------------------------------ errors and codes
def _malformed(tmp_path: Path) -> str:
    path = tmp_path / "bad.urdf"
    path.write_text('<robot name="r">\n  <link name="a">\n</robot>\n', encoding="utf-8")
    return str(path)


ERRORS = [
    pytest.param(["fk", "0", "0"], "q", id="two-values"),
    pytest.param(["fk", "0", "0", "0", "0", "0"], "q", id="five-values"),
    pytest.param(["fk", "--json"], "q", id="no-values"),
    pytest.param(["fk", "abc", "0", "0", "0"], "q1", id="abc"),
    pytest.param(["fk", "0", "0", "0", "0x1"], "q4", id="hex"),
    pytest.param(["fk", "nan", "0", "0", "0"], "q1", id="nan"),
    pytest.param(["fk", "0", "inf", "0", "0"], "q2", id="inf"),
    pytest.param(["fk", "0", "0", "1e999", "0"], "q3", id="overflow"),
    pytest.param(["fk", "--", "-inf", "0", "0", "0"], "q1", id="-inf"),
    pytest.param(["jacobian", "0", "NaN", "0", "0"], "q2", id="jacobian-nan"),
    pytest.param(["fk", "--robot", "nope", "0", "0", "0", "0"], "nope", id="unknown-robot"),
    pytest.param(["jacobian", "--robot", "nope", "0", "0", "0", "0"], "nope", id="jacobian-unknown-robot"),
    pytest.param(["fk", "--set", "foo=1", "0", "0", "0", "0"], "foo", id="unknown-set-key"),
    pytest.param(["fk", "--set", "l1=-1", "0", "0", "0", "0"], "l1", id="negative-l1"),
    pytest.param(["fk", "--set", "l1=0", "0", "0", "0", "0"], "l1", id="zero-l1"),
    pytest.param(["fk", "--set", "l1=nan", "0", "0", "0", "0"], "l1", id="nan-l1"),
    pytest.param(["fk", "--set", "l1=abc", "0", "0", "0", "0"], "l1", id="text-l1"),
    pytest.param(["fk", "--set", "l1=", "0", "0", "0", "0"], "l1", id="empty-l1"),
    pytest.param(["fk", "--set", "l1=${__import__('os').getcwd()}", "0", "0", "0", "0"], "l1", id="inject-l1"),
    pytest.param(["fk", "--set", "joint1_lower=3", "0", "0", "0", "0"], "joint1_lower", id="lower>upper"),
    pytest.param(["fk", "--set", "l1", "0", "0", "0", "0"], "l1", id="set-without-equals"),
    pytest.param(["fk", "--set", "=1", "0", "0", "0", "0"], "=1", id="set-without-key"),
    pytest.param(["bogus"], "bogus", id="unknown-command"),
    pytest.param(["fk", "--bogus", "0", "0", "0", "0"], "--bogus", id="unknown-option"),
    pytest.param(["jacobian", "--reference", "bogus", "0", "0", "0", "0"], "bogus", id="bad-reference"),
    pytest.param(["jacobian", "--reference", "world", "--frame", "nope", "0", "0", "0", "0"], "nope", id="bad-frame"),
    pytest.param(["fk", "--urdf", "{missing}", "0", "0", "0", "0"], "missing.urdf", id="urdf-missing"),
    pytest.param(["fk", "--urdf", "{malformed}", "0", "0", "0", "0"], "line 3", id="urdf-malformed"),
    pytest.param(["fk", "--urdf", "{malformed}", "--set", "l1=0.3", "0", "0", "0", "0"], "overrides", id="urdf+set"),
    pytest.param(["urdf", "--prefix", "a b"], "prefix", id="bad-prefix"),
    pytest.param(["urdf", "--prefix", "${x}"], "prefix", id="inject-prefix"),
    pytest.param(["urdf", "--robot", "nope"], "nope", id="urdf-unknown-robot"),
    pytest.param(["urdf", "--set", "l2=-0.2"], "l2", id="urdf-bad-set"),
]


@pytest.mark.parametrize(("argv", "needle"), ERRORS)
def test_invalid_input_exits_2_with_one_error_line(
    argv: list[str], needle: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    subst = {"{missing}": str(tmp_path / "missing.urdf"), "{malformed}": _malformed(tmp_path)}
    argv = [subst.get(a, a) for a in argv]
    rc, out, err = run(capsys, argv)
    assert rc == 2
    assert out == ""
    assert_one_error_line(err)
    assert needle in err


def test_config_folder_yaml_error_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "broken"
    shutil.copytree(CONFIG / "default", folder)
    limits = folder / "joint_limits.yaml"
    limits.write_text(limits.read_text(encoding="utf-8").replace("upper: !degrees 132", "upper: [1, 2", 1))
    rc, out, err = run(capsys, ["fk", "--robot", str(folder), "0", "0", "0", "0"])
    assert rc == 2 and out == ""
    assert_one_error_line(err)  # yaml's multi-line report folded into one line
    assert "joint_limits.yaml" in err


def test_no_command_exits_2(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, [])
    assert rc == 2
    assert out == ""
    assert err.strip()


def test_no_command_is_one_error_line(capsys: pytest.CaptureFixture[str]) -> None:
    rc, _, err = run(capsys, [])
    assert rc == 2
    assert_one_error_line(err)


def test_q_outside_limits_warns(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["fk", "--json", "3", "0", "0", "0"])  # joint1 limit is 132 deg = 2.30 rad
    assert rc == 0
    assert json.loads(out)["position"] == pytest.approx(closed_form_pose("default", np.array([3, 0, 0, 0]))[0].tolist())
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning:") and "joint1" in lines[0]


def test_each_joint_outside_limits_warns(capsys: pytest.CaptureFixture[str]) -> None:
    rc, _, err = run(capsys, ["fk", "--deg", "--mm", "--", "-140", "151", "-60", "361"])  # stroke -50..100 mm
    assert rc == 0
    lines = err.splitlines()
    assert len(lines) == 4 and all(line.startswith("warning:") for line in lines)
    for joint, line in zip(("joint1", "joint2", "joint3", "joint4"), lines):
        assert joint in line


def test_q_on_the_limit_is_inside(capsys: pytest.CaptureFixture[str]) -> None:
    limit = repr(math.radians(132))
    rc, _, err = run(capsys, ["fk", "--strict", "--", limit, "0", "-0.05", "0"])
    assert rc == 0 and err == ""
    rc, _, err = run(capsys, ["fk", "--strict", "--", "-" + limit, "0", "0.1", "0"])
    assert rc == 0 and err == ""


@pytest.mark.parametrize("command", ["fk", "jacobian"])
def test_strict_refuses_q_outside_limits(command: str, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, [command, "--strict", "--json", "0", "0", "0.2", "0"])  # stroke is 0.150 m
    assert rc == 3
    assert out == ""
    assert_one_error_line(err)
    assert "joint3" in err


def test_negative_exponent_notation_is_a_number(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["fk", "--json", "-1e-3", "0", "0", "0"])
    assert rc == 0, err
    pos, _, _ = closed_form_pose("default", np.array([-1e-3, 0, 0, 0]))
    assert json.loads(out)["position"] == pytest.approx(pos.tolist(), abs=1e-12)


def test_huge_q_is_refused_without_python_warnings(capsys: pytest.CaptureFixture[str]) -> None:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rc, _, err = run(capsys, ["fk", "0", "1e200", "0", "0"])
    assert rc in (2, 3)
    assert [str(w.message) for w in caught] == []


@pytest.mark.parametrize("flag", ["--version", "--help"])
def test_version_and_help_return(flag: str, capsys: pytest.CaptureFixture[str]) -> None:
    try:
        rc = main([flag])
    except SystemExit as exc:
        pytest.fail(f"main([{flag!r}]) raised SystemExit({exc.code}) instead of returning")
    assert rc == 0
    assert capsys.readouterr().out.strip()


# ----------------------------------------------------------------------------------------- commands
def test_the_command_map_is_what_the_modules_register() -> None:
    """scara_pin.cli.COMMANDS (main imports only the module of the command it runs) against each module's own
    register(): every command is mapped to the module that registers it, and nothing else is mapped."""
    import importlib

    from scara_pin.cli import COMMANDS

    class Recorder:
        def __init__(self) -> None:
            self.names: list[str] = []

        def add_parser(self, name: str, **kwargs: object) -> object:
            self.names.append(name)
            return argparse.ArgumentParser().add_subparsers().add_parser(name)

    registered = {}
    for module in sorted(set(COMMANDS.values())):
        rec = Recorder()
        importlib.import_module(f"scara_pin.cli.{module}").register(rec)
        registered.update({name: module for name in rec.names})
    assert registered == COMMANDS
    modules = {p.stem for p in (REPO / "scara_pin" / "cli").glob("*.py") if not p.stem.startswith("_")}
    assert modules == set(COMMANDS.values())  # a new command module is in the map


# ----------------------------------------------------------------------------------------- robots
def test_robots_lists_default_and_s1(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["robots"])
    assert rc == 0 and err == ""
    head, *lines = out.splitlines()
    assert head.split() == ["robot", "kind", "reach", "[mm]", "stroke", "[mm]", "payload", "[kg]"]
    rows = {line.split()[0]: line.split() for line in lines if line.split() and line.split()[0] in available_robots()}
    names = list(rows)
    assert {"default", "s1"} <= set(names)
    assert names == sorted(names)
    data = fk_json(capsys, ["robots", "--json"])
    assert data["robots"] == names
    assert Path(data["config_dir"]).resolve() == CONFIG.resolve()
    # the default robot's figures from its yaml, by the closed forms (issue 31 item 8): reach l1 + l2 and
    # |l1 + l2 e^(i q2max)|, stroke the quill's range, payload effort3 / g - the quill's and flange's masses
    p = load_parameters("default").values
    r_min = math.hypot(p["l1"] + p["l2"] * math.cos(p["joint2_upper"]), p["l2"] * math.sin(p["joint2_upper"]))
    payload = p["joint3_effort"] / 9.81 - p["quill_mass"] - p["flange_mass"]
    stroke = p["joint3_upper"] - p["joint3_lower"]
    assert rows["default"][1:] == ["scara", f"{r_min * 1e3:.0f}", "-", f"{(p['l1'] + p['l2']) * 1e3:.0f}",
                                   f"{stroke * 1e3:.0f}", f"{payload:.2f}"]  # fmt: skip
    facts = {f["name"]: f for f in data["facts"]}
    assert facts["default"]["payload"] == pytest.approx(payload, rel=1e-12)
    assert facts["default"]["reach"] == pytest.approx([r_min, p["l1"] + p["l2"]], abs=1e-12)


# ------------------------------------------------------------------------------------------- urdf
def _joint2_x(urdf: str) -> float:
    root = ET.fromstring(urdf)
    return float(root.find("joint[@name='joint2']/origin").get("xyz").split()[0])


def test_urdf_to_stdout(capsys: pytest.CaptureFixture[str]) -> None:
    rc, out, err = run(capsys, ["urdf", "--robot", "s1", "--set", "l1=0.25"])
    assert rc == 0 and err == ""
    root = ET.fromstring(out)
    assert root.tag == "robot" and root.get("name") == "s1"
    assert _joint2_x(out) == pytest.approx(0.25, abs=1e-15)


def test_urdf_output_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "scara.urdf"
    rc, out, err = run(capsys, ["urdf", "-o", str(target), "--prefix", "left_"])
    assert rc == 0 and out == ""
    assert not err.startswith("error")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scara.urdf"]  # no temporary file left over
    root = ET.fromstring(target.read_text(encoding="utf-8"))
    assert root.get("name") == "default"
    assert root.find("joint[@name='left_joint1']") is not None


def test_urdf_output_replaces_an_existing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "scara.urdf"
    target.write_text("OLD", encoding="utf-8")
    rc, _, _ = run(capsys, ["urdf", "-o", str(target), "--set", "l1=0.3"])
    assert rc == 0
    assert _joint2_x(target.read_text(encoding="utf-8")) == pytest.approx(0.3, abs=1e-15)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scara.urdf"]


def test_urdf_output_relative_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    rc, _, _ = run(capsys, ["urdf", "-o", "here.urdf"])
    assert rc == 0
    assert ET.fromstring((tmp_path / "here.urdf").read_text(encoding="utf-8")).tag == "robot"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["here.urdf"]


def test_urdf_output_into_missing_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "nonexistent" / "dir" / "x.urdf"
    rc, out, err = run(capsys, ["urdf", "-o", str(target)])
    assert rc == 2 and out == ""
    assert_one_error_line(err)
    assert not target.exists() and not target.parent.exists()
    assert list(tmp_path.iterdir()) == []


def test_urdf_output_into_slash_nonexistent(capsys: pytest.CaptureFixture[str]) -> None:
    if Path("/nonexistent").exists():
        pytest.skip("/nonexistent exists on this machine")
    rc, _, err = run(capsys, ["urdf", "-o", "/nonexistent/dir/x.urdf"])
    assert rc == 2
    assert_one_error_line(err)
    assert not Path("/nonexistent/dir/x.urdf").exists()


def test_urdf_output_onto_a_folder_is_invalid_input(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "out").mkdir()
    rc, _, err = run(capsys, ["urdf", "-o", str(tmp_path / "out")])
    assert rc == 2
    assert "internal error" not in err


def _fail_replace(*args, **kwargs):
    raise OSError(28, "No space left on device")


@pytest.mark.parametrize(
    ("failure", "code"),
    [("replace", 2), ("write", 2), ("interrupt", 130)],
)
def test_urdf_output_failure_keeps_the_old_file(
    failure: str, code: int, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "scara.urdf"
    target.write_text("OLD CONTENT", encoding="utf-8")
    if failure == "replace":
        monkeypatch.setattr(os, "replace", _fail_replace)
    else:
        exc = OSError(28, "No space left on device") if failure == "write" else KeyboardInterrupt()
        real_write_text = Path.write_text

        def half_write(self: Path, text: str, *args: object, **kwargs: object) -> int:
            real_write_text(self, text[: len(text) // 2], *args, **kwargs)  # type: ignore[arg-type]
            raise exc

        monkeypatch.setattr(Path, "write_text", half_write)
    rc, out, err = run(capsys, ["urdf", "-o", str(target)])
    monkeypatch.undo()
    assert rc == code
    assert out == ""
    assert_one_error_line(err)
    assert target.read_text(encoding="utf-8") == "OLD CONTENT"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scara.urdf"]


# --------------------------------------------------------------------------- real processes
@pytest.mark.parametrize(
    "argv",
    [["fk", "0", "0", "0", "0"], ["jacobian", "0", "0.5", "0", "0"], ["ik", "0.3", "0.1", "-0.07", "0.2"]],
    ids=lambda argv: argv[0],
)
def test_startup_does_not_import_heavy_packages(argv: list[str]) -> None:
    code = (
        "import sys\n"
        "from scara_pin.cli import main\n"
        f"rc = main({argv!r})\n"
        f"heavy = sorted(m for m in sys.modules if m.split('.')[0] in {set(HEAVY)!r})\n"
        "print('RESULT', rc, heavy)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=TIMEOUT, cwd=REPO, check=False
    )
    assert proc.returncode == 0, proc.stderr
    result = [line for line in proc.stdout.splitlines() if line.startswith("RESULT")]
    assert result == ["RESULT 0 []"], proc.stdout


def _console_script() -> str:
    script = shutil.which("scara-pin", path=str(Path(sys.executable).parent))
    if script is None:
        pytest.skip("the scara-pin console script is not installed next to this Python")
    return script


def test_console_script_fk() -> None:
    proc = subprocess.run(
        [_console_script(), "fk", "--json", "0.1", "0.2", "0.05", "0.3"],
        capture_output=True, text=True, timeout=TIMEOUT, check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert proc.stderr == ""
    data = json.loads(proc.stdout)
    pos, yaw, _ = closed_form_pose("default", np.array([0.1, 0.2, 0.05, 0.3]))
    assert data["position"] == pytest.approx(pos.tolist(), abs=1e-12)
    assert data["yaw"] == pytest.approx(yaw, abs=1e-12)


def test_console_script_error_and_version() -> None:
    script = _console_script()
    proc = subprocess.run([script, "fk", "abc", "0", "0", "0"], capture_output=True, text=True, timeout=TIMEOUT)
    assert proc.returncode == 2 and proc.stdout == ""
    assert_one_error_line(proc.stderr)
    assert "Traceback" not in proc.stderr
    proc = subprocess.run([script, "--version"], capture_output=True, text=True, timeout=TIMEOUT)
    assert proc.returncode == 0
    assert proc.stdout.startswith("scara-pin ")


def test_parser_of_one_command_is_the_full_parsers() -> None:
    """main() builds only the command it runs (start-up): that parser is, option for option, the full one's."""
    from scara_pin.cli import build_parser

    def options(parser: argparse.ArgumentParser) -> list[tuple]:
        return [(a.dest, tuple(a.option_strings), a.nargs, a.default, a.required,
                 getattr(a.type, "__qualname__", a.type), a.help) for a in parser._actions]  # fmt: skip

    full = build_parser()
    commands = full._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    assert len(commands) >= 13
    for name, sub in commands.items():
        one = build_parser(name)._subparsers._group_actions[0].choices  # type: ignore[union-attr]
        assert list(one) == [name]
        assert options(one[name]) == options(sub), name
        assert one[name].get_default("func") is sub.get_default("func")
    everything = build_parser("no-such-command")._subparsers._group_actions[0].choices  # type: ignore[union-attr]
    assert list(everything) == list(commands)  # argparse then names the choices
