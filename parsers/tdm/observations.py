"""TDM :class:`Message` <-> TrackingTable and ramp table.

Rows keep the TDM ``keyword``, ``segment`` (index), ``line`` (in the file),
``time_system``, ``freq_offset`` (Hz, FREQ_OFFSET of the segment) and ``range_modulus``
(in the row's unit) beside the contract columns; ``record`` is the data line's index in
the file. Values are SI (see :mod:`parsers.tdm.keywords`). Tags: integrated types
(DOPPLER_INTEGRATED, DOPPLER_COUNT, RECEIVE_FREQ*) follow INTEGRATION_REF and have
``count_time`` = INTEGRATION_INTERVAL; the others follow TIMETAG_REF (default receive).
Stations: a ``..._n`` keyword belongs to PARTICIPANT_n; other rows go from the first to the last
participant of PATH (or PATH_1). ``RECEIVE_FREQ_n`` of the path's last participant was sent by the
first of a three-participant PATH (1,2,1 or 1,2,3); ``spacecraft`` is the middle one of such a PATH,
or the sender of a two-participant one (one-way down), else ''. TRANSMIT_FREQ_n rows (with
TRANSMIT_FREQ_RATE_n at the same epoch, else rate 0) also make the ramp table, and rows transmitted
by a station that has ramps are marked ``ramped``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from parsers import table as tt
from parsers.errors import ParseError, ParseReport, handle
from parsers.tdm import keywords as kw
from parsers.tdm import times
from parsers.tdm.message import Message, Segment

_REF = {"START": "interval_start", "MIDDLE": "interval_mid", "END": "interval_end"}
_TAG = {"TRANSMIT": "transmit", "RECEIVE": "receive"}
EXTRA = {"keyword": "str", "segment": "int64", "line": "int64", "time_system": "str", "freq_offset": "float64",
         "range_modulus": "float64"}


def _number(meta: dict, key: str) -> float:
    return float(meta[key]) if key in meta else np.nan


def _segment_rows(seg: Segment, index: int, first: int, path, errors, report: ParseReport) -> pd.DataFrame:
    meta = seg.meta
    keys = np.array(seg.keyword, dtype=object)
    lines = np.array(seg.line, dtype=np.int64)
    text = pd.Series(seg.value, dtype=object)
    values = pd.to_numeric(text, errors="coerce").to_numpy(np.float64)
    epochs = times.from_text(np.array(seg.epoch, dtype=object))
    bad = np.isnat(epochs) | (np.isnan(values) & ~text.str.lower().isin(["nan"]).to_numpy())
    for i in np.flatnonzero(bad):
        what = "epoch" if np.isnat(epochs[i]) else "value"
        handle(ParseError(path, f"{keys[i]}: bad {what} in {seg.epoch[i]!r} {seg.value[i]!r}",
                          line=int(lines[i]), record=keys[i]), errors, report)
    good = ~bad
    keys, lines, values, epochs = keys[good], lines[good], values[good], epochs[good]
    record = first + np.flatnonzero(good)
    n = len(keys)
    range_units = meta.get("RANGE_UNITS", "km")
    unit = np.empty(n, dtype=object)
    factor = np.empty(n)
    observable = np.empty(n, dtype=object)
    angles = kw.ANGLE_NAMES.get(meta.get("ANGLE_TYPE"), ("angle_1", "angle_2"))
    for key in set(keys):
        sel = keys == key
        unit[sel], factor[sel] = kw.unit_and_factor(key, range_units)
        observable[sel] = {"ANGLE_1": angles[0], "ANGLE_2": angles[1]}.get(key, kw.DATA[key][0])
    participants = {i: meta.get(f"PARTICIPANT_{i}", "") for i in range(1, 6)}
    path_ = [int(p) for p in meta.get("PATH", meta.get("PATH_1", "0")).split(",")]
    tx = np.full(n, participants.get(path_[0], ""), dtype=object)
    rx = np.full(n, participants.get(path_[-1], ""), dtype=object)
    spacecraft = np.full(n, participants.get(path_[1], "") if len(path_) == 3 else "", dtype=object)
    for key in set(keys):
        p = kw.participant(key)
        if p is not None:
            sel = keys == key
            (tx if key.startswith("TRANSMIT") else rx)[sel] = participants[p]
            (rx if key.startswith("TRANSMIT") else tx)[sel] = ""
            if key.startswith("RECEIVE") and p == path_[-1]:  # the path's receiver: its transmitter is the path's
                if len(path_) == 3:                            # first (1,2,1 or 1,2,3); one-way down (2,1): none
                    tx[sel] = participants.get(path_[0], "")
                elif len(path_) == 2:
                    spacecraft[sel] = participants.get(path_[0], "")
    integrated = np.isin(keys, list(kw.INTEGRATED))
    tag = np.where(integrated, _REF.get(meta.get("INTEGRATION_REF"), "interval_mid"),
                   _TAG[meta.get("TIMETAG_REF", "RECEIVE")])
    count_time = np.where(integrated, _number(meta, "INTEGRATION_INTERVAL"), 0.0)
    num, den = _number(meta, "TURNAROUND_NUMERATOR"), _number(meta, "TURNAROUND_DENOMINATOR")
    modulus = np.where(keys == "RANGE", _number(meta, "RANGE_MODULUS") * factor, np.nan)
    scale = meta["TIME_SYSTEM"]
    return tt.build(n, epoch=times.to_utc(epochs, scale), tag=tag, observable=observable, value=values * factor,
                    unit=unit, count_time=count_time, station_tx=tx, station_rx=rx, spacecraft=spacecraft,
                    band_up=meta.get("TRANSMIT_BAND", ""), band_down=meta.get("RECEIVE_BAND", ""),
                    transponder_ratio=num / den if den else np.nan, record=record, flags=0,
                    keyword=keys, segment=np.int64(index), line=lines, time_system=scale,
                    freq_offset=_number(meta, "FREQ_OFFSET"), range_modulus=modulus)


def tracking(msg: Message, source: str, path, errors: str, report: ParseReport) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(TrackingTable, ramp table) of ``msg``."""
    parts, first = [], 0
    for i, seg in enumerate(msg.segments):
        parts.append(_segment_rows(seg, i, first, path, errors, report))
        first += len(seg.keyword)
    df = pd.concat(parts, ignore_index=True) if parts else tt.empty(EXTRA)
    df["source"] = source
    df = df.sort_values(["epoch", "record"], kind="stable").reset_index(drop=True)
    ramps = _ramps(df, msg, source)
    df["ramped"] = df["station_tx"].isin(set(ramps["station"])) & ~df["keyword"].str.startswith("TRANSMIT")
    return df, ramps


