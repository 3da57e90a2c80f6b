"""Spherical-harmonic gravity: acceleration and its gradient in the body-fixed frame.

Cunningham's solid-harmonic recursion written for fully normalized functions
V_nm, W_nm (potential U = GM/R * sum C_nm V_nm + S_nm W_nm, V_00 = R/r); the
normalized recursion is stable to degree several hundred outside the body.
First derivatives of V_nm, W_nm are linear combinations of degree n+1 terms
(:func:`_derivative`), so each acceleration component is a fixed linear
combination of the V, W of degrees <= N+1, and each gradient element one of the
V, W of degrees <= Np+2 (Np <= N the degree of the partials). Those combinations'
coefficients depend on the field only: :func:`field_table` computes them once
per field. V_nm and W_nm of one order obey the same recursion in n, so
V_nm + i W_nm = Q_nm P(n, m) e^(i m lambda) with one real recursion per order
(Q, scaled by P so that it needs one factor per entry) and e^(i m lambda) by
rotation. Each evaluation sweeps degree by degree: Q of every order (a loop over
m that vectorizes), then the 3 acceleration sums and, to degree Np+2, the 6
gradient sums, against the table's rows; nothing is allocated.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def recursion_factors(nmax: int) -> np.ndarray:
    """Factors (7, nmax+3, nmax+3), indexed [k, m, n], of the normalized recursion and derivative rules."""
    size = nmax + 3
    f = np.zeros((7, size, size))
    for n in range(size):
        for m in range(n + 1):
            if n >= 1 and m < n:
                f[0, m, n] = np.sqrt((2 * n + 1) * (2 * n - 1) / ((n - m) * (n + m)))
                if n >= 2:
                    f[1, m, n] = np.sqrt((2 * n + 1) * (n + m - 1) * (n - m - 1)
                                         / ((2 * n - 3) * (n + m) * (n - m)))
            if n >= 1 and m == n:
                f[2, n, n] = np.sqrt((2 * n + 1) / (2 * n) * (2.0 if n == 1 else 1.0))
            k = (2 * n + 1) / (2 * n + 3)
            if m == 0:
                f[3, m, n] = np.sqrt(k * (n + 1) * (n + 2) / 2.0)
            else:
                f[3, m, n] = 0.5 * np.sqrt(k * (n + m + 1) * (n + m + 2))
                f[4, m, n] = 0.5 * np.sqrt(k * (n - m + 2) * (n - m + 1) * (2.0 if m == 1 else 1.0))
            f[5, m, n] = np.sqrt(k * (n + m + 1) * (n - m + 1))
    return f


def _derivative(axis: int, a: np.ndarray, b: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The functional sum a V + b W ([n, m], degrees <= N) differentiated along x, y or z (times R).

    Returns (a', b') over degrees <= N+1 with R d/d axis (sum a V + b W) = sum a' V + b' W, the
    adjoint of the normalized derivative rules (Cunningham):
    R dV_nm/dz = -f5 V_n+1,m, R dW_nm/dz = -f5 W_n+1,m; R dV_n0/dx = -f3 V_n+1,1,
    R dV_n0/dy = -f3 W_n+1,1; m > 0: R dV_nm/dx = -f3 V_n+1,m+1 + f4 V_n+1,m-1,
    R dV_nm/dy = -f3 W_n+1,m+1 - f4 W_n+1,m-1, R dW_nm/dx = -f3 W_n+1,m+1 + f4 W_n+1,m-1,
    R dW_nm/dy = f3 V_n+1,m+1 + f4 V_n+1,m-1 (f3, f4, f5 of (m, n) from :func:`recursion_factors`).
    """
    N = a.shape[0] - 1
    a2 = np.zeros((N + 2, N + 2))
    b2 = np.zeros((N + 2, N + 2))
    for n in range(N + 1):
        m = np.arange(n + 1)
        p, q, s = f[3, m, n], f[4, m, n], f[5, m, n]
        if axis == 2:
            a2[n + 1, m] -= s * a[n, m]
            b2[n + 1, m] -= s * b[n, m]
            continue
        k = m[1:]
        pk, qk = p[1:], q[1:]
        if axis == 0:
            a2[n + 1, 1] -= p[0] * a[n, 0]
            a2[n + 1, k + 1] -= pk * a[n, k]
            a2[n + 1, k - 1] += qk * a[n, k]
            b2[n + 1, k + 1] -= pk * b[n, k]
            b2[n + 1, k - 1] += qk * b[n, k]
        else:
            b2[n + 1, 1] -= p[0] * a[n, 0]
            b2[n + 1, k + 1] -= pk * a[n, k]
            b2[n + 1, k - 1] -= qk * a[n, k]
            a2[n + 1, k + 1] += pk * b[n, k]
            a2[n + 1, k - 1] += qk * b[n, k]
    return a2, b2


