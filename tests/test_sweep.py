"""Sweeps (scara_pin.sweep, `scara-pin sweep`): a job over many variants on Dask, the rows in Parquet.

Independent routes: the serial rows (``--workers 0``, in this process) equal each variant's job planned directly
through the Job API (``Job.load(...).replace(...).plan(robot)``); the rows of a real 2-worker ``LocalCluster``, of
a sweep whose worker is killed mid-way, of a Ctrl-C'd sweep run again, and of a scheduler and a worker started as
separate processes (``dask scheduler``, ``dask worker``) all equal the serial rows to 1e-12 s, every variant exactly
once on disk. The sweep: tests/data/sweep/sweep.yaml, 12 variants of a one-place tray (6 on ``s1``, whose quill
cannot reach the feeder: infeasible rows).
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import scara_pin
from scara_pin.cli import main
from scara_pin.sweep import QUIET, load_spec, open_client, sweep

DATA = Path(__file__).parent / "data" / "sweep"
SPEC = DATA / "sweep.yaml"
JOB = DATA / "job.yaml"
REPO = Path(__file__).parent.parent
NUMBERS = ("total", "parts_per_hour", "steady_parts_per_hour", "binding_share")
SAME = ("variant", "key", "status", "reason", "binding", "robot", "speed")


@pytest.fixture(scope="module")
def serial_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("serial")


@pytest.fixture(scope="module")
def serial(serial_folder: Path) -> pd.DataFrame:
    """The reference: every variant in this process, one after the other (``--workers 0``)."""
    return sweep(SPEC, workers=0, out=serial_folder)


@pytest.fixture(scope="module")
def client():  # noqa: ANN201 - a distributed.Client
    """A real local cluster of 2 single-threaded worker processes, as the command line starts it."""
    with open_client(workers=2) as c:
        yield c


def assert_same_rows(rows: pd.DataFrame, reference: pd.DataFrame, count: int = 12) -> None:
    """The same variants, statuses, reasons and numbers (1e-12 s; NaN where the reference has NaN): ``rows`` are
    ``count`` of the reference's (by key), in its order."""
    reference = reference[reference["key"].isin(set(rows["key"]))].reset_index(drop=True)
    rows = rows.sort_values("key", key=lambda k: k.map({v: n for n, v in enumerate(reference["key"])}))
    rows = rows.reset_index(drop=True)
    assert len(rows) == len(reference) == count
    for c in SAME if count == 12 else SAME[1:]:  # a part of the sweep numbers its variants its own way
        assert rows[c].tolist() == reference[c].tolist(), c
    assert [list(v) for v in rows["base.xyz"]] == [list(v) for v in reference["base.xyz"]]
    for c in NUMBERS:
        a, b = rows[c].to_numpy(dtype=float), reference[c].to_numpy(dtype=float)
        assert np.array_equal(np.isnan(a), np.isnan(b)), c
        assert np.nanmax(np.abs(a - b)) <= 1e-12 * (1 if c == "total" else max(1.0, np.nanmax(np.abs(b)))), c


def on_disk(folder: Path) -> pd.DataFrame:
    """Every row of a results folder, as pandas reads the Parquet dataset (not through the sweep's reader)."""
    return pd.read_parquet(folder)


# ------------------------------------------------------------------------------------------------ the spec
def test_the_spec_expands_to_the_grid_in_the_files_order() -> None:
    spec = load_spec(SPEC)
    variants = list(spec.variants())
    assert spec.count == len(variants) == 12 and spec.columns == ("robot", "base.xyz", "speed")
    assert [dict(v.values)["speed"] for v in variants[:3]] == [60, 80, 100]  # the last key fastest
    assert dict(variants[3].values)["base.xyz"] == [20.0, 0.0, 0.0] and variants[6].robot == "s1"
    assert len({v.key for v in variants}) == 12
    assert [v.key for v in load_spec(SPEC).variants()] == [v.key for v in variants]  # a content key: stable


