"""Time scales against outside references: IERS Bulletin C leap seconds (via SOFA/ERFA
``dat``), ERFA ``dtdb``, SPICE ``str2et`` with naif0012.tls, GPS−UTC from IS-GPS-200."""

from __future__ import annotations

import erfa
import numpy as np
import pytest
import spiceypy as sp

import odpipe.time as T


def _dt(*s):
    return np.array(s, dtype="datetime64[ns]")


def test_tai_minus_utc_published_steps():
    # IERS Bulletin C: 10 s from 1972-01-01, 11 s from 1972-07-01, 36 s on 2016-12-31, 37 s from 2017-01-01
    e = _dt("1972-01-01T00:00", "1972-06-30T23:59:59", "1972-07-01T00:00", "2016-12-31T23:59:59.999",
            "2017-01-01T00:00:00")
    np.testing.assert_array_equal(T.tai_minus_utc(e), [10, 10, 11, 36, 37])


def test_tai_minus_utc_matches_sofa_dat_every_month():
    months = np.arange(np.datetime64("1972-01"), np.datetime64("2026-01"), np.timedelta64(1, "M"))
    ours = T.tai_minus_utc(months.astype("datetime64[ns]"))
    y = months.astype("datetime64[Y]").astype(int) + 1970
    m = months.astype(int) % 12 + 1
    sofa = erfa.dat(y, m, np.ones_like(y), np.zeros(len(y)))
    np.testing.assert_array_equal(ours, sofa)


def test_before_1972_and_missing_epochs_are_errors():
    with pytest.raises(ValueError, match="1969-07-20"):
        T.utc_to_tdb(np.datetime64("1969-07-20T20:17"))
    with pytest.raises(ValueError, match="NaT"):
        T.utc_to_tdb(np.array(["2012-01-01", "NaT"], dtype="datetime64[ns]"))
    with pytest.raises(ValueError, match="NaN"):
        T.tdb_to_utc(np.array([0.0, np.nan]))
    with pytest.raises(TypeError, match="datetime64"):
        T.utc_to_tdb(np.array([1.0, 2.0]))


def test_tt_and_tai_offsets():
    e = _dt("2017-01-01T00:00:00")
    assert T.utc_to_tai(e)[0] == np.datetime64("2017-01-01T00:00:37", "ns")
    assert T.utc_to_tt(e)[0] == np.datetime64("2017-01-01T00:01:09.184", "ns")
    assert T.tt_to_utc(T.utc_to_tt(e))[0] == e[0]


def test_tdb_minus_tt_equals_erfa_dtdb_with_station_terms():
    t = np.linspace(-5e8, 8e8, 50)
    station = np.array([-2353621.42, -4641341.472, 3677052.318])  # DSS-14, m
    ours = T.tdb_minus_tt(t, station)
    ut = np.mod(t / 86400.0 + 0.5, 1.0)
    ref = erfa.dtdb(2451545.0, t / 86400.0, ut, np.arctan2(station[1], station[0]),
                    np.hypot(station[0], station[1]) / 1e3, station[2] / 1e3)
    np.testing.assert_allclose(ours, ref, rtol=0, atol=1e-15)
    geo = T.tdb_minus_tt(t)
    assert 0.1e-6 < np.abs(ours - geo).max() < 3e-6  # the topocentric term is ~2 µs
    assert np.abs(geo).max() < 1.7e-3


@pytest.mark.realdata
def test_utc_to_tdb_agrees_with_spice(shared_data):
    lsk = str(shared_data / "kernels" / "naif0012.tls")
    sp.furnsh(lsk)
    try:
        iso = ["1980-01-06T00:00:00", "2006-02-27T12:34:56.5", "2012-04-08T06:20:00", "2016-12-31T23:59:59",
               "2017-01-01T00:00:00"]
        ours = T.utc_to_tdb(_dt(*iso))
        spice = np.array([sp.str2et(s) for s in iso])
        # SPICE's TDB-TT is a 1-term formula (|error| < 30 µs against the full series used here)
        np.testing.assert_allclose(ours, spice, rtol=0, atol=3e-5)  # measured 21 µs
    finally:
        sp.unload(lsk)  # only ours: other modules may hold kernels in the same session


