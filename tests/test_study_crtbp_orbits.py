"""CRTBP reference orbits: halo periodicity and period, Keplerian orbiters by vis-viva."""

import numpy as np
import pytest

from odpipe.dynamics.crtbp import jacobi_constant, propagate_crtbp
from odpipe.studies.crtbp_orbits import correct_halo, halo_by_period, halo_start, keplerian_orbit

MU = 0.01215


def test_halo_of_requested_period_closes_after_one_period():
    s, T = halo_by_period(2.78, 0.82938, 0.22550, 0.11, 0.13, MU)
    assert T == pytest.approx(2.78, abs=1e-9)
    tr = propagate_crtbp(s, 0.0, T, MU, with_stm=False)
    end = tr.state(T)[0]
    assert np.allclose(end, s, atol=1e-7)                          # periodic
    assert abs(jacobi_constant(end, MU) - jacobi_constant(s, MU)) < 1e-11
    assert s[2] > 0.1                                               # a halo, not a planar Lyapunov orbit


@pytest.mark.parametrize("at,north", [("apolune", True), ("perilune", True), ("apolune", False)])
def test_halo_start_picks_the_crossing_and_hemisphere(at, north):
    s, T = halo_by_period(3.30, 1.1137, 0.1953, 0.03, 0.075, MU)       # L2 halo, starts near perilune
    x = halo_start(s, T, MU, at, north)
    other = propagate_crtbp(x, 0.0, T / 2, MU, with_stm=False).state(T / 2)[0]
    moon = np.array([1 - MU, 0, 0])
    assert (np.linalg.norm(x[:3] - moon) > np.linalg.norm(other[:3] - moon)) == (at == "apolune")
    assert (x[2] > 0) == north and abs(x[1]) < 1e-9 and abs(x[3]) < 1e-9   # on the x-z plane, crossing it
    assert np.allclose(propagate_crtbp(x, 0.0, T, MU, with_stm=False).state(T)[0], x, atol=1e-7)
    assert jacobi_constant(x, MU) == pytest.approx(jacobi_constant(s, MU), abs=1e-10)


def test_correct_halo_keeps_the_amplitude():
    s, T = correct_halo(0.8234, 0.01, 0.13, MU)
    assert s[2] == 0.01
    assert 2.7 < T < 2.8                                           # ~11.9 d small L1 halo
    assert np.all(np.isfinite(s))


@pytest.mark.parametrize("primary,ecc,nu", [("moon", 0.5, 0.0), ("moon", 0.5, np.pi), ("earth", 0.0, 1.0)])
def test_keplerian_orbit_obeys_vis_viva(primary, ecc, nu):
    period = 0.2139
    x = keplerian_orbit(period, ecc, np.radians(56.2), MU, true_anomaly=nu, primary=primary)
    gm, centre = (MU, 1 - MU) if primary == "moon" else (1 - MU, -MU)
    r_vec = x[:3] - [centre, 0, 0]
    v_inertial = x[3:] + np.cross([0, 0, 1.0], r_vec)
    a = (gm * (period / (2 * np.pi)) ** 2) ** (1 / 3)
    r = np.linalg.norm(r_vec)
    assert r == pytest.approx(a * (1 - ecc**2) / (1 + ecc * np.cos(nu)), rel=1e-12)
    assert np.linalg.norm(v_inertial) ** 2 == pytest.approx(gm * (2 / r - 1 / a), rel=1e-12)
    assert np.degrees(np.arccos(np.cross(r_vec, v_inertial)[2] / np.linalg.norm(np.cross(r_vec, v_inertial)))) \
        == pytest.approx(56.2)
