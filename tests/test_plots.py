"""Every picture of the package: object-oriented matplotlib (no pyplot, the caller's backend left alone),
a PNG written atomically (no temporary file left, an existing file replaced whole)."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from scara_pin import load_robot
from scara_pin.units import DisplayUnits

PNG = b"\x89PNG\r\n\x1a\n"


def test_plots_leave_the_callers_matplotlib_alone(tmp_path: Path) -> None:
    code = textwrap.dedent(f"""
        import sys
        from pathlib import Path
        import matplotlib
        matplotlib.use("svg")  # the caller's choice: a plot must not switch it
        import numpy as np
        from scara_pin import load_robot
        from scara_pin.motion.plan import MotionRequest, plan_motion
        from scara_pin.viz.cycle import plot_cycle
        from scara_pin.viz.plots import plot_trajectory
        from scara_pin.workspace.palletizer import plot_envelope
        from scara_pin.workspace import workspace_of
        from scara_pin.workspace.scara import plot_workspace, workspace

        out = Path({str(tmp_path)!r})
        robot = load_robot("default")
        (out / "ws.png").write_text("OLD")
        plot_workspace(workspace(robot), str(out / "ws.png"))
        plot_envelope(workspace_of(load_robot("palletizer")), str(out / "env.png"))
        q0, q1 = np.array([0.2, 0.6, 0.01, 0.1]), np.array([0.9, 1.3, 0.04, -0.4])
        plot_trajectory(plan_motion(robot, MotionRequest(start_q=q0, end_q=q1)).trajectory, out / "traj.png",
                        robot=robot)
        arch = plan_motion(robot, MotionRequest(start_pose=np.array([0.30, -0.10, -0.09, 0.0]),
                                                end_pose=np.array([0.25, 0.15, -0.09, 0.3]), arch=True))
        plot_cycle(arch.arch, out / "cycle.png", robot=robot)
        pyplot = sys.modules.get("matplotlib.pyplot")  # toppra imports it itself; we must leave no figure there
        print(matplotlib.get_backend(), pyplot.get_fignums() if pyplot else [])
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["svg", "[]"]
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["cycle.png", "env.png", "traj.png", "ws.png"]  # no temporary file left behind
    for name in names:
        data = (tmp_path / name).read_bytes()
        assert data.startswith(PNG) and len(data) > 10_000, name


# ------------------------------------------------------------------------------------ figures read as objects

DEG = 180.0 / math.pi  # written here, not taken from the package
HUMAN = DisplayUnits("mm", "deg")


@pytest.fixture(scope="module")
def robot():  # type: ignore[no-untyped-def]
    return load_robot("default")


@pytest.fixture(scope="module")
def optimal(robot):  # type: ignore[no-untyped-def]
    """A time-optimal joint line: its velocity or acceleration limits bind, so they are drawn on scale."""
    from scara_pin.motion.plan import MotionRequest, plan_motion

    plan = plan_motion(robot, MotionRequest(start_q=np.array([-1.0, -1.2, 0.0, -2.0]),
                                            end_q=np.array([1.2, 1.4, 0.09, 2.5])))  # fmt: skip
    return plan.trajectory


def _panels(fig):  # type: ignore[no-untyped-def]
    """{(joint label, quantity): axes} of the joint panels, read from their y labels."""
    out = {}
    for ax in fig.axes:
        label = ax.get_ylabel()
        if label.startswith("joint"):
            joint, quantity = label.split()[:2]
            out[joint, quantity] = ax
    return out


def _limits_drawn(ax):  # type: ignore[no-untyped-def]
    return sorted(float(line.get_ydata()[0]) for line in ax.lines if line.get_gid() == "limit")


