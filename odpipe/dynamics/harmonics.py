"""Spherical-harmonic gravity: acceleration and its gradient in the body-fixed frame.

Cunningham's solid-harmonic recursion written for fully normalized functions
V_nm, W_nm (potential U = GM/R * sum C_nm V_nm + S_nm W_nm, V_00 = R/r); the
normalized recursion is stable to degree several hundred outside the body.
First derivatives of V_nm, W_nm are linear combinations of degree n+1 terms
(:func:`_derivative`), so each acceleration component is a fixed linear
combination of the V, W of degrees <= N+1, and each gradient element one of the
V, W of degrees <= Np+2 (Np <= N the degree of the partials). Those combinations'
coefficients depend on the field only: :func:`field_table` computes them once
per field, and each evaluation builds V, W column by column (order m, four
independent recursions at a time, no table of V, W kept) and sums every column
against its coefficients in one pass: 3 acceleration and 6 gradient components.
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


# rows of the packed table (see field_table): sectoral and recursion factors f2, f0, f1 of (m, n),
# then the coefficients of V, W in R^2/GM a_x, a_y, a_z and in R^3/GM of the gradient's xx, xy, xz, yy, yz, zz
RS, RA, RB = 0, 1, 2
ACC = 3  # a_x: rows ACC, ACC+1 (V, W); a_y: ACC+2, ACC+3; a_z: ACC+4, ACC+5
GRAD = 9  # gradient element e in GRAD_ELEMENTS: rows GRAD + 2e (V), GRAD + 2e + 1 (W)
GRAD_ELEMENTS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
ROWS = GRAD + 2 * len(GRAD_ELEMENTS)
# V rows of the acceleration and of the gradient sums (arrays, not literal ints: one compiled signature)
ACC_ROWS = np.arange(ACC, GRAD, 2)
GRAD_ROWS = np.arange(GRAD, ROWS, 2)


def field_table(C: np.ndarray, S: np.ndarray, nmax: int, ngrad: int) -> tuple[np.ndarray, np.ndarray]:
    """Packed table of a field for :func:`sh_acceleration`: (start (ntop+2,) int64, T (ROWS, npairs)).

    ``C``, ``S`` [n, m] (a GravityField's), used to degree ``nmax``, the gradient to degree
    ``ngrad`` (-1: none); the central term C00 is included and degree 1 skipped (centre of mass
    origin). Entry (m, n), m <= n <= ntop = max(nmax+1, ngrad+2), is column ``start[m] + n - m``:
    order by order, degree contiguous, so each column's sums read every row of T as one stream.
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
    start = np.zeros(ntop + 2, dtype=np.int64)
    for m in range(ntop + 1):
        start[m + 1] = start[m] + ntop - m + 1
    T = np.zeros((ROWS, start[-1]))
    for m in range(ntop + 1):
        n = np.arange(m, ntop + 1)
        cols = start[m] + n - m
        T[RS, cols[0]] = f[2, m, m]
        T[RA, cols], T[RB, cols] = f[0, m, n], f[1, m, n]
        for i, (fa, fb) in enumerate(funcs):
            if m >= fa.shape[0]:
                continue
            inside = n < fa.shape[0]
            T[ACC + 2 * i, cols[inside]] = fa[n[inside], m]
            T[ACC + 2 * i + 1, cols[inside]] = fb[n[inside], m]
    return start, T


BLOCK = 4  # columns built together: independent recursions the CPU overlaps


@njit(cache=True)
def _step(k, j, n, start, T, zr, rr, Vb, Wb):
    """V, W of degree n in column k (buffer row j, degree n at index n + 1) from degrees n-1 and n-2."""
    i = np.uint64(start[k] + n - k)
    a = T[RA, i] * zr
    b = T[RB, i] * rr
    Vb[j, n + 1] = a * Vb[j, n] - b * Vb[j, n - 1]
    Wb[j, n + 1] = a * Wb[j, n] - b * Wb[j, n - 1]


@njit(cache=True)
def _columns(k0, k1, ntop, start, T, zr, rr, Vs, Ws, Vb, Wb):
    """Columns k0 <= k < k1 (at most BLOCK) of V, W, degrees k..ntop, into buffer rows k - k0
    (degree n at index n + 1).

    Starts from the sectorals Vs, Ws; f1 of (k, k+1) is 0, so degree k-1 (set to 0) starts
    each column. A full block's four recursions run in registers, interleaved.
    """
    for k in range(k0, k1):
        Vb[k - k0, k + 1] = Vs[k]
        Wb[k - k0, k + 1] = Ws[k]
        Vb[k - k0, k] = 0.0
        Wb[k - k0, k] = 0.0
    n0 = min(k0 + BLOCK, ntop + 1)
    for n in range(k0 + 1, n0):  # the staircase: column k starts at n = k + 1
        for k in range(k0, min(k1, n)):
            _step(k, k - k0, n, start, T, zr, rr, Vb, Wb)
    if k1 - k0 < BLOCK:
        for n in range(n0, ntop + 1):
            for k in range(k0, k1):
                _step(k, k - k0, n, start, T, zr, rr, Vb, Wb)
        return
    v0, v1, v2, v3 = Vb[0, n0], Vb[1, n0], Vb[2, n0], Vb[3, n0]
    u0, u1, u2, u3 = Vb[0, n0 - 1], Vb[1, n0 - 1], Vb[2, n0 - 1], Vb[3, n0 - 1]
    w0, w1, w2, w3 = Wb[0, n0], Wb[1, n0], Wb[2, n0], Wb[3, n0]
    x0, x1, x2, x3 = Wb[0, n0 - 1], Wb[1, n0 - 1], Wb[2, n0 - 1], Wb[3, n0 - 1]
    i0, i1, i2, i3 = start[k0] - k0, start[k0 + 1] - k0 - 1, start[k0 + 2] - k0 - 2, start[k0 + 3] - k0 - 3
    for n in range(n0, ntop + 1):
        a0, b0 = T[RA, np.uint64(i0 + n)] * zr, T[RB, np.uint64(i0 + n)] * rr
        a1, b1 = T[RA, np.uint64(i1 + n)] * zr, T[RB, np.uint64(i1 + n)] * rr
        a2, b2 = T[RA, np.uint64(i2 + n)] * zr, T[RB, np.uint64(i2 + n)] * rr
        a3, b3 = T[RA, np.uint64(i3 + n)] * zr, T[RB, np.uint64(i3 + n)] * rr
        v0, u0, w0, x0 = a0 * v0 - b0 * u0, v0, a0 * w0 - b0 * x0, w0
        v1, u1, w1, x1 = a1 * v1 - b1 * u1, v1, a1 * w1 - b1 * x1, w1
        v2, u2, w2, x2 = a2 * v2 - b2 * u2, v2, a2 * w2 - b2 * x2, w2
        v3, u3, w3, x3 = a3 * v3 - b3 * u3, v3, a3 * w3 - b3 * x3, w3
        un = np.uint64(n + 1)
        Vb[0, un], Vb[1, un], Vb[2, un], Vb[3, un] = v0, v1, v2, v3
        Wb[0, un], Wb[1, un], Wb[2, un], Wb[3, un] = w0, w1, w2, w3


@njit(cache=True, fastmath={"reassoc", "contract"})
def _column_sums(k, n1, rows, start, T, V, W, out):
    """Add sum over degrees k..n1 of T[row] V + T[row+1] W, for the V rows ``rows``, to out[0 .. len(rows)).

    Reassociated (fastmath) so that the sums vectorize; tested within 1e-12 of ordered sums.
    """
    i0 = start[k] - k
    for e in range(rows.shape[0]):
        ra = np.uint64(rows[e])
        rb = np.uint64(rows[e] + 1)
        total = 0.0
        for n in range(k, n1 + 1):
            i = np.uint64(i0 + n)
            un = np.uint64(n)
            total += T[ra, i] * V[un] + T[rb, i] * W[un]
        out[e] += total


def workspace(nmax: int, ngrad: int) -> np.ndarray:
    """Scratch array for :func:`sh_acceleration` up to degree ``nmax``, gradient degree ``ngrad``."""
    ntop = max(nmax + 1, ngrad + 2)
    return np.zeros(2 * (ntop + 1) + 2 * BLOCK * (ntop + 2) + 9)


@njit(cache=True)
def sh_acceleration(r_bf, gm, radius, start, T, nmax, ngrad, work, acc, grad):
    """Acceleration (m/s^2) into ``acc`` and, when ngrad >= 0, its gradient
    (1/s^2, symmetric 3x3, from degrees <= ngrad) into ``grad``, body-fixed, at ``r_bf`` (m).

    ``start``, ``T`` from :func:`field_table` of the field to degree ``nmax`` with gradient
    degree ``ngrad`` (or higher); ``work`` from :func:`workspace` (or larger), so that an
    evaluation allocates nothing. Includes the central term C00; degree 1 is skipped.
    """
    ntop = nmax + 1 if ngrad < 0 else max(nmax + 1, ngrad + 2)
    r2 = r_bf[0] ** 2 + r_bf[1] ** 2 + r_bf[2] ** 2
    rho = radius / r2
    xr, yr, zr, rr = r_bf[0] * rho, r_bf[1] * rho, r_bf[2] * rho, radius * rho
    Vs = work[: ntop + 1]  # sectorals V[k, k], W[k, k]
    Ws = work[ntop + 1: 2 * ntop + 2]
    nb = BLOCK * (ntop + 2)
    # the block's columns, degree n at index n + 1: index 0 stays 0 (column 0's degree -1)
    Vb = work[2 * ntop + 2: 2 * ntop + 2 + nb].reshape((BLOCK, ntop + 2))
    Wb = work[2 * ntop + 2 + nb: 2 * ntop + 2 + 2 * nb].reshape((BLOCK, ntop + 2))
    sums = work[2 * ntop + 2 + 2 * nb: 2 * ntop + 2 + 2 * nb + 9]  # a_x, a_y, a_z, the gradient elements
    sums[:] = 0.0
    Vb[0, 0] = 0.0
    Wb[0, 0] = 0.0
    Vs[0] = radius / np.sqrt(r2)
    Ws[0] = 0.0
    for k in range(1, ntop + 1):
        f2 = T[RS, start[k]]
        Vs[k] = f2 * (xr * Vs[k - 1] - yr * Ws[k - 1])
        Ws[k] = f2 * (xr * Ws[k - 1] + yr * Vs[k - 1])
    g = sums[3:]
    for k0 in range(0, ntop + 1, BLOCK):
        k1 = min(k0 + BLOCK, ntop + 1)
        _columns(k0, k1, ntop, start, T, zr, rr, Vs, Ws, Vb, Wb)
        for k in range(k0, k1):
            V, W = Vb[k - k0, 1:], Wb[k - k0, 1:]
            _column_sums(k, min(nmax + 1, ntop), ACC_ROWS, start, T, V, W, sums)
            if k <= ngrad + 2:
                _column_sums(k, ngrad + 2, GRAD_ROWS, start, T, V, W, g)
    c = gm / (radius * radius)
    for i in range(3):
        acc[i] = c * sums[i]
    if ngrad < 0:
        return
    c /= radius
    for e in range(len(GRAD_ELEMENTS)):
        i, j = GRAD_ELEMENTS[e]
        grad[i, j] = c * g[e]
        grad[j, i] = c * g[e]
