"""Maneuver files: the GRAIL-A log decoded against its text, and the plan schema round trip."""

import numpy as np
import pandas as pd
import pytest

from parsers.errors import ParseError, ParseReport
from parsers.maneuvers import PLAN_COLUMNS, read, read_mas, read_plan, sniff, write_plan

MAS = "grail/mas00_2012_04_06_a_04.asc"


@pytest.mark.realdata
def test_grail_log_rows_match_the_file_text(shared_data):
    path = shared_data / MAS
    text = path.read_text().splitlines()
    log = read_mas(path)
    # every non-header line is one event (header: 4 lines, one quoted name per line break)
    assert len(log) == sum(1 for ln in text[4:] if ln.strip()) == 174
    tcm = log[log["event"] == "TCM-A2 (13.973 m/sec)"].iloc[0]
    assert text[tcm["line"] - 1].startswith("TCM-A2 (13.973 m/sec)   9/30/2011   11-273   18:03:03.968")
    assert tcm["epoch"] == pd.Timestamp("2011-09-30T18:03:03.968")  # 2011 day 273 = 30 Sep
    assert tcm["dv_mps"] == 13.973 and tcm["kind"] == "maneuver"
    assert (tcm["fuel_kg"], tcm["fuel_sigma_2s_kg"], tcm["mass_kg"]) == (104.08999, 0.33, 304.29769)
    assert (tcm["cm_x"], tcm["cm_y"], tcm["cm_z"]) == (0.45918, 0.00054, -0.00002)
    assert (tcm["boresight_x"], tcm["boresight_y"], tcm["boresight_z"]) == (0.0373865, -0.0375066, -0.9985968)
    loi = log[log["event"].str.startswith("LOI")].iloc[0]
    assert loi["epoch"] == pd.Timestamp("2011-12-31T21:59:36.208") and loi["dv_mps"] == 190.78
    # two spaces inside a name, four before a date: still one field each
    ecm = log[log["event"] == "ECM-A1  (38.3427 m/s)"].iloc[0]
    assert ecm["dv_mps"] == 38.3427 and ecm["mass_kg"] == 214.96007
    assert log.loc[log["event"] == "Desat 051", "epoch"].iloc[0] == pd.Timestamp("2012-04-28T22:44:12.512")
    # the last line carries only fuel and mass; the rest is blank
    last = log.iloc[-1]
    assert last["event"] == "Burn To Depletion (20.59 m/sec)" and last["mass_kg"] == 200.54858
    assert np.isnan(last["cm_x"]) and np.isnan(last["boresight_z"])
    # Date is the Pacific calendar day (Desat 053: 01:08 UTC on 3 May = 2 May PDT); Desat 011 fits neither
    d53 = log[log["event"] == "Desat 053"].iloc[0]
    assert d53["date"] == "5/2/2012" and d53["epoch"].day == 3 and not d53["date_mismatch"]
    assert log.loc[log["date_mismatch"], "event"].tolist() == ["Desat 011"]
    assert (log["kind"] == "desat").sum() == sum("Desat" in ln.split("   ")[0] for ln in text[4:])
    assert sniff(path.read_bytes()[:4096]) and len(read(path)) == 174


def plan():
    return pd.DataFrame({
        "name": ["TCM-1", "LOI"], "epoch": pd.to_datetime(["2012-04-09T12:00:00.125", "2012-04-10T03:04:05"], format="ISO8601"),
        "kind": ["impulsive", "finite"], "frame": ["RTN", "VNB"],
        "dv1": [0.1, np.nan], "dv2": [-0.02, np.nan], "dv3": [3e-4, np.nan],
        "duration": [np.nan, 2400.0], "thrust": [np.nan, 22.0],
        "dir1": [np.nan, 0.6], "dir2": [np.nan, 0.0], "dir3": [np.nan, -0.8], "mass": [np.nan, 300.0],
        "sigma_dv": [1e-3, 0.05], "sigma_time": [1.0, 10.0]})


@pytest.mark.parametrize("suffix", [".csv", ".toml"])
def test_plan_round_trip(tmp_path, suffix):
    p = tmp_path / f"plan{suffix}"
    write_plan(plan(), p)
    assert sniff(p.read_bytes())
    back = read(p)
    pd.testing.assert_frame_equal(back[PLAN_COLUMNS], plan()[PLAN_COLUMNS], check_dtype=False)


def test_plan_errors_name_the_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("# plan\nname,epoch,kind,frame,dv1,dv2,dv3\n"
                 "A,2012-01-01T00:00:00,impulsive,RTN,1,2,3\n"
                 "B,2012-01-01T00:00:00,impulsive,LVLH,1,2,3\n"
                 "C,2012-01-01T00:00:00,finite,RTN,,,\n")
    with pytest.raises(ParseError) as err:
        read_plan(p)
    assert err.value.line == 4 and "frame" in err.value.reason
    report = ParseReport()
    df = read_plan(p, errors="report", report=report)
    assert df["name"].tolist() == ["A"]
    assert [e.line for e in report] == [4, 5]
    t = tmp_path / "bad.toml"
    t.write_text('[[maneuver]]\nname = "X"\nepoch = 2012-01-01T00:00:00Z\nkind = "finite"\nframe = "ICRF"\n'
                 'duration = 10.0\nthrust = 1.0\ndirection = [1.0, 1.0, 0.0]\n')
    with pytest.raises(ParseError, match="unit vector"):
        read_plan(t)


