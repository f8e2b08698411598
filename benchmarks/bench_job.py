#!/usr/bin/env python
"""Benchmark: the issue's 4 x 6 tray job (docs/examples/tray) and the palletizer's job (docs/examples/palletizer)
against their moves planned alone, and the clock.

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_job.py [tray] [palletizer] [cache]
[--variants]``, the two jobs by default); reported, not enforced (the suite's tests/test_job_plan.py checks the
tray's promises on a 2 x 2 tray, tests/test_job_palletizer.py the palletizer's on the whole job).

The tray:

1. ``scara-pin job docs/examples/tray/job.yaml --json --out tray.csv --rate 10000`` in a subprocess, timed.
2. Every jump of it planned ALONE by ``scara-pin traj --arch --from-pose A --to-pose B --json`` (in this
   process, ``main([...])``: the command's own code), A and B the places' poses written here from the
   corners' FK (the grid of the three taught corners); the final ``move: home`` by ``traj --linear`` between
   the same configurations. Printed: the largest |job - alone| per kind, and the job's total against the sum
   of the moves alone and the dwells (the issue's promise: 1e-6 s).
3. The README's excerpt of the job's table: each of its lines (but the planning time's) in the command's text
   output.
4. The CSV at 10 kHz: the worst |qd| / vmax and |qdd| / amax of its rows, the same by finite differences
   of its positions (a mean over a step, never above the maximum), and the farthest place from the nearest
   row (the SCARA's closed-form FK: every place is passed through).

The palletizer (2 layers of 3 boxes from a conveyor, issue 28 item 3):

5. ``scara-pin job docs/examples/palletizer/job.yaml --json --out pal.csv --rate 10000`` in a subprocess: its
   wall and CPU time (the child's), total, boxes per hour, the closest pair the package's verifier found.
6. Each jump planned alone (``jump_move`` between the same configurations, no cell): the largest
   |job - alone| and the total against the jumps alone and the grips.
7. The clearance checked independently at every 10 kHz row (tests/test_job_palletizer.py's
   ``independent_clearance``: coal on Pinocchio's collision model, the boxes from the JSON).
8. ``--variants``: the same job filled near-first (the boxes carried over the boxes already placed) and with
   10 mm between the boxes instead of 20: whether they plan, and how long that takes.

The design loop (``cache``, issue 34), in a plan cache of its own:

9. the tray job planned once, then run again unchanged ``ROUNDS`` times, each round beside ``python -c "import
   scara_pin"``, interleaved: the medians of their wall times and their ratio (the promise: at most 1.5);
10. ``docs/examples/tray/frames.yaml`` (pose points, the tray in a frame), then the tray moved 80 mm with ``--set
    frames.tray.xyz=[...]``: the moves each run planned and read from the cache, and its wall time.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from scara_pin import load_robot
from scara_pin.cli import main
from scara_pin.job import Job

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "docs" / "examples" / "tray" / "job.yaml"
PALLETIZER = ROOT / "docs" / "examples" / "palletizer"
RATE = 10_000.0


def _cli(argv: list[str]) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(argv)
    if code != 0:
        raise SystemExit(f"scara-pin {' '.join(argv)}: exit {code}")
    return json.loads(out.getvalue())


def main_() -> None:
    robot = load_robot("default")
    job = Job.load(EXAMPLE)
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "tray.csv"
        t0 = time.perf_counter()
        done = subprocess.run([sys.executable, "-c", "import sys; from scara_pin.cli import main; sys.exit(main())",
                               "job", str(EXAMPLE), "--json", "--out", str(csv), "--rate", str(RATE)],
                              capture_output=True, text=True, check=True)  # fmt: skip
        wall = time.perf_counter() - t0
        out = json.loads(done.stdout)
        data = np.loadtxt(csv, delimiter=",", skiprows=1)
        side = Path(tmp) / "alone.csv"
        fk = {n: robot.tool_pose(job.points[n].q) for n in ("feeder", "T11", "T16", "T41")}
        places = [fk["T11"] + c / 5 * (fk["T16"] - fk["T11"]) + r / 3 * (fk["T41"] - fk["T11"])
                  for r in range(4) for c in range(6)]  # fmt: skip
        worst = {"jump": 0.0, "move": 0.0}
        alone_total, poses_off = 0.0, 0.0
        previous = fk["feeder"]
        q_prev = job.points["feeder"].q
        t1 = time.perf_counter()
        for step in out["steps"]:
            if step["kind"] == "dwell":
                alone_total += step["duration"]
                continue
            if step["kind"] == "jump":
                target = places[step["place"]["index"] - 1] if step["place"] else fk["feeder"]
                poses_off = max(poses_off, float(np.max(np.abs(np.array(step["pose"]) - target))))
                alone = _cli(["traj", "--arch", "--from-pose", *map(repr, previous.tolist()), "--to-pose",
                              *map(repr, target.tolist()), "--json", "--out", str(side)])  # fmt: skip
                previous = target
            else:
                alone = _cli(["traj", "--linear", "--from", *(repr(float(v)) for v in q_prev), "--to",
                              *(repr(float(v)) for v in step["q"]), "--json", "--out", str(side)])  # fmt: skip
            worst[step["kind"]] = max(worst[step["kind"]], abs(step["duration"] - alone["duration"]))
            alone_total += alone["duration"]
            q_prev = np.array(step["q"])
        alone_wall = time.perf_counter() - t1
    text = subprocess.run([sys.executable, "-c", "import sys; from scara_pin.cli import main; sys.exit(main())",
                           "job", "docs/examples/tray/job.yaml"], capture_output=True, text=True, check=True,
                          cwd=ROOT).stdout.splitlines()  # fmt: skip
    readme = (ROOT / "README.md").read_text().split("$ .venv/bin/scara-pin job docs/examples/tray/job.yaml\n")[1]
    excerpt = [line for line in readme.split("```")[0].splitlines() if line and line.strip() != "..."]
    stale = [line for line in excerpt if not line.startswith("planning") and line not in text]
    t, q, qd, qdd = data[:, 0], data[:, 1:5], data[:, 5:9], data[:, 9:13]
    v, a = np.array(robot.limits.velocity), np.array(robot.limits.acceleration)
    h = 1.0 / RATE
    a_ = q[..., 0], q[..., 0] + q[..., 1]
    xyz = np.stack([0.2 * np.cos(a_[0]) + 0.2 * np.cos(a_[1]), 0.2 * np.sin(a_[0]) + 0.2 * np.sin(a_[1]),
                    -0.05 - q[..., 2]], -1)  # the default robot's closed-form FK  # fmt: skip
    miss = max(float(np.min(np.linalg.norm(xyz - p[:3], axis=1))) for p in places)
    jumps = sum(s["kind"] == "jump" for s in out["steps"])
    print(f"job        {EXAMPLE.relative_to(EXAMPLE.parents[3])}: {len(out['steps'])} steps, {jumps} jumps, "
          f"{out['places']} places")  # fmt: skip
    print(f"total      {out['total']:.6f} s, {out['parts_per_hour']:,.1f} parts per hour")
    print(f"alone      sum of the moves planned alone and the dwells {alone_total:.6f} s: |difference| "
          f"{abs(out['total'] - alone_total):.2e} s")  # fmt: skip
    print(f"per move   largest |job - alone|: jumps {worst['jump']:.2e} s, straight move {worst['move']:.2e} s; "
          f"places' poses off by {poses_off:.1e}")  # fmt: skip
    print(f"csv        {len(t):,} rows at {RATE:g} Hz: |qd|/vmax {np.max(np.abs(qd) / v):.9f}, |qdd|/amax "
          f"{np.max(np.abs(qdd) / a):.9f}; by differences {np.max(np.abs(np.diff(q, axis=0)) / h / v):.9f}, "
          f"{np.max(np.abs(np.diff(q, 2, axis=0)) / h**2 / a):.9f}; farthest place from a row {miss:.1e} m")
    print(f"README     {len(excerpt)} lines of the job's table: " + (f"STALE: {stale}" if stale else "as the command "
          "prints them"))  # fmt: skip
    st = out["planning"]
    print(f"planning   `scara-pin job` {wall:.1f} s wall ({st['planned']} moves planned, {st['reversed']} jumps "
          f"reversed, {st['seconds']:.1f} s planning); the {jumps + 1} moves alone, in one process: "
          f"{alone_wall:.1f} s")  # fmt: skip


def _job(path: Path, *extra: str) -> tuple[subprocess.CompletedProcess[str], float, float]:
    """``scara-pin job PATH ...`` in a subprocess: (the process, its wall time [s], its CPU time [s])."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-c", "import sys; from scara_pin.cli import main; sys.exit(main())", "job",
                           str(path), *extra], capture_output=True, text=True, check=False)  # fmt: skip
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return done, wall, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def palletizer(variants: bool) -> None:
    from scara_pin.motion.jump import jump_move

    sys.path.insert(0, str(ROOT / "tests"))
    from test_job_palletizer import independent_clearance

    robot = load_robot("palletizer")
    with tempfile.TemporaryDirectory() as tmp:
        csv = Path(tmp) / "pal.csv"
        done, wall, cpu = _job(PALLETIZER / "job.yaml", "--json", "--out", str(csv), "--rate", str(RATE))
        if done.returncode != 0:
            raise SystemExit(done.stderr)
        out = json.loads(done.stdout)
        worst, alone_total, t1 = 0.0, 0.0, time.perf_counter()
        for step in out["steps"]:
            if step["kind"] != "jump":
                alone_total += step["duration"]
                continue
            qA, qB = np.array(out["steps"][step["index"] - 2]["q"]), np.array(step["q"])
            alone = jump_move(robot, robot.tool_pose(qA), robot.tool_pose(qB), start=qA, end=qB, torque=False)
            worst = max(worst, abs(step["duration"] - alone.duration))
            alone_total += alone.duration
        alone_wall = time.perf_counter() - t1
        t2 = time.perf_counter()
        distance, pair, when, exact, margin = independent_clearance(out, csv, robot)
        check_wall = time.perf_counter() - t2
    closest = out["closest"]
    jumps = sum(s["kind"] == "jump" for s in out["steps"])
    print(f"job        docs/examples/palletizer/job.yaml: {len(out['steps'])} steps, {jumps} jumps, "
          f"{len(out['boxes'])} boxes")  # fmt: skip
    print(f"total      {out['total']:.6f} s, {out['boxes_per_hour']:,.1f} boxes per hour")
    print(f"alone      the jumps planned alone (no cell) and the grips {alone_total:.6f} s: |difference| "
          f"{abs(out['total'] - alone_total):.2e} s; largest |job - alone| of a jump {worst:.2e} s")  # fmt: skip
    print(f"closest    verifier: {closest['pair']} {closest['distance'] * 1e3:.3f} mm (step {closest['step']}); "
          f"independent coal at {RATE:g} Hz: {pair} {distance * 1e3:.3f} mm at t = {when:.4f} s ({exact:,} exact "
          f"distances, {check_wall:.1f} s); margin {margin * 1e3:g} mm")  # fmt: skip
    st = out["planning"]
    print(f"planning   `scara-pin job` {wall:.1f} s wall, {cpu:.1f} s CPU ({st['planned']} moves planned); the "
          f"{jumps} jumps alone without the cell, in one process: {alone_wall:.1f} s")  # fmt: skip
    if not variants:
        return
    with tempfile.TemporaryDirectory() as tmp:
        for name, edit in (("near-first", lambda text: text.replace("corners: [S1, S3]", "corners: [S3, S1]")),
                           ("10 mm gaps", None)):  # fmt: skip
            folder = Path(tmp) / name.replace(" ", "_")
            shutil.copytree(PALLETIZER, folder)
            job = folder / "job.yaml"
            if edit is not None:
                job.write_text(edit(job.read_text()))
            else:  # S1 and S3 taught 10 mm closer to the middle: a pitch of 0.31 m for 0.3 m boxes
                from scara_pin.motion.points import PointSet, TaughtPoint, read_points, write_points

                points = read_points(folder / "points.yaml")
                moved = []
                for p in points:
                    if p.name in ("S1", "S3"):
                        pose = p.pose.copy()
                        pose[1] -= 0.01 * np.sign(pose[1])
                        p = TaughtPoint.at(robot, p.name, robot.ik_nearest(pose, p.q))
                    moved.append(p)
                write_points(folder / "points.yaml", PointSet(tuple(moved), points.robot, points.base, points.tool))
            done, wall, cpu = _job(job, "--json")
            if done.returncode == 0:
                found = json.loads(done.stdout)
                print(f"variant    {name}: {found['total']:.6f} s, {found['boxes_per_hour']:,.1f} boxes per hour; "
                      f"{wall:.1f} s wall, {cpu:.1f} s CPU")  # fmt: skip
            else:
                print(f"variant    {name}: exit {done.returncode} after {wall:.1f} s wall, {cpu:.1f} s CPU: "
                      f"{done.stderr.strip().split(': ', 2)[-1]}")  # fmt: skip


