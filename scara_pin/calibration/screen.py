"""The measurements checked against the nominal model before any fit: units, readings, limits, distinct poses.

A calibration corrects the small errors of a description (tenths of a millimetre to a few millimetres,
fractions of a degree). Data the nominal model misses by a large part of the robot's size are not this robot's
measurements as the file's columns define them (SI units; the base frame, or ``--frame device``), and a fit
would turn them into a wrong URDF with good-looking statistics. :func:`screen` compares every row with the
nominal model's prediction (in the device frame, after the rigid alignment of the two point sets) and refuses
(:class:`~scara_pin.errors.InvalidInputError`, exit code 2) what cannot be a calibration, saying what the data
look like instead:

- joint readings in degrees (a prismatic joint's in millimetres): read so, they fit the nominal model
  ``DEGREES_GAIN`` times better than as radians (metres);
- positions in other units: the nominal error is above ``REFUSE_FRACTION`` of the chain's length (the median
  over the rows, so that a few gross rows do not decide) and the measured positions' size is not the
  model's (their RMS distance from the base, or from their centroid in the device frame): 1000 times is
  millimetres; any other gross error is refused as not this robot, frame or columns;
- readings outside the joint limits (by more than ``LIMIT_TOL``): refused naming the rows, as a controller
  never reports them; where the URDF's limits are narrower than the controller's, the caller accepts them
  (``accept_outside_limits``) and gets a warning;
- fewer DISTINCT poses than identifiable errors: rows that repeat a pose (the same readings) average its
  noise but identify nothing more, and would make the statistics lie (a residual of 1e-17 m on one pose).

Warned (the fit goes on; the warning says what to check): a nominal error above ``WARN_FRACTION`` of the
chain's length (a missing tool offset, an encoder zero far off, a frame mix-up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError
from .chain import ChainModel, MeasurementFrame, kabsch
from .measurements import Measurements

__all__ = [
    "DEGREES_GAIN",
    "LIMIT_TOL",
    "REFUSE_FRACTION",
    "WARN_FRACTION",
    "Screening",
    "nominal_view",
    "screen",
]

REFUSE_FRACTION = 0.25
"""A median nominal error above this fraction of the chain's length is refused (not a calibration's error)."""
WARN_FRACTION = 0.02
"""A median nominal error above this fraction of the chain's length is warned about (1 cm on a 0.5 m arm)."""
DEGREES_GAIN = 10.0
"""Readings are said to be degrees (mm) when read so they fit the nominal model this many times better."""
LIMIT_TOL = 1e-6
"""[rad or m] a reading beyond a joint limit by more than this is outside it."""
_SHOWN = 3
"""Rows named in a message."""


@dataclass(frozen=True, eq=False)
class Screening:
    """What the nominal model says of the data.

    Attributes:
        pose: per row, the index of its distinct pose (:meth:`Measurements.poses`).
        distinct: the number of distinct poses.
        device0: ``deviceMbase`` of the rigid alignment of the nominal predictions with the measurements
            (identity in the base frame).
        nominal_error: [m] the nominal model's position error, median over the rows.
        warnings: what the user must know before trusting the result.
    """

    pose: np.ndarray
    distinct: int
    device0: pin.SE3
    nominal_error: float
    warnings: tuple[str, ...]


def nominal_view(chain: ChainModel, readings: np.ndarray, position: np.ndarray) -> tuple[np.ndarray, pin.SE3]:
    """The nominal model's positions at ``readings`` in the measurement frame, and ``deviceMbase`` used.

    In the base frame, the positions in the base frame (and the identity); in the device frame, aligned on the
    measured ``position`` by :func:`~scara_pin.calibration.chain.kabsch`.
    """
    p, _ = chain.predict(np.zeros(chain.size), chain.pinocchio_q(readings), pin.SE3.Identity(), jacobian=False)
    p = p[:, :3]
    if chain.frame is MeasurementFrame.BASE:
        return p, pin.SE3.Identity()
    dMb = kabsch(p, position)
    return p @ dMb.rotation.T + dMb.translation, dMb


def _median_error(chain: ChainModel, readings: np.ndarray, position: np.ndarray) -> float:
    predicted, _ = nominal_view(chain, readings, position)
    return float(np.median(np.linalg.norm(predicted - position, axis=1)))


def _size(points: np.ndarray, centred: bool) -> float:
    """The RMS distance of points from their centroid (``centred``) or from the origin."""
    d = points - points.mean(axis=0) if centred else points
    return float(np.sqrt(np.mean(np.sum(d**2, axis=1))))


def _human_readings(chain: ChainModel) -> list[tuple[str, np.ndarray]]:
    """The ways readings are commonly given in human units: per way, its name and the factors to SI per joint."""
    kinds = chain.robot.joint_kinds
    to_si = {"angle": math.pi / 180.0, "length": 1e-3}
    ways = []
    for name, which in (("degrees", {"angle"}), ("millimetres", {"length"}), ("degrees and millimetres",
                                                                               {"angle", "length"})):  # fmt: skip
        if which <= set(kinds):
            ways.append((name, np.array([to_si[k] if k in which else 1.0 for k in kinds])))
    return ways


