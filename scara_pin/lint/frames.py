"""Rules of the frames and axes: where the joints of q point at q = 0 (in the base frame), the zero pose, origins.

Each rule is a function of the :class:`~scara_pin.lint.context.Context`; its code and place in the run are in
:data:`scara_pin.lint.registry.RULES`. The axes are the linter's own walk of the tree (independent of
Pinocchio); the tolerances are the closed form's (:mod:`scara_pin.kinematics.scara_geometry`).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import UrdfError
from ..kinematics.scara_geometry import NEAR_PARALLEL_TOL, WRIST_TILT_MAX  # beyond: tilted (the wrist: up to the max)
from ..urdf_rules import TOOL_NAMES, choose_frames
from .context import SAMPLES, Context, LintJoint, Stop
from .report import Severity

__all__ = [
    "FULL_PRECISION", "OFFSET_RANGE", "RPY_EXACT", "RPY_NEAR", "TILT_TOL", "axis_down", "axis_flipped",
    "axis_near_parallel", "axis_tilted", "frame_missing", "length_implausible", "prismatic_position",
    "rpy_approximate", "tool_ambiguous", "tool_frame", "wrist_tilted", "zero_pose_bent", "zero_pose_direction",
    "zero_pose_folded",
]  # fmt: skip

TILT_TOL = 1e-6
"""[rad] an axis further than this from the base z axis is not vertical (near-parallel up to NEAR_PARALLEL_TOL)."""
RPY_NEAR = 0.01
"""[rad] an rpy value this close to a nonzero multiple of pi/2 (but not equal to it) is an approximation."""
FULL_PRECISION = 15
"""Significant digits from which an rpy value near k pi/2 is deliberate (a calibrated origin), not a typed
approximation such as 3.14 or 1.5708 (one typed with 15 digits is within RPY_EXACT of k pi/2 anyway)."""
RPY_EXACT = 1e-12
"""[rad] closer than this to k pi/2 is taken as exact (a float's repr of pi is 1.2e-16 away)."""
OFFSET_RANGE = 10.0
"""[m] a joint origin offset beyond this is implausible (millimetres written as metres)."""


def frame_missing(ctx: Context) -> None:
    """``--tool``/``--base`` names no link, or a base that moves: the loader's frames (choose_frames)."""
    try:
        ctx.chosen = choose_frames(list(ctx.tree.links), ctx.edges, tool=ctx.tool_asked, base=ctx.base_asked,
                                   origin=ctx.source)  # fmt: skip
    except UrdfError as exc:
        ctx.error("frame-missing", str(exc).removeprefix(f"{ctx.source}: "))
        raise Stop from None


def tool_frame(ctx: Context) -> None:
    """No ``tool0``: which link is the tool, why (the loader's choice), and the other links the tree ends in."""
    chosen = ctx.chosen
    if chosen.note is None or ctx.tool is None:
        return
    others = ", ".join(f"{c.link} ({len(c.free)})" for c in chosen.alternatives[:6])
    more = f" and {len(chosen.alternatives) - 6} more" if len(chosen.alternatives) > 6 else ""
    ctx.add(Severity.INFO, "tool-frame", chosen.note + (f"; the tree's other ends (free joints to them): {others}{more}"
                                                        if others else ""))  # fmt: skip


def tool_ambiguous(ctx: Context) -> None:
    """No ``tool0``, and two links end equally long chains with no name to tell them apart."""
    chosen = ctx.chosen
    if not chosen.ambiguous or ctx.tool is None:
        return
    tied = [c.link for c in chosen.alternatives if len(c.free) == len(chosen.alternatives[0].free)]
    n = len(chosen.alternatives[0].free)
    ctx.add(Severity.WARNING, "tool-ambiguous",
            f"the tool frame is ambiguous: {chosen.tool} and {', '.join(tied)} each end a chain of {n} free joints "
            f"and no name ({', '.join(TOOL_NAMES)}) tells them apart; {chosen.tool} is taken (the deepest, then the "
            "first in the file): name the tool with --tool, or add a tool0 link")  # fmt: skip


def _wrist_only(ctx: Context) -> bool:
    """The wrist alone may tilt further (scara_geometry's rule): the last of 4, revolute, the others near-vertical."""
    chain = ctx.chain.joints
    return len(chain) == 4 and chain[-1].type != "prismatic" and all(
        ctx.tilt(j.name) <= NEAR_PARALLEL_TOL for j in chain[:-1])  # fmt: skip


def _tilted(ctx: Context) -> list[tuple[LintJoint, float, bool]]:
    """The joints of q tilted beyond the near-parallel tolerance: (joint, tilt [rad], the wrist alone tilts)."""
    wrist_only = _wrist_only(ctx)
    chain = ctx.chain.joints
    return [(j, ctx.tilt(j.name), wrist_only and j is chain[-1]) for j in chain if ctx.tilt(j.name) > NEAR_PARALLEL_TOL]


def _tilt_text(tilt: float) -> str:
    return f"{math.degrees(tilt):.6g} deg ({tilt:.3g} rad)"


def wrist_tilted(ctx: Context) -> None:
    """The wrist's axis alone tilted, up to 0.1 rad: solutions refined on the model."""
    for j, tilt, wrist in _tilted(ctx):
        if wrist and tilt <= WRIST_TILT_MAX:  # the closed form's rule (scara_geometry)
            ctx.add(Severity.WARNING, "wrist-tilted",
                    f"joint {j.name}'s axis is {_tilt_text(tilt)} away from the base z axis: the wrist alone tilts (at "
                    f"most {WRIST_TILT_MAX:g} rad): the tool's roll/pitch follow {j.name}, and a tool point off its "
                    "axis moves up and down as it turns; nothing that carries the wrist point depends on it: the "
                    "closed form's solutions are refined on the model, the workspace is that of "
                    f"{j.name}'s axis at the tool's height", j.line, j.name)  # fmt: skip


def axis_tilted(ctx: Context) -> None:
    """An axis more than 1e-2 rad from vertical: the SCARA closed form refuses it (a palletizer's are its own)."""
    robot = ctx.robot if not ctx.has_errors else None
    if robot is not None and robot.kind == "palletizer":  # its horizontal arm joints are its own
        return
    for j, tilt, wrist in _tilted(ctx):
        if not (wrist and tilt <= WRIST_TILT_MAX):
            ctx.add(Severity.WARNING, "axis-tilted",
                    f"joint {j.name}'s axis is {_tilt_text(tilt)} away from the base z axis (more than "
                    f"{NEAR_PARALLEL_TOL:g} rad): the closed-form IK refuses it; only numeric IK applies", j.line,
                    j.name)  # fmt: skip


def axis_near_parallel(ctx: Context) -> None:
    """An axis 1e-6 .. 1e-2 rad from vertical (per joint)."""
    for j in ctx.chain.joints:
        tilt = ctx.tilt(j.name)
        if TILT_TOL < tilt <= NEAR_PARALLEL_TOL:
            ctx.add(Severity.INFO, "axis-near-parallel",
                    f"joint {j.name}'s axis is {_tilt_text(tilt)} away from the base z axis (at most "
                    f"{NEAR_PARALLEL_TOL:g} rad: near-parallel; the closed form's solutions are refined on the "
                    "model, see near-parallel)", j.line, j.name)  # fmt: skip


def _down(ctx: Context) -> list[LintJoint]:
    """The vertical joints of q whose axis points along base -z."""
    return [j for j in ctx.chain.joints if ctx.tilt(j.name) <= TILT_TOL and ctx.axes[j.name][2] < 0]


def axis_flipped(ctx: Context) -> None:
    """A revolute axis along base -z: q turns clockwise (handled)."""
    for j in _down(ctx):
        if j.type != "prismatic":
            ctx.add(Severity.WARNING, "axis-flipped", f"joint {j.name}'s axis points along base -z: q turns "
                    "clockwise seen from above (handled by the toolkit)", j.line, j.name)  # fmt: skip


def axis_down(ctx: Context) -> None:
    """A quill whose q grows downward (the usual convention)."""
    for j in _down(ctx):
        if j.type == "prismatic":
            ctx.add(Severity.INFO, "axis-down", f"joint {j.name} (prismatic) moves along base -z: q grows downward "
                    "(the usual quill convention)", j.line, j.name)  # fmt: skip


def prismatic_position(ctx: Context) -> None:
    """The prismatic joint of 4 not third (a lifting column first): supported."""
    chain = ctx.chain.joints
    at = [i for i, j in enumerate(chain) if j.type == "prismatic"]
    if len(at) == 1 and len(chain) == 4 and at[0] != 2:
        j = chain[at[0]]
        ctx.add(Severity.WARNING, "prismatic-position",
                f"the prismatic joint {j.name} is joint {at[0] + 1} of 4, not the third "
                f"({'the whole arm lifts' if at[0] == 0 else 'an unusual layout'}): supported", j.line,
                j.name)  # fmt: skip


def _arms(ctx: Context) -> tuple[LintJoint, float, float, float] | None:
    """The arms at q = 0, with 3 revolute joints of q and both arms longer than 1 nm in plan.

    Returns:
        (joint 1, arm 1's heading from +x [deg], arm 2's turn from arm 1 [deg], the wrist's distance from the
        shoulder axis [m]), or None.
    """
    bMo = ctx.base_from_root
    revolute = [(j, (bMo @ j.world)[:3, 3]) for j in ctx.chain.joints if j.type != "prismatic"]
    if len(revolute) != 3:
        return None
    (ja, pa), (_, pb), (_, pc) = revolute
    u1, u2 = (pb - pa)[:2], (pc - pb)[:2]
    if min(np.linalg.norm(u1), np.linalg.norm(u2)) <= 1e-9:
        return None
    heading = math.degrees(math.atan2(u1[1], u1[0]))
    gamma = math.degrees(math.atan2(u1[0] * u2[1] - u1[1] * u2[0], u1 @ u2))
    return ja, heading, gamma, float(np.linalg.norm(pc[:2] - pa[:2]))


def zero_pose_folded(ctx: Context) -> None:
    """The elbow folded back at q = 0."""
    arms = _arms(ctx)
    if arms is not None and abs(arms[2]) > 170.0:
        ja, _, gamma, reach = arms
        ctx.add(Severity.WARNING, "zero-pose-folded", f"at q = 0 the arm is folded: arm 2 turns {gamma:.4g} deg from "
                f"arm 1 (the wrist is {reach:.4g} m from the shoulder axis)", ja.line)  # fmt: skip


def zero_pose_bent(ctx: Context) -> None:
    """Arm 2 turned from arm 1 at q = 0 (by 1 to 170 deg)."""
    arms = _arms(ctx)
    if arms is not None and 1.0 < abs(arms[2]) <= 170.0:
        ctx.add(Severity.INFO, "zero-pose-bent", f"at q = 0 arm 2 turns {arms[2]:.4g} deg from arm 1")


def zero_pose_direction(ctx: Context) -> None:
    """Arm 1 pointing elsewhere than +x at q = 0: handled by the zero offsets."""
    arms = _arms(ctx)
    if arms is not None and abs(arms[1]) > 1.0:
        ja, heading = arms[0], arms[1]
        names = {90: "+y", -90: "-y", 180: "-x", -180: "-x"}
        named = names.get(int(round(heading)), f"{heading:.4g} deg from +x")
        ctx.add(Severity.INFO, "zero-pose-direction", f"at q = 0 arm 1 points along {named} ({heading:.4g} deg from "
                "+x), not +x: the zero offset is handled by the toolkit", ja.line, ja.name)  # fmt: skip


def length_implausible(ctx: Context) -> None:
    """A joint origin offset beyond 10 m: millimetres written as metres?"""
    for j in ctx.tree.order:
        if max(abs(v) for v in j.xyz) > OFFSET_RANGE:
            ctx.add(Severity.WARNING, "length-implausible",
                    f"joint {j.name}'s origin xyz {' '.join(f'{v:g}' for v in j.xyz)} is more than {OFFSET_RANGE:g} m "
                    "long: millimetres written as metres?", j.origin_line, j.name)  # fmt: skip


def _full_precision(value: float) -> bool:
    """Whether ``value`` needs FULL_PRECISION significant digits or more: written by a program, not typed."""
    digits = repr(abs(value)).split("e")[0].replace(".", "").lstrip("0")
    return len(digits) >= FULL_PRECISION


def rpy_approximate(ctx: Context) -> None:
    """An rpy value such as 3.14 or 1.5708 near a multiple of pi/2, with the tool position error it causes.

    The error is measured, not estimated: the tool point with the value as written against the exact value,
    the most over the configurations of :attr:`~scara_pin.lint.context.Context.samples` (the limits' corners
    and seeded ones), by the linter's own walk of the chain.
    """
    tool = ctx.tool
    on_path = {j.name for j in ctx.tree.supports(tool)} if tool else set()
    for j in ctx.tree.order:
        for axis_name, (k, value) in zip(("roll", "pitch", "yaw"), enumerate(j.rpy)):
            n = round(value / (math.pi / 2))
            err = value - n * math.pi / 2
            if n == 0 or not RPY_EXACT < abs(err) < RPY_NEAR or _full_precision(value):
                continue
            exact = {1: "pi/2", -1: "-pi/2", 2: "pi", -2: "-pi"}.get(n, f"{n}*pi/2")
            fixed = tuple(n * math.pi / 2 if i == k else v for i, v in enumerate(j.rpy))
            mm = 1000.0 * max((float(np.linalg.norm(ctx.tool_position(q) - ctx.tool_position(q, (j.name, fixed))))
                               for q in ctx.samples), default=0.0) if j.name in on_path else 0.0  # fmt: skip
            where = (f"the tool point moves up to {mm:.3g} mm from where {exact} puts it (the most over "
                     f"{len(ctx.samples)} configurations: the limits' corners and {SAMPLES} seeded)"
                     if j.name in on_path else f"joint {j.name} does not carry the tool: 0 mm at the tool")
            ctx.add(Severity.WARNING if mm >= 1e-3 else Severity.INFO, "rpy-approximate",
                    f"joint {j.name}: rpy {axis_name} = {value!r} approximates {exact} (error {abs(err):.3g} rad = "
                    f"{math.degrees(abs(err)):.3g} deg): {where}; write {exact} as {n * math.pi / 2!r}",
                    j.origin_line, j.name)  # fmt: skip
