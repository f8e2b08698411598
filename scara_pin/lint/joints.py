"""Rules of the joints and their limits: numbers, ``<limit>``, ranges, velocities.

Each rule is a function of the :class:`~scara_pin.lint.context.Context`; its code and place in the run are in
:data:`scara_pin.lint.registry.RULES`.
"""

from __future__ import annotations

import math

from ..urdf_rules import joint_problem
from .context import Context, LintJoint
from .report import Severity

__all__ = [
    "PLACEHOLDER_VELOCITIES", "PRISMATIC_RANGE", "PRISMATIC_VELOCITY", "REVOLUTE_RANGE", "REVOLUTE_VELOCITY",
    "bad_number", "continuous_joint", "limit_missing", "limits_empty", "limits_implausible", "limits_inverted",
    "velocity_implausible", "velocity_placeholder", "velocity_zero",
]  # fmt: skip

REVOLUTE_RANGE = 4 * math.pi
"""[rad] a revolute limit beyond two turns either way is implausible (degrees written as radians)."""
PRISMATIC_RANGE = 5.0
"""[m] a SCARA stroke limit beyond this is implausible (millimetres written as metres)."""
PLACEHOLDER_VELOCITIES = (100.0, 1000.0, 10000.0)
"""Velocity limits that are placeholders whatever the joint."""
REVOLUTE_VELOCITY = (0.05, 50.0)
"""[rad/s] plausible range of a SCARA joint's velocity limit."""
PRISMATIC_VELOCITY = (0.05, 10.0)
"""[m/s] plausible range of a SCARA quill's velocity limit."""
_LIMIT_NUMBERS = ("lower", "upper", "velocity", "effort")


def bad_number(ctx: Context) -> None:
    """An origin, axis or limit that is not finite numbers (urdfdom's grammar), or a zero axis."""
    for j in ctx.document.joints:
        if not j.name:
            continue
        for what, attr, values, default, line in (("origin", "xyz", j.xyz, 3, j.origin_line),
                                                  ("origin", "rpy", j.rpy, 3, j.origin_line),
                                                  ("axis", "xyz", j.axis, 3, j.axis_line)):  # fmt: skip
            if what == "axis" and j.type in ("fixed", "floating"):  # urdfdom never reads their axis
                continue
            if len(values) != default or not all(math.isfinite(v) for v in values):
                el = j.el.find(what)
                raw = "" if el is None else el.get(attr, "")
                ctx.error("bad-number", f"{what} {attr}={raw!r} of joint {j.name} must be {default} finite numbers",
                          line, j.name)  # fmt: skip
                if what == "axis":
                    j.axis = (1.0, 0.0, 0.0)
        if j.movable and len(j.axis) == 3 and math.hypot(*j.axis) < 1e-12:
            problem = joint_problem(j.name, j.type, j.axis, None, None)  # the loader's rule (the zero axis)
            if problem is not None:
                ctx.error(problem[0], problem[1], j.line, j.name)
        for attr in _LIMIT_NUMBERS:
            value = j.numbers(attr)
            if value and not math.isfinite(value[0]):
                ctx.error("bad-number", f"joint {j.name}'s {attr} limit is {j.limit[attr]!r}: not a "  # type: ignore[index]
                          "finite number", j.limit_line, j.name)  # fmt: skip


def continuous_joint(ctx: Context) -> None:
    """A continuous joint of q: Pinocchio's (cos, sin), one angle in scara-pin's q."""
    for j in ctx.chain.joints:
        if j.type == "continuous":
            ctx.add(Severity.WARNING, "continuous-joint",
                    f"joint {j.name} is continuous: Pinocchio gives it nq = 2 (cos, sin) and nv = 1, while scara-pin's "
                    "q holds one value per joint (its angle: converted to cos, sin for Pinocchio; no position limit, "
                    "IK solutions presented in [-pi, pi]); "
                    + ("its <limit> lower/upper are ignored" if j.limit is not None else "it has no limits"),
                    j.line, j.name)  # fmt: skip


def limit_missing(ctx: Context) -> None:
    """A joint of q without ``<limit>``, effort, velocity (urdfdom refuses it), or lower/upper (read as 0)."""
    for j in ctx.chain.joints:
        lim = j.limit
        if lim is None:
            if j.type != "continuous":
                ctx.error("limit-missing", f"{j.type} joint {j.name} has no <limit>: urdfdom refuses it", j.line,
                          j.name)  # fmt: skip
            continue
        for attr in ("velocity", "effort"):
            if attr not in lim:
                ctx.error("limit-missing", f"joint {j.name}'s <limit> has no {attr}: urdfdom refuses it",
                          j.limit_line, j.name)  # fmt: skip
        missing = [a for a in ("lower", "upper") if a not in lim]
        if j.type != "continuous" and missing:
            lo, hi = ((j.numbers(a) or (0.0,))[0] for a in ("lower", "upper"))  # urdfdom reads an absent one as 0
            if lo < hi:  # the loader's rule (joint_problem) takes the range
                ctx.add(Severity.WARNING, "limit-missing", f"joint {j.name}'s <limit> has no {' and '.join(missing)}"
                        f": read as 0 (urdfdom's default), the range is [{lo:g}, {hi:g}]", j.limit_line,
                        j.name)  # fmt: skip
            else:
                ctx.error("limit-missing", f"joint {j.name}'s <limit> has no {' and '.join(missing)}: read as 0, "
                          f"the range [{lo:g}, {hi:g}] is empty: the joint cannot move", j.limit_line,
                          j.name)  # fmt: skip


