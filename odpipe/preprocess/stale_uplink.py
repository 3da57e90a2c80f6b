"""An instant a fixed time into the uplink ramp record in force at each row's tag.

MESSENGER's odf07155 has range passes whose points read the uplink phase not at reception but 599 s into
the 20-min ramp record holding the tag (when the tag is that late in it): the ``uplink_epoch`` that
:func:`odpipe.measurements.dsn.dsn_range` accepts (docs/validation.md, MESSENGER).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.preprocess.flags import Flag


def into_segment(ramps: pd.DataFrame, station, epochs, seconds: float) -> np.ndarray:
    """UTC datetime64[ns] per row: ``seconds`` (s) after the start of ``station``'s ramp record covering
    ``epochs``; NaT where the tag comes earlier than that in its record or no record covers it."""
    station = np.broadcast_to(np.asarray(station, dtype=object), np.shape(epochs))
    t = np.asarray(epochs, dtype="datetime64[ns]")
    out = np.full(t.shape, np.datetime64("NaT"), dtype="datetime64[ns]")
    step = np.timedelta64(int(round(seconds * 1e9)), "ns")
    for st in np.unique(station):
        g = ramps[ramps["station"] == st].sort_values("start", kind="stable")
        start, end = g["start"].to_numpy("datetime64[ns]"), g["end"].to_numpy("datetime64[ns]")
        mine = np.flatnonzero(station == st)
        k = np.searchsorted(start, t[mine], side="right") - 1
        ok = k >= 0
        at = np.where(ok, start[np.maximum(k, 0)] + step, np.datetime64("NaT"))
        ok &= (t[mine] < end[np.maximum(k, 0)]) & (at <= t[mine])
        out[mine[ok]] = at[ok]
    return out


def stale_uplink_range(table: pd.DataFrame, ramps: pd.DataFrame, sections) -> tuple[pd.DataFrame, tuple[int, int]]:
    """Apply ``[[preprocess.range_uplink_epoch]]`` sections (start, end, station_rx, into_ramp_s) to ``table``.

    Range rows in a section's window get ``uplink_epoch`` = :func:`into_segment` of their transmitter; those
    tagged earlier in their ramp record are flagged USER. Returns the table and (rows removed, rows given an epoch).
    """
    out = table.copy()
    if "uplink_epoch" not in out.columns:
        out["uplink_epoch"] = np.full(len(out), np.datetime64("NaT"), dtype="datetime64[ns]")
    epoch = out["epoch"].to_numpy("datetime64[ns]")
    removed = read = 0
    for w in sections:
        mine = (out["observable"] == "range").to_numpy() & (epoch >= np.datetime64(w.start, "ns")) \
            & (epoch <= np.datetime64(w.end, "ns"))
        if w.station_rx:
            mine &= (out["station_rx"] == w.station_rx).to_numpy()
        idx = np.flatnonzero(mine)
        at = into_segment(ramps, out["station_tx"].to_numpy(object)[idx], epoch[idx], w.into_ramp_s)
        late = ~np.isnat(at)
        out.loc[out.index[idx[late]], "uplink_epoch"] = at[late]
        out.loc[out.index[idx[~late]], "flags"] = out["flags"].to_numpy()[idx[~late]] | int(Flag.USER)
        removed, read = removed + int((~late).sum()), read + int(late.sum())
    return out, (removed, read)
