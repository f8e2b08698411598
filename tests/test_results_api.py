"""Python results as a Pinocchio / robotics-toolbox user expects them (issue 31 item 5): payloads in kilograms,
results that print as their summary, one plotting signature, ``robot.plot(q)``.

Independent routes: the payload's effect on the model from its masses (Pinocchio's own inertias); the stick
figure against the SCARA's closed-form forward kinematics written here (l1, l2 from the robot's yaml).
"""

from __future__ import annotations

import contextlib
import importlib
import inspect
import io
import math
import pkgutil
import re

import numpy as np
import pytest

import scara_pin
from scara_pin import ParameterError, load_robot
from scara_pin.cli import main
from scara_pin.motion.payload import Payload, as_payload, with_payload
from scara_pin.units import HUMAN, DisplayUnits

MAX_REPR = 2500  # characters: a summary, never the arrays


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


def _public_callables():
    for info in pkgutil.walk_packages(scara_pin.__path__, "scara_pin."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]) or ".cli" in info.name:
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if inspect.isfunction(obj) or inspect.isclass(obj):
                yield f"{info.name}.{name}", obj


# ------------------------------------------------------------------------------------------------ payload
def test_every_public_function_that_takes_a_payload_takes_kilograms() -> None:
    takers = {}
    for where, obj in _public_callables():
        if inspect.isclass(obj) and not where.endswith("Request"):  # results record the Payload they carried
            continue
        try:
            params = inspect.signature(obj).parameters
        except (TypeError, ValueError):
            continue
        if "payload" in params:
            takers[where] = str(params["payload"].annotation)
    assert len(takers) >= 6, takers  # standard_cycle, arch_move, jump_move, verify, with_payload, MotionRequest
    assert all("PayloadLike" in a for a in takers.values()), takers


def test_a_number_is_kilograms_at_the_tool(robot) -> None:
    assert as_payload(2.0) == Payload(2.0) and as_payload(3) == Payload(3.0) and as_payload(None) == Payload()
    joint = robot.model.frames[robot.tool_id].parentJoint
    base = robot.model.inertias[joint].mass
    assert with_payload(robot, 2.0).model.inertias[joint].mass == pytest.approx(base + 2.0, abs=1e-12)
    assert with_payload(robot, 0.0) is robot
    for bad in (-1.0, math.nan, True, "2", [2.0]):
        with pytest.raises(ParameterError):
            as_payload(bad)  # type: ignore[arg-type]


def test_motion_calls_take_kilograms(robot) -> None:
    from scara_pin.motion.cycle import standard_cycle
    from scara_pin.motion.plan import MotionRequest
    from scara_pin.motion.timing import time_optimal
    from scara_pin.motion.verify import verify

    traj = time_optimal(robot, [[0.0, 0.0, 0.0, 0.0], [0.5, 1.0, 0.02, 0.3]])
    as_number = verify(robot, traj, torque=True, payload=2.0).torque
    as_object = verify(robot, traj, torque=True, payload=Payload(2.0)).torque
    unloaded = verify(robot, traj, torque=True).torque
    assert as_number is not None and as_object is not None and unloaded is not None
    assert as_number.ratio == as_object.ratio and as_number.ratio != unloaded.ratio
    assert MotionRequest(start_q=[0, 0, 0, 0], end_q=[0.1, 0, 0, 0], torque=True, payload=2).payload == Payload(2.0)
    cycle = standard_cycle(robot, payload=2.0)  # the issue: AttributeError: 'float' object has no attribute 'mass'
    assert cycle.move.payload == Payload(2.0)


# ------------------------------------------------------------------------------------------------ repr
@pytest.fixture(scope="module")
def results(robot):
    from scara_pin.calibration import plan_experiment
    from scara_pin.motion.cycle import arch_path, standard_cycle
    from scara_pin.motion.jerk import time_optimal_jerk
    from scara_pin.motion.plan import MotionRequest, plan_motion
    from scara_pin.motion.verify import verify
    from scara_pin.viz import show
    from scara_pin.workspace import workspace_of

    plan = plan_motion(robot, MotionRequest(start_q=[0, 0, 0, 0], end_q=[0.5, 0.5, 0.02, 0.1]))
    cycle = standard_cycle(robot)
    lines = standard_cycle(robot, path="lines")
    path = arch_path(robot, [0.26087, -0.1525, -0.0875, 0.0], [0.26087, 0.1525, -0.0875, 0.0], rise=0.025)
    return {
        "IKResult": robot.ik([0.3, 0.1, -0.1, 0.5]),
        "BatchIKResult": robot.ik_batch(np.array([[0.3, 0.1, -0.1, 0.5], [5.0, 0.0, 0.0, 0.0]])),
        "MotionPlan": plan,
        "Trajectory": plan.trajectory,
        "Verification": verify(robot, plan.trajectory, torque=True),
        "CycleResult": cycle,
        "JumpMove": cycle.move,
        "ArchMove": lines.move,
        "JerkResult": time_optimal_jerk(robot, path, 2000.0),
        "Workspace": workspace_of(robot),
        "ExperimentPlan": plan_experiment(robot, 20),
        "SceneView": show(robot),
        "Robot": robot,
    }


