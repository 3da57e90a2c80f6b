"""Format detection, ``odpipe inspect`` on real ODFs, and the convert -> edit -> compress command chain."""

from collections import Counter

import numpy as np
import pandas as pd
import pytest

from odpipe.cli import main
from parsers import formats

TYPES = {"11": "doppler_1way", "12": "doppler_2way", "13": "doppler_3way", "36": "range", "37": "range"}


def inspect_lines(capsys, *paths):
    assert main(["inspect", *map(str, paths)]) == 0
    return capsys.readouterr().out.splitlines()


def field(lines, name):
    """Parsed 'name: k v, k v' line of the inspect output."""
    text = next(ln for ln in lines if ln.startswith(name + ":")).split(":", 1)[1]
    return dict((kv.rsplit(" ", 1)[0].strip(), kv.rsplit(" ", 1)[1]) for kv in text.split(","))


@pytest.mark.realdata
def test_detect_formats_of_real_files(shared_data, tmp_path):
    expect = {"grail/grblugf2012_099_0620smmmv1.odf": "parsers.odf",
              "cassini/S18TIGM2006_058_0005X25MV1.ODF": "parsers.odf",
              "utdf/LSUTDF_367501_119_2019_044_1555.trk": "parsers.utdf",
              "grail/mas00_2012_04_06_a_04.asc": "parsers.maneuvers"}
    for rel, name in expect.items():
        assert formats.detect(shared_data / rel) == name, rel


@pytest.mark.realdata
def test_inspect_reads_calibration_files(shared_data, capsys):
    """README: `odpipe inspect` says what a calibration file holds, too. Cassini's TRK-2-23 cards and the
    IGS-format IONEX day, counted in the raw text: the model named in each card's MODEL(...), its
    DSN(...) complex; the IONEX file's START OF TEC MAP records and its header's grid."""
    import re

    tro = shared_data / "cassini" / "S18TIGE2006_032_2006_059.TRO"
    ion = shared_data / "cassini" / "S19TIGE2006_060_2006_090.ION"
    ionex = shared_data / "ionex" / "gpsg0150.19i"
    lines = inspect_lines(capsys, tro, ion, ionex)
    for path in (tro, ion):
        cards = re.findall(r"MODEL\s*\(([A-Z ]+)\)\s*FROM.*?DSN\((C\d0)\)", " ".join(path.read_text().split()))
        assert f"cards: {len(cards)}" in lines
        for model in {m for m, _ in cards}:
            per = Counter(c for m, c in cards if m == model)
            assert any(ln.startswith(f"{model}: {sum(per.values())} cards, "
                                     + ", ".join(f"{c} {n}" for c, n in sorted(per.items())) + ";")
                       for ln in lines), (model, per)
    assert "format: parsers.trk223" in lines and "spacecraft (SCID): 82" in lines   # Cassini's DSN id
    text = ionex.read_text()
    assert f"TEC maps: {text.count('START OF TEC MAP')}" in lines and "format: parsers.ionex" in lines
    assert "epochs: 2019-01-15T00:00:00 .. 2019-01-16T00:00:00 UTC, every 3600 s" in lines   # its header's
    assert "grid: latitude 87.5 .. -87.5 deg (71), longitude -180 .. 180 deg (73), height 350 km" in lines


