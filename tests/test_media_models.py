"""Troposphere and ionosphere models against published and peer-documented values."""

import re

import numpy as np
import pytest

from odpipe.media import niell, saastamoinen
from odpipe.media.ionosphere import IonexModel, group_delay, pierce_point
from odpipe.media.seasonal import dsn_seasonal
from parsers.ionex import read_ionex

F_L1 = 1575.42e6


def test_niell_matches_orekit_documented_factors():
    # Orekit NiellMappingFunctionModelTest.testMappingFactors: 1994-01-01 (doy 1), lat 48 deg,
    # lon 0.20 deg, h 68 m, elevation 5 deg -> hydrostatic 10.16, wet 10.75 (given to 2 decimals)
    e, lat = np.radians(5.0), np.radians(48.0)
    assert niell.hydrostatic(e, lat, 68.0, 1) == pytest.approx(10.16, abs=0.005)
    assert niell.wet(e, lat) == pytest.approx(10.75, abs=0.005)


def test_niell_limits_and_hemispheres():
    lat = np.radians(40.0)
    assert niell.hydrostatic(np.pi / 2, lat, 1000.0, 77) == pytest.approx(1.0, abs=1e-12)
    assert niell.wet(np.pi / 2, lat) == pytest.approx(1.0, abs=1e-12)
    # southern winter = northern winter half a year later (Niell: phase shift of 365.25/2 days)
    assert niell.hydrostatic(0.2, -lat, 0.0, 28 + 365.25 / 2) == pytest.approx(niell.hydrostatic(0.2, lat, 0.0, 28))
    # above ~15 deg the mapping is close to 1/sin(e) (Niell 1996, fig. 1: < 1 % difference)
    assert niell.wet(np.radians(30), lat) == pytest.approx(1 / np.sin(np.radians(30)), rel=0.01)


def test_saastamoinen_standard_sea_level():
    # Davis et al. (1985): ZHD = 0.0022768 P / f(phi, h); at 1013.25 hPa, 45 deg, sea level: 2.3070 m
    assert saastamoinen.zenith_hydrostatic(101325.0, np.radians(45.0), 0.0) == pytest.approx(2.3070, abs=1e-4)


@pytest.mark.realdata
def test_standard_atmosphere_zenith_matches_orekit_table(shared_data):
    # Orekit tropospheric-delay.txt: canonical Saastamoinen, standard atmosphere, heights 0..5000 m,
    # total delay (m, rounded to 0.1) in the 90 deg column
    text = (shared_data / "media" / "atmosphere" / "tropospheric-delay.txt").read_text()
    rows = [r for r in text.splitlines() if re.match(r"^\s*\d+\s*\|", r)]
    for row in rows:
        cells = [float(c) for c in row.replace("|", " ").split()]
        h, zenith = cells[0], cells[-1]
        dry, wet = saastamoinen.standard_zenith_delays(np.radians(45.0), h)
        # table rounding (0.05 m) plus up to 1 cm from its CIPM-2007 water-vapour law vs our Bean & Dutton
        assert dry + wet == pytest.approx(zenith, abs=0.06), h


def test_dsn_seasonal_model_values():
    cs = dsn_seasonal()
    t = np.datetime64("1972-01-01T00:00", "ns")
    # at the TRIG epoch every cosine is 1, sine 0: a0 + sum(c_k) from TRK-2-23 coefficients
    assert cs.zenith_delay("DSS-14", t, "dry")[0] == pytest.approx(2.0521 + 0.0082 - 0.0004 - 0.0015 - 0.0011)
    assert cs.zenith_delay("DSS-43", t, "wet")[0] == pytest.approx(0.1149 + 0.0255 + 0.0010 + 0.0036 + 0.0007)
    # Goldstone summer is wetter than winter; Canberra the other way round
    jan, jul = np.array(["2006-01-15", "2006-07-15"], dtype="datetime64[ns]")
    assert cs.zenith_delay("DSS-25", jul, "wet")[0] > cs.zenith_delay("DSS-25", jan, "wet")[0]
    assert cs.zenith_delay("DSS-34", jan, "wet")[0] > cs.zenith_delay("DSS-34", jul, "wet")[0]


@pytest.fixture(scope="module")
def gim(shared_data):
    return read_ionex(shared_data / "ionex" / "gpsg0150.19i")


@pytest.mark.realdata
def test_zenith_l1_delay_matches_orekit(gim):
    # Orekit GlobalIonosphereMapModelTest (file gpsg0150.19i, simple linear time interpolation, GPS L1):
    # testDelayAtIPP: 2019-01-15 03:43:12 UTC, 30 N 130 W, zenith -> 1.557 m
    # testSpacecraftState: same epoch, Cuttack 20.5236 N 85.7881 E, zenith at the site -> 2.173 m
    model = IonexModel(gim, time_interpolation="linear")
    t = np.datetime64("2019-01-15T03:43:12", "ns")
    assert group_delay(model.vtec(30.0, -130.0, t), F_L1) == pytest.approx(1.557, abs=1e-3)
    assert group_delay(model.vtec(20.5236, 85.7881, t), F_L1) == pytest.approx(2.173, abs=1e-3)


