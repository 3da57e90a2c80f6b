"""Equations of motion with variational equations (numba).

State vector y = [r (3), v (3), Phi (6x6, row-major), S (6 x p, row-major)]:
dr/dt = v, dv/dt = a(t, r, v; p), dPhi/dt = A Phi, dS/dt = A S + [0; da/dp],
A = [[0, I], [da/dr, da/dv]]. Without the STM, y is the 6-vector only.
``model`` is the tuple made by :func:`odpipe.dynamics.forces.compile_model`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import overload

from odpipe.numerics.chebyshev import evaluate
from odpipe.dynamics.dop853 import derivative
from odpipe.dynamics.drag import drag_acceleration
from odpipe.dynamics.forces import PARAM_CD, PARAM_EMP, PARAM_RHO_D, PARAM_RHO_S, PARAM_SCALE
from odpipe.dynamics.harmonics import sh_acceleration
from odpipe.dynamics.pointmass import central, third_body
from odpipe.dynamics.relativity import schwarzschild
from odpipe.dynamics.rtn import rtn_acceleration, rtn_axes
from odpipe.dynamics.srp import shadow_factor, srp_acceleration
from odpipe.environment.ephemeris import interp_positions


@njit(cache=True)
def spacecraft_mass(t, mass0, burns):
    """Mass (kg) at t after the mass flow of the finite burns."""
    m = mass0
    for k in range(burns.shape[0]):
        m -= burns[k, 3] * min(max(t - burns[k, 0], 0.0), burns[k, 1] - burns[k, 0])
    return m


@njit(cache=True)
def acceleration(t, r, v, model, acc, grad_r, grad_v, dadp):
    """Total acceleration (m/s^2), its partials wrt r, v and the parameters (p, 3)."""
    (flags, scal, coeffs, pm, C, S, fac, sh_meta, rot_coefs, rot_meta, srp_row, surfaces, occ,
     emp, burns, pmap, drag) = model
    with_stm = flags[1] == 1
    pos = interp_positions(coeffs, scal[2], scal[3], t)
    if scal[0] > 0.0:
        central(r, scal[0], acc, grad_r)
    for k in range(pm.shape[0]):
        s = pos[int(pm[k, 1])]
        if pm[k, 2] > 0.0:
            third_body(r, s, pm[k, 0], acc, grad_r)
        else:  # body carries SH: indirect point-mass term only
            sn = np.sqrt(np.sum(s * s))
            acc -= pm[k, 0] * s / sn**3
    rot = np.empty(9)
    a_bf = np.empty(3)
    g_bf = np.zeros((3, 3))
    for k in range(sh_meta.shape[0]):
        slot = int(sh_meta[k, 4])
        rel = r - pos[slot] if slot >= 0 else r.copy()
        evaluate(rot_coefs, rot_meta, int(sh_meta[k, 5]), t, rot)
        M = rot.reshape((3, 3))
        ngrad = int(sh_meta[k, 3])
        sh_acceleration(M @ rel, sh_meta[k, 0], sh_meta[k, 1], C[k], S[k], int(sh_meta[k, 2]), ngrad,
                        fac, a_bf, g_bf)
        acc += M.T @ a_bf
        if ngrad >= 0:
            grad_r += M.T @ g_bf @ M
    if flags[0] == 1:
        schwarzschild(r, v, scal[4], acc, grad_r, grad_v)
    mass = spacecraft_mass(t, scal[1], burns)
    if srp_row[0] > 0.0:
        r_sun = pos[flags[2]] if flags[2] >= 0 else np.zeros(3)
        nu = 1.0
        for k in range(occ.shape[0]):
            r_b = pos[int(occ[k, 1])] if occ[k, 1] >= 0 else np.zeros(3)
            nu *= shadow_factor(r, r_sun, r_b, occ[k, 0])
        ns = surfaces.shape[0]
        d_scale = np.zeros(3)
        d_rs = np.zeros((ns, 3))
        d_rd = np.zeros((ns, 3))
        srp_acceleration(r, r_sun, nu, srp_row[3], srp_row[2], mass, srp_row[1], surfaces,
                         acc, grad_r, d_scale, d_rs, d_rd)
        for p in range(pmap.shape[0]):
            kind, idx = pmap[p, 0], pmap[p, 1]
            if kind == PARAM_SCALE:
                dadp[p] += d_scale
            elif kind == PARAM_RHO_S:
                dadp[p] += d_rs[idx]
            elif kind == PARAM_RHO_D:
                dadp[p] += d_rd[idx]
    if drag[0] > 0.0:
        d_cd = np.zeros(3)
        drag_acceleration(r, v, pos[int(drag[4])], drag[1], drag[2], mass, drag[3], acc, grad_r, grad_v, d_cd)
        for p in range(pmap.shape[0]):
            if pmap[p, 0] == PARAM_CD:
                dadp[p] += d_cd
    t_seg = scal[5]  # mid-epoch of the segment: piecewise-constant terms switch only between segments
    for b in range(emp.shape[0]):
        if emp[b, 0] <= t_seg < emp[b, 1]:
            rtn_acceleration(r, v, emp[b, 2:5], acc, grad_r, grad_v)
            axes = rtn_axes(r, v)
            for p in range(pmap.shape[0]):
                if pmap[p, 0] == PARAM_EMP and pmap[p, 1] // 3 == b:
                    dadp[p] += axes[:, pmap[p, 1] % 3]
    for b in range(burns.shape[0]):
        if burns[b, 0] <= t_seg < burns[b, 1]:
            a_thrust = burns[b, 2] / mass * burns[b, 4:7]
            if burns[b, 7] > 0.0:
                rtn_acceleration(r, v, a_thrust, acc, grad_r, grad_v)
            else:
                acc += a_thrust
    return with_stm


@njit(cache=True)
def rhs(t, y, model, dy):
    """dy/dt for the state with (optionally) STM and parameter sensitivities."""
    r = y[0:3]
    v = y[3:6]
    npar = model[15].shape[0]
    acc = np.zeros(3)
    grad_r = np.zeros((3, 3))
    grad_v = np.zeros((3, 3))
    dadp = np.zeros((npar, 3))
    with_stm = acceleration(t, r, v, model, acc, grad_r, grad_v, dadp)
    dy[0:3] = v
    dy[3:6] = acc
    if not with_stm:
        return
    # columns of [Phi | S]: Phi stored at 6 + 6*row + col, S at 42 + npar*row + col
    col = np.empty(6)
    for c in range(6 + npar):
        for i in range(6):
            col[i] = y[6 + 6 * i + c] if c < 6 else y[42 + npar * i + c - 6]
        for i in range(3):
            d_v = dadp[c - 6, i] if c >= 6 else 0.0
            for j in range(3):
                d_v += grad_r[i, j] * col[j] + grad_v[i, j] * col[3 + j]
            if c < 6:
                dy[6 + 6 * i + c] = col[3 + i]
                dy[6 + 6 * (3 + i) + c] = d_v
            else:
                dy[42 + npar * i + c - 6] = col[3 + i]
                dy[42 + npar * (3 + i) + c - 6] = d_v


@overload(derivative)
def _derivative_orbit(t, y, model, dy):
    if isinstance(model, types.BaseTuple):
        return rhs.py_func
    return None
