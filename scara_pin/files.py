"""Output files written atomically: a temporary file in the same folder, flushed to disk, then a rename.

An error, Ctrl-C or SIGTERM (the command line turns it into the same clean-up) leaves the old file or
none, never a half-written one; so does a Ctrl-C or SIGTERM that a library swallowed while the output was
being made (:func:`scara_pin.signals.raise_pending` is called before the rename). Used by every command
that writes a file (URDF, trajectories, setpoints, plots, HTML pages, batch IK results).

Rules:

- only regular files are written, or standard output for the name ``-``; an existing character device
  (``/dev/null``), block device, FIFO, socket or folder is refused with an
  :class:`~scara_pin.errors.InvalidInputError` (exit code 2), never replaced;
- a symbolic link is replaced by the new file (its target is never written through);
- the temporary file is created with mode ``0o666`` (or the ``mode`` asked) filtered by the process umask, as
  ``open()`` would;
  the umask is never read or changed (no process-wide state is touched, so threads may write at once);
- the data is ``fsync``-ed before the rename, and the folder after it (where the system allows).

Before any work, a command checks all its outputs together with :func:`check_outputs`: each name as above
(and a plot's ending), at most one of them on standard output, and no output the same file as one of the
command's inputs or as another output (after resolving links: a measurements file named as ``--out`` would
be replaced by the URDF; ``--out X --overlay X`` would keep one of two outputs). The outputs are then declared
(:func:`scara_pin.limits.declare_outputs`): a file the command reads later (a mesh of its cell, a xacro
include) that is one of them is refused when it is opened, and just before the rename each declared output is
checked once more against every file the command read.

**All outputs or none.** Inside :func:`outputs_together` the renames wait: each output is written to its
temporary file, and when the block ends they are all moved into place together, with SIGINT and SIGTERM held
for the few renames (a signal that arrives then is raised after them). An error, Ctrl-C or SIGTERM before the
end leaves none of them (``--out t.csv --plot t.png --html t.html``: all three, or none).
"""

from __future__ import annotations

import os
import signal
import stat
import sys
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping
from contextlib import contextmanager, suppress
from contextvars import ContextVar
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, Literal

from .errors import InvalidInputError
from .limits import check_not_read, declared_option
from .signals import raise_pending

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "FIGURE_FORMATS",
    "STDOUT",
    "atomic_output",
    "check_output_path",
    "check_outputs",
    "figure_format",
    "finish",
    "new_figure",
    "outputs_together",
    "save_figure",
    "write_atomic_with",
    "write_text_atomic",
]

STDOUT = "-"
"""The output name that means standard output."""

_KINDS = (
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISDIR, "a folder"),
)


def check_output_path(path: str | os.PathLike[str]) -> Path:
    """``path`` as a :class:`Path` if a regular file may be written there (or ``-``), else refuse it.

    Raises:
        InvalidInputError: the folder does not exist, or ``path`` exists and is not a regular file or a
            symbolic link (a device, FIFO, socket or folder).
    """
    path = Path(path)
    if str(path) == STDOUT:
        return path
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInputError(f"cannot write {path}: folder {folder} does not exist")
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return path
    except OSError as exc:
        raise InvalidInputError(f"cannot write {path}: {exc.strerror or exc}") from None
    for test, kind in _KINDS:
        if test(mode):
            raise InvalidInputError(f"cannot write {path}: it is {kind}; scara-pin writes regular files only "
                                    "(or - for standard output)")  # fmt: skip
    return path


PathLike = str | os.PathLike[str]


def _identity(path: PathLike) -> tuple[int, int] | str:
    """What ``path`` names: the (device, inode) of an existing file (links followed; hard links too).

    A file that does not exist (yet): its absolute path, the links of its existing part resolved.
    """
    try:
        st = os.stat(path)
    except OSError:
        return str(Path(path).resolve())
    return (st.st_dev, st.st_ino)


