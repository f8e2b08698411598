"""The results of a calibration: frozen objects, with the report in words and as a JSON-ready dict."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from ..summary import Summarized
from .chain import Group, MeasurementFrame

if TYPE_CHECKING:
    from ..units import DisplayUnits
    from .chain import ChainModel
    from .measurements import Measurements

__all__ = [
    "CalibrationResult",
    "CrossValidation",
    "Loss",
    "Outlier",
    "ParameterEstimate",
    "ParameterStatus",
    "ResidualStats",
]


class Loss(enum.Enum):
    """The loss of the least-squares fit (scipy's ``least_squares`` names): linear, or robust to outliers."""

    LINEAR = "linear"
    SOFT_L1 = "soft_l1"
    HUBER = "huber"
    CAUCHY = "cauchy"
    ARCTAN = "arctan"


class ParameterStatus(enum.Enum):
    """Whether an error was identified or fixed at its nominal value (zero)."""

    IDENTIFIED = "identified"
    FIXED = "fixed"


@dataclass(frozen=True)
class ParameterEstimate:
    """One candidate error after the fit.

    Attributes:
        name: e.g. ``"joint2.x"``; group: its family; unit: ``"m"``, ``"rad"`` or ``"1"``.
        value: the identified error (0 when fixed) [unit].
        std: its standard deviation [unit] (0 when fixed; NaN when the fit has no redundancy to estimate it).
        status: identified or fixed.
        reason: why it is fixed (``"not separable from joint1.z"``, ``"no effect on the measurements"``), or "".
    """

    name: str
    group: Group
    unit: str
    value: float
    std: float
    status: ParameterStatus
    reason: str = ""


@dataclass(frozen=True)
class ResidualStats:
    """The residuals (model minus measurement) of a set of rows.

    Attributes:
        rows: how many rows.
        rms: the RMS over the x, y and z coordinates [m].
        max: the largest position error (distance) [m].
        yaw_rms, yaw_max: the same for the yaw [rad] (NaN when not measured).
    """

    rows: int
    rms: float
    max: float
    yaw_rms: float = math.nan
    yaw_max: float = math.nan

    @classmethod
    def of(cls, residuals: np.ndarray) -> ResidualStats:
        """Statistics of (n, 3) or (n, 4) residuals (x, y, z[, yaw])."""
        if len(residuals) == 0:
            return cls(0, math.nan, math.nan)
        p = residuals[:, :3]
        yaw = residuals[:, 3] if residuals.shape[1] > 3 else None
        return cls(len(residuals), float(np.sqrt(np.mean(p**2))), float(np.linalg.norm(p, axis=1).max()),
                   math.nan if yaw is None else float(np.sqrt(np.mean(yaw**2))),
                   math.nan if yaw is None else float(np.abs(yaw).max()))  # fmt: skip

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (SI units; NaN as null)."""
        return {k: _json(v) for k, v in (("rows", self.rows), ("rms", self.rms), ("max", self.max),
                                         ("yaw_rms", self.yaw_rms), ("yaw_max", self.yaw_max))}  # fmt: skip


@dataclass(frozen=True)
class Outlier:
    """A measured pose the robust fit found grossly off, left out of the final fit.

    Attributes:
        row: its index in the measurements (0-based). where: its line in the file (or row number), in words.
        distance: its position error under the final model [m].
        standardised: its standardised residual under the final model (a prediction's: see
            :attr:`CalibrationResult.standardised`).
    """

    row: int
    where: str
    distance: float
    standardised: float = math.nan


@dataclass(frozen=True)
class CrossValidation:
    """Held-out prediction: each of ``folds`` groups of rows predicted by a fit on the other rows.

    The groups are made of distinct poses: a pose measured again is in one group with all its rows (a fit that
    saw the pose would predict it too well).

    Attributes:
        folds: the number of groups. held_out: the statistics of the held-out predictions' residuals.
        residuals: (n, 3) or (n, 4) per row used by the final fit (in order), its residual (model minus
            measurement) as predicted by the fit without its pose [m, rad].
    """

    folds: int
    held_out: ResidualStats
    residuals: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)), repr=False)


@dataclass(frozen=True, eq=False, repr=False)
class CalibrationResult(Summarized):
    """A calibrated robot: the identified errors, their covariance, the residuals and the report.

    Attributes:
        chain: the error model (the nominal robot, the measurement frame, the candidate errors).
        measurements: the measured poses.
        theta: the value of every candidate error (0 for the fixed ones), in ``chain.parameters`` order.
        parameters: every candidate error with its value, standard deviation and status.
        identified: the names of the identified errors, in the order of ``covariance``.
        covariance: their covariance matrix [units of each], ``sigma^2 (J^T J)^-1``.
        sigma: the estimated measurement noise, per coordinate [m] (NaN without redundancy).
        device0: ``deviceMbase`` where the fit started (the rigid alignment of the nominal predictions).
        used: per row, whether the final fit used it (False: an outlier).
        residuals_before, residuals_after: (n, 3) or (n, 4) residuals, model minus measurement, of the nominal
            and the calibrated model, every row [m, rad].
        before, after: their statistics over the rows used.
        outliers: the rows left out (robust loss only).
        cross_validation: the held-out prediction, or None (too few rows, or not asked).
        structural_count: how many errors a rich set of poses identifies for this model.
        condition: the condition number of the identified errors' unit columns.
        loss: the loss of the fit. nfev: the model evaluations of the final fit.
        notes: what the user should know (unexcited errors, no cross-validation, ...).
        urdf: the calibrated URDF (the input's text, with the changed ``<origin>`` elements only).
        warnings: what may make the result wrong (readings outside the limits used, a large nominal error,
            outliers kept by the linear loss, errors too large for a calibration).
        distinct: the number of distinct poses (rows with the same readings are one pose).
        second_order: the identified errors without first-order effect at the nominal model, identified at the
            estimate (where the other errors make them act).
        standardised: per row, its standardised residual ``sqrt(r^T (I - H)^-1 r) / sigma`` (``r``: its
            weighted residual, ``H``: its block of the hat matrix; ``I + H`` for a row left out): about
            ``sqrt(coordinates)`` for a row as noisy as the others, far more for a gross error (NaN when
            ``sigma`` is not known).
    """

    chain: ChainModel
    measurements: Measurements
    theta: np.ndarray
    parameters: tuple[ParameterEstimate, ...]
    identified: tuple[str, ...]
    covariance: np.ndarray
    sigma: float
    device0: pin.SE3
    used: np.ndarray
    residuals_before: np.ndarray
    residuals_after: np.ndarray
    before: ResidualStats
    after: ResidualStats
    outliers: tuple[Outlier, ...]
    cross_validation: CrossValidation | None
    structural_count: int
    condition: float
    loss: Loss
    nfev: int
    notes: tuple[str, ...]
    urdf: str = field(repr=False)
    warnings: tuple[str, ...] = ()
    distinct: int = 0
    second_order: tuple[str, ...] = ()
    standardised: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)

    # ------------------------------------------------------------------------------ queries
    def parameter(self, name: str) -> ParameterEstimate:
        """The estimate of the error named ``name`` (KeyError if there is none)."""
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    @property
    def fixed(self) -> tuple[ParameterEstimate, ...]:
        """The errors fixed at their nominal value, with the reason."""
        return tuple(p for p in self.parameters if p.status is ParameterStatus.FIXED)

    @property
    def scales(self) -> dict[str, float]:
        """Per prismatic joint: the factor from its reading to its true stroke (1: no scale error)."""
        return self.chain.scales(self.theta)

    @property
    def largest_standardised(self) -> Outlier | None:
        """The used row with the largest standardised residual (as an :class:`Outlier` record), or None."""
        values = np.where(self.used, self.standardised, -np.inf) if len(self.standardised) else np.zeros(0)
        if not len(values) or not np.isfinite(values).any():
            return None
        i = int(np.nanargmax(np.where(np.isfinite(values), values, -np.inf)))
        return Outlier(i, self.measurements.where(i), float(np.linalg.norm(self.residuals_after[i, :3])),
                       float(self.standardised[i]))  # fmt: skip

    @property
    def device(self) -> pin.SE3 | None:
        """``deviceMbase``: the base's placement in the measuring device's frame (None in the base frame)."""
        if self.chain.frame is MeasurementFrame.BASE:
            return None
        return self.chain.device_placement(self.theta, self.device0)

    def model_q(self, readings: np.ndarray) -> np.ndarray:
        """Joint readings (n, dof) or (dof,) as the calibrated URDF's q: each prismatic reading times its scale."""
        q = np.array(readings, dtype=float)
        scale = np.ones(q.shape[-1])
        names = self.chain.robot.joint_names
        for joint, s in self.scales.items():
            scale[names.index(joint)] = s
        return q * scale

    def predict(self, readings: np.ndarray) -> np.ndarray:
        """The calibrated model's measurement at joint readings (n, dof): (n, 3) positions [m] (+ yaw [rad])."""
        q = np.array(readings, dtype=float, ndmin=2)
        out, _ = self.chain.predict(self.theta, self.chain.pinocchio_q(q), self.device0, jacobian=False)
        return out

    # ------------------------------------------------------------------------------ report
    def to_dict(self) -> dict[str, Any]:
        """Everything but the URDF, JSON-ready (SI units: m, rad; NaN as null)."""
        dev = self.device
        return {
            "robot": self.chain.robot.name,
            "units": {"length": "m", "angle": "rad"},
            "frame": self.chain.frame.value,
            "model": sorted(g.value for g in self.chain.groups),
            "yaw": self.chain.yaw,
            "loss": self.loss.value,
            "rows": len(self.measurements),
            "distinct_poses": self.distinct,
            "rows_used": int(self.used.sum()),
            "structural_count": self.structural_count,
            "identified_count": len(self.identified),
            "second_order": list(self.second_order),
            "condition": _json(self.condition),
            "sigma": _json(self.sigma),
            "before": self.before.to_dict(),
            "after": self.after.to_dict(),
            "cross_validation": None if self.cross_validation is None else
            {"folds": self.cross_validation.folds, "held_out": self.cross_validation.held_out.to_dict()},
            "parameters": [{"name": p.name, "group": p.group.value, "unit": p.unit, "value": _json(p.value),
                            "std": _json(p.std), "status": p.status.value, "reason": p.reason}
                           for p in self.parameters],
            "scales": self.scales,
            "device": None if dev is None else {"xyz": dev.translation.tolist(),
                                                "rpy": _rpy(dev.rotation).tolist()},
            "outliers": [{"row": o.row, "where": o.where, "distance": o.distance,
                          "standardised": _json(o.standardised)} for o in self.outliers],
            "largest_standardised": None if (big := self.largest_standardised) is None else
            {"row": big.row, "where": big.where, "value": big.standardised, "distance": big.distance},
            "warnings": list(self.warnings),
            "notes": list(self.notes),
            "identified": list(self.identified),
            "covariance": self.covariance.tolist(),
        }  # fmt: skip

    def summary(self, units: DisplayUnits | None = None) -> str:
        """:meth:`report` in ``units`` (default SI): what ``scara-pin calibrate`` prints."""
        return self.report("m", "rad") if units is None else self.report(units.length, units.angle)

    def report(self, length_unit: str = "m", angle_unit: str = "rad", *, warnings: bool = True) -> str:
        """The report in words: residuals, identified errors with their deviations, fixed ones and why.

        Args:
            length_unit: ``"m"`` or ``"mm"``.
            angle_unit: ``"rad"`` or ``"deg"``.
            warnings: begin with the warnings (the command line prints them on stderr instead).
        """
        L = 1000.0 if length_unit == "mm" else 1.0
        A = 180.0 / math.pi if angle_unit == "deg" else 1.0

        def scaled(p: ParameterEstimate, v: float) -> str:
            if p.unit == "m":
                return f"{v * L:+.6g} {length_unit}"
            if p.unit == "rad":
                return f"{v * A:+.6g} {angle_unit}"
            return f"{v:+.6g}"

        def stats(s: ResidualStats) -> str:
            text = f"rms {s.rms * L:.4g} {length_unit}, max {s.max * L:.4g} {length_unit}"
            if not math.isnan(s.yaw_rms):
                text += f"; yaw rms {s.yaw_rms * A:.4g} {angle_unit}, max {s.yaw_max * A:.4g} {angle_unit}"
            return text

        c = self.chain
        n = len(self.measurements)
        second = (f"; {len(self.second_order)} more act at the calibrated model: {', '.join(self.second_order)}"
                  if self.second_order else "")  # fmt: skip
        lines = [f"warning: {w}" for w in self.warnings] if warnings else []
        lines += [
            f"calibration of {c.robot.name!r}: {n} rows ({self.distinct} distinct poses, {int(self.used.sum())} rows "
            f"used), measured in the {c.frame.value} frame{' with the yaw' if c.yaw else ''}; model "
            f"{', '.join(sorted(g.value for g in c.groups))}; loss {self.loss.value}",
            f"identified {len(self.identified)} of {c.size} candidate errors (a rich set of poses identifies "
            f"{self.structural_count} at the nominal model{second}); condition number {self.condition:.4g}",
            f"residual before: {stats(self.before)}",
            f"residual after:  {stats(self.after)}",
        ]
        big = self.largest_standardised
        if big is not None:
            lines.append(f"largest standardised residual: {big.standardised:.3g} at {big.where} "
                         f"({big.distance * L:.4g} {length_unit} off; about {math.sqrt(c.rows_per_pose):.2g} for a "
                         "row as noisy as the others)")  # fmt: skip
        if self.cross_validation is not None:
            cv = self.cross_validation
            lines.append(f"held out ({cv.folds}-fold cross-validation): {stats(cv.held_out)}")
        if not math.isnan(self.sigma):
            lines.append(f"estimated measurement noise: {self.sigma * L:.4g} {length_unit} per coordinate")
        lines.append("identified errors (value +/- standard deviation):")
        for p in self.parameters:
            if p.status is ParameterStatus.IDENTIFIED:
                std = "n/a" if math.isnan(p.std) else scaled(p, p.std).lstrip("+")
                lines.append(f"  {p.name:<22} {scaled(p, p.value):>18}  +/- {std}")
        if self.fixed:
            lines.append("fixed at the nominal value (cannot be separated by these measurements):")
            for p in self.fixed:
                lines.append(f"  {p.name:<22} {p.reason}")
        for joint, s in self.scales.items():
            if abs(s - 1.0) > 1e-12:  # (below: rounding)
                lines.append(f"{joint}: scale {s:.9g}: URDF has no joint scale; the calibrated URDF's {joint} is "
                             f"{s:.9g} x the reading (scale the readings in the controller)")  # fmt: skip
        dev = self.device
        if dev is not None:
            xyz = " ".join(f"{v * L:.6g}" for v in dev.translation)
            rpy = " ".join(f"{v * A:.6g}" for v in _rpy(dev.rotation))
            lines.append(f"base in the device frame: xyz {xyz} {length_unit}, rpy {rpy} {angle_unit}")
        for o in self.outliers:
            lines.append(f"outlier: {o.where}: {o.distance * L:.4g} {length_unit} off, standardised residual "
                         f"{o.standardised:.3g} (left out of the fit)")  # fmt: skip
        lines.extend(f"note: {n}" for n in self.notes)
        return "\n".join(lines)


def _rpy(R: np.ndarray) -> np.ndarray:
    return np.asarray(pin.rpy.matrixToRpy(R), dtype=float)


def _json(v: float) -> float | None:
    return None if isinstance(v, float) and not math.isfinite(v) else v
