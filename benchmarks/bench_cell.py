#!/usr/bin/env python
"""Benchmark: the jump in a cell (issue 27) against independent minima, the clock, and a sampling planner.

How to run. ``make bench-cell`` makes ``.venv-bench-cell`` (pyroboplan 1.3.1 from PyPI on top of ``-e .``:
see the Makefile for why it is installed without its pins) and runs the whole script there, about 4-6
minutes on the 2-core machine. With the project's interpreter (``.venv/bin/python benchmarks/bench_cell.py``)
parts 1 and 2 run and part 3 is skipped with a note. Options: ``--quick`` (3 seeds, 2 rounds), ``--seeds N``,
``--runs N``. Reported, not enforced (exit 0 unless something breaks). The machine is shared: every time is
given as wall time AND CPU time (``time.process_time`` in this process; ``getrusage(RUSAGE_CHILDREN)`` for
the commands run), medians of one run.

The task: the default robot's standard-cycle placement of ``tests/test_cell_motion.py`` (FROM -> TO, 305 mm
along +y, rest to rest), its limits (``robot.limits``: joint velocity and acceleration), the jump rule (the tool
at or above z_top = max(zA, zB) + 25 mm beyond 5 mm of A and B horizontally), margin 2 mm.

1. **Optimality**, on the three held-out cells of ``tests/test_cell_motion.py`` (CELLS: around, over, link):
   ours (``jump_move(robot, FROM, TO, cell=...)``: duration, planning wall and CPU time) against the
   independent minimum of ``tests/cell_reference.py`` (``minimum_time``: its own transcription, closed-form
   kinematics and distances, IPOPT) from three warm starts: a via point 60 mm LEFT of the straight line (toward
   the base), 60 mm RIGHT, and OVER it (15 mm above z_top), the fastest converged kept. Gap = ours /
   minimum - 1 (the issue's target: within 2 %). Ours is checked here too, independently of the package's
   verifier: every checked pair's distance with coal on Pinocchio's collision model of the URDF
   (``cell_sampling.DenseCheck``) and the limit ratios, at 10 kHz and on both sides of every breakpoint.
2. **Planning time of the command line**: ``scara-pin traj --arch --cell FILE --from-pose FROM --to-pose TO
   --out samples.csv`` (the samples written, as a user would) against ``python -c "import toppra,
   scara_pin"``, interleaved rounds, medians: with the AROUND cell as a YAML file (one obstacle; target
   <= 3x) and with a cell of 20 obstacles (:data:`CELL20`: boxes, cylinders, spheres around the workspace, the
   post of AROUND in the way, others near the path, and ONE mesh, ``trimesh.creation.icosphere(subdivisions=4)``,
   5,120 triangles, written as an STL; target <= 6x). The same 20 with the mesh replaced by a sphere of its
   radius is timed too (what the mesh costs). A command whose first run takes more than :data:`SLOW` s is not
   repeated (its ratio is from that run, said so). The samples of each 20-obstacle run are checked with coal
   here: the start and goal clear, every obstacle's closest distance over the motion, and the motion against
   the jump without the cell (which obstacles matter).
3. **The sampling baseline** (``cell_sampling``: pyroboplan 1.3.1's RRT-Connect and shortcutting, then
   TOPP-RA on a fixed grid, the rule imposed as lift, gate and descent, every motion checked at 10 kHz; its
   module docstring says exactly how, and what in pyroboplan is corrected): 10 seeds per cell; the valid
   motions' median and best durations, the planning wall and CPU time, how many seeds were valid, and what
   failed on the way.
4. **Summary** (markdown).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import importlib.util
import math
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent / "tests")]  # the helpers here; the held-out cells and the reference

import cell_sampling  # noqa: E402
from cell_reference import minimum_time  # noqa: E402
from test_cell_motion import CELLS, FROM, MARGIN, TO, Z_TOP, _cell  # noqa: E402

from scara_pin import Robot, load_robot  # noqa: E402
from scara_pin.motion.jump import jump_move  # noqa: E402

RATE = cell_sampling.RATE
WITHIN = 0.02  # the issue: within 2 % of the independent minimum
TARGET_ONE, TARGET_20 = 3.0, 6.0  # planning wall time / python -c "import toppra, scara_pin", at most
SEEDS, RUNS = 10, 5
SLOW = 60.0
"""[s] a command whose first run takes longer is not repeated (the script stays within ~10 minutes)."""
VIA_OFFSET, VIA_RAISE = 0.06, 0.015  # [m] the reference's warm starts: beside the straight line, above z_top

MESH_RADIUS = 0.03
CELL20: tuple[dict[str, object], ...] = (  # the cell file's entries (base frame, SI); the mesh file is written
    # in the way: the post of AROUND (the tool goes round it); near the path: a low stub, a wall near the goal,
    # the mesh (a rock) under the traverse
    {"name": "post", "shape": "cylinder", "radius": 0.02, "length": 0.6, "xyz": [0.306, -0.052, 0.0]},
    {"name": "stub", "shape": "cylinder", "radius": 0.015, "length": 0.13, "xyz": [0.20, 0.04, -0.135]},
    {"name": "wall", "shape": "box", "size": [0.3, 0.01, 0.1], "xyz": [0.30, 0.11, -0.12]},
    {"name": "rock", "shape": "mesh", "file": "rock.stl", "xyz": [0.27, 0.03, -0.11]},
    # around the workspace: the table (clear of the pedestal), feeders, trays, a camera post, a conveyor, ...
    {"name": "table", "shape": "box", "size": [0.45, 0.9, 0.02], "xyz": [0.35, 0.0, -0.21]},
    {"name": "feeder", "shape": "box", "size": [0.1, 0.15, 0.08], "xyz": [0.0, 0.33, -0.16]},
    {"name": "tray", "shape": "box", "size": [0.12, 0.12, 0.03], "xyz": [0.05, -0.33, -0.185]},
    {"name": "camera_post", "shape": "cylinder", "radius": 0.03, "length": 0.5, "xyz": [-0.25, 0.25, 0.0]},
    {"name": "conveyor", "shape": "box", "size": [0.15, 0.8, 0.05], "xyz": [0.56, 0.0, -0.15]},
    {"name": "cabinet", "shape": "box", "size": [0.1, 0.6, 0.6], "xyz": [-0.42, 0.0, 0.0]},
    {"name": "guard", "shape": "box", "size": [0.02, 0.3, 0.3], "xyz": [0.52, -0.35, 0.0], "rpy": [0, 0, 0.3]},
    {"name": "pipe", "shape": "cylinder", "radius": 0.02, "length": 0.5, "xyz": [0.0, -0.47, 0.2],
     "rpy": [0, math.pi / 2, 0]},  # fmt: skip
    {"name": "column", "shape": "cylinder", "radius": 0.025, "length": 0.5, "xyz": [0.45, -0.3, 0.0]},
    {"name": "lamp", "shape": "sphere", "radius": 0.04, "xyz": [-0.2, -0.2, 0.15]},
    {"name": "ball1", "shape": "sphere", "radius": 0.03, "xyz": [0.1, 0.47, 0.0]},
    {"name": "ball2", "shape": "sphere", "radius": 0.025, "xyz": [-0.3, 0.05, -0.1]},
    {"name": "sensor", "shape": "sphere", "radius": 0.02, "xyz": [0.46, 0.3, 0.05]},
    {"name": "bracket", "shape": "box", "size": [0.05, 0.05, 0.2], "xyz": [-0.15, 0.35, 0.1], "rpy": [0.2, 0, 0]},
    {"name": "duct", "shape": "cylinder", "radius": 0.03, "length": 0.6, "xyz": [-0.3, 0.0, 0.3],
     "rpy": [math.pi / 2, 0, 0]},  # fmt: skip
    {"name": "bin", "shape": "box", "size": [0.15, 0.1, 0.1], "xyz": [-0.1, -0.4, -0.15], "rpy": [0, 0, 0.5]},
)


@dataclass
class Clock:
    """Wall and CPU time of this process and of its finished children since it was made [s]."""

    def __post_init__(self) -> None:
        self.w0, self.c0, self.k0 = time.perf_counter(), time.process_time(), _children_cpu()

    def own(self) -> tuple[float, float]:
        return time.perf_counter() - self.w0, time.process_time() - self.c0

    def child(self) -> tuple[float, float]:
        return time.perf_counter() - self.w0, _children_cpu() - self.k0


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _med(xs: list[float]) -> float:
    return statistics.median(xs) if xs else math.nan


# ---------------------------------------------------------------------------------------------- part 1
@dataclass
class Ours:
    name: str
    duration: float
    minimum: float
    best_via: str
    converged: str
    wall: float
    cpu: float
    distance: float
    pair: str
    ratio: float
    q_from: np.ndarray
    q_to: np.ndarray

    @property
    def gap(self) -> float:
        return self.duration / self.minimum - 1.0


def _vias() -> dict[str, tuple[tuple[float, float, float], ...]]:
    u = (TO[:2] - FROM[:2]) / np.linalg.norm(TO[:2] - FROM[:2])
    left = np.array([-u[1], u[0]])
    mid = (FROM[:2] + TO[:2]) / 2
    return {"left": ((*(mid + VIA_OFFSET * left), Z_TOP),), "right": ((*(mid - VIA_OFFSET * left), Z_TOP),),
            "over": ((*mid, Z_TOP + VIA_RAISE),)}  # fmt: skip


def _jump_samples(traj: object) -> np.ndarray:
    """10 kHz and both sides of every breakpoint of a jump's trajectory."""
    piece = traj.pieces[0]
    T = traj.duration
    b = piece.breakpoints()
    t = np.concatenate([np.arange(math.floor(T * RATE) + 1) / RATE, b, b[1:] - 1e-9 * np.diff(b)])
    return np.clip(t, 0.0, T)


