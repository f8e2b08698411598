"""The residuals of a calibration as a picture (matplotlib, imported on first use)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .results import CalibrationResult

__all__ = ["plot_residuals"]


def plot_residuals(result: CalibrationResult, path: str | os.PathLike[str]) -> Path:
    """Each measured pose's position error before and after the calibration (log scale), outliers marked.

    The x axis is each row's line in the measurement file (its row number for arrays), as the report and the
    outlier list name it. Written atomically (:func:`scara_pin.files.save_figure`); the format follows the
    name (.png, .svg, .pdf).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..files import save_figure

    before = np.linalg.norm(result.residuals_before[:, :3], axis=1) * 1e3
    after = np.linalg.norm(result.residuals_after[:, :3], axis=1) * 1e3
    rows = np.array(result.measurements.lines, dtype=float)  # as messages name the rows: line (or row) numbers
    fig, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
    ax.bar(rows - 0.2, before, width=0.4, color="0.6", label=f"nominal (rms {result.before.rms * 1e3:.3g} mm)")
    ax.bar(rows + 0.2, after, width=0.4, color="tab:blue", label=f"calibrated (rms {result.after.rms * 1e3:.3g} mm)")
    if result.outliers:
        out = [o.row for o in result.outliers]
        ax.bar(rows[out] + 0.2, after[out], width=0.4, color="tab:red", label="outliers (left out)")
    if result.cross_validation is not None:
        ax.axhline(result.cross_validation.held_out.rms * 1e3 * np.sqrt(3), color="tab:green", lw=1, ls="--",
                   label=f"held out: rms x sqrt(3) = {result.cross_validation.held_out.rms * 1e3 * np.sqrt(3):.3g} mm")
    positive = np.concatenate([before, after])
    positive = positive[positive > 0]
    if len(positive) and positive.max() / positive.min() > 100:
        ax.set_yscale("log")
    from_file = result.measurements.where(0).startswith("line") if len(before) else False
    ax.set_xlabel("measured pose (line in the measurement file)" if from_file else "measured pose (row)")
    ax.set_ylabel("position error [mm]")
    ax.set_title(f"calibration of {result.chain.robot.name}: {len(result.identified)} errors identified")
    ax.legend(loc="best", fontsize=8)
    try:
        return save_figure(fig, path)
    finally:
        plt.close(fig)
