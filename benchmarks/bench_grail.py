"""GRAIL-B a priori orbits for the daily arcs, and optionally one arc fit end to end (figures printed, never asserted).

    python benchmarks/bench_grail.py            # a priori state of every runs/grail_b_2012_04_*.toml arc
    python benchmarks/bench_grail.py --fit 09   # plus fit_arc of that arc through its run configuration

For each arc the a priori orbit comes from :func:`odpipe.pipeline.apriori.doppler_apriori` (what
``odpipe apriori`` runs): the 2-way Doppler of the station with the most 60-s points in the arc's first
8 h, its first 5.5 h, the arc's lunar field to degree 12, Earth and Sun. It prints the epoch (UTC) and
state as ``[initial_state]``, the post-fit RMS, the elements and the time taken.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from odpipe.pipeline.apriori import doppler_apriori, initial_state_toml  # noqa: E402
from odpipe.pipeline.config import load_config  # noqa: E402


def apriori(cfg_path: Path):
    """Time :func:`odpipe.pipeline.apriori.doppler_apriori` (what ``odpipe apriori`` runs) on one arc."""
    clock = time.perf_counter()
    res, rows = doppler_apriori(load_config(cfg_path))
    took = time.perf_counter() - clock
    el = res.elements
    print(f"{cfg_path.name}: {rows['station_rx'].iloc[0]} {len(rows)} rows {rows['epoch'].min()} .. "
          f"{rows['epoch'].max()}, {took:.0f} s")
    print(f"  post-fit {res.rms_los * 1e3:.0f} mm/s = {res.rms_hz * 1e3:.0f} mHz; candidates:")
    print(res.candidates[["period", "raan", "inc", "arglat", "score", "postfit_rms"]].to_string())
    print(f"  altitude {el['altitude'] / 1e3:.1f} km, period {el['period'] / 60:.2f} min, e {el['e']:.4f}, "
          f"inc {np.degrees(el['inc']):.2f} deg, RAAN {np.degrees(el['raan']):.2f} deg (PA)")
    print(initial_state_toml(res))
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
    ap.add_argument("--runs", default=str(ROOT / "runs"), help="folder of the run configurations")
    args = ap.parse_args()
    for path in sorted(Path(args.runs).glob("grail_b_2012_04_*.toml")):
        apriori(path)
    if args.fit:
        fit(Path(args.runs) / f"grail_b_2012_04_{args.fit}.toml")


if __name__ == "__main__":
    main()
