"""Doppler compression to a longer count time, exact for both kinds of Doppler data.

* Count-averaged Doppler (``doppler_*``, ``range_rate``, ``sst_doppler`` with a
  count time): N back-to-back count intervals average, weighted by their count
  times, to exactly the count-averaged Doppler over their union (unit Hz or
  m/s). Other Doppler counts in cycles (TDM ``doppler_count*``) pass
  through: whether a count is per interval or a running counter is the
  reader's to state.
* Accumulated phase (``phase_*``, ``total_phase`` in cycles with no count time,
  e.g. TRK-2-34 carrier and total count phase): the difference of phase at the
  ends of a window over its length is exactly the mean frequency (Hz) over it;
  the row becomes ``<observable>_rate`` tagged at the middle of the interval.
  (UTDF counters arrive already differenced into Hz by the UTDF reader.)
* Running Doppler counts (TRK-2-34 ``doppler_count_<mode>``, cycles of the
  biased Doppler tone): differenced the same way, less ``doppler_bias_hz``,
  they become ``doppler_<mode>`` in Hz (DSN sign) over each window.

Windows never span a gap (phase: a hole over twice the usual spacing), an
overlap, a pass, an uplink ramp segment or a source file. Each segment's windows start at its first sample, so only a segment's last
window can be short; ``partial`` says what becomes of it. Edited rows
(``flags != 0``) and other observables pass through unchanged. Every output row
says which raw records went into it (``source_records``, ``record_first``,
``record_last``, ``n_samples``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from odpipe.preprocess.flags import Flag
from odpipe.preprocess.noise import third_difference_scatter
from odpipe.tracking import ramp_segments
from odpipe.tracking.passes import assign_passes
from odpipe.tracking.timetags import interval_bounds, tag_epoch
from parsers.table import COLUMNS

AVERAGED = ("range_rate", "sst_doppler")
RATE_UNITS = ("Hz", "m/s")
NEW_COLUMNS = ["n_samples", "record_first", "record_last", "source_records", "scatter"]


@dataclass
class CompressionReport:
    """What compression did: raw rows in, rows out by kind, and raw records not represented."""

    raw_rows: int = 0
    averaged_rows: int = 0
    phase_rows: int = 0
    passthrough_rows: int = 0
    partial_rows: int = 0
    dropped: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=["source", "record", "reason"]))

    def lines(self) -> list[str]:
        """Human-readable summary."""
        return [f"raw rows: {self.raw_rows}",
                f"compressed count-averaged rows: {self.averaged_rows}",
                f"phase-differenced rows: {self.phase_rows}",
                f"passed through unchanged: {self.passthrough_rows}",
                f"partial (short) windows: {self.partial_rows}",
                f"raw records not represented: {len(self.dropped)}"]


def _is_averaged(df: pd.DataFrame) -> np.ndarray:
    obs = df["observable"].astype(str)
    return ((obs.str.startswith("doppler") | obs.isin(AVERAGED)).to_numpy()
            & df["unit"].isin(RATE_UNITS).to_numpy()
            & (df["count_time"].to_numpy(dtype=float) > 0) & (df["flags"].to_numpy() == 0))


def _is_phase(df: pd.DataFrame) -> np.ndarray:
    obs = df["observable"].astype(str)
    return ((obs.str.startswith("phase") | (obs == "total_phase")).to_numpy()
            & (df["unit"].to_numpy() == "cycles") & (df["count_time"].fillna(0).to_numpy() == 0)
            & (df["flags"].to_numpy() == 0))


def _is_running_count(df: pd.DataFrame) -> np.ndarray:
    """Running Doppler counts (TRK-2-34 ``doppler_count_<mode>``, cycles of the biased Doppler tone
    accumulated since the start of a series; each record's count time is the time since the last)."""
    return (df["observable"].astype(str).str.startswith("doppler_count_").to_numpy()
            & (df["unit"].to_numpy() == "cycles") & (df["flags"].to_numpy() == 0)
            & ("doppler_bias_hz" in df.columns))


def _segments(df: pd.DataFrame, start, end, ramps, tol_ns, contiguous: bool, delay_ns: int):
    """Sort order and segment id (sorted) of runs that windows may not cross."""
    ramp = ramp_segments.segment_index(df["station_tx"].to_numpy(), df["ramped"].to_numpy(), start - delay_ns,
                                       ramps)
    src = pd.factorize(df["source"])[0]
    order = np.lexsort((start, ramp, src, df["pass_id"].to_numpy()))
    brk = np.zeros(len(df), dtype=bool)
    brk[0] = True
    for key in (df["pass_id"].to_numpy(), src, ramp):
        k = key[order]
        brk[1:] |= k[1:] != k[:-1]
    if contiguous:
        brk[1:] |= np.abs(start[order][1:] - end[order][:-1]) > tol_ns
    return order, np.cumsum(brk) - 1


def _group_records(records: np.ndarray, group: np.ndarray, n_groups: int) -> list:
    cuts = np.flatnonzero(np.diff(group)) + 1
    return np.split(records, cuts) if n_groups else []


# Media columns of a Doppler row are changes of the delay over its count interval (odpipe.media.apply):
# over a window they add up; of accumulated phase, the window's change is the difference of its ends.
INTERVAL_CHANGES = ("tropo_m", "iono_m", "media_m", "media_ru")


def _window_changes(sub: pd.DataFrame, a: np.ndarray, b: np.ndarray, per_interval: bool) -> dict:
    """Media columns of windows [a, b] of rows: sums over rows a+1..b (per-interval changes, running
    counts) or x[b] - x[a] (delays at samples, accumulated phase)."""
    out = {}
    for col in INTERVAL_CHANGES:
        if col in sub:
            x = np.nan_to_num(sub[col].to_numpy(dtype=float))
            out[col] = (np.cumsum(x)[b] - np.cumsum(x)[a]) if per_interval else x[b] - x[a]
    return out


def _extra_columns(sub: pd.DataFrame, group: np.ndarray, first: np.ndarray, weights: np.ndarray,
                   n_groups: int) -> dict:
    """Format-specific columns of the compressed rows.

    Media changes (:data:`INTERVAL_CHANGES`) add up over the window; other
    floats (e.g. elevation) become count-time-weighted means;
    integer codes are kept where constant over the window and set to -1 where
    not (raw parts of the observable, counters); other columns keep the first value.
    """
    out = {}
    for col in sub.columns:
        if col in COLUMNS or col in NEW_COLUMNS:
            continue
        kind = sub[col].dtype.kind
        if col in INTERVAL_CHANGES:
            out[col] = np.bincount(group, weights=np.nan_to_num(sub[col].to_numpy(dtype=float)), minlength=n_groups)
        elif kind == "f":
            x = sub[col].to_numpy(dtype=float)
            out[col] = np.bincount(group, weights=x * weights, minlength=n_groups) / np.bincount(
                group, weights=weights, minlength=n_groups)
        elif kind in "iu":
            x = sub[col].to_numpy()
            same = np.minimum.reduceat(x, first) == np.maximum.reduceat(x, first)
            out[col] = np.where(same, x[first], -1)
    return out


def _compress_averaged(df, ramps, count_ns, tol_ns, delay_ns):
    epoch = df["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64)
    start, end = interval_bounds(epoch, df["count_time"].to_numpy(), df["tag"].to_numpy())
    order, seg = _segments(df, start, end, ramps, tol_ns, contiguous=True, delay_ns=delay_ns)
    sub = df.iloc[order].reset_index(drop=True)
    s, e = start[order], end[order]
    first_of_seg = np.r_[0, np.flatnonzero(np.diff(seg)) + 1]
    seg_start = s[first_of_seg][seg]
    window = (s - seg_start + tol_ns) // count_ns
    newgrp = np.r_[True, (seg[1:] != seg[:-1]) | (window[1:] != window[:-1])]
    grp = np.cumsum(newgrp) - 1
    ng = int(grp[-1]) + 1
    first = np.flatnonzero(newgrp)
    last = np.r_[first[1:] - 1, len(sub) - 1]
    ct = sub["count_time"].to_numpy(dtype=float)
    v = sub["value"].to_numpy(dtype=float)
    ref = v[first][grp]  # subtract each window's first value: sums stay precise
    total_ct = np.bincount(grp, weights=ct, minlength=ng)
    value = v[first] + np.bincount(grp, weights=(v - ref) * ct, minlength=ng) / total_ct
    scatter, _ = third_difference_scatter(v, grp, ng)
    ratio = np.sqrt(ct[first] / total_ct)
    sigma = np.where(np.isfinite(scatter), scatter, sub["sigma"].to_numpy(dtype=float)[first]) * ratio
    out = sub.iloc[first].reset_index(drop=True)
    out["epoch"] = tag_epoch(s[first], e[last], out["tag"].to_numpy()).view("datetime64[ns]")
    out["value"] = value
    out["sigma"] = sigma
    out["count_time"] = (e[last] - s[first]) / 1e9
    records = sub["record"].to_numpy()
    out["record_first"] = records[first]
    out["record_last"] = records[last]
    out["n_samples"] = np.bincount(grp, minlength=ng)
    out["source_records"] = _group_records(records, grp, ng)
    out["scatter"] = scatter
    for col, x in _extra_columns(sub, grp, first, ct, ng).items():
        out[col] = x
    return out


def _compress_phase(df, ramps, count_ns, tol_ns, delay_ns, per_interval: bool = False):
    t = df["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64)
    order, seg = _segments(df, t, t, ramps, tol_ns, contiguous=False, delay_ns=delay_ns)
    sub = df.iloc[order].reset_index(drop=True)
    t = t[order]
    # a hole longer than twice the usual sample spacing may hide a loss of lock: never difference across it
    step = np.diff(t)
    usual = pd.Series(step).groupby(seg[1:]).transform("median").to_numpy()
    seg = np.cumsum(np.r_[True, (seg[1:] != seg[:-1]) | (step > 2 * usual)]) - 1
    phase = sub["value"].to_numpy(dtype=float)
    first_of_seg = np.r_[0, np.flatnonzero(np.diff(seg)) + 1]
    last_of_seg = np.r_[first_of_seg[1:] - 1, len(sub) - 1]
    rel = (t - t[first_of_seg][seg]) % count_ns
    node = (rel <= tol_ns) | (rel >= count_ns - tol_ns)
    node[last_of_seg] = True
    nodes = np.flatnonzero(node)
    a, b = nodes[:-1], nodes[1:]
    keep = seg[a] == seg[b]
    a, b = a[keep], b[keep]
    span_s = (t[b] - t[a]) / 1e9
    # samples a..b belong to window j; label each sample by the window that starts at or before it
    win = np.full(len(sub), -1)
    win[a] = np.arange(len(a))
    win = np.maximum.accumulate(win)
    scatter, _ = third_difference_scatter(phase, np.where(win >= 0, win, len(a)), len(a) + 1)
    scatter = scatter[:-1]
    sig_phase = np.where(np.isfinite(scatter), scatter, sub["sigma"].to_numpy(dtype=float)[a])
    out = sub.iloc[a].reset_index(drop=True)
    out["epoch"] = ((t[a] + t[b]) // 2).view("datetime64[ns]")
    out["tag"] = "interval_mid"
    out["observable"] = out["observable"] + "_rate"
    out["unit"] = "Hz"
    out["value"] = (phase[b] - phase[a]) / span_s
    out["sigma"] = np.sqrt(2.0) * sig_phase / span_s
    out["count_time"] = span_s
    records = sub["record"].to_numpy()
    out["record_first"] = records[a]
    out["record_last"] = records[b]
    out["n_samples"] = b - a + 1
    out["source_records"] = [records[i:j + 1] for i, j in zip(a, b)]
    out["scatter"] = scatter * np.sqrt(2.0) / span_s
    for col, x in _window_changes(sub, a, b, per_interval).items():
        out[col] = x
    covered = (win >= 0) & (np.arange(len(sub)) <= np.append(b, -1)[win])
    unused = sub.loc[~covered, ["source", "record"]].assign(reason="phase sample without a partner")
    return out, unused


def _passthrough(df):
    out = df.copy()
    rec = out["record"].to_numpy()
    out["n_samples"] = 1
    out["record_first"] = rec
    out["record_last"] = rec
    out["source_records"] = list(rec.reshape(-1, 1))
    out["scatter"] = np.nan
    return out


def compress(table: pd.DataFrame, count_time: float = 60.0, *, ramps: pd.DataFrame | None = None,
             partial: str = "keep", tol: float = 1e-4, max_gap: float = 600.0, ramp_delay: float = 0.0):
    """Compress Doppler in ``table`` to ``count_time`` (s); returns (table, CompressionReport).

    ``partial``: a window shorter than ``count_time`` by more than ``tol`` (s) is
    kept as a shorter count ("keep"), kept with the PARTIAL_COUNT flag ("flag"),
    or left out and its raw records listed in the report ("drop"). Passes are
    assigned first (``max_gap``, s) when ``pass_id`` is unset. Sigma of a
    compressed row is the per-sample scatter (third differences, or the a priori
    sigma when a window has under 4 samples) times sqrt(raw count / new count).
    The ramp in force for a sample is looked up ``ramp_delay`` s (e.g. the
    round-trip light time, when known) before its count starts.
    """
    if partial not in ("keep", "flag", "drop"):
        raise ValueError(f"partial must be keep, flag or drop, not {partial!r}")
    ramps = ramp_segments.store(ramps)
    if (table["pass_id"] < 0).any():
        table = assign_passes(table, ramps, max_gap=max_gap, ramp_delay=ramp_delay)
    count_ns, tol_ns, delay_ns = (int(round(x * 1e9)) for x in (count_time, tol, ramp_delay))
    avg, pha, cnt = _is_averaged(table), _is_phase(table), _is_running_count(table)
    report = CompressionReport(raw_rows=len(table))
    parts, dropped = [], []
    if avg.any():
        parts.append(_compress_averaged(table[avg], ramps, count_ns, tol_ns, delay_ns))
        report.averaged_rows = len(parts[-1])
    if pha.any():
        rows, unused = _compress_phase(table[pha], ramps, count_ns, tol_ns, delay_ns)
        parts.append(rows)
        dropped.append(unused)
        report.phase_rows = len(rows)
    if cnt.any():  # differenced like phase: mean biased Doppler over each window, less the bias
        rows, unused = _compress_phase(table[cnt], ramps, count_ns, tol_ns, delay_ns, per_interval=True)
        rows["observable"] = rows["observable"].str.replace("doppler_count_", "doppler_", regex=False) \
            .str.removesuffix("_rate")
        rows["value"] = rows["value"] - rows["doppler_bias_hz"].to_numpy(float)
        parts.append(rows)
        dropped.append(unused)
        report.phase_rows += len(rows)
    compressed = pd.concat(parts, ignore_index=True) if parts else None
    if compressed is not None:
        short = compressed["count_time"].to_numpy() < count_time - tol
        report.partial_rows = int(short.sum())
        if partial == "flag":
            compressed.loc[short, "flags"] = compressed.loc[short, "flags"] | int(Flag.PARTIAL_COUNT)
        elif partial == "drop":
            gone = compressed[short]
            dropped.append(pd.DataFrame({"source": np.repeat(gone["source"].to_numpy(), gone["n_samples"]),
                                         "record": np.concatenate(list(gone["source_records"])) if len(gone) else [],
                                         "reason": "partial window"}))
            compressed = compressed[~short]
    rest = _passthrough(table[~(avg | pha | cnt)])
    report.passthrough_rows = len(rest)
    out = pd.concat([p for p in (compressed, rest) if p is not None], ignore_index=True)
    out = out.sort_values(["epoch", "pass_id"], kind="stable").reset_index(drop=True)
    if dropped:
        report.dropped = pd.concat(dropped, ignore_index=True)
    return out, report
