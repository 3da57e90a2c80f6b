"""An L1 halo and a GEO satellite tracked only by each other in the CRTBP (seed 000, Fujimoto et al. sec. 2.1).

Instantaneous crosslink range (1 m) and range-rate (1 cm/s) every 100 s; a priori
100 m / 1 cm/s per axis; initial deviations of 100 m and 1 cm/s (the paper's Table 3
vectors, applied in the rotating frame); GM Earth 398,600.4415 and Moon 4,902.80 km^3/s^2.
The halo and the GEO orientation are not given for sec. 2.1: a 12-day L1 halo of the
family (config) and a circular 1-sidereal-day orbit about the Earth (inclination to the
Earth-Moon plane in the config). The paper's state-noise compensation (1e-13 and
1e-14 m/s^2) is carried in the CRLB; the fit's dynamics are the truth's.
Products: filter convergence of both spacecraft (one run and an optional Monte
Carlo), CRLB, post-fit residuals, beside the paper's statements.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pandas as pd

from odpipe.constants import SECONDS_PER_DAY
from odpipe.analysis.montecarlo import monte_carlo, rms_over_runs, rss
from odpipe.dynamics.crtbp import EarthMoonUnits

from .crtbp_problem import RANGE, RANGE_RATE
from .crtbp_orbits import halo_by_period, keplerian_orbit
from .crosslink_pair import CrosslinkPair
from .study_report import plot_convergence, write_markdown, write_table

DAY = SECONDS_PER_DAY
SIDEREAL_DAY = 86164.0905


def setup(cfg) -> CrosslinkPair:
    u, h, g, f = cfg["units"], cfg["halo"], cfg["geo"], cfg["filter"]
    U = EarthMoonUnits(length=u["length_km"] * 1e3, gm1=u["gm_earth_km3s2"] * 1e9,
                       gm2=u["gm_moon_km3s2"] * 1e9)
    halo, _ = halo_by_period(h["period_days"] * DAY / U.time, h["x0"], h["vy0"], h["z_start"],
                             h["z_stop"], U.mu, h["dz"])
    geo = keplerian_orbit(SIDEREAL_DAY / U.time, 0.0, np.radians(g["inclination_deg"]), U.mu,
                          true_anomaly=np.radians(g.get("phase_deg", 0.0)), primary="earth")
    dev = np.concatenate([np.asarray(f["deviation_halo"], float), np.asarray(f["deviation_geo"], float)])
    return CrosslinkPair(U, U.to_si(halo), U.to_si(geo), arc=cfg["arc_days"] * DAY,
                         dt=cfg["cadence_s"], kinds=(RANGE, RANGE_RATE),
                         sigma=(cfg["noise"]["range_m"], cfg["noise"]["range_rate_mps"]),
                         apriori=(f["apriori_pos_m"], f["apriori_vel_mps"]),
                         error=(f["apriori_pos_m"], f["apriori_vel_mps"]),
                         block=f["block_h"] * 3600.0, first=0, max_iter=f["max_iter"],
                         sigma_acc=tuple(f["snc_mps2"]), deviation=dev)


def _first_below(t, y, level):
    """First time (days) after which y stays below level (nan if never)."""
    above = np.flatnonzero(y >= level)
    k = 0 if above.size == 0 else above[-1] + 1
    return t[k] / DAY if k < t.size else np.nan


def sensitivity(cfg) -> pd.DataFrame:
    """CRLB per-axis position sigma at the comparison day for the config's [[variant]]
    set-ups (halo and GEO choices the paper leaves open)."""
    rows = []
    for v in [{"name": "this run"}] + cfg.get("variant", []):
        c = copy.deepcopy(cfg)
        c["halo"].update(v.get("halo", {}))
        c["geo"].update(v.get("geo", {}))
        t, P = setup(c).crlb()
        s = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
        k = np.argmin(np.abs(t / DAY - cfg["compare_day"]))
        rows.append({"set-up": v["name"], "halo period d": c["halo"]["period_days"],
                     "GEO inclination deg": c["geo"]["inclination_deg"],
                     "halo max axis CRLB m": float(s[k, :3].max()),
                     "GEO max axis CRLB m": float(s[k, 6:9].max())})
    return pd.DataFrame(rows)


def run(cfg: dict, out, log=print) -> dict:
    pair = setup(cfg)
    log(f"halo period {cfg['halo']['period_days']} d, arc {cfg['arc_days']} d, {pair.epochs.size} epochs")
    one = pair(np.random.default_rng(cfg["seed"]))
    t_c, P = pair.crlb()
    crlb_sig = np.sqrt(np.diagonal(P, axis1=1, axis2=2))
    t = one["grid"]
    sig = one["filtered_sigma"]
    paper = cfg["paper"]
    day = cfg["compare_day"]
    k = np.argmin(np.abs(t / DAY - day))
    kc = np.argmin(np.abs(t_c / DAY - day))
    rows = []
    for sc, cs in (("L1 halo", slice(0, 3)), ("GEO", slice(6, 9))):
        pos_sig = rss(sig, cs)
        rows.append({"spacecraft": sc, "quantity": f"max per-axis position sigma at day {day} (m)",
                     "paper": paper["position_sigma_m"], "odpipe": float(np.max(sig[k, cs])),
                     "odpipe CRLB": float(np.max(crlb_sig[kc, cs]))})
        rows.append({"spacecraft": sc, "quantity": f"3-D position sigma at day {day} (m)",
                     "paper": np.nan, "odpipe": float(pos_sig[k]),
                     "odpipe CRLB": float(rss(crlb_sig, cs)[kc])})
        rows.append({"spacecraft": sc, "quantity": f"3-D position error at day {day} (m)",
                     "paper": np.nan, "odpipe": float(np.linalg.norm(one["filtered"][k, cs])),
                     "odpipe CRLB": np.nan})
        rows.append({"spacecraft": sc, "quantity": f"days until every axis sigma < {paper['level_m']} m",
                     "paper": paper["days_to_level"],
                     "odpipe": _first_below(t, np.max(sig[:, cs], axis=1), paper["level_m"]),
                     "odpipe CRLB": _first_below(t_c, np.max(crlb_sig[:, cs], axis=1), paper["level_m"])})
    rows.append({"spacecraft": "both", "quantity": "post-fit range residual RMS (m)",
                 "paper": paper["postfit_range_rms_m"], "odpipe": one["postfit_rms"][0], "odpipe CRLB": np.nan})
    rows.append({"spacecraft": "both", "quantity": "post-fit range-rate residual RMS (m/s)",
                 "paper": np.nan, "odpipe": one["postfit_rms"][1], "odpipe CRLB": np.nan})
    table = pd.DataFrame(rows)
    panels = []
    curves_mc = None
    n_mc = cfg["montecarlo"]["runs"]
    if n_mc:
        runs = monte_carlo(replace(pair, deviation=None), n_mc,
                           cfg["montecarlo"]["seed"], parallel=cfg["montecarlo"].get("parallel", False))
        curves_mc = rms_over_runs(np.array([r["filtered"] for r in runs]))
    for sc, cs in (("L1 halo", slice(0, 3)), ("GEO", slice(6, 9))):
        for what, off, unit in (("position", 0, "m"), ("velocity", 3, "m/s")):
            c = slice(cs.start + off, cs.stop + off)
            curves = [("|truth - filtered|", np.linalg.norm(one["filtered"][:, c], axis=1), {"color": "k"}),
                      ("3-D 3-sigma filter", 3 * rss(sig, c), {"color": "k", "ls": ":"}),
                      ("3-D CRLB", rss(crlb_sig, c), {"color": "C2", "ls": "--", "t": t_c / DAY})]
            if curves_mc is not None:
                curves.append((f"MC RMS ({n_mc} runs)", rss(curves_mc, c), {"color": "C1"}))
            panels.append({"title": f"{sc} {what} ({unit})", "t_days": t / DAY, "curves": curves})
    plot_convergence(out, "convergence", panels, "m")   # the left column's unit (positions); titles say each
    sections = [("Paper vs odpipe", write_table(out, "halo_geo_crtbp", table) + "\n![convergence](convergence.png)\n"),
                ("Run", f"fit converged: {one['converged']} in {one['iterations']} iterations; "
                        f"{pair.epochs.size} epochs of range and range-rate.\n"),
                (f"Sensitivity to the unspecified set-up (CRLB at day {day}, paper: about 1 m)",
                 write_table(out, "sensitivity", sensitivity(cfg)))]
    write_markdown(out, "Study halo_geo_crtbp: GEO + EML1 halo in the CRTBP (Fujimoto et al. sec. 2.1)", sections)
    for r in rows:
        log(f"{r['spacecraft']}: {r['quantity']}: paper {r['paper']}, odpipe {r['odpipe']:.4g}")
    return {"table": table}
