"""Robust statistics for editing: median/MAD outlier tests and a robust piecewise-polynomial detrend.

The MAD is scaled by 1.4826 so that it estimates the 1-sigma of Gaussian noise.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

MAD_TO_SIGMA = 1.4826


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


def gross(values: np.ndarray, group: np.ndarray, k: float = 20.0, use: np.ndarray | None = None) -> np.ndarray:
    """True where a value lies more than ``k`` robust sigmas of the group's *values* from their median.

    A smooth signal never leaves that band (a sinusoid spans about 1 robust sigma
    either side), so this catches gross blunders whatever the fit, even isolated samples.
    """
    v = pd.Series(np.asarray(values, dtype=float))
    g = pd.Series(np.asarray(group))
    ok = np.ones(len(v), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    med = g.map(v[ok].groupby(g[ok]).median()).to_numpy(dtype=float)
    return np.abs(v.to_numpy() - med) > k * mad_sigma(v.to_numpy(), g.to_numpy(), ok)


def _chunks(t_s: np.ndarray, group: np.ndarray, length: float) -> np.ndarray:
    """Label of consecutive ``length``-second pieces of each group; a short last piece joins the one before."""
    g = pd.Series(group)
    t = pd.Series(t_s)
    rel = (t - t.groupby(g).transform("min")).to_numpy()
    span = t.groupby(g).transform("max").to_numpy() - t.groupby(g).transform("min").to_numpy()
    last = np.maximum(np.floor(span / length) - 1, 0)
    piece = np.minimum(np.floor(rel / length), last)
    return pd.DataFrame({"g": group, "p": piece}).groupby(["g", "p"], sort=False).ngroup().to_numpy()


def _fit(powers, v, w, starts, chunk, degree):
    """Weighted least-squares polynomial per chunk (batched normal equations); fitted values.

    Rows are sorted by chunk, chunk i starting at row ``starts[i]``; ``powers``
    holds x**0 .. x**(2 degree) per row.
    """
    wp = powers * w[:, None]
    s = np.add.reduceat(wp, starts, axis=0)
    b = np.add.reduceat(wp[:, :degree + 1] * v[:, None], starts, axis=0)
    idx = np.arange(degree + 1)
    normal = s[:, idx[:, None] + idx[None, :]]
    ridge = 1e-10 * (s[:, :1, None] + 1.0) * np.eye(degree + 1)
    coef = np.linalg.solve(normal + ridge, b[..., None])[..., 0]
    return np.einsum("ij,ij->i", powers[:, :degree + 1], coef[chunk])


def robust_detrend(t_s: np.ndarray, values: np.ndarray, group: np.ndarray, *, use: np.ndarray | None = None,
                   piece: float = 300.0, degree: int = 5, k: float = 6.0, iterations: int = 5):
    """Residuals of ``values`` about a robust polynomial of ``degree`` fitted to each ``piece``-second
    stretch of each group (e.g. pass), and the final inlier mask.

    Start: rows within 10 MADs of their stretch's median; then fit, keep rows within
    ``k`` robust sigmas (MAD of inliers' residuals per stretch), refit, ``iterations`` times.
    """
    t = np.asarray(t_s, dtype=float)
    v = np.asarray(values, dtype=float)
    use = np.ones(len(v), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    resid, inlier = np.zeros(len(v)), np.zeros(len(v), dtype=bool)
    if len(v) == 0:
        return resid, inlier
    chunk = _chunks(t, np.asarray(group), piece)
    order = np.argsort(chunk, kind="stable")
    chunk, t, v, use = chunk[order], t[order], v[order], use[order]
    starts = np.flatnonzero(np.r_[True, chunk[1:] != chunk[:-1]])
    t0 = np.minimum.reduceat(t, starts)[chunk]
    t1 = np.maximum.reduceat(t, starts)[chunk]
    x = np.where(t1 > t0, 2 * (t - t0) / np.where(t1 > t0, t1 - t0, 1.0) - 1, 0.0)
    centre = pd.Series(chunk).map(pd.Series(v[use]).groupby(chunk[use]).median()).to_numpy()
    y = v - np.nan_to_num(centre)
    inl = use & (np.abs(y) <= 10 * np.nan_to_num(mad_sigma(v, chunk, use), nan=np.inf) + 1e-300)
    powers = np.vander(x, 2 * degree + 1, increasing=True)
    for _ in range(iterations):
        res = y - _fit(powers, np.where(inl, y, 0.0), inl.astype(float), starts, chunk, degree)
        sig = mad_sigma(res, chunk, inl)
        inl = use & (np.abs(res) <= k * np.nan_to_num(sig, nan=np.inf))
    resid[order], inlier[order] = res, inl
    return resid, inlier
