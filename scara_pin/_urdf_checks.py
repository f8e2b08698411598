"""What urdfdom would refuse in a URDF, checked in Python first (private): the loader's pre-check.

urdfdom reports its reasons on the C-level stderr and Pinocchio then raises a generic ``ValueError`` ("The XML
stream does not contain a valid URDF model."). Capturing that stderr means redirecting file descriptor 2,
which is process-wide state. Instead, urdfdom's parser is mirrored here, on the parsed XML, with messages
that name the element, the attribute and the value: urdfdom then only sees documents it accepts.

The mirror follows urdfdom as Pinocchio 4.1 ships it (tests/test_urdf_differential.py runs it against
``pinocchio.buildModelFromXML`` and ``buildGeomFromUrdfString`` on a corpus and its mutations):

- numbers: :func:`urdf_number` and :func:`urdf_vector` (a C++ stream reading a double: blanks before, none
  after; vectors split at spaces only; no ``inf``, ``nan``, ``0x``, ``1_0``);
- only the FIRST child of a kind is read where urdfdom reads one (``<origin>``, ``<limit>``, ``<axis>``,
  ``<mimic>``, ``<inertial>``, ``<geometry>`` and its first element): a second one, or an unknown tag after
  the shape, is ignored by both;
- names: a ``name`` attribute must be there, and may be empty (``<robot name="">``, ``<joint name="">``,
  ``<material name="">``, as in the Dobot MG400 and Kawasaki duAro descriptions);
- a fixed (or floating) joint's ``<axis>`` is never read.

The pre-check refuses exactly what urdfdom refuses, except where a rule of :data:`PRECHECK_RULES` says why it
is deliberately stricter, and says in its message what urdfdom would do instead: a document too large to
load in bounded work; an ``<inertial>``, a ``<visual>`` or a ``<collision>`` urdfdom cannot read (it stops
reading the link there: a partial inertia, and Pinocchio then loads none of the link's visuals and collisions,
or none of its collisions) or a negative mass (kept); a link that is the child of two joints (urdfdom keeps
one, Pinocchio builds its branch twice). What urdfdom reads and
ignores (an inline ``<material>`` whose ``<color>`` it cannot parse, a global material without colour)
loads, as it does in Pinocchio.
"""

from __future__ import annotations

import collections
import contextlib
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from dataclasses import dataclass

from .limits import MAX_URDF_ELEMENTS
from .units import NUMBER_TEXT
from .urdf_rules import UrdfRuleError

__all__ = [
    "PRECHECK_RULES",
    "PrecheckError",
    "PrecheckRule",
    "check_root",
    "check_urdf_tree",
    "parse_urdf_xml",
    "second_parents",
    "urdf_number",
    "urdf_vector",
    "urdfdom_ignores",
    "xacro_leftovers",
]

_JOINT_TYPES = frozenset(("revolute", "continuous", "prismatic", "fixed", "floating", "planar"))
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_SHAPES = {"box": (("size", 3),), "cylinder": (("length", 1), ("radius", 1)), "sphere": (("radius", 1),),
           "mesh": (("filename", 0), ("scale", -3))}  # fmt: skip
"""urdfdom's shapes and their attributes: (name, count); 0 text, a negative count an optional vector."""
_BLANKS = " \t\n\v\f\r"  # what a C++ stream skips before a number (isspace in the C locale)
_VERSIONS = ((1, 0), (1, 1), (1, 2))
"""The URDF versions Pinocchio's urdfdom reads (``<robot version="...">``; absent: 1.0)."""


# ------------------------------------------------------------------------------------ urdfdom's numbers
def urdf_number(text: str) -> float | None:
    """A number as urdfdom reads one (``strToDouble``), or None when it refuses the text.

    A C++ stream in the C locale: blanks before the number are skipped, nothing may follow it (``"1 "`` is
    refused), ASCII digits with an optional sign, point and exponent (:data:`scara_pin.units.NUMBER_TEXT`),
    no ``inf``/``nan``, and a value beyond the largest double is refused.
    """
    stripped = text.lstrip(_BLANKS)
    if not NUMBER_TEXT.fullmatch(stripped):
        return None
    value = float(stripped)
    return value if math.isfinite(value) else None


