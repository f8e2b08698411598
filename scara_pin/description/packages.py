"""ROS-style packages without ROS: ``$(find pkg)`` in a user's xacro and ``package://pkg/...`` file names.

A package is a folder holding a ``package.xml`` (its ``<name>`` names it). Packages are searched, first to
last, in:

1. the ``--package-path`` folders (each a folder holding packages, searched recursively as ``rospack``
   does: a package's own subfolders, hidden folders and folders marked ``CATKIN_IGNORE`` are not entered);
2. the folders above the robot's file (its own package, when the file lives in one);
3. ``AMENT_PREFIX_PATH`` (ROS 2: ``<prefix>/share/<pkg>``) and ``ROS_PACKAGE_PATH`` (ROS 1, searched as 1).

A package folder is input like any other (it may come from a stranger), so the search is bounded:

- each folder is entered once (its ``(st_dev, st_ino)`` is remembered): a symbolic link back up the tree,
  or two links to one folder, cost one listing, not 2^depth;
- at most :data:`~scara_pin.limits.MAX_WALK_DEPTH` folders deep and
  :data:`~scara_pin.limits.MAX_WALK_ENTRIES` entries listed per folder searched (the search says so when a
  package is then not found);
- a ``package.xml`` is read only if it is a regular file (opened non-blocking, then checked: a FIFO is
  never waited for) of at most :data:`~scara_pin.limits.MAX_PACKAGE_XML_BYTES`; one that is not is
  skipped, and named when the package is not found.

The xacro expansion is xacro's, driven by xacrodoc (no ROS installation needed). Every file it reads (an
``<xacro:include>``, a ``load_yaml``) follows the same rules: regular files only, at most
:data:`~scara_pin.limits.MAX_XACRO_FILES` files and :data:`~scara_pin.limits.MAX_DOCUMENT_BYTES` bytes in
all; a yaml file that xacro's ``load_yaml`` reads is first read by the package's bounded loader
(:func:`~scara_pin.description.yaml_units.load_yaml`: an alias bomb is refused). A relative include is
resolved against the folder of the file that includes it (as ROS's xacro does), never against the current
folder.

Security: expanding a xacro file runs the expressions written in it (``${...}``, ``$(eval ...)``): only
the user's own files are expanded, never text from the command line (no ``--set`` into a user's xacro). The
expansion runs in a child process, bounded in time and memory (:mod:`~scara_pin.description.expansion`:
``${(9**9**9) % 7}`` or a macro calling itself twice 30 deep end with a message, not a hang).
"""

from __future__ import annotations

import builtins
import io
import os
import re
import stat
import sys
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from ..errors import InvalidInputError, UrdfError, YamlError
from ..limits import (
    MAX_DOCUMENT_BYTES,
    MAX_PACKAGE_XML_BYTES,
    MAX_WALK_DEPTH,
    MAX_WALK_ENTRIES,
    MAX_XACRO_FILES,
    MAX_XACRO_MEMORY,
    OutputIsInputError,
    UnreadableFileError,
    open_regular,
    read_bytes,
    read_text,
)
from .expansion import bounded, xacro_lock

__all__ = ["PackagePath", "read_robot_file", "xacro_lock"]

_PACKAGE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*\Z")
"""What a package's name may be (ROS REP 144 and more): a folder name, never a path."""
_SHOWN_NOTES = 3
"""Notes (skipped package.xml files, caps reached) named in a 'package not found' message."""



# ----------------------------------------------------------------------------------------- the search
@dataclass(frozen=True)
class _Manifest:
    name: str
    metapackage: bool


def _read_manifest(folder: Path, notes: list[str]) -> _Manifest | None:
    """The ``package.xml`` of ``folder``: its name; None (and a note saying why) when it cannot be used."""
    path = folder / "package.xml"
    try:
        data = read_bytes(path, "package.xml", MAX_PACKAGE_XML_BYTES)  # regular files only, never blocks
    except InvalidInputError as exc:
        notes.append(str(exc))
        return None
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        notes.append(f"{path}: not XML ({exc})")
        return None
    name = (root.findtext("name") or "").strip()
    if not name:
        notes.append(f"{path}: no <name>")
        return None
    return _Manifest(name, root.find("./export/metapackage") is not None)


def _is_dir(entry: os.DirEntry[str]) -> bool:
    try:
        return entry.is_dir()  # follows links, as rospack does; stat only, nothing is opened
    except OSError:
        return False


@dataclass(frozen=True)
class _Walk:
    """The packages under one folder (first found wins) and what the search skipped."""

    found: dict[str, Path]
    notes: list[str]


