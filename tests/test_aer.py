"""Orekit ``.aer`` reader: W3B's az/el and range table against its raw text and Orekit's counts."""

import numpy as np
import pytest

from parsers import aer, formats
from parsers.errors import ParseError

W3B = "orekit_od/W3B/W3B.aer"


@pytest.mark.realdata
def test_w3b_counts_match_orekits_test(shared_data):
    path = shared_data / W3B
    assert formats.detect(path) == "parsers.aer"
    d = aer.read(path, spacecraft="W3B")
    t = d.table
    # Orekit's OrbitDeterminationTest.testW3B fits nbRange = 182 ranges and nbAzi = nbEle = 339 angle pairs
    assert t["observable"].value_counts().to_dict() == {"angle_az": 339, "angle_el": 339, "range": 182}
    assert d.meta["stations"] == ["CastleRock", "Fucino", "Kumsan", "Pretoria", "Uralla"]
    assert t.query("observable == 'range'").groupby("station_rx").size().to_dict() == \
        {"CastleRock": 54, "Fucino": 28, "Kumsan": 33, "Pretoria": 30, "Uralla": 37}
    assert (t["spacecraft"] == "W3B").all() and (t["tag"] == "receive").all() and len(d.report) == 0
    assert t["epoch"].is_monotonic_increasing
    assert t["epoch"].iloc[0] == np.datetime64("2010-11-02T03:00:13.385100", "ns")
    assert t["epoch"].iloc[-1] == np.datetime64("2010-11-02T18:47:33.565600", "ns")


@pytest.mark.realdata
def test_w3b_lines_decoded_from_the_raw_text(shared_data):
    t = aer.read(shared_data / W3B).table.set_index(["line", "observable"])
    # line 23: 2010-11-02T03:00:13.3851   RANGE       Uralla         38014.9488
    r = t.loc[(23, "range")]
    assert (r["value"], r["unit"], r["station_tx"], r["station_rx"], r["record"]) == \
        (pytest.approx(38014948.8), "m", "Uralla", "Uralla", 22)
    # line 24: 2010-11-02T03:00:50.5716   AZ_EL       Kumsan           211.1446   43.4099
    az, el = t.loc[(24, "angle_az")], t.loc[(24, "angle_el")]
    assert az["value"] == pytest.approx(np.radians(211.1446), abs=1e-15)
    assert el["value"] == pytest.approx(np.radians(43.4099), abs=1e-15)
    assert (az["unit"], az["station_tx"], az["station_rx"]) == ("rad", "", "Kumsan")
    assert az["epoch"] == el["epoch"] == np.datetime64("2010-11-02T03:00:50.5716", "ns")


@pytest.mark.realdata
def test_lageos2_range_table_is_orekits_first_lageos2_set(shared_data):
    # Orekit's earlier testLageos2 fitted this file: nbRange = 258
    t = aer.read(shared_data / "orekit_od/Lageos2/Lageos2_test.aer").table
    assert len(t) == 258 and t.groupby("station_rx").size().to_dict() == \
        {"GODL": 7, "HA4T": 29, "SISL": 41, "YARL": 181}
    assert t["value"].iloc[0] == pytest.approx(7021334.976)    # 2016-02-14T03:17:37.047 RANGE YARL 7021.334976


@pytest.mark.parametrize("line, reason", [
    ("2010-11-02T03:00:13.3851   RANGE       Uralla", "RANGE needs 4 fields"),              # truncated
    ("2010-11-02T03:00:13.3851   RANGE       Uralla  38O14.9488", "must be a number"),     # bad number
    ("2010-11-02T03:00:13.3851   DOPPLER     Uralla  1.0", "unknown measurement type 'DOPPLER'"),
    ("2010-11-02T03:00:13.3851   AZ_EL       Kumsan  211.1446", "AZ_EL needs 5 fields"),
    ("2010-13-02T03:00:13.3851   RANGE       Uralla  1.0", "not a calendar date"),
    ("2010/11/02 03:00:13   RANGE       Uralla  1.0", "not ISO-8601"),
])
def test_bad_lines_name_file_and_line(tmp_path, line, reason):
    p = tmp_path / "bad.aer"
    p.write_text("# a comment\n\n2010-11-02T03:00:00 RANGE Uralla 38000.0\n" + line + "\n")
    with pytest.raises(ParseError) as e:
        aer.read(p)
    assert e.value.line == 4 and reason in str(e.value) and str(e.value).startswith(f"{p}, line 4")
    d = aer.read(p, errors="report")
    assert len(d.table) == 1 and [err.line for err in d.report] == [4]