def test_inspect_unknown_and_unreadable_inputs(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("nothing to see here\n")
    assert formats.detect(tmp_path / "notes.txt") is None
    assert main(["inspect", str(tmp_path / "notes.txt")]) == 2  # bad input: an error, not a summary
    assert "notes.txt: format not recognised" in capsys.readouterr().err
    assert main(["inspect", str(tmp_path), str(tmp_path / "absent.odf")]) == 2  # a folder, a missing file
    err = capsys.readouterr().err.splitlines()
    assert err == [f"error: {tmp_path}: Is a directory", f"error: {tmp_path / 'absent.odf'}: No such file or directory"]


@pytest.mark.realdata
def test_inspect_messenger_matches_the_independent_listing(shared_data, capsys):
    rows = [ln.split() for ln in (shared_data / "messenger" / "odf07155.txt").read_text().splitlines()]
    data = [r for r in rows if len(r) == 19 and r[0].replace(".", "").isdigit()]
    want = Counter(TYPES[r[7]] for r in data)
    lines = inspect_lines(capsys, shared_data / "messenger" / "odf07155.odf")
    assert "format: parsers.odf" in lines and f"rows: {len(data)}" in lines
    assert {k: int(v) for k, v in field(lines, "observable").items()} == dict(want)
    t = np.array([float(r[0]) for r in data])
    first = np.datetime64("1950-01-01") + np.timedelta64(int(t.min()), "s")
    last = np.datetime64("1950-01-01") + np.timedelta64(int(t.max()), "s")
    assert f"span: {pd.Timestamp(first)} .. {pd.Timestamp(last)} UTC" in lines
    doppler_ct = Counter(int(r[17]) / 100 for r in data if r[7] in ("11", "12", "13"))
    assert f"count times (s): " + ", ".join(f"{k:g} x{v}" for k, v in sorted(doppler_ct.items())) in lines
    assert "unreadable records: 0" in lines


@pytest.mark.realdata
def test_inspect_grail_and_cassini_agree_with_the_data_notes(shared_data, capsys):
    grail = sorted((shared_data / "grail").glob("*.odf"))
    lines = inspect_lines(capsys, *grail)
    blocks = "\n".join(lines).split("== ")[1:]
    stations = set()
    for block in blocks:
        b = block.splitlines()
        assert "format: parsers.odf" in b
        assert field(b, "spacecraft") .keys() == {"181"}                 # README: DSN id 181
        assert set(field(b, "observable")) == {"doppler_1way", "doppler_2way"}
        assert "count times (s): 1" in next(ln for ln in b if ln.startswith("count times"))
        assert next(ln for ln in b if ln.startswith("ramps:"))            # ramp groups present
        stations |= set(field(b, "station_rx"))
    # README: DSS-14/15/24/25/27/34/54/55/65 over the four files
    assert stations <= {f"DSS-{n}" for n in (14, 15, 24, 25, 27, 34, 54, 55, 65)} and len(stations) >= 8
    cas = inspect_lines(capsys, shared_data / "cassini" / "S18TIGM2006_058_0005X25MV1.ODF")
    assert field(cas, "spacecraft").keys() == {"82"}
    assert set(field(cas, "observable")) == {"doppler_2way", "doppler_3way", "range"}
    assert set(field(cas, "band_down")) == {"X", "Ka"} and set(field(cas, "station_rx")) == {"DSS-25", "DSS-34"}
    assert next(ln for ln in cas if ln.startswith("span:")).startswith("span: 2006-02-27")


@pytest.mark.realdata
def test_convert_edit_compress_commands(shared_data, tmp_path, capsys):
    from odpipe.preprocess import store
    from odpipe.preprocess.flags import Flag

    src = shared_data / "grail" / "grblugf2012_099_0620smmmv1.odf"
    raw, edited, comp = tmp_path / "raw.parquet", tmp_path / "edited.parquet", tmp_path / "c60.parquet"
    assert main(["convert", str(src), "-o", str(raw)]) == 0
    assert main(["edit", str(raw), "-o", str(edited), "--no-elevation-mask"]) == 0
    assert main(["compress", str(edited), "-o", str(comp), "--count-time", "60"]) == 0
    out = capsys.readouterr().out
    t_raw, ramps = store.read(raw)
    t_edit, _ = store.read(edited)
    t_comp, ramps_c = store.read(comp)
    assert len(t_raw) == len(t_edit) == 41810 and ramps is not None and len(ramps_c) == len(ramps)
    # the 2.8e7 Hz one-way record 21121 is edited as a blunder and survives compression flagged
    row = t_comp[t_comp["record"] == 21121]
    assert len(row) == 1 and row["flags"].iloc[0] & int(Flag.BLUNDER)
    assert sum(len(r) for r in t_comp["source_records"]) == len(t_raw)
    assert t_comp["count_time"].max() == 60.0 and "raw records not represented: 0" in out
    # an ODF written as TDM: every Doppler row becomes a RECEIVE_FREQ line, the ramps TRANSMIT_FREQ lines
    assert main(["convert", str(src), "-o", str(tmp_path / "x.tdm")]) == 0
    back = formats.read_any(tmp_path / "x.tdm")
    assert (back.table["observable"] == "receive_freq").sum() == len(t_raw) and len(back.ramps) == len(ramps)


@pytest.mark.realdata
def test_convert_tdm_between_syntaxes(shared_data, tmp_path):
    src = shared_data / "tdm" / "kvn" / "TDMExample2.txt"
    assert main(["convert", str(src), "-o", str(tmp_path / "e2.xml")]) == 0
    a, b = formats.read_any(src).table, formats.read_any(tmp_path / "e2.xml").table
    assert formats.detect(tmp_path / "e2.xml") == "parsers.tdm"
    assert np.array_equal(a["value"], b["value"]) and np.array_equal(a["epoch"], b["epoch"])


@pytest.mark.realdata
def test_inspect_shows_a_tdm_as_a_run_reads_it(shared_data, tmp_path, capsys):
    """MESSENGER's ODF written as a TDM: inspect counts the same observables, stations and passes as for
    the ODF (RECEIVE_FREQ_n as DSN Doppler, TRANSMIT_FREQ lines as ramps), and says how many TDM lines
    the file holds (the 2,228 records and the 169 ramps' frequency and rate lines)."""
    odf = shared_data / "messenger/odf07155.odf"
    assert main(["convert", str(odf), "-o", str(tmp_path / "m.tdm")]) == 0
    capsys.readouterr()
    from_odf, from_tdm = inspect_lines(capsys, odf), inspect_lines(capsys, tmp_path / "m.tdm")
    for name in ("observable", "station_tx", "station_rx", "spacecraft", "ramps"):
        assert field(from_tdm, name) == field(from_odf, name), name
    assert field(from_odf, "observable") == {"doppler_1way": "23", "doppler_2way": "2053", "doppler_3way": "91",
                                             "range": "61"}
    assert any(line.startswith("TDM lines: 2566;") for line in from_tdm)
