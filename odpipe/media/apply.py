"""Media corrections of a TrackingTable, leg by leg, at each leg's own time and frequency.

For every row the downlink leg is evaluated at the receiving station at
reception, and (two- and three-way data) the uplink leg at the transmitting
station at ``reception - round-trip light time``. Range rows get the summed
group delays of their legs; Doppler rows (count-averaged) get the change of
the summed phase delays over the count interval, end minus start — not the
delay itself. Running Doppler counts (TRK-2-34 ``doppler_count_<mode>``, each
row counting since the previous one) are Doppler rows of their mode: their
changes add up to the change over any compressed window. Columns added:

- ``tropo_m``, ``iono_m``, ``media_m`` (sum): m of path delay (range rows),
  m of delay change over the count interval (Doppler rows; the range-rate
  equivalent is ``media_m / count_time``). Subtract from the observable.
- ``media_ru``: ``media_m`` of range rows in range units, from the uplink
  frequency at transmission (row value or ramp; NaN when neither is known).
- Laser rows (a finite ``wavelength_nm``) get the Mendes-Pavlis optical troposphere from the
  row's own meteorology (:mod:`odpipe.media.mendes_pavlis`) and no ionosphere.
- ``media_source`` / ``media_source_up``: which file and card (or model)
  gave the downlink / uplink values; ``media_note``: why a fallback was used.

:func:`fallbacks` lists, per pass, the rows whose correction is a fallback or missing.

The spacecraft direction comes from ``target_itrs(t_utc) -> (N, 3)`` m
(apparent position seen from the ground at ground time), or from the
table's ``elevation_rx``/``azimuth_rx`` columns (rad), interpolated in time
per station. The round-trip light time comes from a ``rtlt_s`` column, else
from ``target_itrs`` (twice the station-spacecraft distance over c), else it
is taken as 0 and the note says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from odpipe.constants import C_LIGHT
from odpipe.environment.stations import StationCatalog, itrs_to_geodetic, topocentric
from odpipe.measurements.bands import range_unit_factor
from odpipe.media import mendes_pavlis, saastamoinen
from odpipe.media.model import MediaModel
from odpipe.media.smoothing import smooth_by_group
from odpipe.tracking import ramp_segments
from odpipe.tracking.passes import assign_passes
from odpipe.tracking.timetags import interval_bounds

# nominal DSN sky frequencies (Hz) when a row has no usable frequency
NOMINAL_HZ = {("up", "S"): 2.115e9, ("up", "X"): 7.16e9, ("up", "KA"): 34.3e9,
              ("down", "S"): 2.295e9, ("down", "X"): 8.42e9, ("down", "KA"): 32.05e9}
TWO_LEG = ("range", "doppler_2way", "doppler_3way")
GROUND = TWO_LEG + ("doppler_1way",)
NOT_GROUND = "not a ground radiometric observable: no correction"
NO_VALUE = "no correction computed"
NOT_ASKED = "row not asked for: no correction"


def calibrate(table: pd.DataFrame, model: MediaModel, *, target_itrs=None, ramps=None,
              catalog: StationCatalog | None = None, order: int | None = 10, rows=None):
    """(table with media columns, per-pass coverage report): :func:`calibrated` and :func:`pass_report`."""
    out = calibrated(table, model, target_itrs=target_itrs, ramps=ramps, catalog=catalog, order=order, rows=rows)
    return out, pass_report(out)


def calibrated(table: pd.DataFrame, model: MediaModel, *, target_itrs=None, ramps=None,
               catalog: StationCatalog | None = None, order: int | None = 10, rows=None) -> pd.DataFrame:
    """A copy of ``table`` with the media columns.

    ``ramps``: the uplink ramp table (or RampStore) beside the table, giving ramped rows their
    uplink frequency at transmission; ``order=None`` disables per-pass smoothing. ``rows``: a boolean
    mask of the rows to correct (default all); the others get none and a note saying so. Where passes
    hold one observable each (as :func:`assign_passes` makes them), a corrected row's value does not
    depend on which other rows are corrected.
    """
    catalog = catalog or StationCatalog.default()
    out = assign_passes(table) if (table["pass_id"] < 0).all() and len(table) else table.copy()   # a copy
    n = len(out)
    # a running Doppler count is a Doppler row of its mode (its interval: since the previous count)
    obs = strings(out["observable"], str)
    obs = np.char.replace(obs, "doppler_count_", "doppler_") if obs.size else obs
    ground = np.isin(obs, GROUND)
    wanted = np.ones(n, bool) if rows is None else np.asarray(rows, bool)
    doppler = np.char.startswith(obs, "doppler")
    epoch = out["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64)
    ct = np.where(doppler, out["count_time"].to_numpy(dtype=float), 0.0)
    start, end = interval_bounds(epoch, ct, out["tag"].to_numpy())
    rtlt, rtlt_note = _round_trip(out, target_itrs, catalog, epoch)

    # rows without geometry (NaN light time) get no direction either, so no correction: 0 is a placeholder
    rtlt_ns = np.rint(np.nan_to_num(rtlt) * 1e9).astype(np.int64)
    f_up, f_down, f_up_known = _frequencies(out, obs, epoch - rtlt_ns, ramps)
    s = _samples(out, obs, ground & wanted, doppler, epoch, start, end, rtlt_ns, f_up, f_down)
    tropo, iono, lab_t, lab_i = _leg_delays(s, out, model, target_itrs, catalog)
    if order is not None and s.row.size:
        key = np.ravel_multi_index((s.pass_code, s.up.astype(np.int64), s.station),
                                   (s.pass_code.max() + 1, 2, len(s.stations)))
        tsec = (s.t - s.t.min()) * 1e-9
        tropo = smooth_by_group(tsec, tropo, key, order)
        iono = smooth_by_group(tsec, iono, key, order)
    iono = np.where(s.phase, -iono, iono)
    rows, sign = s.row, s.sign
    out["tropo_m"] = _row_sum(n, rows, sign * tropo, ground & wanted)
    out["iono_m"] = _row_sum(n, rows, sign * iono, ground & wanted)
    out["media_m"] = out["tropo_m"] + out["iono_m"]
    is_range = obs == "range"
    bands, band_idx = np.unique(strings(out["band_up"], str), return_inverse=True)
    f_ru = f_up_known * range_unit_factor(bands)[band_idx]
    out["media_ru"] = np.where(is_range, out["media_m"].to_numpy() / C_LIGHT * f_ru, np.nan)
    code, texts = _source_texts(lab_t, lab_i)
    texts = np.append(np.asarray(texts, dtype=object), "")
    for leg_up, col in ((False, "media_source"), (True, "media_source_up")):
        pick = (sign > 0) & (s.up == leg_up)
        row_code = np.full(n, len(texts) - 1)
        row_code[rows[pick]] = code[pick]
        out[col] = categorical(row_code, texts)
    out["media_note"] = _notes(n, rows, code, texts.astype(str), ground, np.isin(obs, TWO_LEG), rtlt_note, wanted)
    return out


def strings(column: pd.Series, dtype=object) -> np.ndarray:
    """A column as a numpy array of ``dtype``, each distinct value converted once (a str column of
    many rows holds few names)."""
    codes, names = pd.factorize(column, use_na_sentinel=False)
    return np.asarray(names.to_numpy(dtype=dtype))[codes]


def categorical(codes: np.ndarray, texts: np.ndarray) -> pd.Categorical:
    """``pd.Categorical(texts[codes])`` (categories: the distinct texts present, sorted), each distinct
    code's text looked at once instead of once per row."""
    present, inverse = np.unique(codes, return_inverse=True)
    categories, to_category = np.unique(texts[present].astype(str), return_inverse=True)
    return pd.Categorical.from_codes(to_category[inverse], pd.Index(categories, dtype="str"))


