"""The straight-leg arch and its standard cycle (scara_pin.motion.cycle ``path="lines"``, jerk, payload;
``scara-pin cycle --path lines`` / ``traj --arch --path lines``). The jump, the default, is tests/test_jump.py.

Independent routes: limits re-checked from the samples (numpy); torques by Pinocchio's RNEA on a model the
test loads itself with the payload appended as a body (appendBodyToJoint, not the library's route); the
geometry from FK of the sampled joints; the exported CSV checked by finite differences (q -> qd -> qdd ->
jerk).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.motion.cycle import STANDARD_RISE, STANDARD_SPAN, standard_cycle, trajectory_jerk
from scara_pin.motion.jerk import JerkLaw
from scara_pin.motion.payload import Payload
from scara_pin.motion.timing import TimingOptions

PROMISE = 1e-6
JERK = [20000.0, 40000.0, 2000.0, 100000.0]  # rad/s^3, rad/s^3, m/s^3, rad/s^3
MASS, COM = 2.0, (0.01, 0.0, 0.03)  # kg; m in the tool frame


def _loaded_model(robot, mass, com):  # the test's own payload route
    model = pin.Model(robot.model)
    frame = model.frames[robot.tool_id]
    model.appendBodyToJoint(frame.parentJoint, pin.Inertia(mass, frame.placement.act(np.array(com)), np.zeros((3, 3))),
                            pin.SE3.Identity())
    return model


def _torques(model, q, qd, qdd):
    data = model.createData()
    return np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))])


@pytest.fixture(scope="module")
def robot():
    return load_robot("default")


@pytest.fixture(scope="module")
def jerk_cycle(robot):
    return standard_cycle(robot, payload=Payload(MASS, COM), jerk=JERK, path="lines")


@dataclasses.dataclass
class CliRun:
    code: int
    out: str
    folder: Path
    planned: list  # (keyword arguments, CycleResult) of each standard_cycle call the command made


@pytest.fixture(scope="module")
def cli_corners(tmp_path_factory):
    """``cycle --path lines --no-blend --plot --out --json`` run once, in-process. standard_cycle is wrapped (not
    replaced) to record what the command planned, so the library tests below share that planning instead of
    repeating it."""
    import scara_pin.motion.cycle as cycle_module

    folder = tmp_path_factory.mktemp("cycle-cli")
    real = cycle_module.standard_cycle
    planned = []

    def recording(*args, **kwargs):
        planned.append((kwargs, real(*args, **kwargs)))
        return planned[-1][1]

    out = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(out):
        mp.setattr(cycle_module, "standard_cycle", recording)
        code = main(["cycle", "--path", "lines", "--no-blend", "--plot", str(folder / "c.png"), "--out",
                     str(folder / "c.csv"), "--json"])
    return CliRun(code, out.getvalue(), folder, planned)


@pytest.fixture(scope="module")
def plain(robot, cli_corners):
    """(blended, corners): ``standard_cycle(robot, path="lines")``, and the same with ``blend=0.0`` as the CLI's
    --no-blend planned it (asserted here: that call is this one, every other argument at its default; the
    command's second call is the jump it compares with)."""
    assert len(cli_corners.planned) == 2
    kwargs, corners = cli_corners.planned[0]
    assert kwargs["blend"] == 0.0 and kwargs["span"] == STANDARD_SPAN and kwargs["rise"] == STANDARD_RISE
    assert kwargs["start"] is None and kwargs["direction"] is None and kwargs["jerk"] is None
    assert kwargs["payload"] == Payload() and kwargs["limits"] == robot.limits and kwargs["max_height"] is None
    assert kwargs["path"].value == "lines"
    assert kwargs["torque"] is True and kwargs["cell"] is None  # efforts apply unless --no-torque; no --cell
    assert kwargs.keys() == {"start", "direction", "span", "rise", "blend", "payload", "jerk", "limits", "path",
                             "max_height", "cell", "torque"}  # fmt: skip
    assert cli_corners.planned[1][0]["path"].value == "jump"
    return standard_cycle(robot, path="lines"), corners


def _check_times(traj):
    """1 kHz, and every breakpoint of the jerk laws (the path jerk's closed-form extrema) and each one's left side."""
    t = [np.arange(0.0, traj.duration, 1e-3)]
    t0 = 0.0
    for m in traj.pieces:
        assert isinstance(m.law, JerkLaw)
        bp = m.law.breakpoints()
        t += [t0 + bp, t0 + bp[:-1] + np.diff(bp) * (1 - 1e-9)]
        t0 += m.duration
    return np.concatenate(t)


def test_jerk_cycle_keeps_every_limit_with_payload(robot, jerk_cycle):
    traj = jerk_cycle.move.trajectory
    t = _check_times(traj)
    q, qd, qdd = traj.sample(t)
    lim = robot.limits
    assert np.max(np.abs(qd) / lim.velocity) <= 1 + PROMISE
    assert np.max(np.abs(qdd) / lim.acceleration) <= 1 + PROMISE
    assert np.max(np.abs(trajectory_jerk(traj, t)) / JERK) <= 1 + PROMISE
    tau = _torques(_loaded_model(robot, MASS, COM), q, qd, qdd)
    assert np.max(np.abs(tau) / lim.effort) <= 1 + PROMISE
    # the payload is really in: the quill carries its weight (2 kg * g more than without it)
    tau0 = _torques(robot.model, q, qd, qdd)
    assert np.abs(tau - tau0)[:, 2].max() > MASS * 9.0
    # a limit is active somewhere (the jerk one, here): not a trivially slow result
    assert max(v for v in jerk_cycle.move.ratios.values() if v is not None) > 0.999


def test_geometry_up_across_back(robot, plain):
    for result in plain:
        traj = result.move.trajectory
        t_mid = traj.pieces[0].duration if len(traj.pieces) == 2 else sum(p.duration for p in traj.pieces[:3])
        t = np.concatenate([np.linspace(0.0, traj.duration, 3001), [t_mid]])
        poses = np.array([robot.tool_pose(q) for q in traj.sample(t)[0]])
        start = poses[0]
        assert np.abs(poses[-2] - start).max() < 1e-9  # t = duration: back to the start
        assert poses[:, 2].max() - start[2] == pytest.approx(0.025, abs=1e-6)
        assert poses[:, 2].min() == pytest.approx(start[2], abs=1e-9)
        across = np.linalg.norm(poses[:, :2] - start[:2], axis=1)
        assert across.max() == pytest.approx(0.305, abs=1e-6)
        assert np.linalg.norm(poses[-1, :2] - poses[-2, :2]) == pytest.approx(0.305, abs=1e-6)  # t_mid: at B


def test_blended_strictly_faster(plain):
    blended, corners = plain
    assert blended.cycle_time < corners.cycle_time - 1e-3
    assert [leg.name for leg in corners.move.legs][:3] == ["lift", "traverse", "descend"]


def test_more_payload_never_faster(robot):
    # effort limits low enough that the torque binds: the time must grow with the payload
    lim = dataclasses.replace(robot.limits, effort=(12.0, 6.0, 150.0, 2.0))
    # the ordering of the times is the point here, not the limits between samples (checked elsewhere):
    # the verification's default density of 16 points per grid segment is enough and 4 times faster
    coarse = TimingOptions(check_subdivisions=16)
    times = [standard_cycle(robot, payload=Payload(m), limits=lim, options=coarse, path="lines").cycle_time
             for m in (0.0, 1.0, 2.0)]  # fmt: skip
    assert times[0] < times[1] < times[2]


def test_csv_by_finite_differences(robot, jerk_cycle, tmp_path):
    out = jerk_cycle.move.trajectory.to_csv(tmp_path / "cycle.csv", rate=1000.0)  # what cycle --out writes
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    t, q, qd, qdd = data[:, 0], data[:, 1:5], data[:, 5:9], data[:, 9:13]
    dt = 1e-3
    assert t[-1] == pytest.approx(jerk_cycle.cycle_time, abs=1e-3)
    # central differences against the exported rates; with |jerk| <= J the exact bounds are
    # |(q(t+h) - q(t-h)) / 2h - qd(t)| <= J h^2 / 6 and |(qd(t+h) - qd(t-h)) / 2h - qdd(t)| <= J h / 2
    jmax = np.array(JERK)
    slack = 1 + 1e-6
    assert np.all(np.abs((q[2:] - q[:-2]) / (2 * dt) - qd[1:-1]) <= jmax * dt**2 / 6 * slack + 1e-12)
    assert np.all(np.abs((qd[2:] - qd[:-2]) / (2 * dt) - qdd[1:-1]) <= jmax * dt / 2 * slack + 1e-12)
    # jerk by differences of the exported accelerations: a mean of the true jerk, so within the limit
    fd_jerk = np.diff(qdd, axis=0) / dt
    assert np.max(np.abs(fd_jerk) / jmax) <= 1 + 1e-6
    lim = robot.limits
    assert np.max(np.abs(qd) / lim.velocity) <= 1 + PROMISE
    assert np.max(np.abs(qdd) / lim.acceleration) <= 1 + PROMISE
    tau = _torques(_loaded_model(robot, MASS, COM), q, qd, qdd)
    assert np.max(np.abs(tau) / lim.effort) <= 1 + PROMISE


def test_cli_plot_json_and_text(cli_corners, plain):
    tmp_path = cli_corners.folder
    png, csv = tmp_path / "c.png", tmp_path / "c.csv"
    assert cli_corners.code == 0
    summary = json.loads(cli_corners.out)
    assert summary["cycle_time"] == plain[1].cycle_time  # what the command planned is what it reports
    assert summary["path"] == "lines" and summary["jump_cycle_time"] == cli_corners.planned[1][1].cycle_time
    assert summary["jump_cycle_time"] < summary["cycle_time"]  # the jump is faster (and the output says so)
    assert {"cycle_time", "legs", "limits"} <= summary.keys()
    assert [leg["name"] for leg in summary["legs"]] == ["lift", "traverse", "descend"] * 2
    assert abs(sum(leg["duration"] for leg in summary["legs"]) - summary["cycle_time"]) < 1e-9
    assert np.loadtxt(csv, delimiter=",", skiprows=1)[-1, 0] == pytest.approx(summary["cycle_time"], abs=1e-3)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".*.tmp"))



