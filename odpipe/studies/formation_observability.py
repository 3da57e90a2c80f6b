"""Range-only vs range-rate-only crosslinks in cislunar formations (seed 002, Turan et al. 2022).

Pairs EML1/EML2 halo, EML1 halo/lunar orbiter and EML2 halo/lunar orbiter in the
CRTBP; halos picked from their families by the periods of Table 1, the lunar
orbiter a Keplerian ellipse of 0.93 d (orbit not given in the paper; set in the
config). Products:

* Table 1: Xi_mean (eq. 25 with the rows' epoch-mapped partials, mean over
  epochs and the 12 components), cond(N) and 1/min eig(N) of the unweighted
  Gramian (eq. 22) in CRTBP units, range-only and range-rate-only;
* Monte Carlo (eq. 28) RMS position/velocity errors of the filter, range-only vs
  range-rate-only, with the CRLB along the truth;
* noise sweep (Figs. 4-5): CRLB position error at the end of the arc per noise level.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from odpipe.constants import SECONDS_PER_DAY
from odpipe.analysis.montecarlo import monte_carlo, rms_over_runs, rss
from odpipe.analysis.observability import gramian, observability_measures, snr_ratio
from odpipe.dynamics.crtbp import jacobi_constant

from .crtbp_problem import RANGE, RANGE_RATE, units_from_mu
from .crtbp_orbits import halo_by_period, halo_start, keplerian_orbit
from .crosslink_pair import CrosslinkPair
from .study_report import plot_convergence, spread, write_markdown, write_table

DAY = SECONDS_PER_DAY
TYPES = {"range": (RANGE,), "range-rate": (RANGE_RATE,)}


def units(cfg):
    u = cfg["units"]
    return units_from_mu(u["length_km"] * 1e3, u["gm_earth_km3s2"] * 1e9 / (1 - u["mu"]), u["mu"])


def orbits(cfg, U):
    """{'L1': [(state_nd, period_tu)], 'L2': [...], 'lunar': (state_nd, period_tu)}."""
    out = {}
    for name in ("L1", "L2"):
        h = cfg["halo"][name]
        fam = [halo_by_period(p, h["x0"], h["vy0"], h["z_start"], h["z_stop"], U.mu, h["dz"])
               for p in h["periods_tu"]]
        out[name] = [(halo_start(s, T, U.mu, cfg["halo"]["start"], cfg["halo"]["north"]), T) for s, T in fam]
    lo = cfg["lunar"]
    p = lo["period_days"] * DAY / U.time
    out["lunar"] = (keplerian_orbit(p, lo["ecc"], np.radians(lo["inc_deg"]), U.mu,
                                  np.radians(lo.get("raan_deg", 0.0)), np.radians(lo.get("argp_deg", 0.0)),
                                  np.radians(lo.get("true_anomaly_deg", 0.0))), p)
    return out


def formations(cfg, U, orb):
    """Table 1 columns in the paper's order: (label, pair with range-only data)."""
    base = dict(units=U, dt=cfg["cadence"]["dt_tu"] * U.time,
                sigma=(cfg["noise"]["range_m"], cfg["noise"]["range_rate_mps"]),
                apriori=(cfg["filter"]["apriori_pos_m"], cfg["filter"]["apriori_vel_mps"]),
                error=(cfg["filter"]["error_pos_m"], cfg["filter"]["error_vel_mps"]),
                block=cfg["filter"]["block_h"] * 3600.0, max_iter=cfg["filter"]["max_iter"])
    cols = []
    for group, a, b in (("EML1/L2", "L1", "L2"), ("EML1/Lunar", "L1", "lunar"),
                        ("EML2/Lunar", "L2", "lunar")):
        for i in range(len(orb["L1"])):
            s1, p1 = orb[a][i]
            s2, p2 = orb[b][i] if b != "lunar" else orb["lunar"]
            label = f"{group} {p1:.2f}" + (f"/{p2:.2f}" if b != "lunar" else "")
            cols.append((label, CrosslinkPair(x1=U.to_si(s1), x2=U.to_si(s2),
                                              arc=max(p1, p2) * U.time, **base)))
    return cols


