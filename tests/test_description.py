"""scara_pin.description: yaml parameters -> validated numbers -> xacro -> URDF.

Expected values come from the robots' documented numbers (the sources cited in the yaml comments),
from ``math.radians`` and from the xacro files themselves, never from scara_pin's own output.
"""

from __future__ import annotations

import math
import re
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import xacro

from scara_pin import (
    InvalidInputError,
    ParameterError,
    UnknownRobotError,
    available_robots,
    generate_urdf,
    load_parameters,
    load_robot,
    robot_from_urdf,
)

REPO = Path(__file__).resolve().parents[1]
URDF_DIR = REPO / "urdf"
CONFIG = URDF_DIR / "config"
ENTRY = URDF_DIR / "scara.urdf.xacro"
JOINTS = ("joint1", "joint2", "joint3", "joint4")

# Documented position limits (yaml comments: YK400XE ranges for `default`, its 150 mm stroke placed from
# q3 = -0.050 m (tool at the reference plane) to 0.100 m; the S1 teaching arm for `s1`): revolute joints
# in degrees, the quill (joint3) in metres.
DOCUMENTED_LIMITS = {
    "default": {"joint1": (-132, 132), "joint2": (-150, 150), "joint3": (-0.050, 0.100), "joint4": (-360, 360)},
    "s1": {"joint1": (-170, 170), "joint2": (-150, 150), "joint3": (0.0, 0.100), "joint4": (-360, 360)},
}
# Arm lengths from the sources (S4: 200 mm + 200 mm; S1: 50 mm + 150 mm).
ARMS = {"default": (0.200, 0.200), "s1": (0.050, 0.150)}


# ------------------------------------------------------------------------------------------- helpers
def _floats(text: str | None) -> tuple[float, ...]:
    return tuple(float(v) for v in (text or "0 0 0").split())


def joints_of(urdf: str) -> dict[str, dict[str, object]]:
    """Every joint of a URDF text: type, parent, child, origin, axis and limits, as floats."""
    root = ET.fromstring(urdf)
    out: dict[str, dict[str, object]] = {}
    for j in root.findall("joint"):
        origin = j.find("origin")
        axis = j.find("axis")
        limit = j.find("limit")
        out[j.get("name")] = {
            "type": j.get("type"),
            "parent": j.find("parent").get("link"),
            "child": j.find("child").get("link"),
            "xyz": _floats(origin.get("xyz") if origin is not None else None),
            "rpy": _floats(origin.get("rpy") if origin is not None else None),
            "axis": _floats(axis.get("xyz")) if axis is not None else None,
            "limit": {k: float(v) for k, v in limit.attrib.items()} if limit is not None else None,
        }
    return out


def masses_of(urdf: str) -> dict[str, float]:
    root = ET.fromstring(urdf)
    return {
        link.get("name"): float(link.find("inertial/mass").get("value"))
        for link in root.findall("link")
        if link.find("inertial") is not None
    }


def assert_joints_equal(a: dict, b: dict) -> None:
    assert a.keys() == b.keys()
    for name in a:
        ja, jb = a[name], b[name]
        for key in ("type", "parent", "child"):
            assert ja[key] == jb[key], (name, key)
        for key in ("xyz", "rpy", "axis"):
            assert ja[key] == pytest.approx(jb[key], abs=1e-15), (name, key)
        if ja["limit"] is None or jb["limit"] is None:
            assert ja["limit"] is jb["limit"], name
        else:
            assert ja["limit"].keys() == jb["limit"].keys(), name
            for key in ja["limit"]:
                assert ja["limit"][key] == pytest.approx(jb["limit"][key], rel=1e-15, abs=1e-15), (name, key)


def expected_limit(robot: str, joint: str) -> tuple[float, float]:
    lo, hi = DOCUMENTED_LIMITS[robot][joint]
    if joint == "joint3":
        return lo, hi
    return math.radians(lo), math.radians(hi)


@pytest.fixture
def xacro_calls(monkeypatch: pytest.MonkeyPatch) -> list[dict]:
    """Record every call of xacro.process_file (the real one still runs)."""
    calls: list[dict] = []
    real = xacro.process_file

    def spy(*args, **kwargs):
        calls.append({"args": args, "mappings": kwargs.get("mappings")})
        return real(*args, **kwargs)

    monkeypatch.setattr(xacro, "process_file", spy)
    return calls


