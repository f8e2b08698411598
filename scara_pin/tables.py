"""The one reader of the CSV files the package reads, in bounded memory.

Trajectories (``view --traj``, :func:`~scara_pin.motion.trajectory.load_trajectory`) and batch IK targets
(``ik --input``) are read here.

Built on :func:`scara_pin.limits.text_lines` (bounded line length and count, UTF-8, no NUL) and the
standard :mod:`csv` module (quoting). The rules, the same for every file:

- blank lines and lines starting with ``#`` are skipped;
- the first other line is the header; the wanted columns are found by name (case and surrounding blanks
  ignored), other columns are ignored; with ``exact=True`` the header must be exactly the wanted names; a
  name may carry its unit in brackets (``q1 [rad]``, as a job's trajectory writes it): with ``units``, it
  must be one of those the column takes (a file in other units is refused, never read as SI);
- every data row has as many cells as the header, and the wanted cells are plain numbers
  (no ``nan``, ``inf``, ``1_000``) of magnitude at most
  :data:`scara_pin.limits.MAX_NUMBER`.

Errors are :class:`~scara_pin.errors.InvalidInputError` (exit code 2) naming the file and the line.
"""

from __future__ import annotations

import csv
import math
import os
import re
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import IO

import numpy as np

from ._checks import NUMBER_TEXT
from .errors import InvalidInputError
from .limits import MAX_NUMBER, MAX_ROWS, UnreadableFileError, open_regular, text_lines

__all__ = ["csv_rows", "open_csv", "read_csv"]

_UNIT = re.compile(r"^(.*?)\s*\[([^\[\]]*)\]\s*$")
"""A column name with its unit in brackets: ``q1 [rad]``."""


@contextmanager
def open_csv(path: str | os.PathLike[str]) -> Iterator[IO[bytes]]:
    """Open a CSV file for :func:`csv_rows` (binary), or an :class:`InvalidInputError` saying why not."""
    path = Path(path)
    if path.is_dir():
        raise InvalidInputError(f"{path}: cannot be read (it is a folder)")
    if path.exists() and not path.is_file():  # a FIFO would block the open until a writer comes; a device
        raise InvalidInputError(f"{path}: cannot be read (not a regular file: a FIFO, a socket or a device)")
    try:  # O_NONBLOCK, then fstat: a FIFO swapped in after the checks above is refused, never waited for
        handle = open_regular(path, "CSV file")
    except UnreadableFileError as exc:
        raise InvalidInputError(f"{path}: cannot be read ({exc.reason})") from None
    with handle:
        yield handle


def csv_rows(
    handle: IO[bytes],
    origin: str,
    columns: Sequence[str],
    *,
    exact: bool = False,
    max_rows: int = MAX_ROWS,
    progress: Callable[[int], object] | None = None,
    optional: Sequence[str] = (),
    units: Mapping[str, Collection[str]] | None = None,
) -> Iterator[tuple[int, list[float]]]:
    """Stream ``(line number, values of the wanted columns)`` from a CSV file, in bounded memory.

    The header is checked when the first row is asked for (an empty file or a bad header raises then).

    Args:
        handle: the file, opened in binary mode (see :func:`open_csv`).
        origin: the file's name in messages.
        columns: the wanted column names, in the order their values are returned.
        exact: the header must be exactly ``columns`` (in order, nothing else).
        max_rows: the most lines read (a cap, refused above).
        progress: called with the bytes of each line read (for a progress bar).
        optional: column names read when the header has them, their values after the wanted ones; NaN for
            a column the header lacks (a cell is never NaN: ``nan`` is refused).
        units: for a wanted column, the units its name may carry in brackets (``{"t": ("s",)}``); None: any.

    Raises:
        InvalidInputError: unreadable text (see :func:`~scara_pin.limits.text_lines`), not CSV, a header
            without a wanted column, a row of another length than the header, a cell that is not a number.
    """
    wanted = [c.strip().lower() for c in columns]
    line = 0

    def texts() -> Iterator[str]:
        nonlocal line
        for number, text in text_lines(handle, origin, max_rows):
            line = number
            if progress is not None:
                progress(len(text) + 1)
            if text.strip() and not text.lstrip().startswith("#"):
                yield text

    reader = csv.reader(texts())
    try:
        header = next(reader, None)
        if header is None:
            raise InvalidInputError(f"{origin}: empty file; the first line must be the header {','.join(columns)}")
        names: list[str] = []
        marked: list[str | None] = []
        for h in header:
            m = _UNIT.match(h.strip())
            names.append((m.group(1) if m else h).strip().lower())
            marked.append(m.group(2).strip() if m else None)
        if exact and names != wanted:
            raise InvalidInputError(f"{origin}: the first line must be the header {','.join(columns)}")
        missing = [c for c in wanted if c not in names]
        if missing:
            raise InvalidInputError(f"{origin}: the header has no column {', '.join(missing)}; it must name "
                                    f"{','.join(columns)} (header: {','.join(header)[:200]})")  # fmt: skip
        index = [names.index(c) for c in wanted]
        for c, i in zip(columns, index):
            allowed, unit = None if units is None else units.get(c), marked[i]
            if allowed is not None and unit is not None and unit not in allowed:
                raise InvalidInputError(f"{origin}: column {header[i].strip()[:60]} is in {unit[:20]}; it must be "
                                        f"in {' or '.join(allowed)} (SI)")  # fmt: skip
        extra = [names.index(c) if c in names else -1 for c in (o.strip().lower() for o in optional)]
        for row in reader:
            if len(row) != len(header):
                raise InvalidInputError(f"{origin}, line {line}: {len(row)} values, expected {len(header)} "
                                        f"({','.join(header)[:200]})")  # fmt: skip
            values = [_cell(origin, line, header[i], row[i]) for i in index]
            yield line, values + [_cell(origin, line, header[i], row[i]) if i >= 0 else math.nan for i in extra]
    except csv.Error as exc:
        raise InvalidInputError(f"{origin}, line {line}: not CSV ({exc})") from None


def read_csv(
    path: str | os.PathLike[str],
    columns: Sequence[str],
    *,
    exact: bool = False,
    max_rows: int = MAX_ROWS,
    optional: Sequence[str] = (),
    units: Mapping[str, Collection[str]] | None = None,
) -> np.ndarray:
    """The wanted columns of a CSV file as an (n, len(columns)) float array, n >= 1 (see :func:`csv_rows`).

    With ``optional`` columns: (n, len(columns) + len(optional)), NaN in an optional column the file lacks.

    Raises:
        InvalidInputError: as :func:`csv_rows`, and a file with no data row.
    """
    with open_csv(path) as handle:
        rows = [values for _, values in csv_rows(handle, str(path), columns, exact=exact, max_rows=max_rows,
                                                 optional=optional, units=units)]  # fmt: skip
    if not rows:
        raise InvalidInputError(f"{path}: no data row after the header")
    return np.array(rows, dtype=float)


def _cell(origin: str, line: int, name: str, text: str) -> float:
    stripped = text.strip(" \t")
    if not NUMBER_TEXT.fullmatch(stripped):
        shown = stripped if len(stripped) <= 40 else stripped[:40] + "..."
        raise InvalidInputError(f"{origin}, line {line}: {name.strip()} = {shown!r} is not a plain number "
                                "(such as 0.25, -3, 1.5e-3)")  # fmt: skip
    value = float(stripped)
    if not abs(value) <= MAX_NUMBER:
        raise InvalidInputError(f"{origin}, line {line}: {name.strip()} = {stripped} is beyond +/-{MAX_NUMBER:g}")
    return value