ROUNDS = 7
"""Interleaved rounds of the cached job and of the bare import (their medians are compared)."""


def cache() -> None:
    """The design loop: an unchanged job run again, against Python's start with scara-pin; a moved tray."""
    import statistics

    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, SCARA_PIN_CACHE_DIR=tmp)
        cmd = [sys.executable, "-c", "import sys; from scara_pin.cli import main; sys.exit(main())", "job"]

        def timed(argv: list[str]) -> tuple[float, str]:
            t0 = time.perf_counter()
            done = subprocess.run(argv, capture_output=True, text=True, check=True, env=env, cwd=ROOT)
            return time.perf_counter() - t0, done.stdout

        first, text = timed([*cmd, str(EXAMPLE)])
        print(f"first      {EXAMPLE.name}: {first:.2f} s wall; {text.strip().splitlines()[-1]}")
        runs, imports = [], []
        for _ in range(ROUNDS):
            imports.append(timed([sys.executable, "-c", "import scara_pin"])[0])
            wall, text = timed([*cmd, str(EXAMPLE)])
            runs.append(wall)
        run, imp = statistics.median(runs), statistics.median(imports)
        print(f"again      {text.strip().splitlines()[-1]}")
        print(f"rerun      median of {ROUNDS}: {run:.3f} s wall; `python -c \"import scara_pin\"` {imp:.3f} s: "
              f"{run / imp:.2f}x")  # fmt: skip
        frames = EXAMPLE.parent / "frames.yaml"
        for what, extra in (("frames", []), ("frames again", []),
                            ("tray moved", ["--set", "frames.tray.xyz=[300,-60,-100]"])):  # fmt: skip
            wall, text = timed([*cmd, str(frames), *extra])
            print(f"{what:<10} {wall:.2f} s wall; {text.strip().splitlines()[-1]}")


if __name__ == "__main__":
    chosen = [a for a in sys.argv[1:] if not a.startswith("--")] or ["tray", "palletizer"]
    if "cache" in chosen:
        cache()
    if "tray" in chosen:
        main_()
    if "palletizer" in chosen:
        palletizer("--variants" in sys.argv)
