"""What ``cycle`` tells (issue 31 item 4): the worst ratio of each limit that applies, the limits the bound
uses and leaves out, and the torque panel of the cycle plot with a payload or effort limits.

Independent route for the torques: Pinocchio's RNEA on a model the test loads itself with the payload
appended as a body (tests/test_cycle.py's route, not the library's ``with_payload``), on the cycle sampled
at 20 kHz.
"""

from __future__ import annotations

import contextlib
import io
import json
import re

import numpy as np
import pytest
from test_cycle import _loaded_model, _torques

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.motion.cycle import standard_cycle
from scara_pin.units import HUMAN
from scara_pin.viz.cycle import TORQUE_LABEL, plot_cycle

MASS = 2.0  # kg, at the tool frame's origin (a number: kilograms)


def _run(*argv: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(list(argv)) == 0
    return out.getvalue()


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


@pytest.fixture(scope="module")
def loaded(robot):
    return standard_cycle(robot, payload=MASS)


def _independent_torque_ratio(robot, result, mass: float) -> tuple[float, int]:
    """max |tau| / effort over the cycle at 20 kHz, RNEA on the test's own loaded model; (ratio, joint)."""
    traj = result.move.trajectory
    t = np.linspace(0.0, traj.duration, int(traj.duration * 20000) + 1)
    q, qd, qdd = traj.sample(t)
    tau = _torques(_loaded_model(robot, mass, (0.0, 0.0, 0.0)), q, qd, qdd)
    ratio = np.abs(tau) / np.array(robot.limits.effort)
    j = int(np.argmax(ratio.max(axis=0)))
    return float(ratio.max()), j


def test_cycle_prints_the_worst_ratio_of_each_limit(robot, loaded) -> None:
    text = _run("cycle", "--payload", "2")
    line = next(x for x in text.splitlines() if x.startswith("limits "))
    found = dict(re.findall(r"(velocity|acceleration|jerk|torque) ([0-9.]+) \(joint\d\)", line))
    assert set(found) == {"velocity", "acceleration", "torque"}  # no jerk limit given: no jerk ratio
    expected, joint = _independent_torque_ratio(robot, loaded, MASS)
    assert float(found["torque"]) == pytest.approx(expected, abs=3e-4)  # 4 decimals; 20 kHz grid vs exact peaks
    assert f"torque {found['torque']} (joint{joint + 1})" in line
    traj = loaded.move.trajectory  # velocity and acceleration from the samples, numpy only
    _, qd, qdd = traj.sample(np.linspace(0.0, traj.duration, 20001))
    assert float(found["velocity"]) == pytest.approx((np.abs(qd) / robot.limits.velocity).max(), abs=2e-4)
    assert float(found["acceleration"]) == pytest.approx((np.abs(qdd) / robot.limits.acceleration).max(), abs=2e-4)
    assert line.endswith("binding: acceleration")  # the torque at 0.68 costs no time: that is why 2 kg = 0 kg
    # the frame: 2 kg prints the 0 kg time, and now the torque ratio says why
    assert "cycle time  0.7617" in text and float(found["torque"]) < 1.0


def test_the_bound_line_names_the_limits_it_uses(robot) -> None:
    plain = next(x for x in _run("cycle").splitlines() if x.startswith("bound "))
    assert "velocity and acceleration limits" in plain and "not the torque limits" in plain
    jerk = _run("cycle", "--jerk-limit", "2000")
    bound = next(x for x in jerk.splitlines() if x.startswith("bound "))
    assert "velocity, acceleration and jerk limits" in bound and "not the torque limits" in bound
    limits = next(x for x in jerk.splitlines() if x.startswith("limits "))
    assert re.search(r"jerk 1\.0000 \(joint\d\)", limits)  # a jerk-limited cycle rides its jerk limit


def test_json_names_the_worst_of_each_limit(robot, loaded) -> None:
    doc = json.loads(_run("cycle", "--payload", "2", "--json"))
    assert set(doc["worst"]) == {"velocity", "acceleration", "torque"}
    expected, joint = _independent_torque_ratio(robot, loaded, MASS)
    assert doc["worst"]["torque"]["ratio"] == pytest.approx(expected, abs=3e-4)  # 20 kHz grid vs the exact peaks
    assert doc["worst"]["torque"]["joint"] == f"joint{joint + 1}"


def _panels(fig) -> dict[str, object]:
    return {ax.get_ylabel(): ax for ax in fig.axes if ax.get_ylabel()}


def test_the_cycle_plot_has_a_torque_panel_with_a_payload(robot, loaded, tmp_path) -> None:
    fig = plot_cycle(loaded, tmp_path / "cycle.png", robot=robot, units=HUMAN)
    panels = _panels(fig)
    assert TORQUE_LABEL in panels and (tmp_path / "cycle.png").stat().st_size > 10_000
    drawn = max(float(np.nanmax(line.get_ydata())) for line in panels[TORQUE_LABEL].get_lines()[:4])
    expected, _ = _independent_torque_ratio(robot, loaded, MASS)
    assert drawn == pytest.approx(expected, abs=5e-3)  # the plot samples at 2 kHz
    assert panels["z [mm]"] is not None  # lengths in the units asked


def test_the_torque_panel_is_there_without_a_payload_too(robot) -> None:
    """A robot's effort limits are always known (JointLimits refuses an infinite one) and the cycle always
    respects them: its plot always shows them; the ratios drawn are the unloaded arm's."""
    result = standard_cycle(robot)
    panels = _panels(plot_cycle(result, robot=robot))
    drawn = max(float(np.nanmax(line.get_ydata())) for line in panels[TORQUE_LABEL].get_lines()[:4])
    assert drawn == pytest.approx(_independent_torque_ratio(robot, result, 0.0)[0], abs=5e-3)
    assert drawn < _independent_torque_ratio(robot, result, MASS)[0]  # the payload's share
