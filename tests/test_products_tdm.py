"""Real ODF data written as CCSDS TDM 2.0 (odpipe.products.tdm) and read back by odpipe and by ccsds-ndm.

The MESSENGER ODF odf07155 (ramped X-band 1/2/3-way Doppler, sequential range, 169 ramp
records) becomes RECEIVE_FREQ_n (received frequency over each 60-s count), RANGE in RU and
TRANSMIT_FREQ_n/TRANSMIT_FREQ_RATE_n ramps; reading the TDM back must give the ODF's values:
``M2 f_REF - RECEIVE_FREQ`` = the ODF Doppler (DSN convention, tudat's Moyer eq. 13-54).
"""

from __future__ import annotations

import numpy as np
import pytest

from odpipe.products.tdm import to_tdm


@pytest.fixture(scope="module")
def messenger(shared_data):
    from parsers import odf

    return odf.read(shared_data / "messenger" / "odf07155.odf")


@pytest.mark.realdata
@pytest.mark.parametrize("syntax", ["kvn", "xml"])
def test_odf_to_tdm_reads_back_value_for_value(messenger, tmp_path, syntax):
    from parsers import tdm

    out, skipped = to_tdm(messenger, creation_date="2026-11-22T00:00:00")
    assert skipped.empty
    path = tmp_path / f"messenger.{syntax}"
    tdm.write(path, out, syntax=syntax)
    back = tdm.read(path)
    src = messenger.table
    # ramps: every ODF ramp start, frequency and rate
    r0 = messenger.ramps.sort_values(["station", "start"]).reset_index(drop=True)
    r1 = back.ramps.sort_values(["station", "start"]).reset_index(drop=True)
    assert (r1["station"] == r0["station"]).all() and (r1["start"] == r0["start"]).all()
    assert np.array_equal(r1["freq_hz"], r0["freq_hz"]) and np.array_equal(r1["rate_hz_s"], r0["rate_hz_s"])
    # two-way Doppler: M2 f_REF - received frequency gives the ODF value back
    two = src[src["observable"] == "doppler_2way"].sort_values(["station_rx", "epoch"])
    rf = back.table[(back.table["observable"] == "receive_freq") & back.table["station_tx"].eq("")]
    rf = rf.merge(two[["epoch", "station_rx", "value", "reference_hz"]], on=["epoch", "station_rx"],
                  suffixes=("", "_odf"))
    assert len(rf) == len(two)
    m2 = 880 / 749
    assert np.allclose(m2 * rf["reference_hz"] - rf["value"], rf["value_odf"], rtol=0, atol=2e-6)  # Hz
    assert set(rf["count_time"]) == {60.0} and set(rf["tag"]) == {"interval_mid"}
    # range in RU with its modulus
    rng_src = src[src["observable"] == "range"].sort_values(["station_rx", "epoch"])
    rng = back.table[back.table["observable"] == "range"].sort_values(["station_rx", "epoch"])
    assert np.array_equal(rng["value"].to_numpy(), rng_src["value"].to_numpy()) and set(rng["unit"]) == {"RU"}
    assert set(rng["range_modulus"]) == {1048576.0}


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
    # the first DSS-14 two-way record (tudat decodes 1.563486099 Hz against f_REF 7177641534 Hz)
    assert first.epoch.startswith("2007-06-04T20:53:12")
    assert 880 / 749 * 7177641534.0 - first.receive_freq_1 == pytest.approx(1.563486099, abs=2e-6)
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
