"""Solid Earth tide displacement against the IERS Conventions (2010) DEHANTTIDEINEL test cases."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.solid_tides import solid_earth_tide, station_tide_displacement
from odpipe.environment.stations import StationCatalog

# IERS DEHANTTIDEINEL.F prolog: date (0h UTC), station, Sun, Moon (ITRS, m) -> displacement (m)
IERS_CASES = [
    ("2009-04-13", (4075578.385, 931852.890, 4801570.154),
     (137859926952.015, 54228127881.4350, 23509422341.6960), (-179996231.920342, -312468450.131567, -169288918.592160),
     (0.7700420357108125891e-01, 0.6304056321824967613e-01, 0.5516568152597246810e-01)),
    ("2012-07-13", (1112189.660, -4842955.026, 3985352.284),
     (-54537460436.2357, 130244288385.279, 56463429031.5996), (300396716.912, 243238281.451, 120548075.939),
     (-0.2036831479592075833e-01, 0.5658254776225972449e-01, -0.7597679676871742227e-01)),
    ("2015-07-15", (1112200.5696, -4842957.8511, 3985345.9122),
     (100210282451.6279, 103055630398.3160, 56855096480.4475), (369817604.4348, 1897917.5258, 120804980.8284),
     (0.00509570869172363845, 0.0828663025983528700, -0.0636634925404189617)),
]


@pytest.mark.parametrize("date, sta, sun, moon, expected", IERS_CASES)
def test_iers_dehanttideinel_cases(date, sta, sun, moon, expected):
    d = solid_earth_tide(np.array(sta), np.array(sun), np.array(moon), np.datetime64(date + "T00:00", "ns"))
    np.testing.assert_allclose(d, expected, rtol=0, atol=1e-9)  # measured 1e-16 m


def test_vectorized_cases_equal_single_ones():
    sta = np.array([c[1] for c in IERS_CASES])
    sun = np.array([c[2] for c in IERS_CASES])
    moon = np.array([c[3] for c in IERS_CASES])
    t = np.array([c[0] for c in IERS_CASES], dtype="datetime64[ns]")
    np.testing.assert_allclose(solid_earth_tide(sta, sun, moon, t), [c[4] for c in IERS_CASES], rtol=0, atol=1e-9)


def test_dss14_displacement_over_a_day_has_the_known_size():
    st = StationCatalog.default()["DSS-14"]
    t = np.arange(np.datetime64("2012-04-08T00:00"), np.datetime64("2012-04-09T00:00"),
                  np.timedelta64(20, "m")).astype("datetime64[ns]")
    d = station_tide_displacement(st.position_itrs(t), t, Ephemeris.open())
    up = np.einsum("ni,ni->n", d, st.position_itrs(t) / np.linalg.norm(st.position_itrs(t), axis=1)[:, None])
    assert 0.15 < up.max() - up.min() < 0.8       # semidiurnal radial swing of decimetres
    assert np.linalg.norm(d, axis=1).max() < 0.45  # bounded by the ~0.4 m maximum of the body tide
