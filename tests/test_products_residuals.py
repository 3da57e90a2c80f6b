"""Residual statistics per station and per pass, in line-of-sight units and in the observable's unit;
the editing table that adds up with them."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from odpipe.preprocess.flags import Flag, summary
from odpipe.numerics.precision import decimals, significant
from odpipe.operations.report import html_table
from odpipe.products.residuals import edit_summary, report_tables, series, statistics


@pytest.fixture
def res():
    rng = np.random.default_rng(3)
    n = 400
    hz_per_mps = 15.2  # S-band two-way: 1 mm/s = 15.2 mHz
    los = np.where(np.arange(n) < 200, 1e-3, 3e-3) * rng.standard_normal(n)
    out = pd.DataFrame({"station_rx": "DSS-24", "observable": "doppler_2way", "pass_id": np.arange(n) // 200,
                        "epoch": np.datetime64("2012-04-09T04:00", "ns") + np.arange(n) * np.timedelta64(60, "s"),
                        "unit": "Hz", "postfit_los": los, "apriori_orbit_los": 2 * los, "postfit": los * hz_per_mps,
                        "flags": 0, "status": ""})
    out.loc[5, "flags"] = int(Flag.RESIDUAL)  # an edited row is counted, not used
    out.loc[7, "status"] = "no light-time solution"  # a row the models could not compute
    return out, los, hz_per_mps


def test_rms_per_station_and_pass_in_both_units(res):
    res, los, hz_per_mps = res
    per_pass = statistics(res, by=("station_rx", "pass_id"))
    want = [np.sqrt(np.mean(np.delete(los[:200], [5, 7]) ** 2)), np.sqrt(np.mean(los[200:] ** 2))]
    assert per_pass["postfit_rms"].tolist() == pytest.approx(want, rel=1e-12)
    assert per_pass["prefit_rms"].tolist() == pytest.approx(2 * np.array(want), rel=1e-12)  # the a priori's
    assert per_pass["postfit_rms_obs"].tolist() == pytest.approx(np.array(want) * hz_per_mps, rel=1e-12)
    assert per_pass["obs_unit"].tolist() == ["Hz", "Hz"]
    assert per_pass["n_used"].tolist() == [198, 200] and per_pass["n_edited"].tolist() == [1, 0]
    assert per_pass["n_failed"].tolist() == [1, 0]
    assert per_pass["start"].iloc[1] == np.datetime64("2012-04-09T07:20", "ns")  # row 200
    whole = statistics(res)
    assert whole["postfit_rms"].iloc[0] == pytest.approx(np.sqrt(np.mean(np.delete(los, [5, 7]) ** 2)), rel=1e-12)
    assert whole["los_unit"].tolist() == ["m/s"]


def test_one_stations_s_and_x_band_one_way_are_kept_apart(res):
    """GRAIL's S-band one-way counts against a transponder oscillator 70-100 times worse than the X-band
    beacon's: a station's statistics per band, the edited-before counts from the tracking rows' band_down."""
    res, los, _ = res
    res = res.assign(observable="doppler_1way", band=np.where(np.arange(len(res)) % 2 == 0, "X", "S"))
    before = pd.DataFrame({"station_rx": ["DSS-24"] * 3, "observable": "doppler_1way", "band_down": ["s", "S", "x"]})
    stats = statistics(res, edited_before=before).set_index("band")
    used = (res["flags"] == 0) & (res["status"] == "")
    for band in ("S", "X"):
        sel = used & (res["band"] == band)
        assert stats.loc[band, "postfit_rms"] == pytest.approx(np.sqrt(np.mean(res.loc[sel, "postfit_los"] ** 2)),
                                                               rel=1e-12)
        assert stats.loc[band, "n_used"] == sel.sum()
    assert stats.loc["S", "n_edited"] == 1 + 2 and stats.loc["X", "n_edited"] == 0 + 1   # row 5 is S-band
    (_, table, _), = report_tables(stats.reset_index())
    assert table["band"].tolist() == ["S", "X"]
    (_, table, _), = report_tables(statistics(res.assign(band="")))
    assert "band" not in table   # no band column where no row has one
    used = ((res["flags"] == 0) & (res["status"] == "")).to_numpy()
    assert series(res, ~used)[:2].tolist() == ["DSS-24 X", "DSS-24 S"]   # the plot's legend too
    assert series(res.assign(band="X"), ~used)[:2].tolist() == ["DSS-24", "DSS-24"]


