"""Receiver lock transients at the start of Doppler series.

A one-way Doppler series starts when the station's receiver acquires the spacecraft's carrier; a two-way
series when the transponder locks to the swept-in uplink and turns the downlink coherent, a frequency step
the receiver locks to again. Until its carrier loop has settled, the counted frequency is off by far more
than the noise, for a few seconds. The 60-s windows of compression average the transient into the
series' first point, where the spike tests, which judge a row by its neighbours on both sides, see only
one side. GRAIL-B 2012-04-09, DSS-65's X-band one-way from 04:34:42 UTC: the first three 1-s samples are
+8.0, +19.6 and +5.1 Hz off the next ten minutes' smooth course, where those samples scatter by 0.03-0.08 Hz;
averaged into the first 60-s point they make it +20.0 mm/s (the one-way fit's residual there: +18.9).

The test judges each contiguous raw series (one link, equally spaced samples at their own count time)
against itself, before compression: fourth differences cancel a signal smooth to degree 3 over five
samples, and their robust scale (MAD about zero) over the whole series is the noise's. The series is settled
at the first of ``CLEAN_RUN`` consecutive fourth differences within ``k`` such sigmas; the samples before
it are the transient. Settling later than ``MAX_LOCK_S`` after the first sample is not a lock transient
(then nothing is flagged: a noisy series is left to the other tests).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.tracking.passes import LINK

from .compress import RATE_UNITS   # count-averaged Doppler (running counts in cycles are not judged)
from .robust import MAD_TO_SIGMA

MAX_LOCK_S = 60.0   # s: one compressed window; carrier loops settle within seconds
CLEAN_RUN = 3       # consecutive fourth differences within bounds: the loop has settled
SPACING_TOL = 1e-3  # s: samples this close to one count time apart are back to back


def settled_at(values: np.ndarray, k: float) -> int:
    """Index of the first sample after the transient of one contiguous, equally spaced series (0: none);
    -1 when the series never settles or is too short to judge (fewer than 4 + ``CLEAN_RUN`` samples)."""
    v = np.asarray(values, dtype=float)
    if len(v) < 4 + CLEAN_RUN:
        return -1
    d4 = v[4:] - 4 * v[3:-1] + 6 * v[2:-2] - 4 * v[1:-3] + v[:-4]
    scale = MAD_TO_SIGMA * np.median(np.abs(d4))
    if not scale > 0:
        return -1
    ok = np.abs(d4) <= k * scale
    run = np.convolve(ok, np.ones(CLEAN_RUN, dtype=int), "valid") == CLEAN_RUN   # run[j]: d4[j..j+2] all ok
    hit = np.flatnonzero(run)
    return int(hit[0]) if len(hit) else -1


def lock_transients(table: pd.DataFrame, k: float, max_lock_s: float = MAX_LOCK_S) -> np.ndarray:
    """True for the unflagged raw Doppler rows (``doppler_*`` in Hz or m/s, ``count_time`` > 0) in a lock transient:
    the samples at the start of each contiguous series before it settles (:func:`settled_at`), when it
    settles within ``max_lock_s`` s of the series' first sample."""
    bad = np.zeros(len(table), dtype=bool)
    ct = table["count_time"].to_numpy(dtype=float)
    doppler = table["observable"].astype(str).str.startswith("doppler").to_numpy()
    use = doppler & table["unit"].isin(RATE_UNITS).to_numpy() & (ct > 0) & (table["flags"].to_numpy() == 0)
    if not use.any():
        return bad
    sub = table[use]
    t = sub["epoch"].to_numpy("datetime64[ns]").astype(np.int64) / 1e9
    link = sub.groupby(LINK, sort=False, dropna=False).ngroup().to_numpy()
    order = np.lexsort((t, link))
    ts, cs, ls = t[order], ct[use][order], link[order]
    # a new series at a new link, a change of count time, or a step other than one count time
    new = np.r_[True, (ls[1:] != ls[:-1]) | (cs[1:] != cs[:-1]) | (np.abs(np.diff(ts) - cs[1:]) > SPACING_TOL)]
    starts = np.flatnonzero(new)
    values = sub["value"].to_numpy(dtype=float)[order]
    flagged = np.zeros(len(sub), dtype=bool)
    for a, b in zip(starts, np.r_[starts[1:], len(sub)]):
        j = settled_at(values[a:b], k)
        if j > 0 and ts[a + j] - ts[a] <= max_lock_s:
            flagged[a:a + j] = True
    bad[np.flatnonzero(use)[order[flagged]]] = True
    return bad
