"""Piecewise Chebyshev tables of vector functions of time, evaluable from numba.

Ephemeris positions and body-fixed rotation matrices are fitted once per arc
on fixed-length segments (Chebyshev nodes of the first kind), so the
integrator's force kernel reads them without calling back into Python.
A table is a ``(coefficients, meta)`` pair: coefficients (nchannels, nseg,
degree+1, dim) and meta (nchannels, 3) = [t_start, segment length, nseg].
"""

from __future__ import annotations

import numpy as np
from numba import njit


def fit_channel(fun, t0: float, t1: float, segment: float, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Fit ``fun(t: (N,)) -> (N, dim)`` on [t0, t1] (s) with segments of ``segment`` s.

    Returns coefficients (nseg, degree+1, dim) and meta [t_start, segment, nseg].
    """
    nseg = max(1, int(np.ceil((t1 - t0) / segment - 1e-9)))
    k = np.arange(degree + 1)
    nodes = np.cos(np.pi * (k + 0.5) / (degree + 1))  # in (-1, 1)
    starts = t0 + segment * np.arange(nseg)
    t = (starts[:, None] + 0.5 * segment * (nodes[None, :] + 1.0)).ravel()
    values = np.asarray(fun(t), dtype=float).reshape(nseg, degree + 1, -1)
    # discrete Chebyshev transform at first-kind nodes
    T = np.cos(np.outer(k, np.pi * (k + 0.5) / (degree + 1)))  # T_j(node_i) as [j, i]
    coef = 2.0 / (degree + 1) * np.einsum("ji,sid->sjd", T, values)
    coef[:, 0, :] *= 0.5
    return coef, np.array([t0, segment, nseg], dtype=float)


def stack_channels(channels: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Pad fitted channels to one (nch, nseg, degree+1, dim) array and (nch, 3) meta."""
    if not channels:
        return np.zeros((1, 1, 1, 9)), np.array([[0.0, 1.0, 1.0]])
    nseg = max(c.shape[0] for c, _ in channels)
    ndeg = max(c.shape[1] for c, _ in channels)
    dim = max(c.shape[2] for c, _ in channels)
    coefs = np.zeros((len(channels), nseg, ndeg, dim))
    for i, (c, _) in enumerate(channels):
        coefs[i, : c.shape[0], : c.shape[1], : c.shape[2]] = c
    return coefs, np.array([m for _, m in channels])


@njit(cache=True)
def evaluate(coefs, meta, ch, t, out):
    """Write channel ``ch`` at time ``t`` (s) into ``out`` (dim,) by Clenshaw's recurrence."""
    t_start, seg, nseg = meta[ch, 0], meta[ch, 1], int(meta[ch, 2])
    i = int((t - t_start) // seg)
    if i < 0:
        i = 0
    elif i >= nseg:
        i = nseg - 1
    x = 2.0 * (t - t_start - i * seg) / seg - 1.0
    ndeg = coefs.shape[2]
    for d in range(out.shape[0]):
        b1 = 0.0
        b2 = 0.0
        for j in range(ndeg - 1, 0, -1):
            b1, b2 = 2.0 * x * b1 - b2 + coefs[ch, i, j, d], b1
        out[d] = x * b1 - b2 + coefs[ch, i, 0, d]
