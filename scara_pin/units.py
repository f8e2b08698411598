"""Units for people: the units a person reads and types, how numbers are printed and typed for them.

The one grammar of a number as text is :data:`NUMBER_TEXT` (typed values, URDF attributes, yaml and CSV).

Inside the package everything is SI (m, rad, s). People type and read millimetres and degrees too:
:class:`DisplayUnits` names the unit chosen for lengths and for angles, and scales SI values to it.

Printed numbers are rounded to the resolution of their unit, :data:`RESOLUTION` (1e-9 in SI: 1 nm, 1 nrad,
1 ns, the bar of exact kinematics) expressed in the unit shown: 9 decimals in m and rad, 6 in mm, 7 in
deg. Trailing zeros are dropped, and a value that rounds to zero prints ``0``, never ``-0`` or ``1e-17``:
``cos(pi/2) * 400 mm`` prints ``0``, ``0.18999999999999986 m`` prints ``0.19``. Machine outputs (JSON,
CSV) keep every bit; only text for people is rounded.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from .errors import ParameterError

__all__ = [
    "ANGLE_UNITS",
    "HUMAN",
    "LENGTH_UNITS",
    "NUMBER_TEXT",
    "RESOLUTION",
    "SI",
    "DisplayUnits",
    "decimals_for",
    "format_number",
    "format_vector",
    "number_text",
]

NUMBER_TEXT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
"""The one grammar of a number as text (typed by a user, or in a URDF, a yaml or a CSV file): ASCII digits,
optional sign, decimal point and exponent. No ``_`` separators, no other digits, no hex, no nan/inf words:
what a robotics user types, and what urdfdom's parser accepts."""


def number_text(text: str) -> float:
    """``text`` (surrounding blanks allowed) as a float if it follows :data:`NUMBER_TEXT`, else NaN."""
    stripped = text.strip(" \t\n\r")
    return float(stripped) if NUMBER_TEXT.fullmatch(stripped) else math.nan


LENGTH_UNITS: dict[str, float] = {"m": 1.0, "mm": 1000.0}
"""Length units a person may choose, with their size in metres^-1 (multiply SI by it)."""
ANGLE_UNITS: dict[str, float] = {"rad": 1.0, "deg": 180.0 / math.pi}
"""Angle units a person may choose, with their scale from radians."""
RESOLUTION = 1e-9
"""The resolution of printed values in SI (1 nm, 1 nrad, 1 ns): every printed number is rounded to it."""
_MAX_DECIMALS = 15


def decimals_for(scale: float, resolution: float = RESOLUTION) -> int:
    """Decimals that show ``resolution`` (an SI amount) in a unit ``scale`` times SI.

    Examples: 9 for m and rad (scale 1), 6 for mm (1000), 7 for deg (57.3: 1e-7 deg = 1.7e-9 rad), 3 for
    mm^2 (scale 1e6 with a resolution of 1e-9 m^2).

    Args:
        scale: display value per SI value (1000 for mm) [-].
        resolution: the SI amount the last printed digit stands for.
    """
    if not (scale > 0 and resolution > 0 and math.isfinite(scale * resolution)):
        raise ParameterError("scale", scale, "must be a finite number > 0")
    return min(_MAX_DECIMALS, max(0, round(-math.log10(scale * resolution))))


def format_number(value: float, decimals: int) -> str:
    """``value`` rounded to ``decimals`` decimals, trailing zeros dropped, ``-0`` printed ``0``.

    ``format_number(2.4492936e-14, 6) == "0"``, ``format_number(0.18999999999999986, 9) == "0.19"``,
    ``format_number(-1.5, 3) == "-1.5"``. NaN and infinities print as ``nan``, ``inf``, ``-inf``.
    """
    value = float(value)
    if not math.isfinite(value):
        return repr(value)
    text = f"{value:.{decimals}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def format_vector(values: Iterable[float], decimals: int | Sequence[int], width: int = 0) -> str:
    """``[a, b, c]``: each value through :func:`format_number`, right-aligned to ``width`` characters.

    Args:
        values: the numbers.
        decimals: one count for all, or one per value.
        width: the least width of each cell (0: no padding); a matrix printed row by row lines up with it.
    """
    items = [float(v) for v in values]
    per = [decimals] * len(items) if isinstance(decimals, int) else list(decimals)
    if len(per) != len(items):
        raise ParameterError("decimals", decimals, f"must be one count or {len(items)} (one per value)")
    return "[" + ", ".join(format_number(v, d).rjust(width) for v, d in zip(items, per)) + "]"