def test_a_changed_job_is_a_new_key(tmp_path: Path) -> None:
    """The key digests the job's text: a rerun after an edit plans again."""
    (tmp_path / "job.yaml").write_text(JOB.read_text().replace("dwell: 0.05", "dwell: 0.06"))
    (tmp_path / "sweep.yaml").write_text(SPEC.read_text())
    old, new = [[v.key for v in load_spec(p).variants()] for p in (SPEC, tmp_path / "sweep.yaml")]
    assert not set(old) & set(new)


def _box_stl(path: Path, half: float) -> None:
    """An ASCII STL of a closed cube of half-side ``half`` [m], written here (twelve triangles)."""
    v = [(x, y, z) for x in (-half, half) for y in (-half, half) for z in (-half, half)]
    faces = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4), (2, 6, 3), (3, 6, 7), (0, 4, 2),
             (2, 4, 6), (1, 3, 5), (3, 7, 5)]  # fmt: skip
    body = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x} {y} {z}\n" for x, y, z in
                   (v[i] for i in f)) + "endloop\nendfacet\n" for f in faces)  # fmt: skip
    path.write_text(f"solid box\n{body}endsolid box\n")


def test_the_key_digests_the_cell_and_its_meshes_and_each_varied_file(tmp_path: Path) -> None:
    """A rerun after a mesh is edited plans again (the key holds the triangles, not the file's name); with the cell
    varied, an edit of one cell's mesh changes the keys of that cell's variants only."""
    for name in ("a", "b"):
        _box_stl(tmp_path / f"{name}.stl", 0.02)
        (tmp_path / f"{name}.yaml").write_text(f"obstacles:\n  - {{name: crate, shape: mesh, file: {name}.stl, "
                                               "xyz: [0.0, 0.45, -0.1]}\n")  # fmt: skip
    job = JOB.read_text().replace("start: feeder", "cell: a.yaml\nstart: feeder")
    (tmp_path / "job.yaml").write_text(job)
    (tmp_path / "one.yaml").write_text("job: job.yaml\nvary:\n  speed: [60, 80]\n")
    (tmp_path / "two.yaml").write_text("job: job.yaml\nvary:\n  cell: [a.yaml, b.yaml]\n  speed: [60, 80]\n")

    def keys(name: str) -> list[str]:
        return [v.key for v in load_spec(tmp_path / name).variants()]

    one, two = keys("one.yaml"), keys("two.yaml")
    _box_stl(tmp_path / "b.stl", 0.03)  # b's mesh grows: the variants on cell b only
    assert keys("one.yaml") == one
    again = keys("two.yaml")
    assert again[:2] == two[:2] and not set(again[2:]) & set(two)
    _box_stl(tmp_path / "a.stl", 0.025)  # the job's own cell's mesh: every key
    assert not set(keys("one.yaml")) & set(one)
    assert keys("two.yaml")[2:] == again[2:] and not set(keys("two.yaml")[:2]) & set(two)


def test_sobol_samples_are_seeded_scrambled_and_inside_the_ranges(tmp_path: Path) -> None:
    text = (f"job: {JOB}\nvary:\n  base.xyz: {{from: [-10, -20, 0], to: [10, 20, 0], steps: [5, 5, 1]}}\n"
            "  speed: [70, 100]\nsamples: 16\nseed: SEED\n")  # fmt: skip
    draws = {}
    for seed in (1, 2):
        (tmp_path / f"s{seed}.yaml").write_text(text.replace("SEED", str(seed)))
        spec = load_spec(tmp_path / f"s{seed}.yaml")
        xyz = np.array([dict(v.values)["base.xyz"] for v in spec.variants()])
        assert spec.count == len(xyz) == 32  # 16 samples x the 2 speeds
        assert np.all(np.abs(xyz[:, 0]) <= 10) and np.all(np.abs(xyz[:, 1]) <= 20) and np.all(xyz[:, 2] == 0)
        draws[seed] = xyz
    from scipy.stats import qmc

    expected = qmc.Sobol(2, scramble=True, seed=1).random(16)  # the same sequence, drawn independently
    assert np.allclose(draws[1][::2, :2], expected * [20, 40] - [10, 20], rtol=0, atol=1e-12)
    assert not np.allclose(draws[1], draws[2])