def urdf_vector(text: str, n: int = 3) -> tuple[float, ...] | None:
    """``n`` numbers as urdfdom reads a vector (split at spaces only, each by :func:`urdf_number`), or None."""
    values = [urdf_number(piece) for piece in text.split(" ") if piece]
    if len(values) != n or any(v is None for v in values):
        return None
    return tuple(values)  # type: ignore[arg-type]


def _number_problem(raw: str, n: int) -> str:
    """Why urdfdom refuses ``raw`` as ``n`` numbers (one, when ``n`` is 1), in a phrase."""
    pieces = [raw] if n == 1 else [p for p in raw.split(" ") if p]
    for piece in pieces:
        if urdf_number(piece) is not None:
            continue
        core = piece.lstrip(_BLANKS)
        if core and core[-1] in _BLANKS and urdf_number(core.rstrip(_BLANKS)) is not None:
            return "a blank after a number (urdfdom reads nothing after it)"
        if n > 1 and any(c in piece for c in _BLANKS):
            return "numbers separated by a tab or a line break (urdfdom separates them by spaces only)"
        if NUMBER_TEXT.fullmatch(core):
            return f"{core[:40]!r} is beyond the largest double"
        return f"{core[:40]!r} is not a number (ASCII digits, a sign, a point, an exponent)" if core else \
            "no number"  # fmt: skip
    return f"{len(pieces)} number{'s' if len(pieces) != 1 else ''}: urdfdom reads {n} finite number{'s' * (n > 1)} here"


class PrecheckError(UrdfRuleError):
    """A document the loader's pre-check refuses; ``rule``: the name of the rule of :data:`PRECHECK_RULES`."""


@dataclass(frozen=True)
class PrecheckRule:
    """One rule of the pre-check.

    Attributes:
        name: its name (``PrecheckError.rule``).
        check: refuses (:class:`PrecheckError`) a parsed document that breaks it; ``(root, origin)``.
        stricter: None when urdfdom (so Pinocchio) refuses the same documents; else why the toolkit refuses
            documents urdfdom takes (each refusal's message says what urdfdom would do with that document).
    """

    name: str
    check: Callable[[ET.Element, str], None]
    stricter: str | None = None


def _refuse(rule: str, origin: str, message: str) -> PrecheckError:
    return PrecheckError(rule, f"{origin}: not a valid URDF: {message}")


def _numbers(rule: str, el: ET.Element | None, attrs: tuple[tuple[str, int], ...], where: str, origin: str,
             suffix: str = "") -> None:  # fmt: skip
    """Refuse an attribute of ``el`` that urdfdom cannot read as its count of numbers (absent ones pass)."""
    if el is None:
        return
    for attr, n in attrs:
        raw = el.get(attr)
        if raw is None:
            continue
        ok = urdf_number(raw) is not None if n == 1 else urdf_vector(raw, n) is not None
        if not ok:
            raise _refuse(rule, origin, f"{where} <{el.tag}> {attr}={raw[:60]!r}: {_number_problem(raw, n)}{suffix}")


_POSE = (("xyz", 3), ("rpy", 3))


def _joints(root: ET.Element) -> Iterator[tuple[str, ET.Element]]:
    return ((el.get("name", ""), el) for el in root.findall("joint"))


def _joint_where(name: str) -> str:
    return f"joint {name}'s" if name else "joint ''s"


def _link_where(link: ET.Element) -> str:
    return f"link {link.get('name')}'s"


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
    if root.get("name") is None:
        raise _refuse("robot-name", origin, "the <robot> has no name attribute (name=\"\" would do)")


