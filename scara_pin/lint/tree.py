"""Rules of the tree and its names: the XML, the elements' names, the links joints connect, the chain of q.

Each rule is a function of the :class:`~scara_pin.lint.context.Context`; its code and place in the run are in
:data:`scara_pin.lint.registry.RULES`.
"""

from __future__ import annotations

import re
from pathlib import Path

from .._urdf_checks import second_parents, xacro_leftovers
from ..description import JOINT_COUNTS
from ..errors import InvalidInputError, UrdfError
from .context import KNOWN_TYPES, Context, Stop, shown_path
from .report import Finding, Severity

__all__ = [
    "disconnected", "duplicate_name", "geared", "joint_count", "joint_type", "joints", "locked",
    "malformed_xml", "mimic_ignored", "mimic_unresolved", "missing_link", "missing_name", "no_wrist", "not_serial",
    "root_not_robot",
    "too_large", "two_parents", "unreadable", "xacro_failed", "xacro_ignored", "xacro_not_expanded",
]  # fmt: skip


def unreadable(ctx: Context) -> None:
    """A file that cannot be read (missing, too large, not UTF-8, a device); its URDF text read otherwise."""
    from ..description.packages import PackagePath, read_robot_file
    from ..limits import check_input_file

    path = ctx.path
    if path is None:  # text given
        return
    try:  # bounded: /dev/zero or a huge file is refused, not read whole
        check_input_file(path, "URDF")
        ctx.load_kwargs["package_path"] = PackagePath(ctx.package_dirs, path.parent)
        if not path.name.endswith(".xacro"):
            ctx.text = read_robot_file(path, ctx.load_kwargs["package_path"])
    except (InvalidInputError, UrdfError) as exc:
        reason = f"cannot be read ({exc})" if isinstance(exc, InvalidInputError) else getattr(exc, "reason", str(exc))
        ctx.error("unreadable", reason.removeprefix(f"{path}: "))
        raise Stop from None


def xacro_failed(ctx: Context) -> None:
    """A ``.xacro`` file that cannot be expanded (a missing package, an undefined property: where, when known)."""
    from ..description.xacro_sources import expand_with_sources

    path = ctx.path
    if path is None or not path.name.endswith(".xacro"):
        return
    try:  # the loader's text, and where each element was written
        ctx.text, ctx.sources = expand_with_sources(path, ctx.load_kwargs["package_path"])
    except UrdfError as exc:
        reason = getattr(exc, "reason", str(exc)).removeprefix(f"{path}: ")
        file, line = getattr(exc, "file", None), getattr(exc, "line", None)  # where xacro failed, when known
        shown = None if file is None else shown_path(str(path), Path(file), path.resolve())
        ctx.findings.append(Finding(Severity.ERROR, "xacro-failed", reason, line, None, shown))
        raise Stop from None


def malformed_xml(ctx: Context) -> None:
    """The text is not well-formed XML (expat's reason and line)."""
    try:
        _ = ctx.parsed
    except Exception as exc:  # expat.ExpatError (malformed), ValueError (encoding declarations)
        ctx.error("malformed-xml", f"malformed XML: {getattr(exc, 'args', [exc])[0]}", getattr(exc, "lineno", None))
        raise Stop from None


def root_not_robot(ctx: Context) -> None:
    """The root element is not ``<robot>``."""
    root, lines = ctx.parsed
    if root.tag != "robot":
        ctx.error("root-not-robot", f"the root element is <{root.tag}>, not <robot>", lines.get(root))
        raise Stop


def too_large(ctx: Context) -> None:
    """More links and joints than :data:`~scara_pin.limits.MAX_CHECK_ELEMENTS`."""
    from ..limits import MAX_CHECK_ELEMENTS

    root = ctx.parsed[0]
    size = len(root.findall("link")) + len(root.findall("joint"))
    if size > MAX_CHECK_ELEMENTS:
        ctx.error("too-large", f"{size} links and joints, above the cap of {MAX_CHECK_ELEMENTS:,}")
        raise Stop


