"""Where a URDF ``<mesh filename=...>`` is: the resolver the viewer and ``scara-pin check`` share.

A mesh's name is ``package://pkg/path`` (looked up as :mod:`scara_pin.description.packages` says:
``--package-path``, the folders above the robot's file, ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH``),
``file:///abs/path``, an absolute path or a path relative to the robot's file. Rules:

- no network: any other scheme (``http://``, ``https://``, ...) is refused;
- no escape: the resolved file (symbolic links followed) must lie inside the package it names, or for other
  names inside one of the package folders searched or the robot file's folder;
- PyBullet's way: an absolute name that does not exist (``/Mesh/Visual/Base.stl``, as CAD exporters for
  PyBullet write them) is read relative to the robot file's folder when the file is there, with a warning
  saying so (:func:`pybullet_path`).

The viewer reads the meshes (:mod:`scara_pin.cell.meshes`); ``check`` only says which are missing or refused
(:func:`mesh_file`), from this same module, below the viewer's layer.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .packages import PackagePath

__all__ = ["MeshProblem", "mesh_file", "pybullet_path", "resolve_mesh"]


class MeshProblem(Exception):
    """Why a mesh is not drawn (the message names the file); reported as a warning, never raised to users."""


def _inside(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def pybullet_path(filename: str, packages: PackagePath) -> Path | None:
    """The file an absolute mesh name that does not exist means in PyBullet's reading, or None.

    PyBullet tries a mesh name as written, then prefixed with the URDF's folder: ``/Mesh/Visual/Base.stl`` is
    ``<the file's folder>/Mesh/Visual/Base.stl`` when that file exists and the absolute one does not.
    """
    raw = Path(filename)
    if "://" in filename or not raw.is_absolute() or packages.origin_dir is None or raw.exists():
        return None
    beside = packages.origin_dir / filename.lstrip("/")
    return beside if beside.is_file() else None


def resolve_mesh(filename: str, packages: PackagePath, *, warn: bool = True) -> Path:
    """The file a URDF mesh name refers to, within the allowed folders (see the module docstring).

    ``warn``: log the warning of a name read PyBullet's way (:func:`pybullet_path`), once per robot (``check``
    says it as a finding instead).

    Raises:
        MeshProblem: a network or unknown scheme, a missing package, a path out of the allowed folders.
    """
    from ..errors import UrdfError

    beside = pybullet_path(filename, packages)
    if beside is not None:
        note = (f"mesh {filename!r} does not exist: read as {beside}, relative to the robot file's folder "
                "(PyBullet's rule)")
        if warn and packages.first_time(note):
            import logging

            logging.getLogger("scara_pin").warning("%s", note)
        filename = str(beside)

    scheme, sep, rest = filename.partition("://")
    if not sep:
        scheme, rest = "", filename
    if scheme == "package":
        package, _, relative = rest.partition("/")
        try:
            folder = packages.find(package)
        except UrdfError as exc:
            raise MeshProblem(f"mesh {filename!r}: {exc}") from None
        path = (folder / relative).resolve()
        if not _inside(path, folder):
            raise MeshProblem(f"mesh {filename!r} leaves its package folder {folder}: not read")
        return path
    if scheme not in ("", "file"):
        raise MeshProblem(f"mesh {filename!r}: the {scheme}:// scheme is not supported (no file is fetched "
                          "from the network): not read")  # fmt: skip
    raw = Path(rest)
    if not raw.is_absolute():
        if packages.origin_dir is None:
            raise MeshProblem(f"mesh {filename!r} is relative but the robot has no file to resolve it from")
        raw = packages.origin_dir / raw
    path = raw.resolve()
    roots = packages.roots()
    if not any(_inside(path, root) for root in roots):
        raise MeshProblem(f"mesh {filename!r} is outside the package folders and the robot file's folder "
                          f"({', '.join(str(r) for r in roots) or 'none'}): not read")  # fmt: skip
    return path


def mesh_file(filename: str, packages: PackagePath, *, warn: bool = True) -> Path:
    """The existing file a mesh name refers to (:func:`resolve_mesh`, then the file must exist).

    Raises:
        MeshProblem: no filename, refused (scheme, escape), a missing package, or no such file.
    """
    if not filename:
        raise MeshProblem("a <mesh> has no filename")
    path = resolve_mesh(filename, packages, warn=warn)
    if not path.is_file():
        what = "is not a regular file (a device, FIFO, socket or folder)" if path.exists() else "does not exist"
        raise MeshProblem(f"mesh {filename!r}: {path} {what}")
    return path
