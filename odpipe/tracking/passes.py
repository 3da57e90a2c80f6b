"""Tracking passes: runs of one link's samples without gaps or configuration changes.

A link is (station_tx, station_rx, spacecraft, observable, band_up, band_down).
A new pass starts after a gap longer than ``max_gap`` (s, from the end of one
count interval to the start of the next) and than ``gap_factor`` times the
link's median sample spacing (sparse range points are not passes each), when the count time, the ramped flag or
the (unramped) uplink frequency changes, or at an uplink ramp discontinuity.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.tracking import ramp_segments
from odpipe.tracking.timetags import interval_bounds

LINK = ["station_tx", "station_rx", "spacecraft", "observable", "band_up", "band_down"]


def link_id(table: pd.DataFrame) -> np.ndarray:
    """Integer id of each row's link (same id = same link)."""
    return table.groupby(LINK, sort=True, dropna=False).ngroup().to_numpy()


def _changed(x: np.ndarray) -> np.ndarray:
    """True where x[i] differs from x[i-1] (NaN equals NaN); False at i=0."""
    out = np.zeros(len(x), dtype=bool)
    if len(x) > 1:
        a, b = x[1:], x[:-1]
        if a.dtype.kind == "f":
            out[1:] = ~((a == b) | (np.isnan(a) & np.isnan(b)))
        else:
            out[1:] = a != b
    return out


def assign_passes(table: pd.DataFrame, ramps: pd.DataFrame | None = None, *, max_gap: float = 600.0,
                  gap_factor: float = 3.0, jump_tol_hz: float = 1.0, ramp_delay: float = 0.0) -> pd.DataFrame:
    """A copy of ``table`` with ``pass_id`` set (0..P-1, numbered by link then time).

    Ramp jumps count ``ramp_delay`` s (e.g. the round-trip light time) after they are transmitted.
    """
    out = table.copy()
    if len(out) == 0:
        return out
    epoch = out["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64)
    start, end = interval_bounds(epoch, out["count_time"].to_numpy(), out["tag"].to_numpy())
    link = link_id(out)
    order = np.lexsort((start, link))
    jumps = ramp_segments.segment_index(out["station_tx"].to_numpy(), out["ramped"].to_numpy(),
                                        start - int(round(ramp_delay * 1e9)), ramps, jumps_only=True,
                                        jump_tol_hz=jump_tol_hz)
    new = np.zeros(len(out), dtype=bool)
    new[0] = True
    # end of the link's latest interval so far (overlapping counts allowed)
    prev_end = pd.Series(end[order]).groupby(link[order]).cummax().to_numpy()
    gap_s = (start[order][1:] - prev_end[:-1]) / 1e9
    step = pd.Series(np.diff(start[order]) / 1e9)
    same = link[order][1:] == link[order][:-1]
    spacing = step[same].groupby(link[order][1:][same]).median()  # s, each link's usual sample spacing
    allowed = np.maximum(max_gap, gap_factor * pd.Series(link[order][1:]).map(spacing).fillna(0).to_numpy())
    new[1:] |= gap_s > allowed
    # a zero count time (the origin sample of running counts) takes its link's next count time: it opens
    # the pass its counts continue instead of making a pass of its own
    ct = pd.Series(out["count_time"].to_numpy(dtype=float)[order]).replace(0.0, np.nan)
    ct = ct.groupby(link[order]).bfill().fillna(0.0).to_numpy()
    new |= _changed(ct)
    for col in (link, out["ramped"].to_numpy(dtype=bool), out["uplink_hz"].to_numpy(dtype=float), jumps):
        new |= _changed(np.asarray(col)[order])
    pass_sorted = np.cumsum(new) - 1
    pid = np.empty(len(out), dtype=np.int64)
    pid[order] = pass_sorted
    out["pass_id"] = pid
    return out


def pass_summary(table: pd.DataFrame) -> pd.DataFrame:
    """One row per pass: link, start, end (UTC tags), samples, count time (s), ramped."""
    g = table.groupby("pass_id", sort=True)
    first = g[LINK + ["count_time", "ramped"]].first()
    return first.assign(start=g["epoch"].min(), end=g["epoch"].max(), samples=g.size()).reset_index()
