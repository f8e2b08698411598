"""Lint a third-party SCARA URDF: what is wrong, where (line numbers), and whether the toolkit can use it.

Organised as linters are (ruff's rule modules, urdfdom's per-element parsers): each rule is a small function
with its code, in a module per family, and one table (:data:`RULES`, ``scara-pin check --list-rules``) gives
every rule its code, family, severity and place in the run:

- :mod:`~scara_pin.lint.tree`: the XML, names, the links joints connect, the chain of q;
- :mod:`~scara_pin.lint.joints`: numbers, ``<limit>``, ranges, velocities;
- :mod:`~scara_pin.lint.frames`: the tool and base frames, the axes at q = 0, the zero pose, origins;
- :mod:`~scara_pin.lint.geometry`: inertial numbers, the meshes the viewer draws;
- :mod:`~scara_pin.lint.scope`: whether the toolkit loads it, and what kind of arm it is.

The rules share a :class:`~scara_pin.lint.context.Context`: the document read with each element's line (expat),
the tree walked at q = 0 with the linter's own transforms (independent of Pinocchio), and the robot as
:class:`scara_pin.model.RobotModel` loads it, so that what ``check`` reports is what the other commands will do.
The tool and base frames, and the rules that make a joint unusable (inverted limits, zero axis), are the
loader's own (:mod:`scara_pin.urdf_rules`).

Severities: ``error`` (the file is unusable), ``warning`` (usable, but check it), ``info``. Status:
``unusable`` if any error (exit code 2), else ``warnings`` if any warning (exit code 4), else ``clean``
(exit code 0).
"""

from __future__ import annotations

from .checker import check_urdf, check_urdf_file
from .registry import FAMILIES, RULES, Rule, rules_text
from .report import CheckReport, CheckStatus, Finding, JointInfo, Severity

__all__ = [
    "FAMILIES",
    "RULES",
    "CheckReport",
    "CheckStatus",
    "Finding",
    "JointInfo",
    "Rule",
    "Severity",
    "check_urdf",
    "check_urdf_file",
    "rules_text",
]
