"""GCRS↔ITRS against the SOFA cookbook matrix and SPICE (NAIF high-precision Earth PCK)."""

from __future__ import annotations

import numpy as np
import pytest
import spiceypy as sp

from odpipe.environment.eop import ARCSEC, EOPValues, eop_at
from odpipe.environment.stations import StationCatalog
from odpipe.frames.earth import (_cip_xys_direct, cip_xys, gcrs_to_itrs, gcrs_to_itrs_state, itrs_to_gcrs,
                                 itrs_to_gcrs_state)
from odpipe.time import utc_to_tdb

# SOFA "Tools for Earth Attitude" cookbook (sofa_pn), example of 2007-04-05 12:00 UTC, IERS Bulletin values:
# UT1-UTC = -0.072073685 s, xp = 0.0349282", yp = 0.4833163", dX06 = 0.1750 mas, dY06 = -0.2259 mas.
COOKBOOK_EOP = EOPValues(np.array(-0.072073685), np.array(0.0349282 * ARCSEC), np.array(0.4833163 * ARCSEC),
                         np.array(0.1750e-3 * ARCSEC), np.array(-0.2259e-3 * ARCSEC), np.array(0.0))
# Its celestial-to-terrestrial matrix "IAU 2006/2000A, CIO based, using X,Y series":
COOKBOOK_RC2T_06_XY = np.array([
    [+0.973104317697536, +0.230363826239128, -0.000703163481769],
    [-0.230363800456036, +0.973104570632801, +0.000118545368117],
    [+0.000711560162594, +0.000046626402444, +0.999999745754024]])


def test_sofa_cookbook_matrix_to_1e12():
    m = gcrs_to_itrs(np.datetime64("2007-04-05T12:00"), COOKBOOK_EOP)
    assert np.abs(m - COOKBOOK_RC2T_06_XY).max() < 1e-12  # measured 3.6e-13


def test_same_epoch_given_as_tdb_seconds():
    utc = np.datetime64("2007-04-05T12:00", "ns")
    a = gcrs_to_itrs(utc, COOKBOOK_EOP)
    b = gcrs_to_itrs(utc_to_tdb(utc), COOKBOOK_EOP)
    assert np.abs(a - b).max() < 1e-12  # float64 TDB resolves ~60 ns -> ERA to ~4e-12 rad; measured 4e-13


def test_gridded_cip_matches_the_full_series():
    tt = np.linspace(4500.0, 4503.0, 5000)  # days past J2000: 3 days at ~52 s spacing
    x, y, s = cip_xys(tt)
    xd, yd, sd = _cip_xys_direct(tt)
    err = max(np.abs(x - xd).max(), np.abs(y - yd).max(), np.abs(s - sd).max())
    assert err < 1e-13  # rad; 1e-13 rad = 0.6 µm on the Earth's surface


def test_many_epochs_use_the_cip_grid_and_match_single_epoch_matrices():
    t = np.arange(np.datetime64("2020-01-01"), np.datetime64("2020-01-02"), np.timedelta64(10, "s"))
    m = gcrs_to_itrs(t)
    assert m.shape == (len(t), 3, 3)
    # 8640 epochs go through the 1-hour CIP grid, 9 epochs through the full series: measured 4e-14 rad
    np.testing.assert_allclose(m[::1000] @ itrs_to_gcrs(t[::1000]), np.broadcast_to(np.eye(3), (9, 3, 3)),
                               rtol=0, atol=1e-13)


def test_rotation_velocity_equals_finite_difference_and_state_round_trips():
    r_itrs = np.array([-2353621.42, -4641341.472, 3677052.318])
    for epoch in ("2006-02-27T00:00", "2012-04-08T06:00:00", "2016-12-31T23:59:59.6"):  # last: at a leap second
        t0 = np.datetime64(epoch, "ns")
        h = np.timedelta64(200, "ms")
        r_p, _ = itrs_to_gcrs_state(t0 + h, r_itrs)
        r_m, _ = itrs_to_gcrs_state(t0 - h, r_itrs)
        r0, v0 = itrs_to_gcrs_state(t0, r_itrs)
        # m/s; measured <= 2.7e-7 (ω, precession-nutation, tidal UT1 and pole rates all included)
        np.testing.assert_allclose(v0, (r_p - r_m) / 0.4, rtol=0, atol=5e-7)
        r1, v1 = gcrs_to_itrs_state(t0, r0, v0)
        np.testing.assert_allclose(r1, r_itrs, atol=1e-8)
        np.testing.assert_allclose(v1, 0.0, atol=1e-11)


@pytest.mark.realdata
def test_dss14_gcrs_position_agrees_with_spice(shared_data):
    k = shared_data / "kernels"
    kernels = [str(k / n) for n in ("naif0012.tls", "earth_000101_190127_181105.bpc", "earthstns_itrf93_201023.bsp")]
    for path in kernels:
        sp.furnsh(path)
    try:
        dss14 = StationCatalog.default()["DSS-14"]
        for day in ("2006-02-27", "2012-04-08", "2017-06-01"):
            utc = np.arange(np.datetime64(day + "T00:00"), np.datetime64(day + "T23:59"),
                            np.timedelta64(3, "h")).astype("datetime64[ns]")
            et = utc_to_tdb(utc)
            spice = np.array([sp.spkezr("DSS-14", x, "J2000", "NONE", "EARTH")[0] for x in et]) * 1e3
            itrf93 = np.array([sp.spkezr("DSS-14", x, "ITRF93", "NONE", "EARTH")[0][:3] for x in et]) * 1e3
            # the station model itself (810-005 epoch 2003.0 + plate motion) equals NAIF's station SPK
            assert np.abs(dss14.position_itrs(utc) - itrf93).max() < 1e-6
            # like with like: NAIF's PCK is built from daily EOP without the ocean-tide terms
            r, v = itrs_to_gcrs_state(utc, dss14.position_itrs(utc), eop=eop_at(utc, ocean_tides=False))
            # NAIF's EOP-based ITRF93 PCK is tied to the celestial pole as observed (its dPsi/dEps absorb the
            # frame bias), without IAU 2000A/2006 and with older EOP: measured 3..8 cm over these three days
            assert np.linalg.norm(r - spice[:, :3], axis=1).max() < 0.10
            assert np.linalg.norm(v - spice[:, 3:], axis=1).max() < 2e-5  # m/s; measured 5e-6
    finally:
        for path in kernels:  # only ours: other modules may hold kernels in the same session
            sp.unload(path)
