"""ILRS CRD reader: the LAGEOS-2 normal points of Orekit's OD case, decoded against their raw text and
against Orekit's own numbers (its test's 95 ranges, its reception-time range table Lageos2_test.aer)."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from parsers import aer, crd, formats
from parsers.errors import ParseError

NPT = Path("orekit_od/Lageos2/lageos2_20160214.npt")
C = 299_792_458.0


def T(s):
    return np.datetime64(s, "ns")


@pytest.fixture(scope="module")
def npt(shared_data):
    return crd.read(shared_data / NPT)


@pytest.mark.realdata
def test_counts_sessions_and_stations(shared_data, npt):
    assert formats.detect(shared_data / NPT) == "parsers.crd"
    t, s = npt.table, npt.meta["sessions"]
    # 95 normal points: the number Orekit's NumericalOrbitDeterminationTest.testLageos2 fits (nbRange = 95)
    assert len(t) == 95 and len(npt.report) == 0
    assert (t["observable"] == "range").all() and (t["unit"] == "m").all() and (t["tag"] == "receive").all()
    assert t.groupby("station_rx").size().to_dict() == {"7090": 37, "7119": 27, "7825": 17, "7941": 14}
    assert (t["station_tx"] == t["station_rx"]).all()
    assert dict(zip(s["pad_id"], s["station_code"])) == {7090: "YARL", 7119: "HA4T", 7825: "STL3", 7941: "MATM"}
    assert len(s) == 11 and set(s["range_type"]) == {2} and set(s["station_delay_applied"]) == {1}
    assert set(s["target"]) == {"lageos2"} and set(s["ilrs_id"]) == {9207002}
    assert set(s["norad"]) == {22195, -1}                       # HA4T's h3 writes -1
    assert set(t["epoch_event"]) == {2}                        # every record tagged at ground transmit
    assert t["epoch"].is_monotonic_increasing


@pytest.mark.realdata
def test_first_and_last_normal_points_from_the_raw_text(npt):
    t = npt.table
    # line 256 (STL3 session, H4 start 2016 02 11 13 07 39):
    # 11 48576.695142010998 0.048208768002 IDAA  2   120.0      7       80.20 ...
    first = t.iloc[0]
    assert first["line"] == 256 and first["record"] == 255 and first["station_code"] == "STL3"
    assert first["epoch_file"] == T("2016-02-11T13:29:36.695142011")
    assert first["epoch"] == T("2016-02-11T13:29:36.743350779")  # + 0.048208768 s of flight
    assert first["tof_s"] == 0.048208768002 and first["value"] == pytest.approx(C / 2 * 0.048208768002, abs=1e-9)
    assert (first["system_id"], first["wavelength_nm"], first["window_s"], first["n_raw"], first["bin_rms_ps"]) == \
        ("IDAA", 532.10, 120.0, 7, 80.20)
    # meteo: 20 records at 48544.545140 (humidity 80.6) and 48604.545140 (81.4), interpolated at reception
    frac = (48576.743350779 - 48544.54514) / 60.0
    assert first["humidity_pct"] == pytest.approx(80.6 + 0.8 * frac, abs=1e-6)
    assert (first["pressure_mbar"], first["temperature_k"]) == (pytest.approx(927.6), pytest.approx(290.45))
    # line 108 (YARL session, h4 2016 2 14 7 24 37): 11 27403.800561399999 0.042980915799 std 2 120.0 41 64.0 ...
    last = t.iloc[-1]
    assert last["line"] == 108 and last["station_rx"] == "7090" and last["spacecraft"] == "lageos2"
    assert last["epoch_file"] == T("2016-02-14T07:36:43.800561400")
    assert last["epoch"] == T("2016-02-14T07:36:43.843542316")
    assert (last["n_raw"], last["bin_rms_ps"], last["wavelength_nm"]) == (41, 64.0, 532.0)
    # meteo at 27403.843 s is after the session's last 20 record (27403.801: 981.50 mbar 308.50 K 20 %): held
    assert (last["pressure_mbar"], last["temperature_k"], last["humidity_pct"]) == (981.5, 308.5, 20.0)


@pytest.mark.realdata
def test_meta_records_from_the_raw_text(npt):
    m = npt.meta
    assert len(m["meteo"]) == 160 and len(m["calibrations"]) == 12 and len(m["statistics"]) == 11
    cal = m["calibrations"].iloc[0]   # line 10: 40 49336.400564399999 0 std -1 -1 -1.000 105320.0 -17.0 27.0 ...
    assert (cal["line"], cal["data_type"], cal["system_id"], cal["delay_ps"], cal["delay_shift_ps"], cal["rms_ps"]) \
        == (10, 0, "std", 105320.0, -17.0, 27.0)
    assert cal["epoch"] == T("2016-02-13T13:42:16.400564400")
    c2 = m["configuration"].query("record == 'C2' and session == 0").iloc[0]  # c2 0 mcp MCP-PMT 532.000 15.5 ...
    assert (c2["detector_type"], c2["quantum_efficiency_pct"], c2["voltage_v"]) == ("MCP-PMT", 15.5, 3000.0)
    stat = m["statistics"].iloc[-1]   # 50 std1   28.7    .047   3.038    1.0 1
    assert (stat["system_id"], stat["rms_ps"], stat["skew"], stat["data_quality"]) == ("std1", 28.7, 0.047, 1)


@pytest.mark.realdata
def test_reception_times_and_ranges_match_orekits_range_table(shared_data, npt):
    # Lageos2_test.aer is Orekit's own table of these YARL normal points as two-way ranges at reception
    # (UTC to the ms, km to the mm): our t_transmit + tof and c/2 * tof must land on its rows.
    ours = npt.table.query("station_code == 'YARL'")[["epoch", "value"]].sort_values("epoch")
    theirs = aer.read(shared_data / "orekit_od/Lageos2/Lageos2_test.aer").table
    theirs = theirs[(theirs["station_rx"] == "YARL") & (theirs["epoch"] <= ours["epoch"].max() + pd.Timedelta("1ms"))]
    j = pd.merge_asof(theirs[["epoch", "value"]], ours.rename(columns={"value": "ours"}), on="epoch",
                      direction="nearest", tolerance=pd.Timedelta("1ms"))
    assert len(j) == 25 and j["ours"].notna().all()
    assert np.abs(j["value"] - j["ours"]).max() < 1e-3          # m


def _corrupt(shared_data, tmp_path, line_no, new_text):
    lines = (shared_data / NPT).read_text().splitlines()
    lines[line_no - 1] = new_text
    p = tmp_path / "bad.npt"
    p.write_text("\n".join(lines) + "\n")
    return p


@pytest.mark.realdata
@pytest.mark.parametrize("text, reason", [
    ("11 49382.400562600000", "field 3 (tof_s) is missing"),                                    # truncated line
    ("11 49382.400562600000     0.0392373x5685 std 2  120.0     94   57.0", "must be a number"),  # bad number
    ("13 49382.400562600000     0.039237325685 std 2", "unknown CRD record type '13'"),          # wrong type
    ("11 49382.400562600000     0.039237325685 std 9  120.0", "epoch event 9"),
    ("11 49382.400562600000     0.039237325685 xyz 2  120.0", "'xyz' has no C0 record"),
    ("11 4938x.4 0.039237325685 std 2", "non-negative decimal seconds"),
])
def test_corrupted_records_name_file_and_line(shared_data, tmp_path, text, reason):
    bad = _corrupt(shared_data, tmp_path, 12, text)
    with pytest.raises(ParseError) as e:
        crd.read(bad)
    assert e.value.line == 12 and reason in str(e.value)
    assert str(e.value).startswith(f"{bad}, line 12")
    d = crd.read(bad, errors="report")                           # skipped and reported, the rest read
    assert len(d.report) == 1 and d.report.errors[0].line == 12 and len(d.table) == 94


@pytest.mark.realdata
def test_structure_errors(shared_data, tmp_path):
    bad = _corrupt(shared_data, tmp_path, 36, "xx")              # h8 replaced: next h4 opens inside a session
    with pytest.raises(ParseError, match=r"line 36.*unknown CRD record type 'xx'"):
        crd.read(bad)
    with pytest.raises(ParseError, match=r"line 40, record H4: H4 before the H8"):
        crd.read(_corrupt(shared_data, tmp_path, 36, "00 comment instead of h8"))
    with pytest.raises(ParseError, match=r"line 4, record H4: field 4 \(start month\) .*integer"):
        crd.read(_corrupt(shared_data, tmp_path, 4, "h4  1 2016  x 13 13 42 16 2016  2 13 14  6 46  0 0 0 0 1 0 2 0"))


def test_v2_records_and_epoch_events(tmp_path):
    # A v2 file written from the field lists of CRD v2.01: every record type, 'na' values, a pass over 00:00.
    text = """H1 CRD  2 2024 03 01 12
