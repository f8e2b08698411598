"""D-H tables to URDF (scara_pin.description.dh).

Truth from an independent route: the D-H matrix products are written here with numpy (elementary
rotations and translations), and compared with Pinocchio's FK of the generated URDF, frame by frame,
at 1e-12 (lengths below 1 m, so absolute in [m] and in rotation-matrix entries).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from scara_pin import UrdfError, load_urdf, robot_from_urdf
from scara_pin.description.dh import (
    DHTableError,
    dh_example,
    dh_examples,
    dh_to_urdf,
    load_dh_table,
    parse_dh_table,
)
from scara_pin.description.yaml_units import load_yaml
from scara_pin.errors import InvalidInputError, ParameterError

TOL = 1e-12  # [m] and rotation entries: FK of the URDF vs the D-H product
IK_TOL = 1e-9  # [m, rad]: FK(IK(p)) vs p


# ------------------------------------------------------------------ the D-H products, written independently
def Rz(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def Rx(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def Ry(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])


def T(x: float, y: float, z: float) -> np.ndarray:
    M = np.eye(4)
    M[:3, 3] = (x, y, z)
    return M


def dh_frames(table: dict, q: np.ndarray) -> list[np.ndarray]:
    """0_T_i for i = 1..n, then 0_T_tool, straight from the convention's formula."""
    out, M = [], np.eye(4)
    for row, qi in zip(table["joints"], q):
        off = row.get("offset", 0.0)
        theta = qi + off if row["type"] == "R" else row["theta"]
        d = qi + off if row["type"] == "P" else row["d"]
        if table["convention"] == "standard":  # A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha)
            A = Rz(theta) @ T(0, 0, d) @ T(row["a"], 0, 0) @ Rx(row["alpha"])
        else:  # A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta) Tz(d)
            A = Rx(row["alpha"]) @ T(row["a"], 0, 0) @ Rz(theta) @ T(0, 0, d)
        M = M @ A
        out.append(M)
    tool = table.get("tool", {})
    x, y, z = tool.get("xyz", (0, 0, 0))
    r, p, w = tool.get("rpy", (0, 0, 0))
    out.append(M @ T(x, y, z) @ Rz(w) @ Ry(p) @ Rx(r))
    return out


def pin_frames(urdf: str, n: int, q: np.ndarray) -> list[np.ndarray]:
    model = pin.buildModelFromXML(urdf)
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    base = data.oMf[model.getFrameId("base")]
    names = [f"link{i}" for i in range(1, n + 1)] + ["tool0"]
    return [base.actInv(data.oMf[model.getFrameId(name)]).homogeneous for name in names]


SPECIAL_ALPHAS = (0.0, math.pi, -math.pi, math.pi / 2, -math.pi / 2)


def random_table(rng: np.random.Generator, convention: str, n: int) -> dict:
    rows = []
    for i in range(n):
        kind = "R" if rng.random() < 0.6 else "P"
        alpha = float(SPECIAL_ALPHAS[rng.integers(len(SPECIAL_ALPHAS))]) if rng.random() < 0.6 else float(
            rng.uniform(-math.pi, math.pi))
        row = {"name": f"j{i + 1}", "type": kind, "a": float(rng.uniform(-0.5, 0.5)), "alpha": alpha,
               "offset": float(rng.uniform(-math.pi, math.pi) if kind == "R" else rng.uniform(-0.2, 0.2)),
               "lower": -3.0, "upper": 3.0, "velocity": 1.0, "effort": 1.0}
        if kind == "R":
            row.update(theta="q", d=float(rng.uniform(-0.5, 0.5)))
        else:
            row.update(d="q", theta=float(rng.uniform(-math.pi, math.pi)))
        rows.append(row)
    tool = {"xyz": [float(v) for v in rng.uniform(-0.1, 0.1, 3)], "rpy": [float(v) for v in rng.uniform(-3, 3, 3)]}
    return {"name": "random", "convention": convention, "units": {"length": "m", "angle": "rad"},
            "joints": rows, "tool": tool}


def frame_error(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.abs(A - B).max())


