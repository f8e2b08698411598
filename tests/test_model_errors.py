"""The error tree (scara_pin.errors) and the errors of scara_pin.model: bad URDFs, bad q, bad frames."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from scara_pin import (
    DescriptionError,
    InfeasibleError,
    InvalidInputError,
    ParameterError,
    Robot,
    ScaraError,
    UnknownRobotError,
    UrdfError,
    generate_urdf,
    load_robot,
    load_urdf,
    robot_from_urdf,
)

JOINTS = ("joint1", "joint2", "joint3", "joint4")


@pytest.fixture(scope="module")
def robot() -> Robot:
    return load_robot("default")


# ------------------------------------------------------------------------------------ error tree
@pytest.mark.parametrize(
    ("cls", "code"),
    [
        (ScaraError, 1),
        (InvalidInputError, 2),
        (ParameterError, 2),
        (UnknownRobotError, 2),
        (UrdfError, 2),
        (InfeasibleError, 3),
        (DescriptionError, 1),
    ],
)
def test_exit_codes(cls: type, code: int) -> None:
    assert cls.exit_code == code
    assert issubclass(cls, ScaraError)


def test_hierarchy() -> None:
    for cls in (ParameterError, UnknownRobotError, UrdfError):
        assert issubclass(cls, InvalidInputError)
    assert issubclass(InvalidInputError, ValueError)
    assert not issubclass(InfeasibleError, InvalidInputError)
    assert not issubclass(DescriptionError, InvalidInputError)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("l1", -1.0, "must be > 0"), "l1 is -1.0; it must be > 0"),
        (("l1", "abc", "must be a number"), "l1 is 'abc'; it must be a number"),
        (("joint2_velocity", 0.0, "must be > 0", "rad/s"), "joint2_velocity is 0.0 rad/s; it must be > 0"),
        (("q", None, "is required"), "q is None; it is required"),
    ],
)
def test_parameter_error_message(args: tuple, message: str) -> None:
    err = ParameterError(*args)
    assert str(err) == message
    assert (err.name, err.value, err.rule) == args[:3]
    assert err.exit_code == 2


def test_unknown_robot_error_lists_the_robots() -> None:
    err = UnknownRobotError("nope", ["default", "s1"])
    assert "'nope'" in str(err) and "default, s1" in str(err)
    assert err.robot == "nope" and err.available == ["default", "s1"]


def _pickle_cases() -> list[ScaraError]:
    from scara_pin.errors import JobFileError, JobStepError, NoSolutionError, YamlError
    from scara_pin.kinematics.scara_geometry import IKStatus
    from scara_pin.limits import UnreadableFileError

    return [
        ParameterError("l1", -1.0, "must be > 0", "m"),
        NoSolutionError(IKStatus.OUT_OF_REACH, "0.54 m from the shoulder axis, beyond the reach 0.4 m"),
        UnknownRobotError("nope", ["default", "s1"]),
        YamlError("job file j.yaml", 3, "did not find expected node content"),
        JobFileError(Path("j.yaml"), 7, "point feeder is out of reach"),
        JobStepError(Path("j.yaml"), None, "the jump did not converge"),
        UnreadableFileError("job file", Path("/nope.yaml"), "No such file or directory", 2),
        InvalidInputError("a plain message"),
    ]


@pytest.mark.parametrize("error", _pickle_cases(), ids=lambda e: type(e).__name__)
def test_errors_survive_pickle(error: ScaraError) -> None:
    """A task's error on a Dask worker reaches the client by pickle: the same class, message, attributes and code
    (ParameterError, NoSolutionError and UnknownRobotError took more in __init__ than args keeps: loads failed)."""
    import pickle

    again = pickle.loads(pickle.dumps(error))
    assert type(again) is type(error)
    assert str(again) == str(error) and again.args == error.args
    assert again.__dict__ == error.__dict__
    assert again.exit_code == error.exit_code


# ------------------------------------------------------------------------------------- bad URDFs
def _link(name: str) -> str:
    return f'<link name="{name}"/>'


def _joint(name: str, parent: str, child: str, kind: str = "revolute") -> str:
    limit = '<limit lower="-1" upper="1" velocity="1" effort="1"/>' if kind in ("revolute", "prismatic") else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<axis xyz="0 0 1"/>{limit}</joint>'
    )


def _chain(kinds: list[str], extra: str = "", tool: bool = True) -> str:
    links = ["base"] + [f"l{i}" for i in range(1, len(kinds) + 1)]
    body = "".join(_link(n) for n in links)
    body += "".join(_joint(f"joint{i}", links[i - 1], links[i], k) for i, k in enumerate(kinds, start=1))
    if tool:
        body += _link("tool0") + _joint("tool_fixed", links[-1], "tool0", "fixed")
    return f'<robot name="r">{body}{extra}</robot>'


# (text, substrings the message must hold)
BAD_URDFS = {
    "malformed": ('<robot name="r">\n  <link name="a">\n</robot>\n', ["malformed XML", "line 3", "column"]),
    "not-xml": ("this is not xml", ["malformed XML", "line 1"]),
    "empty": ("", ["malformed XML"]),
    "root-not-robot": ('<sdf version="1.6"><model name="m"/></sdf>', ["<sdf>", "<robot>"]),
    "missing-link": (
        f'<robot name="r">{_link("a")}{_joint("j1", "a", "ghost_link")}</robot>',
        ["not a valid URDF", "ghost_link"],
    ),
    "two-roots": (
        f'<robot name="r">{_link("root_a")}{_link("root_b")}{_link("c")}{_joint("j1", "root_a", "c")}</robot>',
        ["not a valid URDF", "root"],
    ),
    "duplicate-links": (
        f'<robot name="r">{_link("dup_link")}{_link("dup_link")}{_link("b")}{_joint("j1", "dup_link", "b")}</robot>',
        ["not a valid URDF", "dup_link"],
    ),
    "cycle": (
        f'<robot name="r">{_link("a")}{_link("b")}{_joint("j1", "a", "b")}{_joint("j2", "b", "a")}</robot>',
        ["not a valid URDF"],
    ),
    "lonely-link": (f'<robot name="r">{_link("alone")}</robot>', ["nq = 0"]),
    "fixed-only": (_chain(["fixed", "fixed"]), ["nq = 0"]),
    # 3 joints (a SCARA without a wrist) are accepted: tests/test_three_joints.py
    # counted as check counts them (issue 39 item 4): joints, each with its URDF type, not Pinocchio's nq
    "two-joints": (_chain(["revolute", "prismatic"]), ["this file has 2 movable joints: joint1 (revolute), joint2 "
                                                       "(prismatic)", "4 single-DOF", "3 without a wrist"]),
    "five-joints": (_chain(["revolute"] * 5), ["this file has 5 movable joints"]),
    # a continuous joint (nq = 2, nv = 1) is accepted since continuous-joint support (tests/test_continuous.py);
    # a planar one (nq = 4, nv = 3) is not a single-DOF joint
    "planar-joint": (_chain(["revolute", "revolute", "prismatic", "planar"]),
                     ["4 movable joints", "joint4 (planar: 3 degrees of freedom)"]),
    # without tool0 the chain's last link is the tool (issue 13): tests/test_real_robots.py; an unknown
    # --tool / --base frame is the error there
}


@pytest.mark.parametrize("case", BAD_URDFS)
def test_bad_urdf_text(case: str, capfd: pytest.CaptureFixture[str]) -> None:
    text, needles = BAD_URDFS[case]
    with pytest.raises(UrdfError) as info:
        robot_from_urdf(text)
    message = str(info.value)
    for needle in needles:
        assert needle in message, (needle, message)
    assert info.value.exit_code == 2
    out, err = capfd.readouterr()
    assert (out, err) == ("", ""), "urdfdom (or pinocchio) wrote to the real stdout/stderr"


@pytest.mark.parametrize("case", BAD_URDFS)
def test_bad_urdf_file(case: str, tmp_path: Path, capfd: pytest.CaptureFixture[str]) -> None:
    text, needles = BAD_URDFS[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(text, encoding="utf-8")
    loaders = (lambda: load_robot(urdf=path), lambda: load_robot("default", urdf=str(path)), lambda: load_urdf(path))
    for loader in loaders:
        with pytest.raises(UrdfError) as info:
            loader()
        message = str(info.value)
        assert str(path) in message
        for needle in needles:
            assert needle in message, (needle, message)
    out, err = capfd.readouterr()
    assert (out, err) == ("", "")


def test_malformed_xml_names_line_and_column() -> None:
    text = '<robot name="r">\n  <link name="a"/>\n  <link name="b" <oops/>\n</robot>'
    with pytest.raises(UrdfError, match=r"line 3, column \d+"):
        robot_from_urdf(text)


@pytest.mark.parametrize("name", ["missing.urdf", "no/such/dir/x.urdf"])
def test_urdf_file_that_does_not_exist(name: str, tmp_path: Path) -> None:
    path = tmp_path / name
    with pytest.raises(UrdfError) as info:
        load_robot(urdf=path)
    assert str(path) in str(info.value) and "cannot be read" in str(info.value)


def test_urdf_path_is_a_directory(tmp_path: Path) -> None:
    with pytest.raises(UrdfError, match="cannot be read"):
        load_robot(urdf=tmp_path)


def test_urdf_file_not_utf8(tmp_path: Path) -> None:
    path = tmp_path / "latin1.urdf"
    path.write_bytes(b'<robot name="r\xe9"/>')
    with pytest.raises(UrdfError, match="cannot be read"):
        load_robot(urdf=path)


def test_overrides_with_urdf_file_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "scara.urdf"
    path.write_text(generate_urdf("default"), encoding="utf-8")
    with pytest.raises(InvalidInputError, match="overrides"):
        load_robot(overrides={"l1": 0.3}, urdf=path)


def test_good_urdf_file_loads_with_its_limits(tmp_path: Path, robot: Robot, capfd: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "scara.urdf"
    path.write_text(generate_urdf("default"), encoding="utf-8")
    from_file = load_robot(urdf=path)
    assert from_file.model.nq == 4
    assert from_file.limits.lower[0] == pytest.approx(math.radians(-132), abs=1e-15)
    assert from_file.limits.upper[2] - from_file.limits.lower[2] == pytest.approx(0.150, abs=1e-15)
    assert all(math.isnan(a) for a in from_file.limits.acceleration)  # URDF has no accelerations
    q = np.array([0.4, -1.2, 0.07, 2.0])
    assert from_file.tool_pose(q) == pytest.approx(robot.tool_pose(q), abs=1e-12)
    assert capfd.readouterr() == ("", "")


# ------------------------------------------------------------------------------------------ check_q
@pytest.mark.parametrize("index", range(4))
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_check_q_non_finite_names_the_joint(robot: Robot, index: int, bad: float) -> None:
    q = [0.1, 0.2, 0.03, 0.4]
    q[index] = bad
    with pytest.raises(ParameterError) as info:
        robot.check_q(q)
    assert info.value.name == JOINTS[index]
    assert "finite" in info.value.rule


@pytest.mark.parametrize(
    "q",
    [
        [],
        [0.1, 0.2, 0.3],
        [0.1, 0.2, 0.3, 0.4, 0.5],
        [[0.1, 0.2, 0.3, 0.4]],
        np.zeros((2, 4)),
        0.5,
        None,
        ["a", "b", "c", "d"],
        ["0.1", "x", "0", "0"],
        "abcd",
        "0.1 0.2 0.3 0.4",
        {"q1": 0.1},
        [1j, 0, 0, 0],
        [object(), 0, 0, 0],
    ],
    ids=lambda q: re.sub(r" at 0x[0-9a-f]+", "", repr(q)),  # no address: the same ids in every process
)
def test_check_q_refuses(robot: Robot, q: object) -> None:
    with pytest.raises(ParameterError) as info:
        robot.check_q(q)
    assert info.value.name == "q"


def test_check_q_refuses_numeric_strings(robot: Robot) -> None:
    with pytest.raises(ParameterError):
        robot.check_q(["0.1", "0.2", "0.03", "0.4"])


@pytest.mark.parametrize("method", ["tool_pose", "tool_placement", "task_jacobian", "frame_jacobian", "manipulability"])
def test_kinematics_check_q(robot: Robot, method: str) -> None:
    with pytest.raises(ParameterError):
        getattr(robot, method)([0.0, math.nan, 0.0, 0.0])
    with pytest.raises(ParameterError):
        getattr(robot, method)([0.0, 0.0, 0.0])


_ARRAY_REFUSED = {
    "NaN": np.array([0.1, math.nan, 0.0, 0.0]),
    "inf": np.array([0.1, 0.2, -math.inf, 0.0]),
    "beyond 1e6": np.array([0.0, 0.0, 0.0, 1.5e6]),
    "3 values": np.zeros(3),
    "5 values": np.zeros(5),
    "4 x 1": np.zeros((4, 1)),
    "1 x 4": np.zeros((1, 4)),
    "0-d": np.array(0.5),
    "booleans": np.array([True, False, True, False]),
    "complex": np.zeros(4, dtype=complex),
    "strings": np.array(["0.1", "0.2", "0.0", "0.0"]),
    "objects": np.array([0.1, 0.2, 0.0, None], dtype=object),
}


@pytest.mark.parametrize("method", ["tool_placement", "task_jacobian"])
@pytest.mark.parametrize("label", list(_ARRAY_REFUSED))
def test_per_call_paths_refuse_bad_arrays(robot: Robot, method: str, label: str) -> None:
    """The per-call paths take a float64 array as it is only when the inline test passes; anything else is
    checked in full: a bad q is a ParameterError, never a silent NaN or a Pinocchio exception."""
    with pytest.raises(ParameterError):
        getattr(robot, method)(_ARRAY_REFUSED[label])


@pytest.mark.parametrize(
    "q",
    [
        np.array([0.4, -1.2, 0.07, 2.0]),
        np.array([0.4, -1.2, 0.07, 2.0], dtype=np.float32).astype(np.float64)[::-1][::-1],  # a view
        np.array([[0.4, 9.0], [-1.2, 9.0], [0.07, 9.0], [2.0, 9.0]])[:, 0],  # not contiguous
        np.array([0.4, -1.2, 0.07, 2.0], dtype=np.float32),
        np.array([1, -1, 0, 2]),
        np.array([0.4, -1.2, 0.07, 2.0]).astype(">f8"),  # big-endian
        [0.4, -1.2, 0.07, 2.0],
        (1, -1, 0, 2),
    ],
    ids=["float64", "view", "strided", "float32", "int", "big-endian", "list", "tuple"],
)
def test_per_call_paths_equal_raw_pinocchio(robot: Robot, q: object) -> None:
    """Whatever the form of a valid q, FK and the task Jacobian are raw Pinocchio's on the same numbers (1e-12):
    baseMtool from framesForwardKinematics on the robot's own model, and the rows x, y, z, wz of its
    LOCAL_WORLD_ALIGNED frame Jacobian rotated into base axes."""
    values = np.array([float(v) for v in np.asarray(q).tolist()])
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, values)
    oMb, oMt = data.oMf[robot.base_id], data.oMf[robot.tool_id]
    J = pin.computeFrameJacobian(robot.model, data, values, robot.tool_id, pin.LOCAL_WORLD_ALIGNED)
    Rbo = oMb.rotation.T
    expected_J = np.vstack([Rbo @ J[:3], (Rbo @ J[3:])[2]])
    assert np.abs(robot.tool_placement(q).homogeneous - oMb.actInv(oMt).homogeneous).max() <= 1e-12
    got_J = robot.task_jacobian(q)
    assert got_J.shape == (4, 4)
    assert np.abs(got_J - expected_J).max() <= 1e-12


def test_per_call_results_are_not_shared(robot: Robot) -> None:
    """Each call returns its own objects: a result kept by the caller does not change with the next call."""
    q1, q2 = np.array([0.4, -1.2, 0.07, 2.0]), np.array([-0.3, 0.5, 0.01, -1.0])
    M1, J1 = robot.tool_placement(q1), robot.task_jacobian(q1)
    M1_copy, J1_copy = M1.homogeneous.copy(), J1.copy()
    robot.tool_placement(q2), robot.task_jacobian(q2)
    assert np.array_equal(M1.homogeneous, M1_copy) and np.array_equal(J1, J1_copy)


def test_check_q_accepts_four_numbers(robot: Robot) -> None:
    q = robot.check_q((1, 2, 0, -3))
    assert q.dtype == float and q.shape == (4,)
    assert q.tolist() == [1.0, 2.0, 0.0, -3.0]


# ------------------------------------------------------------------------------- frames, references
@pytest.mark.parametrize("reference", ["bogus", "", "task", "world_aligned"])
def test_frame_jacobian_bad_reference(robot: Robot, reference: str) -> None:
    with pytest.raises(InvalidInputError) as info:
        robot.frame_jacobian(np.zeros(4), reference=reference)
    assert repr(reference) in str(info.value)


@pytest.mark.parametrize(
    "reference", ["world", "WORLD", "local", "Local_World_Aligned", pin.ReferenceFrame.LOCAL_WORLD_ALIGNED]
)
def test_frame_jacobian_good_reference(robot: Robot, reference: object) -> None:
    J = robot.frame_jacobian(np.array([0.1, 0.2, 0.03, 0.4]), reference=reference)
    assert J.shape == (6, 4)
    assert np.isfinite(J).all()


def test_unknown_frame(robot: Robot) -> None:
    q = np.zeros(4)
    with pytest.raises(InvalidInputError, match="no_such_frame"):
        robot.frame_jacobian(q, frame="no_such_frame")
    with pytest.raises(InvalidInputError, match="no_such_frame"):
        robot.frame_placement(q, "no_such_frame")
    with pytest.raises(InvalidInputError, match="no_such_frame"):
        robot.frame_placement(q, "tool0", relative_to="no_such_frame")
    # the good names work
    assert robot.frame_placement(q, "link2").translation[0] == pytest.approx(0.2, abs=1e-12)


def test_a_subclass_override_of_the_per_call_paths_is_used(robot: Robot) -> None:
    """The closures stand in for the methods only on the class itself: a subclass's override is what its
    instances call (tool_pose and manipulability included), and super() reaches the base computation."""

    class Flange(Robot):
        def tool_placement(self, q: np.ndarray) -> pin.SE3:
            return super().tool_placement(q) * pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1]))

    flanged = Flange(robot.urdf)
    q = np.array([0.4, -1.2, 0.07, 2.0])
    plain = robot.tool_placement(q)
    expected = plain * pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1]))  # tool0's z points down: 0.1 m lower
    assert np.abs(flanged.tool_placement(q).homogeneous - expected.homogeneous).max() <= 1e-15
    assert flanged.tool_pose(q)[2] == pytest.approx(plain.translation[2] - 0.1, abs=1e-15)
    assert hasattr(Robot, "tool_placement") and hasattr(Robot, "task_jacobian")
    assert np.array_equal(Robot.task_jacobian(robot, q), robot.task_jacobian(q))


def test_many_q_by_mistake_are_refused_without_converting_them(robot: Robot) -> None:
    """An (N, 4) array passed as q is a ParameterError, decided from its size: it is never turned into a
    Python list first (2 million rows would take seconds and hundreds of MB)."""
    import tracemalloc

    many = np.zeros((2_000_000, 4))
    tracemalloc.start()
    try:
        for method in (robot.tool_placement, robot.task_jacobian):
            with pytest.raises(ParameterError, match="shape"):
                method(many)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1_000_000, peak


def test_ik_nearest_follows_a_replaced_kinematics() -> None:
    """ik_nearest is the kind's nearest, looked up once; replacing or resetting robot.kinematics resets it."""
    robot = load_robot("default")
    target = robot.tool_pose(np.array([0.4, -1.2, 0.07, 2.0]))
    first = robot.ik_nearest(target)

    class Fake:
        def nearest(self, *args: object, **kwargs: object) -> str:
            return "fake"

    robot.kinematics = Fake()  # type: ignore[assignment]
    assert robot.ik_nearest(target) == "fake"
    del robot.kinematics
    assert np.array_equal(robot.ik_nearest(target), first)
