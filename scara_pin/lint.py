"""Lint a third-party SCARA URDF: what is wrong, where (line numbers), and whether the toolkit can use it.

:func:`check_urdf` reads the XML itself (expat, keeping each element's line), walks the kinematic tree
at q = 0 with its own transforms (independent of Pinocchio), then loads the file with
:class:`scara_pin.model.Robot` and reads the closed-form geometry, so that what it reports is what the
other commands will do.

Findings (``code``: severity):

- structure, each one ``error`` (the file is unusable): ``malformed-xml``, ``root-not-robot``,
  ``xacro-not-expanded``, ``missing-name``, ``duplicate-name``, ``missing-link``, ``two-parents``,
  ``disconnected``, ``joint-type``, ``bad-number``, ``joint-count`` (a SCARA has 4 movable joints, or 3 without
  a wrist like the ROS tutorial's RRP arm), ``not-serial``,
  ``limit-missing``, ``limits-inverted`` (lower > upper), ``limits-empty`` (lower = upper),
  ``not-loadable`` (Pinocchio or :class:`~scara_pin.model.Robot` refuses it; the reason is quoted),
  ``frame-missing`` (``--tool`` / ``--base`` names no link), ``xacro-failed`` (a ``.xacro`` file that
  cannot be expanded: a missing package, say), ``unreadable``;
- ``warning`` (usable, but check it): ``xacro-ignored`` (a URDF holding only ``<xacro:property>`` /
  ``<xacro:arg>`` declarations it never substitutes: the loaders ignore them; any other xacro is
  ``xacro-not-expanded``, the same rule as the loaders'), ``continuous-joint`` (Pinocchio gives it nq = 2, cos/sin),
  ``velocity-zero``, ``velocity-placeholder`` (100, 1000, 10000, or one value on every joint),
  ``limits-implausible`` (revolute limits beyond +/-4 pi: degrees?; strokes beyond 5 m: millimetres?),
  ``length-implausible`` (an origin offset beyond 10 m: millimetres?),
  ``velocity-implausible`` (revolute outside 0.05..50 rad/s, prismatic outside 0.05..10 m/s; a
  deg/s reading is offered), ``axis-flipped`` (a revolute axis along base -z: handled, q turns
  clockwise), ``axis-tilted`` (more than 1e-2 rad from vertical, angle in degrees: the closed-form IK
  refuses; only numeric IK applies), ``not-a-scara`` (an arm of another layout: an R-R-R arm, or a
  palletizer's layout without its levelling parallelogram; what it is and what applies), ``wrist-tilted``
  (the wrist axis alone, up to 0.1 rad: refined on the model), ``closed-form-refused`` (the closed form's own reason),
  ``prismatic-position`` (not third in the chain, e.g. a lifting column first: supported),
  ``near-parallel`` (axes 1e-6 .. 1e-2 rad from vertical, e.g. pi written as 3.14: the tilt and the tool
  position error the closed form would make without refinement, measured on sampled configurations;
  the toolkit refines its solutions on the model; ``info`` below 1 micrometre, and ``info`` when no
  ``rpy-approximate`` warning explains the tilt: deliberate tilts, e.g. a calibrated robot's, are handled exactly),
  ``mesh-missing`` (a visual's mesh that cannot be found or is refused, as the viewer resolves it: the
  viewer draws a box), ``zero-pose-folded`` (the elbow folded back at q = 0), ``rpy-approximate`` (an
  ``rpy`` value such as 3.14 or 1.5708 close to a multiple of pi/2, with the position error it causes: angle
  error times the distance from that joint to the tool at q = 0; ``info`` below 1 micrometre; a value written
  with 15 significant digits or more is deliberate, e.g. a calibrated origin, never reported);
- ``info``: ``joints`` (types and order), ``geared`` (a ``<mimic>`` joint: not in q), ``locked`` (joints off
  the chain root -> tool, fixed), ``palletizer`` (recognised: its closed form applies), ``no-wrist`` (3 joints),
  ``axis-near-parallel`` (per joint, its tilt up to 1e-2 rad), ``axis-down`` (a quill whose q grows downward: the usual
  convention), ``zero-pose-direction`` (the arm points along +y or elsewhere than +x at q = 0: handled
  by the zero offsets), ``zero-pose-bent``, ``tool-frame`` (no ``tool0``: the chain's last link is used).

The tool and base frames, and the rules that make a joint unusable (inverted limits, zero axis), are the
loader's own (:mod:`scara_pin.urdf_rules`): the frames ``check`` names are the frames the commands use.

Status: ``unusable`` if any error (exit code 2), else ``warnings`` if any warning (exit code 4), else
``clean`` (exit code 0).
"""

from __future__ import annotations

import enum
import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from xml.etree.ElementTree import Element, TreeBuilder

import numpy as np

from ._checks import number_text
from ._urdf_checks import xacro_leftovers
from .description.xacro_sources import SourceMap
from .kinematics.scara_geometry import NEAR_PARALLEL_TOL, WRIST_TILT_MAX  # beyond: tilted (the wrist: up to the max)
from .urdf_rules import JointEdge, choose_frames, joint_problem

__all__ = [
    "CheckReport",
    "CheckStatus",
    "Finding",
    "JointInfo",
    "Severity",
    "check_urdf",
    "check_urdf_file",
]

