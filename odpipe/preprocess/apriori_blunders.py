"""Blunders against the a priori orbit: the spike test of :mod:`.robust` on each pass's a priori residuals.

The preprocessing spike test judges a pass's observed values against their neighbours, which needs
equally spaced rows of a signal smooth over the spacing. Ramped lunar-orbiter Doppler is neither: its
compressed windows follow the uplink ramp segments (60-s counts 60-240 s apart) and the values swing by
m/s between windows, so a 44 mm/s blunder passes unseen (GRAIL-B 2012-04-10, DSS-34's first window after
the uplink acquisition). Against an a priori orbit good to km the residuals change by about a mm/s from
row to row, so the same test on the residuals, each pass's rows taken in time order as equally spaced,
finds it; the fit's own innovation test cannot always, because after a tracking gap the predicted
uncertainty it judges by is large.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.measurements import MeasurementSetup, compute, residuals

from .robust import spikes


def apriori_blunders(rows: pd.DataFrame, trajectory, setup: MeasurementSetup, spacecraft: str, k: float,
                     use: np.ndarray) -> np.ndarray:
    """True for the ``use`` rows whose a priori residual (along the line of sight, ``trajectory`` as the
    spacecraft's orbit) misses the quadratic through its three neighbours on both sides by more than
    ``k`` robust sigmas of its pass and link (:func:`.robust.spikes`)."""
    use = np.asarray(use, bool)
    sub = rows[use]   # only these are computed: the other rows may lie outside the a priori orbit's span
    _, res = residuals(sub, compute(sub, {spacecraft: trajectory}, setup))
    group = pd.factorize(sub["observable"].astype(str) + ":" + sub["station_rx"].astype(str) + ":"
                         + sub["station_tx"].astype(str) + ":" + sub["pass_id"].astype(str))[0]
    rank = pd.Series(sub["epoch"].to_numpy("datetime64[ns]").astype(np.int64)).groupby(group).rank(method="first")
    bad = np.zeros(len(rows), bool)
    bad[np.flatnonzero(use)] = spikes((rank.to_numpy() * 1e9).astype(np.int64), res, group, k, np.isfinite(res))
    return bad
