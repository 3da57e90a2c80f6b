"""ILRS CPF reader: the LAGEOS-2 predictions of Orekit's case, against their raw text and Orekit's fitted state."""

from pathlib import Path

import numpy as np
import pytest

from odpipe.frames.earth import itrs_to_gcrs
from parsers import cpf, formats
from parsers.errors import ParseError

DIR = Path("orekit_od/Lageos2")
FULL = DIR / "lageos2_cpf_160213_5441.sgf"


def T(s):
    return np.datetime64(s, "ns")


@pytest.mark.realdata
def test_header_and_records_from_the_raw_text(shared_data):
    assert formats.detect(shared_data / FULL) == "parsers.cpf"
    c = cpf.read(shared_data / FULL)
    h, p = c.header, c.positions
    # H1 CPF  1  SGF 2016  2 13  2  5441 lageos2
    # H2  9207002 5986    22195 2016  2 13  0  0  0 2016  2 13 23 54  0   300 1 1  0 0 0
    assert (h["version"], h["source"], h["sequence"], h["target"]) == (1, "SGF", 5441, "lageos2")
    assert h["produced"] == T("2016-02-13T02:00")
    assert (h["ilrs_id"], h["sic"], h["norad"], h["interval_s"], h["com_applied"]) == (9207002, 5986, 22195, 300, 0)
    assert (h["start"], h["end"]) == (T("2016-02-13T00:00"), T("2016-02-13T23:54"))
    assert c.frame == "ITRF" and len(c.report) == 0
    assert len(p) == 288 and (np.diff(p["epoch"].to_numpy()) == np.timedelta64(300, "s")).all()
    # 10 0 57431      0.00000  0   7049498.186   5346456.274   8307028.039     (line 4)
    first = p.iloc[0]
    assert (first["epoch"], first["mjd"], first["line"]) == (T("2016-02-13"), 57431, 4)
    assert first[["x_m", "y_m", "z_m"]].tolist() == [7049498.186, 5346456.274, 8307028.039]
    # 10 0 57431  86100.00000  0 -10108280.313  -3150523.401  -6140646.075    (line 291, before 99)
    last = p.iloc[-1]
    assert last["epoch"] == T("2016-02-13T23:55") and last[["x_m", "z_m"]].tolist() == [-10108280.313, -6140646.075]
    assert p["vx_mps"].isna().all()                               # no 20 records


@pytest.mark.realdata
def test_thinned_copies_are_subsets_of_the_full_file(shared_data):
    # Orekit's LS and SeqLS files split the full prediction at 57431/21100 .. 59700 (their 00 comment says so)
    full = cpf.read(shared_data / FULL).positions.set_index("epoch")
    ls = cpf.read(shared_data / DIR / "lageos2LS_cpf_160213_5441.sgf")
    seq = cpf.read(shared_data / DIR / "lageos2SeqLS_cpf_160213_5441.sgf")
    assert "Positions from 57431/21100 to 57431/59700 were removed" in ls.comments[1]
    assert len(ls.positions) + len(seq.positions) == 288
    for part in (ls.positions, seq.positions):
        joined = full.loc[part["epoch"], ["x_m", "y_m", "z_m"]].to_numpy()
        assert (joined == part[["x_m", "y_m", "z_m"]].to_numpy()).all()
    assert seq.positions["sod_s"].iloc[[0, -1]].tolist() == [20100.0, 59700.0]


@pytest.mark.realdata
def test_prediction_agrees_with_orekits_fitted_lageos2_state(shared_data):
    # Orekit's NumericalOrbitDeterminationTest.testLageos2 fits the 95 normal points and finds, at
    # 2016-02-13T16:00 UTC in EME2000, r = (7526994.072, -9646309.832, 1464110.239) m (its tolerance 0.62 m).
    # The CPF row of 16:00 (sod 57600), ITRF turned to GCRS (EME2000 differs by the 23-mas frame bias, ~1.4 m
    # here), lands within 3 m: the frame is the body-fixed one H2 names and the epochs are UTC to the second.
    p = cpf.read(shared_data / FULL).positions.set_index("epoch")
    t = T("2016-02-13T16:00")
    r_itrf = p.loc[t, ["x_m", "y_m", "z_m"]].to_numpy(float)
    r_gcrs = itrs_to_gcrs(np.array([t]))[0] @ r_itrf
    orekit = np.array([7526994.072, -9646309.832, 1464110.239])
    assert np.linalg.norm(r_gcrs - orekit) < 3.0
    assert np.linalg.norm(r_itrf) == pytest.approx(np.linalg.norm(orekit), abs=0.1)   # frame-free: |r|
    # one tabulated step earlier is 2 400 km away: the match is not an accident of the epoch
    assert np.linalg.norm(itrs_to_gcrs(np.array([t]))[0] @ p.iloc[p.index.get_loc(t) - 1][["x_m", "y_m", "z_m"]]
                          .to_numpy(float) - orekit) > 1e6