def observability_row(pair: CrosslinkPair) -> dict:
    """Xi_mean, cond(N) and 1/min eig(N) (CRTBP units) for range-only and range-rate-only data."""
    out, H = {}, {}
    for name, kinds in TYPES.items():
        p = replace(pair, kinds=kinds)
        _, kind, H[name] = p.epoch_partials()
        m = observability_measures(gramian(p.nondimensional(H[name], kind)))
        out[f"cond {name}"], out[f"1/min eig {name}"] = m.condition_number, m.unobservability_index
    xi = snr_ratio(H["range"], H["range-rate"], *pair.sigma)
    out["Xi_mean"] = float(np.mean(xi))
    out["Xi_median"] = float(np.median(xi))
    out["Xi<1 fraction"] = float(np.mean(xi < 1))
    return out


def lunar_phase_rows(cfg, U, cols, orb) -> dict:
    """{start true anomaly (deg): {column: Table 1 row}} of the lunar formations over the orbiter's
    starting true anomaly ``lunar.phase_band_deg`` (the paper does not give it)."""
    out = {}
    for nu in cfg["lunar"]["phase_band_deg"]:
        x = U.to_si(_lunar_orbiter(cfg, U, orb["lunar"][1], nu))
        out[nu] = {j: observability_row(replace(pair, x2=x)) for j, (label, pair) in enumerate(cols) if "Lunar" in label}
    return out


def lunar_phase_band(phase_rows: dict) -> dict:
    """{column: {quantity: (min, max)}} over the start phases of :func:`lunar_phase_rows`."""
    by_col = {}
    for rows in phase_rows.values():
        for j, r in rows.items():
            by_col.setdefault(j, []).append(r)
    return {j: {k: (min(v[k] for v in vals), max(v[k] for v in vals)) for k in vals[0]} for j, vals in by_col.items()}


QUANTITIES = (("Xi_mean", "xi_mean"), ("cond range", "cond_range"), ("cond range-rate", "cond_range_rate"),
              ("1/min eig range", "inv_min_eig_range"), ("1/min eig range-rate", "inv_min_eig_range_rate"))


def log_ratios(row: dict, paper: dict, j: int) -> np.ndarray:
    """log10(odpipe / paper) of column j's Gramian measures (cond, 1/min eig; range, range-rate)."""
    return np.array([np.log10(row[k] / paper[p][j]) for k, p in QUANTITIES[1:]])


def halo_start_sensitivity(cfg, U, cols, orb) -> pd.DataFrame:
    """EML1/L2 Gramian measures against the paper for each start of the two halos (apolune or
    perilune crossing, L2 north or south of the plane with L1 north): the geometric mean and the
    largest factor between odpipe and the paper (10^|log10 ratio|), and the spread of odpipe/paper
    over the 16 measures; a last row "all starts" pools the 8 x 16 ratios."""
    paper, rows = cfg["paper"]["table1"], []
    for at1 in ("apolune", "perilune"):
        for at2 in ("apolune", "perilune"):
            for north2 in (True, False):
                L = []
                for j, (label, pair) in enumerate(cols):
                    if not label.startswith("EML1/L2"):
                        continue
                    (s1, T1), (s2, T2) = orb["L1"][j], orb["L2"][j]
                    x1, x2 = halo_start(s1, T1, U.mu, at1, True), halo_start(s2, T2, U.mu, at2, north2)
                    L.append(log_ratios(observability_row(replace(pair, x1=U.to_si(x1), x2=U.to_si(x2))),
                                        paper, j))
                rows.append(_factors(np.array(L), {"L1 start": f"{at1}, north",
                                                   "L2 start": f"{at2}, {'north' if north2 else 'south'}"}))
    pooled = np.concatenate([r.pop("log ratios") for r in rows])
    return pd.DataFrame(rows + [{k: v for k, v in _factors(pooled, {"L1 start": "all starts", "L2 start": ""}).items()
                                 if k != "log ratios"}])


def _factors(L: np.ndarray, labels: dict) -> dict:
    """A choice's row: geometric-mean and worst factor from log10(odpipe/paper) ``L``, and the ratios' spread."""
    return {**labels, "mean factor": 10 ** np.abs(L).mean(), "worst factor": 10 ** np.abs(L).max(),
            **spread(10 ** L), "log ratios": L.ravel()}