def check_outputs(
    outputs: Mapping[str, PathLike | None],
    inputs: Mapping[str, PathLike | Iterable[PathLike] | None] | None = None,
    *,
    figures: Collection[str] = (),
    stdout: str | None = None,
) -> None:
    """Refuse, before any work, outputs that cannot be written as named or that would destroy something.

    Args:
        outputs: option -> file name, e.g. ``{"--out": "c.urdf", "--plot": None}`` (None: not given; ``-``:
            standard output).
        inputs: option -> the file (or files) it reads, e.g. ``{"--measurements": "m.csv"}``.
        figures: the options of ``outputs`` that are plots: their names end in .png, .svg or .pdf (or nothing).
        stdout: what else prints on standard output (e.g. ``"--json"``), or None.

    Raises:
        InvalidInputError: an output that :func:`check_output_path` refuses, a plot named for another format,
            two outputs on standard output, an output that is one of the inputs or another output (the same
            file after resolving links), naming the options.
    """
    named = {option: str(path) for option, path in outputs.items() if path is not None and str(path) != ""}
    for option, path in named.items():
        check_output_path(path)
        if option in figures:
            figure_format(path)
    on_stdout = [option for option, path in named.items() if path == STDOUT] + ([stdout] if stdout else [])
    if len(on_stdout) > 1:
        raise InvalidInputError(f"{', '.join(on_stdout[:-1])} and {on_stdout[-1]} would print on standard output: "
                                "only one output can go there (-)")  # fmt: skip
    files = {option: _identity(path) for option, path in named.items() if path != STDOUT}
    for option, given in (inputs or {}).items():
        items = [] if given is None else [given] if isinstance(given, (str, os.PathLike)) else list(given)
        for item in items:
            key = _identity(item)
            for out, out_key in files.items():
                if out_key == key:
                    raise InvalidInputError(f"{out} {named[out]} is the file {option} {item} reads: it would be "
                                            "replaced; write the output elsewhere")  # fmt: skip
    seen: dict[tuple[int, int] | str, str] = {}
    for option, key in files.items():
        if key in seen:
            raise InvalidInputError(f"{seen[key]} {named[seen[key]]} and {option} {named[option]} are the same file: "
                                    "one output would replace the other; give each its own file")  # fmt: skip
        seen[key] = option


def _new_temp(folder: Path, name: str, created: list[Path], mode: int = 0o666) -> Path:
    """Create an empty temporary file in ``folder`` with ``mode`` & ~umask (exclusive, never reused).

    Its name is put in ``created`` BEFORE it exists, so that a Ctrl-C or SIGTERM arriving at any point
    after its creation finds it there and removes it.
    """
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
    for _ in range(100):
        tmp = folder / f".{name[:64]}.{os.urandom(6).hex()}.tmp"  # as secrets.token_hex(6)
        created.append(tmp)
        try:
            fd = os.open(tmp, flags, mode)
        except FileExistsError:  # someone else's: never ours to delete
            created.remove(tmp)
            continue
        except OSError:
            created.remove(tmp)
            raise
        os.close(fd)
        return tmp
    raise InvalidInputError(f"cannot write in {folder}: no free temporary name")  # pragma: no cover


def _fsync(path: Path, flags: int) -> None:
    fd = os.open(path, flags)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


_BATCH: ContextVar[list[tuple[Path, Path]] | None] = ContextVar("scara_pin_outputs", default=None)
"""The outputs of :func:`outputs_together` waiting for their rename: (temporary file, destination)."""


@contextmanager
def atomic_output(path: str | os.PathLike[str], mode: int = 0o666) -> Iterator[Path]:
    """Yield a temporary file's path; on success move it onto ``path`` (``-``: copy it to stdout), else delete it.

    Write to the yielded path (``open(tmp, "w")``, ``figure.savefig(tmp, format="png")``...). An error,
    Ctrl-C or SIGTERM (under the command line) leaves the old file or none, never a partial one. The new
    file's mode is ``mode`` & ~umask (``0o600``: for its owner only). Inside :func:`outputs_together` the move
    waits for the block's end (all the block's outputs together).

    Raises:
        InvalidInputError: the folder does not exist or cannot be written, ``path`` is not a regular file
            (see the module docstring), the disk is full...
        OutputIsInputError: ``path`` is an output of the running command and a file it read.
    """
    path = check_output_path(path)
    to_stdout = str(path) == STDOUT
    if to_stdout:
        import tempfile  # here: `scara-pin fk` writes no file and does not pay for the import

        folder = Path(tempfile.gettempdir())
    else:
        folder = path.parent if str(path.parent) else Path(".")
    created: list[Path] = []
    batch = _BATCH.get()
    try:
        tmp = _new_temp(folder, "stdout" if to_stdout else path.name, created, mode)
        yield tmp
        raise_pending()  # a Ctrl-C or SIGTERM that a library swallowed meanwhile: nothing is written
        if not to_stdout:
            _fsync(tmp, os.O_RDONLY)
        if batch is not None:  # moved into place with the block's other outputs
            batch.append((tmp, path))
            created.remove(tmp)
            return
        _move(tmp, path)
    except BrokenPipeError:  # the reader of stdout went away: the command line handles it
        raise
    except OSError as exc:
        raise InvalidInputError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        for name in created:  # after the rename: nothing there
            name.unlink(missing_ok=True)


def _check_destination(path: Path) -> None:
    """Just before a rename: still a place for a regular file, and not a file the command read (if an output)."""
    if str(path) == STDOUT:
        return
    check_output_path(path)  # again: it may have changed meanwhile
    option = declared_option(path)
    if option is not None:
        check_not_read(option, path)


