"""Ground tracking of an Earth-Moon L1 halo orbiter and a GEO satellite, with and without LiAISON
crosslinks (seed 004, Leonard 2015, sec. 8.1).

Set-up (thesis secs. 8.1.1-8.1.2, Tables 8.1-8.3): epoch 2020-01-01, a 9-day arc sampled every
100 s. Truth: Earth point mass, Sun, Moon and the planets (DE440; thesis DE405), cannonball SRP
(A/m 0.01 m^2/kg, Cr 1, conical shadows); the GEO satellite also feels GGM02C to 20x20. The
halo orbiter starts from the Table 1 state of seed 000 (the same group's GEO + L1 constellation
at the same epoch: a northern L1 halo of z amplitude 30,000-40,000 km over the arc; the thesis
corrects an A_z = 35,500 km Richardson halo into its ephemeris model instead). The GEO
satellite starts geostationary over 0.10963 N, 80.26889 W (sec. 8.1.1.2).

Data (all models of :func:`odpipe.measurements.compute`, light time solved; the thesis uses
instantaneous range and range-rate): the L1 orbiter's two-way range (m) and X-band two-way
Doppler from the DSN station of Table 8.2 highest above the mask; the GEO satellite's from
Sky Valley; the LiAISON two-way range and round-trip Doppler between the two (rows with the
link through the Earth dropped). White noise of Table 8.3 (Doppler sigmas along the line of
sight) and constant range biases drawn from the Table 8.3 sigmas, one per station and one
for the crosslink. Schedules (sec. 8.1.2.3): (LiAISON gap, ground gap) in hours after each
3-h pass, both starting at epoch; ``inf`` = that data type is not used.

Filter (Table 8.3): epoch states with a priori 1 km / 1 mm/s and initial errors drawn from
them, an SRP scale per spacecraft (20 %, a priori value drawn), Gauss-Markov RTN accelerations
(steady-state 5e-10, 1e-12, 1e-12 m/s^2; correlation time ``acc_tau_s`` and constant batches of
``acc_batch_s``, which the thesis does not give), the five range biases;
dynamics Sun, Moon and Earth, GGM05S 20x20 on the GEO satellite (thesis: a 3-sigma clone of
GGM02C). odpipe's iterated filter-smoother; the figures use the forward filter as the
thesis' EKF: RMS over days 6-9 of the 3-D position error and of the 3-D 3-sigma (Fig. 8.4).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.constants import SECONDS_PER_DAY
from odpipe.dynamics.forces import ForceModel, PointMasses, SolarRadiationPressure, SphericalHarmonics
from odpipe.dynamics.propagator import propagate
from odpipe.environment.gravity import read_gravity
from odpipe.environment.stations import Station, StationCatalog, geodetic_to_itrs
from odpipe.estimation.fit import FitOptions, Observations, build_grid, fit
from odpipe.estimation.registry import ParameterRegistry
from odpipe.frames.earth import itrs_to_gcrs_state
from odpipe.measurements import MeasurementSetup, compute
from odpipe.od.problem import TrackingProblem
from odpipe.simulate.schedule import StateOnly, elevation
from odpipe.time import utc_to_tdb
from parsers.table import build

from .halo_geo_doppler import link_clear
from .study_report import plot_convergence, spread, write_markdown, write_table

DAY = SECONDS_PER_DAY
NAMES = ("L1", "GEO")
MASS_KG = 1000.0                 # only A/m matters
EARTH_RATE = 7.2921158553e-5     # rad/s
X_UPLINK_HZ = 7.19e9


def station_catalog(cfg) -> StationCatalog:
    """The thesis' stations (Table 8.2: geodetic lat, lon deg, height km)."""
    return StationCatalog([Station(name, geodetic_to_itrs(np.radians(lat), np.radians(lon), 1e3 * h))
                           for name, (lat, lon, h) in cfg["stations"].items()], "thesis Table 8.2")


