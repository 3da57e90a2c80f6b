"""Time-tag partial: how a row's computed value moves with its time tag.

A station whose tags are late by dt (s) records at tag t what happened at t - dt, so its observed value
is the computed value at t less ``rate * dt``, ``rate`` the observable's own rate (two-way Doppler: the
line-of-sight acceleration, in the row's unit per s). The rate is a backward difference of
:func:`.compute` with every tag moved by -h (ramp and calibration tables held, so it is a pure tag
error), error about h/2 times the observable's second derivative: for a 2-h lunar orbit's Doppler
about 4e-4 of the rate at h = 0.5 s. Backward, because a segment's trajectory ends at its last row.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .compute import MeasurementSetup, compute


def tag_rate(rows: pd.DataFrame, trajectories, setup: MeasurementSetup, value: np.ndarray,
             h: float = 0.5) -> np.ndarray:
    """d computed / d tag (row units per s) of ``rows``, whose computed values at their tags are ``value``."""
    earlier = rows.assign(epoch=rows["epoch"] - pd.Timedelta(seconds=h))
    return (np.asarray(value, float) - compute(earlier, trajectories, setup).value) / h
