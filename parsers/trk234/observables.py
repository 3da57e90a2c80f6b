"""TRK-2-34 record blocks -> TrackingTable rows and the uplink ramp table.

Rows per format code (``value`` in the format's own unit, named in ``unit``):

- 0 uplink carrier phase: ``phase_uplink`` (cycles; hi*2^32 + lo + frac*2^-32), tag 'transmit'
- 1 downlink carrier phase: ``phase_downlink`` (cycles; sample 0 at the time tag)
- 2/3 sequential ranging phase: ``range_phase_uplink`` / ``range_phase_downlink`` (RU)
- 4/5 PN ranging phase: ``pn_phase_uplink`` / ``pn_phase_downlink`` (RU)
- 6 Doppler count: ``doppler_count_1way/2way/3way`` (cycles, tag 'interval_end'), by the Doppler mode
- 7 sequential range and 14 PN range: ``range`` (RU)
- 8 angles: ``angle_1`` and ``angle_2`` (rad from degrees; ``angle_type`` keeps the SIS code)
- 11 DRVID: ``drvid`` (RU)
- 16 carrier frequency observable: ``carrier_freq`` (Hz), one row per observation
- 17 total count phase: ``total_phase`` (cycles), one row per observation

Stations, mode and bands of SFDUs with a downlink follow :func:`_link` (validated fields
first). Formats 9 (ramps) go to the ramp table (every ramp record starts a segment that
ends where the station's next one starts, whatever its ``ramp_type``, which is kept);
10, 12, 13, 15 carry no navigation observable here and stay in the record blocks only.
Every row keeps ``format_code`` and ``record`` (index of its SFDU in the file), so all of
that SFDU's fields can be found in the blocks.

What these interpretations rest on (the SIS text itself is not available here): the byte
layout of every field agrees with JPL's PyTrk234 (tests/test_trk234.py). Three independent
converters agree with the rest: NASA's trk234-to-GMD script (phase = hi*2^32 + lo +
frac*2^-32; total count phase at the SFDU time, consecutive SFDUs ``obs_cnt_time``
apart), Tudat's TNF loader (observation 0 of format 16 at the SFDU time, count time
``obs_cnt_time``; the link rules of :func:`_link`) and CU Boulder's scarabaeus (range in
RU, RU per second = 16 * exc_scalar_num / exc_scalar_den * uplink Hz, quoting TRK-2-34
Rev N note 39). Assumed, not confirmed by any source: observation k of one format 16/17
SFDU at the SFDU time + k * obs_cnt_time; the degree unit of angles; the RU unit of
ranging phases and DRVID; ``range`` = ``rng_obs`` (format 7) and ``rng_obs_dl``
(format 14), where those converters instead take ``meas_rng`` and apply the station
calibrations and Z-height corrections themselves; and every ramp record starting a
segment, where Tudat keeps only ramp types 1 (start) and 4/5 (end).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.constants import SECONDS_PER_DAY
from parsers import table as tt
from parsers.trk234 import layout
from parsers.trk234.sfdu import Block

_DEG = np.pi / 180.0


def utc(year, doy, sec) -> np.ndarray:
    """datetime64[ns] UTC from (year, day of year, seconds of day) arrays."""
    jan1 = (np.asarray(year, np.int64) - 1970).astype("datetime64[Y]").astype("datetime64[D]")
    ns = np.round(np.asarray(sec, np.float64) * 1e9).astype(np.int64).astype("timedelta64[ns]")
    return jan1 + (np.asarray(doy, np.int64) - 1).astype("timedelta64[D]") + ns


def phase_cycles(hi, lo, frac) -> np.ndarray:
    """Cycles from the SIS's three unsigned words: hi * 2^32 + lo + frac * 2^-32."""
    return (np.asarray(hi, np.float64) * 4294967296.0 + np.asarray(lo, np.float64)
            + np.asarray(frac, np.float64) / 4294967296.0)


_DSS = np.array([""] + [f"DSS-{i:02d}" for i in range(1, 256)], dtype=object)
_BAND = np.array([layout.BANDS.get(c, "?") for c in range(256)], dtype=object)
_NUMBER = np.array([str(i) for i in range(256)], dtype=object)


def _dss(ids) -> np.ndarray:
    return _DSS[np.asarray(ids)]


def _band(codes) -> np.ndarray:
    return _BAND[np.asarray(codes)]


_DOPPLER = {1: "1way", 2: "2way", 3: "3way"}


