"""Rules shared by the loader (:class:`scara_pin.model.RobotModel`) and the linter (:mod:`scara_pin.lint`).

One place for what both must agree on, so that whatever ``scara-pin check`` says the toolkit will do, it
does:

- :func:`choose_frames`: the tool and base frames (``tool0`` if present, else the link the arm ends in:
  the end of the chain through the most free joints; ``base`` if present, else the root link; a named
  frame that does not exist is an error);
- :func:`resolve_mimics`: each ``<mimic>`` joint's free joint, through chains of mimics (a mimic of a
  mimic: multipliers and offsets composed), or why Pinocchio cannot take it;
- :func:`joint_problem`: a joint the toolkit cannot use (zero axis, non-finite or inverted limits, a range
  of zero width);
- :func:`locked_joints`: the joints the loader locks (off the chain from the root to the tool, or asked for);
- :data:`LOADER_RULES`: the toolkit's own refusals of files Pinocchio loads, each with its reason
  (:class:`UrdfRuleError` names the rule of each refusal).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass

from .errors import UrdfError

__all__ = [
    "LOADER_RULES",
    "MOVABLE",
    "TOOL_NAMES",
    "FrameChoice",
    "JointEdge",
    "Mimic",
    "ToolCandidate",
    "UrdfRuleError",
    "axis_of",
    "choose_frames",
    "edges_of",
    "joint_problem",
    "locked_joints",
    "mimic_error",
    "read_tree",
    "resolve_mimics",
    "zero_within",
]

MOVABLE = ("revolute", "continuous", "prismatic")
"""URDF joint types that move (each one value of q)."""
TOOL_NAMES = ("tool0", "flange", "tcp", "ee", "end_effector")
"""Names of a tool link, preferred in this order among links that end equally long chains (a name matches
when its words, split at ``_``, ``-``, ``.`` and between letters and digits, contain them: ``mg400_flange``,
``magician_link_ee``, ``end_effector_shaft``)."""


class UrdfRuleError(UrdfError):
    """A URDF refused by a named rule.

    ``rule``: a rule of the pre-check (urdfdom's, ``scara_pin._urdf_checks.PRECHECK_RULES``) or of the
    toolkit (:data:`LOADER_RULES`).
    """

    def __init__(self, rule: str, message: str) -> None:
        self.rule = rule
        super().__init__(message)


LOADER_RULES: dict[str, str] = {
    "bad-number": "a movable joint whose axis is the zero vector (an <axis> without xyz) moves nothing: no "
                  "kinematics, no Jacobian of full rank",
    "limits-inverted": "lower above upper: no value of the joint is inside its limits (IK, trajectories, the "
                       "workspace need one)",
    "limits-empty": "lower equal to upper: the joint cannot move (--lock fixes a joint on purpose)",
    "mimic-unresolved": "the toolkit honours <mimic> as Pinocchio's mimic parser does (mimic=True): a mimic "
                        "that parser refuses (a loop, a missing or fixed source, a source built after it, "
                        "a continuous joint following a bounded one) is refused too, unless it is locked with "
                        "its source",
    "joint-count": "a SCARA has 4 single-DOF joints on the chain from the root to the tool (3 without a wrist), "
                   "a palletizer 4",
    "no-movable-joint": "no movable joint is connected to the root link: nothing to compute",
    "frame-missing": "a --tool or --base that is not a link of the file, or a base that moves",
    "lock": "a --lock that names no movable joint, or a value outside the joint's limits",
}  # fmt: skip
"""The toolkit's own rules: what it refuses although Pinocchio's parser loads it, and why (the loader raises
:class:`UrdfRuleError` with the rule's name; tests/test_urdf_differential.py checks every refusal against
Pinocchio)."""


@dataclass(frozen=True)
class JointEdge:
    """A URDF joint as the tree sees it: name, type, parent link, child link; its limits and mimic as written.

    ``lower``/``upper``: the position limits (None when absent); ``mimic``: the joint it follows, if any
    (a movable joint's ``<mimic>``), with ``multiplier`` and ``offset`` as written.
    """

    name: str
    type: str
    parent: str
    child: str
    lower: float | None = None
    upper: float | None = None
    mimic: str | None = None
    multiplier: float = 1.0
    offset: float = 0.0
    unnamed_mimic: bool = False

    @property
    def free(self) -> bool:
        """A movable joint that follows no other: a degree of freedom."""
        return self.type in MOVABLE and self.mimic is None


@dataclass(frozen=True)
class Mimic:
    """A ``<mimic>`` joint resolved down to the free joint it follows: ``value = multiplier * source + offset``.

    ``via``: the mimic joints between it and ``source`` (empty when it follows a free joint directly).
    ``unbuildable``: why Pinocchio's mimic parser cannot build it (its source built after it, or a continuous
    joint following a bounded one), else None: the loader then locks it with its source when that source is
    locked (:func:`locked_joints`), and refuses it otherwise (:func:`mimic_error`).
    """

    joint: str
    source: str
    multiplier: float
    offset: float
    via: tuple[str, ...] = ()
    unbuildable: str | None = None


@dataclass(frozen=True)
class ToolCandidate:
    """A link that ends the arm: a leaf of the tree, or the hand its fingers hang from.

    Attributes:
        link: its name. free: the free joints between the root and it, root first. depth: all joints on the way.
        hand: the fingers hanging from it (sibling movable joints ending the tree), when it is a hand.
    """

    link: str
    free: tuple[str, ...]
    depth: int
    hand: tuple[str, ...] = ()


@dataclass(frozen=True)
class FrameChoice:
    """The frames the toolkit uses.

    Attributes:
        base: the reference frame of poses (a link).
        tool: the tool frame (a link).
        note: when the tool was chosen by default without a ``tool0``: the one-line notice saying which
            link is the tool and why (the CLI prints it as ``info:``); else None.
        root: the root link of the tree.
        alternatives: the other links that end the arm (best first), when the tool was chosen by default.
        ambiguous: when chosen by default: another link ends an equally long chain and no name decides.
    """

    base: str
    tool: str
    note: str | None = None
    root: str = ""
    alternatives: tuple[ToolCandidate, ...] = ()
    ambiguous: bool = False


def _dfs(links: Sequence[str], joints: Sequence[JointEdge]) -> tuple[str, list[JointEdge], dict[str, list[JointEdge]]]:
    """(root link, joints depth-first from the root with siblings in file order, children of each link)."""
    children: dict[str, list[JointEdge]] = {}
    for j in joints:
        children.setdefault(j.parent, []).append(j)
    has_parent = {j.child for j in joints}
    root = next((name for name in links if name not in has_parent), links[0] if links else "")
    order: list[JointEdge] = []
    seen = {root}
    stack = list(reversed(children.get(root, [])))
    while stack:
        j = stack.pop()
        if j.child in seen:
            continue
        seen.add(j.child)
        order.append(j)
        stack.extend(reversed(children.get(j.child, [])))
    return root, order, children


def _downstream_of_movable(order: Sequence[JointEdge]) -> set[str]:
    """The links that a movable joint carries (``order``: depth-first from the root)."""
    moving: set[str] = set()
    for j in order:
        if j.type in MOVABLE or j.parent in moving:
            moving.add(j.child)
    return moving


def choose_frames(
    links: Sequence[str],
    joints: Sequence[JointEdge],
    *,
    tool: str | None = None,
    base: str | None = None,
    origin: str = "URDF",
) -> FrameChoice:
    """Pick the tool and base frames of a URDF tree.

    Args:
        links: the link names, in file order.
        joints: the joints, in file order.
        tool: the tool frame asked for (``--tool``); default: ``tool0`` if present, else the link the arm
            ends in: the first of :func:`tool_candidates` (the end of the chain through the most free joints;
            among equals, a name of :data:`TOOL_NAMES`), with a note saying why and the alternatives.
        base: the base frame asked for (``--base``), a link fixed to the root; default: ``base`` if present,
            else the root link.
        origin: how to name the source in error messages.

    Raises:
        UrdfError: a frame asked for is not a link of the file (the message lists the links), or a base
            that a movable joint carries.
    """
    for what, name in (("tool", tool), ("base", base)):
        if name is not None and name not in links:
            shown = ", ".join(links[:40]) + (f", ... ({len(links) - 40} more)" if len(links) > 40 else "")
            raise UrdfRuleError("frame-missing", f"{origin}: no link named {name!r} for the {what} frame (--{what}); "
                                f"links: {shown}")
    root, order, children = _dfs(links, joints)
    reached = {root} | {j.child for j in order}
    for what, name in (("tool", tool if tool is not None else "tool0" if "tool0" in links else None),
                       ("base", base if base is not None else "base" if "base" in links else None)):  # fmt: skip
        if name is not None and name not in reached:
            raise UrdfRuleError("frame-missing", f"{origin}: the {what} frame {name!r} is not connected to the root "
                                f"link {root} (the joints above it form a cycle): --{what} picks another link")
    if base is None:
        base = "base" if "base" in links else root
    else:  # the base is fixed: no movable joint between it and the root
        parent_of = {j.child: j for j in order}
        link = base
        while link in parent_of:
            if parent_of[link].type in MOVABLE:
                fixed = ", ".join([root] + [j.child for j in order if j.child not in _downstream_of_movable(order)])
                raise UrdfRuleError("frame-missing", f"{origin}: the base frame (--base) {base!r} moves with joint "
                                f"{parent_of[link].name}: the base must be fixed to the root link; "
                                f"fixed links: {fixed}")  # fmt: skip
            link = parent_of[link].parent
    if tool is not None or "tool0" in links:
        return FrameChoice(base=base, tool=tool or "tool0", root=root)
    candidates = tool_candidates(root, order, children)
    if not candidates:
        return FrameChoice(base=base, tool=root, root=root)
    best = candidates[0]
    ambiguous = len(candidates) > 1 and len(candidates[1].free) == len(best.free) \
        and _name_rank(candidates[1].link) == _name_rank(best.link)  # fmt: skip
    why = f"it ends the chain through the most free joints, {len(best.free)}"
    if _name_rank(best.link) < len(TOOL_NAMES):
        why += f", and its name says {TOOL_NAMES[_name_rank(best.link)]}"
    elif best.hand:
        why += f"; the hand of the fingers {', '.join(best.hand)}"
    note = f"no tool0 frame: {best.link} is taken as the tool ({why})"
    if ambiguous:
        note += f"; {candidates[1].link} ends as many and no name tells them apart"
    note += "; --tool FRAME picks another"
    return FrameChoice(base=base, tool=best.link, note=note, root=root, alternatives=tuple(candidates[1:]),
                       ambiguous=ambiguous)  # fmt: skip


def _words(name: str) -> list[str]:
    """A name's words: split at ``_``, ``-``, ``.``, and between letters and digits; lower case."""
    return [w for w in re.split(r"[_\-.]+|(?<=[a-z])(?=\d)|(?<=\d)(?=[a-z])", name.lower()) if w]


def _name_rank(link: str) -> int:
    """The index in :data:`TOOL_NAMES` of the first name whose words the link's words contain (else its length)."""
    words = _words(link)
    for i, name in enumerate(TOOL_NAMES):
        parts = _words(name)
        if any(words[k : k + len(parts)] == parts for k in range(len(words) - len(parts) + 1)):
            return i
    return len(TOOL_NAMES)


def tool_candidates(root: str, order: Sequence[JointEdge], children: dict[str, list[JointEdge]]
                    ) -> list[ToolCandidate]:  # fmt: skip
    """The links the arm may end in, best first (the default tool is the first, :func:`choose_frames`).

    The leaves of the tree, except that the fingers of a hand are not the arm: where a link carries two or
    more movable joints with nothing movable below them (a gripper's jaws, one usually a ``<mimic>`` of the
    other), the link itself (the hand) stands for the leaves below them. Ranked by the free joints between
    the root and them (most first: the arm, not a parallelogram's rod, which only ``<mimic>`` joints move),
    then by :data:`TOOL_NAMES`, then the deeper first, then file order.
    """
    moving_below: set[str] = set()
    for j in reversed(order):
        if j.type in MOVABLE or j.child in moving_below:
            moving_below.add(j.parent)
    out: list[ToolCandidate] = []
    stack: list[tuple[str, tuple[str, ...], int]] = [(root, (), 0)]
    while stack:
        link, free, depth = stack.pop()
        kids = children.get(link, [])
        movable = [j for j in kids if j.type in MOVABLE]
        fingers = tuple(j.name for j in movable) if len(movable) >= 2 and any(j.mimic is None for j in movable) \
            and not any(j.child in moving_below for j in movable) else ()  # fmt: skip
        if not kids or fingers:
            out.append(ToolCandidate(link, free, depth, fingers))
        for j in reversed(kids):  # the first child popped first: file order
            if j.name not in fingers:
                stack.append((j.child, free + ((j.name,) if j.free else ()), depth + 1))
    index = {c.link: i for i, c in enumerate(out)}
    return sorted(out, key=lambda c: (-len(c.free), _name_rank(c.link), -c.depth, index[c.link]))




def zero_within(lower: float | None, upper: float | None) -> float:
    """0, or the nearest limit when 0 is outside [lower, upper] (None: no limit) [rad or m].

    Where a joint rests by default: a locked joint, a page's first pose, the pendant's start.
    """
    value = 0.0 if lower is None else max(0.0, lower)
    return value if upper is None else min(value, upper)


def joint_problem(
    name: str, kind: str, axis: Sequence[float], lower: float | None, upper: float | None
) -> tuple[str, str] | None:
    """Why a movable joint is unusable, as ``(code, message)``, or None.

    Args:
        name: the joint's name.
        kind: its URDF type (``revolute``, ``continuous``, ``prismatic``).
        axis: its axis as written (any nonzero length: it is normalised).
        lower: its lower position limit as written (None: absent, read as 0 as urdfdom does); ignored for
            a continuous joint.
        upper: its upper position limit, likewise.
    """
    if not (all(math.isfinite(v) for v in axis) and math.hypot(*axis) > 1e-12):
        return "bad-number", f"joint {name}'s axis is the zero vector (or not finite): it must be a nonzero vector"
    if kind == "continuous":
        return None
    lo = 0.0 if lower is None else lower
    hi = 0.0 if upper is None else upper
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "bad-number", f"joint {name}'s limits [{lo:g}, {hi:g}] must be finite numbers"
    rule = "lower must be below upper"
    if lo > hi:
        return "limits-inverted", f"joint {name}: lower {lo:g} > upper {hi:g}: inverted limits ({rule})"
    if lo == hi:
        return "limits-empty", f"joint {name}: lower = upper = {lo:g}: the joint cannot move ({rule})"
    return None


def _float(text: str | None) -> float | None:
    """A number as written (NaN when malformed), None when absent."""
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        return math.nan


def edges_of(root: ET.Element) -> tuple[list[str], list[JointEdge]]:
    """The link names and the joints of a parsed URDF, in file order (nothing checked; NaN for bad numbers).

    A ``<mimic joint="">`` names no joint (unless a joint is named ""): the joint is free, as Pinocchio's default
    parser reads it (``unnamed_mimic``: the loader says so and hands Pinocchio the joint without it).
    """
    links = [el.get("name", "") for el in root.findall("link")]
    named_empty = any(el.get("name") == "" for el in root.findall("joint"))
    joints = []
    for el in root.findall("joint"):
        parent, child, limit, mimic = el.find("parent"), el.find("child"), el.find("limit"), el.find("mimic")
        lo = _float(limit.get("lower")) if limit is not None else None
        hi = _float(limit.get("upper")) if limit is not None else None
        unnamed = mimic is not None and mimic.get("joint") == "" and not named_empty
        if unnamed:
            mimic = None
        joints.append(JointEdge(
            el.get("name", ""), el.get("type", ""), parent.get("link", "") if parent is not None else "",
            child.get("link", "") if child is not None else "", lo, hi,
            None if mimic is None else mimic.get("joint", ""),
            1.0 if mimic is None else float(_float(mimic.get("multiplier", "1"))),  # type: ignore[arg-type]
            0.0 if mimic is None else float(_float(mimic.get("offset", "0"))),  # type: ignore[arg-type]
            unnamed,
        ))  # fmt: skip
    return links, joints


def axis_of(el: ET.Element) -> list[float]:
    """A joint's axis as urdfdom reads it (NaN where a number is malformed).

    (1, 0, 0) without ``<axis>``, the zero vector for an ``<axis>`` without xyz.
    """
    axis_el = el.find("axis")
    text = "1 0 0" if axis_el is None else axis_el.get("xyz", "0 0 0")
    try:
        return [float(v) for v in text.split()]
    except ValueError:
        return [math.nan]


def read_tree(root: ET.Element, origin: str) -> tuple[list[str], list[JointEdge]]:
    """The links and joints of a parsed URDF (file order), and check every movable joint (:func:`joint_problem`).

    The joints checked are the free ones the root reaches (Pinocchio's tree: a joint in a cycle is not in it).

    Raises:
        UrdfRuleError: the first unusable joint (one line naming the joint and the rule).
    """
    links, joints = edges_of(root)
    reached = {j.name for j in _dfs(links, joints)[1]}
    for el, j in zip(root.findall("joint"), joints):
        if not j.free or j.name not in reached:  # a mimic joint follows another: not in q
            continue
        problem = joint_problem(j.name, j.type, axis_of(el), j.lower, j.upper)
        if problem is not None:
            raise UrdfRuleError(problem[0], f"{origin}: {problem[1]} [{problem[0]}]")
    return links, joints


def _pinocchio_order(joints: Sequence[JointEdge]) -> dict[str, int]:
    """Each joint's place in the order Pinocchio builds the tree: depth-first, a link's children by name.

    (urdfdom keeps the joints in a map sorted by name and lists each link's child joints in that order.)
    """
    children: dict[str, list[JointEdge]] = {}
    for j in sorted(joints, key=lambda e: e.name.encode()):
        children.setdefault(j.parent, []).append(j)
    has_parent = {j.child for j in joints}
    stack = [j for link in children if link not in has_parent for j in reversed(children[link])]
    out: dict[str, int] = {}
    while stack:
        j = stack.pop()
        if j.name in out:
            continue
        out[j.name] = len(out)
        stack.extend(reversed(children.get(j.child, [])))
    return out


def resolve_mimics(joints: Sequence[JointEdge], origin: str) -> dict[str, Mimic]:
    """Each movable ``<mimic>`` joint's free joint, multiplier and offset, through chains of mimics.

    A joint following a joint that itself follows another (a parallelogram's plate following its rod) is
    the composition: ``a = m1 b + c1``, ``b = m2 f + c2`` give ``a = (m1 m2) f + (m1 c2 + c1)``. Pinocchio
    takes one level only: the loader hands it the composed ``<mimic>`` (:class:`scara_pin.model.RobotModel`).

    A mimic that Pinocchio's mimic parser cannot build is returned with the reason (``Mimic.unbuildable``): a
    continuous joint following a bounded one or the reverse (Pinocchio's configurations differ: (cos, sin)
    against an angle), or a source that Pinocchio builds after its mimic (it builds each link's child joints
    in name order, and needs the source first). The loader locks such a mimic with its source when the source
    is locked (a gripper's second jaw, off the arm), and refuses it otherwise (:func:`mimic_error`).

    Raises:
        UrdfRuleError: (``mimic-unresolved``) what has no free joint at its end, naming the joints: a loop of
            mimics, a source that is no joint of the file, or not a movable one.
    """
    by_name = {j.name: j for j in joints}
    out: dict[str, Mimic] = {}
    order = _pinocchio_order(joints)
    for j in joints:
        if j.type not in MOVABLE or j.mimic is None or j.name not in order:  # (a joint the root does not reach:
            continue  # Pinocchio never builds it)
        m, c, path, name = j.multiplier, j.offset, [j.name], j.mimic
        while True:
            src = by_name.get(name)
            if src is None or src.type not in MOVABLE:
                what = "which is no joint of the file" if src is None else f"a {src.type} joint"
                raise UrdfRuleError("mimic-unresolved", f"{origin}: joint {path[-1]} follows {name!r} (<mimic>), "
                                    f"{what}: a <mimic> follows a revolute, continuous or prismatic joint")  # fmt: skip
            if src.name in path:
                loop = " -> ".join([*path[path.index(src.name) :], src.name])
                raise UrdfRuleError("mimic-unresolved", f"{origin}: the <mimic> joints {loop} follow one another in "
                                    "a loop: none of them is free, so none has a value")  # fmt: skip
            if src.name not in order:
                raise UrdfRuleError("mimic-unresolved", f"{origin}: joint {path[-1]} follows {src.name} (<mimic>), "
                                    "which is not connected to the root link (its joints form a cycle): Pinocchio "
                                    "never builds it")  # fmt: skip
            if src.mimic is None:
                break
            path.append(src.name)
            m, c, name = m * src.multiplier, m * src.offset + c, src.mimic
        unbuildable = None
        if (j.type == "continuous") != (src.type == "continuous"):
            unbuildable = (f"joint {j.name} ({j.type}) follows {src.name} ({src.type}) (<mimic>): Pinocchio takes a "
                           "mimic of a continuous joint only as a continuous joint, and the reverse")  # fmt: skip
        elif order[src.name] > order[j.name]:
            unbuildable = (f"joint {j.name} follows {src.name} (<mimic>), but Pinocchio builds {src.name} after "
                           "it (depth-first, each link's child joints in name order) and needs the followed "
                           "joint first")  # fmt: skip
        out[j.name] = Mimic(j.name, src.name, m, c, tuple(path[1:]), unbuildable)
    return out


def locked_joints(
    links: Sequence[str], joints: Sequence[JointEdge], tool: str, lock: Collection[str], mimics: Mapping[str, Mimic]
) -> set[str]:
    """The free joints the loader locks (:mod:`scara_pin.chain`).

    Those off the chain from the root to ``tool``, those named in ``lock``, and the source of each mimic named
    in ``lock`` (a mimic is locked with its source).
    """
    _, order, _ = _dfs(links, joints)
    parent_of = {j.child: j for j in order}
    chain: set[str] = set()
    link = tool
    while link in parent_of and parent_of[link].name not in chain:
        chain.add(parent_of[link].name)
        link = parent_of[link].parent
    out = {j.name for j in order if j.free and j.name not in chain}
    for name in lock:
        out.add(mimics[name].source if name in mimics else name)
    return out


def mimic_error(mimic: Mimic, origin: str) -> UrdfRuleError:
    """The refusal of a mimic Pinocchio cannot build (``unbuildable``) whose source stays free."""
    fix = (f"rename the branches so that {mimic.source}'s comes first" if "builds" in (mimic.unbuildable or "")
           else f"give {mimic.joint} the type of {mimic.source}")  # fmt: skip
    return UrdfRuleError("mimic-unresolved", f"{origin}: {mimic.unbuildable}; {mimic.source} moves freely, so "
                         f"{mimic.joint} cannot be locked with it (--lock {mimic.source}=VALUE locks both): {fix}")
