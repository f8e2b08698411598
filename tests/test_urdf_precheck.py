"""The loader's pre-check refuses a URDF if and only if Pinocchio does (issue 29 item 7), or says why not.

Every rule of :data:`scara_pin._urdf_checks.PRECHECK_RULES` is run on documents mutated from one valid
robot; each document also goes to ``pinocchio.buildModelFromXML`` (urdfdom's parser), the independent
judge. A rule without a ``stricter`` reason must agree with it; a rule with one refuses documents Pinocchio
takes, and says why. Documents that urdfdom reads while ignoring a part (an inline colour written ``rgb=``,
the community file of ``tests/data/round3/rgb_colours.urdf``) load in both.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from quirks import run

from scara_pin import load_robot, robot_from_urdf
from scara_pin._urdf_checks import PRECHECK_RULES, PrecheckError, check_urdf_tree
from scara_pin.limits import MAX_URDF_ELEMENTS
from scara_pin.lint import check_urdf_file

RGB = Path(__file__).resolve().parent / "data" / "round3" / "rgb_colours.urdf"

BASE = """<robot name="r">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <material name="logo"><texture filename="logo.png"/></material>
  <link name="base_link">
    <visual><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><box size="0.2 0.2 0.2"/></geometry>
      <material name="grey"/></visual>
    <inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="2"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <link name="arm">
    <visual><geometry><cylinder radius="0.05" length="0.3"/></geometry>
      <material name="red"><color rgba="1 0 0 1"/></material></visual>
    <visual><geometry><mesh filename="package://p/arm.stl" scale="0.001 0.001 0.001"/></geometry></visual>
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><sphere radius="0.1"/></geometry></collision>
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <link name="quill"/>
  <link name="flange"/>
  <link name="plate"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="arm"/>
    <origin xyz="0 0 0.4" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="2"/><dynamics damping="0.1" friction="0"/></joint>
  <joint name="j2" type="prismatic"><parent link="arm"/><child link="quill"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="0 0 -1"/>
    <limit lower="0" upper="0.2" effort="10" velocity="1"/></joint>
  <joint name="j3" type="continuous"><parent link="quill"/><child link="flange"/><axis xyz="0 0 1"/></joint>
  <joint name="j4" type="revolute"><parent link="arm"/><child link="plate"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="j1" multiplier="-1" offset="0.5"/></joint>
