"""xacro diagnostics (issue 21): ``check`` on a xacro file points at the file and line where each element was
written (the entry file, a file it includes, a macro's definition), or says that a line is the expansion's.

The fixture ``tests/data/packages/macro_scara_description`` (written for these tests) is a 6-line entry xacro
that includes ``urdf/inc/scara_macro.xacro`` and calls its macro; the quirks (a velocity limit of 0, pi
written as 3.14) sit in the included file. Expected lines are found by searching the files' own text here.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.description.packages import PackagePath, read_robot_file
from scara_pin.description.xacro_sources import expand_with_sources
from scara_pin.errors import UrdfError
from scara_pin.lint import check_urdf_file

PACKAGE = Path(__file__).resolve().parent / "data" / "packages" / "macro_scara_description"
ENTRY = PACKAGE / "urdf" / "macro_scara.urdf.xacro"
MACRO = PACKAGE / "urdf" / "inc" / "scara_macro.xacro"


def line_of(path: Path, needle: str) -> int:
    (number,) = [i for i, line in enumerate(path.read_text().splitlines(), start=1) if needle in line]
    return number


def test_the_text_is_the_loaders_and_every_urdf_element_has_its_source() -> None:
    packages = PackagePath((), ENTRY.parent)
    text, sources = expand_with_sources(ENTRY, packages)
    assert text == read_robot_file(ENTRY, packages)  # byte for byte: the tags are gone
    assert "scara_pin_src" not in text
    expanded = text.splitlines()
    # each mapped line holds an element whose start tag is on the source line (same tag name)
    for number, (file, line) in sources.lines.items():
        tag = expanded[number - 1].strip().split()[0].rstrip(">/")
        assert file.read_text().splitlines()[line - 1].strip().startswith(tag), (number, file, line)
    assert {f.name for f, _ in sources.lines.values()} == {"macro_scara.urdf.xacro", "scara_macro.xacro"}
    assert sources.where(1) is None  # the XML declaration: no element


def test_check_points_at_the_included_file(capsys: pytest.CaptureFixture[str]) -> None:
    report = check_urdf_file(ENTRY)
    assert report.exit_code == 4
    (zero,) = report.find("velocity-zero")
    assert zero.file is not None and Path(zero.file).resolve() == MACRO
    assert zero.line == line_of(MACRO, 'velocity="0"')
    expanded = read_robot_file(ENTRY, PackagePath((), ENTRY.parent)).splitlines()
    assert zero.expanded_line is not None and 'velocity="0.0"' in expanded[zero.expanded_line - 1].replace(
        'velocity="0"', 'velocity="0.0"')  # fmt: skip
    assert zero.expanded_line > len(ENTRY.read_text().splitlines())  # the number the old report printed
    (rpy,) = report.find("rpy-approximate")
    assert rpy.line == line_of(MACRO, 'rpy="3.14 0 0"') and Path(str(rpy.file)).name == "scara_macro.xacro"
    joints = {j.name: j for j in report.joints}
    assert joints["j1"].line == line_of(MACRO, 'name="${prefix}j1"') and joints["j1"].file == zero.file
    rc = main(["check", str(ENTRY)])
    out = capsys.readouterr().out
    assert rc == 4 and f"scara_macro.xacro:{zero.line}: warning: joint j3's velocity limit is 0" in out
    assert f"{ENTRY}:{zero.expanded_line}:" not in out
    rc = main(["check", str(ENTRY), "--json"])
    doc = json.loads(capsys.readouterr().out)
    (item,) = [f for f in doc["findings"] if f["code"] == "velocity-zero"]
    assert (item["line"], item["expanded_line"]) == (zero.line, zero.expanded_line)
    assert item["file"].endswith("urdf/inc/scara_macro.xacro")


def test_an_element_made_by_xacro_is_a_line_of_the_expansion(tmp_path: Path) -> None:
    """A <xacro:element> writes no line of its own: the finding says the line is the expanded document's."""
    ws = tmp_path / "ws"
    shutil.copytree(PACKAGE, ws / PACKAGE.name)
    entry = ws / PACKAGE.name / "urdf" / ENTRY.name
    made = '  <xacro:element xacro:name="link" name="link1"/>\n'  # after the macro's link1: the duplicate
    entry.write_text(entry.read_text().replace("</robot>", made + "</robot>"))
    report = check_urdf_file(entry)
    (dup,) = report.find("duplicate-name")
    assert dup.line is None and dup.file is None and dup.expanded_line is not None
    first = line_of(MACRO, '<link name="${name}">')  # link1 was first written by the macro scara_link
    assert f"scara_macro.xacro:{first}" in dup.message
    assert f"(line {dup.expanded_line} of the expanded document)" in report.format_text()


def test_a_xacro_error_in_the_included_file_names_it(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ws = tmp_path / "ws"
    shutil.copytree(PACKAGE, ws / PACKAGE.name)
    macro = ws / PACKAGE.name / "urdf" / "inc" / MACRO.name
    macro.write_text(macro.read_text().replace('upper="${stroke}"', 'upper="${strok}"'))
    entry = ws / PACKAGE.name / "urdf" / ENTRY.name
    report = check_urdf_file(entry)
    (f,) = report.findings
    assert f.code == "xacro-failed" and "strok" in f.message
    assert Path(str(f.file)).resolve() == macro.resolve() and f.line == line_of(macro, "${strok}")
    with pytest.raises(UrdfError, match=rf"strok.*written at {macro}:{f.line}"):
        load_robot(urdf=entry)
    assert main(["fk", "--urdf", str(entry), "0", "0", "0", "0"]) == 2
    assert f"scara_macro.xacro:{f.line}" in capsys.readouterr().err


def test_the_macro_fixture_loads_with_pinocchios_fk_and_its_ik_round_trips() -> None:
    """FK equals Pinocchio's model of the expanded file (mimic=True); IK (refined: pi written as 3.14)
    reaches every target to 1e-9 inside the limits and finds the sampled q."""
    import numpy as np
    import pinocchio as pin

    robot = load_robot(urdf=ENTRY)
    model = pin.buildModelFromXML(read_robot_file(ENTRY, PackagePath((), ENTRY.parent)), mimic=True)
    data = model.createData()
    tool = model.getFrameId("tool0")
    limits = ((-2.5, 2.5), (-2.6, 2.6), (0.0, 0.2), (-6.0, 6.0))
    rng = np.random.default_rng(66)
    for _ in range(30):
        q = np.array([rng.uniform(lo, hi) for lo, hi in limits])
        pin.framesForwardKinematics(model, data, q)
        np.testing.assert_allclose(robot.tool_placement(q).homogeneous, data.oMf[tool].homogeneous, rtol=0, atol=1e-12)
        target = robot.tool_pose(q)
        res = robot.ik(target)
        assert res.success, res.message
        for sol in res.solutions:
            pin.framesForwardKinematics(model, data, sol.q)
            M = data.oMf[tool]
            assert np.abs(M.translation - target[:3]).max() <= 1e-9
            assert abs(np.remainder(np.arctan2(M.rotation[1, 0], M.rotation[0, 0]) - target[3] + np.pi, 2 * np.pi)
                       - np.pi) <= 1e-9  # fmt: skip
            assert all(lo - 1e-12 <= v <= hi + 1e-12 for v, (lo, hi) in zip(sol.q, limits))
        assert min(sol.distance(q) for sol in res.solutions) <= 1e-9
