"""UTDF reader/writer against decoded values published with other readers.

External references: Astro::UTDF (trwyant/perl-Astro-UTDF) t/real_data.t for
doppler.utdf and the t/utdf.t version that reads data.utd (values quoted below
with the format the Perl test prints them in); utdfgo (ATTron/utdfgo) whose
test packet copies the last record of the LSUTDF file (year 19, SIC 3675,
VID 1, 3772500 s of year); PROVENANCE.md (301 records, 15:49:59-15:55:00,
S band) and the LSUTDF file name (SIC 3675, VID 01, pad 119, 2019 day 044).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from parsers import ParseError, utdf

C_KM_S = 299792.458
LSUTDF = "utdf/LSUTDF_367501_119_2019_044_1555.trk"
FIXTURE_DIR = Path(__file__).resolve().parents[1] / "fixtures" / "utdf"


def _row(d, record, observable):
    t = d.table
    return t[(t["record"] == record) & (t["observable"] == observable)].iloc[0]


def _unix(ts) -> float:
    return (np.datetime64(ts, "ns") - np.datetime64("1970-01-01", "ns")) / np.timedelta64(1, "s")


@pytest.mark.realdata
def test_data_utd_matches_astro_utdf(shared_data):
    d = utdf.read(shared_data / "utdf/data.utd")
    rec = d.meta["records"].loc[1]
    assert (rec["agc"], rec["validity"], rec["sic"], rec["vid"], rec["year"]) == (1234, 7, 86, 99, 10)
    assert (rec["seconds_of_year"], rec["microseconds"], rec["router"]) == (6656491, 0, "AA")
    assert (rec["tracker_and_interval"], rec["tx_pad"], rec["rx_pad"]) == (4097, 42, 42)
    assert (rec["tx_antenna_type"], rec["rx_antenna_type"], rec["mode"]) == (64, 64, 0)
    assert rec["doppler_count"] == 465608177 and rec["tdrss"] == b""
    az, el = _row(d, 1, "angle_az"), _row(d, 1, "angle_el")
    assert f"{az['value']:.9f}" == "5.852690027" and f"{el['value']:.9f}" == "0.953498911"
    assert _unix(az["epoch"]) == 1268960491  # Fri Mar 19 01:01:31 2010
    dop = _row(d, 1, "doppler_2way")
    # Astro::UTDF's shift; the table's value carries the DSN sign (positive receding): minus the shift
    assert f"{dop['doppler_shift_hz']:.3f}" == "25608.177" and dop["value"] == -dop["doppler_shift_hz"]
    assert dop["count_time"] == 1.0
    assert dop["uplink_hz"] == 2050000000 and f"{dop['transponder_ratio']:.8f}" == "1.08597285"
    range_rate = C_KM_S / (2 * dop["uplink_hz"] * dop["transponder_ratio"]) * dop["value"]  # DSN: F = 2 M f rdot / c
    assert f"{range_rate:.10f}" == "-1.7242353358"
    rng = _row(d, 1, "range")
    assert f"{rng['value'] * 1e9:.5f}" == "2811436.10547" and rng["unit"] == "s"
    assert f"{rng['value'] * C_KM_S / 2:.5f}" == "421.42367"
    assert (dop["tracker_type"], dop["data_interval_s"], dop["band_code"]) == (1, 1, 3)
    assert d.meta["records"].loc[1, "band_and_type"] & 0x0F == 4  # transmission type: real time
    assert (dop["band_up"], dop["band_down"], dop["station_rx"], dop["spacecraft"]) == ("S", "S", "PAD-42", "86")
    assert np.isnan(_row(d, 0, "doppler_2way")["value"])  # no prior record: kept, value unknown


@pytest.mark.realdata
def test_doppler_utdf_matches_astro_utdf(shared_data):
    d = utdf.read(shared_data / "utdf/doppler.utdf")
    assert set(d.table["observable"]) == {"doppler_2way"}  # validity 0x02, zero range and angles
    dop = _row(d, 1, "doppler_2way")
    assert dop["doppler_count"] == 43701446204 and f"{dop['doppler_shift_hz']:.3f}" == "40131.725"
    assert dop["value"] == -dop["doppler_shift_hz"]
    range_rate = C_KM_S / (2 * dop["uplink_hz"] * dop["transponder_ratio"]) * dop["value"]  # DSN: F = 2 M f rdot / c
    assert range_rate == pytest.approx(-2.70363808094889, rel=1e-14)
    assert _unix(dop["epoch"]) == 1260236511  # Tue Dec  8 01:41:51 2009
    assert (dop["data_interval_s"], dop["validity"], dop["band_code"]) == (256, 2, 0)
    assert d.meta["records"].loc[1, "mode"] == 544
    assert (dop["uplink_hz"], dop["station_rx"], dop["vid"], dop["spacecraft"]) == (2048854000, "PAD-87", 1, "3250")
    assert d.meta["records"].loc[1, "year"] == 9 and dop["tracker_type"] == 0


@pytest.mark.realdata
def test_lsutdf_matches_file_name_provenance_and_utdfgo(shared_data):
    d = utdf.read(shared_data / LSUTDF)
    rec = d.meta["records"]
    assert len(rec) == 301 and len(d.report) == 0
    assert set(rec["sic"]) == {3675} and set(rec["vid"]) == {1}
    assert set(rec["tx_pad"]) == set(rec["rx_pad"]) == {119}
    t = d.table
    assert str(t["epoch"].min()) == "2019-02-13 15:49:59" and str(t["epoch"].max()) == "2019-02-13 15:55:00"
    assert t["epoch"].max().day_of_year == 44
    last = rec.iloc[-1]
    assert (last["year"], last["seconds_of_year"], last["microseconds"]) == (19, 3772500, 0)
    assert set(t["band_down"]) == {"S"} and (t["data_interval_s"] == 1).all()
    dop = t[t["observable"] == "doppler_2way"]
    assert len(dop) == 301 and dop["value"].isna().sum() == 1
    # the file skips one second (record 45); the count there advanced by one second's worth only
    steps = rec["seconds_of_year"].diff()
    assert list(steps[steps != 1].dropna().index) == [45]
    assert list(dop.loc[dop["count_time"] != 1, "record"]) == [0, 45]
    # smooth S-band Doppler apart from that glitch: 4 jumps (into and out of records 45-46)
    jumps = dop["value"].diff().abs()
    assert jumps.median() < 1 and (jumps > 50).sum() == 4


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["utdf/data.utd", "utdf/doppler.utdf", LSUTDF])
def test_write_reproduces_every_byte(shared_data, tmp_path, name):
    src = shared_data / name
    out = tmp_path / "copy.utdf"
    utdf.write(out, utdf.read(src).meta["records"])
    assert out.read_bytes() == src.read_bytes()


def _fixture_cases() -> pd.DataFrame:
    """The records the fixture script writes."""
    spec = importlib.util.spec_from_file_location("make", FIXTURE_DIR / "make_astro_utdf_cases.py")
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    return make.cases()


def test_fixture_made_by_the_writer():
    path = FIXTURE_DIR / "astro_utdf_cases.utdf"
    assert utdf.encode(_fixture_cases()) == path.read_bytes()
    d = utdf.read(path)
    t = d.table
    assert str(t["epoch"].iloc[0]) == "2009-04-01 00:00:00.314159"  # Astro::UTDF: 01-Apr-2009 00:00:00
    x = t[t["observable"] == "angle_x"]["value"]
    assert np.allclose(x, 1.0, atol=2 * np.pi / 2**32)
    rng = t[t["observable"] == "range"]["value"].iloc[0]
    assert rng * 1e9 == pytest.approx(9876543210, abs=1e-6)
    dop = t[t["observable"] == "doppler_2way"]
    assert np.isnan(dop["value"].iloc[0])
    np.testing.assert_allclose(dop["doppler_shift_hz"].iloc[1:], 26.0, atol=1e-9)  # shift set by the cases
    np.testing.assert_allclose(dop["value"].iloc[1:], -26.0, atol=1e-9)
    np.testing.assert_array_equal(dop["count_time"].iloc[1:], [1.0, 0.5])
    assert (t["tracker_type"] == 9).all() and (d.meta["records"]["router"] == "??").all()


def test_year_byte():
    rec = pd.DataFrame({"year": [8, 69, 70, 99, 119], "seconds_of_year": 0, "microseconds": 0})
    assert [str(e)[:4] for e in utdf.epochs(rec)] == ["2008", "2069", "1970", "1999", "2019"]


def test_encode_refuses_values_that_do_not_fit():
    bad = _fixture_cases()
    bad.loc[0, "range_delay"] = 1 << 48
    with pytest.raises(ValueError, match="range_delay"):
        utdf.encode(bad)


@pytest.mark.realdata
def test_truncated_and_corrupt_records(shared_data, tmp_path):
    buf = bytearray((shared_data / LSUTDF).read_bytes())
    p = tmp_path / "cut.utdf"
    p.write_bytes(bytes(buf[: 75 * 10 + 30]))
    with pytest.raises(ParseError) as e:
        utdf.read(p)
    assert (e.value.offset, e.value.record) == (750, 10) and str(p) in str(e.value)
    assert len(utdf.read(p, errors="report").meta["records"]) == 10
    buf[75 * 5 + 73] = 0xFF  # rear sync of record 5
    p.write_bytes(bytes(buf))
    with pytest.raises(ParseError, match="sync") as e:
        utdf.read(p)
    assert (e.value.offset, e.value.record) == (375, 5)
    d = utdf.read(p, errors="report")
    assert [err.record for err in d.report] == [5] and len(d.meta["records"]) == 300
    assert 5 not in set(d.table["record"])


@pytest.mark.realdata
def test_sniff(shared_data):
    assert utdf.sniff((shared_data / LSUTDF).read_bytes()[:80])
    assert not utdf.sniff((shared_data / "messenger/odf07155.odf").read_bytes()[:80])


def test_running_count_is_not_differenced_across_a_pass_gap(tmp_path):
    # The writer's records twice, a day apart: the first record of the second pass starts a new
    # series instead of averaging the Doppler over the whole gap between passes.
    recs = _fixture_cases()
    later = recs.copy()
    later["seconds_of_year"] = later["seconds_of_year"] + 86400
    utdf.write(tmp_path / "two_passes.utdf", pd.concat([recs, later], ignore_index=True))
    dop = utdf.read(tmp_path / "two_passes.utdf").table
    dop = dop[dop["observable"] == "doppler_2way"].reset_index(drop=True)
    n = len(dop) // 2
    assert np.isnan(dop["value"].iloc[n])
    np.testing.assert_array_equal(dop["count_time"].iloc[n + 1:], dop["count_time"].iloc[1:n])


@pytest.mark.realdata
def test_duplicated_record_is_flagged_not_dropped(shared_data, tmp_path):
    from parsers import table as tt
    buf = (shared_data / LSUTDF).read_bytes()[:75 * 10]
    p = tmp_path / "dup.utdf"
    p.write_bytes(buf[:75 * 5] + buf[75 * 3:75 * 4] + buf[75 * 5:])  # record 3 again as record 5
    d = utdf.read(p)
    (tmp_path / "once.utdf").write_bytes(buf)
    once = utdf.read(tmp_path / "once.utdf")
    dup = (d.table["flags"] & tt.DUPLICATE) != 0
    assert set(d.table.loc[dup, "record"]) == {5}
    assert dup.sum() == (once.table["record"] == 3).sum() > 0
    assert not ((once.table["flags"] & tt.DUPLICATE) != 0).any()


@pytest.mark.parametrize("blob", [b"", b"\x0d\x0a\x01" + b"\x00" * 40])
def test_empty_file_is_a_parse_error_in_both_modes(tmp_path, blob):
    p = tmp_path / "empty.utdf"
    p.write_bytes(blob)
    for mode in ("raise", "report"):
        with pytest.raises(ParseError, match="no UTDF record"):
            utdf.read(p, errors=mode)
