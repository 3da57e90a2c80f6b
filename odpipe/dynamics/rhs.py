"""Equations of motion with variational equations (numba).

State vector y = [r (3), v (3), Phi (6x6, row-major), S (6 x p, row-major)]:
dr/dt = v, dv/dt = a(t, r, v; p), dPhi/dt = A Phi, dS/dt = A S + [0; da/dp],
A = [[0, I], [da/dr, da/dv]]. Without the STM, y is the 6-vector only.
``model`` is the :data:`~odpipe.dynamics.forces.CompiledModel` made by
:func:`odpipe.dynamics.forces.compile_model`; the acceleration is the sum of every
registered force's ``contribute`` (:mod:`odpipe.dynamics.force_registry`).
"""

from __future__ import annotations

from numba import literal_unroll, njit, types
from numba.extending import overload

from odpipe.dynamics.dop853 import derivative
from odpipe.dynamics.forces import SCRATCH_FIXED, CompiledModel
from odpipe.dynamics.force_registry import Environment, contribute
from odpipe.dynamics.thrust import spacecraft_mass
from odpipe.environment.ephemeris import interp_positions_into


@njit(cache=True)
def acceleration(t, r, v, model, acc, grad_r, grad_v, dadp):
    """Add the total acceleration (m/s^2) and its partials wrt r, v and the parameters (p, 3)."""
    interp_positions_into(model.eph_coeffs, model.eph_t_start, model.eph_t_step, t, model.pos)
    env = Environment(model.pos, spacecraft_mass(t, model.mass, model.mass_flow), model.segment[0])
    for force in literal_unroll(model.forces):
        contribute(force, t, r, v, env, acc, grad_r, grad_v, dadp)


@njit(cache=True)
def rhs(t, y, model, dy):
    """dy/dt for the state with (optionally) STM and parameter sensitivities; works in ``model.work``."""
    r = y[0:3]
    v = y[3:6]
    npar = model.n_params
    w = model.work
    w[:] = 0.0
    acc = w[0:3]
    grad_r = w[3:12].reshape((3, 3))
    grad_v = w[12:21].reshape((3, 3))
    col = w[21:27]
    dadp = w[SCRATCH_FIXED:SCRATCH_FIXED + 3 * npar].reshape((npar, 3))
    acceleration(t, r, v, model, acc, grad_r, grad_v, dadp)
    dy[0:3] = v
    dy[3:6] = acc
    if not model.with_stm:
        return
    # columns of [Phi | S]: Phi stored at 6 + 6*row + col, S at 42 + npar*row + col
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
    if isinstance(model, types.BaseNamedTuple) and model.instance_class is CompiledModel:
        return rhs.py_func
    return None