def lunar_phase_sensitivity(cfg, phase_rows: dict) -> pd.DataFrame:
    """The lunar columns' Gramian measures against the paper for each start phase of :func:`lunar_phase_rows`:
    factors and spread over the 32 measures, and a last row pooling every phase."""
    rows = [_factors(np.array([log_ratios(r, cfg["paper"]["table1"], j) for j, r in cols.items()]),
                     {"start true anomaly deg": nu}) for nu, cols in phase_rows.items()]
    pooled = np.concatenate([r.pop("log ratios") for r in rows])
    return pd.DataFrame(rows + [{k: v for k, v in _factors(pooled, {"start true anomaly deg": "all"}).items()
                                 if k != "log ratios"}])


def _lunar_orbiter(cfg, U, period, nu_deg) -> np.ndarray:
    """The configured lunar orbiter (CRTBP units) started at true anomaly ``nu_deg``."""
    lo = cfg["lunar"]
    return keplerian_orbit(period, lo["ecc"], np.radians(lo["inc_deg"]), U.mu, np.radians(lo.get("raan_deg", 0.0)),
                           np.radians(lo.get("argp_deg", 0.0)), np.radians(nu_deg))


def montecarlo_curves(pair: CrosslinkPair, n_runs: int, seed: int, parallel: bool, workers=None):
    """RMS (eq. 28) filtered errors per type and the CRLB: {type: dict of arrays}."""
    out = {}
    for name, kinds in TYPES.items():
        p = replace(pair, kinds=kinds)
        runs = monte_carlo(p, n_runs, seed, parallel=parallel, n_workers=workers)
        rms = rms_over_runs(np.array([r["filtered"] for r in runs]))
        t_crlb, P = p.crlb()
        sig = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
        out[name] = {"t": runs[0]["grid"], "rms": rms, "t_crlb": t_crlb, "crlb": sig,
                     "converged": float(np.mean([r["converged"] for r in runs]))}
    return out


def _final(t, y, arc_frac=0.25):
    """Mean of y over the last quarter of the arc (the converged level)."""
    sel = t >= t[-1] * (1 - arc_frac)
    return float(np.mean(y[sel]))


