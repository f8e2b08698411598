"""Targets, references and weights as the closed forms take them: checked once, at the edge (private)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .._checks import MAGNITUDE_MAX, as_floats, as_vector
from ..errors import InvalidInputError, NoSolutionError, ParameterError

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..ik_results import IKResult

__all__ = ["batch_inputs", "check_magnitude", "parse_target", "placement_matrix", "reference_floats", "weight_floats"]

_F64 = np.dtype(np.float64)
_isfinite = math.isfinite
_TARGET_RULE = "must be (x, y, z, yaw) or a 4 x 4 pose"


def parse_target(target: object, yaw0: float, R0: np.ndarray) -> tuple[float, float, float, float, float]:
    """(x, y, z, alpha, tilt) of a target: alpha = yaw - yaw0, tilt the angle of its rotation from a pure yaw.

    Args:
        target: (x, y, z, yaw) [m, rad], a 4 x 4 pose or a pin.SE3, of the tool frame in the base frame.
        yaw0: the tool's yaw at q = 0 [rad].
        R0: the tool's rotation at q = 0 (a pure-yaw target is Rz(alpha) R0).

    Raises:
        ParameterError: not (x, y, z, yaw) or a 4 x 4 pose, a value not finite or beyond +/-MAGNITUDE_MAX.
    """
    kind = type(target)
    m = MAGNITUDE_MAX
    if kind is np.ndarray and target.dtype is _F64 and target.shape == (4,):  # type: ignore[attr-defined]
        x, y, z, yaw = target.tolist()  # type: ignore[attr-defined]
        if -m <= x <= m and -m <= y <= m and -m <= z <= m and -m <= yaw <= m:  # NaN fails every comparison
            return x, y, z, yaw - yaw0, 0.0
    elif kind is tuple or kind is list:
        try:
            a: Any
            b: Any
            c: Any
            d: Any
            a, b, c, d = target  # type: ignore[misc]
            if type(a) is float and type(b) is float and type(c) is float and type(d) is float:
                x, y, z, yaw = a, b, c, d
            else:
                x, y, z, yaw = float(a), float(b), float(c), float(d)
            if -m <= x <= m and -m <= y <= m and -m <= z <= m and -m <= yaw <= m:  # NaN fails every comparison
                return x, y, z, yaw - yaw0, 0.0
        except (TypeError, ValueError, OverflowError):
            pass  # not 4 plain numbers (a 4 x 4 pose as nested lists, say): the general route below says why
    M = placement_matrix(target)
    if M.shape == (4,):
        x, y, z, yaw = (float(v) for v in as_vector("target", M))
        check_magnitude((x, y, z, yaw))
        return x, y, z, yaw - yaw0, 0.0
    if M.shape != (4, 4) or not np.isfinite(M).all():
        raise ParameterError("target", "array of shape " + str(M.shape), _TARGET_RULE)
    check_magnitude(M[:3, 3].tolist())
    R = M[:3, :3]
    if np.abs(R.T @ R - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0:
        raise ParameterError("target rotation", R.round(12).tolist(), "must be a rotation matrix")
    E = R @ R0.T  # a pure yaw of the tool's zero-pose rotation: E = Rz(alpha)
    tilt = math.atan2(math.hypot(E[0, 2], E[1, 2]), E[2, 2])
    return float(M[0, 3]), float(M[1, 3]), float(M[2, 3]), math.atan2(E[1, 0], E[0, 0]), tilt


def placement_matrix(target: object) -> np.ndarray:
    """A target as a float array: a pin.SE3's 4 x 4 matrix, else the values as given (shape not checked here)."""
    return target.homogeneous if isinstance(target, pin.SE3) else as_floats("target", target, _TARGET_RULE)


def check_magnitude(values: ArrayLike) -> None:
    """Raise a ParameterError naming the first of (x, y, z, yaw) that is not finite or beyond +/-MAGNITUDE_MAX."""
    for name, v in zip(("x", "y", "z", "yaw"), values):
        if not _isfinite(v):
            raise ParameterError(f"target {name}", v, "must be finite")
        if abs(v) > MAGNITUDE_MAX:
            raise ParameterError(f"target {name}", v, f"must be within +/-{MAGNITUDE_MAX:g} (m or rad)")