def geo_state(cfg, t0: float, gm: float) -> np.ndarray:
    """GCRS state (m, m/s) at TDB ``t0`` of a geostationary satellite over cfg['geo'] lat/lon (deg)."""
    lat, lon = np.radians(cfg["geo"]["lat_deg"]), np.radians(cfg["geo"]["lon_deg"])
    r = (gm / EARTH_RATE**2) ** (1 / 3)
    r_itrs = r * np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    pos, vel = itrs_to_gcrs_state(np.array([t0]), r_itrs[None, :])
    return np.concatenate([pos[0], vel[0]])


def force_models(cfg, eph, which: str) -> dict:
    """'truth' or 'filter' force models by spacecraft (Earth-centred, SRP scale 1)."""
    d = cfg[which]
    field = read_gravity(Path(d["gravity_file"]))
    out = {}
    for sc in NAMES:
        comps = [PointMasses(list(d["bodies"])),
                 SolarRadiationPressure(cr_area=cfg["srp"]["cr"] * cfg["srp"]["area_to_mass"] * MASS_KG)]
        deg = d["earth_degree"].get(sc, 0)
        if deg:
            comps.append(SphericalHarmonics("earth", field.truncated(deg), deg))
        out[sc] = ForceModel("earth", comps, mass=MASS_KG, ephemeris=eph)
    return out


def _link_rows(epochs, obs_range, obs_rate, link, **cols) -> pd.DataFrame:
    """Range (m, at reception) and Doppler (count-averaged, tagged at the interval end) rows of one link."""
    n = epochs.size
    rng = build(n, epoch=epochs, observable=obs_range, unit="m", tag="receive", **cols)
    rate = build(n, epoch=epochs, observable=obs_rate, unit="m/s" if obs_rate == "sst_doppler" else "Hz",
                 tag="interval_end", **cols)
    out = pd.concat([rng, rate], ignore_index=True)
    out["link"] = link
    return out


def tracking_rows(cfg, truth: dict, setup: MeasurementSetup, start: np.datetime64) -> pd.DataFrame:
    """Every candidate row of the arc (noise-free values, ordered by time) with 'link'
    ('dsn', 'geo', 'sst'), 'time' (TDB s) and 'to_los' columns."""
    step = np.timedelta64(int(cfg["interval_s"] * 1e9), "ns")
    epochs = np.arange(start + step, start + np.timedelta64(int(cfg["arc_days"] * DAY * 1e9), "ns"), step)
    mask = np.radians(cfg["mask_deg"])
    common = dict(count_time=cfg["count_time_s"], band_up="X", band_down="X", uplink_hz=X_UPLINK_HZ,
                  ramped=False, source="simulated", pass_id=0)
    el = np.array([elevation(truth["L1"], setup, st, "L1", epochs) for st in cfg["dsn"]])
    best = np.argmax(el, axis=0)
    up = el[best, np.arange(epochs.size)] > mask
    dsn = _link_rows(epochs[up], "range", "doppler_2way", "dsn", spacecraft="L1",
                     station_tx=np.array(cfg["dsn"], object)[best[up]],
                     station_rx=np.array(cfg["dsn"], object)[best[up]], **common)
    g = cfg["geo_station"]
    seen = elevation(truth["GEO"], setup, g, "GEO", epochs) > mask
    geo = _link_rows(epochs[seen], "range", "doppler_2way", "geo", spacecraft="GEO", station_tx=g, station_rx=g,
                     **common)
    t = np.asarray(utc_to_tdb(epochs), float)
    clear = link_clear(truth["L1"].state(t)[:, :3], truth["GEO"].state(t)[:, :3])
    sst = _link_rows(epochs[clear], "sst_range", "sst_doppler", "sst", spacecraft="L1", spacecraft_2="GEO",
                     station_tx="", station_rx="", **{k: v for k, v in common.items() if k != "uplink_hz"})
    rows = pd.concat([dsn, geo, sst], ignore_index=True)
    rows["spacecraft_2"] = rows["spacecraft_2"].fillna("")
    rows = rows.sort_values("epoch", kind="stable").reset_index(drop=True)
    ev = compute(rows, {sc: StateOnly(tr) for sc, tr in truth.items()}, setup)
    if (ev.status != "").any():
        raise RuntimeError(f"rows the models cannot compute: {set(ev.status[ev.status != ''])}")
    rows["value"] = ev.value
    rows["to_los"] = np.abs(ev.to_los)
    rows["time"] = np.asarray(utc_to_tdb(rows["epoch"].to_numpy("datetime64[ns]")), float)
    return rows


