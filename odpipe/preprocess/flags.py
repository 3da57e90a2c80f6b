"""Edit reasons: the bits of the TrackingTable ``flags`` column.

A row with ``flags == 0`` is used by the fit; any set bit says why it is not.
"""

from __future__ import annotations

import enum

import numpy as np
import pandas as pd

from parsers import table as tt


class Flag(enum.IntFlag):
    """One bit per edit reason."""

    ELEVATION = 1 << 0       # below the station elevation mask
    DUPLICATE = tt.DUPLICATE  # same sample already present (first occurrence kept); readers set it too
    INVALID = tt.INVALID      # the format marks the record invalid, or the value is not finite (set at read)
    BLUNDER = 1 << 3         # gross outlier of the detrended signal (median/MAD)
    AMBIGUITY = 1 << 4       # range outside its modulus or ambiguous against the model
    USER = 1 << 5            # analyst's edit window
    SHORT_PASS = 1 << 6      # pass too short (few samples or short duration)
    OUTSIDE_ARC = 1 << 7     # outside the fit arc
    RESIDUAL = 1 << 8        # residual outlier during the fit
    PARTIAL_COUNT = 1 << 9   # compressed sample shorter than the target count time
    UPLINK = 1 << 10         # transmitted during an uplink acquisition (retune, sweep): not on the ramp table
    NONFINITE = 1 << 11      # value, sigma, computed value or partials NaN or infinite, or sigma <= 0


def names(value: int) -> list[str]:
    """Names of the reasons set in one ``flags`` value, lowest bit first."""
    return [f.name.lower() for f in Flag if int(value) & int(f)]


def set_flag(flags: np.ndarray, mask: np.ndarray, reason: Flag) -> np.ndarray:
    """``flags`` with ``reason`` OR-ed into the rows where ``mask`` is true (new array)."""
    out = np.asarray(flags, dtype=np.int64).copy()
    out[np.asarray(mask, dtype=bool)] |= int(reason)
    return out


def summary(flags) -> pd.DataFrame:
    """Rows edited per reason: columns ``reason``, ``rows`` (a row with two reasons counts in both).

    The last line, ``used``, counts rows with no flag set.
    """
    f = np.asarray(flags, dtype=np.int64)
    rows = [(fl.name.lower(), int(np.count_nonzero(f & int(fl)))) for fl in Flag]
    rows.append(("used", int(np.count_nonzero(f == 0))))
    return pd.DataFrame(rows, columns=["reason", "rows"])
