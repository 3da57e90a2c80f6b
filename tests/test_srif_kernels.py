"""The SRIF's structured fast paths against the plain algebra they shortcut.

``mapped`` (time update) against ``R Phi^-1`` by a general inverse followed by numpy's Householder QR (same
triangle up to row signs), for transitions ``[[M, Q], [0, I]]`` with M 6 x 6 and 12 x 12 and for one whose
last row is not the identity's (the general path). ``stacked_triangles`` (through ``solve_informations``
and ``information_estimates``) against ``solve_information`` of each array (LAPACK geqrf and trtri) on
triangular arrays (the filter's), arrays ``R Phi`` (the smoother's) and full ones. Random, well-conditioned
cases; agreement within 1e-12 relative (rounding).
"""

import numpy as np
import pytest

from odpipe.estimation.srif import information_estimates, solve_information, solve_informations
from odpipe.estimation.srif_kernels import dynamic_rows, mapped, stacked_triangles, unreduced_rows

N = 54   # the long libration arc's parameter count


def _triangle(rng, n=N):
    """Well-conditioned upper-triangular R: diagonal 1..10, off-diagonal N(0, 0.3)."""
    return np.triu(rng.normal(scale=0.3, size=(n, n)), 1) + np.diag(rng.uniform(1.0, 10.0, n))


def _transition(rng, d, n=N):
    """``[[M, Q], [0, I]]`` with M (d, d) near 1.5 I."""
    Phi = np.eye(n)
    Phi[:d] = rng.normal(scale=0.2, size=(d, n))
    Phi[:d, :d] += 1.5 * np.eye(d)
    return Phi


def _rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


def _signed_like(T, ref):
    """Rows of ``T`` with the signs of ``ref``'s diagonal (a triangle is unique up to row signs)."""
    return T * (np.sign(np.diag(T[:, :ref.shape[0]])) * np.sign(np.diag(ref)))[:, None]


@pytest.mark.parametrize("d, last_row", [(6, False), (12, False), (6, True)])
def test_time_update_matches_inverse_and_qr(d, last_row):
    rng = np.random.default_rng(d + last_row)
    R, z = _triangle(rng), rng.normal(size=N)
    Phi = _transition(rng, d)
    if last_row:                                   # e.g. a clock offset driven by a drift: not [0 | I]
        Phi[-1, -2] = 60.0
    assert dynamic_rows(Phi) == (N if last_row else d)
    R1, z1 = mapped(R, z, Phi)
    T = np.linalg.qr(np.column_stack([R @ np.linalg.inv(Phi), z]), mode="r")
    T = _signed_like(T, R1)
    assert np.array_equal(R1, np.triu(R1))
    assert _rel(R1, T[:, :N]) < 1e-12 and _rel(z1, T[:, N]) < 1e-12


def test_time_update_identity_leaves_the_array():
    rng = np.random.default_rng(3)
    R, z = _triangle(rng), rng.normal(size=N)
    R1, z1 = mapped(R, z, np.eye(N))
    assert np.array_equal(R1, R) and np.array_equal(z1, z)


@pytest.mark.parametrize("kind", ["filter", "smoother", "full"])
def test_stacked_read_outs_match_lapack(kind):
    rng = np.random.default_rng(len(kind))
    K, n_est = 5, N - 4
    R = np.array([_triangle(rng) for _ in range(K)])
    if kind == "smoother":                          # R Phi: only the first d rows leave the triangle
        R = np.array([Rk @ _transition(rng, 12) for Rk in R])
    elif kind == "full":
        R = np.array([Rk @ np.linalg.qr(rng.normal(size=(N, N)))[0] for Rk in R])
    z = rng.normal(size=(K, N))
    assert [unreduced_rows(Rk) for Rk in R] == {"filter": [0] * K, "smoother": [12] * K, "full": [N] * K}[kind]
    c_bar, c_sigma = rng.normal(size=N - n_est), rng.uniform(0.5, 2.0, N - n_est)
    x, P, Pc = solve_informations(R, z, n_est, c_bar, c_sigma)
    ref = [solve_information(Rk, zk, n_est, c_bar, c_sigma) for Rk, zk in zip(R, z)]   # LAPACK geqrf, trtri
    xr, Pr, Pcr = (np.array([getattr(g, a) for g in ref]) for a in ("x", "P", "P_consider"))
    assert _rel(x, xr) < 1e-12 and _rel(P, Pr) < 1e-12 and _rel(Pc, Pcr) < 1e-12
    assert _rel(information_estimates(R, z, n_est, c_bar), xr) < 1e-12
    T = stacked_triangles(R, z)[:, :, :N]
    assert np.array_equal(T, np.triu(T))