def _move(tmp: Path, path: Path) -> None:
    """The temporary file ``tmp`` (written, flushed) onto ``path``, or copied to standard output for ``-``."""
    _check_destination(path)
    if str(path) == STDOUT:
        sys.stdout.flush()
        with tmp.open("rb") as src:
            out = getattr(sys.stdout, "buffer", None)
            if out is None:  # a text stream (tests): text outputs only
                sys.stdout.write(src.read().decode("utf-8"))
            else:
                import shutil

                shutil.copyfileobj(src, out)
        sys.stdout.flush()
        tmp.unlink(missing_ok=True)
        return
    os.replace(tmp, path)
    folder = path.parent if str(path.parent) else Path(".")
    with suppress(OSError):  # the rename itself, on disk (some systems cannot fsync a folder)
        _fsync(folder, os.O_RDONLY)


_HELD = {signal.SIGINT, signal.SIGTERM}


@contextmanager
def outputs_together() -> Iterator[None]:
    """The outputs written inside the block (by :func:`atomic_output` and its users) appear together at its end.

    Each is written to its temporary file as usual; at the end, after a last look for a signal a library
    swallowed, every destination is checked again and the files are renamed into place one after the other
    with SIGINT and SIGTERM held (a signal that arrives meanwhile is raised right after the last rename). An
    error, Ctrl-C or SIGTERM inside the block (or in the checks) deletes the temporary files: none is written.

    Raises:
        InvalidInputError: a destination that can no longer be written, or an output that is a file read.
    """
    pending: list[tuple[Path, Path]] = []
    token = _BATCH.set(pending)
    active = True
    done = False
    try:
        yield
        _BATCH.reset(token)  # the renames below are this block's own
        active = False
        raise_pending()
        for _, path in pending:
            _check_destination(path)
        held = hasattr(signal, "pthread_sigmask")
        if held:
            signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
        try:
            for tmp, path in pending:
                _move(tmp, path)
            done = True
        finally:
            if held:
                signal.pthread_sigmask(signal.SIG_UNBLOCK, _HELD)
    except OSError as exc:
        raise InvalidInputError(f"cannot write the outputs: {exc.strerror or exc}") from None
    finally:
        if active:
            _BATCH.reset(token)
        if not done:
            for tmp, _ in pending:
                tmp.unlink(missing_ok=True)


def write_text_atomic(path: str | os.PathLike[str], text: str, mode: int = 0o666) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (``-``: standard output), a new file of ``mode`` & ~umask."""
    path = Path(path)
    with atomic_output(path, mode) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="")
    return path


def write_atomic_with(path: str | os.PathLike[str], produce: Callable[[IO[str]], Any]) -> Path:
    """Let ``produce(handle)`` write a text file (UTF-8, no newline translation), atomically."""
    path = Path(path)
    with atomic_output(path) as tmp, tmp.open("w", encoding="utf-8", newline="") as handle:
        produce(handle)
    return path


FIGURE_FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
"""What a plot's file name may end with, and the format written."""


def figure_format(path: str | os.PathLike[str]) -> str:
    """The format a plot named ``path`` is written in: its ending's (.png, .svg, .pdf), PNG without one.

    Raises:
        InvalidInputError: another ending (the file would not be what its name says).
    """
    path = Path(path)
    fmt = FIGURE_FORMATS.get(path.suffix.lower()) if path.suffix else "png"  # "-" (stdout) too
    if fmt is None:
        raise InvalidInputError(f"cannot write {path}: a plot is written as {', '.join(FIGURE_FORMATS)}; "
                                "name the file with one of these endings")  # fmt: skip
    return fmt


def save_figure(figure: Any, path: str | os.PathLike[str], **kwargs: Any) -> Path:
    """Write a matplotlib figure atomically, in the format its name says (.png, .svg, .pdf; PNG without one).

    Raises:
        InvalidInputError: another ending (the file would not be what its name says), or an unwritable path.
    """
    path = Path(path)
    fmt = figure_format(path)
    with atomic_output(path) as tmp:
        figure.savefig(tmp, format=fmt, **kwargs)
    return path


def new_figure(width: float, height: float, layout: Literal["constrained"] | None = "constrained") -> Figure:
    """A matplotlib Figure on its own Agg canvas (no pyplot: the caller's backend and figures are untouched).

    Args:
        width: figure width [inch].
        height: figure height [inch].
        layout: matplotlib's layout engine (None: the figure as drawn, trimmed when saved instead).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout=layout)
    FigureCanvasAgg(fig)
    return fig


def finish(fig: Figure, path: str | os.PathLike[str] | None, dpi: int = 120, **kwargs: Any) -> Figure:
    """Write ``fig`` to ``path`` when one is given (atomically; PNG, SVG or PDF by the ending), and return it."""
    if path is not None:
        save_figure(fig, path, dpi=dpi, **kwargs)
    return fig
