"""CCSDS TDM reader/writer on the Blue Book examples and Orekit's malformed files.

Expected values are those Orekit's TdmParserTest asserts for the same files
(CS-SI/Orekit src/test/java/org/orekit/files/ccsds/ndm/tdm/TdmParserTest.java), which
come from the annex examples of CCSDS 503.0-B-1; error lines are the ones Orekit reports.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from parsers import ParseError, tdm

pytestmark = pytest.mark.realdata
C = 299792458.0


def _t(s):
    return pd.Timestamp(s)


@pytest.fixture(scope="module")
def kvn(shared_data):
    return lambda name: shared_data / "tdm" / "kvn" / name


@pytest.fixture(scope="module")
def xmlf(shared_data):
    return lambda name: shared_data / "tdm" / "xml" / name


def test_example2_one_way_with_frequency_offset(kvn):
    d = tdm.read(kvn("TDMExample2.txt"))
    t = d.table
    assert list(t["keyword"]) == ["TRANSMIT_FREQ_2"] + ["RECEIVE_FREQ_1"] * 6
    assert list(t["value"]) == [32023442781.733, -409.2735, -371.1568, -333.0551, -294.9673, -256.9054, -218.7951]
    assert t["epoch"].iloc[0] == _t("2005-06-08T17:41:00") and t["epoch"].iloc[-1] == _t("2005-06-08T17:41:05")
    assert set(t["freq_offset"]) == {32021035200.0}
    rx = t[t["keyword"] == "RECEIVE_FREQ_1"]
    assert set(rx["station_rx"]) == {"DSS-25"} and set(rx["tag"]) == {"interval_mid"} and set(rx["count_time"]) == {1.0}
    assert d.meta["version"] == "1.0" and d.meta["header"]["ORIGINATOR"] == "NASA/JPL"
    assert d.meta["comments"] == ["TDM example created by yyyyy-nnnA Nav Team (NASA/JPL)",
                                  "StarTrek 1-way data, Ka band down"]
    seg = d.meta["segments"][0]
    assert seg.meta["PATH"] == "2,1" and float(seg.meta["TRANSMIT_DELAY_1"]) == 0.000077
    assert seg.meta_comments == ["This is a meta-data comment"] and seg.data_comments == ["This is a data comment"]
    ramp = d.ramps.iloc[0]
    assert (ramp["station"], ramp["freq_hz"], ramp["rate_hz_s"]) == ("yyyy-nnnA", 32023442781.733, 0.0)


@pytest.mark.parametrize("syntax", ["kvn", "xml"])
def test_example2_one_way_becomes_doppler_against_the_spacecraft_frequency(kvn, xmlf, syntax):
    """The fit's reading (odpipe.products.tdm.doppler_from_tdm): the received frequency is RECEIVE_FREQ_1 +
    FREQ_OFFSET, the one-way Doppler the spacecraft's TRANSMIT_FREQ_2 less it (Hz, positive receding)."""
    from odpipe.products.tdm import doppler_from_tdm

    d, left = doppler_from_tdm(tdm.read(kvn("TDMExample2.txt") if syntax == "kvn" else xmlf("TDMExample2.xml")))
    t = d.table
    assert left == 0 and list(t["observable"]) == ["doppler_1way"] * 6
    received = 32021035200.0 + np.array([-409.2735, -371.1568, -333.0551, -294.9673, -256.9054, -218.7951])
    assert np.allclose(t["value"], 32023442781.733 - received, rtol=0, atol=1e-5)
    assert set(t["uplink_hz"]) == {32023442781.733} and set(t["spacecraft"]) == {"yyyy-nnnA"}
    assert set(t["station_rx"]) == {"DSS-25"} and set(t["station_tx"]) == {""}


def test_example6_five_leg_received_frequency_stays_as_read(kvn):
    """PATH 1,2,3,2,1 with an unnumbered RECEIVE_FREQ: no link the Doppler models know, kept as received."""
    from odpipe.products.tdm import doppler_from_tdm

    d, left = doppler_from_tdm(tdm.read(kvn("TDMExample6.txt")))
    rf = d.table[d.table["keyword"] == "RECEIVE_FREQ"]
    assert left == 0 and len(rf) == 4 and set(rf["observable"]) == {"receive_freq"} and set(rf["value"]) == {2287487999.0}
    assert not d.table["keyword"].str.startswith("TRANSMIT_FREQ").any() and len(d.ramps) == 4