# rows of the packed table (see field_table): the recursion factor c of (n, m) (the sectoral factor f2 of m
# at n = m), then the coefficients of V, W in R^2/GM a_x, a_y, a_z and in R^3/GM of the gradient's xx, xy,
# xz, yy, yz, zz, each times the column's scale P(n, m) (see field_table)
REC = 0
ACC = 1  # a_x: rows ACC (V), ACC+1 (W); a_y: ACC+2, ACC+3; a_z: ACC+4, ACC+5
GRAD = 7  # gradient element e in GRAD_ELEMENTS: rows GRAD + 2e (V), GRAD + 2e + 1 (W)
GRAD_ELEMENTS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
ROWS = GRAD + 2 * len(GRAD_ELEMENTS)


def field_table(C: np.ndarray, S: np.ndarray, nmax: int, ngrad: int) -> np.ndarray:
    """Packed table T (ROWS, npairs) of a field for :func:`sh_acceleration`.

    ``C``, ``S`` [n, m] (a GravityField's), used to degree ``nmax``, the gradient to degree
    ``ngrad`` (-1: none); the central term C00 is included and degree 1 skipped (centre of mass
    origin). Entry (n, m), m <= n <= ntop = max(nmax+1, ngrad+2), is column n(n+1)/2 + m: degree
    by degree, order contiguous. The kernel's recursion runs on Q_nm, V_nm + i W_nm = Q_nm P(n, m)
    e^(i m lambda), with P(n, m) the product of the normalized factors f0 of (k, m), m < k <= n:
    Q_nm = z' Q_n-1,m - r'^2 c Q_n-2,m (z' = zR/r^2, r' = R/r) with one factor per entry,
    c = (n-1-m)(n-1+m) / ((2n-1)(2n-3)) = 1 / f0(n-1, m)^2 (f2 of m at n = m, the sectoral step).
    P(n, m) < 1e62 to degree 205; the coefficient rows carry it.
    """
    ntop = max(nmax + 1, ngrad + 2)
    f = recursion_factors(ntop)
    a = np.zeros((nmax + 1, nmax + 1))
    b = np.zeros_like(a)
    a[2:, :] = np.tril(np.asarray(C, float)[2:nmax + 1, :nmax + 1], 2)
    b[2:, :] = np.tril(np.asarray(S, float)[2:nmax + 1, :nmax + 1], 2)
    a[0, 0] = C[0][0]
    funcs = [_derivative(axis, a, b, f) for axis in range(3)]
    if ngrad >= 0:
        first = [_derivative(axis, a[: ngrad + 1, : ngrad + 1], b[: ngrad + 1, : ngrad + 1], f) for axis in range(3)]
        funcs += [_derivative(i, *first[j], f) for i, j in GRAD_ELEMENTS]
    T = np.zeros((ROWS, (ntop + 1) * (ntop + 2) // 2))
    scale = np.ones(ntop + 1)  # P(n, m) for the current n, all m <= n
    for n in range(ntop + 1):
        m = np.arange(n + 1)
        cols = n * (n + 1) // 2 + m
        scale[:n] *= f[0, :n, n]
        T[REC, cols[:n]] = (n - 1 - m[:n]) * (n - 1 + m[:n]) / ((2 * n - 1) * (2 * n - 3))
        T[REC, cols[n]] = f[2, n, n]
        for i, (fa, fb) in enumerate(funcs):
            if n < fa.shape[0]:
                T[ACC + 2 * i, cols] = fa[n, : n + 1] * scale[: n + 1]
                T[ACC + 2 * i + 1, cols] = fb[n, : n + 1] * scale[: n + 1]
    return T


def workspace(nmax: int, ngrad: int) -> np.ndarray:
    """Scratch array for :func:`sh_acceleration` up to degree ``nmax``, gradient degree ``ngrad``."""
    return np.zeros(6 * (max(nmax + 1, ngrad + 2) + 1) + 9)


@njit(cache=True)
def _degree(n, b, zr, rr, hr, T, q1, q2, cm, sm, V, W):
    """Degree n >= 1 from degree n-1 (q1) and n-2 (q2, overwritten): Q of orders m < n by the
    recursion, the sectoral Q_nn from Q_n-1,n-1; then V, W [m <= n] = Q (cos, sin)(m lambda)."""
    for m in range(n):
        q2[m] = zr * q1[m] - rr * T[REC, np.uint64(b + m)] * q2[m]
    q2[n] = T[REC, np.uint64(b + n)] * hr * q1[n - 1]
    q1[n] = 0.0  # Q of degree n-1 at order n: starts that order's recursion at degree n+1
    for m in range(n + 1):
        V[m] = q2[m] * cm[m]
        W[m] = q2[m] * sm[m]


@njit(cache=True, fastmath={"reassoc", "contract"})
def _series(T, row, b, n, V, W):
    """Three sums over orders m <= n at degree n (table columns from b): T[row + 2k] V + T[row + 2k + 1] W,
    k = 0, 1, 2.

    Reassociated (fastmath) so that the sums vectorize; tested within 1e-12 of ordered sums.
    """
    x = y = z = 0.0
    for m in range(n + 1):
        i = np.uint64(b + m)
        v, w = V[m], W[m]
        x += T[np.uint64(row), i] * v + T[np.uint64(row + 1), i] * w
        y += T[np.uint64(row + 2), i] * v + T[np.uint64(row + 3), i] * w
        z += T[np.uint64(row + 4), i] * v + T[np.uint64(row + 5), i] * w
    return x, y, z


@njit(cache=True)
def sh_acceleration(r_bf, gm, radius, T, nmax, ngrad, work, acc, grad):
    """Acceleration (m/s^2) into ``acc`` and, when ngrad >= 0, its gradient
    (1/s^2, symmetric 3x3, from degrees <= ngrad) into ``grad``, body-fixed, at ``r_bf`` (m).

    ``T`` from :func:`field_table` of the field to degree ``nmax`` with gradient degree
    ``ngrad`` (or higher); ``work`` from :func:`workspace` (or larger), so that an evaluation
    allocates nothing. Includes the central term C00; degree 1 is skipped. Degree by degree:
    Q of every order (V and W share it: V, W = Q (cos, sin)(m lambda)), then the 3 acceleration
    sums and, to degree ngrad + 2, the 6 gradient sums.
    """
    ntop = nmax + 1 if ngrad < 0 else max(nmax + 1, ngrad + 2)
    x, y, z = r_bf[0], r_bf[1], r_bf[2]
    r2 = x * x + y * y + z * z
    rho = radius / r2
    h = np.sqrt(x * x + y * y)
    cl, sl = (x / h, y / h) if h > 0.0 else (1.0, 0.0)
    size = ntop + 1
    q1 = work[0:size]
    q2 = work[size: 2 * size]
    cm = work[2 * size: 3 * size]
    sm = work[3 * size: 4 * size]
    V = work[4 * size: 5 * size]
    W = work[5 * size: 6 * size]
    sums = work[6 * size: 6 * size + 9]  # R^2/GM a_x, a_y, a_z, R^3/GM the gradient elements
    sums[:] = 0.0
    q1[0] = radius / np.sqrt(r2)
    q2[0] = 0.0
    cm[0], sm[0] = 1.0, 0.0
    zr, rr, hr = z * rho, radius * rho, h * rho
    for n in range(1, ntop + 1):  # degree 0 adds nothing: its rows are zero
        cm[n] = cm[n - 1] * cl - sm[n - 1] * sl
        sm[n] = sm[n - 1] * cl + cm[n - 1] * sl
        b = n * (n + 1) // 2
        _degree(n, b, zr, rr, hr, T, q1, q2, cm, sm, V, W)
        q1, q2 = q2, q1
        for k in range(3 if n <= ngrad + 2 else 1):  # acceleration, then the gradient's two halves
            s0, s1, s2 = _series(T, ACC + 6 * k, b, n, V, W)
            sums[3 * k] += s0
            sums[3 * k + 1] += s1
            sums[3 * k + 2] += s2
    c = gm / (radius * radius)
    for i in range(3):
        acc[i] = c * sums[i]
    if ngrad < 0:
        return
    c /= radius
    for e in range(len(GRAD_ELEMENTS)):
        i, j = GRAD_ELEMENTS[e]
        grad[i, j] = c * sums[3 + e]
        grad[j, i] = c * sums[3 + e]
