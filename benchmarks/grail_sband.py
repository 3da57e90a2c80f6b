"""What drives GRAIL-B's S-band one-way downlink (issue #24 item 4), measured against a fitted orbit.

Each daily arc's raw one-way samples (both bands, every ``--every``-th, inside the arc) are computed along the
arc's fitted orbit (its ``trajectory.oem``) with a nominal oscillator (y0 = y1 = 0). A one-way residual r (Hz) at
downlink reference f is then the oscillator's fractional offset ``y = -r / f`` plus the orbit's error, the
uncalibrated media and the 1-s noise (together ~1e-11). Printed per band, station and series of samples (a gap
over ``--gap`` s starts a new series): the mean y, its RMS about a line and the line's slope (1/s); beside them
the arc's fitted X-band oscillator (its parameters.csv).

``--acquisition-only``: the leave-one-out candidate "sband" run again (into ``OUT/sband_acq``, the nightly chain)
with the S-band one-way series that begin within ``--after-two-way`` s of the end of a two-way series of the
spacecraft removed at ingest: the transponder coasting from its last uplink-locked frequency, which no offset and
drift follow (m/s off a line), leaving the acquisition series before each two-way lock. A what-if for judging
what the S band can give, not a pipeline rule.

    nice .venv/bin/python benchmarks/grail_sband.py [--runs runs/out] [--arcs grail_b_2012_04_10 ...] [--every 10]
    nice .venv/bin/python benchmarks/grail_sband.py --acquisition-only [--out out/grail_loo]
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

import odpipe.pipeline.run as pipeline_run
from grail_arcs import DAILY, RUNS, run_start, run_variant
from grail_loo import CANDIDATES
from odpipe.analysis.overlap import oem_trajectory
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.measurements import MeasurementSetup, compute
from odpipe.measurements.residuals import residuals
from odpipe.measurements.bands import ONE_WAY_SCALE
from odpipe.pipeline import setup as build
from odpipe.pipeline.config import load_config
from odpipe.pipeline.ingest import ingest


def series(rows: pd.DataFrame, gap_s: float) -> np.ndarray:
    """A series number per row: a new one at each station, band or gap over ``gap_s`` s (rows in time order)."""
    t = rows["epoch"].to_numpy("datetime64[ns]").astype(np.int64) / 1e9
    key = rows["station_rx"].astype(str) + ":" + rows["band_down"].astype(str)
    new = np.r_[True, (key.to_numpy()[1:] != key.to_numpy()[:-1]) | (np.diff(t) > gap_s)]
    return np.cumsum(new)


def one_way_rows(name: str, every: int) -> pd.DataFrame:
    """Arc ``name``'s raw one-way samples of its spacecraft inside the arc (10 s from its ends), every
    ``every``-th per station and band."""
    cfg = load_config(RUNS / f"{name}.toml")
    table = ingest(cfg.data.files, cfg.data.errors, cfg.arc.spacecraft).table
    epoch = table["epoch"].to_numpy("datetime64[ns]")
    margin = np.timedelta64(10, "s")   # the light time and count: the signal left inside the fitted orbit's span
    keep = ((table["observable"] == "doppler_1way") & (table["spacecraft"].astype(str) == cfg.arc.spacecraft)
            & (epoch >= np.datetime64(cfg.arc.start) + margin) & (epoch <= np.datetime64(cfg.arc.end) - margin))
    rows = table[keep.to_numpy()].sort_values(["station_rx", "band_down", "epoch"], kind="stable")
    return rows[rows.groupby(["station_rx", "band_down"]).cumcount().to_numpy() % every == 0].reset_index(drop=True)


def oscillator_table(name: str, runs: Path, gap_s: float, every: int) -> pd.DataFrame:
    """Per series of one-way samples of arc ``name``: station, band, span, n, mean y, its RMS about a line and the
    line's slope (1/s), y = -(observed - computed) / f_ref with a nominal oscillator along the fitted orbit."""
    cfg = load_config(RUNS / f"{name}.toml")
    trajectory = oem_trajectory(runs / name / "current" / "trajectory.oem")
    meas = MeasurementSetup(build.force_model(cfg).ephemeris, build.station_catalog(cfg), gcrs_to_itrs=gcrs_to_itrs,
                            station_displacement=build.station_displacement(cfg.measurements))
    rows = one_way_rows(name, every)
    ev = compute(rows, {cfg.arc.spacecraft: trajectory}, meas)
    res, _ = residuals(rows, ev)
    scale = rows["band_down"].astype(str).map(ONE_WAY_SCALE).to_numpy(float)
    y = -res / (rows["uplink_hz"].to_numpy(float) * scale)
    rows = rows.assign(y=y, series=series(rows, gap_s))
    out = []
    for _, g in rows[np.isfinite(y)].groupby("series"):
        t = g["epoch"].to_numpy("datetime64[ns]").astype(np.int64) / 1e9
        fit = np.polyfit(t - t.mean(), g["y"], 1) if len(g) > 2 else (np.nan, g["y"].mean())
        out.append({"arc": name, "station": g["station_rx"].iloc[0], "band": g["band_down"].iloc[0],
                    "start": g["epoch"].min(), "end": g["epoch"].max(), "n": len(g), "y_mean": g["y"].mean(),
                    "y_rms_about_line": np.std(g["y"] - np.polyval(fit, t - t.mean())), "slope_per_s": fit[0],
                    "f_ref_hz": float(g["uplink_hz"].iloc[0])})
    return pd.DataFrame(out)


