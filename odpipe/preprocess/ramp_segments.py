"""Which uplink ramp segment each sample was counted under, and where ramps jump.

A ramp table (:data:`parsers.table.RAMP_COLUMNS`) lists linear segments per
transmitting station. A new segment whose start frequency differs from the
previous segment extrapolated to that instant is a *discontinuity* (a jump).
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def _sorted(ramps: pd.DataFrame) -> pd.DataFrame:
    return ramps.sort_values(["station", "start"], kind="stable")


def ramp_jumps(ramps: pd.DataFrame, tol_hz: float = 1.0) -> pd.Series:
    """True for ramp rows that start with a frequency jump > ``tol_hz`` (Hz) from the previous segment.

    The first segment of a station is not a jump. Index as ``ramps``.
    """
    r = _sorted(ramps)
    same = r["station"].to_numpy() == np.roll(r["station"].to_numpy(), 1)
    same[:1] = False
    dt = (r["start"] - r["start"].shift(1)).dt.total_seconds().to_numpy()
    predicted = r["freq_hz"].shift(1).to_numpy() + r["rate_hz_s"].shift(1).to_numpy() * dt
    jump = same & (np.abs(r["freq_hz"].to_numpy() - predicted) > tol_hz)
    return pd.Series(jump, index=r.index).reindex(ramps.index)


def segment_index(station_tx, ramped, start_ns, ramps: pd.DataFrame | None, *, jumps_only: bool = False):
    """For each sample, the position (in ``ramps``' station-sorted order) of the ramp in effect at ``start_ns``.

    With ``jumps_only`` the count is of jumps up to that time instead, so it
    changes only at discontinuities. -1 where the sample is not ramped or no
    ramp of its station has started yet.
    """
    n = len(start_ns)
    out = np.full(n, -1, dtype=np.int64)
    if ramps is None or len(ramps) == 0:
        return out
    r = _sorted(ramps)
    starts = r["start"].to_numpy().astype("datetime64[ns]").view(np.int64)
    jump = ramp_jumps(r).to_numpy()
    station_tx = np.asarray(station_tx, dtype=object)
    ramped = np.asarray(ramped, dtype=bool)
    stations = r["station"].to_numpy()
    for st in np.unique(stations):
        lo, hi = np.searchsorted(stations, st, "left"), np.searchsorted(stations, st, "right")
        rows = np.flatnonzero(ramped & (station_tx == st))
        k = np.searchsorted(starts[lo:hi], start_ns[rows], side="right") - 1
        if jumps_only:
            marks = np.concatenate([[0], np.cumsum(jump[lo:hi])])
            out[rows] = np.where(k >= 0, lo + marks[k + 1], -1)
        else:
            out[rows] = np.where(k >= 0, lo + k, -1)
    return out
