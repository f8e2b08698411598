"""Inputs users really give the command line: CSVs saved by Excel, FIFOs, both --robot and --urdf, a branch
with the numeric IK, a 3-joint arm's trajectory shown in the viewer."""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np
import pytest

from scara_pin import load_robot
from scara_pin.cli import main

DATA = Path(__file__).parent / "data"


def one_error(capsys: pytest.CaptureFixture[str]) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:"), err
    return err[0]


def test_a_csv_with_a_byte_order_mark_and_crlf_is_read(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot("default")
    q = np.array([0.2, 0.9, 0.03, -0.4])
    x, y, z, yaw = robot.tool_pose(q).tolist()
    (tmp_path / "in.csv").write_bytes(b"\xef\xbb\xbfx,y,z,yaw\r\n" + f"{x!r},{y!r},{z!r},{yaw!r}\r\n".encode())
    assert main(["ik", "--input", str(tmp_path / "in.csv"), "--output", str(tmp_path / "out.csv")]) == 0
    with (tmp_path / "out.csv").open() as handle:
        (row,) = list(csv.DictReader(handle))
    got = np.array([float(row[f"q{i}"]) for i in range(1, 5)])
    assert np.abs(robot.tool_pose(got) - robot.tool_pose(q)).max() <= 1e-12


def test_a_fifo_input_is_refused_not_waited_on(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    os.mkfifo(tmp_path / "ff")  # nobody writes it: opening it would block forever
    assert main(["ik", "--input", str(tmp_path / "ff"), "--output", str(tmp_path / "o.csv")]) == 2
    assert "not a regular file" in one_error(capsys)
    assert not (tmp_path / "o.csv").exists()


def test_robot_and_urdf_together_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fk", "--robot", "s1", "--urdf", str(DATA / "default.urdf"), "0", "0", "0", "0"]) == 2
    assert "not both" in one_error(capsys)


def test_a_branch_with_the_numeric_ik_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["ik", "0.3", "0.1", "-0.1", "0.5", "--numeric", "--branch", "left"]) == 2
    assert "--near" in one_error(capsys)


def test_a_three_joint_trajectory_is_shown(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = str(DATA / "three_joint" / "arm3_rrp.urdf")
    csv_path, html = tmp_path / "t3.csv", tmp_path / "a.html"
    assert main(["traj", "--urdf", urdf, "--from", "0", "0", "0", "--to", "1", "0.5", "0.1", "--acceleration", "5", "5",
                 "2", "--out", str(csv_path)]) == 0  # fmt: skip
    assert main(["view", "--urdf", urdf, "--traj", str(csv_path), "--html", str(html)]) == 0
    assert html.stat().st_size > 100_000  # the page with meshcat's script and the motion


def test_a_plot_is_written_in_the_format_its_name_says(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["workspace", "--plot", str(tmp_path / "ws.svg")]) == 0
    assert (tmp_path / "ws.svg").read_bytes().lstrip().startswith((b"<?xml", b"<svg"))
    assert main(["workspace", "--plot", str(tmp_path / "ws.png")]) == 0
    assert (tmp_path / "ws.png").read_bytes().startswith(b"\x89PNG")
    capsys.readouterr()
    assert main(["workspace", "--plot", str(tmp_path / "ws.jpg")]) == 2
    assert ".png, .svg, .pdf" in one_error(capsys)
    assert not (tmp_path / "ws.jpg").exists()


def test_a_payload_the_quill_cannot_hold_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    # 15.3 kg on the quill: its static load exceeds the joint3 effort limit (150 N)
    assert main(["traj", "--from", "0", "0.1", "0", "0", "--to", "0.5", "0.6", "0.02", "0.3", "--torque",
                 "--payload", "15.3"]) == 3  # fmt: skip
    message = one_error(capsys)
    assert "static load on joint3" in message and "cannot even hold still" in message
