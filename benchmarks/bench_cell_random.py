#!/usr/bin/env python3
"""Benchmark: the jump in random cells built around a clear reference motion (tests/cell_random.py, issue 37).

Each seed draws a cell (three to eight boxes, cylinders, spheres and convex meshes, half the time a carried box)
around a reference jump known to be clear (the free jump, or one bent round a post taken away afterwards). The
planner must solve every cell, verified and certified clear between its samples, no slower than the reference's
own time-optimal timing. Printed: how many were solved, the distribution of ours / reference, planning times.

    .venv/bin/python benchmarks/bench_cell_random.py [--seeds 200] [--workers 2] [--markdown]
"""

from __future__ import annotations

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def one(seed: int) -> dict[str, object]:
    from cell_random import MARGIN, random_cell

    from scara_pin import load_robot
    from scara_pin.motion.jump import jump_move
    from scara_pin.motion.verify import DISTANCE_TOL

    robot = load_robot("default")
    drawn = random_cell(robot, seed)
    row: dict[str, object] = {"seed": seed, "kind": drawn.kind, "obstacles": len(drawn.cell.obstacles),
                              "carried": drawn.cell.carried is not None, "reference": drawn.reference.duration}
    t0 = time.perf_counter()
    try:
        move = jump_move(robot, drawn.A, drawn.B, cell=drawn.cell)
    except Exception as exc:  # noqa: BLE001 - a failure is a row of the report
        row.update(status="failed", reason=str(exc)[:200], seconds=time.perf_counter() - t0)
        return row
    ok = move.distance.certified.certified and move.distance.bound >= MARGIN - DISTANCE_TOL
    row.update(status="ok" if ok else "not certified", ours=move.duration,
               ratio=move.duration / drawn.reference.duration, seconds=time.perf_counter() - t0)
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--first", type=int, default=1, help="the first seed (a run in parts)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--markdown", action="store_true", help="print the docs/benchmarks.md table")
    args = ap.parse_args()
    seeds = list(range(args.first, args.first + args.seeds))
    rows = []
    with ProcessPoolExecutor(args.workers) as pool:
        for r in pool.map(one, seeds):  # in order, each printed as it is done (a long run can be read as it goes)
            rows.append(r)
            print(f"seed {r['seed']}: {r['status']} {r['kind']} {r['obstacles']} obstacles"
                  f"{', carried' if r['carried'] else ''}: ours/reference {float(r.get('ratio', np.nan)):.4f}, "
                  f"{float(r['seconds']):.1f} s", flush=True)  # type: ignore[arg-type]  # fmt: skip
    solved = [r for r in rows if r["status"] == "ok"]
    slower = [r for r in solved if float(r["ratio"]) > 1.0 + 1e-6]  # type: ignore[arg-type]
    for r in rows:
        if r["status"] != "ok" or r in slower:
            print("!", r)
    ratio = np.array([float(r["ratio"]) for r in solved])  # type: ignore[arg-type]
    secs = np.array([float(r["seconds"]) for r in rows])  # type: ignore[arg-type]
    print(f"cells {len(rows)}: solved and certified {len(solved)}, slower than the reference {len(slower)}")
    for kind in ("free", "detour"):
        k = np.array([float(r["ratio"]) for r in solved if r["kind"] == kind])  # type: ignore[arg-type]
        if len(k):
            q = np.quantile(k, [0.0, 0.1, 0.5, 0.9, 1.0])
            print(f"  {kind:>6} ({len(k)}): ours / reference min {q[0]:.4f}, p10 {q[1]:.4f}, median {q[2]:.4f}, "
                  f"p90 {q[3]:.4f}, max {q[4]:.4f}")  # fmt: skip
    print(f"planning time [s]: median {np.median(secs):.2f}, p90 {np.quantile(secs, 0.9):.2f}, max {secs.max():.2f}")
    if args.markdown:
        print("\n| cells | solved, certified | slower than the reference | ours / reference: min | median | max |")
        print("|---:|---:|---:|---:|---:|---:|")
        print(f"| {len(rows)} | {len(solved)} | {len(slower)} | {ratio.min():.4f} | {np.median(ratio):.4f} | "
              f"{ratio.max():.4f} |")  # fmt: skip
    return 0 if len(solved) == len(rows) and not slower else 1


if __name__ == "__main__":
    raise SystemExit(main())
