"""Pallets: a grid of places taught by its corners, in layers (Epson SPEL+'s ``Pallet``).

A pallet of R rows, C columns and L layers is taught by the poses (x, y, z, yaw) of its corner places on
the first layer: ``[1, 1]``, ``[1, C]``, ``[R, 1]`` and optionally ``[R, C]``. With u = (c - 1) / (C - 1)
and v = (r - 1) / (R - 1) (0 when C or R is 1), place [r, c] is

- three corners: the affine grid  P = P11 + u (P1C - P11) + v (PR1 - P11);
- four corners: the bilinear one  P = (1 - u)(1 - v) P11 + u (1 - v) P1C + (1 - u) v PR1 + u v PRC
  (a tray that is not a parallelogram, or a fixture taught slightly skewed),

applied to x, y, z and the yaw alike (each corner's yaw taken within pi of the first's, so the yaw turns
the short way); layer l is ``(l - 1) * layer_height`` higher. A single row or column is taught by its two
ends, ``[1, 1]`` and ``[1, C]`` (or ``[R, 1]``); a single place by itself.

Places are numbered from 1 as SPEL+ numbers them: row by row within a layer, layer by layer,
``i = ((l - 1) R + (r - 1)) C + c``. A loop visits them in an :class:`Order`: ``rows`` (that numbering),
``columns`` (column by column), ``serpentine`` (row by row, every other row backwards); every order
finishes a layer before the next.

Refused (:class:`~scara_pin.errors.InvalidInputError`): corners that coincide (closer than
:data:`COINCIDENT` m), three corners on one line (the two edges within :data:`COLLINEAR` rad of parallel),
and four corners that are not in the order above (the bilinear grid folds over itself).
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InvalidInputError

__all__ = ["COINCIDENT", "COLLINEAR", "Order", "Pallet"]

COINCIDENT = 1e-6
"""[m] two corners closer than this are the same point: no pallet spans them."""
COLLINEAR = 1e-3
"""[rad] the two edges from corner [1, 1] closer than this to parallel (or antiparallel): collinear corners."""


class Order(enum.Enum):
    """The order a loop visits a pallet's places in; the value is its name in a job file."""

    ROWS = "rows"
    COLUMNS = "columns"
    SERPENTINE = "serpentine"


