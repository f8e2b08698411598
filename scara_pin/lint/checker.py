"""The entry points of ``scara-pin check``: lint URDF text or a file (a ``.xacro`` expanded as the loader does)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from .context import Context
from .registry import run
from .report import CheckReport, JointInfo

__all__ = ["check_urdf", "check_urdf_file"]


def _report(ctx: Context) -> CheckReport:
    """Run the rules on ``ctx``; the report, with the joints of q as written and their axes (once the frames known)."""
    run(ctx)
    if getattr(ctx, "chosen", None) is None:  # stopped before the frames: no chain to show
        return CheckReport(ctx.source, tuple(ctx.findings))
    joints = []
    for j in ctx.chain.joints:
        axis = ctx.axes[j.name]
        where = ctx.sources.where(j.line) if ctx.sources is not None else None
        if ctx.sources is None:
            joints.append(JointInfo(j.name, j.type, j.line, j.parent, j.child, axis))
        else:
            joints.append(JointInfo(j.name, j.type, where[1] if where else None, j.parent, j.child, axis,
                                    ctx.shown(where[0]) if where else None))  # fmt: skip
    return CheckReport(ctx.source, tuple(ctx.findings), tuple(joints), ctx.tool, ctx.chosen.base)


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
    return _report(Context(text, origin, tool, base, lock))


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
    return _report(Context("", str(path), tool, base, lock, Path(path), package_dirs))
