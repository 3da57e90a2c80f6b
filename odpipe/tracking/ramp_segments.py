"""Which uplink ramp segment each sample was counted under, and where ramps are discontinuous.

Ramps go through :class:`parsers.ramps.RampStore`, which merges, deduplicates and
checks them; its ``jump`` findings (a retuning) and ``gap`` findings (no ramp
in force) are the discontinuities that end a pass.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from parsers.ramps import RampStore


def store(ramps, jump_tol_hz: float = 1.0) -> RampStore | None:
    """A RampStore from a ramp table (or the store itself); None when there are no ramps."""
    if ramps is None or isinstance(ramps, RampStore):
        return ramps
    return RampStore(ramps, jump_tol_hz=jump_tol_hz) if len(ramps) else None


def discontinuities(rs: RampStore) -> pd.DataFrame:
    """Per station, the UTC instants where the uplink frequency jumps or a coverage gap ends."""
    f = rs.findings
    jump = f.loc[f["kind"] == "jump", ["station", "start"]].rename(columns={"start": "at"})
    gap = f.loc[f["kind"] == "gap", ["station", "end"]].rename(columns={"end": "at"})
    out = pd.concat([jump, gap], ignore_index=True)
    out["at"] = pd.to_datetime(out["at"]).astype("datetime64[ns]")
    return out.sort_values(["station", "at"], kind="stable").reset_index(drop=True)


def segment_index(station_tx, ramped, start_ns, ramps, *, jumps_only: bool = False,
                  jump_tol_hz: float = 1.0) -> np.ndarray:
    """Label of the ramp segment in force at each sample's ``start_ns`` (int64 ns), per station.

    With ``jumps_only`` the label counts discontinuities instead, so it changes
    only where the ramp is discontinuous. -1 for unramped samples and before a
    station's first ramp.
    """
    out = np.full(len(start_ns), -1, dtype=np.int64)
    rs = store(ramps, jump_tol_hz)
    if rs is None:
        return out
    if jumps_only:
        marks = discontinuities(rs)
        times, stations = marks["at"].to_numpy().view(np.int64), marks["station"].to_numpy()
    else:
        times = rs.segments["start"].to_numpy().astype("datetime64[ns]").view(np.int64)
        stations = rs.segments["station"].to_numpy()
    station_tx = np.asarray(station_tx, dtype=object)
    ramped = np.asarray(ramped, dtype=bool)
    start_ns = np.asarray(start_ns, dtype=np.int64)
    for st in np.unique(rs.segments["station"].to_numpy()):
        mine = np.flatnonzero(stations == st)
        rows = np.flatnonzero(ramped & (station_tx == st))
        k = np.searchsorted(times[mine], start_ns[rows], side="right")
        out[rows] = k if jumps_only else np.where(k > 0, mine[0] + k - 1 if len(mine) else -1, -1)
    return out
