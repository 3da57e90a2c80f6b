"""Consider analysis of runs/messenger_2007_06_04.toml: what limits the MESSENGER Doppler-only solution.

Refits the run's own fitted table (``out/messenger_2007_06_04/current/tracking.parquet``, run it first)
from its solution, once without and once with each error source considered (not estimated), and prints
the epoch-state 1-sigma (m, m/s; position and velocity RSS) and its growth: DSN station ITRS coordinates
(``STATION_M`` per axis), the media calibration scale (``MEDIA`` of the model troposphere, no TRK-2-23
cards), and the SRP scale held fixed instead of estimated (its estimate's shift of the state, in sigmas).
Run: ``python benchmarks/messenger_consider.py`` from the repository root (about a minute).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from odpipe.od.arc import fit_arc
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import load_config
from odpipe.pipeline.ingest import ingest

ROOT = Path(__file__).resolve().parents[1]
STATION_M, MEDIA = 0.05, 0.2  # m per axis (DSN ITRF coordinates, 2007); fraction of the model media delay


def _sigmas(P) -> tuple[float, float]:
    d = np.sqrt(np.diag(P)[:6])
    return float(np.linalg.norm(d[:3])), float(np.linalg.norm(d[3:]))


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
    print(f"data only: position {p0 / 1e3:.1f} km, velocity {v0:.3f} m/s (1 sigma RSS at the arc start)")
    for label, setup in (("stations", replace(base, station_sigma=STATION_M)), ("media", replace(base, media_sigma=MEDIA))):
        arc = fit_arc(table, setup)
        p, v = _sigmas(arc.covariances[0])
        print(f"+ {label:9s} considered: position {p / 1e3:.1f} km (x{p / p0:.3f}), velocity {v:.3f} m/s (x{v / v0:.3f})")
    fixed = fit_arc(table, replace(base, srp_scale_sigma=None))
    shift = fixed.states[0] - plain.states[0]
    sig = np.sqrt(np.diag(plain.covariances[0]))
    print(f"SRP scale fixed at 1: state shift {np.linalg.norm(shift[:3]) / 1e3:.1f} km, "
          f"{np.linalg.norm(shift[3:]):.3f} m/s; largest {np.max(np.abs(shift / sig)):.2f} sigma")
    print(plain.parameters.to_string())


if __name__ == "__main__":
    main()
