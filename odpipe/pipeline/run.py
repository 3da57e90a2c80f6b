"""``odpipe run``: one arc through every stage into a run directory.

ingest → geometry (a priori trajectory) → media calibration → Doppler
compression → editing → iterated filter-smoother → products. Every product is
written into a new attempt folder; the run becomes ``current`` only when all
of them are there (:mod:`odpipe.operations.rundir`), so a failed or killed run
leaves the previous good products untouched. An arc whose config and input
files are unchanged since its last complete run is skipped.
"""

from __future__ import annotations

import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe import __version__
from odpipe.analysis import maneuvers as maneuver_report
from odpipe.analysis import station_diagnostics
from odpipe.estimation.maneuvers import detect_maneuvers
from odpipe.media.apply import calibrated
from odpipe.media.ionosphere import IonexModel
from odpipe.media.model import MediaModel
from odpipe.od.arc import ManeuverPlan, a_priori_reference, fit_arc
from odpipe.od.outward import iteration_stages, labelled
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import RunConfig, load_config
from odpipe.pipeline.geometry import add_geometry, apparent_itrs, median_round_trip
from odpipe.pipeline.ingest import ingest
from odpipe.pipeline.fitted_trajectory import fitted_segments
from odpipe.preprocess.apriori_blunders import apriori_blunders
from odpipe.preprocess.lock_transient import lock_transients
from odpipe.preprocess.compress import compress
from odpipe.preprocess.edit import EditConfig, edit
from odpipe.preprocess.flags import Flag
from odpipe.preprocess.flags import summary as flag_summary
from odpipe.products import parameters, residuals
from odpipe.preprocess.stale_uplink import stale_uplink_range
from parsers.atomic import write_parquet, write_text
from odpipe.products.oem import write_oem
from odpipe.products.spk import write_spk
from odpipe.operations import rundir
from odpipe.operations.schema import ConfigError
from odpipe.numerics.precision import significant
from odpipe.operations.report import Section, write_report
from odpipe.time import tdb_to_utc
from odpipe.tracking import ramp_segments
from parsers.ionex import read_ionex
from parsers.trk223 import read_trk223


class RunLog:
    """Lines to the terminal (with elapsed time) and to the run's log file."""

    def __init__(self, progress):
        self.progress, self.lines, self.t0 = progress, [], time.perf_counter()

    def __call__(self, line: str, terminal: bool = True) -> None:
        stamped = f"[{time.perf_counter() - self.t0:7.1f} s] {line}"
        self.lines.append(stamped)
        if self.progress and terminal:
            self.progress(stamped)


def fitted_rows(table: pd.DataFrame, observables: list[str]) -> np.ndarray:
    """Rows of the configured observables: "observable", or "observable:BAND" for one downlink band; a
    running Doppler count (``doppler_count_<mode>``) is the ``doppler_<mode>`` row it is compressed into."""
    keep = np.zeros(len(table), bool)
    names = table["observable"].astype(str).str.replace("doppler_count_", "doppler_", regex=False).to_numpy()
    for entry in observables:
        obs, _, band = entry.partition(":")
        sel = names == obs
        keep |= sel & (table["band_down"].astype(str).to_numpy() == band) if band else sel
    return keep


def run_config(path, *, force: bool = False, progress=print) -> dict:
    """Run the arc of config ``path``; returns ``{"status": "complete" | "skipped", "run": folder, ...}``."""
    cfg = load_config(path)
    root = cfg.run.output / cfg.run.name
    source = cfg.initial_state.from_oem
    if source is not None and not source.exists():
        raise ConfigError(cfg.path, "initial_state.from_oem", f"{source} does not exist (run its arc first)")
    fingerprint = rundir.fingerprint(cfg.text, build.input_files(cfg))
    if not force and rundir.up_to_date(root, fingerprint):
        if progress:
            progress(f"{cfg.run.name}: unchanged since its last complete run, skipped ({root / 'current'})")
        return {"status": "skipped", "run": str(root / "current")}
    attempt = rundir.start(root)
    log = RunLog(progress)
    try:
        summary = _run(cfg, attempt, log, fingerprint)
        log(f"complete; products in {root / 'current'}")
        write_text(attempt.path / "run.log", "\n".join(log.lines) + "\n")
        attempt.finish(fingerprint, summary)
        return {"status": "complete", "run": str(root / "current"), **summary}
    except BaseException as exc:
        log(f"FAILED: {exc!r}")
        write_text(attempt.path / "run.log", "\n".join(log.lines) + "\n")
        attempt.fail(exc)
        raise


