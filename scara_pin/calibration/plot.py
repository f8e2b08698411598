"""The residuals of a calibration as a picture (matplotlib, imported on first use)."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from ..units import HUMAN, DisplayUnits
from .results import CalibrationResult

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_residuals"]


def plot_residuals(
    result: CalibrationResult, path: str | os.PathLike[str] | None = None, *, units: DisplayUnits = HUMAN
) -> Figure:
    """Each measured pose's position error before and after the calibration (log scale), outliers marked.

    The x axis is each row's line in the measurement file (its row number for arrays), as the report and the
    outlier list name it.

    Args:
        result: the calibration.
        path: write the figure here (PNG, SVG or PDF by the ending; atomically); None: only return it.
        units: the length unit of the errors (default mm: calibration errors are a fraction of one).

    Returns:
        the matplotlib Figure (on its own Agg canvas: no pyplot, the caller's figures are untouched).
    """
    from ..files import new_figure, save_figure

    k, Ln = units.scale("length"), units.name("length")
    before = np.linalg.norm(result.residuals_before[:, :3], axis=1) * k
    after = np.linalg.norm(result.residuals_after[:, :3], axis=1) * k
    rows = np.array(result.measurements.lines, dtype=float)  # as messages name the rows: line (or row) numbers
    fig = new_figure(9, 4.5)
    ax = fig.add_subplot()
    ax.bar(rows - 0.2, before, width=0.4, color="0.6", label=f"nominal (rms {result.before.rms * k:.3g} {Ln})")
    ax.bar(rows + 0.2, after, width=0.4, color="tab:blue", label=f"calibrated (rms {result.after.rms * k:.3g} {Ln})")
    if result.outliers:
        out = [o.row for o in result.outliers]
        ax.bar(rows[out] + 0.2, after[out], width=0.4, color="tab:red", label="outliers (left out)")
    if result.cross_validation is not None:
        held = result.cross_validation.held_out.rms * k * np.sqrt(3)
        ax.axhline(held, color="tab:green", lw=1, ls="--", label=f"held out: rms x sqrt(3) = {held:.3g} {Ln}")
    positive = np.concatenate([before, after])
    positive = positive[positive > 0]
    if len(positive) and positive.max() / positive.min() > 100:
        ax.set_yscale("log")
    from_file = result.measurements.where(0).startswith("line") if len(before) else False
    ax.set_xlabel("measured pose (line in the measurement file)" if from_file else "measured pose (row)")
    ax.set_ylabel(f"position error [{Ln}]")
    ax.set_title(f"calibration of {result.chain.robot.name}: {len(result.identified)} errors identified")
    ax.legend(loc="best", fontsize=8)
    if path is not None:
        save_figure(fig, path)
    return fig
