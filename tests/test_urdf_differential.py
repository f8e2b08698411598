"""The loader and ``check`` against Pinocchio's own parsers, on every description of the tests and their mutants.

Issue 39 item 6: a pre-check that claims to refuse what urdfdom refuses must never refuse what Pinocchio loads.
The corpus is every URDF and xacro file of tests/data and the shipped robots' URDF; each mutant is one change
(tests/urdf_mutants.py: attributes emptied, removed, blanks around them, numbers written another way, unknown
attributes and elements, elements duplicated, removed or reordered, values taken from other elements). The
judge is Pinocchio: ``buildModelFromXML`` and ``buildGeomFromUrdfString`` (visual and collision). A refusal
of a document Pinocchio loads must come from a rule that says why it is stricter, and its reason must hold
for that document (checked on Pinocchio's reading); a refusal of a document Pinocchio refuses must name the
element (never Pinocchio's bare "does not contain a valid URDF model"); nothing crashes. 1,000 random mutants
here, seeded, and the systematic ones (each kind of attribute emptied, then removed: the variants urdfdom
tolerates, met every run); benchmarks/bench_urdf_differential.py runs as many as asked.

Then the cases the issue names, one test each: the seven classes refused while Pinocchio loaded them, the
numbers with a blank after them, the two crashes.
"""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin
import pytest
import urdf_mutants as um

from scara_pin import robot_from_urdf
from scara_pin._urdf_checks import PRECHECK_RULES, PrecheckError, urdf_number, urdf_vector
from scara_pin.errors import UrdfError
from scara_pin.lint import check_urdf
from scara_pin.urdf_rules import LOADER_RULES

N_MUTANTS = 1000
SEED = 39
N_CHECKED = 60  # mutants that `check` lints too (each ~20 ms: the table of rules, the model)


@pytest.fixture(scope="module")
def corpus() -> dict[str, str]:
    return um.corpus()


