"""Output files written atomically: a temporary file in the same folder, then a rename.

An error or Ctrl-C leaves the old file or none, never a half-written one. Used by every command that
writes a file (URDF, trajectories, setpoints, plots, HTML pages, batch IK results).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from .errors import InvalidInputError

__all__ = ["atomic_output", "write_atomic_with", "write_text_atomic"]


@contextmanager
def atomic_output(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary file next to ``path``; on success rename it onto ``path``, else delete it.

    An error (or Ctrl-C) leaves the old file or none, never a partial one.

    Raises:
        InvalidInputError: the folder does not exist or cannot be written, or ``path`` is a folder.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise InvalidInputError(f"cannot write {path}: folder {folder} does not exist")
    if path.is_dir():
        raise InvalidInputError(f"cannot write {path}: it is a folder")
    try:
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    except OSError as exc:
        raise InvalidInputError(f"cannot write in {folder}: {exc.strerror}") from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        mask = os.umask(0o022)  # mkstemp makes the file private: give it the usual permissions
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise InvalidInputError(f"cannot write {path}: {exc.strerror or exc}") from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; return the path."""
    path = Path(path)
    with atomic_output(path) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="")
    return path


def write_atomic_with(path: str | os.PathLike[str], produce: Callable[[IO[str]], Any]) -> Path:
    """Let ``produce(handle)`` write a text file (UTF-8, no newline translation), atomically."""
    path = Path(path)
    with atomic_output(path) as tmp, tmp.open("w", encoding="utf-8", newline="") as handle:
        produce(handle)
    return path
