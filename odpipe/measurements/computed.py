"""What every observable model returns: values and partials, vectorized over rows.

State partials are given per *event* (a participant at the epoch where the
signal touched it), in the light-time solve frame (ICRF axes):
``d_pos`` = d value / d position (unit/m) and ``d_vel`` = d value / d velocity
(unit/(m/s), zero for light-time observables: velocities enter through the
state transition matrix). Other parameters (biases, clock coefficients,
delays, media scale) are in ``params`` as d value / d parameter per row.
``to_los`` converts one unit of the value to metres (range types) or m/s
(rate types) along the line of sight, for residuals.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class EventPartial:
    """Partials with respect to one participant's state at one event epoch.

    role: 'spacecraft', 'station_tx', 'station_rx' (DSN) or 'sc1', 'sc2' (crosslinks);
    t: TDB s past J2000 of the event (N,); d_pos, d_vel: (N,3).
    """

    role: str
    t: np.ndarray
    d_pos: np.ndarray
    d_vel: np.ndarray | None = None


@dataclass
class Computed:
    """Computed observables of N rows: value in ``unit``, event partials, parameter partials, LOS scale."""

    value: np.ndarray
    unit: str
    events: list[EventPartial]
    params: dict[str, np.ndarray] = field(default_factory=dict)
    to_los: np.ndarray | float = 1.0


@dataclass
class ConstantUplink:
    """A constant uplink (or reference) frequency per row, Hz, with the ramp-store interface.

    ``phase`` and ``frequency`` match :class:`parsers.ramps.RampStore` so the
    observables integrate a constant and a ramped uplink with the same code;
    the station argument is ignored (the frequency is already per row).
    """

    freq_hz: np.ndarray

    def frequency(self, station, t, offset=0.0):
        n = np.size(np.atleast_1d(np.asarray(t, dtype="datetime64[ns]")))
        return np.broadcast_to(np.asarray(self.freq_hz, dtype=float), (n,)).copy()

    def phase(self, station, t0, t1, offset0=0.0, offset1=0.0):
        a = np.atleast_1d(np.asarray(t0, dtype="datetime64[ns]")).astype(np.int64)
        b = np.atleast_1d(np.asarray(t1, dtype="datetime64[ns]")).astype(np.int64)
        dur = (b - a) * 1e-9 + (np.asarray(offset1, dtype=float) - np.asarray(offset0, dtype=float))
        return np.asarray(self.freq_hz, dtype=float) * dur