def _walk(top: Path) -> _Walk:
    """Rospack's recursive search of ``top``, bounded (see the module docstring), in sorted order."""
    found: dict[str, Path] = {}
    notes: list[str] = []
    seen: set[tuple[int, int]] = set()
    listed = 0
    deep = False
    stack = [(top, 0)]
    while stack:
        folder, depth = stack.pop()
        try:
            st = os.stat(folder)
        except OSError:
            continue
        if (st.st_dev, st.st_ino) in seen or not stat.S_ISDIR(st.st_mode):
            continue  # a folder reached again (a link loop, two links to one folder): listed once
        seen.add((st.st_dev, st.st_ino))
        names: set[str] = set()
        subdirs: list[str] = []
        try:
            with os.scandir(folder) as entries:
                for entry in entries:
                    listed += 1
                    if listed > MAX_WALK_ENTRIES:
                        break
                    names.add(entry.name)
                    if not entry.name.startswith(".") and _is_dir(entry):
                        subdirs.append(entry.name)
        except OSError:
            continue
        if listed > MAX_WALK_ENTRIES:
            notes.append(f"the search of {top} stopped after {MAX_WALK_ENTRIES:,} folder entries (the cap)")
            break
        if "CATKIN_IGNORE" in names:
            continue
        if "package.xml" in names:  # a package: its subfolders hold no other package
            manifest = _read_manifest(folder, notes)
            if manifest is not None and not manifest.metapackage:
                found.setdefault(manifest.name, folder)
            continue
        if "rospack_nosubdirs" in names:
            continue
        if depth >= MAX_WALK_DEPTH:
            deep = deep or bool(subdirs)
            continue
        stack.extend((folder / name, depth + 1) for name in sorted(subdirs, reverse=True))
    if deep:
        notes.append(f"folders more than {MAX_WALK_DEPTH} levels below {top} were not searched (the cap)")
    return _Walk(found, notes)


def _walk_up(origin: Path, package: str, notes: list[str]) -> Path | None:
    """The folder above ``origin`` (or itself) that is the package ``package``, or None."""
    for folder in (origin, *origin.parents):
        if os.path.lexists(folder / "package.xml"):
            manifest = _read_manifest(folder, notes)
            if manifest is not None and manifest.name == package:
                return folder
        manifest_xml = folder / "manifest.xml"  # rosbuild (ROS 1's first build system): the folder names it
        if folder.name == package and manifest_xml.is_file():
            return folder
    return None


