"""RTN (radial, transverse, normal) frame and the partials of a fixed-RTN vector.

R = r/|r|, N = (r x v)/|r x v|, T = N x R. For an acceleration with constant
RTN components a = aR R + aT T + aN N, :func:`rtn_acceleration` also returns
d a / d r and d a / d v, needed by the STM. Both run on scalars (no array is
allocated: they are called at every force evaluation).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _skew(a, i, k):
    """Element (i, k) of the cross-product matrix [a x] (a: 3-tuple or array)."""
    if i == k:
        return 0.0
    return a[3 - i - k] if (k - i) % 3 == 2 else -a[3 - i - k]


@njit(cache=True)
def _frame(r, v):
    """(R, T, N) unit vectors as 3-tuples, |r| (m) and |r x v| (m^2/s)."""
    h = (r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0])
    rn = np.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    hn = np.sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2])
    R = (r[0] / rn, r[1] / rn, r[2] / rn)
    N = (h[0] / hn, h[1] / hn, h[2] / hn)
    T = (N[1] * R[2] - N[2] * R[1], N[2] * R[0] - N[0] * R[2], N[0] * R[1] - N[1] * R[0])
    return R, T, N, rn, hn


@njit(cache=True)
def add_rtn_axes(r, v, rows, dadp):
    """Add the R, T, N unit vectors (ICRF) to rows ``rows[0..2]`` of ``dadp`` (a row < 0: skipped)."""
    axes = _frame(r, v)[:3]
    for c in range(3):
        if rows[c] >= 0:
            u = axes[c]
            for i in range(3):
                dadp[rows[c], i] += u[i]


@njit(cache=True)
def _projector(u, scale, i, j):
    """Element (i, j) of (I - u u^T) / scale."""
    return ((1.0 if i == j else 0.0) - u[i] * u[j]) / scale


@njit(cache=True)
def _dn_dr(N, hn, v, i, j):
    """d N / d r (i, j) = -(I - N N^T)/|h| [v x] (d h / d r = -[v x])."""
    s = 0.0
    for k in range(3):
        s -= _projector(N, hn, i, k) * _skew(v, k, j)
    return s


@njit(cache=True)
def _dn_dv(N, hn, r, i, j):
    """d N / d v (i, j) = (I - N N^T)/|h| [r x] (d h / d v = [r x])."""
    s = 0.0
    for k in range(3):
        s += _projector(N, hn, i, k) * _skew(r, k, j)
    return s


@njit(cache=True)
def rtn_acceleration(r, v, a_rtn, acc, grad_r, grad_v):
    """Add M a_rtn to ``acc`` and its partials wrt r and v to grad_r, grad_v (M: columns R, T, N)."""
    R, T, N, rn, hn = _frame(r, v)
    aR, aT, aN = a_rtn[0], a_rtn[1], a_rtn[2]
    for i in range(3):
        acc[i] += aR * R[i] + aT * T[i] + aN * N[i]
    for i in range(3):
        for j in range(3):
            dT_dr = 0.0   # [N x] dR/dr - [R x] dN/dr
            dT_dv = 0.0   # -[R x] dN/dv
            for k in range(3):
                dT_dr += _skew(N, i, k) * _projector(R, rn, k, j) - _skew(R, i, k) * _dn_dr(N, hn, v, k, j)
                dT_dv -= _skew(R, i, k) * _dn_dv(N, hn, r, k, j)
            grad_r[i, j] += aR * _projector(R, rn, i, j) + aT * dT_dr + aN * _dn_dr(N, hn, v, i, j)
            grad_v[i, j] += aT * dT_dv + aN * _dn_dv(N, hn, r, i, j)
