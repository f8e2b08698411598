"""Planning a job (scara_pin.job.planning, ``scara-pin job``): its time is the sum of its moves planned alone.

Independent routes for every expected value:

- each jump planned alone by ``scara-pin traj --arch --from-pose --to-pose`` (the command a user times one move
  with) between the places' poses written here from the corners' Pinocchio FK;
- the speed and acceleration percentages: ``traj --arch`` on a robot whose URDF is regenerated with its
  velocity (acceleration) limits halved (``--set joint1_velocity=...``);
- a reversed jump: ``jump_move`` solved from its own end;
- a joint move: the slowest joint's 1-DOF minimum time in closed form (d / v + v / a, or 2 sqrt(d / a));
  a straight move: ``traj --linear`` between the same configurations;
- the written trajectory: the limits by finite differences of its positions (a mean of the velocity or
  acceleration over the step, never above their maxima), the places by the SCARA's closed-form FK.

The 4 x 6 tray of the issue is ``benchmarks/bench_job.py``; a 2 x 2 tray here keeps the suite short.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from sigint import default_sigint
from test_job import POSES, line_of, write_job

from scara_pin import Robot
from scara_pin.cli import main
from scara_pin.job import Job, Source
from scara_pin.motion.jump import jump_move

RATE = 10_000.0
PROMISE = 1e-6  # [s] the job's times against the moves planned alone; relative excess of a limit
DWELL = 0.05

TRAY = f"""start: feeder
pallets:
  tray: {{corners: [T11, T12, T21], rows: 2, columns: 2}}
steps:
  - speed: 100
  - for: tray
    do:
      - jump: tray[i]
      - dwell: {DWELL}
      - jump: feeder
      - dwell: {DWELL}