def _range(j: LintJoint) -> tuple[float, float] | None:
    """(lower, upper) of a joint with a position range, both written and finite; else None."""
    if j.type == "continuous" or not j.numbers("lower") or not j.numbers("upper"):
        return None
    lo, hi = j.numbers("lower")[0], j.numbers("upper")[0]
    return (lo, hi) if math.isfinite(lo + hi) else None


def _problem(ctx: Context, code: str) -> None:
    for j in ctx.chain.joints:
        rng = _range(j)
        problem = None if rng is None else joint_problem(j.name, j.type, j.axis, *rng)  # the loader's rule
        if problem is not None and problem[0] == code:
            ctx.error(code, problem[1], j.limit_line, j.name)


def limits_inverted(ctx: Context) -> None:
    """Lower limit above upper (the loader's rule, scara_pin.urdf_rules.joint_problem)."""
    _problem(ctx, "limits-inverted")


def limits_empty(ctx: Context) -> None:
    """Lower limit equal to upper: the joint cannot move (the loader's rule)."""
    _problem(ctx, "limits-empty")


def limits_implausible(ctx: Context) -> None:
    """Revolute limits beyond +/-4 pi (degrees?), strokes beyond 5 m (millimetres?)."""
    for j in ctx.chain.joints:
        rng = _range(j)
        if rng is None:
            continue
        lo, hi = rng
        if j.type == "revolute" and max(abs(lo), abs(hi)) > REVOLUTE_RANGE:
            ctx.add(Severity.WARNING, "limits-implausible",
                    f"joint {j.name}'s limits [{lo:g}, {hi:g}] rad are {math.degrees(lo):.4g}..{math.degrees(hi):.4g} "
                    f"deg ({(hi - lo) / (2 * math.pi):.3g} turns): degrees written as radians?", j.limit_line,
                    j.name)  # fmt: skip
        elif j.type == "prismatic" and max(abs(lo), abs(hi)) > PRISMATIC_RANGE:
            ctx.add(Severity.WARNING, "limits-implausible",
                    f"joint {j.name}'s stroke [{lo:g}, {hi:g}] m is longer than {PRISMATIC_RANGE:g} m: millimetres "
                    "written as metres?", j.limit_line, j.name)  # fmt: skip


def _velocities(ctx: Context) -> list[tuple[LintJoint, float]]:
    """The joints of q with a finite velocity limit, and that limit."""
    out = []
    for j in ctx.chain.joints:
        v = j.numbers("velocity")
        if v and math.isfinite(v[0]):
            out.append((j, v[0]))
    return out


def _unit(j: LintJoint) -> str:
    return "m/s" if j.type == "prismatic" else "rad/s"


def velocity_zero(ctx: Context) -> None:
    """A velocity limit of 0: a placeholder."""
    for j, v in _velocities(ctx):
        if v == 0:
            ctx.add(Severity.WARNING, "velocity-zero", f"joint {j.name}'s velocity limit is 0 {_unit(j)}: a "
                    "placeholder; timing and trajectories need the real limit (> 0)", j.limit_line, j.name)


def velocity_placeholder(ctx: Context) -> None:
    """A velocity limit of 100, 1000 or 10000, or one value on every joint."""
    found = _velocities(ctx)
    for j, v in found:
        if v in PLACEHOLDER_VELOCITIES:
            ctx.add(Severity.WARNING, "velocity-placeholder", f"joint {j.name}'s velocity limit is {v:g} {_unit(j)}: "
                    "a placeholder value", j.limit_line, j.name)  # fmt: skip
    values = [v for _, v in found]
    if len(values) >= 3 and len(set(values)) == 1 and values[0] != 0 and values[0] not in PLACEHOLDER_VELOCITIES:
        first = next((j.limit_line for j in ctx.chain.joints if j.limit is not None), None)
        ctx.add(Severity.WARNING, "velocity-placeholder",
                f"every joint has the velocity limit {values[0]:g} (rad/s and m/s alike): a placeholder?", first)


def velocity_implausible(ctx: Context) -> None:
    """A velocity limit outside 0.05..50 rad/s (revolute) or 0.05..10 m/s (prismatic); a deg/s reading offered.

    A prismatic joint slower than the range is information, not a warning: a lead-screw lift at 0.03 m/s is real.
    """
    for j, v in _velocities(ctx):
        low, high = PRISMATIC_VELOCITY if j.type == "prismatic" else REVOLUTE_VELOCITY
        if v == 0 or v in PLACEHOLDER_VELOCITIES or low <= v <= high:
            continue
        note = ""
        as_deg = v * 180.0 / math.pi
        if abs(as_deg - round(as_deg)) < 1e-6 * max(1.0, as_deg) and round(as_deg) != 0:
            note = f"; it is {round(as_deg):g} deg/s converted to rad: a unit error?"
        if j.type == "prismatic" and 0 < v < low and not note:
            ctx.add(Severity.INFO, "velocity-implausible",
                    f"joint {j.name}'s velocity limit {v:g} m/s is below {low:g} m/s: a slow axis (a lead-screw "
                    "lift?); every motion is timed to it", j.limit_line, j.name)  # fmt: skip
            continue
        ctx.add(Severity.WARNING, "velocity-implausible",
                f"joint {j.name}'s velocity limit {v:g} {_unit(j)} is outside {low:g}..{high:g} {_unit(j)}{note}",
                j.limit_line, j.name)  # fmt: skip