# ------------------------------------------------------------------ FK of the URDF = D-H product
@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", range(8))
def test_urdf_fk_equals_dh_product_random_tables(convention: str, seed: int) -> None:
    rng = np.random.default_rng(1000 + seed)
    n = int(rng.integers(1, 7))
    table = random_table(rng, convention, n)
    urdf = dh_to_urdf(table)
    for q in rng.uniform(-3, 3, size=(25, n)):
        for i, (got, want) in enumerate(zip(pin_frames(urdf, n, q), dh_frames(table, q))):
            assert frame_error(got, want) <= TOL, (convention, seed, i, q)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_every_special_alpha_is_exact(convention: str) -> None:
    """alpha in {0, pi, -pi, pi/2, -pi/2} on every row, with offsets at pi/2 (the rpy gimbal lock if merged)."""
    rng = np.random.default_rng(3)
    for alpha in SPECIAL_ALPHAS:
        table = random_table(rng, convention, 4)
        for row in table["joints"]:
            row["alpha"] = alpha
            row["offset"] = math.pi / 2
        urdf = dh_to_urdf(table)
        for q in rng.uniform(-3, 3, size=(10, 4)):
            for got, want in zip(pin_frames(urdf, 4, q), dh_frames(table, q)):
                assert frame_error(got, want) <= TOL


def test_the_dh_product_is_not_trivially_matched() -> None:
    """Guard on the test's own route: swapping the conventions gives a different product."""
    table = random_table(np.random.default_rng(11), "standard", 4)
    urdf = dh_to_urdf(table)
    other = dict(table, convention="modified")
    q = np.array([0.3, -0.2, 0.1, 0.7])
    assert max(frame_error(g, w) for g, w in zip(pin_frames(urdf, 4, q), dh_frames(other, q))) > 1e-3


# ------------------------------------------------------------------ the shipped examples (S1, S3)
def _load(name: str) -> dict:
    data = load_yaml(dh_example(name).read_text(encoding="utf-8"))
    for row in data["joints"]:  # the examples write alpha = pi as text; the test's product needs the number
        row.update({k: math.pi for k, v in row.items() if v == "pi"})
    return data


def test_examples_are_shipped() -> None:
    assert set(dh_examples()) >= {"s1_dh", "s3_dh"}
    # under urdf/, which the wheel force-includes as scara_pin/urdf
    assert dh_example("s1_dh").parent.parent.name == "urdf"


@pytest.mark.parametrize("name", ["s1_dh", "s3_dh"])
def test_example_fk_equals_its_dh_product(name: str) -> None:
    data = _load(name)
    robot = robot_from_urdf(dh_to_urdf(dh_example(name)), origin=name)
    lo, hi = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    for q in np.random.default_rng(21).uniform(lo, hi, size=(100, 4)):
        want = dh_frames(data, q)[-1]
        got = robot.tool_placement(q).homogeneous
        assert frame_error(got, want) <= TOL


def test_s1_example_matches_the_digest_formulas() -> None:
    """S1 (corrected, digest): x = l1 c1 + l2 c12, y = l1 s1 + l2 s12, z = d1 - q3, yaw = q1 + q2 - q4."""
    robot = robot_from_urdf(dh_to_urdf(dh_example("s1_dh")))
    for q in np.random.default_rng(2).uniform(robot.model.lowerPositionLimit, robot.model.upperPositionLimit,
                                              size=(100, 4)):  # fmt: skip
        q1, q2, q3, q4 = q
        want = [0.05 * math.cos(q1) + 0.15 * math.cos(q1 + q2), 0.05 * math.sin(q1) + 0.15 * math.sin(q1 + q2),
                0.100 - q3, q1 + q2 - q4]  # fmt: skip
        got = robot.tool_pose(q)
        assert np.abs(got[:3] - want[:3]).max() <= TOL
        assert abs(math.remainder(got[3] - want[3], 2 * math.pi)) <= TOL
        assert robot.tool_placement(q).rotation[2, 2] == pytest.approx(-1.0, abs=TOL)  # tool z down


