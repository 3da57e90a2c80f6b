"""Uplink acquisitions (retune + sweep) and the ODF ramped-Doppler convention on real MESSENGER data.

Independent values: tudat's ODF processing test (tudat-team/tudat,
tests/src/simulation/estimation_setup/unitTestProcessOdfData.cpp) decodes the
first DSS-14 two-way records of the same file odf07155.odf as: Doppler
1.563486099 Hz at 234262457.184812993 s TDB past J2000, reference frequency
7177641534 Hz, 60-s count; range 333589.366953747 RU at 234262616.184812933 s TDB.
tudat's Doppler model (Moyer eq. 13-54) is ``M2_R f_REF - (M2/Tc) integral(f_T dt1)``,
odpipe's :func:`odpipe.measurements.dsn.dsn_doppler` with ``reference=f_REF``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from odpipe.preprocess.flags import Flag
from odpipe.preprocess.uplink import acquisitions, in_acquisition
from parsers.ramps import RampStore

T0 = np.datetime64("2020-01-01T00:00:00", "ns")


def _ramps():
    s = lambda m: T0 + np.timedelta64(int(m * 60e9), "ns")  # noqa: E731
    rows = [  # track, retune to idle at 60 min, sweep 80-82 (pause) 82.5-84, track again
        ("DSS-25", s(0), s(60), 7.2e9, 0.5),
        ("DSS-25", s(60), s(80), 7.2e9 - 9e3, 0.0),
        ("DSS-25", s(80), s(82), 7.2e9 - 9e3, 100.0),
        ("DSS-25", s(82.5), s(84), 7.2e9 + 3e3, -100.0),
        ("DSS-25", s(84), s(200), 7.2e9 - 6e3, 0.3),
        ("DSS-25", s(150), s(200), 7.2e9 - 6e3 + 0.3 * 3960 + 5e3, 0.3),  # in-lock retune: no sweep follows
    ]
    df = pd.DataFrame(rows, columns=["station", "start", "end", "freq_hz", "rate_hz_s"])
    df.loc[4, "end"] = s(150)
    df["band"], df["source"], df["record"] = "X", "synthetic", np.arange(len(df))
    return RampStore(df, jump_tol_hz=1.0)


def test_acquisition_spans_from_retune_to_end_of_merged_sweep():
    acq = acquisitions(_ramps())
    minutes = ((acq[["start", "end"]] - pd.Timestamp(T0)) / pd.Timedelta("1min")).to_numpy()
    # the sweep pair (20-s pause) is one sweep; the retune at 60 min runs to its end; the retune at 150 is no acquisition
    assert minutes.tolist() == [[60.0, 84.0], [80.0, 84.0]]


def test_rows_transmitted_during_acquisition_are_flagged():
    rs = _ramps()
    rtlt = 600.0
    t3 = T0 + (np.arange(0, 200, 1.0) * 60e9).astype("timedelta64[ns]")  # one 60-s count each minute, mid-tagged
    table = pd.DataFrame({"epoch": t3, "tag": "interval_mid", "count_time": 60.0, "observable": "doppler_2way",
                          "station_tx": "DSS-25", "rtlt_s": rtlt})
    hit = in_acquisition(table, rs)
    t1_mid = (t3 - T0).astype(np.int64) / 60e9 - rtlt / 60
    expect = (t1_mid + 0.5 >= 60) & (t1_mid - 0.5 <= 84)
    assert np.array_equal(hit, expect)
    table["observable"] = "doppler_1way"  # one-way data do not depend on the uplink
    assert not in_acquisition(table, rs).any()


@pytest.mark.realdata
def test_messenger_tudat_decoded_values(shared_data):
    from odpipe.time import utc_to_tdb
    from parsers import odf

    t = odf.read(shared_data / "messenger" / "odf07155.odf").table
    dop = t[(t["observable"] == "doppler_2way") & (t["station_rx"] == "DSS-14")].iloc[0]
    rng = t[(t["observable"] == "range") & (t["station_rx"] == "DSS-14")].iloc[0]
    assert dop["value"] == pytest.approx(1.563486099, abs=1e-9)
    assert dop["reference_hz"] == 7177641534.0 and dop["count_time"] == 60.0
    assert rng["value"] == pytest.approx(333589.366953747, abs=1e-9)
    tdb = utc_to_tdb(np.array([dop["epoch"].to_datetime64(), rng["epoch"].to_datetime64()]))
    assert tdb == pytest.approx([234262457.184812993, 234262616.184812933], abs=1e-5)


@pytest.mark.realdata
def test_messenger_doppler_continuous_across_ramps_once_acquisitions_are_edited(shared_data):
    """Venus stands in for MESSENGER (flyby 2007-06-05 23:08): observed minus computed is then MESSENGER's
    velocity relative to Venus, smooth over a pass, whatever the ramps do - except where the uplink was
    being acquired (retune + sweep), where the data leave the ramp table by hundreds of m/s."""
    from odpipe.measurements import MeasurementSetup, compute, residuals
    from odpipe.time import utc_to_tdb
    from parsers import odf

    data = odf.read(shared_data / "messenger" / "odf07155.odf")
    rs = RampStore(data.ramps, jump_tol_hz=1.0)
    setup = MeasurementSetup.default(ramps=rs)

    class VenusProxy:
        center = "ssb"

        def state(self, t):
            return setup.ephemeris.state("venus", "ssb", t)

    rows = data.table[data.table["observable"].isin(["doppler_2way", "doppler_3way"])].reset_index(drop=True)
    rows = rows[(np.abs(rows["value"]) < 1e7) & (rows["epoch"] < "2007-06-05T12:00")].reset_index(drop=True)
    ev = compute(rows, {"236": VenusProxy()}, setup)
    _, los = residuals(rows, ev)
    rel = setup.ephemeris.state("venus", "earth", utc_to_tdb(rows["epoch"].to_numpy()))[:, :3]
    rows["rtlt_s"] = 2 * np.linalg.norm(rel, axis=1) / 299792458.0  # m
    hit = in_acquisition(rows, rs)
    # the retune at 20:10:28 and sweep 20:38:23-20:39:44 at DSS-63, the sweeps of DSS-63 09:24-10:10
    assert hit.sum() > 40

    def worst_step(keep):
        worst = 0.0
        for _, g in rows[keep].assign(los=los[keep]).groupby(["station_tx", "station_rx"]):
            e, v = g["epoch"].to_numpy(), g["los"].to_numpy()
            same = np.diff(e) < np.timedelta64(30, "m")
            if same.any():
                worst = max(worst, np.abs(np.diff(v))[same].max())
        return worst

    assert worst_step(np.ones(len(rows), bool)) > 100.0  # m/s: the acquisitions
    assert worst_step(~hit) < 1.0  # every other ramp join, hundreds of them, is continuous


def test_uplink_flag_is_its_own_reason():
    assert Flag.UPLINK.name == "UPLINK" and int(Flag.UPLINK) == 1 << 10