def _run(cfg: RunConfig, attempt, log: RunLog, fingerprint: dict) -> dict:
    data = ingest(cfg.data.files, cfg.data.errors, cfg.arc.spacecraft)
    for line in data.log:
        log(line)
    table = data.table[data.table["spacecraft"].astype(str) == cfg.arc.spacecraft].reset_index(drop=True)
    log(f"ingest: {len(table)} rows of spacecraft {cfg.arc.spacecraft} "
        f"({', '.join(f'{k} {v}' for k, v in table['observable'].value_counts().items())})")

    fm = build.force_model(cfg)
    catalog = build.station_catalog(cfg)
    setup = build.arc_setup(cfg, fm, data.store, catalog)
    shared: dict = {}   # reference segments: the a priori one integrated here is the fit's first
    apriori = a_priori_reference(setup, shared)
    table = add_geometry(table, apriori, fm.ephemeris, catalog)
    log(f"geometry: elevation and light time from the a priori trajectory ({apriori.n_eval} force evaluations)")

    cal = cfg.calibration
    if cal.media:
        model = MediaModel(read_trk223(*cal.tro, *cal.ion) if (cal.tro or cal.ion) else None,
                           IonexModel(read_ionex(*cal.ionex)) if cal.ionex else None, cal.standard_troposphere)

        def media(rows, trajectory):   # only the rows of the fitted observables are corrected
            return calibrated(rows, model, target_itrs=apparent_itrs(trajectory, fm.ephemeris), ramps=data.store,
                              catalog=catalog, order=None if cal.smoothing_order < 0 else cal.smoothing_order,
                              rows=fitted_rows(rows, cfg.data.observables))

        table = media(table, apriori)
        sources = table["media_source"].value_counts()
        sources = sources[(sources.index != "") & (sources > 0)].head(4)   # "": rows not corrected
        log(f"calibrate: media on {int(np.isfinite(table['media_m']).sum())} rows; sources: "
            + "; ".join(f"{k} ({v} rows)" for k, v in sources.items()))
    else:
        log("calibrate: media corrections off (calibration.media = false)")

    pre = cfg.preprocess
    if pre.lock_transient_k is not None:   # on the raw samples: compression would average them into a pass's first row
        lock = lock_transients(table, pre.lock_transient_k)
        table.loc[lock, "flags"] = table.loc[lock, "flags"] | int(Flag.BLUNDER)
        log(f"edit: raw Doppler samples in a lock transient {int(lock.sum())}"
            + "".join(f", {k} {v}" for k, v in table.loc[lock, "station_rx"].value_counts().sort_index().items()))
    rtlt = median_round_trip(table)
    n_raw = len(table)
    ramps = ramp_segments.store(data.ramps)   # compression's and editing's view of the ramps, built once
    table, creport = compress(table, pre.count_time, ramps=ramps, partial=pre.partial, ramp_delay=rtlt)
    log(f"compress: {n_raw} rows -> {len(table)} at {pre.count_time:g} s count time")
    table = table[fitted_rows(table, cfg.data.observables)].reset_index(drop=True)  # after: counts -> Hz
    log(f"observables fitted: {', '.join(f'{k} {v}' for k, v in table['observable'].value_counts().items())}")
    edit_cfg = EditConfig(min_elevation=np.radians(pre.elevation_mask_deg), blunder_k=pre.blunder_k,
                          min_pass_samples=pre.min_pass_samples, windows=[vars(w) for w in pre.edit_windows],
                          arc=(np.datetime64(cfg.arc.start, "ns"), np.datetime64(cfg.arc.end, "ns")))
    table, edits = edit(table, ramps, edit_cfg)
    if pre.range_uplink_epoch:
        table, removed = stale_uplink_range(table, data.ramps, pre.range_uplink_epoch)
        edits = flag_summary(table["flags"])
        log(f"range read at a stale uplink phase: {int(removed[1])} rows, {int(removed[0])} earlier in their ramp "
            "record removed")
    log("edit: " + ", ".join(f"{r} {n}" for r, n in zip(edits["reason"], edits["rows"]) if n))
    before = table.iloc[:0]   # rows edited before the fit by a test on the rows it is given (per-station counts)
    if pre.apriori_blunder_k is not None:
        bad = apriori_blunders(table, apriori, setup.measurements, cfg.arc.spacecraft, pre.apriori_blunder_k,
                               table["flags"].to_numpy() == 0)
        table.loc[bad, "flags"] = table.loc[bad, "flags"] | int(Flag.BLUNDER)
        before, edits = table[bad], flag_summary(table["flags"])
        log(f"edit: blunders against the a priori orbit {int(bad.sum())}")

    t0 = time.perf_counter()
    arc = _fit(table, setup, log, shared)
    if setup.outward is not None and cal.media:
        # the media came from the a priori orbit, far off away from its epoch: again from the fit, then refit
        setup, shared = replace(setup, state0=arc.states[0], outward=None), {}
        table = media(table, a_priori_reference(setup, shared))
        log("calibrate: media again along the outward fit's orbit; the whole arc fitted again from it")
        arc = _fit(table, setup, log, shared, after=(arc, "refit: media along the fitted orbit"))
    findings = unlogged_maneuvers(arc.residuals)
    log(f"innovation test for unlogged maneuvers: {len(findings)} finding(s)")
    sigma = cfg.estimation.detected_maneuver_sigma
    if len(findings) and sigma is not None:
        added = tuple(_detected_plan(k, f.after_tdb, f.epoch_tdb, sigma) for k, f in enumerate(findings.itertuples()))
        log(f"refit with {len(added)} detected maneuver(s) estimated ({sigma} m/s per axis a priori)")
        arc = _fit(table, replace(setup, maneuvers=tuple(setup.maneuvers) + added), log, shared,
                   after=(arc, "refit: detected maneuvers estimated"))
    fit_seconds = time.perf_counter() - t0
    return _products(cfg, attempt, log, table, arc, edits, fit_seconds, findings, fingerprint, data.ramps, before)


