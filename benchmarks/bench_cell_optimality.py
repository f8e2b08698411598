"""The cells of tests/test_cell_optimality.py solved again: the independent references and the planner's jumps.

For each cell: the reference minimum solved now by tests/cell_reference.py (IPOPT, the tests' own transcription,
from the cell's warm starts), the value recorded in the test (they must agree: the recording is this solve's), the
planner's jump and its ratio to the reference (within 2 %, not more than 0.1 % below). Seconds to minutes per cell
(the references). ``--markdown`` prints the table for docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from cell_reference import minimum_time  # noqa: E402
from test_cell_optimality import CELLS, REFERENCES, _cell  # noqa: E402

from scara_pin import load_robot  # noqa: E402
from scara_pin.motion.jump import jump_move  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cells", nargs="*", help="the cells' names (default: all)")
    ap.add_argument("--markdown", action="store_true")
    args = ap.parse_args()
    robot = load_robot("default")
    rows, bad = [], 0
    for name in args.cells or sorted(CELLS):
        A, B, posts, boxes, vias = CELLS[name]
        t0 = time.perf_counter()
        ours = jump_move(robot, A, B, cell=_cell(posts, boxes)).duration
        t1 = time.perf_counter()
        ref = minimum_time(robot, A, B, posts=posts, boxes=boxes, vias=tuple(vias))
        t2 = time.perf_counter()
        same = abs(ref - REFERENCES[name]) <= 1e-6 * REFERENCES[name]
        ok = same and ref * 0.999 <= ours <= ref * 1.02
        bad += not ok
        rows.append((name, ours, ref, REFERENCES[name], ours / ref, t1 - t0, t2 - t1, ok))
        print(f"{name:16s} ours {ours:.6f} s  reference {ref:.6f} s (recorded {REFERENCES[name]:.6f})  "
              f"ratio {ours / ref:.4f}  planning {t1 - t0:.1f} s, reference {t2 - t1:.1f} s  "
              f"{'ok' if ok else 'FAILED'}", flush=True)  # fmt: skip
    if args.markdown:
        print("\n| cell | ours [s] | independent minimum [s] | ours / minimum | planning [s] |")
        print("|---|---|---|---|---|")
        for name, ours, ref, _, ratio, t_ours, _, _ in rows:
            print(f"| {name} | {ours:.4f} | {ref:.4f} | {ratio:.4f} | {t_ours:.1f} |")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
