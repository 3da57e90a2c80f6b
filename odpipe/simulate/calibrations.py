"""Simulated TRK-2-23 media calibrations (.TRO troposphere, .ION ionosphere).

Troposphere: for each DSN complex and UTC day, WET and DRY NUPART zenith
deviations from the DSN seasonal model as a quadratic normalized power series
(NRMPOW) with coefficients ~ N(0, sigma). Ionosphere: for each DSN pass, the
S-band line-of-sight range delay (CHPART, m at 2295 MHz) for the spacecraft as
a quadratic NRMPOW over the pass (+- 10 min), c0 = sigma (1 + |N(0,1)|), c1, c2 ~ N(0, sigma/4).
Coefficients are rounded to 0.1 mm as written; the simulator reads the text
back and uses it, so the calibration stage removes exactly what was added.
"""

from __future__ import annotations

import numpy as np

from parsers.trk223 import complex_of


def _csp_time(t: np.datetime64) -> str:
    s = str(t.astype("datetime64[s]"))
    return f"{s[2:4]}/{s[5:7]}/{s[8:10]},{s[11:19]}"


def tro_text(stations, start: np.datetime64, end: np.datetime64, sigma_wet: float, sigma_dry: float, rng) -> str:
    """TRK-2-23 .TRO cards for the DSN complexes of ``stations`` over whole UTC days covering [start, end]."""
    complexes = sorted({complex_of(s) for s in stations} - {""})
    days = np.arange(start.astype("datetime64[D]"), end.astype("datetime64[D]") + np.timedelta64(1, "D"))
    lines = []
    for cx in complexes:
        for d in days:
            a, b = d.astype("datetime64[ns]"), (d + np.timedelta64(1, "D")).astype("datetime64[ns]")
            for model, sigma in (("DRY NUPART", sigma_dry), ("WET NUPART", sigma_wet)):
                c = np.round(sigma * rng.standard_normal(3), 4)
                lines += _card(c, model, a, b, cx, sigma)
    return "\n".join(lines) + "\n"


def ion_text(passes, scid: int, sigma: float, rng) -> str:
    """TRK-2-23 .ION cards, one per (DSN station, start, end) pass, for spacecraft ``scid``."""
    margin = np.timedelta64(600, "s")
    lines = []
    for station, start, end in passes:
        c = np.round(np.array([sigma * (1 + abs(rng.standard_normal())), *(0.25 * sigma * rng.standard_normal(2))]), 4)
        lines += _card(c, "CHPART", start - margin, end + margin, station.replace("DSS-", ""), sigma, f" SCID({scid})")
    return "\n".join(lines) + "\n"


def _card(c, model, a, b, network, fitsig, extra="") -> list[str]:
    coefs = ", ".join(f"{v:.4f}" for v in c)
    return [f"# FITSIG= {fitsig:.4f}", f"ADJUST(DOPRNG) BY NRMPOW({coefs}) MODEL({model})",
            f"  FROM({_csp_time(a)}) TO({_csp_time(b)}) DSN({network}){extra}."]
