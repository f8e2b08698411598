"""Resource bounds: every size that an input sets is computed BEFORE the work and refused above a cap.

One place for the caps and the checks, used by the command line and the library alike:

- :func:`check_count` refuses a number of samples, setpoints, animation frames, grid points or rows above
  its cap (or not finite) with an :class:`~scara_pin.errors.InvalidInputError` (exit code 2), before any
  array of that size exists;
- :func:`open_regular` opens a file for reading only if it is a regular file: it opens with ``O_NONBLOCK``
  FIRST and checks the open file (``fstat``), so a FIFO swapped in after a check cannot block the open;
- :func:`read_bytes` and :func:`read_text` read a whole file (URDF, yaml, JSON, a mesh, a package's
  ``package.xml``, a xacro include) through :func:`open_regular`, with a byte cap: nothing larger is read;
- :func:`text_lines` streams a text file line by line, each line at most :data:`MAX_LINE_CHARS`
  characters, bad UTF-8 and NUL bytes refused with the line number;
- while a command runs (:func:`files_recorded`), every file :func:`open_regular` opens is recorded by its
  identity (device, inode: whatever the route to it, a symbolic link, a hard link, ``..``), and the command's
  outputs, once declared (:func:`declare_outputs`), are never read: a mesh, an include or a points file that is
  one of them is refused the moment it is opened (:class:`OutputIsInputError`), and the atomic writer
  (:mod:`scara_pin.files`) checks them against every file read before it replaces any.

The caps are module constants (documented in docs/cli.md, "Resource limits"); they are generous for a robot cell
and small enough that one command never needs more than a few GB of memory.
"""

from __future__ import annotations

import math
import os
import stat
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from .errors import InvalidInputError

