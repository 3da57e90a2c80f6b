"""The per-pass media plot of `odpipe calibrate --plots`: Doppler rows as the range-rate equivalent in mm/s,
ticks on whole UTC minutes, and nothing cut off or overlapping (the y label ran off the left edge, the
fallback note sat on the x label, the axis read 'm change over count' with a 1e-6 multiplier)."""

import numpy as np
import pandas as pd
import pytest

import odpipe.media.plot as media_plot


@pytest.fixture
def figure(monkeypatch):
    saved = []
    monkeypatch.setattr(media_plot, "save_figure", lambda path, fig, **kw: saved.append(fig))
    return saved


def _pass(observable, count_time, minutes):
    n = int(minutes * 60 / count_time)
    tropo = -2e-6 * count_time * (1 + np.arange(n) / n)   # m of delay change over each count
    return pd.DataFrame({"pass_id": 12, "station_rx": "DSS-54", "observable": observable, "count_time": count_time,
                         "epoch": np.datetime64("2012-04-10T03:20:10", "ns")
                         + np.arange(n) * np.timedelta64(int(count_time), "s"),
                         "tropo_m": tropo, "iono_m": 0.0, "media_m": tropo,
                         "media_note": "no TRO coverage: DSN seasonal model used; no ionosphere calibration: none "
                                       "applied"})


@pytest.mark.parametrize("count_time, minutes", [(1.0, 5), (60.0, 75)])
def test_doppler_media_plot_in_mm_per_s_with_nothing_cut_or_overlapping(figure, count_time, minutes):
    rows = _pass("doppler_1way", count_time, minutes)
    media_plot.plot_pass_delays(rows, 12, "x.png")
    fig = figure[0]
    fig.canvas.draw()
    ax = fig.axes[0]
    assert ax.get_ylabel() == "range-rate correction (mm/s)" and ax.get_xlabel() == "time (UTC)"
    tropo = next(line for line in ax.get_lines() if line.get_label() == "troposphere")
    np.testing.assert_allclose(tropo.get_ydata(), rows["tropo_m"] / count_time * 1e3)   # -0.002 .. -0.004 mm/s
    assert ax.yaxis.get_offset_text().get_text() == ""                                  # no "1e-6" above the axis
    ticks = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
    assert ticks and all(len(t) == 5 or t.endswith(":00") for t in ticks), ticks       # whole minutes (HH:MM)
    assert "2012-04-10T03:20:10 UTC" in ax.get_title()
    boxes = {t.get_text(): t.get_window_extent() for t in [ax.xaxis.label, ax.yaxis.label, ax.title, *fig.texts]}
    for text, box in boxes.items():
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.x1 and box.y1 <= fig.bbox.y1, text
    note = next(b for t, b in boxes.items() if t.startswith("no TRO"))
    assert note.y1 < boxes["time (UTC)"].y0 and note.y1 < ax.xaxis.get_tightbbox().y0


def test_range_media_plot_in_m(figure):
    media_plot.plot_pass_delays(_pass("range", 60.0, 30), 12, "x.png")
    ax = figure[0].axes[0]
    assert ax.get_ylabel() == "range delay (m)"
    np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), _pass("range", 60.0, 30)["tropo_m"])
