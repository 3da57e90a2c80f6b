"""The estimated-parameter product: each parameter's unit, and report tables at the precision it carries.

A fit's parameter table has columns ``name``, ``kind``, ``apriori``,
``estimate``, ``sigma`` in SI units (:mod:`odpipe.estimation.registry`). For
a reader they are grouped by unit: positions and biases in m, angle biases (rad) in deg, velocities
in m/s, ΔV in mm/s, maneuver epoch offsets in s, scale factors; each row's sigma to 2 significant
figures and its a priori, estimate and change to the sigma's second digit, never finer than the
group's resolution (the mm, 1e-6 deg, the µm/s, the µm/s, the ms, 1e-5): a 68-m position sigma
shows its estimate to the metre. Stochastic accelerations in m/s², frequency drifts in 1/s and
fractional frequency offsets keep 4 significant figures.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.numerics.precision import decimals, significant

# (unit, factor from SI, finest decimals shown) of each display group; None: 4 significant figures
_GROUPS = {
    "m": ("m", 1.0, 3),
    "rad": ("deg", 180.0 / np.pi, 6),
    "m/s": ("m/s", 1.0, 6),
    "dv": ("mm/s", 1e3, 3),
    "s": ("s", 1.0, 3),
    "m/s2": ("m/s²", 1.0, None),
    "m/s3": ("m/s³", 1.0, None),
    "1/s": ("1/s", 1.0, None),
    "1": ("1", 1.0, 5),
    "y0": ("1", 1.0, None),
}
_TITLES = {"m": "positions, station coordinates and range biases", "rad": "angle biases", "m/s": "velocities",
           "dv": "maneuver ΔV components", "s": "maneuver epoch offsets and station time-tag offsets", "m/s2": "stochastic and polynomial accelerations",
           "m/s3": "polynomial acceleration drifts",
           "1/s": "frequency drifts", "1": "scale factors", "y0": "fractional frequency offsets"}


def group(name: str, kind: str) -> str:
    """The display group (a key of the unit table) of parameter ``name`` of ``kind``."""
    if kind == "state":
        return "m/s" if name.rsplit(".", 1)[-1].startswith("v") else "m"
    if kind == "bias" and name.startswith("bias.angle_"):
        return "rad"
    if kind in ("bias", "station"):
        return "m"
    if kind == "maneuver":
        return "dv"
    if kind in ("maneuver_epoch", "timing"):
        return "s"
    if kind == "stochastic":
        return "m/s2"
    if kind == "clock":
        return "1/s" if name.endswith("_y1") else "y0"
    if kind == "dynamic" and ".poly[" in name:
        return "m/s3" if name.endswith("1") else "m/s2"
    if kind in ("dynamic", "media"):
        return "1"
    raise ValueError(f"parameter {name!r}: no unit known for kind {kind!r}")


def with_units(params: pd.DataFrame) -> pd.DataFrame:
    """The parameter table with a ``unit`` column (SI, as the values are)."""
    units = {"dv": "m/s", "m/s2": "m/s^2", "m/s3": "m/s^3", "y0": "1"}
    out = params.copy()
    out.insert(2, "unit", [units.get(g, g) for g in map(group, params["name"], params["kind"])])
    return out


def report_tables(params: pd.DataFrame) -> list[tuple[str, pd.DataFrame, dict]]:
    """(caption, table, formats) per unit: parameter, kind, a priori, estimate, their difference and
    the estimate's sigma in the display unit."""
    keys = [group(n, k) for n, k in zip(params["name"], params["kind"])]
    out = []
    for key in _GROUPS:
        sub = params[[k == key for k in keys]]
        if sub.empty:
            continue
        unit, factor, finest = _GROUPS[key]
        change = sub["estimate"] - sub["apriori"]
        t = pd.DataFrame({"parameter": sub["name"], "kind": sub["kind"],
                          f"a priori ({unit})": sub["apriori"] * factor, f"estimate ({unit})": sub["estimate"] * factor,
                          f"estimate − a priori ({unit})": change * factor, f"sigma ({unit})": sub["sigma"] * factor})
        if finest is None:
            formats = {c: "{:.4g}" for c in t.columns[2:]}
        else:   # each row to its sigma's second digit, never finer than the group's resolution
            rows = [f"{{:.{min(finest, decimals(s / 10)) if np.isfinite(s) and s > 0 else finest}f}}"
                    for s in t[f"sigma ({unit})"]]
            formats = {c: rows for c in t.columns[2:5]} | {f"sigma ({unit})": _sigma_format(finest)}
        out.append((f"{_TITLES[key]} ({unit})", t, formats))
    return out


def _sigma_format(finest: int):
    """A sigma to 2 significant figures: positional down to 2 decimals past the group's resolution
    ``finest``, in powers of ten below (a zero or undefined one to ``finest`` decimals)."""
    def text(value: float) -> str:
        if not (np.isfinite(value) and value > 0):
            return f"{value:.{finest}f}"
        return significant(value, 2) if decimals(value / 10) <= finest + 2 else f"{value:.2g}"
    return text