def screen(chain: ChainModel, measurements: Measurements, count: int, *,
           accept_outside_limits: bool = False) -> Screening:  # fmt: skip
    """Check the measurements against the nominal model (see the module docstring).

    Args:
        chain: the error model (its nominal robot, the measurement frame).
        measurements: the measured poses (their readings already checked: one per joint, finite).
        count: the number of errors a rich set of poses identifies (the structural count).
        accept_outside_limits: use readings outside the joint limits (with a warning) instead of refusing them.

    Raises:
        InvalidInputError: readings in degrees, positions in other units or not this robot's, readings outside
            the limits (unless accepted), fewer distinct poses than ``count``: one line naming the cause and
            what to do.
    """
    m, robot, src = measurements, chain.robot, measurements.source
    length = chain.length
    warnings: list[str] = []
    q, p = m.q, m.position
    error = _median_error(chain, q, p)
    for name, factor in _human_readings(chain):
        human = _median_error(chain, q * factor, p)
        if human * DEGREES_GAIN < error and human <= WARN_FRACTION * length:
            raise InvalidInputError(
                f"{src}: the joint readings look like {name}: read as radians and metres the nominal model misses "
                f"the measured positions by {error:.3g} m (median), read as {name} by {human:.3g} m; the q columns "
                "must be in SI units (rad, m)"
            )
    outside = [(k, bad) for k in range(len(m)) if (bad := robot.outside_limits(q[k], tol=LIMIT_TOL))]
    if error > REFUSE_FRACTION * length:
        centred = chain.frame is MeasurementFrame.DEVICE
        predicted, _ = nominal_view(chain, q, p)
        ratio = _size(p, centred) / max(_size(predicted, centred), 1e-300)
        where = f"in the {chain.frame.value} frame"
        if 900.0 <= ratio <= 1100.0:
            why = f"the measured positions are {ratio:.4g} times the model's: millimetres? x, y, z must be in metres"
        elif not 0.5 <= ratio <= 2.0:
            why = (f"the measured positions are {ratio:.3g} times the model's: x, y, z must be in metres, {where} "
                   "(--frame device: the measuring device's own)")  # fmt: skip
        elif outside:
            why = (f"{len(outside)} of {len(m)} rows have readings outside the joint limits ({_rows(m, outside)}): "
                   "a zero offset, or units other than the model's?")  # fmt: skip
        else:
            why = (f"not this robot's measurements {where}? check the robot (--robot, --set: the tool offset of the "
                   "measured target), --frame and the columns (q in URDF joint order)")  # fmt: skip
        raise InvalidInputError(
            f"{src}: the nominal model misses the measured positions by {error:.3g} m (median over the rows), "
            f"{error / length:.3g} times the chain's length {length:.3g} m, where a calibration corrects errors of "
            f"millimetres: {why}"
        )
    if outside:
        text = f"{len(outside)} of {len(m)} rows have readings outside the joint limits ({_rows(m, outside)})"
        if not accept_outside_limits:
            raise InvalidInputError(
                f"{src}: {text}: a controller does not report such readings (a zero offset, other units?); fix "
                "the readings, or the URDF's limits, or, where the controller's limits are wider than the URDF's, "
                "accept them (--allow-outside-limits)"
            )
        warnings.append(f"{text}: used as measured (the URDF's limits are narrower than the controller's?)")
    if error > WARN_FRACTION * length:
        warnings.append(
            f"the nominal model misses the measured positions by {error * 1e3:.3g} mm (median over the rows), "
            f"{100 * error / length:.2g} % of the chain's length: large for a calibration (errors of tenths of a "
            "millimetre to a few millimetres); check the measured target's offset (the tool frame, e.g. --set "
            f"tool_x=...), the frame (--frame) and the joints' zeros"
        )
    pose, distinct = m.poses()
    if distinct < count:
        plural = "s" if distinct != 1 else ""
        poses = (f"{distinct} measured poses" if distinct == len(m) else f"{len(m)} rows hold {distinct} distinct "
                 f"pose{plural} (rows with the same readings measure one pose again)")  # fmt: skip
        raise InvalidInputError(
            f"{src}: {poses} for {count} identifiable parameters: at least {count} distinct poses are needed, a few "
            f"times more to average the noise (scara-pin calibrate --plan {3 * count} proposes poses)"
        )  # fmt: skip
    _, device0 = nominal_view(chain, q, p)
    return Screening(pose, distinct, device0, error, tuple(warnings))


def _rows(m: Measurements, outside: list[tuple[int, list[str]]]) -> str:
    shown = "; ".join(f"{m.where(k)}: {bad[0]}" for k, bad in outside[:_SHOWN])
    return shown + ("; ..." if len(outside) > _SHOWN else "")
