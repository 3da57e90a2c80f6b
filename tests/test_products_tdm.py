"""Real ODF data written as CCSDS TDM 2.0 (odpipe.products.tdm) and read back by odpipe and by ccsds-ndm.

The MESSENGER, GRAIL-B and Cassini ODFs (ramped S/X/Ka 1/2/3-way Doppler, sequential range, ramp
records) become RECEIVE_FREQ_n (received frequency over each 60-s count, less FREQ_OFFSET = M2 f_REF),
RANGE in RU and TRANSMIT_FREQ_n/TRANSMIT_FREQ_RATE_n ramps; reading the TDM back must give the ODF's values:
``M2 f_REF - (RECEIVE_FREQ + FREQ_OFFSET)`` = the ODF Doppler (DSN convention, tudat's Moyer eq. 13-54).
"""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.products.tdm import doppler_from_tdm, to_tdm


@pytest.fixture(scope="module")
def messenger(shared_data):
    from parsers import odf

    return odf.read(shared_data / "messenger" / "odf07155.odf")


ODFS = {"messenger": "messenger/odf07155.odf", "grail": "grail/grblugf2012_101_0350smmmv1.odf",
        "cassini": "cassini/S18TIGM2006_058_0005X25MV1.ODF"}
KEY = ["observable", "station_tx", "station_rx", "band_down", "epoch"]


def _round_trip(data, path, syntax):
    from parsers import tdm

    out, skipped = to_tdm(data, creation_date="2026-11-22T00:00:00")
    assert skipped.empty
    tdm.write(path, out, syntax=syntax)
    back, left = doppler_from_tdm(tdm.read(path))
    assert left == 0
    return back


@pytest.mark.realdata
@pytest.mark.parametrize("syntax", ["kvn", "xml"])
@pytest.mark.parametrize("mission", sorted(ODFS))
def test_odf_through_tdm_gives_the_odf_back(shared_data, tmp_path, mission, syntax):
    """Every ODF observable, epoch (ns), value (bit for bit), station, band, count time and uplink ramp comes
    back from the TDM; the references the Doppler is formed against come back to the last bit of M2 f_R."""
    from parsers import odf

    src = odf.read(shared_data / ODFS[mission])
    back = _round_trip(src, tmp_path / f"{mission}.{syntax}", syntax)
    a, b = src.table, back.table
    assert len(a) == len(b) and set(b["observable"]) == set(a["observable"])
    m = a.merge(b, on=KEY, suffixes=("", "_tdm"), validate="one_to_one")
    assert len(m) == len(a)
    assert np.array_equal(m["value"], m["value_tdm"])
    for col in ("tag", "unit", "count_time", "spacecraft", "band_up", "ramped"):
        assert (m[col] == m[f"{col}_tdm"]).all(), col
    dop = m[m["observable"].isin(["doppler_2way", "doppler_3way"])]
    assert np.array_equal(dop["transponder_ratio"], dop["transponder_ratio_tdm"])
    assert np.allclose(dop["reference_hz_tdm"], dop["reference_hz"], rtol=2e-16, atol=0)  # FREQ_OFFSET / M2
    one = m[m["observable"] == "doppler_1way"]   # the ODF's S-band-scale reference times 880/240 at X band
    scale = one["band_down"].map({"S": 1.0, "X": 880 / 240}).to_numpy()
    assert np.array_equal(one["uplink_hz_tdm"], one["uplink_hz"] * scale)
    rng = m[m["observable"] == "range"]
    assert np.array_equal(rng["range_modulus"], rng["range_modulus_ru"])
    # ramps: start, frequency, rate, band of every record; a TDM has no end of a station's last ramp
    r0 = src.ramps.sort_values(["station", "start"]).reset_index(drop=True)
    r1 = back.ramps.sort_values(["station", "start"]).reset_index(drop=True)
    for col in ("station", "start", "freq_hz", "rate_hz_s", "band"):
        assert np.array_equal(r1[col].to_numpy(), r0[col].to_numpy()), col
    last = r1["station"].ne(r1["station"].shift(-1)).to_numpy()
    assert (r1["end"][~last] == r0["end"][~last]).all() and r1["end"][last].isna().all()