def test_report_tables_show_mm_per_s_and_the_observed_unit(res):
    res, los, hz_per_mps = res
    (caption, table, formats), = report_tables(statistics(res, by=("station_rx", "observable", "pass_id")))
    assert caption == "doppler_2way (observed in Hz)"
    assert list(table.columns) == ["station_rx", "pass_id", "n_used", "n_edited", "n_failed", "start (UTC)",
                                   "end (UTC)", "pre-fit RMS (mm/s)", "post-fit mean (mm/s)", "post-fit RMS (mm/s)",
                                   "post-fit RMS (Hz)"]
    assert table["post-fit RMS (mm/s)"].iloc[1] == pytest.approx(np.sqrt(np.mean(los[200:] ** 2)) * 1e3, rel=1e-12)


def test_report_tables_print_statistics_at_the_precision_they_carry(res):
    """Each RMS to 3 significant figures; each post-fit mean to the first digit of the table's smallest
    standard error: pass 0 holds 198 rows of 1 mm/s scatter (standard error 0.07 mm/s: 2 decimals)."""
    res, los, _ = res
    (_, table, formats), = report_tables(statistics(res, by=("station_rx", "observable", "pass_id")))
    page = html_table(table, formats)
    kept = np.delete(los[:200], [5, 7]) * 1e3   # mm/s
    rms0, rms1 = np.sqrt(np.mean(kept ** 2)), np.sqrt(np.mean((los[200:] * 1e3) ** 2))
    assert 0.05 < rms0 / np.sqrt(198) < 0.1 and rms1 / np.sqrt(200) > rms0 / np.sqrt(198)
    cells = re.findall(r"<td>([^<]*)</td>", page)
    for text in (f"{kept.mean():.2f}", f"{los[200:].mean() * 1e3:.2f}", f"{rms0:#.3g}", f"{2 * rms0:#.3g}",
                 f"{rms1:#.3g}"):
        assert text.rstrip(".") in cells, (text, cells)


def test_a_mean_that_rounds_to_zero_has_no_sign(res):
    res, _, _ = res
    used = (res["pass_id"] == 0) & (res["flags"] == 0) & (res["status"] == "")
    res["postfit_los"] -= res.loc[used, "postfit_los"].mean() + 1e-7   # pass 0's mean: -0.0001 mm/s
    (_, table, formats), = report_tables(statistics(res, by=("station_rx", "observable", "pass_id")))
    assert re.findall(r"<td[^>]*>([^<]*)</td>", html_table(table, formats))[8] == "0.00"   # pass 0, post-fit mean


@pytest.mark.parametrize("value, text", [(4516.098, "4520"), (0.52062, "0.521"), (12.0, "12.0"),
                                         (-0.0124, "-0.0124"), (0.999999, "1.00"),
                                         (0.52999, "0.530"), (9.9996, "10.0"), (0.0, "0.00"),
                                         (0.73, "0.730"), (0.5, "0.500"), (0.073, "0.0730"),
                                         (-0.73, "-0.730")])
def test_significant_figures(value, text):
    assert significant(value) == text


def test_decimals_of_a_standard_error():
    assert [decimals(x) for x in (0.13, 0.004, 25.0, 0.0, np.nan)] == [1, 3, 0, 0, 0]


def test_edit_summary_adds_up_with_the_residual_tables(res):
    res, _, _ = res
    flags = np.zeros(450, int)
    flags[:30] = int(Flag.ELEVATION)
    flags[30:40] = int(Flag.BLUNDER)  # 410 rows handed to the fit, 400 of them in its residual table
    table = edit_summary(summary(flags), res)
    rows = dict(zip(table["reason"], table["rows"]))
    assert rows == {"elevation": 30, "blunder": 10, "passed to the fit": 410,
                    "outside the arc or no data sigma": 10, "not computable: no light-time solution": 1,
                    "edited (innovation test)": 1, "fitted": 398}
    stats = statistics(res)
    assert rows["fitted"] == stats["n_used"].sum() and rows["edited (innovation test)"] == stats["n_edited"].sum()
    assert rows["passed to the fit"] == table.loc[table["stage"] == "fit", "rows"].sum()


