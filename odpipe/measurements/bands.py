"""Radio bands: transponder turnaround ratios and range-unit factors.

Facts from Moyer, *Formulation for Observed and Computed Values of Deep Space
Network Data Types for Navigation* (DESCANSO Monograph 2), chapter 13, and the
DSN Telecommunications Link Design Handbook (810-005):

* turnaround ratio M2 = f_down / f_up of a coherent transponder, per band pair;
* range unit (RU): sequential and PN range is counted in cycles of a signal
  derived from the uplink. The range in RU accumulated between transmission t1
  and reception t3 is ``F * integral(f_up dt, t1, t3)`` with
  F = 1/2 (S-band uplink), 221/(749*2) (X-band uplink), 221/(3599*2) (Ka-band uplink).
  One RU is therefore about 1/(F f_up) seconds of round-trip light time.
"""

from __future__ import annotations

import numpy as np

# (uplink band, downlink band) -> M2 = f_down / f_up
TURNAROUND = {
    ("S", "S"): 240 / 221,
    ("S", "X"): 880 / 221,
    ("X", "S"): 240 / 749,
    ("X", "X"): 880 / 749,
    ("X", "Ka"): 3344 / 749,
    ("Ka", "Ka"): 3360 / 3599,
}

# downlink band -> factor from an S-band-scale one-way reference to the downlink (ODF convention)
ONE_WAY_SCALE = {"S": 1.0, "X": 880 / 240, "Ka": 3344 / 240}

# uplink band -> F (range units per cycle of uplink)
RANGE_UNIT_FACTOR = {"S": 1 / 2, "X": 221 / (749 * 2), "Ka": 221 / (3599 * 2)}


def turnaround_ratio(band_up, band_down) -> np.ndarray:
    """M2 = f_down/f_up per row (dimensionless); NaN where the band pair is unknown or one-way."""
    up = np.atleast_1d(np.asarray(band_up, dtype=object)).astype(str)
    down = np.broadcast_to(np.atleast_1d(np.asarray(band_down, dtype=object)).astype(str), up.shape)
    pairs, inv = np.unique(np.char.add(np.char.add(up, "/"), down), return_inverse=True)
    table = np.array([TURNAROUND.get(tuple(band_name(b) for b in p.split("/", 1)), np.nan) for p in pairs])
    return table[inv.ravel()]


def range_unit_factor(band_up) -> np.ndarray:
    """F per row (RU per uplink cycle); NaN for an unknown band."""
    up = np.atleast_1d(np.asarray(band_up, dtype=object)).astype(str)
    names, inv = np.unique(up, return_inverse=True)
    return np.array([RANGE_UNIT_FACTOR.get(band_name(u), np.nan) for u in names])[inv.ravel()]


def band_name(band) -> str:
    """Canonical band name: S, X, Ka (case-insensitive input)."""
    b = str(band).strip()
    return "Ka" if b.upper() == "KA" else b.upper()


def downlink_bands(rows) -> np.ndarray:
    """Each tracking row's downlink band name (S, X, Ka) from its ``band_down``; "" where a row has none
    (laser range, crosslinks, tables without the column)."""
    if "band_down" not in rows:
        return np.full(len(rows), "", dtype=object)
    codes = rows["band_down"].astype(object).where(rows["band_down"].notna(), "").astype(str)
    names = {b: band_name(b) if b else "" for b in codes.unique()}
    return codes.map(names).to_numpy(object)
