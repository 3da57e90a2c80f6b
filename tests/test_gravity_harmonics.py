"""SH acceleration and gradient vs an independent potential (scipy spherical harmonics).

The reference potential is summed with scipy's orthonormal Y_nm (no recursion of
ours), then differentiated by central finite differences. The kernel's reassociated
(fastmath) sums are checked against exactly rounded sums (math.fsum) of the same series.
"""

import math

import numpy as np
import pytest
from scipy.special import sph_harm_y

from odpipe.dynamics.harmonics import field_table, recursion_factors, sh_acceleration, workspace


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
    T = field_table(C, S, nmax, nmax)
    acc, grad = np.zeros(3), np.zeros((3, 3))
    sh_acceleration(r, gm, radius, T, nmax, nmax, workspace(nmax, nmax), acc, grad)
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
    T = field_table(g.C, g.S, 200, -1)
    for r in ([1.2e6, 0.8e6, 0.9e6], [1.0e3, -2.0e3, 1.793e6]):
        r = np.array(r) * 1.793e6 / np.linalg.norm(r)
        acc, grad = np.zeros(3), np.zeros((3, 3))
        sh_acceleration(r, g.gm, g.radius, T, 200, -1, workspace(200, -1), acc, grad)
        h = 2.0
        ref = np.array([(_potential(r + e, g.gm, g.radius, g.C, g.S, 200)
                         - _potential(r - e, g.gm, g.radius, g.C, g.S, 200)) / (2 * h)
                        for e in np.eye(3) * h])
        central = -g.gm * r / np.linalg.norm(r) ** 3
        np.testing.assert_allclose(acc - central, ref, rtol=0, atol=2e-9)


def _solid_harmonics(r, radius, N, f):
    """Normalized V[n, m], W[n, m], n <= N, by the ordered recursion (numpy, float64)."""
    x, y, z = r
    r2 = x * x + y * y + z * z
    xr, yr, zr, rr = x * radius / r2, y * radius / r2, z * radius / r2, radius * radius / r2
    V, W = np.zeros((N + 1, N + 2)), np.zeros((N + 1, N + 2))
    V[0, 0] = radius / np.sqrt(r2)
    for n in range(1, N + 1):
        m = np.arange(n)
        V[n, m] = f[0, m, n] * zr * V[n - 1, m] - (f[1, m, n] * rr * V[n - 2, m] if n >= 2 else 0.0)
        W[n, m] = f[0, m, n] * zr * W[n - 1, m] - (f[1, m, n] * rr * W[n - 2, m] if n >= 2 else 0.0)
        V[n, n] = f[2, n, n] * (xr * V[n - 1, n - 1] - yr * W[n - 1, n - 1])
        W[n, n] = f[2, n, n] * (xr * W[n - 1, n - 1] + yr * V[n - 1, n - 1])
    return V, W


def _derivatives(V, W, f):
    """R d/dx, R d/dy, R d/dz of V, W for degrees n <= N-1 (Cunningham's normalized rules)."""
    N = V.shape[0] - 1
    out = {a: (np.zeros((N, N + 1)), np.zeros((N, N + 1))) for a in "xyz"}
    for n in range(N):
        m = np.arange(n + 1)
        p, q, s = f[3, m, n], f[4, m, n], f[5, m, n]
        up = np.minimum(m + 1, N + 1)
        down = np.maximum(m - 1, 0)
        out["z"][0][n, m], out["z"][1][n, m] = -s * V[n + 1, m], -s * W[n + 1, m]
        out["x"][0][n, m] = -p * V[n + 1, up] + np.where(m > 0, q * V[n + 1, down], 0.0)
        out["x"][1][n, m] = np.where(m > 0, -p * W[n + 1, up] + q * W[n + 1, down], 0.0)
        out["y"][0][n, m] = -p * W[n + 1, up] - np.where(m > 0, q * W[n + 1, down], 0.0)
        out["y"][1][n, m] = np.where(m > 0, p * V[n + 1, up] + q * V[n + 1, down], 0.0)
    return out


