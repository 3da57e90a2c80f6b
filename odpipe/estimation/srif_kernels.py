"""Compiled SRIF operations (numba): Householder updates, innovations, and a filter pass over grid intervals.

The Householder reflections are LAPACK's (``dlarfg``: ``beta = -sign(alpha) |(alpha, x)|``), so an
information array comes out as :func:`.srif.triangularize` gives it, up to rounding. A pass over the
intervals of a stretch without process noise (:func:`filter_intervals`) runs in one compiled loop: per
interval, the information array at its start is kept, its rows are tested against the filter's
prediction (innovation k-sigma test) and absorbed, and the array is mapped to the next epoch.

A transition ``[[M, Q], [0, I]]`` (a spacecraft's state rows first, constant parameters after) changes only
the first rows of a triangular array, and the smoother's arrays ``R Phi...`` leave the triangle only there:
the reflections then run over those rows alone (:func:`mapped`, :func:`stacked_triangles`).
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def householder(A, ncols, below):
    """Triangularize the first ``ncols`` columns of ``A`` (m, c) in place by Householder reflections applied
    to every column; below-diagonal entries of those columns are set to zero. Rows above ``below`` are
    taken to be zero below the diagonal already (a triangle with rows appended: ``below`` its row count;
    0 for none), so the reflections skip them."""
    m, c = A.shape
    for j in range(min(ncols, m)):
        first = max(j + 1, below)
        xnorm2 = 0.0
        for i in range(first, m):
            xnorm2 += A[i, j] * A[i, j]
        if xnorm2 == 0.0:
            continue
        alpha = A[j, j]
        beta = -np.copysign(np.sqrt(alpha * alpha + xnorm2), alpha)
        tau = (beta - alpha) / beta
        scale = 1.0 / (alpha - beta)
        for i in range(first, m):
            A[i, j] *= scale
        A[j, j] = beta
        for col in range(j + 1, c):
            w = A[j, col]
            for i in range(first, m):
                w += A[i, j] * A[i, col]
            w *= tau
            A[j, col] -= w
            for i in range(first, m):
                A[i, col] -= w * A[i, j]
        for i in range(first, m):
            A[i, j] = 0.0


@numba.njit(cache=True)
def upper_inverse(R):
    """Inverse of an upper-triangular matrix by back substitution; raises on a zero diagonal."""
    n = R.shape[0]
    X = np.zeros((n, n))
    for j in range(n):
        if R[j, j] == 0.0:
            raise np.linalg.LinAlgError("singular square-root information matrix")
    for j in range(n - 1, -1, -1):
        X[j, j] = 1.0 / R[j, j]
        for i in range(j - 1, -1, -1):
            s = 0.0
            for k in range(i + 1, j + 1):
                s += R[i, k] * X[k, j]
            X[i, j] = -s / R[i, i]
    return X


@numba.njit(cache=True)
def innovations(R, z, H, y, sigma, use, n_est, c_bar, c_sigma, nu, s):
    """Into ``nu``, ``s`` (rows with ``use``): ``y - H x`` and ``sqrt(H P H^T + sigma^2)``, x and P from the
    triangular array ``[R | z]`` with the consider parameters (the last ``n - n_est``) at their a priori
    ``c_bar``, ``c_sigma`` (P includes their effect)."""
    n = R.shape[0]
    Rinv = upper_inverse(R[:n_est, :n_est])
    x = np.empty(n)
    if n_est == n:
        x[:] = Rinv @ z
        for i in range(H.shape[0]):
            if use[i]:
                g = H[i] @ Rinv
                nu[i] = y[i] - H[i] @ x
                s[i] = np.sqrt(g @ g + sigma[i] ** 2)
        return
    Rec = np.ascontiguousarray(R[:n_est, n_est:])
    x[:n_est] = Rinv @ (z[:n_est] - Rec @ c_bar)
    x[n_est:] = c_bar
    S = Rinv @ Rec                          # -d(x_e)/d(c)
    c2 = c_sigma ** 2
    for i in range(H.shape[0]):
        if use[i]:
            he, hc = np.ascontiguousarray(H[i, :n_est]), H[i, n_est:]
            g = he @ Rinv
            a = hc - he @ S                 # d(h x)/d(c) with x_e following c
            nu[i] = y[i] - H[i] @ x
            s[i] = np.sqrt(g @ g + np.sum(a * a * c2) + sigma[i] ** 2)


@numba.njit(cache=True)
def absorb(R, z, H, y, w):
    """Rows ``H dx = y`` weighted by ``w`` (1/sigma) into ``[R | z]``: new (R, z) and the whitened residual
    sum of squares they add."""
    n, m = R.shape[0], H.shape[0]
    A = np.empty((n + m, n + 1))
    A[:n, :n] = R
    A[:n, n] = z
    for i in range(m):
        for j in range(n):
            A[n + i, j] = H[i, j] * w[i]
        A[n + i, n] = y[i] * w[i]
    householder(A, n, n)
    e2 = 0.0
    for i in range(n, n + m):
        e2 += A[i, n] * A[i, n]
    return A[:n, :n].copy(), A[:n, n].copy(), e2


@numba.njit(cache=True)
def dynamic_rows(Phi):
    """Rows of ``Phi`` (n, n) up to the last that differs from the identity's: ``d`` with
    ``Phi = [[M, Q], [0, I]]``, M (d, d)."""
    n = Phi.shape[0]
    for i in range(n - 1, -1, -1):
        for j in range(n):
            if Phi[i, j] != (1.0 if i == j else 0.0):
                return i + 1
    return 0


@numba.njit(cache=True)
def unreduced_rows(A):
    """Rows of ``A`` (m, c) up to the last with a nonzero left of its diagonal: rows from the count on are
    already upper triangular."""
    for i in range(A.shape[0] - 1, 0, -1):
        for j in range(min(i, A.shape[1])):
            if A[i, j] != 0.0:
                return i + 1
    return 0


@numba.njit(cache=True)
def mapped(R, z, Phi):
    """``[R | z]`` of ``dx+ = Phi dx``: ``R Phi^-1`` re-triangularized. With ``Phi = [[M, Q], [0, I]]``
    (:func:`dynamic_rows` d < n) only R's first d rows change, to ``[R11 M^-1, R12 - R11 M^-1 Q]``, and
    reflections over those rows restore the triangle (O(d^2 n)); otherwise LAPACK gesv and a full pass."""
    n = R.shape[0]
    d = dynamic_rows(Phi)
    A = np.empty((n, n + 1))
    A[:, n] = z
    if d == n:
        A[:, :n] = np.linalg.solve(Phi.T, R.T).T
        householder(A, n, 0)
    else:
        A[:, :n] = R
        if d > 0:
            B = np.linalg.solve(np.ascontiguousarray(Phi[:d, :d].T), np.ascontiguousarray(R[:d, :d].T)).T
            A[:d, :d] = B
            A[:d, d:n] = R[:d, d:] - B @ np.ascontiguousarray(Phi[:d, d:])
            householder(A[:d], d, 0)
    return A[:, :n].copy(), A[:, n].copy()


@numba.njit(cache=True)
def stacked_triangles(R, z):
    """K information arrays ``[R | z]`` (K, m, n), (K, m) triangularized (K, m, n + 1), each reflected over
    its :func:`unreduced_rows` only (none for the filter's triangular arrays, the first d for the smoother's
    ``R Phi...``)."""
    K, m, n = R.shape
    T = np.empty((K, m, n + 1))
    for k in range(K):
        T[k, :, :n] = R[k]
        T[k, :, n] = z[k]
        householder(T[k, :unreduced_rows(T[k])], n, 0)
    return T


@numba.njit(cache=True)
def stacked_upper_solve(T, b):
    """x (K, n) of ``T[k] x[k] = b[k]``, T (K, n, n) upper triangular, by back substitution."""
    K, n = b.shape
    x = np.empty((K, n))
    for k in range(K):
        for i in range(n - 1, -1, -1):
            if T[k, i, i] == 0.0:
                raise np.linalg.LinAlgError("singular square-root information matrix")
            s = b[k, i]
            for j in range(i + 1, n):
                s -= T[k, i, j] * x[k, j]
            x[k, i] = s / T[k, i, i]
    return x


@numba.njit(cache=True)
def stacked_upper_inverse(T):
    """:func:`upper_inverse` of K upper-triangular matrices (K, n, n)."""
    out = np.empty(T.shape)
    for k in range(T.shape[0]):
        out[k] = upper_inverse(T[k])
    return out


@numba.njit(cache=True)
def filter_intervals(R, z, Phi, H, y, sigma, use, edit_y, bounds, edit_k, n_est, c_bar, c_sigma):
    """K grid intervals without process noise: per interval k, keep ``[R | z]`` (its start), test its rows
    ``bounds[k]:bounds[k+1]`` (those with ``use``) against the prediction (edited when ``|nu| > edit_k s``
    and, with ``edit_y``, ``|y| > edit_k sigma``), absorb the others, and map by ``Phi[k]``.

    Returns (R at the starts (K, n, n), z at the starts (K, n), R and z at the end, nu, s, edited, chi2)."""
    K, n, m = Phi.shape[0], R.shape[0], y.size
    Rs, zs = np.empty((K, n, n)), np.empty((K, n))
    nu, s = np.full(m, np.nan), np.full(m, np.nan)
    bad = np.zeros(m, np.bool_)
    chi2 = 0.0
    for k in range(K):
        Rs[k], zs[k] = R, z
        lo, hi = bounds[k], bounds[k + 1]
        if hi > lo:
            innovations(R, z, H[lo:hi], y[lo:hi], sigma[lo:hi], use[lo:hi], n_est, c_bar, c_sigma, nu[lo:hi],
                        s[lo:hi])
            keep = np.zeros(hi - lo, np.bool_)
            for i in range(lo, hi):
                if use[i]:
                    bad[i] = np.abs(nu[i]) > edit_k * s[i] and (not edit_y or np.abs(y[i]) > edit_k * sigma[i])
                    keep[i - lo] = not bad[i]
            if keep.any():
                rows = np.flatnonzero(keep) + lo
                R, z, e2 = absorb(R, z, H[rows], y[rows], 1.0 / sigma[rows])
                chi2 += e2
        R, z = mapped(R, z, Phi[k])
    return Rs, zs, R, z, nu, s, bad, chi2


@numba.njit(cache=True)
def backward_maps(R, Phi):
    """Smoother over K maps ``dx+ = Phi[k] dx`` from the array ``R`` after the last: ``R Phi[K-1] ... Phi[k]``
    for every k, (K, n, n)."""
    K, n = Phi.shape[0], R.shape[0]
    out = np.empty((K, n, n))
    cur = R.copy()
    for k in range(K - 1, -1, -1):
        cur = cur @ Phi[k]
        out[k] = cur
    return out
