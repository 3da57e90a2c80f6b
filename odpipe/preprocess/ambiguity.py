"""Range ambiguity: observed range is known modulo the ranging modulus.

The filter resolves it against the computed range: add the whole number of
moduli that brings the observation closest to the model. When the model is
off by nearly half a modulus the choice is ambiguous and the row is flagged.
"""

from __future__ import annotations

import numpy as np


def resolve(observed: np.ndarray, computed: np.ndarray, modulus: np.ndarray, margin: float = 0.1):
    """(resolved range, ambiguous mask); same unit throughout (e.g. RU).

    ``ambiguous`` is true where the resolved residual is within ``margin`` x modulus
    of +-modulus/2 (or any input is not finite).
    """
    o, c, m = (np.asarray(x, dtype=float) for x in (observed, computed, modulus))
    n = np.rint((c - o) / m)
    resolved = o + n * m
    ambiguous = ~np.isfinite(resolved) | (np.abs(c - resolved) > (0.5 - margin) * m)
    return resolved, ambiguous
