"""The units of the numbers users type and read on the command line (the units rule, docs/units.md)."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..errors import InvalidInputError, ParameterError
from ..units import DisplayUnits
from ._numbers import number

if TYPE_CHECKING:
    from .._typing import ArrayLike

Q_NAMES = ("q1", "q2", "q3", "q4")
Q_KINDS = ("angle", "angle", "length", "angle")  # what each joint value measures
POSE_KINDS = ("length", "length", "length", "angle")  # x, y, z, yaw


class Units:
    """The units of the numbers the user types and reads: ``--mm --deg``, ``--units LENGTH,ANGLE``, or SI.

    The units rule (docs/units.md): typed numbers are SI (m, rad) unless the command line says otherwise;
    ``--mm --deg`` (or ``--units mm,deg``) switches both; ``--units`` names each kind explicitly (``m,deg``,
    ``mm,rad``, ``deg``: the kind left out stays SI). One flag alone, ``--deg`` or ``--mm``, is refused
    (exit 2) as soon as the command reads a typed value of the OTHER kind, which would silently stay SI:
    ``fk --deg 90 0 10 0`` would read q3 = 10 as metres. Text output uses the same units; JSON stays SI.

    Attributes:
        display: the units of the text (:class:`scara_pin.units.DisplayUnits`).
        alone: ``"--deg"`` or ``"--mm"`` when that flag was given without the other (the rule applies).
        q: what each joint value measures (``"angle"``/``"length"``); ``robot_from_args`` sets the robot's own.
    """

    def __init__(self, deg: bool = False, mm: bool = False, *, spec: str | None = None) -> None:
        if spec is not None:
            if deg or mm:
                raise InvalidInputError("give either --units or --deg/--mm, not both")
            self.display = DisplayUnits.parse(spec)
            self.alone: str | None = None
        else:
            self.display = DisplayUnits("mm" if mm else "m", "deg" if deg else "rad")
            self.alone = "--deg" if deg and not mm else "--mm" if mm and not deg else None
        self.angle = self.display.scale("angle")
        self.length = self.display.scale("length")
        self.angle_name = self.display.angle
        self.length_name = self.display.length
        self.q: tuple[str, ...] = Q_KINDS  # what each joint value measures; robot_from_args sets the robot's own

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> Units:
        """The units of a parsed command line (its ``--deg``, ``--mm`` and ``--units``, those it has)."""
        return cls(getattr(args, "deg", False), getattr(args, "mm", False), spec=getattr(args, "units", None))

    def scale(self, kinds: Sequence[str]) -> list[float]:
        """Multipliers from SI for a sequence of quantity kinds ("angle" / "length")."""
        return [self.angle if k == "angle" else self.length for k in kinds]

    def names(self, kinds: Sequence[str]) -> list[str]:
        """Unit names for a sequence of quantity kinds."""
        return [self.angle_name if k == "angle" else self.length_name for k in kinds]

    def guard(self, names: Sequence[str], texts: Sequence[str], kinds: Sequence[str]) -> None:
        """Refuse a typed value of the kind a lone ``--deg`` / ``--mm`` leaves in SI (the units rule).

        Raises:
            InvalidInputError: ``--deg`` alone and a length typed, or ``--mm`` alone and an angle typed.
        """
        if self.alone is None:
            return
        other = "length" if self.alone == "--deg" else "angle"
        for name, text, kind in zip(names, texts, kinds):
            if kind == other:
                shown = text.strip()[:40]
                if other == "length":
                    raise InvalidInputError(f"--deg without --mm: {name} = {shown} is a length and would be read "
                                            "in metres; add --mm to type millimetres (or --units deg,m to keep "
                                            "metres)")  # fmt: skip
                raise InvalidInputError(f"--mm without --deg: {name} = {shown} is an angle and would be read in "
                                        "radians; add --deg to type degrees (or --units mm,rad to keep "
                                        "radians)")  # fmt: skip

    def value(self, name: str, text: str, kind: str) -> float:
        """One typed value of a kind ("length" / "angle"), in SI, after the units rule."""
        self.guard((name,), (text,), (kind,))
        return number(name, text) / (self.angle if kind == "angle" else self.length)

    def fmt(self, values: ArrayLike, kinds: str | Sequence[str], width: int = 0) -> str:
        """SI values as ``[a, b, c]`` in the user's units, rounded to the unit's resolution (scara_pin.units)."""
        return self.display.format_vector(values, kinds, width)  # type: ignore[arg-type]

    def num(self, value: float, kind: str) -> str:
        """One SI value in the user's units, rounded to the unit's resolution (no unit name)."""
        return self.display.format(value, kind)


def jerk_limits(args: argparse.Namespace, units: Units) -> list[float] | None:
    """``--jerk-limit J`` or ``J1 J2 J3 J4``, SI out, or None.

    In the user's units (the units rule): each joint's value in its own unit, rad/s^3 or m/s^3 (deg/s^3, mm/s^3
    with --deg/--mm); one value stands for every joint, each in its unit.
    """
    if getattr(args, "jerk_limit", None) is None:
        return None
    n = len(units.q)
    if len(args.jerk_limit) not in (1, n):
        raise ParameterError("--jerk-limit", " ".join(args.jerk_limit), f"must be one number or {n} (one per joint)")
    texts = list(args.jerk_limit) * n if len(args.jerk_limit) == 1 else list(args.jerk_limit)
    units.guard([f"--jerk-limit q{i + 1}" for i in range(n)], texts, units.q)
    values = [number("--jerk-limit", t) / sc for t, sc in zip(texts, units.scale(units.q))]
    if not all(v > 0 for v in values):
        raise ParameterError("--jerk-limit", values, "must be > 0", "rad/s^3 or m/s^3")
    return values
