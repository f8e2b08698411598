"""Differential testing of the loader against Pinocchio's own parsers (issue 39): the corpus, its mutants, the verdicts.

Shared by tests/test_urdf_differential.py (a fixed number of mutants, seeded) and
benchmarks/bench_urdf_differential.py (as many as asked). Nothing here imports the toolkit's readers to make
the mutants or to judge them: the documents are edited with the standard library's ElementTree and with text
substitutions, and the judge is Pinocchio (``buildModelFromXML``, and ``buildGeomFromUrdfString`` for the visual
and the collision geometry, every mesh file pointed at one small mesh written here).

A mutant is one change to one document of the corpus (every URDF and xacro file of tests/data, and the shipped
robots' URDF): an attribute emptied, removed, given a blank before or after, numbers written another way
urdfdom reads (``1.``, ``+1``, ``1e0``, doubled spaces) or another way it does not (a tab between numbers,
``1_0``, ``nan``), an unknown attribute; an element duplicated, removed, its children reordered, an unknown
element inserted (also one with an undeclared prefix, ``<gazebo:plugin>``); a value taken from another
element (a link's name for a joint's parent, another joint's name, another joint type).
"""

from __future__ import annotations

import copy
import logging
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

DATA = Path(__file__).resolve().parent / "data"
PACKAGES = (DATA / "packages", DATA / "round4")

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_XACRO_NS = "http://www.ros.org/wiki/xacro"


def corpus() -> dict[str, str]:
    """Every URDF and xacro file of tests/data (xacro expanded) and the shipped robots' URDF, by name."""
    from scara_pin.description import available_robots, generate_urdf
    from scara_pin.description.packages import PackagePath, read_robot_file

    out: dict[str, str] = {}
    for path in sorted(DATA.rglob("*.urdf")) + sorted(DATA.rglob("*.xacro")):
        if path.suffix == ".xacro" and not path.name.endswith(".urdf.xacro"):
            continue  # an included macro file, not a robot
        try:
            text = read_robot_file(path, PackagePath(PACKAGES, path.parent))
        except Exception:  # a fixture that does not expand (a xacro file of macros only expands fine)
            continue
        out[str(path.relative_to(DATA))] = text
    for name in available_robots():
        out[f"shipped:{name}"] = generate_urdf(name)
    return out


# ----------------------------------------------------------------------------------------- the mutations
def _elements(root: ET.Element) -> list[tuple[ET.Element | None, ET.Element]]:
    """(parent, element) of the root (parent None) and of every element below it."""
    out: list[tuple[ET.Element | None, ET.Element]] = [(None, root)]
    for parent in root.iter():
        out.extend((parent, child) for child in parent)
    return out


def _variant(value: str, rng: np.random.Generator) -> str:
    """The numbers of ``value`` written another way urdfdom reads: ``1.``, ``+1``, ``1e0``, leading zeros, doubled
    spaces between numbers."""
    def one(m: re.Match[str]) -> str:
        t = m.group()
        k = int(rng.integers(4))
        if k == 0 and "." not in t and "e" not in t.lower():
            return t + "."
        if k == 1 and t[0] not in "+-":
            return "+" + t
        if k == 2 and "e" not in t.lower():
            return t + "e0"
        return "0" + t.lstrip("+") if t[0] != "-" and k == 3 else t

    return "  ".join(_NUMBER.sub(one, p) for p in value.split(" ") if p) if " " in value.strip() else \
        _NUMBER.sub(one, value)  # fmt: skip


_GARBAGE = ("1_0", "nan", "inf", "0x1", "1e400", "1,5", "one", "")


@dataclass
class Mutant:
    """One mutated document: its corpus file, the change (a short description) and its text."""

    source: str
    change: str
    text: str


