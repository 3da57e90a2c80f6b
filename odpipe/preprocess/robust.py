"""Robust statistics for editing: median/MAD outlier tests, a gross-range test and a spike detector.

The MAD is scaled by 1.4826 so that it estimates the 1-sigma of Gaussian noise.

The spike detector detrends each sample against its neighbours: the quadratic
through the three samples before it, extrapolated one step (3v[i-1] - 3v[i-2] +
v[i-3]), and the same from the three samples after it. A blunder misses both
predictions; a slope or level change (an uplink ramp or retuning arriving one
light time later, unknown here) spoils only the prediction from one side, so
the smaller of the two misses is the detrended signal. The price: a blunder
within two samples of a slope change is judged against that change's size, and
two adjacent blunders of similar size can pass as a slope change (the fit's
residual editor sees them).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

MAD_TO_SIGMA = 1.4826
# A level or slope change among the neighbours spoils a one-step quadratic prediction by at
# most twice the second difference it leaves (a straddled slope change: an eighth of it).
KINK_FACTOR = 3.0


def mad_sigma(values: np.ndarray, group: np.ndarray, use: np.ndarray | None = None) -> np.ndarray:
    """Per-row robust 1-sigma (MAD about the median) of ``values`` within the row's group.

    Only rows with ``use`` true enter the statistics; every row gets its group's value
    (NaN when a group has no usable row).
    """
    v = pd.Series(np.asarray(values, dtype=float))
    g = pd.Series(np.asarray(group))
    use = np.ones(len(v), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    med = v[use].groupby(g[use]).median()
    dev = (v - g.map(med)).abs()
    mad = dev[use].groupby(g[use]).median()
    return (MAD_TO_SIGMA * g.map(mad)).to_numpy(dtype=float)


def outliers(residual: np.ndarray, group: np.ndarray, k: float = 5.0, use: np.ndarray | None = None) -> np.ndarray:
    """True where |residual - group median| > k robust sigmas of its group (e.g. per pass or station).

    This is the test a filter calls on its residuals between iterations.
    """
    r = pd.Series(np.asarray(residual, dtype=float))
    g = pd.Series(np.asarray(group))
    ok = np.ones(len(r), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    med = g.map(r[ok].groupby(g[ok]).median()).to_numpy(dtype=float)
    sig = mad_sigma(r.to_numpy(), g.to_numpy(), ok)
    return np.abs(r.to_numpy() - med) > k * sig


def gross(values: np.ndarray, group: np.ndarray, k: float = 5.0, use: np.ndarray | None = None) -> np.ndarray:
    """True where a value lies more than ``k`` times the group's 10-90 % spread beyond that spread.

    A pass's Doppler, ramps and all, stays within a few such spreads; a 1e8 Hz
    record does not, even when no neighbour can predict it.
    """
    v = pd.Series(np.asarray(values, dtype=float))
    g = pd.Series(np.asarray(group))
    ok = np.ones(len(v), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    q = v[ok].groupby(g[ok]).quantile([0.1, 0.9]).unstack().reindex(columns=[0.1, 0.9])
    lo, hi = g.map(q[0.1]).to_numpy(dtype=float), g.map(q[0.9]).to_numpy(dtype=float)
    spread = hi - lo
    return (v.to_numpy() < lo - k * spread) | (v.to_numpy() > hi + k * spread)


def _neighbours_ok(t: np.ndarray, g: np.ndarray, use: np.ndarray, tol_ns: int) -> np.ndarray:
    """For sorted rows: True at i when rows i-3..i-1 share i's group, are usable and equally spaced up to i."""
    n = len(t)
    ok = np.zeros(n, dtype=bool)
    if n < 4:
        return ok
    step = np.diff(t)
    i = np.arange(3, n)
    ok[3:] = ((g[i - 3] == g[i]) & use[i - 1] & use[i - 2] & use[i - 3]
              & (np.abs(step[i - 1] - step[i - 2]) <= tol_ns) & (np.abs(step[i - 2] - step[i - 3]) <= tol_ns))
    return ok


def spike_deviation(t_ns: np.ndarray, values: np.ndarray, group: np.ndarray, use: np.ndarray | None = None,
                    tol_ns: int = 1_000_000):
    """(miss, kink) per sample, in the unit of ``values``.

    ``miss``: the smaller miss of the one-step quadratic predictions from either
    side (NaN where neither side can predict). ``kink``: the largest slope change
    the neighbours show without the sample itself (second differences on each
    side, and the slope after minus the slope before).
    Only equally spaced (to ``tol_ns``) usable samples of the same group count.
    """
    t = np.asarray(t_ns, dtype=np.int64)
    v = np.asarray(values, dtype=float)
    g = np.asarray(group)
    use = np.ones(len(v), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    order = np.lexsort((t, g))
    ts, vs, gs, us = t[order], v[order], g[order], use[order]
    n = len(v)
    miss, curve, ok, slope = np.full((2, n), np.inf), np.zeros((2, n)), np.zeros((2, n), dtype=bool), np.zeros((2, n))
    for side, (tt, vv, gg, uu) in enumerate([(ts, vs, gs, us), (-ts[::-1], vs[::-1], gs[::-1], us[::-1])]):
        o = _neighbours_ok(tt, gg, uu, tol_ns)
        pred, d2, d1 = np.full(n, np.nan), np.zeros(n), np.zeros(n)
        if n >= 4:
            pred[3:] = 3 * vv[2:-1] - 3 * vv[1:-2] + vv[:-3]
            d2[3:] = vv[2:-1] - 2 * vv[1:-2] + vv[:-3]
            d1[3:] = vv[1:-2] - vv[2:-1]   # slope one step away (reversed side: sign flips with time)
        m = np.where(o, np.abs(vv - pred), np.inf)
        rev = slice(None) if side == 0 else slice(None, None, -1)
        miss[side], curve[side], ok[side], slope[side] = m[rev], np.where(o, np.abs(d2), 0.0)[rev], o[rev], d1[rev]
    best = miss.min(axis=0)
    outer = np.where(ok[0] & ok[1], np.abs(-slope[1] - slope[0]), 0.0)
    kink = np.maximum(np.maximum(curve[0], curve[1]), outer)
    dev, exc = np.empty(n), np.empty(n)
    dev[order] = np.where(np.isfinite(best), best, np.nan)
    exc[order] = kink
    return dev, exc


def spikes(t_ns: np.ndarray, values: np.ndarray, group: np.ndarray, k: float = 10.0,
           use: np.ndarray | None = None, rounds: int = 3) -> np.ndarray:
    """True where the miss of :func:`spike_deviation` exceeds ``k`` robust sigmas of its group
    and ``KINK_FACTOR`` times the neighbours' slope change.

    The scale is median(miss)/0.6745 over the group's usable rows (a miss's
    expected value is zero, so no median is subtracted); a group whose scale
    is zero is not judged. Up to ``rounds`` passes: samples found in one no
    longer predict their neighbours in the next, so a blunder beside a blunder is found.
    """
    use = np.ones(len(values), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    g = pd.Series(np.asarray(group))
    bad = np.zeros(len(use), dtype=bool)
    for _ in range(rounds):
        dev, kink = spike_deviation(t_ns, values, group, use & ~bad)
        ok = use & ~bad & np.isfinite(dev)
        scale = g.map(pd.Series(dev)[ok].groupby(g[ok]).median()).to_numpy(dtype=float) * MAD_TO_SIGMA
        new = use & ~bad & (scale > 0) & (dev > k * scale) & (dev > KINK_FACTOR * kink)
        if not new.any():
            break
        bad |= new
    return bad
