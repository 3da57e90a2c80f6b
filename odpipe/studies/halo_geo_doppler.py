"""An L1 halo and a GEO satellite with two-way crosslink Doppler and high-fidelity dynamics (seed 000,
Fujimoto et al. secs. 3-4).

Truth: Earth-centred ICRF states of Table 1 at 2020-01-01 (UTC), point masses of the
Sun, Moon and planets (DE440; the paper: DE405) and a 20x20 Earth field on the GEO
satellite (GGM02C, as the paper). Filter: Sun, Moon and a 5x5 Earth field,
white RTN accelerations over 1000-s batches as state-noise compensation
(Q = 4e-14 (m/s^2)^2 per axis, eqs. 10-11), one constant Doppler bias, the
initial deviations of Table 3. Data: :func:`odpipe.measurements.compute`
'sst_doppler' (round-trip path change over the count time, light time solved),
every 1000 s for 19.9957 d, white noise and a constant bias, rows with the link
through the Earth removed and, as in the paper, no tracking while the GEO satellite's
|v_x| < 1500 m/s (``filter.geo_cutoff_vx_mps``; v_x of the truth, the paper's estimate is
within cm/s of it). Estimators over :class:`odpipe.od.problem.TrackingProblem` (``estimators``):
odpipe's iterated filter-smoother and the paper's single EKF pass (:mod:`.ekf`); accuracy =
truth - filtered, RMS over the last half of the arc per axis (Tables 4-5; Table 6, the S band
with the L1 state known: ``known_bands``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import EGM96_RADIUS, SECONDS_PER_DAY
from odpipe.dynamics.forces import ForceModel, PointMasses, SphericalHarmonics
from odpipe.dynamics.propagator import propagate
from odpipe.environment.gravity import read_gravity
from odpipe.estimation.fit import FitOptions, Observations, build_grid, fit
from odpipe.estimation.registry import ParameterRegistry
from odpipe.measurements import MeasurementSetup, compute
from odpipe.od.problem import TrackingProblem
from odpipe.time import utc_to_tdb
from parsers.table import build

from .ekf import ekf
from .study_report import plot_convergence, write_markdown, write_table

DAY = SECONDS_PER_DAY
R_EARTH = EGM96_RADIUS
NAMES = ("L1", "GEO")
ESTIMATORS = """
Estimators, each on the same data (accuracy = truth minus the forward filter's estimate):

- filter_smoother: odpipe's iterated square-root information filter-smoother, relinearized about the
  smoothed solution on growing arcs (``stage_days``); the forward filter of its last iteration.
- ekf: the paper's estimator, one extended Kalman filter pass (:mod:`odpipe.studies.ekf`, Joseph update,
  reference reset to the estimate after every point) with the same SNC (white accelerations over each
  1000-s interval, also through the data gaps).
- ekf_gap_snc: the same pass with eqs. 10-11 taken literally: Gamma Q Gamma^T over the time since the
  previous point, so a gap of n intervals adds n^2 times one interval's velocity variance.
"""
DIFFERENCES = """\
- Filter: see the estimators above; the paper names only an EKF.
- Table 6 ("perfect L1 state knowledge", the a priori covariance "reduced to 0"): the L1 a priori has
  no deviation and sigmas of 1 mm and 1 um/s (``known_*``); its SNC stays, as eq. 10 is per spacecraft.
- What limits the accuracy: the paper's S- and X-band accuracies are nearly equal (L1 293 and 296 m)
  although the Doppler noise differs 10x, so its accuracy is not set by the data noise; it names
  growing numerical integration errors as what spoils its bias estimate. odpipe integrates to 1e-12
  (relative), and its X-band errors are 2-2.4x below its S-band ones, as noise-limited estimates are.
- State-noise compensation: Q = 4e-14 (m/s^2)^2 per axis as white accelerations held over each 1000-s
  data interval. With one Doppler point per interval they absorb much of the noise: post-fit residuals
  are 0.76 sigma (S) and 0.06 sigma (X); the paper's X-band post-fit RMS, 2.03e-5 m/s, is 0.2 sigma.
- GEO cut-off: no data while the GEO satellite's |v_x| < 1500 m/s (the paper: "absolute velocity in
  the x-direction ... less than 1500 m/s"), taken from the truth rather than the estimate.
- Not given in the paper, chosen here: the count time (60 s), the bias a priori (1 mm/s on the line
  of sight), the a priori of Table 1 read as variances (100 m, 0.1 m/s), the noise draws (``seed``).
