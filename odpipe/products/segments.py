"""The trajectory product that OEM and SPK writers take: states (and covariances) on a time grid."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class EphemerisSegment:
    """States of one object about one centre over one continuous span.

    ``t_tdb`` (N,) TDB seconds past J2000, increasing; ``states`` (N,6) m, m/s in
    ICRF axes relative to ``center`` (NAIF name); ``covariances`` optional
    (M,6,6) in m², m²/s, m²/s² at ``covariance_t_tdb`` (M,) (default: the
    state epochs; a filter's grid is often coarser than the product's).
    """

    t_tdb: np.ndarray
    states: np.ndarray
    center: str = "earth"
    covariances: np.ndarray | None = None
    covariance_t_tdb: np.ndarray | None = None

    def __post_init__(self):
        self.t_tdb = np.asarray(self.t_tdb, dtype=float)
        self.states = np.asarray(self.states, dtype=float)
        if self.states.shape != (self.t_tdb.size, 6):
            raise ValueError(f"states must be ({self.t_tdb.size}, 6), got {self.states.shape}")
        if self.t_tdb.size < 2 or np.any(np.diff(self.t_tdb) <= 0):
            raise ValueError("a segment needs at least two strictly increasing epochs")
        if self.covariances is not None:
            self.covariances = np.asarray(self.covariances, dtype=float)
            tc = self.t_tdb if self.covariance_t_tdb is None else self.covariance_t_tdb
            self.covariance_t_tdb = np.asarray(tc, dtype=float)
            if self.covariances.shape != (self.covariance_t_tdb.size, 6, 6):
                raise ValueError(f"covariances must be ({self.covariance_t_tdb.size}, 6, 6), "
                                 f"got {self.covariances.shape}")
