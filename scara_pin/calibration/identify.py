"""Which errors the measurements can separate: the base parameters of an identification Jacobian.

The identification Jacobian ``W`` (one row per measured coordinate, one column per candidate error, at the
nominal description or at an estimate) tells what each error does to the measurements. Two errors whose columns are
proportional, or a column in the span of others, cannot be told apart by any fit: such a column is fixed
at its nominal value (zero error) and the errors it depends on absorb it (FIGAROH's base parameters, from
a QR decomposition of the regressor).

The columns are taken in an order of preference (the error model's, :mod:`scara_pin.calibration.chain`; at
an estimate, the errors already identified first), each scaled to unit norm (so that metres, radians and scales
compare), by a QR decomposition without pivoting kept column by column (Gram-Schmidt, orthogonalised
twice): a column is kept when the part of it outside the span of the columns kept before is at least
``IDENTIFY_TOL`` of its norm (``|R_ii|`` of the unit column, the sine of its angle to that span); below,
its estimate would amplify the measurement noise a million times. A column of zero norm is an error with
no effect on the measurements.

A fixed error's dependencies are the least-squares coefficients of its unit column on the kept unit
columns: the report names the kept errors with a coefficient above ``DEPENDENCY_TOL``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["DEPENDENCY_TOL", "IDENTIFY_TOL", "Identifiability", "identify"]

IDENTIFY_TOL = 1e-6
"""The smallest sine between a unit column and the span of the columns kept before it, for it to be kept."""
DEPENDENCY_TOL = 1e-6
"""[1] A kept error whose coefficient in a fixed one's unit column is above this is named as absorbing it."""
_ZERO = 1e-12
"""[1] A column this small relative to the largest one has no effect on the measurements."""


@dataclass(frozen=True)
class Identifiability:
    """The errors the measurements separate, and what each of the others depends on.

    Attributes:
        kept: indices of the identified (base) errors, in the model's order (ascending).
        fixed: indices of the others (fixed at zero error).
        depends: per fixed error (same order as ``fixed``), the indices of the kept errors it cannot be
            separated from; empty when it has no effect on the measurements.
        sines: per candidate error, the sine of its unit column's angle to the span of the columns kept
            before it (0 for a column without effect).
        condition: the condition number of the kept unit columns (how well the kept errors are separated).
    """

    kept: tuple[int, ...]
    fixed: tuple[int, ...]
    depends: tuple[tuple[int, ...], ...]
    sines: np.ndarray
    condition: float

    def reasons(self, names: Sequence[str]) -> dict[int, str]:
        """Per fixed error: why it is fixed, in words."""
        out = {}
        for i, dep in zip(self.fixed, self.depends):
            if not dep:
                out[i] = "no effect on the measurements"
            else:
                out[i] = "not separable from " + ", ".join(names[k] for k in dep)
        return out


def identify(W: np.ndarray, tol: float = IDENTIFY_TOL, order: Sequence[int] | None = None) -> Identifiability:
    """The base errors of the identification Jacobian ``W`` (m x p), columns in order of preference.

    Args:
        W: the Jacobian of the measurements with respect to the candidate errors (at the nominal model, or at
            an estimate).
        tol: the smallest sine kept (:data:`IDENTIFY_TOL`).
        order: the order of preference, a permutation of the column indices (default: the columns' order).
            The indices returned are the columns' own, ``kept`` sorted.
    """
    m, p = W.shape
    order = list(range(p)) if order is None else [int(k) for k in order]
    if sorted(order) != list(range(p)):
        raise ValueError(f"order must be a permutation of 0 .. {p - 1}")
    norms = np.linalg.norm(W, axis=0)
    big = float(norms.max()) if p else 0.0
    basis = np.zeros((m, 0))
    kept: list[int] = []
    sines = np.zeros(p)
    for k in order:
        if norms[k] <= _ZERO * big or norms[k] == 0.0:
            continue
        v = W[:, k] / norms[k]
        for _ in range(2):  # Gram-Schmidt twice: orthogonal to working precision
            v = v - basis @ (basis.T @ v)
        s = float(np.linalg.norm(v))
        sines[k] = s
        if s >= tol:
            kept.append(k)
            basis = np.column_stack([basis, v / s])
    kept.sort()
    fixed = [k for k in range(p) if k not in kept]
    depends: list[tuple[int, ...]] = []
    if kept:
        U = W[:, kept] / norms[kept]
        sv = np.linalg.svd(U, compute_uv=False)
        condition = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
        for k in fixed:
            if norms[k] <= _ZERO * big or norms[k] == 0.0:
                depends.append(())
                continue
            beta = np.linalg.lstsq(U, W[:, k] / norms[k], rcond=None)[0]
            depends.append(tuple(kept[i] for i in np.flatnonzero(np.abs(beta) > DEPENDENCY_TOL)))
    else:
        condition = float("inf")
        depends = [() for _ in fixed]
    return Identifiability(tuple(kept), tuple(fixed), tuple(depends), sines, condition)
