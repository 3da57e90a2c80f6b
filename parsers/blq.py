"""Reader of BLQ ocean-loading coefficient files (Scherneck/Bos format, e.g. Onsala's loading service).

Lines starting ``$$`` are comments. Each site is a name line (first word the site
name, e.g. ``SHLD/C1`` or ``ONSALA``) followed by six lines of 11 numbers in the
column order M2 S2 N2 K2 K1 O1 P1 Q1 MF MM SSA: amplitudes (m) of the radial
(up), tangential west and tangential south displacement, then their phases (deg,
Greenwich phase lags, positive lagging). :func:`read` gives ``{name: BlqSite}``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from parsers.errors import ParseError

CONSTITUENTS = ("M2", "S2", "N2", "K2", "K1", "O1", "P1", "Q1", "MF", "MM", "SSA")


@dataclass(frozen=True)
class BlqSite:
    """Ocean-loading coefficients of one site: ``amplitude_m`` and ``phase_deg`` (3, 11), rows up, west, south."""

    name: str
    amplitude_m: np.ndarray
    phase_deg: np.ndarray


def read(path) -> dict[str, BlqSite]:
    """Sites of the BLQ file ``path`` by name (upper case); ParseError naming the line on bad input."""
    path = Path(path)
    lines = [(i, ln.strip()) for i, ln in enumerate(path.read_text(errors="replace").splitlines(), 1)
             if ln.strip() and not ln.lstrip().startswith("$$")]
    sites: dict[str, BlqSite] = {}
    k = 0
    while k < len(lines):
        line_no, text = lines[k]
        name = text.split()[0].upper()
        block = lines[k + 1:k + 7]
        if len(block) < 6:
            raise ParseError(path, f"site {name!r} has {len(block)} coefficient lines, expected 6", line=line_no)
        rows = []
        for n, t in block:
            try:
                values = [float(v) for v in t.split()]
            except ValueError:
                raise ParseError(path, f"site {name!r}: non-numeric coefficient in {t!r}", line=n) from None
            if len(values) != len(CONSTITUENTS) or not np.all(np.isfinite(values)):
                raise ParseError(path, f"site {name!r}: expected {len(CONSTITUENTS)} finite numbers, got {t!r}",
                                 line=n)
            rows.append(values)
        coeff = np.array(rows)
        if np.any(coeff[:3] < 0):
            raise ParseError(path, f"site {name!r}: negative amplitude", line=block[0][0])
        sites[name] = BlqSite(name, coeff[:3], coeff[3:])
        k += 7
    if not sites:
        raise ParseError(path, "no site in the file")
    return sites