@pytest.fixture(scope="module")
def default_urdf() -> str:
    return generate_urdf("default")


@pytest.fixture
def config_copy(tmp_path: Path) -> Path:
    """A writable copy of config/default, in a folder named ``myarm``."""
    dst = tmp_path / "myarm"
    shutil.copytree(CONFIG / "default", dst)
    return dst


def edit_yaml(path: Path, key: str, new_line: str | None) -> None:
    """Replace the (single) line ``<indent>key: ...`` of a yaml file; None deletes it."""
    text = path.read_text(encoding="utf-8")
    pattern = re.compile(rf"^(\s*){re.escape(key)}:.*$", re.MULTILINE)
    assert len(pattern.findall(text)) == 1, f"{key} must appear once in {path.name}"
    if new_line is None:
        text = pattern.sub("", text)
    else:
        text = pattern.sub(lambda m: m.group(1) + new_line, text)
    path.write_text(text, encoding="utf-8")


# ------------------------------------------------------------------------------- the shipped robots
def test_available_robots_lists_shipped_configs() -> None:
    robots = available_robots()
    assert {"default", "s1"} <= set(robots)
    assert robots == sorted(robots)


@pytest.mark.parametrize("robot", ["default", "s1"])
@pytest.mark.parametrize("joint", JOINTS)
def test_documented_position_limits_reach_the_urdf(robot: str, joint: str) -> None:
    limit = joints_of(generate_urdf(robot))[joint]["limit"]
    lo, hi = expected_limit(robot, joint)
    assert limit["lower"] == pytest.approx(lo, rel=0, abs=1e-15)
    assert limit["upper"] == pytest.approx(hi, rel=0, abs=1e-15)


def test_default_joint1_lower_is_exactly_minus_132_degrees(default_urdf: str) -> None:
    assert joints_of(default_urdf)["joint1"]["limit"]["lower"] == math.radians(-132)


@pytest.mark.parametrize("robot", ["default", "s1"])
def test_robot_name_and_arm_lengths_in_urdf(robot: str) -> None:
    urdf = generate_urdf(robot)
    assert ET.fromstring(urdf).get("name") == robot
    j = joints_of(urdf)
    l1, l2 = ARMS[robot]
    assert j["joint2"]["xyz"][0] == pytest.approx(l1, abs=1e-15)
    assert j["joint3"]["xyz"][0] == pytest.approx(l2, abs=1e-15)
    # q3 > 0 lowers the quill: joint3's axis is -z; the other three turn about +z
    assert j["joint3"]["type"] == "prismatic" and j["joint3"]["axis"] == (0.0, 0.0, -1.0)
    for name in ("joint1", "joint2", "joint4"):
        assert j[name]["type"] == "revolute" and j[name]["axis"] == (0.0, 0.0, 1.0)


def test_parameters_in_si_units() -> None:
    params = load_parameters("default")
    assert params["l1"] == 0.2 and params["l2"] == 0.2 and params["d3"] == -0.05
    assert params["joint1_lower"] == pytest.approx(math.radians(-132), abs=1e-15)
    assert params["joint1_velocity"] == pytest.approx(math.radians(420), abs=1e-12)
    assert params["joint3_upper"] - params["joint3_lower"] == pytest.approx(0.150, abs=1e-15)  # YK400XE stroke
    assert params.limits.lower[0] == params["joint1_lower"]


