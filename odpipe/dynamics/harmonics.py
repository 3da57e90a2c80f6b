"""Spherical-harmonic gravity: acceleration and its gradient in the body-fixed frame.

Cunningham's solid-harmonic recursion written for fully normalized functions
V_nm, W_nm (potential U = GM/R * sum C_nm V_nm + S_nm W_nm, V_00 = R/r); the
normalized recursion is stable to degree several hundred outside the body.
First derivatives of V_nm, W_nm are linear combinations of degree n+1 terms
and second derivatives apply the same rule to the first-derivative arrays, so
acceleration needs degree N+1 and the gradient (for the STM) degree Np+2,
with Np <= N the (possibly lower) degree of the partials. The acceleration
sweeps the orders m one column at a time (three columns of V, W in memory);
the gradient uses full (Np+3)^2 tables.
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


def by_order(C: np.ndarray) -> np.ndarray:
    """Coefficients [n, m] of a GravityField re-stored as [m, n] for the kernels."""
    return np.ascontiguousarray(np.asarray(C).T)


@njit(cache=True)
def solid_harmonics(x, y, z, radius, nmax, f, V, W):
    """Fill normalized V[n, m], W[n, m] for n <= nmax at body-fixed (x, y, z) m."""
    r2 = x * x + y * y + z * z
    rho = radius / r2
    xr, yr, zr, rr = x * rho, y * rho, z * rho, radius * rho
    V[0, 0] = radius / np.sqrt(r2)
    W[0, 0] = 0.0
    for n in range(1, nmax + 1):
        for m in range(n):
            v = f[0, m, n] * zr * V[n - 1, m]
            w = f[0, m, n] * zr * W[n - 1, m]
            if n >= 2 and m <= n - 2:
                v -= f[1, m, n] * rr * V[n - 2, m]
                w -= f[1, m, n] * rr * W[n - 2, m]
            V[n, m] = v
            W[n, m] = w
        V[n, n] = f[2, n, n] * (xr * V[n - 1, n - 1] - yr * W[n - 1, n - 1])
        W[n, n] = f[2, n, n] * (xr * W[n - 1, n - 1] + yr * V[n - 1, n - 1])


@njit(cache=True)
def _derivatives(nmax, f, radius, V, W, Vx, Vy, Vz, Wx, Wy, Wz):
    """First derivatives (1/m) of V, W for n <= nmax from degree n+1 terms."""
    for n in range(nmax + 1):
        for m in range(n + 1):
            p = f[3, m, n] / radius
            q = f[4, m, n] / radius
            s = f[5, m, n] / radius
            Vz[n, m] = -s * V[n + 1, m]
            Wz[n, m] = -s * W[n + 1, m]
            if m == 0:
                Vx[n, 0] = -p * V[n + 1, 1]
                Vy[n, 0] = -p * W[n + 1, 1]
                Wx[n, 0] = 0.0
                Wy[n, 0] = 0.0
            else:
                Vx[n, m] = -p * V[n + 1, m + 1] + q * V[n + 1, m - 1]
                Vy[n, m] = -p * W[n + 1, m + 1] - q * W[n + 1, m - 1]
                Wx[n, m] = -p * W[n + 1, m + 1] + q * W[n + 1, m - 1]
                Wy[n, m] = p * V[n + 1, m + 1] + q * V[n + 1, m - 1]


@njit(cache=True)
def _contract(nmax, C, S, A, B):
    """sum over n <= nmax (from degree 2 up, plus n=0) of C*A + S*B."""
    total = C[0, 0] * A[0, 0]
    for n in range(2, nmax + 1):
        for m in range(n + 1):
            total += C[m, n] * A[n, m] + S[m, n] * B[n, m]
    return total


@njit(cache=True)
def _column(m, ntop, f, xr, yr, zr, rr, v_diag, w_diag, Vc, Wc):
    """Column m of V, W (n = m..ntop) from the diagonal V, W[m-1, m-1] (or V_00 for m = 0)."""
    if m == 0:
        Vc[0] = v_diag
        Wc[0] = 0.0
    else:
        Vc[m] = f[2, m, m] * (xr * v_diag - yr * w_diag)
        Wc[m] = f[2, m, m] * (xr * w_diag + yr * v_diag)
    for n in range(m + 1, ntop + 1):
        Vc[n] = f[0, m, n] * zr * Vc[n - 1]
        Wc[n] = f[0, m, n] * zr * Wc[n - 1]
        if n >= m + 2:
            Vc[n] -= f[1, m, n] * rr * Vc[n - 2]
            Wc[n] -= f[1, m, n] * rr * Wc[n - 2]


@njit(cache=True)
def _acceleration(r_bf, gm, radius, C, S, nmax, f, acc):
    """Acceleration only, sweeping V, W one order m at a time (three columns in memory)."""
    ntop = nmax + 1
    r2 = r_bf[0] ** 2 + r_bf[1] ** 2 + r_bf[2] ** 2
    rho = radius / r2
    xr, yr, zr, rr = r_bf[0] * rho, r_bf[1] * rho, r_bf[2] * rho, radius * rho
    Vp = np.zeros(ntop + 1)
    Wp = np.zeros(ntop + 1)
    Vm = np.zeros(ntop + 1)
    Wm = np.zeros(ntop + 1)
    Vn = np.zeros(ntop + 1)
    Wn = np.zeros(ntop + 1)
    _column(0, ntop, f, xr, yr, zr, rr, radius / np.sqrt(r2), 0.0, Vm, Wm)
    _column(1, ntop, f, xr, yr, zr, rr, Vm[0], Wm[0], Vn, Wn)
    ax = 0.0
    ay = 0.0
    az = 0.0
    for m in range(nmax + 1):
        # one pass over n: accumulate order m (columns m-1, m, m+1 at degree n+1) and build
        # column m+2 in place of column m-1 (independent work the CPU overlaps with the recursion)
        m2 = m + 2
        f2 = f[2, m2, m2] if m2 <= ntop else 0.0
        for n in range(m, ntop + 1):
            if n >= 2 and n <= nmax:
                c = C[m, n]
                s = S[m, n]
                p = f[3, m, n]
                q = f[4, m, n]
                az -= f[5, m, n] * (c * Vm[n + 1] + s * Wm[n + 1])
                if m == 0:
                    ax -= c * p * Vn[n + 1]
                    ay -= c * p * Wn[n + 1]
                else:
                    ax += c * (q * Vp[n + 1] - p * Vn[n + 1]) + s * (q * Wp[n + 1] - p * Wn[n + 1])
                    ay -= c * (p * Wn[n + 1] + q * Wp[n + 1]) - s * (p * Vn[n + 1] + q * Vp[n + 1])
            if n == m2:
                Vp[n] = f2 * (xr * Vn[m + 1] - yr * Wn[m + 1])
                Wp[n] = f2 * (xr * Wn[m + 1] + yr * Vn[m + 1])
            elif n > m2:
                Vp[n] = f[0, m2, n] * zr * Vp[n - 1]
                Wp[n] = f[0, m2, n] * zr * Wp[n - 1]
                if n >= m2 + 2:
                    Vp[n] -= f[1, m2, n] * rr * Vp[n - 2]
                    Wp[n] -= f[1, m2, n] * rr * Wp[n - 2]
        if m == 0:  # central term C00 V00: d/dx V00 = -p00 V11 etc.
            ax -= C[0, 0] * f[3, 0, 0] * Vn[1]
            ay -= C[0, 0] * f[3, 0, 0] * Wn[1]
            az -= C[0, 0] * f[5, 0, 0] * Vm[1]
        Vp, Wp, Vm, Wm, Vn, Wn = Vm, Wm, Vn, Wn, Vp, Wp
    k = gm / (radius * radius)
    acc[0] = k * ax
    acc[1] = k * ay
    acc[2] = k * az


@njit(cache=True)
def sh_acceleration(r_bf, gm, radius, C, S, nmax, ngrad, f, acc, grad):
    """Acceleration (m/s^2) into ``acc`` and, when ngrad >= 0, its gradient
    (1/s^2, symmetric 3x3, from degrees <= ngrad) into ``grad``, body-fixed.

    ``C``, ``S`` are stored by order, [m, n] (see :func:`by_order`), ``f`` from
    :func:`recursion_factors`, so the inner loops over degree are contiguous.

    Includes the central term C00; degree 1 is skipped (centre of mass origin).
    """
    _acceleration(r_bf, gm, radius, C, S, nmax, f, acc)
    if ngrad < 0:
        return
    ntop = ngrad + 2
    size = ntop + 1
    V = np.empty((size, size))
    W = np.empty((size, size))
    solid_harmonics(r_bf[0], r_bf[1], r_bf[2], radius, ntop, f, V, W)
    nd = ntop - 1
    Vx = np.zeros((nd + 1, nd + 1))
    Vy = np.zeros_like(Vx)
    Vz = np.zeros_like(Vx)
    Wx = np.zeros_like(Vx)
    Wy = np.zeros_like(Vx)
    Wz = np.zeros_like(Vx)
    _derivatives(nd, f, radius, V, W, Vx, Vy, Vz, Wx, Wy, Wz)
    k = gm / radius
    first = ((Vx, Wx), (Vy, Wy), (Vz, Wz))
    n2 = ngrad + 1
    Ax = np.zeros((n2 + 1, n2 + 1))
    Ay = np.zeros_like(Ax)
    Az = np.zeros_like(Ax)
    Bx = np.zeros_like(Ax)
    By = np.zeros_like(Ax)
    Bz = np.zeros_like(Ax)
    for j in range(3):
        Vj, Wj = first[j]
        # derivatives of (Vj, Wj) along x, y, z, from degree n+1 of Vj, Wj
        _derivatives(ngrad, f, radius, Vj, Wj, Ax, Ay, Az, Bx, By, Bz)
        grad[0, j] = k * _contract(ngrad, C, S, Ax, Bx)
        grad[1, j] = k * _contract(ngrad, C, S, Ay, By)
        grad[2, j] = k * _contract(ngrad, C, S, Az, Bz)
