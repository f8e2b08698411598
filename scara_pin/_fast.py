"""The per-call hot paths: the compiled :mod:`scara_pin._speedups` when it was built, else pure Python.

Both routes give the same answers (``tests/test_speedups.py`` runs them against each other); the compiled
one is what the per-call speed figures in README are measured with. ``SCARA_PIN_NO_SPEEDUPS=1`` in the
environment, read at import, forces the Python route (to compare, or to rule the C module out).
"""

from __future__ import annotations

import importlib
import os
import warnings
from collections.abc import Callable
from types import ModuleType
from typing import Any

import numpy as np

_Q_MAX = 1e6
"""[rad or m] the largest joint value taken as a configuration (beyond it an angle has no precision)."""
Q_MAX2 = (0.5 * _Q_MAX) ** 2
"""The largest sum of squares of q that :func:`q_ok` waves through (NaN and inf never pass)."""

_F64 = np.dtype(np.float64)
_ROWS = np.array([0, 1, 2, 5])  # x, y, z, wz of a 6-row Jacobian

API_VERSION = 2
"""The version of scara_pin/_speedups.c this Python code is written for (its API_VERSION)."""
GEOMETRY_DOUBLES = 43
"""The number of doubles in the packed SCARA geometry (ScaraGeometry._cparams, struct Geometry in C)."""

speedups: ModuleType | None = None
"""The compiled module, or None (not built, built from another version, or SCARA_PIN_NO_SPEEDUPS=1)."""
if os.environ.get("SCARA_PIN_NO_SPEEDUPS") != "1":
    try:
        speedups = importlib.import_module("scara_pin._speedups")
    except ImportError:  # built without a C compiler (see hatch_build.py)
        pass
    else:
        if getattr(speedups, "API_VERSION", None) != API_VERSION or speedups.geometry_size() != GEOMETRY_DOUBLES:
            warnings.warn(
                f"scara_pin._speedups at {speedups.__file__} was built from another version of scara-pin; "
                "ignoring it (the pure-Python route gives the same answers; reinstall to rebuild it)",
                RuntimeWarning,
                stacklevel=1,
            )
            speedups = None


def q_ok_py(q: Any) -> bool:
    """True when ``q`` is obviously valid: a 1-D float64 ndarray of 4 values, sum of squares <= Q_MAX2.

    False only means "run the full check" (``Robot.check_q``); it never lets a bad ``q`` through.
    """
    if type(q) is np.ndarray and q.dtype is _F64 and q.ndim == 1:  # _F64: native byte order
        try:
            a, b, c, d = q.tolist()
        except ValueError:
            return False
        return a * a + b * b + c * c + d * d <= Q_MAX2  # NaN and inf fail this comparison
    return False


def task_rows_py(J: np.ndarray) -> np.ndarray:
    """Rows 0, 1, 2 and 5 (x, y, z, wz) of a (6, n) Jacobian, as a new array."""
    return J.take(_ROWS, 0)


def nearest_none(*args: object) -> None:
    """Stands for the compiled ``nearest`` without the module: "no answer here", i.e. the Python route."""
    return None


q_ok: Callable[[Any], bool] = q_ok_py
task_rows: Callable[[np.ndarray], np.ndarray] = task_rows_py
nearest: Callable[..., np.ndarray | None] = nearest_none
"""``nearest(params, target, reference, weights, branch)``: see scara_pin/_speedups.c and ik.solve_nearest."""
if speedups is not None:
    speedups.set_q_max2(Q_MAX2)
    q_ok, task_rows, nearest = speedups.q_ok, speedups.task_rows, speedups.nearest
