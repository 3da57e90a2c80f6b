"""Ramp store: uplink frequency ramps per station, merged across files.

Any ramp table with the columns of :data:`parsers.table.RAMP_COLUMNS` (from
the ODF, TRK-2-34 or TDM readers) can be added. Each station's segments are
merged in time order; exact duplicates (the same ramp listed in two files)
are kept once. A segment without an end runs to the next segment's start
(the last one to +infinity). The store checks itself and lists what it found
in :attr:`RampStore.findings` instead of raising:

    duplicate    the same segment given twice (kept once)
    reversed     end before start (segment dropped)
    zero_length  end == start (an end-of-ramp marker; covers no time)
    overlap      a segment ends after the next one starts (the next one wins)
    gap          no segment between one end and the next start (f undefined)
    open_end     the last segment has no end time
    jump         the frequency at a join differs from the previous segment's
                 end frequency by more than ``jump_tol_hz`` (a retuning)

Evaluation, vectorized over rows; ``station`` is one name or an array of
names ('DSS-25'), ``t`` a datetime64[ns] UTC array (or anything numpy turns
into one) and the optional ``offset`` a float64 array of seconds added to
``t`` (to carry the sub-nanosecond part of a light-time solution):

    f  = store.frequency(station, t, offset)          # Hz, NaN outside coverage
    ph = store.phase(station, t0, t1, off0, off1)      # cycles, integral of f dt from t0 to t1
    fm = store.mean_frequency(station, t0, t1, off0, off1)   # Hz = phase / (t1 - t0)

For ramped Doppler with count interval Tc, the transmitted phase over the
transmit interval [t_T(start), t_T(end)] is ``phase(station_tx, t_T0, t_T1)``.
Intervals that touch a gap or leave the coverage give NaN. The phase is
computed as f_ref*(t1 - t0) + integral of (f - f_ref), f_ref being a per
station constant, with t1 - t0 taken from integer nanoseconds plus the offset
difference, so a 60 s X-band count keeps ~1e-4 cycle precision;
``mean_frequency`` avoids the large f_ref*(t1 - t0) term altogether.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from parsers.table import RAMP_COLUMNS, empty_ramps

FINDING_COLUMNS = ["station", "kind", "start", "end", "detail", "source", "record"]
_NEVER = np.iinfo(np.int64).max


@dataclass
class _Station:
    """One station's merged segments as int64 ns since 1970 and float64 Hz, Hz/s."""

    start: np.ndarray
    end: np.ndarray  # effective end: next start for open segments, _NEVER for the last open one
    freq: np.ndarray
    rate: np.ndarray
    f_ref: float
    cum_dev: np.ndarray  # cycles of (f - f_ref) from the first start to each segment start
    gaps_before: np.ndarray  # number of gaps before each segment


