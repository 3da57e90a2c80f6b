"""Which spacecraft oscillator a one-way Doppler row counts against: names and lookup.

A one-way downlink is referenced to an oscillator on board, ``f_ref (1 + y0 + y1 (t - t_ref))``
(:func:`.dsn.one_way_doppler`). A spacecraft may carry several: GRAIL's X-band beacon is driven by its
ultra-stable oscillator (one y0, y1 over days), while its S-band transponder, when not locked to an uplink,
transmits from its own auxiliary oscillator, whose offset differs by 1e-8..1e-7 from one acquisition to the
next (docs/validation.md). Oscillators are named, most general first:

* ``"<sc>"``: every one-way band of the spacecraft;
* ``"<sc>:<band>"``: one downlink band (S, X, Ka);
* ``"<sc>:<band>:pass<N>"``: one pass of that band (``pass_id`` N, :mod:`odpipe.tracking.passes`).

A row counts against the most specific name that is known (e.g. present in ``MeasurementSetup.oscillators``).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .bands import band_name


def name(spacecraft: str, band: str | None = None, pass_id: int | None = None) -> str:
    """The oscillator name of a spacecraft, optionally one band of it and one pass of that band."""
    if band is None:
        return str(spacecraft)
    head = f"{spacecraft}:{band_name(band)}"
    return head if pass_id is None else f"{head}:pass{int(pass_id)}"


def row_names(spacecraft: str, rows: pd.DataFrame, known) -> np.ndarray:
    """Per row (columns ``band_down``, optional ``pass_id``), the most specific name of ``known`` that applies,
    else the spacecraft's own name (object array)."""
    bands = rows["band_down"].astype(str).to_numpy(object)
    passes = rows["pass_id"].to_numpy().astype(int) if "pass_id" in rows.columns else np.full(len(rows), -1)
    chosen: dict = {}   # (band, pass) -> name: a handful of combinations per call
    out = np.empty(len(rows), dtype=object)
    for i, combo in enumerate(zip(bands, passes.tolist())):
        got = chosen.get(combo)
        if got is None:
            band, pid = combo
            specific = [n for n in (name(spacecraft, band, pid), name(spacecraft, band)) if n in known]
            got = chosen[combo] = specific[0] if specific else name(spacecraft)
        out[i] = got
    return out
