"""Helpers of the pendant tests: the tool pose and a held joint's rate from Pinocchio (computed here), the
page's rounded readouts read back in SI, checking their format, and `scara-pin teach` in a subprocess."""

from __future__ import annotations

import math
import re
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

DECIMALS = {"mm": 3, "deg": 3, "m": 6, "rad": 6}
"""The readouts' decimals per unit: 1 um and 0.001 deg (1e-6 m, 1e-6 rad)."""
TO_SI = {"mm": 1e-3, "m": 1.0, "deg": math.pi / 180, "rad": 1.0}


def read_values(text: str, names: tuple[str, ...]) -> tuple[np.ndarray, list[str]]:
    """``name = value unit`` lines as SI values and their units; each value has its unit's decimals, never ``-0``."""
    found = {name: (value, unit) for name, value, unit in re.findall(r"(\w+) = (\S+) (mm|m|deg|rad)\b", text)}
    assert set(found) >= set(names), text
    values, units = [], []
    for name in names:
        value, unit = found[name]
        assert re.fullmatch(rf"-?\d+\.\d{{{DECIMALS[unit]}}}", value), (name, value, unit)
        assert float(value) != 0 or not value.startswith("-"), f"negative zero in {text!r}"
        values.append(float(value) * TO_SI[unit])
        units.append(unit)
    return np.array(values), units


def readout(page: Any) -> tuple[np.ndarray, list[str]]:
    """The tool pose readout (x, y, z [m], yaw [rad]) and the units it was shown in."""
    return read_values(page.inner_text("#tool-pose"), ("x", "y", "z", "yaw"))


def resolution(units: list[str]) -> np.ndarray:
    """Half a unit of the last shown decimal, in SI (what rounding may change), per value."""
    return np.array([0.5 * 10.0 ** -DECIMALS[u] * TO_SI[u] for u in units])


def pin_placement(robot: Any, q: np.ndarray) -> Any:
    """The tool frame in the base frame (a ``pin.SE3``) from Pinocchio's frame placements, computed here."""
    import pinocchio as pin

    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, robot.to_pinocchio_q(q))
    return data.oMf[robot.model.getFrameId(robot.base_frame)].actInv(data.oMf[robot.model.getFrameId(robot.tool_frame)])


def pin_pose(robot: Any, q: np.ndarray) -> np.ndarray:
    """(x, y, z, yaw) of :func:`pin_placement` [m, rad], the yaw as atan2(R[1, 0], R[0, 0])."""
    M = pin_placement(robot, q)
    return np.array([*M.translation, math.atan2(M.rotation[1, 0], M.rotation[0, 0])])


def joint_rate(robot: Any, q: np.ndarray, j: int, override: float) -> float:
    """The hold-to-jog rate of joint j [rad/s]: its velocity limit, or the manual speed of the tool's origin (from
    Pinocchio's frame Jacobian here: the origin's speed per unit of joint j's rate), times the override (a robot
    without continuous joints: joint j is column j)."""
    import pinocchio as pin

    from scara_pin.motion.manual import MANUAL_SPEED

    data = robot.model.createData()
    pin.computeJointJacobians(robot.model, data, robot.to_pinocchio_q(q))
    pin.framesForwardKinematics(robot.model, data, robot.to_pinocchio_q(q))
    J = pin.getFrameJacobian(robot.model, data, robot.model.getFrameId(robot.tool_frame), pin.LOCAL_WORLD_ALIGNED)
    return override * min(float(robot.limits.velocity[j]), MANUAL_SPEED / float(np.linalg.norm(J[:3, j])))


@contextmanager
def teach_process(*args: str) -> Iterator[tuple[str, int, subprocess.Popen[str]]]:
    """``scara-pin teach --port 0 ARGS`` in a subprocess: (its URL, its port, the process), once it says its URL.

    At the end it is stopped with Ctrl-C, which must end it with exit code 0, no traceback or internal error on
    stderr, and the port closed.
    """
    import psutil
    import pytest
    from sigint import default_sigint

    script = Path(sys.executable).parent / "scara-pin"
    cmd = [str(script)] if script.exists() else [sys.executable, "-m", "scara_pin.cli"]
    proc = subprocess.Popen([*cmd, "teach", "--port", "0", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, preexec_fn=default_sigint)  # fmt: skip
    port = None
    try:
        line = proc.stdout.readline()  # type: ignore[union-attr]
        match = re.search(r"(http://127\.0\.0\.1:(\d+)/)", line)
        assert match, line
        port = int(match.group(2))
        yield match.group(1), port, proc
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(timeout=10)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    err = proc.stderr.read()  # type: ignore[union-attr]
    assert code == 0 and "Traceback" not in err and "internal error" not in err, err
    assert port is not None
    assert not [c for c in psutil.net_connections("inet") if c.laddr.port == port and c.status == "LISTEN"]
    with socket.socket() as s, pytest.raises(OSError):
        s.settimeout(2)
        s.connect(("127.0.0.1", port))
