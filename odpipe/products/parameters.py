"""The estimated-parameter product: each parameter's unit, and report tables at the precision it carries.

A fit's parameter table has columns ``name``, ``kind``, ``apriori``,
``estimate``, ``sigma`` in SI units (:mod:`odpipe.estimation.registry`). For
a reader they are grouped by unit: positions and biases in m to the mm, angle biases (rad) in deg to
1e-6 deg,
velocities in m/s to the µm/s, ΔV in mm/s to the µm/s, maneuver epoch offsets
in s to the ms, stochastic accelerations in m/s² and drifts in 1/s to 4
significant figures, scale factors to 1e-5.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

# (unit, factor from SI, format) of each display group
_GROUPS = {
    "m": ("m", 1.0, "{:.3f}"),
    "rad": ("deg", 180.0 / np.pi, "{:.6f}"),
    "m/s": ("m/s", 1.0, "{:.6f}"),
    "dv": ("mm/s", 1e3, "{:.3f}"),
    "s": ("s", 1.0, "{:.3f}"),
    "m/s2": ("m/s²", 1.0, "{:.4g}"),
    "m/s3": ("m/s³", 1.0, "{:.4g}"),
    "1/s": ("1/s", 1.0, "{:.4g}"),
    "1": ("1", 1.0, "{:.5f}"),
}
_TITLES = {"m": "positions, station coordinates and range biases", "rad": "angle biases", "m/s": "velocities",
           "dv": "maneuver ΔV components", "s": "maneuver epoch offsets and station time-tag offsets", "m/s2": "stochastic and polynomial accelerations",
           "m/s3": "polynomial acceleration drifts",
           "1/s": "frequency drifts", "1": "scale factors and fractional offsets"}


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
        return "1/s" if name.endswith("_y1") else "1"
    if kind == "dynamic" and ".poly[" in name:
        return "m/s3" if name.endswith("1") else "m/s2"
    if kind in ("dynamic", "media"):
        return "1"
    raise ValueError(f"parameter {name!r}: no unit known for kind {kind!r}")


def with_units(params: pd.DataFrame) -> pd.DataFrame:
    """The parameter table with a ``unit`` column (SI, as the values are)."""
    units = {"dv": "m/s", "m/s2": "m/s^2", "m/s3": "m/s^3"}
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
        unit, factor, fmt = _GROUPS[key]
        change = sub["estimate"] - sub["apriori"]
        t = pd.DataFrame({"parameter": sub["name"], "kind": sub["kind"],
                          f"a priori ({unit})": sub["apriori"] * factor, f"estimate ({unit})": sub["estimate"] * factor,
                          f"estimate − a priori ({unit})": change * factor, f"sigma ({unit})": sub["sigma"] * factor})
        formats = {c: fmt for c in t.columns[2:]}
        out.append((f"{_TITLES[key]} ({unit})", t, formats))
    return out
