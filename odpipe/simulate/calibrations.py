"""Simulated TRK-2-23 media calibrations (.TRO troposphere, .ION ionosphere) and their errors.

Troposphere: for each DSN complex and UTC day, WET and DRY NUPART zenith
deviations from the DSN seasonal model as a quadratic normalized power series
(NRMPOW) with coefficients ~ N(0, sigma). Ionosphere: for each DSN pass, the
S-band line-of-sight range delay (CHPART, m at 2295 MHz) for the spacecraft as
a quadratic NRMPOW over the pass (+- 10 min), c0 = sigma (1 + |N(0,1)|), c1, c2 ~ N(0, sigma/4).
Calibration errors: the true delay of each card is its written series plus a
quadratic whose RMS over the card is ``error`` (coefficients ~ N(0, error / sqrt(1 + 1/3 + 1/5)),
the mean square of a normalized quadratic over [-1, 1]); the written card states ``error`` as its
FITSIG. Without an error (None) no error is drawn and the true cards are the written ones. Each function returns (written, true) card texts: the files carry the
written one, the simulated observables the true one. Coefficients are rounded to
0.1 mm as written.
"""

from __future__ import annotations

import numpy as np

from parsers.trk223 import complex_of

QUADRATIC_RMS = np.sqrt(1.0 + 1.0 / 3.0 + 1.0 / 5.0)  # RMS over [-1, 1] of a quadratic with unit coefficients


def _csp_time(t: np.datetime64) -> str:
    s = str(t.astype("datetime64[s]"))
    return f"{s[2:4]}/{s[5:7]}/{s[8:10]},{s[11:19]}"


def tro_text(stations, start: np.datetime64, end: np.datetime64, sigma_wet: float, sigma_dry: float, rng,
             error_wet: float | None = None, error_dry: float | None = None) -> tuple[str, str]:
    """(written, true) TRK-2-23 .TRO cards for the DSN complexes of ``stations`` over whole UTC days
    covering [start, end]."""
    complexes = sorted({complex_of(s) for s in stations} - {""})
    days = np.arange(start.astype("datetime64[D]"), end.astype("datetime64[D]") + np.timedelta64(1, "D"))
    written, true = [], []
    for cx in complexes:
        for d in days:
            a, b = d.astype("datetime64[ns]"), (d + np.timedelta64(1, "D")).astype("datetime64[ns]")
            for model, sigma, error in (("DRY NUPART", sigma_dry, error_dry), ("WET NUPART", sigma_wet, error_wet)):
                c = np.round(sigma * rng.standard_normal(3), 4)
                e = _error(error, rng)
                written += _card(c, model, a, b, cx, error)
                true += _card(c + e, model, a, b, cx, error)
    return "\n".join(written) + "\n", "\n".join(true) + "\n"


def ion_text(passes, scid: int, sigma: float, rng, error: float | None = None) -> tuple[str, str]:
    """(written, true) TRK-2-23 .ION cards, one per (DSN station, start, end) pass, for spacecraft ``scid``."""
    margin = np.timedelta64(600, "s")
    written, true = [], []
    for station, start, end in passes:
        c = np.round(np.array([sigma * (1 + abs(rng.standard_normal())), *(0.25 * sigma * rng.standard_normal(2))]), 4)
        e = _error(error, rng)
        dsn, extra = station.replace("DSS-", ""), f" SCID({scid})"
        written += _card(c, "CHPART", start - margin, end + margin, dsn, error, extra)
        true += _card(c + e, "CHPART", start - margin, end + margin, dsn, error, extra)
    return "\n".join(written) + "\n", "\n".join(true) + "\n"


def _error(error, rng) -> np.ndarray:
    """Error coefficients (3,) of one card: RMS ``error`` over it; zeros, drawing nothing, when None."""
    return np.zeros(3) if error is None else error / QUADRATIC_RMS * rng.standard_normal(3)


def _card(c, model, a, b, network, fitsig, extra="") -> list[str]:
    coefs = ", ".join(f"{v:.4f}" for v in c)
    return [f"# FITSIG= {fitsig or 0.0:.7f}", f"ADJUST(DOPRNG) BY NRMPOW({coefs}) MODEL({model})",
            f"  FROM({_csp_time(a)}) TO({_csp_time(b)}) DSN({network}){extra}."]
