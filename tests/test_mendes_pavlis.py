"""Mendes-Pavlis optical troposphere against the IERS Conventions (2010) test cases.

The Conventions' software (FCULZD_HPA, FCUL_A) states its test case, McDonald Observatory on
2009-08-14, and Orekit's MendesPavlisModelTest checks the same numbers: latitude 30.67166667 deg,
height 2010.344 m, 798.4188 hPa, water vapour 14.322 hPa, 532 nm -> zenith hydrostatic
1.932992176591644 m, non-hydrostatic 0.2233748255158704e-2 m (total 1.935225924846803 m);
FCULa at 15 deg elevation, height 2075 m, 300.15 K -> 3.800243667312344. Orekit derives the
14.322 hPa from 40 % humidity at 300.15 K with CIPM-2007.
"""

import numpy as np
import pytest

from odpipe.media import mendes_pavlis as mp

LAT = np.radians(30.67166667)


def test_zenith_delays_of_the_conventions_test_case():
    dry, wet = mp.zenith_delays(798.4188e2, 14.322e2, LAT, 2010.344, 532.0)
    # Orekit's tolerance; we are 3.8e-6 m above the published hydrostatic value (2e-6 relative, a
    # rounding in the published run) and 4.5e-9 m from the non-hydrostatic one
    assert dry == pytest.approx(1.932992176591644, abs=4e-6)
    assert wet == pytest.approx(0.2233748255158704e-2, abs=1e-8)
    assert dry + wet == pytest.approx(1.935225924846803, abs=4e-6)


def test_fcula_mapping_of_the_conventions_test_case():
    assert mp.mapping(np.radians(15.0), LAT, 2075.0, 300.15) == pytest.approx(3.800243667312344, abs=1e-12)
    assert mp.mapping(np.pi / 2, LAT, 2075.0, 300.15) == pytest.approx(1.0, abs=1e-15)


def test_vapour_pressure_from_humidity_gives_the_test_case_value():
    assert mp.vapour_pressure(40.0, 300.15, 798.4188e2) == pytest.approx(14.322e2, abs=0.05)


def test_dispersion_follows_the_wavelength():
    # the dispersion factor is 1 near 532 nm by construction of the 2.416579e-3 constant ...
    f_h, _ = mp.dispersion(532.0)
    assert f_h == pytest.approx(1.0, abs=1e-6)
    # ... and the infrared (1064 nm) delay is 4.5 % below the green one (group refractivity of air falls
    # with wavelength); 2.45 m at the zenith of a sea-level site in green light
    d532 = mp.slant_delay(np.pi / 2, np.radians(45), 0.0, 1013.25e2, 288.15, 50.0, 532.0)
    d1064 = mp.slant_delay(np.pi / 2, np.radians(45), 0.0, 1013.25e2, 288.15, 50.0, 1064.0)
    assert 2.44 < d532 < 2.46 and 0.95 < d1064 / d532 < 0.96


def test_laser_rows_get_it_from_their_own_meteo_in_calibrate():
    from odpipe.environment.stations import StationCatalog, itrs_to_geodetic, topocentric
    from odpipe.media import saastamoinen
    from odpipe.media.apply import calibrate
    from odpipe.media.model import MediaModel
    from parsers import table as tt

    st = StationCatalog.default()["DSS-25"]
    lat, _, h = itrs_to_geodetic(st.r_itrs)
    sat = st.r_itrs * 1.6                                         # fixed in ITRS above the site: one elevation
    _, el, _ = topocentric(st, sat, None)
    ep = np.datetime64("2016-02-13T12:00", "ns") + np.arange(3) * np.timedelta64(60, "s")
    rows = tt.build(3, epoch=ep, tag="receive", observable="range", unit="m", value=7e6, station_tx="DSS-25",
                    station_rx="DSS-25", spacecraft="sat", wavelength_nm=[532.0, 1064.0, np.nan],
                    pressure_mbar=[900.0, np.nan, 900.0], temperature_k=290.0, humidity_pct=40.0)
    out, _ = calibrate(rows, MediaModel(), target_itrs=lambda t: np.broadcast_to(sat, (np.size(t), 3)), order=None)
    one_way = mp.slant_delay(el, lat, h, 900e2, 290.0, 40.0, 532.0)
    assert out["tropo_m"].iloc[0] == pytest.approx(2 * one_way, abs=1e-9)         # both legs, row's meteo
    p, t, e = saastamoinen.standard_atmosphere(h)                                  # no pressure: standard
    dry, wet = mp.zenith_delays(p, e, lat, h, 1064.0)
    assert out["tropo_m"].iloc[1] == pytest.approx(2 * (dry + wet) * mp.mapping(el, lat, h, t), abs=1e-9)
    assert (out["iono_m"].iloc[:2] == 0).all()
    assert list(out["media_source"].astype(str)) == [
        "tropo: Mendes-Pavlis (row meteo) | iono: not at optical wavelengths",
        "tropo: Mendes-Pavlis (no meteo) | iono: not at optical wavelengths",
        "tropo: DSN-seasonal (no TRO) | iono: none"]                              # a radio row: as before
    assert out["media_note"].iloc[1] == "laser row without meteorology: standard atmosphere used"
