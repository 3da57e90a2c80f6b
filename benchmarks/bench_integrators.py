"""Fixed-step against adaptive integration: the onboard-filter trade of seed 003 (Li et al.).

One day of the DRO-LEO scenario's LEO (400 km, 97.4 deg): Earth 50x50 (GGM02C), Sun and Moon,
with the STM. For adaptive DOP853 (rtol 1e-12), RK4 at 60 s and fixed 8th-order DOP853 steps
of 30 s to 10 min: wall time (best of 3), steps and the position error after one day against
adaptive DOP853 at rtol 1e-13.

Run: .venv/bin/python benchmarks/bench_integrators.py
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from odpipe.dynamics.forces import ForceModel, PointMasses, SphericalHarmonics
from odpipe.dynamics.propagator import propagate
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.gravity import read_gravity
from odpipe.studies.dro_leo_dowr import circular_state
from odpipe.time import utc_to_tdb

DATA = Path(os.environ.get("ODPIPE_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
CASES = {"adaptive DOP853, rtol 1e-12": {},
         "RK4, 60 s": {"method": "rk4", "max_step": 60.0},
         "8th order, 30 s": {"rtol": np.inf, "max_step": 30.0},
         "8th order, 60 s": {"rtol": np.inf, "max_step": 60.0},
         "8th order, 5 min": {"rtol": np.inf, "max_step": 300.0},
         "8th order, 10 min": {"rtol": np.inf, "max_step": 600.0}}


def main():
    eph = Ephemeris.open("de440")
    field = read_gravity(DATA / "gravity/tudat/ggm02c.txt").truncated(50)
    fm = ForceModel("earth", [PointMasses(["sun", "moon"]), SphericalHarmonics("earth", field, 50)], ephemeris=eph)
    t0 = float(utc_to_tdb(np.datetime64("2023-01-01T00:00:00", "ns")))
    t1 = t0 + 86400.0
    x0 = circular_state(eph.gm("earth"), 6878.137e3, *np.radians([97.4065, 10.3886, 0.0]))
    ref = propagate(x0, t0, t1, fm, with_stm=False, rtol=1e-13, atol=1e-12).state(t1)[0]
    print(f"{'integrator':28s} {'time (s)':>9s} {'steps':>6s} {'error after 1 d (m)':>20s}")
    for name, kw in CASES.items():
        propagate(x0, t0, t0 + 600.0, fm, **kw)                           # compile
        best = np.inf
        for _ in range(3):
            t = time.perf_counter()
            tr = propagate(x0, t0, t1, fm, **kw)
            best = min(best, time.perf_counter() - t)
        err = np.linalg.norm(tr.state(t1)[0][:3] - ref[:3])
        print(f"{name:28s} {best:9.2f} {tr.n_steps:6d} {err:20.3g}")


if __name__ == "__main__":
    main()