def _source_texts(lab_t, lab_i):
    """(code per sample, texts): ``"tropo: <lab_t> | iono: <lab_i>"`` of each sample, as codes into the
    distinct texts in order of first appearance (as :func:`pandas.factorize`), each text built once."""
    ct, names_t = pd.factorize(lab_t)
    ci, names_i = pd.factorize(lab_i)
    pair, first = np.unique(ct * len(names_i) + ci, return_index=True)
    order = np.argsort(first, kind="stable")     # distinct pairs in order of first appearance
    rank = np.empty(order.size, np.int64)
    rank[order] = np.arange(order.size)
    code = rank[np.searchsorted(pair, ct * len(names_i) + ci)]
    p = pair[order]
    texts = np.array(["tropo: " + names_t[k // len(names_i)] + " | iono: " + names_i[k % len(names_i)] for k in p],
                     dtype=object)
    return code, texts


@dataclass(frozen=True)
class _Samples:
    """One sample per (row, leg, instant), as arrays: its ``row``, leg (``up``: the uplink), ``sign``
    (+1 the count's end or a range's tag, -1 a Doppler count's start), ``station`` (index into
    ``stations``; -1 none), ground time ``t`` (int64 ns UTC), leg frequency ``f`` (Hz), ``phase``
    (a Doppler row: phase delay), ``pass_code`` (the row's pass, numbered from 0) and ``spacecraft``
    (index into ``spacecraft_names``; -1 none)."""

    row: np.ndarray
    up: np.ndarray
    sign: np.ndarray
    station: np.ndarray
    t: np.ndarray
    f: np.ndarray
    phase: np.ndarray
    pass_code: np.ndarray
    spacecraft: np.ndarray
    stations: np.ndarray
    spacecraft_names: np.ndarray


def _samples(t, obs, ground, doppler, epoch, start, end, rtlt_ns, f_up, f_down) -> _Samples:
    """The samples of the rows ``ground``: the station, its ground time (ns) and the leg frequency.

    Range rows have one instant (the tag); Doppler rows two, the count's end (sign +1) and
    start (sign -1). Uplink instants are one round-trip light time before reception.
    """
    n = len(t)
    names = pd.factorize(np.concatenate([strings(t["station_rx"]), strings(t["station_tx"])]))
    rx, tx = names[0][:n], names[0][n:]
    parts = []
    up_rows = ground & np.isin(obs, TWO_LEG)
    for up, station, freq, leg_rows, shift in ((False, rx, f_down, ground, 0), (True, tx, f_up, up_rows, rtlt_ns)):
        for sign, at in ((1.0, np.where(doppler, end, epoch)), (-1.0, start)):
            rows = np.flatnonzero(leg_rows & ((sign > 0) | doppler))
            parts.append((rows, np.full(rows.size, up), np.full(rows.size, sign), station[rows], (at - shift)[rows],
                          freq[rows]))
    row, up, sign, station, when, f = (np.concatenate(c) for c in zip(*parts))
    sc, sc_names = pd.factorize(t["spacecraft"])
    return _Samples(row, up, sign, station, when, f, doppler[row], pd.factorize(t["pass_id"].to_numpy()[row])[0],
                    sc[row], np.asarray(names[1], dtype=object), np.asarray(sc_names.to_numpy(dtype=object)))


def _frequencies(t: pd.DataFrame, obs, tx_ns, ramps):
    """(uplink Hz, downlink Hz) per row: table value or ramp at transmission, turnaround, else nominal."""
    up = t["uplink_hz"].to_numpy(dtype=float).copy()
    store = ramp_segments.store(ramps)
    ramped = t["ramped"].to_numpy(dtype=bool) & np.isnan(up)
    if store is not None and ramped.any():
        tx_station = strings(t["station_tx"])[ramped]
        up[ramped] = store.frequency(tx_station, tx_ns[ramped].view("datetime64[ns]"))
    nominal = {}
    for leg, col in (("up", "band_up"), ("down", "band_down")):
        bands, idx = np.unique(strings(t[col], str), return_inverse=True)
        nominal[leg] = np.array([NOMINAL_HZ.get((leg, b.upper()), np.nan) for b in bands])[idx]
    f_up = np.where(np.isfinite(up), up, nominal["up"])
    one_way = strings(t["observable"]) == "doppler_1way"
    turned = f_up * t["transponder_ratio"].to_numpy(dtype=float)
    f_down = np.where(one_way & np.isfinite(up), up, np.where(np.isfinite(turned), turned, nominal["down"]))
    return f_up, f_down, up


def _round_trip(t: pd.DataFrame, target_itrs, catalog, epoch_ns):
    """(round-trip light time s per row, note) from a column, the target, or 0."""
    if "rtlt_s" in t.columns:
        return t["rtlt_s"].to_numpy(dtype=float), ""
    if target_itrs is None:
        return np.zeros(len(t)), "uplink at reception time (no light time known)"
    rtlt = np.zeros(len(t))
    times = epoch_ns.view("datetime64[ns]")
    for name, idx in t.groupby("station_rx").indices.items():
        if name in catalog:
            st = catalog[name]
            rtlt[idx] = 2.0 * np.linalg.norm(np.asarray(target_itrs(times[idx])) - st.position_itrs(times[idx]),
                                             axis=-1) / C_LIGHT
    return rtlt, ""


def _leg_delays(s: _Samples, table, model: MediaModel, target_itrs, catalog):
    """Group delays (troposphere, ionosphere, m) and their source labels per sample."""
    m = s.row.size
    tropo, iono = np.full(m, np.nan), np.full(m, np.nan)
    lab_t = np.full(m, "no station", dtype=object)
    lab_i = lab_t.copy()
    t_all = s.t.view("datetime64[ns]")
    for k, idx in pd.Series(np.arange(m)).groupby(s.station).indices.items():
        name = s.stations[k] if k >= 0 else None
        if name not in catalog:
            continue
        st = catalog[name]
        lat, lon, h = itrs_to_geodetic(st.r_itrs)
        lat_c = np.arctan2(st.r_itrs[2], np.hypot(st.r_itrs[0], st.r_itrs[1]))     # for the spherical shell
        t = t_all[idx]
        tu, back = np.unique(t, return_inverse=True)   # a count's end is the next one's start
        az, el = _direction(name, tu, table, None if target_itrs is None else np.asarray(target_itrs(tu)), st)
        d_t, l_t = model.troposphere(name, tu, np.where(el > 0.0, el, np.pi / 2), lat, h)   # once per time
        az, el, d_t, l_t = az[back], el[back], d_t[back], l_t[back]
        bad = ~(el > 0.0)        # no direction, or below the horizon
        el_ok = np.where(bad, np.pi / 2, el)
        az_ok = np.where(bad, 0.0, az)
        for sc, sub in pd.Series(np.arange(idx.size)).groupby(s.spacecraft[idx]).indices.items():
            if sc < 0:
                continue
            d_i, l_i = model.ionosphere(name, s.spacecraft_names[sc], t[sub], el_ok[sub], az_ok[sub], lat_c, lon,
                                        s.f[idx][sub])
            iono[idx[sub]] = np.where(bad[sub], np.nan, d_i)
            lab_i[idx[sub]] = np.where(bad[sub], "no direction", l_i)
        optical = _optical(table, s.row[idx], el_ok, lat, h)
        if optical is not None:
            laser, d_o, l_o = optical
            d_t, l_t = np.where(laser, d_o, d_t), np.where(laser, l_o, l_t)
            iono[idx] = np.where(laser & ~bad, 0.0, iono[idx])
            lab_i[idx] = np.where(laser & ~bad, "not at optical wavelengths", lab_i[idx])
        tropo[idx] = np.where(bad, np.nan, d_t)
        lab_t[idx] = np.where(bad, "no direction", l_t)
    return tropo, iono, lab_t, lab_i


def _optical(table, rows, elevation, lat, h):
    """(laser mask, Mendes-Pavlis delay m, label) of samples whose rows carry ``wavelength_nm``, else None.

    The row's surface meteorology (``pressure_mbar``, ``temperature_k``, ``humidity_pct``) is used
    for both legs; where any of it is missing, the standard atmosphere at the site.
    """
    if "wavelength_nm" not in table.columns:
        return None
    laser = np.isfinite(table["wavelength_nm"].to_numpy(dtype=float)[rows])
    if not laser.any():
        return None
    cols = ("pressure_mbar", "temperature_k", "humidity_pct")
    p, t, rh = (table[c].to_numpy(dtype=float)[rows] if c in table.columns else np.full(rows.size, np.nan)
                for c in cols)
    p = p * 100.0
    e = mendes_pavlis.vapour_pressure(rh, t, p)
    measured = np.isfinite(p) & np.isfinite(t) & np.isfinite(e)
    p0, t0, e0 = saastamoinen.standard_atmosphere(h)
    p, t, e = np.where(measured, p, p0), np.where(measured, t, t0), np.where(measured, e, e0)
    lam = np.where(laser, table["wavelength_nm"].to_numpy(dtype=float)[rows], 532.0)
    dry, wet = mendes_pavlis.zenith_delays(p, e, lat, h, lam)
    delay = (dry + wet) * mendes_pavlis.mapping(elevation, lat, h, t)
    label = np.where(measured, "Mendes-Pavlis (row meteo)", "Mendes-Pavlis (no meteo)")
    return laser, delay, label.astype(object)


def _direction(station, t, table, target, st):
    """(azimuth, elevation) rad at a station at UTC times ``t`` from the target's ITRS positions there (m)
    or, when None, the table's columns."""
    if target is not None:
        az, el, _ = topocentric(st, target, t)
        return az, el
    if "elevation_rx" not in table.columns:
        return np.full(t.size, np.nan), np.full(t.size, np.nan)
    rows = table[table["station_rx"] == station]
    tt = rows["epoch"].to_numpy().astype("datetime64[ns]").view(np.int64).astype(float)
    order = np.argsort(tt)
    tt, el = tt[order], rows["elevation_rx"].to_numpy(dtype=float)[order]
    az = np.unwrap(rows["azimuth_rx"].to_numpy(dtype=float)[order]) if "azimuth_rx" in rows else np.zeros(tt.size)
    x = t.view(np.int64).astype(float)
    if tt.size == 0:
        return np.full(t.size, np.nan), np.full(t.size, np.nan)
    inside = (x >= tt[0]) & (x <= tt[-1])
    return (np.mod(np.interp(x, tt, az), 2 * np.pi),
            np.where(inside, np.interp(x, tt, el), np.nan))


def _row_sum(n, rows, values, ground):
    out = np.zeros(n)
    np.add.at(out, rows, values)
    bad = np.zeros(n, dtype=bool)
    np.logical_or.at(bad, rows, ~np.isfinite(values))
    return np.where(ground & ~bad, out, np.nan)


def _notes(n, rows, code, texts, ground, two_leg, rtlt_note, wanted):
    """Per row: why its correction is partial or a fallback (from every sample's source text)."""
    reasons = [("(no TRO)", "no TRO coverage: DSN seasonal model used"),
               ("standard-atmosphere", "non-DSN station: standard atmosphere used"),
               ("(no meteo)", "laser row without meteorology: standard atmosphere used"),
               ("iono: none", "no ionosphere calibration: none applied"),
               ("no direction", "no spacecraft direction or below horizon: no correction"),
               ("no station", "station not in catalog: no correction")]
    bits = np.zeros(n, dtype=np.int64)
    for k, (flag, _) in enumerate(reasons):
        hit = (np.char.find(texts, flag) >= 0)[code]
        np.bitwise_or.at(bits, rows[hit], 1 << k)
    extra = [(two_leg & wanted, rtlt_note), (~ground, NOT_GROUND), (ground & ~wanted, NOT_ASKED)]
    for k, (mask, _) in enumerate(extra, len(reasons)):
        bits |= np.where(mask, 1 << k, 0)
    words = [text for _, text in reasons] + [text for _, text in extra]
    uniq, inv = np.unique(bits, return_inverse=True)
    names = ["; ".join(w for k, w in enumerate(words) if u >> k & 1 and w) for u in uniq]
    return categorical(inv, np.asarray(names, dtype=object))


def pass_report(t: pd.DataFrame) -> pd.DataFrame:
    """Per pass: station, rows, time span, sources used, and notes (fallbacks and their reasons)."""
    g = t.groupby("pass_id", sort=True)
    return pd.DataFrame({
        "station_rx": g["station_rx"].first(),
        "observable": g["observable"].first(),
        "rows": g.size(),
        "start": g["epoch"].min(),
        "end": g["epoch"].max(),
        "sources": _joined(t["pass_id"], t["media_source"], " || ", None),
        "notes": _joined(t["pass_id"], t["media_note"], "; ", "; "),
    }).reset_index()


def _joined(pass_id: pd.Series, text: pd.Series, sep: str, split: str | None) -> pd.Series:
    """Per pass: the distinct values of ``text`` (each cut at ``split`` first, empty parts dropped), sorted
    and joined with ``sep``; each distinct value of a pass is handled once."""
    pairs = pd.DataFrame({"pass_id": pass_id.to_numpy(), "text": text.astype(str).to_numpy()}).drop_duplicates()
    if split is not None:
        pairs = pairs.assign(text=pairs["text"].str.split(split)).explode("text")
        pairs = pairs[pairs["text"] != ""].drop_duplicates()
    return pairs.sort_values("text", kind="stable").groupby("pass_id", sort=True)["text"].agg(sep.join).reindex(
        pd.Index(np.unique(pass_id.to_numpy()), name="pass_id"), fill_value="")


def fallbacks(t: pd.DataFrame) -> pd.DataFrame:
    """Per pass and reason, the rows of a calibrated table whose correction is a fallback or missing.

    Reasons are the ``media_note`` parts, and ``NO_VALUE`` for a ground row left NaN without one;
    rows that need no correction (not ground radiometric) are left out. Columns ``pass_id``,
    ``station_rx``, ``observable``, ``start``, ``end`` (UTC of the pass), ``reason``, ``rows``
    (rows of the pass with that reason) and ``of`` (rows of the pass).
    """
    note = t["media_note"].astype(str)
    ground = ~note.str.contains(NOT_GROUND, regex=False)
    reason = note.where((note != "") | t["media_m"].notna(), NO_VALUE)
    g = t.groupby("pass_id", sort=True)
    passes = pd.DataFrame({"station_rx": g["station_rx"].first(), "observable": g["observable"].first(),
                           "start": g["epoch"].min(), "end": g["epoch"].max(), "of": g.size()})
    rows = pd.DataFrame({"pass_id": t["pass_id"].to_numpy(), "reason": reason.to_numpy()})[ground.to_numpy()]
    rows = rows[rows["reason"] != ""].assign(reason=lambda d: d["reason"].str.split("; ")).explode("reason")
    counts = rows.groupby(["pass_id", "reason"], sort=True).size().rename("rows").reset_index()
    out = counts.join(passes, on="pass_id")
    return out[["pass_id", "station_rx", "observable", "start", "end", "reason", "rows", "of"]]