def _mutate(root: ET.Element, rng: np.random.Generator) -> str | None:
    """Apply one random change to ``root`` (in place); its description, or None when it did not apply."""
    items = _elements(root)
    parent, el = items[int(rng.integers(len(items)))]
    kind = int(rng.integers(13))
    attrs = list(el.attrib)
    if kind <= 5 and not attrs:
        return None
    if kind <= 5:
        a = attrs[int(rng.integers(len(attrs)))]
        v = el.get(a, "")
        if kind == 0:
            el.set(a, "")
            return f"<{el.tag}> {a} emptied"
        if kind == 1:
            del el.attrib[a]
            return f"<{el.tag}> {a} removed"
        if kind == 2:
            el.set(a, v + " ")
            return f"<{el.tag}> {a}={v + ' '!r} (a blank after)"
        if kind == 3:
            blank = (" ", "\t", "\n")[int(rng.integers(3))]
            el.set(a, blank + v)
            return f"<{el.tag}> {a}={blank + v!r} (a blank before)"
        if kind == 4:
            if not _NUMBER.search(v):
                return None
            if " " in v.strip() and rng.random() < 0.3:
                new = "\t".join(p for p in v.split(" ") if p)
            elif rng.random() < 0.2:
                new = str(_GARBAGE[int(rng.integers(len(_GARBAGE)))])
            else:
                new = _variant(v, rng)
            el.set(a, new)
            return f"<{el.tag}> {a}={new!r}"
        # kind 5: a value taken from another element of the same tag (a name, a link, a type)
        others = [o.get(a) for o in root.iter(el.tag) if o.get(a) not in (None, v)]
        if el.tag == "joint" and a == "type":
            others = ["revolute", "continuous", "prismatic", "fixed", "floating", "planar", "hinge"]
        if el.tag in ("parent", "child", "mimic"):
            others = [o.get("name") for o in root.iter("link" if el.tag != "mimic" else "joint")]
        others = [o for o in others if o is not None and o != v]
        if not others:
            return None
        new = others[int(rng.integers(len(others)))]
        el.set(a, new)
        return f"<{el.tag}> {a}={new!r} (was {v!r})"
    if kind == 6:
        el.set("unknown_attribute", "1")
        return f"<{el.tag}> gets an unknown attribute"
    if kind == 7 and parent is not None:
        copied = copy.deepcopy(el)
        if rng.random() < 0.5 and copied.attrib:  # the copy changed: a second one that differs
            a = list(copied.attrib)[int(rng.integers(len(copied.attrib)))]
            copied.set(a, "garbage")
        parent.insert(list(parent).index(el) + 1, copied)
        return f"<{el.tag}> duplicated"
    if kind == 8 and parent is not None:
        parent.remove(el)
        return f"<{el.tag}> removed"
    if kind == 9 and len(el) >= 2:
        children = list(el)
        for c in children:
            el.remove(c)
        for c in reversed(children):
            el.append(c)
        return f"<{el.tag}>'s children reordered"
    if kind == 10:
        el.insert(int(rng.integers(len(el) + 1)), ET.Element("unknown_tag", {"value": "1"}))
        return f"<{el.tag}> gets an unknown child element"
    if kind == 11:
        return "prefixed"  # done on the text (an undeclared prefix cannot be made with ElementTree)
    if kind == 12 and el.tag == "geometry" and len(el):
        el.append(ET.Element(("box", "sphere", "unknown_shape")[int(rng.integers(3))], {"size": "1 1 1",
                                                                                          "radius": "1"}))
        return "<geometry> gets a second element"
    return None


def mutants(texts: dict[str, str], n: int, seed: int) -> Iterator[Mutant]:
    """``n`` single-change mutants of the corpus ``texts`` (round robin over the files), seeded."""
    rng = np.random.default_rng(seed)
    names = sorted(texts)
    parsed = {name: ET.fromstring(texts[name]) for name in names}
    made = 0
    k = 0
    while made < n:
        name = names[k % len(names)]
        k += 1
        root = copy.deepcopy(parsed[name])
        change = _mutate(root, rng)
        if change is None:
            continue
        text = ET.tostring(root, encoding="unicode")
        if change == "prefixed":
            tags = [m.end() for m in re.finditer(r"<(link|robot|visual|joint)\b[^>]*?(?<!/)>", text)]
            if not tags:
                continue
            at = tags[int(rng.integers(len(tags)))]
            text = text[:at] + '<gazebo:plugin name="p" filename="libp.so"/>' + text[at:]
            change = "an element with an undeclared prefix, <gazebo:plugin>"
        made += 1
        yield Mutant(name, change, text)


