"""Issue 30, "inputs that lie": the fuzz round's rows that broke, kept as tests (items 1, 4, 7, 8, 10 here;
the torque of the jump (6) and the tool-speed sizing (9): tests/test_jump.py; the cache (5):
tests/test_description_cache.py; the yaml loader itself: tests/test_yaml_units.py).

- 1: a yaml alias bomb (520 bytes, 9^9 values) in every yaml file the tool reads: a points file (``traj``,
  ``cycle``, ``teach``), a robot's config folder, a D-H table, a yaml file a user's xacro loads. Each is run
  in a subprocess under the limits of tests/test_hostile.py (3 GB, 60 s): exit 2, one ``error:`` line naming
  the file, the line and the cap, within seconds (it hung, growing 20 MB/s).
- 4: an output that is an input (or another output, or a bad plot name) is refused BEFORE any work, through
  every command that writes: exit 2, the input's bytes unchanged, no output written.
- 7: numbers in a points file follow the command line's grammar (hex, binary, ``_``, base 60 refused; a
  5000-digit integer is exit 2 naming the point).
- 8: a point outside the limits, or beyond the number range, is named with its file (never as ``--from``).
- 10: ``--lock J=0.5 --lock J=-0.5`` (and ``--set`` twice) is refused naming the joint.
"""

from __future__ import annotations

import json
import re
import shutil
from collections.abc import Callable
from pathlib import Path

import pytest
from test_hostile import assert_one_error, cli

from scara_pin.cli import main

REPO = Path(__file__).resolve().parents[1]
CONFIG = REPO / "urdf" / "config" / "default"


def bomb() -> str:
    """The issue's 520-byte alias bomb, as a flow list: 9 strings, then 8 levels of 9 aliases each (9^9)."""
    text = "[&a [" + ", ".join(['"lol"'] * 9) + "]"
    for prev, name in zip("abcdefgh", "bcdefghi"):
        text += f", &{name} [" + ", ".join([f"*{prev}"] * 9) + "]"
    return text + "]"


# --------------------------------------------------------------------------------------------- 1: yaml bombs
POINTS_OK = "points:\n- name: P1\n  q: [0.3, 0.9, 0.02, -0.5]\n- name: P2\n  q: [0.5, 0.7, 0.02, -0.2]\n"


def _points_with_bomb(where: str) -> str:
    b = bomb()
    if where == "q":
        return POINTS_OK.replace("[0.3, 0.9, 0.02, -0.5]", b)
    if where == "pose":
        return POINTS_OK.replace("  q: [0.3, 0.9, 0.02, -0.5]\n", f"  q: [0.3, 0.9, 0.02, -0.5]\n  pose: {b}\n")
    if where == "name":
        return POINTS_OK.replace("name: P1", f"name: {b}")
    return f"format: {b}\n" + POINTS_OK


def _config_with_bomb(tmp: Path) -> None:
    folder = tmp / "arm"
    shutil.copytree(CONFIG, folder)
    with (folder / "kinematics.yaml").open("a") as handle:
        handle.write(f"extra: {bomb()}\n")


def _xacro_with_bomb(tmp: Path) -> None:
    (tmp / "b.yaml").write_text(f"v: {bomb()}\n")
    (tmp / "r.urdf.xacro").write_text(
        '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        "  <xacro:property name=\"p\" value=\"${xacro.load_yaml('b.yaml')}\"/>\n"
        "  <link name=\"base\"/>\n  <link name=\"l_${p['v']}\"/>\n</robot>\n"
    )