"""


def scara_xyz(q: np.ndarray) -> np.ndarray:
    """Tool position of the default robot from its URDF numbers: l1 = l2 = 0.2 m, z = -0.05 - q3."""
    a, b = q[..., 0], q[..., 0] + q[..., 1]
    return np.stack([0.2 * np.cos(a) + 0.2 * np.cos(b), 0.2 * np.sin(a) + 0.2 * np.sin(b), -0.05 - q[..., 2]], -1)


def _json(capsys: pytest.CaptureFixture[str], argv: list[str]) -> dict:
    assert main(argv) == 0, capsys.readouterr().err
    return json.loads(capsys.readouterr().out)


def _alone(capsys: pytest.CaptureFixture[str], tmp: Path, a: list[float], b: list[float], *extra: str) -> dict:
    """The jump from pose a to pose b planned alone: ``scara-pin traj --arch --from-pose A --to-pose B``."""
    return _json(capsys, ["traj", "--arch", "--from-pose", *map(repr, a), "--to-pose", *map(repr, b), "--json",
                          "--out", str(tmp / "alone.csv"), *extra])  # fmt: skip


def test_a_tray_job_is_its_jumps_planned_alone_and_its_dwells(robot_default: Robot, tmp_path: Path,
                                                              capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    job = write_job(tmp_path, TRAY, robot_default)
    csv = tmp_path / "job.csv"
    out = _json(capsys, ["job", str(job), "--json", "--out", str(csv), "--rate", str(RATE)])
    steps = out["steps"]
    assert [s["kind"] for s in steps] == ["jump", "dwell", "jump", "dwell"] * 4
    # the places: the grid of the corners' poses (Pinocchio's FK of the taught q), row by row
    fk = {n: robot_default.tool_pose(Job.load(job).points[n].q) for n in ("feeder", "T11", "T12", "T21")}
    places = [fk["T11"] + c * (fk["T12"] - fk["T11"]) + r * (fk["T21"] - fk["T11"]) for r in (0, 1) for c in (0, 1)]
    total = 0.0
    for k, step in enumerate(steps):
        assert step["t_end"] - step["t_start"] == pytest.approx(step["duration"], abs=1e-12)
        if k:
            assert step["t_start"] == steps[k - 1]["t_end"]
        if step["kind"] == "dwell":
            assert step["duration"] == pytest.approx(DWELL, abs=1e-15)
            total += DWELL
            continue
        going = step["target"] != "feeder"
        place = places[k // 4]
        a, b = (fk["feeder"], place) if going else (place, fk["feeder"])
        assert step["pose"] == pytest.approx(b.tolist(), abs=1e-12)
        alone = _alone(capsys, tmp_path, a.tolist(), b.tolist())
        assert step["duration"] == pytest.approx(alone["duration"], abs=PROMISE), (k, step["target"])
        assert alone["q_from"] == pytest.approx(steps[k - 2]["q"] if k else Job.load(job).points["feeder"].q.tolist(),
                                                abs=1e-9)  # the same configurations as the job's  # fmt: skip
        assert alone["q_to"] == pytest.approx(step["q"], abs=1e-9)
        assert step["binding"] and max(b["ratio"] for b in step["binding"]) >= 0.999  # something binds
        total += alone["duration"]
    assert out["total"] == pytest.approx(total, abs=len(steps) * PROMISE)
    assert out["places"] == 4 and out["parts_per_hour"] == pytest.approx(4 * 3600 / out["total"], rel=1e-12)
    # the CSV at 10 kHz: every limit, and every place passed through
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    t, q, qd, qdd = data[:, 0], data[:, 1:5], data[:, 5:9], data[:, 9:13]
    assert t[-1] >= out["total"] and np.diff(t) == pytest.approx(1 / RATE, abs=1e-12)
    v, acc = np.array(robot_default.limits.velocity), np.array(robot_default.limits.acceleration)
    assert (np.abs(qd) <= v * (1 + PROMISE)).all() and (np.abs(qdd) <= acc * (1 + PROMISE)).all()
    h = 1 / RATE
    floor = 4 * np.finfo(float).eps * np.max(np.abs(q)) / h  # rounding of the differences
    assert (np.abs(np.diff(q, axis=0)) / h <= v * (1 + PROMISE) + floor).all()  # a mean of qd over a step
    assert (np.abs(np.diff(q, 2, axis=0)) / h**2 <= acc * (1 + PROMISE) + floor / h).all()  # a mean of qdd
    xyz = scara_xyz(q)
    for place in places:
        assert np.min(np.linalg.norm(xyz - place[:3], axis=1)) <= 1e-9


@pytest.mark.parametrize(("key", "limit"), [("speed", "velocity"), ("accel", "acceleration")])
def test_half_speed_is_the_jump_with_halved_limits(key: str, limit: str, robot_default: Robot, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    job = write_job(tmp_path, f"start: feeder\nsteps:\n  - {key}: 50\n  - jump: T22\n", robot_default)
    half = Job.load(job).plan(robot_default).steps[0].duration
    full = Job.load(write_job(tmp_path, "start: feeder\nsteps:\n  - jump: T22\n", robot_default)).plan(
        robot_default).steps[0].duration  # fmt: skip
    values = getattr(robot_default.limits, limit)
    halved = [f"--set=joint{j + 1}_{limit}={values[j] / 2!r}" for j in range(4)]
    alone = _alone(capsys, tmp_path, list(POSES["feeder"]), list(POSES["T22"]), *halved)
    assert half == pytest.approx(alone["duration"], abs=PROMISE)
    assert half > 1.05 * full  # the percentage acts


def test_the_torques_with_a_payload(robot_default: Robot, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``torque: true`` and 8 kg: the jump of ``traj --arch --torque --payload 8``, on which a torque binds."""
    job = write_job(tmp_path, "start: feeder\ntorque: true\npayload: {mass: 8, com: [0, 0, 0.03]}\nsteps:\n"
                    "  - jump: T22\n", robot_default)  # fmt: skip
    step = Job.load(job).plan(robot_default).steps[0]
    alone = _alone(capsys, tmp_path, list(POSES["feeder"]), list(POSES["T22"]), "--torque", "--payload", "8",
                   "--payload-com", "0", "0", "0.03")  # fmt: skip
    assert step.duration == pytest.approx(alone["duration"], abs=PROMISE)
    assert "torque" in {b.quantity for b in step.binding}  # the payload acts


def test_a_return_jump_is_the_jump_reversed_and_a_repeat_is_reused(robot_default: Robot, tmp_path: Path) -> None:
    job = Job.load(write_job(tmp_path, "start: feeder\nsteps:\n  - jump: T22\n  - jump: feeder\n  - jump: T22\n",
                             robot_default))  # fmt: skip
    result = job.plan(robot_default)
    assert [s.planned for s in result.steps] == [Source.PLANNED.value, Source.REVERSED.value, Source.SAME.value]
    assert (result.stats.planned, result.stats.reversed, result.stats.same) == (1, 1, 1)
    qf, q22 = job.points["feeder"].q, job.points["T22"].q
    back = jump_move(robot_default, robot_default.tool_pose(q22), robot_default.tool_pose(qf), start=q22, end=qf,
                     torque=False)  # solved from its own end  # fmt: skip
    out, rev = result.steps[0], result.steps[1]
    assert rev.duration == pytest.approx(back.duration, abs=PROMISE)
    assert result.steps[2].duration == pytest.approx(out.duration, abs=1e-12)
    T = out.duration
    tau = np.random.default_rng(3).uniform(0.0, T, 50)
    q_out = result.trajectory.sample(tau)[0]
    q_back = result.trajectory.sample(rev.t_start + (T - tau))[0]
    assert q_back == pytest.approx(q_out, abs=1e-12)
    assert result.total == pytest.approx(3 * T + (rev.duration - T), abs=1e-12)