MAX_EPOCH_WINDOW_S = 600.0  # s: a burn found between rows closer than this also gets its epoch estimated


def _detected_plan(k: int, after: float, epoch: float, sigma: float) -> ManeuverPlan:
    """The impulsive maneuver estimated for a finding: in the middle of the window between the last quiet
    row and the first excess row, its epoch estimated within half that window; after a longer gap (no
    data to place it) at the gap's start, epoch not estimated."""
    half = 0.5 * (epoch - after)
    if 2 * half <= MAX_EPOCH_WINDOW_S:
        return ManeuverPlan(f"detected{k}", after + half, sigma=sigma, sigma_epoch=max(half, 1.0))
    return ManeuverPlan(f"detected{k}", after, sigma=sigma)


def _fit(table, setup, log, shared, after=None):
    """Fit the arc; ``after``: (the arc fitted before, label) of a refit, whose iterations stay first in the
    history (the summary counts every fit's), this fit's labelled."""
    t0 = time.perf_counter()
    arc = fit_arc(table, setup, shared)
    for h in arc.history:
        log(f"fit iteration: {json.dumps(h, default=float)}", terminal=False)  # the fit logged it live
    log(f"fit: {'converged' if arc.converged else 'NOT converged'} in {len(arc.history)} iterations, "
        f"{time.perf_counter() - t0:.1f} s")
    if after is not None:
        arc.history = after[0].history + labelled(arc.history, after[1])
    return arc


def unlogged_maneuvers(res: pd.DataFrame, window: int = 20, p_false: float = 1e-6) -> pd.DataFrame:
    """Suspected unlogged maneuvers: the chi-square window test of
    :func:`odpipe.estimation.maneuvers.detect_maneuvers` on the filter's normalized innovations of the
    fitted rows. Columns: ``after_tdb`` (last quiet row) and ``epoch_tdb`` (first excess row), TDB s,
    their UTC ``after``/``epoch``, ``statistic`` and ``threshold`` (chi-square over ``window`` rows)."""
    ok = (res["status"] == "") & np.isfinite(res["innovation"]) & (res["innovation_sigma"] > 0)
    r = res[ok].sort_values("time", kind="stable")
    found = detect_maneuvers(r["time"].to_numpy(), (r["innovation"] / r["innovation_sigma"]).to_numpy(),
                             window, p_false)
    out = pd.DataFrame([{"after_tdb": f.after, "epoch_tdb": f.epoch, "statistic": f.statistic,
                         "threshold": f.threshold} for f in found],
                       columns=["after_tdb", "epoch_tdb", "statistic", "threshold"])
    for col in ("after", "epoch"):
        out.insert(len(out.columns), col, tdb_to_utc(out[f"{col}_tdb"].to_numpy(float)) if len(out) else [])
    return out


