"""SH acceleration and gradient vs an independent potential (scipy spherical harmonics).

The reference potential is summed with scipy's orthonormal Y_nm (no recursion of
ours), then differentiated by central finite differences.
"""

import numpy as np
import pytest
from scipy.special import sph_harm_y

from odpipe.dynamics.harmonics import by_order, recursion_factors, sh_acceleration


def _potential(r, gm, radius, C, S, nmax):
    """U (m^2/s^2) without the central term, from 4-pi normalized P_nm via scipy's Y_nm."""
    x, y, z = r
    rr = np.sqrt(x * x + y * y + z * z)
    colat, lon = np.arccos(z / rr), np.arctan2(y, x)
    total = 0.0
    for n in range(2, nmax + 1):
        m = np.arange(n + 1)
        Y = sph_harm_y(n, m, colat, lon)  # orthonormal, with Condon-Shortley phase
        scale = np.sqrt(4 * np.pi * np.where(m == 0, 1.0, 2.0)) * (-1.0) ** m
        total += (radius / rr) ** n * np.sum(scale * (C[n, m] * Y.real + S[n, m] * Y.imag))
    return gm / rr * total


def _random_field(nmax, seed):
    rng = np.random.default_rng(seed)
    C = rng.normal(size=(nmax + 1, nmax + 1)) * 1e-6
    S = rng.normal(size=(nmax + 1, nmax + 1)) * 1e-6
    C, S = np.tril(C), np.tril(S)
    S[:, 0] = 0.0
    C[0, 0], C[1, :], S[1, :] = 1.0, 0.0, 0.0
    return C, S


@pytest.mark.parametrize("r", [[7.0e6, -1.2e6, 2.3e6], [1.0e5, 2.0e5, 6.9e6], [-4.1e6, 3.3e6, -4.2e6]])
def test_acceleration_and_gradient_vs_potential(r):
    nmax, gm, radius = 12, 3.986004415e14, 6378136.3
    C, S = _random_field(nmax, 7)
    r = np.array(r)
    f = recursion_factors(nmax)
    acc, grad = np.zeros(3), np.zeros((3, 3))
    sh_acceleration(r, gm, radius, by_order(C), by_order(S), nmax, nmax, f, acc, grad)
    central = -gm * r / np.linalg.norm(r) ** 3
    h = 10.0
    ref_acc = np.zeros(3)
    ref_grad = np.zeros((3, 3))
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        ref_acc[i] = (_potential(r + e, gm, radius, C, S, nmax)
                      - _potential(r - e, gm, radius, C, S, nmax)) / (2 * h)
    H = 500.0
    for i in range(3):
        for j in range(3):
            ei, ej = np.eye(3)[i] * H, np.eye(3)[j] * H
            ref_grad[i, j] = (_potential(r + ei + ej, gm, radius, C, S, nmax)
                              - _potential(r + ei - ej, gm, radius, C, S, nmax)
                              - _potential(r - ei + ej, gm, radius, C, S, nmax)
                              + _potential(r - ei - ej, gm, radius, C, S, nmax)) / (4 * H * H)
    rn = np.linalg.norm(r)
    central_grad = gm / rn**3 * (3 * np.outer(r, r) / rn**2 - np.eye(3))
    np.testing.assert_allclose(acc - central, ref_acc, rtol=0, atol=1e-9 * np.abs(ref_acc).max())
    np.testing.assert_allclose(grad - central_grad, ref_grad, rtol=0,
                               atol=1e-6 * np.abs(ref_grad).max())
    np.testing.assert_allclose(grad, grad.T, rtol=0, atol=1e-15 * np.abs(grad).max())


@pytest.mark.realdata
def test_degree_200_lunar_field_low_orbit(shared_data):
    """LP 200x200 at 55 km altitude over the pole and equator: full-degree sum vs scipy."""
    from odpipe.environment.gravity import read_gravity

    g = read_gravity(shared_data / "gravity/tudat/lpe200.txt")
    f = recursion_factors(200)
    for r in ([1.2e6, 0.8e6, 0.9e6], [1.0e3, -2.0e3, 1.793e6]):
        r = np.array(r) * 1.793e6 / np.linalg.norm(r)
        acc, grad = np.zeros(3), np.zeros((3, 3))
        sh_acceleration(r, g.gm, g.radius, by_order(g.C), by_order(g.S), 200, -1, f, acc, grad)
        h = 2.0
        ref = np.array([(_potential(r + e, g.gm, g.radius, g.C, g.S, 200)
                         - _potential(r - e, g.gm, g.radius, g.C, g.S, 200)) / (2 * h)
                        for e in np.eye(3) * h])
        central = -g.gm * r / np.linalg.norm(r) ** 3
        np.testing.assert_allclose(acc - central, ref, rtol=0, atol=2e-9)
