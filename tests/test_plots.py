"""Every picture of the package: object-oriented matplotlib (no pyplot, the caller's backend left alone),
a PNG written atomically (no temporary file left, an existing file replaced whole)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

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
        plot_cycle(robot, arch.arch, out / "cycle.png")
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