def test_example4_range_in_range_units_and_ramps(kvn):
    d = tdm.read(kvn("TDMExample4.txt"))
    t = d.table
    rng = t[t["observable"] == "range"]
    assert list(rng["value"][:4]) == [39242998.5151986, 61172265.3115234, 15998108.8168328, 37938284.4138008]
    assert set(rng["unit"]) == {"RU"} and set(rng["range_modulus"]) == {2.0e26}
    assert set(rng["tag"]) == {"receive"} and set(rng["station_tx"]) == {"DSS-24"}
    assert list(d.ramps["freq_hz"][:2]) == [7180064367.3536, 7180064472.3146]
    assert list(d.ramps["rate_hz_s"][:2]) == [0.59299, 0.59305]
    assert rng["ramped"].all() and not t[t["keyword"] == "TRANSMIT_FREQ_1"]["ramped"].any()
    assert d.ramps["start"].iloc[0] == _t("2005-07-10T00:31:51")
    assert d.ramps["end"].iloc[0] == d.ramps["start"].iloc[1] and pd.isna(d.ramps["end"].iloc[-1])


def test_example6_km_range_and_azel_degrees(kvn):
    t = tdm.read(kvn("TDMExample6.txt")).table
    first = t[t["epoch"] == _t("1998-06-10T00:57:37")].set_index("keyword")
    assert first.loc["RANGE", "value"] == pytest.approx(80452754.2, rel=1e-12)
    assert first.loc["RANGE", "unit"] == "m" and first.loc["RANGE", "range_modulus"] == 1000.0
    assert first.loc["ANGLE_1", "observable"] == "angle_az"
    assert first.loc["ANGLE_1", "value"] == pytest.approx(math.radians(256.64002393), rel=1e-12)
    assert first.loc["ANGLE_2", "value"] == pytest.approx(math.radians(13.38100016), rel=1e-12)
    assert first.loc["RECEIVE_FREQ", "value"] == 2287487999.0
    last = t[t["keyword"] == "RANGE"]["value"].iloc[-1]
    assert last == pytest.approx(80452633.1, rel=1e-12)


def test_example8_two_segments_range_in_seconds(kvn):
    t = tdm.read(kvn("TDMExample8.txt")).table
    s0 = t[t["segment"] == 0]
    dop = s0[s0["keyword"] == "DOPPLER_INTEGRATED"]
    assert list(dop["value"]) == pytest.approx([-1498.776048, -2201.305217, 929.545817], rel=1e-12)
    assert set(dop["tag"]) == {"interval_end"} and set(dop["observable"]) == {"range_rate"}
    assert set(s0[s0["keyword"] == "ANGLE_1"]["observable"]) == {"angle_x"}
    s1 = t[t["segment"] == 1]
    rng = s1[s1["keyword"] == "RANGE"]
    # Orekit converts seconds with c; we keep seconds (unit "s"), the same number divided by c.
    assert list(rng["value"] * C) == pytest.approx([4.00165248953670e4 * C, 3.57238793591890e4 * C,
                                                    3.48156855860090e4 * C], rel=1e-12)
    assert set(rng["unit"]) == {"s"} and set(rng["range_modulus"]) == {1.0e7}
    az = s1[s1["keyword"] == "ANGLE_1"]
    assert az["value"].iloc[-1] == pytest.approx(math.radians(243.73365222), rel=1e-12)
    assert set(s1["station_tx"]) == {"WHM1"} == set(s1["station_rx"])


def test_example15_clock_segments(kvn):
    d = tdm.read(kvn("TDMExample15.txt"))
    t = d.table.sort_values("record")
    assert len(d.meta["segments"]) == 3
    seg2 = t[t["segment"] == 2]
    assert list(seg2["value"]) == [-1.782e-6, 1.736e-13, -1.767e-6, 1.157e-14, -1.766e-6, 8.102e-14, -1.759e-6]
    assert list(seg2["unit"][:2]) == ["s", "s/s"]
    assert d.meta["segments"][0].meta_comments == ["Note: SPC10 switched back to Maser1 from Maser2 on 2005-142"]
    assert len(d.meta["comments"]) == 5


def test_all_keywords_in_si_units(kvn):
    # Orekit: with every unit converted, observation i has the value i+1 (STEC kept in TECU here).
    t = tdm.read(kvn("TDMExampleAllKeywordsSequential.txt")).table.sort_values("record")
    assert len(t) == 47
    expect = np.arange(1, 48, dtype=float)
    stec = (t["keyword"] == "STEC").to_numpy()
    assert t["value"].to_numpy()[~stec] == pytest.approx(expect[~stec], rel=1e-12)
    assert t["value"].to_numpy()[stec] == pytest.approx([42.0e-16])
    assert list(t["epoch"]) == list(pd.Timestamp("2017-06-14T10:53:00") + pd.to_timedelta(expect, unit="s"))
    assert set(t[t["keyword"] == "RANGE"]["unit"]) == {"RU"}
    assert t.set_index("keyword").loc["ANGLE_1", "observable"] == "angle_ra"
    assert t["transponder_ratio"].iloc[0] == 240 / 221


