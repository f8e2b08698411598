"""What urdfdom would refuse in a URDF, checked in Python first (private): the loader's pre-check.

urdfdom reports its reasons on the C-level stderr and Pinocchio then raises a generic ``ValueError``.
Capturing that stderr means redirecting file descriptor 2, which is process-wide state (another thread's
messages are lost, a crash leaves fd 2 on a temporary file). Instead, the rules urdfdom enforces are
checked here, on the parsed XML, with messages that name the element: urdfdom then only sees documents it
accepts.

The pre-check refuses exactly what ``pinocchio.buildModelFromXML`` refuses (tests/test_urdf_precheck.py runs
every rule on mutated documents through both), except where a rule of :data:`PRECHECK_RULES` says why it is
deliberately stricter: a document too large to load in bounded work; an ``<inertial>`` urdfdom would drop
(the link silently massless) or a negative mass it would keep; a ``<visual>`` or ``<collision>`` urdfdom
would drop, renumbering the link's others. What urdfdom reads and ignores (an inline ``<material>`` whose
``<color>`` it cannot parse, a global material without colour) loads, as it does in Pinocchio.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from ._checks import number_text
from .errors import UrdfError
from .limits import MAX_URDF_ELEMENTS

__all__ = [
    "PRECHECK_RULES",
    "PrecheckError",
    "PrecheckRule",
    "check_root",
    "check_urdf_tree",
    "urdfdom_ignores",
    "xacro_leftovers",
]

_JOINT_TYPES = frozenset(("revolute", "continuous", "prismatic", "fixed", "floating", "planar"))
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
# (element path below a link or joint, attribute, number of values); numbers urdfdom parses
_INERTIAL_NUMBERS = (
    ("inertial/origin", "xyz", 3), ("inertial/origin", "rpy", 3), ("inertial/mass", "value", 1),
    *(("inertial/inertia", a, 1) for a in _INERTIA),
)  # fmt: skip
_GEOMETRY_NUMBERS = (
    ("origin", "xyz", 3), ("origin", "rpy", 3), ("geometry/box", "size", 3), ("geometry/cylinder", "radius", 1),
    ("geometry/cylinder", "length", 1), ("geometry/sphere", "radius", 1), ("geometry/mesh", "scale", 3),
)  # fmt: skip
_JOINT_NUMBERS = (
    ("origin", "xyz", 3), ("origin", "rpy", 3), ("axis", "xyz", 3),
    *(("limit", a, 1) for a in ("lower", "upper", "effort", "velocity")),
    ("dynamics", "damping", 1), ("dynamics", "friction", 1),
    ("mimic", "multiplier", 1), ("mimic", "offset", 1),
)  # fmt: skip
_SHAPES = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",), "mesh": ("filename",)}


class PrecheckError(UrdfError):
    """A document the loader's pre-check refuses; ``rule``: the name of the rule of :data:`PRECHECK_RULES`."""

    def __init__(self, rule: str, message: str) -> None:
        self.rule = rule
        super().__init__(message)


@dataclass(frozen=True)
class PrecheckRule:
    """One rule of the pre-check.

    Attributes:
        name: its name (``PrecheckError.rule``).
        check: refuses (:class:`PrecheckError`) a parsed document that breaks it; ``(root, origin)``.
        stricter: None when urdfdom (so Pinocchio) refuses the same documents; else why the toolkit refuses
            documents urdfdom takes.
    """

    name: str
    check: Callable[[ET.Element, str], None]
    stricter: str | None = None


def _refuse(rule: str, origin: str, message: str) -> PrecheckError:
    return PrecheckError(rule, f"{origin}: not a valid URDF: {message}")


def _numbers(rule: str, el: ET.Element, attr: str, n: int, where: str, origin: str) -> None:
    raw = el.get(attr)
    if raw is None:
        return
    values = [number_text(p) for p in raw.split()]  # urdfdom's grammar: no "1_0", no "0x1"
    if len(values) != n or not all(math.isfinite(v) for v in values):
        what = "a finite number" if n == 1 else f"{n} finite numbers"
        raise _refuse(rule, origin, f"{where} {attr}={raw[:60]!r} must be {what}")


def _named(rule: str, elements: list[ET.Element], origin: str) -> None:
    """Each element named, no name twice (links, joints)."""
    seen: set[str] = set()
    for el in elements:
        name = el.get("name")
        if not name:
            raise _refuse(rule, origin, f"a <{el.tag}> has no name")
        if name in seen:
            raise _refuse(rule, origin, f"{el.tag} {name!r} is defined twice")
        seen.add(name)


def _joints(root: ET.Element) -> Iterator[tuple[str, ET.Element]]:
    return ((el.get("name", ""), el) for el in root.findall("joint"))


# ------------------------------------------------------------------------------------------ the rules
def check_root(root: ET.Element, origin: str) -> None:
    """Refuse a document whose root element is not ``<robot>`` (the first rule; the loader runs it first)."""
    if root.tag != "robot":
        raise PrecheckError("root", f"{origin}: the root element is <{root.tag}>, not <robot>")


