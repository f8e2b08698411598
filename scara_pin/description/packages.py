"""ROS-style packages without ROS: ``$(find pkg)`` in a user's xacro and ``package://pkg/...`` file names.

A package is a folder holding a ``package.xml`` (its ``<name>`` names it). Packages are searched, first to
last, in:

1. the ``--package-path`` folders (each a folder holding packages, searched recursively as ``rospack``
   does);
2. the folders above the robot's file (its own package, when the file lives in one);
3. ``AMENT_PREFIX_PATH`` (ROS 2: ``<prefix>/share/<pkg>``) and ``ROS_PACKAGE_PATH`` (ROS 1).

The search and the xacro expansion are xacrodoc's (which resolves packages without a ROS installation).

Security: expanding a xacro file runs the expressions written in it (``${...}``, ``$(eval ...)``): only
the user's own files are expanded, never text from the command line (no ``--set`` into a user's xacro).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import UrdfError

__all__ = ["PackagePath", "read_robot_file"]


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

    def _configure(self) -> Any:
        """Set xacrodoc's package finder (module-wide, used by ``$(find)``) to this search order."""
        from xacrodoc import packages

        packages.reset()  # its default: ament_index (if importable) or rospkg on ROS_PACKAGE_PATH
        ros, ament = self._env_dirs()
        # look_in / walk_up_from insert at the front: add the last searched first
        if ros:
            packages.look_in([str(p) for p in ros])
        if ament:
            packages.look_in([str(p) for p in ament])
        if self.origin_dir is not None:
            packages.walk_up_from(self.origin_dir)
        if self.dirs:
            packages.look_in([str(p) for p in self.dirs])
        return packages

    def _not_found(self, package: str) -> UrdfError:
        where = ", ".join(str(d) for d in self.dirs) or "none given"
        return UrdfError(f"package {package!r} not found (searched: --package-path {where}; the folders above "
                         f"{self.origin_dir or 'the file'}; ROS_PACKAGE_PATH; AMENT_PREFIX_PATH): "
                         "add its parent folder with --package-path DIR")  # fmt: skip

    def find(self, package: str) -> Path:
        """The folder of a package.

        Raises:
            UrdfError: no such package (the message names it and where it was looked for).
        """
        packages = self._configure()
        try:
            return Path(packages.get_path(package)).resolve()
        except packages.PackageNotFoundError:
            raise self._not_found(package) from None
        except Exception as exc:  # rospkg's ResourceNotFound escapes xacrodoc in some set-ups; a bad package.xml
            raise UrdfError(f"package {package!r}: {exc}") from None

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

        Raises:
            UrdfError: a missing package, or xacro's own error (one line).
        """
        from xacro import XacroException
        from xacrodoc import XacroDoc

        packages = self._configure()
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise UrdfError(f"{path}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
        try:
            doc = XacroDoc.from_string(text, resolve_packages=False, rootdir=path.parent)
        except packages.PackageNotFoundError as exc:
            raise self._not_found(exc.args[0] if exc.args else "?") from None
        except Exception as exc:  # xacro raises plain Python errors for bad expressions, XML errors...
            # a missing package wrapped by xacro (xacrodoc 2.0.0 raises its own copy of XacroException)
            missing = getattr(exc, "exc", None) or exc.__context__
            if isinstance(missing, packages.PackageNotFoundError):
                raise self._not_found(missing.args[0] if missing.args else "?") from None
            if isinstance(exc, XacroException):
                raise UrdfError(f"{path}: xacro: {' '.join(str(exc).split())}") from None
            raise UrdfError(f"{path}: xacro: {type(exc).__name__}: {' '.join(str(exc).split())}") from None
        return str(doc.dom.toprettyxml(indent="  "))


def read_robot_file(path: str | Path, package_path: PackagePath) -> str:
    """The URDF text of a robot file: read as is, or expanded when its name ends in ``.xacro``.

    Raises:
        UrdfError: unreadable file, xacro error or missing package.
    """
    path = Path(path)
    if path.name.endswith(".xacro"):
        return package_path.expand_xacro(path)
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise UrdfError(f"{path}: cannot be read ({getattr(exc, 'strerror', None) or exc})") from None
