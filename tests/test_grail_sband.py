"""GRAIL-B's S-band one-way Doppler: what its frequency reference is, from the decoded ODF records.

The X-band one-way is the beacon driven by the ultra-stable oscillator; the S-band one-way (5-minute series at
each acquisition, before the two-way lock) comes from the transponder. Where both bands are received at one
station at the same second, the ratio of their received frequencies, each over its reference, is
``(1 + y_S) / (1 + y_X)`` whatever the orbit (the Doppler shift is one fraction for both bands; only the
ionosphere's dispersive rate differs, and the ratio leaves 8e-12 about a parabola): the oscillators' offset,
orbit-free. Against the fitted orbit
(benchmarks/grail_sband.py, docs/validation.md) the 2012-04-10 DSS-34 5-min series gave y_S = 1.395e-6 and
1.352e-6 and the arc's X oscillator y_X = 1.510e-8: the ratio must give their differences, and show the offset
re-set between the series of one station by more than any single y0 and y1 over the arc could follow.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from odpipe.analysis.overlap import SampledTrajectory
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.measurements import MeasurementSetup, compute, oscillators
from odpipe.measurements.bands import ONE_WAY_SCALE
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import load_config
from odpipe.pipeline.ingest import ingest
from odpipe.time import utc_to_tdb

RUNS = Path(__file__).resolve().parents[1] / "runs"
DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "grail"
ODF = DATA / "grblugf2012_101_0350smmmv1.odf"
# (series start UTC, y_S - y_X along the fitted orbit over the 5-min series: 1.395e-6, 1.352e-6 minus 1.510e-8;
# the third series is 17 min long, its mean over them not comparable)
DSS34 = (("2012-04-10T14:41", 1.380e-6), ("2012-04-10T16:34", 1.337e-6), ("2012-04-10T18:28", None))


@pytest.fixture(scope="module")
def one_way(shared_data):
    t = ingest([ODF], "report").table
    t = t[(t["observable"] == "doppler_1way") & (t["spacecraft"].astype(str) == "181")
          & (t["station_rx"] == "DSS-34")]
    return t.sort_values("epoch", kind="stable").reset_index(drop=True)


def _received_fraction(rows: pd.DataFrame) -> pd.Series:
    """(f_ref - value) / f_ref per row, indexed by epoch: the received over the reference frequency."""
    f = rows["uplink_hz"].to_numpy(float) * rows["band_down"].map(ONE_WAY_SCALE).to_numpy(float)
    return pd.Series((f - rows["value"].to_numpy(float)) / f, index=rows["epoch"].to_numpy())


@pytest.mark.realdata
def test_s_and_x_oscillator_offset_from_the_records_alone_resets_between_series(one_way):
    """The first 5 minutes of each series: the orbit-free offset agrees with the fitted orbit's within 2e-9;
    it moves by 4e-8 (100 Hz at S band, 13 m/s of range rate) between the first two series, 1h54m apart;
    within a series it bends: a line leaves 1.8e-10 (5 cm/s) on the first, a parabola under 3e-11."""
    offsets, about_line = [], []
    for start, along_orbit in DSS34:
        t0 = np.datetime64(start)
        near = one_way[(one_way["epoch"] >= t0) & (one_way["epoch"] < t0 + np.timedelta64(30, "m"))]
        s = _received_fraction(near[near["band_down"] == "S"])
        x = _received_fraction(near[near["band_down"] == "X"])
        both = pd.DatetimeIndex(s.index.intersection(x.index)[10:300])   # after any lock transient, 290 s
        assert len(both) > 260, start
        ratio = (s[both] / x[both] - 1.0).to_numpy()
        t = (both - both[0]).total_seconds().to_numpy()
        assert along_orbit is None or abs(np.mean(ratio) - along_orbit) < 2e-9, (start, np.mean(ratio))
        assert np.std(ratio - np.polyval(np.polyfit(t, ratio, 2), t)) < 3e-11, start
        offsets.append(np.mean(ratio))
        about_line.append(np.std(ratio - np.polyval(np.polyfit(t, ratio, 1), t)))
    assert abs(offsets[1] - offsets[0]) > 3e-8 and abs(offsets[2] - offsets[1]) < 1e-8
    assert about_line[0] > 1e-10


@pytest.mark.realdata
def test_mixed_band_rows_of_one_station_each_take_their_band_and_their_oscillator(one_way):
    """The real S and X rows of one station in one call: each row scaled to its own band and counted against
    its own oscillator (X the band's, S its pass's). A body at rest 100 km above the Moon stands for the orbit:
    the computed received fraction then differs between the bands by exactly the oscillators' ratio."""
    cfg = load_config(RUNS / "grail_b_2012_04_10.toml")
    t0 = np.datetime64(DSS34[0][0])
    rows = one_way[(one_way["epoch"] >= t0) & (one_way["epoch"] < t0 + np.timedelta64(6, "m"))]
    rows = rows.assign(pass_id=np.where(rows["band_down"] == "S", 7, 3)).reset_index(drop=True)
    t = np.asarray(utc_to_tdb(np.array([t0 - np.timedelta64(60, "s"), t0 + np.timedelta64(10, "m")])), float)
    grid = np.linspace(t[0], t[1], 80)
    still = np.zeros((grid.size, 6))
    still[:, 0] = 1.84e6                                         # m: 100 km above the Moon, at rest with it
    moon = SampledTrajectory(grid, still, "moon")
    y_x, y_s = 1.51e-8, 1.38e-6
    osc = {oscillators.name("181", "X"): (y_x, 0.0, 0.0), oscillators.name("181", "S", 7): (y_s, 0.0, 0.0),
           oscillators.name("181", "S", 8): (5e-6, 0.0, 0.0)}    # another pass's: not these rows'
    setup = MeasurementSetup(build.force_model(cfg).ephemeris, build.station_catalog(cfg), gcrs_to_itrs=gcrs_to_itrs,
                             oscillators=osc)
    ev = compute(rows, {"181": moon}, setup)
    computed = _received_fraction(rows.assign(value=ev.value))
    s, x = computed[(rows["band_down"] == "S").to_numpy()], computed[(rows["band_down"] == "X").to_numpy()]
    both = s.index.intersection(x.index)
    assert len(both) > 200
    np.testing.assert_allclose((s[both] / x[both]).to_numpy(), (1 + y_s) / (1 + y_x), rtol=0, atol=1e-12)
    assert set(k for k in ev.partials if k.startswith("oscillator:")) == {"oscillator:181:X", "oscillator:181:S:pass7"}
    d, s_rows = ev.partials["oscillator:181:S:pass7"], (rows["band_down"] == "S").to_numpy()
    assert np.all(d[~s_rows] == 0) and np.all(d[s_rows, 0] < 0)