def doppler_mode(r: np.ndarray) -> np.ndarray:
    """Doppler mode (1, 2, 3 way; 0 none, 4 invalid): the validated ``vld_dop_mode``, else ``prdx_mode``."""
    return np.where(r["vld_dop_mode"] != 0, r["vld_dop_mode"], r["prdx_mode"]).astype(np.int64)


def _link(r: np.ndarray, station_rx: np.ndarray) -> dict:
    """Transmitting station and uplink band of SFDUs with a downlink (C124, C125, C127).

    The validated fields win over the predicted ones (``vld_ul_stn`` over the
    receiver for 2-way and ``ul_prdx_stn`` for 3-way; ``vld_dop_mode`` over
    ``prdx_mode``), as Tudat's TNF loader reads them; the uplink band is
    ``ul_band_dl`` (the uplink band the downlink channel reports), else
    ``ul_band``. One-way rows (and modes none or invalid) have no transmitter
    and no uplink band.
    """
    mode = doppler_mode(r)
    predicted = np.where(mode == 2, station_rx, np.where(mode == 3, _dss(r["ul_prdx_stn"]), ""))
    tx = np.where(r["vld_ul_stn"] != 0, _dss(r["vld_ul_stn"]), predicted)
    band = r["ul_band_dl"]
    if "ul_band" in r.dtype.names:
        band = np.where(band != 0, band, r["ul_band"])
    no_uplink = (mode == 1) | (mode == 0) | (mode == 4)
    return {"station_tx": np.where(no_uplink, "", tx).astype(object),
            "band_up": np.where(no_uplink, "", _band(band)).astype(object)}


def _common(r: np.ndarray, fc: int) -> dict:
    """Columns every format shares: time tag, spacecraft, stations and bands from the secondary CHDO."""
    names = r.dtype.names
    cols = {"epoch": utc(r["year"], r["doy"], r["sec"]), "spacecraft": _NUMBER[r["scft_id"]]}
    if "ul_dss_id" in names:
        cols["station_tx"] = _dss(r["ul_dss_id"])
    if "ul_band" in names:
        cols["band_up"] = _band(r["ul_band"])
    if "dl_dss_id" in names:
        cols["station_rx"] = _dss(r["dl_dss_id"])
    if "vld_dop_mode" in names:  # downlink, derived and filtered SFDUs
        cols.update(_link(r, cols["station_rx"]))
    if "vld_dl_band" in names:
        cols["band_down"] = _band(r["vld_dl_band"])
    elif "dl_band" in names:
        cols["band_down"] = _band(r["dl_band"])
    if "scft_transpd_turn_den" in names:
        den = r["scft_transpd_turn_den"].astype(np.float64)
        cols["transponder_ratio"] = np.where(den > 0, r["scft_transpd_turn_num"] / np.where(den > 0, den, 1),
                                             np.nan)
    if "cnt_time" in names:
        with np.errstate(invalid="ignore"):  # a signalling-NaN bit pattern stays NaN, no warning
            cols["count_time"] = r["cnt_time"].astype(np.float64)
    cols["tag"] = "transmit" if layout.CLASS_OF_FORMAT[fc] == "C123" else "receive"
    cols["format_code"] = np.int64(fc)
    return cols