def _version_number(piece: str) -> int | None:
    """The ``strToUnsigned`` of urdfdom: C's strtol (blanks and a sign first), the whole piece, >= 0, as uint32."""
    core = piece.lstrip(_BLANKS)
    if not re.fullmatch(r"[+-]?[0-9]+", core, re.ASCII):
        return None
    value = max(min(int(core), 2**63 - 1), -(2**63))
    return None if value < 0 else value & 0xFFFFFFFF


def _version(root: ET.Element, origin: str) -> None:
    raw = root.get("version")
    if raw is None:
        return
    pieces = raw.split(".")
    if pieces and pieces[-1] == "":  # urdfdom's split keeps no empty last piece ("1.0." is 1.0)
        pieces.pop()
    numbers = [_version_number(p) for p in pieces] if len(pieces) == 2 else []
    if len(numbers) != 2 or None in numbers or tuple(numbers) not in _VERSIONS:
        shown = ", ".join(f"{a}.{b}" for a, b in _VERSIONS)
        raise _refuse("urdf-version", origin, f"<robot> version={raw[:40]!r}: urdfdom reads the versions {shown} "
                                              "(written major.minor)")  # fmt: skip


def _materials(root: ET.Element, origin: str) -> None:
    seen: set[str] = set()
    for material in root.findall("material"):  # global ones; urdfdom ignores a colour it cannot read
        name = material.get("name", "")  # a nameless one is kept under the name ""
        if name in seen:
            raise _refuse("material-unique", origin, f"<material name={name!r}> is defined twice")
        seen.add(name)


def _link_names(root: ET.Element, origin: str) -> None:
    links = root.findall("link")
    seen: set[str] = set()
    for el in links:
        name = el.get("name", "")
        if not name and len(links) > 1:  # no joint can name it: urdfdom finds it a second root
            what = "no name attribute" if el.get("name") is None else "name=\"\""
            raise _refuse("link-name", origin, f"a <link> has {what}: no joint can name it as its parent or child, "
                                               "so the tree would have two root links")  # fmt: skip
        if name in seen:
            raise _refuse("link-name", origin, f"<link name={name!r}> is defined twice")
        seen.add(name)
    if not links:
        raise _refuse("link-name", origin, "the document has no <link> (a URDF has at least one; a xacro file of "
                                           "macros only defines them: call one, or load the file that does)")


def _lost(link: ET.Element, visuals: bool) -> str:
    """What Pinocchio loses of a link when urdfdom stops reading it: ``none of the link's 2 <visual>s and ...``.

    At its inertial or a visual: every visual and collision; at a collision: every collision (urdfdom then leaves
    the link's first visual, or collision, unset, and Pinocchio reads a link's geometry from it).
    """
    nv = len(link.findall("visual")) if visuals else 0
    nc = len(link.findall("collision"))
    parts = [f"{n} <{tag}>{'s' if n != 1 else ''}" for n, tag in ((nv, "visual"), (nc, "collision")) if n]
    return f"none of the link's {' and '.join(parts)}" if parts else "no geometry of the link (it has none)"


def _inertial(root: ET.Element, origin: str) -> None:
    for link in root.findall("link"):
        inertial = link.find("inertial")  # urdfdom reads the first one only
        if inertial is None:
            continue
        where = f"{_link_where(link)} <inertial>"
        consequence = (f": urdfdom would stop reading link {link.get('name')} there (a partial inertia), and "
                       f"Pinocchio would load {_lost(link, True)}; the toolkit refuses it")  # fmt: skip
        _numbers("inertial", inertial.find("origin"), _POSE, where, origin, consequence)
        for part in ("mass", "inertia"):
            if inertial.find(part) is None:
                raise _refuse("inertial", origin, f"{where} has no <{part}>{consequence}")
        mass = inertial.find("mass")
        if mass.get("value") is None:  # type: ignore[union-attr]
            raise _refuse("inertial", origin, f"{where} <mass> has no value{consequence}")
        _numbers("inertial", mass, (("value", 1),), where, origin, consequence)
        inertia = inertial.find("inertia")
        missing = [a for a in _INERTIA if a not in inertia.attrib]  # type: ignore[union-attr]
        if missing:
            raise _refuse("inertial", origin, f"{where} <inertia> has no {', '.join(missing)}{consequence}")
        _numbers("inertial", inertia, tuple((a, 1) for a in _INERTIA), where, origin, consequence)
        value = urdf_number(mass.get("value", ""))  # type: ignore[union-attr]
        if value is not None and value < 0:
            raise _refuse("inertial", origin, f"{where} <mass> value={mass.get('value')!r} is negative: urdfdom "  # type: ignore[union-attr]
                                              "keeps it, and every torque and payload would be wrong")  # fmt: skip