def xacro_not_expanded(ctx: Context) -> None:
    """Xacro in a URDF that changes the robot (a macro, a condition, a substitution): the loaders' rule."""
    leftover = xacro_leftovers(ctx.document.root)
    if leftover is not None and leftover[0]:
        ctx.error("xacro-not-expanded", leftover[1], ctx.document.line(leftover[2]))
        raise Stop


def xacro_ignored(ctx: Context) -> None:
    """Only ``<xacro:property>``/``<xacro:arg>`` declarations never substituted: the loaders ignore them."""
    leftover = xacro_leftovers(ctx.document.root)
    if leftover is not None and not leftover[0]:
        ctx.add(Severity.WARNING, "xacro-ignored", leftover[1], ctx.document.line(leftover[2]))


def missing_name(ctx: Context) -> None:
    """A ``<joint>`` without a name attribute, a ``<link>`` without a name (or named "") beside other links.

    ``name=""`` is a name for urdfdom (and Pinocchio): a joint may have it; a link named "" cannot be any joint's
    parent or child, so beside other links it makes a second root (the loader's rule, ``link-name``).
    """
    doc = ctx.document
    for name, el in doc.links:
        if not name and len(doc.links) > 1:
            what = "no name" if el.get("name") is None else 'name=""'
            ctx.error("missing-name", f"a <link> has {what}: no joint can name it as its parent or child (a second "
                      "root link)", doc.line(el))  # fmt: skip
    for j in doc.joints:
        if j.el.get("name") is None:
            ctx.error("missing-name", 'a <joint> has no name attribute (name="" would do)', j.line)


def duplicate_name(ctx: Context) -> None:
    """Two links, or two joints, of one name."""
    doc = ctx.document
    first: dict[str, int | None] = {}
    for name, el in doc.links:
        if name and name in first:
            ctx.error("duplicate-name", f"link {name!r} is defined twice (first at {ctx.at(first[name])})",
                      doc.line(el))  # fmt: skip
        first.setdefault(name, doc.line(el))
    seen: dict[str, int | None] = {}
    for j in doc.joints:
        if j.name and j.name in seen:
            ctx.error("duplicate-name", f"joint {j.name!r} is defined twice (first at {ctx.at(seen[j.name])})",
                      j.line, j.name)  # fmt: skip
        seen.setdefault(j.name, j.line)


def joint_type(ctx: Context) -> None:
    """A joint type URDF does not have (an error), or one a SCARA does not (floating, planar: a warning)."""
    for j in ctx.document.joints:
        if not j.name:
            continue
        if j.type not in KNOWN_TYPES:
            ctx.error("joint-type", f"joint {j.name} has type {(j.type or None)!r}: not a URDF joint type", j.line,
                      j.name)  # fmt: skip
        elif j.type in ("floating", "planar"):
            ctx.add(Severity.WARNING, "joint-type", f"joint {j.name} is {j.type}: a SCARA has revolute and prismatic "
                    "joints (off the arm's chain it is locked; on it, the file does not load)", j.line,
                    j.name)  # fmt: skip


def missing_link(ctx: Context) -> None:
    """A joint's parent or child that is no link of the file."""
    names = {name for name, _ in ctx.document.links}
    for j in ctx.document.joints:
        if not j.name:
            continue
        for role in ("parent", "child"):
            target = getattr(j, role)
            if not target or target not in names:
                shown = f"link {target!r}, which is not defined" if target else f"no <{role} link=...>"
                ctx.error("missing-link", f"joint {j.name}'s {role} is {shown}", j.line, j.name)