@dataclass(frozen=True)
class DisplayUnits:
    """The units a person reads and types: one for lengths, one for angles (time stays in s).

    Attributes:
        length: ``"m"`` or ``"mm"``.
        angle: ``"rad"`` or ``"deg"``.
    """

    length: str = "m"
    angle: str = "rad"

    def __post_init__(self) -> None:
        if self.length not in LENGTH_UNITS:
            raise ParameterError("length unit", self.length, f"must be one of {', '.join(LENGTH_UNITS)}")
        if self.angle not in ANGLE_UNITS:
            raise ParameterError("angle unit", self.angle, f"must be one of {', '.join(ANGLE_UNITS)}")

    @classmethod
    def parse(cls, text: str) -> DisplayUnits:
        """Units from a list such as ``"mm,deg"``, ``"deg"`` or ``"m,rad"`` (any order; an omitted kind stays SI).

        Raises:
            ParameterError: an unknown unit, or two units of one kind.
        """
        found: dict[str, str] = {}
        for token in (t.strip() for t in text.split(",")):
            kind = "length" if token in LENGTH_UNITS else "angle" if token in ANGLE_UNITS else None
            if kind is None:
                raise ParameterError("--units", text[:40], "must list units among m, mm (lengths) and rad, deg "
                                     "(angles), e.g. mm,deg")  # fmt: skip
            if kind in found:
                raise ParameterError("--units", text[:40], f"names two {kind} units; give one of each kind")
            found[kind] = token
        return cls(**found)

    def scale(self, kind: str) -> float:
        """Display value per SI value for a quantity kind: ``"length"``, ``"angle"``, ``"area"`` or ``"time"``."""
        if kind == "length":
            return LENGTH_UNITS[self.length]
        if kind == "angle":
            return ANGLE_UNITS[self.angle]
        if kind == "area":
            return LENGTH_UNITS[self.length] ** 2
        if kind == "time":
            return 1.0
        raise ParameterError("quantity kind", kind, "must be length, angle, area or time")

    def name(self, kind: str) -> str:
        """The unit name of a quantity kind (``"mm"``, ``"deg"``, ``"mm^2"``, ``"s"``)."""
        return {"length": self.length, "angle": self.angle, "area": f"{self.length}^2", "time": "s"}[kind]

    def decimals(self, kind: str) -> int:
        """Decimals printed for a quantity kind in these units (see :func:`decimals_for`)."""
        return decimals_for(self.scale(kind))

    def format(self, value: float, kind: str) -> str:
        """An SI value of a quantity kind, in these units, rounded to its resolution (no unit name)."""
        return format_number(value * self.scale(kind), self.decimals(kind))

    def format_vector(self, values: Iterable[float], kinds: str | Sequence[str], width: int = 0) -> str:
        """SI values, each of its kind (one kind for all, or one per value), as ``[a, b, c]`` in these units."""
        items = [float(v) for v in values]
        per = [kinds] * len(items) if isinstance(kinds, str) else list(kinds)
        if len(per) != len(items):
            raise ParameterError("kinds", kinds, f"must be one kind or {len(items)} (one per value)")
        return format_vector([v * self.scale(k) for v, k in zip(items, per)], [self.decimals(k) for k in per], width)


SI = DisplayUnits()
"""Metres and radians."""
HUMAN = DisplayUnits("mm", "deg")
"""Millimetres and degrees (a controller's units)."""
