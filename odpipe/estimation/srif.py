"""Square-root information filter (Bierman 1977) with consider parameters.

The filter keeps the information array ``[R | z]`` of the deviation ``dx`` from
a reference, with ``R dx = z - nu``, ``nu ~ N(0, I)``. The vector is in registry
canonical order: ``n_est`` estimated parameters, then consider parameters whose
a priori (deviation ``c_bar``, sigma ``c_sigma``) is never replaced by data.

Operations, all by Householder triangularization (LAPACK's reflections; the updates and the stacked
read-outs compiled in :mod:`.srif_kernels`, the rest by LAPACK geqrf):

* :meth:`SRIF.measurement_update` -- rows ``H dx = y + eps``, ``eps ~ N(0, sigma^2)``;
* :meth:`SRIF.time_update` -- deterministic map ``dx+ = Phi dx``;
* :meth:`SRIF.intervals` -- grid intervals without process noise in one compiled pass: marks,
  measurement blocks after an innovation test, maps;
* :meth:`SRIF.process_noise` -- Bierman's colored-noise update of stochastic
  parameters ``p+ = m p + w`` at one instant (m = 0 white, 0 < m < 1
  Gauss-Markov, m = 1 random walk); its eliminated rows are kept for the smoother.

Every operation is appended to ``SRIF.log`` so that :mod:`.smoother` can run the
square-root information smoother backwards.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg.lapack import dgeqrf, dtrtri

from . import srif_kernels as kernels


@lru_cache(maxsize=64)
def _strictly_lower(k: int, n: int):
    return np.tril_indices(k, -1, n)


def triangularize(A: np.ndarray) -> np.ndarray:
    """Upper-triangular factor of ``A`` by Householder QR (rows ``min(m, n)``)."""
    k = min(A.shape)
    T = dgeqrf(A)[0][:k]
    T[_strictly_lower(k, A.shape[1])] = 0.0
    return T


@dataclass(frozen=True)
class Gaussian:
    """Estimate of the deviation and its covariances (registry units).

    P: computed (noise-only) covariance; consider parameters carry their a priori.
    P_consider: covariance including the effect of consider-parameter errors.
    """

    x: np.ndarray
    P: np.ndarray
    P_consider: np.ndarray

    @property
    def sigma(self) -> np.ndarray:
        return np.sqrt(np.diag(self.P_consider))


def _augmented(R, z) -> np.ndarray:
    """``[R | z]``: (m, n + 1), or (K, m, n + 1) for stacks of arrays."""
    R, z = np.asarray(R, float), np.asarray(z, float)
    A = np.empty(R.shape[:-1] + (R.shape[-1] + 1,))
    A[..., :-1] = R
    A[..., -1] = z
    return A


def _rows(a) -> np.ndarray:
    """``a`` as a C-contiguous float64 array (the compiled kernels' one signature)."""
    return np.ascontiguousarray(a, dtype=float)


def _inverse(R):
    """Inverse of an upper-triangular matrix (LAPACK trtri; small, unthreaded)."""
    Rinv, info = dtrtri(R)
    if info != 0:
        raise np.linalg.LinAlgError("singular square-root information matrix")
    return Rinv


def solve_information(R, z, n_est, c_bar, c_sigma, triangular=False) -> Gaussian:
    """Estimate and covariances from an information array (any row order unless
    ``triangular``, which skips the re-triangularization)."""
    n = R.shape[1]
    T = _augmented(R, z) if triangular else triangularize(_augmented(R, z))
    Ree, Rec, ze = T[:n_est, :n_est], T[:n_est, n_est:n], T[:n_est, n]
    Rinv = _inverse(Ree)
    S = Rinv @ Rec                          # -d(x_e)/d(c)
    x = np.concatenate([Rinv @ (ze - Rec @ c_bar), c_bar])
    P = np.zeros((n, n))
    P[:n_est, :n_est] = Rinv @ Rinv.T
    if n_est == n:
        return Gaussian(x, P, P)
    Pcc = np.diag(c_sigma**2)
    P[n_est:, n_est:] = Pcc
    Pc = P.copy()
    SP = S @ Pcc
    Pc[:n_est, :n_est] += SP @ S.T
    Pc[:n_est, n_est:] = -SP
    Pc[n_est:, :n_est] = -SP.T
    return Gaussian(x, P, Pc)


def _stacked_factors(R, z, n_est):
    """Triangular factors of stacked information arrays (K, m, n), (K, m): (T_ee, T_ec, T_e,z)."""
    n = R.shape[-1]
    T = kernels.stacked_triangles(_rows(R), _rows(z))
    return T[:, :n_est, :n_est], T[:, :n_est, n_est:n], T[:, :n_est, n]


def information_estimates(R, z, n_est, c_bar) -> np.ndarray:
    """Estimates only (no covariance) of K stacked information arrays R (K, m, n), z (K, m), the consider part
    at ``c_bar``: (K, n)."""
    Ree, Rec, ze = _stacked_factors(R, z, n_est)
    xe = kernels.stacked_upper_solve(_rows(Ree), _rows(ze - Rec @ c_bar))
    return np.concatenate([xe, np.broadcast_to(c_bar, (xe.shape[0], c_bar.size))], axis=1)


def solve_informations(R, z, n_est, c_bar, c_sigma) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`solve_information` of K stacked arrays at once: x (K, n), P (K, n, n), P_consider (K, n, n)."""
    Ree, Rec, ze = _stacked_factors(R, z, n_est)
    Rinv = kernels.stacked_upper_inverse(_rows(Ree))
    K, n = Rinv.shape[0], R.shape[-1]
    x = np.concatenate([np.einsum("kij,kj->ki", Rinv, ze - Rec @ c_bar),
                        np.broadcast_to(c_bar, (K, c_bar.size))], axis=1)
    P = np.zeros((K, n, n))
    P[:, :n_est, :n_est] = Rinv @ Rinv.transpose(0, 2, 1)
    if n_est == n:
        return x, P, P
    P[:, n_est:, n_est:] = np.diag(c_sigma**2)
    Pc = P.copy()
    S = Rinv @ Rec                          # -d(x_e)/d(c)
    SP = S * c_sigma**2
    Pc[:, :n_est, :n_est] += SP @ S.transpose(0, 2, 1)
    Pc[:, :n_est, n_est:] = -SP
    Pc[:, n_est:, :n_est] = -SP.transpose(0, 2, 1)
    return x, P, Pc


class SRIF:
    """Square-root information filter on an ``n``-vector, the last ``n - n_est`` considered."""

    def __init__(self, R, z, n_est=None, c_bar=None, c_sigma=None):
        n = np.shape(R)[1]
        T = triangularize(_augmented(R, z))
        self.R, self.z = T[:n, :n], T[:n, n]
        self.n_est = n if n_est is None else int(n_est)
        nc = n - self.n_est
        self.c_bar = np.zeros(nc) if c_bar is None else np.asarray(c_bar, float)
        self.c_sigma = np.ones(nc) if c_sigma is None else np.asarray(c_sigma, float)
        self.chi2 = 0.0          # accumulated whitened residual sum of squares
        self.log: list = []

    @classmethod
    def from_apriori(cls, sigma, dx=None, n_est=None):
        """Diagonal a priori: deviation ``dx`` (default 0) with standard deviations ``sigma``."""
        sigma = np.asarray(sigma, float)
        dx = np.zeros_like(sigma) if dx is None else np.asarray(dx, float)
        n_est = sigma.size if n_est is None else n_est
        return cls(np.diag(1.0 / sigma), dx / sigma, n_est, dx[n_est:], sigma[n_est:])

    @property
    def n(self) -> int:
        return self.R.shape[1]

    # -- updates ---------------------------------------------------------
    def measurement_update(self, H, y, sigma) -> float:
        """Absorb rows ``H dx = y`` with noise ``sigma``; return their contribution to
        the whitened residual sum of squares (also accumulated in ``chi2``)."""
        H = _rows(np.atleast_2d(H))
        self.R, self.z, e2 = kernels.absorb(_rows(self.R), _rows(self.z), H, _rows(y), 1.0 / _rows(sigma))
        self.chi2 += e2
        return e2

    def time_update(self, Phi):
        """Deterministic map ``dx+ = Phi dx`` (Phi invertible, n x n)."""
        Phi = _rows(Phi)
        self.R, self.z = kernels.mapped(_rows(self.R), _rows(self.z), Phi)
        self.log.append(("map", Phi))

    def intervals(self, first, Phi, H, y, sigma, use, bounds, edit_k, edit_y=False):
        """Grid intervals ``first, first + 1, ...`` without process noise, in one compiled pass: at each, a
        ``mark``, the rows ``bounds[k]:bounds[k + 1]`` of ``H dx = y`` (noise ``sigma``; those with ``use``)
        absorbed unless the innovation test edits them (``|nu| > edit_k s``, and with ``edit_y`` also
        ``|y| > edit_k sigma``), and the map ``Phi[k]`` (K, n, n).

        Returns the information arrays at the marks ((K, n, n), (K, n)) and per row the innovation nu,
        its predicted sigma s (NaN where not ``use``) and whether it was edited."""
        Phi = _rows(Phi)
        Rs, zs, self.R, self.z, nu, s, bad, chi2 = kernels.filter_intervals(
            _rows(self.R), _rows(self.z), Phi, _rows(H), _rows(y), _rows(sigma), np.ascontiguousarray(use, bool),
            bool(edit_y), np.ascontiguousarray(bounds, np.int64), float(edit_k), self.n_est, _rows(self.c_bar),
            _rows(self.c_sigma))
        self.chi2 += chi2
        self.log.append(("intervals", first, Phi))
        return Rs, zs, nu, s, bad

    def process_noise(self, idx, m, q, offset=None):
        """Colored-noise step ``p+ = m p + offset + w``, ``w ~ N(0, q)`` on parameters ``idx``.

        ``offset`` (default 0) is the reference's own jump, ``m p_ref - p+_ref``
        with sign so that deviations obey the equation above.
        """
        idx = np.asarray(idx, int)
        k = idx.size
        m = np.broadcast_to(np.asarray(m, float), (k,))
        sq = np.sqrt(np.broadcast_to(np.asarray(q, float), (k,)))
        off = np.zeros(k) if offset is None else np.asarray(offset, float)
        n = self.n
        # variables: [p_old (k) | dx_new (n)]; dx_new carries p_new in slots idx
        A = np.zeros((n + k, k + n + 1))
        A[:n, :k] = self.R[:, idx]
        rest = np.ones(n, bool)
        rest[idx] = False
        A[:n, k:k + n][:, rest] = self.R[:, rest]
        A[:n, -1] = self.z
        A[n:, :k] = np.diag(-m / sq)
        A[n + np.arange(k), k + idx] = 1.0 / sq
        A[n:, -1] = off / sq
        T = triangularize(A)
        self.log.append(("noise", idx, T[:k, :k], T[:k, k:k + n], T[:k, -1]))
        self.R, self.z = T[k:, k:k + n], T[k:, -1]

    def mark(self, label):
        """Record a point where the smoother should report (e.g. a grid epoch)."""
        self.log.append(("mark", label))

    # -- read-out ---------------------------------------------------------
    def gaussian(self) -> Gaussian:
        return solve_information(self.R, self.z, self.n_est, self.c_bar, self.c_sigma,
                                 triangular=True)

    def innovations(self, H, y, sigma):
        """Pre-update residuals ``y - H x`` and their predicted standard deviations.

        The prediction variance includes the estimate's covariance with the
        consider parameters' effect, and the measurement noise.
        """
        H = _rows(np.atleast_2d(H))
        nu, s = np.empty(H.shape[0]), np.empty(H.shape[0])
        kernels.innovations(_rows(self.R), _rows(self.z), H, _rows(y), _rows(sigma), np.ones(H.shape[0], bool),
                            self.n_est, _rows(self.c_bar), _rows(self.c_sigma), nu, s)
        return nu, s
