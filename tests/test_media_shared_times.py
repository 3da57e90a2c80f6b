"""Media corrections computed once per station and distinct time equal the straightforward computation.

Two Goldstone antennas (DSS-24 two-way, DSS-25 one-way) track one target at the same time tags: the
target's direction and the troposphere are computed once per station and distinct ground time (a count's
end is the next one's start), and each station's corrections equal those of a table holding that
station's rows alone, exactly. Row labels and sources equal the straightforward string concatenation.
"""

import numpy as np
import pandas as pd

from odpipe.media.apply import _source_texts, calibrate, calibrated, categorical, strings
from odpipe.media.model import MediaModel
from parsers import table as tt

T0 = np.datetime64("2012-04-10T04:00", "ns")


def target(t):
    """A far target fixed in inertial space (as tests/test_media_apply.py), up over Goldstone for hours."""
    s = (np.asarray(t, "datetime64[ns]") - T0) / np.timedelta64(1, "s")
    th = 2 * np.pi * s / 86164.0905 + 2.6
    ra, dec = 0.3 + 2 * np.pi * 5.3 / 23.934, 0.1
    return 1.3e12 * np.stack([np.cos(dec) * np.cos(ra - th), np.cos(dec) * np.sin(ra - th),
                              np.full_like(th, np.sin(dec))], -1)


class Counted:
    """``target`` that remembers the times it was asked for."""

    def __init__(self):
        self.asked = []

    def __call__(self, t):
        self.asked.append(np.asarray(t, "datetime64[ns]"))
        return target(t)


def _table(n=80):
    ep = np.repeat(T0 + np.arange(n // 2) * np.timedelta64(60, "s"), 2)
    two = np.arange(n) % 2 == 0
    return tt.build(n, epoch=ep, tag="interval_mid", value=0.0, unit="Hz", count_time=60.0,
                    observable=np.where(two, "doppler_2way", "doppler_1way"),
                    station_tx=np.where(two, "DSS-24", ""), station_rx=np.where(two, "DSS-24", "DSS-25"),
                    spacecraft="181", band_up="S", band_down=np.where(two, "S", "X"), uplink_hz=2.1e9,
                    transponder_ratio=240 / 221, rtlt_s=2.6)


def test_stations_sharing_times_equal_each_station_alone():
    tab, model = _table(), MediaModel()
    counted = Counted()
    both = calibrated(tab, model, target_itrs=counted, order=None)   # (smoothing: times from the table's first)
    assert len(counted.asked) == 2            # one call per station (DSS-24: both legs)
    for asked in counted.asked:               # each distinct time once: 41 count bounds per leg, not 80
        assert asked.size == np.unique(asked).size <= 2 * 41
    assert sorted(a.size for a in counted.asked) == [41, 82]
    for station in ("DSS-24", "DSS-25"):
        rows = (tab["station_rx"] == station).to_numpy()
        alone = calibrated(tab[rows].reset_index(drop=True), model, target_itrs=target, order=None)
        for col in ("tropo_m", "iono_m", "media_m"):
            np.testing.assert_array_equal(both.loc[rows, col].to_numpy(), alone[col].to_numpy())
        for col in ("media_source", "media_source_up", "media_note"):
            assert list(both.loc[rows, col].astype(str)) == list(alone[col].astype(str))
    assert np.isfinite(both["media_m"]).all()


def test_calibrate_is_calibrated_with_its_pass_report():
    tab = _table(20)
    out, report = calibrate(tab, MediaModel(), target_itrs=target)
    pd.testing.assert_frame_equal(out, calibrated(tab, MediaModel(), target_itrs=target))
    assert report["rows"].sum() == len(tab)


def test_strings_equal_the_column_converted_row_by_row():
    col = pd.Series(["DSS-24", "DSS-25", None, "DSS-24", "DSS-54"], dtype="str")
    for dtype in (object, str):
        got, expected = strings(col, dtype), col.to_numpy(dtype=dtype)
        assert got.dtype == expected.dtype and list(map(repr, got)) == list(map(repr, expected))   # nan too


def test_source_texts_equal_the_concatenated_labels_factorized():
    rng = np.random.default_rng(5)
    lab_t = rng.choice(np.array(["DSN-seasonal (no TRO)", "no direction", "a.TRO:12 + DSN-seasonal"], object), 500)
    lab_i = rng.choice(np.array(["none", "no direction", "b.ION:3"], object), 500)
    code, texts = _source_texts(lab_t, lab_i)
    expected_code, expected_texts = pd.factorize("tropo: " + pd.Series(lab_t) + " | iono: " + pd.Series(lab_i))
    np.testing.assert_array_equal(code, expected_code)
    assert list(texts) == list(expected_texts)


def test_categorical_equals_the_categorical_of_the_texts_row_by_row():
    texts = np.array(["no TRO; none", "", "no direction", ""], dtype=object)   # a text may repeat
    codes = np.array([0, 1, 3, 3, 0, 2, 1])
    pd.testing.assert_series_equal(pd.Series(categorical(codes, texts)), pd.Series(pd.Categorical(texts[codes])))
    pd.testing.assert_series_equal(pd.Series(categorical(codes[:2], texts)),   # only the texts present
                                   pd.Series(pd.Categorical(texts[codes[:2]])))