@pytest.fixture(scope="module")
def mesh(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("mesh") / "m.stl"
    path.write_text(um.MESH_STL)
    return path


def test_the_corpus_is_every_description_of_the_tests_and_the_shipped_robots(corpus: dict[str, str]) -> None:
    urdf = {str(p.relative_to(um.DATA)) for p in um.DATA.rglob("*.urdf")}
    assert urdf <= set(corpus)
    assert {"round4/vendor_gripper_scara.urdf", "round4/mg400_empty_material.urdf", "round4/duaro_empty_material.urdf",
            "round3/rgb_colours.urdf", "shipped:default", "shipped:s1", "shipped:palletizer"} <= set(corpus)
    xacro = [name for name in corpus if name.endswith(".xacro")]
    assert len(xacro) >= 3 and "round4/rprr_lab_description/urdf/rprr_lab.urdf.xacro" in xacro


def test_a_thousand_mutants_never_refused_beyond_what_pinocchio_refuses(
    corpus: dict[str, str], mesh: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """The differential test itself (capfd swallows urdfdom's lines on the C-level stderr)."""
    wrong: list[str] = []
    refused = loaded = 0
    start = time.perf_counter()
    for m in um.mutants(corpus, N_MUTANTS, SEED):
        toolkit, problem = um.verdict(m, mesh)
        if problem is not None:
            wrong.append(f"{m.source}: {m.change}: {problem}")
        loaded += toolkit.loads
        refused += not toolkit.loads
    seconds = time.perf_counter() - start
    assert not wrong, f"{len(wrong)} of {N_MUTANTS} mutants:\n" + "\n".join(wrong[:20])
    assert refused >= 100 and loaded >= 300, (refused, loaded)  # both kinds are exercised: the test can fail
    assert seconds < 60.0, seconds  # a few seconds on an idle machine


def test_each_attribute_emptied_and_removed_never_refused_beyond_what_pinocchio_refuses(
    corpus: dict[str, str], mesh: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Every (element kind, attribute) of the corpus emptied, then removed (tests/urdf_mutants.py: systematic).

    The two regressions of issues 29 and 39 were of this kind (a ``<color>`` without rgba, a ``<material
    name="">`` in a visual): random mutants meet such an attribute by chance, these every run, in files that
    were in the corpus before either regression (the shipped robots, default.urdf).
    """
    made = list(um.systematic(corpus))
    wrong = [f"{m.source}: {m.change}: {p}" for m in made if (p := um.verdict(m, mesh)[1]) is not None]
    assert not wrong, f"{len(wrong)} of {len(made)} mutants:\n" + "\n".join(wrong[:20])
    changes = {m.change for m in made}
    assert {"<visual/material> name emptied", "<material/color> rgba removed", "<robot> name emptied",
            "<robot/joint> name emptied"} <= changes and len(made) >= 150  # fmt: skip
    disagree = [f"{m.source}: {m.change}: {d}" for m in made[::3] if (d := um.check_disagrees(m)) is not None]
    assert not disagree, "\n".join(disagree)


def test_check_agrees_with_the_loader_on_mutants(corpus: dict[str, str], capfd: pytest.CaptureFixture[str]) -> None:
    """Loadable means check exits 0 or 4; refused means 2 (and check never crashes)."""
    wrong = [f"{m.source}: {m.change}: {d}" for m in um.mutants(corpus, N_CHECKED, SEED + 1)
             if (d := um.check_disagrees(m)) is not None]  # fmt: skip
    assert not wrong, "\n".join(wrong)


def test_each_refusal_of_what_pinocchio_loads_is_a_declared_rule_with_its_reason() -> None:
    stricter = [r for r in PRECHECK_RULES if r.stricter is not None]
    assert {r.name for r in stricter} == {"size", "inertial", "geometry", "two-parents"}
    assert all(len(r.stricter) > 60 for r in stricter)  # type: ignore[arg-type]
    assert {"limits-inverted", "mimic-unresolved", "joint-count", "bad-number"} <= set(LOADER_RULES)
    assert all(len(why) > 40 for why in LOADER_RULES.values())


# ----------------------------------------------------------------------------- the classes the issue names
BASE = (um.DATA / "round4" / "vendor_gripper_scara.urdf").read_text()


def _edit(old: str, new: str) -> str:
    assert BASE.count(old) >= 1, old
    return BASE.replace(old, new, 1)


_FIXED = ('<joint name="tool_mount" type="fixed"><parent link="link4"/><child link="mount"/>'
          '<origin xyz="0 0 -0.05"/><axis xyz="{axis}"/></joint><link name="mount"/></robot>')  # fmt: skip
SEVEN = {
    "robot_name_empty": _edit('<robot name="vendor_gripper_scara">', '<robot name="">'),
    "joint_name_empty": _edit('<joint name="arm4_joint" type="revolute">', '<joint name="" type="revolute">'),
    "mimic_joint_empty": _edit('<mimic joint="arm5r_joint"', '<mimic joint=""'),
    "fixed_axis_four_numbers": _edit("</robot>", _FIXED.format(axis="0 0 1 0")),
    "fixed_axis_blank": _edit("</robot>", _FIXED.format(axis=" ")),
    "visual_material_name_empty": _edit('<material name="vendor_white"><color', '<material name=""><color'),
    "two_shapes": _edit('<box size="0.26 0.07 0.04"/></geometry>',  # (link1's visual: written before its collision)
                        '<box size="0.26 0.07 0.04"/><sphere radius="0.1"/></geometry>'),
    "shape_then_unknown_tag": _edit('<box size="0.2 0.06 0.04"/></geometry>',
                                    '<box size="0.2 0.06 0.04"/><unknown_tag/></geometry>'),
}


@pytest.mark.parametrize("case", SEVEN)
def test_the_seven_classes_load_as_in_pinocchio(case: str, mesh: Path, capfd: pytest.CaptureFixture[str]) -> None:
    """Each was refused by a rule claiming to match Pinocchio's parser while Pinocchio loaded it."""
    text = SEVEN[case]
    judge = um.pinocchio_verdict(text, mesh)
    assert judge.loads, judge.error or judge.geometry_error  # the independent route: Pinocchio takes it
    robot = robot_from_urdf(text)  # the toolkit takes it too
    assert robot.joint_names[:3] == ("arm1_joint", "arm2_joint", "arm3_joint")
    assert um.verdict(um.Mutant("vendor_gripper_scara.urdf", case, text), mesh) == (um.Toolkit(), None)
    assert check_urdf(text).exit_code in (0, 4)


def test_an_empty_joint_name_is_a_name(capfd: pytest.CaptureFixture[str]) -> None:
    robot = robot_from_urdf(SEVEN["joint_name_empty"])
    assert robot.joint_names == ("arm1_joint", "arm2_joint", "arm3_joint", "")
    assert robot_from_urdf(SEVEN["robot_name_empty"]).name == ""


def test_a_mimic_naming_no_joint_is_a_free_joint_with_a_warning(caplog: pytest.LogCaptureFixture,
                                                                capfd: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """Pinocchio's parser reads the jaw as a free joint; so does the toolkit (off the arm: locked), and says so."""
    with caplog.at_level("WARNING", logger="scara_pin"):
        robot = robot_from_urdf(SEVEN["mimic_joint_empty"])
    assert 'arm5l_joint is free' in caplog.text and '<mimic joint="">' in caplog.text
    assert {lj.name: lj.reason for lj in robot.locked} == {"arm5l_joint": "off-chain", "arm5r_joint": "off-chain"}
    (finding,) = check_urdf(SEVEN["mimic_joint_empty"]).find("mimic-ignored")
    assert finding.severity.value == "warning" and finding.joint == "arm5l_joint"


def test_the_first_shape_is_the_one_drawn_as_in_pinocchio(capfd: pytest.CaptureFixture[str]) -> None:
    """Two shapes in one <geometry>: urdfdom reads the first; the toolkit's geometry is Pinocchio's."""
    robot = robot_from_urdf(SEVEN["two_shapes"])
    shape = robot.visual_model.geometryObjects[robot.visual_model.getGeometryId("link1_0")].geometry
    assert type(shape).__name__ == "Box" and shape.halfSide.tolist() == pytest.approx([0.13, 0.035, 0.02])


@pytest.mark.parametrize(("where", "old", "new", "needles"), [
    ("limit velocity", 'effort="10" velocity="3.5"', 'effort="10" velocity="3.5 "',
     ["joint arm2_joint's <limit>", "velocity='3.5 '", "a blank after a number"]),
    ("limit effort", 'effort="20" velocity="3.5"', 'effort="20 " velocity="3.5"',
     ["joint arm1_joint's <limit>", "effort='20 '", "a blank after a number"]),
    ("mimic multiplier", 'multiplier="1"', 'multiplier="1 "', ["joint arm5l_joint's <mimic>", "multiplier='1 '"]),
    ("origin with a tab", '<origin xyz="0.2 0 0.04"', '<origin xyz="0.2\t0 0.04"',
     ["joint arm2_joint's <origin>", "xyz='0.2\\t0 0.04'", "tab or a line break"]),
    ("version", '<robot name="vendor_gripper_scara">', '<robot name="vendor_gripper_scara" version="1.0.1">',
     ["<robot> version='1.0.1'"]),
    ("dynamics", '<limit lower="-2.5" upper="2.5" effort="20" velocity="3.5"/>',
     '<limit lower="-2.5" upper="2.5" effort="20" velocity="3.5"/><dynamics/>',
     ["joint arm1_joint's <dynamics> has neither damping nor friction"]),
])  # fmt: skip
def test_what_pinocchio_refuses_is_refused_naming_the_element_attribute_and_value(
    where: str, old: str, new: str, needles: list[str], capfd: pytest.CaptureFixture[str]
) -> None:
    """Item 6: 74 mutants Pinocchio refuses got only its bare message, 68 of them numbers with a blank after them."""
    text = _edit(old, new)
    with pytest.raises((ValueError, RuntimeError), match="does not contain a valid URDF"):
        pin.buildModelFromXML(text)  # the judge refuses it
    with pytest.raises(PrecheckError) as info:
        robot_from_urdf(text)
    for needle in needles:
        assert needle in str(info.value), str(info.value)
    assert "does not contain a valid URDF" not in str(info.value)


def test_urdfdom_numbers_as_pinocchio_reads_them(capfd: pytest.CaptureFixture[str]) -> None:
    """The grammar of the pre-check, each case judged by Pinocchio itself (a joint's velocity limit)."""
    cases = ["1", "1.", ".5", "+1", "-0", "1e+5", "1E5", "00001", " 1", "\t1", "1 ", "1\t", "1e", ".", "", "inf",
             "nan", "0x10", "1_0", "1,5", "1e400", "1e-400", "1.8e308", "- 1", "1f"]  # fmt: skip
    for raw in cases:
        escaped = raw.replace("\t", "&#9;")
        text = BASE.replace('effort="10" velocity="3.5"', f'effort="10" velocity="{escaped}"', 1)
        try:
            model = pin.buildModelFromXML(text)
            expected: float | None = float(model.velocityLimit[1])
        except (ValueError, RuntimeError):
            expected = None
        assert urdf_number(raw) == expected, raw
    assert urdf_vector("0 0  1 ") == (0.0, 0.0, 1.0) and urdf_vector("0 0\t1") is None and urdf_vector("0 1") is None


def test_an_undeclared_prefix_is_a_tag_like_any_other(capfd: pytest.CaptureFixture[str]) -> None:
    """tinyxml2 knows no namespaces: <gazebo:plugin> without xmlns:gazebo loads in Pinocchio, and here."""
    text = _edit('<link name="link3">', '<link name="link3"><gazebo:plugin name="p"/>')
    with pytest.raises(ET.ParseError):
        ET.fromstring(text)  # a namespace-aware reader refuses it
    pin.buildModelFromXML(text)
    assert robot_from_urdf(text).joint_names[0] == "arm1_joint"
    assert check_urdf(text).exit_code in (0, 4)


def test_a_link_with_two_parents_and_nothing_movable_below_loads_as_urdfdom_reads_it(
    caplog: pytest.LogCaptureFixture, capfd: pytest.CaptureFixture[str]
) -> None:
    """urdfdom keeps the last parent by name; a fixed branch is the same frames again in Pinocchio: loaded, said."""
    text = _edit("</robot>", '<link name="cam"/><joint name="a_cam" type="fixed"><parent link="link2"/>'
                 '<child link="cam"/><origin xyz="0.1 0 0"/></joint><joint name="b_cam" type="fixed"><parent '
                 'link="link1"/><child link="cam"/><origin xyz="0.05 0 0"/></joint></robot>')  # fmt: skip
    model = pin.buildModelFromXML(text)
    assert len(set(model.names)) == len(model.names)  # a sane model: each joint once
    with caplog.at_level("WARNING", logger="scara_pin"):
        robot = robot_from_urdf(text)
    assert "'a_cam' is ignored" in caplog.text
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    # the frame where urdfdom puts it: b_cam (the last by name), on link1
    assert robot.frame_placement([0, 0, 0, 0], "cam").translation.tolist() == pytest.approx(
        data.oMf[model.getFrameId("cam")].translation.tolist(), abs=1e-12)
    # the joint urdfdom keeps is movable: Pinocchio builds it twice, under one name
    moving = _edit("</robot>", '<link name="cam"/><joint name="b_cam" type="revolute"><parent link="link2"/>'
                   '<child link="cam"/><axis xyz="0 0 1"/><limit effort="1" velocity="1" lower="-1" upper="1"/>'
                   '</joint><joint name="a_cam" type="fixed"><parent link="link2"/><child link="cam"/></joint>'
                   '</robot>')  # fmt: skip
    names = list(pin.buildModelFromXML(moving).names)
    assert names.count("b_cam") == 2
    with pytest.raises(PrecheckError, match="builds the link's branch twice"):
        robot_from_urdf(moving)


def test_inverted_limits_check_says_so_without_crashing(capfd: pytest.CaptureFixture[str]) -> None:
    """Item 6: check on a file with inverted limits crashed (ValueError: high - low < 0); the loader refused it."""
    path = um.DATA / "round4" / "inverted_limits.urdf"
    from scara_pin.lint import check_urdf_file

    report = check_urdf_file(path)
    assert report.exit_code == 2
    (f,) = report.find("limits-inverted")
    assert "j2" in f.message and "lower 2.5 > upper -2.5" in f.message
    assert report.find("rpy-approximate")  # the rule that sampled the arm's range ran
    with pytest.raises(UrdfError, match="inverted limits"):
        robot_from_urdf(path.read_text())
