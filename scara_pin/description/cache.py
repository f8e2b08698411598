"""The description cache: a configured robot's parameters and URDF, kept between runs of the command line.

Making a configured robot's URDF means importing PyYAML and xacro and expanding the templates: about 30 ms,
half of what ``scara-pin fk`` adds to ``import pinocchio``. The result depends only on its inputs, so it is
kept in a file named by their SHA-256 digest:

- the bytes of the robot's three yaml files, its name and the folder they are in;
- the overrides (``--set``), as the floats they are;
- the bytes of every ``*.xacro`` template of the description (the entry, the macro, ``inc/``);
- the bytes of xacro's own module (an upgrade of xacro is a new key) and this package's version.

A change to any of them is a new key: the robot is made again and the new result kept. The file holds
JSON (the kind, the parameters by flat name, the URDF text); on a hit the parameters are validated again
(:class:`~scara_pin.description.RobotParameters`), and a file that cannot be read, is not what it should
be, or fails that validation is ignored (the robot is made again and the file replaced). Nothing is ever
fatal: a folder that cannot be written only means no caching.

Where: ``$SCARA_PIN_CACHE_DIR``, else ``$XDG_CACHE_HOME/scara-pin``, else ``~/.cache/scara-pin``;
``SCARA_PIN_NO_CACHE=1`` turns it off (every run then makes the robot). Files are written atomically and
read only if they are regular files of at most :data:`MAX_ENTRY_BYTES`.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["FORMAT", "MAX_ENTRY_BYTES", "DescriptionCache"]

log = logging.getLogger(__name__)

FORMAT = 1
"""The layout of a cache file (part of every key: a new layout never reads an old file)."""
MAX_ENTRY_BYTES = 8 * 1024 * 1024
"""[bytes] a cache file larger than this is not read (a generated URDF is about 10 KB)."""


@dataclass(frozen=True)
class DescriptionCache:
    """A folder of cache files, or none (``folder is None``: caching off).

    Attributes:
        folder: where the files are.
    """

    folder: Path | None

    @classmethod
    def default(cls) -> DescriptionCache:
        """The cache the environment asks for (module docstring)."""
        if os.environ.get("SCARA_PIN_NO_CACHE", "") not in ("", "0"):
            return cls(None)
        explicit = os.environ.get("SCARA_PIN_CACHE_DIR")
        if explicit:
            return cls(Path(explicit))
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        return cls(Path(base) / "scara-pin")

    def key(self, name: str, folder: Path, texts: Mapping[str, str], overrides: Mapping[str, float],
            description: Path) -> str:  # fmt: skip
        """The SHA-256 digest (hex) of everything a configured robot is made from (module docstring)."""
        import importlib.util

        from .._version import __version__

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
            add(f"template {template.relative_to(description)}", template.read_bytes())
        spec = importlib.util.find_spec("xacro")
        origin = None if spec is None else spec.origin
        add("xacro", b"" if origin is None else Path(origin).read_bytes())
        return digest.hexdigest()

    def _path(self, key: str) -> Path | None:
        return None if self.folder is None else self.folder / f"{key}.json"

    def get(self, key: str) -> dict[str, Any] | None:
        """The entry kept under ``key``, or None (none, caching off, or a file that is not one of ours)."""
        from ..limits import read_bytes

        path = self._path(key)
        if path is None or not path.exists():
            return None
        try:
            entry = json.loads(read_bytes(path, "cache file", MAX_ENTRY_BYTES).decode("utf-8"))
        except Exception as exc:  # unreadable, too large, not JSON: made again and replaced
            log.debug("description cache: %s ignored (%s)", path, exc)
            return None
        if not (isinstance(entry, dict) and isinstance(entry.get("urdf"), str) and isinstance(entry.get("values"), dict)
                and isinstance(entry.get("kind"), str)):  # fmt: skip
            return None
        return entry

    def put(self, key: str, entry: Mapping[str, Any]) -> None:
        """Keep ``entry`` under ``key`` (atomically); a folder that cannot be written is only logged."""
        from ..files import write_text_atomic

        path = self._path(key)
        if path is None:
            return
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_text_atomic(path, json.dumps(entry))
        except Exception as exc:  # a read-only home, a full disk: no caching, never an error
            log.debug("description cache: %s not written (%s)", path, exc)
