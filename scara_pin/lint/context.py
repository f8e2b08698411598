"""What the rules of ``check`` share: the file as read, the findings so far, and what earlier rules established.

A :class:`Context` is made per file. The rules (:mod:`scara_pin.lint.registry`) run in the table's order; each
reads the context and adds findings. What several rules read is computed here once, lazily: the parsed
document with each element's line (:attr:`Context.document`), the tree walked at q = 0 with its own transforms,
independent of Pinocchio (:attr:`Context.tree`), the tool and base frames (the loader's own rule,
:func:`scara_pin.urdf_rules.choose_frames`), the chain between them (:attr:`Context.chain`), the axes in the base
frame (:attr:`Context.axes`), and the robot as the toolkit loads it (:attr:`Context.robot`): so that what
``check`` reports is what the other commands will do. A rule reading the tree runs only after the rules that
make it well-formed found no error (the table's gates).
"""

from __future__ import annotations

import itertools
import logging
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any
from xml.etree.ElementTree import Element

import numpy as np

from .._checks import number_text
from .._urdf_checks import parse_urdf_xml
from ..errors import UrdfError
from ..kinematics.kinds import kinematics_for
from ..model import RobotModel
from ..urdf_rules import MOVABLE, FrameChoice, JointEdge, Mimic, locked_joints, mimic_error, resolve_mimics, zero_within
from .report import Finding, Severity

if TYPE_CHECKING:
    from ..description.xacro_sources import SourceMap

__all__ = ["KNOWN_TYPES", "SAMPLES", "Context", "LintJoint", "Stop", "rpy_matrix", "shown_path"]

KNOWN_TYPES = (*MOVABLE, "fixed", "floating", "planar")
"""URDF joint types."""
SAMPLES = 200
"""Seeded uniform configurations (seed 0) a rule samples besides the limits' combinations (:attr:`Context.samples`)."""


class Stop(Exception):
    """Internal: stop the checks (the findings so far say why)."""