@pytest.mark.realdata
@pytest.mark.parametrize("line_no, text, reason", [
    (10, "10 0 57431   1800.00000  0  -1602177.318", "expected 8 fields"),                           # truncated
    (10, "10 0 57431   1800.00000  0  -1602177.3x8   7846824.514   9291243.088", "must be a number"),
    (10, "11 0 57431   1800.00000  0  -1602177.318   7846824.514   9291243.088", "unknown CPF record type '11'"),
    (10, "20 0 1.0 2.0", "expected 5 fields"),
    (2, "H2  9207002 5986    22195 2016  2 13  0  0  0 2016  2 13 23 54  0   300 1 1  7 0 0", "reference frame 7"),
])
def test_corrupted_copies_name_file_and_line(shared_data, tmp_path, line_no, text, reason):
    lines = (shared_data / FULL).read_text().split("\n")
    lines[line_no - 1] = text
    bad = tmp_path / "bad.sgf"
    bad.write_text("\n".join(lines))
    with pytest.raises(ParseError) as e:
        cpf.read(bad)
    assert e.value.line == line_no and reason in str(e.value) and str(e.value).startswith(f"{bad}, line {line_no}")
    if line_no == 10:
        c = cpf.read(bad, errors="report")
        assert [err.line for err in c.report] == [10] and len(c.positions) == 287    # that one 10 record lost


def test_v2_header_velocities_and_end_record(tmp_path):
    p = tmp_path / "v2.cpf"
    p.write_text("H1 CPF  2  HTS 2024 03 01 10  6011 02 lageos1\n"
                 "H2  7603901 1155     8820 2024  3  1  0  0  0 2024  3  2  0  0  0   120 1 1  2 0 0 1\n"
                 "H5 0.2510\nH9\n"
                 "10 0 60370  43200.000000  0   1.0 2.0 3.0\n20 0 4.0 5.0 6.0\n30 0 0.1 0.2 0.3 12.5\n"
                 "10 0 60370  43320.500000  0   7.0 8.0 9.0\n99\n")
    c = cpf.read(p)
    assert (c.header["version"], c.header["sub_daily"], c.header["target"], c.header["location"]) == \
        (2, 2, "lageos1", 1)
    assert c.frame == "EME2000" and c.header["H5"] == "0.2510"
    assert c.positions["epoch"].tolist() == [T("2024-03-01T12:00"), T("2024-03-01T12:02:00.5")]
    assert c.positions.iloc[0][["vx_mps", "vy_mps", "vz_mps"]].tolist() == [4.0, 5.0, 6.0]
    assert np.isnan(c.positions.iloc[1]["vx_mps"])
    p.write_text(p.read_text() + "10 0 60370  43440.0  0   1.0 2.0 3.0\n")
    with pytest.raises(ParseError, match="line 10, record 10: record after the 99"):
        cpf.read(p)


@pytest.mark.realdata
def test_inspect_describes_and_convert_refuses_a_cpf(shared_data, tmp_path, capsys):
    from odpipe.cli import main

    assert main(["inspect", str(shared_data / FULL)]) == 0
    out = capsys.readouterr().out
    assert "format: parsers.cpf" in out and "frame: ITRF" in out and "positions: 288" in out
    # bad input: one line on stderr, status 2
    assert main(["convert", str(shared_data / FULL), "-o", str(tmp_path / "x.parquet")]) == 2
    assert capsys.readouterr().err == f"error: {shared_data / FULL} is not tracking data\n"
