"""Issue 34's small frictions of the command line (item 10): each one the integrator hit, as a test.

Truth from the documented behaviour: ``-v`` after the command logs as it does before it (a debug line the
command writes only when verbose), ``workspace --deg`` reads ``--yaw`` in degrees (the same region as the
radians typed), ``check --robot`` checks the URDF the robot is made from (the same findings as the file
written by ``scara-pin urdf``).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from scara_pin.cli import main


def test_verbose_is_taken_after_the_command_as_before_it(capsys: pytest.CaptureFixture[str]) -> None:
    outputs = []
    for argv in (["-v", "ik", "0.3", "0.1", "-0.06", "0.5"], ["ik", "0.3", "0.1", "-0.06", "0.5", "-v"],
                 ["ik", "0.3", "0.1", "-0.06", "0.5"]):  # fmt: skip
        assert main(argv) == 0
        outputs.append(capsys.readouterr())
    assert outputs[0].out == outputs[1].out == outputs[2].out
    assert outputs[0].err == outputs[1].err  # what -v logs, the same wherever it is written
    assert main(["ik", "0.3", "0.1", "-0.06", "0.5", "-x"]) == 2  # another unknown option stays refused
    assert "unrecognized arguments: -x" in capsys.readouterr().err


def test_workspace_takes_deg_for_the_yaw(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    cell = tmp_path / "post.yaml"
    cell.write_text("obstacles:\n  - {name: post, shape: cylinder, radius: 0.02, length: 0.3, xyz: [0.3, 0, -0.05]}\n")
    common = ["workspace", "--cell", str(cell), "--json"]
    assert main([*common, "--height", "-0.1", "--resolution", "0.02", "--yaw", str(math.radians(30))]) == 0
    rad = json.loads(capsys.readouterr().out)
    assert main([*common, "--deg", "--mm", "--height", "-100", "--resolution", "20", "--yaw", "30"]) == 0
    deg = json.loads(capsys.readouterr().out)
    assert deg["area"] == pytest.approx(rad["area"], rel=1e-12) and deg["area"] > 0
    assert deg["yaw"]["values"] == [pytest.approx(math.radians(30), abs=1e-15)]


def test_check_takes_a_configured_robot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = tmp_path / "s1.urdf"
    assert main(["urdf", "--robot", "s1", "-o", str(urdf)]) == 0
    capsys.readouterr()
    assert main(["check", str(urdf), "--json"]) == 0
    from_file = json.loads(capsys.readouterr().out)
    assert main(["check", "--robot", "s1", "--json"]) == 0
    from_robot = json.loads(capsys.readouterr().out)
    assert [f["code"] for f in from_robot["findings"]] == [f["code"] for f in from_file["findings"]]
    assert from_robot["status"] == from_file["status"] == "clean"
    assert main(["check", str(urdf), "--robot", "s1"]) == 2
    assert "not both" in capsys.readouterr().err