def _size(root: ET.Element, origin: str) -> None:
    links, joints = len(root.findall("link")), len(root.findall("joint"))
    if links + joints > MAX_URDF_ELEMENTS:
        raise PrecheckError("size", f"{origin}: {links} links and {joints} joints, above the cap of "
                                    f"{MAX_URDF_ELEMENTS:,} elements; refused")  # fmt: skip


def _robot_name(root: ET.Element, origin: str) -> None:
    if not root.get("name"):
        raise _refuse("robot-name", origin, "the <robot> has no name")


def _materials(root: ET.Element, origin: str) -> None:
    seen: set[str] = set()
    for material in root.findall("material"):  # global ones; urdfdom ignores a colour it cannot read
        name = material.get("name", "")
        if name and name in seen:
            raise _refuse("material-unique", origin, f"material {name!r} is defined twice")
        seen.add(name)


def _link_names(root: ET.Element, origin: str) -> None:
    _named("link-name", root.findall("link"), origin)
    if root.find("link") is None:
        raise _refuse("link-name", origin, "the document has no <link> (a URDF has at least one; a xacro file of "
                                           "macros only defines them: call one, or load the file that does)")


def _inertial(root: ET.Element, origin: str) -> None:
    for link in root.findall("link"):
        where = f"link {link.get('name')}'s"
        for path, attr, n in _INERTIAL_NUMBERS:
            for sub in link.findall(path):
                _numbers("inertial", sub, attr, n, f"{where} <{path}>", origin)
        for inertial in link.findall("inertial"):
            for part in ("mass", "inertia"):
                if inertial.find(part) is None:
                    raise _refuse("inertial", origin, f"{where} <inertial> has no <{part}>")
            inertia = inertial.find("inertia")
            missing = [a for a in _INERTIA if inertia is not None and a not in inertia.attrib]
            if missing:
                raise _refuse("inertial", origin, f"{where} <inertia> has no {', '.join(missing)}")
        mass = link.find("inertial/mass")
        if mass is not None and float(mass.get("value", "0")) < 0:
            raise _refuse("inertial", origin, f"{where} mass {mass.get('value')} must be >= 0")


def _geometry(root: ET.Element, origin: str) -> None:
    for link in root.findall("link"):
        for part in ("visual", "collision"):
            for item in link.findall(part):
                where = f"link {link.get('name')}'s <{part}>"
                for path, attr, n in _GEOMETRY_NUMBERS:
                    for sub in item.findall(path):
                        _numbers("geometry", sub, attr, n, where, origin)
                geometry = item.find("geometry")
                shapes = [] if geometry is None else list(geometry)
                if len(shapes) != 1 or shapes[0].tag not in _SHAPES:
                    found = ", ".join(f"<{c.tag}>" for c in shapes) or "nothing"
                    raise _refuse("geometry", origin, f"{where} <geometry> must hold one of <box>, <cylinder>, "
                                                      f"<sphere>, <mesh>; it holds {found}")  # fmt: skip
                for attr in _SHAPES[shapes[0].tag]:
                    if shapes[0].get(attr) is None:
                        raise _refuse("geometry", origin, f"{where} <{shapes[0].tag}> has no {attr}")
                material = item.find("material")
                if part == "visual" and material is not None and not material.get("name"):
                    raise _refuse("geometry", origin, f"{where} <material> has no name")


def _joint_names(root: ET.Element, origin: str) -> None:
    _named("joint-name", root.findall("joint"), origin)