def systematic(texts: dict[str, str], per_kind: int = 2) -> Iterator[Mutant]:
    """Each attribute of each kind of element emptied, then removed: the variants urdfdom tolerates, every run.

    A kind is an element's tag under its parent's tag (``visual/material`` is not ``robot/material``); each
    (kind, attribute) is changed in the first ``per_kind`` files of the corpus (by name) that have it, at its
    first occurrence there. The random mutants of :func:`mutants` meet a given attribute by chance (a
    ``<material name="">`` in a visual about once in 4,000); these meet each one whatever the seed, so a rule
    that refuses an empty name or a missing attribute urdfdom tolerates fails the test every time.
    """
    seen: dict[tuple[str, str, str], int] = {}
    for name in sorted(texts):
        root = ET.fromstring(texts[name])
        order = list(root.iter())
        here: set[tuple[str, str, str]] = set()
        for parent, el in _elements(root):
            for attr in sorted(el.attrib):
                kind = ("" if parent is None else parent.tag, el.tag, attr)
                if kind in here or seen.get(kind, 0) >= per_kind:
                    continue
                here.add(kind)
                seen[kind] = seen.get(kind, 0) + 1
                at = order.index(el)
                for how in ("emptied", "removed"):
                    changed = copy.deepcopy(root)
                    target = list(changed.iter())[at]
                    if how == "emptied":
                        target.set(attr, "")
                    else:
                        del target.attrib[attr]
                    where = f"{kind[0]}/{kind[1]}" if kind[0] else kind[1]
                    yield Mutant(name, f"<{where}> {attr} {how}", ET.tostring(changed, encoding="unicode"))


# ----------------------------------------------------------------------------------------- the judges
MESH_STL = """solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 0.01 0 0
vertex 0 0.01 0
endloop
endfacet
endsolid t
"""
_MESH_FILE = re.compile(r"(<mesh\b[^>]*?\bfilename=)(\"[^\"]+\"|'[^']+')")


@dataclass
class Pinocchio:
    """Pinocchio's verdict on a document: the model (default parser, mimics as free joints), the geometries."""

    model: pin.Model | None = None
    error: str | None = None
    visual: int | None = None
    collision: int | None = None
    geometry_error: str | None = None
    mimic_refused: bool | None = None
    extra: dict[str, object] = field(default_factory=dict)

    @property
    def loads(self) -> bool:
        """The model and both geometries load."""
        return self.model is not None and self.geometry_error is None


def pinocchio_verdict(text: str, mesh: Path, geometry: bool = True) -> Pinocchio:
    """Pinocchio's own parsers on ``text``: ``buildModelFromXML`` (and with ``mimic=True``), then the visual and the
    collision geometry (each mesh file name pointed at ``mesh``, an existing file)."""
    out = Pinocchio()
    try:
        out.model = pin.buildModelFromXML(text)
    except (ValueError, RuntimeError) as exc:
        out.error = str(exc)
        return out
    if not geometry:
        return out
    pointed = _MESH_FILE.sub(lambda m: f'{m.group(1)}"{mesh}"', text)
    try:
        out.visual = pin.buildGeomFromUrdfString(out.model, pointed, pin.GeometryType.VISUAL).ngeoms
        out.collision = pin.buildGeomFromUrdfString(out.model, pointed, pin.GeometryType.COLLISION).ngeoms
    except (ValueError, RuntimeError) as exc:
        out.geometry_error = str(exc)
    return out


def mimic_refused(text: str) -> bool:
    """Whether Pinocchio's mimic parser (``mimic=True``) refuses ``text``."""
    try:
        pin.buildModelFromXML(text, mimic=True)
    except (ValueError, RuntimeError):
        return True
    return False


@dataclass
class Toolkit:
    """The loader's verdict: loaded, or refused by a rule (``rule``, ``message``); ``crash``: any other exception."""

    rule: str | None = None
    message: str | None = None
    crash: str | None = None

    @property
    def loads(self) -> bool:
        return self.rule is None and self.crash is None


