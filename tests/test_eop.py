"""EOP from the IERS tables: nodes equal the published rows, leap seconds handled, JPL EOP file agrees."""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.environment.eop import ARCSEC, default_eop, eop_at, iers_data_dir, read_jpl_eop


def test_values_at_nodes_equal_the_published_c04_row():
    # IERS 20 C04 row for 2012-04-08 (MJD 56025), read here independently of the module's parser
    row = next(line.split() for line in (iers_data_dir() / "eopc04.1962-now").read_text().splitlines()
               if not line.startswith("#") and line.split()[4] == "56025.00")
    v = eop_at(np.datetime64("2012-04-08T00:00"))
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
