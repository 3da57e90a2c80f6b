"""EOP from the IERS tables: nodes equal the published rows, leap seconds handled, JPL EOP file agrees."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.environment.eop import ARCSEC, default_eop, eop_at, iers_data_dir, read_jpl_eop
from odpipe.environment.eop_tides import _orthotide_partials, ocean_tide_eop


def test_values_at_nodes_equal_the_published_c04_row():
    # IERS 20 C04 row for 2012-04-08 (MJD 56025), read here independently of the module's parser
    row = next(line.split() for line in (iers_data_dir() / "eopc04.1962-now").read_text().splitlines()
               if not line.startswith("#") and line.split()[4] == "56025.00")
    v = eop_at(np.datetime64("2012-04-08T00:00"), ocean_tides=False)
    assert v.xp == pytest.approx(float(row[5]) * ARCSEC, abs=1e-15)
    assert v.yp == pytest.approx(float(row[6]) * ARCSEC, abs=1e-15)
    assert v.ut1_utc == pytest.approx(float(row[7]), abs=1e-12)
    assert v.dx == pytest.approx(float(row[8]) * ARCSEC, abs=1e-15)
    assert v.lod == pytest.approx(float(row[12]), abs=1e-12)


def test_ut1_utc_jumps_by_the_leap_second_and_ut1_is_continuous():
    e = np.array(["2016-12-31T23:59:59.999", "2017-01-01T00:00:00"], dtype="datetime64[ns]")
    v = eop_at(e)
    assert v.ut1_utc[1] - v.ut1_utc[0] == pytest.approx(1.0, abs=1e-6)
    assert 0.4 < v.ut1_utc[1] < 0.6  # Bulletin A/C04: UT1-UTC ≈ +0.59 s right after the 2017 leap second


def test_outside_table_is_an_error_naming_the_epoch():
    lo, hi = default_eop().span
    with pytest.raises(ValueError, match="2099-01-01"):
        eop_at(np.datetime64("2099-01-01T00:00"))
    assert hi > np.datetime64("2026-01-01")


@pytest.mark.realdata
def test_jpl_eop_file_agrees_with_iers(shared_data):
    # JPL/DSN EOP file delivered with the Cassini data (MJD, PM mas, TAI-UT1, TAI-UTC)
    jpl = read_jpl_eop(shared_data / "cassini" / "S18TIGE2005_141_2006_142.EOP")
    t = np.arange(np.datetime64("2005-06-01"), np.datetime64("2006-02-27"), np.timedelta64(7, "h"))
    a, b = jpl.at(t), eop_at(t)
    assert np.abs(a.ut1_utc - b.ut1_utc).max() < 1e-4            # measured 62 µs
    assert np.abs(a.xp - b.xp).max() < 3e-3 * ARCSEC              # measured 1.9 mas (ITRF93 vs ITRF2020 pole)
    assert np.abs(a.yp - b.yp).max() < 3e-3 * ARCSEC              # measured 2.4 mas
    with pytest.raises(ValueError, match="2007-01-01"):
        jpl.at(np.datetime64("2007-01-01"))


def test_malformed_jpl_eop_names_the_line(tmp_path):
    p = tmp_path / "bad.EOP"
    p.write_text(" EOP=\n 53511.0,  -72.44,  328.40,  32.613341,  32.0,  -52.83,   -4.68, $ ok\n 53512.0, x\n")
    with pytest.raises(ValueError, match="bad.EOP:3"):
        read_jpl_eop(p)


def test_ocean_tide_eop_matches_the_iers_test_cases():
    # IERS Conventions software ORTHO_EOP test case: MJD 47100 ->
    # dx = -162.8386373279636530 µas, dy = 117.7907525842668974 µas, dUT1 = -23.39092370609808214 µs
    dx, dy, dut1 = ocean_tide_eop(47100.0)
    np.testing.assert_allclose([dx, dy, dut1], [-162.8386373279636530, 117.7907525842668974, -23.39092370609808214],
                               rtol=0, atol=1e-9)
    # CNMTX test case: MJD 54964 -> the 12 orthotide partials h(1..12)
    h = _orthotide_partials(np.array(54964.0))
    np.testing.assert_allclose(h, [15.35873641938967360, 9.784941251812741214, -5.520740128266865554,
                                   3.575314211234633888, -13.93717453496387648, -9.167400321705855504,
                                   5.532815475865292321, 9.558741883500834646, -10.22541212627272600,
                                   0.8367570529461261231, 1.946355176475630611, -13.55702062247304696],
                               rtol=0, atol=1e-9)


def test_ocean_tides_are_added_to_interpolated_eop():
    t = np.arange(np.datetime64("2012-04-08T00:00"), np.datetime64("2012-04-09T00:00"), np.timedelta64(1, "h"))
    with_tides, without = eop_at(t), eop_at(t, ocean_tides=False)
    ut1 = with_tides.ut1_utc - without.ut1_utc
    assert 5e-6 < np.abs(ut1).max() < 1e-4   # tens of µs, diurnal/semidiurnal
    assert np.abs(with_tides.xp - without.xp).max() < 1e-3 * ARCSEC