def optimality(robot: Robot) -> list[Ours]:
    print("1. The jump in the three held-out cells (tests/test_cell_motion.py) against the independent minimum")
    print("   (tests/cell_reference.py, warm starts left / right / over); ours checked here with coal at 10 kHz\n")
    lim = robot.limits
    v, a = np.array(lim.velocity), np.array(lim.acceleration)
    out = []
    for name, (posts, boxes, _) in CELLS.items():
        cell = _cell(posts, boxes)
        clock = Clock()
        move = jump_move(robot, FROM, TO, cell=cell)
        wall, cpu = clock.own()
        refs = {}
        for via, points in _vias().items():
            try:
                refs[via] = minimum_time(robot, FROM, TO, posts, boxes, MARGIN, [points])
            except AssertionError:  # "no warm start converged"
                refs[via] = math.nan
        best_via = min((k for k in refs if math.isfinite(refs[k])), key=lambda k: refs[k])
        q, qd, qdd = move.trajectory.sample(_jump_samples(move.trajectory))
        check = cell_sampling.DenseCheck(robot, cell)
        d, pair = check.closest(q)
        ratio = float(max(np.max(np.abs(qd) / v), np.max(np.abs(qdd) / a)))
        converged = ", ".join(f"{k} {t:.6f}" if math.isfinite(t) else f"{k} -" for k, t in refs.items())
        row = Ours(name, move.duration, refs[best_via], best_via, converged, wall, cpu, d, pair, ratio,
                   move.q_from, move.q_to)  # fmt: skip
        out.append(row)
        print(f"   {name:<7} ours {row.duration:.6f} s (planned in {wall:.2f} s wall, {cpu:.2f} s CPU); minimum "
              f"{row.minimum:.6f} s ({converged}; '-': did not converge); gap {row.gap * 100:+.2f} % "
              f"(target within {WITHIN * 100:g} %: {'met' if abs(row.gap) <= WITHIN else 'MISSED'}); "
              f"independent check: closest {pair} {d * 1e3:.4f} mm (margin {MARGIN * 1e3:g} mm), worst limit "
              f"ratio {ratio:.7f}", flush=True)  # fmt: skip
    return out