def test_s1_and_s3_are_the_same_robot() -> None:
    """S3's q = (q1, q2, d1 - q3, -q4) of S1 gives the same tool position and yaw; tool z differs (down/up)."""
    s1 = robot_from_urdf(dh_to_urdf(dh_example("s1_dh")), origin="s1")
    s3 = robot_from_urdf(dh_to_urdf(dh_example("s3_dh")), origin="s3")
    d1 = 0.100
    lo, hi = s1.model.lowerPositionLimit, s1.model.upperPositionLimit
    for q in np.random.default_rng(4).uniform(lo, hi, size=(200, 4)):
        q3 = np.array([q[0], q[1], d1 - q[2], -q[3]])
        assert np.all(q3 >= s3.model.lowerPositionLimit) and np.all(q3 <= s3.model.upperPositionLimit)
        a, b = s1.tool_pose(q), s3.tool_pose(q3)
        assert np.abs(a[:3] - b[:3]).max() <= TOL
        assert abs(math.remainder(a[3] - b[3], 2 * math.pi)) <= TOL
        Ra, Rb = s1.tool_placement(q).rotation, s3.tool_placement(q3).rotation
        assert np.abs(Ra @ np.diag([1.0, -1.0, -1.0]) - Rb).max() <= TOL  # up to Rx(pi) on the tool
    # and the closed-form IK of each finds the other's configuration
    q = np.array([0.4, -0.9, 0.03, 1.2])
    q3 = np.array([0.4, -0.9, d1 - 0.03, -1.2])
    res = s3.ik(s1.tool_pose(q))
    assert min(np.abs(s.q - q3).max() for s in res.solutions) <= IK_TOL


@pytest.mark.parametrize("name", ["s1_dh", "s3_dh"])
def test_example_ik_round_trip(name: str) -> None:
    robot = robot_from_urdf(dh_to_urdf(dh_example(name)), origin=name)
    lo, hi = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    for q in np.random.default_rng(8).uniform(lo, hi, size=(200, 4)):
        p = robot.tool_pose(q)
        res = robot.ik(p)
        assert res.success, res.message
        for s in res.solutions:
            e = robot.tool_pose(s.q) - p
            e[3] = math.remainder(e[3], 2 * math.pi)
            assert np.abs(e).max() <= IK_TOL


def test_urdf_names_and_limits() -> None:
    import xml.etree.ElementTree as ET

    root = ET.fromstring(dh_to_urdf(dh_example("s1_dh")))
    links = {el.get("name") for el in root.iter("link")}
    assert {"base_link", "base", "link1", "link4", "tool0"} <= links
    joints = {el.get("name"): el for el in root.iter("joint")}
    lim = joints["joint1"].find("limit")
    assert float(lim.get("lower")) == -math.radians(170)  # !degrees read as radians, written as repr
    assert joints["joint3"].get("type") == "prismatic"
    assert float(joints["joint3"].find("limit").get("upper")) == 0.1


def test_load_from_path_and_string_path(tmp_path: Path) -> None:
    text = dh_example("s3_dh").read_text(encoding="utf-8")
    p = tmp_path / "t.yaml"
    p.write_text(text, encoding="utf-8")
    assert dh_to_urdf(p) == dh_to_urdf(str(p)) == dh_to_urdf(load_dh_table(p))


def test_pi_expressions_and_tags() -> None:
    data = _load("s1_dh")
    cases = (("pi", math.pi), ("-pi/2", -math.pi / 2), ("2*pi/3", 2 * math.pi / 3), ("+ pi / 4", math.pi / 4))
    for text, value in cases:
        data["joints"][1]["alpha"] = text
        assert parse_dh_table(data).rows[1].alpha == pytest.approx(value, abs=1e-15)
    raw = load_yaml("a: !millimeters 50\nb: !degrees 90")
    assert raw == {"a": pytest.approx(0.05, abs=1e-17), "b": pytest.approx(math.pi / 2, abs=1e-16)}


# ------------------------------------------------------------------ validation: typed errors naming row and field
def _bad(mutate) -> DHTableError:
    data = _load("s1_dh")
    mutate(data)
    with pytest.raises(DHTableError) as info:
        parse_dh_table(data, origin="t.yaml")
    return info.value


