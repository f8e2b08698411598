"""What urdfdom would refuse in a URDF, checked in Python first (private).

urdfdom reports its reasons on the C-level stderr and Pinocchio then raises a generic ``ValueError``.
Capturing that stderr means redirecting file descriptor 2, which is process-wide state (another thread's
messages are lost, a crash leaves fd 2 on a temporary file). Instead, the rules urdfdom enforces are
checked here, on the parsed XML, with messages that name the element: urdfdom then only sees documents it
accepts. The size is bounded too (:data:`scara_pin.limits.MAX_URDF_ELEMENTS`).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

from ._checks import number_text
from .errors import UrdfError
from .limits import MAX_URDF_ELEMENTS

_JOINT_TYPES = frozenset(("revolute", "continuous", "prismatic", "fixed", "floating", "planar"))
# (element path below a link or joint, attribute, number of values); numbers urdfdom parses
_LINK_NUMBERS = (
    ("inertial/origin", "xyz", 3), ("inertial/origin", "rpy", 3), ("inertial/mass", "value", 1),
    *(("inertial/inertia", a, 1) for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")),
    *((f"{part}/origin", a, 3) for part in ("visual", "collision") for a in ("xyz", "rpy")),
    *((f"{part}/geometry/box", "size", 3) for part in ("visual", "collision")),
    *((f"{part}/geometry/{shape}", a, 1) for part in ("visual", "collision")
      for shape, a in (("cylinder", "radius"), ("cylinder", "length"), ("sphere", "radius"))),
    *((f"{part}/geometry/mesh", "scale", 3) for part in ("visual", "collision")),
)  # fmt: skip
_JOINT_NUMBERS = (
    ("origin", "xyz", 3), ("origin", "rpy", 3), ("axis", "xyz", 3),
    *(("limit", a, 1) for a in ("lower", "upper", "effort", "velocity")),
    ("dynamics", "damping", 1), ("dynamics", "friction", 1),
    ("mimic", "multiplier", 1), ("mimic", "offset", 1),
)  # fmt: skip


def _numbers(el: ET.Element, attr: str, n: int, where: str, origin: str) -> None:
    raw = el.get(attr)
    if raw is None:
        return
    values = [number_text(p) for p in raw.split()]  # urdfdom's grammar: no "1_0", no "0x1"
    if len(values) != n or not all(math.isfinite(v) for v in values):
        rule = "a finite number" if n == 1 else f"{n} finite numbers"
        raise UrdfError(f"{origin}: not a valid URDF: {where} {attr}={raw[:60]!r} must be {rule}")


_SHAPES = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",), "mesh": ("filename",)}


def _geometry(geometry: ET.Element | None, where: str, origin: str) -> None:
    """One known shape with its attributes (urdfdom drops the element, with its own stderr lines, otherwise)."""
    shapes = [] if geometry is None else list(geometry)
    if len(shapes) != 1 or shapes[0].tag not in _SHAPES:
        found = ", ".join(f"<{c.tag}>" for c in shapes) or "nothing"
        raise UrdfError(f"{origin}: not a valid URDF: {where} <geometry> must hold one of <box>, <cylinder>, "
                        f"<sphere>, <mesh>; it holds {found}")  # fmt: skip
    for attr in _SHAPES[shapes[0].tag]:
        if shapes[0].get(attr) is None:
            raise UrdfError(f"{origin}: not a valid URDF: {where} <{shapes[0].tag}> has no {attr}")


def _unique_name(el: ET.Element, seen: set[str], origin: str) -> str:
    """The ``name`` of a <link> or <joint>: present, and not seen before among its kind (then recorded)."""
    name = el.get("name")
    if not name:
        raise UrdfError(f"{origin}: not a valid URDF: a <{el.tag}> has no name")
    if name in seen:
        raise UrdfError(f"{origin}: not a valid URDF: {el.tag} {name!r} is defined twice")
    seen.add(name)
    return name


def check_urdf_tree(root: ET.Element, origin: str) -> None:
    """Refuse (:class:`UrdfError`) what urdfdom would refuse, with a message naming the element.

    Links: named, unique, numbers finite (mass >= 0). Joints: named, unique, a known type, parent and
    child links that exist, limits with effort and velocity where required, numbers finite. The tree: one
    root link, each link the child of at most one joint (hence no cycle). At most
    :data:`~scara_pin.limits.MAX_URDF_ELEMENTS` links and joints.
    """
    links = root.findall("link")
    joints = root.findall("joint")
    if len(links) + len(joints) > MAX_URDF_ELEMENTS:
        raise UrdfError(f"{origin}: {len(links)} links and {len(joints)} joints, above the cap of "
                        f"{MAX_URDF_ELEMENTS:,} elements; refused")  # fmt: skip
    for material in root.findall("material"):  # a global one defines a colour or a texture
        if material.find("color") is None and material.find("texture") is None:
            raise UrdfError(f"{origin}: not a valid URDF: material {material.get('name')!r} has neither <color> "
                            "nor <texture>")  # fmt: skip
    for color in root.iter("color"):  # in global and inline <material>s
        if color.get("rgba") is None:
            raise UrdfError(f"{origin}: not a valid URDF: a <material>'s <color> has no rgba")
        _numbers(color, "rgba", 4, "a <material>'s <color>", origin)
        if not all(0.0 <= number_text(v) <= 1.0 for v in color.get("rgba", "0 0 0 0").split()):
            raise UrdfError(f"{origin}: not a valid URDF: a <material>'s <color> rgba={color.get('rgba')!r} "
                            "must be 4 numbers in [0, 1]")  # fmt: skip
    names: set[str] = set()
    for el in links:
        name = _unique_name(el, names, origin)
        for path, attr, n in _LINK_NUMBERS:
            for sub in el.findall(path):
                _numbers(sub, attr, n, f"link {name}'s <{path}>", origin)
        for inertial in el.findall("inertial"):
            for part in ("mass", "inertia"):
                if inertial.find(part) is None:
                    raise UrdfError(f"{origin}: not a valid URDF: link {name}'s <inertial> has no <{part}>")
        for part in ("visual", "collision"):
            for item in el.findall(part):
                _geometry(item.find("geometry"), f"link {name}'s <{part}>", origin)
        mass = el.find("inertial/mass")
        if mass is not None and float(mass.get("value", "0")) < 0:
            raise UrdfError(f"{origin}: not a valid URDF: link {name}'s mass {mass.get('value')} must be >= 0")
    seen: set[str] = set()
    parent_of: dict[str, str] = {}
    for el in joints:
        name = _unique_name(el, seen, origin)
        kind = el.get("type")
        if kind not in _JOINT_TYPES:
            raise UrdfError(f"{origin}: not a valid URDF: joint {name} has type {kind!r}")
        for role in ("parent", "child"):
            tag = el.find(role)
            link = None if tag is None else tag.get("link")
            if not link:
                raise UrdfError(f"{origin}: not a valid URDF: joint {name} has no {role} link")
            if link not in names:
                raise UrdfError(f"{origin}: not a valid URDF: joint {name}'s {role} link {link!r} is not defined")
        child = el.find("child").get("link")  # type: ignore[union-attr]
        if child in parent_of:
            raise UrdfError(f"{origin}: not a valid URDF: link {child!r} is the child of joints {parent_of[child]} "
                            f"and {name}")  # fmt: skip
        parent_of[child] = name  # type: ignore[index]
        for path, attr, n in _JOINT_NUMBERS:
            for sub in el.findall(path):
                _numbers(sub, attr, n, f"joint {name}'s <{path}>", origin)
        if kind in ("revolute", "prismatic"):
            limit = el.find("limit")
            if limit is None or limit.get("effort") is None or limit.get("velocity") is None:
                raise UrdfError(f"{origin}: not a valid URDF: {kind} joint {name} needs <limit> with effort and "
                                "velocity")  # fmt: skip
    roots = [str(el.get("name")) for el in links if el.get("name") not in parent_of]
    if len(roots) != 1 and links:
        shown = ", ".join(roots[:5]) + (" ..." if len(roots) > 5 else "")
        raise UrdfError(f"{origin}: not a valid URDF: {len(roots)} root links ({shown or 'none: a cycle'}); "
                        "a URDF tree has exactly one root link")  # fmt: skip


_XACRO_NAMESPACES = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro", "http://wiki.ros.org/xacro")
_INERT_XACRO = frozenset(("property", "arg"))
"""xacro declarations that change nothing in a document that never substitutes them (no ``${``, ``$(``)."""


def _xacro_name(tag: str) -> str | None:
    """``property`` for ``xacro:property`` (a parser without namespaces) or ``{ns}property``; else None."""
    if tag.startswith("xacro:"):
        return tag[6:]
    if tag.startswith("{"):
        ns, _, local = tag[1:].partition("}")
        if ns in _XACRO_NAMESPACES:
            return local
    return None


def xacro_leftovers(root: ET.Element) -> tuple[bool, str, ET.Element] | None:
    """Xacro in a document read as URDF: the rule the loader and ``scara-pin check`` share.

    A URDF file (not named ``.xacro``) is read as written, never expanded. xacro left in it is

    - harmless when it is only declarations (``<xacro:property>``, ``<xacro:arg>``) that the document never
      substitutes (no ``${...}`` nor ``$(...)`` in any attribute): they are ignored, with a warning;
    - an error otherwise (a macro call, ``<xacro:if>``, an include, a substitution): read as written, the
      file would be a different robot (or no robot), so it must be expanded first.

    Returns:
        None when the document holds no xacro, else ``(blocking, message, first element concerned)``.
    """
    found: list[tuple[str, ET.Element]] = []
    substituted: ET.Element | None = None
    for el in root.iter():
        name = _xacro_name(el.tag) if isinstance(el.tag, str) else None
        if name is not None:
            found.append((name, el))
        elif substituted is None and any("${" in v or "$(" in v for v in el.attrib.values()):
            substituted = el
    if not found and substituted is None:
        return None
    counts: dict[str, int] = {}
    for name, _ in found:
        counts[name] = counts.get(name, 0) + 1
    listing = ", ".join(f"{n} <xacro:{k}>" for k, n in counts.items())
    if substituted is not None:
        attr, value = next((a, v) for a, v in substituted.attrib.items() if "${" in v or "$(" in v)
        return True, (f"<{substituted.tag}> {attr}={value[:60]!r} is a xacro substitution: this is a xacro document; "
                      "expand it first (name it .xacro, or run xacro)"), substituted  # fmt: skip
    if set(counts) <= _INERT_XACRO:
        return False, (f"{listing} declared but never substituted (no ${{...}} in the document): ignored, the "
                       "file is read as plain URDF"), found[0][1]  # fmt: skip
    name, el = next((n, e) for n, e in found if n not in _INERT_XACRO)
    return True, (f"<xacro:{name}> found ({listing}): this is a xacro document; expand it first (name it .xacro, "
                  "or run xacro)"), el  # fmt: skip
