"""RTN (radial, transverse, normal) frame and the partials of a fixed-RTN vector.

R = r/|r|, N = (r x v)/|r x v|, T = N x R. For an acceleration with constant
RTN components a = aR R + aT T + aN N, :func:`rtn_acceleration` also returns
d a / d r and d a / d v, needed by the STM.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit(cache=True)
def _skew(a):
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


@njit(cache=True)
def rtn_axes(r, v):
    """(3, 3) matrix whose columns are the R, T, N unit vectors in ICRF."""
    h = _cross(r, v)
    R = r / np.sqrt(np.sum(r * r))
    N = h / np.sqrt(np.sum(h * h))
    T = _cross(N, R)
    M = np.empty((3, 3))
    M[:, 0], M[:, 1], M[:, 2] = R, T, N
    return M


@njit(cache=True)
def rtn_acceleration(r, v, a_rtn, acc, grad_r, grad_v):
    """Add M a_rtn to ``acc`` and its partials wrt r and v to grad_r, grad_v."""
    h = _cross(r, v)
    rn = np.sqrt(np.sum(r * r))
    hn = np.sqrt(np.sum(h * h))
    R = r / rn
    N = h / hn
    T = _cross(N, R)
    eye = np.eye(3)
    dR_dr = (eye - np.outer(R, R)) / rn
    dN_dh = (eye - np.outer(N, N)) / hn
    dN_dr = dN_dh @ (-_skew(v))  # dh/dr = -[v x]
    dN_dv = dN_dh @ _skew(r)  # dh/dv = [r x]
    dT_dr = _skew(N) @ dR_dr - _skew(R) @ dN_dr
    dT_dv = -_skew(R) @ dN_dv
    for i in range(3):
        acc[i] += a_rtn[0] * R[i] + a_rtn[1] * T[i] + a_rtn[2] * N[i]
    grad_r[:, :] += a_rtn[0] * dR_dr + a_rtn[1] * dT_dr + a_rtn[2] * dN_dr
    grad_v[:, :] += a_rtn[1] * dT_dv + a_rtn[2] * dN_dv