@dataclass(frozen=True)
class PackagePath:
    """Where the packages of a robot's file are looked for.

    Attributes:
        dirs: folders holding packages (``--package-path``), searched first, in order.
        origin_dir: the folder of the robot's file (URDF or xacro): relative file names start there, and
            the package holding the file (found by walking up from it) is searched after ``dirs``.
    """

    dirs: tuple[Path, ...] = ()
    origin_dir: Path | None = None
    _walks: dict[Path, _Walk] = field(default_factory=dict, init=False, repr=False, compare=False, hash=False)
    _said: set[str] = field(default_factory=set, init=False, repr=False, compare=False, hash=False)

    def first_time(self, note: str) -> bool:
        """Whether ``note`` is said for the first time about this robot's files (a warning said once, not per use)."""
        if note in self._said:
            return False
        self._said.add(note)
        return True

    def __post_init__(self) -> None:
        for d in self.dirs:
            if not Path(d).is_dir():
                raise UrdfError(f"--package-path {str(d)!r} is not a folder")
        object.__setattr__(self, "dirs", tuple(Path(d).resolve() for d in self.dirs))
        if self.origin_dir is not None:
            object.__setattr__(self, "origin_dir", Path(self.origin_dir).resolve())

    @staticmethod
    def _env_dirs() -> tuple[list[Path], list[Path]]:
        """(ROS_PACKAGE_PATH folders, AMENT_PREFIX_PATH share folders) that exist."""
        ros = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        ament = [Path(p) / "share" for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
        return [p for p in ros if p.is_dir()], [p for p in ament if p.is_dir()]

    def _walked(self, folder: Path) -> _Walk:
        """The search of one folder, done once per folder (a xacro may name many packages)."""
        walk = self._walks.get(folder)
        if walk is None:
            walk = self._walks[folder] = _walk(folder)
        return walk

    def _lookup(self, package: str, notes: list[str]) -> Path | None:
        for folder in self.dirs:
            walk = self._walked(folder)
            notes.extend(walk.notes)
            if package in walk.found:
                return walk.found[package]
        if self.origin_dir is not None:
            hit = _walk_up(self.origin_dir, package, notes)
            if hit is not None:
                return hit
        ros, ament = self._env_dirs()
        if _PACKAGE_NAME.match(package):
            for share in ament:
                if (share / package).is_dir():
                    return share / package
        for folder in ros:
            walk = self._walked(folder.resolve())
            notes.extend(walk.notes)
            if package in walk.found:
                return walk.found[package]
        return None

    def _not_found(self, package: str, notes: list[str]) -> UrdfError:
        where = ", ".join(str(d) for d in self.dirs) or "none given"
        skipped = ""
        if notes:
            unique = list(dict.fromkeys(notes))
            more = f" and {len(unique) - _SHOWN_NOTES} more" if len(unique) > _SHOWN_NOTES else ""
            skipped = f"; skipped: {'; '.join(unique[:_SHOWN_NOTES])}{more}"
        return UrdfError(f"package {package!r} not found (searched: --package-path {where}; the folders above "
                         f"{self.origin_dir or 'the file'}; ROS_PACKAGE_PATH; AMENT_PREFIX_PATH{skipped}): "
                         "add its parent folder with --package-path DIR")  # fmt: skip

    def find(self, package: str) -> Path:
        """The folder of a package.

        Raises:
            UrdfError: no such package (the message names it, where it was looked for, and the
                ``package.xml`` files skipped and caps reached on the way).
        """
        notes: list[str] = []
        folder = self._lookup(package, notes)
        if folder is None:
            raise self._not_found(package, notes)
        return folder.resolve()

    def roots(self) -> tuple[Path, ...]:
        """The folders files may be read from: the package folders searched, and the file's own folder."""
        ros, ament = self._env_dirs()
        out = [*self.dirs, *(p.resolve() for p in ament), *(p.resolve() for p in ros)]
        if self.origin_dir is not None:
            out.append(self.origin_dir)
            for d in (self.origin_dir, *self.origin_dir.parents):  # the package holding the file
                if (d / "package.xml").is_file():
                    out.append(d)
                    break
        return tuple(out)

    def expand_xacro(self, path: Path) -> str:
        """The URDF text of a xacro file, ``$(find pkg)`` resolved (``package://`` names are kept).

        Relative includes are resolved against the including file's folder; every file read follows the
        module's rules (regular files, bounded). The expansion runs under the time and memory bounds of
        :func:`~scara_pin.description.expansion.bounded`.

        Raises:
            UrdfError: a missing package, an include that is not a regular file or over the caps, xacro's own
                error (one line; an error in an included file names it), or a bound of the expansion reached.
        """
        path = Path(path)
        return bounded(str(path), lambda: self._expanded(path))

    def _expanded(self, path: Path) -> str:
        """:meth:`expand_xacro`'s work (in the child process)."""
        from xacro import XacroException
        from xacrodoc import XacroDoc, packages

        text = _read_robot_text(path)
        missing: list[UrdfError] = []

        def find(package: str) -> str:  # $(find pkg)
            try:
                return str(self.find(package))
            except UrdfError as exc:
                missing.append(exc)
                raise packages.PackageNotFoundError(package) from None

        session = None
        try:
            with _xacro_session(path, find) as session:
                doc = XacroDoc.from_string(text, resolve_packages=False, rootdir=path.parent)
        except Exception as exc:  # xacro raises plain Python errors for bad expressions, XML errors...
            where = f"{path}" if session is None or session.failed_in is None \
                else f"{path}: in the included file {session.failed_in}"  # fmt: skip
            refused = _in_chain(exc, _Refused)
            if refused is not None:
                raise UrdfError(f"{path}: xacro: {refused}") from None
            if _in_chain(exc, MemoryError) is not None:
                raise UrdfError(f"{where}: xacro: the expansion needed more than {MAX_XACRO_MEMORY / 2**20:,.0f} MiB "
                                "of memory, the cap (MAX_XACRO_MEMORY); not expanded") from None
            clash = _in_chain(exc, OutputIsInputError)
            if clash is not None:
                raise clash from None
            if missing:
                raise missing[-1] from None
            # a missing package wrapped by xacro (xacrodoc 2.0.0 raises its own copy of XacroException)
            not_found = _in_chain(exc, packages.PackageNotFoundError)
            if not_found is not None:
                raise self._not_found(not_found.args[0] if not_found.args else "?", []) from None
            if isinstance(exc, XacroException):
                raise UrdfError(f"{where}: xacro: {' '.join(str(exc).split())}") from None
            raise UrdfError(f"{where}: xacro: {type(exc).__name__}: {' '.join(str(exc).split())}") from None
        return str(doc.dom.toprettyxml(indent="  "))


# ----------------------------------------------------------------------------------------- xacro's files
class _Refused(Exception):
    """A file xacro asked for that is not read (not a regular file, over a cap): an error, never skipped."""


def _in_chain(exc: BaseException, kind: type[BaseException]) -> Any:
    """The first exception of type ``kind`` among ``exc``, what it wraps (``.exc``), its cause and context."""
    todo: list[BaseException | None] = [exc]
    seen: set[int] = set()
    while todo:
        item = todo.pop(0)
        if item is None or id(item) in seen:
            continue
        seen.add(id(item))
        if isinstance(item, kind):
            return item
        todo.extend((getattr(item, "exc", None), item.__cause__, item.__context__))
    return None


class _XacroFiles:
    """xacro's ``open`` while one file is expanded: regular files only, bounded in number and bytes.

    ``failed_in``: the file xacro was reading when the expansion failed (an include's), or None (the top file).
    """

    def __init__(self) -> None:
        self.files = 0
        self.bytes = 0
        self.failed_in: str | None = None

    def open(self, file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> IO[Any]:
        if mode not in ("r", "rt", "rb"):  # xacro writes only its command line's output file
            return builtins.open(file, mode, *args, **kwargs)
        self.files += 1
        if self.files > MAX_XACRO_FILES:
            raise _Refused(f"more than {MAX_XACRO_FILES:,} files read (includes, yaml), the cap; {file} was next")
        try:
            handle = open_regular(file, "xacro input")
        except UnreadableFileError as exc:
            if exc.errno is not None:  # missing, no permission: xacro's own message (and optional includes)
                raise OSError(exc.errno, exc.reason, str(file)) from None
            raise _Refused(str(exc)) from None
        budget = MAX_DOCUMENT_BYTES - self.bytes
        with handle:
            data = handle.read(budget + 1)
        if len(data) > budget:
            raise _Refused(f"the files read by the expansion (includes, yaml) exceed {MAX_DOCUMENT_BYTES:,} "
                           f"bytes, the cap; {file} was the last")  # fmt: skip
        self.bytes += len(data)
        caller = sys._getframe(1)
        if caller.f_code.co_name == "load_yaml" and caller.f_globals.get("__name__") == "xacro":
            _check_yaml(data, file)
        if "b" in mode:
            return io.BytesIO(data)
        return io.TextIOWrapper(io.BytesIO(data), encoding="utf-8")


def _check_yaml(data: bytes, file: object) -> None:
    """Refuse a yaml file for xacro's ``load_yaml`` that the bounded loader refuses (an alias bomb, too deep).

    xacro parses it again (its values, its tags); an invalid file is left to xacro's own error.
    """
    from .yaml_units import load_yaml

    try:
        load_yaml(data.decode("utf-8", errors="replace"), f"yaml file {file}")
    except YamlError as exc:
        if exc.refused:
            raise _Refused(str(exc)) from None


@contextmanager
def _xacro_session(path: Path, find: Callable[[str], str]) -> Iterator[_XacroFiles]:
    """Xacro set up to expand ``path``, :data:`xacro_lock` held; everything is put back afterwards.

    Its file stack starts at the file (relative includes resolve against the including file's folder),
    ``open`` is :class:`_XacroFiles`, ``$(find)`` is ``find``.
    """
    import xacro
    from xacro import substitution_args

    files = _XacroFiles()
    with xacro_lock:
        saved = (xacro.__dict__.get("open"), xacro.filestack, xacro.macrostack, xacro.all_includes,
                 substitution_args._eval_find)  # fmt: skip
        xacro.open = files.open  # type: ignore[attr-defined]
        xacro.init_stacks(str(path.resolve()))
        xacro.all_includes = []
        substitution_args._eval_find = find
        try:
            yield files
        except BaseException:
            stack = [f for f in (xacro.filestack or []) if f]
            if stack and os.path.abspath(stack[-1]) != os.path.abspath(path):
                files.failed_in = stack[-1]  # the included file being read (its line is the error's)
            raise
        finally:
            if saved[0] is None:
                del xacro.open  # type: ignore[attr-defined]
            else:
                xacro.open = saved[0]  # type: ignore[attr-defined]
            xacro.filestack, xacro.macrostack, xacro.all_includes = saved[1], saved[2], saved[3]
            substitution_args._eval_find = saved[4]


def _read_robot_text(path: Path) -> str:
    """The text of the robot's own file: a regular UTF-8 file of at most MAX_DOCUMENT_BYTES."""
    try:
        return read_text(path, "robot file")
    except UnreadableFileError as exc:
        raise UrdfError(f"{path}: cannot be read ({exc.reason})") from None
    except InvalidInputError as exc:
        raise UrdfError(f"{path}: cannot be read ({exc})") from None


def read_robot_file(path: str | Path, package_path: PackagePath) -> str:
    """The URDF text of a robot file: read as is, or expanded when its name ends in ``.xacro``.

    Raises:
        UrdfError: unreadable file (missing, not a regular file, too large, not UTF-8), xacro error or
            missing package.
    """
    path = Path(path)
    if path.name.endswith(".xacro"):
        return package_path.expand_xacro(path)
    return _read_robot_text(path)
