"""Input checks shared by the path and trajectory modules (private)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from .description import JOINT_COUNTS, JOINT_NAMES
from .errors import ParameterError
from .units import NUMBER_TEXT, number_text  # noqa: F401 - re-exported: the grammar lives in units.py (below description)

if TYPE_CHECKING:
    from ._typing import ArrayLike

MAGNITUDE_MAX = 1e6
"""[m or rad] the largest joint value or target coordinate taken as such: beyond it an angle has no
precision left (its ulp exceeds 1e-10 rad) and no SCARA is that large."""



def as_floats(name: str, value: object, rule: str) -> np.ndarray:
    """``value`` as a float array (any shape), or a ParameterError saying ``rule``.

    Strings, objects and integers too large for a float give the ParameterError, never a bare TypeError,
    ValueError or OverflowError.
    """
    if isinstance(value, (str, bytes)):
        raise ParameterError(name, ParameterError.NOTHING, rule)
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise ParameterError(name, ParameterError.NOTHING, rule) from None
    return arr


def as_vector(name: str, value: object, n: int | None = 4) -> np.ndarray:
    """``value`` as ``n`` finite floats (None: one per joint, 4 or 3: JOINT_COUNTS), or a ParameterError."""
    counts = JOINT_COUNTS if n is None else (n,)
    what = " or ".join(map(str, counts))
    arr = as_floats(name, value, f"must be {what} numbers")
    if arr.ndim != 1 or len(arr) not in counts:
        raise ParameterError(name, value, f"must be {what} numbers (got shape {arr.shape})")
    if not np.isfinite(arr).all():
        raise ParameterError(name, arr.tolist(), "must be finite")
    return arr


def as_positive(name: str, value: object, unit: str = "") -> float:
    """``value`` as a finite float > 0, or a :class:`ParameterError`."""
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be a number") from None
    if not (math.isfinite(v) and v > 0.0):
        raise ParameterError(name, v, "must be finite and > 0", unit)
    return v


def as_rows(name: str, value: object) -> np.ndarray:
    """``value`` as an (m, n) float array of finite numbers, m >= 2, n a joint count (4, or 3), or a ParameterError."""
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "must be rows of 4 numbers (3 without a wrist)") from None
    if arr.ndim != 2 or arr.shape[1] not in JOINT_COUNTS or arr.shape[0] < 2:
        raise ParameterError(name, f"array of shape {arr.shape}", "must have shape (m, 4), or (m, 3) without a "
                             "wrist, with m >= 2")  # fmt: skip
    if not np.isfinite(arr).all():
        raise ParameterError(name, arr.tolist(), "must be finite")
    return arr


def as_limit_vector(name: str, values: ArrayLike, unit: str | Sequence[str], names: Sequence[str] = JOINT_NAMES,
                    unbounded: bool = False) -> np.ndarray:  # fmt: skip
    """Per-joint limits (velocity, acceleration...) as an array; each finite and > 0 (``names``: the joints').

    ``unit``: one for every joint, or each joint's (``rad/s`` for a revolute joint, ``m/s`` for a prismatic one).
    A refusal names a configured robot's parameter (``joint2_velocity``, what ``--set`` takes), else the joint of
    the file (``the velocity limit of joint joint_tool_rotate``). ``unbounded``: +inf is taken too, as no limit
    (the effort of a URDF joint without ``<limit>``).
    """
    arr = np.array(values, dtype=float)
    if arr.ndim != 1 or len(arr) not in JOINT_COUNTS:
        raise ParameterError(name, values, "must hold one value per joint (4, or 3 without a wrist)")
    units = [unit] * len(arr) if isinstance(unit, str) else list(unit)
    configured = tuple(names[: len(arr)]) == JOINT_NAMES[: len(arr)]
    for joint, v, u in zip(names, arr.tolist(), units):
        label = f"{joint}_{name}" if configured else f"the {name} limit of joint {joint}"
        if math.isnan(v):
            raise ParameterError(label, v, "must be given (a URDF file has no acceleration limits)")
        if not ((math.isfinite(v) or (unbounded and v == math.inf)) and v > 0.0):
            hint = " (a URDF joint without <limit>, or a placeholder 0: load_robot(velocity=...), --velocity)" \
                if name == "velocity" else ""  # fmt: skip
            raise ParameterError(label, v, "must be finite and > 0" + hint, u)
    return arr