@pytest.mark.parametrize(
    ("mutate", "needles"),
    [
        (lambda d: d["joints"][1].__setitem__("alpha", float("nan")), ["t.yaml", "row 2", "joint2", "alpha", "finite"]),
        (lambda d: d["joints"][0].__setitem__("a", float("inf")), ["row 1", "a", "finite"]),
        (lambda d: d["joints"][0].__setitem__("a", "0.05; import os"), ["row 1", "a", "must be a number"]),
        (lambda d: d["joints"][0].__setitem__("a", "__import__('os')"), ["row 1", "a", "must be a number"]),
        (lambda d: d["joints"][0].__setitem__("d", True), ["row 1", "d", "must be a number"]),
        (lambda d: d["joints"][0].__setitem__("a", [1]), ["row 1", "a", "must be a number"]),
        (lambda d: d["joints"][0].__setitem__("a", 1e9), ["row 1", "a", "within"]),
        (lambda d: d["joints"][2].__setitem__("type", "X"), ["row 3", "joint3", "type", "R (revolute) or P"]),
        (lambda d: d["joints"][2].__setitem__("type", None), ["row 3", "type"]),
        (lambda d: d["joints"][0].__setitem__("theta", 0.3), ["row 1", "theta", "variable", "offset"]),
        (lambda d: d["joints"][2].__setitem__("d", 0.1), ["row 3", "d", "variable"]),
        (lambda d: d["joints"][1].pop("alpha"), ["row 2", "alpha", "required"]),
        (lambda d: d["joints"][1].pop("lower"), ["row 2", "lower", "required"]),
        (lambda d: d["joints"][1].__setitem__("lower", 3.0), ["row 2", "lower", "must be < upper"]),
        (lambda d: d["joints"][1].__setitem__("upper", d["joints"][1]["lower"]), ["row 2", "lower", "< upper"]),
        (lambda d: d["joints"][3].__setitem__("velocity", 0.0), ["row 4", "joint4", "velocity", "> 0"]),
        (lambda d: d["joints"][3].__setitem__("effort", -1.0), ["row 4", "effort", "> 0"]),
        (lambda d: d["joints"][3].__setitem__("name", "joint1"), ["row 4", "name", "unique", "row 1"]),
        (lambda d: d["joints"][3].__setitem__("name", "tool0"), ["row 4", "name", "generated link"]),
        (lambda d: d["joints"][3].__setitem__("name", "a b"), ["row 4", "name"]),
        (lambda d: d["joints"][3].__setitem__("name", "${evil}"), ["row 4", "name"]),
        (lambda d: d["joints"][3].__setitem__("alhpa", 0.0), ["row 4", "alhpa", "not a field"]),
        (lambda d: d["joints"].__setitem__(0, [1, 2]), ["row 1", "mapping"]),
        (lambda d: d.__setitem__("convention", "craig"), ["convention", "standard or modified"]),
        (lambda d: d.pop("convention"), ["convention", "standard or modified"]),
        (lambda d: d.pop("units"), ["units", "must be stated"]),
        (lambda d: d.__setitem__("units", {"length": "mm", "angle": "rad"}), ["units.length", "must be m"]),
        (lambda d: d.__setitem__("units", {"length": "m", "angle": "deg"}), ["units.angle", "must be rad"]),
        (lambda d: d.__setitem__("joints", []), ["joints", "non-empty"]),
        (lambda d: d.__setitem__("joints", [d["joints"][0]] * 65), ["joints", "at most 64"]),
        (lambda d: d.__setitem__("name", "x\"/><evil"), ["name"]),
        (lambda d: d.__setitem__("tool", {"xyz": [0, 0]}), ["tool.xyz", "3 numbers"]),
        (lambda d: d.__setitem__("tool", {"rpy": [0, "nan", 0]}), ["tool.rpy[1]", "number"]),
        (lambda d: d.__setitem__("tool", {"quat": [0, 0, 0, 1]}), ["quat", "not a field"]),
        (lambda d: d.__setitem__("extra", 1), ["extra", "not a field"]),
    ],
)  # fmt: skip
def test_bad_table_is_refused_naming_row_and_field(mutate, needles: list[str]) -> None:
    err = _bad(mutate)
    msg = str(err)
    assert "\n" not in msg
    for needle in needles:
        assert needle in msg, msg
    assert isinstance(err, ParameterError) and isinstance(err, InvalidInputError)
    assert err.exit_code == 2


def test_error_attributes() -> None:
    err = _bad(lambda d: d["joints"][1].__setitem__("alpha", "x"))
    assert (err.row, err.field) == (2, "alpha")