class RampStore:
    """Uplink ramps of many stations and files, with findings and vectorized evaluation.

    ``segments`` is the merged table in use (duplicates and reversed segments
    removed, sorted by station and start); ``findings`` lists what was found.
    """

    def __init__(self, *tables: pd.DataFrame, jump_tol_hz: float = 1e-3):
        self.jump_tol_hz = jump_tol_hz
        self._given = empty_ramps()
        self.segments = empty_ramps()
        self.findings = pd.DataFrame(columns=FINDING_COLUMNS)
        self._stations: dict[str, _Station] = {}
        for tbl in tables:
            self.add(tbl)

    def add(self, ramps: pd.DataFrame) -> None:
        """Merge a ramp table (RAMP_COLUMNS) into the store and re-validate."""
        missing = [c for c in RAMP_COLUMNS if c not in ramps.columns]
        if missing:
            raise ValueError(f"not a ramp table: missing columns {missing}")
        new = ramps[list(RAMP_COLUMNS)].copy()
        new["start"] = pd.to_datetime(new["start"]).astype("datetime64[ns]")
        new["end"] = pd.to_datetime(new["end"]).astype("datetime64[ns]")
        both = [t for t in (self._given, new) if len(t)]
        self._given = pd.concat(both, ignore_index=True) if both else empty_ramps()
        self._build()

    @property
    def stations(self) -> list[str]:
        return sorted(self._stations)

    def frequency(self, station, t, offset=0.0) -> np.ndarray:
        """Uplink frequency (Hz) at ``t`` (+ ``offset`` s); NaN where no segment covers it."""
        t_ns, off = _times(t, offset)
        out = np.full(t_ns.shape, np.nan)
        for name, rows in _by_station(station, t_ns.shape):
            s = self._stations.get(name)
            if s is None:
                continue
            k, tau, ok = _locate(s, t_ns[rows], off[rows])
            kk = np.clip(k, 0, None)
            out[rows[ok]] = (s.freq[kk] + s.rate[kk] * tau)[ok]
        return out

    def phase(self, station, t0, t1, offset0=0.0, offset1=0.0) -> np.ndarray:
        """Integral of the uplink frequency from t0 to t1 (cycles); NaN across gaps or outside."""
        dev, dur, f_ref = self._integral(station, t0, t1, offset0, offset1)
        return f_ref * dur + dev

    def mean_frequency(self, station, t0, t1, offset0=0.0, offset1=0.0) -> np.ndarray:
        """Mean uplink frequency over [t0, t1] (Hz) = phase / (t1 - t0)."""
        dev, dur, f_ref = self._integral(station, t0, t1, offset0, offset1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return f_ref + dev / dur

    def _integral(self, station, t0, t1, offset0, offset1):
        """(integral of f - f_ref in cycles, t1 - t0 in s, f_ref in Hz) per row."""
        a_ns, a_off = _times(t0, offset0)
        b_ns, b_off = _times(t1, offset1)
        a_ns, b_ns = np.broadcast_arrays(a_ns, b_ns)
        a_off, b_off = np.broadcast_to(a_off, a_ns.shape), np.broadcast_to(b_off, a_ns.shape)
        dur = (b_ns - a_ns) * 1e-9 + (b_off - a_off)
        dev = np.full(a_ns.shape, np.nan)
        f_ref = np.full(a_ns.shape, np.nan)
        for name, rows in _by_station(station, a_ns.shape):
            s = self._stations.get(name)
            if s is None:
                continue
            ka, ta, oka = _locate(s, a_ns[rows], a_off[rows])
            kb, tb, okb = _locate(s, b_ns[rows], b_off[rows])
            ka, kb = np.clip(ka, 0, None), np.clip(kb, 0, None)
            ok = oka & okb & (s.gaps_before[ka] == s.gaps_before[kb])
            ga = s.cum_dev[ka] + ta * (s.freq[ka] - s.f_ref) + 0.5 * s.rate[ka] * ta**2
            gb = s.cum_dev[kb] + tb * (s.freq[kb] - s.f_ref) + 0.5 * s.rate[kb] * tb**2
            dev[rows[ok]] = (gb - ga)[ok]
            f_ref[rows] = s.f_ref
        return dev, dur, f_ref

    def _build(self) -> None:
        """Merge, deduplicate, validate and index every station's segments."""
        findings = []
        self._stations = {}
        seg = self._given
        dup = seg.duplicated(["station", "start", "end", "freq_hz", "rate_hz_s"], keep="first")
        findings.append(_finding(seg[dup], "duplicate", seg.loc[dup, "end"], 0.0))
        seg = seg[~dup]
        rev = seg["end"].notna() & (seg["end"] < seg["start"])
        findings.append(_finding(seg[rev], "reversed", seg.loc[rev, "end"],
                                 (seg.loc[rev, "start"] - seg.loc[rev, "end"]).dt.total_seconds()))
        seg = seg[~rev]
        zero = seg["end"] == seg["start"]
        findings.append(_finding(seg[zero], "zero_length", seg.loc[zero, "end"], 0.0))
        seg = seg.sort_values(["station", "start", "record"], kind="stable")
        self.segments = seg.reset_index(drop=True)
        for name, g in seg[~zero.reindex(seg.index)].groupby("station", sort=True):
            st, found = _index_station(g, self.jump_tol_hz)
            self._stations[name] = st
            findings.extend(found)
        nonempty = [f for f in findings if len(f)]
        self.findings = (pd.concat(nonempty, ignore_index=True) if nonempty
                         else pd.DataFrame(columns=FINDING_COLUMNS))


def _index_station(g: pd.DataFrame, jump_tol_hz: float):
    """A station's arrays and its overlap/gap/open_end/jump findings."""
    start = g["start"].to_numpy().astype(np.int64)
    end_given = g["end"].to_numpy()
    open_ = np.isnat(end_given)
    nxt = np.append(start[1:], _NEVER)
    end = np.where(open_, nxt, end_given.astype(np.int64))
    freq = g["freq_hz"].to_numpy(float)
    rate = g["rate_hz_s"].to_numpy(float)
    found = []
    over = end[:-1] > start[1:]
    found.append(_finding(g.iloc[1:][over], "overlap", g["end"].iloc[:-1][over].to_numpy(),
                          (end[:-1] - start[1:])[over] / 1e9))
    end[:-1] = np.minimum(end[:-1], start[1:])
    gap = end[:-1] < start[1:]
    found.append(_finding(g.iloc[:-1][gap], "gap", g["start"].iloc[1:][gap].to_numpy(),
                          (start[1:] - end[:-1])[gap] / 1e9, start_col="end"))
    if open_[-1]:
        found.append(_finding(g.iloc[-1:], "open_end", np.array(["NaT"], "datetime64[ns]"), np.nan))
    dur = np.where(end == _NEVER, 0, end - start) / 1e9
    f_end = freq + rate * dur
    joined = ~gap
    jump = f_end[:-1][joined] - freq[1:][joined]
    big = np.abs(jump) > jump_tol_hz
    found.append(_finding(g.iloc[1:][joined][big], "jump", g["start"].iloc[1:][joined][big].to_numpy(),
                          -jump[big]))
    f_ref = float(np.round(freq[0]))
    full = dur * (freq - f_ref) + 0.5 * rate * dur**2
    cum = np.concatenate(([0.0], np.cumsum(full[:-1])))
    gaps_before = np.concatenate(([0], np.cumsum(gap)))
    return _Station(start, end, freq, rate, f_ref, cum, gaps_before), found


def _finding(rows: pd.DataFrame, kind: str, end, detail, start_col: str = "start") -> pd.DataFrame:
    """Findings of one kind for ``rows`` (detail: s for overlap/gap/reversed, Hz for jump)."""
    return pd.DataFrame({
        "station": rows["station"].to_numpy(), "kind": kind,
        "start": rows[start_col].to_numpy(), "end": np.asarray(end, dtype="datetime64[ns]"),
        "detail": np.broadcast_to(np.asarray(detail, dtype=float), (len(rows),)),
        "source": rows["source"].to_numpy(), "record": rows["record"].to_numpy(),
    })


def _times(t, offset):
    """int64 ns since 1970 and float64 s offsets, as arrays."""
    t_ns = np.atleast_1d(np.asarray(t, dtype="datetime64[ns]")).astype(np.int64)
    off = np.broadcast_to(np.asarray(offset, dtype=float), t_ns.shape)
    return t_ns, off


def _by_station(station, shape):
    """(name, row indices) per distinct station name."""
    if isinstance(station, str):
        yield station, np.arange(int(np.prod(shape)))
        return
    names = np.broadcast_to(np.asarray(station, dtype=object), shape)
    codes, uniq = pd.factorize(names)
    order = np.argsort(codes, kind="stable")
    bounds = np.searchsorted(codes[order], np.arange(len(uniq) + 1))
    for j, name in enumerate(uniq):
        yield name, order[bounds[j]:bounds[j + 1]]


def _locate(s: _Station, t_ns: np.ndarray, off: np.ndarray):
    """Segment index, seconds since its start, and whether a segment covers the time."""
    whole = np.round(off).astype(np.int64)
    t_ns, off = t_ns + whole * 1_000_000_000, off - whole  # now |off| <= 0.5 s
    k = np.searchsorted(s.start, t_ns, side="right") - 1
    k -= (k >= 0) & (t_ns == s.start[np.clip(k, 0, None)]) & (off < 0)  # just before a start
    kk = np.clip(k, 0, None)
    after_start = off >= (s.start[kk] - t_ns) * 1e-9
    before_end = (s.end[kk] == _NEVER) | (off <= (s.end[kk] - t_ns) * 1e-9)
    tau = (t_ns - s.start[kk]) * 1e-9 + off
    return k, tau, (k >= 0) & after_start & before_end