@pytest.mark.parametrize(
    "argv, code, words",
    [
        (["--payload", "-1"], 2, "payload"),
        (["--payload", "nan"], 2, "finite"),
        (["--rise", "nan"], 2, "finite"),
        (["--span", "2.0"], 2, "beyond the reach"),
        (["--jerk-limit", "1", "2"], 2, "one number or 4"),
        (["--path", "lines", "--arch", "0.01", "--no-blend"], 2, "exclude"),
        (["--arch", "0.01"], 2, "--path lines"),
        (["--path", "lines", "--from", "0.3", "0", "-0.0875", "0", "--direction", "1", "0"], 3, "path fails"),
    ],
)
def test_cli_errors(argv, code, words, capsys):
    assert main(["cycle", *argv]) == code
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and words in err


def test_urdf_needs_accelerations(tmp_path, capsys):
    urdf = tmp_path / "r.urdf"
    assert main(["urdf", "-o", str(urdf)]) == 0
    capsys.readouterr()
    assert main(["cycle", "--urdf", str(urdf)]) == 2
    err = capsys.readouterr().err
    assert "acceleration" in err and "URDF" in err


def test_traj_arch_and_payload(tmp_path, capsys):
    base = ["traj", "--from-pose", "0.3", "-0.1", "-0.1", "0", "--to-pose", "0.25", "0.15", "-0.08", "1"]
    argv = [*base, "--arch", "--path", "lines", "--torque", "--payload", "1", "--json", "--out",
            str(tmp_path / "a.csv")]
    assert main(argv) == 0
    arch = json.loads(capsys.readouterr().out)
    assert arch["method"].startswith("straight-leg arch") and arch["limit_ratios"]["torque"] > 0
    assert arch["jump_duration"] < arch["duration"]
    assert main([*base, "--payload", "1"]) == 2  # payload without --torque
    assert "--torque" in capsys.readouterr().err


