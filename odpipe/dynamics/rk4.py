"""Classical 4th-order Runge-Kutta with fixed steps, compiled with numba.

``integrate_rk4(model, t0, y0, t1, h, n_err)`` returns what :func:`dop853.integrate`
returns, (t, y, F, n_eval), with F holding the cubic Hermite interpolant of each step in
DOP853's dense-output layout (its higher-order terms zero), so trajectories read it with
the same ``dense``. Steps are ``h`` long, the last one shorter to land on t1. This is the
integrator of onboard filters that cannot afford DOP853, kept to study what it costs.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from odpipe.dynamics.dop853 import derivative


@njit(cache=True)
def integrate_rk4(model, t0, y0, t1, h_step, n_err):
    n = y0.shape[0]
    direction = 1.0 if t1 >= t0 else -1.0
    span = abs(t1 - t0)
    n_steps = int(np.ceil(span / h_step - 1e-9)) if span > 0.0 else 0
    ts = np.empty(n_steps + 1)
    ys = np.empty((n_steps + 1, n))
    Fs = np.zeros((n_steps, 7, n))
    k1, k2, k3, k4, ytmp = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    y = y0.copy()
    t = t0
    derivative(t, y, model, k1)
    n_eval = 1
    ts[0] = t
    ys[0] = y
    for k in range(n_steps):
        h = direction * min(h_step, abs(t1 - t))
        for i in range(n):
            ytmp[i] = y[i] + 0.5 * h * k1[i]
        derivative(t + 0.5 * h, ytmp, model, k2)
        for i in range(n):
            ytmp[i] = y[i] + 0.5 * h * k2[i]
        derivative(t + 0.5 * h, ytmp, model, k3)
        for i in range(n):
            ytmp[i] = y[i] + h * k3[i]
        derivative(t + h, ytmp, model, k4)
        t_new = t1 if k == n_steps - 1 else t + h
        for i in range(n):
            ytmp[i] = y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        derivative(t_new, ytmp, model, k2)         # f at the step end: Hermite slope and next k1
        n_eval += 4
        for i in range(n):
            dy = ytmp[i] - y[i]
            Fs[k, 0, i] = dy
            Fs[k, 1, i] = h * k1[i] - dy
            Fs[k, 2, i] = 2.0 * dy - h * (k2[i] + k1[i])
        t = t_new
        y[:] = ytmp
        k1[:] = k2
        ts[k + 1] = t
        ys[k + 1] = y
    return ts, ys, Fs, n_eval