@dataclass(frozen=True)
class Pallet:
    """A pallet: its corner points (by name), rows, columns and layers (module docstring).

    Attributes:
        name: the pallet's name in the job.
        corners: the names of the taught corner points, ``[1, 1]`` first (see :meth:`corners_needed`).
        rows, columns, layers: the grid's size, each >= 1.
        layer_height: [m] the rise from one layer to the next (> 0 when ``layers`` > 1).
    """

    name: str
    corners: tuple[str, ...]
    rows: int
    columns: int
    layers: int = 1
    layer_height: float = 0.0

    def __post_init__(self) -> None:
        for what in ("rows", "columns", "layers"):
            n = getattr(self, what)
            if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                raise InvalidInputError(f"pallet {self.name}: {what} must be a whole number >= 1, got {n!r}")
        h = self.layer_height
        if isinstance(h, bool) or not isinstance(h, (int, float)) or not math.isfinite(h):
            raise InvalidInputError(f"pallet {self.name}: layer_height must be a finite number [m], got {h!r}")
        if self.layers > 1 and not h > 0.0:
            raise InvalidInputError(f"pallet {self.name}: {self.layers} layers need a layer_height > 0 [m], "
                                    f"got {h!r}")  # fmt: skip
        needed = self.corners_needed()
        if len(self.corners) not in needed:
            raise InvalidInputError(f"pallet {self.name}: {self.rows} x {self.columns} places take "
                                    f"{' or '.join(map(str, needed))} corners ({self.corner_names()}), got "
                                    f"{len(self.corners)}")  # fmt: skip

    @property
    def places(self) -> int:
        """The number of places: rows x columns x layers."""
        return self.rows * self.columns * self.layers

    def corners_needed(self) -> tuple[int, ...]:
        """How many corners teach this grid: (3, 4) for rows and columns, 2 for one line, 1 for one place."""
        if self.rows == 1 and self.columns == 1:
            return (1,)
        if self.rows == 1 or self.columns == 1:
            return (2,)
        return (3, 4)

    def corner_names(self) -> str:
        """The corners' grid positions in the order a job lists them, e.g. ``[1,1], [1,6], [4,1] (, [4,6])``."""
        R, C = self.rows, self.columns
        if R == 1 and C == 1:
            return "[1,1]"
        if R == 1 or C == 1:
            return f"[1,1], [{R},{C}]"
        return f"[1,1], [1,{C}], [{R},1] (, [{R},{C}])"

    def place(self, index: int) -> tuple[int, int, int]:
        """(row, column, layer), each from 1, of place ``index`` (from 1; module docstring's numbering)."""
        if not 1 <= index <= self.places:
            raise InvalidInputError(f"index {index} is past the end of pallet {self.name} ({self.places} places, "
                                    f"numbered from 1)")  # fmt: skip
        k = index - 1
        layer, k = divmod(k, self.rows * self.columns)
        row, col = divmod(k, self.columns)
        return row + 1, col + 1, layer + 1

    def order(self, order: Order = Order.ROWS) -> list[int]:
        """The place numbers in the order a loop visits them."""
        R, C = self.rows, self.columns
        out = []
        for layer in range(self.layers):
            base = layer * R * C
            if order is Order.COLUMNS:
                out += [base + r * C + c + 1 for c in range(C) for r in range(R)]
            else:
                for r in range(R):
                    cols = range(C - 1, -1, -1) if order is Order.SERPENTINE and r % 2 else range(C)
                    out += [base + r * C + c + 1 for c in cols]
        return out

    def corner_poses(self, poses: np.ndarray) -> np.ndarray:
        """The corners' poses checked, each yaw within pi of the first's: what :meth:`pose` takes.

        Args:
            poses: (len(corners), 4) poses (x, y, z, yaw) of the corner points, in the order of :attr:`corners`.

        Raises:
            InvalidInputError: corners that coincide, collinear corners, or four corners out of order.
        """
        P = np.array(poses, dtype=float).reshape(len(self.corners), 4)
        P[1:, 3] = P[0, 3] + np.remainder(P[1:, 3] - P[0, 3] + math.pi, 2.0 * math.pi) - math.pi
        self._check(P)
        return P

    def pose(self, corners: np.ndarray, index: int) -> np.ndarray:
        """The pose (x, y, z, yaw) of place ``index`` [m, rad] from :meth:`corner_poses`' result."""
        row, col, layer = self.place(index)
        P = corners
        u = (col - 1) / (self.columns - 1) if self.columns > 1 else 0.0
        v = (row - 1) / (self.rows - 1) if self.rows > 1 else 0.0
        if len(P) == 1:
            out = P[0].copy()
        elif len(P) == 2:  # one row (u) or one column (v) from its two ends
            out = P[0] + (u if self.rows == 1 else v) * (P[1] - P[0])
        elif len(P) == 3:
            out = P[0] + u * (P[1] - P[0]) + v * (P[2] - P[0])
        else:
            out = (1 - u) * (1 - v) * P[0] + u * (1 - v) * P[1] + (1 - u) * v * P[2] + u * v * P[3]
        out[2] += (layer - 1) * self.layer_height
        return out

    def _check(self, P: np.ndarray) -> None:
        names = self.corners
        for i in range(len(P)):
            for j in range(i):
                if np.linalg.norm(P[i, :3] - P[j, :3]) < COINCIDENT:
                    raise InvalidInputError(f"pallet {self.name}: corners {names[j]} and {names[i]} are the same "
                                            f"point (closer than {COINCIDENT:g} m)")  # fmt: skip
        if len(P) < 3:
            return
        e_c, e_r = P[1, :3] - P[0, :3], P[2, :3] - P[0, :3]
        normal = np.cross(e_c, e_r)
        sine = float(np.linalg.norm(normal) / (np.linalg.norm(e_c) * np.linalg.norm(e_r)))
        if sine < math.sin(COLLINEAR):
            raise InvalidInputError(f"pallet {self.name}: corners {', '.join(names[:3])} are collinear (the edges "
                                    f"[1,1]-[1,{self.columns}] and [1,1]-[{self.rows},1] are "
                                    f"{math.degrees(math.asin(min(sine, 1.0))):.3g} deg from parallel): they "
                                    "span no grid")  # fmt: skip
        if len(P) == 4:  # the bilinear map keeps its orientation at every corner, or it folds over
            p11, p1c, pr1, prc = (p[:3] for p in P)
            for u, v in ((0, 0), (1, 0), (0, 1), (1, 1)):
                du = (1 - v) * (p1c - p11) + v * (prc - pr1)
                dv = (1 - u) * (pr1 - p11) + u * (prc - p1c)
                if float(np.dot(np.cross(du, dv), normal)) <= 0.0:
                    raise InvalidInputError(f"pallet {self.name}: the 4 corners {', '.join(names)} are not in the "
                                            f"order [1,1], [1,{self.columns}], [{self.rows},1], "
                                            f"[{self.rows},{self.columns}]: the grid folds over itself")  # fmt: skip