def _products(cfg, attempt, log, table, arc, edits, fit_seconds, findings, fingerprint, ramps=None,
              before=None) -> dict:
    res = arc.residuals
    res["apriori_orbit_los"] = residuals.apriori_orbit_los(arc, table)
    stats = residuals.statistics(res, edited_before=before)
    write_parquet(attempt.product("tracking.parquet"), table)
    write_parquet(attempt.product("residuals.parquet"), res)
    write_text(attempt.product("residual_statistics.csv"), stats.to_csv(index=False))
    per_pass = residuals.statistics(res, by=("station_rx", "observable", "band", "pass_id"), edited_before=before)
    write_text(attempt.product("residual_statistics_passes.csv"), per_pass.to_csv(index=False))
    diag = station_diagnostics.diagnose(station_diagnostics.rows_used(res, table, ramps), params=arc.parameters)
    write_text(attempt.product("station_diagnostics.csv"), diag.to_csv(index=False))
    params = parameters.with_units(arc.parameters)
    write_text(attempt.product("parameters.csv"), params.to_csv(index=False))
    man_rows = man_stats = None
    if len(arc.maneuvers):
        mt = maneuver_report.flatten(arc.maneuvers)
        write_text(attempt.product("maneuvers.csv"), mt.to_csv(index=False))
        man_rows, man_stats = maneuver_report.evaluate(mt)
        write_text(attempt.product("maneuver_evaluation.csv"), man_stats.to_csv())
    arc.solution.save(attempt.product("solution.npz"))
    segments = fitted_segments(arc, cfg.products.step)
    name = cfg.products.object_name or cfg.arc.spacecraft
    prov = provenance(cfg, fingerprint, f"odpipe run {cfg.run.name}: smoothed solution")
    if cfg.products.oem:
        write_oem(attempt.product("trajectory.oem"), segments, name, cfg.arc.spacecraft, comments=prov)
    if cfg.products.spk:
        write_spk(attempt.product("trajectory.bsp"), segments, cfg.products.naif_id, comments=prov)
    figures = []
    if cfg.products.plots:
        for which, caption in (("prefit", "pre-fit residuals (on the a priori orbit)"),
                               ("postfit", "post-fit residuals")):
            png = attempt.product(f"residuals_{which}.png")
            residuals.plot(res, png, which, f"{cfg.run.name}: {caption}")
            figures.append((png, f"{caption}, along the line of sight (angles in degrees)"
                                 if any(res["unit"] == "rad") else f"{caption}, along the line of sight"))
    summary = _summary(cfg, arc, stats, fit_seconds)
    write_text(attempt.product("summary.json"), json.dumps(summary, indent=1, default=float))
    write_text(attempt.product("unlogged_maneuvers.csv"), findings.to_csv(index=False))
    write_report(attempt.product("report.html"), f"odpipe run {cfg.run.name}", _headline(summary),
                 _sections(cfg, res, stats, per_pass, diag, edits, params, figures, findings, man_rows, man_stats,
                           arc.maneuvers["epoch"].to_numpy(float) if len(arc.maneuvers) else None))
    log(f"products: OEM/SPK ({sum(len(s.t_tdb) for s in segments)} states in {len(segments)} segments), "
        "residuals, parameters, report.html")
    return summary


def provenance(cfg, fingerprint: dict, what: str) -> list[str]:
    """Comment lines naming what made a product: odpipe's version (and its source hash), the config
    (name, path, SHA-256) and the SHA-256 of every input file (``fingerprint``: :func:`rundir.fingerprint`)."""
    lines = [what, f"software: odpipe {__version__} (source sha256 {fingerprint['software_sha256']})",
             f"config: {cfg.run.name} {Path(cfg.path).resolve()} sha256 {fingerprint['config_sha256']}"]
    return lines + [f"input: {Path(p).name} sha256 {h}" for p, h in fingerprint["inputs"].items()]


