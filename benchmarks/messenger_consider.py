"""Consider analysis of runs/messenger_2007_06_04.toml (Doppler + DSS-63's 06-04 range): what limits the solution.

Refits the run's own fitted table (``runs/out/messenger_2007_06_04/current/tracking.parquet``: run
runs/messenger_2007_06_04_doppler.toml, then runs/messenger_2007_06_04.toml, first) from its solution, and prints
the epoch-state 1-sigma (m, m/s; position and velocity RSS) and its growth with each error source considered (not
estimated): DSN station ITRS coordinates (``STATION_M`` per axis), the media calibration scale (``MEDIA`` of the
model troposphere, no TRK-2-23 cards), and the SRP scale held fixed instead of estimated (its estimate's shift of
the state, in sigmas). Then the range's part: the same fit without the range, and with the range pass's bias
a priori tightened from the run's 1 km (no delay calibration in the ODF) to what a calibrated station and
transponder delay would give (``CALIBRATED_M``); and, as a covariance study, with the range points the run removes
(USER: the 22 of the other three passes that follow no known reading) replaced by the values the fitted orbit
computes (what four whole good passes would give).
Run: ``python benchmarks/messenger_consider.py`` from the repository root (4.1 s on 2026-11-26).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.api import ArcProducts
from odpipe.measurements import compute
from odpipe.od.arc import fit_arc
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import load_config
from odpipe.pipeline.ingest import ingest
from odpipe.preprocess.flags import Flag

ROOT = Path(__file__).resolve().parents[1]
STATION_M, MEDIA = 0.05, 0.2  # m per axis (DSN ITRF coordinates, 2007); fraction of the model media delay
CALIBRATED_M = (10.0, 2.0)  # m, range-bias a priori of a calibrated station + transponder delay


def _sigmas(P) -> tuple[float, float]:
    d = np.sqrt(np.diag(P)[:6])
    return float(np.linalg.norm(d[:3])), float(np.linalg.norm(d[3:]))


def _los_split(P, state, fm, t) -> tuple[float, float]:
    """Position 1-sigma (m) along the Earth-spacecraft line of sight and across it (RSS of the other two axes)."""
    u = state[:3] - fm.ephemeris.state("earth", "sun", np.array([t]))[0, :3]
    u /= np.linalg.norm(u)
    along = float(np.sqrt(u @ P[:3, :3] @ u))
    return along, float(np.sqrt(max(np.trace(P[:3, :3]) - along ** 2, 0.0)))


def main():
    cfg = load_config(ROOT / "runs/messenger_2007_06_04.toml")
    run = cfg.path.parent / cfg.run.output / cfg.run.name / "current"
    table = pd.read_parquet(run / "tracking.parquet")
    data = ingest(list(cfg.data.files), cfg.data.errors, cfg.arc.spacecraft)
    fm = build.force_model(cfg)
    base = build.arc_setup(cfg, fm, data.store, build.station_catalog(cfg))
    fitted = pd.read_csv(run / "parameters.csv").set_index("name")["estimate"]
    base = replace(base, state0=fitted[[f"{cfg.arc.spacecraft}.{c}" for c in ("x", "y", "z", "vx", "vy", "vz")]]
                   .to_numpy(float), sigma_scale=(1.0,), max_iter=3)
    plain = fit_arc(table, base)
    p0, v0 = _sigmas(plain.covariances[0])
    print(f"data only: position {p0 / 1e3:.2f} km, velocity {v0 * 1e3:.1f} mm/s (1 sigma RSS at the arc start)")
    along, across = _los_split(plain.covariances[0], plain.states[0], fm, base.start)
    print(f"  position along the line of sight {along / 1e3:.2f} km, across it {across / 1e3:.2f} km")
    for label, setup in (("stations", replace(base, station_sigma=STATION_M)), ("media", replace(base, media_sigma=MEDIA))):
        arc = fit_arc(table, setup)
        p, v = _sigmas(arc.covariances[0])
        print(f"+ {label:9s} considered: position {p / 1e3:.2f} km (x{p / p0:.3f}), velocity {v * 1e3:.1f} mm/s "
              f"(x{v / v0:.3f})")
    fixed = fit_arc(table, replace(base, srp_scale_sigma=None))
    shift = fixed.states[0] - plain.states[0]
    sig = np.sqrt(np.diag(plain.covariances[0]))
    print(f"SRP scale fixed at 1: state shift {np.linalg.norm(shift[:3]) / 1e3:.2f} km, "
          f"{np.linalg.norm(shift[3:]) * 1e3:.1f} mm/s; largest {np.max(np.abs(shift / sig)):.2f} sigma")
    doppler = fit_arc(table[table["observable"] != "range"].reset_index(drop=True), replace(base, range_bias_sigma=None))
    p, v = _sigmas(doppler.covariances[0])
    along, across = _los_split(doppler.covariances[0], doppler.states[0], fm, base.start)
    print(f"without the range: position {p / 1e3:.2f} km (x{p / p0:.3f}; along the line of sight {along / 1e3:.2f} km, "
          f"across {across / 1e3:.2f} km), velocity {v * 1e3:.1f} mm/s (x{v / v0:.3f})")
    for b in CALIBRATED_M:
        arc = fit_arc(table, replace(base, range_bias_sigma=b))
        p, v = _sigmas(arc.covariances[0])
        print(f"range bias a priori {b:g} m: position {p / 1e3:.2f} km (x{p / p0:.3f}), velocity {v * 1e3:.1f} mm/s "
              f"(x{v / v0:.3f})")
    sim = table.copy()
    edited = ((sim["observable"] == "range") & (sim["flags"] == int(Flag.USER))).to_numpy()
    ev = compute(sim[edited].reset_index(drop=True), {cfg.arc.spacecraft: ArcProducts(run).trajectory},
                 base.measurements)
    sim.loc[edited, "value"] = ev.value
    sim.loc[edited, "flags"] = 0
    for b in (cfg.estimation.range_bias_sigma,) + CALIBRATED_M:
        arc = fit_arc(sim, replace(base, range_bias_sigma=b))
        p, v = _sigmas(arc.covariances[0])
        along, across = _los_split(arc.covariances[0], arc.states[0], fm, base.start)
        print(f"four range passes ({int(edited.sum())} simulated points), bias a priori {b:g} m: position {p / 1e3:.2f} km "
              f"(x{p / p0:.3f}; along the line of sight {along / 1e3:.2f} km, across {across / 1e3:.2f} km), "
              f"velocity {v * 1e3:.1f} mm/s (x{v / v0:.3f})")
    print(plain.parameters.to_string())


if __name__ == "__main__":
    main()