- Models: DE440 (paper DE405); GGM02C, as the paper.
"""


def force_models(cfg, eph, which: str) -> dict:
    """'truth' or 'filter' force models by spacecraft (Earth-centred)."""
    d = cfg[which]
    field = read_gravity(Path(cfg["gravity_file"]))
    out = {}
    for sc in NAMES:
        comps = [PointMasses(list(d["bodies"]))]
        deg = d["earth_degree"].get(sc, 0)
        if deg:
            comps.append(SphericalHarmonics("earth", field.truncated(deg), deg))
        out[sc] = ForceModel("earth", comps, ephemeris=eph)
    return out


def _rows(epochs, cfg):
    n = epochs.size
    return build(n, epoch=epochs, observable="sst_doppler", unit="m/s", station_tx="", station_rx="",
                 spacecraft="L1", spacecraft_2=np.array(["GEO"] * n, dtype=object), tag="interval_end",
                 count_time=cfg["count_time_s"], band_up="", band_down="", uplink_hz=np.nan, ramped=False,
                 transponder_ratio=np.nan, value=0.0, sigma=np.nan, pass_id=0, flags=0,
                 source="simulated", record=np.arange(n))


def link_clear(r1, r2) -> np.ndarray:
    """True where the segment r1-r2 (Earth-centred, m) misses the Earth."""
    d = r2 - r1
    s = np.clip(-np.einsum("ij,ij->i", r1, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return np.linalg.norm(r1 + s[:, None] * d, axis=1) > R_EARTH


def simulate(cfg: dict, log=print) -> dict:
    """Truth, the tracked epochs and one noisy data set per band (drawn in the bands' order):
    {meas, t0, t1, x0, truth, times, to_los, data (band -> rows), tracked, epochs}."""
    meas = MeasurementSetup.default()
    t0 = float(utc_to_tdb(np.datetime64(cfg["epoch_utc"], "ns")))
    t1 = t0 + cfg["arc_days"] * DAY
    x0 = {sc: np.asarray(cfg["state"][sc], float) for sc in NAMES}
    truth_fm = force_models(cfg, meas.ephemeris, "truth")
    truth = {sc: propagate(x0[sc], t0, t1 + 60.0, truth_fm[sc]) for sc in NAMES}   # data start at t0 + interval
    log("truth propagated")
    step = np.timedelta64(int(cfg["interval_s"] * 1e9), "ns")
    start = np.datetime64(cfg["epoch_utc"], "ns")
    epochs = np.arange(start + step, start + np.timedelta64(int(cfg["arc_days"] * DAY * 1e9), "ns"), step)
    t_rx = np.asarray(utc_to_tdb(epochs), float)
    clear = link_clear(truth["L1"].state(t_rx)[:, :3], truth["GEO"].state(t_rx)[:, :3])
    cutoff = cfg["filter"].get("geo_cutoff_vx_mps", 0.0)
    tracked = clear & (np.abs(truth["GEO"].state(t_rx)[:, 3]) >= cutoff)
    log(f"{clear.sum()} of {clear.size} epochs with a clear link, {tracked.sum()} with GEO |vx| >= {cutoff} m/s")
    rows = _rows(epochs[tracked], cfg).reset_index(drop=True)
    ev = compute(rows, truth, meas)
    if (ev.status != "").any():
        raise RuntimeError(f"rows the models cannot compute: {set(ev.status[ev.status != ''])}")
    rng = np.random.default_rng(cfg["seed"])
    data = {}
    for band in cfg["bands"]:
        b = cfg["band"][band]
        data[band] = rows.copy()
        data[band]["value"] = ev.value + b["bias_mps"] + rng.normal(size=len(rows)) * b["sigma_mps"]
        data[band]["sigma"] = b["sigma_mps"]
    return {"meas": meas, "t0": t0, "t1": t1, "x0": x0, "truth": truth, "times": t_rx[tracked],
            "to_los": float(np.unique(ev.to_los)[0]),             # 1/2: round-trip path rate to LOS rate
            "data": data, "tracked": int(tracked.sum()), "epochs": int(tracked.size)}


def cases(cfg) -> list[tuple[str, str, str | None]]:
    """(case, band, known spacecraft) of the run: each band, then ``known_bands`` with the L1 state known."""
    return [(band, band, None) for band in cfg["bands"]] + [(f"{b}_L1_known", b, "L1") for b in cfg["known_bands"]]


def evaluate(cfg, sim: dict, case: str, band: str, known, estimator: str, log=print) -> tuple[dict, list[dict]]:
    """One estimator on one case: its result and the table rows (3-D and per-axis RMS over the last half
    beside the paper's ``[paper.<case>]``)."""
    t0, t1 = sim["t0"], sim["t1"]
    res = _fit(cfg, sim["meas"], sim["data"][band], sim["times"], sim["to_los"], sim["x0"], t0, t1, estimator,
               known, log)
    grid = res["grid"]
    half = grid >= t0 + 0.5 * (t1 - t0)
    truth_g = np.concatenate([sim["truth"][sc].state(grid) for sc in NAMES], axis=1)
    res["error"] = res["filtered"][:, :12] - truth_g
    rms = np.sqrt(np.mean(res["error"][half] ** 2, axis=0))
    paper, table = cfg["paper"][case], []
    for i, sc in enumerate(NAMES):
        for what, off, unit in (("Pos", 0, "m"), ("Vel", 3, "m/s")):
            ref = paper.get(f"{sc}_{what.lower()}")
            if ref is None:                      # Table 6 gives the GEO satellite only
                continue
            r = rms[6 * i + off: 6 * i + off + 3]
            table.append({"case": case, "estimator": estimator, "spacecraft": sc, "quantity": f"{what} RMS [{unit}]",
                          "paper x": ref[0], "paper y": ref[1], "paper z": ref[2], "paper 3D": ref[3],
                          "odpipe x": r[0], "odpipe y": r[1], "odpipe z": r[2], "odpipe 3D": float(np.sqrt(np.sum(r**2))),
                          "odpipe/paper 3D": float(np.sqrt(np.sum(r**2)) / ref[3])})
    log(f"{case} {estimator}: bias estimate {res['bias']:.3e} +- {res['bias_sigma']:.1e} m/s (truth "
        f"{cfg['band'][band]['bias_mps']}), post-fit RMS {res['postfit_rms']:.3e} m/s")
    return res, table


def run(cfg: dict, out, log=print) -> dict:
    sim = simulate(cfg, log)
    t0 = sim["t0"]
    results, panels, tables = {}, [], []
    for case, band, known in cases(cfg):
        for estimator in cfg["estimators"]:
            res, rows = evaluate(cfg, sim, case, band, known, estimator, log)
            results[(case, estimator)] = res
            tables += rows
            if estimator != cfg["estimators"][0]:
                continue
            sig = np.sqrt(np.diagonal(res["filtered_P"], axis1=1, axis2=2))
            for i, sc in enumerate(NAMES):
                if sc == known:
                    continue
                c = slice(6 * i, 6 * i + 3)
                panels.append({"title": f"{case} {sc} position (m), {estimator}", "t_days": (res["grid"] - t0) / DAY,
                               "curves": [("|truth - filtered|", np.linalg.norm(res["error"][:, c], axis=1),
                                           {"color": "k"}),
                                          ("3-D 3-sigma", 3 * np.linalg.norm(sig[:, c], axis=1),
                                           {"color": "k", "ls": ":"})]})
    table = pd.DataFrame(tables)
    plot_convergence(out, "convergence", panels, "m")
    notes = "\n".join(f"- {case}, {est}: bias {r['bias']:.3e} +- {r['bias_sigma']:.1e} m/s, post-fit residual RMS "
                      f"{r['postfit_rms']:.3e} m/s{'' if r['converged'] is None else ', converged ' + str(r['converged'])}"
                      for (case, est), r in results.items())
    notes += (f"\n- paper: X-band post-fit RMS {cfg['paper']['X']['postfit_rms_mps']} m/s; {sim['tracked']} of "
              f"{sim['epochs']} epochs tracked (link clear of the Earth, GEO |v_x| >= "
              f"{cfg['filter'].get('geo_cutoff_vx_mps', 0.0)} m/s); truth bias per band "
              + ", ".join(f"{band} {cfg['band'][band]['bias_mps']} m/s" for band in cfg["bands"]))
    write_markdown(out, "Study halo_geo_doppler: GEO + EML1 halo, two-way crosslink Doppler (Fujimoto et al. secs. 3-4)",
                   [("Tables 4-6: accuracy RMS over the last half, paper vs odpipe by estimator",
                     write_table(out, "tables456", table) + ESTIMATORS + "\n![convergence](convergence.png)\n"),
                    ("Fit", notes + "\n"), ("Differences from the paper's set-up", DIFFERENCES)])
    return {"table": table, "results": results}


def _registry(cfg, x0, known) -> ParameterRegistry:
    """States (a priori = truth + Table 3 deviation; a ``known`` spacecraft: truth, sigma ``known_*``),
    the SNC accelerations (white over each data interval), the Doppler bias."""
    f = cfg["filter"]
    reg = ParameterRegistry()
    for sc in NAMES:
        if sc == known:
            reg.add_state(sc, x0[sc], f["known_pos_m"], f["known_vel_mps"])
        else:
            reg.add_state(sc, x0[sc] + np.asarray(cfg["deviation"][sc], float), f["apriori_pos_m"], f["apriori_vel_mps"])
    for sc in NAMES:
        reg.add_stochastic_acceleration(sc, f["snc_sigma_mps2"], 0.0, cfg["interval_s"])
    reg.add("bias.sst_doppler", "bias", 0.0, f["bias_sigma_los_mps"], owner="L1", observable="sst_doppler")
    return reg


def _fit(cfg, meas, rows, times, to_los, x0, t0, t1, estimator, known, log):
    """One estimator on one data set: 'filter_smoother' (odpipe's), 'ekf' (one pass, SNC per data
    interval) or 'ekf_gap_snc' (one pass, eqs. 10-11 over each gap between data)."""
    if estimator == "filter_smoother":
        return _filter_smoother(cfg, meas, rows, times, to_los, x0, t0, t1, known, log)
    gap = estimator == "ekf_gap_snc"
    reg = _registry(cfg, x0, known)
    fm = force_models(cfg, meas.ephemeris, "filter")
    grid, _ = build_grid(reg, t0, t1, cfg["interval_s"])
    prob, dynamics = (TrackingProblem(reg, rows.iloc[sel], times[sel], fm, meas, t0, t1,
                                      lookback=2 * cfg["count_time_s"] + 60.0, epochs=grid)
                      for sel in (slice(None), slice(0)))            # the rows, and none for the transitions
    obs = Observations(times, rows["value"].to_numpy(float), rows["sigma"].to_numpy(float), np.zeros(len(rows), int))
    starts = [reg.index(f"{sc}.x") for sc in NAMES]
    q = cfg["filter"]["snc_sigma_mps2"] ** 2
    res = ekf(prob, obs, t0, t1, cfg["interval_s"], gap_snc=(q, starts) if gap else None, dynamics=dynamics)
    ib = reg.index("bias.sst_doppler")
    return {"grid": res.grid, "filtered": res.x, "filtered_P": res.P, "bias": float(res.x[-1, ib] / to_los),
            "bias_sigma": float(np.sqrt(res.P[-1, ib, ib]) / to_los),
            "postfit_rms": float(np.sqrt(np.nanmean(res.postfit**2))), "converged": None}


def _filter_smoother(cfg, meas, rows, times, to_los, x0, t0, t1, known, log):
    f = cfg["filter"]
    reg = _registry(cfg, x0, known)
    opts = FitOptions(max_iter=f["max_iter"], block=cfg["interval_s"])
    fm = force_models(cfg, meas.ephemeris, "filter")
    x_ref = None
    for days in list(f["stage_days"]) + [None]:     # relinearize on growing arcs (a priori unchanged)
        end = t1 if days is None else min(t1, t0 + days * DAY)
        sel = times <= end
        grid, _ = build_grid(reg, t0, end, opts.block)
        prob = TrackingProblem(reg, rows[sel].reset_index(drop=True), times[sel], fm, meas, t0, end,
                               lookback=2 * cfg["count_time_s"] + 60.0, epochs=grid)
        obs = Observations(times[sel], rows["value"].to_numpy(float)[sel], rows["sigma"].to_numpy(float)[sel],
                           np.zeros(int(sel.sum()), int))
        sol = fit(prob, obs, t0, end, opts, x_ref=x_ref)
        x_ref = sol.smoothed_x[0]
        log(f"  arc to {(end - t0) / DAY:.1f} d: {len(sol.history)} iterations, post-fit RMS "
            f"{sol.history[-1]['postfit_rms']:.3f} (whitened), converged {sol.converged}")
    ib = reg.index("bias.sst_doppler")
    post = sol.residuals["postfit"].to_numpy()
    return {"grid": sol.grid, "filtered": sol.filtered_x, "filtered_P": sol.filtered_P,
            "bias": float(sol.smoothed_x[0, ib] / to_los), "bias_sigma": float(np.sqrt(sol.smoothed_P[0, ib, ib]) / to_los),
            "postfit_rms": float(np.sqrt(np.nanmean(post**2))), "converged": sol.converged}
