"""Count intervals from time tags and back, per the TrackingTable ``tag`` convention.

Times are int64 nanoseconds since 1970-01-01 UTC (the ``epoch`` column's view);
count times are seconds. ODF Doppler is tagged at the middle of its count interval
(``interval_mid``); other formats tag the end or the start.
"""

from __future__ import annotations

import numpy as np

_START_OFFSET = {"interval_mid": 0.5, "interval_end": 1.0, "interval_start": 0.0}


def interval_bounds(epoch_ns: np.ndarray, count_time_s: np.ndarray, tag: np.ndarray):
    """(start, end) of each count interval, int64 ns.

    Raises ValueError for a row with a positive count time whose tag does not
    place the interval (e.g. 'receive').
    """
    epoch_ns = np.asarray(epoch_ns, dtype=np.int64)
    ct_ns = np.rint(np.nan_to_num(np.asarray(count_time_s, dtype=float)) * 1e9).astype(np.int64)
    tag = np.asarray(tag, dtype=object)
    frac = np.full(len(epoch_ns), np.nan)
    for name, f in _START_OFFSET.items():
        frac[tag == name] = f
    bad = np.isnan(frac) & (ct_ns > 0)
    if bad.any():
        raise ValueError(f"time tag {tag[bad][0]!r} does not place a count interval")
    frac = np.nan_to_num(frac)
    start = epoch_ns - np.rint(frac * ct_ns).astype(np.int64)
    return start, start + ct_ns


def tag_epoch(start_ns: np.ndarray, end_ns: np.ndarray, tag: np.ndarray) -> np.ndarray:
    """Time tag (int64 ns) of intervals [start, end) under each row's ``tag`` convention."""
    start_ns = np.asarray(start_ns, dtype=np.int64)
    length = np.asarray(end_ns, dtype=np.int64) - start_ns
    frac = np.zeros(len(start_ns))
    tag = np.asarray(tag, dtype=object)
    for name, f in _START_OFFSET.items():
        frac[tag == name] = f
    return start_ns + np.rint(frac * length).astype(np.int64)