def bias_parameters(cfg) -> list[tuple]:
    """(name, sigma m, info) of the estimated range biases: one per station and one for the crosslink."""
    f = cfg["filter"]
    out = [(f"bias.range.{st}", f["dsn_bias_m"], {"observable": "range", "station": st}) for st in cfg["dsn"]]
    out.append((f"bias.range.{cfg['geo_station']}", f["geo_bias_m"],
                {"observable": "range", "station": cfg["geo_station"]}))
    out.append(("bias.sst_range", f["sst_bias_m"], {"observable": "sst_range"}))
    return out


def observe(cfg, rows: pd.DataFrame, rng) -> pd.DataFrame:
    """Rows with white noise (Table 8.3, along the line of sight) and the true range biases added;
    'sigma' in row units; the drawn biases in ``rows.attrs['bias']`` (m)."""
    noise = cfg["noise"]
    out = rows.copy()
    sig_los = np.empty(len(out))
    is_range = (out["unit"] == "m").to_numpy()
    for link in ("dsn", "geo", "sst"):
        for kind in ("range", "rate"):
            sel = (out["link"] == link).to_numpy() & (is_range == (kind == "range"))
            sig_los[sel] = noise[f"{link}_{kind}"]
    out["sigma"] = sig_los / out["to_los"].to_numpy()
    out["value"] = out["value"] + out["sigma"] * rng.normal(size=len(out))
    biases = {}
    for name, sigma, info in bias_parameters(cfg):
        biases[name] = float(rng.normal() * sigma)
        sel = (out["observable"] == info["observable"]).to_numpy().copy()
        if "station" in info:
            sel &= (out["station_rx"] == info["station"]).to_numpy()
        out.loc[sel, "value"] += biases[name]
    out.attrs["bias"] = biases
    return out


def scheduled(t_rel: np.ndarray, gap_h: float, pass_h: float) -> np.ndarray:
    """True at times t_rel (s past epoch) inside a ``pass_h`` pass of a pass/gap cycle; all False for an infinite gap."""
    if not np.isfinite(gap_h):
        return np.zeros(t_rel.shape, bool)
    return np.mod(t_rel, 3600.0 * (pass_h + gap_h)) < 3600.0 * pass_h


def case_rows(cfg, rows: pd.DataFrame, case: dict, t0: float) -> pd.DataFrame:
    """The rows a schedule {liaison_gap_h, ground_gap_h[, ground_offset_h]} uses (the ground passes
    start ``ground_offset_h`` after the epoch, sec. 8.1.2.4; 0 by default)."""
    t_rel = rows["time"].to_numpy() - t0
    sst = (rows["link"] == "sst").to_numpy()
    t_ground = t_rel - 3600.0 * case.get("ground_offset_h", 0.0)
    keep = np.where(sst, scheduled(t_rel, case["liaison_gap_h"], cfg["pass_h"]),
                    (t_ground >= 0) & scheduled(t_ground, case["ground_gap_h"], cfg["pass_h"]))
    return rows[keep].reset_index(drop=True)


