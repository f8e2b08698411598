"""Rules of the links' geometry: inertial numbers and the meshes the viewer draws.

Each rule is a function of the :class:`~scara_pin.lint.context.Context`; its code and place in the run are in
:data:`scara_pin.lint.registry.RULES`.
"""

from __future__ import annotations

import copy
import math

from .._checks import number_text
from .._urdf_checks import urdfdom_ignores
from .context import Context
from .report import Severity

__all__ = ["bad_inertial", "colour_ignored", "mesh_missing", "mesh_path"]

_INERTIAL = (("mass", ("value",)), ("inertia", ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")))


def bad_inertial(ctx: Context) -> None:
    """A link's mass or inertia that is not finite (NaN would poison every torque), or a negative mass."""
    doc = ctx.document
    for name, el in doc.links:
        inertial = el.find("inertial")
        if inertial is None:
            continue
        for what, attrs in _INERTIAL:
            part = inertial.find(what)
            for attr in attrs if part is not None else ():
                raw = part.get(attr)  # type: ignore[union-attr]
                if raw is None:
                    continue
                value = number_text(raw)
                if not math.isfinite(value) or (what == "mass" and value < 0):
                    rule = "must be a finite number >= 0" if what == "mass" else "must be a finite number"
                    ctx.error("bad-inertial", f"link {name or '?'}'s {what} {attr}={raw!r} {rule}", doc.line(el))


def _visual_meshes(ctx: Context) -> tuple[dict[str, list[str]], dict[str, int | None]]:
    """Each visual mesh file name: the links naming it, and the line of its first ``<mesh>``."""
    doc = ctx.document
    links: dict[str, list[str]] = {}
    first: dict[str, int | None] = {}
    for name, el in doc.links:
        for mesh in el.findall("visual/geometry/mesh"):
            filename = mesh.get("filename", "")
            links.setdefault(filename, []).append(name or "?")
            first.setdefault(filename, doc.line(mesh))
    return links, first


def _shown(names: list[str]) -> str:
    return ", ".join(names[:6]) + (f" and {len(names) - 6} more" if len(names) > 6 else "")


def mesh_missing(ctx: Context) -> None:
    """A visual's mesh the viewer cannot find or may not read (it draws a box instead).

    Found by the viewer's own resolver (:func:`scara_pin.description.mesh_paths.mesh_file`), for a file
    (``check_urdf_file``: the package folders known); one finding per file name, naming its links.
    """
    from ..description.mesh_paths import MeshProblem, mesh_file

    packages = ctx.load_kwargs.get("package_path")
    if packages is None:  # URDF text without a file: nowhere to look relative names up
        return
    links, first = _visual_meshes(ctx)
    for filename, names in links.items():
        try:
            mesh_file(filename, packages, warn=False)
        except MeshProblem as exc:
            ctx.add(Severity.WARNING, "mesh-missing", f"{exc}: the viewer draws link {_shown(names)} as a placeholder "
                    "box", first[filename])  # fmt: skip


def mesh_path(ctx: Context) -> None:
    """A mesh named PyBullet's way (``/Mesh/Visual/Base.stl``, absolute but missing): read from the file's folder."""
    from ..description.mesh_paths import pybullet_path

    packages = ctx.load_kwargs.get("package_path")
    if packages is None:
        return
    links, first = _visual_meshes(ctx)
    for filename, names in links.items():
        beside = pybullet_path(filename, packages)
        if beside is not None:
            ctx.add(Severity.WARNING, "mesh-path", f"mesh {filename!r} does not exist as written: the viewer reads "
                    f"{beside} for link {_shown(names)}, relative to the file's folder (PyBullet's rule)",
                    first[filename])  # fmt: skip


def colour_ignored(ctx: Context) -> None:
    """Colours urdfdom cannot read and ignores (``rgb=``, a malformed ``rgba``): the loader's rule, said once."""
    ignored = urdfdom_ignores(copy.deepcopy(ctx.parsed[0]))
    if ignored:
        ctx.add(Severity.WARNING, "colour-ignored", f"colours URDF cannot read, ignored by urdfdom and the toolkit "
                f"(a colour is <color rgba=\"r g b a\"/>, each in [0, 1]): {_shown(ignored)}")  # fmt: skip
