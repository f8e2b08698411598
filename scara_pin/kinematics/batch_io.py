"""Batch IK between files: a CSV of tool poses in, a CSV of joint values out, streamed in bounded memory.

Input: a header naming ``x, y, z, yaw`` (other columns ignored), one target per row, in the file's units
(``pose_scale`` converts SI to them). Output, written atomically (:mod:`scara_pin.files`):
``x, y, z, yaw, q1, q2, q3, q4, branch, status``, one row per target in input order, the joint cells
empty and ``branch`` blank where there is no solution. Rows are solved in chunks by the vectorised
closed form (:meth:`scara_pin.model.RobotModel.ik_batch`), so memory stays bounded whatever the file's size.
"""

from __future__ import annotations

import csv
import math
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidInputError
from ..files import check_outputs, write_atomic_with
from ..limits import MAX_ROWS
from ..tables import csv_rows, open_csv

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = ["CHUNK", "INPUT_COLUMNS", "OUTPUT_COLUMNS", "BatchSummary", "solve_csv"]

INPUT_COLUMNS = ("x", "y", "z", "yaw")
OUTPUT_COLUMNS = ("x", "y", "z", "yaw", "q1", "q2", "q3", "q4", "branch", "status")
CHUNK = 65536
"""Targets solved per call of the vectorised IK (and held in memory at once)."""


@dataclass(frozen=True)
class BatchSummary:
    """What :func:`solve_csv` did.

    Attributes:
        output: the file written.
        total: targets read.
        failed: targets without a solution (their status says why).
    """

    output: Path
    total: int
    failed: int

    @property
    def solved(self) -> int:
        """Targets with a solution."""
        return self.total - self.failed


def solve_csv(
    robot: RobotModel,
    source: str | os.PathLike[str],
    destination: str | os.PathLike[str],
    *,
    pose_scale: Sequence[float] = (1.0, 1.0, 1.0, 1.0),
    q_scale: Sequence[float] = (1.0, 1.0, 1.0, 1.0),
    branch: str | None = None,
    reference: ArrayLike | None = None,
    progress: bool = False,
) -> BatchSummary:
    """Solve every target of the CSV ``source`` and write the joints to ``destination`` (atomically).

    Args:
        robot: the robot.
        source: the targets' CSV file (see the module docstring).
        destination: the output CSV file; left untouched if the input turns out malformed.
        pose_scale: multipliers from SI to the file's units of x, y, z, yaw (1000 for mm, 180 / pi for deg).
        q_scale: multipliers from SI to the output units of q1..q4.
        branch: one of the robot's branches (``robot.kinematics.branches``), or None: the solution nearest
            ``reference``.
        reference: [rad, m] the joint values the nearest solution is measured from (default q = 0).
        progress: show a progress bar (tqdm, on standard error) when standard error is a terminal.

    Raises:
        InvalidInputError: unreadable or malformed input (the line is named), a bad output path or branch.
    """
    kin = robot.kinematics
    if branch is not None and branch not in kin.branches:
        raise InvalidInputError(f"branch {branch!r} is not a branch of a {robot.kind} ({', '.join(kin.branches)})")
    pose_unit = np.array(pose_scale, dtype=float)
    q_unit = np.array(q_scale, dtype=float)
    if pose_unit.shape != (4,) or q_unit.shape != (4,) or not (np.isfinite(pose_unit).all() and (pose_unit > 0).all()
                                                                 and np.isfinite(q_unit).all() and (q_unit > 0).all()):
        raise InvalidInputError("pose_scale and q_scale must be 4 finite numbers > 0 each")  # fmt: skip
    check_outputs({"destination": destination}, {"source": source})  # never the source itself (links resolved)
    out_path = Path(destination)
    src = Path(source)
    names = {int(c): c.name for c in kin.status}
    labels = {1: kin.branches[0], -1: kin.branches[1], 0: ""}
    counts = [0, 0]  # total, failed

    def flush(writer: Any, chunk: list[list[float]]) -> None:
        if not chunk:
            return
        T = np.array(chunk) / pose_unit
        res = robot.ik_batch(T, reference, branch="nearest" if branch is None else branch)
        for t, q, b, st in zip(T * pose_unit, res.q * q_unit, res.branch, res.status):
            writer.writerow([*(repr(float(v)) for v in t), *("" if math.isnan(v) else repr(float(v)) for v in q),
                             labels[int(b)], names[int(st)]])  # fmt: skip
        counts[0] += len(chunk)
        counts[1] += int((res.status != 0).sum())

    def write(f: IO[str], handle: IO[bytes], bar: Any) -> None:
        writer = csv.writer(f)
        rows = csv_rows(handle, str(src), INPUT_COLUMNS, max_rows=MAX_ROWS, progress=bar.update)
        chunk: list[list[float]] = []
        for k, (_, values) in enumerate(rows):
            if k == 0:
                writer.writerow(OUTPUT_COLUMNS)
            chunk.append(values)
            if len(chunk) == CHUNK:
                flush(writer, chunk)
                chunk = []
        if counts[0] == 0 and not chunk:
            writer.writerow(OUTPUT_COLUMNS)  # a header and no row: an empty result, still a valid CSV
        flush(writer, chunk)

    with open_csv(src) as handle:
        size = src.stat().st_size if src.is_file() else None
        from tqdm import tqdm

        with tqdm(total=size, unit="B", unit_scale=True, desc=f"ik {src.name}", file=sys.stderr,
                  disable=not (progress and sys.stderr.isatty()), leave=False) as bar:  # fmt: skip
            write_atomic_with(out_path, lambda f: write(f, handle, bar))
    return BatchSummary(out_path, counts[0], counts[1])
