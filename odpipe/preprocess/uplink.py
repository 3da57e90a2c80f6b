"""Uplink acquisitions: spans when a station's uplink is not yet in lock, so two/three-way data
do not follow its ramp table.

A DSN uplink acquisition retunes the exciter (a frequency *jump* in the ramp
table), turns the transmitter on and sweeps the uplink through the
spacecraft receiver's best-lock frequency (ramps of the order of 100 Hz/s)
before the tracking ramps start. Until the sweep ends, the spacecraft is not
locked to the ramp the table lists, and two/three-way data whose transmit
interval falls in that span are not coherent with it. In the MESSENGER ODF
odf07155 (DSS-63, 2007-06-04 20:10:28 retune, 20:38:23-20:39:44 sweep) such
Doppler sits 290 m/s off the rest of the pass while every other ramp join
(hundreds of 20-min ramp segments) leaves the residuals continuous to 0.3 m/s.

An acquisition is the span from a jump to the end of the sweep that starts
within ``max_lead`` s after it, and every sweep on its own. A jump with no
sweep after it (an in-lock retune) is no acquisition.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.tracking.timetags import interval_bounds
from parsers.ramps import RampStore

UPLINK_OBSERVABLES = ("doppler_2way", "doppler_3way", "range")


def acquisitions(rs: RampStore, sweep_rate: float = 10.0, max_lead: float = 3600.0,
                 max_pause: float = 120.0) -> pd.DataFrame:
    """Per station, UTC spans (``station``, ``start``, ``end``) of uplink acquisitions.

    ``sweep_rate``: |ramp rate| (Hz/s) above which a segment is a sweep;
    ``max_lead``: longest time (s) from a retune to the sweep that completes it;
    ``max_pause``: sweeps (up and down) less than this apart (s) are one sweep.
    """
    seg = rs.segments
    jumps = rs.findings[rs.findings["kind"] == "jump"]
    pause = np.timedelta64(int(max_pause * 1e9), "ns")
    lead = np.timedelta64(int(max_lead * 1e9), "ns")
    rows = []
    for station, g in seg.groupby("station", sort=True):
        sweeps = _merged(g[np.abs(g["rate_hz_s"].to_numpy(float)) > sweep_rate], pause)
        rows += [(station, a, b) for a, b in sweeps]
        starts = np.array([a for a, _ in sweeps], dtype="datetime64[ns]")
        for at in jumps.loc[jumps["station"] == station, "start"].to_numpy().astype("datetime64[ns]"):
            k = np.searchsorted(starts, at)
            if k < len(starts) and starts[k] - at <= lead:
                rows.append((station, at, sweeps[k][1]))
    out = pd.DataFrame(rows, columns=["station", "start", "end"])
    return out.sort_values(["station", "start"], kind="stable").reset_index(drop=True)


def _merged(sweep: pd.DataFrame, pause) -> list:
    """Sweep segments joined into (start, end) spans where less than ``pause`` apart."""
    spans = []
    for a, b in zip(sweep["start"].to_numpy().astype("datetime64[ns]"), sweep["end"].to_numpy().astype("datetime64[ns]")):
        if spans and a <= spans[-1][1] + pause:
            spans[-1] = (spans[-1][0], max(spans[-1][1], b))
        else:
            spans.append((a, b))
    return spans


def in_acquisition(table: pd.DataFrame, rs: RampStore | None, sweep_rate: float = 10.0,
                   max_lead: float = 3600.0) -> np.ndarray:
    """Two/three-way rows whose transmit interval overlaps an acquisition of their ``station_tx``.

    The transmit interval is the count interval moved back by the round-trip
    light time (``rtlt_s`` column, s; rows without it are not judged).
    """
    hit = np.zeros(len(table), dtype=bool)
    if rs is None or "rtlt_s" not in table or not len(table):
        return hit
    spans = acquisitions(rs, sweep_rate, max_lead)
    if not len(spans):
        return hit
    obs = table["observable"].to_numpy()
    rtlt = table["rtlt_s"].to_numpy(dtype=float)
    use = np.isin(obs, UPLINK_OBSERVABLES) & np.isfinite(rtlt)
    if not use.any():
        return hit
    sub = table[use]
    t0, t1 = interval_bounds(sub["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64),
                             sub["count_time"].to_numpy(dtype=float), sub["tag"].to_numpy())
    back = np.rint(rtlt[use] * 1e9).astype(np.int64)
    t0, t1 = t0 - back, t1 - back
    tx = sub["station_tx"].to_numpy()
    found = np.zeros(len(sub), dtype=bool)
    for station, g in spans.groupby("station"):
        mine = tx == station
        a = g["start"].to_numpy().astype("datetime64[ns]").view(np.int64)
        b = g["end"].to_numpy().astype("datetime64[ns]").view(np.int64)
        found[mine] = ((t0[mine, None] <= b[None, :]) & (t1[mine, None] >= a[None, :])).any(axis=1)
    hit[np.flatnonzero(use)] = found
    return hit