BOMBS: list[tuple[str, list[str], Callable[[Path], None]]] = [
    *((f"traj-points-{w}", ["traj", "--points", "{tmp}/p.yaml", "--through", "P1", "P2"],
       lambda tmp, w=w: (tmp / "p.yaml").write_text(_points_with_bomb(w))) for w in ("q", "pose", "name", "format")),
    ("cycle-points", ["cycle", "--points", "{tmp}/p.yaml", "--from-point", "P1", "--to-point", "P2"],
     lambda tmp: (tmp / "p.yaml").write_text(_points_with_bomb("q"))),
    ("teach-points", ["teach", "--points", "{tmp}/p.yaml", "--port", "0"],
     lambda tmp: (tmp / "p.yaml").write_text(_points_with_bomb("q"))),
    ("fk-config-folder", ["fk", "--robot", "{tmp}/arm", "0", "0", "0", "0"], _config_with_bomb),
    ("urdf-dh", ["urdf", "--dh", "{tmp}/t.yaml"], lambda tmp: (tmp / "t.yaml").write_text(f"name: {bomb()}\n")),
    ("fk-xacro-load-yaml", ["fk", "--urdf", "{tmp}/r.urdf.xacro", "0", "0", "0", "0"], _xacro_with_bomb),
]  # fmt: skip


@pytest.mark.parametrize(("args", "make"), [b[1:] for b in BOMBS], ids=[b[0] for b in BOMBS])
def test_a_yaml_alias_bomb_is_refused_at_once(args: list[str], make: Callable[[Path], None], tmp_path: Path) -> None:
    make(tmp_path)
    done = cli([a.replace("{tmp}", str(tmp_path)) for a in args], cwd=tmp_path, timeout=60)
    assert_one_error(done, 2)
    assert "more than 500,000 values" in done.err and re.search(r"line \d", done.err) and "cap" in done.err, done.err
    assert done.seconds < 20


# ------------------------------------------------------------------------------- 4: outputs that destroy inputs
def _plan(tmp: Path) -> Path:
    """A measurement file (the poses of a plan, at their nominal positions)."""
    path = tmp / "m.csv"
    assert main(["calibrate", "--plan", "20", "--out", str(path)]) == 0
    return path


def _cfg(tmp: Path) -> Path:
    folder = tmp / "arm"
    shutil.copytree(CONFIG, folder)
    return folder


MOVE = ["--from", "0", "0.1", "0", "0", "--to", "0.5", "0.6", "0.02", "0.3"]
OUTPUTS = [
    # (id, argv with {tmp}, the files to make first, words of the error, files that must keep their bytes)
    ("calibrate-out-is-measurements", ["calibrate", "--measurements", "{tmp}/m.csv", "--out", "{tmp}/m.csv"],
     "--out {tmp}/m.csv is the file --measurements"),
    ("calibrate-overlay-is-measurements-link",
     ["calibrate", "--measurements", "{tmp}/m.csv", "--overlay", "{tmp}/link.csv"],
     "--overlay {tmp}/link.csv is the file"),
    ("calibrate-out-and-overlay-one-file",
     ["calibrate", "--measurements", "{tmp}/m.csv", "--out", "{tmp}/x", "--overlay", "{tmp}/x"], "are the same file"),
    ("calibrate-bad-plot-name-first",
     ["calibrate", "--measurements", "{tmp}/m.csv", "--out", "{tmp}/c.urdf", "--overlay", "{tmp}/o.yaml", "--plot",
      "{tmp}/p.xyz"], "a plot is written as"),
    ("calibrate-out-is-robot-yaml", ["calibrate", "--robot", "{tmp}/arm", "--measurements", "{tmp}/m.csv", "--out",
                                     "{tmp}/arm/kinematics.yaml"], "is the file --robot"),
    ("traj-out-is-points", ["traj", "--points", "{tmp}/p.yaml", "--through", "P1", "P2", "--out", "{tmp}/p.yaml"],
     "--out {tmp}/p.yaml is the file --points"),
    ("traj-setpoints-is-urdf", ["traj", "--urdf", "{tmp}/r.urdf", "--acceleration", "10", "10", "1", "10", *MOVE,
                                "--setpoints", "{tmp}/r.urdf"], "--setpoints {tmp}/r.urdf is the file --urdf"),
    ("traj-out-and-setpoints-one-file", ["traj", *MOVE, "--out", "{tmp}/t.csv", "--setpoints", "{tmp}/./t.csv"],
     "are the same file"),
    ("cycle-out-is-points", ["cycle", "--points", "{tmp}/p.yaml", "--from-point", "P1", "--to-point", "P2", "--out",
                             "{tmp}/hard.yaml"], "is the file --points"),
    ("cycle-bad-plot-name-first", ["cycle", "--out", "{tmp}/c.csv", "--plot", "{tmp}/c.txt"], "a plot is written as"),
    ("jog-out-and-plot-one-file", ["jog", "--from", "0", "0.5", "0.02", "0", "--direction", "1", "0", "--out",
                                   "{tmp}/j.png", "--plot", "{tmp}/j.png"], "are the same file"),
    ("view-html-is-traj", ["view", "--traj", "{tmp}/t0.csv", "--html", "{tmp}/t0.csv"], "is the file --traj"),
    ("workspace-plot-is-urdf", ["workspace", "--urdf", "{tmp}/r.png", "--plot", "{tmp}/r.png"], "is the file --urdf"),
    ("ik-output-is-input", ["ik", "--input", "{tmp}/in.csv", "--output", "{tmp}/in.csv"],
     "--output {tmp}/in.csv is the file --input"),
    ("urdf-output-is-dh", ["urdf", "--dh", "{tmp}/t.yaml", "-o", "{tmp}/t.yaml"], "is the file --dh"),
    ("urdf-output-is-robot-yaml", ["urdf", "--robot", "{tmp}/arm", "-o", "{tmp}/arm/joint_limits.yaml"],
     "is the file --robot"),
]  # fmt: skip


