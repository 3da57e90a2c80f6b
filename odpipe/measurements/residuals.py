"""Residuals observed - computed, in the observable's unit and along the line of sight.

Range rows with a finite ``range_modulus`` (TRK-2-34) or ``range_modulus_ru`` (ODF), in RU, are wrapped into [-M/2, M/2):
the ambiguity is resolved to the computed value; azimuth residuals are wrapped into
[-pi, pi) (a track across north). The line-of-sight form multiplies by
:attr:`Evaluation.to_los`: metres of one-way range for range types (RU -> m: c / (2 F f_up)), m/s of
range-rate for Doppler (Hz -> m/s: c / (2 M2 f_up) two/three-way, c / f one-way), metres across the sky
for angles.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


def residuals(rows: pd.DataFrame, evaluation) -> tuple[np.ndarray, np.ndarray]:
    """(observed - computed in row units, the same along the line of sight in m or m/s)."""
    res = rows["value"].to_numpy(float) - evaluation.value
    col = next((c for c in ("range_modulus", "range_modulus_ru") if c in rows.columns), None)
    if col is not None:
        m = rows[col].to_numpy(float)
        wrap = (rows["observable"].to_numpy(object) == "range") & np.isfinite(m) & (m > 0)
        mm = np.where(wrap, m, 1.0)
        res = np.where(wrap, np.mod(res + mm / 2, mm) - mm / 2, res)
    az = rows["observable"].to_numpy(object) == "angle_az"
    res = np.where(az, np.mod(res + np.pi, 2 * np.pi) - np.pi, res)
    return res, res * evaluation.to_los
