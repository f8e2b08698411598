"""What ``scara-pin check`` reports: findings, their severity, the verdict on a file (data only)."""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import Any

__all__ = ["CheckReport", "CheckStatus", "Finding", "JointInfo", "Severity"]


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
        code: a stable identifier: the code of a rule of :data:`scara_pin.lint.RULES` (``scara-pin check
            --list-rules``).
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