def initial_guess(cfg, x0: dict, rng) -> dict:
    """A priori epoch states and SRP scales, drawn about the truth from the Table 8.3 sigmas."""
    f = cfg["filter"]
    sig = np.array([f["apriori_pos_m"]] * 3 + [f["apriori_vel_mps"]] * 3)
    return {sc: (x0[sc] + sig * rng.normal(size=6), 1.0 + f["srp_sigma"] * rng.normal()) for sc in NAMES}


def registry(cfg, guess: dict) -> ParameterRegistry:
    """States, SRP scales, Gauss-Markov RTN accelerations and range biases (Table 8.3)."""
    f = cfg["filter"]
    reg = ParameterRegistry()
    for sc in NAMES:
        reg.add_state(sc, guess[sc][0], f["apriori_pos_m"], f["apriori_vel_mps"])
    for sc in NAMES:
        reg.add(f"{sc}.srp_scale", "dynamic", guess[sc][1], f["srp_sigma"], owner=sc, model="srp_scale")
    for sc in NAMES:
        for axis, sigma in zip("RTN", f["acc_sigma_rtn"]):
            reg.add_stochastic_acceleration(sc, sigma, f["acc_tau_s"], f["acc_batch_s"], axes=(axis,))
    for name, sigma, info in bias_parameters(cfg):
        reg.add(name, "bias", 0.0, sigma, owner="", **info)
    return reg


def _problem(cfg, setup, rows: pd.DataFrame, reg, fm: dict, t0: float, t1: float, shared=None) -> TrackingProblem:
    """The fit's TrackingProblem over ``rows`` (``shared``: segments already flown, see TrackingProblem)."""
    grid, _ = build_grid(reg, t0, t1, cfg["filter"]["block_s"])
    return TrackingProblem(reg, rows, rows["time"].to_numpy(), fm, setup, t0, t1, lookback=cfg["count_time_s"] + 60.0,
                           epochs=grid, shared=shared)


def fit_case(cfg, setup, rows: pd.DataFrame, guess: dict, fm: dict, t0: float, t1: float, shared=None):
    """Fit one schedule's rows (``shared``: segments already flown, e.g. :func:`apriori_segments`); returns the
    odpipe Solution and the registry."""
    reg = registry(cfg, guess)
    opts = FitOptions(max_iter=cfg["filter"]["max_iter"], block=cfg["filter"]["block_s"])
    prob = _problem(cfg, setup, rows, reg, fm, t0, t1, shared)
    obs = Observations(prob.times, rows["value"].to_numpy(float), rows["sigma"].to_numpy(float),
                       np.zeros(len(rows), int))
    return fit(prob, obs, t0, t1, opts), reg


def apriori_segments(cfg, sim: dict) -> dict:
    """The reference every schedule's fit flies first (from the a priori states and SRP scales, the stochastic
    accelerations at zero: the same for every schedule and filter setting), flown once per set-up and kept in
    ``sim``: a fresh copy of TrackingProblem's ``shared`` segments for each fit (its later passes add theirs)."""
    if "apriori_segments" not in sim:
        shared = {}
        reg = registry(cfg, sim["guess"])
        _problem(cfg, sim["setup"], sim["rows"].iloc[:0], reg, sim["fm"], sim["t0"], sim["t1"],
                 shared).reference(reg.apriori)
        sim["apriori_segments"] = shared
    return dict(sim["apriori_segments"])


def fit_schedule(cfg, sim: dict, case: dict, cfg_fit=None) -> dict:
    """One schedule on the :func:`prepare` set-up ``sim`` (filter settings of ``cfg_fit``, default
    ``cfg``): {solution, registry, metrics, rows}. Fits are kept in ``sim`` by schedule and settings, so a
    schedule asked for again (the trade study's diagonal is also in its mesh) is not refitted."""
    cfg_fit = cfg_fit or cfg
    key = json.dumps([case["liaison_gap_h"], case["ground_gap_h"], case.get("ground_offset_h", 0.0),
                      cfg["pass_h"], cfg["window_days"]]
                     + [cfg_fit[k] for k in ("filter", "dsn", "geo_station", "count_time_s")])
    fits = sim.setdefault("fits", {})
    if key not in fits:
        rows = case_rows(cfg, sim["rows"], case, sim["t0"])
        sol, reg = fit_case(cfg_fit, sim["setup"], rows, sim["guess"], sim["fm"], sim["t0"], sim["t1"],
                            apriori_segments(cfg, sim))
        fits[key] = {"solution": sol, "registry": reg, "rows": rows,
                     "metrics": position_metrics(sol, sim["truth"], sim["t0"], cfg["window_days"])}
    return fits[key]


