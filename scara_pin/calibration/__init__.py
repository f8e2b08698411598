"""Kinematic calibration: identify a robot's description from measured tool positions.

Beside :mod:`scara_pin.kinematics` in the layers (it imports the description, the model and the kinematics;
nothing below imports it). The loop, for any serial chain the toolkit loads (no per-robot code):

- :func:`plan_experiment`: the joint configurations to measure (D- or E-optimal);
- :class:`Measurements`: the joint readings and the measured tool positions (CSV, or arrays); without a
  tracker, :func:`simulate` measures them on a perturbed copy of the robot;
- :func:`calibrate`: the data checked against the nominal model (:mod:`~scara_pin.calibration.screen`), the
  identifiable errors (:mod:`~scara_pin.calibration.identify`, at the nominal model and at the estimate) of
  the error model (:mod:`~scara_pin.calibration.chain`), fitted by nonlinear least squares on Pinocchio's
  forward kinematics (:mod:`~scara_pin.calibration.fit`; robust to outliers by default), with their
  covariance, the residuals before and after, a cross-validation by pose and the calibrated URDF
  (:class:`CalibrationResult`);
- :func:`yaml_overlay`: a configured robot's changed yaml parameters; :func:`plot_residuals`: a picture.
"""

from .chain import ALL_GROUPS, ChainModel, ErrorParameter, Group, MeasurementFrame, ParameterKind
from .design import Criterion, ExperimentPlan, plan_experiment
from .fit import CalibrationOptions, calibrate, structural_count
from .identify import Identifiability, identify
from .measurements import Measurements, measurement_columns
from .overlay import YamlOverlay, yaml_overlay
from .plot import plot_residuals
from .results import (
    CalibrationResult,
    CrossValidation,
    Loss,
    Outlier,
    ParameterEstimate,
    ParameterStatus,
    ResidualStats,
)
from .simulate import Simulation, simulate

__all__ = [
    "ALL_GROUPS",
    "CalibrationOptions",
    "CalibrationResult",
    "ChainModel",
    "Criterion",
    "CrossValidation",
    "ErrorParameter",
    "ExperimentPlan",
    "Group",
    "Identifiability",
    "Loss",
    "MeasurementFrame",
    "Measurements",
    "Outlier",
    "ParameterEstimate",
    "ParameterKind",
    "ParameterStatus",
    "ResidualStats",
    "Simulation",
    "YamlOverlay",
    "calibrate",
    "identify",
    "measurement_columns",
    "plan_experiment",
    "plot_residuals",
    "simulate",
    "structural_count",
    "yaml_overlay",
]
