"""Data editing: each editor returns a row mask for one edit reason; :func:`edit` applies them.

Rows are flagged (``flags`` bits, :mod:`odpipe.preprocess.flags`), never dropped.
Editors look only at columns, so they run on any TrackingTable:

* elevation mask: ``elevation_rx`` column (rad, at the receiver), from :mod:`odpipe.pipeline.geometry`;
* duplicates: same link and time tag as an earlier row (the first is kept);
* format validity: ``validity`` != 0 (ODF) or ``valid`` false;
* blunders: per pass, a gross test on the values and a robust (median/MAD)
  test on the signal detrended against each sample's neighbours
  (:func:`odpipe.preprocess.robust.spikes`);
* range ambiguity: range outside [0, modulus) (``range_modulus_ru`` or ``range_modulus``);
* uplink acquisitions: two/three-way rows transmitted while the uplink was being
  retuned and swept into lock (:mod:`odpipe.preprocess.uplink`; needs ``rtlt_s``);
* short passes, outside the arc, analyst windows;
* residual outliers during a fit (:func:`residual_outliers`, called by the filter).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from odpipe.preprocess.flags import Flag, set_flag, summary
from odpipe.preprocess.robust import gross, outliers, spikes
from odpipe.preprocess.uplink import in_acquisition
from odpipe.tracking.passes import LINK, assign_passes, link_id
from odpipe.tracking.ramp_segments import store

log = logging.getLogger(__name__)


@dataclass
class EditConfig:
    """Editing settings (SI: s, rad)."""

    min_elevation: float = np.radians(10.0)  # rad; -inf: no elevation mask
    blunder_k: float = 10.0         # robust sigmas of the spike deviation
    gross_k: float = 5.0            # 10-90 % spreads of the pass's values
    min_pass_samples: int = 10
    min_pass_duration: float = 0.0  # s
    arc: tuple | None = None        # (start, end) UTC
    windows: list = field(default_factory=list)  # analyst windows: dicts start, end[, station_rx, observable]
    max_gap: float = 600.0          # s, pass break
    sweep_rate: float = 10.0        # Hz/s, |ramp rate| of an acquisition sweep
    acquisition_lead: float = 3600.0  # s, longest retune-to-sweep time of one acquisition


MODULUS_COLUMNS = ("range_modulus_ru", "range_modulus")


def _ns(table):
    return table["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64)


def below_elevation(table: pd.DataFrame, min_elevation: float) -> np.ndarray:
    """Rows whose ``elevation_rx`` (rad) is below ``min_elevation``; none if the column is absent."""
    if "elevation_rx" not in table:
        return np.zeros(len(table), dtype=bool)
    return table["elevation_rx"].to_numpy(dtype=float) < min_elevation


def duplicates(table: pd.DataFrame) -> np.ndarray:
    """Rows repeating an earlier row's link and time tag."""
    return table.duplicated(subset=LINK + ["epoch"], keep="first").to_numpy()


def invalid(table: pd.DataFrame) -> np.ndarray:
    """Rows the format marks invalid, and rows with no usable value.

    A row's own ``valid`` flag decides where it is given (UTDF: the row's
    validity bit; its ``validity`` byte is a bit field, not a verdict);
    elsewhere ``validity`` != 0 (ODF: 0 good, 1 bad). A row whose value is
    not finite (e.g. the first UTDF count of a series), or a Doppler row
    without a count time, is invalid too.
    """
    value = table["value"].to_numpy(dtype=float)
    doppler = table["observable"].astype(str).str.startswith("doppler").to_numpy()
    bad = ~np.isfinite(value) | (doppler & ~np.isfinite(table["count_time"].to_numpy(dtype=float)))
    given = np.zeros(len(table), dtype=bool)
    if "valid" in table:
        v = table["valid"]
        given = v.notna().to_numpy()
        bad = given & (v.astype(object) == False).to_numpy()  # noqa: E712 - explicit False only
    if "validity" in table:
        bad |= ~given & (table["validity"].fillna(0).to_numpy() != 0)
    return bad


def blunders(table: pd.DataFrame, config: EditConfig | None = None, use: np.ndarray | None = None) -> np.ndarray:
    """Gross outliers per pass (``pass_id`` must be set); only rows with ``use`` true are tested.
    Azimuths are unwrapped within each pass (its rows in time order) before they are tested.

    Ambiguous (modular) range is left to the fit, where it is resolved against the model.
    """
    config = config or EditConfig()
    use = np.ones(len(table), dtype=bool) if use is None else np.asarray(use, dtype=bool)
    v = table["value"].to_numpy(dtype=float)
    use = use & np.isfinite(v) & np.isnan(range_modulus(table))
    # one group per (link, pass): never judge one observable's values against another's
    pid = pd.Series(link_id(table)).astype(str).add(":").add(table["pass_id"].astype(str).to_numpy())
    pid = pd.factorize(pid)[0]
    az = (table["observable"].to_numpy() == "angle_az") & np.isfinite(v)
    if az.any():  # azimuths crossing north unwrapped within a pass: 359.9 deg then 0.1 deg is a 0.2 deg step
        v = v.copy()
        v[az] = pd.Series(v[az]).groupby(pid[az]).transform(np.unwrap).to_numpy()
    bad = use & gross(v, pid, config.gross_k, use)
    return bad | spikes(_ns(table), v, pid, config.blunder_k, use & ~bad)