def position_metrics(sol, truth: dict, t0: float, window_days, level_m: float = 100.0) -> dict:
    """Per spacecraft: filtered 3-D error and 3-sigma (m) on the grid, their RMS over the window,
    the final 3-sigma, the day after which the 3-sigma stays below ``level_m`` and the mean
    normalized error squared e^T P^-1 e / 3 over the window (1 for a consistent filter)."""
    grid = sol.grid
    win = (grid >= t0 + window_days[0] * DAY) & (grid <= t0 + window_days[1] * DAY)
    out = {}
    for i, sc in enumerate(NAMES):
        c = slice(6 * i, 6 * i + 3)
        e = sol.filtered_x[:, c] - truth[sc].state(grid)[:, :3]
        P = sol.filtered_P[:, c, c]
        sig3 = 3.0 * np.sqrt(np.trace(P, axis1=1, axis2=2))
        nees = np.einsum("ni,ni->n", e, np.linalg.solve(P, e[:, :, None])[:, :, 0]) / 3.0
        err = np.linalg.norm(e, axis=1)
        above = np.flatnonzero(sig3 >= level_m)
        if not above.size:
            below = 0.0
        elif above[-1] == grid.size - 1:
            below = np.nan                 # never stays below
        else:
            below = (grid[above[-1] + 1] - t0) / DAY
        out[sc] = {"err": err, "sig3": sig3, "rms_err": float(np.sqrt(np.mean(err[win] ** 2))),
                   "rms_sig3": float(np.sqrt(np.mean(sig3[win] ** 2))), "final_sig3": float(sig3[-1]),
                   "below100_d": float(below), "nees": float(np.mean(nees[win]))}
    return out


def table_rows(name: str, case: dict, m: dict, paper: dict) -> list[dict]:
    """Report rows of one case: the thesis' figures (NaN where it gives none) beside odpipe's."""
    out = []
    for sc in NAMES:
        ref = {k: paper.get(f"{sc}_{k}", np.nan) for k in ("rms_sig3", "final_sig3", "below100_d")}
        out.append({"case": name, "(LiAISON, ground) gap h": f"({case['liaison_gap_h']:g}, {case['ground_gap_h']:g})",
                    "spacecraft": sc,
                    "thesis 3s RMS d6-9": ref["rms_sig3"], "odpipe 3s RMS d6-9": m[sc]["rms_sig3"],
                    "thesis final 3s": ref["final_sig3"], "odpipe final 3s": m[sc]["final_sig3"],
                    "thesis day 3s<100 m": ref["below100_d"], "odpipe day 3s<100 m": m[sc]["below100_d"],
                    "odpipe error RMS d6-9": m[sc]["rms_err"], "odpipe e'P^-1e/3 d6-9": m[sc]["nees"],
                    "thesis note": paper.get("note", "")})
    return out


FIGURES = ("3s RMS d6-9", "final 3s", "day 3s<100 m")


