#!/usr/bin/env python
"""Benchmark: a straight move through a post, refused before any timing, against ``scara-pin fk 0 0 0 0``.

Issue 37 asks that "a straight move through a post [be] refused in <= 3x the time of ``scara-pin fk 0 0 0 0``"
(1.66 s, about 2.9x, before its item 6; a tray job's straight move through a camera post was refused after 39 s).
The fixed path is now followed in the cell before TOPP-RA and the 10 kHz verifier run
(:func:`scara_pin.motion.plan.check_fixed_path`: conservative advancement on coal's distances), so the refusal
costs the command's start, the cell and the path.

Measured: whole-process wall times of

- ``scara-pin traj --linear --cell post.yaml --from-pose 0.306 -0.2 -0.08 0 --to-pose 0.306 0.1 -0.08 0`` (the
  README's post, 20 mm in radius, across the line: exit 3, ``the motion comes closer than the margin: ...``),
- ``scara-pin job`` of the tray's two places with the post moved onto the straight move home (exit 3),
- ``scara-pin fk 0 0 0 0`` (the reference),

interleaved (the order alternating), bytecode and the description cache in a private temporary folder filled by a
warm-up run, as ``benchmarks/bench_fk.py`` measures the cold start. Before timing, each refusal is checked: exit 3,
one ``error:`` line naming the post and saying it was found before any timing. Reported: medians, the ratio of the
medians, and whether the target (3x) is met; ``--json`` prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TARGET = 3.0
RUNS, QUICK_RUNS = 10, 4
POST = ("margin: 0.002\nobstacles:\n"
        "  - {name: post, shape: cylinder, radius: 0.02, length: 0.3, xyz: [0.306, -0.052, -0.05]}\n")
CAMERA = ("margin: 0.002\nobstacles:\n"
          "  - {name: camera, shape: cylinder, radius: 0.01, length: 0.4, xyz: [0.125, -0.21, 0.0]}\n")


def commands(folder: Path) -> dict[str, list[str]]:
    """The three commands, their files written in ``folder``."""
    (folder / "post.yaml").write_text(POST)
    (folder / "camera.yaml").write_text(CAMERA)
    tray = REPO / "docs" / "examples" / "tray"
    (folder / "points.yaml").write_bytes((tray / "points.yaml").read_bytes())
    (folder / "job.yaml").write_text((tray / "small.yaml").read_text().replace("steps:", "cell: camera.yaml\nsteps:"))
    script = str(Path(sys.executable).with_name("scara-pin"))
    return {
        "move": [script, "traj", "--linear", "--cell", str(folder / "post.yaml"), "--from-pose", "0.306", "-0.2",
                 "-0.08", "0", "--to-pose", "0.306", "0.1", "-0.08", "0"],
        "job": [script, "job", str(folder / "job.yaml")],
        "fk": [script, "fk", "0", "0", "0", "0"],
    }  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer runs")
    parser.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = parser.parse_args()
    runs = QUICK_RUNS if args.quick else RUNS
    with tempfile.TemporaryDirectory(prefix="bench-fixed-path-") as tmp:
        folder = Path(tmp)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "SCARA_PIN_NO_CACHE")}
        env.update(PYTHONPYCACHEPREFIX=str(folder / "pycache"), SCARA_PIN_CACHE_DIR=str(folder / "cache"),
                   OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")  # fmt: skip
        cmds = commands(folder)

        def run(name: str) -> tuple[float, subprocess.CompletedProcess[str]]:
            t0 = time.perf_counter()
            done = subprocess.run(cmds[name], capture_output=True, text=True, env=env, check=False, cwd=folder)
            return time.perf_counter() - t0, done

        for name in cmds:  # warm-up (bytecode, the description cache), and the answers checked
            _, done = run(name)
            if name == "fk":
                if done.returncode != 0:
                    print(f"fk failed: {done.stderr}", file=sys.stderr)
                    return 1
                continue
            lines = done.stderr.strip().splitlines()
            if done.returncode != 3 or len(lines) != 1 or "found before any timing" not in lines[0] \
                    or ("post" if name == "move" else "camera") not in lines[0]:  # fmt: skip
                print(f"{name}: not the refusal expected: exit {done.returncode}: {done.stderr}", file=sys.stderr)
                return 1
            if name == "move":
                message = lines[0]
        samples: dict[str, list[float]] = {name: [] for name in cmds}
        names = list(cmds)
        for i in range(runs):
            for name in names if i % 2 == 0 else names[::-1]:
                samples[name].append(run(name)[0])
    medians = {name: statistics.median(v) for name, v in samples.items()}
    report = {
        "runs": runs,
        "median_seconds": medians,
        "ratio_move_to_fk": medians["move"] / medians["fk"],
        "ratio_job_to_fk": medians["job"] / medians["fk"],
        "target": TARGET,
        "met": medians["move"] / medians["fk"] <= TARGET,
        "message": message,
        "load_average": os.getloadavg(),
    }
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"straight move through a post, refused  {medians['move']:.3f} s  ({report['ratio_move_to_fk']:.2f}x fk; "
          f"target <= {TARGET:g}x: {'met' if report['met'] else 'MISSED'})")
    print(f"tray job, its move home through a post  {medians['job']:.3f} s  ({report['ratio_job_to_fk']:.2f}x fk)")
    print(f"scara-pin fk 0 0 0 0                    {medians['fk']:.3f} s")
    print(f"medians of {runs} interleaved runs; load average {', '.join(f'{v:.2f}' for v in os.getloadavg())}")
    print(f"the refusal: {message}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