def _sections(cfg, res, stats, per_pass, diag, edits, params, figures, findings, man_rows, man_stats,
              man_epochs) -> list[Section]:
    resid = Section("Residuals per station").text(
        "Along the line of sight: Doppler in mm/s, range in m" + ("; angles in m across it (range × angle), "
        "in degrees in the plots. " if any(res["unit"] == "rad") else ". ") + residuals.prefit_note(res) + " Post-fit: "
        "against the smoothed solution; the last column is the post-fit RMS in the observable's own unit. "
        "Each RMS to 3 significant figures, each mean to the first digit of its standard error "
        "(RMS/√n).").tables(residuals.report_tables(stats))
    for png, caption in figures:
        resid.figure(png, caption)
    diagnostics = Section("Station diagnostics (two-way Doppler)").text(station_diagnostics.summary(diag))
    if len(diag):
        diagnostics.table(*station_diagnostics.report_table(diag))
    sections = [resid, Section("Residuals per pass").tables(residuals.report_tables(per_pass)), diagnostics,
                Section("Editing").text("Where every row went: the preprocessing editors (a row with two reasons "
                                        "counts in both), then the fit; 'fitted' is the residual tables' used "
                                        "rows.").table(residuals.edit_summary(edits, res)),
                Section("Estimated parameters (epoch values; stochastic accelerations: first batch)").tables(
                    parameters.report_tables(params))]
    detected = Section("Unlogged maneuvers (innovation test)")
    detected.text(f"{len(findings)} finding(s): runs of 20 normalized filter innovations beyond the chi-square "
                  "1e-6 quantile" + ("; each was estimated as an impulsive maneuver (see the parameters)"
                                     if len(findings) and cfg.estimation.detected_maneuver_sigma is not None
                                     else ("; not estimated (estimation.detected_maneuver_sigma unset)"
                                           if len(findings) else ".")))
    if len(findings):
        detected.table(findings[["after", "epoch", "statistic", "threshold"]].rename(
            columns={"after": "last quiet row (UTC)", "epoch": "first excess row (UTC)",
                     "statistic": "window sum (chi-square)", "threshold": "threshold (chi-square)"}),
            {"window sum (chi-square)": "{:.1f}", "threshold (chi-square)": "{:.1f}"})
    sections.append(detected)
    if man_stats is not None:
        sections.append(Section("Maneuvers (designed − estimated)").tables(
            maneuver_report.report_tables(man_rows, man_stats, tdb_to_utc(man_epochs))))
    return sections


def _headline(summary: dict) -> dict:
    """The report's headline: the summary with its times and durations labelled, "post-fit" spelt as the
    report's tables spell it (summary.json keeps its keys), its RMS and sigmas written to their 3 significant
    figures (0.120, as the tables, not the float's 0.12), one line per fit of the arc."""
    names = {"start": "start (UTC)", "end": "end (UTC)", "fit_seconds": "fit time (s)",
             "iterations": "iterations (all fits)"}
    out = {names.get(k, k.replace("postfit RMS", "post-fit RMS", 1)):
           significant(v) if k.startswith(("postfit RMS", "epoch position sigma", "epoch velocity sigma")) else v
           for k, v in summary.items() if k != "iterations_per_fit"}
    out["iterations per fit"] = "\n".join(f"{s['fit']}{' ' + ' .. '.join(s['window']) if 'window' in s else ''}: "
                                          f"{s['iterations']}" for s in summary["iterations_per_fit"])
    return out


def _three(x) -> float:
    """An RMS or sigma to the 3 significant figures it carries (:func:`odpipe.numerics.precision.significant`)."""
    return float(significant(x))


def _summary(cfg, arc, stats, fit_seconds) -> dict:
    out = {"arc": cfg.run.name, "spacecraft": cfg.arc.spacecraft, "start": cfg.arc.start, "end": cfg.arc.end,
           "converged": bool(arc.converged), "iterations": len(arc.history),
           "iterations_per_fit": iteration_stages(arc.history), "fit_seconds": round(fit_seconds, 2)}
    for row in stats.itertuples(index=False):
        scale, unit = residuals.display_scale(row.observable)
        out[f"postfit RMS {row.observable} {row.station_rx} ({unit})"] = _three(row.postfit_rms * scale)
    sig = arc.covariances[0]
    out["epoch position sigma (m)"] = _three(np.sqrt(np.trace(sig[:3, :3])))
    out["epoch velocity sigma (mm/s)"] = _three(np.sqrt(np.trace(sig[3:, 3:])) * 1e3)
    return out