def after_two_way(table: pd.DataFrame, within_s: float, gap_s: float = 600.0) -> np.ndarray:
    """True for the S-band one-way rows of series (``gap_s``) that begin within ``within_s`` s after the end of a
    two-way Doppler series (any station) of the same spacecraft."""
    t = table["epoch"].to_numpy("datetime64[ns]").astype(np.int64) / 1e9
    two = np.sort(t[(table["observable"] == "doppler_2way").to_numpy()])
    ends = two[np.r_[np.diff(two) > gap_s, True]] if two.size else two
    one = ((table["observable"] == "doppler_1way") & (table["band_down"].astype(str) == "S")).to_numpy()
    out = np.zeros(len(table), bool)
    idx = np.flatnonzero(one)
    if idx.size == 0 or ends.size == 0:
        return out
    rows = table.iloc[idx].assign(_t=t[idx], _i=idx).sort_values(["station_rx", "_t"])
    first = rows["_t"].groupby(series(rows.rename(columns={"_t": "t"}), gap_s)).transform("min").to_numpy()
    k = np.searchsorted(ends, first, side="right") - 1
    since = np.where(k >= 0, first - ends[np.maximum(k, 0)], np.inf)
    out[rows["_i"].to_numpy()] = since <= within_s
    return out


def _acquisition_only(within_s: float):
    """An ingest without the S-band one-way series that begin within ``within_s`` s after a two-way series ends."""
    def read(files, errors, *spacecraft):
        data = ingest(files, errors, *spacecraft)
        return replace(data, table=data.table[~after_two_way(data.table, within_s)].reset_index(drop=True))
    return read


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=RUNS / "out", help="folder of the arcs' run folders")
    ap.add_argument("--arcs", nargs="*", default=DAILY)
    ap.add_argument("--gap", type=float, default=600.0, help="s: a longer gap starts a new series")
    ap.add_argument("--every", type=int, default=10, help="every n-th raw sample")
    ap.add_argument("--acquisition-only", action="store_true", help="run the what-if chain (see above)")
    ap.add_argument("--after-two-way", type=float, default=300.0, help="s: coasting series begin within this")
    ap.add_argument("--out", type=Path, default=Path("out/grail_loo"), help="the leave-one-out folder")
    args = ap.parse_args()
    pd.set_option("display.width", 200)
    if args.acquisition_only:
        out = args.out.resolve()
        saved, pipeline_run.ingest = pipeline_run.ingest, _acquisition_only(args.after_two_way)
        try:
            print(run_variant(out / "sband_acq", CANDIDATES["sband"], run_start(out / "start")))
        finally:
            pipeline_run.ingest = saved
        return
    for name in args.arcs:
        tab = oscillator_table(name, args.runs, args.gap, args.every)
        params = pd.read_csv(args.runs / name / "current" / "parameters.csv").set_index("name")
        osc = params[params["kind"] == "clock"]["estimate"]
        print(f"\n{name}: fitted X oscillator {dict(osc)}")
        print(tab.drop(columns="arc").to_string(index=False, float_format=lambda v: f"{v:.4g}"))


if __name__ == "__main__":
    main()