def _joint_types(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        if el.get("type") not in _JOINT_TYPES:
            raise _refuse("joint-type", origin, f"joint {name} has type {el.get('type')!r}")


def _joint_links(root: ET.Element, origin: str) -> None:
    links = {el.get("name") for el in root.findall("link")}
    for name, el in _joints(root):
        for role in ("parent", "child"):
            tag = el.find(role)
            link = None if tag is None else tag.get("link")
            if not link:
                raise _refuse("joint-links", origin, f"joint {name} has no {role} link")
            if link not in links:
                raise _refuse("joint-links", origin, f"joint {name}'s {role} link {link!r} is not defined")


def _joint_numbers(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        for path, attr, n in _JOINT_NUMBERS:
            for sub in el.findall(path):
                _numbers("joint-numbers", sub, attr, n, f"joint {name}'s <{path}>", origin)


def _joint_limits(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        kind = el.get("type")
        limit = el.find("limit")
        if kind in ("revolute", "prismatic") and (limit is None or limit.get("effort") is None
                                                  or limit.get("velocity") is None):  # fmt: skip
            raise _refuse("joint-limit", origin, f"{kind} joint {name} needs <limit> with effort and velocity")


def _mimic_joint(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        mimic = el.find("mimic")
        if mimic is not None and not mimic.get("joint"):
            raise _refuse("mimic-joint", origin, f"joint {name}'s <mimic> names no joint (joint=...)")


def _tree(root: ET.Element, origin: str) -> None:
    parent_of: dict[str, str] = {}
    for name, el in _joints(root):
        child = el.find("child").get("link")  # type: ignore[union-attr]  # (joint-links ran first)
        if child in parent_of:
            raise _refuse("tree", origin, f"link {child!r} is the child of joints {parent_of[child]} and {name}")
        parent_of[child] = name  # type: ignore[index]
    links = root.findall("link")
    roots = [str(el.get("name")) for el in links if el.get("name") not in parent_of]
    if len(roots) != 1 and links:
        shown = ", ".join(roots[:5]) + (" ..." if len(roots) > 5 else "")
        raise _refuse("tree", origin, f"{len(roots)} root links ({shown or 'none: a cycle'}); a URDF tree has "
                                      "exactly one root link")  # fmt: skip


PRECHECK_RULES: tuple[PrecheckRule, ...] = (
    PrecheckRule("root", check_root),
    PrecheckRule("size", _size, "the work is bounded: a document above MAX_URDF_ELEMENTS links and joints is refused "
                                "before any is done"),
    PrecheckRule("robot-name", _robot_name),
    PrecheckRule("material-unique", _materials),
    PrecheckRule("link-name", _link_names),
    PrecheckRule("inertial", _inertial, "urdfdom drops an <inertial> it cannot read (the link then has no mass) and "
                                        "keeps a negative mass: torques, payloads and timing would be silently wrong"),
    PrecheckRule("geometry", _geometry, "urdfdom drops a <visual> or <collision> it cannot read (a shape, a number, "
                                        "a nameless material), renumbering the link's others, by which the viewer "
                                        "pairs its meshes with Pinocchio's geometry: meshes on the wrong parts"),
    PrecheckRule("joint-name", _joint_names),
    PrecheckRule("joint-type", _joint_types),
    PrecheckRule("joint-links", _joint_links),
    PrecheckRule("joint-numbers", _joint_numbers),
    PrecheckRule("joint-limit", _joint_limits),
    PrecheckRule("mimic-joint", _mimic_joint),
    PrecheckRule("tree", _tree),
)  # fmt: skip
"""The pre-check's rules, in the order they run (the first broken one refuses the document)."""


def _colour_problem(color: ET.Element) -> str | None:
    """Why urdfdom cannot read a ``<color>``: ``"no rgba"`` (``rgb=`` is not URDF), ``"malformed"``, or None."""
    raw = color.get("rgba")
    if raw is None:
        return "no rgba"
    pieces = [number_text(p) for p in raw.split()]
    if not all(0.0 <= v <= 1.0 for v in pieces):  # NaN fails too: urdfdom throws and says so
        return "malformed"
    return None if len(pieces) == 4 else "no rgba"  # a wrong count: read as no colour, silently


def urdfdom_ignores(root: ET.Element) -> list[str]:
    """Remove from ``root`` the colours urdfdom reads, ignores and complains about on its C-level stderr; say which.

    urdfdom keeps such a document (so does the pre-check: what Pinocchio loads, loads) but writes lines to file
    descriptor 2. It drops: a global ``<material>`` without a name, or whose colour it cannot read and that has
    no texture file (the visuals naming it keep their own empty material); a ``<color>`` whose ``rgba`` has
    a component that is not a number in [0, 1] (malformed). An inline colour without ``rgba`` (``rgb=``, a
    common slip) it drops quietly. Removing them first changes nothing in the model and keeps the terminal
    clean; the loader warns once instead, naming them.

    Returns:
        One phrase per element removed (``material 'grey' (no rgba)``), in document order.
    """
    out = []
    for material in root.findall("material"):  # global: a readable colour or a texture file
        name, color, texture = material.get("name"), material.find("color"), material.find("texture")
        textured = texture is not None and bool(texture.get("filename"))
        problem = "no name" if not name else (_colour_problem(color) if color is not None else "no <color>")
        if problem == "malformed" and color is not None:  # complained about, texture or not
            material.remove(color)
        elif problem in ("no rgba", "no <color>") and textured:  # the texture is its definition
            problem = None
        if problem is not None:
            if not (name and textured):
                root.remove(material)
            out.append(f"material {name!r} ({problem})" if name else "a nameless <material>")
    for visual in root.iter("visual"):  # inline: ignored quietly without rgba, with a complaint when malformed
        for material in visual.findall("material"):
            for color in material.findall("color"):
                problem = _colour_problem(color)
                if problem is not None:
                    material.remove(color)
                    written = " ".join(f"{k}={v[:40]!r}" for k, v in color.attrib.items()) or "nothing"
                    out.append(f"material {material.get('name')!r}'s <color {written}> ({problem})")
    return out


def check_urdf_tree(root: ET.Element, origin: str) -> None:
    """Refuse (:class:`PrecheckError`) what urdfdom would refuse, and what :data:`PRECHECK_RULES` refuses on purpose.

    Links: named, unique, inertial numbers finite (mass >= 0), visuals and collisions readable. Joints:
    named, unique, a known type, parent and child links that exist, limits with effort and velocity where
    required, numbers finite, a ``<mimic>`` naming its joint. The tree: one root link, each link the child of
    at most one joint (hence no cycle). Global materials: no name twice. At most
    :data:`~scara_pin.limits.MAX_URDF_ELEMENTS` links and joints.
    """
    for rule in PRECHECK_RULES:
        rule.check(root, origin)


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
