"""Reference orbits in the Earth-Moon CRTBP (nondimensional rotating frame).

* Halo orbits: symmetric periodic orbits through the x-z plane, found by
  differential correction to a perpendicular half-period crossing (vx = vz = 0
  at y = 0) with z0 fixed, and picked out of the family by period (secant on z0).
* Keplerian orbiters (lunar orbiter, GEO): an ellipse of given period about the
  Moon or the Earth, set in the rotating frame at t = 0 (primary-centred axes
  parallel to the rotating axes).
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from odpipe.dynamics.crtbp import crtbp_rhs, propagate_crtbp


def half_period_crossing(state, mu: float, t_max: float = 4.0):
    """First y = 0 crossing after t > 0.1 (nondimensional): (t, state, STM)."""
    tr = propagate_crtbp(state, 0.0, t_max, mu)
    ts = np.linspace(0.1, t_max, 800)
    y = tr.state(ts)[:, 1]
    i = np.flatnonzero(np.sign(y[:-1]) != np.sign(y[1:]))
    if i.size == 0:
        raise RuntimeError("no x-z plane crossing")
    tc = brentq(lambda t: tr.state(t)[0, 1], ts[i[0]], ts[i[0] + 1], xtol=1e-14)
    return tc, tr.state(tc)[0], tr.stm(tc)[0]


def correct_halo(x0: float, z0: float, vy0: float, mu: float, hold: str = "z",
                 tol: float = 1e-11):
    """Periodic orbit through (x0, 0, z0) with velocity (0, vy0, 0): (state, period).

    ``hold``: 'z' keeps z0 and corrects (x0, vy0) (the amplitude stays: a halo, not the
    planar Lyapunov orbit that holding x0 near the bifurcation can fall onto); 'x' keeps x0.
    """
    s = np.array([x0, 0.0, z0, 0.0, vy0, 0.0])
    free = [2, 4] if hold == "x" else [0, 4]
    for _ in range(50):
        tc, X, Phi = half_period_crossing(s, mu)
        if max(abs(X[3]), abs(X[5])) < tol:
            return s, 2 * tc
        f = np.empty(6)
        crtbp_rhs(0.0, X, np.array([mu]), f)
        J = Phi[np.ix_([3, 5], free)] - np.outer(f[[3, 5]], Phi[1, free]) / X[4]
        d = np.linalg.solve(J, -X[[3, 5]])
        s[free] += d * min(1.0, 0.01 / np.max(np.abs(d)))
    raise RuntimeError("halo correction did not converge")


def halo_family(x0: float, vy0: float, z0s, mu: float) -> list:
    """Natural-parameter continuation in z0 (linear predictor): [(state, period), ...]."""
    out = []
    for z in z0s:
        gx, gv = x0, vy0
        if len(out) >= 2:
            gx, gv = 2 * out[-1][0][[0, 4]] - out[-2][0][[0, 4]]
        elif out:
            gx, gv = out[-1][0][[0, 4]]
        out.append(correct_halo(gx, z, gv, mu, hold="z"))
    return out


def halo_by_period(period: float, x0: float, vy0: float, z_start: float, z_stop: float,
                   mu: float, dz: float = 0.01):
    """Halo orbit of the given period (nondimensional): the first member past z_start.

    The family is continued in z0 from (x0, z_start, vy0) towards z_stop; returns (state, period).
    """
    z0s = np.arange(z_start, z_stop + 0.5 * dz, dz)
    fam = halo_family(x0, vy0, z0s, mu)
    miss = np.array([T for _, T in fam]) - period
    k = np.flatnonzero(np.sign(miss[:-1]) != np.sign(miss[1:]))
    if k.size == 0:
        raise ValueError(f"no halo of period {period} for z0 in [{z_start}, {z_stop}]")
    za, zb = z0s[k[0]], z0s[k[0] + 1]
    a, b = fam[k[0]][0][[0, 4]], fam[k[0] + 1][0][[0, 4]]

    def member(z):             # guess interpolated between the bracketing members
        g = a + (b - a) * (z - za) / (zb - za)
        return correct_halo(g[0], z, g[1], mu, hold="z")

    return member(brentq(lambda z: member(z)[1] - period, za, zb, xtol=1e-13))


def halo_start(state, period: float, mu: float, at: str = "apolune", north: bool = True) -> np.ndarray:
    """The halo through ``state`` (a y = 0 crossing) started at its x-z crossing farthest from
    ('apolune') or nearest to ('perilune') the Moon, mirrored so that crossing has z > 0 if
    ``north`` (z < 0 otherwise)."""
    if at not in ("apolune", "perilune"):
        raise ValueError(f"halo start must be 'apolune' or 'perilune', not {at!r}")
    other = propagate_crtbp(state, 0.0, 0.5 * period, mu, with_stm=False).state(0.5 * period)[0]
    moon = np.array([1 - mu, 0.0, 0.0])
    far = np.linalg.norm(state[:3] - moon) > np.linalg.norm(other[:3] - moon)
    s = np.array(state if far == (at == "apolune") else other, dtype=float)
    if (s[2] > 0) != north:
        s[[2, 5]] *= -1
    return s


def keplerian_orbit(period: float, ecc: float, inc: float, mu: float, raan: float = 0.0,
                    argp: float = 0.0, true_anomaly: float = 0.0, primary: str = "moon") -> np.ndarray:
    """Rotating-frame nondimensional state of a Keplerian orbit about 'moon' or 'earth'
    (period nondimensional, angles in rad, two-body GM of the primary only)."""
    gm, centre = (mu, 1 - mu) if primary == "moon" else (1 - mu, -mu)
    a = (gm * (period / (2 * np.pi)) ** 2) ** (1 / 3)
    p = a * (1 - ecc**2)
    r = p / (1 + ecc * np.cos(true_anomaly))
    r_pf = r * np.array([np.cos(true_anomaly), np.sin(true_anomaly), 0.0])
    v_pf = np.sqrt(gm / p) * np.array([-np.sin(true_anomaly), ecc + np.cos(true_anomaly), 0.0])
    cO, sO, ci, si, cw, sw = np.cos(raan), np.sin(raan), np.cos(inc), np.sin(inc), np.cos(argp), np.sin(argp)
    R = np.array([[cO * cw - sO * sw * ci, -cO * sw - sO * cw * ci, sO * si],
                  [sO * cw + cO * sw * ci, -sO * sw + cO * cw * ci, -cO * si],
                  [sw * si, cw * si, ci]])
    r_in, v_in = R @ r_pf, R @ v_pf
    pos = r_in + np.array([centre, 0.0, 0.0])
    vel = v_in - np.cross([0.0, 0.0, 1.0], r_in)       # inertial -> rotating (omega = 1)
    return np.concatenate([pos, vel])