def test_trajectory_figure_one_panel_per_joint_with_its_units_and_limits(robot, optimal, tmp_path: Path
                                                                          ) -> None:  # type: ignore[no-untyped-def]
    from matplotlib.figure import Figure

    from scara_pin.viz.plots import plot_trajectory

    fig = plot_trajectory(optimal, robot=robot, units=HUMAN, law="joint line, time-optimal", samples=400)
    assert isinstance(fig, Figure) and list(tmp_path.iterdir()) == []  # returned, nothing written
    panels = _panels(fig)
    assert len(panels) == 12 and len(fig.axes) == 12 + 3  # 4 joints x (q, qd, qdd), plan, side, tool speed
    unit = {"joint1": "deg", "joint2": "deg", "joint3": "mm", "joint4": "deg"}
    for (joint, quantity), ax in panels.items():
        per = {"position": "", "velocity": "/s", "acceleration": "/s²"}[quantity]
        assert ax.get_ylabel() == f"{joint} {quantity} [{unit[joint]}{per}]"
    scale = [DEG, DEG, 1000.0, DEG]  # display value per SI value, joint by joint
    lim = robot.limits
    binding = 0
    for j in range(4):
        name = f"joint{j + 1}"
        for quantity, bounds in (("velocity", lim.velocity[j]), ("acceleration", lim.acceleration[j])):
            drawn = _limits_drawn(panels[name, quantity])
            expected = [-bounds * scale[j], bounds * scale[j]]
            note = [t for t in panels[name, quantity].texts if t.get_gid() == "limit-note"]
            assert drawn == pytest.approx(expected, rel=1e-12) or (not drawn and note), (name, quantity)
            binding += bool(drawn)
        for d in _limits_drawn(panels[name, "position"]):  # those on scale: this joint's own
            assert min(abs(d - lim.lower[j] * scale[j]), abs(d - lim.upper[j] * scale[j])) < 1e-9
        # the curve is the trajectory in the chosen unit
        t = panels[name, "velocity"].lines[0].get_xdata()
        _, qd, _ = optimal.sample(np.asarray(t))
        assert np.abs(panels[name, "velocity"].lines[0].get_ydata() - qd[:, j] * scale[j]).max() < 1e-9
    assert binding >= 2  # time-optimal: some limit binds, and is drawn on its own joint's panel
    assert fig._suptitle.get_text() == f"default: joint line, time-optimal, {optimal.duration:.4g} s"


def test_tool_speed_panel_is_the_tool_speed(robot, optimal) -> None:  # type: ignore[no-untyped-def]
    from scara_pin.viz.plots import plot_trajectory

    fig = plot_trajectory(optimal, robot=robot, units=HUMAN, tool_speed=0.5, samples=2001)
    (ax,) = [a for a in fig.axes if a.get_ylabel().startswith("tool speed")]
    assert ax.get_ylabel() == "tool speed |v| [mm/s]" and ax.get_xlabel() == "time t [s]"
    t, v = ax.lines[0].get_xdata(), ax.lines[0].get_ydata()
    # independent route: central differences of the FK tool positions, in mm/s
    h = 1e-6
    qa = optimal.sample(np.clip(t - h, 0, optimal.duration))[0]
    qb = optimal.sample(np.clip(t + h, 0, optimal.duration))[0]
    pa = np.array([robot.tool_pose(x)[:3] for x in qa])
    pb = np.array([robot.tool_pose(x)[:3] for x in qb])
    dt = np.clip(t + h, 0, optimal.duration) - np.clip(t - h, 0, optimal.duration)
    fd = np.linalg.norm(pb - pa, axis=1) / dt * 1000.0
    assert np.abs(v - fd).max() < 1e-3 * max(1.0, fd.max())
    assert _limits_drawn(ax) == [pytest.approx(500.0, rel=1e-12)] or any(
        t.get_gid() == "limit-note" for t in ax.texts)
    plan = [a for a in fig.axes if a.get_title() == "tool path, plan view"][0]
    assert (plan.get_xlabel(), plan.get_ylabel()) == ("x [mm] (base frame)", "y [mm]")


def test_torque_column_holds_the_quill_against_gravity(robot) -> None:  # type: ignore[no-untyped-def]
    """At rest the quill (a prismatic joint3) carries the weight of everything below it; joint1's torque is 0."""
    from scara_pin.motion.payload import Payload, with_payload
    from scara_pin.motion.trajectory import quintic
    from scara_pin.viz.plots import plot_trajectory

    loaded = with_payload(robot, Payload(1.0, (0.0, 0.0, 0.0)))
    tr = quintic(np.array([0.2, 0.5, 0.02, 0.0]), np.array([0.8, 1.0, 0.05, 1.0]), 2.0)
    fig = plot_trajectory(tr, robot=loaded, units=HUMAN, torque=True, samples=50)
    panels = _panels(fig)
    assert len(panels) == 16 and len(fig.axes) == 19
    assert panels["joint1", "torque"].get_ylabel() == "joint1 torque [N·m]"
    assert panels["joint3", "force"].get_ylabel() == "joint3 force [N]"
    model = loaded.model
    j3 = model.getJointId(loaded.joint_names[2])
    below = [j for j in range(j3, model.njoints) if j == j3 or model.parents[j] >= j3]
    weight = 9.81 * sum(model.inertias[j].mass for j in below)
    f0 = panels["joint3", "force"].lines[0].get_ydata()[0]
    assert abs(abs(f0) - weight) < 1e-9 * weight and weight > 1.0  # 1 kg payload included
    assert abs(panels["joint1", "torque"].lines[0].get_ydata()[0]) < 1e-9  # vertical axis: gravity does no work
    effort = robot.limits.effort
    assert _limits_drawn(panels["joint3", "force"]) in ([], [pytest.approx(-effort[2]), pytest.approx(effort[2])])