def _shape_problem(item: ET.Element) -> str | None:
    """Why urdfdom cannot read a ``<visual>`` or ``<collision>`` (its origin, its shape; a visual's material)."""
    origin = item.find("origin")
    for attr, n in _POSE:
        raw = None if origin is None else origin.get(attr)
        if raw is not None and urdf_vector(raw, n) is None:
            return f"<origin> {attr}={raw[:60]!r}: {_number_problem(raw, n)}"
    geometry = item.find("geometry")
    if geometry is None:
        return "no <geometry>"
    shape = next(iter(geometry), None)  # urdfdom reads the first element only (a second one is ignored)
    if shape is None:
        return "<geometry> holds nothing (urdfdom reads its first element: <box>, <cylinder>, <sphere>, <mesh>)"
    if shape.tag not in _SHAPES:
        return (f"<geometry>'s first element is <{shape.tag}>, not <box>, <cylinder>, <sphere> or <mesh> (urdfdom "
                "reads the first element only)")  # fmt: skip
    for attr, n in _SHAPES[shape.tag]:
        raw = shape.get(attr)
        if raw is None:
            if n >= 0:
                return f"<{shape.tag}> has no {attr}"
            continue
        if n and (urdf_number(raw) is None if n == 1 else urdf_vector(raw, abs(n)) is None):
            return f"<{shape.tag}> {attr}={raw[:60]!r}: {_number_problem(raw, abs(n))}"
    material = item.find("material")
    if item.tag == "visual" and material is not None and material.get("name") is None:
        return "<material> has no name attribute (name=\"\" would do)"
    return None


def _geometry(root: ET.Element, origin: str) -> None:
    for link in root.findall("link"):
        for part in ("visual", "collision"):
            items = link.findall(part)
            for item in items:
                problem = _shape_problem(item)
                if problem is None:
                    continue
                lost = _lost(link, part == "visual")
                ordinal = f" #{items.index(item) + 1} of {len(items)}" if len(items) > 1 else ""
                raise _refuse("geometry", origin, f"{_link_where(link)} <{item.tag}>{ordinal}: {problem}; urdfdom "
                                                  f"would stop reading the link there, and Pinocchio would load "
                                                  f"{lost}; the toolkit refuses it")  # fmt: skip


def _joint_names(root: ET.Element, origin: str) -> None:
    seen: set[str] = set()
    for el in root.findall("joint"):
        name = el.get("name")
        if name is None:
            raise _refuse("joint-name", origin, "a <joint> has no name attribute (name=\"\" would do)")
        if name in seen:
            raise _refuse("joint-name", origin, f"<joint name={name!r}> is defined twice")
        seen.add(name)


