"""Any TrackingTable (ODF, TRK-2-34, UTDF, simulated) as a CCSDS TDM 2.0: segments, keywords, ramps.

:func:`to_tdm` returns a :class:`parsers.TrackingData` that :func:`parsers.tdm.write`
writes as KVN or XML. One segment per link (transmitter, spacecraft, receiver), kind
of data, bands and count time; participants are the stations and the spacecraft,
PATH 1,2,1 (two-way) or 1,2,3 (three-way), 2,1 (one-way down). What each observable becomes:

* two/three-way Doppler F (Hz, DSN sign) -> ``RECEIVE_FREQ_n`` (Hz), the received frequency
  averaged over the count interval, INTEGRATION_INTERVAL = count time: ``f = M2 f_R - F`` with
  ``f_R`` the receiver's reference the Doppler was formed against. A constant one (the ODF
  reference frequency of ramped ODF rows, a constant uplink) goes to FREQ_OFFSET = M2 f_R, the
  line holding ``f - FREQ_OFFSET = -F`` (a segment per offset); otherwise ``f_R`` is the mean
  ramped uplink over the count interval at the receiver and the line holds ``f``.
  TURNAROUND_NUMERATOR/DENOMINATOR from the bands; the uplink ramps become ``TRANSMIT_FREQ_n``
  and ``TRANSMIT_FREQ_RATE_n`` lines at each ramp start (a segment per station);
* one-way Doppler -> ``RECEIVE_FREQ_n`` = -F with FREQ_OFFSET = the reference (ODF: S-band-scale
  reference times the band's ratio, :data:`odpipe.measurements.bands.ONE_WAY_SCALE`);
* range in m, RU or s -> ``RANGE`` (RANGE_UNITS km, RU or s; RANGE_MODULUS when given);
* range-rate (m/s) -> ``DOPPLER_INTEGRATED`` (with a count time) or ``DOPPLER_INSTANTANEOUS`` (km/s);
* antenna angles -> ``ANGLE_1``/``ANGLE_2`` (deg, ANGLE_TYPE AZEL, RADEC or XEYN);
* media and rows already read from a TDM keep their keyword.

Rows of any other kind (e.g. raw running Doppler counts: compress them first) are not
written; :func:`to_tdm` returns them as ``skipped`` so the caller can say so. Metadata keywords
follow the order of the standard's metadata table. :func:`doppler_from_tdm` is the inverse: a
TDM's received frequencies as the fit's Doppler.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.measurements.bands import ONE_WAY_SCALE, band_name, turnaround_ratio
from parsers.ramps import RampStore
from parsers.table import TrackingData
from parsers.tdm import keywords
from parsers.tdm.message import Segment

ANGLES = {("angle_az", "angle_el"): "AZEL", ("angle_ra", "angle_dec"): "RADEC", ("angle_x", "angle_y"): "XEYN"}
_PASS_THROUGH = {"tropo_dry": "TROPO_DRY", "tropo_wet": "TROPO_WET", "stec": "STEC", "pressure": "PRESSURE",
                 "temperature": "TEMPERATURE", "relative_humidity": "RHUMIDITY", "clock_bias": "CLOCK_BIAS",
                 "clock_drift": "CLOCK_DRIFT"}
_TAG_REF = {"interval_start": "START", "interval_mid": "MIDDLE", "interval_end": "END"}
_RANGE_UNITS = {"m": ("km", 1e-3), "RU": ("RU", 1.0), "s": ("s", 1.0)}


def to_tdm(data: TrackingData, originator: str = "odpipe", creation_date=None) -> tuple[TrackingData, pd.DataFrame]:
    """(TDM-ready TrackingData with ``segment``/``keyword`` per row and segment metadata, skipped rows).

    ``creation_date``: UTC (datetime64 or ISO text) for the header; default now.
    """
    t = data.table.reset_index(drop=True)
    store = RampStore(data.ramps) if data.ramps is not None and len(data.ramps) else None
    value, keyword = np.full(len(t), np.nan), np.full(len(t), "", dtype=object)
    offset = np.full(len(t), np.nan)
    obs = t["observable"].to_numpy(object)
    dop = np.isin(obs, ["doppler_2way", "doppler_3way"])
    (value[dop], offset[dop]), keyword[dop] = _two_way_receive_freq(t[dop], store), "RECEIVE_FREQ"
    one = obs == "doppler_1way"
    value[one], keyword[one] = -t.loc[one, "value"].to_numpy(float), "RECEIVE_FREQ"
    offset[one] = _one_way_reference(t[one])
    value[one & ~np.isfinite(offset)] = np.nan   # a one-way row with no reference has no received frequency
    # values stay in the TDM reader's SI units (m, m/s, rad): the writer converts to the file's
    rng = (obs == "range") & t["unit"].isin(list(_RANGE_UNITS)).to_numpy()
    value[rng], keyword[rng] = t.loc[rng, "value"].to_numpy(float), "RANGE"
    rr = obs == "range_rate"
    value[rr] = t.loc[rr, "value"].to_numpy(float)
    keyword[rr] = np.where(t.loc[rr, "count_time"].fillna(0).to_numpy() > 0, "DOPPLER_INTEGRATED",
                           "DOPPLER_INSTANTANEOUS")
    for names in ANGLES:
        for i, name in enumerate(names):
            sel = obs == name
            value[sel], keyword[sel] = t.loc[sel, "value"].to_numpy(float), f"ANGLE_{i + 1}"
    for name, key in _PASS_THROUGH.items():
        sel = obs == name
        value[sel], keyword[sel] = t.loc[sel, "value"].to_numpy(float), key
    if "keyword" in t.columns:  # rows read from a TDM keep theirs
        given = (keyword == "") & t["keyword"].fillna("").astype(str).ne("").to_numpy()
        keyword[given], value[given] = t.loc[given, "keyword"].to_numpy(object), t.loc[given, "value"].to_numpy(float)
    ok = (keyword != "") & np.isfinite(value)
    rows = t[ok].assign(tdm_value=value[ok], tdm_keyword=keyword[ok], tdm_offset=offset[ok])
    segments, parts = [], []
    for key, g in rows.groupby(_segment_key(rows), sort=False, dropna=False):
        seg, g = _segment(key, g)
        g = g.assign(segment=len(segments))
        segments.append(seg)
        parts.append(g)
    if store is not None:
        for station, g in store.segments.groupby("station", sort=True):
            seg, rp = _ramp_segment(station, g)
            segments.append(seg)
            parts.append(rp.assign(segment=len(segments) - 1))
    table = pd.concat(parts, ignore_index=True) if parts else rows
    table = table.assign(value=table["tdm_value"], keyword=table["tdm_keyword"])
    table["record"] = np.arange(len(table))
    created = np.datetime64("now", "s") if creation_date is None else np.datetime64(creation_date, "s")
    meta = {"version": "2.0", "header": {"CREATION_DATE": str(created), "ORIGINATOR": originator},
            "comments": [f"written by odpipe from {', '.join(sorted(set(map(str, t['source']))))}"
                         if "source" in t.columns and len(t) else "written by odpipe"],
            "segments": segments}
    return TrackingData(table, data.ramps, data.report, meta), t[~ok]


def _segment_key(rows: pd.DataFrame) -> list:
    kind = rows["tdm_keyword"].map(lambda k: "ANGLE" if k.startswith("ANGLE") else k)
    angle_type = rows["observable"].map(lambda o: next((v for k, v in ANGLES.items() if o in k), ""))
    return [kind, angle_type, rows["station_tx"].fillna(""), rows["station_rx"].fillna(""),
            rows["spacecraft"].astype(str), rows["band_up"].fillna(""), rows["band_down"].fillna(""),
            rows["count_time"].fillna(0.0), rows["unit"], rows["tag"], rows["tdm_offset"].fillna(0.0)]


def _segment(key, g: pd.DataFrame):
    kind, angle_type, tx, rx, sc, up, down, count, unit, tag, offset = key
    participants = [p for p in dict.fromkeys([tx, sc, rx]) if p]
    number = {p: i + 1 for i, p in enumerate(participants)}
    meta = {"TIME_SYSTEM": "UTC"}
    for p, i in number.items():
        meta[f"PARTICIPANT_{i}"] = p
    meta["MODE"] = "SEQUENTIAL"
    meta["PATH"] = ",".join(str(number[p]) for p in [tx, sc, rx] if p)
    if up:
        meta["TRANSMIT_BAND"] = band_name(up)
    if down:
        meta["RECEIVE_BAND"] = band_name(down)
    if kind == "RECEIVE_FREQ":
        g = g.assign(tdm_keyword=f"RECEIVE_FREQ_{number[rx]}")
        meta["INTEGRATION_INTERVAL"] = repr(float(count))
        meta["INTEGRATION_REF"] = _TAG_REF.get(tag, "MIDDLE")
        if up and down:
            num, den = _turnaround(up, down)
            meta["TURNAROUND_NUMERATOR"], meta["TURNAROUND_DENOMINATOR"] = str(num), str(den)
        if offset:
            meta["FREQ_OFFSET"] = repr(float(offset))
    elif kind == "RANGE":
        units = _RANGE_UNITS[unit][0]
        meta["RANGE_MODE"] = "COHERENT"
        meta["RANGE_UNITS"] = units
        modulus = _modulus(g)
        if np.isfinite(modulus):
            meta["RANGE_MODULUS"] = repr(modulus * _RANGE_UNITS[unit][1])
    elif kind == "DOPPLER_INTEGRATED":
        meta["INTEGRATION_INTERVAL"] = repr(float(count))
        meta["INTEGRATION_REF"] = _TAG_REF.get(tag, "MIDDLE")
    elif kind == "ANGLE":
        meta["ANGLE_TYPE"] = angle_type
    if kind != "RECEIVE_FREQ" and tag in ("receive", "transmit"):
        meta["TIMETAG_REF"] = tag.upper()
    meta["START_TIME"] = _ccsds(g["epoch"].min())
    meta["STOP_TIME"] = _ccsds(g["epoch"].max())
    return Segment(meta=_ordered(meta)), g


def _ramp_segment(station: str, g: pd.DataFrame):
    """TRANSMIT_FREQ_1 / TRANSMIT_FREQ_RATE_1 at each ramp start of ``station``."""
    start = g["start"].to_numpy("datetime64[ns]")
    n = len(g)
    rows = pd.DataFrame({
        "epoch": np.concatenate([start, start]),
        "tdm_value": np.concatenate([g["freq_hz"].to_numpy(float), g["rate_hz_s"].to_numpy(float)]),
        "tdm_keyword": ["TRANSMIT_FREQ_1"] * n + ["TRANSMIT_FREQ_RATE_1"] * n,
        "order": np.concatenate([np.arange(n) * 2, np.arange(n) * 2 + 1]),
    }).sort_values("order", kind="stable").drop(columns="order")
    band = str(g["band"].iloc[0]) if "band" in g.columns and len(g) else ""
    meta = {"TIME_SYSTEM": "UTC", "PARTICIPANT_1": station, "MODE": "SEQUENTIAL"}
    if band:
        meta["TRANSMIT_BAND"] = band_name(band)
    meta["START_TIME"], meta["STOP_TIME"] = _ccsds(start.min()), _ccsds(start.max())
    return Segment(meta=_ordered(meta)), rows


def _ordered(meta: dict) -> dict:
    """``meta`` in the order of the standard's metadata table."""
    return {k: meta[k] for k in keywords.ORDER if k in meta}


