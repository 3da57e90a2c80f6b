"""Earth-Moon libration orbits: a CRTBP Lyapunov orbit about L1/L2 and its geocentric ICRF state.

The planar Lyapunov orbit is found by differential correction in the CRTBP
(odpipe.dynamics.crtbp): start on the x axis with velocity along y, and
correct vy0 until vx vanishes at the next x-axis crossing (half period).
A three-dimensional (Lissajous-like) start adds an out-of-plane offset z0 to it
(:func:`odpipe.simulate.truth.initial_state`): the vertical motion is a centre at
a frequency close to the in-plane one, and the station keeping removes the unstable mode.
A nondimensional rotating state is put into the real Earth-Moon geometry at
an epoch with the instantaneous (pulsating) synodic frame of the ephemeris
Moon: positions scaled by the Earth-Moon distance d, velocities by d|w|,
plus the frame rotation; this is the inverse of
:func:`odpipe.frames.local.earth_moon_rotating_state`.
"""

from __future__ import annotations

import numpy as np

from odpipe.dynamics.crtbp import propagate_crtbp
from odpipe.frames.local import synodic_matrix


def collinear_point(mu: float, which: int) -> float:
    """x (nondimensional, barycentric) of L1 (which=1) or L2 (which=2)."""
    from scipy.optimize import brentq

    def dx(x):
        r1, r2 = abs(x + mu), abs(x - 1 + mu)
        return x - (1 - mu) * (x + mu) / r1**3 - mu * (x - 1 + mu) / r2**3

    lo, hi = ((0.5, 1 - mu - 1e-6) if which == 1 else (1 - mu + 1e-6, 1.5))
    return brentq(dx, lo, hi)


def lyapunov_orbit(mu: float, which: int, amplitude: float, iterations: int = 30):
    """(state0 (6,), period) of the planar Lyapunov orbit about L``which`` starting ``amplitude`` (nondim) Earthward of it."""
    xl = collinear_point(mu, which)
    x0 = xl - amplitude
    c2 = (1 - mu) / abs(xl + mu) ** 3 + mu / abs(xl - 1 + mu) ** 3
    w = np.sqrt((2 - c2 + np.sqrt(9 * c2**2 - 8 * c2)) / 2)   # linear in-plane frequency
    vy = amplitude * (w**2 + 1 + 2 * c2) / 2                  # linear guess k*w*A, corrected below
    t_half = 1.4
    for _ in range(iterations):
        t_half, st, phi, acc = _half_period(np.array([x0, 0.0, 0.0, 0.0, vy, 0.0]), mu)
        # d vx(t_half)/d vy0 with the crossing time moving to keep y = 0
        step = -st[3] / (phi[3, 4] - acc[0] * phi[1, 4] / st[4])
        vy += step
        if abs(step) < 1e-13:
            break
    return np.array([x0, 0.0, 0.0, 0.0, vy, 0.0]), 2.0 * t_half


def _half_period(s0, mu):
    """(t, state, STM, acceleration) at the first y = 0 crossing after t = 0.5 (nondim) of the CRTBP from ``s0``."""
    tr = propagate_crtbp(s0, 0.0, 4.0, mu, with_stm=True)
    ts = np.linspace(0.5, 4.0, 3501)
    y = tr.state(ts)[:, 1]
    k = np.flatnonzero(np.sign(y[1:]) != np.sign(y[:-1]))
    if not k.size:
        raise ValueError(f"no x-z plane crossing from {s0}")
    t = _crossing(tr, ts[k[0]], ts[k[0] + 1])
    st = tr.state(t)[0]
    return t, st, tr.stm(t)[0], _crtbp_accel(st, mu)


def _crossing(tr, a, b):
    from scipy.optimize import brentq

    return brentq(lambda t: tr.state(t)[0, 1], a, b, xtol=1e-14)


def _crtbp_accel(s, mu):
    x, y, z, vx, vy, _ = s
    r1 = np.array([x + mu, y, z])
    r2 = np.array([x - 1 + mu, y, z])
    g = -(1 - mu) * r1 / np.linalg.norm(r1) ** 3 - mu * r2 / np.linalg.norm(r2) ** 3
    return g + np.array([x + 2 * vy, y - 2 * vx, 0.0])


def rotating_to_icrf(state_nd, mu: float, moon_state) -> np.ndarray:
    """Geocentric ICRF state (m, m/s) of a nondimensional barycentric rotating state, given the Moon's geocentric state.

    Pulsating frame: r = mu r_moon + d M^T rho, v = mu v_moon + M^T rho' d |w| + w x rel + (d'/d) rel.
    """
    r_m, v_m = np.asarray(moon_state[:3], float), np.asarray(moon_state[3:6], float)
    m, omega = synodic_matrix(r_m, v_m)
    d = np.linalg.norm(r_m)
    w = np.linalg.norm(omega)
    rel = m.T @ (np.asarray(state_nd[:3]) * d)
    rel_v = m.T @ (np.asarray(state_nd[3:6]) * d * w)
    return np.concatenate([rel + mu * r_m, rel_v + np.cross(omega, rel) + (r_m @ v_m / d**2) * rel + mu * v_m])


def icrf_to_rotating(state, mu: float, moon_state) -> np.ndarray:
    """Nondimensional pulsating rotating states (N,6) of geocentric ICRF states (N,6); inverse of :func:`rotating_to_icrf`."""
    s, mo = np.atleast_2d(state), np.atleast_2d(moon_state)
    r_m, v_m = mo[:, :3], mo[:, 3:]
    m, omega = synodic_matrix(r_m, v_m)
    d = np.linalg.norm(r_m, axis=1, keepdims=True)
    w = np.linalg.norm(omega, axis=1, keepdims=True)
    rel = s[:, :3] - mu * r_m
    rel_v = s[:, 3:] - mu * v_m - np.cross(omega, rel) - np.sum(r_m * v_m, 1, keepdims=True) / d**2 * rel
    return np.concatenate([np.einsum("nij,nj->ni", m, rel) / d, np.einsum("nij,nj->ni", m, rel_v) / (d * w)], axis=1)