def _ramps(df: pd.DataFrame, msg: Message, source: str) -> pd.DataFrame:
    freq = df[df["keyword"].str.match(r"^TRANSMIT_FREQ_\d$")]
    if freq.empty:
        return tt.empty_ramps()
    rate = df[df["keyword"].str.match(r"^TRANSMIT_FREQ_RATE_\d$")]
    rate_key = rate.assign(n=rate["keyword"].str[-1])[["segment", "n", "epoch", "value"]]
    f = freq.assign(n=freq["keyword"].str[-1]).merge(rate_key, on=["segment", "n", "epoch"], how="left",
                                                      suffixes=("", "_rate"))
    bands = [s.meta.get("TRANSMIT_BAND", "") for s in msg.segments]
    ramps = pd.DataFrame({
        "station": f["station_tx"].to_numpy(), "start": f["epoch"].to_numpy(), "end": np.datetime64("NaT", "ns"),
        "freq_hz": f["value"].to_numpy(), "rate_hz_s": f["value_rate"].fillna(0.0).to_numpy(),
        "band": [bands[s] for s in f["segment"]], "source": source, "record": f["record"].to_numpy(),
    }).sort_values(["station", "start", "record"], kind="stable")
    ramps["end"] = ramps.groupby("station")["start"].shift(-1)
    return ramps.sort_values(["start", "record"], kind="stable").reset_index(drop=True)


def _file_values(si: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """TDM-unit values that give back exactly ``si`` when the reader multiplies by ``factor``."""
    x = si / factor
    for _ in range(4):
        off = (x * factor != si) & np.isfinite(si)
        if not off.any():
            break
        x[off] = np.nextafter(x[off], np.where(x[off] * factor[off] < si[off], np.inf, -np.inf))
    return x


def message(table: pd.DataFrame, meta: dict) -> Message:
    """The :class:`Message` that reads back as ``table`` (rows carry ``segment`` and ``keyword``)."""
    msg = Message(version=meta.get("version", "2.0"), header=dict(meta.get("header", {})),
                  comments=list(meta.get("comments", [])))
    rows = table.sort_values("record", kind="stable")
    for i, template in enumerate(meta["segments"]):
        part = rows[rows["segment"] == i]
        keys = part["keyword"].to_numpy(dtype=object)
        factor = np.array([kw.unit_and_factor(k, template.meta.get("RANGE_UNITS", "km"))[1] for k in keys])
        values = _file_values(part["value"].to_numpy(np.float64), factor)
        epochs = times.from_utc(part["epoch"].to_numpy("datetime64[ns]"), template.meta["TIME_SYSTEM"])
        msg.segments.append(Segment(meta=dict(template.meta), meta_comments=list(template.meta_comments),
                                    data_comments=list(template.data_comments), keyword=list(keys),
                                    epoch=list(times.to_text(epochs)), value=[repr(float(v)) for v in values],
                                    line=[0] * len(keys)))
    return msg