def two_parents(ctx: Context) -> None:
    """A link that is the child of two joints: an error with movable joints below it, else a warning.

    The loader's rule (``scara_pin._urdf_checks.second_parents``).
    """
    order = {j.name: k for k, j in enumerate(ctx.document.joints)}
    for link, kept, other, harmful in second_parents(ctx.document.root):
        j = ctx.tree.joints.get(max(kept, other, key=lambda n: order.get(n, -1)))  # the second written
        line, name = (j.line, j.name) if j is not None else (None, None)
        if harmful:
            ctx.error("two-parents", f"link {link} is the child of joints {other} and {kept}: urdfdom keeps {kept}, "
                      "and Pinocchio would build the link's branch twice, its movable joints named twice", line,
                      name)  # fmt: skip
        else:
            ctx.add(Severity.WARNING, "two-parents", f"link {link} is the child of joints {other} and {kept}: {other} "
                    "is ignored, as urdfdom does (it keeps the last by name)", line, name)  # fmt: skip


def disconnected(ctx: Context) -> None:
    """Not one tree: no link, several root links, every link a joint's child; links the root does not reach."""
    tree = ctx.tree
    if not tree.links:
        ctx.error("disconnected", "the document has no <link>: a URDF has at least one (a xacro file of macros only "
                  "defines them: call one, or check the file that does)")  # fmt: skip
        return
    roots = [name for name in tree.links if name not in tree.parent_of]
    if len(roots) != 1:
        shown = ", ".join(f"{r} ({ctx.at(tree.links[r])})" for r in roots) or \
            f"every one of its {len(tree.links)} links is a joint's child (a cycle)"  # fmt: skip
        ctx.error("disconnected", f"the tree must have one root link; this file has {len(roots)}: {shown}")
        return
    unreached = [n for n in tree.links if n not in tree.link_world]
    if unreached:  # urdfdom and Pinocchio leave them out: the robot is the tree the root reaches
        ctx.add(Severity.WARNING, "disconnected", f"links not connected to the root {tree.root}: "
                f"{', '.join(unreached[:12])} (joints in a cycle): Pinocchio leaves them out",
                tree.links[unreached[0]])  # fmt: skip


def locked(ctx: Context) -> None:
    """Free joints off the chain root -> tool: the loader locks them."""
    off = ctx.chain.off_chain
    if off:
        shown = ", ".join(j.name for j in off[:12]) + (" ..." if len(off) > 12 else "")
        ctx.add(Severity.INFO, "locked", f"{len(off)} movable joint(s) not on the chain {ctx.tree.root} -> "
                f"{ctx.chosen.tool} are locked (at 0, or the nearest limit; --lock JOINT=VALUE sets them): {shown}")


def geared(ctx: Context) -> None:
    """A ``<mimic>`` joint: it follows another, not in q (a mimic of a mimic: the composition, to the free joint)."""
    resolved = ctx.mimics[0]
    for j in ctx.chain.movable:
        if j.mimic is not None:
            src, m, c = j.mimic
            unit = "m" if j.type == "prismatic" else "rad"
            r = resolved.get(j.name)
            through = "" if r is None or not r.via else (
                f"; {src} follows {' -> '.join(r.via[1:] + (r.source,))} in turn: {j.name} = {r.multiplier:.9g} * "
                f"{r.source} + {r.offset:.9g} {unit}, as the toolkit hands it to Pinocchio")  # fmt: skip
            locked = "" if r is None or r.unbuildable is None else (
                f"; {r.unbuildable}: the loader locks it with {r.source} (off the arm, or --lock)")  # fmt: skip
            ctx.add(Severity.INFO, "geared", f"joint {j.name} follows {src} (<mimic>): {j.name} = {m:.9g} * {src} "
                    f"+ {c:.9g} {unit}{through}; not a degree of freedom (not in q), reported beside it{locked}",
                    j.line, j.name)  # fmt: skip


def mimic_unresolved(ctx: Context) -> None:
    """A ``<mimic>`` that leads to no free joint (a loop, a missing or fixed source) or that Pinocchio cannot take."""
    error = ctx.mimics[1]
    if error is not None:
        text = str(error).removeprefix(f"{ctx.source}: ")
        found = ((re.search(rf"(?<!\w){re.escape(name)}(?!\w)", text), name) for name in ctx.tree.joints)
        at = [(m.start(), name) for m, name in found if m is not None]
        joint = ctx.tree.joints[min(at)[1]] if at else None  # the first joint the message names
        ctx.error("mimic-unresolved", text, joint.line if joint else None,
                  joint.name if joint else None)  # fmt: skip