# ---------------------------------------------------------------------------------------------- part 2
def _yaml_cell(entries: tuple[dict[str, object], ...] | list[dict[str, object]]) -> str:
    import yaml

    return yaml.safe_dump({"margin": MARGIN, "obstacles": [dict(e) for e in entries]}, sort_keys=False)


def _write_cells(folder: Path) -> dict[str, Path]:
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=4, radius=MESH_RADIUS)
    mesh.export(folder / "rock.stl")
    posts, boxes, _ = CELLS["around"]
    around = [o.to_dict() for o in _cell(posts, boxes).obstacles]
    if any(o["shape"] != "cylinder" for o in around):
        raise RuntimeError("the AROUND cell holds more than a post: write its boxes' sizes here")
    sphere = [e if e["shape"] != "mesh" else {"name": e["name"], "shape": "sphere", "radius": MESH_RADIUS,
                                              "xyz": e["xyz"]} for e in CELL20]  # fmt: skip
    column = [{"name": "column", "shape": "cylinder", "radius": 0.01, "length": 0.6, "xyz": [0.24, -0.08, 0.0]}]
    files = {"around": around, "column": column, "20 (mesh)": CELL20, "20 (mesh -> sphere)": sphere}
    out = {}
    for key, entries in files.items():
        path = folder / f"cell-{len(out)}.yaml"
        path.write_text(_yaml_cell(list(entries)))
        out[key] = path
    return out


