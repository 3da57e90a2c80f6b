"""Receiver lock transients at Doppler series starts (preprocess.lock_transient_k).

Constructed: 1-s Doppler of a lunar orbiter's size (a 3-kHz swing over the 7,070-s orbit, on a drift) with
0.01 Hz white noise. A series whose first three samples carry +8, +20 and +5 Hz (the size seen at
GRAIL-B's DSS-65 one-way acquisition) must lose exactly those; a clean series, a glitch in mid-series and a
series that takes longer than a minute to settle must lose nothing.

Real: GRAIL-B's ODF of 2012-04-09. DSS-65's X-band one-way series from 04:34:42 UTC must lose its first three
samples, and their excess over the course of the settled samples, averaged into the first 60-s window, must
be the +18.9 mm/s post-fit residual the one-way fit left at that window (docs/validation.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from odpipe.measurements.bands import ONE_WAY_SCALE
from odpipe.pipeline.ingest import ingest
from odpipe.preprocess.lock_transient import lock_transients

C = 299_792_458.0
ODF = Path(__file__).resolve().parents[2] / "shared" / "data" / "grail" / "grblugf2012_100_0434smmmv1.odf"


def series(start: str, n: int, station: str, observable: str = "doppler_1way", noise: float = 0.01, seed: int = 0):
    """``n`` back-to-back 1-s Doppler samples (Hz) of a lunar-orbit-like signal from ``start``."""
    t = np.arange(n, dtype=float)
    rng = np.random.default_rng(seed)
    value = -6000.0 + 0.05 * t + 1500.0 * np.sin(2 * np.pi * t / 7070.0 + seed) + rng.normal(0.0, noise, n)
    return pd.DataFrame({"epoch": pd.Timestamp(start) + pd.to_timedelta(t, "s"), "observable": observable,
                         "value": value, "unit": "Hz", "count_time": 1.0, "flags": 0, "station_tx": "DSS-24",
                         "station_rx": station, "spacecraft": "181", "band_up": "S", "band_down": "X"})


def test_a_lock_transient_is_cut_and_nothing_else():
    settling = series("2012-04-09T04:00:00", 900, "DSS-65")
    settling.loc[:2, "value"] += [8.0, 20.0, 5.0]
    clean = series("2012-04-09T06:00:00", 900, "DSS-24", seed=1)
    glitch = series("2012-04-09T08:00:00", 900, "DSS-54", seed=2)
    glitch.loc[300, "value"] += 20.0
    slow = series("2012-04-09T10:00:00", 900, "DSS-34", seed=3)
    slow.loc[:79, "value"] += np.random.default_rng(9).normal(0.0, 2.0, 80)   # 80 s unsettled: not a lock transient
    twoway = series("2012-04-09T12:00:00", 900, "DSS-34", "doppler_2way", seed=4)
    twoway.loc[:4, "value"] += [3.0, -6.0, 2.0, 1.0, 1.5]
    table = pd.concat([clean, settling, glitch, slow, twoway], ignore_index=True)
    hit = lock_transients(table, 10.0)
    first = len(clean)
    second = first + len(settling) + len(glitch) + len(slow)
    assert list(np.flatnonzero(hit)) == [first, first + 1, first + 2] + list(range(second, second + 5))


def test_a_gap_starts_a_new_series_and_flagged_rows_are_not_judged():
    a = series("2012-04-09T04:00:00", 400, "DSS-65")
    b = series("2012-04-09T04:06:50", 400, "DSS-65", seed=5)   # 10 s after a's last sample
    b.loc[:1, "value"] += [15.0, 4.0]
    table = pd.concat([a, b], ignore_index=True)
    assert list(np.flatnonzero(lock_transients(table, 10.0))) == [400, 401]
    table.loc[400, "flags"] = 1
    assert list(np.flatnonzero(lock_transients(table, 10.0))) == [401]


@pytest.mark.skipif(not ODF.exists(), reason="shared GRAIL data not present")
def test_the_real_dss65_one_way_acquisition():
    table = ingest([ODF], "report", "181").table
    hit = lock_transients(table, 10.0)
    mine = (table["station_rx"] == "DSS-65") & (table["observable"] == "doppler_1way") & (table["band_down"] == "X")
    start = pd.Timestamp("2012-04-09T04:34:42")
    assert table.loc[hit & mine, "epoch"].tolist() == [start + pd.Timedelta(seconds=s) for s in range(3)]
    x = table[mine & (table["epoch"] >= start)].sort_values("epoch")
    t = (x["epoch"] - start).dt.total_seconds().to_numpy()
    settled = (t >= 3) & (t <= 600)
    course = np.polyval(np.polyfit(t[settled], x["value"].to_numpy()[settled], 5), t)
    excess_hz = (x["value"].to_numpy() - course)[t < 3].sum() / 60.0   # in the first 60-s window's mean
    f_down = x["uplink_hz"].iloc[0] * ONE_WAY_SCALE["X"]   # the model's X-band downlink (the ODF's S-scale reference)
    # 20.0 mm/s: the fit takes up a little of a blunder it keeps, so its residual is the smaller
    assert abs(excess_hz) * C / f_down == pytest.approx(0.0189, rel=0.1)
