"""Measured poses: joint readings and the tool position (and yaw) measured at each.

A measurement file is CSV read by the package's one reader (:mod:`scara_pin.tables`: a header, blank and
``#`` lines skipped, plain numbers only, the line named in every error): the columns ``q1 .. qN`` (the
robot's joint readings in URDF joint order, N = ``robot.dof``, [rad] or [m]), ``x, y, z`` (the measured
tool position [m], in the robot's base frame or in the measuring device's frame) and, optionally, ``yaw``
(the tool's measured yaw [rad], ``atan2(R[1, 0], R[0, 0])`` of its rotation). Other columns are ignored, but
a column ``q{N+1}`` (a joint reading the robot has no joint for: another robot's data) is refused.

Rows whose readings agree to ``DISTINCT_TOL`` are one pose measured again (:meth:`Measurements.poses`): they
repeat a measurement (averaging its noise) but identify nothing more.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

import numpy as np

from ..errors import InvalidInputError, ParameterError
from ..model import RobotModel

__all__ = ["DISTINCT_TOL", "Measurements", "measurement_columns"]

DISTINCT_TOL = 1e-6
"""[rad or m] rows whose readings, rounded to this grid, are equal are one pose (measured again)."""


def measurement_columns(dof: int) -> tuple[str, ...]:
    """The columns a measurement file must have for a robot with ``dof`` joints (``yaw`` is optional)."""
    return (*(f"q{i + 1}" for i in range(dof)), "x", "y", "z")


@dataclass(frozen=True, eq=False)
class Measurements:
    """Measured poses.

    Attributes:
        q: (n, dof) joint readings [rad, m], URDF joint order.
        position: (n, 3) measured tool positions [m].
        yaw: (n,) measured tool yaws [rad], or None when not measured.
        lines: per row, its line in the source file (1-based), or its row number (1-based) for arrays.
        source: where the rows come from (a file name), for messages.
    """

    q: np.ndarray
    position: np.ndarray
    yaw: np.ndarray | None = None
    lines: tuple[int, ...] = field(default=())
    source: str = "measurements"

    def __post_init__(self) -> None:
        q = np.array(self.q, dtype=float, ndmin=2)
        p = np.array(self.position, dtype=float, ndmin=2)
        if q.ndim != 2 or p.ndim != 2 or p.shape[1] != 3 or len(q) != len(p):
            raise ParameterError("measurements", f"q of shape {q.shape}, position of shape {p.shape}",
                                 "must be (n, dof) joint readings and (n, 3) positions")  # fmt: skip
        yaw = None if self.yaw is None else np.array(self.yaw, dtype=float).reshape(-1)
        if yaw is not None and len(yaw) != len(q):
            raise ParameterError("yaw", f"{len(yaw)} values", f"must be one per pose ({len(q)})")
        lines = tuple(self.lines) or tuple(range(1, len(q) + 1))
        if len(lines) != len(q):
            raise ParameterError("lines", f"{len(lines)} values", f"must be one per pose ({len(q)})")
        for k, row in enumerate(np.column_stack([q, p] + ([yaw] if yaw is not None else []))):
            if not np.isfinite(row).all():
                where = _where(self.source, lines[k])
                raise InvalidInputError(f"{self.source}, {where}: a value is not a finite number")
        for a in (q, p) + ((yaw,) if yaw is not None else ()):
            a.setflags(write=False)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "position", p)
        object.__setattr__(self, "yaw", yaw)
        object.__setattr__(self, "lines", lines)

    def __len__(self) -> int:
        return len(self.q)

    def values(self) -> np.ndarray:
        """(n, 3) positions, or (n, 4) with the yaw as the 4th column."""
        return self.position if self.yaw is None else np.column_stack([self.position, self.yaw])

    def subset(self, rows: np.ndarray) -> Measurements:
        """The measurements of the given rows (indices or a boolean mask)."""
        idx = np.arange(len(self))[rows]
        return Measurements(self.q[idx], self.position[idx], None if self.yaw is None else self.yaw[idx],
                            tuple(self.lines[i] for i in idx), self.source)  # fmt: skip

    def where(self, row: int) -> str:
        """How messages name row ``row`` (0-based): its line in the file, or its row number."""
        return _where(self.source, self.lines[row])

    def poses(self) -> tuple[np.ndarray, int]:
        """Per row, the index of its distinct pose (in order of first appearance), and how many there are.

        Two rows are the same pose when their readings, rounded to :data:`DISTINCT_TOL`, are equal.
        """
        grid = np.round(self.q / DISTINCT_TOL)
        _, first, inverse = np.unique(grid, axis=0, return_index=True, return_inverse=True)
        rank = np.empty(len(first), dtype=int)
        rank[np.argsort(first)] = np.arange(len(first))  # number the poses in the rows' order
        return rank[inverse.reshape(-1)], len(first)

    def check(self, robot: RobotModel) -> None:
        """Refuse readings the robot cannot take (the limits: :func:`~scara_pin.calibration.screen.screen`).

        Raises:
            InvalidInputError: not ``robot.dof`` readings per row, or a reading beyond +/-1e6 (naming the row).
        """
        if self.q.shape[1] != robot.dof:
            raise InvalidInputError(f"{self.source}: {self.q.shape[1]} joint readings per row; robot "
                                    f"{robot.name!r} has {robot.dof} joints")  # fmt: skip
        for k, q in enumerate(self.q):
            try:
                robot.check_q(q)
            except ParameterError as exc:
                raise InvalidInputError(f"{self.source}, {self.where(k)}: {exc}") from None

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], dof: int) -> Measurements:
        """Read a measurement file (see the module docstring) for a robot with ``dof`` joints.

        Raises:
            InvalidInputError: unreadable, a missing column, a cell that is not a plain number (naming the line
                and the column), no data row.
        """
        from ..limits import MAX_CALIBRATION_ROWS
        from ..tables import csv_rows, open_csv

        columns = measurement_columns(dof)
        lines, rows = [], []
        extra = f"q{dof + 1}"
        with open_csv(path) as handle:
            for line, values in csv_rows(handle, str(path), columns, max_rows=MAX_CALIBRATION_ROWS,
                                         optional=("yaw", extra)):  # fmt: skip
                if not math.isnan(values[-1]):
                    raise InvalidInputError(
                        f"{path}: column {extra}: the file has readings of more joints than the robot's {dof} "
                        f"({', '.join(columns[:dof])}): measurements of another robot? (give the robot they were "
                        "measured on)"
                    )
                lines.append(line)
                rows.append(values[:-1])
        if not rows:
            raise InvalidInputError(f"{path}: no data row after the header")
        table = np.array(rows, dtype=float)
        yaw = table[:, -1]
        has_yaw = not np.isnan(yaw).all()
        return cls(table[:, :dof], table[:, dof:dof + 3], yaw if has_yaw else None, tuple(lines), str(path))


def _where(source: str, line: int) -> str:
    return f"line {line}" if source != "measurements" else f"row {line}"

