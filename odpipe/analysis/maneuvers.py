"""Maneuver reconstruction: designed against estimated ΔV, as the thesis' Table 4.4.

For each maneuver: the magnitude difference | |ΔV_designed| − |ΔV_estimated| |
and each component's difference |d_i − e_i|, in mm/s and in percent of the
designed magnitude or component (NaN where the design is zero), with the estimated magnitude's 1σ from the
per-axis σ (diagonal only, which the table carries). Over all maneuvers the
summary gives Average, Median, Max and Min rows. Components are in the frame
the ΔV were estimated in (ICRF here; the ARTEMIS table used true of date).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.numerics.precision import significant

COLUMNS = ["Mag. (mm/s)", "Mag. (%)", "X (mm/s)", "X (%)", "Y (mm/s)", "Y (%)", "Z (mm/s)", "Z (%)"]


def _nonzero(x: np.ndarray) -> np.ndarray:
    """x with zeros as NaN: a percentage of a zero design is undefined, not infinite."""
    return np.where(x > 0, x, np.nan)


def flatten(table: pd.DataFrame) -> pd.DataFrame:
    """A maneuver table with 3-vector columns (``designed``, ``estimated``, ``sigma``, ...) as
    flat ``<name>_x|y|z`` columns, the form written to CSV."""
    out = pd.DataFrame(index=table.index)
    for col in table.columns:
        values = table[col].to_numpy()
        if len(values) and isinstance(values[0], np.ndarray) and values[0].shape == (3,):
            for i, axis in enumerate("xyz"):
                out[f"{col}_{axis}"] = [float(v[i]) for v in values]
        else:
            out[col] = values
    return out


def _vectors(table: pd.DataFrame, name: str) -> np.ndarray:
    return table[[f"{name}_{a}" for a in "xyz"]].to_numpy(float)


def evaluate(table: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(per-maneuver rows, Average/Median/Max/Min summary) from a flat table (:func:`flatten`):
    ``maneuver``, ``designed_x|y|z``, ``estimated_x|y|z`` and ``sigma_x|y|z`` (m/s)."""
    d, e, s = _vectors(table, "designed"), _vectors(table, "estimated"), _vectors(table, "sigma")
    dmag, emag = np.linalg.norm(d, axis=1), np.linalg.norm(e, axis=1)
    unit = e / np.where(emag > 0, emag, 1.0)[:, None]
    rows = pd.DataFrame({"maneuver": table["maneuver"].to_numpy(),
                         "designed (mm/s)": dmag * 1e3, "estimated (mm/s)": emag * 1e3,
                         "estimated sigma (mm/s)": np.sqrt(np.sum((unit * s) ** 2, axis=1)) * 1e3})
    figures = [np.abs(dmag - emag), np.abs(dmag - emag) / _nonzero(dmag)]
    for i in range(3):
        figures += [np.abs(d[:, i] - e[:, i]), np.abs(d[:, i] - e[:, i]) / _nonzero(np.abs(d[:, i]))]
    for name, values in zip(COLUMNS, figures):
        rows[name] = values * (1e3 if "mm/s" in name else 100.0)
    stats = pd.DataFrame({name: [rows[name].mean(), rows[name].median(), rows[name].max(), rows[name].min()]
                          for name in COLUMNS},  # NaN skipped; all-NaN columns stay NaN
                         index=["Average", "Median", "Max", "Min"])
    return rows, stats


def report_tables(rows: pd.DataFrame, stats: pd.DataFrame, epochs_utc=None) -> list[tuple[str, pd.DataFrame, dict]]:
    """(caption, table, formats) of :func:`evaluate`'s rows and summary for a report: each maneuver's mm/s to the
    µm/s and percentages to 0.01 %; the statistics over all maneuvers (median, average, ...) to 3 significant
    figures, as the demo's comparison with the thesis gives them; ``epochs_utc`` (datetime64, one per row) adds
    each maneuver's epoch."""
    per = rows.copy()
    if epochs_utc is not None:
        per.insert(1, "epoch (UTC)", np.asarray(epochs_utc, "datetime64[ns]"))
    formats = {c: "{:.3f}" if "mm/s" in c else "{:.2f}" for c in per.columns if "mm/s" in c or "%" in c}
    summary = stats.reset_index().rename(columns={"index": "statistic"})
    return [("per maneuver", per, formats), ("over all maneuvers (a percentage of a zero design is undefined: –)",
                                             summary, {c: significant for c in COLUMNS})]
