"""Acceptance bounds for estimation errors, taken from the chi-square distribution (scipy.stats.chi2).

Every bound has a false-alarm probability ``alpha`` (default 1e-3) for a consistent estimator:
errors drawn from the reported covariance. Bounds over many correlated quantities use the
union bound (valid for any correlation) for maxima, and for means over correlated epochs the
bounds of a single draw (a mean of identically distributed terms is no more spread than one).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

ALPHA = 1e-3


def nees(err: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """Normalized estimation error squared e' P^-1 e, for one error (n,) or a stack (k, n) / (k, n, n)."""
    err = np.asarray(err, float)
    if err.ndim == 1:
        return float(err @ np.linalg.solve(cov, err))
    return np.einsum("ki,ki->k", err, np.linalg.solve(cov, err[..., None])[..., 0])


def nees_upper(dof: int, alpha: float = ALPHA) -> float:
    """Upper bound of one chi-square(dof) draw."""
    return float(chi2.ppf(1.0 - alpha, dof))


def nees_mean_bounds(dof: int, runs: int = 1, alpha: float = ALPHA) -> tuple[float, float]:
    """Two-sided bounds of the mean of ``runs`` independent chi-square(dof) draws."""
    lo, hi = chi2.ppf([alpha / 2, 1.0 - alpha / 2], runs * dof) / runs
    return float(lo), float(hi)


def max_z(count: int, alpha: float = ALPHA) -> float:
    """Bound on the largest |error / sigma| among ``count`` standard normal terms (union bound)."""
    return float(np.sqrt(chi2.ppf(1.0 - alpha / count, 1)))


def assert_within_covariance(err, cov, alpha: float = ALPHA) -> float:
    """Assert e' P^-1 e below the chi-square bound and each |e_i| / sigma_i below the union bound; returns the NEES."""
    err = np.asarray(err, float)
    q = nees(err, cov)
    z = err / np.sqrt(np.diag(cov))
    assert q < nees_upper(err.size, alpha), (q, nees_upper(err.size, alpha), z)
    assert np.all(np.abs(z) < max_z(err.size, alpha)), z
    return q


def rms_bounds(count: int, fitted: int = 0, alpha: float = ALPHA) -> tuple[float, float]:
    """Bounds of the RMS of ``count`` residuals / sigma when ``fitted`` parameters were fitted to them
    (chi-square with count - fitted to count degrees of freedom)."""
    lo = chi2.ppf(alpha / 2, count - fitted) / count
    hi = chi2.ppf(1.0 - alpha / 2, count) / count
    return float(np.sqrt(lo)), float(np.sqrt(hi))