def test_a_station_has_one_colour_in_every_panel(monkeypatch):
    """GRAIL-B 04-08's pre-fit plot: one-way from DSS-14, -24, -34, -65 and two-way from DSS-24, -27, -34, -65;
    DSS-24 was orange in the one-way panel and blue in the two-way one (each panel's own colour cycle)."""
    import odpipe.products.residuals as residuals

    saved = []
    monkeypatch.setattr(residuals, "save_figure", lambda path, fig, **kw: saved.append(fig))
    panels = {"doppler_1way": ("DSS-14", "DSS-24", "DSS-34", "DSS-65"),
              "doppler_2way": ("DSS-24", "DSS-27", "DSS-34", "DSS-65")}
    rows = pd.DataFrame([{"station_rx": st, "observable": obs, "band": "S",
                          "epoch": np.datetime64("2012-04-08T06:00", "ns") + np.timedelta64(60 * k, "s"),
                          "postfit_los": 1e-3 * (-1) ** k, "flags": 0, "status": ""}
                         for obs, stations in panels.items() for st in stations for k in range(5)])
    residuals.plot(rows, "x.png", "postfit")
    colours = {}
    for ax in saved[0].axes:
        for line in ax.get_lines():
            colours.setdefault(line.get_label().split(" (")[0], set()).add(line.get_color())
    assert set(colours) == {"DSS-14", "DSS-24", "DSS-27", "DSS-34", "DSS-65"}
    assert all(len(c) == 1 for c in colours.values()), colours
    assert len(set().union(*colours.values())) == 5   # and the stations apart


def test_angle_residuals_are_plotted_in_degrees(monkeypatch):
    """W3B's pre-fit plot drew azimuth and elevation as range x angle in m (up to -200000 at 40,000 km, tick
    labels running into the axis label); they are plotted in degrees, the unit Orekit's and the config's
    are in: 0.005 deg at 40,000 km (3.5 km across the line of sight) is drawn as 0.005."""
    import odpipe.products.residuals as residuals

    saved = []
    monkeypatch.setattr(residuals, "save_figure", lambda path, fig, **kw: saved.append(fig))
    rho, angle = 40e6, np.array([0.005, -0.005, 0.01])   # m, deg
    t = np.datetime64("2010-11-02T14:00", "ns") + np.arange(3) * np.timedelta64(60, "s")
    rows = pd.concat([
        pd.DataFrame({"station_rx": "CastleRock", "observable": "angle_az", "unit": "rad", "epoch": t,
                      "to_los": rho, "postfit_los": rho * np.radians(angle), "flags": 0, "status": ""}),
        pd.DataFrame({"station_rx": "CastleRock", "observable": "range", "unit": "m", "epoch": t,
                      "to_los": 1.0, "postfit_los": [2.0, -1.0, 3.0], "flags": 0, "status": ""})], ignore_index=True)
    residuals.plot(rows, "x.png", "postfit")
    az, rng = saved[0].axes
    assert az.get_ylabel() == "angle_az (deg)" and rng.get_ylabel() == "range (m)"
    np.testing.assert_allclose(az.get_lines()[0].get_ydata(), angle, rtol=1e-12)
    np.testing.assert_allclose(rng.get_lines()[0].get_ydata(), [2.0, -1.0, 3.0])