def _joint_types(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        if el.get("type") not in _JOINT_TYPES:
            raise _refuse("joint-type", origin, f"<joint name={name!r}> type={el.get('type')!r}: not a URDF joint "
                                                f"type ({', '.join(sorted(_JOINT_TYPES))})")  # fmt: skip


def _joint_links(root: ET.Element, origin: str) -> None:
    links = {el.get("name", "") for el in root.findall("link")}
    for name, el in _joints(root):
        for role in ("parent", "child"):
            tag = el.find(role)
            link = None if tag is None else tag.get("link")
            if not link:
                written = f"<{role} link=\"\">" if link == "" else f"<{role}> without link=" if tag is not None \
                    else f"no <{role}>"  # fmt: skip
                raise _refuse("joint-links", origin, f"{_joint_where(name)} {written}: a joint names its {role} link")
            if link not in links:
                raise _refuse("joint-links", origin, f"{_joint_where(name)} <{role} link={link!r}>: no <link> of "
                                                     "that name")  # fmt: skip


_JOINT_NUMBERS: tuple[tuple[str, tuple[tuple[str, int], ...]], ...] = (
    ("origin", _POSE),
    ("limit", (("lower", 1), ("upper", 1), ("effort", 1), ("velocity", 1))),
    ("safety_controller", (("soft_lower_limit", 1), ("soft_upper_limit", 1), ("k_position", 1), ("k_velocity", 1))),
    ("calibration", (("rising", 1), ("falling", 1))),
    ("mimic", (("multiplier", 1), ("offset", 1))),
    ("dynamics", (("damping", 1), ("friction", 1))),
)
"""The numbers urdfdom reads in a joint: (its first child of that tag, the attributes and their counts)."""


def _joint_numbers(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        where = _joint_where(name)
        for tag, attrs in _JOINT_NUMBERS:
            _numbers("joint-numbers", el.find(tag), attrs, where, origin)
        if el.get("type") not in ("fixed", "floating"):  # urdfdom never reads a fixed joint's axis
            _numbers("joint-numbers", el.find("axis"), (("xyz", 3),), where, origin)


def _joint_limits(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        kind = el.get("type")
        limit = el.find("limit")
        if limit is None:
            if kind in ("revolute", "prismatic"):
                raise _refuse("joint-limit", origin, f"{kind} <joint name={name!r}> has no <limit> (urdfdom needs "
                                                     "one, with effort and velocity)")  # fmt: skip
            continue
        missing = [a for a in ("effort", "velocity") if limit.get(a) is None]
        if missing:  # any joint's <limit>, a fixed one's too
            raise _refuse("joint-limit", origin, f"{_joint_where(name)} <limit> has no {' and no '.join(missing)} "
                                                 "(urdfdom needs both)")  # fmt: skip


def _joint_parts(root: ET.Element, origin: str) -> None:
    """A ``<safety_controller>`` without k_velocity, a ``<dynamics>`` with neither damping nor friction."""
    for name, el in _joints(root):
        safety = el.find("safety_controller")
        if safety is not None and safety.get("k_velocity") is None:
            raise _refuse("joint-parts", origin, f"{_joint_where(name)} <safety_controller> has no k_velocity "
                                                 "(urdfdom needs it)")  # fmt: skip
        dynamics = el.find("dynamics")
        if dynamics is not None and dynamics.get("damping") is None and dynamics.get("friction") is None:
            raise _refuse("joint-parts", origin, f"{_joint_where(name)} <dynamics> has neither damping nor friction "
                                                 "(urdfdom needs one)")  # fmt: skip


def _mimic_joint(root: ET.Element, origin: str) -> None:
    for name, el in _joints(root):
        mimic = el.find("mimic")
        if mimic is not None and mimic.get("joint") is None:
            raise _refuse("mimic-joint", origin, f"{_joint_where(name)} <mimic> has no joint attribute (the joint "
                                                 "it follows)")  # fmt: skip


def second_parents(root: ET.Element) -> list[tuple[str, str, str, bool]]:
    """Links that are the child of two joints (or more): ``(link, joint kept, joint ignored, harmful)``.

    urdfdom keeps one parent joint per link, the last by name, and Pinocchio builds the link once per joint
    naming it: once more with the kept joint. That is harmless when the kept joint and every joint below the
    link are fixed (the same frames again: the robot is the one with the kept joint), harmful otherwise (movable
    joints built twice, under the same names).
    """
    joints = root.findall("joint")
    by_child: dict[str, list[ET.Element]] = {}
    children: dict[str, list[ET.Element]] = {}
    for el in joints:
        by_child.setdefault(el.find("child").get("link", ""), []).append(el)  # type: ignore[union-attr]
        children.setdefault(el.find("parent").get("link", ""), []).append(el)  # type: ignore[union-attr]
    out: list[tuple[str, str, str, bool]] = []
    for link, parents in by_child.items():
        if len(parents) < 2:
            continue
        kept = max(parents, key=lambda el: el.get("name", "").encode())
        movable = kept.get("type") != "fixed"
        seen, stack = {link}, [link]
        while stack and not movable:  # every joint below the link
            for el in children.get(stack.pop(), []):
                movable = movable or el.get("type") != "fixed"
                child = el.find("child").get("link", "")  # type: ignore[union-attr]
                if child not in seen:
                    seen.add(child)
                    stack.append(child)
        out.extend((link, kept.get("name", ""), el.get("name", ""), movable) for el in parents if el is not kept)
    return out


def _two_parents(root: ET.Element, origin: str) -> None:
    for link, kept, other, harmful in second_parents(root):
        if harmful:
            raise _refuse("two-parents", origin, f"<link name={link!r}> is the child of joints {other!r} and "
                                                 f"{kept!r}: urdfdom keeps {kept!r}, and Pinocchio builds the link's "
                                                 "branch twice, its movable joints named twice")  # fmt: skip


def _tree(root: ET.Element, origin: str) -> None:
    children = {el.find("child").get("link") for el in root.findall("joint")}  # type: ignore[union-attr]
    links = root.findall("link")
    roots = [str(el.get("name", "")) for el in links if el.get("name", "") not in children]
    if len(roots) != 1:
        shown = ", ".join(roots[:5]) + (" ..." if len(roots) > 5 else "")
        raise _refuse("tree", origin, f"{len(roots)} root links ({shown or 'every link is a joint child: a cycle'}); "
                                      "a URDF tree has exactly one root link")  # fmt: skip


PRECHECK_RULES: tuple[PrecheckRule, ...] = (
    PrecheckRule("root", check_root),
    PrecheckRule("size", _size, "the work is bounded: a document above MAX_URDF_ELEMENTS links and joints is refused "
                                "before any is done"),
    PrecheckRule("robot-name", _robot_name),
    PrecheckRule("urdf-version", _version),
    PrecheckRule("material-unique", _materials),
    PrecheckRule("link-name", _link_names),
    PrecheckRule("inertial", _inertial, "urdfdom stops reading a link at an <inertial> it cannot read (a partial "
                                        "inertia, and Pinocchio loads none of the link's visuals and collisions) and "
                                        "keeps a negative mass: torques, payloads, pictures and collisions would be "
                                        "silently wrong"),
    PrecheckRule("geometry", _geometry, "urdfdom stops reading a link at a <visual> or <collision> it cannot read, "
                                        "and Pinocchio then loads none of the link's visuals and collisions (none of "
                                        "its collisions, at a collision): parts missing from the pictures and from "
                                        "the collision checks"),
    PrecheckRule("joint-name", _joint_names),
    PrecheckRule("joint-type", _joint_types),
    PrecheckRule("joint-links", _joint_links),
    PrecheckRule("joint-numbers", _joint_numbers),
    PrecheckRule("joint-limit", _joint_limits),
    PrecheckRule("joint-parts", _joint_parts),
    PrecheckRule("mimic-joint", _mimic_joint),
    PrecheckRule("two-parents", _two_parents,
                 "urdfdom takes a link that is the child of two joints (it keeps the last by name), and Pinocchio then "
                 "builds that link's branch twice: its movable joints twice, under the same names (a branch of fixed "
                 "joints only is the same frames again: loaded, with a warning)"),
    PrecheckRule("tree", _tree),
)  # fmt: skip
"""The pre-check's rules, in the order they run (the first broken one refuses the document)."""


def check_urdf_tree(root: ET.Element, origin: str) -> None:
    """Refuse (:class:`PrecheckError`) what urdfdom would refuse, and what :data:`PRECHECK_RULES` refuses on purpose.

    The robot: a name attribute, a version urdfdom reads. Global materials: no name twice. Links: named,
    unique, at least one; the first ``<inertial>`` readable (mass >= 0), every visual and collision readable.
    Joints: a name attribute, unique, a known type, parent and child links that exist, the numbers of their
    first ``<origin>``, ``<axis>`` (not a fixed joint's), ``<limit>``, ``<safety_controller>``,
    ``<calibration>``, ``<mimic>`` and ``<dynamics>`` readable, ``<limit>`` with effort and velocity (and
    present on a revolute or prismatic joint), a ``<mimic>`` with its joint attribute. The tree: one root
    link, a link the child of two joints only when nothing movable hangs from it (stricter than urdfdom). At
    most :data:`~scara_pin.limits.MAX_URDF_ELEMENTS` links and joints.
    """
    for rule in PRECHECK_RULES:
        rule.check(root, origin)


# ------------------------------------------------------------------------------------ what urdfdom ignores
def _colour_problem(color: ET.Element) -> str | None:
    """Why urdfdom cannot read a ``<color>``: ``"no rgba"`` (``rgb=`` is not URDF), ``"malformed"``, or None."""
    raw = color.get("rgba")
    if raw is None:
        return "no rgba"
    pieces = [urdf_number(p) for p in raw.split(" ") if p]
    if not all(v is not None and 0.0 <= v <= 1.0 for v in pieces):  # urdfdom throws and says so
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


# ------------------------------------------------------------------------------------ the document as urdfdom reads it
_RAW_BLANK_VALUE = re.compile(r"\"[^\"<]*[\t\n\r][^\"<]*\"|'[^'<]*[\t\n\r][^'<]*'")
"""A quoted value holding a tab or a line break (an attribute's; in a comment or text, changing it is harmless)."""
_CHARACTER_REFERENCE = {"\r\n": "&#10;", "\r": "&#10;", "\n": "&#10;", "\t": "&#9;"}


def _keep_blanks(value: re.Match[str]) -> str:
    """A quoted value whose tabs and line breaks are kept as character references (its line breaks after it)."""
    text = value.group()
    breaks = text.count("\n") + text.count("\r") - text.count("\r\n")
    return re.sub(r"\r\n|[\r\n\t]", lambda m: _CHARACTER_REFERENCE[m.group()], text) + "\n" * breaks


def parse_urdf_xml(text: str, lines: bool = True) -> tuple[ET.Element, dict[ET.Element, int]]:
    r"""The document as urdfdom's XML reader (tinyxml2) sees it, with each element's line (when ``lines``).

    Two differences from a standard XML reader are undone: namespaces mean nothing to tinyxml2 (a prefix
    never declared, ``<gazebo:plugin>``, is a tag like any other: read without namespaces here), and it keeps
    the tabs and line breaks written inside an attribute value (``xyz="0 0\t1"``, which urdfdom refuses),
    where XML turns them into spaces.

    Raises:
        xml.parsers.expat.ExpatError: the text is not well-formed XML (``lineno``, ``offset``).
    """
    from xml.parsers import expat

    if "\t" in text or "\n" in text or "\r" in text:
        text = _RAW_BLANK_VALUE.sub(_keep_blanks, text)
    if not lines and "xmlns" not in text:  # no namespace declared: ElementTree's C reader reads the same tree
        with contextlib.suppress(ET.ParseError):  # an undeclared prefix (or not XML): read as tinyxml2 reads it, below
            return ET.fromstring(text), {}
    builder = ET.TreeBuilder()
    found: dict[ET.Element, int] = {}
    parser = expat.ParserCreate()
    parser.buffer_text = True

    def start(tag: str, attrs: dict[str, str]) -> None:
        found[builder.start(tag, attrs)] = parser.CurrentLineNumber

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.CharacterDataHandler = builder.data
    parser.Parse(text, True)
    return builder.close(), found


# ------------------------------------------------------------------------------------ xacro left in a URDF
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
    counts = collections.Counter(name for name, _ in found)
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
