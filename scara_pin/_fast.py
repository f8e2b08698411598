"""The per-call hot paths: the compiled :mod:`scara_pin._speedups` when it was built, else pure Python.

Both routes give the same answers (``tests/test_speedups.py`` runs them against each other); the compiled
one is what the per-call speed figures in README are measured with. ``SCARA_PIN_NO_SPEEDUPS=1`` in the
environment, read at import, forces the Python route (to compare, or to rule the C module out).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

_Q_MAX = 1e6
"""[rad or m] the largest joint value taken as a configuration (beyond it an angle has no precision)."""
Q_MAX2 = (0.5 * _Q_MAX) ** 2
"""The largest sum of squares of q that :func:`q_ok` waves through (NaN and inf never pass)."""

_F64 = np.dtype(np.float64)
_ROWS = np.array([0, 1, 2, 5])  # x, y, z, wz of a 6-row Jacobian

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
speedups = None