# ----------------------------------------------------------------- xacro run by hand (no mappings)
def test_standalone_xacro_equals_generated_default(
    default_urdf: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # the yaml paths inside the xacro must not depend on the working dir
    standalone = xacro.process_file(str(ENTRY)).toxml()
    assert_joints_equal(joints_of(standalone), joints_of(default_urdf))
    assert masses_of(standalone) == pytest.approx(masses_of(default_urdf))


@pytest.mark.parametrize("joint", ["joint1", "joint2", "joint4"])
def test_degrees_tag_agrees_between_xacro_and_python(joint: str, default_urdf: str) -> None:
    """xacro's own !degrees (standalone run) and scara_pin's reading give the same radians."""
    standalone = joints_of(xacro.process_file(str(ENTRY)).toxml())[joint]["limit"]
    generated = joints_of(default_urdf)[joint]["limit"]
    lo, hi = expected_limit("default", joint)
    for limit in (standalone, generated):
        assert limit["lower"] == pytest.approx(lo, rel=0, abs=1e-15)
        assert limit["upper"] == pytest.approx(hi, rel=0, abs=1e-15)


# --------------------------------------------------------------------------- what reaches xacro
def test_every_xacro_arg_gets_a_mapping(xacro_calls: list[dict]) -> None:
    """A missing mapping would silently fall back to the default robot's value for every robot."""
    declared = set(re.findall(r'<xacro:arg\s+name="([^"]+)"', ENTRY.read_text(encoding="utf-8")))
    assert "l1" in declared and "prefix" in declared
    generate_urdf("s1")
    assert len(xacro_calls) == 1
    assert set(xacro_calls[0]["mappings"]) == declared


def test_mappings_are_float_reprs(xacro_calls: list[dict]) -> None:
    generate_urdf("default", {"l1": "0.25", "tool_yaw": 1, "d3": -0.05}, prefix="left_")
    (call,) = xacro_calls
    mappings = call["mappings"]
    assert mappings.pop("prefix") == "left_"
    assert mappings, "no numeric mappings at all"
    for key, text in mappings.items():
        assert isinstance(text, str), key
        value = float(text)
        assert math.isfinite(value), key
        assert text == repr(value), (key, text)
    assert mappings["l1"] == "0.25"
    assert mappings["tool_yaw"] == "1.0"
    assert mappings["joint1_lower"] == repr(math.radians(-132))
    # accelerations have no URDF element: they never go to xacro
    assert not [k for k in mappings if k.endswith("_acceleration")]


def test_mappings_passed_to_xacro_are_a_fresh_copy(xacro_calls: list[dict]) -> None:
    params = load_parameters("default")
    generate_urdf(params)
    first = xacro_calls[0]["mappings"]
    first["l1"] = "9.0"
    first["prefix"] = "evil_"
    first.clear()
    urdf = generate_urdf(params)
    second = xacro_calls[1]["mappings"]
    assert second is not first
    assert second["l1"] == "0.2" and second["prefix"] == ""
    assert joints_of(urdf)["joint2"]["xyz"][0] == pytest.approx(0.2, abs=1e-15)
    assert params["l1"] == 0.2


def test_no_state_leaks_between_generations() -> None:
    generate_urdf("s1", {"l1": 0.33}, prefix="other_")
    j = joints_of(generate_urdf("default"))
    assert j["joint2"]["xyz"][0] == pytest.approx(0.2, abs=1e-15)
    assert "joint1" in j


# ----------------------------------------------------------------------------------- overrides
@pytest.mark.parametrize("value", [0.25, "0.25", " 0.25 ", 1 / 4])
def test_override_l1_moves_joint2(value: object) -> None:
    j = joints_of(generate_urdf("default", {"l1": value}))
    assert j["joint2"]["xyz"] == pytest.approx((0.25, 0.0, 0.0), abs=1e-15)
    assert j["joint3"]["xyz"][0] == pytest.approx(0.2, abs=1e-15)  # l2 untouched


def test_override_changes_limits_and_offsets() -> None:
    j = joints_of(generate_urdf("s1", {"joint1_upper": math.radians(100), "d3": -0.01, "tool_z": 0.02}))
    assert j["joint1"]["limit"]["upper"] == pytest.approx(math.radians(100), abs=1e-15)
    assert j["joint1"]["limit"]["lower"] == pytest.approx(math.radians(-170), abs=1e-15)
    assert j["joint3"]["xyz"][2] == pytest.approx(-0.01, abs=1e-15)
    assert j["flange-tool0_fixed_joint"]["xyz"][2] == pytest.approx(0.02, abs=1e-15)


def test_override_of_acceleration_is_kept_in_python() -> None:
    params = load_parameters("default", {"joint2_acceleration": "12.5"})
    assert params["joint2_acceleration"] == 12.5
    assert params.limits.acceleration[1] == 12.5


def test_overrides_do_not_modify_the_caller_mapping() -> None:
    overrides = {"l1": "0.3"}
    load_parameters("default", overrides)
    assert overrides == {"l1": "0.3"}


_POSITIVE = (
    ["l1", "l2"]
    + [f"{b}_{q}" for b in ("base", "link1", "link2", "quill", "flange") for q in ("mass", "radius")]
    + ["quill_length", "flange_length"]
    + [f"{j}_{f}" for j in JOINTS for f in ("velocity", "acceleration", "effort")]
)

# (overrides, name the error must carry, text the rule must contain)
_BAD_OVERRIDES = (
    [pytest.param({k: v}, k, "> 0", id=f"{k}={v}") for k in _POSITIVE for v in (0, -1.0)]
    + [pytest.param({k: "-0.0"}, k, "> 0", id=f"{k}=-0.0") for k in ("l1", "joint3_velocity")]
    + [
        pytest.param({k: v}, k, "finite", id=f"{k}={v!r}")
        for k in ("l1", "d1", "tool_yaw", "joint2_lower")
        for v in (math.nan, math.inf, -math.inf, "nan", "inf", "-Infinity", "1e999")
    ]
    + [
        pytest.param({"joint1_lower": "2.4"}, "joint1_lower", "joint1_upper", id="lower>upper"),
        pytest.param({"joint2_lower": math.radians(150)}, "joint2_lower", "joint2_upper", id="lower==upper"),
        pytest.param({"joint3_lower": 0.07, "joint3_upper": "0.07"}, "joint3_lower", "joint3_upper", id="both-equal"),
        pytest.param({"joint4_upper": -7}, "joint4_lower", "joint4_upper", id="upper<lower"),
        pytest.param({"base_height": -0.4}, "base_height + d1", "> 0", id="column<0"),
        pytest.param({"bogus": 1}, "bogus", "not a parameter", id="unknown-key"),
        pytest.param({"L1": 0.2}, "L1", "not a parameter", id="wrong-case-key"),
        pytest.param({"joint1_acceleration ": 1}, "joint1_acceleration ", "not a parameter", id="key-space"),
        pytest.param({"l1": "abc"}, "l1", "must be a number", id="text"),
        pytest.param({"l1": ""}, "l1", "must be a number", id="empty"),
        pytest.param({"l1": "0.2m"}, "l1", "must be a number", id="unit-suffix"),
        pytest.param({"l1": "0,2"}, "l1", "must be a number", id="comma"),
        pytest.param({"l1": True}, "l1", "must be a number", id="bool"),
        pytest.param({"l1": None}, "l1", "must be a number", id="none"),
        pytest.param({"l1": [0.2]}, "l1", "must be a number", id="list"),
        pytest.param({"l1": "1+1"}, "l1", "must be a number", id="expr"),
        pytest.param({"l1": "$(arg l1)"}, "l1", "must be a number", id="xacro-arg"),
        pytest.param({"l1": "${l2}"}, "l1", "must be a number", id="xacro-property"),
        pytest.param({"l1": "${__import__('os').getcwd()}"}, "l1", "must be a number", id="python-expr"),
        pytest.param({"d1": "0.1 ${pi}"}, "d1", "must be a number", id="trailing-expr"),
    ]
)


@pytest.mark.parametrize("entry", ["load_parameters", "generate_urdf", "load_robot"])
@pytest.mark.parametrize(("overrides", "name", "rule"), _BAD_OVERRIDES)
def test_bad_override_is_refused_before_xacro(
    entry: str, overrides: dict, name: str, rule: str, xacro_calls: list[dict]
) -> None:
    func = {"load_parameters": load_parameters, "generate_urdf": generate_urdf, "load_robot": load_robot}[entry]
    with pytest.raises(ParameterError) as info:
        func("default", overrides)
    err = info.value
    assert err.name == name
    assert rule in err.rule
    assert str(err).startswith(f"{name} is ")
    assert str(err).endswith(f"; it {err.rule}")
    assert err.exit_code == 2
    assert xacro_calls == []


def test_injection_never_reaches_xacro(tmp_path: Path, xacro_calls: list[dict]) -> None:
    marker = tmp_path / "pwned"
    payloads = [
        f"${{__import__('os').system('touch {marker}')}}",
        f"$(eval __import__('os').system('touch {marker}'))",
        f"0.2${{__import__('pathlib').Path('{marker}').touch()}}",
    ]
    for payload in payloads:
        for entry in (load_parameters, generate_urdf, load_robot):
            with pytest.raises(ParameterError) as info:
                entry("default", {"l1": payload})
            assert info.value.name == "l1" and info.value.value == payload
    assert xacro_calls == []
    assert not marker.exists()


def test_injection_through_a_config_yaml_is_refused(config_copy: Path, xacro_calls: list[dict]) -> None:
    marker = config_copy.parent / "pwned"
    edit_yaml(config_copy / "kinematics.yaml", "l2", f"l2: \"${{__import__('os').system('touch {marker}')}}\"")
    with pytest.raises(ParameterError) as info:
        generate_urdf(config_copy)
    assert "l2" in info.value.name and "must be a number" in info.value.rule
    assert xacro_calls == []
    assert not marker.exists()


@pytest.mark.parametrize("value", [np.float32(0.25), np.int64(1)])
def test_numpy_scalar_overrides_are_numbers(value: object) -> None:
    assert load_parameters("default", {"l2": value})["l2"] == pytest.approx(float(value))


# --------------------------------------------------------------------------------------- prefix
@pytest.mark.parametrize(
    "prefix", ["$", "{", "${x}", "$(arg l1)", "a b", " ", "left ", "'", '"', "a'b", 'x"', "a\nb", "a-b", "a/b"]
)
def test_bad_prefix_is_refused_before_xacro(prefix: str, xacro_calls: list[dict]) -> None:
    with pytest.raises(ParameterError) as info:
        generate_urdf("default", prefix=prefix)
    assert info.value.name == "prefix"
    assert info.value.value == prefix
    assert xacro_calls == []


def test_prefix_injection_never_runs(tmp_path: Path, xacro_calls: list[dict]) -> None:
    marker = tmp_path / "pwned"
    with pytest.raises(ParameterError):
        generate_urdf("default", prefix=f"${{__import__('os').system('touch {marker}')}}")
    assert xacro_calls == [] and not marker.exists()


def test_prefix_prefixes_every_link_and_joint(default_urdf: str) -> None:
    plain = ET.fromstring(default_urdf)
    left = ET.fromstring(generate_urdf("default", prefix="left_"))
    for tag in ("link", "joint", "material"):
        names = [e.get("name") for e in left.iter(tag) if e.get("name")]
        assert names, tag
        assert all(n.startswith("left_") for n in names), (tag, names)
        assert sorted(n[len("left_") :] for n in names) == sorted(
            e.get("name") for e in plain.iter(tag) if e.get("name")
        )
    for tag in ("parent", "child"):
        assert all(e.get("link").startswith("left_") for e in left.iter(tag))
    assert {j.get("name") for j in left.findall("joint")} >= {f"left_{j}" for j in JOINTS}


def test_prefixed_urdf_has_the_same_kinematics() -> None:
    plain = load_robot("default")
    left = robot_from_urdf(generate_urdf("default", prefix="left_"), base_frame="left_base", tool_frame="left_tool0")
    assert [left.model.names[i] for i in range(1, 5)] == [f"left_{j}" for j in JOINTS]
    q = np.array([0.3, -0.7, 0.04, 1.1])
    assert left.tool_pose(q) == pytest.approx(plain.tool_pose(q), abs=1e-12)


# ------------------------------------------------------------------------------- config folders
def test_config_folder_copy_loads_like_the_shipped_robot(config_copy: Path) -> None:
    params = load_parameters(config_copy)
    assert params.name == "myarm"
    assert dict(params.values) == dict(load_parameters("default").values)
    assert load_parameters(str(config_copy)).values == params.values
    urdf = generate_urdf(config_copy)
    assert ET.fromstring(urdf).get("name") == "myarm"


def test_config_folder_edit_reaches_the_urdf(config_copy: Path) -> None:
    edit_yaml(config_copy / "kinematics.yaml", "l1", "l1: 0.3")
    assert joints_of(generate_urdf(config_copy))["joint2"]["xyz"][0] == pytest.approx(0.3, abs=1e-15)


def test_config_degrees_tag_read_as_radians(config_copy: Path) -> None:
    text = (config_copy / "joint_limits.yaml").read_text(encoding="utf-8")
    text = text.replace("upper: !degrees 132", "upper: !degrees 90", 1)
    (config_copy / "joint_limits.yaml").write_text(text, encoding="utf-8")
    params = load_parameters(config_copy)
    assert params["joint1_upper"] == pytest.approx(math.pi / 2, rel=0, abs=1e-15)
    limit = joints_of(generate_urdf(config_copy))["joint1"]["limit"]
    assert limit["upper"] == pytest.approx(math.radians(90), rel=0, abs=1e-15)
    assert limit["lower"] == pytest.approx(math.radians(-132), rel=0, abs=1e-15)


def test_config_missing_key(config_copy: Path) -> None:
    edit_yaml(config_copy / "kinematics.yaml", "l2", None)
    with pytest.raises(ParameterError) as info:
        load_parameters(config_copy)
    assert info.value.name.startswith("l2 ") and "kinematics.yaml" in info.value.name
    assert "required" in info.value.rule


def test_config_unknown_key(config_copy: Path) -> None:
    edit_yaml(config_copy / "kinematics.yaml", "l2", "l2: 0.2\nl3: 0.1")
    with pytest.raises(ParameterError) as info:
        load_parameters(config_copy)
    assert info.value.name.startswith("l3 ") and "kinematics.yaml" in info.value.name
    assert "not a parameter" in info.value.rule


@pytest.mark.parametrize(
    ("line", "rule"),
    [
        ("l1: abc", "must be a number"),
        ("l1: null", "must be a number"),
        ("l1: true", "must be a number"),
        ("l1: [0.2]", "must be a number"),
        ("l1: .nan", "finite"),
        ("l1: .inf", "finite"),
        ("l1: -0.2", "> 0"),
        ("l1: 0", "> 0"),
    ],
)
def test_config_bad_value(config_copy: Path, line: str, rule: str, xacro_calls: list[dict]) -> None:
    edit_yaml(config_copy / "kinematics.yaml", "l1", line)
    with pytest.raises(ParameterError) as info:
        generate_urdf(config_copy)
    assert info.value.name.startswith("l1")
    assert rule in info.value.rule
    assert xacro_calls == []


def test_config_bad_limit_value(config_copy: Path) -> None:
    text = (config_copy / "joint_limits.yaml").read_text(encoding="utf-8")
    (config_copy / "joint_limits.yaml").write_text(text.replace("effort: 20.0", "effort: 0.0"), encoding="utf-8")
    with pytest.raises(ParameterError) as info:
        load_parameters(config_copy)
    assert info.value.name == "joint2_effort" and "> 0" in info.value.rule


def test_config_yaml_syntax_error(config_copy: Path) -> None:
    path = config_copy / "joint_limits.yaml"
    path.write_text(path.read_text(encoding="utf-8").replace("upper: !degrees 132", "upper: [1, 2", 1))
    with pytest.raises(ParameterError) as info:
        load_parameters(config_copy)
    assert "joint_limits.yaml" in info.value.name
    assert "yaml" in info.value.rule


def test_config_missing_file(config_copy: Path) -> None:
    (config_copy / "physical_parameters.yaml").unlink()
    with pytest.raises(ParameterError) as info:
        load_parameters(config_copy)
    assert "physical_parameters.yaml" in info.value.name
    assert "cannot be read" in info.value.rule


def test_config_bad_degrees_value_names_the_parameter(config_copy: Path) -> None:
    path = config_copy / "joint_limits.yaml"
    path.write_text(path.read_text(encoding="utf-8").replace("upper: !degrees 132", "upper: !degrees abc", 1))
    with pytest.raises(ParameterError) as info:
        load_parameters(config_copy)
    assert "joint1_upper" in info.value.name or "joint_limits.yaml" in info.value.name


# -------------------------------------------------------------------------------- unknown robots
@pytest.mark.parametrize("robot", ["nope", "", "Default", "default ", "../config/default", "s1/..", "${x}"])
def test_unknown_robot(robot: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, xacro_calls: list[dict]) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UnknownRobotError) as info:
        generate_urdf(robot)
    err = info.value
    assert isinstance(err, InvalidInputError) and err.exit_code == 2
    assert err.robot == robot
    assert {"default", "s1"} <= set(err.available)
    assert repr(robot) in str(err)
    assert xacro_calls == []


def test_folder_without_yaml_is_unknown_robot(tmp_path: Path) -> None:
    (tmp_path / "empty").mkdir()
    with pytest.raises(UnknownRobotError):
        load_parameters(tmp_path / "empty")


def test_shipped_robot_not_shadowed_by_cwd_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "default").mkdir()
    monkeypatch.chdir(tmp_path)
    assert load_parameters("default")["l1"] == 0.2