@pytest.mark.parametrize(("args", "words"), [o[1:] for o in OUTPUTS], ids=[o[0] for o in OUTPUTS])
def test_an_output_never_destroys_an_input(args: list[str], words: str, tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    measurements = _plan(tmp_path)
    (tmp_path / "link.csv").symlink_to(measurements)
    (tmp_path / "p.yaml").write_text(POINTS_OK)
    (tmp_path / "hard.yaml").hardlink_to(tmp_path / "p.yaml")
    _cfg(tmp_path)
    assert main(["urdf", "-o", str(tmp_path / "r.urdf")]) == 0
    shutil.copy(tmp_path / "r.urdf", tmp_path / "r.png")
    assert main(["traj", *MOVE, "--out", str(tmp_path / "t0.csv")]) == 0
    (tmp_path / "in.csv").write_text("x,y,z,yaw\n0.3,0.1,-0.08,0\n")
    shutil.copy(REPO / "urdf" / "examples" / "s1_dh.yaml", tmp_path / "t.yaml")
    before = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    capsys.readouterr()
    assert main([a.replace("{tmp}", str(tmp_path)) for a in args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and words.replace("{tmp}", str(tmp_path)) in err, err
    after = {p: p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert after == before  # every input intact, and no output written (not even the valid ones)


def test_the_shared_check_in_the_library(tmp_path: Path) -> None:
    """scara_pin.files.check_outputs (what every command calls), and the batch IK writer that calls it too."""
    from scara_pin import load_robot
    from scara_pin.errors import InvalidInputError
    from scara_pin.files import check_outputs
    from scara_pin.kinematics.batch_io import solve_csv

    data = tmp_path / "d.csv"
    data.write_text("x,y,z,yaw\n0.3,0.1,-0.08,0\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "up").symlink_to(tmp_path)
    check_outputs({"--out": tmp_path / "new.csv", "--plot": tmp_path / "new.png", "--json-out": "-"},
                  {"--in": [data]}, figures=("--plot",))  # fmt: skip
    for outputs, inputs, words in [
        ({"--out": tmp_path / "sub" / "up" / "d.csv"}, {"--in": [data]}, "is the file --in"),  # through a link
        ({"--a": tmp_path / "x", "--b": tmp_path / "sub" / ".." / "x"}, {}, "are the same file"),
        ({"--a": "-", "--b": "-"}, {}, "--a and --b would print on standard output"),
        ({"--plot": tmp_path / "p.jpg"}, {}, "a plot is written as"),
    ]:
        with pytest.raises(InvalidInputError, match=words):
            check_outputs(outputs, inputs, figures=("--plot",))
    with pytest.raises(InvalidInputError, match="is the file source"):
        solve_csv(load_robot("default"), data, data)
    assert data.read_text() == "x,y,z,yaw\n0.3,0.1,-0.08,0\n"


# ------------------------------------------------------------------------------------ 7, 8: numbers and names
@pytest.mark.parametrize(
    ("value", "code", "words"),
    [
        ("0x1", 2, "'0x1': not a plain number"),
        ("0b0", 2, "'0b0': not a plain number"),
        ("0_1", 2, "'0_1': not a plain number"),
        ("0:0.5", 2, "'0:0.5': not a plain number"),
        ("1" * 5000, 2, "infinite or beyond the float range"),
        ("1" * 300, 2, "must be within +/-1e+06"),  # the number range: named with the point, never as --from q1
        ("2.9", 3, "point P1 is outside the joint limits: joint1 = 2.9"),
    ],
    ids=["hex", "binary", "underscore", "base-60", "5000-digits", "300-digits", "outside-limits"],
)
def test_points_file_values_are_named_with_their_point_and_file(
    value: str, code: int, words: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "p.yaml"
    path.write_text(POINTS_OK.replace("[0.3, 0.9", f"[{value}, 0.9"))
    for command in (["traj", "--through", "P1", "P2"], ["cycle", "--from-point", "P1", "--to-point", "P2"]):
        assert main([command[0], "--points", str(path), *command[1:]]) == code
        err = capsys.readouterr().err
        assert err.startswith(f"error: points file {path}") and err.count("\n") == 1, err
        assert words in err and "P1" in err and "--from" not in err, err
    if code == 2 and value != "1" * 300:  # the line too (yaml)
        assert " line 3: point P1: q " in err, err


@pytest.mark.parametrize("value", ["0x1", "1_0", "1" * 5000])
def test_csv_points_values_name_their_point(value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "p.csv"
    path.write_text(f"name,q1,q2,q3,q4\nP1,{value},0.9,0.02,-0.5\nP2,0.5,0.7,0.02,-0.2\n")
    assert main(["traj", "--points", str(path), "--through", "P1", "P2"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: points file {path} line 2: point P1: q1 = ") and err.count("\n") == 1, err
    assert len(err) < 300  # the 5000 digits are not echoed


# --------------------------------------------------------------------------------------------- 10: given twice
@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["fk", "--lock", "joint4=0.5", "--lock", "joint4=-0.5", "0", "0", "0"],
         "--lock joint4 is given twice (0.5 and -0.5)"),
        (["fk", "--set", "l1=0.2", "--set", " l1=0.3", "0", "0", "0", "0"], "--set l1 is given twice (0.2 and 0.3)"),
        (["check", "{urdf}", "--lock", "joint4=0", "--lock", "joint4=0"], "--lock joint4 is given twice"),
    ],
)  # fmt: skip
def test_an_option_given_twice_for_one_joint_is_refused(args: list[str], words: str, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    urdf = tmp_path / "r.urdf"
    assert main(["urdf", "-o", str(urdf)]) == 0
    capsys.readouterr()
    assert main([a.replace("{urdf}", str(urdf)) for a in args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and words in err, err
    # once is fine: joint4 locked at 0.5, three joints left; the tool's yaw is 0.5 + q1 + q2 (the wrist's turn)
    assert main(["fk", "--json", "--lock", "joint4=0.5", "0.1", "0.2", "0"]) == 0
    assert json.loads(capsys.readouterr().out)["yaw"] == pytest.approx(0.8, abs=1e-12)