def test_joint_and_straight_moves_and_the_outputs(robot_default: Robot, tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    job = write_job(tmp_path, "start: feeder\nsteps:\n  - speed: 80\n  - go: home\n  - move: T22\n", robot_default)
    files = {flag: tmp_path / f"job.{ext}" for flag, ext in (("--plot", "png"), ("--html", "html"))}
    args = [item for flag, f in files.items() for item in (flag, str(f))]
    out = _json(capsys, ["job", str(job), "--json", *args])
    go, move = out["steps"]
    points = Job.load(job).points
    d = np.abs(points["home"].q - points["feeder"].q)
    v, a = 0.8 * np.array(robot_default.limits.velocity), np.array(robot_default.limits.acceleration)
    one = np.where(d >= v * v / a, d / v + v / a, 2 * np.sqrt(d / a))  # each joint alone, rest to rest
    assert go["duration"] == pytest.approx(float(np.max(one)), abs=1e-9)
    assert go["binding"][0]["joint"] == f"joint{int(np.argmax(one)) + 1}"
    assert move["speed_percent"] == 80.0
    qh, q22 = points["home"].q, points["T22"].q
    scaled = [f"--set=joint{j + 1}_velocity={robot_default.limits.velocity[j] * 0.8!r}" for j in range(4)]
    ends = [item for flag, q in (("--from", qh), ("--to", q22)) for item in (flag, *(repr(float(v)) for v in q))]
    alone = _json(capsys, ["traj", "--linear", *ends, "--json", "--out", str(tmp_path / "line.csv"), *scaled])
    assert move["duration"] == pytest.approx(alone["duration"], abs=1e-9)
    assert out["outputs"] == {"plot": str(files["--plot"]), "page": str(files["--html"])}
    assert files["--plot"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    page = files["--html"].read_text()
    assert '"motion"' in page and "<html" in page.lower()


def test_the_timeline_plot(robot_default: Robot, tmp_path: Path) -> None:
    from scara_pin.viz.job import plot_job

    job = write_job(tmp_path, "start: feeder\nsteps:\n  - jump: T22\n  - dwell: 0.1\n  - go: feeder\n", robot_default)
    result = Job.load(job).plan(robot_default)
    fig = plot_job(result, robot=robot_default)
    band, ax_v, ax_a = fig.axes[:3]
    assert [p.get_gid() for p in band.patches] == ["step-jump", "step-go"]  # the dwell left blank
    for ax in (ax_v, ax_a):
        top = max(float(np.max(line.get_ydata())) for line in ax.get_lines() if line.get_label().startswith("joint"))
        assert 0.999 <= top <= 1 + PROMISE  # each move touches a limit, none exceeds it


def test_ctrl_c_during_a_long_job_is_130_and_no_file(robot_default: Robot, tmp_path: Path) -> None:
    body = "start: feeder\npallets:\n  tray: {corners: [T11, T12, T21], rows: 6, columns: 6}\nsteps:\n" \
           "  - for: tray\n    do:\n      - jump: tray[i]\n      - jump: feeder\n"  # fmt: skip
    job = write_job(tmp_path, body, robot_default)
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    env.pop("SCARA_PIN_DEBUG", None)
    proc = subprocess.Popen([sys.executable, "-c", "import sys; from scara_pin.cli import main; sys.exit(main())",
                             "-v", "job", str(job), "--out", "out.csv", "--no-cache"], cwd=tmp_path,
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, preexec_fn=default_sigint,
                            env=env)  # fmt: skip
    assert proc.stderr is not None
    deadline = time.monotonic() + 60
    for text in proc.stderr:  # the first move planned: the job is under way
        if "job: line" in text or time.monotonic() > deadline:
            break
    assert proc.poll() is None, "the job ended before the signal: make it longer"
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip().splitlines()[-1] == "error: interrupted"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["job.yaml", "points.yaml"]  # no out.csv, no .tmp


def test_a_move_the_planner_refuses_names_its_line(robot_default: Robot, tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """T11 and T12 are 0.15 m apart: a clearance radius of 0.1 m leaves no traverse (the planner's exit 2)."""
    job = write_job(tmp_path, "start: T11\nsteps:\n  - jump: T12\n    clearance_radius: 0.1\n", robot_default)
    assert main(["job", str(job)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {job} line {line_of(job, 'jump: T12')}: jump T11 -> T12: the poses are 0.15 m "
                          "apart horizontally, not more than twice the clearance radius 0.1 m"), err
