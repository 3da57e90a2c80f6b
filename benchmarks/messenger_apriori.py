"""The a priori orbit of runs/messenger_2007_06_04_doppler.toml from the arc's own two-way Doppler and the flyby epoch.

MESSENGER flew by Venus on 2007-06-05 at 23:08 UTC, 338 km above the surface (mission reports); the run finds its
a priori in-run (``[initial_state] from_flyby``, :func:`odpipe.pipeline.apriori.flyby_search`), assuming only the
epoch. This prints that search: its candidates, the post-fit line-of-sight RMS, the closest approach it finds
beside the published one, and the state about the Sun the run starts from.
Run: ``python benchmarks/messenger_apriori.py`` (a few minutes).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from odpipe.pipeline.apriori import flyby_apriori, flyby_search
from odpipe.pipeline.config import load_config
from odpipe.time import tdb_to_utc

ROOT = Path(__file__).resolve().parents[1]
FLYBY_ALTITUDE, VENUS_RADIUS = 338e3, 6051.8e3


def main():
    t = time.perf_counter()
    cfg = load_config(ROOT / "runs/messenger_2007_06_04_doppler.toml")
    res = flyby_search(cfg)
    print(res.candidates.to_string())
    print(f"post-fit line-of-sight RMS {res.rms_los * 1e3:.1f} mm/s of {int((res.rows['flags'] == 0).sum())} rows")
    print(f"closest approach {res.periapsis / 1e3:.0f} km from Venus's centre at "
          f"{np.datetime64(tdb_to_utc(np.array([res.periapsis_epoch]))[0], 's')} UTC "
          f"(published: {(VENUS_RADIUS + FLYBY_ALTITUDE) / 1e3:.0f} km at {cfg.initial_state.from_flyby.epoch})")
    epoch, sun = flyby_apriori(cfg, res)
    utc = np.datetime64(tdb_to_utc(np.array([epoch]))[0], "ms")
    print(f"a priori at {utc} UTC, ICRF about the Sun: " + ", ".join(f"{v:.3f}" for v in sun[:3]) + " m, "
          + ", ".join(f"{v:.6f}" for v in sun[3:]) + " m/s")
    print(f"{time.perf_counter() - t:.0f} s")


if __name__ == "__main__":
    main()