def run(cfg: dict, out, log=print) -> dict:
    U = units(cfg)
    log(f"units: L = {U.length/1e3:.2f} km, T = {U.time/DAY:.4f} d, mu = {U.mu}")
    orb = orbits(cfg, U)
    cols = formations(cfg, U, orb)
    paper = cfg["paper"]["table1"]
    rows = []
    for j, (label, pair) in enumerate(cols):
        r = observability_row(pair)
        rows.append({"formation": label, **r})
        log(f"{label}: Xi_mean {r['Xi_mean']:.1f}, cond {r['cond range']:.2e}/{r['cond range-rate']:.2e}, "
            f"1/min eig {r['1/min eig range']:.3g}/{r['1/min eig range-rate']:.3g}")
    obs = pd.DataFrame(rows)
    phase_rows = lunar_phase_rows(cfg, U, cols, orb)
    band = lunar_phase_band(phase_rows)
    side = []
    for key, pkey in QUANTITIES:
        for j, (label, _) in enumerate(cols):
            lo, hi = band.get(j, {}).get(key, (np.nan, np.nan))
            side.append({"quantity": key, "formation": label, "paper": paper[pkey][j],
                         "odpipe": obs[key][j], "odpipe/paper": obs[key][j] / paper[pkey][j],
                         "odpipe min (lunar phase)": lo, "odpipe max (lunar phase)": hi})
    side = pd.DataFrame(side)
    orbit_rows = [{"orbit": f"{n} #{i}", "period TU": T, "period d": T * U.time / DAY,
                   "Jacobi C": float(jacobi_constant(s, U.mu)), "x0": s[0], "z0": s[2], "vy0": s[4]}
                  for n in ("L1", "L2") for i, (s, T) in enumerate(orb[n])]
    s, T = orb["lunar"]
    orbit_rows.append({"orbit": "lunar", "period TU": T, "period d": T * U.time / DAY,
                       "Jacobi C": float(jacobi_constant(s, U.mu)), "x0": s[0], "z0": s[2], "vy0": s[4]})
    sections = [("Orbits (from the paper's periods)", write_table(out, "orbits", pd.DataFrame(orbit_rows))),
                ("Table 1: paper vs odpipe", write_table(out, "table1", side))]
    log("EML1/L2: sensitivity to the halos' start")
    sections.append(("EML1/L2 Table 1 against the halos' start (the paper gives neither phase nor hemisphere; "
                     "deviation factors over the 4 columns x 4 Gramian measures)",
                     write_table(out, "halo_start", halo_start_sensitivity(cfg, U, cols, orb))))
    sections.append(("Lunar columns of Table 1 against the orbiter's start phase (the paper gives the period only; "
                     "factors and odpipe/paper spread over the 8 columns x 4 Gramian measures)",
                     write_table(out, "lunar_phase", lunar_phase_sensitivity(cfg, phase_rows))))

    # Monte Carlo and CRLB on the selected formations
    mc = cfg["montecarlo"]
    mc_rows, panels = [], []
    for j in mc["columns"]:
        label, pair = cols[j]
        log(f"Monte Carlo {label}: {mc['runs']} runs per data type")
        curves = montecarlo_curves(pair, mc["runs"], mc["seed"], mc.get("parallel", False),
                                   mc.get("workers"))
        for sc, cs in (("sc1", slice(0, 3)), ("sc2", slice(6, 9))):
            panel = {"title": f"{label} {sc}", "t_days": None, "curves": []}
            for name, style in (("range", "C0"), ("range-rate", "C3")):
                c = curves[name]
                pos = rss(c["rms"], cs)
                vel = rss(c["rms"], slice(cs.start + 3, cs.stop + 3))
                bound = rss(c["crlb"], cs)
                panel["curves"] += [(f"{name} MC RMS", pos, {"color": style, "t": c["t"] / DAY}),
                                    (f"{name} CRLB", bound, {"color": style, "ls": "--",
                                                             "t": c["t_crlb"] / DAY})]
                mc_rows.append({"formation": label, "spacecraft": sc, "data": name,
                                "pos RMS m (last 1/4)": _final(c["t"], pos),
                                "vel RMS mm/s (last 1/4)": 1e3 * _final(c["t"], vel),
                                "pos CRLB m (last 1/4)": _final(c["t_crlb"], bound),
                                "runs converged": c["converged"]})
            panels.append(panel)
    mc_df = pd.DataFrame(mc_rows)
    plot_convergence(out, "convergence", panels, "3-D position error (m)")
    sections.append(("Monte Carlo RMS position/velocity (filter) and CRLB", write_table(out, "montecarlo", mc_df)
                     + "\n![convergence](convergence.png)\n"))

    # noise sweep with the CRLB (Figs. 4-5)
    sw = cfg["sweep"]
    sweep_rows = []
    for j in mc["columns"]:
        label, pair = cols[j]
        for name, kinds, levels in (("range", (RANGE,), sw["range_m"]),
                                    ("range-rate", (RANGE_RATE,), sw["range_rate_mps"])):
            for lev in levels:
                sig = (lev, pair.sigma[1]) if name == "range" else (pair.sigma[0], lev)
                t, P = replace(pair, kinds=kinds, sigma=sig).crlb()
                d = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
                sweep_rows.append({"formation": label, "data": name, "sigma": lev,
                                   "sc1 pos CRLB m (last 1/4)": _final(t, rss(d, slice(0, 3))),
                                   "sc2 pos CRLB m (last 1/4)": _final(t, rss(d, slice(6, 9)))})
    sections.append(("Noise sweep (CRLB), cf. Figs. 4-5", write_table(out, "sweep", pd.DataFrame(sweep_rows))))
    snc_rows = []
    for j in mc["columns"]:
        label, pair = cols[j]
        for sa in sw["snc_mps2"]:
            level = {}
            for name, kinds in TYPES.items():
                t, P = replace(pair, kinds=kinds, sigma_acc=(sa, sa)).crlb()
                d = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
                level[name] = [_final(t, rss(d, cs)) for cs in (slice(0, 3), slice(6, 9))]
            snc_rows.append({"formation": label, "SNC sigma m/s^2": sa,
                             "sc1 range m": level["range"][0], "sc1 range-rate m": level["range-rate"][0],
                             "sc2 range m": level["range"][1], "sc2 range-rate m": level["range-rate"][1],
                             "sc1 rate/range": level["range-rate"][0] / level["range"][0],
                             "sc2 rate/range": level["range-rate"][1] / level["range"][1]})
    sections.append(("State-noise compensation (CRLB, eq. 3.31): the paper's tuned SNC narrows the gap",
                     write_table(out, "snc", pd.DataFrame(snc_rows))))
    write_markdown(out, "Study formation_observability: range-only vs range-rate-only (Turan et al.)", sections)
    return {"table1": side, "montecarlo": mc_df, "sweep": pd.DataFrame(sweep_rows)}
