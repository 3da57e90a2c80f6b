"""Dormand-Prince 8(5,3) integrator with 7th-order dense output, compiled with numba.

The Butcher tableau, error weights and dense-output coefficients are the
published DOP853 constants (Hairer, Norsett & Wanner, Solving ODE I), taken
from scipy's coefficient table so they are typed nowhere here. The 3/5-order
error norm and the step-size controller follow Hairer's DOP853: the next step is
h * 0.9 * err^(-1/8), kept within [0.333, 6] times the last one, never longer than
the rejected one right after a rejection, and stretched by up to 1 % to land on t1.
The last stage, f at the step's end (the next step's first), is evaluated only once
a step is accepted. The error norm
covers the first ``n_err`` components only (the state; the variational part
rides on the same steps). ``rtol = inf`` takes fixed steps of ``h_max`` (the last one
shorter to land on t1) without error control, the way onboard filters integrate.
``h_first > 0`` is the first step's length (s) instead of Hairer's starting heuristic (0.01 of
the state's scale over its rate: a few seconds for a low lunar orbit, whose steps are about a
minute, so that a short integration spends most of its steps growing from it).

``integrate(model, t0, y0, t1, rtol, atol, h_max, n_err, h_first)`` -> (t (k+1,),
y (k+1, n), F (k, 7, n), n_eval). The right-hand side is ``derivative(t, y,
model, dy)``, which each dynamics module implements with
``numba.extending.overload`` selected by the type of its ``model`` (the
orbit model tuple, the CRTBP parameter array); a dispatcher passed as an
argument would defeat numba's on-disk cache. ``dense(t, y, F, tq, n)`` evaluates the
first ``n`` components of the interpolant at times ``tq``.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.integrate._ivp import dop853_coefficients as _dop

A = np.ascontiguousarray(_dop.A, dtype=float)
B = np.ascontiguousarray(_dop.B, dtype=float)
C = np.ascontiguousarray(_dop.C, dtype=float)
E3 = np.ascontiguousarray(_dop.E3, dtype=float)
E5 = np.ascontiguousarray(_dop.E5, dtype=float)
D = np.ascontiguousarray(_dop.D, dtype=float)
N_STAGES = _dop.N_STAGES  # 12
N_EXT = _dop.N_STAGES_EXTENDED  # 16

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.333, 6.0   # Hairer's safe, fac1, fac2: h_new / h in [fac1, fac2]


@njit(cache=True)
def _step_factor(err):
    """h_new / h for the error norm ``err`` of the last step (accepted or not)."""
    if err == 0.0:
        return MAX_FACTOR
    return min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * err ** (-1.0 / 8.0)))


@njit(cache=True)
def _error_norm(K, h, y, y_new, rtol, atol, n_err):
    e5 = 0.0
    e3 = 0.0
    for i in range(n_err):
        sc = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        s5 = 0.0
        s3 = 0.0
        for s in range(N_STAGES):   # the weights' last entry, of f at the step's end, is zero
            s5 += E5[s] * K[s, i]
            s3 += E3[s] * K[s, i]
        e5 += (s5 / sc) ** 2
        e3 += (s3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n_err)


@njit(cache=True)
def _stage(K, y, h, s, ytmp):
    n = y.shape[0]
    for i in range(n):
        acc = 0.0
        for j in range(s):
            acc += A[s, j] * K[j, i]
        ytmp[i] = y[i] + h * acc


def derivative(t, y, model, dy):
    """dy/dt of ``model`` into ``dy``: implemented per model type with numba overloads."""
    raise NotImplementedError("derivative() is only callable from numba code")


@njit(cache=True)
def integrate(model, t0, y0, t1, rtol, atol, h_max, n_err, h_first):
    n = y0.shape[0]
    direction = 1.0 if t1 >= t0 else -1.0
    cap = 64
    ts = np.empty(cap)
    ys = np.empty((cap, n))
    Fs = np.empty((cap, 7, n))
    K = np.empty((N_EXT, n))
    ytmp = np.empty(n)
    y = y0.copy()
    y_new = np.empty(n)
    t = t0
    derivative(t, y, model, K[0])
    n_eval = 1
    ts[0] = t
    ys[0] = y
    k = 0
    span = abs(t1 - t0)
    if span == 0.0:
        return ts[:1].copy(), ys[:1].copy(), Fs[:0].copy(), n_eval
    # initial step (Hairer's heuristic on the error components)
    d0 = 0.0
    d1 = 0.0
    for i in range(n_err):
        sc = atol + rtol * abs(y[i])
        d0 += (y[i] / sc) ** 2
        d1 += (K[0, i] / sc) ** 2
    d0 = np.sqrt(d0 / n_err)
    d1 = np.sqrt(d1 / n_err)
    fixed = rtol == np.inf                       # fixed steps of h_max, no error control
    h_abs = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    if h_first > 0.0:
        h_abs = h_first
    h_abs = min(h_max if fixed else h_abs, h_max, span)
    rejected = False
    while True:
        remaining = abs(t1 - t)
        if remaining <= 1e-12 * max(1.0, abs(t1)):
            break
        if h_abs * (1.0 if fixed else 1.01) >= remaining:
            h_abs = remaining
        h = direction * h_abs
        for s in range(1, N_STAGES):
            _stage(K, y, h, s, ytmp)
            derivative(t + C[s] * h, ytmp, model, K[s])
        for i in range(n):
            acc = 0.0
            for s in range(N_STAGES):
                acc += B[s] * K[s, i]
            y_new[i] = y[i] + h * acc
        t_new = t + h if h_abs < remaining else t1
        n_eval += N_STAGES - 1
        err = 0.0 if fixed else _error_norm(K, h, y, y_new, rtol, atol, n_err)
        if err > 1.0:
            h_abs *= _step_factor(err)
            rejected = True
            if h_abs < 1e-10 * max(1.0, abs(t)):
                raise RuntimeError("DOP853: step size underflow")
            continue
        # accepted: f at the step's end, then three more stages for the dense output
        derivative(t_new, y_new, model, K[N_STAGES])
        for s in range(N_STAGES + 1, N_EXT):
            _stage(K, y, h, s, ytmp)
            derivative(t + C[s] * h, ytmp, model, K[s])
        n_eval += N_EXT - N_STAGES
        if k + 1 >= cap:
            cap *= 2
            ts2 = np.empty(cap)
            ys2 = np.empty((cap, n))
            Fs2 = np.empty((cap, 7, n))
            ts2[: k + 1] = ts[: k + 1]
            ys2[: k + 1] = ys[: k + 1]
            Fs2[:k] = Fs[:k]
            ts, ys, Fs = ts2, ys2, Fs2
        for i in range(n):
            dy = y_new[i] - y[i]
            Fs[k, 0, i] = dy
            Fs[k, 1, i] = h * K[0, i] - dy
            Fs[k, 2, i] = 2.0 * dy - h * (K[N_STAGES, i] + K[0, i])
            for r in range(4):
                acc = 0.0
                for s in range(N_EXT):
                    acc += D[r, s] * K[s, i]
                Fs[k, 3 + r, i] = h * acc
        k += 1
        t = t_new
        y[:] = y_new
        ts[k] = t
        ys[k] = y
        K[0] = K[N_STAGES]
        factor = _step_factor(err)
        h_abs = min(h_abs * (min(factor, 1.0) if rejected else factor), h_max)
        rejected = False
    return ts[: k + 1].copy(), ys[: k + 1].copy(), Fs[:k].copy(), n_eval


@njit(cache=True)
def dense(ts, ys, Fs, tq, n):
    """The first ``n`` interpolated components (len(tq), n) at times ``tq`` inside [ts[0], ts[-1]]
    (``n = 6``: the state alone, without the variational columns)."""
    out = np.empty((tq.shape[0], n))
    nstep = ts.shape[0] - 1
    forward = ts[-1] >= ts[0]
    for q in range(tq.shape[0]):
        t = tq[q]
        if forward:
            j = np.searchsorted(ts, t) - 1
        else:
            j = nstep - np.searchsorted(ts[::-1], t)
        j = min(max(j, 0), nstep - 1)
        if nstep == 0:
            out[q] = ys[0, :n]
            continue
        x = (t - ts[j]) / (ts[j + 1] - ts[j])
        for i in range(n):
            acc = 0.0
            for r in range(6, -1, -1):
                acc += Fs[j, r, i]
                acc *= x if (6 - r) % 2 == 0 else 1.0 - x
            out[q, i] = ys[j, i] + acc
    return out