def toolkit_verdict(text: str) -> Toolkit:
    """:class:`scara_pin.model.RobotModel` on ``text`` (a stranger's URDF: pre-check, Pinocchio, the chain)."""
    from scara_pin.errors import ScaraError
    from scara_pin.model import RobotModel

    logger = logging.getLogger("scara_pin")
    level = logger.level
    logger.setLevel(logging.ERROR)  # the loader's warnings (colours ignored, a mimic naming no joint) are not verdicts
    try:
        RobotModel(text, origin="m.urdf")
    except ScaraError as exc:
        return Toolkit(rule=getattr(exc, "rule", "unnamed"), message=str(exc))
    except Exception as exc:  # noqa: BLE001 - a crash is the finding
        return Toolkit(crash=f"{type(exc).__name__}: {exc}")
    finally:
        logger.setLevel(level)
    return Toolkit()


def written_geometry(text: str, model: pin.Model) -> tuple[int, int]:
    """The ``<visual>`` and ``<collision>`` elements written in the links Pinocchio's model has (standard library)."""
    root = ET.fromstring(text.replace("gazebo:plugin", "gazebo_plugin"))
    visuals = collisions = 0
    for link in root.findall("link"):
        if model.existBodyName(link.get("name", "")):
            visuals += len(link.findall("visual"))
            collisions += len(link.findall("collision"))
    return visuals, collisions


# ----------------------------------------------------------------------------------------- the verdict
def _lost_in_message(message: str) -> int | None:
    """The number of visuals and collisions a refusal says urdfdom would drop (None: it says none)."""
    counts = [int(n) for n in re.findall(r"(\d+) <(?:visual|collision)>s?", message)]
    return sum(counts) if counts else None


def _joint_named(message: str, model: pin.Model) -> str | None:
    """The first joint of ``model`` a message names (``joint j2``, ``joint j2's``)."""
    for name in re.findall(r"joint (\S+?)(?:'s|:|,| |$)", message):
        if model.existJointName(name):
            return name
    return None


def _floats(el: ET.Element | None, attrs: tuple[str, ...]) -> list[float]:
    out = []
    for a in attrs:
        try:
            out.append(float((el.get(a) if el is not None else None) or "nan"))
        except ValueError:
            out.append(float("nan"))
    return out