@pytest.mark.parametrize("name", ["TDMExample2", "TDMExample4", "TDMExample6", "TDMExample8", "TDMExample15",
                                  "TDMExampleAllKeywordsSequential", "TDMExampleAllKeywordsSingleDiff"])
def test_kvn_and_xml_examples_decode_to_the_same_table(kvn, xmlf, name):
    a = tdm.read(kvn(name + ".txt"))
    b = tdm.read(xmlf(name + ".xml"))
    cols = ["epoch", "keyword", "observable", "value", "unit", "tag", "station_tx", "station_rx", "count_time"]
    # the XML files write the same epochs as calendar dates and numbers as 7.7E-5 etc.
    pd.testing.assert_frame_equal(a.table[cols], b.table[cols])
    for sa, sb in zip(a.meta["segments"], b.meta["segments"], strict=True):
        assert sa.meta.keys() == sb.meta.keys()
        for key, va in sa.meta.items():
            vb = sb.meta[key]
            same = float(va) == float(vb) if key in tdm.keywords.NUMBER else (
                pd.Timestamp(tdm.times.from_text([va])[0]) == pd.Timestamp(tdm.times.from_text([vb])[0])
                if key in tdm.keywords.TIME else va == vb)
            assert same, (key, va, vb)


@pytest.mark.parametrize("syntax", ["kvn", "xml"])
@pytest.mark.parametrize("name", ["kvn/TDMExample2.txt", "kvn/TDMExample4.txt", "kvn/TDMExample6.txt",
                                  "kvn/TDMExample8.txt", "kvn/TDMExample15.txt",
                                  "kvn/TDMExampleAllKeywordsSingleDiff.txt", "xml/TDM-inconsistent-time-systems.xml"])
def test_read_write_read_is_value_for_value(shared_data, tmp_path, name, syntax):
    d = tdm.read(shared_data / "tdm" / name)
    out = tmp_path / f"again.{syntax}"
    tdm.write(out, d, syntax=syntax)
    again = tdm.read(out)
    drop = ["source", "line"]
    pd.testing.assert_frame_equal(d.table.drop(columns=drop), again.table.drop(columns=drop), check_exact=True)
    pd.testing.assert_frame_equal(d.ramps.drop(columns="source"), again.ramps.drop(columns="source"))
    assert [s.meta for s in d.meta["segments"]] == [s.meta for s in again.meta["segments"]]
    assert d.meta["comments"] == again.meta["comments"] and d.meta["header"] == again.meta["header"]


@pytest.mark.parametrize("name, line, keyword", [
    ("kvn/TDM-data-inconsistent-line.txt", 25, "RECEIVE_FREQ_1"),
    ("kvn/TDM-data-number-format-error.txt", 26, "RECEIVE_FREQ_1"),
    ("kvn/TDM-data-wrong-keyword.txt", 26, "WRONG_KEYWORD"),
    ("kvn/TDM-metadata-number-format-error.txt", 17, "TRANSMIT_DELAY_1"),
    ("kvn/TDM-metadata-wrong-keyword.txt", 16, "WRONG_KEYWORD"),
    ("kvn/TDM-metadata-timesystem-not-implemented.txt", 7, "TIME_SYSTEM"),
    ("kvn/TDM-issue963.txt", 13, "PATH"),
    ("xml/TDM-data-inconsistent-block.xml", 32, "TRANSMIT_FREQ_2"),
    ("xml/TDM-data-number-format-error.xml", 47, "RECEIVE_FREQ_1"),
    ("xml/TDM-data-wrong-keyword.xml", 47, "WRONG_KEYWORD"),
    ("xml/TDM-metadata-number-format-error.xml", 24, "TRANSMIT_DELAY_1"),
    ("xml/TDM-metadata-wrong-keyword.xml", 23, "WRONG_KEYWORD"),
    ("xml/TDM-metadata-timesystem-not-implemented.xml", 14, "TIME_SYSTEM"),
    ("xml/TDM-missing-timesystem.xml", 16, "TIME_SYSTEM"),
    ("xml/TDM-missing-participants.xml", 11, "PARTICIPANT_1"),
    ("xml/TDM-external-doctype.xml", 2, "DOCTYPE"),
])
def test_malformed_files_name_file_line_and_keyword(shared_data, name, line, keyword):
    path = shared_data / "tdm" / name
    with pytest.raises(ParseError) as err:
        tdm.read(path)
    assert (err.value.path, err.value.line, err.value.record) == (str(path), line, keyword)


def test_bad_data_lines_are_reported_and_skipped(kvn):
    d = tdm.read(kvn("TDM-data-number-format-error.txt"), errors="report")
    assert [(e.line, e.record) for e in d.report] == [(26, "RECEIVE_FREQ_1")]
    assert len(d.table) == 6