TILT_TOL = 1e-6
"""[rad] an axis further than this from the base z axis is not vertical (near-parallel up to NEAR_PARALLEL_TOL)."""
RPY_NEAR = 0.01
"""[rad] an rpy value this close to a nonzero multiple of pi/2 (but not equal to it) is an approximation."""
FULL_PRECISION = 15
"""Significant digits from which an rpy value near k pi/2 is deliberate (a calibrated origin), not a typed
approximation such as 3.14 or 1.5708 (one typed with 15 digits is within RPY_EXACT of k pi/2 anyway)."""
RPY_EXACT = 1e-12
"""[rad] closer than this to k pi/2 is taken as exact (a float's repr of pi is 1.2e-16 away)."""
REVOLUTE_RANGE = 4 * math.pi
"""[rad] a revolute limit beyond two turns either way is implausible (degrees written as radians)."""
PRISMATIC_RANGE = 5.0
"""[m] a SCARA stroke limit beyond this is implausible (millimetres written as metres)."""
OFFSET_RANGE = 10.0
"""[m] a joint origin offset beyond this is implausible (millimetres written as metres)."""
PLACEHOLDER_VELOCITIES = (100.0, 1000.0, 10000.0)
REVOLUTE_VELOCITY = (0.05, 50.0)
"""[rad/s] plausible range of a SCARA joint's velocity limit."""
PRISMATIC_VELOCITY = (0.05, 10.0)
"""[m/s] plausible range of a SCARA quill's velocity limit."""
_MOVABLE = ("revolute", "continuous", "prismatic")
_KNOWN = (*_MOVABLE, "fixed", "floating", "planar")


class Severity(enum.Enum):
    """How bad a finding is."""

    INFO = "info"
    WARNING = "warning"
    ERROR = "error"


class CheckStatus(enum.Enum):
    """The verdict on a file, with the command line's exit code."""

    CLEAN = "clean"
    WARNINGS = "warnings"
    UNUSABLE = "unusable"

    @property
    def exit_code(self) -> int:
        """0 clean, 4 warnings, 2 unusable."""
        return {"clean": 0, "warnings": 4, "unusable": 2}[self.value]


@dataclass(frozen=True)
class Finding:
    """One thing found in the file.

    Attributes:
        severity: info, warning or error.
        code: a stable identifier (see the module docstring).
        message: one sentence with the numbers.
        line: the line in the file, when the finding belongs to an element (in ``file`` when given).
        joint: the joint concerned, if any.
        file: a xacro file's findings: the file where the element was written (the checked file, a file it
            includes, the file of the macro that made it); None: the checked file itself.
        expanded_line: a xacro file's findings: the line in the expanded document; with ``line`` None, the
            element was made by xacro and this is all there is to point at.
    """

    severity: Severity
    code: str
    message: str
    line: int | None = None
    joint: str | None = None
    file: str | None = None
    expanded_line: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"severity": self.severity.value, "code": self.code, "message": self.message, "line": self.line,
                "joint": self.joint, "file": self.file, "expanded_line": self.expanded_line}  # fmt: skip


