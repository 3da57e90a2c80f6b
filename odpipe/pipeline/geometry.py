"""Station–spacecraft geometry of every row from a reference trajectory.

Adds ``elevation_rx`` and ``azimuth_rx`` (rad, at the receiving station, of the
light-time-corrected spacecraft direction) and ``rtlt_s`` (round-trip light
time, s), which the media and editing stages use. Accuracy needed there is
modest (mdeg, ms), so the light time is iterated twice in the geocentric frame
and aberration is left out. Rows outside the trajectory's span, or with a
receiver the catalog does not know, get NaN.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.environment.stations import topocentric
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.time import utc_to_tdb

C_LIGHT = 299_792_458.0


def add_geometry(table: pd.DataFrame, trajectory, ephemeris, catalog) -> pd.DataFrame:
    """A copy of ``table`` with ``elevation_rx``, ``azimuth_rx``, ``rtlt_s``."""
    out = table.copy()
    n = len(out)
    el, az, rtlt = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    epochs = out["epoch"].to_numpy("datetime64[ns]")
    t = np.asarray(utc_to_tdb(epochs), float)
    lo, hi = sorted((trajectory.t0, trajectory.t1))
    for station, idx in out.groupby("station_rx", sort=False).indices.items():
        try:
            st = catalog[station]
        except KeyError:
            continue
        idx = idx[(t[idx] >= lo + 2.0) & (t[idx] <= hi)]
        if idx.size == 0:
            continue
        e, ti = epochs[idx], t[idx]
        rot = gcrs_to_itrs(e)
        r_sta = np.einsum("nji,nj->ni", rot, st.position_itrs(e))  # GCRS
        lt = np.zeros(idx.size)
        for _ in range(2):
            r_sc = _geocentric(trajectory, ephemeris, ti - lt)
            lt = np.linalg.norm(r_sc - r_sta, axis=1) / C_LIGHT
        a, el_i, rng = topocentric(st, np.einsum("nij,nj->ni", rot, r_sc), e)
        el[idx], az[idx], rtlt[idx] = el_i, a, 2.0 * rng / C_LIGHT
    out["elevation_rx"], out["azimuth_rx"], out["rtlt_s"] = el, az, rtlt
    return out


def _geocentric(trajectory, ephemeris, t):
    r = trajectory.state(t)[:, :3]
    if trajectory.center != "earth":
        r = r + ephemeris.position(trajectory.center, "earth", t)
    return r
