"""Simulated TRK-2-23 troposphere calibrations: daily deviations from the DSN seasonal model.

For each DSN complex and UTC day, WET and DRY NUPART zenith deviations as a
quadratic normalized power series (NRMPOW) with coefficients ~ N(0, sigma),
rounded to 0.1 mm as written in the .TRO text, which is what the simulator
reads back and uses, so the calibration stage removes exactly what was added.
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
                coefs = ", ".join(f"{v:.4f}" for v in c)
                lines.append(f"# FITSIG= {sigma:.4f}")
                lines.append(f"ADJUST(DOPRNG) BY NRMPOW({coefs}) MODEL({model})")
                lines.append(f"  FROM({_csp_time(a)}) TO({_csp_time(b)}) DSN({cx}).")
    return "\n".join(lines) + "\n"
