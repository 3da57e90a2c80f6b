"""Cramér-Rao lower bound recursion with process noise (Leonard thesis eqs. 3.29-3.32).

Fisher information along the true trajectory (Tichavsky et al.):

    J_k = Q^-1 + H_k^T R_k^-1 H_k - Q^-1 Phi (J_{k-1} + Phi^T Q^-1 Phi)^-1 Phi^T Q^-1   (3.31)

with Phi = Phi(t_k, t_{k-1}), Q = Q_{k-1} = Gamma q Gamma^T (3.32), J_0 = P_0^-1, and
the CRLB P*_k = J_k^-1 (3.29). (The thesis prints ``Phi Q^-1 Phi^T`` inside the
bracket; the transposes as above are the ones that make 3.31 reduce to 3.30.)
By the matrix inversion lemma 3.31 equals

    J_k = (Phi J_{k-1}^-1 Phi^T + Q)^-1 + H_k^T R_k^-1 H_k,

which is what is computed here: it also holds for the singular Q of eq. 3.32
(3 acceleration axes driving 6 states) and is eq. 3.30 when Q = 0.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import block_diag


def snc_gamma(dt: float) -> np.ndarray:
    """Gamma(t_k, t_k-1) of a constant acceleration over dt (s) into [r; v]: (6, 3)."""
    return np.vstack([0.5 * dt * dt * np.eye(3), dt * np.eye(3)])


def snc_process_noise(dt: float, sigma_acc) -> np.ndarray:
    """Q = Gamma q Gamma^T (eq. 3.32), q = sigma_acc^2 I3 (m/s^2) per spacecraft, block diagonal."""
    blocks = [s * s * snc_gamma(dt) @ snc_gamma(dt).T for s in np.atleast_1d(sigma_acc)]
    return block_diag(*blocks)


def _spd_inverse(A: np.ndarray) -> np.ndarray:
    L = np.linalg.cholesky(0.5 * (A + A.T))
    Li = np.linalg.inv(L)
    return Li.T @ Li


def fisher_step(J: np.ndarray, Phi: np.ndarray, H: np.ndarray, R_inv: np.ndarray,
                Q: np.ndarray | None = None) -> np.ndarray:
    """One recursion of eq. 3.31 (3.30 when Q is None): J_{k-1} -> J_k.

    H (m, n) at t_k w.r.t. the state at t_k; R_inv (m, m) or (m,) diagonal weights.
    """
    P_bar = Phi @ _spd_inverse(J) @ Phi.T
    if Q is not None:
        P_bar = P_bar + Q
    W = np.diag(R_inv) if np.ndim(R_inv) == 1 else R_inv
    return _spd_inverse(P_bar) + H.T @ W @ H


def crlb_history(P0: np.ndarray, Phis, Hs, R_invs, Qs=None) -> np.ndarray:
    """CRLB covariances P*_k = J_k^-1 after each epoch k = 1..K: (K, n, n).

    Phis[k]: Phi(t_k, t_{k-1}); Hs[k], R_invs[k]: rows at t_k (may have 0 rows);
    Qs[k]: process noise over (t_{k-1}, t_k] or None.
    """
    J = _spd_inverse(P0)
    out = []
    for k in range(len(Phis)):
        J = fisher_step(J, Phis[k], Hs[k], R_invs[k], None if Qs is None else Qs[k])
        out.append(_spd_inverse(J))
    return np.array(out)