def mimic_ignored(ctx: Context) -> None:
    """A ``<mimic joint="">``: it names no joint; ignored (the joint is free), as Pinocchio's parser reads it."""
    for j in ctx.document.joints:
        if j.unnamed_mimic:
            ctx.add(Severity.WARNING, "mimic-ignored", f'joint {j.name}\'s <mimic joint=""> names no joint: ignored, '
                    "as Pinocchio's parser reads it; the joint is free", j.line, j.name)  # fmt: skip


def _listing(ctx: Context) -> str:
    joints = ctx.chain.joints
    listing = ", ".join(f"{j.name} ({j.type}, {ctx.at(j.line)})" for j in joints[:12])
    if len(joints) > 12:
        listing += f", ... ({len(joints) - 12} more)"
    return listing or "none"


def joints(ctx: Context) -> None:
    """The joints of q, in chain order."""
    ctx.add(Severity.INFO, "joints", f"{len(ctx.chain.joints)} movable joints in chain order: {_listing(ctx)}")


def _branched(ctx: Context) -> bool:
    """Not 4 joints (or 3) on the chain, but as many free joints in the whole tree: one hung on the wrong link."""
    chain = ctx.chain
    return bool(chain.off_chain) and len(chain.joints) + len(chain.off_chain) in JOINT_COUNTS


def joint_count(ctx: Context) -> None:
    """Not 4 joints (or 3 without a wrist) on the chain root -> tool; the joints off it are locked, not blamed."""
    n = len(ctx.chain.joints)
    if n in JOINT_COUNTS or _branched(ctx):
        return
    if not ctx.chain.off_chain:
        ctx.error("joint-count", f"a SCARA has 4 movable joints (3 revolute, 1 prismatic), or 3 without a wrist (2 "
                  f"revolute, 1 prismatic); this file has {n}: {_listing(ctx)}")  # fmt: skip
        return
    ctx.error("joint-count", f"the chain {ctx.tree.root} -> {ctx.chosen.tool} has {n} free joints: {_listing(ctx)}; "
              f"a SCARA has 4 (3 without a wrist) ({len(ctx.chain.off_chain)} joint(s) off the chain are locked, "
              "not counted): --tool picks an arm's last link, --lock JOINT=VALUE fixes a joint of the chain, "
              "<mimic> makes a passive joint follow another")  # fmt: skip


def not_serial(ctx: Context) -> None:
    """Too few joints on the chain, the others hung off it: where the tree branches (a joint on the wrong link)."""
    chain = ctx.chain
    if len(chain.joints) in JOINT_COUNTS or not _branched(ctx):
        return
    free = [j for j in chain.movable if j.mimic is None and j.name not in ctx.lock]
    for a, b in zip(free, free[1:]):
        if a not in ctx.tree.supports(b.child):
            ctx.error("not-serial", f"joint {b.name} is not downstream of {a.name}: not a serial chain (the chain "
                      f"{ctx.tree.root} -> {ctx.chosen.tool} has {len(chain.joints)} movable joints; --tool picks an "
                      "arm's last link)", b.line, b.name)  # fmt: skip
            return


def no_wrist(ctx: Context) -> None:
    """Three joints: a SCARA without a wrist (2 revolute, 1 prismatic)."""
    chain = ctx.chain.joints
    if len(chain) == 3 and sorted(j.type == "prismatic" for j in chain) == [False, False, True]:
        ctx.add(Severity.INFO, "no-wrist", "3 movable joints: a SCARA without a wrist (2 revolute, 1 prismatic); fk "
                "takes 3 joint values and ik a tool point X Y Z (the tool's yaw follows the arm)")  # fmt: skip