def reference_floats(reference: object, n: int = 4) -> list[float]:
    """A reference configuration as n finite floats within +/-MAGNITUDE_MAX (default: zeros)."""
    if reference is None:
        return [0.0] * n
    if type(reference) is np.ndarray and reference.dtype is _F64 and reference.shape == (n,):  # type: ignore[attr-defined]
        out = reference.tolist()  # type: ignore[attr-defined]
        if n == 4:
            a, b, c, d = out
            m = MAGNITUDE_MAX
            if -m <= a <= m and -m <= b <= m and -m <= c <= m and -m <= d <= m:  # NaN fails
                return out  # type: ignore[no-any-return]
    arr = as_vector("reference", reference, n)
    if (np.abs(arr) > MAGNITUDE_MAX).any():
        raise ParameterError("reference", arr.tolist(), f"must be within +/-{MAGNITUDE_MAX:g} (rad or m)")
    return arr.tolist()  # type: ignore[no-any-return]


def weight_floats(weights: object, n: int = 4) -> list[float]:
    """Weights of a joint-space distance as n finite floats >= 0."""
    w = as_vector("weights", weights, n)
    if (w < 0).any():
        raise ParameterError("weights", w.tolist(), "must be >= 0")
    return w.tolist()  # type: ignore[no-any-return]


def batch_inputs(targets: object, reference: object, branch: str, branches: tuple[str, ...]
                 ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """The checked (N, 4) targets and the (4,) or (N, 4) reference of a vectorised closed form.

    Args:
        targets: (N, 4) x, y, z, yaw [m, rad], finite, within +/-MAGNITUDE_MAX.
        reference: (4,) or (N, 4) finite joint values, or None (zeros).
        branch: ``"nearest"`` or one of ``branches``.
        branches: the kind's branch names.

    Raises:
        ParameterError: a shape, or a value that is not finite or out of range.
        InvalidInputError: an unknown branch.
    """
    T = as_floats("targets", targets, "must be an (N, 4) array of x, y, z, yaw")
    if T.ndim != 2 or T.shape[1] != 4:
        raise ParameterError("targets", f"array of shape {T.shape}", "must have shape (N, 4): x, y, z, yaw")
    if branch not in ("nearest", *branches):
        names = ", ".join(repr(b) for b in ("nearest", *branches))
        raise InvalidInputError(f"branch {branch!r} must be {names.rsplit(', ', 1)[0]} or {names.rsplit(', ', 1)[1]}")
    if T.size and not (T.max() <= MAGNITUDE_MAX and T.min() >= -MAGNITUDE_MAX):  # NaN fails the comparisons
        check_magnitude(T[int(np.argmax(~(np.abs(T) <= MAGNITUDE_MAX).all(axis=1)))].tolist())
    ref = np.zeros(4) if reference is None else as_floats("reference", reference, "must be 4 values or (N, 4)")
    if ref.shape not in ((4,), (T.shape[0], 4)) or not np.isfinite(ref).all():
        raise ParameterError("reference", f"array of shape {ref.shape}", "must be 4 finite values or (N, 4)")
    return T, ref


def nearest_q(res: IKResult, reference: ArrayLike | None, weights: ArrayLike | None, branch: str,
                n: int) -> np.ndarray:  # fmt: skip
    """The solution of ``res`` nearest ``reference`` (weighted, ``n`` joints), as a new array.

    Raises:
        NoSolutionError: ``res`` has no solution (on ``branch``).
    """
    ref = reference_floats(reference, n)
    w = None if weights is None else weight_floats(weights, n)
    best = res.nearest(ref, w, branch) if res.success else None
    if best is None:
        raise NoSolutionError(res.status, res.message if not res.success else f"no {branch} solution")
    return best.q.copy()
