"""Earth orientation tabulated once per span (an arc, a batch of rows): a Chebyshev table of the GCRS->ITRS matrix.

The measurement models ask for the full IAU 2006/2000A rotation with EOP at every
light-time event of every row (several times per row and iteration); over an arc
the nine matrix elements are smooth (daily rotation, nutation, interpolated EOP),
so they are fitted once on hourly segments of degree 12
(:func:`odpipe.numerics.chebyshev.fit_channel`) and evaluated from the table.
The table reproduces the full model to < 1e-12 rad (6 micrometres at a station;
tested), far below the model's own EOP-interpolation jitter.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from odpipe.numerics.chebyshev import evaluate, fit_channel

SEGMENT_S, DEGREE = 3600.0, 12


@njit(cache=True)
def _evaluate_many(coefs, meta, ch, t, out):
    for i in range(t.size):
        evaluate(coefs, meta, ch, t[i], out[i])


def node_count(t0: float, t1: float) -> int:
    """Epochs at which a table over [t0, t1] (TDB s) evaluates the full rotation: its pieces' Chebyshev nodes."""
    return int(np.ceil(t1 / SEGMENT_S) - np.floor(t0 / SEGMENT_S)) * (DEGREE + 1)


class TabulatedRotation:
    """``rotation(t) -> (N, 3, 3)`` tabulated over ``[t0, t1]`` (TDB s); outside it, an error."""

    def __init__(self, rotation, t0: float, t1: float):
        # segments on whole multiples of SEGMENT_S: tables of overlapping spans give identical values
        t0, t1 = np.floor(t0 / SEGMENT_S) * SEGMENT_S, np.ceil(t1 / SEGMENT_S) * SEGMENT_S
        self.t0, self.t1 = float(t0), float(t1)
        coef, meta = fit_channel(lambda t: np.asarray(rotation(t), float).reshape(-1, 9), t0, t1, SEGMENT_S, DEGREE)
        self._coefs, self._meta = coef[None], meta[None]

    def __call__(self, t) -> np.ndarray:
        t = np.ascontiguousarray(np.atleast_1d(np.asarray(t, float)))  # one compiled signature
        if t.size and (t.min() < self.t0 or t.max() > self.t1):
            raise ValueError(f"epoch outside the tabulated Earth orientation [{self.t0}, {self.t1}] TDB s")
        out = np.empty((t.size, 9))
        _evaluate_many(self._coefs, self._meta, 0, t, out)  # channel 0 from Python: int64, not a literal
        return out.reshape(-1, 3, 3)
