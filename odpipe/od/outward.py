"""Fitting an arc outward from the a priori epoch (``ArcSetup.outward``).

An a priori state good at its own epoch (LAGEOS-2: Orekit's, 4 m and 1 m/s off) is kilometres off
when propagated to a data start days earlier, and the whole arc at once need not converge from it.
So the rows within a window about the a priori epoch are fitted first, then windows ``factor`` times
wider, each clipped to the arc, until the arc is covered; every window starts from the last
window's smoothed estimate at its start, propagated to the new start, with the arc's a priori sigmas
(loose ones, so counting the a priori again changes nothing that matters). The last fit is the whole
arc's, with the arc's own editing; the earlier ones edit nothing.
"""

from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np
import pandas as pd

from odpipe.dynamics.propagator import propagate
from odpipe.time import tdb_to_utc

_log = logging.getLogger(__name__)


def windows(start: float, end: float, epoch: float, half: float, factor: float) -> list[tuple[float, float]]:
    """The windows (TDB s) fitted before the whole arc ``[start, end]``: ``epoch ± half``, widened
    ``factor`` times each step, clipped to the arc (those outside it left out); the whole arc itself is
    not in the list."""
    out = []
    while True:
        a, b = max(start, epoch - half), min(end, epoch + half)
        if a <= start and b >= end:
            return out
        if a < b:
            out.append((a, b))
        half *= factor


def _state_at(state: np.ndarray, t0: float, t1: float, force_model) -> np.ndarray:
    if t0 == t1:
        return state
    return propagate(state, t0, t1, force_model, with_stm=False).state(np.array([t1]))[0]


def fit_outward(table: pd.DataFrame, setup):
    """:func:`~odpipe.od.arc.fit_arc` over growing windows about ``setup.outward[0]``; the whole arc's
    solution, its ``history`` every window's iterations in order (each entry's ``window`` the window's
    (start, end) TDB s)."""
    from .arc import fit_arc, select_rows

    epoch, half, factor = setup.outward
    base = replace(setup, outward=None)
    t_state, state = setup.start, np.asarray(setup.state0, float)
    history, used = [], -1
    for a, b in windows(setup.start, setup.end, epoch, half, factor):
        sub = replace(base, start=a, end=b, edit_k=(np.inf,), state0=_state_at(state, t_state, a, setup.force_model))
        n = len(select_rows(table, sub)[0])
        if n == 0 or n == used:  # nothing new to fit in this window
            continue
        utc = (tdb_to_utc(np.array([a, b])) + np.timedelta64(500, "ms")).astype("datetime64[s]")
        _log.info("outward fit: %d rows of %s .. %s UTC", n, *utc)
        sol = fit_arc(table, sub)
        history += [{**h, "window": (a, b)} for h in sol.history]
        t_state, state, used = sol.epochs[0], sol.states[0], n
    _log.info("outward fit: the whole arc")
    sol = fit_arc(table, replace(base, state0=_state_at(state, t_state, setup.start, setup.force_model)))
    sol.history = history + [{**h, "window": (setup.start, setup.end)} for h in sol.history]
    return sol
