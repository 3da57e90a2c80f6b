"""Four-point Lagrange (cubic) interpolation on a uniform grid, vectorized."""

from __future__ import annotations

import numpy as np


def lagrange4_uniform(x0: float, h: float, values: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Cubic Lagrange interpolation of ``values`` (n, ...) sampled at ``x0 + k*h``.

    Uses the 4 nodes around each ``x`` (shifted inward at the table ends).
    The caller checks that ``x`` lies in [x0, x0 + (n-1)h].
    """
    n = values.shape[0]
    if n < 4:
        raise ValueError(f"cubic interpolation needs at least 4 nodes, got {n}")
    u = (np.asarray(x, dtype=float) - x0) / h
    i = np.clip(np.floor(u).astype(np.int64) - 1, 0, n - 4)
    p = u - i  # position relative to node i, in [0, 3]
    w0 = -(p - 1) * (p - 2) * (p - 3) / 6.0
    w1 = p * (p - 2) * (p - 3) / 2.0
    w2 = -p * (p - 1) * (p - 3) / 2.0
    w3 = p * (p - 1) * (p - 2) / 6.0
    extra = (slice(None),) + (None,) * (values.ndim - 1)
    return (w0[extra] * values[i] + w1[extra] * values[i + 1]
            + w2[extra] * values[i + 2] + w3[extra] * values[i + 3])


def on_uniform_grid(fn, x, step: float, min_points: int = 200) -> np.ndarray:
    """``fn(x)`` for many ``x``: evaluated on nodes ``step`` apart and interpolated (cubic).

    For a smooth ``fn`` (shortest period P) the error is about (2π·step/P)^4/100
    of its amplitude. Falls back to ``fn(x)`` when ``x`` has fewer than
    ``min_points`` values or would need more nodes than half its size.
    ``fn`` maps an array (n,) to (n,) or (n, k).
    """
    x = np.asarray(x, dtype=float)
    if x.size < min_points:
        return fn(x)
    lo = np.floor(x.min() / step) * step - step
    n = max(int(np.ceil((x.max() - lo) / step)) + 2, 4)
    if n >= x.size // 2:
        return fn(x)
    values = np.asarray(fn(lo + step * np.arange(n)))
    out = lagrange4_uniform(lo, step, values, x.ravel())
    return out.reshape(x.shape + values.shape[1:])
