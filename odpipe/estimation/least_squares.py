"""Batch weighted least squares with a priori (normal equations, Tapley et al. 4.3).

For arcs without process noise. Solves, about a reference, for the epoch
deviation ``dx`` minimizing
``(y - H dx)^T W (y - H dx) + (dx - dx_bar)^T P_bar^{-1} (dx - dx_bar)``
by Cholesky factorization of the information (normal) matrix; an independent
check on the SRIF-smoother, which must agree with it when there is no process noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_factor, cho_solve


@dataclass(frozen=True)
class BatchSolution:
    """Epoch deviation ``x``, covariance ``P`` and post-fit residuals (measurement units)."""

    x: np.ndarray
    P: np.ndarray
    postfit: np.ndarray


def batch_least_squares(H, y, sigma, P_bar, dx_bar=None) -> BatchSolution:
    """Weighted least squares of rows ``H dx = y + eps`` (eps ~ N(0, sigma^2)) with a priori.

    H: (m, n) partials w.r.t. the epoch parameters; y: (m,) observed minus computed;
    sigma: (m,) noise; P_bar: (n, n) a priori covariance; dx_bar: a priori deviation.
    """
    H = np.atleast_2d(H)
    w = 1.0 / np.asarray(sigma, float) ** 2
    n = H.shape[1]
    dx_bar = np.zeros(n) if dx_bar is None else np.asarray(dx_bar, float)
    Lambda_bar = np.linalg.inv(P_bar)
    Lambda = H.T @ (H * w[:, None]) + Lambda_bar
    N = H.T @ (w * y) + Lambda_bar @ dx_bar
    c = cho_factor(Lambda)
    x = cho_solve(c, N)
    P = cho_solve(c, np.eye(n))
    return BatchSolution(x, 0.5 * (P + P.T), y - H @ x)