def tau_spread(cfg, sim: dict, log=print) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The ``sensitivity.tau_cases`` refitted with each correlation time ``sensitivity.acc_tau_s`` (the thesis
    gives none): every thesis figure with odpipe's beside it per correlation time, and per figure the
    spread of odpipe/thesis over them (with the correlation times of its ends) and of odpipe's figure
    (max/min: how sensitive it is to the choice)."""
    sens, rows = cfg["sensitivity"], []
    for tau in sens["acc_tau_s"]:
        cfg_tau = dict(cfg, filter=dict(cfg["filter"], acc_tau_s=tau))
        for name in sens["tau_cases"]:
            case = cfg["cases"][name]
            m = fit_schedule(cfg, sim, case, cfg_tau)["metrics"]
            log(f"{name}, correlation time {tau / 3600:g} h: "
                + ", ".join(f"{sc} 3-sigma {m[sc]['rms_sig3']:.1f} m" for sc in NAMES))
            for r in table_rows(name, case, m, cfg["paper"].get(name, {})):
                rows += [{"case": name, "spacecraft": r["spacecraft"], "figure": fig, "tau h": tau / 3600.0,
                          "thesis": r[f"thesis {fig}"], "odpipe": r[f"odpipe {fig}"],
                          "odpipe/thesis": r[f"odpipe {fig}"] / r[f"thesis {fig}"]}
                         for fig in FIGURES if np.isfinite(r[f"thesis {fig}"])]
    df = pd.DataFrame(rows)
    summary = []
    for (name, sc, fig), g in df.groupby(["case", "spacecraft", "figure"], sort=False):
        ratio = g["odpipe/thesis"].to_numpy()
        summary.append({"case": name, "spacecraft": sc, "figure": fig, "thesis": g["thesis"].iloc[0], **spread(ratio),
                        "max/min": float(ratio.max() / ratio.min()),
                        "tau h at min": g["tau h"].iloc[int(np.argmin(ratio))],
                        "tau h at max": g["tau h"].iloc[int(np.argmax(ratio))]})
    return df, pd.DataFrame(summary)


def rtn_sig3(sol, truth, sc: str, t0: float, window_days) -> np.ndarray:
    """RMS over the window of the filter's position 3-sigma (m) along the truth's radial, transverse and
    normal axes of spacecraft ``sc``."""
    i = NAMES.index(sc)
    grid = sol.grid
    win = (grid >= t0 + window_days[0] * DAY) & (grid <= t0 + window_days[1] * DAY)
    x = truth[sc].state(grid[win])
    r = x[:, :3] / np.linalg.norm(x[:, :3], axis=1)[:, None]
    n = np.cross(x[:, :3], x[:, 3:])
    n /= np.linalg.norm(n, axis=1)[:, None]
    A = np.stack([r, np.cross(n, r), n], axis=1)                    # rows R, T, N
    P = sol.filtered_P[win][:, 6 * i:6 * i + 3, 6 * i:6 * i + 3]
    var = np.einsum("kij,kjl,kil->ki", A, P, A)
    return 3.0 * np.sqrt(np.mean(var, axis=0))


def geo_ground_only(cfg, sim: dict, log=print) -> pd.DataFrame:
    """Why the GEO satellite's uncertainty shrinks from Sky Valley tracking alone (the thesis: it is not
    reduced): the "ground" case with Table 8.3's filter and with one choice changed at a time (a priori
    velocity ``sensitivity.geo_apriori_vel_mps``, correlation time ``sensitivity.acc_tau_s``, accelerations
    x ``acc_scale``); the GEO 3-D 3-sigma RMS over the window, its reduction from the a priori and its
    R/T/N parts."""
    f, sens, case = cfg["filter"], cfg["sensitivity"], cfg["cases"]["ground"]
    variants = [("Table 8.3 (1 km, 1 mm/s, tau 1 d)", f)]
    variants += [(f"a priori velocity {v:g} m/s", dict(f, apriori_vel_mps=v)) for v in sens["geo_apriori_vel_mps"]]
    variants += [(f"tau {t / 3600:g} h", dict(f, acc_tau_s=t)) for t in sens["acc_tau_s"] if t != f["acc_tau_s"]]
    variants.append((f"accelerations x{sens['acc_scale']:g}",
                     dict(f, acc_sigma_rtn=[sens["acc_scale"] * a for a in f["acc_sigma_rtn"]])))
    rows = []
    for label, filt in variants:
        res = fit_schedule(cfg, sim, case, dict(cfg, filter=filt))
        m = res["metrics"]["GEO"]
        apriori = 3.0 * np.sqrt(3.0) * filt["apriori_pos_m"]
        rtn = rtn_sig3(res["solution"], sim["truth"], "GEO", sim["t0"], cfg["window_days"])
        log(f"GEO from the ground alone, {label}: 3-sigma {m['rms_sig3']:.0f} m, {apriori / m['rms_sig3']:.1f}x "
            f"below the a priori")
        rows.append({"filter": label, "GEO 3s RMS d6-9": m["rms_sig3"], "a priori 3-D 3s": apriori,
                     "reduction": apriori / m["rms_sig3"], "R 3s": rtn[0], "T 3s": rtn[1], "N 3s": rtn[2],
                     "error RMS d6-9": m["rms_err"]})
    return pd.DataFrame(rows)


def observed_biases(cfg, rows: pd.DataFrame) -> list[str]:
    """Names of the range biases that some of ``rows`` depend on."""
    return [name for name, _, info in bias_parameters(cfg)
            if ((rows["observable"] == info["observable"]) & (rows["station_rx"] == info.get("station", ""))).any()]


def bias_summary(cfg, res: dict) -> str:
    """Smoothed range biases (m) +- 1 sigma of one case's fit, for the biases its rows observe."""
    sol, reg = res["solution"], res["registry"]
    ks = {name: reg.index(name) for name in observed_biases(cfg, res["rows"])}
    return "biases " + ", ".join(f"{n.split('.')[-1]} {sol.smoothed_x[0, k]:.2f} +- "
                                 f"{np.sqrt(sol.smoothed_P[0, k, k]):.2f}" for n, k in ks.items())