def _two_way_receive_freq(rows: pd.DataFrame, store: RampStore | None) -> tuple[np.ndarray, np.ndarray]:
    """(RECEIVE_FREQ, FREQ_OFFSET) in Hz of two/three-way Doppler rows F: the mean received frequency over
    the count interval is f = M2 f_R - F. A constant reference f_R (the ODF's reference frequency of ramped
    rows, a constant uplink) is given as FREQ_OFFSET = M2 f_R with RECEIVE_FREQ = f - FREQ_OFFSET = -F, so the
    reader has it back to the bit; a ramp's mean over the count (NaN offset) is written into f itself."""
    if rows.empty:
        return np.empty(0), np.empty(0)
    ref = rows["uplink_hz"].to_numpy(float)
    ramped = rows["ramped"].to_numpy(bool)
    constant = ~ramped & np.isfinite(ref)
    if "reference_hz" in rows.columns:
        given = ramped & np.isfinite(rows["reference_hz"].to_numpy(float))
        ref = np.where(given, rows["reference_hz"].to_numpy(float), ref)
        ramped, constant = ramped & ~given, constant | given
    if ramped.any() and store is not None:
        ref[ramped] = _ramp_reference(rows[ramped], store)
    f, m2 = rows["value"].to_numpy(float), _m2(rows)
    return np.where(constant, -f, m2 * ref - f), np.where(constant, m2 * ref, np.nan)


