"""Pass segmentation and time-tag intervals on synthetic tracking with known structure."""

import numpy as np
import pandas as pd
import pytest

from odpipe.preprocess.flags import Flag, names
from odpipe.tracking.passes import assign_passes, pass_summary
from odpipe.tracking.timetags import interval_bounds, tag_epoch
from parsers.table import build, empty_ramps

T0 = np.datetime64("2012-04-09T00:00:00", "ns")


def doppler(t_s, **kw):
    cols = dict(epoch=T0 + (np.asarray(t_s) * 1e9).astype("timedelta64[ns]"), tag="interval_mid",
                observable="doppler_2way", value=0.0, unit="Hz", count_time=1.0, station_tx="DSS-24",
                station_rx="DSS-24", spacecraft="181", band_up="S", band_down="S", uplink_hz=2.1e9,
                source="synthetic", record=np.arange(len(t_s)), flags=0)
    cols.update(kw)
    return build(len(t_s), **cols)


def test_passes_break_at_gaps_and_configuration_changes():
    a = doppler(np.arange(0.5, 100.0))                                  # pass 0
    b = doppler(np.arange(700.5, 800.0))                                # after a 600-s hole: same pass (not > 600)
    c = doppler(np.arange(1401.5, 1500.0))                              # 601.5-s hole: new pass
    d = doppler(np.arange(1500.5, 1600.0), uplink_hz=2.1e9 + 5.0)       # uplink retuned: new pass
    e = doppler(np.arange(1605.0, 1700.0, 10.0), uplink_hz=2.1e9 + 5.0, count_time=10.0)  # count time change
    f = doppler(np.arange(0.5, 100.0), station_rx="DSS-25", observable="doppler_3way")  # another link
    tab = pd.concat([a, b, c, d, e, f], ignore_index=True).sample(frac=1.0, random_state=1)
    out = assign_passes(tab, max_gap=600.0)
    n = [len(x) for x in (a, b, c, d, e, f)]
    expect = np.repeat([0, 0, 1, 2, 3, 4], n)
    got = out.sort_index()["pass_id"].to_numpy()
    # same partition (ids numbered by link then time)
    assert pd.crosstab(got, expect).gt(0).sum(axis=1).eq(1).all() and len(set(got)) == 5
    summ = pass_summary(out)
    assert sorted(summ["samples"]) == sorted([n[0] + n[1], n[2], n[3], n[4], n[5]])


def test_sparse_range_points_form_one_pass():
    t = np.r_[np.arange(0, 6) * 1800.0, 50000.0 + np.arange(0, 4) * 1800.0]  # 30-min points, then a new pass
    rng = doppler(t, observable="range", unit="RU", count_time=0.0, tag="receive")
    out = assign_passes(rng, max_gap=600.0)
    assert out["pass_id"].tolist() == [0] * 6 + [1] * 4


def test_ramp_jump_splits_a_pass_but_a_rate_change_does_not():
    tab = doppler(np.arange(0.5, 600.0), ramped=True, uplink_hz=np.nan)
    start = [T0, T0 + np.timedelta64(200, "s"), T0 + np.timedelta64(400, "s")]
    ramps = pd.concat([empty_ramps(), pd.DataFrame({
        "station": "DSS-24", "start": start, "end": pd.NaT,
        "freq_hz": [2.1e9, 2.1e9 + 200 * 3.0, 2.1e9 + 200 * 3.0 + 200 * -1.0 + 5e3],  # 5 kHz retune at 400 s
        "rate_hz_s": [3.0, -1.0, 0.0], "band": "S", "source": "synthetic", "record": [0, 1, 2]})],
        ignore_index=True)
    out = assign_passes(tab, ramps)
    t = (out["epoch"] - T0).dt.total_seconds().to_numpy()
    assert out["pass_id"].nunique() == 2
    assert (out.loc[t < 400, "pass_id"] == out["pass_id"].iloc[0]).all()
    assert (out.loc[t > 400, "pass_id"] != out["pass_id"].iloc[0]).all()


@pytest.mark.parametrize("tag,offset", [("interval_mid", 0.5), ("interval_end", 1.0), ("interval_start", 0.0)])
def test_interval_bounds_follow_the_tag(tag, offset):
    epoch = np.array([10_000_000_000, 20_000_000_000])
    start, end = interval_bounds(epoch, np.array([10.0, 2.0]), np.array([tag, tag], dtype=object))
    assert list(end - start) == [10_000_000_000, 2_000_000_000]
    assert list(epoch - start) == [int(offset * 10e9), int(offset * 2e9)]
    assert list(tag_epoch(start, end, np.array([tag, tag], dtype=object))) == list(epoch)


def test_receive_tag_with_a_count_time_is_refused():
    with pytest.raises(ValueError, match="receive"):
        interval_bounds(np.array([0]), np.array([1.0]), np.array(["receive"], dtype=object))


def test_flag_names():
    assert names(int(Flag.ELEVATION | Flag.BLUNDER)) == ["elevation", "blunder"]
    assert names(0) == []
    assert len({int(f) for f in Flag}) == len(Flag)  # one bit each