def prepare(cfg: dict, log=print) -> dict:
    """Truth, every candidate row with its noise, the a priori draws and the filter's force models:
    {setup, t0, t1, x0, truth, rows, guess, fm}."""
    setup = MeasurementSetup.default()
    setup.stations = station_catalog(cfg)
    start = np.datetime64(cfg["epoch_utc"], "ns")
    t0 = float(utc_to_tdb(start))
    t1 = t0 + cfg["arc_days"] * DAY
    gm = setup.ephemeris.gm("earth")
    x0 = {"L1": np.asarray(cfg["state"]["L1"], float), "GEO": geo_state(cfg, t0, gm)}
    truth_fm = force_models(cfg, setup.ephemeris, "truth")
    truth = {sc: propagate(x0[sc], t0, t1 + 600.0, truth_fm[sc], with_stm=False) for sc in NAMES}
    rng = np.random.default_rng(cfg["seed"])
    rows = observe(cfg, tracking_rows(cfg, truth, setup, start), rng)
    guess = initial_guess(cfg, x0, rng)
    log(f"truth and {len(rows)} candidate rows; biases {rows.attrs['bias']}")
    return {"setup": setup, "t0": t0, "t1": t1, "x0": x0, "truth": truth, "rows": rows, "guess": guess,
            "fm": force_models(cfg, setup.ephemeris, "filter")}