# ------------------------------------------------------------------------------------------ serial = Job API
def test_serial_rows_equal_each_variant_planned_through_the_job_api(serial: pd.DataFrame) -> None:
    from scara_pin import InfeasibleError, load_robot
    from scara_pin.job import Job

    robots = {name: load_robot(name) for name in ("default", "s1")}
    assert serial["status"].tolist() == ["ok"] * 6 + ["infeasible"] * 6  # an infeasible variant is a row
    for row in serial.to_dict("records"):
        job = Job.load(JOB).replace({"base.xyz": list(row["base.xyz"]), "speed": row["speed"], "robot": row["robot"]})
        try:
            result = job.plan(robots[row["robot"]], cache=False)
        except InfeasibleError as exc:
            assert row["status"] == "infeasible" and row["reason"] == " ".join(str(exc).split())
            assert math.isnan(row["total"])
            continue
        assert row["status"] == "ok" and row["reason"] == ""
        assert abs(row["total"] - result.total) <= 1e-12
        assert row["parts_per_hour"] == pytest.approx(result.parts_per_hour, rel=1e-14)
        assert row["steady_parts_per_hour"] == pytest.approx(result.steady_parts_per_hour, rel=1e-14)
        assert row["worker"].startswith("local ")
    assert serial.loc[0, "binding"] == "acceleration joint1"  # the tray's jumps: J1 bang-bang (docs/job.md)


# ------------------------------------------------------------------------------------------ on a cluster
def test_a_local_cluster_gives_the_serial_rows(serial: pd.DataFrame, client, tmp_path: Path) -> None:  # noqa: ANN001
    rows = sweep(SPEC, client, out=tmp_path / "r")
    assert_same_rows(rows, serial)
    assert set(rows["worker"]) <= set(client.scheduler_info()["workers"]) and rows["worker"].nunique() == 2
    disk = on_disk(tmp_path / "r")
    assert sorted(disk["key"]) == sorted(serial["key"])  # every variant once on disk
    assert_same_rows(disk.sort_values("variant").reset_index(drop=True), serial)


def test_variants_batched_per_task_give_the_serial_rows(serial: pd.DataFrame, client, tmp_path: Path) -> None:  # noqa: ANN001
    """``per_task=5``: the 12 variants in 3 tasks (5, 5, 2), each row as the serial run's, every variant once."""
    from distributed import get_task_stream

    with get_task_stream(client) as stream:
        rows = sweep(SPEC, client, out=tmp_path / "r", per_task=5)
    assert_same_rows(rows, serial)
    assert sorted(on_disk(tmp_path / "r")["key"]) == sorted(serial["key"])
    assert len([t for t in stream.data if str(t["key"]).startswith("sweep-")]) == 3


