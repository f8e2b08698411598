"""A sweep's rows as a picture: parts per hour over the placement grid (a heat map), or a Pareto front.

- A varied vector key (``base.xyz``, ``frames.tray.xyz``) whose values differ in exactly two components: a heat map
  of the best parts per hour at each of its grid points (the best over the other keys), the infeasible points
  crossed out, the best variant ringed.
- Otherwise a scatter of the planned variants: parts per hour against the closest distance to the cell (in a cell)
  or against the first numeric varied key, the Pareto front (no variant both faster and farther / lower) drawn.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..units import SI, DisplayUnits
from .plots import finish, new_figure

if TYPE_CHECKING:
    import pandas as pd
    from matplotlib.figure import Figure

__all__ = ["pareto_front", "placement_axes", "plot_sweep"]

_AXES = "xyz"


def placement_axes(rows: pd.DataFrame, columns: Sequence[str]) -> tuple[str, int, int] | None:
    """(column, i, j): the first varied vector column whose values differ in exactly components i and j, or None."""
    for c in columns:
        values = [v for v in rows[c] if isinstance(v, (list, tuple, np.ndarray))]
        if not values or len(values) != len(rows):
            continue
        table = np.array([np.asarray(v, dtype=float) for v in values])
        if table.ndim != 2:
            continue
        varying = [k for k in range(table.shape[1]) if np.ptp(table[:, k]) > 0]
        if len(varying) == 2:
            return c, varying[0], varying[1]
    return None


def pareto_front(x: np.ndarray, y: np.ndarray, x_larger: bool = True) -> np.ndarray:
    """Indices of the points no other beats on both: a larger y (parts/h) and a larger (or smaller) x."""
    sx = x if x_larger else -x
    keep = [i for i in range(len(x)) if not np.any((sx >= sx[i]) & (y >= y[i]) & ((sx > sx[i]) | (y > y[i])))]
    return np.array(sorted(keep, key=lambda i: x[i]), dtype=int)


def plot_sweep(rows: pd.DataFrame, path: str | os.PathLike[str] | None = None, *,
               columns: Sequence[str] | None = None, units: DisplayUnits = SI) -> Figure:  # fmt: skip
    """Draw a sweep's rows (module docstring) and write the picture to ``path`` (PNG, SVG, PDF) if given.

    Args:
        rows: the sweep's rows (:func:`scara_pin.sweep.sweep`).
        path: the picture's file (PNG, SVG, PDF), or None.
        columns: the varied keys; default: the rows' columns before ``variant`` (where a sweep puts them).
        units: the job file's units (the varied values are in them): the placement's axes say its length unit.
    """
    if columns is None:
        names = list(rows.columns)
        columns = names[: names.index("variant")] if "variant" in names else []
    length_unit = units.name("length")
    fig = new_figure(7.0, 5.5)
    ax = fig.add_subplot(1, 1, 1)
    ok = rows[rows["status"] == "ok"]
    place = placement_axes(rows, columns)
    if place is not None:
        _heat_map(ax, fig, rows, ok, place, length_unit)
    else:
        _front(ax, ok, columns)
    return finish(fig, path)


def _heat_map(ax: Any, fig: Any, rows: Any, ok: Any, place: tuple[str, int, int], unit: str) -> None:
    column, i, j = place
    xy = np.array([[float(v[i]), float(v[j])] for v in rows[column]])
    xs, ys = np.unique(xy[:, 0]), np.unique(xy[:, 1])
    grid = np.full((len(ys), len(xs)), math.nan)
    for (x, y), status, rate in zip(xy, rows["status"], rows["parts_per_hour"]):
        a, b = np.searchsorted(ys, y), np.searchsorted(xs, x)
        if status == "ok" and not rate <= grid[a, b]:
            grid[a, b] = rate
    image = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(grid), cmap="viridis", shading="flat")
    fig.colorbar(image, ax=ax, label="parts per hour (best over the other keys)")
    bad = np.isnan(grid)
    if bad.any():
        b, a = np.nonzero(bad.T)
        ax.plot(xs[b], ys[a], "x", color="tab:red", label="no feasible variant")
    if not ok.empty:
        best = ok.loc[ok["parts_per_hour"].idxmax()]
        ax.plot(float(best[column][i]), float(best[column][j]), "o", mfc="none", mec="white", ms=14, mew=2,
                label=f"best: {best['parts_per_hour']:,.1f} parts/h")  # fmt: skip
    suffix = f" [{unit}]" if unit else ""
    ax.set_xlabel(f"{column} {_AXES[i] if i < 3 else i}{suffix}")
    ax.set_ylabel(f"{column} {_AXES[j] if j < 3 else j}{suffix}")
    ax.set_title("Parts per hour over the placement grid")
    ax.set_aspect("equal", adjustable="box")
    ax.legend(loc="best", fontsize="small")


def _edges(centres: np.ndarray) -> np.ndarray:
    if len(centres) == 1:
        return np.array([centres[0] - 0.5, centres[0] + 0.5])
    mid = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


def _front(ax: Any, ok: Any, columns: Sequence[str]) -> None:
    y = ok["parts_per_hour"].to_numpy(dtype=float)
    distances = ok["closest_distance"].to_numpy(dtype=float)
    if len(ok) and np.isfinite(distances).any():
        x, label, larger = distances * 1e3, "closest distance to the cell [mm]", True
    else:
        numeric = [c for c in columns if c in ok and ok[c].map(lambda v: isinstance(v, (int, float))).all()]
        if numeric:
            x, label, larger = ok[numeric[0]].to_numpy(dtype=float), numeric[0], False
        else:
            x, label, larger = ok["variant"].to_numpy(dtype=float), "variant", False
    ax.scatter(x, y, s=18, color="tab:blue", label="planned variants")
    if len(ok):
        front = pareto_front(x, y, larger)
        ax.plot(x[front], y[front], "-o", color="tab:orange", ms=5,
                label=f"Pareto front: more parts/h, {'more' if larger else 'less'} {label}")  # fmt: skip
    ax.set_xlabel(label)
    ax.set_ylabel("parts per hour")
    ax.set_title("Parts per hour of the planned variants")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
