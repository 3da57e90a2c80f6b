"""Moon PA/ME/IAU frames against SPICE pxform on NAIF kernels (moon_080317.tf, DE421 PA bpc, pck00010)."""

from __future__ import annotations

import numpy as np
import pytest
import spiceypy as sp

from odpipe.frames.moon import moon_iau_to_icrf, moon_me_to_icrf, moon_me_to_pa, moon_pa_to_icrf

EPOCHS = np.linspace(-2.0e8, 8.0e8, 11)  # 1993..2025, TDB s past J2000


@pytest.fixture()
def spice(shared_data):
    k = shared_data / "kernels"
    kernels = [str(k / f) for f in ("naif0012.tls", "moon_080317.tf", "moon_pa_de421_1900-2050.bpc", "pck00010.tpc")]
    for path in kernels:
        sp.furnsh(path)
    yield sp
    for path in kernels:  # only ours: other modules may hold kernels in the same session
        sp.unload(path)


@pytest.mark.realdata
def test_pa_from_the_bpc_equals_spice(spice, shared_data):
    # SPICE labels the DE421 inertial axes 'J2000'; they are the ICRF, so no frame bias in either
    ref = np.array([spice.pxform("MOON_PA", "J2000", t) for t in EPOCHS])
    ours = moon_pa_to_icrf(EPOCHS, shared_data / "kernels" / "moon_pa_de421_1900-2050.bpc")
    assert np.abs(ours - ref).max() < 1e-12  # measured 8e-13 (W ~ 3.6e3 rad: cos/sin round-off)


@pytest.mark.realdata
def test_pa_from_the_de421_package_librations_equals_spice(spice):
    ref = np.array([spice.pxform("MOON_PA", "J2000", t) for t in EPOCHS])
    assert np.abs(moon_pa_to_icrf(EPOCHS) - ref).max() < 2e-12  # measured 1.3e-12 (3 m-rad at the surface: 2 nm)


@pytest.mark.realdata
def test_me_and_iau_frames_equal_spice(spice):
    me = np.array([spice.pxform("MOON_ME", "J2000", t) for t in EPOCHS])
    assert np.abs(moon_me_to_icrf(EPOCHS) - me).max() < 2e-12
    np.testing.assert_allclose(moon_me_to_pa(), spice.pxform("MOON_ME", "MOON_PA", 0.0), rtol=0, atol=1e-15)
    iau = np.array([spice.pxform("IAU_MOON", "J2000", t) for t in EPOCHS])
    assert np.abs(moon_iau_to_icrf(EPOCHS) - iau).max() < 1e-12


def test_pa_and_iau_differ_by_the_expected_tens_of_arcseconds():
    # The IAU model approximates the ME frame to ~100 m on the surface (Archinal et al. 2011): < 150"
    d = np.swapaxes(moon_iau_to_icrf(EPOCHS), 1, 2) @ moon_me_to_icrf(EPOCHS)
    angle = np.arccos(np.clip((np.trace(d, axis1=1, axis2=2) - 1) / 2, -1, 1))
    assert np.degrees(angle).max() * 3600 < 150


def test_outside_libration_span_is_an_error():
    with pytest.raises(ValueError, match="lunar librations unavailable"):
        moon_pa_to_icrf(np.array([0.0, 7.0e9]))  # 2221: beyond the de421 package (1900-2200)