__all__ = [
    "MAX_CALIBRATION_ROWS",
    "MAX_CELL_BYTES",
    "MAX_CELL_MESH_BYTES",
    "MAX_CELL_OBSTACLES",
    "MAX_CELL_TRIANGLES",
    "MAX_CHECK_ELEMENTS",
    "MAX_DOCUMENT_BYTES",
    "MAX_DWELL",
    "MAX_FRAMES",
    "MAX_JOB_BYTES",
    "MAX_JOB_DEPTH",
    "MAX_JOB_STEPS",
    "MAX_LINE_CHARS",
    "MAX_MESH_BYTES",
    "MAX_NUMBER",
    "MAX_PACKAGE_XML_BYTES",
    "MAX_PAGE_MESH_BYTES",
    "MAX_PAGE_MESH_READ",
    "MAX_PATH_POINTS",
    "MAX_PLAN_POSES",
    "MAX_PLAN_WORK",
    "MAX_ROWS",
    "MAX_SAMPLES",
    "MAX_SWEEP_VARIANTS",
    "MAX_URDF_ELEMENTS",
    "MAX_VISUALS",
    "MAX_WALK_DEPTH",
    "MAX_WALK_ENTRIES",
    "MAX_WORKSPACE_GRID",
    "MAX_XACRO_FILES",
    "MAX_XACRO_MEMORY",
    "MAX_XACRO_SECONDS",
    "MAX_YAML_DEPTH",
    "MAX_YAML_NODES",
    "OutputIsInputError",
    "UnreadableFileError",
    "check_count",
    "check_input_file",
    "check_not_read",
    "declare_outputs",
    "declared_option",
    "files_read",
    "files_recorded",
    "open_regular",
    "record_read",
    "read_bytes",
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
MAX_CALIBRATION_ROWS = 20_000
"""Lines of one calibration measurement file (each fit evaluates the model on every row, about 0.1 ms each)."""
MAX_PLAN_POSES = 1_000
"""Poses of one calibration experiment plan (``calibrate --plan N``)."""
MAX_PLAN_WORK = 4_000_000
"""Poses times candidate poses of one plan (each choice scores every candidate: about 1 s per million)."""
MAX_LINE_CHARS = 65_536
"""Characters of one line of a CSV input."""
MAX_DOCUMENT_BYTES = 64 * 1024 * 1024
"""Bytes of one document read whole: URDF, D-H table, trajectory JSON."""
MAX_URDF_ELEMENTS = 2_000
"""Links plus joints of one URDF (a SCARA has about 12). urdfdom and Pinocchio walk the tree recursively:
a chain about 5,000 links deep overflows the C stack (a crash, not an error), 3,000 does not."""
MAX_POINTS = 10_000
"""Taught points of one points file (``teach --points``, ``traj --points``): a cell has tens."""
MAX_POINTS_BYTES = 4 * 1024 * 1024
"""Bytes of one points file (10,000 points at full precision take about 1.5 MB)."""
MAX_JOB_BYTES = 2 * 1024 * 1024
"""Bytes of one job file (``scara-pin job``): a job is a page of steps; its pallets and loops make it long."""
MAX_JOB_DEPTH = 4
"""``for`` loops nested in one another in a job (a pallet's layers, rows and columns are one loop)."""
MAX_DWELL = 3_600
"""Seconds of one dwell, pick or place of a job (an hour at rest; with :data:`MAX_JOB_STEPS` a job's total stays
finite: ``dwell: 1e308`` twice made it infinite, and ``--json`` printed ``Infinity``)."""
MAX_JOB_STEPS = 10_000
"""Moves and dwells one job expands to, its loops unrolled (counted before any is built; each new jump is a
solve of about 0.1-0.5 s)."""
MAX_YAML_NODES = 500_000
"""Values (scalars, lists, mappings) of one yaml document, an alias counted at the size of all it stands for
(a points file of 10,000 points holds about 150,000; 520 bytes of nested aliases stand for 9^9)."""
MAX_YAML_DEPTH = 64
"""Levels of nesting of one yaml document (a points file has 4)."""
MAX_CHECK_ELEMENTS = 50_000
"""Links plus joints of one URDF that ``check`` lints (pure Python, linear; larger than what loads)."""

# ----------------------------------------------------------------------- cells (obstacles around the robot)
MAX_CELL_BYTES = 4 * 1024 * 1024
"""Bytes of one cell file (YAML, URDF or xacro; meshes are read under their own caps)."""
MAX_CELL_OBSTACLES = 500
"""Obstacles of one cell, placed boxes of a job included (every one is checked against every link at each of
the 10 kHz samples of a motion: 500 obstacles and 6 links take about 3 ms a sample)."""
MAX_CELL_TRIANGLES = 200_000
"""Mesh triangles of one cell, all its meshes together, a file counted once per shape naming it, from its header
or text BEFORE it is parsed (coal's bounding-volume tree keeps a distance query near a few microseconds up to
there)."""
MAX_CELL_MESH_BYTES = 256 * 1024 * 1024
"""Bytes of the mesh files of one cell, each file once, from their sizes before any is read, then as read
(decompressed); one file is at most :data:`MAX_MESH_BYTES`."""
MAX_WORKSPACE_GRID = 250_000
"""Grid points of one collision-free region (``workspace --cell --height``: 500 x 500; each reachable point
costs up to two IK solutions and their distance checks, about 10 s at the cap)."""

# ----------------------------------------------------------------------- sweeps (many jobs, docs/sweep.md)
MAX_SWEEP_VARIANTS = 1_000_000
"""Variants of one sweep (``scara-pin sweep``: the grid's product, or ``samples`` times the lists'), counted before
any is made: each is a job planned (0.3-60 s), so 10^6 is about a day on a thousand cores; a Parquet row each."""

# ----------------------------------------------------------------------- files named by packages and meshes
MAX_MESH_BYTES = 200 * 1024 * 1024
"""Bytes of one mesh file, counted AFTER decompression (a ``.dae`` that is a zip or gzip archive): a mesh
holding more is not read (a placeholder box is drawn)."""
MAX_PAGE_MESH_READ = 1024 * 1024 * 1024
"""Bytes of mesh files read (after decompression) to draw one robot; each file is read once, however many
visuals name it. The meshes beyond are drawn as placeholder boxes."""
MAX_PAGE_MESH_BYTES = 128 * 1024 * 1024
"""Bytes of triangles (float32 vertices, uint32 indices) embedded in one page, each mesh once however many
visuals name it (about 5 million triangles). The meshes beyond are drawn as placeholder boxes."""
MAX_VISUALS = 2_000
"""Visuals (``<visual>`` elements) of one robot drawn in a page (a SCARA has about 10)."""
MAX_PACKAGE_XML_BYTES = 1024 * 1024
"""Bytes of one ``package.xml`` read while looking for a package (a real one is a few KB)."""
MAX_WALK_DEPTH = 16
"""Folders below a package folder searched (``--package-path``, ``ROS_PACKAGE_PATH``) for packages."""
MAX_WALK_ENTRIES = 200_000
"""Folder entries listed by the search of one package folder (links to folders already seen are skipped)."""
MAX_XACRO_FILES = 1_000
"""Files (includes, yaml) read by the expansion of one xacro file; their bytes together are at most
:data:`MAX_DOCUMENT_BYTES`."""
MAX_XACRO_SECONDS = 10
"""Seconds (wall clock) of one xacro expansion, robot or cell: it runs in a child process, killed at the cap (a
macro calling itself twice 30 deep, ``${(9**9**9) % 7}``; a real description expands in well under a second)."""
MAX_XACRO_MEMORY = 1024 * 1024 * 1024
"""Bytes of memory one xacro expansion may take beyond what the process held (its child's address space is capped
there: an allocation beyond fails)."""


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


_NOT_REGULAR = "not a regular file (a device, FIFO, socket or folder)"


class UnreadableFileError(InvalidInputError):
    """A file that cannot be opened for reading, or is not a regular file (exit code 2).

    Attributes:
        path: the file.
        reason: why, e.g. ``"No such file or directory"``.
        errno: the system's error number (``errno.ENOENT``...), or None for a file that is not regular.
    """

    def __init__(self, what: str, path: Path, reason: str, errno: int | None = None) -> None:
        super().__init__(f"cannot read {what} {path}: {reason}")
        self.path = path
        self.reason = reason
        self.errno = errno


# ----------------------------------------------------------------------- what a command reads and writes
Identity = tuple[int, int]
"""A file's (device, inode): the same file whatever the name it is reached by."""


class OutputIsInputError(InvalidInputError):
    """An output of the command is a file the command reads (exit code 2): it would be replaced.

    Attributes:
        option: the output's option (``--out``), output: its name as given, read: the input's name as read.
    """

    def __init__(self, option: str, output: str, what: str, read: str) -> None:
        super().__init__(f"{option} {output} is the {what} {read} that this command reads: it would be replaced; "
                         "write the output elsewhere")  # fmt: skip
        self.option, self.output, self.what, self.read = option, output, what, read

    def __reduce__(self) -> tuple[type, tuple[str, str, str, str]]:
        return (type(self), (self.option, self.output, self.what, self.read))  # pickled from a child process


@dataclass
class _Record:
    """The files one command has read (identity -> (what, name)) and the outputs it declared (identity -> option)."""

    reads: dict[Identity, tuple[str, str]] = field(default_factory=dict)
    outputs: dict[Identity, tuple[str, str]] = field(default_factory=dict)
    declared: dict[str, str] = field(default_factory=dict)  # resolved name -> option


_RECORD: ContextVar[_Record | None] = ContextVar("scara_pin_files", default=None)


@contextmanager
def files_recorded() -> Iterator[None]:
    """While a command runs (the command line's ``main``): the files it reads are recorded (module docstring).

    Outside it (a library user's program) nothing is recorded and nothing is refused for it.
    """
    token = _RECORD.set(_Record())
    try:
        yield
    finally:
        _RECORD.reset(token)


def _identity(path: str | os.PathLike[str]) -> Identity | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (st.st_dev, st.st_ino)


def record_read(identity: Identity, name: str, what: str = "file") -> None:
    """Record that the command read the file ``identity`` (called by :func:`open_regular`; and for reads elsewhere).

    Raises:
        OutputIsInputError: the file is one of the command's declared outputs.
    """
    record = _RECORD.get()
    if record is None:
        return
    record.reads.setdefault(identity, (what, name))
    if identity in record.outputs:
        option, output = record.outputs[identity]
        raise OutputIsInputError(option, output, what, name)


def files_read() -> dict[Identity, tuple[str, str]]:
    """The files the running command has read so far: identity -> (what, name); empty outside a command."""
    record = _RECORD.get()
    return {} if record is None else dict(record.reads)


def check_not_read(option: str, path: str | os.PathLike[str]) -> None:
    """Refuse an output ``path`` that names a file the running command has read (any route to it).

    Raises:
        OutputIsInputError: it does.
    """
    record = _RECORD.get()
    key = None if record is None else _identity(path)
    if record is not None and key is not None and key in record.reads:
        what, name = record.reads[key]
        raise OutputIsInputError(option, str(path), what, name)


def declare_outputs(outputs: Mapping[str, str | os.PathLike[str] | None]) -> None:
    """The running command's outputs (option -> file; None or ``-``: none): a file among them is never read after.

    Raises:
        OutputIsInputError: one of them is a file the command has read already.
    """
    record = _RECORD.get()
    if record is None:
        return
    for option, path in outputs.items():
        if path is None or str(path) in ("", "-"):
            continue
        check_not_read(option, path)
        record.declared[str(Path(path).resolve())] = option
        key = _identity(path)
        if key is not None:
            record.outputs[key] = (option, str(path))


def declared_option(path: str | os.PathLike[str]) -> str | None:
    """The option under which the running command declared ``path`` as an output (:func:`declare_outputs`), or None."""
    record = _RECORD.get()
    return None if record is None else record.declared.get(str(Path(path).resolve()))


def open_regular(path: str | os.PathLike[str], what: str = "file") -> IO[bytes]:
    """Open ``path`` for reading (binary) if it is a regular file; never blocks on a FIFO.

    The file is checked (``stat``: a device is not even opened), opened with ``O_NONBLOCK`` and checked
    again (``fstat`` of the open file): a FIFO swapped in between returns at once from the open instead of
    blocking it, and is refused. The flag is cleared before the handle is returned (reads of a regular
    file never block anyway).

    While a command runs, the file is recorded as read (:func:`record_read`).

    Raises:
        UnreadableFileError: missing, unreadable, or not a regular file (a device such as ``/dev/zero``,
            a FIFO, a socket, a folder).
        OutputIsInputError: the file is one of the running command's outputs.
    """
    path = Path(path)
    try:  # a device is not even opened (opening some has effects: a tape rewinds)
        regular = stat.S_ISREG(os.stat(path).st_mode)
    except OSError as exc:
        raise UnreadableFileError(what, path, exc.strerror or str(exc), exc.errno) from None
    if not regular:
        raise UnreadableFileError(what, path, _NOT_REGULAR)
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        raise UnreadableFileError(what, path, exc.strerror or str(exc), exc.errno) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise UnreadableFileError(what, path, _NOT_REGULAR)
        record_read((st.st_dev, st.st_ino), str(path), what)
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def check_input_file(path: str | os.PathLike[str], what: str = "file", limit: int = MAX_DOCUMENT_BYTES) -> Path:
    """``path`` if it is a regular file of at most ``limit`` bytes (so that reading it whole is bounded).

    Raises:
        InvalidInputError: missing, not a regular file (a device such as ``/dev/zero``, a FIFO, a folder),
            or larger than ``limit``.
    """
    path = Path(path)
    with open_regular(path, what) as handle:
        size = os.fstat(handle.fileno()).st_size
    if size > limit:
        raise InvalidInputError(f"{what} {path} is {size:,} bytes, above the cap of {limit:,}; refused")
    return path


def read_bytes(path: str | os.PathLike[str], what: str = "file", limit: int = MAX_DOCUMENT_BYTES) -> bytes:
    """The bytes of a regular file (:func:`open_regular`) of at most ``limit`` bytes; larger files are refused.

    At most ``limit + 1`` bytes are read, whatever the file's size says (it may grow meanwhile); the buffer is the
    file's size, not the cap's.

    Raises:
        InvalidInputError: missing, unreadable, not a regular file, or over ``limit`` bytes.
    """
    with open_regular(path, what) as handle:
        try:
            size = os.fstat(handle.fileno()).st_size
            if size > limit:
                raise InvalidInputError(f"{what} {path} is {size:,} bytes, above the cap of {limit:,}; refused")
            data = handle.read(size + 1)  # what the file says it holds: no buffer of the cap's size
            if len(data) > size:  # it grew meanwhile: the rest, up to the cap
                data += handle.read(limit + 1 - len(data))
        except OSError as exc:
            raise InvalidInputError(f"cannot read {what} {path}: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise InvalidInputError(f"{what} {path} is larger than {limit:,} bytes; refused")
    return data


def read_text(path: str | os.PathLike[str], what: str = "file", limit: int = MAX_DOCUMENT_BYTES) -> str:
    """The UTF-8 text of a regular file of at most ``limit`` bytes (:func:`read_bytes`).

    Raises:
        InvalidInputError: missing, unreadable, not a regular file, over ``limit`` bytes, or not UTF-8.
    """
    data = read_bytes(path, what, limit)
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
