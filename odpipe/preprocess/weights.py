"""Per-station data weights from post-fit residuals (the ARTEMIS practice).

After each fit iteration a station's measurement sigma becomes the RMS of its
post-fit residuals of that observable, iterated to convergence, as the ARTEMIS
orbit determination did (seeds/004, section 4.2.4).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

KEYS = ["station_rx", "observable"]


def station_weights(table: pd.DataFrame, residual: np.ndarray, min_rows: int = 10) -> pd.DataFrame:
    """Per (station_rx, observable): ``rows`` used, residual ``mean``, ``rms`` (unit of the value).

    Only unflagged rows count; groups with fewer than ``min_rows`` rows are left out.
    """
    r = pd.Series(np.asarray(residual, dtype=float), index=table.index)
    used = (table["flags"].to_numpy() == 0) & np.isfinite(r.to_numpy())
    g = r[used].groupby([table.loc[used, k] for k in KEYS])
    w = pd.DataFrame({"rows": g.size(), "mean": g.mean(), "rms": np.sqrt((r[used] ** 2).groupby(
        [table.loc[used, k] for k in KEYS]).mean())}).reset_index()
    return w[w["rows"] >= min_rows].reset_index(drop=True)


def apply_weights(table: pd.DataFrame, weights: pd.DataFrame) -> pd.DataFrame:
    """A copy of ``table`` whose ``sigma`` is its station's post-fit RMS where one is known."""
    out = table.copy()
    rms = out[KEYS].merge(weights[KEYS + ["rms"]], on=KEYS, how="left")["rms"].to_numpy()
    out["sigma"] = np.where(np.isfinite(rms), rms, out["sigma"].to_numpy(dtype=float))
    return out