def test_not_a_mapping() -> None:
    for data in (None, [1, 2], "text", 3):
        with pytest.raises(DHTableError, match="mapping"):
            parse_dh_table(data)


@pytest.mark.parametrize(
    ("text", "needle"),
    [("name: [unclosed\n", "valid yaml (line"), ("joints: !!python/object:os.system x\n", "valid yaml"),
     ("convention: standard\nunits: {length: m, angle: rad}\njoints:\n  - {name: j1, type: R, theta: q, d: 0,"
      " a: !degrees abc, alpha: 0, lower: -1, upper: 1, velocity: 1, effort: 1}\n", "row 1 (j1) a")],
)  # fmt: skip
def test_bad_yaml_file(tmp_path: Path, text: str, needle: str) -> None:
    p = tmp_path / "bad.yaml"
    p.write_text(text, encoding="utf-8")
    with pytest.raises(DHTableError) as info:
        load_dh_table(p)
    assert needle in str(info.value) and str(p) in str(info.value)


def test_missing_file_and_bad_encoding(tmp_path: Path) -> None:
    with pytest.raises(DHTableError, match="cannot be read"):
        load_dh_table(tmp_path / "none.yaml")
    p = tmp_path / "latin.yaml"
    p.write_bytes(b"name: \xe9\xff\n")
    with pytest.raises(DHTableError, match="cannot be read"):
        load_dh_table(p)


def test_unknown_example() -> None:
    with pytest.raises(DHTableError, match="s1_dh"):
        dh_example("nope")


# ------------------------------------------------------------------ property tests (hypothesis)
finite = st.floats(-0.5, 0.5, allow_nan=False)
angle = st.one_of(st.sampled_from(SPECIAL_ALPHAS), st.floats(-math.pi, math.pi, allow_nan=False))


@st.composite
def dh_tables(draw: st.DrawFn, scara: bool = False) -> dict:
    convention = draw(st.sampled_from(["standard", "modified"]))
    if scara:  # vertical parallel axes (alpha in {0, pi}), one prismatic joint anywhere, arms of real length
        n = 4
        kinds = ["R", "R", "R"]
        kinds.insert(draw(st.integers(0, 3)), "P")
    else:
        n = draw(st.integers(1, 6))
        kinds = [draw(st.sampled_from(["R", "P"])) for _ in range(n)]
    rows = []
    for i, kind in enumerate(kinds):
        alpha = draw(st.sampled_from((0.0, math.pi, -math.pi))) if scara else draw(angle)
        a = draw(st.floats(0.05, 0.5)) * draw(st.sampled_from((1.0, -1.0))) if scara else draw(finite)
        row = {"name": f"j{i + 1}", "type": kind, "a": a, "alpha": alpha,
               "offset": draw(angle) if kind == "R" else draw(st.floats(-0.2, 0.2)),
               "lower": -2.5, "upper": 2.5, "velocity": 1.0, "effort": 1.0}
        if kind == "R":
            row.update(theta="q", d=draw(finite))
        else:
            row.update(d="q", theta=draw(angle), lower=-0.3, upper=0.3)
        rows.append(row)
    rpy = [draw(st.sampled_from((0.0, math.pi))), 0.0, draw(angle)] if scara else [draw(angle) for _ in range(3)]
    tool = {"xyz": [draw(finite) for _ in range(3)], "rpy": rpy}
    return {"name": "h", "convention": convention, "units": {"length": "m", "angle": "rad"}, "joints": rows,
            "tool": tool}


@settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(table=dh_tables(), seed=st.integers(0, 2**32 - 1))
def test_property_urdf_agrees_with_dh_product(table: dict, seed: int) -> None:
    n = len(table["joints"])
    urdf = dh_to_urdf(table)
    for q in np.random.default_rng(seed).uniform(-2.5, 2.5, size=(5, n)):
        for got, want in zip(pin_frames(urdf, n, q), dh_frames(table, q)):
            assert frame_error(got, want) <= TOL


