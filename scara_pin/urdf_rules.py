"""Rules shared by the loader (:class:`scara_pin.model.Robot`) and the linter (:mod:`scara_pin.lint`).

One place for what both must agree on, so that whatever ``scara-pin check`` says the toolkit will do, it
does:

- :func:`choose_frames`: the tool and base frames (``tool0`` if present, else the chain's last link;
  ``base`` if present, else the root link; a named frame that does not exist is an error);
- :func:`joint_problem`: a joint the toolkit cannot use (zero axis, non-finite or inverted limits, a range
  of zero width).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .errors import UrdfError

__all__ = ["MOVABLE", "FrameChoice", "JointEdge", "choose_frames", "joint_problem", "read_tree"]

MOVABLE = ("revolute", "continuous", "prismatic")
"""URDF joint types that move (each one value of q)."""


@dataclass(frozen=True)
class JointEdge:
    """A URDF joint as the tree sees it: name, type, parent link, child link; its limits and mimic as written.

    ``lower``/``upper``: the position limits (None when absent); ``mimic``: the joint it follows, if any.
    """

    name: str
    type: str
    parent: str
    child: str
    lower: float | None = None
    upper: float | None = None
    mimic: str | None = None


@dataclass(frozen=True)
class FrameChoice:
    """The frames the toolkit uses.

    Attributes:
        base: the reference frame of poses (a link).
        tool: the tool frame (a link).
        note: when the tool was chosen by default without a ``tool0``: the one-line notice saying which
            link is the tool (the CLI prints it as ``info:``); else None.
        root: the root link of the tree.
    """

    base: str
    tool: str
    note: str | None = None
    root: str = ""


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
        tool: the tool frame asked for (``--tool``); default: ``tool0`` if present, else the chain's last
            link (the deepest link below the last movable joint, the first in file order at each level).
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
            raise UrdfError(f"{origin}: no link named {name!r} for the {what} frame (--{what}); links: {shown}")
    root, order, children = _dfs(links, joints)
    if base is None:
        base = "base" if "base" in links else root
    else:  # the base is fixed: no movable joint between it and the root
        parent_of = {j.child: j for j in order}
        link = base
        while link in parent_of:
            if parent_of[link].type in MOVABLE:
                fixed = ", ".join([root] + [j.child for j in order if j.child not in _downstream_of_movable(order)])
                raise UrdfError(f"{origin}: the base frame (--base) {base!r} moves with joint "
                                f"{parent_of[link].name}: the base must be fixed to the root link; "
                                f"fixed links: {fixed}")  # fmt: skip
            link = parent_of[link].parent
    note = None
    if tool is None:
        if "tool0" in links:
            tool = "tool0"
        else:
            chain = [j for j in order if j.type in MOVABLE]
            tool = root
            level = [chain[-1].child] if chain else []
            while level:
                tool = level[0]
                level = [j.child for link in level for j in children.get(link, [])]
            note = f"no tool0 frame: {tool} (the chain's last link) is taken as the tool; --tool FRAME picks another"
    return FrameChoice(base=base, tool=tool, note=note, root=root)


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
    if text is None:
        return None
    try:
        return float(text)
    except ValueError:
        return math.nan


def read_tree(urdf: str, origin: str) -> tuple[list[str], list[JointEdge]]:
    """Read the links and joints of URDF text (file order), and check every movable joint (:func:`joint_problem`).

    Raises:
        UrdfError: the first unusable joint (one line naming the joint and the rule).
    """
    import xml.etree.ElementTree as ET

    root = ET.fromstring(urdf)  # the caller has parsed it once already: it is well-formed
    links = [el.get("name", "") for el in root.findall("link")]
    joints = []
    for el in root.findall("joint"):
        name, kind = el.get("name", ""), el.get("type", "")
        parent, child = el.find("parent"), el.find("child")
        axis_el, limit, mimic = el.find("axis"), el.find("limit"), el.find("mimic")
        lo = _float(limit.get("lower")) if limit is not None else None
        hi = _float(limit.get("upper")) if limit is not None else None
        joints.append(JointEdge(name, kind, parent.get("link", "") if parent is not None else "",
                                child.get("link", "") if child is not None else "", lo, hi,
                                None if mimic is None else mimic.get("joint", "")))  # fmt: skip
        if kind not in MOVABLE or mimic is not None:  # a mimic joint follows another: not in q
            continue
        try:
            axis = [float(v) for v in (axis_el.get("xyz", "1 0 0") if axis_el is not None else "1 0 0").split()]
        except ValueError:
            axis = [math.nan]
        problem = joint_problem(name, kind, axis, lo, hi)
        if problem is not None:
            raise UrdfError(f"{origin}: {problem[1]} [{problem[0]}]")
    return links, joints
