"""The description cache: a configured robot's parameters and URDF, kept between runs of the command line.

Making a configured robot's URDF means importing PyYAML and xacro and expanding the templates: about 30 ms,
half of what ``scara-pin fk`` adds to ``import pinocchio``. The result depends only on its inputs, so it is
kept in a file named by their SHA-256 digest:

- the bytes of the robot's three yaml files, its name and the folder they are in;
- the overrides (``--set``), as the floats they are;
- the bytes of every ``*.xacro`` template of the description (the entry, the macro, ``inc/``);
- the bytes of xacro's own module (an upgrade of xacro is a new key) and this package's version.

A change to any of them is a new key: the robot is made again and the new result kept. The file holds
a header line with the SHA-256 digest of the key and of the body, then the body, JSON (the kind, the
parameters by flat name, the URDF text).

An entry is trusted only as far as it is checked, on every read:

- it is opened without following a link (``O_NOFOLLOW``): a link in the cache folder is never read
  through; it must be a regular file of the user's, of at most :data:`MAX_ENTRY_BYTES`;
- its digest is computed again: an entry changed since it was written (a flipped bit, an edited length,
  an entry renamed to another key) does not match; it is ignored with ONE warning, the robot is made
  again and the entry replaced (so the next run finds a good one);
- the parameters are validated again (:class:`~scara_pin.description.RobotParameters`).

Entries are written atomically, mode 0600, in a folder of mode 0700 (created so, or narrowed when it is the
user's); a folder that is another user's is not used. Nothing is ever fatal: a folder that cannot be used
only means no caching.

Where: ``$SCARA_PIN_CACHE_DIR``, else ``$XDG_CACHE_HOME/scara-pin``, else ``~/.cache/scara-pin``;
``SCARA_PIN_NO_CACHE=1`` turns it off (every run then makes the robot).

The machinery (the digest header, the checks on reading, the atomic 0600 writes, the folder's rules) is
:class:`DigestStore`'s; the job's plan cache (:mod:`scara_pin.job.cache`) is another store of it, in the
``plans`` folder of the same cache, with its own header and check of what an entry holds.
"""

from __future__ import annotations

import errno
import hashlib
import json
import logging
import os
import stat
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._version import __version__
from ..limits import read_bytes

__all__ = ["FORMAT", "MAX_ENTRY_BYTES", "DescriptionCache", "DigestStore", "cache_folder"]

log = logging.getLogger(__name__)

FORMAT = 2
"""The layout of a cache file (part of every key: a new layout never reads an old file)."""
_HEADER = b"scara-pin description cache sha256="
MAX_ENTRY_BYTES = 8 * 1024 * 1024
"""[bytes] a cache file larger than this is not read (a generated URDF is about 10 KB)."""


def cache_folder() -> Path | None:
    """The user's cache folder (module docstring), or None when ``SCARA_PIN_NO_CACHE`` turns caching off."""
    if os.environ.get("SCARA_PIN_NO_CACHE", "") not in ("", "0"):
        return None
    explicit = os.environ.get("SCARA_PIN_CACHE_DIR")
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "scara-pin"