def test_far_limits_are_noted_not_drawn(robot) -> None:  # type: ignore[no-untyped-def]
    from scara_pin.description import JointLimits
    from scara_pin.motion.trajectory import quintic
    from scara_pin.viz.plots import plot_trajectory

    lim = robot.limits
    wide = JointLimits((-1e6,) * 4, (1e6,) * 4, lim.velocity, lim.acceleration, lim.effort, validate=False)
    tr = quintic(np.zeros(4), np.array([0.01, 0.01, 0.001, 0.01]), 3.0)
    fig = plot_trajectory(tr, robot=robot, limits=wide, samples=50)
    panels = _panels(fig)
    for j in range(4):
        ax = panels[f"joint{j + 1}", "position"]
        assert _limits_drawn(ax) == [] and any("off scale" in t.get_text() for t in ax.texts)
        assert ax.get_ylim()[1] < 1.0  # the curve keeps the panel


def test_the_cli_plot_honours_units_and_shows_torque(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """``traj --arch --torque --payload 1 --deg --mm --plot``: the figure has the torque column, axes in deg and
    mm, the law in the title; ``traj --plot`` of a joint move too (the issue: --deg was ignored, torque shown
    nowhere)."""
    import scara_pin.files as files
    import scara_pin.viz.plots as plots
    from scara_pin.cli import main

    figures, written = [], []
    monkeypatch.setattr(files, "save_figure", lambda fig, path, **kw: written.append((fig, path)))
    real = plots.plot_trajectory

    def spy(*args, **kwargs):  # type: ignore[no-untyped-def]
        figures.append(real(*args, **kwargs))
        return figures[-1]

    monkeypatch.setattr(plots, "plot_trajectory", spy)  # (rendering the PNG is tested above: seconds here)
    png = tmp_path / "arch.png"
    assert main(["traj", "--arch", "--deg", "--mm", "--from-pose", "300", "-100", "-100", "0", "--to-pose", "250",
                 "150", "-80", "57", "--torque", "--payload", "1", "--plot", str(png)]) == 0  # fmt: skip
    fig = figures[-1]
    panels = _panels(fig)
    assert ("joint1", "torque") in panels and panels["joint1", "velocity"].get_ylabel().endswith("[deg/s]")
    assert panels["joint3", "position"].get_ylabel() == "joint3 position [mm]"
    assert fig._suptitle.get_text().startswith("default: jump (arch move)")
    assert written == [(fig, str(png))]  # written where --plot says


def test_workspace_figures_name_the_robot_and_read_in_the_unit_chosen(robot) -> None:  # type: ignore[no-untyped-def]
    from matplotlib.figure import Figure

    from scara_pin.workspace import workspace_of
    from scara_pin.workspace.palletizer import plot_envelope
    from scara_pin.workspace.scara import plot_workspace

    fig = plot_workspace(workspace_of(robot), units=DisplayUnits("mm"), robot_name="default")
    (ax,) = fig.axes
    assert isinstance(fig, Figure) and (ax.get_xlabel(), ax.get_ylabel()) == ("x [mm] (base frame)", "y [mm]")
    assert ax.xaxis.get_major_formatter()(0.2, 0) == "200"  # drawn in m, read in mm
    # default robot: l1 = l2 = 0.2 m, so r_max = 400 mm; the area to 1 mm^2 is in the title
    assert ax.get_title().startswith("default: reachable region") and "400] mm" in ax.get_title()
    pal = load_robot("palletizer")
    fig = plot_envelope(workspace_of(pal), units=DisplayUnits("mm"), robot_name=pal.name)
    (ax,) = fig.axes
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("r: from the waist axis [mm]", "z: above the floor [mm]")
    assert ax.get_title().startswith("palletizer: tool0 in the arm plane") and ax.yaxis.get_major_formatter()(1.5, 0) \
        == "1500"