def _arm_lengths_ok(table: dict) -> bool:
    """The closed form needs arms of length: the plan-view distance between consecutive revolute axes."""
    robot = robot_from_urdf(dh_to_urdf(table))
    try:
        geo = robot.kinematics.geometry
    except UrdfError:  # NotScaraError: an arm of zero length (two revolute axes on one line)
        return False
    return min(geo.l1, geo.l2) > 0.02


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(table=dh_tables(scara=True), seed=st.integers(0, 2**32 - 1))
def test_property_ik_round_trip_on_dh_scaras(table: dict, seed: int) -> None:
    from hypothesis import assume

    assume(_arm_lengths_ok(table))
    robot = robot_from_urdf(dh_to_urdf(table))
    lo, hi = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    for q in np.random.default_rng(seed).uniform(lo, hi, size=(20, 4)):
        want = dh_frames(table, q)[-1]
        assert frame_error(robot.tool_placement(q).homogeneous, want) <= TOL
        p = robot.tool_pose(q)
        res = robot.ik(p)
        assert res.success, res.message
        assert min(np.abs(s.q - q).max() for s in res.solutions) <= 1e-7
        for s in res.solutions:
            e = robot.tool_pose(s.q) - p
            e[3] = math.remainder(e[3], 2 * math.pi)
            assert np.abs(e).max() <= IK_TOL


def test_dataclasses_validate_themselves() -> None:
    from scara_pin.description.dh import DHRow, DHTable

    good = dict(name="j1", type="R", theta=0.0, d=0.1, a=0.2, alpha=0.0, offset=0.0, lower=-1.0, upper=1.0,
                velocity=1.0, effort=1.0)
    row = DHRow(**good)
    for change, needle in ((dict(name="a b"), "name"), (dict(type="X"), "type"), (dict(a=math.nan), "finite"),
                           (dict(lower=2.0), "< upper"), (dict(velocity=0.0), "> 0")):
        with pytest.raises(DHTableError, match=needle):
            DHRow(**{**good, **change})
    with pytest.raises(DHTableError, match="convention"):
        DHTable("t", "craig", (row,))
    with pytest.raises(DHTableError, match="rows"):
        DHTable("t", "standard", ())
    with pytest.raises(DHTableError, match="tool_xyz"):
        DHTable("t", "standard", (row,), tool_xyz=(0.0, math.inf, 0.0))
    assert "<robot" in dh_to_urdf(DHTable("t", "standard", (row,)))


def test_kr5_table_equals_the_hand_written_kr5_urdf() -> None:
    """The KUKA KR5 SCARA standard table (alpha = 0, pi, pi, 0) through dh_to_urdf and the hand-written fixture
    tests/data/third_party/kr5_scara_dh.urdf (joint origins holding the previous row's constants) agree."""
    d = math.radians
    table = {
        "name": "kr5", "convention": "standard", "units": {"length": "m", "angle": "rad"},
        "joints": [
            {"name": "a1", "type": "R", "theta": "q", "d": 0.246, "a": 0.125, "alpha": 0.0, "lower": -d(155),
             "upper": d(155), "velocity": d(525), "effort": 100},
            {"name": "a2", "type": "R", "theta": "q", "d": 0.0, "a": 0.225, "alpha": "pi", "lower": -d(145),
             "upper": d(145), "velocity": d(525), "effort": 100},
            {"name": "a3", "type": "P", "theta": 0.0, "d": "q", "a": 0.0, "alpha": "pi", "lower": 0.046,
             "upper": 0.200, "velocity": 1.0, "effort": 300},
            {"name": "a4", "type": "R", "theta": "q", "d": 0.0, "a": 0.0, "alpha": 0.0, "lower": -d(358),
             "upper": d(358), "velocity": d(2400), "effort": 20},
        ],
    }  # fmt: skip
    generated = robot_from_urdf(dh_to_urdf(table), origin="kr5 table")
    hand = load_urdf(Path(__file__).parent / "data" / "third_party" / "kr5_scara_dh.urdf")
    assert np.allclose(generated.model.lowerPositionLimit, hand.model.lowerPositionLimit, rtol=0, atol=1e-14)
    for q in np.random.default_rng(31).uniform(hand.model.lowerPositionLimit, hand.model.upperPositionLimit,
                                               size=(100, 4)):  # fmt: skip
        assert frame_error(generated.tool_placement(q).homogeneous, hand.tool_placement(q).homogeneous) <= TOL