def test_time_systems_tai_and_gps_become_utc(tmp_path, kvn):
    text = kvn("TDMExample2.txt").read_text().replace("TIME_SYSTEM = UTC", "TIME_SYSTEM = TAI")
    (tmp_path / "tai.txt").write_text(text)
    t = tdm.read(tmp_path / "tai.txt").table
    # TAI-UTC = 32 s from 1999-01-01 to 2005-12-31 (IERS Bulletin C)
    assert t["epoch"].iloc[0] == _t("2005-06-08T17:40:28") and set(t["time_system"]) == {"TAI"}
    t = tdm.read(kvn("TDM-inconsistent-time-systems.txt")).table
    assert set(t[t["segment"] == 1]["time_system"]) == {"TCG"}  # kept in its own scale


def test_sniff(kvn, xmlf):
    assert tdm.sniff(kvn("TDMExample2.txt").read_bytes()[:64])
    assert tdm.sniff(xmlf("TDMExample2.xml").read_bytes()[:256])
    assert not tdm.sniff(b"NJPL2I00C123")


def test_leap_second_scales_match_published_offsets():
    # IERS Bulletin C: TAI-UTC = 34 s until 2012-06-30, 35 s from 2012-07-01; GPS = TAI - 19 s; TT = TAI + 32.184 s.
    gps = np.array(["2012-06-30T12:00:15", "2012-07-01T00:00:16"], dtype="datetime64[ns]")
    assert list(tdm.times.to_utc(gps, "GPS")) == list(np.array(["2012-06-30T12:00:00", "2012-07-01T00:00:00"],
                                                                dtype="datetime64[ns]"))
    tt_ = np.array(["2013-01-01T00:01:07.184"], dtype="datetime64[ns]")
    assert tdm.times.to_utc(tt_, "TT")[0] == np.datetime64("2013-01-01T00:00:00", "ns")
    utc = np.array(["2016-12-31T23:59:59", "2017-01-01T00:00:00"], dtype="datetime64[ns]")
    assert list(tdm.times.to_utc(tdm.times.from_utc(utc, "TAI"), "TAI")) == list(utc)


def test_inf_and_nan_values_are_flagged_rows_and_a_line_without_value_is_reported(kvn, tmp_path):
    from parsers import table as tt
    lines = kvn("TDMExample2.txt").read_text().splitlines()
    rx = [i for i, ln in enumerate(lines) if ln.strip().startswith("RECEIVE_FREQ_1")]
    lines[rx[0]] = lines[rx[0]].rsplit(None, 1)[0] + " inf"
    lines[rx[1]] = lines[rx[1]].rsplit(None, 1)[0] + " 1e400"
    lines[rx[2]] = lines[rx[2]].rsplit(None, 1)[0] + " NaN"
    lines[rx[3]] = lines[rx[3]].rsplit(None, 1)[0]  # the value is missing
    p = tmp_path / "x.tdm"
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError) as err:
        tdm.read(p)
    assert err.value.line == rx[3] + 1
    d = tdm.read(p, errors="report")
    assert [e.line for e in d.report] == [rx[3] + 1]
    t = d.table.set_index("line")
    assert len(t) == 7 - 1
    flagged = t["flags"] & tt.INVALID != 0
    assert sorted(t.index[flagged]) == [rx[0] + 1, rx[1] + 1, rx[2] + 1]  # kept, flagged, never silent
    assert (t.loc[~flagged, "value"].abs() < 1e12).all()


@pytest.mark.parametrize("blob", [b"", b"   \n", b"CCSDS_TDM_VERS = 2.0\nCOMMENT \xff\n"])
def test_empty_or_not_utf8_kvn_is_a_parse_error(tmp_path, blob):
    p = tmp_path / "x.tdm"
    p.write_bytes(blob)
    for mode in ("raise", "report"):
        with pytest.raises(ParseError):
            tdm.read(p, errors=mode)


def test_non_finite_metadata_number_is_a_parse_error(kvn, tmp_path):
    text = kvn("TDMExample2.txt").read_text()
    p = tmp_path / "x.tdm"
    p.write_text(text.replace("TRANSMIT_DELAY_1 = 0.000077", "TRANSMIT_DELAY_1 = 1e400"))
    with pytest.raises(ParseError, match="TRANSMIT_DELAY_1"):
        tdm.read(p, errors="report")


@pytest.mark.parametrize("name, line, rows", [("kvn/TDM-data-wrong-keyword.txt", 26, 6),
                                              ("xml/TDM-data-wrong-keyword.xml", 47, 6)])
def test_wrong_data_keyword_is_reported_in_both_syntaxes(shared_data, name, line, rows):
    d = tdm.read(shared_data / "tdm" / name, errors="report")
    assert [(e.line, e.record) for e in d.report] == [(line, "WRONG_KEYWORD")]
    assert len(d.table) == rows
