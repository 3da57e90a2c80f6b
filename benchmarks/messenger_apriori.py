"""The a priori orbit of runs/messenger_2007_06_04.toml from the arc's own two-way Doppler and the flyby epoch.

MESSENGER flew by Venus on 2007-06-05 at 23:08 UTC, 338 km above the surface (mission reports); the
search assumes only the epoch (:mod:`odpipe.od.flyby_apriori`) and prints the closest approach it
finds beside the published one, then the run's ``[initial_state]`` about the Sun.
Run: ``python benchmarks/messenger_apriori.py`` (a few minutes).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from odpipe.dynamics import forces as F
from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.stations import StationCatalog
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.measurements import MeasurementSetup
from odpipe.od.apriori import doppler_rows
from odpipe.od.flyby_apriori import determine_flyby_orbit
from odpipe.pipeline.ingest import ingest
from odpipe.time import tdb_to_utc, utc_to_tdb

ODF = Path(__file__).resolve().parents[1] / "../shared/data/messenger/odf07155.odf"
FLYBY_UTC, FLYBY_ALTITUDE, VENUS_RADIUS = "2007-06-05T23:08:00", 338e3, 6051.8e3


def main():
    t = time.perf_counter()
    data = ingest([ODF.resolve()], spacecraft="236")
    rows = doppler_rows(data.table, data.ramps, "236")
    eph = Ephemeris.open("de440")
    setup = MeasurementSetup(eph, StationCatalog.default(), ramps=data.store, gcrs_to_itrs=gcrs_to_itrs)
    model = F.ForceModel("venus", [F.PointMasses(["sun", "earth", "mercury", "jupiter"])], ephemeris=eph)
    t_p = float(utc_to_tdb(np.array([np.datetime64(FLYBY_UTC, "ns")]))[0])
    res = determine_flyby_orbit(rows, setup, model, t_p)
    print(res.candidates.to_string())
    print(f"post-fit line-of-sight RMS {res.rms_los * 1e3:.1f} mm/s of {int((res.rows['flags'] == 0).sum())} rows")
    print(f"closest approach {res.periapsis / 1e3:.0f} km from Venus's centre at "
          f"{np.datetime64(tdb_to_utc(np.array([res.periapsis_epoch]))[0], 's')} UTC "
          f"(published: {(VENUS_RADIUS + FLYBY_ALTITUDE) / 1e3:.0f} km at {FLYBY_UTC})")
    sun = res.state + eph.state("venus", "sun", np.array([res.epoch]))[0]
    utc = np.datetime64(tdb_to_utc(np.array([res.epoch]))[0], "ms")
    print(f'[initial_state]\nepoch = "{utc}"\nstate = [' + ", ".join(f"{v:.3f}" for v in sun[:3]) + ", "
          + ", ".join(f"{v:.6f}" for v in sun[3:]) + "]   # m, m/s, ICRF about the Sun")
    print(f"{time.perf_counter() - t:.0f} s")


if __name__ == "__main__":
    main()
