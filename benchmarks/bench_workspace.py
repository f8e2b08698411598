#!/usr/bin/env python
"""Benchmark: exact workspace ray queries per second, and the exact area against Monte Carlo.

Run with the project's interpreter (``.venv/bin/python benchmarks/bench_workspace.py``):

- ray queries: ``Workspace.ray_batch`` on N = 100 000 seeded rays (starts from uniform joint samples within
  the limits, uniform directions), single-threaded (BLAS/OpenMP pools pinned to 1 thread before numpy is
  imported; the ray code is elementwise numpy anyway). The rate is N over the median of the rounds' wall
  times. The scalar ``Workspace.ray`` is timed on 2000 rays for comparison. Target: >= 100 000 rays/s
  (batch), reported, not enforced.
- area: the exact area (Green's theorem over the boundary arcs) against a Monte Carlo estimate with
  ``contains`` on 10^6 uniform points of the reach box, with its standard error and the z-score.

Before timing, every limit set's batch answers on 300 rays are checked against an independent march +
bisection along each ray with ``contains`` (exact set, tol = 0): on a disagreement above 1e-9 m it says so
and exits 1 without timing.

Options: ``--quick`` (fewer rounds and samples), ``--json`` (one JSON object instead of the table).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402

import numpy as np  # noqa: E402

from scara_pin import load_robot  # noqa: E402
from scara_pin.kinematics.scara import ScaraGeometry  # noqa: E402
from scara_pin.workspace.scara import Workspace, workspace  # noqa: E402

TARGET = 100_000  # rays per second, batch API
N_RAYS = 100_000
TOL = 1e-9
SEED = 0


def limit_sets() -> dict[str, ScaraGeometry]:
    """The shipped robots, and the S5 robot (l1 = 0.325, l2 = 0.275) under several limit sets."""
    out = {name: load_robot(name).kinematics.geometry for name in ("default", "s1")}
    base = out["default"]
    d = math.radians

    def s5(j1: tuple[float, float], j2: tuple[float, float]) -> ScaraGeometry:
        return replace(base, u1=(0.325, 0.0), u2=(0.275, 0.0), lower=(d(j1[0]), d(j2[0]), *base.lower[2:]),
                       upper=(d(j1[1]), d(j2[1]), *base.upper[2:]))  # fmt: skip

    out["S5 +/-132, +/-88"] = s5((-132, 132), (-88, 88))
    out["J1 full turn"] = s5((-200, 200), (-150, 150))
    out["J2 without 0"] = s5((-100, 60), (30, 140))
    out["J2 beyond pi"] = s5((-120, 120), (-200, 200))
    return out


def random_rays(geo: ScaraGeometry, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    ra, rb = geo.revolute[0], geo.revolute[1]
    q1 = rng.uniform(geo.lower[ra], geo.upper[ra], n)
    q2 = rng.uniform(geo.lower[rb], geo.upper[rb], n)
    t = geo.signs[ra] * q1 + geo.beta1
    g = t + geo.elbow_angle(q2)
    S = np.column_stack((geo.a1[0] + geo.l1 * np.cos(t) + geo.l2 * np.cos(g),
                         geo.a1[1] + geo.l1 * np.sin(t) + geo.l2 * np.sin(g)))  # fmt: skip
    a = rng.uniform(-math.pi, math.pi, n)
    return S, np.column_stack((np.cos(a), np.sin(a)))


def bisection(ws: Workspace, S: np.ndarray, D: np.ndarray, step: float = 1e-4) -> np.ndarray:
    """First exit along each ray from ``contains`` alone: march by ``step``, then bisect."""
    g = ws.geometry
    u = np.arange(0.0, 2.5 * (g.l1 + g.l2), step)
    lo = np.empty(len(S))
    for i in range(len(S)):
        ok = ws.contains(S[i] + u[:, None] * D[i], tol=0.0)
        lo[i] = u[max(int(np.argmin(ok)) - 1, 0)]
    hi = lo + step
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        ok = ws.contains(S + mid[:, None] * D, tol=0.0)
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    return 0.5 * (lo + hi)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer rounds and Monte Carlo samples")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    args = parser.parse_args(argv)
    rounds, n_mc = (3, 200_000) if args.quick else (9, 1_000_000)
    rows = []
    for name, geo in limit_sets().items():
        ws = workspace(geo)
        rng = np.random.default_rng(SEED)
        S, D = random_rays(geo, 300, rng)
        err = float(np.abs(ws.ray_batch(S, D).distance - bisection(ws, S, D)).max())
        if err > TOL:
            print(f"MISMATCH {name}: ray distances differ from bisection by {err:.3g} m (> {TOL:g})")
            return 1
        S, D = random_rays(geo, N_RAYS, rng)
        ws.ray_batch(S, D)  # warm-up
        times = []
        for _ in range(rounds):
            t0 = time.perf_counter()
            ws.ray_batch(S, D)
            times.append(time.perf_counter() - t0)
        batch_rate = N_RAYS / statistics.median(times)
        t0 = time.perf_counter()
        for i in range(2000):
            ws.ray(S[i], D[i])
        scalar_rate = 2000 / (time.perf_counter() - t0)
        R = geo.l1 + geo.l2
        box = (2 * R) ** 2
        P = np.array(geo.a1) - R + rng.uniform(0.0, 2 * R, (n_mc, 2))
        f = float(ws.contains(P).mean())
        mc = f * box
        sigma = box * math.sqrt(f * (1 - f) / n_mc)
        rows.append({
            "limits": name, "arcs": len(ws.arcs), "loops": len(ws.loops), "batch_rays_per_s": batch_rate,
            "scalar_rays_per_s": scalar_rate, "max_ray_error_m": err, "area_exact_m2": ws.area,
            "area_mc_m2": mc, "area_mc_sigma_m2": sigma, "z_score": (mc - ws.area) / sigma,
        })  # fmt: skip
    if args.json:
        print(json.dumps({"target_rays_per_s": TARGET, "n_rays": N_RAYS, "n_mc": n_mc, "rows": rows}, indent=1))
        return 0
    print(f"Workspace benchmark: {platform.python_implementation()} {platform.python_version()}, numpy "
          f"{np.__version__}, {platform.machine()}; {N_RAYS} rays per batch, median of {rounds} rounds, "
          f"Monte Carlo on {n_mc} points\n")  # fmt: skip
    print("| limits | arcs | loops | batch rays/s | scalar rays/s | ray vs bisection [m] | exact area [m^2] "
          "| MC area [m^2] | MC sigma [m^2] | z |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['limits']} | {r['arcs']} | {r['loops']} | {r['batch_rays_per_s']:,.0f} | "
              f"{r['scalar_rays_per_s']:,.0f} | {r['max_ray_error_m']:.1e} | {r['area_exact_m2']:.6f} | "
              f"{r['area_mc_m2']:.6f} | {r['area_mc_sigma_m2']:.1e} | {r['z_score']:+.2f} |")  # fmt: skip
    worst = min(r["batch_rays_per_s"] for r in rows)
    print(f"\ntarget >= {TARGET:,} rays/s (batch): {'met' if worst >= TARGET else 'MISSED'} "
          f"(slowest {worst:,.0f} rays/s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
