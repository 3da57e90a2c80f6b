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


def labelled(history: list, fit: str) -> list:
    """``history``'s entries, each naming the fit it belongs to (entries already named keep theirs)."""
    return [{"fit": fit, **h} for h in history]


def iteration_stages(history: list) -> list[dict]:
    """Iterations per fit, in order: consecutive entries of one ``fit`` and ``window`` are one stage
    (entries naming no fit: "whole arc"); each stage a dict of ``fit``, ``iterations`` and, where the
    entries carry it, ``window`` (start, end) as UTC ISO strings to the second."""
    stages: list[dict] = []
    for h in history:
        key = (h.get("fit", "whole arc"), tuple(h["window"]) if "window" in h else None)
        if not stages or stages[-1]["_key"] != key:
            stages.append({"_key": key, "fit": key[0], "iterations": 0})
            if key[1] is not None:
                stages[-1]["window"] = [str(u) for u in _utc_seconds(key[1])]
        stages[-1]["iterations"] += 1
    return [{k: v for k, v in s.items() if k != "_key"} for s in stages]


def _utc_seconds(tdb) -> np.ndarray:
    """TDB s as UTC datetime64 rounded to the second."""
    return (tdb_to_utc(np.asarray(tdb, float)) + np.timedelta64(500, "ms")).astype("datetime64[s]")


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
        _log.info("outward fit: %d rows of %s .. %s UTC", n, *_utc_seconds((a, b)))
        sol = fit_arc(table, sub)
        history += labelled([{**h, "window": (a, b)} for h in sol.history], "outward window")
        t_state, state, used = sol.epochs[0], sol.states[0], n
    _log.info("outward fit: the whole arc")
    sol = fit_arc(table, replace(base, state0=_state_at(state, t_state, setup.start, setup.force_model)))
    sol.history = history + labelled([{**h, "window": (setup.start, setup.end)} for h in sol.history], "whole arc")
    return sol
