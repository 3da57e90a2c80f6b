"""Circular restricted three-body problem (CRTBP) with STM, nondimensional and dimensional.

Rotating barycentric frame, unit length L (primaries' separation), unit time
T = sqrt(L^3 / (GM1 + GM2)), mass ratio mu = GM2 / (GM1 + GM2); primaries at
(-mu, 0, 0) and (1 - mu, 0, 0). Equations: x'' - 2y' = dO/dx, y'' + 2x' =
dO/dy, z'' = dO/dz with O = (x^2 + y^2)/2 + (1 - mu)/r1 + mu/r2; Jacobi
constant C = 2 O - |v|^2 is conserved. :func:`propagate_crtbp` returns a
:class:`~odpipe.dynamics.trajectory.Trajectory` whose ``center`` is 'crtbp'
(nondimensional rotating-frame states, not ICRF).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit, types
from numba.extending import overload

from odpipe.constants import EGM96_GM
from odpipe.dynamics.dop853 import derivative, integrate
from odpipe.dynamics.trajectory import Trajectory


@dataclass(frozen=True)
class EarthMoonUnits:
    """Dimensional scales: ``length`` m, ``gm1``/``gm2`` m^3/s^2 (Earth, Moon)."""

    length: float = 384400.0e3
    gm1: float = EGM96_GM
    gm2: float = 4.902800118e12

    @property
    def mu(self) -> float:
        return self.gm2 / (self.gm1 + self.gm2)

    @property
    def time(self) -> float:
        return float(np.sqrt(self.length**3 / (self.gm1 + self.gm2)))

    def to_si(self, x):
        """Nondimensional state(s) (..., 6) -> m, m/s."""
        x = np.asarray(x, float)
        return np.concatenate([x[..., :3] * self.length, x[..., 3:6] * self.length / self.time], -1)

    def from_si(self, x):
        """State(s) (..., 6) in m, m/s -> nondimensional."""
        x = np.asarray(x, float)
        return np.concatenate([x[..., :3] / self.length, x[..., 3:6] * self.time / self.length], -1)


@njit(cache=True)
def pseudo_potential_gradient(r, mu, grad, hess):
    """dO/dr into grad (3,) and d2O/dr2 into hess (3, 3)."""
    p1 = np.array([r[0] + mu, r[1], r[2]])
    p2 = np.array([r[0] - 1.0 + mu, r[1], r[2]])
    r1 = np.sqrt(np.sum(p1 * p1))
    r2 = np.sqrt(np.sum(p2 * p2))
    k1 = (1.0 - mu) / r1**3
    k2 = mu / r2**3
    for i in range(3):
        grad[i] = -k1 * p1[i] - k2 * p2[i] + (r[i] if i < 2 else 0.0)
        for j in range(3):
            eye = 1.0 if i == j else 0.0
            hess[i, j] = (k1 * (3.0 * p1[i] * p1[j] / r1**2 - eye) + k2 * (3.0 * p2[i] * p2[j] / r2**2 - eye)
                          + (eye if i < 2 else 0.0))


@njit(cache=True)
def crtbp_rhs(t, y, model, dy):
    """CRTBP state (and STM when len(y) == 42) derivative; model = [mu]."""
    grad = np.empty(3)
    hess = np.empty((3, 3))
    pseudo_potential_gradient(y[0:3], model[0], grad, hess)
    dy[0:3] = y[3:6]
    dy[3] = grad[0] + 2.0 * y[4]
    dy[4] = grad[1] - 2.0 * y[3]
    dy[5] = grad[2]
    if y.shape[0] == 6:
        return
    for c in range(6):
        for i in range(3):
            dy[6 + 6 * i + c] = y[6 + 6 * (3 + i) + c]
            acc = 0.0
            for j in range(3):
                acc += hess[i, j] * y[6 + 6 * j + c]
            dy[6 + 6 * (3 + i) + c] = acc
        dy[6 + 6 * 3 + c] += 2.0 * y[6 + 6 * 4 + c]
        dy[6 + 6 * 4 + c] -= 2.0 * y[6 + 6 * 3 + c]


@overload(derivative)
def _derivative_crtbp(t, y, model, dy):
    if isinstance(model, types.Array):
        return crtbp_rhs.py_func
    return None


def jacobi_constant(x, mu: float) -> np.ndarray:
    """Jacobi constant C = 2 O - v^2 of nondimensional states (..., 6)."""
    x = np.asarray(x, float)
    r1 = np.linalg.norm(x[..., :3] - [-mu, 0, 0], axis=-1)
    r2 = np.linalg.norm(x[..., :3] - [1 - mu, 0, 0], axis=-1)
    omega = 0.5 * (x[..., 0] ** 2 + x[..., 1] ** 2) + (1 - mu) / r1 + mu / r2
    return 2 * omega - np.sum(x[..., 3:6] ** 2, axis=-1)


def propagate_crtbp(state0, t0: float, t1: float, mu: float, with_stm: bool = True,
                    rtol: float = 1e-12, atol: float = 1e-12) -> Trajectory:
    """Propagate a nondimensional CRTBP state from t0 to t1 (nondimensional time)."""
    y = np.asarray(state0, float).ravel().copy()
    if with_stm:
        y = np.concatenate([y, np.eye(6).ravel()])
    ts, ys, Fs, n_eval = integrate(np.array([mu]), float(t0), y, float(t1), rtol, atol, np.inf, 6, 0.0)
    return Trajectory("crtbp", t0, t1, [], [(ts, ys, Fs)], with_stm, n_eval)
