"""Resource bounds: every size that an input sets is computed BEFORE the work and refused above a cap.

One place for the caps and the checks, used by the command line and the library alike:

- :func:`check_count` refuses a number of samples, setpoints, animation frames, grid points or rows above
  its cap (or not finite) with an :class:`~scara_pin.errors.InvalidInputError` (exit code 2), before any
  array of that size exists;
- :func:`read_text` reads a whole document (URDF, yaml, JSON) with a byte cap: ``/dev/zero`` is refused
  after :data:`MAX_DOCUMENT_BYTES` bytes, never read to the end;
- :func:`text_lines` streams a text file line by line, each line at most :data:`MAX_LINE_CHARS`
  characters, bad UTF-8 and NUL bytes refused with the line number.

The caps are module constants (documented in docs/cli.md, "Resource limits"); they are generous for a robot cell
and small enough that one command never needs more than a few GB of memory.
"""

from __future__ import annotations

import math
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from .errors import InvalidInputError

__all__ = [
    "MAX_DOCUMENT_BYTES",
    "MAX_CHECK_ELEMENTS",
    "MAX_FRAMES",
    "MAX_LINE_CHARS",
    "MAX_NUMBER",
    "MAX_PATH_POINTS",
    "MAX_ROWS",
    "MAX_SAMPLES",
    "MAX_URDF_ELEMENTS",
    "check_count",
    "check_input_file",
    "read_text",
    "text_lines",
]

MAX_NUMBER = 1e12
"""Largest magnitude of a number typed on the command line or read from a batch file (in its units)."""
MAX_SAMPLES = 2_000_000
"""Samples of one trajectory (``--out``, ``--json``, the limit checks at 1 kHz) or setpoints of one file."""
MAX_PATH_POINTS = 1_000_000
"""IK points of one straight tool-line segment (``traj --linear``, ``jog``)."""
MAX_FRAMES = 200_000
"""Animation frames of one ``view`` page or live animation."""
MAX_ROWS = 20_000_000
"""Data rows of one batch file (``ik --input``)."""
MAX_LINE_CHARS = 65_536
"""Characters of one line of a CSV input."""
MAX_DOCUMENT_BYTES = 64 * 1024 * 1024
"""Bytes of one document read whole: URDF, D-H table, trajectory JSON."""
MAX_URDF_ELEMENTS = 2_000
"""Links plus joints of one URDF (a SCARA has about 12). urdfdom and Pinocchio walk the tree recursively:
a chain about 5,000 links deep overflows the C stack (a crash, not an error), 3,000 does not."""
MAX_CHECK_ELEMENTS = 50_000
"""Links plus joints of one URDF that ``check`` lints (pure Python, linear; larger than what loads)."""


def check_count(what: str, n: float, cap: int, hint: str = "") -> int:
    """``n`` as an int if ``0 <= n <= cap``, else an :class:`InvalidInputError` naming ``what`` and the cap.

    Args:
        what: what is counted, e.g. ``"samples (duration 12 s x rate 1000 Hz)"``.
        n: the count, computed from the inputs before the work (a float is fine: inf and NaN are refused).
        cap: the largest count allowed.
        hint: how to stay under the cap (e.g. ``"lower --rate"``).
    """
    if not (isinstance(n, int) or math.isfinite(n)) or n > cap:
        shown = f"{n:.3g}" if isinstance(n, float) else f"{n}"
        raise InvalidInputError(f"{what} would be {shown}, above the cap of {cap:,}{'; ' + hint if hint else ''}")
    if n < 0:
        raise InvalidInputError(f"{what} would be {n}, below 0")
    return int(n)


def _open(path: str | os.PathLike[str], what: str) -> IO[bytes]:
    path = Path(path)
    try:
        if path.is_dir():
            raise InvalidInputError(f"cannot read {what} {path}: it is a folder")
        return path.open("rb")
    except OSError as exc:
        raise InvalidInputError(f"cannot read {what} {path}: {exc.strerror or exc}") from None


def check_input_file(path: str | os.PathLike[str], what: str = "file", limit: int = MAX_DOCUMENT_BYTES) -> Path:
    """``path`` if it is a regular file of at most ``limit`` bytes (so that reading it whole is bounded).

    Raises:
        InvalidInputError: missing, not a regular file (a device such as ``/dev/zero``, a FIFO, a folder),
            or larger than ``limit``.
    """
    path = Path(path)
    try:
        st = os.stat(path)
    except OSError as exc:
        raise InvalidInputError(f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(st.st_mode):
        raise InvalidInputError(f"cannot read {what} {path}: not a regular file (a device, FIFO or folder)")
    if st.st_size > limit:
        raise InvalidInputError(f"{what} {path} is {st.st_size:,} bytes, above the cap of {limit:,}; refused")
    return path


def read_text(path: str | os.PathLike[str], what: str = "file", limit: int = MAX_DOCUMENT_BYTES) -> str:
    """The UTF-8 text of a file of at most ``limit`` bytes; larger (or endless) files are refused.

    Raises:
        InvalidInputError: missing, unreadable, a folder, over ``limit`` bytes, or not UTF-8.
    """
    with _open(path, what) as handle:
        try:
            data = handle.read(limit + 1)
        except OSError as exc:
            raise InvalidInputError(f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise InvalidInputError(f"{what} {path} is larger than {limit:,} bytes; refused")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise InvalidInputError(f"{what} {path}: not UTF-8 text (line {line}, byte {exc.start})") from None


def text_lines(handle: IO[bytes], origin: str, max_rows: int = MAX_ROWS) -> Iterator[tuple[int, str]]:
    """Stream ``(line number, text)`` from a binary handle: UTF-8, bounded line length and line count.

    The line ending is removed. Reads at most :data:`MAX_LINE_CHARS` + 1 bytes per step, so an endless
    input without newlines (``/dev/zero``) is refused after one line's worth.

    Raises:
        InvalidInputError: a line over :data:`MAX_LINE_CHARS`, bad UTF-8, a NUL byte, or too many lines.
    """
    number = 0
    while True:
        try:
            raw = handle.readline(MAX_LINE_CHARS + 2)
        except OSError as exc:
            raise InvalidInputError(f"cannot read {origin}: {exc.strerror or exc}") from None
        if not raw:
            return
        number += 1
        if number > max_rows + 1:  # the header and max_rows rows
            raise InvalidInputError(f"{origin} has more than {max_rows:,} rows, the cap; split it")
        body = raw.rstrip(b"\r\n")
        if len(body) > MAX_LINE_CHARS:
            raise InvalidInputError(f"{origin} line {number} is longer than {MAX_LINE_CHARS:,} characters; refused")
        if b"\0" in body:
            raise InvalidInputError(f"{origin} line {number}: a NUL byte (a binary file, not CSV text)")
        if number == 1 and body.startswith(b"\xef\xbb\xbf"):  # a UTF-8 byte order mark (a CSV saved by Excel)
            body = body[3:]
        try:
            text = body.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise InvalidInputError(f"{origin} line {number}: not UTF-8 text (byte {exc.start + 1})") from None
        yield number, text
