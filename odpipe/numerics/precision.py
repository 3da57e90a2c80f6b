"""Figures at the precision they carry: a statistic to its significant figures, a quantity to the first
significant digit of its standard error (the reports' and the commands' one rule)."""

from __future__ import annotations

import numpy as np


def significant(value: float, digits: int = 3) -> str:
    """``value`` to ``digits`` significant figures in positional notation, trailing zeros kept
    (4516.098 → "4520", 0.52062 → "0.521", 12 → "12.0"): a statistic at the precision it carries."""
    rounded = float(f"{float(value):.{digits}g}")   # first, so a carry (0.52999 → 0.530) keeps its zeros
    if not np.isfinite(rounded):
        return str(rounded)
    exponent = int(np.floor(np.log10(abs(rounded)))) if rounded else 0
    return f"{rounded:.{max(0, digits - 1 - exponent)}f}"   # numpy's positional format gave 0.73 → "0.73"


def decimals(step: float) -> int:
    """Decimals that show a quantity to its first significant digit of ``step`` (e.g. a standard error):
    0.13 → 1, 0.004 → 3, 25 → 0."""
    return max(0, -int(np.floor(np.log10(step)))) if np.isfinite(step) and step > 0 else 0


def plus_minus(mean: float, std: float) -> str:
    """'mean ± std' of a statistic over arcs or runs, each to 3 significant figures ("355 ± 240")."""
    return f"{significant(mean)} ± {significant(std)}"