def _m2(rows: pd.DataFrame) -> np.ndarray:
    """Turnaround ratio per row: ``transponder_ratio`` (TURNAROUND_NUMERATOR/DENOMINATOR), else the bands'."""
    m2 = rows["transponder_ratio"].to_numpy(float)
    return np.where(np.isfinite(m2), m2, turnaround_ratio(rows["band_up"].to_numpy(object),
                                                          rows["band_down"].to_numpy(object)))


def _ramp_reference(rows: pd.DataFrame, store: RampStore) -> np.ndarray:
    """The receiver's reference (Hz): the mean over each count interval at the receiver of its own ramp if it
    has one, else of the transmitter's (as the Doppler model of :mod:`odpipe.measurements.compute` takes it)."""
    from odpipe.tracking.timetags import interval_bounds

    s, e = interval_bounds(rows["epoch"].to_numpy("datetime64[ns]").view(np.int64),
                           rows["count_time"].to_numpy(float), rows["tag"].to_numpy(object))
    rx, tx = rows["station_rx"].to_numpy(object), rows["station_tx"].to_numpy(object)
    st = np.where(np.isin(rx, store.stations), rx, tx)
    return store.mean_frequency(st, s.astype("datetime64[ns]"), e.astype("datetime64[ns]"))


def doppler_from_tdm(data: TrackingData) -> tuple[TrackingData, int]:
    """(``data`` with its ``RECEIVE_FREQ_n`` rows as DSN Doppler, the number of rows left as received frequency).

    The writer's inverse: F = M2 f_R - (RECEIVE_FREQ + FREQ_OFFSET) in Hz, positive receding, M2 from
    TURNAROUND_NUMERATOR/DENOMINATOR or the bands. The receiver's reference f_R is FREQ_OFFSET / M2 where the
    segment gives FREQ_OFFSET (kept as ``reference_hz``; then F = -RECEIVE_FREQ), else the mean over the count
    of the ramps' TRANSMIT_FREQ_n/TRANSMIT_FREQ_RATE_n lines (the receiver's own, else the transmitter's). A row
    of a three-participant PATH becomes ``doppler_2way`` (transmitter = receiver) or ``doppler_3way``; with its
    transmitter's ramps it is ``ramped``, else its uplink is f_R. A one-way row (PATH 2,1) becomes
    ``doppler_1way`` against the spacecraft's own TRANSMIT_FREQ_n (as the standard's one-way example gives it),
    else against FREQ_OFFSET (odpipe's one-way rows: F = -RECEIVE_FREQ). The TRANSMIT_FREQ rows leave the table
    (they are the ramp table); rows with no reference (no FREQ_OFFSET, no ramp coverage) stay ``receive_freq``.
    """
    t = data.table
    if "keyword" not in t.columns:
        return data, 0
    t = t[~t["keyword"].fillna("").astype(str).str.startswith("TRANSMIT_FREQ")].reset_index(drop=True)
    rf = ((t["observable"] == "receive_freq")   # a numbered receiver's, not yet made Doppler
          & t["keyword"].astype(str).str.match(r"^RECEIVE_FREQ_\d$")).to_numpy().copy()
    if not rf.any():
        return TrackingData(t, data.ramps, data.report, data.meta), 0
    t = t.copy()
    rows = t[rf]
    received = rows["value"].to_numpy(float)
    offset = rows["freq_offset"].to_numpy(float) if "freq_offset" in rows.columns else np.full(len(rows), np.nan)
    tx = rows["station_tx"].fillna("").to_numpy(object)
    one = (tx == "") & rows["spacecraft"].fillna("").ne("").to_numpy()
    m2 = np.where(one, 1.0, _m2(rows))
    ref = offset / m2
    value = np.where(np.isfinite(offset), -received, np.nan)   # f_R = FREQ_OFFSET / M2: F = -RECEIVE_FREQ
    if data.ramps is not None and len(data.ramps):
        store = RampStore(data.ramps)
        ramp = ~one & (tx != "") & ~np.isfinite(ref)
        if ramp.any():
            ref[ramp] = _ramp_reference(rows[ramp], store)
        own = one & np.isin(rows["spacecraft"].to_numpy(object), store.stations)  # its TRANSMIT_FREQ_n at the tag
        if own.any():
            f = store.frequency(rows["spacecraft"].to_numpy(object)[own], rows["epoch"].to_numpy("datetime64[ns]")[own])
            own[own] = np.isfinite(f)
            ref[own] = f[np.isfinite(f)]
        sel = ramp | own
        value[sel] = m2[sel] * ref[sel] - (received[sel] + np.nan_to_num(offset[sel]))
    ok = np.isfinite(value) & (one | (tx != ""))
    idx = np.flatnonzero(rf)[ok]
    ramped = t.loc[idx, "ramped"].to_numpy(bool)
    two = tx[ok] == t.loc[idx, "station_rx"].to_numpy(object)
    t.loc[idx, "observable"] = np.where(one[ok], "doppler_1way", np.where(two, "doppler_2way", "doppler_3way"))
    t.loc[idx, "value"] = value[ok]
    t.loc[idx, "uplink_hz"] = np.where(ramped, np.nan, ref[ok])
    t["reference_hz"] = np.nan
    t.loc[idx, "reference_hz"] = np.where(one[ok], np.nan, ref[ok])
    rf[idx] = False
    return TrackingData(t, data.ramps, data.report, data.meta), int(rf.sum())


def _one_way_reference(rows: pd.DataFrame) -> np.ndarray:
    """The one-way reference (Hz), written as FREQ_OFFSET beside RECEIVE_FREQ = -F."""
    ref = rows["uplink_hz"].to_numpy(float)
    if "odf_data_type" in rows.columns and len(rows):
        ref = ref * np.array([ONE_WAY_SCALE.get(band_name(b), np.nan) for b in rows["band_down"]])
    return ref


def _turnaround(up, down) -> tuple[int, int]:
    from fractions import Fraction

    f = Fraction(float(turnaround_ratio([up], [down])[0])).limit_denominator(10000)
    return f.numerator, f.denominator


def _modulus(g: pd.DataFrame) -> float:
    for col in ("range_modulus_ru", "range_modulus"):
        if col in g.columns:
            m = g[col].to_numpy(float)
            if np.isfinite(m).any():
                return float(np.nanmax(m))
    return np.nan


def _ccsds(t) -> str:
    """CCSDS epoch text (UTC, ms)."""
    return str(np.datetime64(t, "ms"))
