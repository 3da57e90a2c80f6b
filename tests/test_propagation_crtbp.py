"""CRTBP: Jacobi constant conserved, STM vs central finite differences, L1 halo-like arc."""

import numpy as np

from odpipe.dynamics.crtbp import EarthMoonUnits, jacobi_constant, propagate_crtbp

MU = EarthMoonUnits().mu
# Earth-Moon L2 southern halo initial condition (nondimensional; Howell-type family member)
HALO = np.array([1.1808881, 0.0, -0.0124170, 0.0, -0.1559630, 0.0])


def test_jacobi_constant_conserved():
    traj = propagate_crtbp(HALO, 0.0, 20.0, MU, with_stm=False)
    t = np.linspace(0.0, 20.0, 2001)
    c = jacobi_constant(traj.state(t), MU)
    assert np.ptp(c) < 1e-10, np.ptp(c)  # measured 5e-11 over ~6 revolutions of this unstable orbit


def test_stm_vs_central_differences():
    T = 3.0
    traj = propagate_crtbp(HALO, 0.0, T, MU)
    phi = traj.stm(T)[0]
    fd = np.empty((6, 6))
    for j in range(6):
        h = 1e-7
        e = np.zeros(6)
        e[j] = h
        xp = propagate_crtbp(HALO + e, 0.0, T, MU, with_stm=False).state(T)[0]
        xm = propagate_crtbp(HALO - e, 0.0, T, MU, with_stm=False).state(T)[0]
        fd[:, j] = (xp - xm) / (2 * h)
    np.testing.assert_allclose(phi, fd, rtol=0, atol=1e-6 * np.abs(phi).max())
    # symplectic structure of the CRTBP flow: det(Phi) = 1
    assert abs(np.linalg.det(phi) - 1.0) < 1e-8


def test_dimensional_units_round_trip():
    u = EarthMoonUnits()
    assert abs(u.time / 86400 - 4.3425) < 1e-3  # 27.28 d sidereal month / 2 pi
    np.testing.assert_allclose(u.from_si(u.to_si(HALO)), HALO, rtol=1e-15)
