"""GRAIL-B a priori orbits for the daily arcs, and optionally one arc fit end to end (figures printed, never asserted).

    python benchmarks/bench_grail.py            # a priori state of every runs/grail_b_2012_04_*.toml arc
    python benchmarks/bench_grail.py --fit 09   # plus fit_arc of that arc through its run configuration

For each arc the a priori orbit comes from the 2-way Doppler of one station (the one with the
most 60-s points in the arc's first 8 h), its first 5.5 h (:func:`odpipe.od.apriori.determine_orbit`,
DE421, lunar field GrazLGM300c to degree 12, Earth and Sun). It prints the epoch (UTC) and state
as the run configurations' ``[initial_state]`` wants them, the post-fit RMS and the elements.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from odpipe.dynamics import forces as F  # noqa: E402
from odpipe.environment.ephemeris import Ephemeris  # noqa: E402
from odpipe.environment.gravity import read_gravity  # noqa: E402
from odpipe.environment.stations import StationCatalog  # noqa: E402
from odpipe.frames.earth import gcrs_to_itrs  # noqa: E402
from odpipe.frames.moon import moon_pa_to_icrf  # noqa: E402
from odpipe.measurements import MeasurementSetup  # noqa: E402
from odpipe.od.apriori import determine_orbit, doppler_rows  # noqa: E402
from odpipe.pipeline.config import load_config  # noqa: E402
from odpipe.pipeline.ingest import ingest  # noqa: E402
from odpipe.time import tdb_to_utc  # noqa: E402

MOON_MEAN_RADIUS = 1737.4e3  # m (IAU WGCCRE, Archinal et al. 2011)
SPAN = pd.Timedelta(hours=5.5)


def apriori(cfg_path: Path, data_root: Path):
    cfg = load_config(cfg_path)
    data = ingest(list(cfg.data.files))
    rows = doppler_rows(data.table, data.ramps, cfg.arc.spacecraft)
    t0, t1 = pd.Timestamp(cfg.arc.start), pd.Timestamp(cfg.arc.end)
    rows = rows[(rows["epoch"] >= t0) & (rows["epoch"] <= t1)]
    catalog = StationCatalog.default()
    rows = rows[rows["station_rx"].isin(catalog.stations)]  # DSS-27 is not in the catalog (change requested)
    first = rows[rows["epoch"] < rows["epoch"].min() + pd.Timedelta(hours=8)]
    station = first["station_rx"].value_counts().idxmax()
    rows = rows[rows["station_rx"] == station]
    rows = rows[rows["epoch"] < rows["epoch"].min() + SPAN].reset_index(drop=True)
    eph = Ephemeris.open("de421")
    setup = MeasurementSetup(eph, catalog, ramps=data.store, gcrs_to_itrs=gcrs_to_itrs)
    field = read_gravity(data_root / "gravity" / "orekit" / "GrazLGM300c.truncated")
    model = F.ForceModel("moon", [F.PointMasses(["earth", "sun"]), F.SphericalHarmonics("moon", field, 12)],
                         ephemeris=eph, central_gm=field.gm)
    clock = time.perf_counter()
    res = determine_orbit(rows, setup, model, cfg.arc.spacecraft, moon_pa_to_icrf, MOON_MEAN_RADIUS)
    took = time.perf_counter() - clock
    el = res.elements
    utc = str(np.datetime64(tdb_to_utc(np.array([res.epoch]))[0], "ms"))
    print(f"{cfg_path.name}: {station} {len(rows)} rows {rows['epoch'].min()} .. {rows['epoch'].max()}, {took:.0f} s")
    print(f"  post-fit {res.rms_los * 1e3:.0f} mm/s = {res.rms_hz * 1e3:.0f} mHz; candidates:")
    print(res.candidates[["period", "raan", "inc", "arglat", "score", "postfit_rms"]].to_string())
    print(f"  altitude {el['altitude'] / 1e3:.1f} km, period {el['period'] / 60:.2f} min, e {el['e']:.4f}, "
          f"inc {np.degrees(el['inc']):.2f} deg, RAAN {np.degrees(el['raan']):.2f} deg (PA)")
    print(f'  epoch = "{utc}"')
    print("  state = [" + ", ".join(f"{v:.3f}" if i < 3 else f"{v:.6f}" for i, v in enumerate(res.state)) + "]")
    return res


def fit(cfg_path: Path):
    """Run the arc through ``odpipe run`` (ingest .. fit_arc .. products); print its summary and time."""
    from odpipe.pipeline.run import run_config

    clock = time.perf_counter()
    out = run_config(cfg_path, force=True, progress=None)
    print(f"fit of {cfg_path.name}: {time.perf_counter() - clock:.0f} s")
    for key, value in out.items():
        print(f"  {key}: {value}")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fit", help="day of April 2012 (08..11) whose arc to fit through its run configuration")
    ap.add_argument("--data", default=str(ROOT.parent / "shared" / "data"))
    ap.add_argument("--runs", default=str(ROOT / "runs"), help="folder of the run configurations")
    args = ap.parse_args()
    for path in sorted(Path(args.runs).glob("grail_b_2012_04_*.toml")):
        apriori(path, Path(args.data))
    if args.fit:
        fit(Path(args.runs) / f"grail_b_2012_04_{args.fit}.toml")


if __name__ == "__main__":
    main()