def test_a_bad_per_task_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["sweep", str(SPEC), "--out", str(tmp_path / "r"), "--per-task", "0"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: --per-task") and err.count("\n") == 1 and not (tmp_path / "r").exists()
    with pytest.raises(scara_pin.errors.ParameterError, match="per_task"):
        sweep(SPEC, workers=0, per_task=2.5)  # type: ignore[arg-type]


def test_the_local_workers_are_quiet_and_single_threaded(client) -> None:  # noqa: ANN001
    import dask

    settings = client.run(lambda: (dask.config.get("distributed.worker.profile.enabled"),
                                   dask.config.get("distributed.admin.tick.interval"),
                                   os.environ.get("MALLOC_TRIM_THRESHOLD_")))  # fmt: skip
    assert len(settings) == 2
    for profile, tick, trim in settings.values():
        assert profile is False and tick == QUIET["distributed.admin.tick.interval"]
        assert trim == QUIET["distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_"]
    assert set(client.nthreads().values()) == {1}
    ignored = client.run(lambda: signal.getsignal(signal.SIGINT) is signal.SIG_IGN)  # Ctrl-C is the client's
    assert list(ignored.values()) == [True, True]


def test_a_worker_killed_mid_sweep_loses_nothing(serial: pd.DataFrame, client, tmp_path: Path) -> None:  # noqa: ANN001
    """SIGKILL to a worker process running a variant: its tasks run elsewhere, no row lost or written twice."""
    killed: list[int] = []

    def kill_one(done: int, total: int) -> None:
        if killed:
            return
        busy = [w for w, keys in client.processing().items() if keys]
        if busy:
            pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    rows = sweep(SPEC, client, out=tmp_path / "r", batch=1, progress=kill_one)
    assert killed, "no worker was running a variant after the first row"
    assert_same_rows(rows, serial)
    disk = on_disk(tmp_path / "r")
    assert sorted(disk["key"]) == sorted(serial["key"])
    deadline = time.monotonic() + 30
    while len(client.scheduler_info()["workers"]) < 2 and time.monotonic() < deadline:  # the nanny restarts it
        time.sleep(0.2)


def _child_env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")])}


def test_ctrl_c_keeps_every_finished_row_and_a_rerun_completes(serial: pd.DataFrame, client, tmp_path: Path,  # noqa: ANN001
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    """Ctrl-C (SIGINT to the command's process group, as a terminal sends it): exit 130, the finished rows on disk,
    each once; the rerun runs only the rest and every variant is on disk exactly once. The command runs on the
    module's cluster (its workers, in another process group, ignore SIGINT anyway: the test above)."""
    from sigint import default_sigint

    out = tmp_path / "r"
    address = client.scheduler.address
    cmd = [sys.executable, "-m", "scara_pin.cli", "sweep", str(SPEC), "--out", str(out), "--scheduler", address,
           "--batch", "1"]  # fmt: skip
    proc = subprocess.Popen(cmd, env=_child_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_sigint)  # fmt: skip
    deadline = time.monotonic() + 60
    while not list(out.glob("part-*.parquet")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr and "error: interrupted" in stderr
    first = on_disk(out)
    assert 1 <= len(first) and first["key"].is_unique and set(first["status"]) <= {"ok", "infeasible"}
    assert main(["sweep", str(SPEC), "--out", str(out), "--scheduler", address]) == 0
    report = capsys.readouterr().out
    assert f"6 ok, 6 infeasible, 0 failed, 0 timeout; {12 - len(first)} run now, {len(first)} from earlier" in report
    assert "best      5 by parts per hour:" in report
    disk = on_disk(out)
    assert sorted(disk["key"]) == sorted(serial["key"])  # the rest, and nothing twice
    assert_same_rows(disk.sort_values("variant").reset_index(drop=True), serial)


@pytest.mark.heavy
def test_ctrl_c_on_the_commands_own_local_cluster(serial: pd.DataFrame, tmp_path: Path) -> None:
    """The default path: the command starts its own LocalCluster, and Ctrl-C reaches its workers too (one process
    group): exit 130 without a worker's traceback, the finished rows each once (about 10 s of start-ups)."""
    from sigint import default_sigint

    out = tmp_path / "r"
    cmd = [sys.executable, "-m", "scara_pin.cli", "sweep", str(SPEC), "--out", str(out), "--workers", "2",
           "--batch", "1"]  # fmt: skip
    proc = subprocess.Popen(cmd, env=_child_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=default_sigint)  # fmt: skip
    deadline = time.monotonic() + 60
    while not list(out.glob("part-*.parquet")) and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in stderr and stderr.endswith("error: interrupted\n"), stderr
    first = on_disk(out)
    assert len(first) >= 1 and first["key"].is_unique and set(first["status"]) <= {"ok", "infeasible"}


def test_a_scheduler_and_a_worker_started_apart_are_reached_by_address(serial: pd.DataFrame, tmp_path: Path,
                                                                        capsys: pytest.CaptureFixture[str]) -> None:
    import json

    file = tmp_path / "scheduler.json"
    env = _child_env()
    common = {"env": env, "stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    scheduler = subprocess.Popen([sys.executable, "-m", "dask", "scheduler", "--host", "127.0.0.1", "--port", "0",
                                  "--no-dashboard", "--scheduler-file", str(file)], **common)  # fmt: skip
    worker = None
    try:
        deadline = time.monotonic() + 30
        while not file.exists() and time.monotonic() < deadline:
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        worker = subprocess.Popen([sys.executable, "-m", "dask", "worker", address, "--nthreads", "1",
                                   "--no-dashboard", "--name", "apart"], **common)  # fmt: skip
        fewer = tmp_path / "sweep.yaml"  # 4 of the 12 variants (the same keys): one worker runs them in turn
        fewer.write_text(SPEC.read_text().replace("job: job.yaml", f"job: {JOB}").replace("[60, 80, 100]", "[100]"))
        code = main(["sweep", str(fewer), "--out", str(tmp_path / "r"), "--scheduler", address, "--json"])
        assert code == 0
        report = json.loads(capsys.readouterr().out)
        assert report["counts"] == {"ok": 2, "infeasible": 2} and report["run"] == 4
        disk = on_disk(tmp_path / "r")
        assert_same_rows(disk, serial, 4)
        assert disk["worker"].nunique() == 1 and disk["worker"][0].startswith("tcp://127.0.0.1:")
    finally:
        for p in (worker, scheduler):
            if p is not None:
                p.terminate()
                p.wait(timeout=30)


# ------------------------------------------------------------------------------------------ refused at once
def _spec(tmp_path: Path, body: str) -> str:
    path = tmp_path / "s.yaml"
    path.write_text(f"job: {JOB}\n" + body)
    return str(path)


@pytest.mark.parametrize(("body", "says"), [
    ("vary: {robot: [default, nope]}\n", "unknown robot 'nope'"),
    ("vary: {speed: []}\n", "an empty list"),
    ("vary: {base.xyz: {from: [0, 0, 0], to: [10, 0, 0], steps: [0, 1, 1]}}\n", "empty range"),
    ("vary: {base.xyz: {from: [0, 0, 0], to: [10, 10, 10], steps: [200, 100, 100]}}\n", "above the cap of 1,000,000"),
    ("vary: {speed: [70]}\nsamples: 0\n", "samples is 0"),
    ("vary: {l1: [0.2]}\n", "not a key of the job file"),
    ("vary: {speed: [70]}\ncolour: red\n", "unknown key 'colour'"),
    ("vary: {frames.tray.xyz: [[1, 2]]}\n", "frames.tray.xyz"),
])  # fmt: skip
def test_a_bad_spec_is_refused_at_once_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str], body: str,
                                                   says: str) -> None:
    start = time.perf_counter()
    code = main(["sweep", _spec(tmp_path, body), "--out", str(tmp_path / "r"), "--workers", "0"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1 and says in err, err
    assert time.perf_counter() - start < 5 and not (tmp_path / "r").exists()


def test_an_unreachable_scheduler_is_refused_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["sweep", str(SPEC), "--out", str(tmp_path / "r"), "--scheduler", "tcp://127.0.0.1:9",
                 "--connect-timeout", "1"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: cannot reach the scheduler tcp://127.0.0.1:9") and err.count("\n") == 1


# ------------------------------------------------------------------------------------------ the rest
@pytest.mark.parametrize("stop", [KeyboardInterrupt, RuntimeError])
def test_whatever_stops_a_sweep_the_finished_rows_are_written(tmp_path: Path, stop: type[BaseException]) -> None:
    """Ctrl-C in this process, or an error (a scheduler lost): the rows finished before it are on disk, once."""
    def progress(done: int, total: int) -> None:
        if done == 2:
            raise stop()

    spec = _spec(tmp_path, "vary: {robot: [s1], speed: [60, 80, 100]}\n")  # infeasible: quick rows
    with pytest.raises(stop):
        sweep(spec, workers=0, out=tmp_path / "r", progress=progress)
    assert on_disk(tmp_path / "r")["variant"].tolist() == [0, 1]


def test_a_variant_past_its_time_limit_is_a_timeout_row(tmp_path: Path) -> None:
    rows = sweep(_spec(tmp_path, "vary: {speed: [100]}\ntimeout: 1e-9\n"), workers=0)
    assert rows["status"].tolist() == ["timeout"] and "time limit" in rows["reason"][0]


def test_a_time_limit_stops_a_move_inside_its_planning() -> None:
    """The limit reaches inside one move (a worker's task runs in a thread no alarm signal reaches): a jump round a
    post (the search on the lattice, IPOPT solves) stopped at its first check, long before the move is planned in
    full; an outer limit that ends sooner stays in force; another thread is not limited."""
    import threading

    from scara_pin import load_robot
    from scara_pin.cell import Cell, Obstacle, Shape
    from scara_pin.motion.jump import jump_move
    from scara_pin.signals import TimeLimit, check_time, time_limit

    robot = load_robot("default")
    start = np.array([0.2608695652173913, -0.1525, -0.0875, 0.0])  # the standard cycle's, a post in its way
    post = Obstacle("post", Shape("cylinder", (0.02, 0.6), np.array([0.306, -0.052, 0.0]), np.zeros(3)))
    cell = Cell((post,), 0.002)
    clock = time.perf_counter()
    with pytest.raises(TimeLimit, match="past the time limit of 0 s"), time_limit(0.0):
        jump_move(robot, start, start + [0, 0.305, 0, 0], cell=cell)
    stopped = time.perf_counter() - clock
    clock = time.perf_counter()
    jump_move(robot, start, start + [0, 0.305, 0, 0], cell=cell)  # no limit in force any more
    assert stopped < (time.perf_counter() - clock) / 3
    with time_limit(0.0), time_limit(60.0), pytest.raises(TimeLimit, match="of 0 s"):
        check_time()
    elsewhere: list[BaseException] = []

    def probe() -> None:
        try:
            check_time()
        except BaseException as exc:  # noqa: BLE001 - recorded for the assertion below
            elsewhere.append(exc)

    with time_limit(0.0):
        thread = threading.Thread(target=probe)
        thread.start()
        thread.join()
    assert not elsewhere
    check_time()  # none in force


def test_a_urdf_robot_travels_as_its_text_and_plans_as_the_configured_one(tmp_path: Path) -> None:
    """``robot: [default, default.urdf]``: the URDF's text goes to the worker (a Robot does not pickle), with the
    sweep's acceleration limits; the same robot gives the same total by either route."""
    from scara_pin import generate_urdf, load_robot

    (tmp_path / "default.urdf").write_text(generate_urdf("default"))
    acc = list(load_robot("default").limits.acceleration)
    rows = sweep(_spec(tmp_path, f"vary: {{robot: [default, default.urdf], speed: [100]}}\nacceleration: {acc}\n"),
                 workers=0)  # fmt: skip
    assert rows["status"].tolist() == ["ok", "ok"], rows["reason"].tolist()
    assert abs(rows["total"][0] - rows["total"][1]) <= 1e-12 and rows["key"].nunique() == 2
    code = main(["sweep", _spec(tmp_path, "vary: {robot: [default.urdf]}\n"), "--out", str(tmp_path / "r")])
    assert code == 2  # a URDF has no acceleration limits: refused at once, before any cluster starts


@pytest.mark.heavy
def test_in_a_cell_the_row_has_the_closest_pair_and_the_cells_cost(tmp_path: Path) -> None:
    """The job of the tray with a camera post (tests/data/sweep/cell.yaml): the row's closest pair, its distance and
    the cell's cost are the JobResult's, planned through the Job API (about 6 s: two plans in a cell)."""
    from scara_pin import load_robot
    from scara_pin.job import Job

    spec = tmp_path / "s.yaml"
    spec.write_text(f"job: {DATA / 'cell.yaml'}\nvary: {{speed: [100]}}\n")
    row = sweep(spec, workers=0).iloc[0]
    result = Job.load(DATA / "cell.yaml").replace(speed=100).plan(load_robot("default"), cache=False)
    clearance = result.closest.clearance
    assert row["status"] == "ok" and abs(row["total"] - result.total) <= 1e-12
    assert row["closest_pair"] == clearance.pair and row["closest_distance"] == clearance.distance
    assert row["cell_cost"] == pytest.approx(result.cell_cost, abs=1e-15)


def test_the_workers_get_absolute_paths(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A worker in another folder (another machine on a shared file system) finds the job and a robot's folder."""
    import shutil

    from scara_pin.description import urdf_dir
    from scara_pin.sweep import recipe_of

    shutil.copytree(urdf_dir() / "config" / "default", tmp_path / "mine")
    (tmp_path / "job.yaml").write_text(JOB.read_text())
    (tmp_path / "s.yaml").write_text("job: job.yaml\nvary: {robot: [default, mine]}\n")
    monkeypatch.chdir(REPO)  # the folder is the sweep file's, not the current one
    recipe = recipe_of(load_spec(os.path.relpath(tmp_path / "s.yaml")))
    assert recipe.job == str(tmp_path.resolve() / "job.yaml")
    robots = dict(recipe.robots)
    assert robots["mine"].folder == str((tmp_path / "mine").resolve()) and robots["default"].folder is None


def test_the_package_is_callable_as_the_issue_spells_it(serial: pd.DataFrame, serial_folder: Path) -> None:
    """``scara_pin.sweep(spec)``: the subpackage is callable; resumed from a folder, nothing is planned again."""
    calls: list[int] = []
    rows = scara_pin.sweep(SPEC, None, workers=0, out=serial_folder, progress=lambda d, t: calls.append(d))
    assert not calls and callable(scara_pin.sweep) and scara_pin.sweep.sweep is sweep
    assert_same_rows(rows, serial)


def test_the_plot_is_a_heat_map_over_a_placement_grid(serial: pd.DataFrame, tmp_path: Path) -> None:
    from scara_pin.viz.sweep import pareto_front, placement_axes, plot_sweep

    xy = [[x, y, 0.0] for x in (0.0, 10.0, 20.0) for y in (0.0, 10.0)]
    rows = pd.DataFrame({"base.xyz": xy, "status": ["ok"] * 5 + ["infeasible"],
                         "parts_per_hour": [1.0, 2.0, 3.0, 4.0, 5.0, math.nan], "closest_distance": [math.nan] * 6,
                         "variant": range(6)})  # fmt: skip
    assert placement_axes(rows, ["base.xyz"]) == ("base.xyz", 0, 1)
    fig = plot_sweep(rows, tmp_path / "h.png", columns=["base.xyz"])
    assert (tmp_path / "h.png").stat().st_size > 1000 and "placement grid" in fig.axes[0].get_title()
    assert placement_axes(serial, ["robot", "base.xyz", "speed"]) is None  # base.xyz varies in x alone
    fig = plot_sweep(serial, tmp_path / "f.svg")  # the varied columns found; parts/h against the speed: a front
    assert "speed" in fig.axes[0].get_xlabel() and (tmp_path / "f.svg").read_text().startswith("<?xml")
    x, y = np.array([1.0, 2.0, 3.0, 2.0]), np.array([3.0, 2.0, 1.0, 1.0])
    assert pareto_front(x, y).tolist() == [0, 1, 2]  # (2, 1) is beaten by (3, 1) and (2, 2)


def test_fk_and_ik_import_neither_dask_nor_pandas_nor_toppra() -> None:
    code = ("import sys; from scara_pin.cli import main; main(['fk', '0', '0', '0', '0']); "
            "main(['ik', '0.3', '0.1', '-0.05', '0.2']); "
            "print(sorted(m for m in ('dask', 'distributed', 'pandas', 'pyarrow', 'toppra') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], env=_child_env(), capture_output=True, text=True, check=True)
    assert out.stdout.strip().splitlines()[-1] == "[]"