def range_modulus(table: pd.DataFrame) -> np.ndarray:
    """Each row's range modulus in its unit (ODF ``range_modulus_ru``, TDM ``range_modulus``); NaN if none."""
    mod = np.full(len(table), np.nan)
    for col in MODULUS_COLUMNS:
        if col in table:
            mod = np.where(np.isnan(mod), table[col].to_numpy(dtype=float), mod)
    return mod


def range_outside_modulus(table: pd.DataFrame) -> np.ndarray:
    """Range rows outside [0, modulus) where the format gives the modulus."""
    mod = range_modulus(table)
    v = table["value"].to_numpy(dtype=float)
    return (table["observable"].to_numpy() == "range") & np.isfinite(mod) & ((v < 0) | (v >= mod))


def short_passes(table: pd.DataFrame, min_samples: int, min_duration: float) -> np.ndarray:
    """Rows of passes lasting less than ``min_duration`` s, and of Doppler passes (count time > 0)
    with fewer than ``min_samples`` rows (sparse range points are not judged by number)."""
    g = table.groupby("pass_id")["epoch"]
    n = g.transform("size").to_numpy()
    dur = (g.transform("max") - g.transform("min")).dt.total_seconds().to_numpy()
    counted = table["count_time"].fillna(0).to_numpy() > 0
    return (counted & (n < min_samples)) | (dur < min_duration)


def outside_arc(table: pd.DataFrame, start, end) -> np.ndarray:
    """Rows tagged before ``start`` or after ``end`` (UTC)."""
    e = table["epoch"]
    return ((e < pd.Timestamp(start)) | (e > pd.Timestamp(end))).to_numpy()


def in_windows(table: pd.DataFrame, windows: list) -> np.ndarray:
    """Rows inside any analyst window {start, end[, station_rx][, observable]} (times UTC, inclusive)."""
    hit = np.zeros(len(table), dtype=bool)
    for w in windows:
        m = (table["epoch"] >= pd.Timestamp(w["start"])) & (table["epoch"] <= pd.Timestamp(w["end"]))
        for col in ("station_rx", "observable"):
            if w.get(col):
                m &= table[col] == w[col]
        hit |= m.to_numpy()
    return hit


def residual_outliers(table: pd.DataFrame, residual: np.ndarray, k: float = 5.0, by: str = "pass_id") -> np.ndarray:
    """Rows whose fit residual is more than ``k`` robust sigmas from their ``by`` group's median.

    The filter calls this between iterations and ORs :attr:`Flag.RESIDUAL` into
    ``flags``; only unflagged rows enter the statistics.
    """
    use = (table["flags"].to_numpy() & ~int(Flag.RESIDUAL)) == 0
    return use & outliers(residual, table[by].to_numpy(), k, use)


def edit(table: pd.DataFrame, ramps: pd.DataFrame | None = None, config: EditConfig | None = None):
    """Flag ``table`` with every editor; returns (new table, summary of rows per reason).

    ``ramps`` (table or RampStore) serve the pass segmentation when ``pass_id`` is unset
    and the uplink-acquisition editor.
    """
    config = config or EditConfig()
    out = assign_passes(table, ramps, max_gap=config.max_gap) if (table["pass_id"] < 0).any() else table.copy()
    flags = out["flags"].to_numpy(dtype=np.int64)
    flags = set_flag(flags, invalid(out), Flag.INVALID)
    flags = set_flag(flags, duplicates(out), Flag.DUPLICATE)
    flags = set_flag(flags, below_elevation(out, config.min_elevation), Flag.ELEVATION)
    flags = set_flag(flags, range_outside_modulus(out), Flag.AMBIGUITY)
    flags = set_flag(flags, in_acquisition(out, store(ramps), config.sweep_rate, config.acquisition_lead),
                     Flag.UPLINK)
    untested = (flags & int(Flag.INVALID | Flag.DUPLICATE | Flag.AMBIGUITY | Flag.UPLINK)) != 0
    flags = set_flag(flags, blunders(out, config, use=~untested), Flag.BLUNDER)
    flags = set_flag(flags, short_passes(out, config.min_pass_samples, config.min_pass_duration), Flag.SHORT_PASS)
    if config.arc is not None:
        flags = set_flag(flags, outside_arc(out, *config.arc), Flag.OUTSIDE_ARC)
    flags = set_flag(flags, in_windows(out, config.windows), Flag.USER)
    out["flags"] = flags
    if np.isfinite(config.min_elevation):  # -inf: no mask asked for, nothing to warn of
        _warn_unmasked(out, flags)
    return out, summary(flags)


def _warn_unmasked(table: pd.DataFrame, flags: np.ndarray) -> None:
    """Log the used station rows the elevation mask could not judge (no ``elevation_rx``)."""
    used = (flags == 0) & (table["station_rx"].astype(str).to_numpy() != "")
    if "elevation_rx" not in table:
        if used.any():
            log.warning("no elevation_rx column: the elevation mask was not applied to %d used rows", used.sum())
        return
    blind = used & ~np.isfinite(table["elevation_rx"].to_numpy(dtype=float))
    if blind.any():
        log.warning("%d used rows have no elevation_rx (NaN): not checked against the elevation mask", blind.sum())
