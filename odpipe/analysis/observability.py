"""Observability of a linearized estimation problem: Gramian, SVD measures, SNR ratio.

Discrete time-varying observability Gramian (Turan et al. eq. 22; Leonard thesis
sec. 3.8): ``N = sum_k Phi(t_k, t0)^T H_k^T W_k H_k Phi(t_k, t0)``, i.e. the
information about the epoch state that the rows carry (W = I gives eq. 22, W =
1/sigma^2 the Fisher information without a priori). Measures from the singular
values of N (Turan et al. eq. 23 and Table 1):

* condition number ``sigma_max / sigma_min`` (Table 1 reports it this way round,
  values ~1e10; the text's wording "smallest to largest" is its reciprocal);
* unobservability index ``1 / sigma_min`` (Krener & Ide), Table 1's "1/min eig(N)"
  (N is symmetric positive semi-definite, so singular values are eigenvalues).

The SNR ratio of two observables a, b (Turan et al. eq. 25) per state component i:
``Xi_i = (sigma_b / sigma_a) |H_a,i / H_b,i|``; Xi > 1 means observable a carries
more signal-to-noise for component i.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def map_to_epoch(H: np.ndarray, Phi: np.ndarray) -> np.ndarray:
    """Rows' partials w.r.t. the epoch state: H_k Phi(t_k, t0); H (m, n), Phi (m, n, n)."""
    return np.einsum("mj,mjk->mk", H, Phi)


def gramian(H_epoch: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """``sum_k H_k^T w_k H_k`` of epoch-mapped rows (m, n); weights (m,) default 1."""
    w = np.ones(H_epoch.shape[0]) if weights is None else np.asarray(weights, float)
    return H_epoch.T @ (w[:, None] * H_epoch)


def cumulative_gramians(H_epoch: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """Gramian after each row: (m, n, n), entry k sums rows 0..k."""
    w = np.ones(H_epoch.shape[0]) if weights is None else np.asarray(weights, float)
    return np.cumsum(np.einsum("mi,m,mj->mij", H_epoch, w, H_epoch), axis=0)


@dataclass(frozen=True)
class ObservabilityMeasures:
    """Singular values (descending) of a Gramian and the measures derived from them."""

    singular_values: np.ndarray

    @property
    def condition_number(self) -> float:
        """sigma_max / sigma_min (inf when rank deficient)."""
        s = self.singular_values
        return float(s[0] / s[-1]) if s[-1] > 0 else np.inf

    @property
    def unobservability_index(self) -> float:
        """1 / sigma_min, in inverse Gramian units (inf when rank deficient)."""
        s = self.singular_values[-1]
        return float(1.0 / s) if s > 0 else np.inf

    def rank(self, rtol: float = 1e-14) -> int:
        s = self.singular_values
        return int(np.sum(s > rtol * s[0]))


def observability_measures(N: np.ndarray) -> ObservabilityMeasures:
    """SVD measures of a Gramian N (Turan et al. eq. 23)."""
    return ObservabilityMeasures(np.linalg.svd(N, compute_uv=False))


def snr_ratio(H_a: np.ndarray, H_b: np.ndarray, sigma_a: float, sigma_b: float) -> np.ndarray:
    """Xi = (sigma_b / sigma_a) |H_a / H_b| elementwise (rows x state components).

    Entries where H_b is zero are inf (where both are zero: nan, no information in either).
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        return (sigma_b / sigma_a) * np.abs(np.asarray(H_a, float) / np.asarray(H_b, float))
