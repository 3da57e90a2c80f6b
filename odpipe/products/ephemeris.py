"""The trajectory product that OEM and SPK writers take: states (and covariances) on a time grid."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class EphemerisSegment:
    """States of one object about one centre over one continuous span.

    ``t_tdb`` (N,) TDB seconds past J2000, increasing; ``states`` (N,6) m, m/s in
    ICRF axes relative to ``center`` (NAIF name); ``covariances`` optional
    (N,6,6) in m², m²/s, m²/s² at the same epochs.
    """

    t_tdb: np.ndarray
    states: np.ndarray
    center: str = "earth"
    covariances: np.ndarray | None = None

    def __post_init__(self):
        self.t_tdb = np.asarray(self.t_tdb, dtype=float)
        self.states = np.asarray(self.states, dtype=float)
        if self.states.shape != (self.t_tdb.size, 6):
            raise ValueError(f"states must be ({self.t_tdb.size}, 6), got {self.states.shape}")
        if self.t_tdb.size < 2 or np.any(np.diff(self.t_tdb) <= 0):
            raise ValueError("a segment needs at least two strictly increasing epochs")
        if self.covariances is not None:
            self.covariances = np.asarray(self.covariances, dtype=float)
            if self.covariances.shape != (self.t_tdb.size, 6, 6):
                raise ValueError(f"covariances must be ({self.t_tdb.size}, 6, 6), got {self.covariances.shape}")
