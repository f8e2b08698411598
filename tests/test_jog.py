"""Jog to the edge (S5) and the `workspace` / `jog` commands."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import scara_pin as sp
from scara_pin.cli import main
from scara_pin.errors import InfeasibleError
from scara_pin.motion.jog import jog_to_edge
from scara_pin.workspace.scara import Limit, workspace


@pytest.fixture(scope="module")
def robot() -> sp.Robot:
    return sp.load_robot("default")


def _bisect_edge(ws, start: np.ndarray, u: np.ndarray) -> float:
    """The distance to the FIRST edge along the ray: march in 0.5 mm steps, then bisect on `contains`."""
    lo = 0.0
    while ws.contains(start + (lo + 5e-4) * u, tol=0.0):
        lo += 5e-4
    hi = lo + 5e-4
    for _ in range(80):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if ws.contains(start + mid * u, tol=0.0) else (lo, mid)
    return lo


CASES = [  # (q0, direction, margin, expected stopping limit)
    ([2.0, 1.0, 0.02, 0.2], [-1.0, 0.0], 0.0, Limit.J1_UPPER),
    ([0.3, 2.0, 0.02, 0.2], [-1.0, -0.2], 0.0, Limit.J1_UPPER),
    ([0.3, 1.0, 0.02, 0.2], [1.0, 0.0], 1e-4, Limit.OUTER),
    ([0.3, 1.0, 0.02, 0.2], [-1.0, 0.3], 1e-3, Limit.OUTER),
    ([0.5, 2.2, 0.02, 0.2], "inward", 0.0, (Limit.J2_UPPER, Limit.J2_LOWER)),
    ([0.5, -2.2, 0.02, 0.2], "inward", 0.0, (Limit.J2_UPPER, Limit.J2_LOWER)),
]


@pytest.mark.parametrize(("q0", "direction", "margin", "limit"), CASES)
def test_jog_stops_on_the_edge_at_rest_inside_the_limits(robot, q0, direction, margin, limit) -> None:
    ws = workspace(robot)
    start = robot.tool_pose(np.array(q0))
    if direction == "inward":  # towards the J1 axis: stopped by the inner circle of the J2 limits
        direction = list(-start[:2])
    jog = jog_to_edge(robot, q0, direction, margin=margin, ws=ws)
    assert jog.hit.limit in (limit if isinstance(limit, tuple) else (limit,))
    u = np.array(direction) / np.linalg.norm(direction)
    edge = _bisect_edge(ws, start[:2], u)
    traj = jog.trajectory
    t = traj.times(1000.0)
    q, qd, qdd = traj.sample(t)
    end = robot.tool_pose(q[-1])
    # ends exactly at the edge minus the margin (edge from an independent bisection on `contains`)
    assert np.linalg.norm(end[:2] - (start[:2] + (edge - margin) * u)) < 1e-9
    assert end[2] == pytest.approx(start[2], abs=1e-12) and end[3] == pytest.approx(start[3], abs=1e-9)
    # at rest at both ends: zero velocity and acceleration
    _, qd_end, qdd_end = traj.sample(np.array([0.0, traj.duration]))
    assert np.abs(qd_end).max() < 1e-12 and np.abs(qdd_end).max() < 1e-9
    # never leaves the region, stays on the line, respects the joint limits at 1 kHz
    poses = np.array([robot.tool_pose(qk) for qk in q[::5]])
    assert ws.contains(poses[:, :2], tol=1e-9).all()
    d = poses[:, :2] - start[:2]
    assert np.abs(d[:, 0] * u[1] - d[:, 1] * u[0]).max() < 1e-9
    lim = robot.limits
    assert (np.abs(qd) <= np.array(lim.velocity) * (1 + 1e-6)).all()
    assert (np.abs(qdd) <= np.array(lim.acceleration) * (1 + 1e-6)).all()
    assert (q >= np.array(lim.lower) - 1e-9).all() and (q <= np.array(lim.upper) + 1e-9).all()
    assert jog.ratio <= 1 + 1e-6


def test_jog_in_3d_stops_at_the_stroke(robot) -> None:
    q0 = [0.3, 1.0, 0.02, 0.2]
    jog = jog_to_edge(robot, q0, [0.2, 0.1, -1.0])
    assert jog.hit.limit is Limit.J3_UPPER
    assert jog.trajectory.q_end[2] == pytest.approx(robot.limits.upper[2], abs=1e-12)


def test_jog_to_a_singular_edge_needs_a_margin(robot) -> None:
    with pytest.raises(InfeasibleError, match="singularity"):
        jog_to_edge(robot, [0.3, 1.0, 0.02, 0.2], [1.0, 0.0])


def test_jog_without_room_or_from_outside(robot) -> None:
    with pytest.raises(InfeasibleError, match="no room"):
        jog_to_edge(robot, [2.0, 1.0, 0.02, 0.2], [-1.0, 0.0], margin=1.0)
    with pytest.raises(sp.ParameterError):
        jog_to_edge(robot, [2.0, 1.0, 0.02, 0.2], [0.0, 0.0])
    with pytest.raises(sp.ParameterError):
        jog_to_edge(robot, [2.0, 1.0, 0.02, 0.2], [1.0, 0.0], margin=-1.0)


# ------------------------------------------------------------------------------------------- CLI
def run(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def test_workspace_cli_json_matches_the_closed_forms(capsys) -> None:
    rc, out, err = run(capsys, ["workspace", "--json"])
    assert rc == 0, err
    ws = json.loads(out)["workspace"]
    l1 = l2 = 0.2
    q2max = math.radians(150)  # default joint_limits.yaml
    assert ws["r_max"] == pytest.approx(l1 + l2, abs=1e-12)
    assert ws["r_min"] == pytest.approx(math.sqrt(l1**2 + l2**2 + 2 * l1 * l2 * math.cos(q2max)), abs=1e-12)
    assert len(ws["arcs"]) >= 4


def test_workspace_cli_ray_and_plot(capsys, tmp_path: Path) -> None:
    png = tmp_path / "ws.png"
    rc, out, err = run(capsys, ["workspace", "--ray", "0.3", "0.1", "1", "0", "--json", "--plot", str(png)])
    assert rc == 0, err
    ray = json.loads(out)["ray"]
    # outer circle r = 0.4 from (0.3, 0.1) along +x: x = sqrt(0.4^2 - 0.1^2)
    assert ray["point"][0] == pytest.approx(math.sqrt(0.16 - 0.01), abs=1e-12)
    assert ray["distance"] == pytest.approx(math.sqrt(0.15) - 0.3, abs=1e-12)
    assert ray["limit"] == "outer"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rc, out, err = run(capsys, ["workspace", "--mm", "--ray", "300", "100", "1", "0"])
    assert rc == 0 and f"{(math.sqrt(0.15) - 0.3) * 1000:.6g}"[:6] in out


@pytest.mark.parametrize(
    ("argv", "code"),
    [
        (["workspace", "--ray", "0.9", "0.1", "1", "0"], 2),
        (["workspace", "--ray", "0.3", "0.1", "0", "0"], 2),
        (["workspace", "--ray", "0.3", "0.1", "1", "0", "--z", "-0.1"], 2),
        (["workspace", "--z", "0"], 2),
        (["jog", "--from", "0.3", "1.0", "0.02", "0.2", "--direction", "1", "0"], 3),
        (["jog", "--from", "0.3", "1.0", "0.02", "0.2", "--direction", "1"], 2),
        (["jog", "--from", "0.3", "9", "0.02", "0.2", "--direction", "1", "0"], 3),
    ],
)
def test_workspace_and_jog_errors(capsys, argv, code) -> None:
    rc, _, err = run(capsys, argv)
    assert rc == code
    assert len([ln for ln in err.splitlines() if ln.startswith("error:")]) == 1


def test_jog_cli_writes_the_trajectory(capsys, tmp_path: Path) -> None:
    out_csv = tmp_path / "jog.csv"
    rc, out, err = run(capsys, ["jog", "--json", "--from", "2.0", "1.0", "0.02", "0.2", "--direction", "-1", "0",
                                "--out", str(out_csv)])  # fmt: skip
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["hit"]["limit"] == "joint1_upper"
    assert doc["q_end"][0] == pytest.approx(math.radians(132), abs=1e-9)
    assert out_csv.read_text().startswith("t,q1,q2,q3,q4")