def test_blended_cycle_keeps_its_limits_between_the_verified_samples(robot, plain):
    """At 100 kHz (far denser than the 1 kHz promise and the verified points) no velocity or acceleration
    limit is exceeded by more than 1e-6 (relative): the blends' fast-changing curvature is verified densely."""
    traj = plain[0].move.trajectory
    t = np.linspace(0.0, traj.duration, 100_000)
    _, qd, qdd = traj.sample(t)
    assert (np.abs(qd) / np.array(robot.limits.velocity)).max() <= 1 + 1e-6
    assert (np.abs(qdd) / np.array(robot.limits.acceleration)).max() <= 1 + 1e-6


def test_jerk_cycle_keeps_its_limits_between_the_verified_samples(robot, jerk_cycle):
    """At 8 kHz (8 times the promise; the jerk law verifies its breakpoints, 16 points between them, the rate
    grid and both sides of the path's knots) no velocity or acceleration limit is exceeded by 1e-6."""
    traj = jerk_cycle.move.trajectory
    t = np.linspace(0.0, traj.duration, int(traj.duration * 8000) + 1)
    _, qd, qdd = traj.sample(t)
    assert (np.abs(qd) / np.array(robot.limits.velocity)).max() <= 1 + 1e-6
    assert (np.abs(qdd) / np.array(robot.limits.acceleration)).max() <= 1 + 1e-6