def _duration(stdout: str) -> float:
    """The duration the command printed (``duration  0.391239239 s``)."""
    found = re.search(r"^duration\s+([0-9.eE+-]+) s", stdout, re.MULTILINE)
    if found is None:
        raise RuntimeError(f"no duration in the command's output: {stdout[:200]!r}")
    return float(found.group(1))


def _triangles(path: Path) -> int:
    from scara_pin.cell import load_cell

    return sum(o.shape.triangles for o in load_cell(path).obstacles)


@dataclass
class Timing:
    walls: list[float]
    cpus: list[float]
    stdout: str = ""

    @property
    def wall(self) -> float:
        return _med(self.walls)

    @property
    def cpu(self) -> float:
        return _med(self.cpus)


def search_time(robot: Robot, runs: int) -> float:
    """The global search alone, in process, on the 20-obstacle cell (issue 37: it adds at most 1 s): median [s]."""
    from scara_pin.cell import load_cell, scene
    from scara_pin.motion.jump.problem import endpoints, top_configuration
    from scara_pin.motion.jump.search import search

    with tempfile.TemporaryDirectory(prefix="bench-cell-") as tmp:
        cell = load_cell(_write_cells(Path(tmp))["20 (mesh)"])
        sc = scene(robot, cell)
        qA, qB = endpoints(robot, FROM, TO, None, None, None)
        tops = (top_configuration(robot, FROM, Z_TOP, qA, "A", 0.025),
                top_configuration(robot, TO, Z_TOP, qB, "B", 0.025))
        times, found = [], None
        for _ in range(runs):
            t0 = time.perf_counter()
            found = search(sc, *tops, Z_TOP, None, np.array(robot.limits.velocity))
            times.append(time.perf_counter() - t0)
    assert found is not None
    print(f"\n2b. The global search in process, 20 obstacles (one a mesh): median {_med(times):.3f} s over {runs} runs "
          f"(target <= 1 s: {'met' if _med(times) <= 1.0 else 'MISSED'}); {len(found.ways)} ways on a lattice of "
          f"{found.nodes:,} configurations, {found.valid:,} clear")  # fmt: skip
    return _med(times)


