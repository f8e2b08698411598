"""A cell: the obstacles around a robot, the part it carries, the pairs never checked, and the margin.

Everything is in the robot's ``base`` frame (the controller's reference frame), SI units. A cell is data:
it knows no robot. :class:`~scara_pin.cell.scene.Scene` puts a cell and a robot together.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import Any

from ..errors import InvalidInputError, brief
from ..limits import MAX_CELL_OBSTACLES, MAX_CELL_TRIANGLES, check_count
from .shapes import Shape

__all__ = ["DEFAULT_MARGIN", "MAX_MARGIN", "Cell", "Obstacle", "check_name"]

DEFAULT_MARGIN = 0.002
"""[m] the margin of a cell file that gives none."""
MAX_MARGIN = 1.0
"""[m] the largest margin (a larger one leaves no room in any cell)."""
_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.:/+-]{0,99}")
CARRIED = "carried"
"""The name of the carried part in pairs and messages."""


def check_name(name: object, what: str) -> str:
    """``name`` if it is a plain name (letters, digits, ``_ . : / + -``; at most 100 characters), else an error."""
    if not isinstance(name, str) or not _NAME.fullmatch(name):
        raise InvalidInputError(f"{what} {brief(name, 44)} must be a name of letters, digits and _ . : / + - "
                                "(at most 100 characters)")  # fmt: skip
    return name


@dataclass(frozen=True, eq=False)
class Obstacle:
    """One obstacle of a cell.

    Attributes:
        name: its name (unique in the cell).
        shape: its shape, placed in the robot's base frame.
        line: the line of the cell file where it is described (0 when made in Python).
        margin: [m] the distance kept from this obstacle when it is larger than the cell's margin, or None (the
            cell's): the obstacle is then checked grown by the difference (:meth:`keep_out`).
    """

    name: str
    shape: Shape
    line: int = 0
    margin: float | None = None

    def __post_init__(self) -> None:
        if self.margin is not None:
            m = float(self.margin)
            if not (math.isfinite(m) and 0.0 <= m <= MAX_MARGIN):
                raise InvalidInputError(f"obstacle {self.name}: margin {m:.6g} m must be finite, in [0, "
                                        f"{MAX_MARGIN:g}] m")  # fmt: skip
            if self.shape.kind == "mesh":
                self.shape.grown(m)  # refused: a mesh takes the cell's margin
            object.__setattr__(self, "margin", m)

    def keep_out(self, margin: float) -> Shape:
        """The shape checked against the cell's ``margin`` [m]: grown by ``self.margin - margin`` when larger."""
        if self.margin is None or self.margin <= margin:
            return self.shape
        return self.shape.grown(self.margin - margin)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (``margin``: its own, when it has one)."""
        return {"name": self.name, **self.shape.to_dict(), **({} if self.margin is None else {"margin": self.margin})}


@dataclass(frozen=True, eq=False)
class Cell:
    """The obstacles around a robot, what it carries and how close it may come.

    Attributes:
        obstacles: the obstacles (names unique), in the robot's base frame.
        margin: [m] the smallest distance kept between the robot (and what it carries) and any obstacle, and
            between links of the robot that are checked against each other.
        carried: what the tool holds, placed in the tool frame, or None.
        allow: pairs of names (links, obstacles, ``carried``) never checked, beyond the defaults (adjacent
            links, links always in contact).
        origin: where the cell comes from (a file name, or "cell").
    """

    obstacles: tuple[Obstacle, ...] = ()
    margin: float = DEFAULT_MARGIN
    carried: Shape | None = None
    allow: tuple[tuple[str, str], ...] = ()
    origin: str = "cell"
    names: frozenset[str] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        check_count(f"obstacles of {self.origin}", len(self.obstacles), MAX_CELL_OBSTACLES)
        triangles = sum(o.shape.triangles for o in self.obstacles) + (self.carried.triangles if self.carried else 0)
        check_count(f"mesh triangles of {self.origin}", triangles, MAX_CELL_TRIANGLES)
        m = float(self.margin)
        if not (math.isfinite(m) and 0.0 <= m <= MAX_MARGIN):
            raise InvalidInputError(f"{self.origin}: margin {m:.6g} m must be finite, in [0, {MAX_MARGIN:g}] m")
        object.__setattr__(self, "margin", m)
        seen: set[str] = set()
        for o in self.obstacles:
            check_name(o.name, f"{self.origin}: obstacle name")
            if o.name in seen or o.name == CARRIED:
                why = "is reserved for the carried part" if o.name == CARRIED else "is used twice"
                raise InvalidInputError(f"{self.origin}: obstacle name {o.name!r} {why}")
            seen.add(o.name)
        pairs = []
        for pair in self.allow:
            if len(pair) != 2:
                raise InvalidInputError(f"{self.origin}: allow takes pairs of names, got {len(pair)}")
            a, b = (check_name(n, f"{self.origin}: allow") for n in pair)
            pairs.append((a, b))
        object.__setattr__(self, "allow", tuple(pairs))
        object.__setattr__(self, "names", frozenset(seen))

    def obstacle(self, name: str) -> Obstacle:
        """The obstacle of that name (InvalidInputError naming the known ones otherwise)."""
        for o in self.obstacles:
            if o.name == name:
                return o
        raise InvalidInputError(f"{self.origin}: no obstacle named {name!r} (obstacles: "
                                f"{', '.join(o.name for o in self.obstacles) or 'none'})")  # fmt: skip

    def with_obstacles(self, extra: tuple[Obstacle, ...] | list[Obstacle]) -> Cell:
        """The cell with more obstacles (e.g. the boxes placed so far on a pallet)."""
        return replace(self, obstacles=self.obstacles + tuple(extra))

    def with_carried(self, carried: Shape | None) -> Cell:
        """The cell with the tool holding ``carried`` (in the tool frame), or nothing."""
        return replace(self, carried=carried)

    def with_margin(self, margin: float) -> Cell:
        """The cell with another margin [m]."""
        return replace(self, margin=margin)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {"origin": self.origin, "margin": self.margin, "obstacles": [o.to_dict() for o in self.obstacles],
                "carried": None if self.carried is None else self.carried.to_dict(),
                "allow": [list(p) for p in self.allow]}  # fmt: skip

    def __repr__(self) -> str:
        carried = "" if self.carried is None else f", carrying a {self.carried.kind}"
        return f"Cell({self.origin}: {len(self.obstacles)} obstacle(s), margin {self.margin * 1e3:g} mm{carried})"