KINDS = ("IKResult", "BatchIKResult", "MotionPlan", "Trajectory", "Verification", "CycleResult", "JumpMove", "ArchMove",
         "JerkResult", "Workspace", "ExperimentPlan", "SceneView", "Robot")  # fmt: skip


@pytest.mark.parametrize("kind", KINDS)
def test_results_print_a_short_summary(results, kind) -> None:
    obj = results[kind]
    text = repr(obj)
    assert type(obj).__name__ == kind and 20 < len(text) < MAX_REPR, (kind, len(text))
    assert "array(" not in text and "<html" not in text.lower()
    html = obj._repr_html_()
    if kind == "SceneView":  # Jupyter's view is the page itself; the repr is one line
        assert html.startswith("<iframe srcdoc=") and f"{len(obj.html):,} characters" in text
    elif kind != "Robot":
        assert html.startswith("<pre") and len(html) < 2 * MAX_REPR


def test_the_cycle_prints_as_the_command_line_does(results) -> None:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["cycle"]) == 0
    solved = re.compile(r"; solved in .*$")  # the solve's wall time differs between two runs
    cli = [solved.sub("", line) for line in out.getvalue().splitlines()]
    mine = [solved.sub("", line) for line in repr(results["CycleResult"]).splitlines()]
    assert mine == cli and len(mine) >= 10


# ------------------------------------------------------------------------------------------------ plots
def test_one_plotting_signature() -> None:
    """plot_*(result, path=None, *, ..., units=...) -> Figure, everywhere."""
    plots = {where: obj for where, obj in _public_callables()
             if inspect.isfunction(obj) and obj.__name__.startswith("plot_")}  # fmt: skip
    assert {w.rsplit(".", 1)[1] for w in plots} >= {"plot_trajectory", "plot_cycle", "plot_workspace", "plot_envelope",
                                                    "plot_residuals", "plot_robot"}  # fmt: skip
    for where, fn in plots.items():
        params = list(inspect.signature(fn).parameters.values())
        first, path = params[0], next(p for p in params if p.name == "path")
        assert first.kind is first.POSITIONAL_OR_KEYWORD and first.default is first.empty, where
        assert path.kind is path.POSITIONAL_OR_KEYWORD and path.default is None, where
        units = inspect.signature(fn).parameters["units"]
        assert units.kind is units.KEYWORD_ONLY and isinstance(units.default, DisplayUnits), where
        assert all(p.kind is p.KEYWORD_ONLY for p in params[params.index(path) + 1 :]), where
        assert "Figure" in str(inspect.signature(fn).return_annotation), where


def test_robot_plot_is_a_stick_figure_of_the_arm(robot, tmp_path) -> None:
    from scara_pin.viz.stick import STICK_GID, TOOL_GID

    q = np.array([0.4, -1.1, 0.03, 0.7])
    fig = robot.plot(q, tmp_path / "arm.png", units=HUMAN, view="top")
    assert (tmp_path / "arm.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    (line,) = [ln for ln in fig.axes[0].get_lines() if ln.get_gid() == STICK_GID]
    xy = np.column_stack([line.get_xdata(), line.get_ydata()]) / 1000.0  # mm -> m
    l1, l2 = robot.parameters.values["l1"], robot.parameters.values["l2"]  # closed form: the planar 2R arm
    elbow = l1 * np.array([math.cos(q[0]), math.sin(q[0])])
    wrist = elbow + l2 * np.array([math.cos(q[0] + q[1]), math.sin(q[0] + q[1])])
    np.testing.assert_allclose(xy[1], [0.0, 0.0], atol=1e-12)  # joint1 on the base axis
    np.testing.assert_allclose(xy[2], elbow, atol=1e-12)
    np.testing.assert_allclose(xy[-1], wrist, atol=1e-12)  # the tool (no tool offset on the default robot)
    np.testing.assert_allclose(xy[-1], robot.tool_pose(q)[:2], atol=1e-12)
    assert {ln.get_gid() for ln in fig.axes[0].get_lines()} >= {f"{TOOL_GID}-{a}" for a in "xyz"}
    three_d = robot.plot(q)  # the default: a 3-D view, SI
    assert three_d.axes[0].name == "3d" and "[m]" in three_d.axes[0].get_xlabel()
    with pytest.raises(ParameterError):
        robot.plot(q, view="front")
    with pytest.raises(ParameterError):
        robot.plot([0.1, 0.2])