H2 TEST 7777 01 02 4 ILRS
H3 sat 1234501 4321 12345 1 1
H4 1 2024 02 29 23 58 00 2024 03 01 00 05 00 0 0 0 0 1 0 2 0
H5 1 24 240229 HTS 5011
C0 0 1064.000 sys las det tim
C1 0 las Nd-YAG 1064.00 2000.00 0.40 10.0 na 1
C2 0 det SPAD 1064.000 20.0 5.0 1.0 ECL na 0.5 90.0 na na 10.0 2000.0 1
C3 0 tim GPS Rb ET ET1 0.0
C4 0 tra 1.5 2.0 3.0 4.0 100.5 1 0 0
C5 0 sw1 trk 1.0 prc 2.0
C6 0 met Vaisala PTB 1 Vaisala HMP 2 Vaisala HMP 3
C7 0 cal target 100.123 1.0 0.0 0.0 0.5 prc 1.0
00 a comment
20 86280.0 1000.00 280.00 50.0 0
20 86399.9 1001.00 281.00 60.0 0
21 86300.0 1.0 90.0 clear 10.0 0.5 2 1 na
30 86300.0 123.4567 45.6789 0 1 1 0.01 0.02
40 86250.0 0 sys na 90 10.000 2000.0 1.0 20.0 0.1 -0.1 5.0 2 2 0 60 50.0
41 86260.0 0 sys 100 90 10.000 2001.0 1.0 20.0 0.1 -0.1 5.0 2 2 0 60 50.0
11 86390.000000000001 0.040000000000 sys 2 30.0 100 20.0 0.1 -0.2 -1.0 50.0 0 12.5
11 10.500000000000 0.030000000000 sys 0 30.0 100 20.0 0.1 -0.2 -1.0 50.0 0 na
10 20.25 0.020000000000 sys 1 2 0 0 100 200
10 30.25 0.010000000000 sys 5 1 0 0 100 200
12 20.25 sys 12.5 0.251 0.0 0.0 1234.5
50 sys 20.0 0.1 -0.2 -1.0 0
H8
H9
"""
    p = tmp_path / "v2.npt"
    p.write_text(text)
    assert formats.detect(p) == "parsers.crd"
    d = crd.read(p)
    t, s = d.table, d.meta["sessions"].iloc[0]
    assert (s["format_version"], s["network"], s["provider"], s["sequence"]) == (2, "ILRS", "HTS", 5011)
    rows = t.set_index("line")
    # event 2 (ground transmit) 23:59:50 + 40 ms; event 0 (ground receive) after midnight: the next day, as is;
    # event 1 (bounce) + tof/2; event 5 (one-way, ground transmit) stays as given, one-way range c * tof
    assert rows.loc[21, "epoch"] == T("2024-02-29T23:59:50.040000000") and rows.loc[21, "tag"] == "receive"
    assert rows.loc[22, "epoch"] == T("2024-03-01T00:00:10.500000000")
    assert rows.loc[23, "epoch"] == T("2024-03-01T00:00:20.260000000")
    assert rows.loc[24, "epoch"] == T("2024-03-01T00:00:30.250000000")
    assert (rows.loc[24, "observable"], rows.loc[24, "tag"], rows.loc[24, "station_tx"], rows.loc[24, "station_rx"]) \
        == ("range_1way", "transmit", "7777", "")
    assert rows.loc[24, "value"] == pytest.approx(C * 0.01) and rows.loc[23, "value"] == pytest.approx(C / 2 * 0.02)
    assert rows.loc[23, "validity"] == 0 and rows.loc[24, "validity"] == 1     # filter flag 1: noise
    assert rows.loc[21, "wavelength_nm"] == 1064.0 and rows.loc[21, "station_code"] == "TEST"
    # humidity at 23:59:50.04 between 86280 (50 %) and 86399.9 (60 %); after 00:00 the last value is held
    assert rows.loc[21, "humidity_pct"] == pytest.approx(50 + 10 * 110.04 / 119.9)
    assert rows.loc[22, "humidity_pct"] == 60.0
    m = d.meta
    assert m["angles"].iloc[0][["azimuth_deg", "elevation_deg", "elevation_rate_degps"]].tolist() == \
        [123.4567, 45.6789, 0.02]
    assert np.isnan(m["meteo_supplements"].iloc[0]["sky_temperature_k"])
    assert m["supplements"].iloc[0][["com_correction_m", "range_rate_mps"]].tolist() == [0.251, 1234.5]
    assert len(m["calibrations"]) == 2 and m["calibrations"]["span"].tolist() == [60, 60]
    assert m["calibrations"]["n_recorded"].tolist() == [-1, 100]                  # "na": not available
    assert m["comments"].iloc[0]["text"] == "a comment"
    c = m["configuration"].set_index("record")
    assert np.isnan(c.loc["C1", "divergence_arcsec"]) and c.loc["C2", "amplifier_in_use"] == "1"
    assert c.loc["C4", "transponder_ref_time_s"] == 100.5 and c.loc["C0", "components"] == "las det tim"
    assert c.loc["C7", "fields"] == "0 cal target 100.123 1.0 0.0 0.0 0.5 prc 1.0"
    with pytest.raises(ParseError, match="line 29, record H1: record after the H9"):
        p.write_text(text + "H1 CRD  2 2024 03 01 12\n")
        crd.read(p)


@pytest.mark.realdata
def test_inspect_and_convert_know_crd(shared_data, tmp_path, capsys):
    from odpipe.cli import main
    from odpipe.preprocess import store

    assert main(["inspect", str(shared_data / NPT)]) == 0
    out = capsys.readouterr().out
    assert "format: parsers.crd" in out and "observable: range 95" in out and "passes: 11" in out
    assert main(["convert", str(shared_data / NPT), "-o", str(tmp_path / "l2.parquet")]) == 0
    table, _ = store.read(tmp_path / "l2.parquet")
    assert len(table) == 95 and table["tof_s"].iloc[0] == 0.048208768002


@pytest.mark.realdata
def test_normal_points_close_on_the_cpf_through_the_troposphere(shared_data, npt):
    """Observed range minus the CPF's geometric range, at the reception times this reader gives.

    The CPF (ITRF, 300 s, 10-point Lagrange) turned to GCRS, light time solved both legs, SLRF2014 stations
    moved by their ILRS eccentricities: what is left is the optical troposphere (about 2.4 mm per hPa at the
    zenith, over sin(elevation)) less LAGEOS-2's 0.251 m centre-of-mass offset (Orekit's
    range.center.of.mass.correction), to within the prediction's error. A time tag at transmission would leave
    200 m, a missing eccentricity (3.18 m up at 7090) over 1 m.
    """
    from scipy.interpolate import BarycentricInterpolator

    from odpipe.environment.stations import StationCatalog, topocentric
    from odpipe.frames.earth import itrs_to_gcrs
    from parsers import cpf

    d = shared_data / "orekit_od/Lageos2"
    pos = cpf.read(d / "lageos2_cpf_160213_5441.sgf").positions
    tc, xyz = pos["epoch"].to_numpy().astype(np.int64) / 1e9, pos[["x_m", "y_m", "z_m"]].to_numpy()
    cat = StationCatalog.default().with_sinex(d / "SLRF2014_POS+VEL_2030.0_200428.snx", "2016-02-13T16:00",
                                              eccentricities=d / "ecc_une.snx")

    def sat_gcrs(t):
        k = min(max(np.searchsorted(tc, t.astype(np.int64) / 1e9) - 5, 0), len(tc) - 10)
        r = BarycentricInterpolator(tc[k:k + 10], xyz[k:k + 10])(t.astype(np.int64) / 1e9)
        return itrs_to_gcrs(np.array([t]))[0] @ r, r

    inside = (npt.table["epoch"] > pos["epoch"].iloc[0] + pd.Timedelta("30min")) & \
        (npt.table["epoch"] < pos["epoch"].iloc[-1] - pd.Timedelta("30min"))
    rows = npt.table[inside]
    assert len(rows) == 49 and set(rows["station_code"]) == {"YARL", "HA4T", "MATM"}
    left = []
    for r in rows.itertuples():
        t3 = np.datetime64(r.epoch, "ns")
        st = cat[r.station_rx]
        r_st = st.position_itrs(np.array([t3]))[0]
        before = lambda s: t3 - np.timedelta64(int(round(s * 1e9)), "ns")  # noqa: E731
        down = up = r.tof_s / 2
        for _ in range(3):
            sat, sat_itrf = sat_gcrs(before(down))
            down = np.linalg.norm(sat - itrs_to_gcrs(np.array([t3]))[0] @ r_st) / C
            up = np.linalg.norm(sat - itrs_to_gcrs(np.array([before(down + up)]))[0] @ r_st) / C
        _, el, _ = topocentric(st, sat_itrf, t3)
        left.append((r.value - C * (up + down) / 2) * np.sin(el) - 2.4e-3 * r.pressure_mbar + 0.251)
    assert np.abs(left).max() < 0.3                                     # m, at the zenith