@pytest.mark.realdata
def test_written_tdm_keeps_the_standards_keyword_order(messenger, tmp_path):
    """Header and metadata keywords in the order, and with the required ones, of the CCSDS TDM 2.0 schema as
    ccsds-ndm models it (its classes are generated from the standard's XSD)."""
    import dataclasses

    from ccsds_ndm.models.ndmxml4 import ndmxml_4_0_0_tdm_2_0 as schema

    from parsers import tdm

    def order(cls):
        fields = [f for f in dataclasses.fields(cls) if f.name != "comment"]
        return ([f.metadata.get("name", f.name.upper()) for f in fields],
                {f.metadata.get("name", f.name.upper()) for f in fields if f.metadata.get("required")})

    out, _ = to_tdm(messenger, creation_date="2026-11-22T00:00:00")
    tdm.write(tmp_path / "m.tdm", out)
    lines = [ln.split("=")[0].strip() for ln in (tmp_path / "m.tdm").read_text().splitlines()]
    assert lines[0] == "CCSDS_TDM_VERS"
    header, meta = order(schema.TdmHeader), order(schema.TdmMetadata)
    assert [k for k in lines[1:lines.index("META_START")] if not k.startswith("COMMENT")] == \
        [k for k in header[0] if k in ("CREATION_DATE", "ORIGINATOR")]
    blocks = 0
    for i, key in enumerate(lines):
        if key == "META_START":
            keys = lines[i + 1:lines.index("META_STOP", i)]
            rank = [meta[0].index(k) for k in keys]
            assert rank == sorted(rank) and meta[1] <= set(keys), keys
            blocks += 1
    assert blocks == len(out.meta["segments"])


@pytest.mark.realdata
def test_tdm_from_odf_read_by_ccsds_ndm(messenger, tmp_path):
    from ccsds_ndm.ndm_io import NdmIo

    from parsers import tdm

    out, _ = to_tdm(messenger, creation_date="2026-11-22T00:00:00")
    tdm.write(tmp_path / "m.xml", out, syntax="xml")
    doc = NdmIo().from_path(tmp_path / "m.xml")
    segs = doc.body.segment
    assert len(segs) == len(out.meta["segments"])
    two_way = [s for s in segs if s.metadata.path == "1,2,1" and s.data.observation[0].receive_freq_1 is not None]
    dss14 = next(s for s in two_way if s.metadata.participant_1 == "DSS-14")
    first = dss14.data.observation[0]
    # the first DSS-14 two-way record (tudat decodes 1.563486099 Hz against f_REF 7177641534 Hz): the received
    # frequency is RECEIVE_FREQ + FREQ_OFFSET, the offset M2 f_REF
    assert first.epoch.startswith("2007-06-04T20:53:12")
    assert dss14.metadata.freq_offset == pytest.approx(880 / 749 * 7177641534.0, rel=1e-15)
    received = first.receive_freq_1 + dss14.metadata.freq_offset
    assert 880 / 749 * 7177641534.0 - received == pytest.approx(1.563486099, abs=2e-6)
    assert dss14.metadata.turnaround_numerator == 880 and dss14.metadata.turnaround_denominator == 749


@pytest.mark.realdata
def test_convert_counts_observations_and_ramp_lines(messenger, shared_data, tmp_path, capsys):
    """`odpipe convert ODF -o X.tdm` counts the ODF's observations and, apart, the TRANSMIT_FREQ and
    TRANSMIT_FREQ_RATE line each of its 169 ramp records becomes."""
    from odpipe.cli import main

    assert main(["convert", str(shared_data / "messenger" / "odf07155.odf"), "-o", str(tmp_path / "m.tdm")]) == 0
    n, ramps = len(messenger.table), len(messenger.ramps)
    assert ramps == 169
    assert f"{n + 2 * ramps} rows ({n} observations, {2 * ramps} ramp lines) -> " in capsys.readouterr().out


@pytest.mark.realdata
def test_convert_tdm_to_parquet_gives_the_odf_doppler(messenger, shared_data, tmp_path, capsys):
    """`odpipe convert ODF -o X.tdm`, then `odpipe convert X.tdm -o Y.parquet`: Y holds the ODF's Doppler and
    range rows (values bit for bit), not received frequencies, and the ramps beside it."""
    from odpipe.cli import main
    from odpipe.preprocess import store

    assert main(["convert", str(shared_data / "messenger" / "odf07155.odf"), "-o", str(tmp_path / "m.tdm")]) == 0
    assert main(["convert", str(tmp_path / "m.tdm"), "-o", str(tmp_path / "m.parquet")]) == 0
    assert "RECEIVE_FREQ rows kept" not in capsys.readouterr().out
    table, ramps = store.read(tmp_path / "m.parquet")
    src = messenger.table
    assert table["observable"].value_counts().to_dict() == src["observable"].value_counts().to_dict()
    m = src.merge(table, on=KEY, suffixes=("", "_tdm"), validate="one_to_one")
    assert len(m) == len(src) == 2228 and np.array_equal(m["value"], m["value_tdm"])
    assert len(ramps) == len(messenger.ramps) == 169