def test_the_legend_leaves_the_points_visible(monkeypatch):
    """W3B's pre-fit azimuths: CastleRock's points ran under the legend fixed in the upper right corner; the
    legend takes the corner with the fewest points under it, here none."""
    import odpipe.products.residuals as residuals

    saved = []
    monkeypatch.setattr(residuals, "save_figure", lambda path, fig, **kw: saved.append(fig))
    t = np.datetime64("2010-11-02T03:00", "ns") + np.arange(120) * np.timedelta64(60, "s")
    y = np.where(np.arange(120) < 60, 0.0, 1.0)    # the second hour high: under an upper-right legend
    rows = pd.DataFrame({"station_rx": np.where(np.arange(120) < 60, "Kumsan", "CastleRock"), "observable": "range",
                         "unit": "m", "epoch": t, "to_los": 1.0, "postfit_los": y, "flags": 0, "status": ""})
    residuals.plot(rows, "x.png", "postfit")
    fig = saved[0]
    fig.canvas.draw()
    ax = fig.axes[0]
    box = ax.get_legend().get_window_extent()
    points = np.vstack([ax.transData.transform(np.column_stack(line.get_data(orig=False))) for line in ax.get_lines()])
    assert not box.count_contains(points)


@pytest.mark.parametrize("hours, ticks, label", [(14 * 24, "2010-12-01", "time (UTC)"),
                                                 (10, "11-30 14:00", "time (UTC, 2010)")])
def test_time_axis_says_the_year(monkeypatch, hours, ticks, label):
    """The twin's 14-day long2 plots read '12-01 00:00', '12-03 00:00', ...: no year on the axis. Day ticks are
    ISO dates; hour ticks keep month-day and time with the year in the axis label."""
    import odpipe.products.residuals as residuals

    saved = []
    monkeypatch.setattr(residuals, "save_figure", lambda path, fig, **kw: saved.append(fig))
    epochs = np.datetime64("2010-11-30T13:00", "ns") + np.arange(50) * np.timedelta64(hours * 72, "s")
    rows = pd.DataFrame({"station_rx": "DSS-24", "observable": "doppler_2way", "band": "S", "epoch": epochs,
                         "postfit_los": 1e-4, "flags": 0, "status": ""})
    residuals.plot(rows, "x.png", "postfit")
    ax = saved[0].axes[-1]
    saved[0].canvas.draw()
    shown = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
    assert ticks in shown, shown
    assert ax.get_xlabel() == label


def test_large_prefit_residuals_are_drawn_in_a_larger_unit(monkeypatch):
    """The twin's long2 pre-fit Doppler (up to 1.8e6 mm/s) and range (1.2e6 m) were drawn under matplotlib's '1e6'
    axis multiplier: they are drawn in m/s and km, the legend's RMS in the same unit; a blunder that was edited
    does not change the unit of the rows kept."""
    import odpipe.products.residuals as residuals

    saved = []
    monkeypatch.setattr(residuals, "save_figure", lambda path, fig, **kw: saved.append(fig))
    t = np.datetime64("2010-12-01T00:00", "ns") + np.arange(4) * np.timedelta64(600, "s")
    big = pd.concat([
        pd.DataFrame({"station_rx": "DSS-24", "observable": "doppler_2way", "epoch": t, "to_los": 1.0,
                      "apriori_orbit_los": [-1800.0, -900.0, 0.0, 300.0], "flags": 0, "status": ""}),   # m/s
        pd.DataFrame({"station_rx": "DSS-24", "observable": "range", "epoch": t, "to_los": 1.0,
                      "apriori_orbit_los": [1.2e6, -3e5, 0.0, 5e5], "flags": 0, "status": ""})], ignore_index=True)
    residuals.plot(big, "x.png", "prefit")
    dop, rng = saved[0].axes
    assert dop.get_ylabel() == "doppler_2way (m/s)" and rng.get_ylabel() == "range (km)"
    np.testing.assert_allclose(dop.get_lines()[0].get_ydata(), [-1800.0, -900.0, 0.0, 300.0])
    np.testing.assert_allclose(rng.get_lines()[0].get_ydata(), [1200.0, -300.0, 0.0, 500.0])
    assert "m/s)" in dop.get_lines()[0].get_label() and "km)" in rng.get_lines()[0].get_label()
    small = pd.DataFrame({"station_rx": "DSS-24", "observable": "doppler_2way", "epoch": t, "to_los": 1.0,
                          "postfit_los": [1e-4, -2e-4, 50.0, 0.0], "flags": [0, 0, 1, 0], "status": ""})
    residuals.plot(small, "y.png", "postfit")
    assert saved[1].axes[0].get_ylabel() == "doppler_2way (mm/s)"   # the 50-m/s blunder is edited