def planning_time(robot: Robot, runs: int) -> dict[str, object]:
    print(f"\n2. Planning time of the command line against python -c \"import toppra, scara_pin\" ({runs} interleaved "
          f"rounds, medians; a command slower than {SLOW:g} s is run once)\n")  # fmt: skip
    exe = str(Path(sys.executable).with_name("scara-pin"))
    pose = [*map(repr, map(float, FROM))], [*map(repr, map(float, TO))]
    with tempfile.TemporaryDirectory(prefix="bench-cell-") as tmp:
        folder = Path(tmp)
        cells = _write_cells(folder)
        commands: dict[str, list[str]] = {"import": [sys.executable, "-c", "import toppra, scara_pin"]}
        for key, path in cells.items():
            commands[key] = [exe, "traj", "--arch", "--cell", str(path), "--from-pose", *pose[0], "--to-pose",
                             *pose[1], "--out", str(folder / f"samples-{len(commands)}.csv")]  # fmt: skip
        got = {k: Timing([], []) for k in commands}
        for r in range(runs):
            for key, argv in commands.items():
                if r > 0 and got[key].walls[0] > SLOW:
                    continue
                clock = Clock()
                done = subprocess.run(argv, capture_output=True, text=True, check=False)
                wall, cpu = clock.child()
                if done.returncode != 0:
                    raise RuntimeError(f"{key}: exit {done.returncode}: {done.stderr.strip()[-400:]}")
                got[key].walls.append(wall)
                got[key].cpus.append(cpu)
                got[key].stdout = done.stdout
        base = got["import"]
        print(f"   {'command':<56}{'runs':>5}{'wall [s]':>10}{'CPU [s]':>9}{'wall ratio':>12}{'CPU ratio':>11}  target")
        ratios = {}
        for key, t in got.items():
            label = "python -c 'import toppra, scara_pin'" if key == "import" else f"traj --arch --cell {key}"
            target = {"around": TARGET_ONE, "20 (mesh)": TARGET_20}.get(key)
            rw, rc = t.wall / base.wall, t.cpu / base.cpu
            ratios[key] = (rw, rc, len(t.walls), t.wall, t.cpu)
            verdict = "" if target is None else f"<= {target:g}x: {'met' if rw <= target else 'MISSED'}"
            print(f"   {label:<56}{len(t.walls):>5}{t.wall:>10.3f}{t.cpu:>9.3f}{rw:>11.2f}x{rc:>10.2f}x  {verdict}")
        print(f"   (the mesh: {_triangles(cells['20 (mesh)'])} triangles; the machine's load average "
              f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores at the end)")
        print("\n   The 20-obstacle motions, checked here (coal on the URDF's collision model, the samples the command "
              "wrote at 1 kHz):")
        free = jump_move(robot, FROM, TO).duration
        from scara_pin.cell import load_cell

        for key in ("20 (mesh)", "20 (mesh -> sphere)"):
            cell = load_cell(cells[key])
            check = cell_sampling.DenseCheck(robot, cell)
            q = np.loadtxt(commands[key][-1], delimiter=",", skiprows=1)[:, 1:5]
            D = check.distances(q)
            ends = D[[0, -1]].min()
            duration = _duration(got[key].stdout)
            per_obstacle: dict[str, float] = {}
            for k, label in enumerate(check.labels):
                if "(self)" not in label:
                    o = label.split(" - ")[1]
                    per_obstacle[o] = min(per_obstacle.get(o, math.inf), float(D[:, k].min()))
            near = sorted(per_obstacle.items(), key=lambda kv: kv[1])
            shown = ", ".join(f"{o} {d * 1e3:.2f}" for o, d in near[:6])
            print(f"   {key}: duration {duration:.6f} s (without the cell {free:.6f} s: the cell costs "
                  f"{(duration / free - 1) * 100:+.1f} %); start and goal {ends * 1e3:.2f} mm from the nearest "
                  f"obstacle or link; closest obstacles [mm]: {shown}; {sum(d > 0.05 for _, d in near)} of "
                  f"{len(near)} stay more than 50 mm away")  # fmt: skip
            if D.min() < MARGIN - cell_sampling.TOL:
                print(f"   !! {key}: the motion comes {D.min() * 1e3:.4f} mm close ({check.labels[D.min(0).argmin()]})")
    return ratios