def test_round_trip_utc_tdb_two_part_is_exact_to_the_ns():
    rng = np.random.default_rng(1)
    ns = rng.integers(np.datetime64("1990-01-01", "ns").astype(np.int64),
                      np.datetime64("2030-01-01", "ns").astype(np.int64), 5000)
    e = ns.astype("datetime64[ns]")
    e = np.concatenate([e, _dt("2016-12-31T23:59:59.999999999", "2017-01-01T00:00:00")])
    whole, frac = T.utc_to_tdb2(e)
    assert np.all((frac >= 0) & (frac < 1))
    np.testing.assert_array_equal(T.tdb2_to_utc(whole, frac), e)
    back = T.tdb_to_utc(T.utc_to_tdb(e))  # float64 path: limited by the ~0.1 µs ulp
    assert np.abs((back - e).astype(np.int64)).max() <= 150


def test_gps_minus_utc_is_18_s_since_2017():
    # IS-GPS-200 / USNO: GPS-UTC = 18 s since 2017-01-01; GPS week 1930 began 2017-01-01T00:00:00 GPS
    e = _dt("2017-01-01T00:00:00", "1980-01-06T00:00:00")
    s = T.utc_to_gps_seconds(e)
    assert s[1] == 0.0
    week, sow = T.utc_to_gps_week(e[:1])
    assert week[0] == 1930 and sow[0] == 18.0
    np.testing.assert_array_equal(T.gps_seconds_to_utc(s), e)


def test_odf_and_day_of_year():
    # ODF time tags count s from 1950-01-01 UTC; 2006-02-27 (DOY 58) is day 20511 after it
    e = T.odf_seconds_to_utc(np.array([20511 * 86400 + 3600]), 0.25)
    assert e[0] == np.datetime64("2006-02-27T01:00:00.25", "ns")
    whole, frac = T.utc_to_odf_seconds(e)
    assert whole[0] == 20511 * 86400 + 3600 and frac[0] == 0.25
    assert T.doy_to_utc(2012, 99, 22800.5) == np.datetime64("2012-04-08T06:20:00.5", "ns")
    y, d, s = T.utc_to_doy(_dt("2012-12-31T23:59:59", "2006-02-27T00:00"))
    np.testing.assert_array_equal(y, [2012, 2006])
    np.testing.assert_array_equal(d, [366, 58])
    with pytest.raises(ValueError, match="day of year"):
        T.doy_to_utc(2012, 367)


def test_geocentric_tdb_minus_tt_from_hourly_values_equals_erfa():
    """The hourly-cached geocentric series, over three years and after a jump to another decade."""
    from odpipe.time.scales import tdb_minus_tt

    rng = np.random.default_rng(1)
    for start in (3.0e8, 8.0e8, 3.0e8):
        t = np.sort(rng.uniform(start, start + 9.5e7, 5000))
        ref = erfa.dtdb(2451545.0, t / 86400.0, 0.0, 0.0, 0.0, 0.0)
        assert np.abs(tdb_minus_tt(t) - ref).max() < 1e-14  # s


def test_geocentric_tdb_minus_tt_extended_a_month_at_a_time_equals_erfa():
    """Requests that widen the kept hours on either side (out of order) give ERFA's values everywhere."""
    from odpipe.time.scales import _HourlyGeocentricDtdb

    series = _HourlyGeocentricDtdb()
    rng = np.random.default_rng(2)
    months = 2.6e6 * np.array([5, 6, 4, 9, 0, 30, 70, 68, 72])  # s past 2006: gaps, back steps, beyond MAX_H
    for start in 1.9e8 + months:
        t = np.sort(rng.uniform(start, start + 2.6e6, 300))
        ref = erfa.dtdb(2451545.0, t / 86400.0, 0.0, 0.0, 0.0, 0.0)
        assert np.abs(series(t / 86400.0) - ref).max() < 1e-14  # s
        assert series.values.size - 1 <= series.MAX_H  # hours