@dataclass(frozen=True)
class JointInfo:
    """A joint as written: name, type, line, and (movable joints) its axis in the base frame at q = 0."""

    name: str
    type: str
    line: int | None
    parent: str
    child: str
    axis: tuple[float, float, float] | None = None
    file: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (``file``: as :class:`Finding`'s)."""
        return {"name": self.name, "type": self.type, "line": self.line, "parent": self.parent,
                "child": self.child, "axis": list(self.axis) if self.axis is not None else None,
                "file": self.file}  # fmt: skip


@dataclass(frozen=True)
class CheckReport:
    """The findings on one file.

    Attributes:
        source: the file name (or ``"URDF"``).
        findings: in the order found (structure, joints, geometry, loading).
        joints: movable joints in chain order (empty when the structure is broken).
        tool_frame: the frame taken as the tool (``tool0`` when present).
        base_frame: the frame poses are expressed in (``base`` when present, else the root link).
    """

    source: str
    findings: tuple[Finding, ...]
    joints: tuple[JointInfo, ...] = ()
    tool_frame: str | None = None
    base_frame: str | None = None

    @property
    def status(self) -> CheckStatus:
        """Unusable with any error, warnings with any warning, else clean."""
        severities = {f.severity for f in self.findings}
        if Severity.ERROR in severities:
            return CheckStatus.UNUSABLE
        if Severity.WARNING in severities:
            return CheckStatus.WARNINGS
        return CheckStatus.CLEAN

    @property
    def exit_code(self) -> int:
        """0 clean, 4 warnings, 2 unusable."""
        return self.status.exit_code

    def codes(self, severity: Severity | None = None) -> list[str]:
        """The finding codes (of one severity, or all)."""
        return [f.code for f in self.findings if severity is None or f.severity is severity]

    def find(self, code: str) -> list[Finding]:
        """The findings with this code."""
        return [f for f in self.findings if f.code == code]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: source, status, exit_code, tool_frame, joints, findings."""
        return {
            "source": self.source,
            "status": self.status.value,
            "exit_code": self.exit_code,
            "tool_frame": self.tool_frame,
            "base_frame": self.base_frame,
            "joints": [j.to_dict() for j in self.joints],
            "findings": [f.to_dict() for f in self.findings],
        }

    def to_json(self) -> str:
        """The JSON document of :meth:`to_dict` (indented, one trailing newline)."""
        import json

        return json.dumps(self.to_dict(), indent=2) + "\n"

    def format_text(self) -> str:
        """One line per finding (``file:line: severity: message [code]``), then the status line."""
        out = []
        for f in self.findings:
            if f.line is not None:
                where = f"{f.file or self.source}:{f.line}"
            elif f.expanded_line is not None:
                where = f"{self.source} (line {f.expanded_line} of the expanded document)"
            else:
                where = self.source
            out.append(f"{where}: {f.severity.value}: {f.message} [{f.code}]")
        out.append(f"{self.source}: {self.status.value}")
        return "\n".join(out)


# ----------------------------------------------------------------------------------------------- parsing
class _Quiet(logging.Filter):
    """Drops every record (the loader's warnings while ``check`` loads the file: they are findings)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return False


class _Unusable(Exception):
    """Internal: stop the checks (the findings so far say why)."""


def _parse(text: str) -> tuple[Element, dict[Element, int]]:
    """An ElementTree of the text, with each element's line (expat's position of its start tag)."""
    from xml.parsers import expat

    builder = TreeBuilder()
    lines: dict[Element, int] = {}
    parser = expat.ParserCreate()

    def start(tag: str, attrs: dict[str, str]) -> None:
        lines[builder.start(tag, attrs)] = parser.CurrentLineNumber

    parser.StartElementHandler = start
    parser.EndElementHandler = builder.end
    parser.Parse(text, True)
    return builder.close(), lines


def _full_precision(value: float) -> bool:
    """Whether ``value`` needs FULL_PRECISION significant digits or more: written by a program, not typed."""
    digits = repr(abs(value)).split("e")[0].replace(".", "").lstrip("0")
    return len(digits) >= FULL_PRECISION


def _rpy_matrix(r: float, p: float, y: float) -> np.ndarray:
    """URDF: R = Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip


@dataclass
class _Joint:
    name: str
    type: str
    line: int | None
    parent: str
    child: str
    xyz: tuple[float, ...] = (0.0, 0.0, 0.0)
    rpy: tuple[float, ...] = (0.0, 0.0, 0.0)
    rpy_line: int | None = None
    axis: tuple[float, ...] = (1.0, 0.0, 0.0)
    limit: dict[str, str] | None = None
    limit_line: int | None = None
    world: np.ndarray = field(default_factory=lambda: np.eye(4))  # joint frame at q = 0 in the root
    mimic: tuple[str, float, float] | None = None  # (joint followed, multiplier, offset)


class _Checker:
    def __init__(self, text: str, source: str, tool: str | None = None, base: str | None = None,
                 load_kwargs: dict[str, Any] | None = None, lock: Mapping[str, float] | None = None
                 ) -> None:  # fmt: skip
        self.text = text
        self.source = source
        self.tool_asked = tool
        self.base_asked = base
        self.lock = dict(lock or {})
        self.load_kwargs = load_kwargs or {}
        self.sources: SourceMap | None = None  # a xacro file's: where each expanded line was written
        self.meshes: list[tuple[str, str, int | None]] = []  # (link, filename, line) of each visual mesh
        self.findings: list[Finding] = []
        self.joints: dict[str, _Joint] = {}
        self.chain: list[_Joint] = []
        self.tool: str | None = None

    def add(
        self, severity: Severity, code: str, message: str, line: int | None = None, joint: str | None = None
    ) -> None:
        if self.sources is None:
            self.findings.append(Finding(severity, code, message, line, joint))
            return
        where = self.sources.where(line)  # the file and line where the element was written
        self.findings.append(Finding(severity, code, message, where[1] if where else None, joint,
                                     self._shown(where[0]) if where else None, line))  # fmt: skip

    def at(self, line: int | None) -> str:
        """``line 12`` in a message; for a xacro file, the file and line where the element was written."""
        where = self.sources.where(line) if self.sources is not None else None
        if where is not None:
            return f"{self._shown(where[0])}:{where[1]}"
        return f"line {line}" if self.sources is None else f"line {line} of the expanded document"

    def _shown(self, path: Path, top: Path | None = None) -> str:
        """A source file's name as the report shows it: the checked file as given, others beside it."""
        import os

        top = top or (self.sources.top if self.sources is not None else Path(self.source).resolve())
        if path == top:
            return self.source
        rel = os.path.relpath(path, top.parent)
        return str(Path(self.source).parent / rel) if not rel.startswith("..") else str(path)

    def error(self, code: str, message: str, line: int | None = None, joint: str | None = None) -> None:
        self.add(Severity.ERROR, code, message, line, joint)

    # ------------------------------------------------------------------------------------- structure
    def _numbers(self, el: Element | None, attr: str, default: tuple[float, ...], where: str, line: int | None,
                 joint: str) -> tuple[float, ...]:  # fmt: skip
        if el is None or el.get(attr) is None:
            return default
        raw = el.get(attr, "")
        values = tuple(number_text(v) for v in raw.split())  # NaN unless urdfdom's grammar
        if len(values) != len(default) or not all(math.isfinite(v) for v in values):
            self.error("bad-number", f"{where} {attr}={raw!r} of joint {joint} must be {len(default)} finite numbers",
                       line, joint)  # fmt: skip
            return default
        return values

    def _inertial(self, link: Element, name: str, line: int | None) -> None:
        """A link's mass and inertia must be finite (NaN would poison every torque); mass >= 0."""
        inertial = link.find("inertial")
        if inertial is None:
            return
        checks: list[tuple[str, Element | None, tuple[str, ...]]] = [
            ("mass", inertial.find("mass"), ("value",)),
            ("inertia", inertial.find("inertia"), ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")),
        ]
        for what, el, attrs in checks:
            if el is None:
                continue
            for attr in attrs:
                raw = el.get(attr)
                if raw is None:
                    continue
                value = number_text(raw)
                if not math.isfinite(value) or (what == "mass" and value < 0):
                    rule = "must be a finite number >= 0" if what == "mass" else "must be a finite number"
                    self.error("bad-inertial", f"link {name}'s {what} {attr}={raw!r} {rule}", line)

    def structure(self) -> None:
        try:
            root, lines = _parse(self.text)
        except Exception as exc:  # expat.ExpatError (malformed), ValueError (encoding declarations)
            line = getattr(exc, "lineno", None)
            self.error("malformed-xml", f"malformed XML: {getattr(exc, 'args', [exc])[0]}", line)
            raise _Unusable from None
        if root.tag != "robot":
            self.error("root-not-robot", f"the root element is <{root.tag}>, not <robot>", lines.get(root))
            raise _Unusable
        from .limits import MAX_CHECK_ELEMENTS

        size = len(root.findall("link")) + len(root.findall("joint"))
        if size > MAX_CHECK_ELEMENTS:
            self.error("too-large", f"{size} links and joints, above the cap of {MAX_CHECK_ELEMENTS:,}")
            raise _Unusable
        leftover = xacro_leftovers(root)  # the loader's rule (scara_pin._urdf_checks)
        if leftover is not None:
            blocking, message, where = leftover
            if blocking:
                self.error("xacro-not-expanded", message, lines.get(where))
                raise _Unusable
            self.add(Severity.WARNING, "xacro-ignored", message, lines.get(where))
        links: dict[str, int | None] = {}
        for el in root.findall("link"):
            name = el.get("name")
            if not name:
                self.error("missing-name", "a <link> has no name", lines.get(el))
            elif name in links:
                self.error("duplicate-name", f"link {name!r} is defined twice (first at {self.at(links[name])})",
                           lines.get(el))  # fmt: skip
            else:
                links[name] = lines.get(el)
            self._inertial(el, name or "?", lines.get(el))
            for visual in el.findall("visual"):  # the viewer's meshes: checked in meshes()
                for mesh in visual.findall("geometry/mesh"):
                    self.meshes.append((name or "?", mesh.get("filename", ""), lines.get(mesh)))
        for el in root.findall("joint"):
            name, kind, line = el.get("name"), el.get("type"), lines.get(el)
            if not name:
                self.error("missing-name", "a <joint> has no name", line)
                continue
            if name in self.joints:
                first = self.joints[name].line
                self.error("duplicate-name", f"joint {name!r} is defined twice (first at {self.at(first)})",
                           line, name)  # fmt: skip
                continue
            if kind not in _KNOWN:
                self.error("joint-type", f"joint {name} has type {kind!r}: not a URDF joint type", line, name)
                continue
            if kind in ("floating", "planar"):
                self.error("joint-type", f"joint {name} is {kind}: a SCARA has revolute and prismatic joints",
                           line, name)  # fmt: skip
                continue
            parent_el, child_el = el.find("parent"), el.find("child")
            ends = []
            for role, sub in (("parent", parent_el), ("child", child_el)):
                target = sub.get("link") if sub is not None else None
                if not target or target not in links:
                    shown = f"link {target!r}, which is not defined" if target else f"no <{role} link=...>"
                    self.error("missing-link", f"joint {name}'s {role} is {shown}", line, name)
                ends.append(target or "")
            origin, axis, limit = el.find("origin"), el.find("axis"), el.find("limit")
            j = _Joint(name, kind, line, ends[0], ends[1])
            oline = lines.get(origin) if origin is not None else line
            j.xyz = self._numbers(origin, "xyz", (0.0, 0.0, 0.0), "origin", oline, name)
            j.rpy = self._numbers(origin, "rpy", (0.0, 0.0, 0.0), "origin", oline, name)
            j.rpy_line = oline
            j.axis = self._numbers(axis, "xyz", (1.0, 0.0, 0.0), "axis", lines.get(axis) if axis is not None else line,
                                   name)  # fmt: skip
            if kind in _MOVABLE and math.hypot(*j.axis) < 1e-12:
                problem = joint_problem(name, kind, j.axis, None, None)  # the loader's rule (the zero axis)
                if problem is not None:
                    self.error(problem[0], problem[1], line, name)
            if limit is not None:
                j.limit, j.limit_line = dict(limit.attrib), lines.get(limit)
            mimic = el.find("mimic")
            if mimic is not None and kind in _MOVABLE:
                m, c = (number_text(mimic.get(a, d)) for a, d in (("multiplier", "1"), ("offset", "0")))
                j.mimic = (mimic.get("joint", ""), m, c)
            self.joints[name] = j
        if any(f.severity is Severity.ERROR for f in self.findings):
            raise _Unusable
        # the tree: one root, every link reached once
        parent_of: dict[str, _Joint] = {}
        for j in self.joints.values():
            if j.child in parent_of:
                other = parent_of[j.child].name
                self.error("two-parents", f"link {j.child} is the child of joints {other} and {j.name}",
                           j.line, j.name)  # fmt: skip
            parent_of[j.child] = j
        if any(f.severity is Severity.ERROR for f in self.findings):
            raise _Unusable
        roots = [name for name in links if name not in parent_of]
        if len(roots) != 1:
            shown = ", ".join(f"{r} ({self.at(links[r])})" for r in roots) or "none (a cycle)"
            self.error("disconnected", f"the tree must have one root link; this file has {len(roots)}: {shown}")
            raise _Unusable
        children: dict[str, list[_Joint]] = {}
        for j in self.joints.values():
            children.setdefault(j.parent, []).append(j)
        self.root = roots[0]
        # depth-first from the root, siblings in file order (a serial chain has one order); iterative
        self.order: list[_Joint] = []
        self.link_world: dict[str, np.ndarray] = {self.root: np.eye(4)}
        stack = list(reversed(children.get(self.root, [])))
        while stack:
            j = stack.pop()
            if j.child in self.link_world:  # reached twice: only through a cycle, reported below
                continue
            M = np.eye(4)
            M[:3, :3] = _rpy_matrix(*j.rpy)
            M[:3, 3] = j.xyz
            j.world = self.link_world[j.parent] @ M
            self.link_world[j.child] = j.world
            self.order.append(j)
            stack.extend(reversed(children.get(j.child, [])))
        unreached = [n for n in links if n not in self.link_world]
        if unreached:
            self.error("disconnected", f"links not connected to the root {self.root}: {', '.join(unreached)} "
                       "(a cycle)", links[unreached[0]])  # fmt: skip
            raise _Unusable
        self.links = links
        self.parent_of = parent_of
        self.children = children

    # ------------------------------------------------------------------------------------- joints
    def frames(self) -> None:
        """The tool and base frames the loader takes (the same function, scara_pin.urdf_rules.choose_frames)."""
        from .errors import UrdfError

        try:
            self.chosen = choose_frames(list(self.links), [JointEdge(j.name, j.type, j.parent, j.child)
                                                           for j in self.joints.values()],
                                        tool=self.tool_asked, base=self.base_asked, origin=self.source)  # fmt: skip
        except UrdfError as exc:
            self.error("frame-missing", str(exc).removeprefix(f"{self.source}: "))
            raise _Unusable from None

    def joint_rules(self) -> None:
        # the chain: the movable joints between the root and the tool, as the loader keeps them
        # (scara_pin.chain): geared (<mimic>) joints follow another, joints off the chain are locked
        on_path: set[str] = set()
        link = self.chosen.tool
        while link in self.parent_of:
            on_path.add(self.parent_of[link].name)
            link = self.parent_of[link].parent
        everything = [j for j in self.order if j.type in _MOVABLE]
        movable = [j for j in everything if j.mimic is None and j.name in on_path and j.name not in self.lock]
        off_chain = [j for j in everything if j.mimic is None and j.name not in on_path and j.name not in self.lock]
        if off_chain:
            shown = ", ".join(j.name for j in off_chain[:12]) + (" ..." if len(off_chain) > 12 else "")
            self.add(Severity.INFO, "locked", f"{len(off_chain)} movable joint(s) not on the chain {self.root} -> "
                     f"{self.chosen.tool} are locked (at 0, or the nearest limit; --lock JOINT=VALUE sets them): "
                     f"{shown}")  # fmt: skip
        for j in everything:
            if j.mimic is not None:
                src, m, c = j.mimic
                unit = "m" if j.type == "prismatic" else "rad"
                self.add(Severity.INFO, "geared", f"joint {j.name} follows {src} (<mimic>): {j.name} = {m:.9g} * {src} "
                         f"+ {c:.9g} {unit}; not a degree of freedom (not in q), reported beside it", j.line, j.name)
        self.chain = movable
        listing = ", ".join(f"{j.name} ({j.type}, {self.at(j.line)})" for j in movable[:12])
        if len(movable) > 12:
            listing += f", ... ({len(movable) - 12} more)"
        self.add(Severity.INFO, "joints", f"{len(movable)} movable joints in chain order: {listing or 'none'}")
        from .description import JOINT_COUNTS  # the loader's rule

        if len(movable) not in JOINT_COUNTS and off_chain:
            # not one arm among others: where the tree branches off the chain (a joint hung on the wrong link)
            free = [j for j in everything if j.mimic is None and j.name not in self.lock]
            for a, b in zip(free, free[1:]):
                if not self._is_ancestor(a, b):
                    self.error("not-serial", f"joint {b.name} is not downstream of {a.name}: not a serial chain (the "
                               f"chain {self.root} -> {self.chosen.tool} has {len(movable)} movable joints; --tool "
                               "picks an arm's last link)", b.line, b.name)  # fmt: skip
                    break
        elif len(movable) not in JOINT_COUNTS:
            self.error("joint-count", f"a SCARA has 4 movable joints (3 revolute, 1 prismatic), or 3 without a "
                       f"wrist (2 revolute, 1 prismatic); this file has {len(movable)}: "
                       f"{listing or 'none'}")  # fmt: skip
        elif len(movable) == 3 and sorted(j.type == "prismatic" for j in movable) == [False, False, True]:
            self.add(Severity.INFO, "no-wrist", "3 movable joints: a SCARA without a wrist (2 revolute, 1 prismatic); "
                     "fk takes 3 joint values and ik a tool point X Y Z (the tool's yaw follows the arm)")  # fmt: skip
        velocities: list[float] = []
        first_limit_line = next((j.limit_line for j in movable if j.limit is not None), None)
        for j in movable:
            unit = "m/s" if j.type == "prismatic" else "rad/s"
            if j.type == "continuous":
                self.add(Severity.WARNING, "continuous-joint",
                         f"joint {j.name} is continuous: Pinocchio gives it nq = 2 (cos, sin) and nv = 1, while "
                         "scara-pin's q holds one value per joint (its angle: converted to cos, sin for Pinocchio; "
                         "no position limit, IK solutions presented in [-pi, pi]); "
                         + ("its <limit> lower/upper are ignored" if j.limit is not None else "it has no limits"),
                         j.line, j.name)  # fmt: skip
            lim = j.limit
            if lim is None:
                if j.type != "continuous":
                    self.error("limit-missing", f"{j.type} joint {j.name} has no <limit>: urdfdom refuses it",
                               j.line, j.name)  # fmt: skip
                continue
            for attr in ("velocity", "effort"):
                if attr not in lim:
                    self.error("limit-missing", f"joint {j.name}'s <limit> has no {attr}: urdfdom refuses it",
                               j.limit_line, j.name)  # fmt: skip
            if j.type != "continuous":
                missing = [a for a in ("lower", "upper") if a not in lim]
                if missing:
                    self.error("limit-missing", f"joint {j.name}'s <limit> has no {' and '.join(missing)}: read as 0, "
                               "the joint cannot move", j.limit_line, j.name)  # fmt: skip
            nums = {}
            for attr in ("lower", "upper", "velocity", "effort"):
                if attr in lim:
                    nums[attr] = number_text(lim[attr])
                    if not math.isfinite(nums[attr]):
                        self.error("bad-number", f"joint {j.name}'s {attr} limit is {lim[attr]!r}: not a finite number",
                                   j.limit_line, j.name)  # fmt: skip
            lo, hi = nums.get("lower", 0.0), nums.get("upper", 0.0)
            if j.type != "continuous" and "lower" in nums and "upper" in nums:
                problem = joint_problem(j.name, j.type, j.axis, lo, hi)  # the loader's rule (scara_pin.urdf_rules)
                if problem is not None and problem[0] != "bad-number":  # non-finite numbers: reported above
                    self.error(problem[0], problem[1], j.limit_line, j.name)
                if j.type == "revolute" and max(abs(lo), abs(hi)) > REVOLUTE_RANGE and math.isfinite(lo + hi):
                    self.add(Severity.WARNING, "limits-implausible",
                             f"joint {j.name}'s limits [{lo:g}, {hi:g}] rad are "
                             f"{math.degrees(lo):.4g}..{math.degrees(hi):.4g} deg "
                             f"({(hi - lo) / (2 * math.pi):.3g} turns): degrees written as radians?",
                             j.limit_line, j.name)  # fmt: skip
                elif j.type == "prismatic" and max(abs(lo), abs(hi)) > PRISMATIC_RANGE and math.isfinite(lo + hi):
                    self.add(Severity.WARNING, "limits-implausible",
                             f"joint {j.name}'s stroke [{lo:g}, {hi:g}] m is longer than {PRISMATIC_RANGE:g} m: "
                             "millimetres written as metres?", j.limit_line, j.name)  # fmt: skip
            v = nums.get("velocity", math.nan)
            if not math.isfinite(v):
                continue
            velocities.append(v)
            low, high = PRISMATIC_VELOCITY if j.type == "prismatic" else REVOLUTE_VELOCITY
            if v == 0:
                self.add(Severity.WARNING, "velocity-zero", f"joint {j.name}'s velocity limit is 0 {unit}: "
                         "a placeholder; "
                         "timing and trajectories need the real limit (> 0)", j.limit_line, j.name)  # fmt: skip
            elif v in PLACEHOLDER_VELOCITIES:
                self.add(Severity.WARNING, "velocity-placeholder", f"joint {j.name}'s velocity limit is {v:g} {unit}: "
                         "a placeholder value", j.limit_line, j.name)  # fmt: skip
            elif v < 0 or not low <= v <= high:
                note = ""
                as_deg = v * 180.0 / math.pi
                if abs(as_deg - round(as_deg)) < 1e-6 * max(1.0, as_deg) and round(as_deg) != 0:
                    note = f"; it is {round(as_deg):g} deg/s converted to rad: a unit error?"
                self.add(Severity.WARNING, "velocity-implausible",
                         f"joint {j.name}'s velocity limit {v:g} {unit} is outside {low:g}..{high:g} {unit}{note}",
                         j.limit_line, j.name)  # fmt: skip
        if len(velocities) >= 3 and len(set(velocities)) == 1 and velocities[0] != 0 \
                and velocities[0] not in PLACEHOLDER_VELOCITIES:  # fmt: skip
            self.add(Severity.WARNING, "velocity-placeholder",
                     f"every joint has the velocity limit {velocities[0]:g} (rad/s and m/s alike): a placeholder?",
                     first_limit_line)

    def _is_ancestor(self, a: _Joint, b: _Joint) -> bool:
        link = b.parent
        while link in self.parent_of:
            j = self.parent_of[link]
            if j is a:
                return True
            link = j.parent
        return False

    # ------------------------------------------------------------------------------------- geometry
    def geometry(self) -> None:
        frames = self.chosen
        base = frames.base
        self.base = base
        bMo = np.linalg.inv(self.link_world[base])
        tool: str | None = frames.tool if self.chain else None
        if frames.note is not None and tool is not None:
            self.add(Severity.INFO, "tool-frame", frames.note)
        self.tool = tool
        p_tool = (bMo @ self.link_world[tool])[:3, 3] if tool else np.zeros(3)
        revolute: list[tuple[_Joint, np.ndarray]] = []
        prismatic_at = [i for i, j in enumerate(self.chain) if j.type == "prismatic"]
        self.axes: dict[str, tuple[float, float, float]] = {}
        tilts = {}
        for j in self.chain:
            axis = (bMo @ j.world)[:3, :3] @ (np.asarray(j.axis) / np.linalg.norm(j.axis))
            self.axes[j.name] = (float(axis[0]), float(axis[1]), float(axis[2]))
            tilts[j.name] = math.atan2(math.hypot(axis[0], axis[1]), abs(axis[2]))
        # the wrist alone may tilt further (scara_geometry's rule): the last of 4, revolute, the others near-vertical
        wrist_only = len(self.chain) == 4 and self.chain[-1].type != "prismatic" and all(
            tilts[j.name] <= NEAR_PARALLEL_TOL for j in self.chain[:-1])  # fmt: skip
        for j in self.chain:
            M = bMo @ j.world
            axis = np.asarray(self.axes[j.name])
            tilt = tilts[j.name]
            wrist = wrist_only and j is self.chain[-1]
            if NEAR_PARALLEL_TOL < tilt <= WRIST_TILT_MAX and wrist:  # the closed form's rule (scara_geometry)
                self.add(Severity.WARNING, "wrist-tilted",
                         f"joint {j.name}'s axis is {math.degrees(tilt):.6g} deg ({tilt:.3g} rad) away from the base z "
                         f"axis: the wrist alone tilts (at most {WRIST_TILT_MAX:g} rad): the tool's roll/pitch follow "
                         f"{j.name}, and a tool point off its axis moves up and down as it turns; nothing that carries "
                         "the wrist point depends on it: the closed form's solutions are refined on the model, the "
                         f"workspace is that of {j.name}'s axis at the tool's height", j.line, j.name)  # fmt: skip
            elif tilt > NEAR_PARALLEL_TOL:
                self.add(Severity.WARNING, "axis-tilted",
                         f"joint {j.name}'s axis is {math.degrees(tilt):.6g} deg ({tilt:.3g} rad) away from the base z "
                         f"axis (more than {NEAR_PARALLEL_TOL:g} rad): the closed-form IK refuses it; only numeric IK "
                         "applies", j.line, j.name)  # fmt: skip
            elif tilt > TILT_TOL:
                self.add(Severity.INFO, "axis-near-parallel",
                         f"joint {j.name}'s axis is {math.degrees(tilt):.6g} deg ({tilt:.3g} rad) away from the base z "
                         f"axis (at most {NEAR_PARALLEL_TOL:g} rad: near-parallel; the closed form's solutions are "
                         "refined on the model, see near-parallel)", j.line, j.name)  # fmt: skip
            elif axis[2] < 0:
                if j.type == "prismatic":
                    self.add(Severity.INFO, "axis-down", f"joint {j.name} (prismatic) moves along base -z: q grows "
                             "downward (the usual quill convention)", j.line, j.name)  # fmt: skip
                else:
                    self.add(Severity.WARNING, "axis-flipped", f"joint {j.name}'s axis points along base -z: q turns "
                             "clockwise seen from above (handled by the toolkit)", j.line, j.name)  # fmt: skip
            if j.type != "prismatic":
                revolute.append((j, M[:3, 3]))
        if len(prismatic_at) == 1 and len(self.chain) == 4 and prismatic_at[0] != 2:
            j = self.chain[prismatic_at[0]]
            self.add(Severity.WARNING, "prismatic-position",
                     f"the prismatic joint {j.name} is joint {prismatic_at[0] + 1} of 4, not the third "
                     f"({'the whole arm lifts' if prismatic_at[0] == 0 else 'an unusual layout'}): supported",
                     j.line, j.name)  # fmt: skip
        if len(revolute) == 3:
            (ja, pa), (_, pb), (_, pc) = revolute
            u1, u2 = (pb - pa)[:2], (pc - pb)[:2]
            if min(np.linalg.norm(u1), np.linalg.norm(u2)) > 1e-9:
                heading = math.degrees(math.atan2(u1[1], u1[0]))
                gamma = math.degrees(math.atan2(u1[0] * u2[1] - u1[1] * u2[0], u1 @ u2))
                if abs(gamma) > 170.0:
                    self.add(Severity.WARNING, "zero-pose-folded",
                             f"at q = 0 the arm is folded: arm 2 turns {gamma:.4g} deg from arm 1 (the wrist is "
                             f"{np.linalg.norm(pc[:2] - pa[:2]):.4g} m from the shoulder axis)", ja.line)  # fmt: skip
                elif abs(gamma) > 1.0:
                    self.add(Severity.INFO, "zero-pose-bent", f"at q = 0 arm 2 turns {gamma:.4g} deg from arm 1")
                if abs(heading) > 1.0:
                    names = {90: "+y", -90: "-y", 180: "-x", -180: "-x"}
                    named = names.get(int(round(heading)), f"{heading:.4g} deg from +x")
                    self.add(Severity.INFO, "zero-pose-direction",
                             f"at q = 0 arm 1 points along {named} ({heading:.4g} deg from +x), not +x: the zero "
                             "offset is handled by the toolkit", ja.line, ja.name)  # fmt: skip
        # rpy values approximating a multiple of pi/2: the tool error at the zero pose; offsets in mm
        for j in self.order:
            if max(abs(v) for v in j.xyz) > OFFSET_RANGE:
                self.add(Severity.WARNING, "length-implausible",
                         f"joint {j.name}'s origin xyz {' '.join(f'{v:g}' for v in j.xyz)} is more than "
                         f"{OFFSET_RANGE:g} m long: millimetres written as metres?", j.rpy_line, j.name)  # fmt: skip
            for _k, (axis_name, value) in enumerate(zip(("roll", "pitch", "yaw"), j.rpy)):
                n = round(value / (math.pi / 2))
                err = value - n * math.pi / 2
                if n == 0 or not RPY_EXACT < abs(err) < RPY_NEAR or _full_precision(value):
                    continue
                exact = {1: "pi/2", -1: "-pi/2", 2: "pi", -2: "-pi"}.get(n, f"{n}*pi/2")
                dist = float(np.linalg.norm(p_tool - (bMo @ j.world)[:3, 3])) if tool else 0.0
                mm = abs(err) * dist * 1000.0
                sev = Severity.WARNING if mm >= 1e-3 else Severity.INFO
                self.add(sev, "rpy-approximate",
                         f"joint {j.name}: rpy {axis_name} = {value!r} approximates {exact} "
                         f"(error {abs(err):.3g} rad = "
                         f"{math.degrees(abs(err)):.3g} deg); the tool is {dist:.4g} m from this joint at q = 0: about "
                         f"{mm:.3g} mm of position error at full reach; write {exact} as {n * math.pi / 2!r}",
                         j.rpy_line, j.name)  # fmt: skip

    # ------------------------------------------------------------------------------------- loading
    def load(self) -> None:
        from .errors import UrdfError
        from .kinematics.kinds import kinematics_for, what_arm
        from .kinematics.scara import NotScaraError
        from .model import Robot

        quiet = _Quiet()  # the loader's warnings are findings here already (xacro-ignored): not logged twice
        logging.getLogger("scara_pin").addFilter(quiet)
        try:
            robot = Robot(self.text, origin=self.source, tool_frame=self.tool_asked, base_frame=self.base_asked,
                          kinematics=kinematics_for, lock=self.lock, **self.load_kwargs)  # the same choose_frames
        except UrdfError as exc:
            self.error("not-loadable", f"the toolkit cannot load it: {exc}")
            return
        finally:
            logging.getLogger("scara_pin").removeFilter(quiet)
        if robot.kind == "palletizer":  # its horizontal arm joints are its own: not a SCARA's tilted axes
            self.findings = [f for f in self.findings if f.code != "axis-tilted"]
        try:
            kinematics = robot.kinematics
        except UrdfError as exc:  # NotScaraError, NotPalletizerError: the kind's own reason
            what = what_arm(robot) if isinstance(exc, NotScaraError) else None
            if what is not None:  # an arm of another shape: what it is and what applies
                self.add(Severity.WARNING, "not-a-scara", what[0].upper() + what[1:])
            elif not any(f.code == "axis-tilted" for f in self.findings):
                self.add(Severity.WARNING, "closed-form-refused",
                         f"the closed-form IK refuses it: {exc}; only numeric IK applies")
            return
        if robot.kind == "palletizer":
            self.add(Severity.INFO, "palletizer", "a palletizer (a waist, two parallel horizontal arm joints, the "
                     "flange kept level by <mimic> joints): the palletizer's closed form applies")  # fmt: skip
            return
        self.near_parallel(robot, kinematics)

    def mesh_files(self) -> None:
        """``mesh-missing``: a visual's mesh the viewer cannot find or may not read (it draws a box instead).

        Found by the viewer's own resolver (:func:`scara_pin.description.mesh_paths.mesh_file`), for a file
        (``check_urdf_file``: the package folders known); one finding per file name, naming its links.
        """
        from .description.mesh_paths import MeshProblem, mesh_file

        packages = self.load_kwargs.get("package_path")
        if packages is None:  # URDF text without a file: nowhere to look relative names up
            return
        links: dict[str, list[str]] = {}
        first: dict[str, int | None] = {}
        for link, filename, line in self.meshes:
            links.setdefault(filename, []).append(link)
            first.setdefault(filename, line)
        for filename, names in links.items():
            try:
                mesh_file(filename, packages)
            except MeshProblem as exc:
                shown = ", ".join(names[:6]) + (f" and {len(names) - 6} more" if len(names) > 6 else "")
                self.add(Severity.WARNING, "mesh-missing",
                         f"{exc}: the viewer draws link {shown} as a placeholder box", first[filename])

    def near_parallel(self, robot: Any, kinematics: Any) -> None:
        """The ``near-parallel`` finding: the axes' tilt, and the error of the closed form without refinement."""
        from .kinematics.polish import unrefined_error
        from .kinematics.scara import EXACT_TILT

        geo = getattr(kinematics, "geometry", None)
        tilt = getattr(geo, "tilt", 0.0)
        if tilt <= EXACT_TILT:
            return
        err = unrefined_error(robot)
        # a tilt that comes with an approximate rpy (3.14) is a typo to fix; one written deliberately (measured,
        # calibrated: scara-pin calibrate writes its origins at full precision) is handled exactly: information
        typo = any(f.code == "rpy-approximate" and f.severity is Severity.WARNING for f in self.findings)
        sev = Severity.WARNING if err.position >= 1e-6 and typo else Severity.INFO
        yaw = f" and {err.yaw:.3g} rad of yaw" if robot.dof == 4 else ""
        self.add(sev, "near-parallel",
                 f"the joint axes are up to {tilt:.3g} rad ({math.degrees(tilt):.3g} deg) from the base z axis: "
                 f"near-parallel; unrefined, the closed form (ideal vertical axes) would miss the tool pose by up "
                 f"to {err.position * 1000:.3g} mm{yaw} (max over {err.samples} sampled configurations, seed "
                 f"{err.seed}); the toolkit refines every solution on the model as written (Newton, to 1e-9)")

    def run(self) -> CheckReport:
        try:
            self.structure()
            self.frames()
            self.joint_rules()
            self.geometry()
            if not any(f.severity is Severity.ERROR for f in self.findings):
                self.load()
            self.mesh_files()
        except _Unusable:
            pass
        joints = tuple(
            JointInfo(j.name, j.type, j.line, j.parent, j.child, getattr(self, "axes", {}).get(j.name))
            if self.sources is None else
            JointInfo(j.name, j.type, where[1] if (where := self.sources.where(j.line)) else None, j.parent, j.child,
                      getattr(self, "axes", {}).get(j.name), self._shown(where[0]) if where else None)
            for j in self.chain
        )  # fmt: skip
        return CheckReport(self.source, tuple(self.findings), joints, self.tool, getattr(self, "base", None))


def check_urdf(
    text: str, *, origin: str = "URDF", tool: str | None = None, base: str | None = None,
    lock: Mapping[str, float] | None = None,
) -> CheckReport:
    """Lint URDF text.

    Args:
        text: the URDF document.
        origin: how to name the source in the report (a file name).
        tool: the tool frame asked for (``--tool``); default as the loader picks it
            (:func:`scara_pin.urdf_rules.choose_frames`).
        base: the base frame asked for (``--base``); likewise.
        lock: joints locked at a value (``--lock``, [rad, m]), as the loader takes them (:mod:`scara_pin.chain`).

    Returns:
        The report; its ``status`` and ``exit_code`` give the verdict. Never raises for bad input.
    """
    return _Checker(text, origin, tool, base, lock=lock).run()


def check_urdf_file(
    path: str | Path, *, tool: str | None = None, base: str | None = None, package_dirs: Sequence[str | Path] = (),
    lock: Mapping[str, float] | None = None,
) -> CheckReport:
    """Lint a URDF file, or a xacro file (``.xacro``: expanded first, as the loader does).

    A xacro file's findings point at the file and line where their element was written (the file itself,
    a file it includes, a macro's definition: ``Finding.file``, ``Finding.line``), with its line in the
    expanded document (``Finding.expanded_line``); an element that xacro made has only the latter.

    An unreadable file gives an ``unreadable`` error finding, a xacro that cannot be expanded (a missing
    package, say) a ``xacro-failed`` one: status unusable. Other arguments as :func:`check_urdf`; packages
    are looked for as the loader does (:mod:`scara_pin.description.packages`).
    """
    from .description.packages import PackagePath, read_robot_file
    from .description.xacro_sources import expand_with_sources
    from .errors import InvalidInputError, UrdfError
    from .limits import check_input_file

    path = Path(path)
    try:  # bounded: /dev/zero or a huge file is refused, not read whole
        check_input_file(path, "URDF")
    except InvalidInputError as exc:
        return CheckReport(str(path), (Finding(Severity.ERROR, "unreadable", f"cannot be read ({exc})"),))
    sources = None
    try:
        packages = PackagePath(tuple(Path(d) for d in package_dirs), path.parent)
        if path.name.endswith(".xacro"):  # the loader's text, and where each element was written
            text, sources = expand_with_sources(path, packages)
        else:
            text = read_robot_file(path, packages)
    except UrdfError as exc:
        code = "xacro-failed" if path.name.endswith(".xacro") and path.is_file() else "unreadable"
        reason = getattr(exc, "reason", str(exc)).removeprefix(f"{path}: ")
        file, line = getattr(exc, "file", None), getattr(exc, "line", None)  # where xacro failed, when known
        shown = None if file is None else _Checker("", str(path))._shown(Path(file), path.resolve())
        return CheckReport(str(path), (Finding(Severity.ERROR, code, reason, line, None, shown),))
    checker = _Checker(text, str(path), tool, base, {"package_path": packages}, lock)
    checker.sources = sources
    return checker.run()