_CSV_HEAD = "name,epoch,kind,frame,dv1,dv2,dv3\n"
_GOOD_ROW = "A,2012-01-01T00:00:00,impulsive,RTN,1,2,3\n"


@pytest.mark.parametrize("row, words", [
    ("B,0000-01-01T00:00:00,impulsive,RTN,1,2,3", "epoch"),        # year 0
    ("B,,impulsive,RTN,1,2,3", "missing epoch"),                    # a maneuver with no epoch
    ("B,now,impulsive,RTN,1,2,3", "ISO 8601"),
    ("B,2012-01-01T00:00:00,impulsive,RTN,1e400,2,3", "finite"),
    ("B,2012-01-01T00:00:00,impulsive,RTN,nan,2,3", "finite"),
    ("B,2012-01-01T00:00:00,impulsive,RTN," + "9" * 5000 + ",2,3", "number"),
    ("B,2012-01-01T00:00:00,impulsive,RTN,1," + "x" * 200_000 + ",3", "CSV"),  # over the csv field limit
    ("B,2012-01-01T00:00:00,impulsive,RTN,1,2", "fields"),
])
def test_bad_csv_plan_rows_are_parse_errors_and_reported(tmp_path, row, words):
    p = tmp_path / "plan.csv"
    p.write_text(_CSV_HEAD + _GOOD_ROW + row + "\n" + _GOOD_ROW.replace("A,", "C,"))
    with pytest.raises(ParseError, match=words) as err:
        read_plan(p)
    assert err.value.line == 3
    report = ParseReport()
    assert read_plan(p, errors="report", report=report)["name"].tolist() == ["A", "C"]
    assert [e.line for e in report] == [3]


@pytest.mark.parametrize("body, words", [
    ('epoch = 0000-01-01T00:00:00Z', "TOML"),            # year 0: tomllib's own ValueError
    ('epoch = 2012-01-01T00:00:00Z\ndv = ' + "9" * 5000, "TOML"),  # 5000-digit integer
    ('epoch = 2012-01-01T00:00:00Z\ndv = 5', "dv"),      # not a 3-vector
    ('dv = [1.0, 2.0, 3.0]', "missing epoch"),           # a plan with no epoch
    ('epoch = 2012-01-01T00:00:00Z\ndv = [1.0, true, 3.0]', "number"),
    ('epoch = 12:00:00\ndv = [1.0, 2.0, 3.0]', "epoch"),
])
def test_bad_toml_plans_are_parse_errors(tmp_path, body, words):
    p = tmp_path / "plan.toml"
    p.write_text(f'[[maneuver]]\nname = "X"\nkind = "impulsive"\nframe = "RTN"\n{body}\n')
    with pytest.raises(ParseError, match=words):
        read_plan(p)


@pytest.mark.parametrize("blob", [b"", b"\n \n", b"name,epoch\xff,kind,frame\n"])
def test_empty_or_not_utf8_plan_is_a_parse_error_in_both_modes(tmp_path, blob):
    p = tmp_path / "plan.csv"
    p.write_bytes(blob)
    for mode in ("raise", "report"):
        with pytest.raises(ParseError) as err:
            read_plan(p, errors=mode, report=ParseReport())
    assert err.value.offset == blob.find(b"\xff") if b"\xff" in blob else err.value.reason == "empty file"


@pytest.mark.realdata
def test_grail_log_bad_byte_and_bad_lines(shared_data, tmp_path):
    text = (shared_data / MAS).read_bytes()
    lines = text.split(b"\n")
    p = tmp_path / "mas.asc"
    p.write_bytes(b"\n".join(lines[:10]) + b"\n\xad\n")
    with pytest.raises(ParseError, match="utf-8") as err:
        read_mas(p)
    assert err.value.offset == len(b"\n".join(lines[:10])) + 1 and err.value.line == 11
    # a mass of 1e400, a day 0 and a field of 200,000 characters: three lines reported, the others kept
    bad = [lines[5].replace(b"306.16464", b"1e400"), lines[6].replace(b"11-256", b"11-000"),
           lines[7] + b"   " + b"9" * 200_000]
    p.write_bytes(b"\n".join(lines[:5] + bad + lines[8:]))
    report = ParseReport()
    log = read_mas(p, errors="report", report=report)
    assert len(log) == 174 - 3 and [e.line for e in report] == [6, 7, 8]
    with pytest.raises(ParseError):
        read_mas(p)


def test_bad_toml_row_names_its_table_line(tmp_path):
    p = tmp_path / "plan.toml"
    write_plan(plan(), p)
    text = p.read_text().replace("kind = \"finite\"", "kind = \"finit\"")
    p.write_text(text)
    with pytest.raises(ParseError, match="kind") as err:
        read_plan(p)
    assert text.splitlines()[err.value.line - 1] == "[[maneuver]]" and err.value.record == 1
    assert err.value.line == [n for n, ln in enumerate(text.splitlines(), 1) if ln == "[[maneuver]]"][1]