@dataclass(frozen=True)
class DigestStore:
    """A folder of entries named by their key, each checked by its digest on every read (module docstring).

    Attributes:
        folder: where the files are; None: caching off.
        what: how warnings name an entry (``description cache``, ``plan cache``).
        header: the first bytes of an entry's header line (the digest follows).
        max_bytes: [bytes] an entry larger than this is not read.
    """

    folder: Path | None
    what: str = "description cache"
    header: bytes = _HEADER
    max_bytes: int = MAX_ENTRY_BYTES

    def check(self, entry: Any) -> None:
        """Refuse (``ValueError``) an entry whose JSON is not what this store holds (a subclass says what)."""

    def _path(self, key: str) -> Path | None:
        return None if self.folder is None else self.folder / f"{key}.json"

    @staticmethod
    def _digest(key: str, body: bytes) -> str:
        """The digest an entry's header holds: of its key (an entry renamed to another key fails) and body."""
        return hashlib.sha256(key.encode() + b"\0" + body).hexdigest()

    def _read(self, path: Path) -> bytes | None:
        """The bytes of the entry ``path`` (None: there is none), opened without following a link.

        Raises:
            OSError: a link (ELOOP), or unreadable.
            ValueError: not a regular file of the user's of at most :attr:`max_bytes`.
        """
        flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
        try:
            fd = os.open(path, flags)
        except FileNotFoundError:
            return None
        with os.fdopen(fd, "rb") as handle:
            st = os.fstat(fd)
            if not stat.S_ISREG(st.st_mode) or st.st_uid != os.getuid() or st.st_size > self.max_bytes:
                raise ValueError("not a regular file of the user's of at most its size cap")
            return handle.read(self.max_bytes + 1)

    def get(self, key: str) -> dict[str, Any] | None:
        """The entry kept under ``key``, verified (module docstring), or None (none, caching off, or a bad entry).

        A bad entry (a link, not a regular file, a digest that does not match, not the JSON it should be) is
        logged as a warning, once: the caller makes it again and :meth:`put` replaces it.
        """
        path = self._path(key)
        if path is None:
            return None
        try:
            data = self._read(path)
            if data is None:
                return None
            header, _, body = data.partition(b"\n")
            expected = self._digest(key, body)
            if not header.startswith(self.header) or header[len(self.header) :].decode("ascii") != expected:
                raise ValueError("its content does not match its digest")
            entry = json.loads(body.decode("utf-8"))
            if not isinstance(entry, dict):
                raise ValueError("it is not a JSON object")
            self.check(entry)
        except (OSError, ValueError, UnicodeDecodeError) as exc:  # json.JSONDecodeError is a ValueError
            if isinstance(exc, OSError):
                reason = "a symbolic link: never followed" if exc.errno == errno.ELOOP else exc.strerror or str(exc)
            else:
                reason = str(exc)
            again = "the robot is made again" if self.what == "description cache" else "it is made again"
            log.warning("%s entry %s ignored (%s): %s and the entry replaced", self.what, path, reason, again)
            return None
        return entry

    def _folder(self) -> Path | None:
        """The cache folder, created with mode 0700 (narrowed to it when it is the user's); None: not usable."""
        folder = self.folder
        if folder is None:
            return None
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        st = os.stat(folder)
        if st.st_uid != os.getuid():
            log.warning("%s folder %s is not the user's: not used", self.what, folder)
            return None
        if stat.S_IMODE(st.st_mode) & 0o077:
            os.chmod(folder, 0o700)
        return folder

    def put(self, key: str, entry: Mapping[str, Any]) -> None:
        """Keep ``entry`` under ``key``: atomically, mode 0600, with its digest (a folder not usable: logged)."""
        from ..files import write_text_atomic

        try:
            folder = self._folder()
            if folder is None:
                return
            body = json.dumps(entry).encode("utf-8")
            text = (self.header + self._digest(key, body).encode("ascii") + b"\n" + body).decode("utf-8")
            write_text_atomic(folder / f"{key}.json", text, mode=0o600)
        except Exception as exc:  # a read-only home, a full disk: no caching, never an error
            log.debug("%s: %s not written (%s)", self.what, self._path(key), exc)


@dataclass(frozen=True)
class DescriptionCache(DigestStore):
    """The description cache: a folder of configured robots, or none (``folder is None``: caching off).

    Attributes:
        folder: where the files are.
    """

    @classmethod
    def default(cls) -> DescriptionCache:
        """The cache the environment asks for (module docstring)."""
        return cls(cache_folder())

    def check(self, entry: Any) -> None:
        """An entry holds a robot: its kind, its parameters by flat name and its URDF text."""
        if not (isinstance(entry.get("urdf"), str) and isinstance(entry.get("values"), dict)
                and isinstance(entry.get("kind"), str)):  # fmt: skip
            raise ValueError("it does not hold a robot")

    def key(self, name: str, folder: Path, texts: Mapping[str, str], overrides: Mapping[str, float],
            description: Path) -> str:  # fmt: skip
        """The SHA-256 digest (hex) of everything a configured robot is made from (module docstring)."""
        import importlib.util

        digest = hashlib.sha256()

        def add(label: str, data: bytes) -> None:
            digest.update(f"{label}\0{len(data)}\0".encode())
            digest.update(data)

        add("format", str(FORMAT).encode())
        add("scara-pin", __version__.encode())
        add("robot", name.encode())
        add("folder", str(folder.resolve()).encode())
        for file, text in sorted(texts.items()):
            add(f"yaml {file}", text.encode())
        add("overrides", repr(sorted((k, float(v)) for k, v in overrides.items())).encode())
        templates = (p for p in description.rglob("*.xacro") if "config" not in p.relative_to(description).parts)
        for template in sorted(templates):
            add(f"template {template.relative_to(description)}", read_bytes(template, "robot template"))
        spec = importlib.util.find_spec("xacro")
        origin = None if spec is None else spec.origin
        add("xacro", b"" if origin is None else Path(origin).read_bytes())
        return digest.hexdigest()