def claim_holds(rule: str, message: str, text: str, pv: Pinocchio) -> str | None:
    """Why a refusal of a document Pinocchio loads is wrong, or None when the rule's reason holds for it.

    Each rule that refuses what Pinocchio's parser loads says why (``stricter`` reasons, LOADER_RULES); here
    the reason is checked against Pinocchio's own reading of the document.
    """
    from scara_pin._urdf_checks import PRECHECK_RULES
    from scara_pin.urdf_rules import LOADER_RULES

    stricter = {r.name: r.stricter for r in PRECHECK_RULES}
    model = pv.model
    assert model is not None
    if rule in stricter and stricter[rule] is None:
        return f"refused by {rule!r}, a rule that claims to refuse only what urdfdom refuses, while Pinocchio loads it"
    if rule not in stricter and rule not in LOADER_RULES:
        return f"refused by {rule!r}, no rule of the pre-check nor of the toolkit's, while Pinocchio loads it"
    root = ET.fromstring(text.replace("gazebo:plugin", "gazebo_plugin"))
    if rule in ("geometry", "inertial"):
        said = _lost_in_message(message)
        written = written_geometry(text, model)
        lost = written[0] - (pv.visual or 0) + written[1] - (pv.collision or 0)
        if rule == "geometry" or said:  # Pinocchio loses them all: the link's visuals and collisions
            return None if said == lost and lost > 0 else f"{rule}: says {said} visuals and collisions dropped, " \
                f"Pinocchio dropped {lost}"  # fmt: skip
        link_name = re.search(r"link (\S+?)'s", message)
        link = next((el for el in root.findall("link") if link_name and el.get("name") == link_name.group(1)), None)
        inertial = None if link is None else link.find("inertial")
        mass = _floats(None if inertial is None else inertial.find("mass"), ("value",))[0]
        tensor = _floats(None if inertial is None else inertial.find("inertia"), ("ixx", "ixy", "ixz", "iyy", "iyz",
                                                                                     "izz"))  # fmt: skip
        if "negative" in message:
            return None if mass < 0 else f"inertial: says negative, the mass written is {mass}"
        changed = not np.isfinite(mass) or mass != 0 or any(v != 0 for v in tensor)  # NaN: unreadable as written
        return None if changed else "inertial: a partial inertia equal to the one written"
    if rule == "bad-number":
        name = _joint_named(message, model)
        axis = next((el.find("axis") for el in root.findall("joint") if el.get("name") == name), None)
        xyz = [0.0] if axis is not None and axis.get("xyz") is None else _floats(axis, ("xyz",)) if axis is None \
            else [float(v) if _NUMBER.fullmatch(v) else float("nan") for v in axis.get("xyz", "").split()]  # fmt: skip
        return None if axis is not None and all(v == 0 for v in xyz) else f"bad-number: joint {name}'s axis {xyz}"
    if rule in ("limits-inverted", "limits-empty"):  # a joint whose limits Pinocchio reads inverted (or equal)
        for j in range(1, model.njoints):
            jm = model.joints[j]
            if jm.nq == 1 and jm.nv == 1:
                lo, hi = model.lowerPositionLimit[jm.idx_q], model.upperPositionLimit[jm.idx_q]
                if (lo > hi) if rule == "limits-inverted" else (lo == hi):
                    return None
        return f"{rule}: Pinocchio reads no joint's limits so ({message!r})"
    if rule == "mimic-unresolved":
        return None if mimic_refused(text) else "mimic-unresolved: Pinocchio's mimic parser loads it"
    if rule == "joint-count":
        counted = re.search(r"this file has (\d+) movable joint", message)
        several = "degrees of freedom" in message  # a floating or planar joint: not single-DOF
        return None if counted and (int(counted.group(1)) not in (3, 4) or several) else f"joint-count: {message!r}"
    if rule == "two-parents":
        names = list(model.names)
        return None if len(set(names)) < len(names) else "two-parents: Pinocchio names each joint once"
    if rule == "no-movable-joint":
        return None if model.nq == 0 else f"no-movable-joint: Pinocchio's model has nq = {model.nq}"
    if rule == "frame-missing":
        frame = re.search(r"frame '([^']*)'", message)
        return None if frame and not model.existFrame(frame.group(1)) else f"frame-missing: {message!r}"
    return f"refused by {rule!r} ({message!r}) while Pinocchio loads it"


def verdict(m: Mutant, mesh: Path) -> tuple[Toolkit, str | None]:
    """The toolkit's verdict on a mutant, and what is wrong with it judged by Pinocchio (None when nothing is).

    - the loader never crashes (only its errors, each naming a rule);
    - a refusal of a document Pinocchio refuses names the element (never Pinocchio's bare "does not contain a
      valid URDF model");
    - a refusal of a document Pinocchio loads (model, visual and collision geometry) is made by a rule that says
      why it is stricter, and its reason holds for that document (:func:`claim_holds`).
    """
    tk = toolkit_verdict(m.text)
    if tk.crash is not None:
        return tk, f"crash: {tk.crash}"
    if tk.loads:
        return tk, None
    assert tk.message is not None and tk.rule is not None
    if tk.rule == "unnamed" or "does not contain a valid URDF model" in tk.message:
        return tk, f"refused without naming the element: {tk.message}"
    pv = pinocchio_verdict(m.text, mesh)
    if not pv.loads:
        return tk, None
    return tk, claim_holds(tk.rule, tk.message, m.text, pv)


def check_disagrees(m: Mutant) -> str | None:
    """``scara-pin check`` against the loader on a mutant: loadable means check exits 0 or 4, refused means 2.

    None when they agree (and check never crashes), else what differs.
    """
    from scara_pin.lint import check_urdf

    tk = toolkit_verdict(m.text)
    try:
        report = check_urdf(m.text, origin="m.urdf")
    except Exception as exc:  # noqa: BLE001 - a crash is the finding
        return f"check crashed: {type(exc).__name__}: {exc}"
    refused = report.exit_code == 2
    if refused == (not tk.loads):
        return None
    errors = [f"{f.code}: {f.message}" for f in report.findings if f.severity.value == "error"]
    return f"check exits {report.exit_code} ({'; '.join(errors)[:300]}) but the loader " + \
        ("loads it" if tk.loads else f"refuses it ({tk.rule}: {tk.message})")  # fmt: skip
