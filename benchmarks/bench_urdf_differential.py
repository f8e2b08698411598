#!/usr/bin/env python
"""Benchmark-style run of the differential test (issue 39): the loader and ``check`` against Pinocchio's parsers.

Run with the project's interpreter from the repository (``.venv/bin/python benchmarks/bench_urdf_differential.py``):
the corpus of tests/test_urdf_differential.py (every URDF and xacro file of tests/data, the shipped robots'
URDF), its systematic mutants (each kind of attribute emptied, then removed) and as many random single-change
mutants as asked (tests/urdf_mutants.py: the same mutations and the same judge,
Pinocchio's ``buildModelFromXML`` and ``buildGeomFromUrdfString``). It prints how many mutants Pinocchio and the
toolkit each load and refuse, the rules that refused them, the mutants per second, and every disagreement
(exit 1 when there is one): a crash, a refusal of what Pinocchio refuses that does not name the element, a
refusal of what Pinocchio loads by a rule whose reason does not hold. ``--check-every K`` lints every K-th
mutant with ``check`` too, which must agree with the loader (loadable: exit 0 or 4; refused: 2).

Options: ``--mutants N`` (default 20 000), ``--seed S`` (default 1), ``--check-every K`` (default 20),
``--json``.
"""

from __future__ import annotations

import argparse
import collections
import itertools
import json
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

import urdf_mutants as um  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--mutants", type=int, default=20_000)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--check-every", type=int, default=20)
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    mesh = Path(tempfile.mkdtemp()) / "m.stl"
    mesh.write_text(um.MESH_STL)
    corpus = um.corpus()
    rules: collections.Counter[str] = collections.Counter()
    wrong: list[str] = []
    loaded = checked = 0
    devnull = os.open(os.devnull, os.O_WRONLY)
    saved = os.dup(2)
    k = -1
    start = time.perf_counter()
    os.dup2(devnull, 2)  # urdfdom's own lines on the C-level stderr (a benchmark process: nothing else writes there)
    try:
        made = itertools.chain(um.systematic(corpus), um.mutants(corpus, args.mutants, args.seed))
        for k, m in enumerate(made):
            toolkit, problem = um.verdict(m, mesh)
            loaded += toolkit.loads
            if not toolkit.loads:
                rules[toolkit.rule or "crash"] += 1
            if problem is not None:
                wrong.append(f"{m.source}: {m.change}: {problem}")
            if args.check_every and k % args.check_every == 0:
                checked += 1
                disagreement = um.check_disagrees(m)
                if disagreement is not None:
                    wrong.append(f"{m.source}: {m.change}: {disagreement}")
    finally:
        os.dup2(saved, 2)
    seconds = time.perf_counter() - start
    total = k + 1
    summary = {"files": len(corpus), "mutants": total, "seed": args.seed, "loaded": loaded,
               "refused": total - loaded, "rules": dict(rules.most_common()), "checked": checked,
               "disagreements": wrong, "seconds": seconds, "per_second": total / seconds}  # fmt: skip
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"corpus      {len(corpus)} files (tests/data URDF and xacro, the shipped robots)")
        print(f"mutants     {total:,} ({total - args.mutants} systematic, {args.mutants:,} random, seed {args.seed}): "
              f"{loaded:,} loaded, {total - loaded:,} refused; "
              f"{checked:,} also through check")
        print("refused by  " + ", ".join(f"{r} {n}" for r, n in rules.most_common()))
        print(f"time        {seconds:.1f} s, {total / seconds:.0f} mutants/s")
        print(f"verdict     {len(wrong)} disagreement(s) with Pinocchio")
        for line in wrong[:50]:
            print(f"  {line}")
    return 1 if wrong else 0


if __name__ == "__main__":
    sys.exit(main())