</robot>"""

# a chain of fixed links hung on the plate: MAX_URDF_ELEMENTS + 1 links and joints in all
CHAIN = "".join(f'<link name="c{i}"/><joint name="f{i}" type="fixed"><parent link="{f"c{i - 1}" if i else "plate"}"/>'
                f'<child link="c{i}"/></joint>' for i in range((MAX_URDF_ELEMENTS - 9) // 2 + 1))  # fmt: skip

# (rule, mutation id, old, new): each document breaks one rule
MUTATIONS = [
    ("root", "not_robot", ("<robot ", "</robot>"), ("<robo ", "</robo>")),
    ("size", "over_the_cap", '<link name="plate"/>', '<link name="plate"/>' + CHAIN),
    ("robot-name", "nameless_robot", '<robot name="r">', "<robot>"),
    ("urdf-version", "version_three_numbers", '<robot name="r">', '<robot name="r" version="1.0.0">'),
    ("urdf-version", "version_two", '<robot name="r">', '<robot name="r" version="2.0">'),
    ("material-unique", "material_twice", '<material name="logo">', '<material name="grey">'),
    ("link-name", "nameless_link", '<link name="plate"/>', "<link/>"),
    ("link-name", "link_twice", '<link name="plate"/>', '<link name="plate"/><link name="plate"/>'),
    ("inertial", "mass_negative", '<mass value="1"/>', '<mass value="-1"/>'),
    ("inertial", "mass_text", '<mass value="1"/>', '<mass value="one"/>'),
    ("inertial", "no_inertia", '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>', ""),
    ("inertial", "inertia_attribute_missing", 'ixx="0.01" ixy="0"', 'ixy="0"'),
    ("inertial", "inertial_origin_nan", '<origin xyz="0 0 0.1" rpy="0 0 0"/><mass', '<origin xyz="0 0 nan"/><mass'),
    ("geometry", "unknown_shape", '<sphere radius="0.1"/>', '<capsule radius="0.1" length="1"/>'),
    ("geometry", "box_without_size", '<box size="0.2 0.2 0.2"/>', "<box/>"),
    ("geometry", "cylinder_radius_text", 'radius="0.05"', 'radius="five"'),
    ("geometry", "mesh_without_file", '<mesh filename="package://p/arm.stl" scale="0.001 0.001 0.001"/>', "<mesh/>"),
    ("geometry", "mesh_scale_two", 'scale="0.001 0.001 0.001"', 'scale="0.001 0.001"'),
    ("geometry", "visual_origin_two", '<origin xyz="0 0 0.1" rpy="0 0 0"/><geometry>',
     '<origin xyz="0 0.1"/><geometry>'),
    ("geometry", "nameless_inline_material", '<material name="red">', "<material>"),
    ("joint-name", "nameless_joint", '<joint name="j3" ', "<joint "),
    ("joint-name", "joint_twice", '<joint name="j3" ', '<joint name="j2" '),
    ("joint-type", "unknown_type", 'type="continuous"', 'type="hinge"'),
    ("joint-type", "no_type", ' type="continuous"', ""),
    ("joint-links", "no_parent", '<parent link="quill"/>', ""),
    ("joint-links", "undefined_child", '<child link="flange"/>', '<child link="wrist"/>'),
    ("joint-numbers", "origin_two", '<origin xyz="0.3 0 0" rpy="0 0 0"/>', '<origin xyz="0.3 0" rpy="0 0 0"/>'),
    ("joint-numbers", "axis_hex", '<axis xyz="0 0 -1"/>', '<axis xyz="0 0 -0x1"/>'),
    ("joint-numbers", "limit_underscore", 'upper="0.2"', 'upper="0_2"'),
    ("joint-numbers", "damping_text", 'damping="0.1"', 'damping="low"'),
    ("joint-numbers", "mimic_multiplier_text", 'multiplier="-1"', 'multiplier="minus one"'),
    ("joint-limit", "no_limit", '<limit lower="0" upper="0.2" effort="10" velocity="1"/>', ""),
    ("joint-limit", "no_effort", 'upper="0.2" effort="10" velocity="1"', 'upper="0.2" velocity="1"'),
    ("joint-limit", "no_velocity", 'upper="2" effort="10" velocity="2"', 'upper="2" effort="10"'),
    ("joint-parts", "dynamics_empty", '<dynamics damping="0.1" friction="0"/>', "<dynamics/>"),
    ("joint-parts", "safety_without_k_velocity", '<dynamics damping="0.1" friction="0"/>',
     '<dynamics damping="0.1" friction="0"/><safety_controller k_position="1"/>'),
    ("mimic-joint", "mimic_without_joint", '<mimic joint="j1" ', "<mimic "),
    ("tree", "two_roots", '<link name="plate"/>', '<link name="plate"/><link name="orphan"/>'),
    ("two-parents", "two_parents", '<parent link="arm"/><child link="plate"/>',
     '<parent link="arm"/><child link="flange"/>'),
]
# read by urdfdom with a part ignored: loaded by both
ACCEPTED = [
    ("inline_colour_rgb", '<color rgba="1 0 0 1"/>', '<color rgb="1 0 0"/>'),
    ("inline_colour_three", '<color rgba="1 0 0 1"/>', '<color rgba="1 0 0"/>'),
    ("inline_colour_range", '<color rgba="1 0 0 1"/>', '<color rgba="2 0 0 1"/>'),
    ("inline_material_empty", '<material name="red"><color rgba="1 0 0 1"/></material>', '<material name="red"/>'),
    ("global_colour_rgb", '<color rgba="0.5 0.5 0.5 1"/>', '<color rgb="0.5 0.5 0.5"/>'),
    ("global_material_empty", '<material name="logo"><texture filename="logo.png"/></material>',
     '<material name="logo"/>'),
    ("global_material_nameless", '<material name="logo">', "<material>"),
]


def mutate(old: str | tuple[str, ...], new: str | tuple[str, ...]) -> str:
    text = BASE
    for a, b in zip((old,) if isinstance(old, str) else old, (new,) if isinstance(new, str) else new):
        assert a in text, a
        text = text.replace(a, b, 1)
    return text


def verdicts(text: str) -> tuple[str | None, bool]:
    """(the pre-check's rule that refuses, None if none; whether Pinocchio refuses)."""
    try:
        check_urdf_tree(ET.fromstring(text), "m.urdf")
        rule = None
    except PrecheckError as exc:
        rule = exc.rule
    try:
        pin.buildModelFromXML(text, mimic=True)
        refused = False
    except (ValueError, RuntimeError):
        refused = True
    return rule, refused


def test_the_base_document_passes_both(capfd: pytest.CaptureFixture[str]) -> None:
    assert verdicts(BASE) == (None, False)


@pytest.mark.parametrize(("rule", "old", "new"), [(r, o, n) for r, _, o, n in MUTATIONS],
                         ids=[m[1] for m in MUTATIONS])  # fmt: skip
def test_the_precheck_refuses_what_pinocchio_refuses(rule: str, old: str, new: str,
                                                     capfd: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """capfd swallows urdfdom's C-level stderr lines."""
    got, pinocchio_refuses = verdicts(mutate(old, new))
    assert got == rule
    stricter = {r.name: r.stricter for r in PRECHECK_RULES}[rule]
    if stricter is None:
        assert pinocchio_refuses, f"the pre-check refuses ({rule}) a document Pinocchio loads"
    else:  # deliberately stricter, with its reason (checked on Pinocchio's reading: tests/test_urdf_differential.py)
        assert len(stricter) > 40


@pytest.mark.parametrize(("old", "new"), [(o, n) for _, o, n in ACCEPTED], ids=[a[0] for a in ACCEPTED])
def test_what_urdfdom_ignores_loads(old: str, new: str, capfd: pytest.CaptureFixture[str]) -> None:
    assert verdicts(mutate(old, new)) == (None, False)


@pytest.mark.parametrize(("old", "new"), [(o, n) for _, o, n in ACCEPTED], ids=[a[0] for a in ACCEPTED])
def test_the_loader_takes_them_quietly_and_says_what_urdfdom_ignores(
    old: str, new: str, capfd: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """No line of urdfdom's on fd 2 (it is given the document less what it would drop); one warning instead."""
    text = mutate(old, new)
    with caplog.at_level("WARNING", logger="scara_pin"):
        robot_from_urdf(text)
    assert capfd.readouterr() == ("", "")
    quiet = new == '<material name="red"/>'  # an inline material reduced to its name: nothing to say
    assert ("colours URDF cannot read, ignored" in caplog.text) is not quiet, caplog.text


def test_every_rule_is_exercised_and_a_stricter_rule_says_why() -> None:
    assert {r for r, *_ in MUTATIONS} == {r.name for r in PRECHECK_RULES}
    for r in PRECHECK_RULES:  # the stricter ones: size (bounded work), inertial, geometry, two parents
        assert r.stricter is None or r.name in ("size", "inertial", "geometry", "two-parents"), r.name


def test_the_community_file_with_rgb_colours_loads(capsys: pytest.CaptureFixture[str]) -> None:
    """The regression: inline <color rgb="..."/> (urdfdom ignores the colour) was refused as an invalid URDF."""
    assert 'rgb="' in RGB.read_text()
    robot = load_robot(urdf=RGB)
    pin.buildModelFromXML(RGB.read_text())  # the judge: Pinocchio loads it too
    q = np.array([0.3, -0.4, 0.05, 1.0])
    rc, out, err = run(capsys, ["fk", "--urdf", str(RGB), *map(repr, q.tolist())])
    assert rc == 0 and "error" not in err
    assert check_urdf_file(RGB).exit_code in (0, 4)
    # a planar SCARA written in the fixture: 0.3 and 0.25 m arms, quill down from 0.35 m, the wrist's yaw
    expected = [0.3 * np.cos(q[0]) + 0.25 * np.cos(q[0] + q[1]), 0.3 * np.sin(q[0]) + 0.25 * np.sin(q[0] + q[1]),
                0.35 - q[2], q[0] + q[1] + q[3]]  # fmt: skip
    np.testing.assert_allclose(robot.tool_pose(q), expected, rtol=0, atol=1e-12)
