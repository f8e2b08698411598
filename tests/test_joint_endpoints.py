"""Every command with joint endpoints, on every shipped robot (issue 39 item 7).

``scara-pin traj --robot palletizer --arch --from Q --to Q`` (the joint endpoints of the palletizing example's
first jump) crashed: the jump unwraps the tool's yaw along the joints, and read a SCARA's geometry (yaw0) from
the palletizer's. Each variant of ``traj`` (time-optimal joint line, quintic, the jump, the straight-leg arch, a
straight tool line, jerk-limited) and ``jog`` runs here on each shipped robot from joint values; the SCARA-only
ones are refused on the palletizer with that reason. The truth: the endpoints reached, the limits kept, and the
palletizer's jump between joints equal to the same jump between their poses (FK).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from quirks import run, texts

from scara_pin import load_robot

ENDPOINTS = {
    "default": (["0.3", "0.5", "0.02", "0.1"], ["-0.2", "0.8", "0.05", "0.6"]),
    "s1": (["0.3", "0.5", "0.05", "0.1"], ["-0.2", "0.8", "0.08", "0.6"]),
    "palletizer": (["1.5707963", "0.749", "2.443", "-1.5707963"], ["-0.17128", "0.96149", "2.44914", "0.17128"]),
}
VARIANTS = {
    "joint": [],
    "quintic": ["--duration", "2"],
    "jump": ["--arch"],
    "arch_lines": ["--arch", "--path", "lines"],
    "linear": ["--linear"],
    "jerk": ["--jerk-limit", "2000"],
}
SCARA_ONLY = {("palletizer", "arch_lines"), ("palletizer", "linear")}


def test_every_shipped_robot_has_its_endpoints() -> None:
    from scara_pin.description import available_robots

    assert set(ENDPOINTS) == set(available_robots())


@pytest.mark.parametrize("variant", VARIANTS)
@pytest.mark.parametrize("name", ENDPOINTS)
def test_traj_with_joint_endpoints_on_every_shipped_robot(name: str, variant: str,
                                                          capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """Item 7: the palletizer's jump between joint endpoints crashed (PalletizerGeometry has no yaw0)."""
    a, b = ENDPOINTS[name]
    rc, out, err = run(capsys, ["traj", "--json", "--robot", name, "--from", *a, "--to", *b, *VARIANTS[variant]])
    assert "internal error" not in err
    if (name, variant) in SCARA_ONLY:
        assert rc == 2 and "SCARA-only" in err
        return
    assert rc == 0, err
    doc = json.loads(out)
    np.testing.assert_allclose(doc["q_from"], [float(v) for v in a], atol=1e-9)  # the move joins the joints given
    np.testing.assert_allclose(doc["q_to"], [float(v) for v in b], atol=1e-9)
    assert doc["duration"] > 0 and max(doc["limit_ratios"].get(k, 0.0) or 0.0 for k in ("velocity",
                                                                                         "acceleration")) <= 1 + 1e-6


def test_the_palletizers_jump_from_joints_equals_the_one_from_poses(capsys: pytest.CaptureFixture[str]) -> None:
    a, b = ENDPOINTS["palletizer"]
    robot = load_robot("palletizer")
    pa, pb = (robot.tool_pose(np.array([float(v) for v in e])) for e in (a, b))
    rc, out, err = run(capsys, ["traj", "--json", "--robot", "palletizer", "--arch", "--from", *a, "--to", *b])
    assert rc == 0, err
    joints = json.loads(out)
    rc, out, err = run(capsys, ["traj", "--json", "--robot", "palletizer", "--arch", "--from-pose", *texts(pa),
                                "--to-pose", *texts(pb)])  # fmt: skip
    assert rc == 0, err
    poses = json.loads(out)
    assert joints["duration"] == pytest.approx(poses["duration"], rel=1e-6)


@pytest.mark.parametrize("name", ["default", "s1"])
def test_jog_from_joint_values_on_every_shipped_scara(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    a, _ = ENDPOINTS[name]
    rc, out, err = run(capsys, ["jog", "--json", "--robot", name, "--from", *a, "--direction", "1", "0", "--margin",
                                "1e-4"])  # (no margin: refused, the stretched arm cannot be reached at rest)
    assert rc == 0 and "internal error" not in err, err
    rc, out, err = run(capsys, ["jog", "--robot", "palletizer", "--from", *ENDPOINTS["palletizer"][0], "--direction",
                                "1", "0"])  # fmt: skip
    assert rc == 2 and "SCARA-only" in err and "internal error" not in err