def _rows(block: Block) -> list[dict]:
    """Column dicts (one per observable kind) of one block."""
    r, fc = block.records, block.format_code
    base = _common(r, fc)
    base["record"] = block.index
    one = {
        0: ("phase_uplink", lambda: phase_cycles(r["ul_hi_phs_cycles"], r["ul_lo_phs_cycles"],
                                                 r["ul_frac_phs_cycles"]), "cycles"),
        1: ("phase_downlink", lambda: phase_cycles(r["phs_hi_0"], r["phs_lo_0"], r["phs_frac_0"]), "cycles"),
        2: ("range_phase_uplink", lambda: r["ul_rng_phs"], "RU"),
        3: ("range_phase_downlink", lambda: r["dl_rng_phs"], "RU"),
        4: ("pn_phase_uplink", lambda: r["ul_rng_phs"], "RU"),
        5: ("pn_phase_downlink", lambda: r["dl_rng_phs"], "RU"),
        7: ("range", lambda: r["rng_obs"], "RU"),
        11: ("drvid", lambda: r["drvid"], "RU"),
        14: ("range", lambda: r["rng_obs_dl"], "RU"),
    }
    if fc in one:
        name, value, unit = one[fc]
        extra = {}
        if fc == 0:
            extra["uplink_hz"] = r["ramp_freq"]
        if fc in (7, 14):
            extra["range_modulus"] = r["rng_modulo"].astype(np.float64)
            extra["uplink_hz"] = r["ul_freq"] if fc == 7 else np.nan
        return [dict(base, observable=name, value=np.asarray(value(), np.float64), unit=unit, **extra)]
    if fc == 6:
        mode = np.array([_DOPPLER.get(m, "unknown") for m in range(256)], dtype=object)[doppler_mode(r)]
        # the count accumulates up to the time tag; count_time is the time since the previous count
        return [dict(base, observable=np.char.add("doppler_count_", mode.astype(str)).astype(object),
                     value=r["dop_cnt"].astype(np.float64), unit="cycles", uplink_hz=r["ul_freq"],
                     doppler_bias_hz=r["dop_cnt_bias_freq"], tag="interval_end")]
    if fc == 8:
        return [dict(base, observable=f"angle_{k}", value=r[f"ang{k}"].astype(np.float64) * _DEG, unit="rad",
                     angle_type=r["ang_type"].astype(np.int64)) for k in (1, 2)]
    if fc in (16, 17):
        n = block.n_obs
        if n == 0:
            return []
        obs = r["obs"]
        spacing = r["obs_cnt_time"].astype(np.float64)
        spacing = np.where(np.isfinite(spacing) & (np.abs(spacing) < SECONDS_PER_DAY), spacing, np.nan)
        step = pd.to_timedelta((np.arange(n) * spacing[:, None]).ravel(), unit="s").to_numpy().reshape(-1, n)
        rep = {k: np.repeat(np.asarray(v), n) if np.ndim(v) else v for k, v in base.items()}
        rep["epoch"] = (base["epoch"][:, None] + step).ravel()
        rep["count_time"] = np.repeat(r["obs_cnt_time"].astype(np.float64), n)
        rep["sample"] = np.tile(np.arange(n), len(r))
        if fc == 16:
            return [dict(rep, observable="carrier_freq", value=obs["rcv_carr_obs"].ravel(), unit="Hz")]
        value = phase_cycles(obs["total_cnt_phs_obs_hi"], obs["total_cnt_phs_obs_lo"], obs["total_cnt_phs_obs_frac"])
        return [dict(rep, observable="total_phase", value=value.ravel(), unit="cycles")]
    return []


def _missing_like(values, n: int) -> np.ndarray:
    kind = np.asarray(values).dtype.kind
    fill = {"f": np.nan, "i": -1, "u": -1, "b": False, "M": np.datetime64("NaT", "ns")}.get(kind, "")
    return np.full(n, fill, dtype=object if kind not in "fiubM" else None)


def tracking_table(blocks: list[Block], source: str) -> pd.DataFrame:
    """The TrackingTable of all navigation observables in ``blocks``, time ordered."""
    parts = [cols for block in blocks for cols in _rows(block)]
    if not parts:
        return tt.empty({"format_code": "int64"})
    sizes = [len(p["record"]) for p in parts]
    names = list(dict.fromkeys(k for p in parts for k in p))
    columns = {}
    for name in names:
        like = next(p[name] for p in parts if name in p)
        columns[name] = np.concatenate([
            np.broadcast_to(np.asarray(p[name]), (n,)) if name in p else _missing_like(like, n)
            for p, n in zip(parts, sizes)])
    df = tt.build_owned(sum(sizes), source=source, flags=0, **columns)
    return df.sort_values(["epoch", "record"], kind="stable").reset_index(drop=True)


def ramp_table(blocks: list[Block], source: str) -> pd.DataFrame:
    """Uplink ramps (format 9) per RAMP_COLUMNS; a segment ends where the station's next one starts."""
    ramps = [b for b in blocks if b.format_code == 9]
    if not ramps:
        return tt.empty_ramps()
    r = np.concatenate([b.records for b in ramps])
    index = np.concatenate([b.index for b in ramps])
    df = pd.DataFrame({
        "station": _dss(r["ul_dss_id"]),
        "start": utc(r["year"], r["doy"], r["sec"]),
        "end": np.datetime64("NaT", "ns"),
        "freq_hz": r["ramp_freq"].astype(np.float64),
        "rate_hz_s": r["ramp_rate"].astype(np.float64),
        "band": _band(r["ul_band"]),
        "source": source,
        "record": index.astype(np.int64),
        "ramp_type": r["ramp_type"].astype(np.int64),
    }).sort_values(["station", "start", "record"], kind="stable")
    df["end"] = df.groupby("station")["start"].shift(-1)
    return df.sort_values(["start", "record"], kind="stable").reset_index(drop=True)
