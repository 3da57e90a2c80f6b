"""Per-pass polynomial smoothing of media delays (operations fit order ~10 per pass)."""

from __future__ import annotations

import numpy as np


def smooth_by_group(t_s, y, group, order: int = 10):
    """``y`` replaced by a least-squares polynomial in time within each group.

    ``t_s``: times (s, any origin); the degree is ``min(order, distinct times - 1)``;
    NaN samples are ignored by the fit and stay NaN.
    """
    t_s, y = np.asarray(t_s, dtype=float), np.asarray(y, dtype=float)
    out = y.copy()
    order_idx = np.argsort(group, kind="stable")
    g = np.asarray(group)[order_idx]
    bounds = np.flatnonzero(np.r_[True, g[1:] != g[:-1], True])
    for a, b in zip(bounds[:-1], bounds[1:]):
        idx = order_idx[a:b]
        ok = idx[np.isfinite(y[idx])]
        degree = min(order, np.unique(t_s[ok]).size - 1)
        if degree < 1:
            continue
        fit = np.polynomial.Polynomial.fit(t_s[ok], y[ok], degree)
        out[ok] = fit(t_s[ok])
    return out
