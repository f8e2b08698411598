"""A joint trajectory piece that is a polynomial in time between breakpoints (the jump planner's output).

Between breakpoints ``t_k`` and ``t_{k+1}`` every joint is a polynomial in the local time ``tau = t - t_k``,

    q(t) = c_k0 + c_k1 tau + c_k2 tau^2 + c_k3 tau^3,

exactly what a planner with piecewise-constant acceleration (degree 2) or jerk (degree 3) integrates: no
interpolation of samples. Velocity, acceleration and jerk are the exact derivatives; the piece is
continuous in q and qd (and in qdd at degree 3) to rounding, which :class:`PolynomialPiece` checks.
It fits :class:`~scara_pin.motion.trajectory.Trajectory` like a motion (sampling, export, setpoints,
``view --traj``); it reverses exactly in time (:meth:`PolynomialPiece.reversed`) and rescales exactly
(:meth:`PolynomialPiece.scaled`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .trajectory import Piece

__all__ = ["PolynomialPiece"]

_CONTINUITY_TOL = 1e-9
"""[rad or m, per s] the largest jump of q or qd accepted at a breakpoint."""


@dataclass(frozen=True, eq=False)
class PolynomialPiece(Piece):
    """Joint polynomials between breakpoints (module docstring).

    Attributes:
        breaks: (n + 1,) increasing times from 0 [s].
        coefficients: (n, degree + 1, dof): ``coefficients[k, i]`` multiplies ``tau^i`` on interval k.
        duration: ``breaks[-1]`` [s] (derived).
    """

    breaks: np.ndarray
    coefficients: np.ndarray
    duration: float = field(init=False)

    def __post_init__(self) -> None:
        t = np.array(self.breaks, dtype=float)
        c = np.array(self.coefficients, dtype=float)
        if t.ndim != 1 or len(t) < 2 or c.ndim != 3 or c.shape[0] != len(t) - 1 or c.shape[1] < 1:
            raise ParameterError("polynomial piece", f"breaks {t.shape}, coefficients {c.shape}",
                                 "must be (n + 1,) and (n, degree + 1, dof)")  # fmt: skip
        if not (np.isfinite(t).all() and np.isfinite(c).all()) or t[0] != 0.0 or not (np.diff(t) > 0).all():
            raise ParameterError("polynomial piece", f"breaks [{t[0]}, ..., {t[-1]}]",
                                 "must be finite, start at 0 and increase strictly")  # fmt: skip
        object.__setattr__(self, "breaks", t)
        object.__setattr__(self, "coefficients", c)
        object.__setattr__(self, "duration", float(t[-1]))
        h = np.diff(t)
        for order in range(min(2, c.shape[1])):  # q and qd continuous at the inner breakpoints
            end = self.local(np.arange(len(h) - 1), h[:-1], order)
            start = self.local(np.arange(1, len(h)), np.zeros(len(h) - 1), order)
            jump = float(np.max(np.abs(end - start), initial=0.0))
            if jump > _CONTINUITY_TOL * max(1.0, float(np.max(np.abs(start), initial=0.0))):
                raise ParameterError("polynomial piece", f"a jump of {jump:.3g} in derivative {order}",
                                     "must be continuous at its breakpoints")  # fmt: skip

    @property
    def degree(self) -> int:
        """The polynomial degree (2: piecewise-constant acceleration, 3: piecewise-constant jerk)."""
        return int(self.coefficients.shape[1] - 1)

    def local(self, k: np.ndarray, tau: np.ndarray, order: int) -> np.ndarray:
        """The order-th derivative on intervals k at local times tau (Horner), (len(k), dof)."""
        c = self.coefficients[k]
        deg = c.shape[1] - 1
        out = np.zeros((len(k), c.shape[2]))
        for i in range(deg, order - 1, -1):
            out = out * tau[:, None] + c[:, i] * (math.factorial(i) / math.factorial(i - order))
        return out

    def _split(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tau = np.clip(np.asarray(tau, dtype=float).ravel(), 0.0, self.duration)
        k = np.clip(np.searchsorted(self.breaks, tau, side="right") - 1, 0, len(self.breaks) - 2)
        return k, tau - self.breaks[k]

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at local times ``tau`` (the interval on the right at a breakpoint)."""
        k, dt = self._split(tau)
        return self.local(k, dt, 0), self.local(k, dt, 1), self.local(k, dt, 2)

    def jerk(self, tau: np.ndarray) -> np.ndarray:
        """Joint jerk (n, dof) at local times ``tau`` (constant on each interval; zero at degree 2)."""
        k, dt = self._split(tau)
        return self.local(k, dt, 3)

    def breakpoints(self) -> np.ndarray:
        """The breakpoint times [s] (where the acceleration, or the jerk, switches)."""
        return self.breaks.copy()

    def reversed(self) -> PolynomialPiece:
        """The same motion played backwards, q_r(t) = q(T - t), exactly.

        The intervals in reverse order, each re-expanded about its other end: c_i' = (-1)^i q^(i)(h) / i!.
        """
        h = np.diff(self.breaks)
        k = np.arange(len(h))
        deg = self.degree
        c = np.stack([self.local(k, h, i) * ((-1.0) ** i / math.factorial(i)) for i in range(deg + 1)], axis=1)
        breaks = np.concatenate([[0.0], np.cumsum(h[::-1])])
        return PolynomialPiece(breaks, c[::-1].copy())

    def scaled(self, k: float) -> PolynomialPiece:
        """The same motion ``k`` times slower, q_k(t) = q(t / k): breaks times k, c_i / k^i."""
        k = float(k)
        if not (math.isfinite(k) and k > 0.0):
            raise ParameterError("k", k, "must be finite and > 0")
        powers = k ** -np.arange(self.degree + 1)
        return PolynomialPiece(self.breaks * k, self.coefficients * powers[None, :, None])