class _Quiet(logging.Filter):
    """Drops every record (the loader's warnings while ``check`` loads the file: they are findings)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return False


def rpy_matrix(r: float, p: float, y: float) -> np.ndarray:
    """URDF: R = Rz(y) Ry(p) Rx(r) (written here: the linter's walk is independent of Pinocchio)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip


def shown_path(source: str, path: Path, top: Path) -> str:
    """A source file's name as the report shows it: the checked file (``top``) as given, others beside it."""
    if path == top:
        return source
    rel = os.path.relpath(path, top.parent)
    return str(Path(source).parent / rel) if not rel.startswith("..") else str(path)


@dataclass
class LintJoint:
    """A ``<joint>`` as written (numbers read with urdfdom's grammar: NaN where it is not a number).

    ``origin_line`` is the line of its ``<origin>`` (else its own); ``mimic`` the joint it follows with the
    multiplier and offset as written; ``world`` its frame at q = 0 in the root link (set by the tree walk).
    """

    el: Element
    name: str
    type: str
    line: int | None
    parent: str
    child: str
    xyz: tuple[float, ...] = (0.0, 0.0, 0.0)
    rpy: tuple[float, ...] = (0.0, 0.0, 0.0)
    origin_line: int | None = None
    axis: tuple[float, ...] = (1.0, 0.0, 0.0)
    axis_line: int | None = None
    limit: dict[str, str] | None = None
    limit_line: int | None = None
    mimic: tuple[str, float, float] | None = None
    unnamed_mimic: bool = False
    world: np.ndarray = field(default_factory=lambda: np.eye(4))

    @property
    def movable(self) -> bool:
        """Revolute, continuous or prismatic."""
        return self.type in MOVABLE

    def numbers(self, attr: str) -> tuple[float, ...]:
        """``limit`` attribute ``attr`` as a 1-tuple (NaN when malformed), or () when absent."""
        raw = None if self.limit is None else self.limit.get(attr)
        return () if raw is None else (number_text(raw),)


def _triple(el: Element | None, attr: str, default: tuple[float, ...]) -> tuple[float, ...]:
    """An attribute of numbers (urdfdom's grammar; NaN where malformed); ``default`` when absent."""
    raw = None if el is None else el.get(attr)
    return default if raw is None else tuple(number_text(v) for v in raw.split())


@dataclass
class Document:
    """The links and joints as written, in file order (duplicates and nameless ones included)."""

    root: Element
    lines: dict[Element, int]
    links: list[tuple[str, Element]]
    joints: list[LintJoint]

    def line(self, el: Element | None) -> int | None:
        """An element's line (None for None)."""
        return None if el is None else self.lines.get(el)


@dataclass
class Tree:
    """The kinematic tree, walked depth-first from the root (siblings in file order), at q = 0.

    Attributes:
        root: the root link. links: each link's line. joints: each joint by name.
        order: the joints depth-first. parent_of: each link's parent joint. children: each link's child joints.
        link_world: each link's frame at q = 0 in the root link.
    """

    root: str
    links: dict[str, int | None]
    joints: dict[str, LintJoint]
    order: list[LintJoint]
    parent_of: dict[str, LintJoint]
    children: dict[str, list[LintJoint]]
    link_world: dict[str, np.ndarray]

    def supports(self, link: str) -> list[LintJoint]:
        """The joints between the root and ``link``, root first."""
        out: list[LintJoint] = []
        seen: set[str] = set()
        while link in self.parent_of and link not in seen:  # (a cycle ends the walk)
            seen.add(link)
            out.append(self.parent_of[link])
            link = self.parent_of[link].parent
        return out[::-1]


@dataclass
class Chain:
    """The joints of q as the loader keeps them (:mod:`scara_pin.chain`).

    Attributes:
        movable: every movable joint, depth-first (geared ones included).
        joints: the chain's free joints from the root to the tool, not locked: the joints of q.
        off_chain: free joints not on that chain and not locked by the user (the loader locks them).
    """

    movable: list[LintJoint]
    joints: list[LintJoint]
    off_chain: list[LintJoint]


class Context:
    """One file being checked: its text and options, the findings so far, what the rules share (module docstring).

    Attributes:
        text: the URDF document (a file's: read by the ``unreadable`` or ``xacro-failed`` rule). source: its name
            in the report. path: the file, when one is checked; package_dirs: where its packages are looked for.
        tool_asked, base_asked: the frames asked for (``--tool``, ``--base``). lock: ``--lock`` values [rad, m].
        load_kwargs: passed to :class:`scara_pin.model.RobotModel` (a file's package folders: set with its text).
        sources: a xacro file's map from expanded lines to where each element was written (likewise).
        findings: in the order found.
    """

    def __init__(self, text: str, source: str, tool: str | None = None, base: str | None = None,
                 lock: Mapping[str, float] | None = None, path: Path | None = None,
                 package_dirs: Sequence[str | Path] = ()) -> None:  # fmt: skip
        self.text = text
        self.source = source
        self.path = path
        self.package_dirs = tuple(Path(d) for d in package_dirs)
        self.tool_asked = tool
        self.base_asked = base
        self.lock = dict(lock or {})
        self.load_kwargs: dict[str, Any] = {}
        self.sources: SourceMap | None = None
        self.findings: list[Finding] = []

    # ------------------------------------------------------------------------------------------ findings
    def add(self, severity: Severity, code: str, message: str, line: int | None = None,
            joint: str | None = None) -> None:  # fmt: skip
        """Record a finding at ``line`` of the checked text (a xacro file's: mapped to where it was written)."""
        if self.sources is None:
            self.findings.append(Finding(severity, code, message, line, joint))
            return
        where = self.sources.where(line)  # the file and line where the element was written
        self.findings.append(Finding(severity, code, message, where[1] if where else None, joint,
                                     self.shown(where[0]) if where else None, line))  # fmt: skip

    def error(self, code: str, message: str, line: int | None = None, joint: str | None = None) -> None:
        """Record an error finding."""
        self.add(Severity.ERROR, code, message, line, joint)

    @property
    def has_errors(self) -> bool:
        """Whether an error was found so far."""
        return any(f.severity is Severity.ERROR for f in self.findings)

    def found(self, code: str, severity: Severity | None = None) -> bool:
        """Whether a finding of ``code`` (of that severity) was made so far."""
        return any(f.code == code and (severity is None or f.severity is severity) for f in self.findings)

    def at(self, line: int | None) -> str:
        """``line 12`` in a message; for a xacro file, the file and line where the element was written."""
        where = self.sources.where(line) if self.sources is not None else None
        if where is not None:
            return f"{self.shown(where[0])}:{where[1]}"
        return f"line {line}" if self.sources is None else f"line {line} of the expanded document"

    def shown(self, path: Path) -> str:
        """A source file's name as the report shows it (:func:`shown_path`)."""
        top = self.sources.top if self.sources is not None else Path(self.source).resolve()
        return shown_path(self.source, path, top)

    # ------------------------------------------------------------------------------------------ the file
    @cached_property
    def parsed(self) -> tuple[Element, dict[Element, int]]:
        """The tree as urdfdom reads it, each element's line (the loader's reader; ``malformed-xml`` parses it)."""
        return parse_urdf_xml(self.text)

    @cached_property
    def document(self) -> Document:
        """The document's links and joints as written (read once the ``too-large`` rule has sized it)."""
        root, lines = self.parsed
        links = [(el.get("name") or "", el) for el in root.findall("link")]
        named_empty = any(el.get("name") == "" for el in root.findall("joint"))
        joints = []
        for el in root.findall("joint"):
            parent_el, child_el = el.find("parent"), el.find("child")
            origin, axis, limit, mimic = el.find("origin"), el.find("axis"), el.find("limit"), el.find("mimic")
            line = lines.get(el)
            j = LintJoint(el, el.get("name") or "", el.get("type") or "", line,
                          (parent_el.get("link") or "") if parent_el is not None else "",
                          (child_el.get("link") or "") if child_el is not None else "")  # fmt: skip
            j.xyz = _triple(origin, "xyz", j.xyz)
            j.rpy = _triple(origin, "rpy", j.rpy)
            j.origin_line = lines.get(origin) if origin is not None else line
            j.axis = _triple(axis, "xyz", (0.0, 0.0, 0.0)) if axis is not None else j.axis  # urdfdom: <axis/> is 0
            j.axis_line = lines.get(axis) if axis is not None else line
            if limit is not None:
                j.limit, j.limit_line = dict(limit.attrib), lines.get(limit)
            if mimic is not None and mimic.get("joint") == "" and not named_empty:  # names no joint: ignored
                j.unnamed_mimic = True
            elif mimic is not None and j.movable:
                m, c = (number_text(mimic.get(a, d)) for a, d in (("multiplier", "1"), ("offset", "0")))
                j.mimic = (mimic.get("joint", ""), m, c)
            joints.append(j)
        return Document(root, lines, links, joints)

    @cached_property
    def tree(self) -> Tree:
        """The tree walked from its root (valid once the tree rules found no error: one root, no cycle)."""
        doc = self.document
        links: dict[str, int | None] = {}
        for name, el in doc.links:
            links.setdefault(name, doc.lines.get(el))
        joints: dict[str, LintJoint] = {}
        for j in doc.joints:
            joints.setdefault(j.name, j)
        parent_of = {j.child: j for j in sorted(joints.values(), key=lambda j: j.name.encode())}  # urdfdom's choice
        children: dict[str, list[LintJoint]] = {}
        for j in joints.values():
            children.setdefault(j.parent, []).append(j)
        roots = [name for name in links if name not in parent_of]
        root = roots[0] if roots else ""
        order: list[LintJoint] = []
        link_world: dict[str, np.ndarray] = {root: np.eye(4)}
        stack = list(reversed(children.get(root, [])))
        while stack:
            j = stack.pop()
            if j.child in link_world or parent_of[j.child] is not j:  # a cycle, or a second parent: not urdfdom's
                continue
            M = np.eye(4)
            M[:3, :3] = rpy_matrix(*j.rpy)
            M[:3, 3] = j.xyz
            j.world = link_world[j.parent] @ M
            link_world[j.child] = j.world
            order.append(j)
            stack.extend(reversed(children.get(j.child, [])))
        return Tree(root, links, joints, order, parent_of, children, link_world)

    chosen: FrameChoice
    """The tool and base frames (set by the ``frame-missing`` rule: the loader's choose_frames)."""

    @cached_property
    def edges(self) -> list[JointEdge]:
        """The joints as the loader's rules read them (:class:`scara_pin.urdf_rules.JointEdge`), file order."""
        out = []
        for j in self.tree.joints.values():
            src, m, c = (None, 1.0, 0.0) if j.mimic is None else j.mimic
            out.append(JointEdge(j.name, j.type, j.parent, j.child, mimic=src, multiplier=m, offset=c))
        return out

    @cached_property
    def mimics(self) -> tuple[dict[str, Mimic], Exception | None]:
        """(each mimic joint resolved to its free joint, None), or ({}, why they cannot be: the loader's error).

        A mimic Pinocchio cannot build (``Mimic.unbuildable``) is the loader's error unless its source is locked
        (then it is locked with it; read once the frames are chosen).
        """
        try:
            resolved = resolve_mimics(self.edges, self.source)
        except UrdfError as exc:
            return {}, exc
        unbuilt = [m for m in resolved.values() if m.unbuildable is not None]
        chosen = getattr(self, "chosen", None)
        if unbuilt and chosen is not None:
            links = list(self.tree.links)
            locked = locked_joints(links, self.edges, chosen.tool, self.lock, resolved)
            for m in unbuilt:
                if m.source not in locked:
                    return {}, mimic_error(m, self.source)
        return resolved, None

    @cached_property
    def chain(self) -> Chain:
        """The joints of q (:class:`Chain`)."""
        tree = self.tree
        on_path = {j.name for j in tree.supports(self.chosen.tool)}
        movable = [j for j in tree.order if j.movable]
        free = [j for j in movable if j.mimic is None and j.name not in self.lock]
        return Chain(movable, [j for j in free if j.name in on_path], [j for j in free if j.name not in on_path])

    @cached_property
    def base_from_root(self) -> np.ndarray:
        """bMo: the root's frame in the base frame (4 x 4)."""
        return np.linalg.inv(self.tree.link_world[self.chosen.base])

    @cached_property
    def axes(self) -> dict[str, tuple[float, float, float]]:
        """Each joint of q's unit axis in the base frame at q = 0."""
        bMo = self.base_from_root
        out = {}
        for j in self.chain.joints:
            axis = (bMo @ j.world)[:3, :3] @ (np.asarray(j.axis) / np.linalg.norm(j.axis))
            out[j.name] = (float(axis[0]), float(axis[1]), float(axis[2]))
        return out

    def tilt(self, joint: str) -> float:
        """The angle between a joint of q's axis and the base z axis, either way [rad]."""
        a = self.axes[joint]
        return math.atan2(math.hypot(a[0], a[1]), abs(a[2]))

    @cached_property
    def samples(self) -> np.ndarray:
        """Configurations of the joints of q (rows), where rules measure what a quirk costs.

        Each joint at its lower limit, mid-range and upper limit in every combination, then :data:`SAMPLES`
        seeded uniform ones (a continuous joint: one turn).
        """
        ranges = []
        for j in self.chain.joints:
            lo, hi = (j.numbers("lower") or (0.0,))[0], (j.numbers("upper") or (0.0,))[0]
            ranges.append((-math.pi, math.pi) if j.type == "continuous" or not math.isfinite(lo + hi)
                          else (min(lo, hi), max(lo, hi)))  # inverted limits: their own error, sampled all the same
        if not ranges:
            return np.zeros((1, 0))
        grid = np.array(list(itertools.product(*[(lo, (lo + hi) / 2.0, hi) for lo, hi in ranges])))
        rng = np.random.default_rng(0)
        return np.vstack([grid, rng.uniform([r[0] for r in ranges], [r[1] for r in ranges], (SAMPLES, len(ranges)))])

    def tool_position(self, q: np.ndarray, rpy: tuple[str, tuple[float, ...]] | None = None) -> np.ndarray:
        """The tool point in the base frame at ``q`` (the joints of q), by the linter's own walk [m].

        ``rpy``: (a joint, the rpy its origin takes instead of the file's). Geared joints follow their free
        joint (:attr:`mimics`); locked ones sit at their ``--lock`` value, else 0 (or their nearest limit).
        """
        index = {j.name: i for i, j in enumerate(self.chain.joints)}
        resolved = self.mimics[0]

        def value(j: LintJoint) -> float:
            if j.name in index:
                return float(q[index[j.name]])
            if j.name in resolved:
                m = resolved[j.name]
                src = self.tree.joints[m.source]
                return m.multiplier * value(src) + m.offset
            lo, hi = (j.numbers("lower") or (None,))[0], (j.numbers("upper") or (None,))[0]
            return self.lock.get(j.name, 0.0 if j.type == "continuous" else zero_within(lo, hi))

        M = np.eye(4)
        for j in self.tree.supports(self.chosen.tool):
            T = np.eye(4)
            T[:3, :3] = rpy_matrix(*(rpy[1] if rpy is not None and rpy[0] == j.name else j.rpy))
            T[:3, 3] = j.xyz
            if j.movable:
                axis, v = np.asarray(j.axis) / np.linalg.norm(j.axis), value(j)
                motion = np.eye(4)
                if j.type == "prismatic":
                    motion[:3, 3] = axis * v
                else:  # Rodrigues
                    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
                    motion[:3, :3] = np.eye(3) + math.sin(v) * K + (1.0 - math.cos(v)) * (K @ K)
                T = T @ motion
            M = M @ T
        return (self.base_from_root @ M)[:3, 3]

    @property
    def tool(self) -> str | None:
        """The tool frame, once the chain has joints (else None)."""
        return self.chosen.tool if getattr(self, "chosen", None) is not None and self.chain.joints else None

    # ------------------------------------------------------------------------------------------ the toolkit
    @cached_property
    def loaded(self) -> tuple[RobotModel | None, Exception | None]:
        """(the robot as the toolkit loads it, None) or (None, the UrdfError saying why it cannot)."""
        quiet = _Quiet()  # the loader's warnings are findings here already (xacro-ignored): not logged twice
        logging.getLogger("scara_pin").addFilter(quiet)
        try:
            robot = RobotModel(self.text, origin=self.source, tool_frame=self.tool_asked, base_frame=self.base_asked,
                          kinematics=kinematics_for, lock=self.lock, **self.load_kwargs)  # the same choose_frames
        except UrdfError as exc:
            return None, exc
        finally:
            logging.getLogger("scara_pin").removeFilter(quiet)
        return robot, None

    @property
    def robot(self) -> RobotModel | None:
        """The loaded robot, or None when the toolkit refuses the file."""
        return self.loaded[0]

    @cached_property
    def kinematics(self) -> tuple[Any, Exception | None]:
        """(the robot's kinematics, None) or (None, the closed form's refusal: NotScaraError, NotPalletizerError)."""
        robot = self.robot
        if robot is None:
            return None, None
        try:
            return robot.kinematics, None
        except UrdfError as exc:
            return None, exc
