"""Data of the per-touch error bar chart (viser's uPlot), without viser.

viser's uPlot binding takes data and options but no JavaScript callbacks, so uPlot's own bar
renderer (``uPlot.paths.bars``, a JS function) cannot be asked for. Each bar is therefore drawn
as a filled outline: the x values go ``i - w, i - w, i + w, i + w`` and the heights ``0, e, e, 0``
for touch ``i`` (1-based, as the pendant numbers touches), and the series is filled down to 0.
Touches flagged as outliers get their own (red) series so they stand out; each series is 0
where it has no bar, which draws along the axis.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
import numpy as np

__all__ = ["BAR_HALF_WIDTH", "MIN_TOP_MM", "ErrorBars", "error_bars", "error_axis_top_mm"]

BAR_HALF_WIDTH = 0.3
"""Half the width of a bar, in touch numbers (bars are 0.6 wide, 0.4 apart)."""

MIN_TOP_MM = 0.01
"""The least top of the error axis, mm. uPlot writes its tick labels with at most three
decimals, so an axis up to 0.001 mm (all errors zero) read "0.001, 0.001, 0.001, 0"; up to
0.01 mm its ticks are at least 0.001 mm apart and read apart."""


def error_axis_top_mm(errors_mm: Sequence[float]) -> float:
    """Top of the error chart's y axis (mm): 1.2 x the largest error, at least
    :data:`MIN_TOP_MM`, rounded up to 1, 2 or 5 x 10^k so the ticks fall on round numbers."""
    e = np.asarray(errors_mm, dtype=float)
    top = max(1.2 * float(np.max(e)) if e.size and np.all(np.isfinite(e)) else 0.0, MIN_TOP_MM)
    k = np.floor(np.log10(top))
    for m in (1.0, 2.0, 5.0, 10.0):
        nice = float(m * 10.0 ** k)
        if nice >= top * (1 - 1e-12):
            return nice
    return float(10.0 ** (k + 1))


@dataclass(frozen=True, eq=False)
class ErrorBars:
    """Columns for ``gui.add_uplot(data=(x, normal, outliers, mean), ...)``.

    Attributes:
        x: outline x values (touch numbers +- half width), ascending.
        normal_mm: outline heights of the touches that are not outliers (mm).
        outlier_mm: outline heights of the outliers (mm).
        mean_mm: the mean error as a flat line (mm), for reference.
    """

    x: np.ndarray
    normal_mm: np.ndarray
    outlier_mm: np.ndarray
    mean_mm: np.ndarray

    @property
    def columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return (self.x, self.normal_mm, self.outlier_mm, self.mean_mm)


def error_bars(touch_numbers: Sequence[int], errors_mm: Sequence[float],
               outliers: Sequence[int] = ()) -> ErrorBars:
    """Bars of ``errors_mm[k]`` at touch ``touch_numbers[k]`` (1-based), outliers apart.

    Args:
        touch_numbers: 1-based number of each touch shown (ascending).
        errors_mm: ``|e_i|`` of each touch, mm (finite, >= 0).
        outliers: 1-based numbers of the touches flagged as outliers.
    """
    n = np.asarray(touch_numbers, dtype=float)
    e = np.asarray(errors_mm, dtype=float)
    if n.shape != e.shape or n.ndim != 1:
        raise ValueError(f"touch_numbers and errors_mm must be equal-length lists, got {n.shape} and {e.shape}.")
    if n.size and np.any(np.diff(n) <= 0):
        raise ValueError("touch_numbers must be strictly ascending.")
    w = BAR_HALF_WIDTH
    x = np.stack([n - w, n - w, n + w, n + w], axis=1).reshape(-1)
    heights = np.stack([np.zeros_like(e), e, e, np.zeros_like(e)], axis=1)
    is_out = np.isin(n, np.asarray(outliers, dtype=float))[:, None]
    normal = np.where(is_out, 0.0, heights).reshape(-1)
    outlier = np.where(is_out, heights, 0.0).reshape(-1)
    mean = np.full_like(x, float(e.mean()) if e.size else 0.0)
    return ErrorBars(x, normal, outlier, mean)
