"""ARTEMIS-P2 navigation figures of the thesis the twin is compared with (seed 004, ch. 4), and the comparison.

Overlaps (§4.5, §4.6): mean ± standard deviation over the overlaps of the per-overlap RMS differences,
radial / in-track / cross-track; position in m, velocity in mm/s. Maneuvers (Table 4.4): designed −
estimated station-keeping delta-v over 17 burns; magnitude and component differences in mm/s and in
percent of the designed magnitude or component (the thesis' components are true of date, odpipe's ICRF).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.numerics.precision import plus_minus, significant

COMPONENTS = ("radial", "intrack", "crosstrack")

# (mean, std) per component: position m, velocity mm/s
OVERLAPS = {
    "short": {"pos": ((15.0, 8.0), (183.0, 146.0), (416.0, 247.0)),
              "vel": ((0.263, 0.182), (1.427, 1.516), (2.825, 1.730))},
    "long": {"pos": ((5.0, 4.0), (66.0, 50.0), (102.0, 53.0)),
             "vel": ((0.062, 0.048), (0.283, 0.221), (0.687, 0.048))},
}

TABLE_4_4 = pd.DataFrame(
    [[1.98, 1.49, 0.93, 1.78, 3.39, 9.43, 2.94, 48.23],
     [0.71, 0.58, 0.61, 1.10, 1.98, 5.69, 1.78, 6.51],
     [19.0, 7.28, 3.78, 6.98, 20.7, 31.86, 12.7, 451.03],
     [0.10, 0.03, 0.21, 0.06, 0.06, 0.30, 0.25, 1.22]],
    index=["Average", "Median", "Max", "Min"],
    columns=["Mag. (mm/s)", "Mag. (%)", "X (mm/s)", "X (%)", "Y (mm/s)", "Y (%)", "Z (mm/s)", "Z (%)"])


def overlap_figures(table: pd.DataFrame) -> dict:
    """{(kind, component): (mean, std)} of an overlap summary (odpipe.analysis.overlap: 'mean', 'std' rows
    last; m and m/s), position in m and velocity in mm/s."""
    mean, std = table.iloc[-2], table.iloc[-1]
    scale = {"pos": 1.0, "vel": 1e3}
    return {(k, c): (float(mean[f"{k}_{c}_rms"]) * scale[k], float(std[f"{k}_{c}_rms"]) * scale[k])
            for k in scale for c in COMPONENTS}


def comparison(overlaps: dict, maneuvers: pd.DataFrame | None) -> pd.DataFrame:
    """Rows (figure, thesis, odpipe, odpipe/thesis): each arc kind's overlap mean per component
    (``overlaps``: {'short'|'long': overlap summary table}) and Table 4.4's medians and averages
    (``maneuvers``: odpipe.analysis.maneuvers.evaluate's summary of the station-keeping burns)."""
    rows = []
    for arc, table in overlaps.items():
        ours = overlap_figures(table)
        for k, unit in (("pos", "m"), ("vel", "mm/s")):
            for c, (m, s) in zip(COMPONENTS, OVERLAPS[arc][k]):
                om, os_ = ours[(k, c)]
                rows.append({"figure": f"{arc}-arc {'position' if k == 'pos' else 'velocity'} {c} ({unit})",
                             "thesis": f"{m:g} ± {s:g}", "odpipe": plus_minus(om, os_),
                             "ratio": om / m})
    if maneuvers is not None:
        for stat in ("Median", "Average"):
            for col in TABLE_4_4.columns:
                ours = float(maneuvers.loc[stat, col])
                rows.append({"figure": f"Table 4.4 {stat.lower()} {col}", "thesis": f"{TABLE_4_4.loc[stat, col]:g}",
                             "odpipe": significant(ours), "ratio": ours / TABLE_4_4.loc[stat, col]})
    out = pd.DataFrame(rows)
    out["ratio"] = out["ratio"].astype(float).replace([np.inf, -np.inf], np.nan)
    return out