# ---------------------------------------------------------------------------------------------- part 3
def sampling(robot: Robot, ours: list[Ours], seeds: int) -> dict[str, cell_sampling.CellResult] | None:
    print(f"\n3. The sampling baseline: pyroboplan RRT-Connect + shortcutting, then TOPP-RA (fixed grid of "
          f"{cell_sampling.GRID} steps), {seeds} seeds per cell, every motion checked at {RATE:g} Hz\n")  # fmt: skip
    if importlib.util.find_spec("pyroboplan") is None:
        print("   skipped: pyroboplan is not importable here (make bench-cell runs this script in .venv-bench-cell)")
        return None
    print(f"   pyroboplan {importlib.metadata.version('pyroboplan')}, toppra {importlib.metadata.version('toppra')}, "
          f"pin {importlib.metadata.version('pin')}; RRT options {cell_sampling.PLANNER}, padding = margin\n")
    out = {}
    for row in ours:
        posts, boxes, _ = CELLS[row.name]
        out[row.name] = cell_sampling.run_cell(robot, _cell(posts, boxes), row.name, FROM, TO, row.q_from,
                                               row.q_to, range(seeds))  # fmt: skip
    print()
    for name, res in out.items():
        found = [s for s in res.seeds if s.found]
        shipped = [s for s in found if s.shipped < MARGIN - cell_sampling.TOL]
        deepest = min((s.shipped for s in found), default=math.nan)
        spline_ok = sum(1 for s in found if s.tries and s.tries[0][2].valid(MARGIN))
        uses = {u: sum(1 for s in res.valid if s.used == u) for u in ("spline", "dense spline", "polyline")}
        wall, cpu = res.planning()
        print(f"   {name:<7} path found {len(found)}/{len(res.seeds)}, valid motions {len(res.valid)}/{len(res.seeds)} "
              f"({', '.join(f'{k} {v}' for k, v in uses.items())}); duration median {res.median():.4f} s, best "
              f"{res.best():.4f} s; planning median {wall:.2f} s wall, {cpu:.2f} s CPU")  # fmt: skip
        print(f"   {'':<7} shortcutting as shipped: {len(shipped)}/{len(found)} paths closer than the margin, the "
              f"worst {-deepest * 1e3 if deepest < 0 else deepest * 1e3:.1f} mm {'deep' if deepest < 0 else 'apart'}; "
              f"first spline valid on {spline_ok}/{len(found)}; toppra's default grid: worst ratios v "
              f"{max(s.default_grid[0] for s in found):.2f}x a {max(s.default_grid[1] for s in found):.2f}x; "
              f"fixed grid a {max(s.fine_grid[1] for s in found):.4f}x before the slow-down (at most "
              f"{max(s.k for s in found):.4f}x)")  # fmt: skip
    return out


# ---------------------------------------------------------------------------------------------- part 4
def summary(ours: list[Ours], ratios: dict[str, object], base: dict[str, cell_sampling.CellResult] | None) -> None:
    print("\n4. Summary (one run; wall times on a shared machine, CPU in brackets)\n")
    print("| cell | ours (s) | independent minimum (s) | gap | our planning (s) | pyroboplan median / best (s) "
          "| pyroboplan valid | pyroboplan planning (s) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for row in ours:
        res = None if base is None else base[row.name]
        if res is None:
            theirs, valid, plan = "not run", "", ""
        else:
            wall, cpu = res.planning()
            theirs = f"{res.median():.3f} / {res.best():.3f}"
            valid = f"{len(res.valid)}/{len(res.seeds)}"
            plan = f"{wall:.2f} ({cpu:.2f})"
        print(f"| {row.name} | {row.duration:.4f} | {row.minimum:.4f} | {row.gap * 100:+.2f} % | {row.wall:.2f} "
              f"({row.cpu:.2f}) | {theirs} | {valid} | {plan} |")  # fmt: skip
    print()
    for key, target in (("around", TARGET_ONE), ("20 (mesh)", TARGET_20), ("20 (mesh -> sphere)", None)):
        rw, rc, n, wall, cpu = ratios[key]  # type: ignore[index]
        verdict = "" if target is None else f", target <= {target:g}x: {'met' if rw <= target else 'MISSED'}"
        print(f"- planning, `traj --arch --cell` {key} / `import toppra, scara_pin`: {rw:.2f}x wall, {rc:.2f}x CPU "
              f"({wall:.2f} s, {cpu:.2f} s CPU; {n} run{'s' if n > 1 else ''}{verdict})")  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="3 seeds, 2 rounds")
    parser.add_argument("--seeds", type=int, default=None, help=f"seeds per cell (default {SEEDS})")
    parser.add_argument("--runs", type=int, default=None, help=f"rounds of the command-line timing (default {RUNS})")
    args = parser.parse_args()
    seeds = args.seeds or (3 if args.quick else SEEDS)
    runs = args.runs or (2 if args.quick else RUNS)
    start = Clock()
    print(f"bench_cell: {time.strftime('%Y-%m-%d %H:%M')}, Python {platform.python_version()}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}; default robot, FROM {FROM.tolist()} -> TO {TO.tolist()}, margin "
          f"{MARGIN * 1e3:g} mm\n")  # fmt: skip
    robot = load_robot("default")
    ours = optimality(robot)
    ratios = planning_time(robot, runs)
    search_time(robot, runs)
    base = sampling(robot, ours, seeds)
    summary(ours, ratios, base)
    wall, cpu = start.own()
    print(f"\n(the script: {wall:.0f} s wall, {cpu:.0f} s CPU in this process)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