def _exact_sum(C, S, V, W, nmax):
    """fsum of C00 V00 + sum_{2 <= n <= nmax} C V + S W."""
    terms = [C[0, 0] * V[0, 0]]
    for n in range(2, nmax + 1):
        terms += list(C[n, : n + 1] * V[n, : n + 1]) + list(S[n, : n + 1] * W[n, : n + 1])
    return math.fsum(terms)


@pytest.mark.realdata
def test_reassociated_sums_within_1e12_of_exactly_rounded_sums(shared_data):
    """Degree 120 lunar field, gradient to 40, at 30 km altitude: fastmath changes < 1e-12 relative."""
    from odpipe.environment.gravity import read_gravity

    g = read_gravity(shared_data / "gravity/tudat/lpe200.txt")
    nmax, ngrad = 120, 40
    C, S = g.truncated(nmax).C, g.truncated(nmax).S
    T = field_table(C, S, nmax, ngrad)
    f = recursion_factors(nmax + 2)
    for r in ([1.2e6, 0.8e6, 0.9e6], [1.0e3, -2.0e3, 1.8e6], [-0.3e6, 1.7e6, -0.2e6]):
        r = np.array(r) * (g.radius + 30e3) / np.linalg.norm(r)
        acc, grad = np.zeros(3), np.zeros((3, 3))
        sh_acceleration(r, g.gm, g.radius, T, nmax, ngrad, workspace(nmax, ngrad), acc, grad)
        V, W = _solid_harmonics(r, g.radius, nmax + 2, f)
        first = _derivatives(V, W, f)
        ref = np.array([_exact_sum(C, S, *first[a], nmax) for a in "xyz"]) * g.gm / g.radius**2
        ref_grad = np.array([[_exact_sum(C, S, *_derivatives(*first[b], f)[a], ngrad) for b in "xyz"]
                             for a in "xyz"]) * g.gm / g.radius**3
        np.testing.assert_allclose(acc, ref, rtol=0, atol=1e-12 * np.linalg.norm(ref))
        np.testing.assert_allclose(grad, ref_grad, rtol=0, atol=1e-12 * np.abs(ref_grad).max())


@pytest.mark.parametrize("r", [[0.0, 0.0, 7.1e6], [0.0, 0.0, -6.9e6], [1e-3, -2e-3, 7.0e6],
                               [7.0e6, 0.0, 0.0], [3.1e6, -4.4e6, 4.0e6]])
def test_j2_field_matches_closed_form_including_the_polar_axis(r):
    """J2 only: a = -3/2 J2 GM R^2 / r^5 (x (1 - 5 z^2/r^2), y (1 - 5 z^2/r^2), z (3 - 5 z^2/r^2)),
    on the spin axis too (longitude undefined), with the gradient as its derivative."""
    gm, radius, j2 = 3.986004415e14, 6378136.3, 1.0826e-3
    C, S = np.zeros((3, 3)), np.zeros((3, 3))
    C[0, 0], C[2, 0] = 1.0, -j2 / np.sqrt(5.0)

    def closed_form(p):
        x, y, z = p
        rn = np.linalg.norm(p)
        k = -1.5 * j2 * gm * radius**2 / rn**5
        return -gm * p / rn**3 + k * np.array([x * (1 - 5 * z * z / rn**2), y * (1 - 5 * z * z / rn**2),
                                               z * (3 - 5 * z * z / rn**2)])

    r = np.array(r)
    acc, grad = np.zeros(3), np.zeros((3, 3))
    sh_acceleration(r, gm, radius, field_table(C, S, 2, 2), 2, 2, workspace(2, 2), acc, grad)
    np.testing.assert_allclose(acc, closed_form(r), rtol=1e-14, atol=0)
    h = 1.0
    ref_grad = np.column_stack([(closed_form(r + e) - closed_form(r - e)) / (2 * h) for e in np.eye(3) * h])
    np.testing.assert_allclose(grad, ref_grad, rtol=0, atol=1e-7 * np.abs(ref_grad).max())