@pytest.mark.realdata
def test_rotated_time_interpolation_matches_orekit(gim):
    # Orekit testTimeInterpolation (55 N 15 E): at 14:00 the grid value 103 (0.1 TECU) for every method;
    # at 14:30 rotated maps give 0.5 ((1-r) 104 + r 105) + 0.5 ((1-r) 101 + r 100) = 102.5, simple gives 102.
    rot, lin = IonexModel(gim), IonexModel(gim, time_interpolation="linear")
    t14, t1430 = np.array(["2019-01-15T14:00", "2019-01-15T14:30"], dtype="datetime64[ns]")
    assert rot.vtec(55.0, 15.0, t14) == pytest.approx(10.3, abs=1e-12)
    assert rot.vtec(55.0, 15.0, t1430) == pytest.approx(10.25, abs=1e-12)
    assert lin.vtec(55.0, 15.0, t1430) == pytest.approx(0.5 * (10.3 + 10.1), abs=1e-12)


@pytest.mark.realdata
def test_bilinear_between_grid_points_and_wrap(gim):
    model = IonexModel(gim, time_interpolation="linear")
    t = np.datetime64("2019-01-15T14:00", "ns")
    k = np.flatnonzero(gim.epochs == t)[0]
    g = lambda la, lo: gim.tec[k, 0, np.flatnonzero(gim.lat_deg == la)[0], np.flatnonzero(gim.lon_deg == lo)[0]]
    expect = 0.25 * 0.6 * g(55.0, 15.0) + 0.75 * 0.6 * g(55.0, 20.0) + 0.25 * 0.4 * g(52.5, 15.0) \
        + 0.75 * 0.4 * g(52.5, 20.0)
    assert model.vtec(54.0, 18.75, t) == pytest.approx(expect, abs=1e-12)
    # Orekit testParser: longitudes 181 = -179 and 0 = 360 give the same delay
    assert model.vtec(45.0, 181.0, t) == pytest.approx(model.vtec(45.0, -179.0, t), abs=1e-12)
    assert model.vtec(45.0, 0.0, t) == pytest.approx(model.vtec(45.0, 360.0, t), abs=1e-12)
    assert np.isnan(model.vtec(45.0, 0.0, np.datetime64("2019-01-14T23:00", "ns")))


def test_pierce_point_thin_shell():
    lat, lon, ob = pierce_point(0.3, 1.0, 0.0, np.pi / 2, 6371e3, 350e3)
    assert (lat, lon, ob) == pytest.approx((0.3, 1.0, 1.0))
    # due north at elevation e: shell angle z' from sin z' = R/(R+H) cos e; IPP north by z - z'
    e = np.radians(20.0)
    zp = np.arcsin(6371 / 6721 * np.cos(e))
    lat, lon, ob = pierce_point(0.3, 1.0, 0.0, e, 6371e3, 350e3)
    assert lat == pytest.approx(0.3 + (np.pi / 2 - e - zp)) and lon == pytest.approx(1.0)
    assert ob == pytest.approx(1 / np.cos(zp))


@pytest.mark.realdata
def test_slant_delay_to_a_leo_matches_orekit(gim):
    # Orekit GlobalIonosphereMapModelTest.testSpacecraftState: Keplerian orbit a 7187990.1979844316 m,
    # e 0.5e-4, i 98.01, w 131.88, RAAN 252.24, true anomaly 250.00 deg (EME2000) at 2019-01-15 03:43:12 UTC,
    # seen from Cuttack (20.5236 N, 85.7881 E, 36 m): L1 path delay 2.811 m (simple linear interpolation)
    from odpipe.environment.stations import Station, geodetic_to_itrs, topocentric
    from odpipe.frames.earth import gcrs_to_itrs

    a, e = 7187990.1979844316, 0.5e-4
    inc, argp, raan, nu = np.radians([98.01, 131.88, 252.24, 250.0])
    r = a * (1 - e * e) / (1 + e * np.cos(nu))
    u = argp + nu
    r_eci = r * np.array([np.cos(raan) * np.cos(u) - np.sin(raan) * np.sin(u) * np.cos(inc),
                          np.sin(raan) * np.cos(u) + np.cos(raan) * np.sin(u) * np.cos(inc),
                          np.sin(u) * np.sin(inc)])
    t = np.array(["2019-01-15T03:43:12"], dtype="datetime64[ns]")
    site = geodetic_to_itrs(np.radians(20.5236), np.radians(85.7881), 36.0)
    az, el, _ = topocentric(Station("Cuttack", site), (gcrs_to_itrs(t)[0] @ r_eci)[None], None)
    lat_c = np.arctan2(site[2], np.hypot(site[0], site[1]))
    model = IonexModel(gim, time_interpolation="linear")
    delay = group_delay(model.slant_tec(lat_c, np.radians(85.7881), az, el, t), F_L1)
    assert delay[0] == pytest.approx(2.811, abs=1e-3)
