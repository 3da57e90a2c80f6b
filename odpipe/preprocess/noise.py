"""Sample scatter from third differences, immune to a signal's trend.

For white noise of standard deviation s, the third difference
x[i+3] - 3x[i+2] + 3x[i+1] - x[i] has variance 20 s^2, while a signal smooth
over four samples (polynomial to degree 2) cancels.
"""

from __future__ import annotations

import numpy as np


def third_difference_scatter(values: np.ndarray, group: np.ndarray, n_groups: int):
    """Per-group noise 1-sigma of samples (unit of ``values``) and the number of differences used.

    ``group`` (sorted, non-decreasing) labels each sample; only differences whose
    four samples share a group count. NaN where a group has fewer than 4 samples.
    """
    v = np.asarray(values, dtype=float)
    g = np.asarray(group)
    if len(v) < 4:
        return np.full(n_groups, np.nan), np.zeros(n_groups, dtype=np.int64)
    d3 = v[3:] - 3 * v[2:-1] + 3 * v[1:-2] - v[:-3]
    ok = g[3:] == g[:-3]
    m = np.bincount(g[:-3][ok], minlength=n_groups)
    ss = np.bincount(g[:-3][ok], weights=d3[ok] ** 2, minlength=n_groups)
    with np.errstate(invalid="ignore", divide="ignore"):
        scatter = np.where(m > 0, np.sqrt(ss / np.maximum(m, 1) / 20.0), np.nan)
    return scatter, m