def run(cfg: dict, out, log=print, sim: dict | None = None) -> dict:
    """Simulate (or take ``sim``, a :func:`prepare` of this set-up), fit every case of cfg['cases'] and write
    report.md, cases.csv and the plots into ``out``; returns the table, per case {solution, registry,
    metrics, rows}, the true epoch states and ``sim``."""
    sim = sim or prepare(cfg, log)
    t0, rows = sim["t0"], sim["rows"]
    table, sigmas, panels, results = [], {sc: [] for sc in NAMES}, [], {}
    sens = cfg["sensitivity"]
    scaled = dict(cfg, filter=dict(cfg["filter"], acc_sigma_rtn=[sens["acc_scale"] * a
                                                                 for a in cfg["filter"]["acc_sigma_rtn"]]))
    runs = [(name, case, cfg) for name, case in cfg["cases"].items()]
    runs += [(f"{name} (acc x{sens['acc_scale']:g})", cfg["cases"][name], scaled) for name in sens["cases"]]
    for name, case, cfg_fit in runs:
        results[name] = fit_schedule(cfg, sim, case, cfg_fit)
        sol, m, sel = results[name]["solution"], results[name]["metrics"], results[name]["rows"]
        log(f"{name}: {len(sel)} rows, {len(sol.history)} iterations, post-fit RMS "
            f"{sol.history[-1]['postfit_rms']:.3f} (whitened), converged {sol.converged}; "
            + ", ".join(f"{sc} 3-sigma {m[sc]['rms_sig3']:.1f} m error {m[sc]['rms_err']:.1f} m" for sc in NAMES))
        table += table_rows(name, case, m, cfg["paper"].get(name.split(" ")[0], {}))
        if cfg_fit is not cfg:
            continue
        t_days = (sol.grid - t0) / DAY
        color = f"C{len(results) - 1}"
        for sc in NAMES:
            sigmas[sc].append((name, m[sc]["sig3"], {"color": color, "t": t_days}))
            panels.append({"title": f"{name} {sc}", "t_days": t_days,
                           "curves": [("|truth - filtered|", m[sc]["err"], {"color": "k"}),
                                      ("3-D 3-sigma", m[sc]["sig3"], {"color": "k", "ls": ":"})]})
    df = pd.DataFrame(table)
    spread_sections, tau_rows, tau_summary, geo = [], None, None, None
    if sens["acc_tau_s"] and sens["tau_cases"]:
        tau_rows, tau_summary = tau_spread(cfg, sim, log)
        spread_sections.append(("Correlation time of the empirical accelerations (not in the thesis): spread of "
                                "odpipe/thesis", write_table(out, "tau_spread", tau_summary) + "\n"
                                + write_table(out, "tau_cases", tau_rows)))
    if sens["geo_apriori_vel_mps"] and "ground" in cfg["cases"]:
        geo = geo_ground_only(cfg, sim, log)
        spread_sections.append(("GEO from Sky Valley alone: what reduces its uncertainty (thesis: not reduced)",
                                write_table(out, "geo_ground_only", geo)))
    plot_convergence(out, "uncertainty", [{"title": f"{sc}: 3-D position 3-sigma of the filter (cf. Fig. 8.5)",
                                           "t_days": None, "curves": sigmas[sc]} for sc in NAMES], "m")
    plot_convergence(out, "position", panels, "m")
    notes = "\n".join(f"- {name}: {len(r['rows'])} rows ("
                      + ", ".join(f"{k} {int((r['rows']['link'] == k).sum())}" for k in ("dsn", "geo", "sst"))
                      + f"), post-fit RMS {r['solution'].history[-1]['postfit_rms']:.3f} (whitened), "
                      f"{len(r['solution'].history)} iterations, converged {r['solution'].converged}; "
                      + bias_summary(cfg, r) for name, r in results.items())
    write_markdown(out, "Study ground_and_crosslink: ground tracking with and without LiAISON, EML1 halo + GEO "
                        "(Leonard thesis sec. 8.1)",
                   [("Position uncertainty and error, thesis vs odpipe",
                     write_table(out, "cases", df) + "\n![uncertainty](uncertainty.png)\n\n![position](position.png)\n"),
                    *spread_sections,
                    ("Differences from the thesis", cfg["report"]["differences"] + "\n"),
                    ("Fits", notes + "\n\nTrue range biases (m): "
                     + ", ".join(f"{k} {v:.2f}" for k, v in rows.attrs["bias"].items()) + "\n")])
    return {"table": df, "results": results, "x0": sim["x0"], "sim": sim, "tau_cases": tau_rows,
            "tau_spread": tau_summary, "geo_ground_only": geo}
